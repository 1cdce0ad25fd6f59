"""The synthesis engine against hand-computed values of the thesis' equations.

Machine for every test unless said: wBMTt with bottom X, middle Y, top Z (thesis 3.02),
travel 0..1000 mm on each axis, grid step 250 mm.
"""

from __future__ import annotations

import math

import pytest
from conftest import build_machine

from esp.core.analysis import analyse, evaluate_point
from esp.core.errors import DataError
from esp.core.machine import Tool
from esp.core.synthesis import tool_cases

P = {"X": 750.0, "Y": 250.0, "Z": 500.0}


def _errors(machine, point=P, tool=0):
    res = evaluate_point(machine, point)
    return res.cases[tool].breakdown.errors_um


def test_zero_data_give_zero_error():
    res = analyse(build_machine({}))
    case = res.cases[0]
    assert case.volumetric.value_um == 0.0
    assert all(e.range_um == 0.0 for e in case.axes.values())


def test_linear_term_alone():
    # eq. 3.1, B direction: B_lin; X.linear 0 -> 8 µm over 0..1000, at x = 750: 6 µm
    m = build_machine({"X.linear": [(0, 0.0), (1000, 8.0)]})
    assert _errors(m) == pytest.approx({"X": 6.0, "Y": 0.0, "Z": 0.0})


def test_straightness_term_alone_after_slope_removal():
    # Y.straightness.Z (M_strt(T) in eq. 3.1, T direction): a bow of 3 µm at the middle on a
    # slope of 2 µm over the stroke. End-point fit removes the line through the ends:
    # values 0, 4, 2 at 0, 500, 1000 -> minus (0, 1, 2) -> 0, 3, 0. At y = 250: 1.5 µm.
    m = build_machine(
        {"Y.straightness.Z": [(0, 0.0), (500, 4.0), (1000, 2.0)]}, straightness_fit="endpoint"
    )
    assert _errors(m) == pytest.approx({"X": 0.0, "Y": 0.0, "Z": 1.5})
    # least squares: mean 2, slope 0.002 µm/mm -> line 1, 2, 3 -> residuals -1, 2, -1;
    # at y = 250 halfway between -1 and 2: 0.5 µm
    m = build_machine({"Y.straightness.Z": [(0, 0.0), (500, 4.0), (1000, 2.0)]})
    assert _errors(m)["Z"] == pytest.approx(0.5)


def test_angular_term_with_lever_and_offset():
    # rigid body: the roll EAX = 5 µm/m of the bottom axis X turns its lever, from X's
    # measurement line to the point, (Y - 100) e_Y + (Z - 200) e_Z = 150 e_Y + 300 e_Z, about
    # +X: e_X × (150 e_Y + 300 e_Z) = 150 e_Z - 300 e_Y -> Y = -1.5 µm, Z = +0.75 µm
    m = build_machine({"X.angular.X": 5.0}, offsets={"Y": 100.0, "Z": 200.0})
    assert _errors(m) == pytest.approx({"X": 0.0, "Y": -1.5, "Z": 0.75})
    # eq. 3.1 as printed: Φ_B(B) acts as +Φ_B(B)·T in M and -Φ_B(B)·M in T:
    # M = 5·(500-200)/1000 = 1.5; T = -5·(250-100)/1000 = -0.75 (the thesis' sign of the roll)
    m = build_machine(
        {"X.angular.X": 5.0},
        offsets={"Y": 100.0, "Z": 200.0},
        model="as-printed",
        angle_convention="thesis",
    )
    assert _errors(m) == pytest.approx({"X": 0.0, "Y": 1.5, "Z": -0.75})


def test_squareness_term():
    # eq. 3.1 B: +BM_sqr·M (squareness.XY) -> 10 µm/m · 250 mm = 2.5 µm
    m = build_machine({"squareness.XY": 10.0})
    assert _errors(m) == pytest.approx({"X": 2.5, "Y": 0.0, "Z": 0.0})


def test_bmwtt_middle_yaw_uses_bottom_lever():
    # eq. 3.3 M: +Φ_T(M)·B; Y.angular.Z = -4 µm/m, x = 750 -> -3 µm; wBMTt does not use it
    comps = {"Y.angular.Z": -4.0}
    assert _errors(build_machine(comps, "BMwTt")) == pytest.approx({"X": 0.0, "Y": -3.0, "Z": 0.0})
    res = analyse(build_machine(comps, "wBMTt"))
    assert res.ignored == ("Y.angular.Z",) and res.cases[0].volumetric.value_um == 0.0


