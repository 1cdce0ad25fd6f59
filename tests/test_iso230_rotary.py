"""ISO 230-2 for a rotary axis: the rotary CSV, the figures in arcsec worked by hand, the
rotary test's notes, the U from the calibrator, and the command's refusals."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from esp.cli import main
from esp.core.errors import ParseError
from esp.iso230.rotary import RotarySetup, read_rotary, rotary_iso230_2, rotary_uncertainty

EXAMPLE = Path(__file__).resolve().parents[1] / "data" / "examples" / "rotary"

#: 0°, 180°, 360°; two runs each way (arcsec)
UP = [[1.0, 3.0, 1.0], [3.0, 5.0, 3.0]]
DOWN = [[0.0, 0.0, 0.0], [0.0, 2.0, 0.0]]


def _write(tmp_path, runs=(UP, DOWN), unit="arcsec", targets=(0, 180, 360), name="c.csv"):
    rows = ["# kind: rotary", "# axis: C", f"# unit: {unit}", "target_deg,run,direction,deviation"]
    run = 0
    for direction, values in zip(("forward", "backward"), runs, strict=True):
        for r in values:
            run += 1
            rows += [f"{t},{run},{direction},{v}" for t, v in zip(targets, r, strict=True)]
    path = tmp_path / name
    path.write_text("\n".join(rows) + "\n")
    return path


def test_figures_by_hand(tmp_path):
    """Means up 2, 4, 2 and down 0, 1, 0; s up √2 at every target, s down 0, √2, 0.
    B_i = 2, 3, 2 -> B = 3; E = 4 - 0; M = max(1, 2.5, 1) - min = 1.5;
    A = max(x̄ + 2s) - min(x̄ - 2s) = (4 + 2√2) - (1 - 2√2), both at 180°."""
    r = rotary_iso230_2(read_rotary(_write(tmp_path)))
    assert r.rotary and r.value_label == "arcsec" and r.position_key == "position_deg"
    assert r.B_i.tolist() == [2.0, 3.0, 2.0]
    assert (r.B, r.E, r.M) == (3.0, 4.0, 1.5)
    assert pytest.approx(3.0 + 4.0 * math.sqrt(2.0)) == r.A
    assert r.to_dict()["targets"][1]["position_deg"] == 180.0
    assert r.to_dict()["axis_kind"] == "rotary"
    # a test over a full turn without 90° and 270°, 0° and 360° compared
    notes = " ".join(r.notes)
    assert "missing: 90°, 270°" in notes
    assert "differ by +0.00 arcsec" in notes


def test_units_are_converted_to_arcsec(tmp_path):
    one = rotary_iso230_2(read_rotary(_write(tmp_path, name="a.csv")))
    urad = [[[v / 206264.806247 * 1e6 for v in r] for r in d] for d in (UP, DOWN)]
    two = rotary_iso230_2(read_rotary(_write(tmp_path, runs=urad, unit="urad", name="b.csv")))
    assert pytest.approx(one.E, rel=1e-9) == two.E


def test_uncertainty_by_hand(tmp_path):
    r = rotary_iso230_2(read_rotary(_write(tmp_path)))
    u = rotary_uncertainty(r, RotarySetup(1.0, 0.5))
    u_dev, u_eve = 1.0 / math.sqrt(3.0), 0.5 / (2.0 * math.sqrt(3.0))
    assert u.get("A") == pytest.approx(2.0 * math.hypot(u_dev, u_eve))
    assert u.get("R") == pytest.approx(2.0 * u_eve)
    # B: the largest |B_i| at 180°: s up √2, s down √2, n = 2 -> u_s = √(2/2 + 2/2)
    assert u.get("B") == pytest.approx(2.0 * math.hypot(u_eve, math.sqrt(2.0)))
    assert rotary_uncertainty(r, RotarySetup(1.0)).missing


def test_bad_rotary_files_name_their_line(tmp_path):
    path = _write(tmp_path)
    text = path.read_text()
    for old, new, expect in (
        ("# unit: arcsec", "# unit: mm", ":3:"),
        ("180,1,forward,3.0", "180,1,sideways,3.0", "sideways"),
        ("360,2,forward,3.0\n", "", "no value at 360"),
    ):
        bad = tmp_path / "bad.csv"
        bad.write_text(text.replace(old, new))
        with pytest.raises(ParseError, match=expect):
            read_rotary(bad)


def test_cli_rotary_json_exit_codes_and_refusals(tmp_path):
    path = EXAMPLE / "C-positioning.csv"
    target = tmp_path / "r.json"
    res = CliRunner().invoke(
        main,
        [
            "iso230-2",
            str(path),
            "--calibrator-accuracy",
            "1",
            "--eve",
            "0.5",
            "--tolerance",
            "A=12",
            "--json",
            str(target),
            "-q",
        ],
    )
    assert res.exit_code == 1, res.output  # A = 15.5 arcsec > 12
    doc = json.loads(target.read_text())
    assert doc["unit"] == "arcsec" and doc["decisions"][0]["unit"] == "arcsec"
    assert doc["uncertainty"]["figures"]["A"]["U_um"] == pytest.approx(
        2.0 * math.hypot(1.0 / math.sqrt(3.0), 0.5 / (2.0 * math.sqrt(3.0)))
    )
    for extra in (["--laser-accuracy", "0.5"], ["--vdi3441"]):
        res = CliRunner().invoke(main, ["iso230-2", str(path), *extra])
        assert res.exit_code == 2
        assert "rotary" in res.output and len(res.output.strip().splitlines()) == 1
    linear = EXAMPLE.parent / "gantry" / "X-linear.rtl"
    res = CliRunner().invoke(main, ["iso230-2", str(linear), "--calibrator-accuracy", "1"])
    assert res.exit_code == 2 and "--calibrator-accuracy" in res.output


def test_example_is_made_again_byte_for_byte(tmp_path):
    import runpy

    runpy.run_path(str(EXAMPLE / "make_positioning.py"), run_name="make")["main"](tmp_path)
    made = (tmp_path / "C-positioning.csv").read_bytes()
    assert made == (EXAMPLE / "C-positioning.csv").read_bytes()
    data = read_rotary(EXAMPLE / "C-positioning.csv")
    assert data.runs["forward"].shape == (5, 13)
    assert np.all(np.isfinite(data.runs["backward"]))
