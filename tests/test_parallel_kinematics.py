"""Nominal kinematics of the serial-parallel machine (Zhao, Fan et al. 2002, eq. 1-5)."""

from __future__ import annotations

import math
import subprocess
import sys

import numpy as np
import pytest

from esp.core.errors import ConfigError, DataError
from esp.parallel.geometry import Geometry, Leg, symmetric_geometry
from esp.parallel.kinematics import (
    dependent_eq4,
    euler_from_rotation,
    forward,
    inverse,
    log_rotation,
    rotation,
    rotation_partials,
    rotation_vector,
)

PAPER = symmetric_geometry(400.0, 200.0, 300.0, 1000.0)


def test_the_symmetric_layout_is_the_papers():
    """Columns at 120° on a circle of radius R about (R/2, 0); the revolute axes are the
    rows of [u] printed under eq. 11; the balls are b_i of eq. 3."""
    s3 = math.sqrt(3.0)
    np.testing.assert_allclose(
        PAPER.joints_mm, [[600, 0], [0, 200 * s3], [0, -200 * s3]], atol=1e-12
    )
    np.testing.assert_allclose(
        PAPER.axes, [[0, 1, 0], [-s3 / 2, -0.5, 0], [s3 / 2, -0.5, 0]], atol=1e-15
    )
    np.testing.assert_allclose(
        PAPER.balls_mm, [[200, 0, 300], [-100, 100 * s3, 300], [-100, -100 * s3, 300]], atol=1e-12
    )
    # the planes of the paper: Y_1 = 0, Y_2 = -√3 (X_2 - R/2), Y_3 = √3 (X_3 - R/2)
    for (x, y), sign in zip(PAPER.joints_mm[1:], (-1, 1), strict=True):
        assert y == pytest.approx(sign * s3 * (x - 200.0))


def test_rotation_is_eq_1():
    a, b, g = 0.3, -0.2, 0.1
    rot = rotation(a, b, g)
    ca, sa, cb, sb, cg, sg = (
        math.cos(a),
        math.sin(a),
        math.cos(b),
        math.sin(b),
        math.cos(g),
        math.sin(g),
    )
    printed = [
        [cb * cg, -cb * sg, sb],
        [sa * sb * cg + ca * sg, -sa * sb * sg + ca * cg, -sa * cb],
        [-ca * sb * cg + sa * sg, ca * sb * sg + sa * cg, ca * cb],
    ]
    np.testing.assert_allclose(rot, printed, atol=1e-15)
    np.testing.assert_allclose(np.array(euler_from_rotation(rot)), [a, b, g], atol=1e-15)


def test_rotation_partials_against_central_differences():
    angles = np.array([0.3, -0.2, 0.1])
    h = 1e-6
    for k, d in enumerate(rotation_partials(*angles)):
        step = np.zeros(3)
        step[k] = h
        numeric = (rotation(*(angles + step)) - rotation(*(angles - step))) / (2 * h)
        np.testing.assert_allclose(d, numeric, atol=1e-9)


def test_rotation_vector_and_log_are_inverse():
    rng = np.random.default_rng(3)
    phi = rng.normal(size=(50, 3))
    phi *= (rng.uniform(1e-9, 3.0, size=50) / np.linalg.norm(phi, axis=1))[:, None]
    rot = rotation_vector(phi)
    np.testing.assert_allclose(
        rot @ np.swapaxes(rot, -1, -2), np.broadcast_to(np.eye(3), rot.shape), atol=1e-14
    )
    np.testing.assert_allclose(log_rotation(rot), phi, atol=1e-12)


def test_dependent_coordinates_agree_with_the_printed_eq_4():
    """x_T, y_T, γ solved from the plane conditions equal the closed form of eq. 4."""
    z, a, b = np.meshgrid(
        [250.0, 300.0], np.linspace(-30, 30, 7), np.linspace(-30, 30, 7), indexing="ij"
    )
    poses = inverse(PAPER, z.ravel(), a.ravel(), b.ravel())
    x, y, g = dependent_eq4(np.radians(a.ravel()), np.radians(b.ravel()), 400.0, 200.0, 300.0)
    np.testing.assert_allclose(poses.x_mm, x, atol=1e-9)
    np.testing.assert_allclose(poses.y_mm, y, atol=1e-9)
    np.testing.assert_allclose(np.radians(poses.gamma_deg), g, atol=1e-12)


def test_paper_pose_by_hand():
    """At α = β = 0 the tool tip is under the columns' centre, (R/2, 0), and each slider
    stands √(l² − (R − r)²) above the ball joints (eq. 5)."""
    pose = inverse(PAPER, 300.0, 0.0, 0.0)
    np.testing.assert_allclose(pose.tip_mm[0], [200.0, 0.0, 300.0], atol=1e-12)
    np.testing.assert_allclose(pose.sliders_mm[0], 600.0 + math.sqrt(1000.0**2 - 200.0**2))
    assert abs(pose.gamma_deg[0]) < 1e-12


def test_inverse_then_forward_round_trip_over_a_grid():
    z, a, b = np.meshgrid(
        np.linspace(0, 600, 4), np.linspace(-40, 40, 9), np.linspace(-40, 40, 9), indexing="ij"
    )
    poses = inverse(PAPER, z.ravel(), a.ravel(), b.ravel())
    back = forward(PAPER, poses.sliders_mm)
    np.testing.assert_allclose(back.tip_mm, poses.tip_mm, atol=1e-8)
    np.testing.assert_allclose(back.alpha_deg, poses.alpha_deg, atol=1e-9)
    np.testing.assert_allclose(back.beta_deg, poses.beta_deg, atol=1e-9)
    np.testing.assert_allclose(back.gamma_deg, poses.gamma_deg, atol=1e-9)
    # and forward then inverse gives the heights back
    again = inverse(PAPER, back.z_mm, back.alpha_deg, back.beta_deg)
    np.testing.assert_allclose(again.sliders_mm, poses.sliders_mm, atol=1e-8)


