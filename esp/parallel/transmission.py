"""Error transmission at one or many poses: the matrices of the paper, the sensitivities
of the tool to every error source, the distance from singularity.

:func:`transmit` is the entry point. It runs the chosen model -- ``"exact"`` (the linkage
analysis, checked against the differential vector method at every call) or
``"as-printed"`` (eq. 10-18 as printed) -- and measures how close each pose is to a
singular configuration by the condition number of the dimensionless Jacobian,

    κ = cond₂([J] D),   D = diag(1, 1, 1, 1/λ, 1/λ, 1/λ),

λ the mean distance from the tool tip to the ball joints (so the rotation columns are
lengths too). κ bounds how much a relative error of the constraints can grow in the
tool's pose; it is ∞ where [J] is singular. A pose with κ above the limit
(:data:`MAX_CONDITION`, or the configuration's ``max_condition``) is refused: near a
singularity first-order error transmission no longer describes the machine.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from esp.core.errors import DataError
from esp.parallel._linalg import solve
from esp.parallel.differential import differential_matrices
from esp.parallel.geometry import Geometry
from esp.parallel.kinematics import Poses
from esp.parallel.linkage import linkage_matrices
from esp.parallel.printed import printed_matrices
from esp.parallel.sources import engine_from_paper

__all__ = ["MAX_CONDITION", "MODELS", "Transmission", "condition_numbers", "transmit"]

#: the error models: derived from the exact kinematics, or eq. 10-18 as printed
MODELS = ("exact", "as-printed")
#: poses whose condition number κ exceeds this are refused (the paper's example pose has
#: κ ≈ 3.9; ±60° tilts of its machine stay below 320)
MAX_CONDITION = 1000.0


@dataclass(frozen=True)
class Transmission:
    """The error transmission at N poses.

    Attributes
    ----------
    model : ``"exact"`` or ``"as-printed"``
    poses : the nominal poses
    table_mm : (N, 2) the X-Y table's positions
    J, J_inv, M, N : (N, 6, 6), (N, 6, 6), (N, 6, 12), (N, 6, 30): the matrices of eq. 12
        and 18, lengths in mm and angles in radians (the paper's units)
    sensitivity : (N, 6, 42) [J]⁻¹ [M | N] in esp's units: µm of e and µrad of ε per µm
        (or µrad) of each source
    condition : (N,) κ, the condition number of the dimensionless [J]
    smallest_singular_value : (N,) of the dimensionless [J] (0 at a singularity)
    methods_difference : (N,) the largest difference between the sensitivities of the
        linkage and the differential vector method (exact model; µm or µrad per unit)
    """

    model: str
    poses: Poses
    table_mm: np.ndarray
    J: np.ndarray
    J_inv: np.ndarray
    M: np.ndarray
    N: np.ndarray
    sensitivity: np.ndarray
    condition: np.ndarray
    smallest_singular_value: np.ndarray
    methods_difference: np.ndarray

    def errors(self, values: npt.ArrayLike) -> np.ndarray:
        """The tool's errors (N, 6) -- e in µm, ε in µrad -- for error values (42,) or
        (N, 42) in µm and µrad."""
        v = np.asarray(values, float)
        if v.ndim == 1:
            return self.sensitivity @ v
        return np.einsum("nij,nj->ni", self.sensitivity, v)


def condition_numbers(jac: np.ndarray, lever_mm: float) -> tuple[np.ndarray, np.ndarray]:
    """κ and the smallest singular value of [J] D (see the module text); (N,) each."""
    scaled = np.array(jac, dtype=float)
    scaled[..., 3:] /= lever_mm
    with np.errstate(divide="ignore", invalid="ignore"):
        sv = np.linalg.svd(scaled, compute_uv=False)
        kappa = np.where(sv[..., -1] > 0, sv[..., 0] / sv[..., -1], np.inf)
    return kappa, sv[..., -1]


def transmit(
    geometry: Geometry,
    poses: Poses,
    table_mm: npt.ArrayLike = (0.0, 0.0),
    *,
    model: str = "exact",
    max_condition: float = MAX_CONDITION,
    check: bool = True,
    compare_methods: bool = True,
) -> Transmission:
    """The error transmission of the machine at ``poses``.

    Parameters
    ----------
    geometry : the machine
    poses : nominal poses (from :func:`esp.parallel.kinematics.inverse`)
    table_mm : (2,) or (N, 2) the X-Y table's position (the lever of its angular errors)
    model : ``"exact"`` (default) or ``"as-printed"``
    max_condition : refuse poses whose κ is larger
    check : refuse near-singular poses (else they are returned, for callers that mask them)
    compare_methods : also run the differential vector method and record the largest
        difference from the linkage analysis (exact model)

    Raises
    ------
    DataError
        A pose is singular or closer to singular than ``max_condition`` allows.
    """
    if model not in MODELS:
        raise DataError(f"model: expected one of {', '.join(MODELS)}, found {model!r}")
    n = len(poses)
    table = np.array(np.broadcast_to(np.asarray(table_mm, float), (n, 2)))
    exact = linkage_matrices(geometry, poses, table)
    kappa, smallest = condition_numbers(exact["J"], geometry.lever_mm)
    if check:
        bad = ~(kappa <= max_condition)
        if np.any(bad):
            i = int(np.argmax(np.where(bad, np.nan_to_num(kappa, posinf=1e300), 0)))
            raise DataError(
                f"pose z_T = {poses.z_mm[i]:g} mm, α = {poses.alpha_deg[i]:g}°, "
                f"β = {poses.beta_deg[i]:g}° is {_how_singular(kappa[i], smallest[i])}: "
                f"condition number of [J] {kappa[i]:.3g} > limit {max_condition:g} "
                "(max_condition); refused"
            )
    difference = np.zeros(n)
    if compare_methods and model == "exact":
        other = differential_matrices(geometry, poses, table)
        difference = np.max(
            np.abs(engine_from_paper(exact["S"]) - engine_from_paper(other["S"])), axis=(1, 2)
        )
    mats = exact if model == "exact" else printed_matrices(geometry, poses, table)
    j_inv = solve(mats["J"], np.broadcast_to(np.eye(6), mats["J"].shape))
    return Transmission(
        model,
        poses,
        table,
        mats["J"],
        j_inv,
        mats["M"],
        mats["N"],
        engine_from_paper(mats["S"]),
        kappa,
        smallest,
        difference,
    )


def _how_singular(kappa: float, smallest: float) -> str:
    if not np.isfinite(kappa) or smallest == 0:
        return "singular (the platform is not held: [J] has no inverse)"
    return f"near-singular (smallest singular value {smallest:.3g})"
