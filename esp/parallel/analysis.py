"""What ``esp parallel`` computes: the analysis at a pose and the sweeps.

:func:`analyse_pose` -- at one commanded pose: the nominal kinematics, the matrices, the
tool's errors for the error values of the machine file with every source's contribution
and share, the exact (nonlinear) errors for the same values as a check of the first-order
model, and the uncertainty. :func:`sweep` -- the error-range sweep at that pose and the
workspace grid.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from esp.core.errors import DataError
from esp.parallel.config import ParallelMachine, PoseSpec
from esp.parallel.exact import exact_errors
from esp.parallel.kinematics import Poses, inverse
from esp.parallel.sweep import (
    ErrorSweep,
    Workspace,
    WorkspaceSpec,
    error_sweep,
    workspace_sweep,
)
from esp.parallel.transmission import MODELS, Transmission, transmit
from esp.parallel.uncertainty import UncertaintyResult, propagate

__all__ = [
    "PoseResult",
    "SweepResult",
    "analyse_pose",
    "default_workspace",
    "sweep",
]


@dataclass(frozen=True)
class PoseResult:
    """The analysis at one pose.

    Attributes
    ----------
    machine : the machine as read
    pose_spec : the commanded pose
    model : the error model used
    transmission : the matrices and sensitivities at the pose (N = 1)
    values : (42,) the error values (µm, µrad)
    errors : (6,) e (µm) and ε (µrad) by the first-order model
    exact : (6,) the same by the exact kinematics (the check of the linear model)
    contributions : (42, 6) each source's signed part of ``errors``
    share_position_pct, share_rotation_pct : (42,) each source's share of |e| and |ε|:
        its contribution projected on the total, c_j · e / |e|² (the shares add up to
        100 %, a source acting against the total has a negative share)
    uncertainty : the uncertainty of the tool's errors, when the file gives one
    """

    machine: ParallelMachine
    pose_spec: PoseSpec
    model: str
    transmission: Transmission
    values: np.ndarray
    errors: np.ndarray
    exact: np.ndarray
    contributions: np.ndarray
    share_position_pct: np.ndarray
    share_rotation_pct: np.ndarray
    uncertainty: UncertaintyResult | None

    @property
    def pose(self) -> Poses:
        return self.transmission.poses


@dataclass(frozen=True)
class SweepResult:
    error: ErrorSweep
    workspace: Workspace
    workspace_spec: WorkspaceSpec


def _shares(contrib: np.ndarray) -> np.ndarray:
    total = contrib.sum(axis=0)
    denom = float(total @ total)
    return 100.0 * contrib @ total / denom if denom > 0 else np.zeros(len(contrib))


def analyse_pose(
    machine: ParallelMachine, pose: PoseSpec | None = None, model: str | None = None
) -> PoseResult:
    """The analysis of ``machine`` at ``pose`` (default: the file's ``[pose]``).

    Raises
    ------
    DataError
        No pose is given, the pose is unreachable, or it is (near-)singular.
    """
    pose = pose or machine.pose
    if pose is None:
        raise DataError('no pose: give --pose "z=..,alpha=..,beta=.." or a [pose] table')
    model = model or machine.model
    if model not in MODELS:
        raise DataError(f"model: expected one of {', '.join(MODELS)}, found {model!r}")
    poses = inverse(machine.geometry, pose.z_mm, pose.alpha_deg, pose.beta_deg)
    trans = transmit(
        machine.geometry,
        poses,
        pose.table_mm,
        model=model,
        max_condition=machine.max_condition,
    )
    values = np.asarray(machine.values, float)
    s = trans.sensitivity[0]
    contrib = (s * values[None, :]).T  # (42, 6)
    errors = contrib.sum(axis=0)
    exact = exact_errors(machine.geometry, poses, pose.table_mm, values)[0]
    unc = None
    if machine.uncertainty is not None:
        unc = propagate(machine.uncertainty, trans, values, machine.geometry)
    result = PoseResult(
        machine,
        pose,
        model,
        trans,
        values,
        errors,
        exact,
        contrib,
        _shares(contrib[:, :3]),
        _shares(contrib[:, 3:]),
        unc,
    )
    _check_finite(result)
    return result


def default_workspace(pose: PoseSpec) -> WorkspaceSpec:
    """The grid swept when the file has no ``[sweep.workspace]``: z_T ± 100 mm in 5 steps,
    α and β from −15° to 15° in 7 steps."""
    return WorkspaceSpec(
        (pose.z_mm - 100.0, pose.z_mm + 100.0, 5), (-15.0, 15.0, 7), (-15.0, 15.0, 7)
    )


def sweep(result: PoseResult) -> SweepResult:
    """The error-range sweep at the pose of ``result`` and the workspace grid."""
    machine = result.machine
    spec = machine.workspace or default_workspace(result.pose_spec)
    unc = machine.uncertainty
    ws = workspace_sweep(
        machine.geometry,
        spec,
        result.values,
        table_mm=result.pose_spec.table_mm,
        model=result.model,
        max_condition=machine.max_condition,
        U=None if unc is None else unc.U,
        k=2.0 if unc is None else unc.k,
    )
    es = error_sweep(result.transmission, result.values, machine.error_sweep)
    out = SweepResult(es, ws, spec)
    for case in es.cases:
        if not np.all(np.isfinite(case.errors)):
            raise DataError("the error sweep gave a non-finite value")  # pragma: no cover
    if not np.all(np.isfinite(ws.errors)):
        raise DataError("the workspace sweep gave a non-finite value")  # pragma: no cover
    return out


def _check_finite(result: PoseResult) -> None:
    arrays = [result.errors, result.exact, result.transmission.sensitivity]
    if result.uncertainty is not None:
        arrays += [result.uncertainty.statistical, result.uncertainty.summation]
    if not all(np.all(np.isfinite(a)) for a in arrays):  # pragma: no cover - refused earlier
        raise DataError("the analysis gave a non-finite value; the pose is too close to singular")
