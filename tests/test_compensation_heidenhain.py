"""HEIDENHAIN *.COM / CONFIG.CMA tables: written, read back by a few lines of their own
here, applied as the control applies them (each column of a .COM entered under an axis of
the active .CMA line is that column's axis as a function of the entered axis, linear
between the AXISPOS points, the BACKLASH column in the negative direction) and checked
against --predict; options and limits."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner
from test_compensation_apply import AXES, one_datum_errors, small, written

from esp.cli import main
from esp.compensation.build import BuildOptions, build
from esp.compensation.formats import FormatSettings, read_files, resolution_um, write_files
from esp.compensation.predict import grid_points, predict
from esp.core.errors import DataError, ParseError

GANTRY = Path(__file__).resolve().parent.parent / "data" / "examples" / "gantry" / "machine.toml"
SPACING = {"X": 20.0, "Y": 50.0, "Z": 50.0}


def table(text):
    lines = text.splitlines()
    header = lines[1].split()
    rows = [line.split() for line in lines[2:] if line != "[END]"]
    return header, np.array(rows, dtype=float)


def heidenhain_correction(files, pts, direction, difference=False):
    """Values are errors in mm (esp's default): the correction is minus them."""
    lines = [line.split() for line in files["CONFIG.CMA"].splitlines()]
    header, active = lines[1], next(r for r in lines[2:] if "*" in r)
    corr = np.zeros_like(pts)
    for master, name in zip(header[2:], active[2:], strict=True):
        cols, data = table(files[name])
        x = data[:, cols.index("AXISPOS")]
        m = AXES.index(master)
        for col in cols[2:]:
            if col == "BACKLASH":
                continue
            fwd = data[:, cols.index(col)]
            bwd = fwd
            if col == master and "BACKLASH" in cols:
                bwd = data[:, cols.index("BACKLASH")] + (fwd if difference else 0.0)
            f, b = np.interp(pts[:, m], x, fwd), np.interp(pts[:, m], x, bwd)
            value = {"forward": f, "backward": b, "mean": 0.5 * (f + b)}[direction]
            if col != master:  # one table for both directions
                value = 0.5 * (f + b)
            corr[:, AXES.index(col)] -= 1000.0 * value
    return corr


@pytest.mark.parametrize("backlash", ["absolute", "difference"])
def test_the_residual_is_that_of_the_files_applied_independently(backlash):
    machine = small()
    settings = FormatSettings(options={"heidenhain-backlash": backlash})
    files, back = written(machine, "heidenhain", settings, spacing_mm=SPACING)
    p = predict(machine, back, resolution_um("heidenhain", settings))
    pts = grid_points(machine, back)
    datum = np.zeros((1, 3))
    diff = backlash == "difference"
    for d in p.directions:
        c = heidenhain_correction(files, pts, d.direction, diff)
        c = c - heidenhain_correction(files, datum, machine.analysis.direction, diff)
        r = one_datum_errors(machine, d.direction, pts) + c
        norm = np.linalg.norm(r, axis=1)
        assert d.after_um == pytest.approx(float(norm.max()), abs=1e-9)
        for k, a in enumerate(AXES):
            assert d.axes_after_um[a] == pytest.approx(float(np.abs(r[:, k]).max()), abs=1e-9)
    assert p.after_um < p.before_um


def test_values_worked_by_hand():
    """X.linear of small() at X = 60 mm: the forward correction is -1.5 µm and the
    backward one -2.7 µm (referred to the mean at X = 0, 0.6 µm); written as errors in
    mm: X = +0.0015, BACKLASH = +0.0027 (or +0.0012 as a difference)."""
    tables = build(small(), "heidenhain", BuildOptions(spacing_mm=SPACING, leave_uncorrected=True))
    cols, data = table(write_files(tables)["X.COM"])
    row = data[list(data[:, cols.index("AXISPOS")]).index(60.0)]
    assert row[cols.index("X")] == pytest.approx(0.0015)
    assert row[cols.index("BACKLASH")] == pytest.approx(0.0027)
    s = FormatSettings(options={"heidenhain-backlash": "difference"})
    cols, data = table(write_files(tables, s)["X.COM"])
    assert data[3, cols.index("BACKLASH")] == pytest.approx(0.0012)
    s = FormatSettings(options={"heidenhain-sign": "correction"})
    cols, data = table(write_files(tables, s)["X.COM"])
    assert data[3, cols.index("X")] == pytest.approx(-0.0015)
    assert read_files("heidenhain", write_files(tables, s), s).axis_tables


def test_limits_and_reader_errors():
    tables = build(small(), "heidenhain", BuildOptions(spacing_mm=SPACING, leave_uncorrected=True))
    with pytest.raises(DataError, match="heidenhain=N"):
        write_files(tables, FormatSettings(limits={"heidenhain": 5}))
    files = write_files(tables)
    broken = {**files, "X.COM": files["X.COM"].replace("[END]\n", "")}
    with pytest.raises(ParseError, match=r"X\.COM.*\[END\]"):
        read_files("heidenhain", broken)
    lines = files["X.COM"].splitlines()
    lines[3] += " 1"
    with pytest.raises(ParseError, match="X.COM:4"):
        read_files("heidenhain", {**files, "X.COM": "\n".join(lines)})


def test_command_refuses_in_one_line():
    args = ["compensate", str(GANTRY), "--format", "heidenhain", "--leave-uncorrected"]
    r = CliRunner().invoke(main, [*args, "--max-points", "heidenhain=10"])
    assert r.exit_code == 2 and "heidenhain=N" in r.output
    assert r.output.strip().count("\n") == 0
