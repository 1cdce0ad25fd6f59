"""HEIDENHAIN nonlinear axis error compensation: compensation-value tables ``*.COM`` and
their assignment table ``*.CMA``.

What the HEIDENHAIN Technical Manuals say (MANUALplus 620, "Nonlinear axis error
compensation": entering compensation values, assigning the tables to the axes; TNC 407 /
415 / 425, section "Non-linear axis error compensation" and module 9095; cited in
docs/compensation.md) and how esp reads them:

* a ``*.COM`` table holds the compensation points in the column ``AXISPOS`` (positions
  referred to the machine datum) and, in a column named after each compensated axis, the
  compensation values at those points; ``BACKLASH`` the values measured in the negative
  direction of traverse;
* the ``*.CMA`` table has a column per axis and, on each line, the ``*.COM`` tables
  entered under the axes; the line marked ``*`` in ``ACTIVE`` is active; the relation is
  [axis of a column of the .COM] = F(axis of the .CMA column in which the .COM is
  entered): ``Y.COM`` under ``Y`` with the columns ``Y`` and ``Z`` is Y = F(Y) (the
  leadscrew) and Z = F(Y) (sag);
* module 9095 reports a ``.COM`` table of more than 256 entries as an error (TNC 407):
  esp refuses more points (``--max-points heidenhain=N`` for a control that takes more).

Not in the documents read, offered as options: the sign of the values
(``heidenhain-sign``, default ``error``: the TNC 407 example plots the values as "Error in
Z"), whether ``BACKLASH`` holds the negative direction's whole value or its difference
from the positive one (``heidenhain-backlash``, default ``absolute``: "the compensation
values measured in the negative direction"), what is applied beyond the last point (esp:
the end value held), the file syntax (esp writes the TNC table layout ``BEGIN name MM``,
a header line, one line per point, ``[END]``); positions and values in mm with 4
decimals (0.1 µm).

This module imports only numpy and the standard library.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from esp.compensation.formats.base import Capabilities, Format, FormatSettings, Limits
from esp.compensation.model import AxisTable, CompensationSet
from esp.core.errors import DataError, ParseError

__all__ = ["CMA_FILE", "FORMATS", "LIMITS", "read", "write"]

CMA_FILE = "CONFIG.CMA"
DECIMALS = 4
LIMITS = {"heidenhain": 256}
OPTIONS = {
    "heidenhain-sign": ("error", "correction"),
    "heidenhain-backlash": ("absolute", "difference"),
}


def _fmt(value: float) -> str:
    return f"{round(float(value), DECIMALS) + 0.0:+.{DECIMALS}f}"


def _options(settings: FormatSettings) -> tuple[float, bool]:
    """(factor from esp's correction in µm to the written mm, BACKLASH as a difference)."""
    sign = -1.0 if settings.option("heidenhain-sign", "error") == "error" else 1.0
    return sign / 1000.0, settings.option("heidenhain-backlash", "absolute") == "difference"


def write(cset: CompensationSet, settings: FormatSettings | None = None) -> dict[str, str]:
    """One ``<input axis>.COM`` per input axis (its leadscrew column, the columns of the
    axes it moves and ``BACKLASH``) and ``CONFIG.CMA``.

    Raises
    ------
    DataError
        A table of more points than the limit, two tables of one input axis on different
        points.
    """
    s = settings or FormatSettings()
    limit = {**LIMITS, **s.limits}["heidenhain"]
    factor, difference = _options(s)
    by_input: dict[str, list[AxisTable]] = {}
    for t in cset.axis_tables:
        by_input.setdefault(t.master, []).append(t)
    files = {}
    for master, tables in sorted(by_input.items()):
        positions = tables[0].positions_mm
        for t in tables[1:]:
            if not np.array_equal(t.positions_mm, positions):
                raise DataError(f"the tables over {master} must share their points (AXISPOS)")
        if positions.size > limit:
            raise DataError(
                f"the table {master}.COM has {positions.size} points; the control takes "
                f"{limit} per table: choose a larger --spacing or give --max-points heidenhain=N"
            )
        tables = sorted(tables, key=lambda t: (t.slave != master, t.slave))
        lead = next((t for t in tables if t.kind == "lead"), None)
        columns = ["NR", "AXISPOS"] + [t.slave for t in tables]
        if lead is not None and lead.bilateral:
            columns.append("BACKLASH")
        lines = [f"BEGIN {master}.COM MM", "".join(f"{c:<14}" for c in columns).rstrip()]
        for i, p in enumerate(positions):
            cells = [str(i), _fmt(p)]
            for t in tables:
                cells.append(_fmt(factor * t.forward_um[i]))
            if "BACKLASH" in columns and lead is not None:
                back = lead.backward_um[i] - (lead.forward_um[i] if difference else 0.0)
                cells.append(_fmt(factor * back))
            lines.append("".join(f"{c:<14}" for c in cells).rstrip())
        lines.append("[END]")
        files[f"{master}.COM"] = "\n".join(lines) + "\n"
    axes = sorted(by_input)
    cma = [f"BEGIN {CMA_FILE}", "".join(f"{c:<10}" for c in ["NR", "ACTIVE", *axes]).rstrip()]
    cma.append("".join(f"{c:<10}" for c in ["0", "*", *(f"{a}.COM" for a in axes)]).rstrip())
    cma.append("[END]")
    files[CMA_FILE] = "\n".join(cma) + "\n"
    return files


def _table(text: str, path: str) -> tuple[list[str], list[tuple[int, list[str]]]]:
    lines = text.splitlines()
    if not lines or not lines[0].startswith("BEGIN "):
        raise ParseError(path, 1, "expected 'BEGIN <name>'")
    if len(lines) < 2:
        raise ParseError(path, None, "no header line")
    header = lines[1].split()
    rows: list[tuple[int, list[str]]] = []
    for n, raw in enumerate(lines[2:], start=3):
        if raw.strip() == "[END]":
            return header, rows
        if raw.strip():
            cells = raw.split()
            if len(cells) != len(header):
                raise ParseError(path, n, f"expected {len(header)} cells, found {len(cells)}")
            rows.append((n, cells))
    raise ParseError(path, None, "expected [END]")


def read(files: Mapping[str, str], settings: FormatSettings | None = None) -> CompensationSet:
    """Read the tables of the active line of ``CONFIG.CMA`` back into axis tables
    (corrections in µm)."""
    s = settings or FormatSettings()
    factor, difference = _options(s)
    if CMA_FILE not in files:
        raise ParseError(CMA_FILE, None, "missing")
    header, rows = _table(files[CMA_FILE], CMA_FILE)
    active = [
        cells for _, cells in rows if "ACTIVE" in header and cells[header.index("ACTIVE")] == "*"
    ]
    if len(active) != 1:
        raise ParseError(
            CMA_FILE, None, f"expected one line marked * in ACTIVE, found {len(active)}"
        )
    tables = []
    for master, name in zip(header, active[0], strict=True):
        if master in ("NR", "ACTIVE"):
            continue
        if name not in files:
            raise ParseError(CMA_FILE, None, f"{name} (column {master}) is missing")
        cols, data = _table(files[name], name)
        try:
            values = np.array([[float(c) for c in cells] for _, cells in data])
        except ValueError:
            raise ParseError(name, None, "expected numbers in every cell") from None
        if "AXISPOS" not in cols or values.shape[0] < 2:
            raise ParseError(name, 2, "expected AXISPOS and at least 2 points")
        positions = values[:, cols.index("AXISPOS")]
        for slave in cols:
            if slave in ("NR", "AXISPOS", "BACKLASH"):
                continue
            fwd = values[:, cols.index(slave)] / factor
            bwd = fwd
            if slave == master and "BACKLASH" in cols:
                back = values[:, cols.index("BACKLASH")] / factor
                bwd = back + (fwd if difference else 0.0)
            kind = "lead" if slave == master else "cross"
            tables.append(AxisTable(slave, master, positions, fwd, bwd, kind))
    return CompensationSet("heidenhain", axis_tables=tuple(tables))


class Heidenhain(Format):
    """HEIDENHAIN .COM tables (one per input axis) and their .CMA assignment."""

    name = "heidenhain"
    description = "HEIDENHAIN nonlinear axis error compensation, *.COM tables and CONFIG.CMA"
    load_words = (
        "copy the .COM tables and CONFIG.CMA to the control (PLC partition), enable the "
        "nonlinear axis error compensation and activate the line marked * in CONFIG.CMA"
    )
    order = 60
    capabilities = Capabilities(
        frozenset({"lead", "cross"}),
        error_kinds=frozenset({"linear", "straightness", "squareness"}),
        bidirectional=True,
        masters_per_axis=2,
    )
    limit_defaults = LIMITS
    format_options = OPTIONS

    def limits(self, settings: FormatSettings) -> Limits:
        return Limits(points_per_table={**LIMITS, **settings.limits}["heidenhain"], tables=3)

    def write(self, cset: CompensationSet, settings: FormatSettings) -> dict[str, str]:
        return write(cset, settings)

    def read(self, files: Mapping[str, str], settings: FormatSettings) -> CompensationSet:
        return read(files, settings)

    def resolution_um(self, settings: FormatSettings) -> float:
        return 1000.0 * 10.0**-DECIMALS


FORMATS = (Heidenhain(),)
