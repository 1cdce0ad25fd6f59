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
reverses: a at θ = 0° and 180° (the ends of the circle along a, where the radial direction
is a), b at 90° and 270° (Kakino et al. 1993, ch. 3). A step is measured within one run, in
its order of travel, against the smooth trend of its neighbours: the readings within
:data:`STEP_WINDOW_DEG` on either side are fitted with a cubic in the angle plus a jump at
the reversal, so that an ellipse, lobes or an offset between the runs (all smooth within
one run) give no step. The noise is the pooled standard deviation of those local fits (at
least :data:`NOISE_FLOOR_UM`); an axis' step (the mean over its reversals and runs) is
reported when it exceeds :data:`STEP_COVERAGE` standard uncertainties.

Every reading is checked when read (:func:`esp.core.values.check`): positions and centres
within ±100 m, the length above 0 and at most 100 m, deviations within ±10 mm; one centre
and one length per circle; each position at the stated length from the centre (within
:data:`LENGTH_TOLERANCE` of it, at least 1 µm) and in the plane of the centre; no position
twice in one run; ``direction`` ``ccw`` or ``cw`` (θ increasing or decreasing).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from esp.core.errors import ParseError
from esp.core.values import QUANTITIES, Quantity, ValueRefused, check, written
from esp.identify.tables import Table, read_table

if TYPE_CHECKING:
    from matplotlib.figure import Figure

__all__ = ["CircleTest", "DirectionResult", "circle_tests"]

#: the half-width of the neighbourhood of a reversal whose trend a step is measured against
STEP_WINDOW_DEG = 30.0
#: the least noise assumed (µm): readings are not taken as finer than 0.01 µm
NOISE_FLOOR_UM = 0.01
#: a step is reported beyond this many standard uncertainties
STEP_COVERAGE = 3.0
#: the positions lie at the stated length from the centre within this fraction of it
LENGTH_TOLERANCE = 1e-3
#: the direction labels: θ increasing (ccw) or decreasing (cw) along the run
DIRECTIONS = ("ccw", "cw")

_LENGTH = Quantity("a ballbar length", "mm", 0.0, 1e5, above_low=True)
_QUANTITY: dict[str, str | Quantity] = {
    "X": "position",
    "Y": "position",
    "Z": "position",
    "cx": "position",
    "cy": "position",
    "cz": "position",
    "length_mm": _LENGTH,
    "deviation_um": "displacement",
}


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
    #: per axis the mean step at its reversals (µm, outward positive), NaN without data
    reversal_steps_um: dict
    file: str
    #: per axis the standard uncertainty of the step (µm)
    reversal_step_u_um: dict | None = None
    #: the noise the steps are judged against (µm, standard deviation of one reading)
    reversal_noise_um: float = float("nan")

    def reversal_reported(self, axis: str) -> bool:
        """True when the step of ``axis`` exceeds :data:`STEP_COVERAGE` standard
        uncertainties."""
        v = self.reversal_steps_um.get(axis, float("nan"))
        u = (self.reversal_step_u_um or {}).get(axis, float("nan"))
        return bool(np.isfinite(v) and np.isfinite(u) and abs(v) > STEP_COVERAGE * u)


def _plane(D: np.ndarray) -> tuple[str, int, int]:
    spread = np.ptp(D, axis=0)
    order = np.argsort(-spread)[:2]
    i, j = sorted(int(k) for k in order)
    return "XYZ"[i] + "XYZ"[j], i, j


def _step(
    theta: np.ndarray, rho: np.ndarray, at: float, increasing: bool
) -> tuple[float, float, float, int] | None:
    """The jump of ``rho`` at the angle ``at`` along the run (after minus before, in its
    order of travel) against a cubic trend of the readings within :data:`STEP_WINDOW_DEG`:
    (step, its variance factor, the sum of squared residuals, degrees of freedom), or None
    with fewer than 3 readings on a side."""
    d = (theta - at + 180.0) % 360.0 - 180.0
    if not increasing:
        d = -d
    near = (np.abs(d) <= STEP_WINDOW_DEG + 1e-6) & (d != 0.0)
    after = int(np.count_nonzero(near & (d > 0)))
    before = int(np.count_nonzero(near & (d < 0)))
    if after < 3 or before < 3:
        return None
    x = np.radians(d[near])
    y = rho[near]
    degree = 3 if x.size >= 8 else 1
    # an axis' backlash b moves the radial deviation by ±(b/2) cos of the angle from the
    # reversal: its jump is b (x > 0) cos x plus a smooth term
    A = np.column_stack([x**k for k in range(degree + 1)] + [(x > 0) * np.cos(x)])
    Q, Rm = np.linalg.qr(A)
    coef = np.linalg.solve(Rm, Q.T @ y)
    res = y - A @ coef
    Rinv = np.linalg.inv(Rm)
    factor = float(Rinv[-1] @ Rinv[-1])  # (AᵀA)⁻¹ of the step
    return float(coef[-1]), factor, float(res @ res), x.size - A.shape[1]


