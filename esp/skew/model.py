"""Squareness and scale of a machine's axes from a workshop's measurements (docs/skew.md).

Two kinds of measurement give the same result, a :class:`SkewResult`:

* :func:`from_squares`: the diagonals AC, BD and the side AD (optionally AB) of a square the
  machine made -- printed, cut or engraved -- measured with a caliper or a rule, one square
  per plane. Corner names as Marlin's configuration names them: A at the origin, D along the
  plane's first axis, B along its second, C opposite A.
* :func:`from_points`: points of a part or a plate, their nominal coordinates and their
  measured ones -- a part the machine made and a reference instrument measured (``made``),
  or a calibrated artefact the machine probed (``probed``).

**The model.** The machine moves the tool by ``M·c`` when commanded ``c`` (a displacement),
where the columns of ``M`` are the directions of the axes' motions, each of length
``1 + scale``. Squareness of a pair (E, L), E the earlier axis, is ``S_EL = cot θ_EL`` with
``θ_EL`` the included angle between the +E and +L motions: positive below 90°, as esp's
squareness (docs/conventions.md); to first order it is the displacement along E per unit of
travel along L. Scale and squareness are properties of the columns alone (their lengths and
angles), so they are independent of how the part lay on the table or the plate on the
machine -- the placement (a rotation and a translation) needs no fitting of its own.

For a square of side a (along E) and b (along L) with included angle θ, the law of cosines
gives ``AC² = a² + b² + 2ab·cos θ`` and ``BD² = a² + b² − 2ab·cos θ``, so
``cos θ = (AC² − BD²) / (4·AB·AD)`` and ``AB² = (AC² + BD²)/2 − AD²`` (the parallelogram law,
which is how Marlin's configuration computes AB). Marlin's factor ``tan(π/2 − θ)`` is
``cot θ``: esp's squareness and Marlin's factor are one number.

Uncertainty (JCGM 100:2008, the GUM): each length's standard uncertainty combines the
caliper's resolution r (rectangular, r/√12), its maximum permissible error a (rectangular,
a/√3) and, for a length read several times, the standard deviation of the mean (type A,
n − 1 degrees of freedom); the readings' errors are taken as independent, which over-states
u(S) when the caliper's error is the same for AC and BD (it cancels in AC² − BD²). The
sensitivities are evaluated numerically (GUM 5.1.3, note 2); effective degrees of freedom by
Welch–Satterthwaite (GUM G.4.1) and the coverage factor for about 95 % (GUM G.3).

NumPy only.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Literal

import numpy as np

from esp.core.errors import ConfigError, DataError
from esp.core.uncertainty.gum import coverage_factor, welch_satterthwaite

__all__ = [
    "AXES",
    "PLANES",
    "Caliper",
    "Estimate",
    "Length",
    "PointSet",
    "Quantity",
    "SkewResult",
    "Square",
    "SquarePlane",
    "from_points",
    "from_squares",
    "machine_matrix",
]

AXES = ("X", "Y", "Z")
#: planes in esp's order: the earlier axis first (docs/conventions.md)
PLANES = ("XY", "XZ", "YZ")
#: the coverage probability of every U this command states
COVERAGE = 0.9545
#: a squareness beyond this (cot θ, about 11°) is not a square: refused
MAX_SQUARENESS = 0.2
#: a scale error beyond this (20 %) is refused
MAX_SCALE = 0.2

Kind = Literal["made", "probed"]


@dataclass(frozen=True)
class Quantity:
    """What an estimate is of: ``squareness`` of a plane (``XY``) or ``scale`` of an axis."""

    kind: Literal["squareness", "scale"]
    name: str

    def __str__(self) -> str:
        return f"{self.kind} {self.name}"


@dataclass(frozen=True)
class Estimate:
    """One result: its value (a ratio: µm/m × 1e-6), standard uncertainty and degrees of
    freedom; U = k·u with k for about 95 % at those degrees of freedom."""

    quantity: Quantity
    value: float
    u: float
    dof: float

    @property
    def k(self) -> float:
        return coverage_factor(COVERAGE, self.dof) if self.u > 0 else 2.0

    @property
    def expanded(self) -> float:
        return self.k * self.u

    @property
    def value_um_per_m(self) -> float:
        return self.value * 1e6

    @property
    def expanded_um_per_m(self) -> float:
        return self.expanded * 1e6

    @property
    def significant(self) -> bool:
        """Whether the value lies beyond its U (a correction shown to help)."""
        return abs(self.value) > self.expanded


@dataclass(frozen=True)
class Caliper:
    """The instrument the lengths were read with: resolution and maximum permissible
    error (±), both in mm."""

    resolution_mm: float = 0.01
    accuracy_mm: float = 0.02

    @property
    def u_mm(self) -> float:
        return math.hypot(self.resolution_mm / math.sqrt(12.0), self.accuracy_mm / math.sqrt(3.0))


@dataclass(frozen=True)
class Length:
    """A length as read: one or more readings of it (mm)."""

    name: str
    readings_mm: tuple[float, ...]

    @property
    def mean_mm(self) -> float:
        return float(np.mean(self.readings_mm))

    def type_a(self) -> tuple[float, float]:
        """(u of the mean, degrees of freedom); (0, inf) for a single reading."""
        n = len(self.readings_mm)
        if n < 2:
            return 0.0, math.inf
        return float(np.std(self.readings_mm, ddof=1)) / math.sqrt(n), float(n - 1)


@dataclass(frozen=True)
class Square:
    """The lengths of one square made in ``plane``: AC, BD, AD and optionally AB, with the
    commanded side ``nominal_mm`` when the scale of the axes is wanted."""

    plane: str
    ac: Length
    bd: Length
    ad: Length
    ab: Length | None = None
    nominal_mm: float | None = None


@dataclass(frozen=True)
class SquarePlane:
    """What one square gave: AB (measured or from the parallelogram law), the included
    angle, and how far the four lengths miss a parallelogram when AB was measured."""

    square: Square
    ab_mm: float
    ab_computed: bool
    angle_deg: float
    parallelogram_misfit_mm: float | None


@dataclass(frozen=True)
class PointSet:
    """Points with nominal and measured coordinates (mm) on ``axes`` (two or three of X, Y,
    Z), from ``path`` (named in errors), with the lines the points came from."""

    axes: tuple[str, ...]
    nominal_mm: np.ndarray
    measured_mm: np.ndarray
    kind: Kind
    path: str = ""
    lines: tuple[int, ...] = ()
    point_u_um: float | None = None


@dataclass(frozen=True)
class SkewResult:
    """Squareness per plane and scale per axis, each with its U, and how they were
    measured. ``estimates`` holds only what was measured."""

    source: Literal["square", "points"]
    kind: Kind
    estimates: tuple[Estimate, ...]
    caliper: Caliper | None = None
    planes: tuple[SquarePlane, ...] = ()
    points: PointSet | None = None
    residual_um: float | None = None
    residual_dof: int | None = None
    warnings: tuple[str, ...] = field(default=())

    def get(self, kind: str, name: str) -> Estimate | None:
        for e in self.estimates:
            if e.quantity.kind == kind and e.quantity.name == name:
                return e
        return None

    def squareness(self) -> dict[str, float]:
        return {e.quantity.name: e.value for e in self.estimates if e.quantity.kind == "squareness"}

    def scales(self) -> dict[str, float]:
        return {e.quantity.name: e.value for e in self.estimates if e.quantity.kind == "scale"}

    def matrix(self) -> np.ndarray:
        """The machine's motion matrix ``M`` (3×3) of these estimates; what was not
        measured is taken as nominal (square, scale 1)."""
        return machine_matrix(self.squareness(), self.scales())


def machine_matrix(squareness: Mapping[str, float], scales: Mapping[str, float]) -> np.ndarray:
    """The exact motion matrix of a machine whose axes have the included angles
    ``θ = acot(S)`` and the lengths ``1 + scale``: X along x, Y in the xy plane, Z completing
    the three angles -- an upper-triangular matrix, the frame in which the firmware's skew
    corrections are written."""
    c = {p: _cos_from_squareness(squareness.get(p, 0.0)) for p in PLANES}
    s_xy = math.sqrt(1.0 - c["XY"] ** 2)
    a = (c["YZ"] - c["XY"] * c["XZ"]) / s_xy
    b2 = 1.0 - c["XZ"] ** 2 - a * a
    if not b2 > 0.0:
        raise DataError("the three squareness values do not describe three axes in space")
    columns = (
        np.array([1.0, 0.0, 0.0]),
        np.array([c["XY"], s_xy, 0.0]),
        np.array([c["XZ"], a, math.sqrt(b2)]),
    )
    m = np.column_stack(
        [col * (1.0 + scales.get(ax, 0.0)) for col, ax in zip(columns, AXES, strict=True)]
    )
    return m


def _cos_from_squareness(s: float) -> float:
    return s / math.sqrt(1.0 + s * s)


def _cot_between(u: np.ndarray, v: np.ndarray) -> float:
    """cot of the angle between two vectors (2 or 3 components)."""
    dot = float(np.dot(u, v))
    if u.size == 2:
        cross = abs(float(u[0] * v[1] - u[1] * v[0]))
    else:
        cross = float(np.linalg.norm(np.cross(u, v)))
    return dot / cross


def _square_values(x: np.ndarray, has_ab: bool, nominal: float | None) -> np.ndarray:
    """(S, scale of the first axis, scale of the second) from the lengths
    (AC, BD, AD[, AB]) of one square; scales NaN without a nominal side."""
    ac, bd, ad = x[0], x[1], x[2]
    ab = x[3] if has_ab else math.sqrt((ac * ac + bd * bd) / 2.0 - ad * ad)
    cos_t = (ac * ac - bd * bd) / (4.0 * ab * ad)
    s = cos_t / math.sqrt(1.0 - cos_t * cos_t)
    if nominal is None:
        return np.array([s, math.nan, math.nan])
    return np.array([s, ad / nominal - 1.0, ab / nominal - 1.0])


def _jacobian(f: Callable[[np.ndarray], np.ndarray], x: np.ndarray) -> np.ndarray:
    """Central differences, steps of 1e-6 of each input's size (GUM 5.1.3, note 2)."""
    cols = []
    for i in range(x.size):
        h = 1e-6 * max(abs(float(x[i])), 1.0)
        up, down = x.copy(), x.copy()
        up[i] += h
        down[i] -= h
        cols.append((f(up) - f(down)) / (2.0 * h))
    return np.column_stack(cols)


