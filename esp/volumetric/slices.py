"""The planes the analysis' maps show, cut from the case's one evaluation: a plane of the
grid with one quantity on it, the faces through a direction's largest error, the
volumetric plane through the worst point, and the bilinear resampling for drawing (numpy
only; the figures are :mod:`esp.volumetric.plots`)."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from esp.core.machine import AXIS_NAMES
from esp.core.results import AnalysisResult, CaseResult, Extreme

if TYPE_CHECKING:
    from esp.core.evaluation import Evaluation

__all__ = [
    "MAP_SAMPLES",
    "Plane",
    "PlaneSlicer",
    "direction_planes",
    "map_surface",
    "volumetric_plane",
    "worst_extreme",
]

#: the number of samples along each axis of a drawn map: the grid values are resampled
#: bilinearly onto an even grid of this size and drawn as an image (quick to draw, small
#: in a PDF, whatever the grid)
MAP_SAMPLES = 256


@dataclass(frozen=True)
class Plane:
    """A plane of the simulation grid with one quantity on it.

    ``axes`` are the two axis letters spanning the plane (horizontal, vertical);
    ``grids_mm`` their positions; ``fixed`` the third axis and its position (mm);
    ``values_um`` has shape ``(len(grids_mm[0]), len(grids_mm[1]))``.
    """

    axes: tuple[str, str]
    grids_mm: tuple[np.ndarray, np.ndarray]
    fixed: tuple[str, float]
    values_um: np.ndarray

    def value_at(self, point: Mapping[str, float]) -> float:
        """The value at the grid node nearest to ``point``."""
        i = int(np.argmin(np.abs(self.grids_mm[0] - point[self.axes[0]])))
        j = int(np.argmin(np.abs(self.grids_mm[1] - point[self.axes[1]])))
        return float(self.values_um[i, j])


class PlaneSlicer:
    """Error fields of single planes of one evaluation (the case's own
    :meth:`esp.core.evaluation.Evaluation.field` with one axis pinned), each computed once and
    shared by every map that needs it."""

    def __init__(self, evaluation: Evaluation):
        self.evaluation = evaluation
        self._cache: dict[tuple[str, float], tuple[dict, dict]] = {}

    def errors(self, axis: str, position_mm: float) -> tuple[dict, dict]:
        key = (axis, float(position_mm))
        if key not in self._cache:
            self._cache[key] = self.evaluation.field(fixed={axis: key[1]})
        return self._cache[key]

    def plane(self, fixed_axis: str, position_mm: float, direction: str | None) -> Plane:
        """The total error of ``direction`` (or the volumetric error when None) on the
        plane ``fixed_axis = position_mm``."""
        grids, errors = self.errors(fixed_axis, position_mm)
        k = AXIS_NAMES.index(fixed_axis)
        if direction is None:
            values = np.sqrt(sum(errors[a] ** 2 for a in AXIS_NAMES))  # eq. 3.4
        else:
            values = errors[direction]
        values = np.take(values, 0, axis=k)
        u, v = (a for a in AXIS_NAMES if a != fixed_axis)
        return Plane((u, v), (grids[u], grids[v]), (fixed_axis, float(position_mm)), values)


def worst_extreme(case: CaseResult, direction: str) -> tuple[str, Extreme]:
    """The extreme of a direction with the larger magnitude: ``("max", extreme)`` or
    ``("min", extreme)`` (the maximum when both are equal)."""
    ext = case.axes[direction]
    if abs(ext.minimum.value_um) > abs(ext.maximum.value_um):
        return "min", ext.minimum
    return "max", ext.maximum


def direction_planes(
    result: AnalysisResult, direction: str, slicer: PlaneSlicer | None = None
) -> tuple[str, Extreme, list[Plane]]:
    """The three faces through the largest error of ``direction`` in the worst tool case:
    the planes XY, XZ and YZ at the worst point's Z, Y and X. Returns the extreme's name
    (``"min"``/``"max"``), the extreme, and the planes."""
    case = result.cases[result.worst]
    slicer = slicer or PlaneSlicer(result.evaluation)
    which, ext = worst_extreme(case, direction)
    planes = [slicer.plane(fixed, ext.at[fixed], direction) for fixed in ("Z", "Y", "X")]
    return which, ext, planes


def volumetric_plane(result: AnalysisResult, slicer: PlaneSlicer | None = None) -> Plane:
    """The volumetric error (eq. 3.4) on the plane through the worst point that spans the
    two axes of longest simulated range (ties broken towards keeping the bottom and
    middle axes, so the plane is normal to the top axis)."""
    machine = result.machine
    case = result.cases[result.worst]
    slicer = slicer or PlaneSlicer(result.evaluation)
    rank = {machine.roles[r]: i for i, r in enumerate(("top", "middle", "bottom"))}

    def span(a: str) -> tuple[float, int]:
        lo, hi = machine.axes[a].simulate_mm
        return (hi - lo, rank[a])

    fixed = min(AXIS_NAMES, key=span)
    return slicer.plane(fixed, case.volumetric.at[fixed], None)


def map_surface(
    u: np.ndarray, v: np.ndarray, values: np.ndarray, samples: int = MAP_SAMPLES
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The grid values resampled bilinearly onto an even ``samples`` x ``samples`` grid for
    drawing as an image.

    Bilinear interpolation (linear along each axis in turn) between the computed nodes
    shows a coarse grid smoothly without inventing extremes: every drawn value lies
    between computed ones. Returns ``(u_even, v_even, values_even)``, indexed ``[u, v]``.
    """
    uf = np.linspace(float(u[0]), float(u[-1]), samples)
    vf = np.linspace(float(v[0]), float(v[-1]), samples)
    along_u = np.array([np.interp(uf, u, values[:, j]) for j in range(v.size)]).T
    fine = np.array([np.interp(vf, v, along_u[i, :]) for i in range(uf.size)])
    return uf, vf, fine
