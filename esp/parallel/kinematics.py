"""Nominal and exact kinematics of the three-strut platform (Zhao, Fan et al. 2002, eq. 1-5).

The platform's pose is the homogeneous transformation [T] of eq. 1: the tool tip at
(x_T, y_T, z_T) in the base frame XYZ and the rotation R = Rx(α) · Ry(β) · Rz(γ) -- α about
X, then β about the new Y, then γ about the new Z (the columns of R are the paper's k, m,
n). The machine has three degrees of freedom: z_T, α and β are commanded; x_T, y_T and γ
follow from the requirement that each ball joint stays in the vertical plane of its strut
(eq. 3-4).

Everything here is vectorised: poses are arrays of shape (N,), rotations (N, 3, 3).

* :func:`inverse` -- (z_T, α, β) -> the dependent (x_T, y_T, γ) and the slider heights H_i
  (eq. 5). The dependent coordinates are found by Newton's method on the three plane
  conditions, for any layout; :func:`dependent_eq4` is the paper's closed form for the
  symmetric layout, kept as a reference (the tests check that the two agree).
* :func:`assemble` -- the exact assembly: the pose that satisfies the six constraint
  equations (three strut lengths, three strut planes) for given slider heights and,
  optionally, given small deviations of the machine from its nominal geometry. It serves
  the forward kinematics (:func:`forward`) and is the nonlinear reference of the error
  models.

Refusals raise :class:`~esp.core.errors.DataError` with one line: a pose no strut can reach, a
slider out of its travel, slider heights that give no assembly in the working mode.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from esp.core.errors import DataError
from esp.core.kinematics.rotations import axis_rotation, exp_rotation, log_rotation, skew
from esp.parallel.geometry import Geometry

__all__ = [
    "Assembly",
    "Deviation",
    "Poses",
    "assemble",
    "dependent_eq4",
    "euler_from_rotation",
    "forward",
    "inverse",
    "log_rotation",
    "rotation",
    "rotation_partials",
    "rotation_vector",
]

_Z = np.array([0.0, 0.0, 1.0])
#: below this angle (rad) :func:`rotation_vector` takes Rodrigues' coefficients from their
#: series (the kinematic chains: 1e-4 rad); the results agree to rounding
_SERIES_BELOW = 1e-8
#: Newton's method stops when every constraint holds to this (mm)
TOLERANCE_MM = 1e-10
_MAX_ITERATIONS = 60


# -- rotations -----------------------------------------------------------------------------


def rotation(alpha: Any, beta: Any, gamma: Any) -> np.ndarray:
    """R = Rx(α) Ry(β) Rz(γ), eq. 1 (angles in radians); shape (..., 3, 3)."""
    ca, sa = np.cos(alpha), np.sin(alpha)
    cb, sb = np.cos(beta), np.sin(beta)
    cg, sg = np.cos(gamma), np.sin(gamma)
    out = np.empty(np.broadcast(ca, cb, cg).shape + (3, 3))
    out[..., 0, 0] = cb * cg
    out[..., 0, 1] = -cb * sg
    out[..., 0, 2] = sb + 0 * cg
    out[..., 1, 0] = sa * sb * cg + ca * sg
    out[..., 1, 1] = -sa * sb * sg + ca * cg
    out[..., 1, 2] = -sa * cb + 0 * cg
    out[..., 2, 0] = -ca * sb * cg + sa * sg
    out[..., 2, 1] = ca * sb * sg + sa * cg
    out[..., 2, 2] = ca * cb + 0 * cg
    return out


def rotation_partials(
    alpha: Any, beta: Any, gamma: Any
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """∂R/∂α, ∂R/∂β, ∂R/∂γ of eq. 1, each (..., 3, 3), by the product rule on
    Rx(α) Ry(β) Rz(γ) (the derivative of an elementary rotation about axis a is
    [a]x times it)."""
    alpha, beta, gamma = np.broadcast_arrays(
        np.asarray(alpha, float), np.asarray(beta, float), np.asarray(gamma, float)
    )
    rx, ry, rz = axis_rotation(0, alpha), axis_rotation(1, beta), axis_rotation(2, gamma)
    kx = skew(np.array([1.0, 0.0, 0.0]))
    ky = skew(np.array([0.0, 1.0, 0.0]))
    kz = skew(_Z)
    d_alpha = kx @ rx @ ry @ rz
    d_beta = rx @ (ky @ ry) @ rz
    d_gamma = rx @ ry @ (kz @ rz)
    return d_alpha, d_beta, d_gamma


def euler_from_rotation(rot: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """α, β, γ (radians) of a rotation written as eq. 1, for |β| < 90°."""
    beta = np.arcsin(np.clip(rot[..., 0, 2], -1.0, 1.0))
    alpha = np.arctan2(-rot[..., 1, 2], rot[..., 2, 2])
    gamma = np.arctan2(-rot[..., 0, 1], rot[..., 0, 0])
    return alpha, beta, gamma


def rotation_vector(phi: Any) -> np.ndarray:
    """The rotation exp([φ]x) of a rotation vector φ (radians), shape (..., 3, 3)
    (Rodrigues' formula, exact for any angle; :func:`esp.core.kinematics.rotations.exp_rotation`
    with the series below 1e-8 rad, as this machine has always evaluated it)."""
    return exp_rotation(phi, series_below=_SERIES_BELOW)


# -- the paper's closed form ---------------------------------------------------------------


def dependent_eq4(
    alpha: Any, beta: Any, R_mm: float, r_mm: float, h_mm: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """x_T, y_T (mm) and γ (radians) as printed in eq. 3-4, for the symmetric layout.

    γ = −arctan(sin α sin β / (cos α + cos β)); x_T = r/2 (k₁ − m₂) − h n₁ + R/2;
    y_T = −(r k₂ + h n₂). Kept as printed: it is the reference the numerical solution of
    :func:`inverse` is tested against.
    """
    sa, ca, sb, cb = np.sin(alpha), np.cos(alpha), np.sin(beta), np.cos(beta)
    gamma = -np.arctan(sa * sb / (ca + cb))
    sg, cg = np.sin(gamma), np.cos(gamma)
    x = r_mm / 2 * (cb * cg + sa * sb * sg - ca * cg) - h_mm * sb + R_mm / 2
    y = h_mm * sa * cb - r_mm * sa * sb * cg - r_mm * ca * sg
    return x, y, gamma


# -- poses ---------------------------------------------------------------------------------


@dataclass(frozen=True)
class Poses:
    """N poses of the platform with their slider heights (arrays of shape (N,) or (N, 3)).

    ``tip_mm`` (N, 3) is (x_T, y_T, z_T); ``rotation`` (N, 3, 3) is R of eq. 1;
    ``sliders_mm`` (N, 3) the heights H_i of the revolute joints; ``elevation_deg`` (N, 3)
    the angle of each strut above the horizontal.
    """

    alpha_deg: np.ndarray
    beta_deg: np.ndarray
    gamma_deg: np.ndarray
    tip_mm: np.ndarray
    rotation: np.ndarray
    sliders_mm: np.ndarray
    elevation_deg: np.ndarray

    @property
    def z_mm(self) -> np.ndarray:
        return self.tip_mm[:, 2]

    @property
    def x_mm(self) -> np.ndarray:
        return self.tip_mm[:, 0]

    @property
    def y_mm(self) -> np.ndarray:
        return self.tip_mm[:, 1]

    def __len__(self) -> int:
        return int(self.tip_mm.shape[0])

    def take(self, index: Any) -> Poses:
        """The poses selected by ``index`` (an index array or a boolean mask)."""
        return Poses(
            *(
                np.asarray(getattr(self, f))[index]
                for f in (
                    "alpha_deg",
                    "beta_deg",
                    "gamma_deg",
                    "tip_mm",
                    "rotation",
                    "sliders_mm",
                    "elevation_deg",
                )
            )
        )


def _where(z: float, alpha_deg: float, beta_deg: float) -> str:
    return f"z_T = {z:g} mm, α = {alpha_deg:g}°, β = {beta_deg:g}°"


def inverse(
    geometry: Geometry, z_mm: Any, alpha_deg: Any, beta_deg: Any, *, check: bool = True
) -> Poses:
    """Inverse kinematics: the slider heights that put the platform at (z_T, α, β).

    Parameters
    ----------
    geometry : the machine
    z_mm, alpha_deg, beta_deg : the commanded pose (scalars or arrays of one shape)
    check : refuse unreachable poses (else their heights are NaN and ``elevation_deg`` is
        NaN: for callers that mask them)

    Returns
    -------
    Poses
        With the dependent x_T, y_T, γ (the plane conditions of eq. 3, solved by Newton's
        method: they are linear in x_T, y_T for a given γ) and H_i of eq. 5 with the
        slider above its ball joint (the positive root).

    Raises
    ------
    DataError
        A strut cannot reach its ball joint (the pose is outside the workspace), or a
        slider height is outside ``geometry.slider_travel_mm``.
    """
    z = np.atleast_1d(np.asarray(z_mm, float)).ravel()
    a_deg = np.atleast_1d(np.asarray(alpha_deg, float)).ravel()
    b_deg = np.atleast_1d(np.asarray(beta_deg, float)).ravel()
    z, a_deg, b_deg = np.broadcast_arrays(z, a_deg, b_deg)
    a, b = np.radians(a_deg), np.radians(b_deg)
    if check and (np.any(np.abs(a_deg) >= 90) or np.any(np.abs(b_deg) >= 90)):
        i = int(np.argmax((np.abs(a_deg) >= 90) | (np.abs(b_deg) >= 90)))
        raise DataError(
            f"pose {_where(z[i], a_deg[i], b_deg[i])}: α and β must lie within ±90° (eq. 1)"
        )
    u = geometry.axes  # (3, 3)
    joints = np.column_stack([geometry.joints_mm, np.zeros(3)])  # (3, 3)
    balls = geometry.balls_mm
    n = z.shape[0]
    x = np.zeros(n)
    y = np.zeros(n)
    g = np.zeros(n)
    for _ in range(_MAX_ITERATIONS):
        rot = rotation(a, b, g)
        q = np.einsum("nij,kj->nki", rot, balls)  # (N, 3 legs, 3)
        tip = np.stack([x, y, z], axis=-1)
        f = np.einsum("kj,nkj->nk", u, tip[:, None, :] + q - joints[None])
        _, _, d_gamma = rotation_partials(a, b, g)
        dq = np.einsum("nij,kj->nki", d_gamma, balls)
        jac = np.empty((n, 3, 3))
        jac[:, :, 0] = u[None, :, 0]
        jac[:, :, 1] = u[None, :, 1]
        jac[:, :, 2] = np.einsum("kj,nkj->nk", u, dq)
        det = np.linalg.det(jac)
        if np.any(~np.isfinite(det)) or np.any(np.abs(det) < 1e-12 * np.max(np.abs(balls))):
            i = int(np.argmin(np.abs(det)))
            raise DataError(
                f"pose {_where(z[i], a_deg[i], b_deg[i])}: the strut planes do not fix the "
                "platform's X, Y and γ (their conditions are singular)"
            )
        step = np.linalg.solve(jac, -f[..., None])[..., 0]
        x, y, g = x + step[:, 0], y + step[:, 1], g + step[:, 2]
        if np.max(np.abs(f)) < TOLERANCE_MM and np.max(np.abs(step[:, :2])) < TOLERANCE_MM:
            break
    else:  # pragma: no cover - Newton on a near-linear system converges in a few steps
        raise DataError("the plane conditions of eq. 3 did not converge")
    rot = rotation(a, b, g)
    tip = np.stack([x, y, z], axis=-1)
    ball_xyz = tip[:, None, :] + np.einsum("nij,kj->nki", rot, balls)  # (N, 3, 3)
    horizontal = np.linalg.norm(ball_xyz[..., :2] - joints[None, :, :2], axis=-1)
    struts = geometry.struts_mm
    room = struts[None, :] ** 2 - horizontal**2
    reach = room > 0
    if check and not np.all(reach):
        i, leg = np.argwhere(~reach)[0]
        raise DataError(
            f"pose {_where(z[i], a_deg[i], b_deg[i])} is unreachable: ball joint {leg + 1} "
            f"is {horizontal[i, leg]:.3f} mm from column {leg + 1}, further than the strut "
            f"length {struts[leg]:g} mm (no strut solution of eq. 5)"
        )
    rise = np.sqrt(np.where(reach, room, np.nan))
    heights = ball_xyz[..., 2] + rise
    elevation = np.degrees(np.arcsin(rise / struts[None, :]))
    if check and geometry.slider_travel_mm is not None:
        lo, hi = geometry.slider_travel_mm
        bad = (heights < lo) | (heights > hi)
        if np.any(bad):
            i, leg = np.argwhere(bad)[0]
            raise DataError(
                f"pose {_where(z[i], a_deg[i], b_deg[i])} is unreachable: slider {leg + 1} "
                f"would stand at H = {heights[i, leg]:.3f} mm, outside its travel "
                f"[{lo:g}, {hi:g}] mm"
            )
    return Poses(a_deg.copy(), b_deg.copy(), np.degrees(g), tip, rot, heights, elevation)


# -- the exact assembly --------------------------------------------------------------------


@dataclass(frozen=True)
class Deviation:
    """Small deviations of a machine from its nominal geometry, for :func:`assemble`.

    Every array broadcasts against (N, ...); lengths in mm, angles in radians.

    Attributes
    ----------
    joint_mm : (..., 3, 3) displacement of each revolute joint's centre in XYZ (the
        slider's error δC_i plus the joint's own δR_i)
    axis_rad : (..., 3, 2) rotation of each revolute axis: tilt about ρ_i and yaw about Z
    ball_mm : (..., 3, 3) displacement of each ball joint in the tool frame (δr_i)
    strut_mm : (..., 3) change of each strut length (δl_i)
    """

    joint_mm: np.ndarray | float = 0.0
    axis_rad: np.ndarray | float = 0.0
    ball_mm: np.ndarray | float = 0.0
    strut_mm: np.ndarray | float = 0.0


@dataclass(frozen=True)
class Assembly:
    """The solution of the six constraint equations: tool tip (N, 3) mm, rotation
    (N, 3, 3), the largest constraint residual (mm) and the Newton iterations taken."""

    tip_mm: np.ndarray
    rotation: np.ndarray
    residual_mm: float
    iterations: int


def _constraints(
    geometry: Geometry, sliders: np.ndarray, dev: Deviation, tip: np.ndarray, rot: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The six constraints and their Jacobian with respect to (δp, δφ)."""
    n = tip.shape[0]
    joints = np.empty((n, 3, 3))
    joints[:, :, :2] = geometry.joints_mm[None]
    joints[:, :, 2] = sliders
    joints = joints + np.broadcast_to(np.asarray(dev.joint_mm, float), (n, 3, 3))
    axis_rad = np.broadcast_to(np.asarray(dev.axis_rad, float), (n, 3, 2))
    omega = axis_rad[..., 0:1] * geometry.radials[None] + axis_rad[..., 1:2] * _Z
    u = np.einsum("nkij,kj->nki", rotation_vector(omega), geometry.axes)
    balls = geometry.balls_mm[None] + np.broadcast_to(np.asarray(dev.ball_mm, float), (n, 3, 3))
    lengths = geometry.struts_mm[None] + np.broadcast_to(np.asarray(dev.strut_mm, float), (n, 3))
    q = np.einsum("nij,nkj->nki", rot, balls)
    s = tip[:, None, :] + q - joints  # joint -> ball
    res = np.concatenate(
        [
            (np.einsum("nki,nki->nk", s, s) - lengths**2) / (2 * lengths),
            np.einsum("nki,nki->nk", u, s),
        ],
        axis=1,
    )
    jac = np.empty((n, 6, 6))
    jac[:, :3, :3] = s / lengths[..., None]
    jac[:, :3, 3:] = np.cross(q, s) / lengths[..., None]
    jac[:, 3:, :3] = u
    jac[:, 3:, 3:] = np.cross(q, u)
    return res, jac, s