def _check_square(sq: Square, where: str) -> None:
    if sq.plane not in PLANES:
        raise ConfigError(where, f"expected a plane XY, XZ or YZ, found {sq.plane!r}")
    ac, bd, ad = sq.ac.mean_mm, sq.bd.mean_mm, sq.ad.mean_mm
    ab2 = (ac * ac + bd * bd) / 2.0 - ad * ad
    if not ab2 > 0.0:
        raise ConfigError(
            where,
            f"expected the diagonals AC, BD and the side AD of one square, found AC {ac:g}, "
            f"BD {bd:g} and AD {ad:g} mm, which no parallelogram has (AD too long)",
        )
    ab = sq.ab.mean_mm if sq.ab is not None else math.sqrt(ab2)
    cos_t = (ac * ac - bd * bd) / (4.0 * ab * ad)
    if not abs(cos_t) < 1.0 or abs(cos_t / math.sqrt(1.0 - cos_t * cos_t)) > MAX_SQUARENESS:
        raise ConfigError(
            where,
            f"expected the lengths of a square, found AC {ac:g} and BD {bd:g} mm: their "
            f"angle is more than {math.degrees(math.atan(MAX_SQUARENESS)):.0f}° from 90°",
        )
    for name, side in (("AD", ad), ("AB", ab)):
        if max(ac, bd) < side:
            raise ConfigError(
                where, f"expected {name} shorter than the diagonals, found {side:g} mm"
            )
    if sq.nominal_mm is not None:
        for name, side in (("AD", ad), ("AB", ab)):
            if abs(side / sq.nominal_mm - 1.0) > MAX_SCALE:
                raise ConfigError(
                    where,
                    f"expected {name} within 20 % of the nominal side {sq.nominal_mm:g} mm, "
                    f"found {side:g} mm",
                )