def test_axis_assignment_follows_roles():
    # bottom Y, middle X, top Z (YXwZt of thesis figure 3.8): B_lin is Y.linear, and Φ_T(B)·M
    # is Y.angular.Z times the X coordinate: 6 µm/m · 750 mm = 4.5 µm in Y
    m = build_machine({"Y.angular.Z": 6.0}, "BwMTt", roles=("Y", "X", "Z"))
    assert _errors(m) == pytest.approx({"X": 0.0, "Y": 4.5, "Z": 0.0})


def test_tool_offset_decomposition_eq_3_6_to_3_9():
    # L = 100, tilt α = 30°, spin β = 60°: P_T = 100 cos 30° = 86.603, P_B = 100 sin 30° sin 60°
    # = 43.301, P_M = 100 sin 30° cos 60° = 25
    # (the thesis measures the tilt from +T: spindle = "+Z")
    tool = Tool(lengths_mm=(100.0,), orientations_deg=((30.0, 60.0),), spindle="+Z")
    (case,) = tool_cases(build_machine(point="TCP", tool=tool))
    assert case.offset_mm == pytest.approx({"X": 43.30127, "Y": 25.0, "Z": 86.60254}, abs=1e-5)
    # by default the spindle points against the top axis: the same tool hangs down
    tool = Tool(lengths_mm=(100.0,), orientations_deg=((30.0, 60.0),))
    (case,) = tool_cases(build_machine(point="TCP", tool=tool))
    assert case.offset_mm == pytest.approx({"X": 43.30127, "Y": 25.0, "Z": -86.60254}, abs=1e-5)


def test_tcp_terms_of_eq_3_10():
    # X.angular.Y = Φ_M(B) = 5 µm/m; tool 200 mm along X (tilt 90, spin 90): B_o = 200.
    # B: +Φ_M(B)·(T+T_o) = 5·500/1000 = 2.5; T: -Φ_M(B)·B_o = -5·200/1000 = -1.0
    tool = Tool(lengths_mm=(200.0,), orientations_deg=((90.0, 90.0),))
    m = build_machine({"X.angular.Y": 5.0}, point="TCP", tool=tool)
    assert _errors(m) == pytest.approx({"X": 2.5, "Y": 0.0, "Z": -1.0})


def test_compensated_case_uses_mechanical_angle_for_the_tool():
    # eq. 3.14 B: +Φ_M(B)·T + γ_M(B)·T_o. Residual Φ = 1 µm/m, mechanical γ = 20 µm/m,
    # tool 150 mm along +Z (tilt 0 from +Z): B = 1·500/1000 + 20·150/1000 = 0.5 + 3.0 = 3.5 µm
    # (the rigid body gives the same: EBX turns Z e_Z into +Z e_X)
    tool = Tool(lengths_mm=(150.0,), orientations_deg=((0.0, 0.0),), spindle="+Z")
    comps = {"X.angular.Y": 1.0, "X.mechanical.Y": 20.0}
    m = build_machine(comps, point="TCP", compensation="MCP", tool=tool)
    assert _errors(m)["X"] == pytest.approx(3.5)
    # without the mechanical angle the case warns and takes γ as zero
    res = analyse(build_machine({"X.angular.Y": 1.0}, point="TCP", compensation="MCP", tool=tool))
    assert any("X.mechanical.Y" in w for w in res.warnings)
    # at the MCP the mechanical data are not used, and say so
    assert "X.mechanical.Y" in analyse(build_machine(comps)).ignored


def test_top_axis_angles_serve_as_gamma():
    # eq. 3.14 B: -γ_M(T)·T_o; the top axis' angular data are its γ: Z.angular.Y = 10 µm/m,
    # T_o = 100 -> -1.0 µm
    tool = Tool(lengths_mm=(100.0,), orientations_deg=((0.0, 0.0),))
    m = build_machine({"Z.angular.Y": 10.0}, point="TCP", compensation="MCP", tool=tool)
    assert _errors(m)["X"] == pytest.approx(-1.0)


