"""TwinCAT CNC / ISG volumetric compensation: the error parameters in the ISG CSV format.

What the Beckhoff documentation (TF5280 Volumetric Compensation, cited in
docs/compensation.md) says and how esp reads it:

* the file is a table: a header line names the columns (an argument such as ``X`` and
  parameter names), the rows below hold the records, white space separates the fields;
  ``//`` starts a comment line; ``#`` breaks the file, and a new header may follow;
* parameter names follow DIN ISO 230: component errors ``EXX EYX EZX EAX EBX ECX`` (and
  those of Y and Z) as functions of their axis' position, position errors without the
  leading ``E`` such as ``C0Y``, ``B0Z``, ``A0Z`` (the squareness of Y to X, Z to X,
  Z to Y) as single values;
* units: offsets in millimetres, angles in radians, arguments (axis positions) in
  millimetres;
* with interpolation ``GRID`` (the default) the parameters are interpolated linearly on
  their grid; the documentation does not say what happens beyond the last record, so esp
  writes every axis' table over its whole travel (prediction: end values held);
* the number of records read is bounded by ``vol_comp[i].max_records`` of the start-up
  list (P-STUP-00100), which the user sets; esp reports the count and refuses more than a
  limit given to it.

The values are the errors (actual - nominal, esp's components as the engine uses them:
straightness with its set-up slope removed); the controller computes the correction from
them with its kinematic model (``negate``, P-VOLC-00009, flips the compensation per
axis). Resolution written: 1 nm and 1 nrad.

This module imports only numpy and the standard library.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from esp.compensation.formats.base import Capabilities, Format, FormatSettings
from esp.compensation.model import CompensationSet, ComponentTable
from esp.core.errors import DataError, ParseError
from esp.core.names import ComponentName

__all__ = ["FORMATS", "FILE", "iso_symbol", "name_of", "scale", "read", "record_count", "write"]

FILE = "volcomp.csv"
DECIMALS_MM = 6
DECIMALS_RAD = 9
_ROT = {"X": "A", "Y": "B", "Z": "C"}


def iso_symbol(name: str) -> str:
    """The ISG parameter name of a component: ``X.linear`` -> ``EXX``,
    ``X.straightness.Y`` -> ``EYX``, ``X.angular.Z`` -> ``ECX``, ``squareness.XY`` ->
    ``C0Y`` (ISO 230-1 EC0Y without the leading E, as the ISG list of position errors)."""
    parts = str(name).split(".")
    if parts[0] == "squareness":
        a, b = parts[1][0], parts[1][1]
        third = next(n for n in "XYZ" if n not in (a, b))
        return f"{_ROT[third]}0{b}"
    axis, kind = parts[0], parts[1]
    if kind == "linear":
        return f"E{axis}{axis}"
    if kind == "straightness":
        return f"E{parts[2]}{axis}"
    if kind == "angular":
        return f"E{_ROT[parts[2]]}{axis}"
    raise DataError(f"{name}: the ISG volumetric table has no parameter for a {kind} error")


def name_of(symbol: str) -> str:
    """The component name of an ISG parameter name (the inverse of :func:`iso_symbol`)."""
    rot = {v: k for k, v in _ROT.items()}
    if len(symbol) == 3 and symbol[1] == "0" and symbol[0] in rot and symbol[2] in "XYZ":
        b = symbol[2]
        pair = [a for a in "XYZ" if a not in (rot[symbol[0]], b)] + [b]
        return "squareness." + "".join(sorted(pair, key="XYZ".index))
    if len(symbol) == 3 and symbol[0] == "E" and symbol[2] in "XYZ":
        what, axis = symbol[1], symbol[2]
        if what == axis:
            return f"{axis}.linear"
        if what in "XYZ":
            return f"{axis}.straightness.{what}"
        if what in rot:
            return f"{axis}.angular.{rot[what]}"
    raise DataError(f"unknown ISG parameter name {symbol!r}")


_name_of = name_of  # the name the tests of this module use


def _fmt(value: float, decimals: int) -> str:
    return f"{round(float(value), decimals) + 0.0:.{decimals}f}"


def scale(name: str) -> tuple[float, int]:
    """Factor from esp's unit to the file's (µm -> mm, µm/m -> rad) and decimals."""
    kind = name.split(".")[1] if not name.startswith("squareness") else "squareness"
    if kind in ("linear", "straightness"):
        return 1e-3, DECIMALS_MM
    return 1e-6, DECIMALS_RAD


def record_count(cset: CompensationSet) -> int:
    """Data rows of the file (one for the position errors, one per table point)."""
    table = cset.component_table
    if table is None:
        return 0
    axes = {name.split(".")[0]: p.size for name, (p, _) in table.curves.items()}
    return (1 if table.squareness else 0) + sum(axes.values())


def write(cset: CompensationSet, max_records: int | None = None) -> dict[str, str]:
    """The text of ``volcomp.csv``.

    Raises
    ------
    DataError
        More records than ``max_records`` (the user's ``vol_comp[i].max_records``).
    """
    table = cset.component_table
    if table is None:
        raise DataError("the isg-volumetric format needs a component table")
    n_records = record_count(cset)
    if max_records is not None and n_records > max_records:
        raise DataError(
            f"the table has {n_records} records; vol_comp[i].max_records (P-STUP-00100) was given "
            f"as {max_records}: raise it in the start-up list or choose a larger --spacing"
        )
    lines = [
        "// volumetric compensation parameters written by esp (ISG CSV format)",
        "// units: positions and offsets in mm, angles in rad; values are errors",
    ]
    if table.squareness:
        names = sorted(table.squareness)
        lines.append(" ".join(iso_symbol(n) for n in names))
        # ISO 230-1 signs: the location error E{t}0{b} of the pair (ComponentName.iso_sign)
        lines.append(
            " ".join(
                _fmt(ComponentName.parse(n).iso_sign * table.squareness[n] * 1e-6, DECIMALS_RAD)
                for n in names
            )
        )
    for axis in "XYZ":
        names = [n for n in table.curves if n.split(".")[0] == axis]
        if not names:
            continue
        order = {f"{axis}.linear": 0}
        names.sort(key=lambda n: (order.get(n, 1), "XYZABC".index(iso_symbol(n)[1])))
        positions = table.curves[names[0]][0]
        for n in names[1:]:
            if not np.array_equal(table.curves[n][0], positions):
                raise DataError(f"{n}: the components of axis {axis} must share their table points")
        if lines[-1] != "#" and len(lines) > 2:
            lines.append("#")
        lines.append(" ".join([axis] + [iso_symbol(n) for n in names]))
        for i, p in enumerate(positions):
            cells = [_fmt(p, DECIMALS_MM)]
            for n in names:
                factor, dec = scale(n)
                cells.append(_fmt(table.curves[n][1][i] * factor, dec))
            lines.append(" ".join(cells))
    return {FILE: "\n".join(lines) + "\n"}


def read(files: Mapping[str, str]) -> CompensationSet:
    """Read ``volcomp.csv`` back into a component table (esp's units)."""
    if FILE not in files:
        raise ParseError(FILE, None, "missing")
    text = files[FILE]
    curves: dict[str, tuple[np.ndarray, np.ndarray]] = {}
    squareness: dict[str, float] = {}
    header: list[str] | None = None
    rows: list[tuple[int, list[float]]] = []

    def flush() -> None:
        if header is None:
            return
        if header[0] in "XYZ":
            axis = header[0]
            data = np.array([r for _, r in rows], dtype=float).reshape(-1, len(header))
            for k, symbol in enumerate(header[1:], start=1):
                name = name_of(symbol)
                if name.split(".")[0] != axis:
                    raise ParseError(FILE, None, f"{symbol} is not a parameter of axis {axis}")
                factor, _ = scale(name)
                curves[name] = (data[:, 0], data[:, k] / factor)
        else:
            if len(rows) != 1:
                raise ParseError(FILE, None, "position errors take exactly one data row")
            for symbol, value in zip(header, rows[0][1], strict=True):
                name = name_of(symbol)
                if not name.startswith("squareness"):
                    raise ParseError(FILE, None, f"{symbol} needs an argument column")
                squareness[name] = ComponentName.parse(name).iso_sign * value * 1e6

    for number, raw in enumerate(text.splitlines(), start=1):
        line = raw.strip()
        if not line or line.startswith("//"):
            continue
        if line == "#":
            flush()
            header, rows = None, []
            continue
        fields = line.split()
        if header is None:
            header = fields
            for symbol in header if header[0] not in "XYZ" else header[1:]:
                try:
                    name_of(symbol)
                except DataError as exc:
                    raise ParseError(FILE, number, str(exc)) from None
            continue
        if len(fields) != len(header):
            raise ParseError(FILE, number, f"expected {len(header)} fields, found {len(fields)}")
        try:
            rows.append((number, [float(f) for f in fields]))
        except ValueError:
            raise ParseError(FILE, number, f"expected numbers, found {line[:60]!r}") from None
    flush()
    return CompensationSet("isg-volumetric", component_table=ComponentTable(curves, squareness))


class ISGVolumetric(Format):
    """The ISG volumetric compensation in the ISG CSV format."""

    name = "isg-volumetric"
    description = "TwinCAT CNC / ISG volumetric compensation, ISG CSV with ISO 230-1 names"
    load_words = (
        "volcomp.csv is the ISG CSV of the volumetric compensation (TF5280); "
        "vol_comp[i].max_records must be at least the records stated"
    )
    records_setting = "vol_comp[i].max_records"
    order = 30
    capabilities = Capabilities(
        frozenset({"component"}),
        error_kinds=frozenset({"linear", "straightness", "angular", "squareness"}),
    )

    def write(self, cset: CompensationSet, settings: FormatSettings) -> dict[str, str]:
        return write(cset, settings.max_records)

    def read(self, files: Mapping[str, str], settings: FormatSettings) -> CompensationSet:
        return read(files)

    def resolution_um(self, settings: FormatSettings) -> float:
        return 1000.0 * 10.0**-DECIMALS_MM

    def records(self, cset: CompensationSet) -> int | None:
        return record_count(cset)


FORMATS = (ISGVolumetric(),)