def _combine(parts: Sequence[tuple[float, float, float]]) -> tuple[float, float, float]:
    """Inverse-variance mean of independent (value, u, dof) estimates of one quantity."""
    if len(parts) == 1:
        return parts[0]
    w = np.array([1.0 / (u * u) if u > 0 else 1e300 for _, u, _ in parts])
    value = float(np.sum(w * np.array([v for v, _, _ in parts])) / np.sum(w))
    u = float(1.0 / math.sqrt(np.sum(w)))
    dof = welch_satterthwaite((u * u * wi, d) for wi, (_, _, d) in zip(w, parts, strict=True))
    return value, u, dof


def from_squares(squares: Sequence[Square], caliper: Caliper) -> SkewResult:
    """Squareness (and scale, with a nominal side) from squares the machine made.

    Raises
    ------
    ConfigError
        A plane given twice, or lengths that are not those of a square (named by the
        option ``--XY`` ...).
    """
    if not squares:
        raise ConfigError("--xy/--xz/--yz", "expected the lengths of at least one square")
    seen: set[str] = set()
    planes: list[SquarePlane] = []
    found: dict[Quantity, list[tuple[float, float, float]]] = {}
    warnings: list[str] = []
    u_cal = caliper.u_mm
    for sq in squares:
        where = f"--{sq.plane.lower()}"
        if sq.plane in seen:
            raise ConfigError(where, "expected one square per plane, found two")
        seen.add(sq.plane)
        _check_square(sq, where)
        lengths = [sq.ac, sq.bd, sq.ad] + ([sq.ab] if sq.ab is not None else [])
        x = np.array([ln.mean_mm for ln in lengths])
        has_ab = sq.ab is not None

        def f(
            v: np.ndarray, has_ab: bool = has_ab, nominal: float | None = sq.nominal_mm
        ) -> np.ndarray:
            return _square_values(v, has_ab, nominal)

        values = f(x)
        jac = _jacobian(f, x)
        type_a = [ln.type_a() for ln in lengths]
        outputs = [Quantity("squareness", sq.plane)]
        if sq.nominal_mm is not None:
            outputs += [Quantity("scale", sq.plane[0]), Quantity("scale", sq.plane[1])]
        for row, q in enumerate(outputs):
            parts = []
            for j, (ua, dof_a) in enumerate(type_a):
                parts.append((jac[row, j] * u_cal, math.inf))
                if ua > 0:
                    parts.append((jac[row, j] * ua, dof_a))
            u = math.sqrt(sum(p * p for p, _ in parts))
            found.setdefault(q, []).append((float(values[row]), u, welch_satterthwaite(parts)))
        ac, bd, ad = x[0], x[1], x[2]
        ab_law = math.sqrt((ac * ac + bd * bd) / 2.0 - ad * ad)
        misfit = None
        if has_ab:
            misfit = float(x[3] - ab_law)
            u_misfit = 2.0 * u_cal * math.sqrt(2.0)
            if abs(misfit) > 3.0 * u_misfit:
                warnings.append(
                    f"{sq.plane}: the four lengths miss a parallelogram by {misfit:+.3f} mm "
                    f"(AB measured against AB from AC, BD, AD): rounded corners or bowed "
                    f"sides? The squareness uses the measured AB"
                )
        ab = float(x[3]) if has_ab else ab_law
        cos_t = (ac * ac - bd * bd) / (4.0 * ab * ad)
        planes.append(SquarePlane(sq, ab, not has_ab, math.degrees(math.acos(cos_t)), misfit))
    estimates = tuple(
        Estimate(q, *_combine(parts))
        for q, parts in sorted(found.items(), key=lambda kv: _order(kv[0]))
    )
    return SkewResult(
        "square", "made", estimates, caliper=caliper, planes=tuple(planes), warnings=tuple(warnings)
    )


