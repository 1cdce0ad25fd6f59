"""esp ballbar: the U of F, G and H from the ballbar's stated specification, verdicts
against tolerances (esp.core.conformity) with their exit codes, and the report folder."""

from __future__ import annotations

import json
import math

import pytest
from click.testing import CliRunner

from esp.ballbar import circle_tests
from esp.ballbar.conditions import Conditions
from esp.ballbar.plots import division_um
from esp.ballbar.synthetic import Effects, synthetic_readings, write_lengths
from esp.ballbar.verdicts import expanded_uncertainty
from esp.cli import main
from esp.core.rounding import rounded

R = 100.0
SPEC = ["feed: 800 mm/min", "calibration_U: 0.2 um", "accuracy: 0.5 um", "resolution: 0.1 um"]
EFFECTS = Effects(squareness_um_per_m=20.0, backlash_um=((2.0, 2.0), (1.0, 1.0)), noise_um=0.05)


@pytest.fixture
def circle(tmp_path):
    path = tmp_path / "circle.csv"
    runs = synthetic_readings(R, EFFECTS, step_deg=2.0, feed_mm_per_min=800.0)
    write_lengths(path, R, runs, header=["machine: VMC 3", "date: 2026-11-30", *SPEC])
    return path


def test_U_of_the_figures_from_the_stated_specification():
    """u_t = √((0.5/√3)² + (0.1/√12)²); U(G) = U(H) = 2 √2 u_t; U(F) = 2 √(u_t² + 0.1²)."""
    c = Conditions(calibration_U_um=0.2, accuracy_um=0.5, resolution_um=0.1)
    u_t = math.hypot(0.5 / math.sqrt(3), 0.1 / math.sqrt(12))
    assert expanded_uncertainty("G", c) == pytest.approx(2 * math.sqrt(2) * u_t)
    assert expanded_uncertainty("H", c) == pytest.approx(2 * math.sqrt(2) * u_t)
    assert expanded_uncertainty("F", c) == pytest.approx(2 * math.hypot(u_t, 0.1))
    assert expanded_uncertainty("G", Conditions(calibration_U_um=0.2)) is None
    assert expanded_uncertainty("F", Conditions(accuracy_um=0.5)) is None


def _H_and_U(path):
    (t,) = circle_tests(path)
    return t.H_um, expanded_uncertainty("H", t.conditions)


CASES = {
    # (rule, tolerance as H + f·U, verdict, exit code)
    "simple, inside": ("simple", 0.5, "conforms", 0),
    "simple, outside": ("simple", -0.5, "does not conform", 1),
    "guarded, inside": ("guarded", 2.0, "conforms", 0),
    "guarded, in the guard band below T": ("guarded", 0.5, "not decided", 3),
    "guarded, in the guard band above T": ("guarded", -0.5, "not decided", 3),
    "guarded, outside": ("guarded", -2.0, "does not conform", 1),
}


@pytest.mark.parametrize("case", CASES)
def test_verdicts_and_exit_codes(circle, case):
    rule, f, verdict, code = CASES[case]
    H, U = _H_and_U(circle)
    limit = f"{H + f * U:.6f}"
    result = CliRunner().invoke(
        main, ["ballbar", str(circle), "--tolerance", f"H={limit}", "--rule", rule, "--json", "-"]
    )
    assert result.exit_code == code, result.output
    (dec,) = json.loads(result.stdout)["decisions"]
    assert dec["verdict"] == verdict and dec["quantity"] == "c1: H"
    assert dec["guard_band"] == pytest.approx(U if rule == "guarded" else 0.0)


def test_the_text_states_G_rounded_to_its_U(circle):
    result = CliRunner().invoke(main, ["ballbar", str(circle), "--tolerance", "G=50"])
    assert result.exit_code == 0, result.output
    (t,) = circle_tests(circle)
    g, u = rounded(t.directions[0].G_um, expanded_uncertainty("G", t.conditions))
    assert f"circular deviation G {g} µm, U = {u} µm" in result.output
    assert f"c1: G ccw {g} µm against 50 µm: conforms" in result.output


def test_a_guarded_rule_without_a_specification_is_refused(tmp_path):
    path = tmp_path / "c.csv"
    write_lengths(path, R, synthetic_readings(R, EFFECTS, step_deg=4.0))
    args = ["ballbar", str(path), "--tolerance", "G=10", "--rule", "guarded"]
    result = CliRunner().invoke(main, args)
    assert result.exit_code == 2
    line = result.output.strip()
    assert line.count("\n") == 0 and "--rule" in line and "accuracy or resolution" in line
    # the same with the specification given as options
    result = CliRunner().invoke(main, [*args, "--accuracy", "0.5"])
    assert result.exit_code in (0, 1, 3), result.output


@pytest.mark.parametrize(
    "given, found",
    [("Q=5", "FIGURE one of F, G, Gb, H"), ("G=-1", "positive tolerance"), ("G", "FIG")],
)
def test_a_bad_tolerance_is_refused_naming_the_option(circle, given, found):
    result = CliRunner().invoke(main, ["ballbar", str(circle), "--tolerance", given])
    assert result.exit_code == 2 and "--tolerance" in result.output
    assert found.split()[0] in result.output


def test_H_of_a_one_way_test_is_refused(tmp_path):
    path = tmp_path / "c.csv"
    runs = synthetic_readings(R, EFFECTS, step_deg=4.0, directions=("ccw",))
    write_lengths(path, R, runs)
    result = CliRunner().invoke(main, ["ballbar", str(path), "--tolerance", "H=5"])
    assert result.exit_code == 2 and "H needs both directions" in result.output


@pytest.mark.slow
def test_the_report_folder(circle, tmp_path):
    from pdf_helpers import page_texts

    out = tmp_path / "report"
    result = CliRunner().invoke(
        main,
        ["ballbar", str(circle), "--out", str(out), "--tolerance", "G=50", "--tolerance", "H=0.5"],
    )
    assert result.exit_code == 1, result.output  # H does not conform
    assert {p.name for p in out.iterdir() if not p.name.startswith(".")} == {
        "report.pdf",
        "polar.png",
        "ballbar.json",
        "ballbar.txt",
    }
    doc = json.loads((out / "ballbar.json").read_text(encoding="utf-8"))
    assert doc["schema"] == "esp.ballbar/2" and len(doc["decisions"]) == 3
    text = " ".join(s for page in page_texts(out / "report.pdf") for _, _, s in page)
    (t,) = circle_tests(circle)
    largest = max(abs(v) for d in t.directions for v in d.residual_um)
    for expected in (
        "ISO 230-4 circular test report",
        "VMC 3",
        "800 mm/min",
        "length U = 0.2 µm (k = 2)",
        "circular hysteresis H",
        "backlash X+ (step at 0°)",
        "µm/m",
        "Verdicts",
        "does not conform",
        f"scale {division_um(largest):g} µm per division",
    ):
        assert expected in text, expected
