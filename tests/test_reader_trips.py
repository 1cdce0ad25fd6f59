"""Small things a reader of esp's outputs trips on: one number format for a tool offset, a
warning when a cross-talk term makes an instrument's U, the file of another command named
for what it is, a straightness CSV refused by iso230-2, the error direction inspect shows."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from esp.cli import main
from esp.config import load_machine
from esp.core.errors import ConfigError
from esp.core.profile import ErrorProfile
from esp.core.uncertainty import laser_angular, level_differential
from esp.core.uncertainty.instruments import CROSS_TALK_SHARE, cross_talk_warning
from esp.report.profile_text import direction_words, inspect_text
from esp.report.words import offset_text

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "data" / "examples"
TWO_R3 = 2.0 * math.sqrt(3.0)
KEY = 'uncertainty.components."X.angular.Y"'


def run(*args: str):
    return CliRunner().invoke(main, list(args))


# -- tool offsets ---------------------------------------------------------------------------


def test_a_tool_offset_has_one_number_format():
    # 150 mm at tilt 40°, spin 30°: the offset the issue showed as X=114.907, Y=83.8606
    assert offset_text({"X": 114.90666, "Y": 83.86058, "Z": -114.9}) == (
        "X=114.907, Y=83.861, Z=-114.900"
    )
    assert offset_text({"X": 0.0, "Y": 0.0, "Z": 150.0}) == "X=0, Y=0, Z=150"
    assert offset_text({"X": 12.5, "Y": 0.25, "Z": 0.0}) == "X=12.50, Y=0.25, Z=0.00"
    assert offset_text({"X": -1e-9, "Y": 0.0, "Z": 1.0}) == "X=0, Y=0, Z=1"  # never -0


@pytest.mark.slow
def test_the_tcp_report_shows_its_offsets_in_one_format():
    result = run("analyse", str(EXAMPLES / "gantry" / "machine-tcp.toml"))
    assert result.exit_code == 0, result.output
    # 150 mm at 45°: 150 sin 45° = 106.066 mm along X and -Z, and Y shown alike
    assert "(offset X=106.066, Y=0.000, Z=-106.066 mm)" in result.stdout


# -- cross talk --------------------------------------------------------------------------------


def test_a_cross_talk_term_that_makes_the_u_is_named():
    # 15 µm/m over a 1 m stroke, 50 mm beam offset: u(cross talk) = 15 · 1000 / 50 / (2√3)
    # = 86.603 µm/m; u(device) = √2 (10 · 0.004 + 1 · 0.5) / (2√3) = 0.2205; Type A with
    # 5 runs of s = 1: 1/√5 = 0.4472. Σu² = 7500 + 0.0486 + 0.2 = 7500.25, the cross talk
    # 99.997 % of it; U = 2 √7500.25 = 173.2 µm/m.
    b = laser_angular(
        measuring_length_mm=1000.0,
        measurement_range_um_per_m=10.0,
        max_angle_um_per_m=15.0,
        beam_offset_mm=50.0,
        runs=5,
        run_std_um_per_m=1.0,
    )
    expected = 2 * math.sqrt(7500.0 + 0.54**2 * 2 / 12 + 0.2)
    assert math.isclose(b.U, expected, rel_tol=1e-12)
    text = cross_talk_warning("X.angular.Y", b, KEY, "laser-angular")
    assert text is not None
    assert text.startswith("X.angular.Y: the laser-angular model gives U = 173.2 µm/m (k = 2)")
    assert "100 % of its variance from the cross-talk term" in text
    assert f"{KEY}.beam_offset_mm" in text and "3.14.3" in text


def test_a_cross_talk_term_below_half_the_variance_passes_without_a_word():
    # 1 µm/m over 100 mm, 50 mm offset: u = 2 / (2√3) = 0.5774, u² = 0.3333; s = 2 with 5
    # runs: u² = 4/5 = 0.8; device √2 (1 · 0.004 + 0.1 · 0.5) / (2√3) = 0.02205, u² =
    # 0.000486; the cross talk is 0.33333 / 1.13382 = 29.40 % < 50 %
    b = laser_angular(
        measuring_length_mm=100.0,
        measurement_range_um_per_m=1.0,
        max_angle_um_per_m=1.0,
        beam_offset_mm=50.0,
        runs=5,
        run_std_um_per_m=2.0,
    )
    cross = next(c for c in b.contributions if c.name == "cross talk")
    assert cross.u == pytest.approx(2.0 / TWO_R3)
    share = cross.u**2 / sum(c.u**2 for c in b.contributions)
    assert share == pytest.approx(0.29399, abs=1e-5) and share < CROSS_TALK_SHARE
    assert cross_talk_warning("X.angular.Y", b, KEY) is None


def test_the_levels_cross_talk_names_the_footprint():
    b = level_differential(
        measuring_length_mm=1000.0,
        max_angle_um_per_m=20.0,
        unit_uncertainty_um_per_m=1.0,
        footprint_length_mm=150.0,
        runs=5,
        run_std_um_per_m=1.0,
    )
    text = cross_talk_warning("Y.angular.X", b, 'uncertainty.components."Y.angular.X"')
    assert text is not None and "footprint_length_mm" in text and "3.14.2" in text


def test_analyse_warns_of_the_cross_talk_of_its_instrument(tmp_path):
    folder = tmp_path / "m"
    folder.mkdir()
    for f in (EXAMPLES / "gantry").iterdir():
        if f.suffix in (".rtl", ".rta", ".stx", ".sty", ".stz"):
            (folder / f.name).write_bytes(f.read_bytes())
    text = (EXAMPLES / "gantry" / "machine.toml").read_text(encoding="utf-8")
    text = text.split("\n[uncertainty]")[0]  # the example's own table replaced by this one
    text += f'\n[uncertainty]\n[{KEY}]\ninstrument = "laser-angular"\nbeam_offset_mm = 50.0\n'
    (folder / "machine.toml").write_text(text, encoding="utf-8")
    machine = load_machine(folder / "machine.toml")
    from esp.core.analysis import _instrument_notes

    (warning,) = _instrument_notes(machine)
    assert warning.startswith("X.angular.Y: the laser-angular model gives U = ")
    assert f"{KEY}.beam_offset_mm" in warning


# -- the file of another command ---------------------------------------------------------------


@pytest.mark.parametrize(
    ("path", "names"),
    [
        ("parallel/machine.toml", "esp parallel FILE"),
        ("chains/gantry-wBMTt.toml", "esp derive FILE"),
        ("heads/fork-head.toml", "esp head FILE"),
        ("rotary/trunnion.toml", "rotary table file"),
    ],
)
def test_a_file_of_another_command_is_named_for_what_it_is(path, names):
    with pytest.raises(ConfigError) as info:
        load_machine(EXAMPLES / path)
    assert names in str(info.value)
    assert "did you mean 'machine'" not in str(info.value)


def test_an_unknown_top_level_key_still_gets_its_hint(tmp_path):
    path = tmp_path / "m.toml"
    path.write_text('[machin]\nname = "x"\n', encoding="utf-8")
    with pytest.raises(ConfigError, match="did you mean 'machine'"):
        load_machine(path)


# -- iso230-2 and a straightness CSV -----------------------------------------------------------


def test_iso230_refuses_a_straightness_csv(tmp_path):
    result = run("iso230-2", str(EXAMPLES / "csv" / "Y-straightness-Z.csv"))
    assert result.exit_code == 2
    assert "expected linear positioning data for ISO 230-2" in result.stderr
    assert "'# error_direction: Z' for axis Y" in result.stderr
    # a name that says so, without the comment
    text = "target_mm,run,direction,deviation\n0,1,forward,0\n100,1,forward,1\n"
    text += "0,2,backward,0\n100,2,backward,1\n0,3,forward,0\n100,3,forward,1\n"
    text += "0,4,backward,0\n100,4,backward,1\n"
    named = tmp_path / "X-straight-Z.csv"
    named.write_text(text, encoding="utf-8")
    result = run("iso230-2", str(named))
    assert result.exit_code == 2 and "its name says straight" in result.stderr
    # '# kind: linear' says it is positioning data after all
    named.write_text("# kind: linear\n" + text, encoding="utf-8")
    assert run("iso230-2", str(named)).exit_code == 0
    plain = tmp_path / "X-pos.csv"
    plain.write_text("# axis: X\n# error_direction: X\n" + text, encoding="utf-8")
    assert run("iso230-2", str(plain)).exit_code == 0


# -- inspect: the error direction --------------------------------------------------------------


def _profile(kind: str, axis: str | None = "X", about: str | None = None) -> ErrorProfile:
    runs = {"forward": np.array([[0.0, 1.0]]), "backward": np.array([[0.0, 1.0]])}
    return ErrorProfile(
        kind=kind, targets_mm=np.array([0.0, 100.0]), runs=runs, axis=axis, error_direction=about
    )


def test_inspect_shows_the_direction_the_kind_implies_or_that_it_is_not_recorded():
    assert direction_words(_profile("linear")) == "X (along the axis: a linear error)"
    assert direction_words(_profile("straightness", about="Z")) == "Z"
    assert direction_words(_profile("straightness")).startswith(
        "not recorded in the file: Y or Z for a straightness of X"
    )
    assert "axes.X.errors.angular.Y" in direction_words(_profile("angular"))
    assert direction_words(_profile("angular", axis=None)) == "not recorded in the file"
    text = inspect_text(_profile("straightness"))
    assert "?" not in text
    assert "component        X.straightness (the error direction is not recorded)" in text


def test_inspect_of_a_shipped_angular_file_has_no_question_mark():
    result = run("inspect", str(EXAMPLES / "gantry" / "X-angular-Y.rta"))
    assert result.exit_code == 0, result.output
    assert "?" not in result.stdout
    assert "error direction  not recorded in the file" in result.stdout
