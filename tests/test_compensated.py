"""Compensated machines: cases 3.10.2, 3.10.4 and 3.10.5 of Longstaff (2002) end to end from
a machine description, against values computed by hand -- with the equations as printed
(``model = "as-printed"``, the thesis' angle signs) and with the rigid-body model; angles
derived with from_linear; and the turning-centre example of ``data/examples/turning-centre``.

The hand machine: wBMTt with bottom X, middle Y, top Z (wXYZt), travel 0..1000 mm on each
axis, evaluated at X = 600, Y = 200, Z = 400 mm, with the tool offset X_o = 100 (B_o),
Z_o = 80 (T_o) mm when at the TCP. Components:

- X.angular.Y, the residual Φ_M(B): points (0, 0), (1000, 10) -> 6 µm/m at x = 600
- X.mechanical.Y, the mechanical γ_M(B): 50 µm/m everywhere
- X.linear 1.5 µm, squareness XZ 3 µm/m
"""

from __future__ import annotations

import importlib.util
import json
import math
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from esp.cli import main
from esp.config import load_machine, machine_from_dict
from esp.core.analysis import analyse, evaluate_point
from esp.core.profile import ErrorProfile
from esp.io.laser10 import write_laser10

EXAMPLE = Path(__file__).resolve().parent.parent / "data" / "examples" / "turning-centre"
P = {"X": 600.0, "Y": 200.0, "Z": 400.0}
PHI = {"points": [[0, 0.0], [1000, 10.0]]}  # 6 µm/m at x = 600
GAMMA = {"constant": 50.0}


def hand_machine(
    point: str,
    compensation: str,
    errors: dict,
    tool: bool = True,
    z_errors: dict | None = None,
    model: str = "as-printed",
):
    axes = {a: {"travel": [0, 1000], "step": 500} for a in "XYZ"}
    axes["X"]["errors"] = errors
    if z_errors:
        axes["Z"]["errors"] = z_errors
    data = {
        "machine": {
            "name": "hand",
            "configuration": "wBMTt",
            "axes": {"bottom": "X", "middle": "Y", "top": "Z"},
        },
        "analysis": {
            "point": point,
            "compensation": compensation,
            "model": model,
            "angle_convention": "thesis",
        },
        "axes": axes,
        "squareness": {"XZ": 3.0},
    }
    if tool:
        data["tool"] = {"orientation": {"offset": {"X": 100, "Z": 80}}}
    return machine_from_dict(data, Path("."), source="machine.toml")


def terms(result) -> dict[tuple[str, str, str], float]:
    """(direction, component, symbol) -> value in µm, of the one tool case."""
    b = result.cases[0].breakdown
    return {(t.direction, t.component, t.symbol): t.value_um for t in b.terms}


ERRORS = {"linear": {"constant": 1.5}, "angular": {"Y": PHI}, "mechanical": {"Y": GAMMA}}


def test_case_3_10_2_mcp_compensated_uses_the_residual_angle():
    m = hand_machine("MCP", "MCP", ERRORS, tool=False)
    res = evaluate_point(m, P)
    assert res.case == "3.10.2" and res.equations == "eq. 3.1"
    # eq. 3.1, B (= X): B_lin + Φ_M(B)·T + BT_sqr·T = 1.5 + 6 x 400/1000 + 3 x 400/1000
    #                                               = 1.5 + 2.4 + 1.2 = 5.1 µm
    assert res.cases[0].breakdown.errors_um == pytest.approx({"X": 5.1, "Y": 0.0, "Z": 0.0})
    t = terms(res)
    assert t["X", "X.angular.Y", "+Φ_M(B)·T"] == pytest.approx(2.4)
    # the mechanical angle is not used at the MCP of a compensated machine
    assert not any(k[1] == "X.mechanical.Y" for k in t)
    assert analyse(m).ignored == ("X.mechanical.Y",)


