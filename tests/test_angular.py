"""The indirect angular error of esp.core.angular (Longstaff 2002, 3.08.1) against hand values,
its error traps, and the round trip of its result through a Laser10 .rta file."""

from __future__ import annotations

import math

import numpy as np
import pytest

from esp.core.angular import UM_PER_M_PER_UM_PER_MM, angular_from_linear, datum_index
from esp.core.errors import DataError
from esp.core.profile import ErrorProfile
from esp.io.laser10 import read_laser10, write_laser10

TARGETS = np.array([0.0, 100.0, 200.0, 300.0, 400.0])


def linear(forward, backward=None, targets=TARGETS, axis="X", source=None) -> ErrorProfile:
    runs = {"forward": np.atleast_2d(np.asarray(forward, dtype=float))}
    if backward is not None:
        runs["backward"] = np.atleast_2d(np.asarray(backward, dtype=float))
    return ErrorProfile("linear", targets, runs, axis=axis, source=source)


def test_unit_factor_by_hand():
    # 1 µm per mm of displacement is 1e-6 m / 1e-3 m = 1e-3 rad = 1000 µrad = 1000 µm/m
    assert UM_PER_M_PER_UM_PER_MM == 1e-6 / 1e-3 * 1e6
    # a difference of 8 µm over D = 800 mm is 8 / 800 x 1000 = 10 µm/m
    a = linear([0.0, 1.0, 2.0, 3.0, 4.0])
    b = linear([0.0, 9.0, 2.0, 3.0, 4.0])
    result = angular_from_linear(a, b, 800.0, 0.0)
    np.testing.assert_allclose(result.curve("forward"), [0.0, 10.0, 0.0, 0.0, 0.0], atol=1e-12)
    # and back: 10 µm/m acting over 800 mm is 10 x 800 / 1000 = 8 µm
    assert result.curve("forward")[1] * 800.0 / 1000.0 == pytest.approx(8.0)


def test_constructed_pair_recovers_the_angle_exactly():
    """Linear error L(x) (no angle effect) on the reference line; the shifted line, D = -800 mm
    away, sees L(x) + angle(x) x D / 1000 for an angle that is zero at the datum x = 200."""
    rng = np.random.default_rng(7)
    angle_um_per_m = np.array([-9.0, 15.0, 0.0, 40.0, 71.0])  # zero at the datum 200 mm
    d_mm = -800.0
    # three runs each way, each with its own (noise-free) linear error and reversal
    lin_fwd = rng.normal(0.0, 3.0, (3, 5)) + np.linspace(0.0, 6.0, 5)
    lin_bwd = lin_fwd - 2.0
    a = linear(lin_fwd, lin_bwd)
    b = linear(lin_fwd + angle_um_per_m * d_mm / 1000, lin_bwd + angle_um_per_m * d_mm / 1000)
    result = angular_from_linear(a, b, d_mm, 200.0)
    for direction in ("forward", "backward", "mean"):
        np.testing.assert_allclose(result.curve(direction), angle_um_per_m, atol=1e-9)
    # every run holds the whole angle
    for runs in result.profile.runs.values():
        np.testing.assert_allclose(runs, np.tile(angle_um_per_m, (3, 1)), atol=1e-9)
    # hand value at 400 mm: 71 µm/m over -800 mm is -56.8 µm of extra linear error
    assert b.runs["forward"][0, 4] - a.runs["forward"][0, 4] == pytest.approx(71 * -0.8)
    assert result.profile.kind == "angular" and result.profile.unit == "um/m"
    assert result.datum_mm == 200.0 and result.displacement_mm == -800.0


def test_a_constant_angle_is_removed_by_the_datum():
    # an extra 5 µm/m everywhere (which the datum defines away) changes nothing
    a = linear([[0.0, 1.0, 2.0, 1.0, 0.0]])
    angle = np.array([1.0, 2.0, 3.0, 0.0, -1.0])
    b = linear(a.runs["forward"] + angle * 500 / 1000)
    b5 = linear(a.runs["forward"] + (angle + 5.0) * 500 / 1000)
    r = angular_from_linear(a, b, 500.0, 300.0)
    r5 = angular_from_linear(a, b5, 500.0, 300.0)
    np.testing.assert_allclose(r.curve("mean"), angle, atol=1e-12)
    np.testing.assert_allclose(r5.curve("mean"), angle, atol=1e-12)


