"""Error transmission by linkage kinematic analysis (Zhao, Fan et al. 2002, section 4.1-4.2).

The platform's small motion, a translation e of the tool tip and a rotation ε, moves ball
joint i by e_i = e + ε × r_i (eq. 7), r_i the vector from the tool tip to the ball joint;
a position error δr_i of the ball joint on the platform adds R δr_i. The strut is rigid and
its ends are joints, so two scalar conditions hold per leg:

* along the strut (eq. 8): the ball joint moves along l_i as much as the revolute joint
  does, plus the strut's length error: l_i · e_i = l_i · δP_i + δl_i, with δP_i = δC_i +
  δR_i the revolute joint's displacement and l_i the unit vector from the revolute joint
  to the ball joint (eq. 15: L_i = l_i l_i);
* across the strut (eq. 11): the ball joint stays in the plane the revolute joint lets the
  strut swing in. When that plane moves with the joint (δP_i along u_i) or turns (the axis
  turned by ω_i = δτ_i ρ_i + δψ_i Z, so that δu_i = ω_i × u_i), the ball joint follows:
  u_i · e_i = u_i · δP_i − l_i ω_i · (u_i × l_i). The paper writes 0 on the right (it
  takes the joint fixed across its plane); here the exact kinematics is followed.

Gathering the six conditions gives [J] Δ_w = [M] δA + [N_w] δB (eq. 12 and its
extension), Δ_w the platform's motion in XYZ. The X-Y table acts in series: the tool
relative to the workpiece is Δ = Δ_w − (δO_P + ε_P × p, ε_P), p the tool tip's position
from the table's reference point, and the table's columns of [N] are [J] times that map.

Lengths are in mm and angles in radians here (the paper's units); see
:func:`esp.parallel.sources.engine_from_paper` for µm and µrad.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from esp.core.kinematics.rotations import skew
from esp.parallel._linalg import solve
from esp.parallel.geometry import Geometry
from esp.parallel.kinematics import Poses

__all__ = ["linkage_matrices", "strut_vectors"]


def strut_vectors(geometry: Geometry, poses: Poses) -> tuple[np.ndarray, np.ndarray]:
    """r_i (tool tip to ball joint) and l_i (unit, revolute joint to ball joint) in XYZ,
    each (N, 3, 3): pose, leg, component."""
    r = np.einsum("nij,kj->nki", poses.rotation, geometry.balls_mm)
    joints = np.empty_like(r)
    joints[..., :2] = geometry.joints_mm[None]
    joints[..., 2] = poses.sliders_mm
    s = poses.tip_mm[:, None, :] + r - joints
    return r, s / geometry.struts_mm[None, :, None]


def linkage_matrices(
    geometry: Geometry, poses: Poses, table_mm: npt.ArrayLike
) -> dict[str, np.ndarray]:
    """[J] (N, 6, 6), [M] (N, 6, 12), [N] (N, 6, 30) and the sensitivities
    S = [J]⁻¹ [M | N] (N, 6, 42) by the linkage analysis, in mm and radians.

    Parameters
    ----------
    geometry : the machine
    poses : the nominal poses
    table_mm : (2,) or (N, 2) the X-Y table's position
    """
    n = len(poses)
    r, lhat = strut_vectors(geometry, poses)
    u = np.broadcast_to(geometry.axes, (n, 3, 3))
    lengths = geometry.struts_mm
    jac = np.empty((n, 6, 6))
    jac[:, :3, :3] = lhat
    jac[:, :3, 3:] = np.cross(r, lhat)
    jac[:, 3:, :3] = u
    jac[:, 3:, 3:] = np.cross(r, u)

    m = np.zeros((n, 6, 12))
    n_w = np.zeros((n, 6, 30))
    rot_t = np.swapaxes(poses.rotation, -1, -2)
    for k in range(3):
        # revolute joint displacement δR_k (eq. 8 and 11) and strut length δl_k
        m[:, k, 4 * k : 4 * k + 3] = lhat[:, k]
        m[:, k, 4 * k + 3] = 1.0
        m[:, 3 + k, 4 * k : 4 * k + 3] = u[:, k]
        # the slider's displacement δC_k moves the joint the same way
        n_w[:, k, 6 * k : 6 * k + 3] = lhat[:, k]
        n_w[:, 3 + k, 6 * k : 6 * k + 3] = u[:, k]
        # the ball joint's own error R δr_k is part of e_k: it moves to the right side
        n_w[:, k, 6 * k + 3 : 6 * k + 6] = -np.einsum("nij,nj->ni", rot_t, lhat[:, k])
        n_w[:, 3 + k, 6 * k + 3 : 6 * k + 6] = -np.einsum("nij,nj->ni", rot_t, u[:, k])
        # the revolute axis turned: the strut's plane turns about the joint
        across = np.cross(u[:, k], lhat[:, k])
        n_w[:, 3 + k, 24 + 2 * k] = -lengths[k] * across @ geometry.radials[k]
        n_w[:, 3 + k, 25 + 2 * k] = -lengths[k] * across[:, 2]
    s_platform = solve(jac, np.concatenate([m, n_w], axis=2))

    # the table in series: Δ = Δ_w − (δO_P + ε_P × p, ε_P)
    lever = poses.tip_mm - _table_point(geometry, table_mm, n)
    series = np.zeros((n, 6, 6))
    series[:, :3, :3] = -np.eye(3)
    series[:, :3, 3:] = skew(lever)  # −ε_P × p = p × ε_P
    series[:, 3:, 3:] = -np.eye(3)
    s_table = series
    s = s_platform.copy()
    s[:, :, 12 + 18 : 12 + 24] = s_table
    n_full = n_w.copy()
    n_full[:, :, 18:24] = jac @ s_table
    return {"J": jac, "M": m, "N": n_full, "S": s}


def _table_point(geometry: Geometry, table_mm: npt.ArrayLike, n: int) -> np.ndarray:
    """(N, 3): the table's reference point in XYZ with the table at ``table_mm``."""
    table = np.broadcast_to(np.asarray(table_mm, float), (n, 2))
    origin = np.asarray(geometry.table_origin_mm, float)
    return origin[None, :] + np.column_stack([table, np.zeros(n)])
