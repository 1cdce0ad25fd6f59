"""The rigid-body model: the fast engine's term tables equal the exact kinematic chain of
the machine to first order, for every configuration, evaluation case and axis assignment.

The referee is :mod:`esp.core.kinematics`: the exact 4x4 chain (``position``) and its exact
first-order sensitivities (``sensitivities``), evaluated independently of the term tables.
"""

from __future__ import annotations

import numpy as np
import pytest

from esp.core.kinematics import position, sensitivities
from esp.core.machine import Analysis, Axis, Component, Machine, Tool
from esp.core.models.derived import CHAIN_ORDER, cartesian_chain, derive_terms, error_symbol
from esp.core.models.signs import angle_signs, differences
from esp.core.models.tool import tool_cases
from esp.core.names import AXIS_NAMES, all_component_names
from esp.core.profile import ErrorProfile
from esp.core.synthesis import Synthesis

FAMILIES = {
    "mcp": ("MCP", "none"),
    "tcp": ("TCP", "none"),
    "tcp-compensated-mcp": ("TCP", "MCP"),
}
ASSIGNMENTS = [("X", "Y", "Z"), ("Y", "X", "Z"), ("Z", "X", "Y")]  # right, left, right


def _profile(rng, kind, axis, travel, scale):
    """A smooth random curve along the axis: a cubic plus a ripple."""
    t = np.linspace(travel[0], travel[1], 41)
    u = (t - travel[0]) / (travel[1] - travel[0])
    c = rng.normal(size=4)
    v = scale * (c[0] + c[1] * u + c[2] * u**2 + c[3] * np.sin(7 * u))
    pkind = "angular" if kind == "mechanical" else kind
    return ErrorProfile.from_values(pkind, t, v, axis=axis)


def random_machine(configuration, letters, family, seed):
    rng = np.random.default_rng(seed)
    travel = {a: (-200.0 + 100 * i, 600.0 + 150 * i) for i, a in enumerate(AXIS_NAMES)}
    offsets = {a: float(rng.uniform(*travel[a])) for a in AXIS_NAMES}
    role_of = dict(zip(letters, ("bottom", "middle", "top"), strict=True))
    axes = {a: Axis(a, role_of[a], travel[a], travel[a], 100.0, offsets[a]) for a in AXIS_NAMES}
    comps = {}
    for name in all_component_names():
        if name.kind == "mechanical" and family != "tcp-compensated-mcp":
            continue
        if name.kind == "squareness":
            comps[name] = Component(name, "squareness", None, name.about, value=rng.normal() * 20)
            continue
        scale = 5.0 if name.kind in ("linear", "straightness") else 12.0  # µm, µm/m
        profile = _profile(rng, name.kind, name.axis, travel[name.axis], scale)
        comps[name] = Component(name, name.kind, name.axis, name.about, profile=profile)
    point, compensation = FAMILIES[family]
    tool = None
    if point == "TCP":
        offset = {a: float(rng.uniform(-250, 250)) for a in AXIS_NAMES}
        tool = Tool(lengths_mm=(), orientations_deg=(), offsets_mm=(offset,))
    return Machine(
        "random",
        configuration,
        dict(zip(("bottom", "middle", "top"), letters, strict=True)),
        axes,
        comps,
        Analysis(point=point, compensation=compensation, straightness_fit="none"),
        tool,
    )


def chain_first_order(machine, family, points):
    """Σ_e ∂p/∂e · e(q) in µm, from the chain's exact sensitivities and the component data."""
    letters = tuple(machine.roles[r] for r in ("bottom", "middle", "top"))
    chain = cartesian_chain(machine.configuration, letters, family == "tcp-compensated-mcp")
    (tool,) = tool_cases(machine)
    params = {f"{a}_off": machine.axes[a].offset_mm for a in AXIS_NAMES}
    params.update({f"P_{a}": tool.offset_mm[a] for a in AXIS_NAMES})
    coords = {a: points[:, i] for i, a in enumerate(AXIS_NAMES)}
    sens = sensitivities(chain, coords, params)
    values = _error_values(machine, chain.errors, points)
    total = np.zeros_like(points)
    for e, s in sens.items():
        total += s * values[e][:, None] * 1000.0  # mm per unit -> µm per unit
    return total, chain, coords, params, values


def _error_values(machine, names, points):
    out = {}
    for e in names:
        comp = _component_of(machine, e)
        if comp is None:
            out[e] = np.zeros(len(points))
        elif comp.kind == "squareness":
            out[e] = np.full(len(points), comp.value)
        else:
            x = points[:, AXIS_NAMES.index(comp.axis)]
            out[e] = comp.profile.at(x)
    return out


def _component_of(machine, symbol):
    for name, comp in machine.components.items():
        if name.kind == "squareness":
            if error_symbol("squareness", None, name.about) == symbol:
                return comp
        elif error_symbol(name.kind, name.axis, name.about) == symbol:
            return comp
    return None


