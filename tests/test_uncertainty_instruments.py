"""Instrument uncertainty models of Longstaff (2002) 3.14, the table 3.2 lookup, Type A.

Every expected value is worked out by hand in the test from the thesis' formula.
"""

from __future__ import annotations

import math
import subprocess
import sys

import numpy as np
import pytest

from esp.core.errors import DataError
from esp.core.profile import ErrorProfile
from esp.core.uncertainty import (
    MODELS,
    ComponentUncertainty,
    Contribution,
    angular_from_linear,
    from_profile,
    laser_angular,
    laser_linear,
    laser_straightness,
    level_differential,
    rectangular,
    run_scatter,
    square,
    thermal_drift,
    type_a,
)

R3 = math.sqrt(3.0)
TWO_R3 = 2.0 * math.sqrt(3.0)  # 3.4641016...


# -- table 3.2 ------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("minutes", "displacement_um", "angle_um_per_m"),
    [(5, 0.0, 0.0), (15, 1.0, 3.0), (30, 2.0, 5.0), (60, 5.0, 10.0)],
)
def test_thermal_drift_at_the_rows_of_table_3_2(minutes, displacement_um, angle_um_per_m):
    for rule in ("step", "interpolate"):
        assert thermal_drift(minutes, "displacement", rule) == displacement_um
        assert thermal_drift(minutes, "angle", rule) == angle_um_per_m


def test_thermal_drift_between_rows_takes_the_next_row_up_by_the_step_rule():
    assert thermal_drift(0, rule="step") == 0.0
    assert thermal_drift(3, rule="step") == 0.0  # below 5 min: the 5 min row
    assert thermal_drift(5.5, rule="step") == 1.0  # -> 15 min row
    assert thermal_drift(16, rule="step") == 2.0  # -> 30 min row
    assert thermal_drift(16, "angle", "step") == 5.0
    assert thermal_drift(31, "angle", "step") == 10.0  # -> 60 min row


def test_thermal_drift_interpolates_by_default():
    # a 31-minute test: 2 µm + (1/30)·(5 - 2) µm = 2.1 µm, not the 60-minute row's 5 µm
    assert thermal_drift(31) == pytest.approx(2.1)
    assert thermal_drift(31, "angle") == pytest.approx(5.0 + 5.0 / 30.0)


def test_thermal_drift_interpolated_between_rows():
    # 22.5 min is half way from 15 to 30: 1 + 0.5 * (2 - 1) µm and 3 + 0.5 * (5 - 3) µm/m
    assert thermal_drift(22.5, "displacement", "interpolate") == pytest.approx(1.5)
    assert thermal_drift(22.5, "angle", "interpolate") == pytest.approx(4.0)
    # 10 min: 0 + (10 - 5) / (15 - 5) * 1
    assert thermal_drift(10, "displacement", "interpolate") == pytest.approx(0.5)


def test_thermal_drift_beyond_60_minutes_continues_at_the_last_rate():
    # 30 -> 60 min adds 3 µm and 5 µm/m; 90 min adds the same again on top of the 60 min row
    assert thermal_drift(90) == pytest.approx(5.0 + 30 * (5.0 - 2.0) / 30)
    assert thermal_drift(90, "angle") == pytest.approx(10.0 + 30 * (10.0 - 5.0) / 30)
    assert thermal_drift(90, "angle", "interpolate") == pytest.approx(15.0)
    # continuous at 60 min, and never below the 60 min row
    assert thermal_drift(60.0 + 1e-9) == pytest.approx(5.0)


def test_thermal_drift_never_decreases_with_duration():
    for quantity in ("displacement", "angle"):
        for rule in ("step", "interpolate"):
            values = [thermal_drift(t, quantity, rule) for t in np.linspace(0, 200, 401)]
            assert all(b >= a for a, b in zip(values, values[1:], strict=False))
            # the step rule is never below the interpolated one
            if rule == "interpolate":
                steps = [thermal_drift(t, quantity) for t in np.linspace(0, 200, 401)]
                assert all(s >= i for s, i in zip(steps, values, strict=True))