def _reversal_steps(
    results: list[DirectionResult], plane: str
) -> tuple[dict[str, float], dict[str, float], float]:
    """Per axis of ``plane`` the mean step at its reversals over the runs, its standard
    uncertainty, and the pooled noise (module docstring)."""
    found: dict[str, list[tuple[float, float]]] = {plane[0]: [], plane[1]: []}
    ss = 0.0
    dof = 0
    for axis, angles in ((plane[0], (0.0, 180.0)), (plane[1], (90.0, 270.0))):
        for res in results:
            th = np.asarray(res.angle_deg)
            rr = np.asarray(res.residual_um)
            for at in angles:
                one = _step(th, rr, at, res.direction.lower() == "ccw")
                if one is None:
                    continue
                found[axis].append((one[0], one[1]))
                ss += one[2]
                dof += one[3]
    noise = max(float(np.sqrt(ss / dof)) if dof > 0 else 0.0, NOISE_FLOOR_UM)
    steps: dict[str, float] = {}
    u: dict[str, float] = {}
    for axis, vals in found.items():
        if not vals:
            steps[axis] = u[axis] = float("nan")
            continue
        v = np.array(vals)
        steps[axis] = float(np.mean(v[:, 0]))
        u[axis] = float(noise * np.sqrt(np.sum(v[:, 1])) / len(v))
    return steps, u, noise


def _check_readings(table: Table) -> None:
    """Every number through the one value check, then the circle's own rules (module
    docstring); a refusal names the file, the line, what was expected and what found."""
    for column, quantity in _QUANTITY.items():
        q = QUANTITIES[quantity] if isinstance(quantity, str) else quantity
        values = np.asarray(table.columns[column], dtype=float)
        # the readings check() would refuse, found at once; check() words the refusal
        low = values <= q.low if q.above_low else values < q.low
        for r in np.flatnonzero(~np.isfinite(values) | low | (values > q.high))[:1]:
            try:
                check(float(values[r]), q, given=written(values[r]))
            except ValueRefused as exc:
                raise table.fail(int(r), f"column {column}: {exc.message}") from None
    if table.has("direction"):
        for r, d in enumerate(table.columns["direction"]):
            if d.lower() not in DIRECTIONS:
                raise table.fail(r, f"column direction: expected ccw or cw, found {d[:40]!r}")


def check_length(
    table: Table, name: str, idx: np.ndarray, P: np.ndarray, centre: np.ndarray, length: float
) -> float:
    """Refuse the first position of circle ``name`` (rows ``idx`` of ``P``, mm) that is not
    ``length`` mm from ``centre`` within :data:`LENGTH_TOLERANCE` of it (at least 1 µm),
    naming its file and line; return that tolerance (mm)."""
    tol = max(LENGTH_TOLERANCE * length, 1e-3)
    dist = np.sqrt(np.sum((P[idx] - centre) ** 2, axis=1))
    off = np.flatnonzero(np.abs(dist - length) > tol)
    if off.size:
        raise table.fail(
            int(idx[off[0]]),
            f"circle {name!r}: expected the position at length_mm {written(length)} mm "
            f"from the centre (within {tol:.3g} mm), found {dist[off[0]]:.6g} mm",
        )
    return tol


