"""The rotations module (esp.core.kinematics.rotations): hand values and the properties
of a rotation (R Rᵀ = I, det R = 1, log(exp(w)) = w, composition about one axis,
conjugation), the series and the direct Rodrigues coefficients across their seam."""

from __future__ import annotations

import math

import numpy as np
import pytest

from esp.core.kinematics.rotations import (
    SERIES_BELOW,
    axis_rotation,
    exp_rotation,
    log_rotation,
    rodrigues,
    skew,
    vee,
)

RNG = np.random.default_rng(20030101)


def _vectors(n: int = 200, largest: float = 3.0) -> np.ndarray:
    """Rotation vectors of angles from 1e-12 rad to ``largest`` rad, random axes."""
    axes = RNG.normal(size=(n, 3))
    axes /= np.linalg.norm(axes, axis=1, keepdims=True)
    angles = np.concatenate(
        [np.geomspace(1e-12, 1e-3, n // 2), RNG.uniform(1e-3, largest, n - n // 2)]
    )
    return axes * angles[:, None]


def test_skew_is_the_cross_product_and_vee_its_inverse():
    v, w = np.array([1.0, 2.0, 3.0]), np.array([4.0, 5.0, 6.0])
    # hand: (2·6 − 3·5, 3·4 − 1·6, 1·5 − 2·4) = (−3, 6, −3)
    assert (skew(v) @ w).tolist() == [-3.0, 6.0, -3.0]
    assert skew(v).tolist() == [[0.0, -3.0, 2.0], [3.0, 0.0, -1.0], [-2.0, 1.0, 0.0]]
    assert vee(skew(v)).tolist() == [1.0, 2.0, 3.0]
    many = _vectors(20)
    np.testing.assert_array_equal(vee(skew(many)), many)


def test_a_rotation_about_a_frame_axis_by_hand():
    c, s = math.cos(0.3), math.sin(0.3)
    # numpy's cos and sin (vectorised, SIMD on some builds and versions) may differ from the C
    # library's by an ulp or two, so c and s are compared to within 4 ulp (the zeros, whose
    # ulp is the smallest subnormal, in effect exactly)
    ulp = np.testing.assert_array_max_ulp
    ulp(axis_rotation(0, 0.3), np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]]), 4)
    ulp(axis_rotation(1, 0.3), np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]]), 4)
    ulp(axis_rotation(2, 0.3), np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]), 4)
    # right-handed: a quarter turn about z takes x to y, about x takes y to z
    np.testing.assert_allclose(axis_rotation(2, math.pi / 2) @ [1, 0, 0], [0, 1, 0], atol=1e-16)
    np.testing.assert_allclose(axis_rotation(0, math.pi / 2) @ [0, 1, 0], [0, 0, 1], atol=1e-16)
    assert axis_rotation(1, np.zeros((4, 2))).shape == (4, 2, 3, 3)


def test_rodrigues_coefficients_by_hand_and_across_the_series_seam():
    a, b = rodrigues(0.0, 0.0, math.pi / 2)
    assert float(a) == pytest.approx(2 / math.pi, rel=1e-15)  # sin θ/θ
    assert float(b) == pytest.approx(4 / math.pi**2, rel=1e-15)  # (1 − cos θ)/θ²
    assert rodrigues(0.0, 0.0, 0.0) == (1.0, 0.5)
    # on either side of the seam the two forms agree: a to rounding; b, whose direct form
    # (1 − cos θ)/θ² cancels to 5e-9 at 1e-4 rad, to 1e-8, which is below rounding in the
    # rotation, where b multiplies [r]×² of size θ² = 1e-8
    for t in (SERIES_BELOW * (1 - 1e-9), SERIES_BELOW * (1 + 1e-9)):
        a, b = rodrigues(t, 0.0, 0.0)
        b_true = 0.5 - t**2 / 24 + t**4 / 720
        assert float(a) == pytest.approx(1 - t**2 / 6 + t**4 / 120, rel=1e-15)
        assert float(b) == pytest.approx(b_true, rel=1e-8)
        assert abs(float(b) - b_true) * t**2 < 1e-16


def test_the_exponential_is_a_rotation():
    rot = exp_rotation(_vectors())
    np.testing.assert_allclose(
        rot @ np.swapaxes(rot, -1, -2), np.broadcast_to(np.eye(3), rot.shape), atol=1e-15
    )
    np.testing.assert_allclose(np.linalg.det(rot), 1.0, atol=1e-14)


def test_the_exponential_about_a_frame_axis_is_that_axis_rotation():
    for k in range(3):
        phi = np.zeros((5, 3))
        theta = np.array([-2.0, -1e-6, 0.0, 1e-3, 2.5])
        phi[:, k] = theta
        np.testing.assert_allclose(exp_rotation(phi), axis_rotation(k, theta), atol=1e-16)


def test_the_log_inverts_the_exponential():
    w = _vectors(largest=3.1)
    np.testing.assert_allclose(log_rotation(exp_rotation(w)), w, rtol=1e-9, atol=1e-18)
    assert log_rotation(np.eye(3)).tolist() == [0.0, 0.0, 0.0]
    # a tiny angle keeps its digits: atan2 and not arccos of the trace
    tiny = np.array([1e-10, -2e-10, 3e-10])
    np.testing.assert_allclose(log_rotation(exp_rotation(tiny)), tiny, rtol=1e-12)


def test_composition_about_one_axis_adds_the_angles_and_conjugation_turns_the_axis():
    w = _vectors(50, largest=1.0)
    np.testing.assert_allclose(
        exp_rotation(0.3 * w) @ exp_rotation(0.7 * w), exp_rotation(w), atol=1e-15
    )
    r = exp_rotation(np.array([0.2, -0.4, 0.9]))
    # R exp([w]×) Rᵀ = exp([R w]×)
    np.testing.assert_allclose(r @ exp_rotation(w) @ r.T, exp_rotation(w @ r.T), atol=1e-15)


def test_the_parallel_machine_uses_these_rotations():
    from esp.parallel.kinematics import log_rotation as parallel_log
    from esp.parallel.kinematics import rotation_vector

    w = _vectors(50)
    assert parallel_log is log_rotation
    np.testing.assert_allclose(rotation_vector(w), exp_rotation(w), rtol=0, atol=1e-15)
