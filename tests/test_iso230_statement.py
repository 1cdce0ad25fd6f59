"""esp iso230-2's statements: test conditions from the file and the options, each figure's
U from the stated instrument (worked by hand below), and decisions against tolerances
under both rules, with their exit codes."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from esp.cli import main
from esp.core.conformity import DecisionRule
from esp.core.errors import ConfigError
from esp.io.load import load_profile
from esp.iso230.positioning import iso230_2
from esp.iso230.statement import (
    LaserSetup,
    conditions_of,
    decisions,
    parse_tolerances,
    uncertainty,
)

RTL = Path(__file__).resolve().parents[1] / "data" / "examples" / "gantry" / "X-linear.rtl"
SETUP = ["--laser-accuracy", "0.5", "--misalignment", "0.5", "--eve", "1.2"]


@pytest.fixture(scope="module")
def measured():
    profile = load_profile(RTL)
    return profile, iso230_2(profile)


def test_length_budget_by_hand(measured):
    """The file: 31 min, material 19.91 -> 20.01 °C (ΔT 0.10, |T − 20| ≤ 0.09), α 11.5;
    L = 1000 mm. By hand, µm: device 0.5/√3; misalignment 10⁶·(1 − cos atan(0.5/1000))
    /(2√3); EVE 1.2/(2√3); temperature change 1·11.5·0.10/(2√3); α 1·0.7·0.09/(2√3)."""
    profile, result = measured
    u = uncertainty(result, profile, LaserSetup(0.5, 0.5, eve_um=1.2))
    r3 = 2.0 * math.sqrt(3.0)
    parts = [
        0.5 / math.sqrt(3.0),
        1e6 * (1.0 - math.cos(math.atan(0.5 / 1000.0))) / r3,
        1.2 / r3,
        11.5 * 0.10 / r3,
        0.7 * 0.09 / r3,
    ]
    expected = 2.0 * math.sqrt(sum(p * p for p in parts))
    for key in ("A", "A_up", "E", "M"):
        assert u.get(key) == pytest.approx(expected, rel=1e-6)
    assert u.length_mm == 1000.0
    # R: the environmental variation alone
    assert u.get("R") == pytest.approx(2.0 * 1.2 / r3, rel=1e-12)
    # B: EVE and the spread of the mean reversal at the largest |B_i|
    i = int(np.argmax(np.abs(result.B_i)))
    u_s = math.sqrt(result.s_up[i] ** 2 / 5 + result.s_down[i] ** 2 / 5)
    assert u.get("B") == pytest.approx(2.0 * math.hypot(1.2 / r3, u_s), rel=1e-12)


def test_without_the_eve_the_thesis_drift_for_the_duration(measured):
    profile, result = measured
    from esp.core.uncertainty.thermal import thermal_drift

    u = uncertainty(result, profile, LaserSetup(0.5, 0.5))
    assert u.get("R") == pytest.approx(2.0 * thermal_drift(31.0, "displacement"), rel=1e-12)


def test_missing_inputs_are_named_and_nothing_is_stated(measured):
    profile, result = measured
    u = uncertainty(result, profile, LaserSetup(None, 0.5))
    assert u.get("A") is None
    assert u.missing == ("the laser's accuracy (--laser-accuracy)",)
    assert u.as_dict() == {"evaluated": False, "missing": list(u.missing)}


def test_conditions_from_the_file_and_the_options(measured):
    profile, _ = measured
    items = dict(conditions_of(profile, {"feed": "2000 mm/min", "dwell": None}))
    assert items["Date and time"].endswith("(31 min)")
    assert items["Air temperature"].startswith("20.18 °C at the start")
    assert "expansion coefficient of 11.5" in items["Expansion compensation"]
    assert items["Feed"] == "2000 mm/min"
    assert "Dwell at each target" not in items


def test_decisions_worked_cases(measured):
    """A = 13.585 µm, U(A) = 1.1228 µm. Guarded (w = U): T = 16 conforms (13.585 ≤ 14.877);
    T = 14 is not decided (12.877 < 13.585 ≤ 15.123); T = 12 does not conform
    (13.585 > 13.123). Simple: T = 14 conforms, T = 13 does not."""
    profile, result = measured
    u = uncertainty(result, profile, LaserSetup(0.5, 0.5, eve_um=1.2))
    guarded = DecisionRule("guarded", key="--rule")
    simple = DecisionRule("simple", key="--rule")
    verdicts = {
        (rule.kind, t): decisions(result, {"A": t}, rule, u)[0].verdict
        for rule, t in ((guarded, 16), (guarded, 14), (guarded, 12), (simple, 14), (simple, 13))
    }
    assert verdicts == {
        ("guarded", 16): "conforms",
        ("guarded", 14): "not decided",
        ("guarded", 12): "does not conform",
        ("simple", 14): "conforms",
        ("simple", 13): "does not conform",
    }
    # B_mean is decided by its size
    d = decisions(result, {"B_mean": 3.0}, simple, u)[0]
    assert d.value == pytest.approx(abs(result.B_mean))


def test_guarded_without_u_is_refused(measured):
    profile, result = measured
    u = uncertainty(result, profile, LaserSetup())
    with pytest.raises(ConfigError, match="--laser-accuracy"):
        decisions(result, {"A": 16}, DecisionRule("guarded", key="--rule"), u)


def test_parse_tolerances_refusals():
    assert parse_tolerances(["A=20", "R_up=4"]) == {"A": 20.0, "R_up": 4.0}
    for bad in ("Q=3", "A=-1", "A=nan", "A"):
        with pytest.raises(ConfigError, match="--tolerance"):
            parse_tolerances([bad])


@pytest.mark.parametrize(
    ("extra", "code"),
    [
        (["--tolerance", "A=16", "--rule", "guarded"], 0),
        (["--tolerance", "A=14", "--rule", "guarded"], 3),
        (["--tolerance", "A=12"], 1),
    ],
)
def test_cli_exit_codes_and_json(tmp_path, extra, code):
    target = tmp_path / "r.json"
    res = CliRunner().invoke(
        main, ["iso230-2", str(RTL), *SETUP, *extra, "--json", str(target), "-q"]
    )
    assert res.exit_code == code, res.output
    doc = json.loads(target.read_text())
    assert doc["uncertainty"]["evaluated"] is True
    assert doc["uncertainty"]["figures"]["A"]["U_um"] == pytest.approx(1.1228, abs=1e-4)
    assert doc["decisions"][0]["quantity"] == "A"
    assert any(c["item"] == "Air pressure" for c in doc["conditions"])


def test_cli_guarded_without_u_is_one_line_exit_2():
    res = CliRunner().invoke(
        main, ["iso230-2", str(RTL), "--tolerance", "A=16", "--rule", "guarded"]
    )
    assert res.exit_code == 2
    lines = res.output.strip().splitlines()
    assert len(lines) == 1 and "--rule" in lines[0] and "--laser-accuracy" in lines[0]


def test_report_states_u_conditions_and_decisions(tmp_path):
    out = tmp_path / "rep"
    res = CliRunner().invoke(
        main,
        [
            "iso230-2",
            str(RTL),
            *SETUP,
            "--tolerance",
            "A=16",
            "--feed",
            "2000 mm/min",
            "--out",
            str(out),
            "-q",
        ],
    )
    assert res.exit_code == 0, res.output
    from pypdf import PdfReader

    text = " ".join(p.extract_text() for p in PdfReader(out / "report.pdf").pages)
    for words in (
        "Measurement uncertainty",
        "Decisions against tolerances",
        "2000 mm/min",
        "U = 1.1 µm",
    ):
        assert words in text, words


def test_fixed_air_compensation_adds_the_airs_change(measured):
    profile, result = measured
    from esp.core.uncertainty.refraction import refractive_index

    u = uncertainty(result, profile, LaserSetup(0.5, 0.5, eve_um=1.2, air_compensation="fixed"))
    budget = dict(u.figures["A"].budget)
    dn = refractive_index(20.27, 101.08, 43.9) - refractive_index(20.18, 101.09, 44.6)
    term = next(v for k, v in budget.items() if k.startswith("air's change"))
    assert term == pytest.approx(1e6 * abs(dn) / (2.0 * math.sqrt(3.0)))
    assert "air's change" not in " ".join(dict(u.figures["R"].budget))


def test_conditions_read_the_air_as_the_uncertainty_does(measured):
    """The air in the conditions is the environment's one reading: hPa turned into kPa,
    an absent material sensor left out."""
    from dataclasses import replace

    profile, _ = measured
    env = dict(profile.environment)
    env["Air press"] = ("1010.9", "1010.8", "1")
    env["Mat temp 2"] = ("-10.000000", "-10.000000", "0")
    items = dict(conditions_of(replace(profile, environment=env), {}))
    assert items["Air pressure"] == "101.09 kPa at the start, 101.08 kPa at the end"
    assert "Material temperature (Mat temp 2)" not in items