def test_sign_follows_file_order_and_displacement():
    a = linear([0.0, 0.0, 0.0, 0.0, 0.0])
    b = linear([0.0, 2.0, 4.0, 6.0, 8.0])  # 2 µm per 100 mm on a line 400 mm away
    forward = angular_from_linear(a, b, 400.0, 0.0).curve("mean")
    np.testing.assert_allclose(forward, [0.0, 5.0, 10.0, 15.0, 20.0])  # 2/400*1000 = 5
    swapped = angular_from_linear(b, a, 400.0, 0.0).curve("mean")
    np.testing.assert_allclose(swapped, -forward)
    both = angular_from_linear(b, a, -400.0, 0.0).curve("mean")
    np.testing.assert_allclose(both, forward)


def test_the_same_file_twice_gives_zero():
    a = linear([[0.0, 3.0, -1.0, 2.0, 5.0], [1.0, 2.0, 0.0, 2.0, 4.0]], [[0.0, 1, 2, 3, 4]])
    r = angular_from_linear(a, a, 250.0, 100.0)
    for runs in r.profile.runs.values():
        assert np.all(runs == 0.0)


def test_runs_are_paired_and_one_datum_correction_is_removed():
    # two forward runs and one backward run; differences (µm) per run, D = 200 mm:
    #   forward 1: 0, 2, 4, 6, 8  -> 0, 10, 20, 30, 40 µm/m
    #   forward 2: 0, 4, 4, 4, 4  -> 0, 20, 20, 20, 20
    #   backward : 2, 2, 2, 2, 2  -> 10, 10, 10, 10, 10
    zero = np.zeros(5)
    a = linear([zero, zero], [zero])
    b = linear([[0, 2, 4, 6, 8], [0, 4, 4, 4, 4]], [[2, 2, 2, 2, 2]])
    # datum 100 mm, bidirectional mean there: forward mean (10+20)/2 = 15, backward 10,
    # mean (15 + 10) / 2 = 12.5, removed from every run
    r = angular_from_linear(a, b, 200.0, 100.0)
    np.testing.assert_allclose(
        r.profile.runs["forward"],
        [[-12.5, -2.5, 7.5, 17.5, 27.5], [-12.5, 7.5, 7.5, 7.5, 7.5]],
    )
    np.testing.assert_allclose(r.profile.runs["backward"], [[-2.5] * 5])
    np.testing.assert_allclose(r.curve("forward"), [-12.5, 2.5, 7.5, 12.5, 17.5])
    np.testing.assert_allclose(r.curve("mean"), [-7.5, 0.0, 2.5, 5.0, 7.5], atol=1e-12)
    # the forward curve zero at the datum instead: 15 removed
    rf = angular_from_linear(a, b, 200.0, 100.0, "forward")
    np.testing.assert_allclose(rf.curve("forward"), [-15.0, 0.0, 5.0, 10.0, 15.0], atol=1e-12)
    np.testing.assert_allclose(rf.curve("backward"), [-5.0] * 5)
    rb = angular_from_linear(a, b, 200.0, 100.0, "reverse")
    assert rb.direction == "backward"
    np.testing.assert_allclose(rb.curve("backward"), [0.0] * 5, atol=1e-12)


def test_to_dict():
    a = linear([0.0, 0.0, 0.0, 0.0, 0.0], source="ref.rtl")
    b = linear([0.0, 1.0, 2.0, 3.0, 4.0], source="shift.rtl")
    d = angular_from_linear(a, b, 100.0, 0.0).to_dict()
    assert list(d)[:6] == ["schema", "unit", "displacement_mm", "datum_mm", "targets_mm", "angle"]
    assert d["schema"] == "esp.angular/1"
    assert d["unit"] == "um/m" and d["displacement_mm"] == 100.0 and d["datum_mm"] == 0.0
    np.testing.assert_array_equal(d["targets_mm"], TARGETS)
    # 1 µm per 100 mm step over D = 100 mm: 10 µm/m per step
    np.testing.assert_allclose(d["angle"]["forward"], [0.0, 10.0, 20.0, 30.0, 40.0])
    assert d["angle"]["backward"] is None  # the files have no backward runs
    np.testing.assert_allclose(d["angle"]["mean"], d["angle"]["forward"])
    assert d["runs"] == {"forward": 1, "backward": 0}
    assert (d["reference"], d["shifted"]) == ("ref.rtl", "shift.rtl")