def assemble(
    geometry: Geometry,
    sliders_mm: Any,
    *,
    start_tip_mm: Any,
    start_rotation: Any,
    deviation: Deviation | None = None,
) -> Assembly:
    """Solve the six constraint equations of the platform exactly.

    Strut i joins the revolute joint P_i = (X_i, Y_i, H_i) (+ its deviation) to the ball
    joint B_i = p + R (b_i + δr_i); the constraints are |B_i − P_i| = l_i + δl_i and
    (B_i − P_i) · u_i' = 0, u_i' the (possibly turned) revolute axis. Newton's method
    from the given start, on (δp, δφ) with R ← exp([δφ]x) R; steps are halved while they
    do not reduce the residual.

    Parameters
    ----------
    geometry : the nominal machine
    sliders_mm : (N, 3) slider heights H_i
    start_tip_mm, start_rotation : (N, 3) and (N, 3, 3), the starting pose
    deviation : small deviations from the nominal geometry (default none)

    Raises
    ------
    DataError
        No assembly is found near the start (the slider heights are not reachable), or the
        one found is not in the working mode (each slider above its ball joint).
    """
    dev = deviation or Deviation()
    sliders = np.atleast_2d(np.asarray(sliders_mm, float))
    tip = np.array(np.broadcast_to(start_tip_mm, (sliders.shape[0], 3)), dtype=float)
    rot = np.array(np.broadcast_to(start_rotation, (sliders.shape[0], 3, 3)), dtype=float)
    res, jac, s = _constraints(geometry, sliders, dev, tip, rot)
    norm = np.max(np.abs(res), axis=1)
    iterations = 0
    with np.errstate(all="ignore"):
        while iterations < _MAX_ITERATIONS and np.max(norm) > TOLERANCE_MM:
            iterations += 1
            try:
                step = np.linalg.solve(jac, -res[..., None])[..., 0]
            except np.linalg.LinAlgError:
                raise DataError(
                    "the platform's constraints are singular at the slider heights given"
                ) from None
            scale = np.ones(len(tip))
            for _ in range(30):
                new_tip = tip + scale[:, None] * step[:, :3]
                new_rot = rotation_vector(scale[:, None] * step[:, 3:]) @ rot
                new_res, new_jac, new_s = _constraints(geometry, sliders, dev, new_tip, new_rot)
                new_norm = np.max(np.abs(new_res), axis=1)
                worse = ~(new_norm < norm) & (norm > TOLERANCE_MM)
                if not np.any(worse):
                    break
                scale = np.where(worse, scale / 2, scale)
            tip, rot, res, jac, s, norm = new_tip, new_rot, new_res, new_jac, new_s, new_norm
    worst = float(np.max(norm)) if norm.size else 0.0
    if not np.isfinite(worst) or worst > 1e3 * TOLERANCE_MM:
        i = int(np.nanargmax(np.where(np.isfinite(norm), norm, np.inf)))
        h = sliders[min(i, sliders.shape[0] - 1)]
        raise DataError(
            f"slider heights H = ({h[0]:g}, {h[1]:g}, {h[2]:g}) mm give no assembly of the "
            "platform (the struts cannot all reach it)"
        )
    if np.any(s[..., 2] >= 0):
        i = int(np.argmax(np.any(s[..., 2] >= 0, axis=1)))
        h = sliders[min(i, sliders.shape[0] - 1)]
        raise DataError(
            f"slider heights H = ({h[0]:g}, {h[1]:g}, {h[2]:g}) mm: the assembly found has a "
            "ball joint above its slider, not the working mode of the machine"
        )
    return Assembly(tip, rot, worst, iterations)