def _check_circle(
    table: Table,
    name: str,
    idx: np.ndarray,
    P: np.ndarray,
    C: np.ndarray,
    L: np.ndarray,
    runs: list[str],
) -> None:
    for k in idx[1:]:
        if not np.array_equal(C[k], C[idx[0]]):
            raise table.fail(
                int(k),
                f"circle {name!r}: expected one centre "
                f"({', '.join(written(v) for v in C[idx[0]])}) mm as on line "
                f"{int(table.lines[idx[0]])}, found ({', '.join(written(v) for v in C[k])})",
            )
        if L[k] != L[idx[0]]:
            raise table.fail(
                int(k),
                f"circle {name!r}: expected one length_mm {written(L[idx[0]])} as on line "
                f"{int(table.lines[idx[0]])}, found {written(L[k])}",
            )
    length = float(L[idx[0]])
    tol = check_length(table, name, idx, P, C[idx[0]], length)
    D = P[idx] - C[idx[0]]
    _, i, j = _plane(D)
    normal = 3 - i - j
    tilt = np.flatnonzero(np.abs(D[:, normal]) > tol)
    if tilt.size:
        k = int(idx[tilt[0]])
        axis = "XYZ"[normal]
        raise table.fail(
            k,
            f"circle {name!r}: expected the position in the plane {'XYZ'[i]}{'XYZ'[j]} of the "
            f"centre ({axis} = {written(C[k, normal])} mm, within {tol:.3g} mm), found "
            f"{axis} = {written(P[k, normal])} mm",
        )
    seen: dict[tuple[str, float, float, float], int] = {}
    for k in idx:
        key = (runs[k], *(round(float(v), 6) for v in P[k]))
        if key in seen:
            raise table.fail(
                int(k),
                f"circle {name!r}: expected each position once in a run, found "
                f"({', '.join(written(v) for v in P[k])}) mm again (also on line "
                f"{int(table.lines[seen[key]])})",
            )
        seen[key] = int(k)


def circle_tests(path: str | Path) -> list[CircleTest]:
    """The ISO 230-4 evaluation of every circle in a ballbar file."""
    table = read_table(
        path,
        ("X", "Y", "Z", "cx", "cy", "cz", "length_mm", "deviation_um"),
        ("circle",),
        (),
        ("direction",),
    )
    _check_readings(table)
    P = np.column_stack([table.columns[c] for c in ("X", "Y", "Z")])
    C = np.column_stack([table.columns[c] for c in ("cx", "cy", "cz")])
    L = np.asarray(table.columns["length_mm"])
    dev = np.asarray(table.columns["deviation_um"])
    labels = table.columns["circle"]
    dirs = (
        tuple(d.lower() for d in table.columns["direction"])
        if table.has("direction")
        else ("ccw",) * len(table)
    )
    out = []
    for name in dict.fromkeys(labels):
        idx = np.array([i for i, g in enumerate(labels) if g == name])
        for d in dict.fromkeys(dirs[k] for k in idx):
            run = [k for k in idx if dirs[k] == d]
            if len(run) < 8:
                raise table.fail(
                    int(run[0]),
                    f"circle {name!r} has {len(run)} readings in direction {d}; expected 8 or more",
                )
        _check_circle(table, str(name), idx, P, C, L, list(dirs))
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
        steps, steps_u, noise = _reversal_steps(results, plane)
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
                steps_u,
                noise,
            )
        )
    if not out:
        raise ParseError(path, None, "no circle found")
    return out


def _finite(v: float) -> float | None:
    return float(v) if np.isfinite(v) else None


def _steps_text(t: CircleTest) -> str:
    """The reversal steps of a circle: those beyond :data:`STEP_COVERAGE` standard
    uncertainties, else "none", with the estimates and the noise they were judged by."""
    u = t.reversal_step_u_um or {}
    est = [
        f"{k} {v:+.3f} ± {u.get(k, float('nan')):.3f}"
        for k, v in t.reversal_steps_um.items()
        if np.isfinite(v)
    ]
    if not est:
        return (
            "  reversal steps (backlash, lost motion): not measured (fewer than 3 readings "
            f"within {STEP_WINDOW_DEG:g} degrees on a side of each reversal)"
        )
    shown_steps = [
        f"{k} {v:+.3f} um" for k, v in t.reversal_steps_um.items() if t.reversal_reported(k)
    ]
    head = ", ".join(shown_steps) if shown_steps else "none"
    return (
        f"  reversal steps (backlash, lost motion): {head} "
        f"(estimates {', '.join(est)} um; reported beyond {STEP_COVERAGE:g} u, "
        f"noise {t.reversal_noise_um:.3f} um)"
    )


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
                        k: (v if t.reversal_reported(k) else None)
                        for k, v in t.reversal_steps_um.items()
                    },
                    "reversal_step_estimates_um": {
                        k: {
                            "step": _finite(v),
                            "u": _finite((t.reversal_step_u_um or {}).get(k, float("nan"))),
                        }
                        for k, v in t.reversal_steps_um.items()
                    },
                    "reversal_noise_um": _finite(t.reversal_noise_um),
                    "reversal_coverage": STEP_COVERAGE,
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
        out.append(_steps_text(t))
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
