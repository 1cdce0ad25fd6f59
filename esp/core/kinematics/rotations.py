"""Rotations in three dimensions: the skew matrix of a vector, rotations about a frame axis,
the exponential of a rotation vector (Rodrigues' formula) and its logarithm (numpy only).

Every function is vectorised: vectors are arrays (..., 3), matrices (..., 3, 3). Angles are
in radians. These are the rotations of the kinematic chains (:mod:`esp.core.kinematics`:
the revolute joints and rotations, the rotation vectors of error motions) and of the
serial-parallel machine (:mod:`esp.parallel`).

Conventions: [v]× is the matrix of the cross product, [v]× w = v × w; a rotation about
frame axis k by θ turns axis k+1 towards axis k+2 (right-handed); exp([φ]×) is the rotation
by |φ| about φ/|φ|.

References
----------
Rodrigues' formula, exp([φ]×) = I + (sin θ/θ) [φ]× + ((1 − cos θ)/θ²) [φ]×², θ = |φ|, and
its inverse: Murray, Li & Sastry (1994), A Mathematical Introduction to Robotic
Manipulation, eq. 2.14 and 2.17-2.18.
"""

from __future__ import annotations

from typing import Any

import numpy as np

__all__ = [
    "SERIES_BELOW",
    "axis_rotation",
    "exp_rotation",
    "log_rotation",
    "rodrigues",
    "skew",
    "vee",
]

#: below this rotation angle (rad) Rodrigues' coefficients come from their series: direct
#: evaluation of (1 − cos θ)/θ² loses half the digits at 1e-8 rad, the series to θ⁴ is exact
#: to rounding below 1e-4 rad
SERIES_BELOW = 1e-4


def skew(v: Any) -> np.ndarray:
    """[v]×, the matrix of the cross product with ``v`` (..., 3): shape (..., 3, 3)."""
    v = np.asarray(v, float)
    out = np.zeros(v.shape[:-1] + (3, 3))
    out[..., 0, 1], out[..., 0, 2] = -v[..., 2], v[..., 1]
    out[..., 1, 0], out[..., 1, 2] = v[..., 2], -v[..., 0]
    out[..., 2, 0], out[..., 2, 1] = -v[..., 1], v[..., 0]
    return out


def vee(a: Any) -> np.ndarray:
    """The vector of the antisymmetric part of ``a`` (..., 3, 3): v with [v]× = (a − aᵀ)/2,
    shape (..., 3); the inverse of :func:`skew`."""
    a = np.asarray(a, float)
    return 0.5 * np.stack(
        [a[..., 2, 1] - a[..., 1, 2], a[..., 0, 2] - a[..., 2, 0], a[..., 1, 0] - a[..., 0, 1]],
        axis=-1,
    )


def axis_rotation(axis: int, theta: Any) -> np.ndarray:
    """The rotation by ``theta`` (any shape, radians) about frame axis ``axis`` (0, 1, 2 for
    x, y, z): shape theta.shape + (3, 3). Rx(θ) = [[1, 0, 0], [0, c, −s], [0, s, c]]."""
    theta = np.asarray(theta, dtype=float)
    c, s = np.cos(theta), np.sin(theta)
    i, j, k = (axis + 1) % 3, (axis + 2) % 3, axis
    out = np.zeros(theta.shape + (3, 3))
    out[..., k, k] = 1.0
    out[..., i, i] = c
    out[..., j, j] = c
    out[..., i, j] = -s
    out[..., j, i] = s
    return out


def _coefficients(t: Any, t2: Any, series_below: float) -> tuple[np.ndarray, np.ndarray]:
    """a = sin θ/θ and b = (1 − cos θ)/θ² at θ = ``t`` (θ² = ``t2``)."""
    small = t < series_below
    safe_t = np.where(small, 1.0, t)
    a = np.where(small, 1.0 - t2 / 6.0 + t2 * t2 / 120.0, np.sin(safe_t) / safe_t)
    b = np.where(
        small, 0.5 - t2 / 24.0 + t2 * t2 / 720.0, (1.0 - np.cos(safe_t)) / (safe_t * safe_t)
    )
    return a, b


def rodrigues(
    rx: Any, ry: Any, rz: Any, *, series_below: float = SERIES_BELOW
) -> tuple[np.ndarray, np.ndarray]:
    """The coefficients a, b of exp([r]×) = I + a [r]× + b [r]×² for the rotation vector
    r = (rx, ry, rz): a = sin θ/θ, b = (1 − cos θ)/θ², θ = |r|, from their series
    a = 1 − θ²/6 + θ⁴/120, b = 1/2 − θ²/24 + θ⁴/720 below ``series_below`` rad."""
    t2 = np.asarray(rx * rx + ry * ry + rz * rz, dtype=float)
    return _coefficients(np.sqrt(t2), t2, series_below)


def exp_rotation(phi: Any, *, series_below: float = SERIES_BELOW) -> np.ndarray:
    """The rotation exp([φ]×) of rotation vectors φ (..., 3) (radians), shape (..., 3, 3):
    Rodrigues' formula with the coefficients of :func:`rodrigues` (θ = |φ| by
    :func:`numpy.linalg.norm`), exact for any angle."""
    phi = np.asarray(phi, float)
    t = np.linalg.norm(phi, axis=-1)
    a, b = _coefficients(t, t * t, series_below)
    k = skew(phi)
    return np.eye(3) + a[..., None, None] * k + b[..., None, None] * (k @ k)


def log_rotation(rot: Any) -> np.ndarray:
    """The rotation vector φ with exp([φ]×) = ``rot`` (..., 3, 3), |φ| < π, shape (..., 3):
    θ = atan2(|w|, (tr R − 1)/2) along w = vee(R), exact for small angles too."""
    rot = np.asarray(rot, float)
    w = vee(rot)
    s = np.linalg.norm(w, axis=-1)
    c = 0.5 * (np.trace(rot, axis1=-2, axis2=-1) - 1.0)
    theta = np.arctan2(s, c)
    factor = np.where(s > 1e-300, theta / np.where(s > 1e-300, s, 1.0), 1.0)
    return w * factor[..., None]