def forward(geometry: Geometry, sliders_mm: Any, *, start: Poses | None = None) -> Poses:
    """Forward kinematics: the pose the platform takes for slider heights H_i.

    Parameters
    ----------
    geometry : the machine
    sliders_mm : (3,) or (N, 3) slider heights
    start : poses to start Newton's method from (default: the level platform, α = β = 0,
        at the height that matches the mean slider height)

    Returns
    -------
    Poses
        With z_T, α, β and the dependent x_T, y_T, γ read from the assembled [T]
        (eq. 1), and the slider heights as given.

    Raises
    ------
    DataError
        As :func:`assemble`.
    """
    sliders = np.atleast_2d(np.asarray(sliders_mm, float))
    if not np.all(np.isfinite(sliders)):
        raise DataError(f"expected finite slider heights, found {sliders.tolist()!r}")
    if start is None:
        level = inverse(geometry, 0.0, 0.0, 0.0)
        z0 = np.mean(sliders - level.sliders_mm, axis=1)
        start = inverse(geometry, z0, np.zeros_like(z0), np.zeros_like(z0), check=False)
    found = assemble(geometry, sliders, start_tip_mm=start.tip_mm, start_rotation=start.rotation)
    a, b, g = euler_from_rotation(found.rotation)
    balls = found.tip_mm[:, None, :] + np.einsum("nij,kj->nki", found.rotation, geometry.balls_mm)
    rise = sliders - balls[..., 2]
    elevation = np.degrees(np.arcsin(np.clip(rise / geometry.struts_mm[None], -1, 1)))
    return Poses(
        np.degrees(a),
        np.degrees(b),
        np.degrees(g),
        found.tip_mm,
        found.rotation,
        sliders,
        elevation,
    )