def _order(q: Quantity) -> tuple[int, int]:
    if q.kind == "squareness":
        return 0, PLANES.index(q.name)
    return 1, AXES.index(q.name)


def _params_of(a: np.ndarray, axes: Sequence[str]) -> np.ndarray:
    """(squareness of each pair, scale of each axis) of a motion matrix's columns."""
    d = len(axes)
    out = []
    for i in range(d):
        for j in range(i + 1, d):
            out.append(_cot_between(a[:, i], a[:, j]))
    for i in range(d):
        out.append(float(np.linalg.norm(a[:, i])) - 1.0)
    return np.array(out)


def from_points(points: PointSet) -> SkewResult:
    """Squareness of every pair of the point set's axes and the scale of each axis, from
    the affine map between nominal and measured coordinates (least squares, every point
    weighted alike).

    A part the machine ``made``: measured = R·M·nominal + t. An artefact the machine
    ``probed``: measured = M⁻¹·(R·nominal + t). Either way the columns' lengths and angles
    of M are those of the fitted map (made) or of its inverse (probed).

    The standard uncertainty of a coordinate is the residual scatter (type A, 2n − 6 or
    3n − 12 degrees of freedom), or half the stated ``point_u_um`` when one is given (the
    residual then checks it).

    Raises
    ------
    DataError
        Too few points, points on a line (or in a plane, for three axes), or a map that
        is not one of a machine (named with the file).
    """
    axes = tuple(points.axes)
    d = len(axes)
    nom = np.asarray(points.nominal_mm, dtype=float)
    mea = np.asarray(points.measured_mm, dtype=float)
    n = nom.shape[0]
    where = points.path or "points"
    need = d + 2  # one more point than the affine map's unknowns per coordinate
    if n < need:
        raise DataError(
            f"{where}: expected at least {need} points for axes {''.join(axes)}, found {n}"
        )
    x = np.column_stack([nom - nom.mean(axis=0), np.ones(n)])
    if np.linalg.matrix_rank(x / np.maximum(np.abs(x).max(axis=0), 1e-300)) < d + 1:
        what = "on one line" if d == 2 else "in one plane"
        raise DataError(f"{where}: expected points spread over {''.join(axes)}, found them {what}")
    xtx_inv = np.linalg.inv(x.T @ x)
    beta = xtx_inv @ x.T @ mea  # (d + 1) × d: column j fits measured coordinate j
    b = beta[:d, :].T  # measured ≈ B·nominal + t
    resid = mea - x @ beta
    dof = d * (n - d - 1)
    s = float(math.sqrt(float(np.sum(resid * resid)) / dof)) if dof > 0 else 0.0
    warnings: list[str] = []
    if points.point_u_um is not None:
        sigma, sigma_dof = points.point_u_um * 1e-3 / 2.0, math.inf
        if s > 3.0 * sigma:
            warnings.append(
                f"the points scatter about the fit by {s * 1e3:.1f} µm (standard deviation), "
                f"more than 3 times the stated u {sigma * 1e3:.1f} µm: the U below is "
                f"based on the stated u"
            )
    else:
        if dof < 1:
            raise DataError(
                f"{where}: {n} points leave no degrees of freedom for the scatter; "
                f"measure more points or state --point-u"
            )
        sigma, sigma_dof = s, float(dof)

    def params(bflat: np.ndarray) -> np.ndarray:
        bm = bflat.reshape(d, d)
        det = float(np.linalg.det(bm))
        if not abs(det) > 1e-12:
            raise DataError(f"{where}: the measured points do not span the nominal ones")
        a = bm if points.kind == "made" else np.linalg.inv(bm)
        return _params_of(a, axes)

    values = params(b.ravel())
    names = [Quantity("squareness", axes[i] + axes[j]) for i in range(d) for j in range(i + 1, d)]
    names += [Quantity("scale", ax) for ax in axes]
    for q, v in zip(names, values, strict=True):
        limit = MAX_SQUARENESS if q.kind == "squareness" else MAX_SCALE
        if not math.isfinite(v) or abs(v) > limit:
            raise DataError(
                f"{where}: the fitted {q} is {v * 1e6:.0f} µm/m, beyond what a machine has; "
                f"are the nominal and measured columns the right way round?"
            )
    # covariance of B's entries: row r of B (measured coordinate r) has σ²·(XᵀX)⁻¹[:d,:d]
    cov_row = sigma * sigma * xtx_inv[:d, :d]
    cov_b = np.kron(np.eye(d), cov_row)
    jac = _jacobian(params, b.ravel())
    cov_p = jac @ cov_b @ jac.T
    estimates = []
    for i, q in enumerate(names):
        u = float(math.sqrt(max(cov_p[i, i], 0.0)))
        estimates.append(Estimate(q, float(values[i]), u, sigma_dof))
    canonical = [_canonical(q) for q in names]
    estimates = [
        Estimate(q, e.value, e.u, e.dof) for q, e in zip(canonical, estimates, strict=True)
    ]
    estimates.sort(key=lambda e: _order(e.quantity))
    return SkewResult(
        "points",
        points.kind,
        tuple(estimates),
        points=points,
        residual_um=s * 1e3,
        residual_dof=dof,
        warnings=tuple(warnings),
    )


def _canonical(q: Quantity) -> Quantity:
    """A plane named in esp's order (``YX`` -> ``XY``): cot θ is symmetric in the pair."""
    if q.kind != "squareness":
        return q
    name = "".join(sorted(q.name, key=AXES.index))
    return Quantity("squareness", name)