def test_doubling_every_error_doubles_every_result():
    comps = {
        "X.linear": [(0, 1.0), (500, -3.0), (1000, 4.0)],
        "Y.straightness.X": [(0, 0.0), (500, 2.0), (1000, -1.0)],
        "Z.angular.X": [(0, 3.0), (1000, -6.0)],
        "X.angular.Z": [(0, -2.0), (1000, 5.0)],
        "squareness.YZ": 7.0,
    }
    double = {
        k: (2 * v if isinstance(v, float) else [(x, 2 * y) for x, y in v]) for k, v in comps.items()
    }
    tool = Tool(lengths_mm=(120.0,), orientations_deg=((45.0, 90.0),))
    a = analyse(build_machine(comps, point="TCP", tool=tool)).cases[0]
    b = analyse(build_machine(double, point="TCP", tool=tool)).cases[0]
    assert b.volumetric.value_um == pytest.approx(2 * a.volumetric.value_um)
    assert b.volumetric.at == a.volumetric.at
    for axis in "XYZ":
        assert b.axes[axis].range_um == pytest.approx(2 * a.axes[axis].range_um)
        assert b.axes[axis].maximum.value_um == pytest.approx(2 * a.axes[axis].maximum.value_um)


def test_extremes_of_a_hand_checkable_grid():
    # X.linear -3, 5, 1 at x = 0, 500, 1000 on a 500 mm grid; Z.linear 0 -> 2.
    m = build_machine(
        {"X.linear": [(0, -3.0), (500, 5.0), (1000, 1.0)], "Z.linear": [(0, 0.0), (1000, 2.0)]},
        step=500.0,
    )
    case = analyse(m).cases[0]
    assert case.axes["X"].minimum.value_um == -3.0 and case.axes["X"].minimum.at["X"] == 0.0
    assert case.axes["X"].maximum.value_um == 5.0 and case.axes["X"].maximum.at["X"] == 500.0
    assert case.axes["X"].range_um == 8.0
    # volumetric: max of sqrt(x² + z²): at x = 500, z = 1000: sqrt(25 + 4)
    assert case.volumetric.value_um == pytest.approx(math.sqrt(29.0))
    assert (case.volumetric.at["X"], case.volumetric.at["Z"]) == (500.0, 1000.0)
    # planar XY ignores Z: 5 at x = 500; planar YZ: only Z: 2
    assert case.planar["XY"].value_um == pytest.approx(5.0)
    assert case.planar["YZ"].value_um == pytest.approx(2.0)
    # the breakdown at the volumetric point: X.linear is all of X, Z.linear all of Z
    vol = case.breakdowns[0]
    assert vol.label == "volumetric"
    shares = {(t.direction, t.component): t.share_pct for t in vol.terms}
    assert shares[("X", "X.linear")] == pytest.approx(100.0)
    assert shares[("Z", "Z.linear")] == pytest.approx(100.0)


@pytest.mark.parametrize(
    "datum, expected",
    [
        # X.linear = 1 + 7·x/1000 µm, so e(750) = 6.25
        ("none", 6.25),
        ("negative", 6.25 - 1.0),  # minus e(0)
        ("centre", 6.25 - 4.5),  # minus e(500), the middle of the travel
        ({"X": 250.0, "Y": 0.0, "Z": 0.0}, 6.25 - 2.75),  # minus e(250)
    ],
)
def test_datum(datum, expected):
    m = build_machine({"X.linear": [(0, 1.0), (1000, 8.0)]}, datum=datum)
    assert _errors(m)["X"] == pytest.approx(expected)
    # the breakdown terms are relative to the datum too, and still sum to the total
    terms = evaluate_point(m, P).cases[0].breakdown.terms
    assert sum(t.value_um for t in terms if t.direction == "X") == pytest.approx(expected)


def test_sweep_reports_the_worst_orientation():
    # Top-axis angles through the tool (eq. 3.10): Z.angular.Y = Φ_M(T) = 10 µm/m acts as
    # -Φ_M(T)·T_o in B and +Φ_M(T)·B_o in T; Z.angular.X = Φ_B(T) = 30 µm/m acts as
    # -Φ_B(T)·T_o in M and +Φ_B(T)·M_o in T. L = 100:
    #   tilt 0        (T_o = 100): B = -1, M = -3        -> sqrt(10) = 3.162
    #   tilt 90 spin 0 (M_o = 100): T = +3                -> 3
    #   tilt 90 spin 90 (B_o = 100): T = +1               -> 1
    tool = Tool(
        lengths_mm=(100.0,),
        orientations_deg=((0.0, 0.0), (90.0, 0.0), (90.0, 90.0)),
        sweep=True,
    )
    m = build_machine({"Z.angular.Y": 10.0, "Z.angular.X": 30.0}, point="TCP", tool=tool)
    res = analyse(m)
    assert [round(e.volumetric.value_um, 3) for e in res.sweep] == [3.162, 3.0, 1.0]
    (case,) = res.cases
    assert (case.tool.tilt_deg, case.tool.spin_deg) == (0.0, 0.0)
    assert case.volumetric.value_um == pytest.approx(math.sqrt(10.0))