def test_case_3_10_4_tcp_compensated_at_the_tcp():
    m = hand_machine("TCP", "TCP", ERRORS)
    res = evaluate_point(m, P)
    assert res.case == "3.10.4" and res.equations == "eq. 3.10"
    # eq. 3.10, B: Φ_M(B)·(T + T_o) = 6 x (400 + 80)/1000 = 2.88; BT_sqr·T = 1.2; B_lin 1.5
    # T: -Φ_M(B)·B_o = -6 x 100/1000 = -0.6 µm
    assert res.cases[0].breakdown.errors_um == pytest.approx(
        {"X": 1.5 + 2.88 + 1.2, "Y": 0.0, "Z": -0.6}
    )
    t = terms(res)
    assert t["X", "X.angular.Y", "+Φ_M(B)·(T+T_o)"] == pytest.approx(2.88)
    assert t["Z", "X.angular.Y", "-Φ_M(B)·B_o"] == pytest.approx(-0.6)
    assert analyse(m).ignored == ("X.mechanical.Y",)
    # the same equations as the uncompensated machine (3.10.3): only the data differ
    same = evaluate_point(hand_machine("TCP", "none", ERRORS), P)
    assert same.case == "3.10.3"
    assert same.cases[0].breakdown.errors_um == res.cases[0].breakdown.errors_um


def test_case_3_10_5_residual_phi_plus_mechanical_gamma():
    m = hand_machine("TCP", "MCP", ERRORS)
    res = evaluate_point(m, P)
    assert res.case == "3.10.5" and res.equations == "eq. 3.14"
    # eq. 3.14, B: B_lin + (Φ_M(B)·T + γ_M(B)·T_o) + BT_sqr·T
    #            = 1.5 + (6 x 400 + 50 x 80)/1000 + 3 x 400/1000 = 1.5 + 2.4 + 4.0 + 1.2 = 9.1
    # T: -γ_M(B)·B_o = -50 x 100/1000 = -5.0 µm (the residual Φ has no say at the tool)
    assert res.cases[0].breakdown.errors_um == pytest.approx({"X": 9.1, "Y": 0.0, "Z": -5.0})
    t = terms(res)
    assert t["X", "X.angular.Y", "+Φ_M(B)·T"] == pytest.approx(2.4)
    assert t["X", "X.mechanical.Y", "+γ_M(B)·T_o"] == pytest.approx(4.0)
    assert t["Z", "X.mechanical.Y", "-γ_M(B)·B_o"] == pytest.approx(-5.0)
    # other mechanical angles the case needs were not given: said, and taken as zero
    assert any("X.mechanical.Z" in w and "taken as zero" in w for w in res.warnings)


def test_case_3_10_5_top_axis_angle_serves_as_gamma():
    # Z.angular.Y = 20 µm/m, no Z.mechanical.Y: it is γ_M(T) of eq. 3.14,
    # B: -γ_M(T)·T_o = -20 x 80/1000 = -1.6; T: +γ_M(T)·B_o = 20 x 100/1000 = 2.0 µm
    m = hand_machine("TCP", "MCP", {}, z_errors={"angular": {"Y": {"constant": 20.0}}})
    t = terms(evaluate_point(m, P))
    assert t["X", "Z.angular.Y", "-γ_M(T)·T_o"] == pytest.approx(-1.6)
    assert t["Z", "Z.angular.Y", "+γ_M(T)·B_o"] == pytest.approx(2.0)