@pytest.mark.parametrize(
    ("args", "match"),
    [
        ((-1.0,), "duration"),
        ((float("nan"),), "duration"),
        (("long",), "duration"),
        ((10.0, "temperature"), "quantity"),
        ((10.0, "angle", "nearest"), "rule"),
    ],
)
def test_thermal_drift_rejects_bad_input(args, match):
    with pytest.raises(DataError, match=match):
        thermal_drift(*args)


# -- Type A and rectangular -----------------------------------------------------------------


def test_type_a_is_s_over_root_n():
    assert type_a(1.2, 6) == pytest.approx(1.2 / math.sqrt(6))
    assert type_a(0.0, 5) == 0.0


def test_rectangular_is_a_over_root_3():
    assert rectangular(3.0) == pytest.approx(3.0 / R3)
    # the thesis' e / (2√3) is a rectangle of full width e
    assert rectangular(6.0 / 2) == pytest.approx(6.0 / TWO_R3)


@pytest.mark.parametrize(
    ("call", "match"),
    [
        (lambda: type_a(1.0, 1), "n >= 2"),
        (lambda: type_a(1.0, 0), "n >= 2"),
        (lambda: type_a(1.0, 2.5), "whole number"),
        (lambda: type_a(-1.0, 5), "std must be >= 0"),
        (lambda: rectangular(-0.1), "half_width must be >= 0"),
        (lambda: rectangular(float("inf")), "finite"),
    ],
)
def test_type_a_and_rectangular_reject_bad_input(call, match):
    with pytest.raises(DataError, match=match):
        call()


# -- the record -----------------------------------------------------------------------------


def test_component_uncertainty_combines_in_quadrature():
    c = ComponentUncertainty.from_budget("test", "um", [("a", 3.0, "um"), ("b", 4.0, "um")], k=2)
    assert pytest.approx(2 * 5.0) == c.U  # 2 * sqrt(9 + 16)
    assert c.u == pytest.approx(5.0)
    assert c.contributions == (Contribution("a", 3.0, "um"), Contribution("b", 4.0, "um"))
    assert [r.name for r in c.ranked()] == ["b", "a"]
    d = c.as_dict()
    assert d["U"] == pytest.approx(10.0) and d["contributions"][1] == {
        "name": "b",
        "u": 4.0,
        "unit": "um",
        "dof": None,  # a Type B value taken as exact: infinite degrees of freedom
    }
    assert d["dof"] is None and c.dof == math.inf


def test_component_uncertainty_given_directly():
    c = ComponentUncertainty(8.0, 2.0, "um/m", "given")
    assert c.u == 4.0 and c.contributions == ()


@pytest.mark.parametrize(
    ("args", "match"),
    [
        ((-1.0, 2.0, "um", "given"), "U must be >= 0"),
        ((1.0, 0.0, "um", "given"), "k must be > 0"),
        ((1.0, 2.0, "mm", "given"), "unit"),
        ((1.0, 2.0, "um", "x", (("a", 3.0, "um"),)), "does not equal"),
        ((6.0, 2.0, "um", "x", (("a", 3.0, "um/m"),)), "is in 'um/m'"),
        ((6.0, 2.0, "um", "x", (("a", -3.0, "um"),)), "must be >= 0"),
        ((6.0, 2.0, "um", "x", (("a", 3.0),)), r"\(name, u, unit\[, dof\]\)"),
    ],
)
def test_component_uncertainty_rejects_inconsistent_records(args, match):
    with pytest.raises(DataError, match=match):
        ComponentUncertainty(*args)


# -- 3.14.1 linear, laser -------------------------------------------------------------------

LINEAR = dict(
    measuring_length_mm=500.0,
    duration_min=15.0,
    temperature_change_degc=0.3,
    max_difference_to_20_degc=1.5,
    u_calibration_um_per_m=0.5,
    alignment_mm=1.0,
    expansion_coefficient_um_per_m_per_degc=11.5,
)