def test_each_tool_length_gets_its_own_result():
    tool = Tool(lengths_mm=(0.0, 100.0, 300.0), orientations_deg=((0.0, 0.0),))
    res = analyse(build_machine({"Z.angular.Y": 10.0}, point="TCP", tool=tool))
    assert [c.volumetric.value_um for c in res.cases] == pytest.approx([0.0, 1.0, 3.0])
    assert res.worst == 2


def test_outside_the_measured_range_is_refused_unless_extrapolating():
    comps = {"X.linear": [(0, 0.0), (800, 4.0)]}
    with pytest.raises(DataError, match=r"X.linear .* 0 to 800 mm .*analysis.extrapolate"):
        analyse(build_machine(comps))
    res = analyse(build_machine(comps, extrapolate=True))
    assert res.cases[0].axes["X"].maximum.value_um == 4.0  # end value held
    assert any("held" in w for w in res.warnings)


def test_direction_selects_runs():
    from esp.core.profile import ErrorProfile

    prof = ErrorProfile(
        "linear", [0.0, 1000.0], {"forward": [[0.0, 4.0]], "backward": [[0.0, 2.0]]}, axis="X"
    )
    point = {"X": 1000.0, "Y": 0.0, "Z": 0.0}
    for direction, value in (("forward", 4.0), ("backward", 2.0), ("mean", 3.0)):
        m = build_machine({"X.linear": prof}, direction=direction)
        assert _errors(m, point)["X"] == pytest.approx(value)


def test_error_field_agrees_with_point_evaluation_and_slices():
    from esp.core.evaluation import evaluate

    comps = {"X.linear": [(0, 1.0), (1000, 8.0)], "X.angular.X": 5.0, "squareness.XY": 3.0}
    m = build_machine(comps, offsets={"Z": 200.0}, datum="negative")
    case = evaluate(m).case()
    grids, errors = case.field()
    assert errors["X"].shape == (5, 5, 5)
    i, j, k = 3, 1, 2  # x = 750, y = 250, z = 500: the point P
    assert (grids["X"][i], grids["Y"][j], grids["Z"][k]) == (750.0, 250.0, 500.0)
    expected = _errors(m)
    assert {a: errors[a][i, j, k] for a in "XYZ"} == pytest.approx(expected)
    grids, sliced = case.field(fixed={"Z": 500.0})
    assert sliced["Y"].shape == (5, 5, 1) and sliced["Y"][i, j, 0] == pytest.approx(expected["Y"])


def test_two_axis_machine_reports_the_plane_of_motion():
    # a turning centre: X and Z move, Y has zero travel (thesis 4.02). On a 500 mm grid:
    # X.linear -2, 0, 3 at x = 0, 500, 1000; Z.straightness.X = 1 µm; X.straightness.Y 4 µm
    # planar XZ at (1000, -, any z): sqrt((3 + 1)² + 0²) = 4; volumetric adds Y: sqrt(16 + 16)
    comps = {
        "X.linear": [(0, -2.0), (500, 0.0), (1000, 3.0)],
        "Z.straightness.X": 1.0,
        "X.straightness.Y": 4.0,
    }
    travel = {"X": (0.0, 1000.0), "Y": (0.0, 0.0), "Z": (0.0, 1000.0)}
    res = analyse(build_machine(comps, "BwMTt", roles=("X", "Y", "Z"), travel=travel, step=500.0))
    (case,) = res.cases
    assert res.plane_of_motion == "XZ"
    assert set(case.planar) == {"XZ"}
    assert case.planar["XZ"].value_um == pytest.approx(4.0)
    assert case.volumetric.value_um == pytest.approx(math.sqrt(32.0))
    assert [b.label for b in case.breakdowns if b.label.startswith("planar")] == ["planar XZ"]
