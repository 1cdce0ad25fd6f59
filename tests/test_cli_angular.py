"""``esp angular``: the indirect angular error on the command line."""

from __future__ import annotations

import json

import numpy as np
import pytest
from click.testing import CliRunner

from esp.angular.text import angular_text
from esp.cli import main
from esp.core.angular import angular_from_linear
from esp.core.profile import ErrorProfile
from esp.io.laser10 import read_laser10, write_laser10

TARGETS = [-400.0, -200.0, 0.0]


@pytest.fixture
def files(tmp_path):
    """ref.rtl and shift.rtl: two runs each way. Shifted minus reference (µm):
    forward runs 4, 0, -2 and 4, 0, -2; backward runs 2, 0, -2 and 2, 0, -2.
    Over D = -400 mm (x 1000): forward -10, 0, 5 and backward -5, 0, 5 µm/m."""
    ref_f = np.array([[1.0, 2.0, 3.0], [1.5, 2.5, 3.5]])
    ref_b = np.array([[0.0, 1.0, 2.0], [0.5, 1.5, 2.5]])
    shift_f = ref_f + [4.0, 0.0, -2.0]
    shift_b = ref_b + [2.0, 0.0, -2.0]
    for name, f, b in (("ref.rtl", ref_f, ref_b), ("shift.rtl", shift_f, shift_b)):
        profile = ErrorProfile("linear", TARGETS, {"forward": f, "backward": b}, axis="X")
        write_laser10(tmp_path / name, profile)
    write_laser10(
        tmp_path / "other.rtl",
        ErrorProfile("linear", [-400.0, -100.0, 0.0], {"forward": ref_f, "backward": ref_b}),
    )
    write_laser10(
        tmp_path / "fewer.rtl",
        ErrorProfile("linear", TARGETS, {"forward": ref_f[:1], "backward": ref_b[:1]}),
    )
    write_laser10(
        tmp_path / "pitch.rta",
        ErrorProfile("angular", TARGETS, {"forward": ref_f, "backward": ref_b}),
    )
    return tmp_path


def run(args):
    runner = CliRunner()
    return runner.invoke(main, [str(a) for a in args], catch_exceptions=False)


def test_table_json_and_rta(files):
    out, doc = files / "angle.rta", files / "pitch.json"
    args = ["angular", files / "ref.rtl", files / "shift.rtl", "--displacement", "-400"]
    res = run([*args, "--datum", "0", "-o", out, "--json", doc])
    assert res.exit_code == 0, res.output
    # datum 0 mm holds -2 µm forward and backward: -2 / -400 x 1000 = 5 µm/m removed
    # forward -15, -5, 0; backward -10, -5, 0; mean -12.5, -5, 0
    data = json.loads(doc.read_text(encoding="utf-8"))
    assert data["unit"] == "um/m" and data["displacement_mm"] == -400.0
    assert data["datum_mm"] == 0.0 and data["targets_mm"] == TARGETS
    assert data["angle"] == {
        "forward": [-15.0, -5.0, 0.0],
        "backward": [-10.0, -5.0, 0.0],
        "mean": [-12.5, -5.0, 0.0],
    }
    back = read_laser10(out)
    assert back.kind == "angular" and back.run_count("forward") == 2
    np.testing.assert_allclose(back.mean("mean"), [-12.5, -5.0, 0.0], atol=1e-12)
    lines = res.output.splitlines()
    assert "  position_mm  forward  backward     mean" in lines
    assert "     -400.000  -15.000   -10.000  -12.500" in lines
    assert "bidirectional mean angle from -12.500 to 0.000 µm/m (range 12.500)" in res.output
    assert f"written {out}" in res.output
    # the text is the library's rendering of the same result
    ref, sh = read_laser10(files / "ref.rtl"), read_laser10(files / "shift.rtl")
    assert res.output.startswith(angular_text(angular_from_linear(ref, sh, -400, 0)))


def test_json_to_stdout_only(files):
    args = ["angular", files / "ref.rtl", files / "shift.rtl", "--displacement", "-400"]
    res = run([*args, "--datum", "-200", "--direction", "forward", "--json", "-"])
    assert res.exit_code == 0
    data = json.loads(res.output)  # nothing but the JSON
    # the forward angle at -200 mm (0 µm/m before the datum) stays zero: nothing removed
    assert data["angle"]["forward"] == [-10.0, 0.0, 5.0]
    assert data["datum_direction"] == "forward"


@pytest.mark.parametrize(
    ("extra", "expected"),
    [
        (["other.rtl", "--displacement", "5", "--datum", "0"], "target 2 at -200 mm"),
        (["fewer.rtl", "--displacement", "5", "--datum", "0"], "2 forward runs in ref.rtl"),
        (["shift.rtl", "--displacement", "5", "--datum", "-300"], "not a target"),
        (
            ["shift.rtl", "--displacement", "0", "--datum", "0"],
            "'--displacement': expected a non-zero distance in mm, at least 0.001 mm in "
            "size, found '0'",
        ),
        (["missing.rtl", "--displacement", "5", "--datum", "0"], "missing.rtl"),
        (["shift.rtl", "--displacement", "5", "--datum", "0", "-o", "out.rtl"], "'.rtl'"),
        (["shift.rtl", "--displacement", "5", "--datum", "0", "--unit", "arcsec"], "arcsec"),
        (["pitch.rta", "--displacement", "5", "--datum", "0"], "expected a linear positioning"),
    ],
)
def test_traps_exit_2_and_write_nothing(files, extra, expected):
    out, doc = files / "out.rta", files / "out.json"
    args = ["angular", files / "ref.rtl", files / extra[0], *extra[1:]]
    if "-o" not in extra:
        args += ["-o", out]
    args += ["--json", doc]
    res = run(args)
    assert res.exit_code == 2
    assert res.output.startswith("esp: error: ")
    assert expected in res.output
    assert "Traceback" not in res.output
    assert not out.exists() and not doc.exists() and not (files / "out.rtl").exists()
    assert sorted(p.name for p in files.iterdir()) == [
        "fewer.rtl",
        "other.rtl",
        "pitch.rta",
        "ref.rtl",
        "shift.rtl",
    ]


def test_missing_option_is_a_usage_error(files):
    res = run(["angular", files / "ref.rtl", files / "shift.rtl", "--datum", "0"])
    assert res.exit_code == 2 and "--displacement" in res.output


def test_quiet_prints_nothing_and_still_writes(files):
    doc = files / "q.json"
    args = ["angular", files / "ref.rtl", files / "shift.rtl", "--displacement", "-400"]
    res = run([*args, "--datum", "0", "--json", doc, "-q"])
    assert res.exit_code == 0, res.output
    assert res.stdout == "" and res.stderr == ""
    assert json.loads(doc.read_text(encoding="utf-8"))["schema"] == "esp.angular/1"
