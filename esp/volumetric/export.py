"""CSV files of an analysis, in long form for spreadsheets and scripts.

* ``extremes.csv``: one row per tool case and figure (each direction's minimum, maximum and
  range, the volumetric accuracy, each planar accuracy), with the point where it occurs;
* ``terms.csv``: one row per tool case, breakdown point and term (the breakdown tables);
* ``grid.csv``: the total error of every direction and the volumetric error at every grid
  point of the worst tool case, for grids of at most :data:`GRID_CSV_MAX_POINTS` points.

Numbers are written with at most 6 decimals (as in the JSON), empty where there is none.
The columns are documented in ``docs/reports.md``. The rows are built here without pandas,
each cell of the type of its column (:func:`typed_rows`: text, an integer, or a float,
``None`` where there is none); the files are written through the pandas frames of
:mod:`esp.volumetric.frames` built from them (``write_extremes_csv``, ``write_terms_csv``,
``write_grid_csv``), which are also what a notebook user gets (``result_frame``,
``terms_frame``, ``grid_frame``).
"""

from __future__ import annotations

import csv
import io
from collections.abc import Callable, Iterable, Sequence
from typing import Any

import numpy as np

from esp.core.errors import DataError
from esp.core.machine import AXIS_NAMES, Machine
from esp.core.results import AnalysisResult, CaseResult
from esp.report.jsonout import plain

__all__ = [
    "EXTREMES_COLUMNS",
    "GRID_COLUMNS",
    "GRID_CSV_MAX_POINTS",
    "TERMS_COLUMNS",
    "check_grid_csv",
    "column_kind",
    "csv_text",
    "extremes_rows",
    "grid_points",
    "grid_table",
    "terms_rows",
    "typed_rows",
]

#: the largest grid (points of one tool case) written by :func:`write_grid_csv`
GRID_CSV_MAX_POINTS = 1_000_000

_CASE_COLUMNS = (
    "case",
    "tool_length_mm",
    "tilt_deg",
    "spin_deg",
    "tool_X_mm",
    "tool_Y_mm",
    "tool_Z_mm",
)
EXTREMES_COLUMNS = _CASE_COLUMNS + ("quantity", "value_um", "X_mm", "Y_mm", "Z_mm")
TERMS_COLUMNS = _CASE_COLUMNS + (
    "point",
    "X_mm",
    "Y_mm",
    "Z_mm",
    "direction",
    "component",
    "iso",
    "source",
    "term",
    "value_um",
    "share_pct",
)
GRID_COLUMNS = ("X_mm", "Y_mm", "Z_mm", "X_um", "Y_um", "Z_um", "volumetric_um")

_TEXT_COLUMNS = frozenset({"quantity", "point", "direction", "component", "iso", "source", "term"})
_INTEGER_COLUMNS = frozenset({"case"})


def column_kind(name: str) -> str:
    """The type of the cells of column ``name``: ``"text"``, ``"integer"`` or ``"number"``
    (a float, ``None`` where there is none)."""
    if name in _TEXT_COLUMNS:
        return "text"
    return "integer" if name in _INTEGER_COLUMNS else "number"


def typed_rows(columns: Sequence[str], rows: Iterable[Sequence]) -> list[list]:
    """``rows`` with every cell of the type of its column (:func:`column_kind`): text as
    ``str`` (empty for none), integers as ``int``, numbers as ``float`` or ``None``."""
    convert: dict[str, Callable[[Any], object]] = {
        "text": lambda c: "" if c is None else str(c),
        "integer": int,
        "number": lambda c: None if c is None else float(c),
    }
    kinds = [convert[column_kind(name)] for name in columns]
    return [[kind(c) for kind, c in zip(kinds, row, strict=True)] for row in rows]


def _cell(value: object) -> str:
    """A CSV cell: empty for None (and NaN, a missing value of a pandas frame), a float
    with at most 6 decimals and never ``-0.0``, anything else as text."""
    if value is None:
        return ""
    if isinstance(value, (float, np.floating)):
        value = plain(float(value))
        return "" if value is None else repr(value)
    if isinstance(value, np.integer):
        return str(int(value))
    return str(value)