def test_case_3_10_5_rigid_body_by_hand():
    """The rigid-body chain of the compensated wBMTt: the residual Φ through the
    coordinates, the mechanical γ through the tool, with thesis-signed data converted (the
    printed eq. 3.14 agrees with the rigid body, so the values are those above)."""
    m = hand_machine("TCP", "MCP", ERRORS, model="rigid-body")
    res = evaluate_point(m, P)
    assert res.case == "3.10.5" and res.equations == "rigid-body chain wBMTt"
    assert res.cases[0].breakdown.errors_um == pytest.approx({"X": 9.1, "Y": 0.0, "Z": -5.0})
    t = terms(res)
    # X: EBX·Z = 6 x 400/1000 (Φ, residual); γEBX·P_Z = 50 x 80/1000 (γ, through the tool)
    assert t["X", "X.angular.Y", "+EBX·Z"] == pytest.approx(2.4)
    assert t["X", "X.mechanical.Y", "+γEBX·P_Z"] == pytest.approx(4.0)
    # Z: e_Y × (100 e_X) = -100 e_Z: -γEBX·P_X = -50 x 100/1000
    assert t["Z", "X.mechanical.Y", "-γEBX·P_X"] == pytest.approx(-5.0)
    # the top axis' angle serves as its γ; in ISO signs Z.angular.Y = +20 µm/m turns the
    # tool (100, 0, 80) about +Y: e_Y × (100 e_X + 80 e_Z) = -100 e_Z + 80 e_X
    m = hand_machine(
        "TCP", "MCP", {}, z_errors={"angular": {"Y": {"constant": 20.0}}}, model="rigid-body"
    )
    iso = replace(m, analysis=replace(m.analysis, angle_convention="iso230-1"))
    t = terms(evaluate_point(iso, P))
    assert t["X", "Z.angular.Y", "+γEBZ·P_Z"] == pytest.approx(1.6)
    assert t["Z", "Z.angular.Y", "-γEBZ·P_X"] == pytest.approx(-2.0)
    # read with the thesis' sign of γ_M(T) (eq. 3.14: -γ_M(T)·T_o in B), as printed above
    t = terms(evaluate_point(m, P))
    assert t["X", "Z.angular.Y", "+γEBZ·P_Z"] == pytest.approx(-1.6)


def test_text_report_names_the_angle_of_each_term():
    """``esp analyse --at`` lists every term with its symbol (Φ residual, γ mechanical) and
    component, so the report says which angle fed which term."""
    m = hand_machine("TCP", "MCP", ERRORS)
    from esp.volumetric.text import render_point

    text = render_point(evaluate_point(m, P))
    assert "case 3.10.5 (eq. 3.14)" in text
    lines = [line.split() for line in text.splitlines()]
    assert lines_with(lines, "+Φ_M(B)·T") == ["X", "X.angular.Y", "EBX", "+Φ_M(B)·T", "2.400"]
    assert lines_with(lines, "+γ_M(B)·T_o") == [
        "X",
        "X.mechanical.Y",
        "EBX",
        "+γ_M(B)·T_o",
        "4.000",
    ]
    assert lines_with(lines, "-γ_M(B)·B_o") == [
        "Z",
        "X.mechanical.Y",
        "EBX",
        "-γ_M(B)·B_o",
        "-5.000",
    ]


def lines_with(lines: list[list[str]], symbol: str) -> list[str]:
    """The fields of the report line holding ``symbol``, without the share column."""
    found = [f for f in lines if symbol in f]
    assert len(found) == 1, found
    return found[0][:5]


# -- from_linear in machine.toml, end to end ------------------------------------------------

X_T = [0.0, 250.0, 500.0, 750.0, 1000.0]
LIN_F = np.array([0.0, 1.0, 3.0, 2.0, 1.0])  # reference line, forward, µm
LIN_B = LIN_F + 0.5  # and backward
PHI_TRUE = np.array([4.0, 2.0, 0.0, -2.0, 6.0])  # µm/m, zero at the datum 500 mm
D_MM = 600.0


def _write_pair(folder: Path) -> None:
    """Noise-free linear runs of X on the line Z = 0 and on the line Z = 600 mm, which sees
    the residual pitch too: angle [µm/m] x 600 mm / 1000 more error."""
    extra = PHI_TRUE * D_MM / 1000.0
    for name, shift in (("ref.rtl", 0.0), ("shift.rtl", extra)):
        runs = {"forward": [LIN_F + shift] * 2, "backward": [LIN_B + shift] * 2}
        write_laser10(folder / name, ErrorProfile("linear", X_T, runs, axis="X"))


