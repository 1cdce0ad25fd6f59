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
from esp.identify.ballbar import circle_tests

ROOT = Path(__file__).resolve().parent.parent
R = 100.0


def _circle(path: Path, radial, backlash_um: float = 0.0) -> None:
    """A circle in XY about (300, 200, 50): ``radial(θ)`` in µm; with backlash, the cw run
    lies ``backlash_um`` outside the ccw run in the half where X runs towards -X."""
    rows = ["circle,direction,X,Y,Z,cx,cy,cz,length_mm,deviation_um"]
    theta = np.radians(np.arange(0.0, 360.0, 2.0))
    for direction in ("ccw", "cw"):
        for t in theta:
            d = radial(t)
            if direction == "cw" and np.sin(t) > 0:
                d += backlash_um
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


def test_a_backlash_step_shows_as_hysteresis_and_reversal_steps(tmp_path):
    _circle(tmp_path / "c.csv", lambda t: 0.0, backlash_um=1.5)
    (c,) = circle_tests(tmp_path / "c.csv")
    assert c.H_um == pytest.approx(1.5, abs=0.05)
    # both paths enclosed about one least-squares centre: at least the hysteresis
    assert c.G_bidirectional_um >= c.H_um - 0.05
    assert c.reversal_steps_um["Y"] > 0.3  # steps where Y reverses (θ = 0°, 180°)


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
