"""The equation tables of Longstaff (2002) eq. 3.1-3.16, checked against each other.

The three families were transcribed independently from the printed equations; where the
thesis says they must agree, they are evaluated and compared:

* eq. 3.10-3.12 with a zero tool offset reduce to eq. 3.1-3.3 (the MCP models);
* eq. 3.14-3.16 with the mechanical angles equal to the residual angles reduce to
  eq. 3.10-3.12 (an uncompensated machine has one set of angles, thesis 3.09).
"""

from __future__ import annotations

import numpy as np
import pytest
from conftest import build_machine

from esp.core.machine import Tool
from esp.core.models.esp import equation_set
from esp.core.models.terms import parse_terms
from esp.core.synthesis import Synthesis, tool_cases

CONFIGS = ("wBMTt", "BwMTt", "BMwTt")


def _all_components(rng, mechanical: bool):
    comps = {}
    for a in "XYZ":
        comps[f"{a}.linear"] = [(0, rng.normal()), (1000, rng.normal())]
        for b in "XYZ":
            if b != a:
                comps[f"{a}.straightness.{b}"] = [(0, rng.normal()), (1000, rng.normal())]
            ang = [(0, rng.normal() * 5), (1000, rng.normal() * 5)]
            comps[f"{a}.angular.{b}"] = ang
            if mechanical:
                comps[f"{a}.mechanical.{b}"] = ang
    for p in ("XY", "XZ", "YZ"):
        comps[f"squareness.{p}"] = rng.normal() * 10
    return comps


def _totals(machine, point, tool_index=0):
    syn = Synthesis.prepare(machine)
    return syn.totals_um(point, tool_cases(machine)[tool_index])


@pytest.mark.parametrize("configuration", CONFIGS)
def test_tcp_models_with_zero_tool_equal_mcp_models(configuration):
    rng = np.random.default_rng(1)
    comps = _all_components(rng, mechanical=False)
    offsets = {"X": 120.0, "Y": -40.0, "Z": 300.0}
    mcp = build_machine(comps, configuration, offsets=offsets)
    tcp = build_machine(
        comps,
        configuration,
        offsets=offsets,
        point="TCP",
        tool=Tool(lengths_mm=(0.0,), orientations_deg=((45.0, 90.0),)),
    )
    for point in ({"X": 0, "Y": 0, "Z": 0}, {"X": 730, "Y": 210, "Z": 980}):
        assert _totals(tcp, point) == pytest.approx(_totals(mcp, point), abs=1e-12)


@pytest.mark.slow
@pytest.mark.parametrize("configuration", CONFIGS)
@pytest.mark.parametrize("tilt, spin", [(0, 0), (90, 0), (90, 90), (45, 270), (135, 180)])
def test_compensated_models_with_gamma_equal_phi_equal_tcp_models(configuration, tilt, spin):
    rng = np.random.default_rng(2)
    comps = _all_components(rng, mechanical=True)
    tool = Tool(lengths_mm=(250.0,), orientations_deg=((float(tilt), float(spin)),))
    offsets = {"X": 500.0, "Y": 100.0, "Z": -20.0}
    plain = build_machine(comps, configuration, offsets=offsets, point="TCP", tool=tool)
    compensated = build_machine(
        comps, configuration, offsets=offsets, point="TCP", compensation="MCP", tool=tool
    )
    for point in ({"X": 1000, "Y": 0, "Z": 500}, {"X": 330, "Y": 870, "Z": 40}):
        assert _totals(compensated, point) == pytest.approx(_totals(plain, point), abs=1e-12)


def test_tool_offsets_change_the_tcp_result():
    """The reduction tests above would pass if the tool were ignored; it is not."""
    rng = np.random.default_rng(3)
    comps = _all_components(rng, mechanical=False)
    tool = Tool(lengths_mm=(300.0,), orientations_deg=((90.0, 0.0),))
    mcp = build_machine(comps)
    tcp = build_machine(comps, point="TCP", tool=tool)
    point = {"X": 500, "Y": 500, "Z": 500}
    assert _totals(tcp, point) != pytest.approx(_totals(mcp, point), abs=1e-6)


def test_equation_sets_are_the_printed_ones():
    # the case picks the set (thesis 3.10)
    assert equation_set("wBMTt", "MCP", "none").source == "eq. 3.1"
    assert equation_set("BwMTt", "MCP", "MCP").source == "eq. 3.2"
    assert equation_set("BMwTt", "TCP", "none").source == "eq. 3.12"
    assert equation_set("BMwTt", "TCP", "TCP").source == "eq. 3.12"
    assert equation_set("BwMTt", "TCP", "MCP").source == "eq. 3.15"
    # eq. 3.1 and 3.2 are printed identical, and kept so
    a = [t.symbol for t in equation_set("wBMTt", "MCP", "none").terms]
    b = [t.symbol for t in equation_set("BwMTt", "MCP", "none").terms]
    assert a == b
    # eq. 3.3, T direction, as printed: T_lin + B_strt(T) + M_strt(T) - Φ_M(M)·B
    t = [x.symbol for x in equation_set("BMwTt", "MCP", "none").terms if x.direction == "T"]
    assert t == ["+T_lin", "+B_strt(T)", "+M_strt(T)", "-Φ_M(M)·B"]
    # every set has the three linear and six straightness terms once each
    for cfg in CONFIGS:
        for point, comp in (("MCP", "none"), ("TCP", "none"), ("TCP", "MCP")):
            terms = equation_set(cfg, point, comp).terms
            assert sum(x.kind == "linear" for x in terms) == 3
            assert len({(x.axis, x.about) for x in terms if x.kind == "straightness"}) == 6
            assert all(x.direction == x.about for x in terms if x.kind == "straightness")


def test_term_parser_levers_and_rejects_junk():
    (term,) = parse_terms("M", "+phi_T(M)*(B-Bo)", "eq. 3.12")
    assert (term.kind, term.axis, term.about) == ("angular", "M", "T")
    assert (term.lever_axis, term.lever_sign, term.tool_axis, term.tool_sign) == ("B", 1, "B", -1)
    (term,) = parse_terms("T", "-gamma_B(T)*Mo", "eq. 3.14")
    assert (term.kind, term.lever_axis, term.tool_axis, term.sign) == ("mechanical", None, "M", -1)
    with pytest.raises(ValueError):
        parse_terms("B", "+B.lin +nonsense", "x")