def test_laser_linear_by_hand():
    c = laser_linear(**LINEAR)
    L_m = 0.5
    u_device = 0.5 * L_m  # 0.25 µm
    u_align = (1.0 / 500.0) / TWO_R3 * L_m  # ratio read as µm/m, over 0.5 m
    u_drift = 1.0  # 15 min row of table 3.2
    u_temp = L_m * 11.5 * 0.3 / TWO_R3  # 0.49797 µm
    u_coef = L_m * 0.7 * 1.5 / TWO_R3  # 0.15155 µm (u(alpha) = 0.7 by default)
    expected = 2 * math.sqrt(u_device**2 + u_align**2 + u_drift**2 + u_temp**2 + u_coef**2)
    assert pytest.approx(expected, rel=1e-12) == c.U
    assert pytest.approx(2.30949, abs=1e-5) == c.U
    assert c.unit == "um" and c.k == 2.0 and c.model == "laser_linear"
    assert [x.u for x in c.contributions] == pytest.approx(
        [u_device, u_align, u_drift, u_temp, u_coef], rel=1e-12
    )


def test_laser_linear_cosine_alignment_by_hand():
    c = laser_linear(**LINEAR, alignment_model="cosine")
    # error L (1 - cos θ), tan θ = 1/500: cos(atan x) = 1 / sqrt(1 + x²); L = 500e3 µm
    e_um = 500e3 * (1 - 1 / math.sqrt(1 + (1 / 500) ** 2))  # ≈ δ²/(2L) = 1 µm
    assert e_um == pytest.approx(1.0, rel=1e-5)
    assert c.contributions[1].u == pytest.approx(e_um / TWO_R3, rel=1e-9)


def test_laser_linear_per_metre_terms_scale_with_length_and_drift_does_not():
    short = laser_linear(**{**LINEAR, "measuring_length_mm": 250.0})
    long = laser_linear(**{**LINEAR, "measuring_length_mm": 1000.0})
    for i in (0, 3, 4):  # device and the two expansion terms
        assert long.contributions[i].u == pytest.approx(4 * short.contributions[i].u)
    assert long.contributions[2].u == short.contributions[2].u == 1.0  # drift
    # the printed alignment (δ/L)/(2√3) per metre, over L_m metres, is δ/1000/(2√3) µm
    assert long.contributions[1].u == pytest.approx(short.contributions[1].u)
    assert long.contributions[1].u == pytest.approx(1.0 / 1000 / TWO_R3)


def test_laser_linear_sign_of_temperatures_is_ignored():
    a = laser_linear(**LINEAR)
    b = laser_linear(
        **{**LINEAR, "temperature_change_degc": -0.3, "max_difference_to_20_degc": -1.5}
    )
    assert a.U == b.U


@pytest.mark.parametrize(
    ("change", "match"),
    [
        ({"measuring_length_mm": 0.0}, "measuring_length_mm must be > 0"),
        ({"measuring_length_mm": -10.0}, "measuring_length_mm must be > 0"),
        ({"u_calibration_um_per_m": -0.5}, "u_calibration_um_per_m must be >= 0"),
        ({"u_calibration_um_per_m": None}, "u_calibration_um_per_m is required"),
        ({"alignment_mm": None}, "alignment_mm is required"),
        ({"duration_min": None}, "duration_min is required"),
        ({"expansion_coefficient_um_per_m_per_degc": None}, "expansion_coefficient"),
        ({"alignment_model": "sine"}, "alignment_model"),
        ({"thermal_rule": "round"}, "thermal_rule"),
        ({"k": 0}, "k must be > 0"),
        ({"alignment_mm": True}, "must be a number"),
    ],
)
def test_laser_linear_rejects_bad_input(change, match):
    with pytest.raises(DataError, match=match):
        laser_linear(**{**LINEAR, **change})


# -- 3.14.2 angular, levels -----------------------------------------------------------------

LEVEL = dict(
    measuring_length_mm=800.0,
    max_angle_um_per_m=-12.0,
    unit_uncertainty_um_per_m=1.0,
    footprint_length_mm=200.0,
    duration_min=20.0,
)


