"""Error transmission by the differential vector method (Zhao, Fan et al. 2002, section 4.3).

Each leg closes a vector loop (eq. 14-15): from the base along the column to the slider
(C_i), to the revolute joint (R_i), along the strut to the ball joint (L_i = l_i l_i) --
and, the other way, to the table (O_P), from the table's reference point to the tool tip
(O_T) and from the tool tip to the ball joint ([T] b_i). Writing the strut vector as the
loop's remainder,

    L_i = O_P + R_P (O_T + T (b_i + δr_i)) − C_i − R_i,

the two conditions of the strut are |L_i|² = l_i² and L_i · u_i = 0. They are
differentiated here with respect to the tool's pose relative to the table, taken in the
paper's own coordinates -- (x_T, y_T, z_T) and the Euler angles (α, β, γ) of eq. 1, whose
partial derivatives ∂T/∂α, ∂T/∂β, ∂T/∂γ are computed from the product of the three
elementary rotations -- and with respect to every error source:

    L_i · dL_i = l_i dl_i,          u_i · dL_i + L_i · du_i = 0,

with dL_i = dO_P + ε_P × (O_T + T b_i) + dO_T + Σ ∂T/∂q_k b_i dq_k + T dδr_i − dC_i − dR_i
and du_i = ω_i × u_i. The small rotation follows from the Euler rates by
[ε]x = Σ ∂T/∂q_k Tᵀ dq_k.

Nothing here is shared with :mod:`esp.parallel.linkage` (no cross products of eq. 7, no
unit strut vector, the table inside the loop rather than in series), so the agreement of
the two is a check of both. The paper's [J], [M], [N] are recovered by dividing each
length condition by l_i and mapping the Euler rates to ε.

Lengths are in mm and angles in radians here.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from esp.core.kinematics.rotations import vee
from esp.parallel._linalg import solve
from esp.parallel.geometry import Geometry
from esp.parallel.kinematics import Poses, rotation, rotation_partials
from esp.parallel.sources import M_COLUMNS, N_COLUMNS, SOURCE_NAMES

__all__ = ["differential_matrices"]

_COL = {name: i for i, name in enumerate(SOURCE_NAMES)}


def differential_matrices(
    geometry: Geometry, poses: Poses, table_mm: npt.ArrayLike
) -> dict[str, np.ndarray]:
    """[J] (N, 6, 6), [M] (N, 6, 12), [N] (N, 6, 30) and S = [J]⁻¹ [M | N] (N, 6, 42) by
    the differential vector method, in mm and radians (same layout as
    :func:`esp.parallel.linkage.linkage_matrices`)."""
    n = len(poses)
    a, b, g = (np.radians(v) for v in (poses.alpha_deg, poses.beta_deg, poses.gamma_deg))
    t = rotation(a, b, g)
    partials = rotation_partials(a, b, g)
    table = np.broadcast_to(np.asarray(table_mm, float), (n, 2))
    o_p = np.asarray(geometry.table_origin_mm, float)[None, :] + np.column_stack(
        [table, np.zeros(n)]
    )
    o_t = poses.tip_mm - o_p
    sources = np.zeros((n, 6, len(SOURCE_NAMES)))
    coords = np.zeros((n, 6, 6))  # d(constraint) / d(x, y, z, α, β, γ)
    for k, leg in enumerate(geometry.legs):
        i = k + 1
        b_k = np.asarray(leg.ball_mm, float)
        c_k = np.column_stack(
            [np.full(n, leg.joint_xy_mm[0]), np.full(n, leg.joint_xy_mm[1]), poses.sliders_mm[:, k]]
        )
        tb = t @ b_k
        w = o_t + tb  # table's reference point -> ball joint
        loop = o_p + w - c_k  # L_i, revolute joint -> ball joint
        u = leg.u
        for row, vec, scale in (
            (k, loop, 1.0 / leg.strut_mm),
            (3 + k, np.broadcast_to(u, (n, 3)), 1.0),
        ):
            coords[:, row, :3] = vec * scale
            for j, d_t in enumerate(partials):
                coords[:, row, 3 + j] = np.einsum("ni,ni->n", vec, d_t @ b_k) * scale
            # the joint's displacement enters with − on the left, + on the right
            for c, axis in enumerate("XYZ"):
                sources[:, row, _COL[f"leg{i}.joint.{axis}"]] = vec[:, c] * scale
                sources[:, row, _COL[f"leg{i}.slider.{axis}"]] = vec[:, c] * scale
                sources[:, row, _COL[f"table.{axis}"]] = -vec[:, c] * scale
            # T dδr_i on the left
            t_vec = np.einsum("nji,nj->ni", t, vec)
            for c, axis in enumerate("xyz"):
                sources[:, row, _COL[f"leg{i}.ball.{axis}"]] = -t_vec[:, c] * scale
            # ε_P × w on the left: vec · (ε_P × w) = ε_P · (w × vec)
            moment = np.cross(w, vec)
            for c, axis in enumerate("ABC"):
                sources[:, row, _COL[f"table.{axis}"]] = -moment[:, c] * scale
        # the strut's length: L · dL = l dl
        sources[:, k, _COL[f"leg{i}.strut"]] = 1.0
        # the plane: u · dL = −L · du, du = ω × u, so −L · (ω × u) = −ω · (u × L)
        across = np.cross(np.broadcast_to(u, (n, 3)), loop)
        sources[:, 3 + k, _COL[f"leg{i}.axis.tilt"]] = -across @ leg.radial
        sources[:, 3 + k, _COL[f"leg{i}.axis.yaw"]] = -across[:, 2]
    solution = solve(coords, sources)  # d(x, y, z, α, β, γ) per source
    rates = np.stack([vee(d_t @ np.swapaxes(t, -1, -2)) for d_t in partials], axis=-1)
    s = np.empty_like(solution)
    s[:, :3] = solution[:, :3]
    s[:, 3:] = rates @ solution[:, 3:]
    # the paper's [J]: the same conditions with the rotation written as ε
    jac = np.empty((n, 6, 6))
    jac[:, :, :3] = coords[:, :, :3]
    jac[:, :, 3:] = coords[:, :, 3:] @ np.linalg.inv(rates)
    m = sources[:, :, [_COL[c] for c in M_COLUMNS]]
    n_mat = sources[:, :, [_COL[c] for c in N_COLUMNS]]
    return {"J": jac, "M": m, "N": n_mat, "S": s}