TOML = """
[machine]
name = "from_linear"
configuration = "wBMTt"
axes = {{ bottom = "X", middle = "Y", top = "Z" }}

[analysis]
point = "{point}"
compensation = "MCP"
model = "as-printed"

[axes.X]
travel = [0, 1000]
step = 250

[axes.X.errors]
linear = "ref.rtl"
angular = {{ Y = {{ from_linear = ["ref.rtl", "shift.rtl"], displacement = 600, datum = 500 }} }}
{mechanical}

[axes.Y]
travel = [0, 0]

[axes.Z]
travel = [0, 600]
step = 300
{tool}
"""


def test_from_linear_in_machine_toml_end_to_end(tmp_path):
    _write_pair(tmp_path)
    config = tmp_path / "machine.toml"
    config.write_text(TOML.format(point="MCP", mechanical="", tool=""), encoding="utf-8")
    m = load_machine(config)
    comp = m.components["X.angular.Y"]
    assert comp.source == "from_linear ref.rtl, shift.rtl (D = 600 mm, datum 500 mm)"
    np.testing.assert_allclose(comp.profile.mean("mean"), PHI_TRUE, atol=1e-9)
    # case 3.10.2 at x = 750, z = 600: B_lin + Φ_M(B)·T = (2 + 2.5)/2 + (-2) x 600/1000
    #                                                   = 2.25 - 1.2 = 1.05 µm
    res = evaluate_point(m, {"X": 750.0, "Y": 0.0, "Z": 600.0})
    assert res.cases[0].breakdown.errors_um["X"] == pytest.approx(1.05)
    # the model reproduces the second measurement at every target: X error at Z = D is
    # the mean of shift.rtl there
    for x, lin, phi in zip(X_T, (LIN_F + LIN_B) / 2, PHI_TRUE, strict=True):
        e = evaluate_point(m, {"X": x, "Y": 0.0, "Z": D_MM}).cases[0].breakdown.errors_um
        assert e["X"] == pytest.approx(lin + phi * D_MM / 1000.0)
    # the command line shows the derivation as the component's source
    out = CliRunner().invoke(main, ["analyse", str(config)])
    assert out.exit_code == 0, out.output
    assert "from_linear ref.rtl, shift.rtl (D = 600 mm, datum 500 mm)" in out.output
    assert "case 3.10.2" in out.output


def test_from_linear_with_mechanical_gamma_at_the_probe(tmp_path):
    """Case 3.10.5: the residual pitch from the two runs at the MCP, a mechanical pitch of
    40 µm/m through a probe 200 mm along X."""
    _write_pair(tmp_path)
    config = tmp_path / "machine.toml"
    config.write_text(
        TOML.format(
            point="TCP",
            mechanical="mechanical = { Y = { constant = 40 } }",
            tool="[tool]\norientation = { offset = { X = 200 } }",
        ),
        encoding="utf-8",
    )
    res = evaluate_point(load_machine(config), {"X": 750.0, "Y": 0.0, "Z": 600.0})
    t = terms(res)
    # X: Φ_M(B)·T = -2 x 600/1000 = -1.2 µm; T_o = 0, so γ_M(B)·T_o = 0
    assert t["X", "X.angular.Y", "+Φ_M(B)·T"] == pytest.approx(-1.2)
    # γ levered by T_o only: this probe has no T_o, so the breakdown leaves the term out
    assert ("X", "X.mechanical.Y", "+γ_M(B)·T_o") not in t
    # Z: -γ_M(B)·B_o = -40 x 200/1000 = -8 µm, from the mechanical angle only
    assert t["Z", "X.mechanical.Y", "-γ_M(B)·B_o"] == pytest.approx(-8.0)
    assert res.cases[0].breakdown.errors_um["Z"] == pytest.approx(-8.0)


# -- the turning-centre example ---------------------------------------------------------------


def _analyse_json(config: Path) -> dict:
    res = CliRunner().invoke(main, ["analyse", str(config), "--json", "-"])
    assert res.exit_code == 0, res.output
    return json.loads(res.output)