def test_level_differential_by_hand_with_thermal_lookup():
    c = level_differential(**LEVEL, runs=3)
    u_device = math.sqrt(2) * 1.0
    u_cross = 12.0 * 800.0 / 200.0 / TWO_R3  # 48 / (2√3), u² = 2304 / 12 = 192
    u_drift = 3.0 + (20.0 - 15.0) / 15.0 * 2.0  # between the 15 and 30 min rows: 11/3
    assert pytest.approx(2 * math.sqrt(u_device**2 + u_cross**2 + u_drift**2)) == c.U
    assert pytest.approx(2 * math.sqrt(2 + 192 + 121 / 9)) == c.U
    assert c.unit == "um/m"
    assert "table 3.2" in c.contributions[-1].name


def test_level_differential_switches_to_type_a_at_five_runs():
    four = level_differential(**LEVEL, runs=4, run_std_um_per_m=0.8)
    five = level_differential(**LEVEL, runs=5, run_std_um_per_m=0.8)
    assert four.contributions[-1].u == pytest.approx(11.0 / 3.0)  # lookup, interpolated
    assert five.contributions[-1].u == pytest.approx(0.8 / math.sqrt(5))  # eq. 3.17
    assert "Type A" in five.contributions[-1].name
    # Type A needs no duration
    c = level_differential(**{**LEVEL, "duration_min": None}, runs=6, run_std_um_per_m=0.8)
    assert c.contributions[-1].u == pytest.approx(0.8 / math.sqrt(6))
    # the threshold is a parameter
    c = level_differential(**LEVEL, runs=4, run_std_um_per_m=0.8, type_a_min_runs=3)
    assert c.contributions[-1].u == pytest.approx(0.4)


@pytest.mark.parametrize(
    ("change", "match"),
    [
        ({"runs": 5}, "run_std_um_per_m is required"),
        ({"duration_min": None}, "duration_min is required"),
        ({"footprint_length_mm": 0.0}, "footprint_length_mm must be > 0"),
        ({"unit_uncertainty_um_per_m": None}, "unit_uncertainty_um_per_m is required"),
        ({"runs": -1}, "runs must be a whole number"),
        ({"runs": 3, "type_a_min_runs": 1}, "type_a_min_runs"),
        ({"measuring_length_mm": 0.0}, "measuring_length_mm must be > 0"),
    ],
)
def test_level_differential_rejects_bad_input(change, match):
    with pytest.raises(DataError, match=match):
        level_differential(**{**LEVEL, **change})


# -- 3.14.3 angular, laser ------------------------------------------------------------------


def test_laser_angular_by_hand():
    c = laser_angular(
        measuring_length_mm=1000.0,
        measurement_range_um_per_m=20.0,
        max_angle_um_per_m=15.0,
        beam_offset_mm=50.0,
        duration_min=10.0,
    )
    u_device = (20.0 * 0.004 + 1.0 * 0.5) / TWO_R3  # 0.58 / (2√3) = 0.16743
    u_cross = 15.0 * 1000.0 / 50.0 / TWO_R3  # 300 / (2√3), u² = 7500
    u_drift = 1.5  # 10 min, halfway from the 5 min row (0) to the 15 min row (3 µm/m)
    expected = 2 * math.sqrt(2 * u_device**2 + u_cross**2 + u_drift**2)  # U of 3.14.3
    assert pytest.approx(expected, rel=1e-12) == c.U
    assert pytest.approx(2 * math.sqrt(2 * 0.58**2 / 12 + 7500 + 2.25)) == c.U
    assert c.contributions[0].u == pytest.approx(math.sqrt(2) * u_device)


def test_laser_angular_type_a_and_errors():
    base = dict(
        measuring_length_mm=500.0,
        measurement_range_um_per_m=4.0,
        max_angle_um_per_m=2.0,
        beam_offset_mm=30.0,
    )
    c = laser_angular(**base, runs=5, run_std_um_per_m=1.0)
    assert c.contributions[-1].u == pytest.approx(1 / math.sqrt(5))
    with pytest.raises(DataError, match="duration_min is required"):
        laser_angular(**base)
    with pytest.raises(DataError, match="beam_offset_mm is required"):
        laser_angular(**{**base, "beam_offset_mm": None}, duration_min=5)
    with pytest.raises(DataError, match="measurement_range_um_per_m must be >= 0"):
        laser_angular(**{**base, "measurement_range_um_per_m": -1.0}, duration_min=5)