def _points(machine, n, seed):
    rng = np.random.default_rng(seed)
    return np.column_stack([rng.uniform(*machine.axes[a].travel_mm, n) for a in AXIS_NAMES])


@pytest.mark.slow
@pytest.mark.parametrize("letters", ASSIGNMENTS, ids=["".join(a) for a in ASSIGNMENTS])
@pytest.mark.parametrize("family", list(FAMILIES))
@pytest.mark.parametrize("configuration", list(CHAIN_ORDER))
def test_engine_equals_the_exact_chain_to_first_order(configuration, family, letters):
    machine = random_machine(
        configuration, letters, family, seed=hash((configuration, family)) % 997
    )
    points = _points(machine, 64, seed=3)
    syn = Synthesis.prepare(machine)
    (tool,) = tool_cases(machine)
    engine = syn.totals_at_um(points, tool)
    first, chain, coords, params, values = chain_first_order(machine, family, points)
    assert np.max(np.abs(engine - first)) < 1e-6  # µm
    # the exact chain: nominal + first order + a second-order remainder
    nominal = position(chain, coords, params, {})
    exact = position(chain, coords, params, values)
    residual_um = np.max(np.abs((exact - nominal) * 1000.0 - first))
    # errors of ~50 µrad and levers below 2 m: products of two errors stay below ~0.1 µm
    assert residual_um < 0.1
    assert np.max(np.abs(first)) > 1.0  # the test is not vacuous


def test_second_order_remainder_shrinks_quadratically():
    machine = random_machine("BMwTt", ("X", "Y", "Z"), "tcp", seed=5)
    points = _points(machine, 32, seed=9)
    first, chain, coords, params, values = chain_first_order(machine, "tcp", points)
    nominal = position(chain, coords, params, {})
    remainders = []
    for scale in (1.0, 0.5, 0.25):
        scaled = {e: v * scale * 50 for e, v in values.items()}  # make second order visible
        exact = position(chain, coords, params, scaled)
        remainders.append(np.max(np.abs((exact - nominal) * 1000.0 - first * scale * 50)))
    assert remainders[0] > 1e-6
    ratios = [remainders[i] / remainders[i + 1] for i in range(2)]
    assert all(3.5 < r < 4.5 for r in ratios), ratios


@pytest.mark.parametrize("configuration", list(CHAIN_ORDER))
def test_every_angle_lever_is_the_chain_after_the_axis(configuration):
    """Each axis' angles are levered by exactly the axes after it in the chain order (and
    the tool): e.g. the table of BwMTt by the middle and top axes, the middle axis of BMwTt
    by the bottom and top axes (issue: lever of a workpiece-side axis)."""
    order = CHAIN_ORDER[configuration]
    table = derive_terms(configuration, ("X", "Y", "Z"), "tcp")
    for i, role in enumerate(order):
        levers = {t.lever_axis for t in table.terms if t.kind == "angular" and t.axis == role} - {
            None
        }
        assert levers == set(order[i + 1 :])
        tools = {t.tool_axis for t in table.terms if t.kind == "angular" and t.axis == role}
        assert tools - {None} == {"B", "M", "T"}


def test_zero_tool_reduces_the_tcp_table_to_the_mcp_table():
    for configuration in CHAIN_ORDER:
        mcp = derive_terms(configuration, ("Y", "X", "Z"), "mcp").terms
        tcp = derive_terms(configuration, ("Y", "X", "Z"), "tcp").terms
        strip = {(t.direction, t.kind, t.axis, t.about, t.sign, t.lever_axis) for t in tcp}
        assert {(t.direction, t.kind, t.axis, t.about, t.sign, t.lever_axis) for t in mcp} == {
            s for s in strip if s[5] is not None or s[1] in ("linear", "straightness")
        }