@pytest.fixture(scope="module")
def example() -> dict[str, dict]:
    return {name: _analyse_json(EXAMPLE / name) for name in ("machine.toml", "machine-mcp.toml")}


@pytest.mark.slow
def test_turning_centre_runs(example):
    mcp, tcp = example["machine-mcp.toml"], example["machine.toml"]
    assert mcp["analysis"]["case"] == "3.10.2" and tcp["analysis"]["case"] == "3.10.5"
    assert mcp["analysis"]["warnings"] == [] and tcp["analysis"]["warnings"] == []
    # the two-axis machine: Y has no travel and is evaluated at one point
    assert tcp["analysis"]["grid"] == {"X": 21, "Y": 1, "Z": 17}
    for config in ("machine.toml", "machine-mcp.toml"):
        res = CliRunner().invoke(main, ["analyse", str(EXAMPLE / config)])
        assert res.exit_code == 0, res.output
        assert "from_linear Xpos_z0.rtl, Xpos_z800.rtl (D = -800 mm, datum -560 mm)" in (res.output)


def test_turning_centre_probe_amplifies_the_mechanical_pitch(example):
    """The residual slope keeps the MCP small; the probe carries the mechanical pitch."""
    mcp = example["machine-mcp.toml"]["worst"]["accuracy_um"]
    cases = example["machine.toml"]["cases"]
    assert [c["tool"]["offset_mm"]["X"] for c in cases] == [170.0, 270.0]
    short, long = (c["volumetric"]["accuracy_um"] for c in cases)
    assert mcp < 10.0
    assert short > 1.8 * mcp and long > 2.5 * mcp and long > short
    # at the worst point of the long probe the Z error is mostly -γ_M(B)·B_o
    worst = cases[1]["breakdown"][0]
    z_terms = {t["term"]: t for t in worst["terms"] if t["direction"] == "Z"}
    gamma = z_terms["-γEBX·P_X"]  # the rigid body's -γ_M(B)·B_o
    assert gamma["component"] == "X.mechanical.Y"
    assert abs(gamma["value_um"]) > 0.6 * abs(worst["errors_um"]["Z"])


def test_turning_centre_mcp_part_is_the_same_in_both_cases(example):
    """At the MCP the X direction holds only Φ (residual) terms, so the X extremes of the
    probe cases equal those of the MCP case: the probe along X adds no X error here."""
    mcp_axes = example["machine-mcp.toml"]["cases"][0]["axes"]["X"]
    for case in example["machine.toml"]["cases"]:
        assert case["axes"]["X"] == mcp_axes


def test_turning_centre_readme_quotes_the_results(example):
    readme = (EXAMPLE / "README.md").read_text(encoding="utf-8")
    values = [example["machine-mcp.toml"]["worst"]["accuracy_um"]]
    values += [c["volumetric"]["accuracy_um"] for c in example["machine.toml"]["cases"]]
    for value in values:
        assert f"{value:.1f} µm" in readme


def test_turning_centre_generator_reproduces_the_files(tmp_path):
    name = "_make_data_turning_centre"
    spec = importlib.util.spec_from_file_location(name, EXAMPLE / "make_data.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    try:
        spec.loader.exec_module(module)
    finally:
        del sys.modules[name]
    written = module.write_files(tmp_path)
    shipped = sorted(p.name for p in EXAMPLE.iterdir() if p.suffix in (".rtl", ".rta"))
    assert sorted(p.name for p in written) == shipped
    for path in written:
        assert path.read_bytes() == (EXAMPLE / path.name).read_bytes(), path.name
    # the residual pitch the generator put in is what the indirect method gets back, to
    # within the noise of the runs (0.3 µm per reading: about 0.2 µm/m on 10 runs)
    derived = load_machine(EXAMPLE / "machine.toml").components["X.angular.Y"].profile
    truth = module.residual_pitch_um_per_m(derived.targets_mm)
    assert np.max(np.abs(derived.mean("mean") - truth)) < 0.6
    assert math.isclose(float(truth[derived.targets_mm.tolist().index(-560.0)]), 0.0)