def _case_cells(n: int, case: CaseResult) -> list:
    t = case.tool
    return [n, t.length_mm, t.tilt_deg, t.spin_deg, *(t.offset_mm[a] for a in AXIS_NAMES)]


def extremes_rows(result: AnalysisResult) -> list[list]:
    """The rows of ``extremes.csv`` (values, not text), in :data:`EXTREMES_COLUMNS` order.

    ``quantity`` is ``"X min"``, ``"X max"``, ``"X range"`` (no point), ... for each
    direction, then ``"volumetric"`` and ``"planar XY"``, ``"planar XZ"``, ``"planar YZ"``.
    """
    rows = []
    for n, case in enumerate(result.cases):
        head = _case_cells(n, case)
        for d, e in case.axes.items():
            for label, ext in (("min", e.minimum), ("max", e.maximum)):
                rows.append(head + [f"{d} {label}", ext.value_um, *(ext.at[a] for a in AXIS_NAMES)])
            rows.append(head + [f"{d} range", e.range_um, None, None, None])
        rows.append(
            head
            + ["volumetric", case.volumetric.value_um, *(case.volumetric.at[a] for a in AXIS_NAMES)]
        )
        for plane, extreme in case.planar.items():
            rows.append(
                head + [f"planar {plane}", extreme.value_um, *(extreme.at[a] for a in AXIS_NAMES)]
            )
    return rows


def terms_rows(result: AnalysisResult) -> list[list]:
    """The rows of ``terms.csv``: every term of every breakdown of every tool case, in
    :data:`TERMS_COLUMNS` order; ``point`` is the breakdown's label (``"volumetric"``,
    ``"planar XY"``, ``"X min"``, ...)."""
    rows = []
    for n, case in enumerate(result.cases):
        head = _case_cells(n, case)
        for b in case.breakdowns:
            where = [b.label, *(b.at[a] for a in AXIS_NAMES)]
            for t in b.terms:
                rows.append(
                    head
                    + where
                    + [t.direction, t.component, t.iso, t.source, t.symbol, t.value_um, t.share_pct]
                )
    return rows


def csv_text(columns: Sequence[str], rows: Iterable[Sequence]) -> str:
    """The CSV text of ``rows`` under ``columns`` (quoted by the csv module where a cell
    holds a comma, a quote or a line break; LF line ends)."""
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(columns)
    for row in rows:
        writer.writerow([_cell(v) for v in row])
    return buffer.getvalue()


def grid_points(machine: Machine) -> int:
    """The number of points of the simulation grid of one tool case."""
    n = 1
    for a in AXIS_NAMES:
        n *= int(machine.axes[a].grid_mm().size)
    return n


def check_grid_csv(machine: Machine, limit: int | None = None) -> None:
    """Refuse (:class:`~esp.core.errors.DataError`) a grid CSV of more than ``limit`` points
    (default :data:`GRID_CSV_MAX_POINTS`), before any work is done."""
    limit = GRID_CSV_MAX_POINTS if limit is None else limit
    n = grid_points(machine)
    if n > limit:
        sizes = " x ".join(str(machine.axes[a].grid_mm().size) for a in AXIS_NAMES)
        raise DataError(
            f"grid CSV refused: the simulation grid has {n:,} points ({sizes}), more than "
            f"the limit of {limit:,}; make axes.*.step larger or axes.*.simulate narrower"
        )


def grid_table(result: AnalysisResult, limit: int | None = None) -> np.ndarray:
    """Every grid point of the worst tool case, shape ``(points, 7)`` in
    :data:`GRID_COLUMNS` order: the position (mm), the total error of each direction and
    the volumetric error (eq. 3.4) in µm, relative to the datum when one is set; X varies
    slowest, Z fastest. Refused (:class:`~esp.core.errors.DataError`) above ``limit`` points
    (default :data:`GRID_CSV_MAX_POINTS`), before any work."""
    machine = result.machine
    check_grid_csv(machine, limit)
    grids, errors = result.evaluation.field()
    mesh = np.meshgrid(*(grids[a] for a in AXIS_NAMES), indexing="ij")
    e = [errors[a] for a in AXIS_NAMES]
    vol = np.sqrt(e[0] ** 2 + e[1] ** 2 + e[2] ** 2)
    return np.column_stack([m.reshape(-1) for m in (*mesh, *e, vol)])