# -- 3.14.4 angular from two linear runs ----------------------------------------------------


def test_angular_from_linear_by_hand_in_the_printed_relative_form():
    c = angular_from_linear(
        U_linear_um=3.0, displacement_mm=200.0, u_displacement_mm=0.05, max_angle_um_per_m=10.0
    )
    u_lin = 3.0 * math.sqrt(2) / 2  # 2.12132 µm
    delta_e = 10.0 * 200.0 / 1000.0  # the linear measurements differ by θ · d = 2 µm
    relative = math.sqrt((u_lin / delta_e) ** 2 + (0.05 / 200.0) ** 2)
    expected = 2 * relative * 10.0  # U = k · (u(angle)/angle) · angle
    assert pytest.approx(expected, rel=1e-12) == c.U
    assert pytest.approx(21.2132, abs=1e-4) == c.U
    assert c.unit == "um/m"


def test_angular_from_linear_with_zero_angle_keeps_the_linear_term():
    c = angular_from_linear(U_linear_um=3.0, displacement_mm=200.0, u_displacement_mm=0.05)
    assert pytest.approx(2 * 1000 * 3.0 * math.sqrt(2) / 2 / 200.0) == c.U
    with pytest.raises(DataError, match="displacement_mm must be > 0"):
        angular_from_linear(U_linear_um=3.0, displacement_mm=0.0, u_displacement_mm=0.05)
    with pytest.raises(DataError, match="U_linear_um is required"):
        angular_from_linear(displacement_mm=100.0, u_displacement_mm=0.05)


# -- 3.14.5 straightness --------------------------------------------------------------------


def test_laser_straightness_by_hand():
    c = laser_straightness(measurement_range_um=300.0, duration_min=15.0, runs=2)
    u_device = (3.0 + 0.01 * 300.0) / TWO_R3  # 6 / (2√3) = 1.7321
    u_align = (300.0 - math.cos(math.radians(1.0)) * 300.0) / TWO_R3  # 0.013190
    u_air = (1.0 + 1.0 * 0.1 * 36.0 * 4) / TWO_R3  # (drift 1 µm + 14.4) / (2√3)
    expected = 2 * math.sqrt(u_device**2 + u_align**2 + u_air**2)
    assert pytest.approx(expected, rel=1e-12) == c.U
    assert pytest.approx(9.5422, abs=1e-4) == c.U
    assert c.unit == "um"


def test_laser_straightness_reproduces_table_3_1_air_and_alignment():
    # table 3.1 (300 µm range): alignment 0.0 µm, air disturbance 4.2 µm
    c = laser_straightness(measurement_range_um=300.0, duration_min=5.0)
    assert round(c.contributions[1].u, 1) == 0.0
    assert round(c.contributions[2].u, 1) == 4.2  # 14.4 / (2√3) = 4.157


def test_laser_straightness_type_a():
    c = laser_straightness(measurement_range_um=50.0, runs=6, run_std_um=1.2)
    assert c.contributions[2].u == pytest.approx(1.2 / math.sqrt(6))
    with pytest.raises(DataError, match="run_std_um is required"):
        laser_straightness(measurement_range_um=50.0, runs=6)
    with pytest.raises(DataError, match="number_of_beams"):
        laser_straightness(measurement_range_um=50.0, duration_min=5, number_of_beams=2.5)


# -- 3.14.6 square --------------------------------------------------------------------------


def test_square_by_hand():
    c = square(measuring_length_mm=500.0, edge_a_um=0.5, edge_b_um=0.6, squareness_um_per_m=2.0)
    L_m = 0.5
    device_um = math.sqrt(0.5**2 + 0.6**2 + (2.0 * L_m / TWO_R3) ** 2)  # sqrt(0.693333)
    u_device = device_um / L_m  # µm over 0.5 m -> µm/m
    u_align = (1.0 / 500.0) / TWO_R3  # Knapp's 1 mm; the ratio read as µm/m
    assert pytest.approx(2 * math.sqrt(u_device**2 + u_align**2), rel=1e-12) == c.U
    assert pytest.approx(2 * math.sqrt(0.693333333 / 0.25 + (0.002 / TWO_R3) ** 2)) == c.U
    assert c.unit == "um/m"


