"""pandas frames of a result (esp.volumetric.frames): the numbers of the CSV files, with
unit-bearing column names, and pandas loaded only when a frame is asked for."""

from __future__ import annotations

import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from esp.core.analysis import analyse
from esp.core.errors import DataError
from esp.volumetric import export, frames

ROOT = Path(__file__).resolve().parent.parent
GANTRY = ROOT / "data" / "examples" / "gantry"


@pytest.fixture(scope="module")
def result():
    """X.linear 0 -> 8 µm over X = 0..400 and Y.linear a constant 1 µm, no datum, on a
    5 x 4 x 3 grid: X error = 0.02 µm/mm · X, Y error = 1 µm, Z error = 0 (eq. 3.1)."""
    from conftest import build_machine

    machine = build_machine(
        {"X.linear": [(0.0, 0.0), (400.0, 8.0)], "Y.linear": 1.0},
        travel={"X": (0.0, 400.0), "Y": (0.0, 300.0), "Z": (0.0, 200.0)},
        step=100.0,
    )
    return analyse(machine)


def test_result_frame_holds_the_extremes(result):
    frame = frames.result_frame(result)
    assert list(frame.columns) == list(export.EXTREMES_COLUMNS)
    assert frame["value_um"].dtype == np.float64 and frame["case"].dtype == np.int64
    by = frame.set_index("quantity")
    # worked by hand: X max 8 µm at X = 400; volumetric sqrt(8² + 1²) = sqrt(65)
    assert by.loc["X max", "value_um"] == pytest.approx(8.0) and by.loc["X max", "X_mm"] == 400
    assert by.loc["volumetric", "value_um"] == pytest.approx(math.sqrt(65.0))
    assert math.isnan(by.loc["X range", "X_mm"])  # a range has no point
    assert frame["tool_length_mm"].isna().all()  # at the MCP: no tool


def test_terms_frame_is_the_breakdowns_in_long_form(result):
    frame = frames.terms_frame(result)
    assert list(frame.columns) == list(export.TERMS_COLUMNS)
    assert len(frame) == sum(len(b.terms) for b in result.cases[0].breakdowns)
    vol = frame[frame["point"] == "volumetric"].set_index("component")
    assert vol.loc["X.linear", "value_um"] == pytest.approx(8.0)
    assert vol.loc["Y.linear", "value_um"] == pytest.approx(1.0)
    # shares of each direction's terms add up to 100 %
    for _, group in frame.dropna(subset=["share_pct"]).groupby(["point", "direction"]):
        assert group["share_pct"].sum() == pytest.approx(100.0)


def test_grid_frame_and_its_limit(result):
    frame = frames.grid_frame(result)
    assert list(frame.columns) == list(export.GRID_COLUMNS) and len(frame) == 5 * 4 * 3
    last = frame.iloc[-1]  # X=400, Y=300, Z=200: errors 8, 1, 0 and sqrt(65)
    assert (last["X_mm"], last["Y_mm"], last["Z_mm"]) == (400.0, 300.0, 200.0)
    assert last["X_um"] == pytest.approx(8.0) and last["volumetric_um"] == pytest.approx(65**0.5)
    with pytest.raises(DataError, match=r"60 points .*limit of 59"):
        frames.grid_frame(result, limit=59)


def test_csv_files_are_written_through_the_frames(result, tmp_path):
    """The files are written through the frames, and the CSV text of a frame is the text of
    its typed rows written directly: the same bytes either way."""
    for frame, write, name, columns, rows in (
        (
            frames.result_frame(result),
            frames.write_extremes_csv,
            "extremes.csv",
            export.EXTREMES_COLUMNS,
            export.extremes_rows(result),
        ),
        (
            frames.terms_frame(result),
            frames.write_terms_csv,
            "terms.csv",
            export.TERMS_COLUMNS,
            export.terms_rows(result),
        ),
    ):
        write(result, tmp_path / name)
        text = (tmp_path / name).read_text(encoding="utf-8")
        assert frames.frame_csv(frame) == text
        assert export.csv_text(columns, export.typed_rows(columns, rows)) == text
    frames.write_grid_csv(result, tmp_path / "grid.csv")
    written = np.loadtxt(tmp_path / "grid.csv", delimiter=",", skiprows=1)
    np.testing.assert_allclose(written, frames.grid_frame(result).to_numpy(), atol=5e-7)


def test_typed_rows_give_each_cell_the_type_of_its_column():
    columns = ("case", "quantity", "value_um", "X_mm")
    rows = export.typed_rows(columns, [[np.int64(2), None, 3, None], [0, "volumetric", 1.5, 7]])
    assert rows == [[2, "", 3.0, None], [0, "volumetric", 1.5, 7.0]]
    assert [type(c) for c in rows[0]] == [int, str, float, type(None)]
    text = export.csv_text(columns, rows)
    assert text == "case,quantity,value_um,X_mm\n2,,3.0,\n0,volumetric,1.5,7.0\n"


def imported(code: str) -> set[str]:
    out = subprocess.run(
        [sys.executable, "-c", code + "\nimport sys\nprint(' '.join(sorted(sys.modules)))"],
        capture_output=True,
        text=True,
        check=True,
        cwd=ROOT,
    )
    return set(out.stdout.split())


@pytest.mark.slow
def test_json_output_loads_neither_pandas_nor_matplotlib():
    modules = imported(
        "from esp.cli import main\n"
        "import contextlib, io\n"
        "with contextlib.redirect_stdout(io.StringIO()):\n"
        f"    main(['analyse', {str(GANTRY / 'machine.toml')!r}, '--json', '-'],"
        " standalone_mode=False)\n"
    )
    assert "esp.core.analysis" in modules
    assert "pandas" not in modules and "matplotlib" not in modules


@pytest.mark.slow
def test_frames_load_pandas_when_called():
    code = "import esp.volumetric.frames, esp.volumetric.export\n"
    assert "pandas" not in imported(code)


def test_facade_functions_give_the_frames():
    """``esp.result_frame()``, ``esp.terms_frame()`` and ``esp.grid_frame()`` are the frames
    of esp.volumetric.frames, for notebook users (the result record itself imports no
    rendering)."""
    import esp
    from esp.volumetric import frames

    path = Path(__file__).resolve().parent.parent / "data" / "examples" / "gantry" / "machine.toml"
    result = esp.analyse(esp.load_machine(path))
    assert esp.result_frame(result).equals(frames.result_frame(result))
    assert esp.terms_frame(result).equals(frames.terms_frame(result))
    grid = esp.grid_frame(result)
    assert len(grid) == 21 * 31 * 25 and grid["volumetric_um"].max() == pytest.approx(
        result.cases[0].volumetric.value_um
    )
