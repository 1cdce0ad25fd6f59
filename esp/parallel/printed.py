"""The error model exactly as printed in Zhao, Fan et al. (2002), eq. 10-18.

Kept to reproduce the paper, not as the default: where it departs from the exact
kinematics (see ``docs/parallel.md``) esp follows the exact kinematics
(:mod:`esp.parallel.linkage`, :mod:`esp.parallel.differential`). As printed:

* the unit strut vector is l_i = (R_i − b_i) / l_i (the definition after eq. 8), i.e. from
  the ball joint to the revolute joint, while eq. 8 adds +δl_i: a longer strut then moves
  the ball joint towards its revolute joint, the opposite of what it does;
* the constraint rows (eq. 11) have 0 on the right: the part of a joint's, ball joint's or
  table's error across the strut's plane is dropped;
* δO_P enters only the strut rows (eq. 17-18), and the table has no rotation, the revolute
  axes no misalignment (those columns are zero).

Lengths in mm, angles in radians; same layout as the exact methods.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from esp.parallel._linalg import solve
from esp.parallel.geometry import Geometry
from esp.parallel.kinematics import Poses
from esp.parallel.linkage import strut_vectors

__all__ = ["printed_matrices"]


def printed_matrices(
    geometry: Geometry, poses: Poses, table_mm: npt.ArrayLike
) -> dict[str, np.ndarray]:
    """[J], [M], [N] and S = [J]⁻¹ [M | N] of eq. 10-18 as printed (``table_mm`` does not
    enter: the printed model has no table lever)."""
    n = len(poses)
    r, lhat = strut_vectors(geometry, poses)
    lp = -lhat  # printed: (R_i − b_i) / l_i
    u = np.broadcast_to(geometry.axes, (n, 3, 3))
    jac = np.empty((n, 6, 6))
    jac[:, :3, :3] = lp
    jac[:, :3, 3:] = np.cross(r, lp)
    jac[:, 3:, :3] = u
    jac[:, 3:, 3:] = np.cross(r, u)
    m = np.zeros((n, 6, 12))
    n_mat = np.zeros((n, 6, 30))
    rot_t = np.swapaxes(poses.rotation, -1, -2)
    for k in range(3):
        m[:, k, 4 * k : 4 * k + 3] = lp[:, k]
        m[:, k, 4 * k + 3] = 1.0
        n_mat[:, k, 6 * k : 6 * k + 3] = lp[:, k]
        n_mat[:, k, 6 * k + 3 : 6 * k + 6] = -np.einsum("nij,nj->ni", rot_t, lp[:, k])
        n_mat[:, k, 18:21] = -lp[:, k]
    s = solve(jac, np.concatenate([m, n_mat], axis=2))
    return {"J": jac, "M": m, "N": n_mat, "S": s}