def test_square_cosine_alignment_by_hand():
    c = square(
        measuring_length_mm=500.0,
        edge_a_um=0.5,
        edge_b_um=0.6,
        squareness_um_per_m=2.0,
        alignment_model="cosine",
    )
    # 1 − cos(atan(1/500)) ≈ (1/500)² / 2 = 2e-6 = 2 µm/m
    assert c.contributions[1].u == pytest.approx(1e6 * (1 - 1 / math.sqrt(1 + 0.002**2)) / TWO_R3)
    assert c.contributions[1].u == pytest.approx(2.0 / TWO_R3, rel=1e-5)


def test_square_rejects_bad_input():
    with pytest.raises(DataError, match="edge_a_um is required"):
        square(measuring_length_mm=500.0, edge_b_um=0.6, squareness_um_per_m=2.0)
    with pytest.raises(DataError, match="edge_b_um must be >= 0"):
        square(measuring_length_mm=500.0, edge_a_um=0.5, edge_b_um=-0.6, squareness_um_per_m=2)
    with pytest.raises(DataError, match="measuring_length_mm must be > 0"):
        square(measuring_length_mm=0.0, edge_a_um=0.5, edge_b_um=0.6, squareness_um_per_m=2)


def test_coverage_factor_scales_u_linearly():
    a = laser_straightness(measurement_range_um=100.0, duration_min=30.0, k=1.0)
    b = laser_straightness(measurement_range_um=100.0, duration_min=30.0, k=3.0)
    assert pytest.approx(3 * a.U) == b.U and b.u == pytest.approx(a.u)


# -- from a profile -------------------------------------------------------------------------

ENVIRONMENT = {
    "Air temp": ("20.337280", "20.384956", "0"),
    "Mat temp 1": ("20.1", "20.4", "1"),
    "Exp coeff": ("11.5", "11.5", "0"),
    "Date Time": ("10:46 Dec 12 2016", "11:01 Dec 12 2016"),
}


def _angular_profile(backward_runs: int = 5, environment=None) -> ErrorProfile:
    forward = np.array([[0.0, v, 2.0] for v in (1.0, 2.0, 3.0, 4.0, 5.0)])  # 5 runs
    backward = np.array([[-1.0, 3.0, 1.0]] * backward_runs)
    return ErrorProfile(
        "angular",
        [0.0, 300.0, 600.0],
        {"forward": forward, "backward": backward},
        axis="X",
        error_direction="Z",
        environment=environment or {},
        source="x-pitch.rta",
    )


def test_run_scatter_max_and_pooled():
    p = _angular_profile()
    s, n = run_scatter(p)
    # forward, middle target: 1..5 -> sample variance (4 + 1 + 0 + 1 + 4) / 4 = 2.5
    assert (s, n) == (pytest.approx(math.sqrt(2.5)), 5)
    s, n = run_scatter(p, "pooled")
    # 10 squared deviations over (3 targets x 4) + (3 targets x 4) = 24 degrees of freedom
    assert s == pytest.approx(math.sqrt(10 / 24)) and n == 5
    assert run_scatter(_angular_profile(backward_runs=1)) == (None, 1)
    with pytest.raises(DataError, match="statistic"):
        run_scatter(p, "median")


