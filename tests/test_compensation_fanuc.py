"""FANUC pitch error compensation (3605#0, 3620-3627 and the incremental pitch data):
written, read back by a few lines of their own here, applied as the control applies them
(the sum of the incremental values from the reference position; a section's value reached
at its far end in the direction of travel, or spread over it) and checked against
--predict; magnification, limits and options."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner
from test_compensation_apply import AXES, one_datum_errors, small, written

from esp.cli import main
from esp.compensation.build import BuildOptions, build
from esp.compensation.formats import FormatSettings, get, write_files
from esp.compensation.predict import grid_points
from esp.core.errors import DataError

GANTRY = Path(__file__).resolve().parent.parent / "data" / "examples" / "gantry" / "machine.toml"
SPACING = {"X": 20.0, "Y": 50.0, "Z": 50.0}


def entries(text):
    out = {}
    for line in text.splitlines():
        m = re.match(r"N(\d+)(?:A(\d+))?P(-?\d+)$", line)
        if m:
            out[(int(m.group(1)), int(m.group(2) or 0))] = int(m.group(3))
    return out


def fanuc_tables(files, origin_mm=0.0, unit_um=1.0):
    """axis index -> (positions mm, forward µm, backward µm): the absolute compensation
    at each position, the sum of the incremental data from the reference position."""
    params, data = entries(files["PARAM.TXT"]), entries(files["PITCH.TXT"])
    out = {}
    for ax in sorted({a for (_, a) in params}):
        ref, lo, hi = params[(3620, ax)], params[(3621, ax)], params[(3622, ax)]
        mag, interval = params[(3623, ax)], params[(3624, ax)]
        n = hi - lo + 1
        pos = origin_mm + (np.arange(n) - (ref - lo)) * interval / 1000.0
        f = np.cumsum([data[(10000 + lo + i, 0)] for i in range(n)]) * mag * unit_um
        f = f - f[ref - lo]
        b = f
        if params[(3605, ax)] == 1:
            neg = params[(3626, ax)]
            b = np.cumsum([data[(10000 + neg + i, 0)] for i in range(n)]) * mag * unit_um
            b = b - b[ref - lo] + params[(3627, ax)] * mag * unit_um
        out[ax - 1] = (pos, f, b)
    return out


def fanuc_correction(files, pts, direction, between="step"):
    corr = np.zeros_like(pts)
    for k, (pos, f, b) in fanuc_tables(files).items():
        x = pts[:, k]
        if between == "linear":
            cf, cb = np.interp(x, pos, f), np.interp(x, pos, b)
        else:  # forward: the value of the last position reached; backward: of the next one
            i = np.clip(np.searchsorted(pos, x + 1e-12, side="right") - 1, 0, pos.size - 1)
            j = np.clip(np.searchsorted(pos, x - 1e-12, side="left"), 0, pos.size - 1)
            cf, cb = f[i], b[j]
        corr[:, k] += {"forward": cf, "backward": cb, "mean": 0.5 * (cf + cb)}[direction]
    return corr


@pytest.mark.parametrize("between", ["step", "linear"])
def test_the_residual_is_that_of_the_files_applied_independently(between):
    machine = small()
    settings = FormatSettings(options={"fanuc-between": between})
    files, back = written(machine, "fanuc", settings, spacing_mm=SPACING)

    p = get("fanuc").predict(machine, back, settings)
    pts = grid_points(machine, back) if between == "linear" else None
    if pts is None:  # the staircase adds points just before and after each position
        from dataclasses import replace

        from esp.compensation.formats.fanuc import staircase

        stepped = replace(back, axis_tables=tuple(staircase(t) for t in back.axis_tables))
        pts = grid_points(machine, stepped)
    datum = np.zeros((1, 3))
    for d in p.directions:
        c = fanuc_correction(files, pts, d.direction, between)
        c = c - fanuc_correction(files, datum, machine.analysis.direction, between)
        r = one_datum_errors(machine, d.direction, pts) + c
        norm = np.linalg.norm(r, axis=1)
        assert d.after_um == pytest.approx(float(norm.max()), abs=1e-9)
        for k, a in enumerate(AXES):
            assert d.axes_after_um[a] == pytest.approx(float(np.abs(r[:, k]).max()), abs=1e-9)
    assert p.after_um < p.before_um


def test_incremental_data_and_the_reversal_at_the_reference_worked_by_hand():
    """X.linear of small() every 20 mm: forward errors 0, 2.1 µm at X = 0, 60 and the
    backward run 1.2 µm above; referred to the mean at X = 0 (0.6 µm) the forward
    correction is 0.6 at 0 and -1.5 at 60 µm, the backward one -0.6 and -2.7. In whole
    µm (magnification 1) the forward absolute values from the reference X = 0 are 0 and
    round(-1.5) - round(0.6) = -2 - 1 = -3, and 3627 = round(-0.6) - round(0.6) = -2."""
    tables = build(small(), "fanuc", BuildOptions(spacing_mm=SPACING, leave_uncorrected=True))
    files = write_files(tables)
    params, data = entries(files["PARAM.TXT"]), entries(files["PITCH.TXT"])
    assert params[(3605, 1)] == 1 and params[(3623, 1)] == 1 and params[(3624, 1)] == 20000
    lo = params[(3621, 1)]
    assert params[(3620, 1)] == lo
    assert data[(10000 + lo, 0)] == 0
    assert sum(data[(10000 + lo + i, 0)] for i in range(4)) == -3
    assert params[(3627, 1)] == -2


def test_magnification_and_limits():
    tables = build(small(), "fanuc", BuildOptions(spacing_mm=SPACING, leave_uncorrected=True))
    params = entries(write_files(tables, FormatSettings(limits={"fanuc_value": 1}))["PARAM.TXT"])
    assert max(v for (n, _), v in params.items() if n == 3623) > 1
    with pytest.raises(DataError, match="fanuc_points"):
        write_files(tables, FormatSettings(limits={"fanuc_points": 20}))
    big = build(small(), "fanuc", BuildOptions(spacing_mm={"X": 100.0}, leave_uncorrected=True))
    with pytest.raises(DataError, match="magnification 100"):
        write_files(big, FormatSettings(options={"fanuc-detection-um": "0.0001"}))


def test_sign_option_flips_the_data():
    tables = build(small(), "fanuc", BuildOptions(spacing_mm=SPACING, leave_uncorrected=True))
    a = entries(write_files(tables)["PITCH.TXT"])
    b = entries(write_files(tables, FormatSettings(options={"fanuc-sign": "error"}))["PITCH.TXT"])
    assert any(a.values()) and all(a[k] == -b[k] for k in a)


def test_command_refuses_in_one_line():
    runner = CliRunner()
    args = ["compensate", str(GANTRY), "--format", "fanuc", "--leave-uncorrected"]
    for extra, word in [
        (["--format-option", "fanuc-between=zig"], "step, linear"),
        (["--format-option", "nope=1"], "fanuc-between"),
        (["--max-points", "fanuc_points=10"], "fanuc_points"),
        (["--spacing", "X=30"], "equidistant"),
    ]:
        r = runner.invoke(main, [*args, *extra])
        assert r.exit_code == 2, r.output
        assert word in r.output and r.output.strip().count("\n") == 0