def test_the_issue_reproductions():
    """Issue 11: a bottom-axis angle through a tool offset, and a top-axis angle with an
    offset in the plane of two workpiece-carried axes."""
    from esp.core.analysis import evaluate_point

    def machine(configuration, name, offset, **analysis):
        m = random_machine(configuration, ("X", "Y", "Z"), "tcp", seed=1)
        comp = Component(
            name,
            "angular",
            name[0],
            name[-1],
            profile=ErrorProfile.from_values("angular", [-1e4, 1e4], [100.0, 100.0], axis=name[0]),
        )
        tool = Tool(lengths_mm=(), orientations_deg=(), offsets_mm=(offset,))
        axes = {
            a: Axis(a, ax.role, ax.travel_mm, ax.simulate_mm, 100.0, 0.0)
            for a, ax in m.axes.items()
        }
        return Machine(
            "repro",
            configuration,
            m.roles,
            axes,
            {name: comp},
            Analysis(point="TCP", **analysis),
            tool,
        )

    at = {"X": 500.0, "Y": 500.0, "Z": 0.0}
    # X.angular.Y = 100 µm/m, tool offset X = 100 mm: the tool tip drops 10 µm in Z
    for configuration in ("wBMTt", "BwMTt"):
        m = machine(configuration, "X.angular.Y", {"X": 100.0})
        errors = evaluate_point(m, at).cases[0].breakdown.errors_um
        assert errors == pytest.approx({"X": 0.0, "Y": 0.0, "Z": -10.0}, abs=1e-9)
    printed = machine(
        "BwMTt", "X.angular.Y", {"X": 100.0}, model="as-printed", angle_convention="thesis"
    )
    assert evaluate_point(printed, at).cases[0].breakdown.errors_um["Z"] == pytest.approx(0.0)
    # Z.angular.Y = 100 µm/m with offset (100, 0, 100) on BMwTt: a rotation about +Y moves
    # the tip along +X for +Z and along -Z for +X: (+10, 0, -10) µm; the print gives an
    # error parallel to the offset, which no rotation can produce
    m = machine("BMwTt", "Z.angular.Y", {"X": 100.0, "Z": 100.0})
    errors = evaluate_point(m, at).cases[0].breakdown.errors_um
    assert errors == pytest.approx({"X": 10.0, "Y": 0.0, "Z": -10.0}, abs=1e-9)
    printed = machine(
        "BMwTt",
        "Z.angular.Y",
        {"X": 100.0, "Z": 100.0},
        model="as-printed",
        angle_convention="thesis",
    )
    errors = evaluate_point(printed, at).cases[0].breakdown.errors_um
    assert errors == pytest.approx({"X": -10.0, "Y": 0.0, "Z": -10.0}, abs=1e-9)


def test_printed_differences_are_the_known_ones():
    """With the thesis' implied angle signs, the printed MCP equations and eq. 3.10/3.14
    agree with the rigid body; eq. 3.11/3.15 miss the bottom axis' tool levers; eq. 3.12/3.16
    mirror the tool offsets along the two workpiece-carried axes."""
    for configuration in ("wBMTt", "BwMTt", "BMwTt"):
        assert differences(configuration, "mcp") == []
    assert differences("wBMTt", "tcp") == [] and differences("wBMTt", "tcp-compensated-mcp") == []
    missing = {(d.direction, d.derived) for d in differences("BwMTt", "tcp")}
    assert missing == {("M", "-Φ_T(B)·B_o"), ("T", "-Φ_M(B)·B_o")}
    assert all(d.why.startswith("missing from the print") for d in differences("BwMTt", "tcp"))
    mirrored = differences("BMwTt", "tcp")
    assert mirrored and all(d.why.startswith("opposite sign to the rigid body") for d in mirrored)
    assert all(("B_o" in d.printed) or ("M_o" in d.printed) for d in mirrored)
    # the implied signs of a right-handed and a left-handed assignment are opposite
    right = angle_signs("wBMTt", ("X", "Y", "Z"))
    left = angle_signs("wBMTt", ("Y", "X", "Z"))
    assert right and all(left[k] == -v for k, v in right.items())


@pytest.mark.parametrize(
    ("name", "displaced", "sign"),
    [("X.angular.Y", "Z", 1.0), ("Y.angular.X", "Z", -1.0), ("X.angular.Z", "Y", -1.0)],
)
def test_from_linear_angle_reproduces_the_difference_of_its_runs(name, displaced, sign):
    """Thesis 3.08.1: the angle from two linear runs of axis K displaced along J is the
    slope dE_K/dJ. The rigid body reads it as the rotation whose term reproduces that slope:
    the term in K with lever J has the sign ε(R, J, K) of e_R × e_J · e_K."""
    from esp.core.models.bind import bind_model

    slope = 7.0  # µm/m: the K error grows by 7 µm per m along J
    axis, _, about = name.split(".")
    profile = ErrorProfile.from_values("angular", [-1e4, 1e4], [slope, slope], axis=axis)
    comp = Component(name, "angular", axis, about, profile=profile, from_linear=True)
    axes = {
        a: Axis(a, r, (0.0, 1000.0), (0.0, 1000.0), 250.0)
        for a, r in zip("XYZ", ("bottom", "middle", "top"), strict=True)
    }
    m = Machine(
        "from_linear", "wBMTt", {"bottom": "X", "middle": "Y", "top": "Z"}, axes, {name: comp}
    )
    assert bind_model(m).input_signs == ({} if sign > 0 else {name: -1.0})
    syn = Synthesis.prepare(m)
    (tool,) = tool_cases(m)
    point = np.array([[300.0, 400.0, 500.0]])
    lever = point[0, AXIS_NAMES.index(displaced)]
    errors = syn.totals_at_um(point, tool)[0]
    assert errors[AXIS_NAMES.index(axis)] == pytest.approx(slope * lever / 1000.0)
