"""ISO 230-4 circular tests of ballbar circles, with their diagnosis.

Definitions (ISO 230-4:2022, clause 3; the same in the 2005 edition): the radial deviation
F is the deviation of the actual path from the nominal radius (largest and smallest,
about the nominal centre: the ballbar's pivot); the circular deviation G is the least
radial separation of two concentric circles enclosing the actual path of one direction
(here about the least-squares centre, ISO 230-4 annex A); the bidirectional circular
deviation G(b) encloses both directions; the circular hysteresis H is the largest radial
difference between the two directions' paths.

A **partial arc** (the largest gap between the angles read wider than
:data:`ARC_GAP_DEG`, such as the 220° arcs of the vertical planes) is evaluated over the
arc: its G, G(b) and H are those of the arc, not of a circle, and the diagnosis gives only
what the arc holds (:mod:`esp.ballbar.diagnosis`).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np

from esp.ballbar.circles import Circle, read_circles
from esp.ballbar.conditions import Conditions
from esp.ballbar.diagnosis import Diagnosis, diagnose

__all__ = [
    "ARC_GAP_DEG",
    "CircleTest",
    "DirectionResult",
    "along_arc",
    "circle_tests",
    "evaluate",
]

#: a gap between the angles wider than this (deg) makes the circle a partial arc
ARC_GAP_DEG = 20.0


@dataclass(frozen=True)
class DirectionResult:
    """One direction of one circle: angles (deg), radial deviation from the nominal
    radius about the nominal centre (µm) and from the least-squares circle (µm)."""

    direction: str
    angle_deg: tuple[float, ...]
    radial_um: tuple[float, ...]
    residual_um: tuple[float, ...]
    F_max_um: float
    F_min_um: float
    G_um: float


@dataclass(frozen=True)
class CircleTest:
    """The ISO 230-4 results of one circle and its diagnosis."""

    circle: Circle
    directions: tuple[DirectionResult, ...]
    G_bidirectional_um: float | None
    H_um: float | None
    centre_offset_um: tuple[float, float]
    diagnosis: Diagnosis

    @property
    def name(self) -> str:
        return self.circle.name

    @property
    def plane(self) -> str:
        return self.circle.plane

    @property
    def radius_mm(self) -> float:
        return self.circle.radius_mm

    @property
    def file(self) -> str:
        return self.circle.file

    @property
    def conditions(self) -> Conditions:
        return self.circle.conditions

    @property
    def F_um(self) -> float:
        """The largest |F| over the directions (µm)."""
        return max(max(abs(d.F_max_um), abs(d.F_min_um)) for d in self.directions)

    @property
    def G_um(self) -> float:
        """The largest G of one direction (µm)."""
        return max(d.G_um for d in self.directions)


def along_arc(angle_deg: np.ndarray, start_deg: float) -> np.ndarray:
    """The angles from the start of an arc (deg, in [0, 360)), a reading a hair before the
    start (angles from positions carry rounding) counted at 0."""
    return (np.asarray(angle_deg) - start_deg + 1e-6) % 360.0 - 1e-6


def _arc(angles_deg: np.ndarray) -> tuple[float, float]:
    """(start, span) of the angles read (deg): (0, 360) for a full circle."""
    t = np.unique(np.round(angles_deg % 360.0, 9))
    if t.size < 2:
        return float(t[0]) if t.size else 0.0, 0.0
    gaps = np.diff(np.r_[t, t[0] + 360.0])
    k = int(np.argmax(gaps))
    spacing = float(np.median(gaps))
    if gaps[k] <= max(ARC_GAP_DEG, 5.0 * spacing):
        return 0.0, 360.0
    start = float(t[(k + 1) % t.size])
    return start, float(360.0 - gaps[k])


def evaluate(circle: Circle) -> CircleTest:
    """The ISO 230-4 values and the diagnosis of one circle."""
    theta = np.concatenate([r.angle_deg for r in circle.runs])
    r = np.concatenate([run.deviation_um for run in circle.runs])
    start, span = _arc(theta)
    full = span >= 360.0
    # the least-squares circle, linearised: r ≈ r0 + a cos θ + b sin θ over both directions
    t = np.radians(theta)
    G3 = np.column_stack([np.ones_like(t), np.cos(t), np.sin(t)])
    coef = np.linalg.lstsq(G3, r, rcond=None)[0]
    rho = r - G3 @ coef
    results = []
    at = 0
    for run in circle.runs:
        n = run.angle_deg.size
        m = slice(at, at + n)
        at += n
        results.append(
            DirectionResult(
                run.direction,
                tuple(float(v) for v in run.angle_deg),
                tuple(float(v) for v in run.deviation_um),
                tuple(float(v) for v in rho[m]),
                float(run.deviation_um.max()),
                float(run.deviation_um.min()),
                float(np.ptp(rho[m])),
            )
        )
    Gb = H = None
    if len(results) == 2:
        Gb = float(np.ptp(rho))
        a, b = results
        if full:
            grid = np.linspace(0.0, 360.0, 721)
            ra = np.interp(grid, a.angle_deg, a.residual_um, period=360.0)
            rb = np.interp(grid, b.angle_deg, b.residual_um, period=360.0)
        else:

            def along(d: DirectionResult) -> tuple[np.ndarray, np.ndarray]:
                phi = along_arc(np.asarray(d.angle_deg), start)
                order = np.argsort(phi)
                return phi[order], np.asarray(d.residual_um)[order]

            pa, va = along(a)
            pb, vb = along(b)
            lo, hi = max(pa[0], pb[0]), min(pa[-1], pb[-1])
            grid = np.linspace(lo, hi, 721)
            ra, rb = np.interp(grid, pa, va), np.interp(grid, pb, vb)
        H = float(np.max(np.abs(ra - rb)))
    return CircleTest(
        circle,
        tuple(results),
        Gb,
        H,
        (float(coef[1]), float(coef[2])),
        diagnose(circle, start, span),
    )


def circle_tests(
    path: str | Path,
    *,
    radius_mm: float | None = None,
    plane: str | None = None,
    conditions: Mapping[str, Any] | None = None,
) -> list[CircleTest]:
    """The ISO 230-4 evaluation of every circle in a ballbar file
    (:func:`esp.ballbar.circles.read_circles`); ``conditions`` (fields of
    :class:`~esp.ballbar.conditions.Conditions`, None for not given) override the file's."""
    circles = read_circles(path, radius_mm=radius_mm, plane=plane)
    if conditions:
        circles = [replace(c, conditions=c.conditions.updated(**conditions)) for c in circles]
    return [evaluate(c) for c in circles]
