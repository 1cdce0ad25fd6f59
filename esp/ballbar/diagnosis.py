"""The diagnosis of a ballbar circle: the machine's errors that shape it, each from its
own signature in the radial deviation (docs/ballbar.md, "Diagnosis").

The deviation δr of the bar's length at the commanded angle θ (in the plane a-b, radius R)
is, to first order, the error vector of the tool against the pivot along the bar:
δr = e_a cos θ + e_b sin θ (Kakino et al. 1993, ch. 3; ISO 230-4:2022, annex A). Each
error of the machine is written as its error vector, which gives its signature; all
signatures are fitted to the readings of every run together by least squares:

* per run: an offset and the set-up's centre (1, cos θ, sin θ);
* scale mismatch ε_a − ε_b (µm/m): e = (ε_a a, ε_b b) gives (R/2)(ε_a − ε_b) cos 2θ;
* out-of-squareness S (µm/m, the tool along +a by S·b): (R S / 2) sin 2θ;
* servo mismatch Δτ = τ_b − τ_a (axis b lags its command by Δτ more than a): e_b =
  −v_b Δτ gives −(s/2) v Δτ sin 2θ, s = +1 ccw, −1 cw: a 45° ellipse that flips with the
  direction; fitted as the lag mismatch v Δτ (µm), in ms when the feed v is stated;
* straightness of axis a as a bow B_a over the diameter (e_b = B_a (1 − (a/R)²)):
  B_a sin³θ; of axis b: B_b cos³θ;
* lobes of order 4 to :data:`LOBE_ORDER` (form the terms above do not explain);
* backlash of axis a at its positive and negative end, b₊ and b₋ (µm): the axis lags half
  the backlash behind its command, b(a) varying linearly between the ends:
  e_a = −½ sgn(v_a) (b₊ (1 + a/R) + b₋ (1 − a/R)) / 2 -- a step of b₊ at θ = 0° and of b₋
  at 180° (90° and 270° for axis b), outward positive; on an arc that reaches one end
  only, the backlash is taken as the same at both;
* lateral play l_a (µm): the carriage of axis a moves across its travel by l when the
  axis reverses, e_b = −½ sgn(v_a) l_a: a kink, not a step, at the reversal, of opposite
  sense in the two directions;
* cyclic error of axis a, e_a = A sin(2π a / p + φ): found by a search over the period p
  (from four reading spacings to R/2), reported with its period and amplitude A.

Readings within :data:`SPIKE_WINDOW_DEG` after an axis reversal (in the order of travel)
are left out of the fit: there a **reversal spike** (the transient of the servo at the
reversal) is the largest residual, reported beyond :data:`SPIKE_COVERAGE` times the scatter
of the other readings within :data:`STICK_WINDOW_DEG` (the noise σ, or a ripple). **Stick-slip**
(the jerky motion of a slow axis) is the ripple of the residuals within
:data:`STICK_WINDOW_DEG` of the axis' reversals, stated as the amplitude of a sinusoid of
the same mean square above the noise σ (of the readings away from every reversal); where
it is found, the readings within that window are left out of the fit too, and the fit is
made again.

A term is reported when it exceeds :data:`COVERAGE` standard uncertainties (σ times the
square root of its diagonal element of (AᵀA)⁻¹; :data:`CYCLIC_COVERAGE` for the searched
cyclic error). The scaling error of the axes (the mean ε in ppm) is the mean radius over
R, given only when the ballbar's length is calibrated (its U stated), with that U in it.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from esp.ballbar.records import Circle

__all__ = [
    "COVERAGE",
    "CYCLIC_COVERAGE",
    "Diagnosis",
    "Term",
    "diagnose",
]

#: a term is reported beyond this many standard uncertainties: with about twenty terms a
#: circle, a circle without errors then reports one with a chance below 0.2 %
COVERAGE = 4.0
#: the cyclic error, found by a search over its period, beyond this many
CYCLIC_COVERAGE = 5.0
#: a reversal spike beyond this many σ (the largest of the readings after a reversal)
SPIKE_COVERAGE = 5.0
#: stick-slip when the mean square near the reversals exceeds σ² by this many of its
#: standard deviations (σ²·√(2/n))
STICK_COVERAGE = 4.0
#: readings this far after a reversal (deg of travel) are left out of the fit
SPIKE_WINDOW_DEG = 5.0
#: the neighbourhood of a reversal where stick-slip is looked for (deg)
STICK_WINDOW_DEG = 10.0
#: a reversal is in the data with 3 readings within this many degrees on each side
REVERSAL_WINDOW_DEG = 30.0
#: the highest order of the lobes fitted as form
LOBE_ORDER = 8
#: the least noise assumed (µm): readings are not taken as finer than 0.01 µm
NOISE_FLOOR_UM = 0.01


@dataclass(frozen=True)
class Term:
    """One term of the diagnosis: its value with standard uncertainty ``u`` in ``unit``,
    whether it is reported (beyond its coverage), or None with ``note`` saying why it is
    not given."""

    key: str
    label: str
    unit: str
    value: float | None
    u: float | None
    reported: bool
    coverage: float = COVERAGE
    note: str = ""
    extra: dict[str, float] = field(default_factory=dict)

    def as_dict(self) -> dict[str, Any]:
        return {
            "key": self.key,
            "label": self.label,
            "unit": self.unit,
            "value": self.value,
            "u": self.u,
            "reported": self.reported,
            "coverage": self.coverage,
            "note": self.note or None,
            **self.extra,
        }


@dataclass(frozen=True)
class Diagnosis:
    """Every term of one circle's diagnosis, the noise σ (µm) they are judged by, the
    arc (start and span, deg; span 360 for a full circle) and notes."""

    terms: tuple[Term, ...]
    noise_um: float
    arc_start_deg: float
    arc_span_deg: float
    notes: tuple[str, ...]

    def term(self, key: str) -> Term:
        for t in self.terms:
            if t.key == key:
                return t
        raise KeyError(key)

    @property
    def full_circle(self) -> bool:
        return self.arc_span_deg >= 360.0


# -- the readings and the signatures ----------------------------------------------------


@dataclass(frozen=True)
class _Data:
    theta: np.ndarray  # rad
    sense: np.ndarray  # +1 ccw, -1 cw
    run: np.ndarray  # run index
    dev: np.ndarray  # µm
    R: float
    a: str
    b: str


#: the reversals: (axis index 0/1, end "+"/"-", angle deg)
_REVERSALS = ((0, "+", 0.0), (0, "-", 180.0), (1, "+", 90.0), (1, "-", 270.0))


def _travel(d: _Data, at_deg: float) -> np.ndarray:
    """The angle travelled since the reversal at ``at_deg`` (deg, negative before it)."""
    return d.sense * ((np.degrees(d.theta) - at_deg + 180.0) % 360.0 - 180.0)


def _sgn_v(d: _Data, axis: int) -> np.ndarray:
    """The sign of the velocity of an axis: v_a ∝ −s sin θ, v_b ∝ s cos θ."""
    if axis == 0:
        return np.sign(-d.sense * np.sin(d.theta))
    return np.sign(d.sense * np.cos(d.theta))


def _coord(d: _Data, axis: int) -> np.ndarray:
    """The coordinate of an axis over R: cos θ or sin θ."""
    return np.cos(d.theta) if axis == 0 else np.sin(d.theta)


def _covered(d: _Data, at_deg: float) -> bool:
    """Whether some run has 3 readings within :data:`REVERSAL_WINDOW_DEG` on each side of
    the reversal at ``at_deg`` (those after it beyond the spike window)."""
    x = _travel(d, at_deg)
    for r in np.unique(d.run):
        m = d.run == r
        before = np.count_nonzero(m & (x < 0) & (x >= -REVERSAL_WINDOW_DEG))
        after = np.count_nonzero(m & (x > SPIKE_WINDOW_DEG) & (x <= REVERSAL_WINDOW_DEG))
        if before >= 3 and after >= 3:
            return True
    return False


def _cyclic_columns(d: _Data, axis: int, k_per_mm: float) -> np.ndarray:
    c = _coord(d, axis)
    phase = 2.0 * np.pi * k_per_mm * d.R * c
    return np.column_stack([c * np.sin(phase), c * np.cos(phase)])


def _columns(d: _Data, covered: dict[tuple[int, str], bool], full: bool) -> dict[str, np.ndarray]:
    """The signature of every term (module docstring), by name; the lobes only on a full
    circle (on an arc they are all but collinear with the ellipse and the bows)."""
    th = d.theta
    cols: dict[str, np.ndarray] = {}
    for r in np.unique(d.run):
        m = (d.run == r).astype(float)
        cols[f"run{r}:offset"] = m
        cols[f"run{r}:centre_a"] = m * np.cos(th)
        cols[f"run{r}:centre_b"] = m * np.sin(th)
    cols["scale_mismatch"] = d.R * 1e-3 / 2.0 * np.cos(2 * th)
    cols["squareness"] = d.R * 1e-3 / 2.0 * np.sin(2 * th)
    if len(np.unique(d.sense)) == 2:
        cols["servo_mismatch"] = -d.sense / 2.0 * np.sin(2 * th)
    cols[f"straightness_{d.a}"] = np.sin(th) ** 3
    cols[f"straightness_{d.b}"] = np.cos(th) ** 3
    for k in range(4, LOBE_ORDER + 1 if full else 4):
        cols[f"lobe{k}:cos"] = np.cos(k * th)
        cols[f"lobe{k}:sin"] = np.sin(k * th)
    names = (d.a, d.b)
    for axis in (0, 1):
        sv = _sgn_v(d, axis)
        c = _coord(d, axis)
        both = covered[(axis, "+")] and covered[(axis, "-")]
        for end, sign in (("+", 1.0), ("-", -1.0)):
            if both:
                cols[f"backlash_{names[axis]}{end}"] = -0.5 * sv * c * (1.0 + sign * c) / 2.0
            elif covered[(axis, end)]:  # the other end outside the arc: taken as the same
                cols[f"backlash_{names[axis]}{end}"] = -0.5 * sv * c
        if covered[(axis, "+")] or covered[(axis, "-")]:
            cols[f"lateral_{names[axis]}"] = -0.5 * sv * _coord(d, 1 - axis)
    return cols


def _fit(A: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    coef = np.linalg.lstsq(A, y, rcond=None)[0]
    return coef, y - A @ coef


def _search_period(
    d: _Data, fit: np.ndarray, A: np.ndarray, axis: int, step_rad: float
) -> tuple[float, np.ndarray] | None:
    """The wavenumber (1/mm) of the cyclic error of an axis that lowers the sum of squares
    most, with its two columns; None when the readings are too sparse."""
    from scipy.optimize import minimize_scalar

    p_min = 4.0 * d.R * step_rad
    p_max = d.R / 2.0
    if p_min >= p_max:
        return None
    _, res = _fit(A[fit], d.dev[fit])
    dk = 1.0 / (16.0 * d.R)
    ks = np.arange(1.0 / p_max, 1.0 / p_min + dk, dk)
    c = _coord(d, axis)[fit]
    best_gain, best_k = -1.0, ks[0]
    for chunk in np.array_split(ks, max(1, ks.size // 200)):
        phase = 2.0 * np.pi * chunk[:, None] * d.R * c[None, :]
        s, co = c * np.sin(phase), c * np.cos(phase)
        s11, s22, s12 = (s * s).sum(1), (co * co).sum(1), (s * co).sum(1)
        b1, b2 = s @ res, co @ res
        det = s11 * s22 - s12**2
        ok = det > 1e-12 * np.maximum(s11 * s22, 1e-300)
        quad = s22 * b1**2 - 2 * s12 * b1 * b2 + s11 * b2**2
        gain = np.where(ok, quad / np.where(ok, det, 1.0), 0.0)
        i = int(np.argmax(gain))
        if gain[i] > best_gain:
            best_gain, best_k = float(gain[i]), float(chunk[i])

    def rss(k: float) -> float:
        B = np.column_stack([A, _cyclic_columns(d, axis, k)])
        return float(np.sum(_fit(B[fit], d.dev[fit])[1] ** 2))

    found = minimize_scalar(
        rss,
        bounds=(max(best_k - dk, 1.0 / p_max), best_k + dk),
        method="bounded",
        options={"xatol": dk * 1e-6},
    )
    k = float(found.x)
    return k, _cyclic_columns(d, axis, k)


def diagnose(circle: Circle, arc_start_deg: float, arc_span_deg: float) -> Diagnosis:
    """The diagnosis of ``circle`` (module docstring)."""
    a, b = circle.plane[0], circle.plane[1]
    R = circle.radius_mm
    d = _Data(
        np.radians(np.concatenate([r.angle_deg for r in circle.runs])),
        np.concatenate([np.full(r.angle_deg.size, r.sense) for r in circle.runs]),
        np.concatenate([np.full(r.angle_deg.size, k) for k, r in enumerate(circle.runs)]),
        np.concatenate([r.deviation_um for r in circle.runs]),
        R,
        a,
        b,
    )
    notes: list[str] = []
    if arc_span_deg < 360.0:
        notes.append(
            f"a partial arc of {arc_span_deg:.0f}° from {arc_start_deg:.0f}°: the terms whose "
            "reversal lies outside it are not given, and the lobes of order 4 and more are "
            "not fitted (on an arc they cannot be told from the ellipse and the bows)"
        )
    covered = {(axis, end): _covered(d, at) for axis, end, at in _REVERSALS}
    cols = _columns(d, covered, arc_span_deg >= 360.0)
    names = list(cols)
    A = np.column_stack([cols[n] for n in names])
    # readings just after a reversal (in the data) are left out of the fit
    spike = np.zeros(d.theta.size, dtype=bool)
    for axis, end, at in _REVERSALS:
        if covered[(axis, end)]:
            x = _travel(d, at)
            spike |= (x > 0) & (x <= SPIKE_WINDOW_DEG)
    fit = ~spike
    step = np.median(np.diff(np.sort(np.unique(d.theta))))
    cyclic: dict[int, float] = {}
    for axis in (0, 1):
        found = _search_period(d, fit, A, axis, float(step))
        if found is None:
            continue
        k, extra = found
        B = np.column_stack([A, extra])
        trial = names + [f"cyclic_{(a, b)[axis]}:s", f"cyclic_{(a, b)[axis]}:c"]
        coef, res = _fit(B[fit], d.dev[fit])
        cov, sigma = _covariance(d, B, fit, res, covered)
        i = len(names)
        amp = float(np.hypot(coef[i], coef[i + 1]))
        u_amp = float(np.sqrt((cov[i, i] + cov[i + 1, i + 1]) / 2.0))
        if amp > CYCLIC_COVERAGE * u_amp:
            A, names = B, trial
            cyclic[axis] = k
    coef, res = _fit(A[fit], d.dev[fit])
    cov, sigma = _covariance(d, A, fit, res, covered)
    stick = _stick_slip(d, d.dev - A @ coef, fit, sigma, covered)
    slipping = [axis for axis, t in enumerate(stick) if t.reported]
    if slipping:
        # a ripple the model does not hold: its readings are left out, as a spike's are
        for axis, _end, at in _REVERSALS:
            if axis in slipping:
                fit = fit & (np.abs(_travel(d, at)) > STICK_WINDOW_DEG)
        coef, res = _fit(A[fit], d.dev[fit])
        cov, sigma = _covariance(d, A, fit, res, covered)
    value = dict(zip(names, coef, strict=True))
    u = dict(zip(names, np.sqrt(np.clip(np.diag(cov), 0.0, None)), strict=True))
    model = A @ coef
    residual = d.dev - model
    terms: list[Term] = []

    def add(key: str, label: str, unit: str, scale: float = 1.0, note: str = "") -> None:
        if key not in value:
            terms.append(Term(key, label, unit, None, None, False, note=note))
            return
        v, uu = float(value[key]) * scale, float(u[key]) * abs(scale)
        terms.append(Term(key, label, unit, v, uu, abs(v) > COVERAGE * uu))

    add("scale_mismatch", f"scale mismatch {a} - {b}", "µm/m")
    _scaling(terms, circle, d, value, u)
    one_way = "servo_mismatch" not in value
    add(
        "squareness",
        f"out-of-squareness {a}{b} (tool along +{a} as {b} grows)",
        "µm/m",
    )
    if one_way:
        notes.append(
            "one direction only: the 45° ellipse of servo mismatch and that of squareness "
            "cannot be told apart; the out-of-squareness stated includes any servo mismatch"
        )
    feed = circle.conditions.feed_mm_per_min
    if one_way:
        add("servo_mismatch", f"servo mismatch ({b} lags {a})", "ms", note="needs both directions")
    elif feed:
        add("servo_mismatch", f"servo mismatch ({b} lags {a})", "ms", scale=60.0 / feed)
    else:
        add(
            "servo_mismatch",
            f"servo mismatch ({b} lags {a}), as lag along the path",
            "µm",
        )
        notes.append("feed not stated: the servo mismatch is given as a lag (µm), not in ms")
    for axis, end, at in _REVERSALS:
        name = (a, b)[axis]
        add(
            f"backlash_{name}{end}",
            f"backlash {name}{end} (step at {at:g}°)",
            "µm",
            note=f"the reversal at {at:g}° is outside the arc; the backlash of {name} is "
            "taken as the same at both ends",
        )
    for axis in (0, 1):
        name, other = (a, b)[axis], (a, b)[1 - axis]
        add(
            f"lateral_{name}",
            f"lateral play of {name} (across, along {other})",
            "µm",
            note=f"no reversal of {name} in the arc",
        )
    terms += _spikes(d, residual, sigma, covered)
    terms += stick
    for axis in (0, 1):
        name, other = (a, b)[axis], (a, b)[1 - axis]
        add(
            f"straightness_{name}",
            f"straightness of {name} (bow over the diameter, along {other})",
            "µm",
        )
    for axis in (0, 1):
        name = (a, b)[axis]
        key = f"cyclic_{name}"
        if axis in cyclic:
            s, c = value[f"{key}:s"], value[f"{key}:c"]
            amp = float(np.hypot(s, c))
            u_amp = float(np.sqrt((u[f"{key}:s"] ** 2 + u[f"{key}:c"] ** 2) / 2.0))
            terms.append(
                Term(
                    key,
                    f"cyclic error of {name}",
                    "µm",
                    amp,
                    u_amp,
                    True,
                    CYCLIC_COVERAGE,
                    extra={"period_mm": 1.0 / cyclic[axis]},
                )
            )
        else:
            terms.append(
                Term(
                    key,
                    f"cyclic error of {name}",
                    "µm",
                    0.0,
                    None,
                    False,
                    CYCLIC_COVERAGE,
                    note=f"none beyond {CYCLIC_COVERAGE:g} u over periods "
                    f"{4.0 * R * float(step):.3g} to {R / 2.0:g} mm",
                )
            )
    return Diagnosis(tuple(terms), sigma, arc_start_deg, arc_span_deg, tuple(notes))


def _far(d: _Data, covered: dict[tuple[int, str], bool]) -> np.ndarray:
    """The readings away from every reversal (beyond the stick-slip window)."""
    near = np.zeros(d.theta.size, dtype=bool)
    for _axis, _end, at in _REVERSALS:
        near |= np.abs(_travel(d, at)) <= STICK_WINDOW_DEG
    return ~near


def _covariance(
    d: _Data,
    A: np.ndarray,
    fit: np.ndarray,
    res: np.ndarray,
    covered: dict[tuple[int, str], bool],
) -> tuple[np.ndarray, float]:
    """σ² (AᵀA)⁻¹ of the fit, σ from the residuals away from the reversals."""
    far = _far(d, covered)[fit]
    n, p = int(np.count_nonzero(far)), A.shape[1]
    share = n / max(res.size, 1)
    dof = max(n - p * share, 1.0)
    sigma = max(float(np.sqrt(np.sum(res[far] ** 2) / dof)) if n else 0.0, NOISE_FLOOR_UM)
    M = A[fit]
    cov = sigma**2 * np.linalg.pinv(M.T @ M)
    return cov, sigma


def _scaling(
    terms: list[Term], circle: Circle, d: _Data, value: dict[str, Any], u: dict[str, Any]
) -> None:
    """The scaling error (mean of the two axes, ppm) from the mean radius, when the bar's
    length is calibrated."""
    runs = np.unique(d.run)
    mean = float(np.mean([value[f"run{r}:offset"] for r in runs]))
    u_fit = float(np.sqrt(np.sum([u[f"run{r}:offset"] ** 2 for r in runs])) / runs.size)
    U_cal = circle.conditions.calibration_U_um
    per = d.R * 1e-3  # µm of radius per µm/m
    label = f"scaling error (mean of {d.a} and {d.b})"
    if U_cal is None:
        terms.append(
            Term(
                "scaling",
                label,
                "ppm",
                None,
                None,
                False,
                note="the ballbar's length is not calibrated (no calibration U stated): "
                "only the scale mismatch is given",
            )
        )
        return
    v = mean / per
    uu = float(np.hypot(u_fit, U_cal / 2.0)) / per
    terms.append(Term("scaling", label, "ppm", v, uu, abs(v) > COVERAGE * uu))


def _spikes(
    d: _Data, residual: np.ndarray, sigma: float, covered: dict[tuple[int, str], bool]
) -> list[Term]:
    out = []
    for axis, end, at in _REVERSALS:
        name = (d.a, d.b)[axis]
        key = f"spike_{name}{end}"
        label = f"reversal spike {name}{end} (at {at:g}°)"
        if not covered[(axis, end)]:
            out.append(
                Term(
                    key,
                    label,
                    "µm",
                    None,
                    None,
                    False,
                    SPIKE_COVERAGE,
                    note=f"the reversal at {at:g}° is outside the arc",
                )
            )
            continue
        x = _travel(d, at)
        window = (x > 0) & (x <= SPIKE_WINDOW_DEG)
        if not window.any():
            out.append(
                Term(
                    key,
                    label,
                    "µm",
                    None,
                    None,
                    False,
                    SPIKE_COVERAGE,
                    note="no reading within the spike window",
                )
            )
            continue
        r = residual[window]
        peak = float(r[int(np.argmax(np.abs(r)))])
        # judged against the scatter near the reversal: the noise, or a stick-slip ripple
        near = (np.abs(x) <= STICK_WINDOW_DEG) & ~window
        scatter = max(sigma, float(np.sqrt(np.mean(residual[near] ** 2))) if near.any() else 0.0)
        out.append(
            Term(
                key,
                label,
                "µm",
                peak,
                scatter,
                abs(peak) > SPIKE_COVERAGE * scatter,
                SPIKE_COVERAGE,
            )
        )
    return out


def _stick_slip(
    d: _Data,
    residual: np.ndarray,
    fit: np.ndarray,
    sigma: float,
    covered: dict[tuple[int, str], bool],
) -> list[Term]:
    out = []
    for axis in (0, 1):
        name = (d.a, d.b)[axis]
        key, label = f"stick_slip_{name}", f"stick-slip of {name} (ripple amplitude)"
        near = np.zeros(d.theta.size, dtype=bool)
        for ax, end, at in _REVERSALS:
            if ax == axis and covered[(ax, end)]:
                near |= np.abs(_travel(d, at)) <= STICK_WINDOW_DEG
        near &= fit
        n = int(np.count_nonzero(near))
        if n < 3:
            out.append(
                Term(
                    key,
                    label,
                    "µm",
                    None,
                    None,
                    False,
                    STICK_COVERAGE,
                    note=f"no reversal of {name} in the arc",
                )
            )
            continue
        ms = float(np.mean(residual[near] ** 2))
        excess = ms - sigma**2
        amp = float(np.sqrt(2.0 * max(excess, 0.0)))
        # the mean square of n readings of noise σ spreads by σ²√(2/n): stick-slip is
        # reported when the excess passes STICK_COVERAGE of that, i.e. the amplitude passes
        threshold = float(np.sqrt(2.0 * STICK_COVERAGE * sigma**2 * np.sqrt(2.0 / n)))
        # u of the amplitude from the spread of the mean square (noise and ripple)
        u_ms = np.sqrt((2.0 * sigma**4 + 4.0 * sigma**2 * max(excess, 0.0)) / n)
        u_amp = float(u_ms / max(amp, sigma))
        out.append(
            Term(
                key,
                label,
                "µm",
                amp,
                u_amp,
                amp > threshold,
                STICK_COVERAGE,
                extra={"mean_square_um2": ms, "threshold_um": threshold},
            )
        )
    return out