def test_an_explicit_layout_gives_the_same_as_the_symmetric_one():
    legs = tuple(
        Leg(tuple(j), tuple(u[:2]), tuple(bb), 1000.0)
        for j, u, bb in zip(PAPER.joints_mm, PAPER.axes, PAPER.balls_mm, strict=True)
    )
    explicit = Geometry(legs, PAPER.table_origin_mm)
    a = inverse(PAPER, 320.0, 12.0, -7.0)
    b = inverse(explicit, 320.0, 12.0, -7.0)
    np.testing.assert_allclose(b.sliders_mm, a.sliders_mm, atol=1e-9)


def _unit(x: float, y: float) -> tuple[float, float]:
    n = math.hypot(x, y)
    return (x / n, y / n)


def test_an_asymmetric_layout_round_trips():
    geometry = Geometry(
        (
            Leg((610.0, 5.0), _unit(0.05, 1.0), (205.0, 3.0, 290.0), 1003.0),
            Leg((-4.0, 350.0), _unit(-0.87, -0.493), (-98.0, 176.0, 305.0), 998.0),
            Leg((3.0, -343.0), _unit(0.86, -0.51), (-103.0, -170.0, 301.0), 1001.0),
        ),
        (200.0, 0.0, 0.0),
    )
    poses = inverse(geometry, [280.0, 330.0], [10.0, -5.0], [-8.0, 15.0])
    back = forward(geometry, poses.sliders_mm)
    np.testing.assert_allclose(back.tip_mm, poses.tip_mm, atol=1e-8)
    np.testing.assert_allclose(back.gamma_deg, poses.gamma_deg, atol=1e-9)


def test_unreachable_pose_is_refused():
    short = symmetric_geometry(400.0, 200.0, 300.0, 150.0)
    with pytest.raises(DataError, match="unreachable: ball joint 1 is 200.000 mm from column 1"):
        inverse(short, 300.0, 0.0, 0.0)
    with pytest.raises(DataError, match="within ±90°"):
        inverse(PAPER, 300.0, 90.0, 0.0)


def test_slider_travel_is_enforced():
    g = symmetric_geometry(400.0, 200.0, 300.0, 1000.0, slider_travel_mm=(0.0, 1500.0))
    with pytest.raises(DataError, match="outside its travel"):
        inverse(g, 300.0, 15.0, 10.0)


@pytest.mark.slow
def test_forward_refuses_heights_with_no_assembly():
    pose = inverse(PAPER, 300.0, 0.0, 0.0)
    with pytest.raises(DataError, match="give no assembly"):
        forward(PAPER, pose.sliders_mm[0] + np.array([0.0, 0.0, 500.0]))
    with pytest.raises(DataError, match="not the working mode"):
        forward(PAPER, pose.sliders_mm[0] + np.array([0.0, 0.0, 2000.0]))
    with pytest.raises(DataError, match="finite"):
        forward(PAPER, [1.0, np.nan, 2.0])


@pytest.mark.parametrize(
    ("args", "key"),
    [
        ((0.0, 200.0, 300.0, 1000.0), "geometry.R_mm"),
        ((400.0, -1.0, 300.0, 1000.0), "geometry.r_mm"),
        ((400.0, 200.0, math.nan, 1000.0), "geometry.h_mm"),
        ((400.0, 200.0, 300.0, -5.0), "geometry.leg1.strut_mm"),
        ((400.0, 200.0, 300.0, (1.0, 2.0)), "geometry.strut_mm"),
    ],
)
def test_bad_geometry_is_refused(args, key):
    with pytest.raises(ConfigError) as info:
        symmetric_geometry(*args)
    assert info.value.key == key


def test_collinear_ball_joints_are_refused():
    legs = (
        Leg((600.0, 0.0), (0.0, 1.0), (0.0, 0.0, 300.0), 1000.0),
        Leg((0.0, 346.0), _unit(-0.866, -0.5), (100.0, 0.0, 300.0), 1000.0),
        Leg((0.0, -346.0), _unit(0.866, -0.5), (200.0, 0.0, 300.0), 1000.0),
    )
    with pytest.raises(ConfigError, match="on one line"):
        Geometry(legs, (0.0, 0.0, 0.0))


@pytest.mark.slow
def test_the_core_imports_only_numpy():
    code = (
        "import sys\n"
        "import esp.parallel, esp.parallel.render\n"
        "bad = ('matplotlib', 'pandas', 'click', 'sympy')\n"
        "print(','.join(sorted(m for m in bad if m in sys.modules)))\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == ""


@pytest.mark.parametrize(
    ("key", "value"),
    [("table_origin_mm", (1.0, 2.0)), ("slider_travel_mm", (0.0, 100.0, 200.0))],
)
def test_a_table_origin_or_slider_travel_of_the_wrong_length_is_a_config_error(key, value):
    with pytest.raises(ConfigError, match=f"geometry.{key}"):
        symmetric_geometry(400.0, 200.0, 300.0, 1000.0, **{key: value})
