"""pandas frames of an analysis, for notebooks and for the report's CSV files.

* :func:`result_frame`: the extremes, one row per tool case and quantity (each
  direction's minimum, maximum and range, the volumetric accuracy, each planar accuracy)
  with its value and the point where it occurs -- ``extremes.csv``;
* :func:`terms_frame`: the breakdowns in long form, one row per tool case, breakdown point
  and term -- ``terms.csv``;
* :func:`grid_frame`: the error at every grid point of the worst tool case -- ``grid.csv``,
  refused above :data:`esp.volumetric.export.GRID_CSV_MAX_POINTS` points.

Column names carry their unit (``value_um``, ``X_mm``, ``tilt_deg``, ``share_pct``); a
missing value (no tool at the MCP, no point for a range, no share when a direction's total
is zero) is NaN. The columns are documented in ``docs/reports.md``.

The frames are built from the typed rows of :func:`esp.volumetric.export.typed_rows`. pandas
is imported when one of these functions is called, never before: ``esp analyse --json``
and the library's core do not load it.

Example
-------
A machine whose only error is X's linear error, 0 to 3 um over its 100 mm of travel:

>>> import tempfile
>>> from pathlib import Path
>>> import esp
>>> with tempfile.TemporaryDirectory() as folder:
...     toml = Path(folder) / "machine.toml"
...     _ = toml.write_text(
...         '[machine]\\nname = "m"\\nconfiguration = "wBMTt"\\n'
...         'axes = { bottom = "X", middle = "Y", top = "Z" }\\n'
...         '[axes.X]\\ntravel = [0, 100]\\nstep = 50\\n'
...         '[axes.X.errors]\\nlinear = { points = [[0, 0], [100, 3]] }\\n'
...         '[axes.Y]\\ntravel = [0, 100]\\nstep = 50\\n'
...         '[axes.Z]\\ntravel = [0, 100]\\nstep = 50\\n',
...         encoding="utf-8",
...     )
...     result = esp.analyse(esp.load_machine(toml))
>>> frame = result_frame(result)
>>> float(frame.set_index("quantity").loc["volumetric", "value_um"])
3.0
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from esp.io.atomic import atomic_path, write_text
from esp.volumetric.export import (
    EXTREMES_COLUMNS,
    GRID_COLUMNS,
    TERMS_COLUMNS,
    column_kind,
    csv_text,
    extremes_rows,
    grid_table,
    terms_rows,
    typed_rows,
)

if TYPE_CHECKING:
    from collections.abc import Iterable, Sequence

    import pandas

    from esp.core.results import AnalysisResult

__all__ = [
    "frame_csv",
    "grid_frame",
    "result_frame",
    "terms_frame",
    "write_extremes_csv",
    "write_grid_csv",
    "write_terms_csv",
]

_DTYPES = {"text": object, "integer": "int64", "number": "float64"}


def _frame(columns: Sequence[str], rows: Iterable[Sequence[Any]]) -> pandas.DataFrame:
    import pandas as pd

    rows = typed_rows(columns, rows)
    data = {}
    for k, name in enumerate(columns):
        kind = column_kind(name)
        cells = [row[k] for row in rows]
        if kind == "number":
            cells = [float("nan") if c is None else c for c in cells]
        data[name] = pd.Series(cells, dtype=_DTYPES[kind])
    return pd.DataFrame(data, columns=list(columns))


def result_frame(result: AnalysisResult) -> pandas.DataFrame:
    """The extremes of every tool case (the rows of ``extremes.csv``).

    Columns: ``case`` (index in ``result.cases``), ``tool_length_mm``, ``tilt_deg``,
    ``spin_deg``, ``tool_X_mm``, ``tool_Y_mm``, ``tool_Z_mm`` (the tool case), ``quantity``
    (``"X min"``, ``"X max"``, ``"X range"``, ..., ``"volumetric"``, ``"planar XY"``, ...),
    ``value_um`` and ``X_mm``, ``Y_mm``, ``Z_mm`` (where; NaN for a range).
    """
    return _frame(EXTREMES_COLUMNS, extremes_rows(result))


def terms_frame(result: AnalysisResult) -> pandas.DataFrame:
    """The breakdowns in long form (the rows of ``terms.csv``): the tool case columns of
    :func:`result_frame`, then ``point`` (the breakdown: ``"volumetric"``, ``"planar
    XY"``, ``"X min"``, ...), ``X_mm``, ``Y_mm``, ``Z_mm``, ``direction``, ``component``,
    ``iso`` (ISO 230-1 name), ``source`` (the equation), ``term`` (its symbol),
    ``value_um`` and ``share_pct`` (of the direction's total; NaN when that is zero)."""
    return _frame(TERMS_COLUMNS, terms_rows(result))


def grid_frame(result: AnalysisResult, limit: int | None = None) -> pandas.DataFrame:
    """The error at every grid point of the worst tool case (the rows of ``grid.csv``):
    ``X_mm``, ``Y_mm``, ``Z_mm``, ``X_um``, ``Y_um``, ``Z_um`` and ``volumetric_um``
    (eq. 3.4), relative to the datum when one is set; X varies slowest, Z fastest.

    Raises :class:`~esp.core.errors.DataError` above ``limit`` points (default
    :data:`esp.volumetric.export.GRID_CSV_MAX_POINTS`), before any work.
    """
    import pandas as pd

    return pd.DataFrame(grid_table(result, limit), columns=list(GRID_COLUMNS))


def frame_csv(frame: pandas.DataFrame) -> str:
    """The CSV text of a frame of this module as the report writes it: a header of the
    column names, numbers with at most 6 decimals (never ``-0.0``), empty cells for NaN,
    cells quoted by the csv module where needed, LF line ends."""
    return csv_text(list(frame.columns), frame.itertuples(index=False, name=None))


# -- the CSV files of the report ------------------------------------------------------------


def write_extremes_csv(result: AnalysisResult, path: str | Path) -> None:
    """Write ``extremes.csv`` (the rows of :func:`result_frame`) atomically."""
    write_text(path, frame_csv(result_frame(result)))


def write_terms_csv(result: AnalysisResult, path: str | Path) -> None:
    """Write ``terms.csv`` (the rows of :func:`terms_frame`) atomically."""
    write_text(path, frame_csv(terms_frame(result)))


def write_grid_csv(result: AnalysisResult, path: str | Path, limit: int | None = None) -> None:
    """Write ``grid.csv`` (the rows of :func:`grid_frame`) atomically, each number with 6
    decimals (as in the JSON; never ``-0``). Refused above ``limit`` points, before any
    work."""
    frame = grid_frame(result, limit)
    table = np.round(frame.to_numpy(dtype=float), 6) + 0.0
    with atomic_path(path) as tmp, open(tmp, "w", encoding="utf-8", newline="\n") as fh:
        fh.write(",".join(frame.columns) + "\n")
        np.savetxt(fh, table, fmt="%.6f", delimiter=",")
