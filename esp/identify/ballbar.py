"""ISO 230-4 circular tests from a ballbar file, with a first-order diagnosis.

The file is the lengths table of ``esp identify`` (docs/formats.md): per reading the
commanded position, the nominal centre and length, the deviation of the measured length
(µm) and, for a bidirectional test, the direction (``ccw``/``cw``). Each circle (label) is
evaluated in its own plane, with the angle θ measured from the first axis of the plane.

Definitions (ISO 230-4:2005, clause 3): the radial deviation F is the deviation of the
actual path from the nominal radius (largest and smallest, about the nominal centre); the
circular deviation G is the least radial separation of two concentric circles enclosing
the actual path of one direction (here about the least-squares centre, ISO 230-4 annex A);
the bidirectional circular deviation G(b) encloses both directions; the circular
hysteresis H is the largest radial difference between the two directions' paths.

Diagnosis (first order, in the plane a-b of the circle, radius R): with the least-squares
centre removed, the radial deviation is r(θ) = c₂ cos 2θ + s₂ sin 2θ + ...; a scale
difference of the two axes gives c₂ = R (ε_a - ε_b) / 2, an out-of-squareness S (the tool
displaced along +a by S·b) gives s₂ = S R / 2 (ISO 230-4:2005 annex B; Kakino et al. 1993,
ch. 3). Backlash and lost motion show as steps of the radial deviation where an axis
reverses (θ = 0° and 180° for b, 90° and 270° for a).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from esp.core.errors import ParseError
from esp.identify.tables import read_table

if TYPE_CHECKING:
    from matplotlib.figure import Figure

__all__ = ["CircleTest", "DirectionResult", "circle_tests"]


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

    name: str
    plane: str
    centre_mm: tuple[float, float, float]
    radius_mm: float
    directions: tuple[DirectionResult, ...]
    G_bidirectional_um: float | None
    H_um: float | None
    centre_offset_um: tuple[float, float]
    scale_difference_um_per_m: float
    squareness_um_per_m: float
    reversal_steps_um: dict
    file: str


def _plane(D: np.ndarray) -> tuple[str, int, int]:
    spread = np.ptp(D, axis=0)
    order = np.argsort(-spread)[:2]
    i, j = sorted(int(k) for k in order)
    return "XYZ"[i] + "XYZ"[j], i, j


def _step(
    theta: np.ndarray, rho: np.ndarray, at: float, forward: bool, width: float = 10.0
) -> float:
    d = (theta - at + 180.0) % 360.0 - 180.0
    if not forward:
        d = -d
    after = rho[(d > 0) & (d <= width)]
    before = rho[(d < 0) & (d >= -width)]
    if after.size == 0 or before.size == 0:
        return float("nan")
    return float(np.median(after) - np.median(before))


def circle_tests(path: str | Path) -> list[CircleTest]:
    """The ISO 230-4 evaluation of every circle in a ballbar file."""
    table = read_table(
        path,
        ("X", "Y", "Z", "cx", "cy", "cz", "length_mm", "deviation_um"),
        ("circle",),
        (),
        ("direction",),
    )
    P = np.column_stack([table.columns[c] for c in ("X", "Y", "Z")])
    C = np.column_stack([table.columns[c] for c in ("cx", "cy", "cz")])
    L = np.asarray(table.columns["length_mm"])
    dev = np.asarray(table.columns["deviation_um"])
    labels = table.columns["circle"]
    dirs = table.columns["direction"] if table.has("direction") else ("ccw",) * len(table)
    out = []
    for name in dict.fromkeys(labels):
        idx = np.array([i for i, g in enumerate(labels) if g == name])
        if idx.size < 8:
            raise table.fail(
                int(idx[0]), f"circle {name!r} has {idx.size} readings; expected 8 or more"
            )
        centre = C[idx[0]]
        radius = float(L[idx[0]])
        D = P[idx] - centre
        plane, i, j = _plane(D)
        theta = np.degrees(np.arctan2(D[:, j], D[:, i])) % 360.0
        r = dev[idx]
        # least-squares circle, linearised: r ≈ r0 + a cos θ + b sin θ (+ order 2 for the
        # diagnosis, fitted over both directions together)
        t = np.radians(theta)
        G2 = np.column_stack([np.ones_like(t), np.cos(t), np.sin(t), np.cos(2 * t), np.sin(2 * t)])
        coef = np.linalg.lstsq(G2, r, rcond=None)[0]
        rho = r - G2[:, :3] @ coef[:3]
        results = []
        directions = [dirs[k] for k in idx]
        for d in dict.fromkeys(directions):
            m = np.array([x == d for x in directions])
            order = np.argsort(theta[m])
            results.append(
                DirectionResult(
                    d,
                    tuple(float(v) for v in theta[m][order]),
                    tuple(float(v) for v in r[m][order]),
                    tuple(float(v) for v in rho[m][order]),
                    float(r[m].max()),
                    float(r[m].min()),
                    float(np.ptp(rho[m])),
                )
            )
        Gb = H = None
        if len(results) == 2:
            Gb = float(np.ptp(rho))
            grid = np.linspace(0.0, 360.0, 721)
            a, b = results
            ra = np.interp(grid, a.angle_deg, a.residual_um, period=360.0)
            rb = np.interp(grid, b.angle_deg, b.residual_um, period=360.0)
            H = float(np.max(np.abs(ra - rb)))
        steps = {}
        for axis, angles in ((plane[1], (0.0, 180.0)), (plane[0], (90.0, 270.0))):
            vals = []
            for res in results:
                th = np.asarray(res.angle_deg)
                rr = np.asarray(res.residual_um)
                forward = res.direction.lower() not in ("cw", "clockwise", "-")
                vals += [_step(th, rr, at, forward) for at in angles]
            vals = [v for v in vals if np.isfinite(v)]
            steps[axis] = float(np.mean(np.abs(vals))) if vals else float("nan")
        out.append(
            CircleTest(
                str(name),
                plane,
                (float(centre[0]), float(centre[1]), float(centre[2])),
                radius,
                tuple(results),
                Gb,
                H,
                (float(coef[1]), float(coef[2])),
                2.0 * float(coef[3]) / radius * 1000.0,
                2.0 * float(coef[4]) / radius * 1000.0,
                steps,
                table.path,
            )
        )
    if not out:
        raise ParseError(path, None, "no circle found")
    return out


def ballbar_dict(tests: list[CircleTest]) -> dict[str, Any]:
    return {
        "schema": "esp.ballbar/1",
        "circles": [
            {
                "name": t.name,
                "file": t.file,
                "plane": t.plane,
                "centre_mm": list(t.centre_mm),
                "radius_mm": t.radius_mm,
                "directions": [
                    {
                        "direction": d.direction,
                        "F_max_um": d.F_max_um,
                        "F_min_um": d.F_min_um,
                        "G_um": d.G_um,
                    }
                    for d in t.directions
                ],
                "G_bidirectional_um": t.G_bidirectional_um,
                "H_um": t.H_um,
                "diagnosis": {
                    "centre_offset_um": list(t.centre_offset_um),
                    "scale_difference_um_per_m": t.scale_difference_um_per_m,
                    "squareness_um_per_m": t.squareness_um_per_m,
                    "reversal_steps_um": {
                        k: (v if np.isfinite(v) else None) for k, v in t.reversal_steps_um.items()
                    },
                },
            }
            for t in tests
        ],
    }


def ballbar_text(tests: list[CircleTest]) -> str:
    out = ["esp ballbar: ISO 230-4 circular tests", ""]
    for t in tests:
        a, b = t.plane[0], t.plane[1]
        centre = ", ".join(f"{v:g}" for v in t.centre_mm)
        out.append(f"Circle {t.name} in {t.plane}, centre ({centre}) mm, radius {t.radius_mm:g} mm")
        for d in t.directions:
            out.append(
                f"  {d.direction:<4} radial deviation F {d.F_min_um:+.3f} .. {d.F_max_um:+.3f} um, "
                f"circular deviation G {d.G_um:.3f} um"
            )
        if t.G_bidirectional_um is not None:
            out.append(
                f"  bidirectional circular deviation G(b) {t.G_bidirectional_um:.3f} um, "
                f"circular hysteresis H {t.H_um:.3f} um"
            )
        out.append(
            f"  diagnosis: scale difference {a} - {b} {t.scale_difference_um_per_m:+.2f} um/m; "
            f"out-of-squareness {t.squareness_um_per_m:+.2f} um/m (tool along +{a} as {b} grows)"
        )
        steps = ", ".join(
            f"{k} {v:.3f} um" for k, v in t.reversal_steps_um.items() if np.isfinite(v)
        )
        if steps:
            out.append(f"  reversal steps (backlash, lost motion): {steps}")
        out.append(
            f"  centre offset of the least-squares circle ({a}, {b}): "
            f"{t.centre_offset_um[0]:+.3f}, {t.centre_offset_um[1]:+.3f} um"
        )
        out.append("")
    return "\n".join(out)


def polar_figure(tests: list[CircleTest], magnify_um_per_mm: float | None = None) -> Figure:
    """Each circle's radial deviation on a polar plot (deviations magnified about a ring)."""
    import math

    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    n = len(tests)
    cols = min(3, n)
    rows = math.ceil(n / cols)
    fig = Figure(figsize=(4.0 * cols, 4.0 * rows), dpi=100, layout="constrained")
    FigureCanvasAgg(fig)
    for k, t in enumerate(tests):
        ax = fig.add_subplot(rows, cols, k + 1, projection="polar")
        span = max(max(abs(v) for v in d.radial_um) for d in t.directions) or 1.0
        ring = 2.0 * span
        for m, d in enumerate(t.directions):
            th = np.radians(np.r_[d.angle_deg, d.angle_deg[0]])
            rr = np.r_[d.radial_um, d.radial_um[0]] + ring
            ax.plot(th, rr, linewidth=1.0, color=f"C{m}", label=d.direction)
        ax.plot(np.linspace(0, 2 * np.pi, 200), np.full(200, ring), color="0.6", linewidth=0.6)
        ax.set_ylim(0, ring + span * 1.2)
        ax.set_yticks(
            [ring - span, ring, ring + span], [f"{-span:.2g}", "0", f"{span:.2g} µm"], fontsize=7
        )
        G = t.G_bidirectional_um if t.G_bidirectional_um is not None else t.directions[0].G_um
        ax.set_title(f"{t.name} ({t.plane}), G {G:.2f} µm", fontsize=9)
        ax.legend(fontsize=7, loc="lower right")
    return fig
