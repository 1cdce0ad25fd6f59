"""Exact evaluation of a chain by homogeneous transforms, vectorised over points.

The referee of every first-order model: each elementary transform is applied exactly --
the exact rotation matrices for large and small angles alike, and the exact rotation of an
error motion's rotation vector (Rodrigues' formula; :mod:`esp.core.kinematics.rotations`) --
so the difference between this and a first-order model is the model's truncation error and
nothing else.

:func:`position` applies the transforms Ψ_N, …, Ψ_1 in turn to the tool point [0, 0, 0, 1]
(the product Ψ_1 … Ψ_N acting on it, without forming 4×4 matrices); :func:`transforms`
forms the 4×4 products themselves (position and orientation of the tool frame).
Both work in blocks of points so that memory stays bounded on large grids.

References
----------
Loh et al. (2004), eq. 1 and 9: the probe's homogeneous transform as the product of the
carriages' transforms. Freeman & Ford (2003), section 4: X = (Π Ψ_i) X⁰.
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping
from typing import Any

import numpy as np

from esp.core.kinematics.chain import Chain, Op, check_finite
from esp.core.kinematics.rotations import axis_rotation, rodrigues, skew

__all__ = ["BLOCK", "position", "rodrigues", "tool_axis", "transforms"]

#: points evaluated together
BLOCK = 65536


def _evaluate(op: Op, env: Mapping[str, Any]) -> list[Any]:
    with np.errstate(all="ignore"):
        values = [e.evaluate(env) for e in op.q]
    return [check_finite(v, k, e) for v, k, e in zip(values, op.keys, op.q, strict=True)]


def _pivot(op: Op, env: Mapping[str, Any]) -> list[Any]:
    with np.errstate(all="ignore"):
        values = [e.evaluate(env) for e in op.pivot]
    return [check_finite(v, k, e) for v, k, e in zip(values, op.pivot_keys, op.pivot, strict=True)]


def _cross(a: tuple[Any, Any, Any], b: tuple[Any, Any, Any]) -> tuple[Any, Any, Any]:
    return (
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    )


def _rotate_point(op: Op, q: list[Any], p: list[Any]) -> list[Any]:
    """``p`` rotated by the angle ``q[0]`` (signed by ``op.sign``) about the frame axis
    ``op.axis`` (a revolute joint or a rotation, "R")."""
    theta = op.sign * q[0]
    c, s = np.cos(theta), np.sin(theta)
    i, j = (op.axis + 1) % 3, (op.axis + 2) % 3
    out = list(p)
    out[i] = c * p[i] - s * p[j]
    out[j] = s * p[i] + c * p[j]
    return out


def _apply(op: Op, env: Mapping[str, Any], p: list[Any]) -> list[Any]:
    """Ψ p for one elementary transform; ``p`` is [x, y, z] (arrays or floats)."""
    q = _evaluate(op, env)
    if op.kind == "T":
        return [p[0] + q[0], p[1] + q[1], p[2] + q[2]]
    if op.kind == "R":
        return _rotate_point(op, q, p)
    piv = _pivot(op, env)
    w = (p[0] - piv[0], p[1] - piv[1], p[2] - piv[2])
    r = (q[3], q[4], q[5])
    a, b = rodrigues(*r)
    u = _cross(r, w)
    v = _cross(r, u)
    return [piv[k] + q[k] + w[k] + a * u[k] + b * v[k] for k in range(3)]


def _blocks(env: Mapping[str, Any], n: int, block: int) -> Iterator[tuple[slice, dict[str, Any]]]:
    """Yield (slice, env restricted to the slice)."""
    for start in range(0, n, block):
        sl = slice(start, min(n, start + block))
        sub = {k: (v[sl] if np.ndim(v) == 1 else v) for k, v in env.items()}
        yield sl, sub


def position(
    chain: Chain,
    coordinates: Mapping[str, Any] | None = None,
    parameters: Mapping[str, Any] | None = None,
    errors: Mapping[str, Any] | None = None,
    *,
    block: int = BLOCK,
) -> np.ndarray:
    """The tool-tip position in the base frame, exactly, at N points.

    Parameters
    ----------
    chain : the chain
    coordinates : name -> value(s), in each coordinate's unit (mm for a prismatic joint,
        degrees for a revolute one unless declared otherwise); numbers or arrays (N,)
    parameters : name -> value, overriding the chain's defaults (in each one's unit)
    errors : name -> value(s) in each error's unit (µm and µrad unless declared
        otherwise); an error not given is zero

    Returns
    -------
    ndarray (N, 3)
        x, y, z of the tool tip in mm (N = 1 when every value is a number).

    Raises
    ------
    ConfigError
        A missing coordinate or parameter, an unknown name, a non-numeric or non-finite
        value (key ``coordinates.X``, ``parameters.G``, ``errors.dx_Y``).
    DataError
        A quantity is not finite at these values (``e/tan(Yp)`` with Yp = 0).
    """
    env, n = chain.environment(coordinates, parameters, errors)
    out = np.empty((n, 3))
    ops = chain.ops
    with chain.named():
        for sl, sub in _blocks(env, n, block):
            m = sl.stop - sl.start
            p: list[Any] = [np.zeros(m), np.zeros(m), np.zeros(m)]
            for op in reversed(ops):
                p = _apply(op, sub, p)
            for k in range(3):
                out[sl, k] = p[k]
    return out


def _matrix(op: Op, env: Mapping[str, Any]) -> tuple[np.ndarray, np.ndarray]:
    """(R, t) of one elementary transform: R (N or 1, 3, 3), t (N or 1, 3)."""
    q = _evaluate(op, env)
    if op.kind == "T":
        t = np.stack(np.broadcast_arrays(*[np.asarray(v, dtype=float) for v in q]), axis=-1)
        t = t.reshape(-1, 3)
        return np.eye(3)[None], t
    if op.kind == "R":
        theta = np.atleast_1d(np.asarray(op.sign * q[0], dtype=float))
        return axis_rotation(op.axis, theta), np.zeros((1, 3))
    piv = np.stack(
        np.broadcast_arrays(*[np.asarray(v, dtype=float) for v in _pivot(op, env)]), axis=-1
    ).reshape(-1, 3)
    r = np.stack(np.broadcast_arrays(*[np.asarray(v, dtype=float) for v in q[3:]]), axis=-1)
    r = r.reshape(-1, 3)
    d = np.stack(np.broadcast_arrays(*[np.asarray(v, dtype=float) for v in q[:3]]), axis=-1)
    d = d.reshape(-1, 3)
    a, b = rodrigues(r[:, 0], r[:, 1], r[:, 2])
    K = skew(r)
    R = np.eye(3)[None] + a[:, None, None] * K + b[:, None, None] * (K @ K)
    t = piv + d - np.einsum("nij,nj->ni", R, np.broadcast_to(piv, (R.shape[0], 3)))
    return R, t


def transforms(
    chain: Chain,
    coordinates: Mapping[str, Any] | None = None,
    parameters: Mapping[str, Any] | None = None,
    errors: Mapping[str, Any] | None = None,
    *,
    block: int = BLOCK,
) -> np.ndarray:
    """The 4×4 homogeneous transform Ψ_1 Ψ_2 … Ψ_N of the tool frame, exactly.

    Arguments as :func:`position`. Returns an array (N, 4, 4): the columns of its upper
    3×3 block are the tool frame's x, y, z axes in the base frame, its last column the
    tool-tip position in mm (equal to :func:`position`).
    """
    env, n = chain.environment(coordinates, parameters, errors)
    out = np.zeros((n, 4, 4))
    out[:, 3, 3] = 1.0
    with chain.named():
        for sl, sub in _blocks(env, n, block):
            _product(chain, sub, sl, out)
    return out


def _product(chain: Chain, sub: Mapping[str, Any], sl: slice, out: np.ndarray) -> None:
    """Multiply out Ψ_1 … Ψ_N for one block of points into ``out[sl]``."""
    R = np.eye(3)[None]
    t = np.zeros((1, 3))
    for op in chain.ops:
        Ri, ti = _matrix(op, sub)
        # (R, t) ∘ (Ri, ti) = (R Ri, R ti + t); leading sizes 1 or N broadcast
        t = t + np.einsum("...ij,...j->...i", R, ti)
        R = R @ Ri
    m = sl.stop - sl.start
    out[sl, :3, :3] = np.broadcast_to(R, (m, 3, 3))
    out[sl, :3, 3] = np.broadcast_to(t, (m, 3))


def tool_axis(
    chain: Chain,
    coordinates: Mapping[str, Any] | None = None,
    parameters: Mapping[str, Any] | None = None,
    errors: Mapping[str, Any] | None = None,
) -> np.ndarray:
    """The z axis of the tool frame (the frame after the last step) in the base frame,
    (N, 3) unit vectors. For Freeman & Ford's angle head, whose last step T(0, 0, −G)
    puts the tip G along −z of the spindle frame, the tool points along −(this axis)
    from the spindle to the tip; the last step is a translation, so the tool frame is
    the spindle frame."""
    return transforms(chain, coordinates, parameters, errors)[:, :3, 2]
