"""The CSV files of a report (esp.volumetric.export), checked against values worked by hand."""

from __future__ import annotations

import csv

import pytest

from esp.core.analysis import analyse
from esp.core.errors import DataError
from esp.volumetric import export, frames


@pytest.fixture
def result(make_machine):
    """X.linear 0 -> 8 µm over X = 0..400 and Y.linear a constant 1 µm, no datum, on a
    5 x 4 x 3 grid: X error = 0.02 µm/mm · X, Y error = 1 µm, Z error = 0 (eq. 3.1)."""
    machine = make_machine(
        {"X.linear": [(0.0, 0.0), (400.0, 8.0)], "Y.linear": 1.0},
        travel={"X": (0.0, 400.0), "Y": (0.0, 300.0), "Z": (0.0, 200.0)},
        step=100.0,
    )
    return analyse(machine)


def by_quantity(rows):
    q = export.EXTREMES_COLUMNS.index("quantity")
    return {r[q]: r for r in rows}


def test_extremes_rows_worked_by_hand(result):
    rows = by_quantity(export.extremes_rows(result))
    v, x = export.EXTREMES_COLUMNS.index("value_um"), export.EXTREMES_COLUMNS.index("X_mm")
    assert rows["X min"][v] == pytest.approx(0.0) and rows["X min"][x] == 0.0
    assert rows["X max"][v] == pytest.approx(8.0) and rows["X max"][x] == 400.0
    assert rows["X range"][v] == pytest.approx(8.0) and rows["X range"][x] is None
    assert rows["Y range"][v] == pytest.approx(0.0)
    # volumetric: sqrt(8² + 1² + 0²) = sqrt(65) at X = 400
    assert rows["volumetric"][v] == pytest.approx(65**0.5) and rows["volumetric"][x] == 400.0
    assert rows["planar XY"][v] == pytest.approx(65**0.5)
    assert rows["planar XZ"][v] == pytest.approx(8.0)  # sqrt(8² + 0²)
    assert rows["planar YZ"][v] == pytest.approx(1.0)  # sqrt(1² + 0²)
    # 3 rows per direction, the volumetric row, 3 planes; at the MCP no tool length
    assert len(rows) == 3 * 3 + 1 + 3
    assert all(r[0] == 0 and r[1] is None for r in rows.values())


def test_terms_rows_are_the_breakdowns_in_long_form(result):
    rows = export.terms_rows(result)
    cols = export.TERMS_COLUMNS
    assert len(rows) == sum(len(b.terms) for b in result.cases[0].breakdowns)
    vol = [r for r in rows if r[cols.index("point")] == "volumetric"]
    values = {r[cols.index("component")]: r[cols.index("value_um")] for r in vol}
    assert values["X.linear"] == pytest.approx(8.0) and values["Y.linear"] == pytest.approx(1.0)


def test_csv_text_has_six_decimals_and_empty_cells(result, tmp_path):
    path = tmp_path / "extremes.csv"
    frames.write_extremes_csv(result, path)
    with open(path, encoding="utf-8", newline="") as fh:
        table = list(csv.DictReader(fh))
    row = next(r for r in table if r["quantity"] == "volumetric")
    assert row["value_um"] == "8.062258"  # sqrt(65) = 8.0622577..., rounded to 6 places
    assert row["tool_length_mm"] == "" and row["X_mm"] == "400.0"


def test_grid_csv_limit(result, tmp_path):
    # 5 x 4 x 3 = 60 points
    assert export.grid_points(result.machine) == 60
    export.check_grid_csv(result.machine, limit=60)
    with pytest.raises(DataError, match=r"60 points \(5 x 4 x 3\).*limit of 59"):
        export.check_grid_csv(result.machine, limit=59)
    path = tmp_path / "grid.csv"
    with pytest.raises(DataError):
        frames.write_grid_csv(result, path, limit=59)
    assert not path.exists()
    frames.write_grid_csv(result, path)
    with open(path, encoding="utf-8", newline="") as fh:
        grid = list(csv.DictReader(fh))
    assert len(grid) == 60
    # X slowest, Z fastest: the second row is X=0, Y=0, Z=100
    assert (grid[1]["X_mm"], grid[1]["Y_mm"], grid[1]["Z_mm"]) == (
        "0.000000",
        "0.000000",
        "100.000000",
    )
    last = grid[-1]  # X=400, Y=300, Z=200: errors 8, 1, 0 and sqrt(65)
    assert (last["X_um"], last["Y_um"], last["Z_um"]) == ("8.000000", "1.000000", "0.000000")
    assert last["volumetric_um"] == "8.062258"