def test_rta_round_trip(tmp_path):
    rng = np.random.default_rng(3)
    a = linear(rng.normal(0, 2, (2, 5)), rng.normal(0, 2, (2, 5)), source="ref.rtl")
    b = linear(rng.normal(0, 2, (2, 5)), rng.normal(0, 2, (2, 5)), source="shift.rtl")
    r = angular_from_linear(a, b, -750.0, 300.0)
    path = tmp_path / "Xpitch.rta"
    write_laser10(path, r.profile)
    back = read_laser10(path)
    assert back.kind == "angular" and back.axis == "X"
    np.testing.assert_array_equal(back.targets_mm, TARGETS)
    for direction in ("forward", "backward"):
        assert back.run_count(direction) == 2
        np.testing.assert_allclose(back.runs[direction], r.profile.runs[direction], atol=1e-6)
    for direction in ("forward", "backward", "mean"):
        np.testing.assert_allclose(back.mean(direction), r.curve(direction), atol=1e-6)
    assert back.metadata["Displacement"] == "-750 mm"
    assert back.metadata["Datum"] == "300 mm (mean angle zero)"
    assert (back.metadata["Reference"], back.metadata["Shifted"]) == ("ref.rtl", "shift.rtl")


# -- the error traps of 3.08.1 ------------------------------------------------------------


def _trap(a, b, d=100.0, datum=0.0, direction="mean") -> str:
    with pytest.raises(DataError) as info:
        angular_from_linear(a, b, d, datum, direction)
    return str(info.value)


def test_trap_different_targets():
    a = linear([0.0] * 5, source="ref.rtl")
    b4 = linear([0.0] * 4, targets=TARGETS[:4], source="shift.rtl")
    msg = _trap(a, b4)
    assert "same targets" in msg and "5 targets in ref.rtl" in msg and "4 in shift.rtl" in msg
    moved = linear([0.0] * 5, targets=TARGETS + [0, 0, 5, 0, 0], source="shift.rtl")
    msg = _trap(a, moved)
    assert "target 3 at 200 mm in ref.rtl but at 205 mm in shift.rtl" in msg


def test_trap_different_runs_or_directions():
    one = linear([[0.0] * 5], [[0.0] * 5], source="ref.rtl")
    two = linear([[0.0] * 5] * 2, [[0.0] * 5], source="shift.rtl")
    assert "1 forward run in ref.rtl and 2 in shift.rtl" in _trap(one, two)
    unidirectional = linear([[0.0] * 5], source="shift.rtl")
    assert "1 backward run in ref.rtl and 0 in shift.rtl" in _trap(one, unidirectional)


def test_trap_datum_not_a_target():
    a = linear([0.0] * 5)
    msg = _trap(a, a, datum=150.0)
    assert "datum 150 mm is not a target" in msg and "0, 100, 200, 300, 400" in msg
    assert datum_index(TARGETS, 300.0) == 3
    assert datum_index(TARGETS, 300.0 + 1e-9) == 3  # within 1e-6 mm is the same target


@pytest.mark.parametrize("d", [0.0, -0.0, math.nan, math.inf])
def test_trap_displacement_zero_or_not_finite(d):
    a = linear([0.0] * 5)
    assert "non-zero displacement" in _trap(a, a, d=d)


def test_trap_other_arguments():
    a = linear([0.0] * 5)
    assert "finite datum" in _trap(a, a, datum=math.nan)
    assert "unknown direction" in _trap(a, a, direction="both")
    assert "no backward runs" in _trap(a, a, direction="reverse")


def test_trap_not_linear_data_or_other_axis():
    a = linear([0.0] * 5, source="ref.rtl")
    ang = ErrorProfile("angular", TARGETS, {"forward": [0.0] * 5}, source="pitch.rta")
    assert "pitch.rta: expected linear positioning data" in _trap(a, ang)
    y = linear([0.0] * 5, axis="Y", source="y.rtl")
    assert "the X axis but y.rtl of the Y axis" in _trap(a, y)
    unknown = linear([0.0] * 5, axis=None)
    assert angular_from_linear(a, unknown, 1.0, 0.0).profile.axis == "X"
