"""Sweeps: one error over a range at a pose (the paper's Fig. 5 and 6), and the error
over a grid of poses of the workspace, with the worst case and where it occurs."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from esp.core.errors import DataError
from esp.parallel.geometry import Geometry
from esp.parallel.kinematics import inverse
from esp.parallel.sources import SOURCE_NAMES, SOURCES
from esp.parallel.transmission import Transmission, transmit
from esp.parallel.uncertainty import statistical_uncertainty

__all__ = [
    "LEG_SOURCES",
    "ErrorSweep",
    "ErrorSweepCase",
    "ErrorSweepSpec",
    "Workspace",
    "WorkspaceSpec",
    "Worst",
    "error_sweep",
    "swept_sources",
    "workspace_sweep",
]

#: the names of a leg's sources without the leg (``slider.Z`` is ``legi.slider.Z``)
LEG_SOURCES = tuple(dict.fromkeys(n.split(".", 1)[1] for n in SOURCE_NAMES if n.startswith("leg")))
#: the largest workspace grid evaluated
MAX_GRID_POINTS = 200_000


@dataclass(frozen=True)
class ErrorSweepSpec:
    """One error swept over a range: ``source`` a leg's source without the leg
    (``"slider.Z"``) or a table source (``"table.X"``); ``start``, ``stop`` in its unit;
    ``cases``: ``"all"`` (every leg the same value, Fig. 5) or a leg ``"1"``, ``"2"``,
    ``"3"`` (that leg only, Fig. 6); a table source has the single case ``"table"``."""

    source: str = "slider.Z"
    start: float = 0.0
    stop: float = 100.0
    steps: int = 11
    cases: tuple[str, ...] = ("all", "1")


@dataclass(frozen=True)
class ErrorSweepCase:
    """One case of a sweep: the swept source names, the values (steps,) and the tool's
    errors (steps, 6), the other sources held at their values."""

    case: str
    sources: tuple[str, ...]
    values: np.ndarray
    errors: np.ndarray


@dataclass(frozen=True)
class ErrorSweep:
    source: str
    unit: str
    cases: tuple[ErrorSweepCase, ...]


def swept_sources(source: str, case: str) -> tuple[str, ...]:
    """The full source names a sweep case sets."""
    if source in LEG_SOURCES:
        legs = (1, 2, 3) if case == "all" else (int(case),)
        return tuple(f"leg{i}.{source}" for i in legs)
    return (source,)


def error_sweep(transmission: Transmission, values: np.ndarray, spec: ErrorSweepSpec) -> ErrorSweep:
    """The tool's errors at the pose of ``transmission`` while the swept sources take each
    value of the range and every other source keeps its value (``values``, (42,))."""
    s = transmission.sensitivity[0]
    grid = np.linspace(spec.start, spec.stop, spec.steps)
    cases = []
    for case in spec.cases:
        names = swept_sources(spec.source, case)
        cols = [SOURCE_NAMES.index(n) for n in names]
        base = np.array(values, float)
        base[cols] = 0.0
        slope = s[:, cols].sum(axis=1)
        errors = (s @ base)[None, :] + grid[:, None] * slope[None, :]
        cases.append(ErrorSweepCase(case, names, grid, errors))
    unit = SOURCES[SOURCE_NAMES.index(swept_sources(spec.source, spec.cases[0])[0])].unit
    return ErrorSweep(spec.source, unit, tuple(cases))


@dataclass(frozen=True)
class WorkspaceSpec:
    """A grid of poses: each axis ``(start, stop, count)``; ``outside``: ``"refuse"`` a
    grid with an unreachable or near-singular pose, or ``"skip"`` such poses."""

    z_mm: tuple[float, float, int]
    alpha_deg: tuple[float, float, int]
    beta_deg: tuple[float, float, int]
    outside: str = "refuse"


@dataclass(frozen=True)
class Worst:
    """The largest magnitude of a quantity over the grid, its signed value and where."""

    quantity: str
    unit: str
    value: float
    z_mm: float
    alpha_deg: float
    beta_deg: float


@dataclass(frozen=True)
class Workspace:
    """The grid evaluated: axes, the mask of poses evaluated (nz, na, nb), and per
    evaluated pose (flattened, in grid order) its coordinates, errors (M, 6), κ and, with
    uncertainties, the statistical U of the six outputs; the poses left out with why."""

    z_mm: np.ndarray
    alpha_deg: np.ndarray
    beta_deg: np.ndarray
    evaluated: np.ndarray
    points: np.ndarray  # (M, 3) z, α, β
    errors: np.ndarray  # (M, 6)
    condition: np.ndarray  # (M,)
    uncertainty: np.ndarray | None  # (M, 6)
    excluded: tuple[tuple[float, float, float, str], ...]
    worst: tuple[Worst, ...]

    def grid(self, values: np.ndarray) -> np.ndarray:
        """``values`` (M,) placed on the grid (nz, na, nb), NaN where not evaluated (for
        plots only)."""
        out = np.full(self.evaluated.shape, np.nan)
        out[self.evaluated] = values
        return out


def _axis(spec: tuple[float, float, int]) -> np.ndarray:
    start, stop, count = spec
    return np.linspace(start, stop, int(count))


def workspace_sweep(
    geometry: Geometry,
    spec: WorkspaceSpec,
    values: np.ndarray,
    *,
    table_mm: npt.ArrayLike = (0.0, 0.0),
    model: str = "exact",
    max_condition: float,
    U: np.ndarray | None = None,
    k: float = 2.0,
) -> Workspace:
    """The tool's errors for ``values`` over the grid of ``spec`` (vectorised).

    Raises
    ------
    DataError
        With ``outside = "refuse"``, a pose of the grid is unreachable or closer to
        singular than ``max_condition``; or no pose of the grid can be evaluated.
    """
    zs, alphas, betas = _axis(spec.z_mm), _axis(spec.alpha_deg), _axis(spec.beta_deg)
    total = zs.size * alphas.size * betas.size
    if total > MAX_GRID_POINTS:
        raise DataError(f"sweep.workspace: {total} poses; at most {MAX_GRID_POINTS} are evaluated")
    zz, aa, bb = np.meshgrid(zs, alphas, betas, indexing="ij")
    flat = np.column_stack([zz.ravel(), aa.ravel(), bb.ravel()])
    in_range = (np.abs(flat[:, 1]) < 90) & (np.abs(flat[:, 2]) < 90)
    poses = inverse(geometry, flat[:, 0], flat[:, 1], flat[:, 2], check=False)
    ok = in_range & np.all(np.isfinite(poses.sliders_mm), axis=1)
    reason = np.where(ok, "", "unreachable").astype(object)
    if geometry.slider_travel_mm is not None:
        lo, hi = geometry.slider_travel_mm
        with np.errstate(invalid="ignore"):
            out = np.any((poses.sliders_mm < lo) | (poses.sliders_mm > hi), axis=1)
        reason[ok & out] = "slider out of travel"
        ok &= ~out
    idx = np.flatnonzero(ok)
    trans = None
    if idx.size:
        trans = transmit(
            geometry,
            poses.take(idx),
            table_mm,
            model=model,
            max_condition=max_condition,
            check=False,
            compare_methods=False,
        )
        singular = ~(trans.condition <= max_condition)
        reason[idx[singular]] = "near-singular"
        ok[idx[singular]] = False
    excluded = [
        (float(flat[i, 0]), float(flat[i, 1]), float(flat[i, 2]), str(reason[i]))
        for i in np.flatnonzero(~ok)
    ]
    if excluded and spec.outside == "refuse":
        z, a, b, why = excluded[0]
        what = {
            "unreachable": "unreachable (no strut solution)",
            "slider out of travel": "unreachable (a slider leaves its travel)",
            "near-singular": f"near-singular (condition number above {max_condition:g})",
        }[why]
        raise DataError(
            f"sweep.workspace: {len(excluded)} of {total} poses cannot be evaluated, e.g. "
            f"z_T = {z:g} mm, α = {a:g}°, β = {b:g}° is {what}; narrow the grid or set "
            'outside = "skip"'
        )
    if not np.any(ok):
        raise DataError("sweep.workspace: no pose of the grid is reachable")
    assert trans is not None  # a pose is ok, so idx was not empty
    keep = ~np.isin(idx, np.flatnonzero(~ok))
    sens = trans.sensitivity[keep]
    errors = sens @ np.asarray(values, float)
    condition = trans.condition[keep]
    points = flat[ok]
    unc = statistical_uncertainty(sens, np.asarray(U, float), k) if U is not None else None
    worst = _worst(points, errors, condition, unc)
    return Workspace(
        zs,
        alphas,
        betas,
        ok.reshape(zz.shape),
        points,
        errors,
        condition,
        unc,
        tuple(excluded),
        worst,
    )


def _worst(
    points: np.ndarray, errors: np.ndarray, condition: np.ndarray, unc: np.ndarray | None
) -> tuple[Worst, ...]:
    quantities = [
        ("|e|", "um", np.linalg.norm(errors[:, :3], axis=1)),
        ("|eps|", "urad", np.linalg.norm(errors[:, 3:], axis=1)),
    ]
    for i, name in enumerate(("e_x", "e_y", "e_z", "eps_x", "eps_y", "eps_z")):
        quantities.append((name, "um" if i < 3 else "urad", errors[:, i]))
    quantities.append(("condition", "", condition))
    if unc is not None:
        quantities.append(("U(e)", "um", np.linalg.norm(unc[:, :3], axis=1)))
        quantities.append(("U(eps)", "urad", np.linalg.norm(unc[:, 3:], axis=1)))
    out = []
    for name, unit, values in quantities:
        j = int(np.argmax(np.abs(values)))
        out.append(Worst(name, unit, float(values[j]), *(float(c) for c in points[j])))
    return tuple(out)
