"""esp ballbar: ISO 230-4 values and the first-order diagnosis against circles made by
hand."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from esp.core.errors import ParseError
from esp.identify.ballbar import STEP_COVERAGE, ballbar_dict, ballbar_text, circle_tests

ROOT = Path(__file__).resolve().parent.parent
R = 100.0


def _circle(
    path: Path,
    radial,
    *,
    backlash_x_um: float = 0.0,
    backlash_y_um: float = 0.0,
    cw_offset_um: float = 0.0,
    step_deg: float = 2.0,
    noise_um: float = 0.0,
) -> None:
    """A circle in XY about (300, 200, 50), run ccw (θ increasing) then cw: ``radial(θ)``
    in µm, the cw run ``cw_offset_um`` further out. Backlash b of an axis leaves the
    actual position b/2 behind the command along the axis' travel: along X it adds
    -(b/2) sign(v_X) cos θ to the radial deviation (v_X = ∓R sin θ ccw / cw), along Y
    -(b/2) sign(v_Y) sin θ (v_Y = ±R cos θ), a jump of b where the axis reverses."""
    rng = np.random.default_rng(7)
    rows = ["circle,direction,X,Y,Z,cx,cy,cz,length_mm,deviation_um"]
    theta = np.radians(np.arange(0.0, 360.0, step_deg))
    for direction, sense in (("ccw", 1.0), ("cw", -1.0)):
        for t in theta:
            d = radial(t) + (cw_offset_um if direction == "cw" else 0.0)
            d -= backlash_x_um / 2 * np.sign(-sense * np.sin(t)) * np.cos(t)
            d -= backlash_y_um / 2 * np.sign(sense * np.cos(t)) * np.sin(t)
            d += noise_um * rng.standard_normal()
            x, y = 300 + R * np.cos(t), 200 + R * np.sin(t)
            rows.append(f"c1,{direction},{x:.6f},{y:.6f},50,300,200,50,{R:g},{d:.6f}")
    path.write_text("\n".join(rows) + "\n")


def test_squareness_is_a_45_degree_ellipse(tmp_path):
    """δa = S·b moves a point of the circle radially by S R sinθ cosθ = (S R / 2) sin 2θ
    (ISO 230-4 annex B): S = 8 µm/m on R = 100 mm gives ±0.4 µm."""
    S = 8.0
    _circle(tmp_path / "c.csv", lambda t: S * 1e-3 * R * np.sin(t) * np.cos(t))
    (c,) = circle_tests(tmp_path / "c.csv")
    assert c.plane == "XY"
    assert c.squareness_um_per_m == pytest.approx(S, abs=1e-5)
    assert c.scale_difference_um_per_m == pytest.approx(0.0, abs=1e-5)
    # G is the peak-to-valley of the ellipse: 2 · S R / 2
    assert c.directions[0].G_um == pytest.approx(S * 1e-3 * R, rel=2e-3)
    assert c.H_um == pytest.approx(0.0, abs=1e-5)


def test_scale_difference_is_an_ellipse_along_the_axes(tmp_path):
    """ε_X = 10 µm/m, ε_Y = 0: δr = R ε_X cos²θ = R ε_X (1 + cos 2θ) / 2."""
    _circle(tmp_path / "c.csv", lambda t: 10e-3 * R * np.cos(t) ** 2)
    (c,) = circle_tests(tmp_path / "c.csv")
    assert c.scale_difference_um_per_m == pytest.approx(10.0, abs=1e-5)
    assert c.squareness_um_per_m == pytest.approx(0.0, abs=1e-5)
    d = c.directions[0]
    assert d.F_max_um == pytest.approx(1.0, abs=1e-5) and d.F_min_um == pytest.approx(0.0, abs=1e-6)


NO_REVERSAL = {
    "nothing": dict(radial=lambda t: 0.0 * t),
    # 10 µm/m on R = 100 mm: ±0.5 µm at 45°, a slope of 1 µm/rad at the reversals
    "squareness": dict(radial=lambda t: 10e-3 * R * np.sin(t) * np.cos(t)),
    "three lobes and a cw offset": dict(radial=lambda t: 1.0 * np.cos(3 * t), cw_offset_um=0.8),
    "cw offset": dict(radial=lambda t: 0.0 * t, cw_offset_um=1.0),
    "lobes, 7.5 degree steps": dict(radial=lambda t: 0.6 * np.sin(4 * t + 0.3), step_deg=7.5),
}


@pytest.mark.parametrize("case", NO_REVERSAL)
def test_a_circle_without_reversal_reports_none(tmp_path, case):
    """A smooth shape within a run (ellipse, lobes) or an offset between the runs is no
    step: the steps are measured against the trend of their neighbours, within one run."""
    _circle(tmp_path / "c.csv", **NO_REVERSAL[case])
    (c,) = circle_tests(tmp_path / "c.csv")
    assert not c.reversal_reported("X") and not c.reversal_reported("Y")
    for axis in "XY":
        assert abs(c.reversal_steps_um[axis]) <= STEP_COVERAGE * c.reversal_step_u_um[axis]
    assert "reversal steps (backlash, lost motion): none (" in ballbar_text([c])
    doc = ballbar_dict([c])["circles"][0]["diagnosis"]
    assert doc["reversal_steps_um"] == {"X": None, "Y": None}
    assert doc["reversal_noise_um"] == pytest.approx(c.reversal_noise_um)


def test_noise_alone_is_no_step_and_is_stated(tmp_path):
    """Gaussian noise of 0.3 µm: no step beyond 3 u, and the noise stated is near 0.3."""
    _circle(tmp_path / "c.csv", lambda t: 0.0 * t, noise_um=0.3)
    (c,) = circle_tests(tmp_path / "c.csv")
    assert not c.reversal_reported("X") and not c.reversal_reported("Y")
    assert 0.2 < c.reversal_noise_um < 0.4
    assert "noise 0.2" in ballbar_text([c]) or "noise 0.3" in ballbar_text([c])


@pytest.mark.parametrize(
    "bx, by, shape, step_deg",
    [
        (2.0, 0.0, lambda t: 0.5 * np.cos(3 * t), 2.0),
        (0.0, 1.2, lambda t: 0.5 * np.sin(2 * t), 2.0),
        (1.0, 3.0, lambda t: 10e-3 * R * np.sin(t) * np.cos(t), 7.5),
    ],
)
def test_a_backlash_step_is_reported_at_its_size(tmp_path, bx, by, shape, step_deg):
    """Backlash b of X is a jump b of the radial deviation at θ = 0° and 180° (X
    reverses), of Y at 90° and 270°, in both runs (Kakino et al. 1993, ch. 3)."""
    _circle(tmp_path / "c.csv", shape, backlash_x_um=bx, backlash_y_um=by, step_deg=step_deg)
    (c,) = circle_tests(tmp_path / "c.csv")
    for axis, b in (("X", bx), ("Y", by)):
        assert c.reversal_steps_um[axis] == pytest.approx(b, abs=0.01)
        assert c.reversal_reported(axis) == (b > 0)
    # a jump b in both runs, of opposite sense: the runs part by up to b
    assert c.H_um == pytest.approx(max(bx, by), rel=0.05)
    text = ballbar_text([c])
    head = text.split("reversal steps (backlash, lost motion): ")[1].split(" (")[0]
    assert head == ", ".join(f"{a} {b:+.3f} um" for a, b in (("X", bx), ("Y", by)) if b)


def test_a_backlash_step_in_noise(tmp_path):
    _circle(tmp_path / "c.csv", lambda t: 0.0 * t, backlash_x_um=1.5, noise_um=0.1)
    (c,) = circle_tests(tmp_path / "c.csv")
    assert c.reversal_reported("X") and not c.reversal_reported("Y")
    assert abs(c.reversal_steps_um["X"] - 1.5) <= 3 * c.reversal_step_u_um["X"]


def test_a_short_circle_names_file_and_line(tmp_path):
    (tmp_path / "c.csv").write_text(
        "circle,X,Y,Z,cx,cy,cz,length_mm,deviation_um\nc1,1,0,0,0,0,0,1,0\n"
    )
    with pytest.raises(ParseError, match=r"c.csv:2: circle 'c1' has 1 readings"):
        circle_tests(tmp_path / "c.csv")


@pytest.mark.slow
def test_cli_writes_polar_plot_and_json(tmp_path):
    _circle(tmp_path / "c.csv", lambda t: 0.2 * np.sin(2 * t))
    run = subprocess.run(
        [
            sys.executable,
            "-m",
            "esp",
            "ballbar",
            str(tmp_path / "c.csv"),
            "--out",
            str(tmp_path / "o"),
            "--json",
            "-",
        ],
        capture_output=True,
        text=True,
        env={"PYTHONPATH": str(ROOT), "PATH": "/usr/bin:/bin"},
    )
    assert run.returncode == 0, run.stderr
    assert json.loads(run.stdout)["schema"] == "esp.ballbar/1"
    assert (tmp_path / "o" / "polar.png").is_file()