def test_from_profile_laser_angular_uses_type_a_with_five_runs_each_way():
    p = _angular_profile()
    c = from_profile("laser_angular", p, beam_offset_mm=50.0)
    # bidirectional mean: forward [0, 3, 2], backward [-1, 3, 1] -> [-0.5, 3, 1.5]
    range_, max_angle = 3.0 - (-0.5), 3.0
    u_device = (range_ * 0.004 + 0.6 * 0.5) / TWO_R3  # span 600 mm = 0.6 m
    u_cross = max_angle * 600.0 / 50.0 / TWO_R3
    u_run = math.sqrt(2.5) / math.sqrt(5)  # s/√n, eq. 3.17
    assert pytest.approx(2 * math.sqrt(2 * u_device**2 + u_cross**2 + u_run**2)) == c.U
    direct = laser_angular(
        measuring_length_mm=600.0,
        measurement_range_um_per_m=3.5,
        max_angle_um_per_m=3.0,
        beam_offset_mm=50.0,
        runs=5,
        run_std_um_per_m=math.sqrt(2.5),
    )
    assert c == direct


def test_from_profile_falls_back_to_the_lookup_below_five_runs():
    p = _angular_profile(backward_runs=4, environment=ENVIRONMENT)
    c = from_profile("laser_angular", p, beam_offset_mm=50.0)
    assert c.contributions[-1].u == 3.0  # 10:46 -> 11:01 is 15 min: angle column, 3 µm/m
    assert "table 3.2" in c.contributions[-1].name
    # without a Date Time line the duration must be given, and the message says why
    p = _angular_profile(backward_runs=4)
    with pytest.raises(DataError, match=r"duration_min is required.*no 'Date Time' line"):
        from_profile("laser_angular", p, beam_offset_mm=50.0)
    c = from_profile("laser_angular", p, beam_offset_mm=50.0, duration_min=40)
    assert c.contributions[-1].u == pytest.approx(5.0 + 10.0 / 30.0 * 5.0)  # 30 -> 60 min rows


def test_from_profile_laser_linear_reads_the_environment():
    runs = np.array([[0.0, 1.0, 2.0], [0.2, 1.2, 2.2]])
    p = ErrorProfile(
        "linear", [0.0, 250.0, 500.0], {"forward": runs}, axis="X", environment=ENVIRONMENT
    )
    c = from_profile("laser_linear", p, u_calibration_um_per_m=0.5, alignment_mm=1.0)
    # span 500 mm; 10:46 -> 11:01 = 15 min; Mat temp 20.1 -> 20.4: ΔT = 0.3, max |T - 20| = 0.4
    expected = laser_linear(
        measuring_length_mm=500.0,
        duration_min=15.0,
        temperature_change_degc=0.3,
        max_difference_to_20_degc=0.4,
        u_calibration_um_per_m=0.5,
        alignment_mm=1.0,
        expansion_coefficient_um_per_m_per_degc=11.5,
    )
    assert pytest.approx(expected.U, rel=1e-12) == c.U
    u_temp = 0.5 * 11.5 * 0.3 / TWO_R3
    u_coef = 0.5 * 0.7 * 0.4 / TWO_R3
    assert [x.u for x in c.contributions[3:]] == pytest.approx([u_temp, u_coef])


def test_from_profile_environment_spellings_and_overrides():
    env = {
        "DATE_TIME": ('"10:46 Dec 12 2016" "12:16 Dec 12 2016"',),  # one raw field, quoted
        "mat-temp-1": "19.0 19.5 1",
        "Mat temp 2": ("0", "0", "0"),  # not fitted: skipped
        "Exp coeff": ("8.0", "8.0", "0"),
    }
    p = ErrorProfile("linear", [0.0, 1000.0], {"forward": [[0.0, 1.0]]}, environment=env)
    c = from_profile("laser_linear", p, u_calibration_um_per_m=0.4, alignment_mm=0.5)
    u_drift = 5.0 + 30 * 3.0 / 30  # 90 min: beyond the table, 8 µm
    u_temp = 1.0 * 8.0 * 0.5 / TWO_R3
    u_coef = 1.0 * 0.7 * 1.0 / TWO_R3  # max |T - 20| = |19.0 - 20| = 1.0
    assert [x.u for x in c.contributions[2:]] == pytest.approx([u_drift, u_temp, u_coef])
    # a value given wins over the file
    c = from_profile(
        "laser_linear", p, u_calibration_um_per_m=0.4, alignment_mm=0.5, duration_min=5
    )
    assert c.contributions[2].u == 0.0


