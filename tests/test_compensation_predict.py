"""The residual after compensation: zero for what a format represents (up to its
resolution), the uncorrected components kept, the reversal by direction, and the command
end to end."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner
from conftest import build_machine

import esp
from esp.cli import main
from esp.compensation.build import BuildOptions, build
from esp.compensation.formats import read_files, resolution_um, write_files
from esp.compensation.predict import grid_points, predict
from esp.core.profile import ErrorProfile

GANTRY = Path(__file__).resolve().parent.parent / "data" / "examples" / "gantry" / "machine.toml"
PNG = b"\x89PNG\r\n\x1a\n"


def applied(machine, fmt, **options):
    tables = build(machine, fmt, BuildOptions(**options))
    return read_files(fmt, write_files(tables)), tables


def residual(machine, fmt, **options):
    back, tables = applied(machine, fmt, **options)
    from dataclasses import replace

    back = replace(back, corrected=tables.corrected, uncorrected=tables.uncorrected)
    return predict(machine, back, resolution_um(fmt))


def linear_machine(**kw):
    """X and Y positioning errors measured in one direction, on points that are not the
    table's (50 mm table on 0..200 mm; data at 0, 70, 130, 200)."""
    comps = {
        "X.linear": [(0.0, 0.0), (70.0, 3.1), (130.0, -1.2), (200.0, 4.4)],
        "Y.linear": [(0.0, 0.0), (70.0, -2.0), (130.0, 1.0), (200.0, 2.5)],
    }
    comps.update(kw)
    return build_machine(comps, travel=(0.0, 200.0), step=50.0)


@pytest.mark.parametrize(
    "fmt, tol",
    [
        ("linuxcnc", 0.0006),
        ("twincat-lead", 0.051),
        ("isg-volumetric", 0.0006),
        ("iso-csv", 0.0006),
    ],
)
def test_a_representable_error_leaves_only_the_resolution(fmt, tol):
    """Tables placed on the data's breakpoints represent the piecewise-linear curves
    exactly; what is left is the rounding of the file."""
    m = linear_machine()
    p = residual(m, fmt, spacing_mm={"X": 10.0, "Y": 10.0, "Z": 10.0})
    assert p.before_um > 4.0
    assert p.after_um <= tol * np.sqrt(2) + 1e-9


def test_a_coarse_table_leaves_the_interpolation_error():
    """50 mm points miss the breakpoints at 70 and 130 mm: the residual there is the
    difference between the measured curve and the table's chord. X, by hand: the table at
    50 mm 3.1*50/70 = 2.2143, at 100 mm 3.1 - 4.3*30/60 = 0.95, at 150 mm
    -1.2 + 5.6*20/70 = 0.4; at 70 mm the chord is 2.2143 - 1.2643*20/50 = 1.7086
    (residual 1.3914), at 130 mm 0.95 - 0.55*30/50 = 0.62 (residual -1.82): the worst."""
    m = linear_machine()
    p = residual(m, "linuxcnc")
    d = p.directions[0]
    assert d.axes_after_um["X"] == pytest.approx(1.82, abs=2e-3)


def test_uncorrected_components_stay_in_the_residual():
    m = linear_machine(**{"X.straightness.Y": [(0.0, 0.0), (100.0, 3.0), (200.0, 0.0)]})
    p = residual(
        m, "linuxcnc", leave_uncorrected=True, spacing_mm={"X": 10.0, "Y": 10.0, "Z": 10.0}
    )
    assert "X.straightness.Y" in p.uncorrected
    # the straightness after the least-squares line: 3 - 1 = 2 µm at the middle, -1 at the ends
    assert p.after_um == pytest.approx(2.0, abs=0.01)


def test_a_bilateral_table_removes_the_reversal_and_a_mean_table_leaves_half():
    profile = ErrorProfile(
        "linear", [0.0, 100.0, 200.0], {"forward": [[0, 2, 4]], "backward": [[3, 5, 7]]}, axis="X"
    )
    m = build_machine({"X.linear": profile}, travel=(0.0, 200.0), step=100.0)
    lead = residual(m, "linuxcnc")
    assert [d.direction for d in lead.directions] == ["forward", "backward"]
    assert lead.after_um <= 0.001
    volumetric = residual(m, "isg-volumetric")
    # the component table holds the mean: each direction keeps half the 3 µm reversal
    assert volumetric.after_um == pytest.approx(1.5, abs=0.001)


def test_before_is_the_field_of_errors_at():
    m = esp.load_machine(GANTRY)
    back, _ = applied(m, "isg-volumetric")
    p = predict(m, back)
    pts = grid_points(m, back)
    from dataclasses import replace

    from esp.compensation.build import with_direction

    # the forward errors referred to the one datum of both directions: the analysis
    # direction's (the mean's) error at the home corner
    raw = replace(m, analysis=replace(m.analysis, datum="none"))
    e = np.asarray(esp.errors_at(with_direction(raw, "forward"), pts))
    e -= np.asarray(esp.errors_at(raw, np.zeros((1, 3))))
    assert p.directions[0].before_um == pytest.approx(np.max(np.linalg.norm(e, axis=1)))


