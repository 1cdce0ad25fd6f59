"""esp ballbar: the ISO 230-4 figures and the diagnosis, against circles made from the
exact geometry of a machine with stated errors (esp.ballbar.synthetic): each effect alone,
all together, none, on a partial arc and in one direction."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from esp.ballbar import circle_tests
from esp.ballbar.diagnosis import SPIKE_WINDOW_DEG, Diagnosis
from esp.ballbar.synthetic import Effects, synthetic_readings, write_angles, write_lengths
from esp.core.errors import ParseError

R = 150.0
STEP = 1.0
FEED = 1000.0  # mm/min
NOISE = 0.05  # µm
#: the header of a calibrated ballbar with its specification
CALIBRATED = [f"feed: {FEED:g} mm/min", "calibration_U: 0.2 um", "accuracy: 0.5 um"]

#: each effect alone: (effects, {term: true value}); the units are the terms' (µm/m, ms,
#: ppm, µm). The spike is the radial deviation at the first reading after the reversal.
_SPIKE_H, _SPIKE_W = 4.0, 0.8
ALONE = {
    # ε = 12 and -3 µm/m: mismatch 15 µm/m, mean (scaling, the bar calibrated) 4.5 ppm
    "scale mismatch": (
        Effects(scale_um_per_m=(12.0, -3.0)),
        {"scale_mismatch": 15.0, "scaling": 4.5},
    ),
    "scaling (calibrated bar)": (Effects(scale_um_per_m=(6.0, 6.0)), {"scaling": 6.0}),
    "squareness": (Effects(squareness_um_per_m=10.0), {"squareness": 10.0}),
    "servo mismatch": (Effects(servo_mismatch_ms=0.5), {"servo_mismatch": 0.5}),
    "backlash per axis and end": (
        Effects(backlash_um=((3.0, 2.0), (1.0, 4.0))),
        {"backlash_X+": 3.0, "backlash_X-": 2.0, "backlash_Y+": 1.0, "backlash_Y-": 4.0},
    ),
    "lateral play": (Effects(lateral_um=(2.0, -1.5)), {"lateral_X": 2.0, "lateral_Y": -1.5}),
    "straightness bow": (
        Effects(bow_um=(3.0, -2.0)),
        {"straightness_X": 3.0, "straightness_Y": -2.0},
    ),
    "cyclic error": (Effects(cyclic=((1.0, 16.0, 0.3), (0.0, 1.0, 0.0))), {"cyclic_X": 1.0}),
    "reversal spike": (
        Effects(spike=((_SPIKE_H, _SPIKE_W), (0.0, 1.0))),
        {
            "spike_X+": _SPIKE_H * np.exp(-STEP / _SPIKE_W) * np.cos(np.radians(STEP)),
            "spike_X-": _SPIKE_H * np.exp(-STEP / _SPIKE_W) * np.cos(np.radians(STEP)),
        },
    ),
    "stick-slip": (Effects(stick_slip=((0.0, 4.0, 10.0), (1.0, 4.0, 10.0))), {"stick_slip_Y": 1.0}),
}
#: the tolerance of a recovered term: this many standard uncertainties, plus a share of
#: its value (the exact geometry's second order, a sampled spike or ripple)
K_TOL, REL_TOL = 4.0, 0.02


def _diagnose(tmp_path: Path, effects: Effects, **kw) -> Diagnosis:
    runs = synthetic_readings(R, effects, step_deg=STEP, feed_mm_per_min=FEED, **kw)
    write_lengths(tmp_path / "c.csv", R, runs, header=CALIBRATED)
    (c,) = circle_tests(tmp_path / "c.csv")
    return c.diagnosis


def _check(d: Diagnosis, truth: dict[str, float]) -> None:
    for t in d.terms:
        if t.key in truth:
            assert t.reported, t
            assert abs(t.value - truth[t.key]) <= K_TOL * t.u + REL_TOL * abs(truth[t.key]), t
        else:
            assert not t.reported, t


@pytest.mark.parametrize("case", ALONE)
def test_each_effect_alone_is_recovered_and_nothing_else(tmp_path, case):
    effects, truth = ALONE[case]
    _check(_diagnose(tmp_path, replace(effects, noise_um=NOISE)), truth)


def test_all_effects_together_are_recovered(tmp_path):
    """Every effect at once (the spike on X, the stick-slip on Y: at one reversal the two
    are not told apart), with a set-up offset of the pivot and a length error of the bar
    within its calibration."""
    effects = Effects(
        scale_um_per_m=(12.0, -3.0),
        squareness_um_per_m=10.0,
        servo_mismatch_ms=0.5,
        backlash_um=((3.0, 2.0), (1.0, 4.0)),
        lateral_um=(2.0, -1.5),
        bow_um=(3.0, -2.0),
        cyclic=((1.0, 16.0, 0.3), (0.0, 1.0, 0.0)),
        spike=((_SPIKE_H, _SPIKE_W), (0.0, 1.0)),
        stick_slip=((0.0, 4.0, 10.0), (1.0, 4.0, 10.0)),
        centre_offset_um=(20.0, -15.0),
        length_error_um=0.1,
        noise_um=NOISE,
    )
    truth: dict[str, float] = {}
    for _, alone in ALONE.values():
        truth.update(alone)
    # the mean scale and the bar's length error: 4.5 ppm + 0.1 µm / 150 mm
    truth["scaling"] = 4.5 + 0.1 / R * 1e3
    d = _diagnose(tmp_path, effects)
    _check(d, truth)


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_a_circle_with_no_error_reports_none_within_its_noise(tmp_path, seed):
    d = _diagnose(tmp_path, Effects(noise_um=0.3), seed=seed)
    _check(d, {})
    assert d.noise_um == pytest.approx(0.3, rel=0.1)


def test_servo_mismatch_without_feed_is_a_lag_in_um(tmp_path):
    """No feed stated: the mismatch is the lag along the path v Δτ (µm), 16.67 mm/s ×
    0.5 ms = 8.33 µm."""
    runs = synthetic_readings(R, Effects(servo_mismatch_ms=0.5), step_deg=2.0)
    write_angles(tmp_path / "c.csv", R, runs)
    (c,) = circle_tests(tmp_path / "c.csv")
    t = c.diagnosis.term("servo_mismatch")
    assert t.unit == "µm" and t.value == pytest.approx(FEED / 60 * 0.5, rel=1e-3)
    assert any("feed not stated" in n for n in c.diagnosis.notes)


def test_an_uncalibrated_bar_gives_scale_mismatch_only(tmp_path):
    runs = synthetic_readings(R, Effects(scale_um_per_m=(8.0, 2.0)), step_deg=2.0)
    write_angles(tmp_path / "c.csv", R, runs)
    (c,) = circle_tests(tmp_path / "c.csv")
    scaling = c.diagnosis.term("scaling")
    assert scaling.value is None and "not calibrated" in scaling.note
    assert c.diagnosis.term("scale_mismatch").value == pytest.approx(6.0, abs=1e-3)


def test_one_direction_cannot_separate_servo_mismatch_from_squareness(tmp_path):
    """Run ccw only: the servo's 45° term −(v Δτ / 2) sin 2θ joins squareness, S − v Δτ / (R/2)
    ... = 10 − 8.333 / 0.15 µm/m."""
    effects = Effects(squareness_um_per_m=10.0, servo_mismatch_ms=0.5)
    d = _diagnose(tmp_path, effects, directions=("ccw",))
    assert d.term("servo_mismatch").value is None
    lag_um = FEED / 60 * 0.5
    assert d.term("squareness").value == pytest.approx(10.0 - lag_um / (R * 1e-3), abs=0.05)
    assert any("one direction only" in n for n in d.notes)


def test_a_220_degree_arc_gives_what_it_holds(tmp_path):
    """An arc from -20° over 220°: the reversal of Y at 270° lies outside it, so its
    backlash, spike and the G of a full circle are not given; the rest is recovered (the
    backlash of Y taken as the same at both ends)."""
    effects = Effects(
        squareness_um_per_m=10.0,
        scale_um_per_m=(12.0, -3.0),
        backlash_um=((3.0, 2.0), (1.5, 1.5)),
        lateral_um=(2.0, 0.0),
        noise_um=NOISE,
    )
    d = _diagnose(tmp_path, effects, start_deg=-20.0, span_deg=220.0)
    assert not d.full_circle and d.arc_span_deg == pytest.approx(220.0)
    for key in ("backlash_Y-", "spike_Y-"):
        assert d.term(key).value is None and "outside the arc" in d.term(key).note
    _check(
        d,
        {
            "squareness": 10.0,
            "scale_mismatch": 15.0,
            "scaling": 4.5,
            "backlash_X+": 3.0,
            "backlash_X-": 2.0,
            "backlash_Y+": 1.5,
            "lateral_X": 2.0,
        },
    )
    assert any("partial arc of 220°" in n for n in d.notes)


def test_spike_window_readings_are_left_out_of_the_fit(tmp_path):
    """A spike decayed within the window leaves the backlash estimate alone."""
    d = _diagnose(
        tmp_path,
        Effects(backlash_um=((2.0, 2.0), (0.0, 0.0)), spike=((5.0, SPIKE_WINDOW_DEG / 20), (0, 1))),
    )
    assert d.term("backlash_X+").value == pytest.approx(2.0, abs=0.01)


# -- the ISO 230-4 figures ----------------------------------------------------------------


def test_squareness_is_a_45_degree_ellipse_of_G(tmp_path):
    """δa = S·b moves a point radially by S R sin θ cos θ: G is its peak-to-valley S R
    (ISO 230-4 annex B), 8 µm/m on R = 150 mm gives 1.2 µm; no hysteresis."""
    runs = synthetic_readings(R, Effects(squareness_um_per_m=8.0), step_deg=1.0)
    write_lengths(tmp_path / "c.csv", R, runs)
    (c,) = circle_tests(tmp_path / "c.csv")
    assert c.plane == "XY"
    assert c.directions[0].G_um == pytest.approx(8e-3 * R, rel=2e-3)
    assert c.H_um == pytest.approx(0.0, abs=1e-5)


def test_F_is_about_the_nominal_centre_and_H_parts_the_runs(tmp_path):
    """A pivot 10 µm off along X: F spans ±10 µm about the nominal radius; backlash b of
    X parts the two runs by b (H)."""
    effects = Effects(centre_offset_um=(10.0, 0.0), backlash_um=((2.0, 2.0), (0.0, 0.0)))
    runs = synthetic_readings(R, effects, step_deg=1.0)
    write_lengths(tmp_path / "c.csv", R, runs)
    (c,) = circle_tests(tmp_path / "c.csv")
    d = c.directions[0]
    assert d.F_max_um == pytest.approx(10.0, abs=1.1) and d.F_min_um == pytest.approx(
        -10.0, abs=1.1
    )
    assert c.H_um == pytest.approx(2.0, rel=0.02)


def test_a_short_circle_names_file_and_line(tmp_path):
    (tmp_path / "c.csv").write_text(
        "circle,X,Y,Z,cx,cy,cz,length_mm,deviation_um\nc1,1,0,0,0,0,0,1,0\n"
    )
    with pytest.raises(ParseError, match=r"c.csv:2: circle 'c1' has 1 readings"):
        circle_tests(tmp_path / "c.csv")


def test_angles_along_an_arc_count_a_reading_a_hair_before_its_start_at_0(tmp_path):
    """Angles from positions carry rounding: 339.9999999° on an arc from 340° is at its
    start, not 360° along it (else the plot and H would join the arc across its gap)."""
    from esp.ballbar.analysis import along_arc

    assert along_arc(np.array([339.9999999, 340.0, 200.0]), 340.0) == pytest.approx(
        [0.0, 0.0, 220.0], abs=1e-6
    )
    runs = synthetic_readings(R, Effects(), step_deg=2.0, start_deg=-20.0, span_deg=220.0)
    write_lengths(tmp_path / "c.csv", R, runs)
    (c,) = circle_tests(tmp_path / "c.csv")
    for d in c.directions:
        phi = along_arc(np.asarray(d.angle_deg), c.diagnosis.arc_start_deg)
        assert phi.min() > -1e-6 and phi.max() < 220.0 + 1e-6