def test_from_profile_reports_what_the_environment_lacks():
    env = {"Date Time": ("10:46 Dec 12 2016",), "Exp coeff": ("n/a",)}
    p = ErrorProfile("linear", [0.0, 500.0], {"forward": [[0.0, 1.0]]}, environment=env)
    with pytest.raises(DataError, match="does not hold a start and an end"):
        from_profile("laser_linear", p, u_calibration_um_per_m=0.5, alignment_mm=1.0)
    with pytest.raises(DataError, match=r"temperature_change_degc.*no 'Mat temp' line"):
        from_profile(
            "laser_linear", p, u_calibration_um_per_m=0.5, alignment_mm=1.0, duration_min=15
        )
    with pytest.raises(DataError, match=r"expansion_coefficient.*holds no number"):
        from_profile(
            "laser_linear",
            p,
            u_calibration_um_per_m=0.5,
            alignment_mm=1.0,
            duration_min=15,
            temperature_change_degc=0.1,
            max_difference_to_20_degc=0.5,
        )
    env = {"Date Time": ("11:01 Dec 12 2016", "10:46 Dec 12 2016")}
    p = ErrorProfile("linear", [0.0, 500.0], {"forward": [[0.0, 1.0]]}, environment=env)
    with pytest.raises(DataError, match="ends before it starts"):
        from_profile("laser_linear", p, u_calibration_um_per_m=0.5, alignment_mm=1.0)


def test_from_profile_straightness_and_square_use_the_profile():
    runs = np.array([[0.0, 4.0, -2.0, 1.0]] * 2)
    p = ErrorProfile(
        "straightness", [0.0, 100.0, 200.0, 300.0], {"forward": runs}, environment=ENVIRONMENT
    )
    c = from_profile("laser_straightness", p)
    u_device = (3.0 + 0.01 * 6.0) / TWO_R3  # range 4 - (-2) = 6 µm
    u_align = 6.0 * (1 - math.cos(math.radians(1.0))) / TWO_R3
    u_air = (1.0 + 14.4) / TWO_R3  # 2 runs: lookup, 15 min -> 1 µm
    assert pytest.approx(2 * math.sqrt(u_device**2 + u_align**2 + u_air**2)) == c.U
    c = from_profile("square", p, edge_a_um=0.5, edge_b_um=0.5, squareness_um_per_m=1.0)
    assert c == square(
        measuring_length_mm=300.0, edge_a_um=0.5, edge_b_um=0.5, squareness_um_per_m=1.0
    )


def test_from_profile_angular_from_linear_takes_the_largest_angle():
    p = _angular_profile()
    c = from_profile(
        "angular_from_linear", p, U_linear_um=3.0, displacement_mm=200.0, u_displacement_mm=0.1
    )
    expected = angular_from_linear(
        U_linear_um=3.0, displacement_mm=200.0, u_displacement_mm=0.1, max_angle_um_per_m=3.0
    )
    assert c == expected


def test_from_profile_rejects_bad_requests():
    p = _angular_profile()
    with pytest.raises(DataError, match="unknown uncertainty model"):
        from_profile("theodolite", p)
    with pytest.raises(DataError, match=r"needs a linear profile.*x-pitch\.rta"):
        from_profile("laser_linear", p)
    with pytest.raises(DataError, match="unknown parameter.*beam_ofset_mm"):
        from_profile("laser_angular", p, beam_ofset_mm=50.0)
    single = ErrorProfile("straightness", [100.0], {"forward": [[1.0]]})
    with pytest.raises(DataError, match="zero measuring length"):
        from_profile("square", single, edge_a_um=0.5, edge_b_um=0.5, squareness_um_per_m=1.0)
    assert set(MODELS) == {
        "laser_linear",
        "level_differential",
        "laser_angular",
        "angular_from_linear",
        "laser_straightness",
        "square",
    }


@pytest.mark.slow
def test_uncertainty_imports_only_numpy_and_the_standard_library():
    code = (
        "import sys, esp.core.uncertainty; "
        "bad = [m for m in ('matplotlib', 'pandas', 'click') if m in sys.modules]; "
        "print(','.join(bad))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == ""