def run(*args):
    return CliRunner().invoke(main, [str(a) for a in args])


@pytest.mark.slow
def test_command_writes_tables_report_and_json(tmp_path):
    """--plot implies --predict; the figure goes where --plot says, not into --out."""
    out = tmp_path / "comp"
    result = run(
        "compensate",
        GANTRY,
        "--format",
        "isg-volumetric",
        "--format",
        "twincat-plane",
        "--leave-uncorrected",
        "--out",
        out,
        "--json",
        tmp_path / "c.json",
        "--plot",
        tmp_path / "before-after.png",
    )
    assert result.exit_code == 0, result.output
    assert "predicted volumetric accuracy" in result.stdout
    assert (out / "isg-volumetric" / "volcomp.csv").is_file()
    # each format's folder: its tables and esp's marker, so that a rerun may replace it
    tables = sorted(p.name for p in (out / "twincat-plane").iterdir())
    assert tables == [".esp-folder.json", "X.lis", "Y.lis", "Z.lis"]
    assert (tmp_path / "before-after.png").read_bytes().startswith(PNG)
    assert not (out / "before-after.png").exists()  # a figure only when asked
    doc = json.loads((tmp_path / "c.json").read_text())
    assert doc["schema"] == "esp.compensation/1"
    vol = doc["formats"][0]["prediction"]
    # the component table holds the mean curves: each direction keeps its difference from
    # the mean, half the reversal (up to 4.1 µm on the gantry)
    assert vol["after_um"] < 5.0 < 30.0 < vol["before_um"]
    # the folder's document is the --json one, the run's provenance included
    assert json.loads((out / "compensation.json").read_text()) == doc
    assert doc["provenance"]["command"][0] == "compensate"


def test_a_plot_target_is_checked_before_any_work(tmp_path):
    (tmp_path / "dir.png").mkdir()
    bad = run("compensate", GANTRY, "--format", "iso-csv", "--plot", tmp_path / "dir.png")
    assert bad.exit_code == 2 and bad.stderr.startswith("esp: error: ")
    assert "--plot" in bad.stderr and bad.stderr.count("\n") == 1


@pytest.mark.slow
def test_predict_without_plot_imports_no_matplotlib(tmp_path):
    code = (
        "import sys\n"
        "from esp.cli import main\n"
        "try:\n"
        # no --out: its folder holds report.pdf, which draws (a table alone needs no figure)
        f"    main(['compensate', {str(GANTRY)!r}, '--format', 'isg-volumetric', '--predict',\n"
        f"          '--json', {str(tmp_path / 'c.json')!r}, '-q'])\n"
        "except SystemExit as exc:\n"
        "    assert exc.code == 0, exc.code\n"
        "print('matplotlib' in sys.modules)\n"
    )
    import os
    import subprocess
    import sys

    root = str(GANTRY.parent.parent.parent.parent)
    env = {**os.environ, "PYTHONPATH": root}
    done = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, env=env, cwd=root
    )
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip().splitlines()[-1] == "False"


@pytest.mark.slow
def test_command_json_to_stdout_and_bad_options(tmp_path):
    result = run("compensate", GANTRY, "--format", "iso-csv", "--json", "-")
    assert result.exit_code == 0, result.output
    assert json.loads(result.stdout)["formats"][0]["format"] == "iso-csv"
    for args, fragment in [
        (("--spacing", "Q=5"), "--spacing"),
        (("--spacing", "X=abc"), "--spacing"),
        (("--cross", "X=X"), "--cross"),
        (("--spacing", "X=0"), "--spacing"),
    ]:
        r = run("compensate", GANTRY, "--format", "twincat-cross", "--leave-uncorrected", *args)
        assert r.exit_code == 2, r.output
        assert r.stderr.startswith("esp: error: ") and r.stderr.count("\n") == 1
        assert fragment in r.stderr


def test_a_five_axis_prediction_says_it_is_of_the_first_setting():
    """The compensation's field is that of the first tool case; on a machine with a head
    (or table) the report says so, and that the head's own errors stay in the residual,
    instead of a headline that looks like the whole machine's."""
    from pathlib import Path

    from click.testing import CliRunner

    from esp.cli import main

    path = Path(__file__).resolve().parent.parent / "data/examples/five-axis/machine.toml"
    r = CliRunner().invoke(main, ["compensate", str(path), "--format", "isg-volumetric"])
    assert r.exit_code == 0, r.output
    assert "note: predicted at the first setting of the head (A = 0°, C = 0°)" in r.output
    assert "the head's own errors stay in the predicted residual" in r.output
