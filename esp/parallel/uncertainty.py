"""Uncertainty of the tool's errors from the uncertainties of the error sources.

The same three methods as ``esp analyse`` (``docs/uncertainty.md``), applied to the
sensitivities S = [J]⁻¹ [M | N] of the machine at a pose. Each source j has an expanded
uncertainty U_j with the coverage factor k of the configuration (u_j = U_j / k).

* ``summation`` -- a bound: Σ_j |S_ij| U_j per output i, the largest error any choice of
  signs of the sources (each +U_j or -U_j) gives (the triangle inequality); the thesis'
  "pure addition" (Longstaff 2002, 4.01.3) kept the signs, which is one such choice;
* ``statistical`` -- per output the root-sum-square of the contributions, expanded with k:
  U_i = k √(Σ_j (S_ij u_j)²) (GUM 5.1.2 for independent inputs, 6.2.1), then the vector
  sum of the three position outputs for the tool tip (Longstaff 2002, 3.14.7);
* ``montecarlo`` -- the statistical figures, plus the distribution of the tool's error
  itself (JCGM 101:2008, GUM Supplement 1): every source drawn as value + z u_j with z
  normal or rectangular of unit standard deviation, from an explicit seeded generator,
  propagated through the exact nonlinear kinematics (or the linear model); the mean,
  standard deviation and the probabilistically symmetric 95 % interval of each output and
  of the position error's length |e|.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from esp.core.errors import DataError
from esp.parallel.exact import exact_errors
from esp.parallel.geometry import Geometry
from esp.parallel.sources import SOURCE_NAMES
from esp.parallel.transmission import Transmission

__all__ = [
    "DISTRIBUTIONS",
    "METHODS",
    "MONTECARLO_MODELS",
    "BudgetLine",
    "MonteCarloSummary",
    "UncertaintyResult",
    "UncertaintySpec",
    "propagate",
]

METHODS = ("statistical", "summation", "montecarlo")
DISTRIBUTIONS = ("normal", "rectangular")
MONTECARLO_MODELS = ("exact", "linear")
_CHUNK = 5000


@dataclass(frozen=True)
class UncertaintySpec:
    """The uncertainties of the sources.

    ``U`` (42,) expanded uncertainties in µm or µrad (:data:`SOURCE_NAMES` order), ``k``
    their coverage factor, ``distributions`` (42,) ``"normal"`` or ``"rectangular"``.
    """

    U: np.ndarray
    k: float = 2.0
    method: str = "statistical"
    samples: int = 20000
    seed: int = 1
    distributions: tuple[str, ...] = ("normal",) * len(SOURCE_NAMES)
    montecarlo_model: str = "exact"


@dataclass(frozen=True)
class BudgetLine:
    """One source's part in the uncertainty: ``U`` (µm or µrad), ``contribution`` (6,) the
    signed S_ij U_j, ``share_position_pct`` and ``share_rotation_pct`` its share of the
    tool tip's position and orientation uncertainty under the method used."""

    source: str
    U: float
    contribution: np.ndarray
    share_position_pct: float
    share_rotation_pct: float


@dataclass(frozen=True)
class MonteCarloSummary:
    """The distribution of the tool's errors: per output (6,) ``mean``, ``std`` (n − 1),
    ``low`` and ``high`` (2.5 % and 97.5 % quantiles), and the same for |e| (µm)."""

    samples: int
    seed: int
    model: str
    mean: np.ndarray
    std: np.ndarray
    low: np.ndarray
    high: np.ndarray
    position_mean_um: float
    position_std_um: float
    position_low_um: float
    position_high_um: float


@dataclass(frozen=True)
class UncertaintyResult:
    """The expanded uncertainties of e (µm) and ε (µrad) by summation and statistically,
    the tool tip's (vector sum of e_x, e_y, e_z) and the budget, largest share first."""

    method: str
    k: float
    summation: np.ndarray
    statistical: np.ndarray
    budget: tuple[BudgetLine, ...]
    montecarlo: MonteCarloSummary | None

    @property
    def position_um(self) -> float:
        """The tool tip's expanded uncertainty under :attr:`method` (montecarlo reports
        the statistical figure)."""
        values = self.summation if self.method == "summation" else self.statistical
        return float(np.linalg.norm(values[:3]))

    @property
    def rotation_urad(self) -> float:
        values = self.summation if self.method == "summation" else self.statistical
        return float(np.linalg.norm(values[3:]))

    @property
    def by_method(self) -> np.ndarray:
        """The six expanded uncertainties of the method used."""
        return self.summation if self.method == "summation" else self.statistical


def statistical_uncertainty(sensitivity: np.ndarray, U: np.ndarray, k: float) -> np.ndarray:
    """k √(Σ_j (S_ij U_j / k)²) for (..., 6, 42) sensitivities: (..., 6)."""
    return k * np.sqrt(np.sum((sensitivity * (U / k)) ** 2, axis=-1))


def _shares(contrib: np.ndarray, method: str) -> tuple[np.ndarray, np.ndarray]:
    """Per source, its share (%) of the position and rotation uncertainty."""
    out = []
    for rows in (slice(0, 3), slice(3, 6)):
        c = contrib[:, rows]
        if method == "summation":
            total = c.sum(axis=0)
            denom = float(total @ total)
            share = c @ total / denom if denom > 0 else np.zeros(len(c))
        else:
            sq = np.sum(c**2, axis=1)
            denom = float(sq.sum())
            share = sq / denom if denom > 0 else np.zeros(len(c))
        out.append(100.0 * share)
    return out[0], out[1]


def propagate(
    spec: UncertaintySpec,
    transmission: Transmission,
    values: np.ndarray,
    geometry: Geometry | None = None,
) -> UncertaintyResult:
    """The uncertainty of the tool's errors at the (single) pose of ``transmission``.

    Parameters
    ----------
    spec : the sources' uncertainties and the method
    transmission : the error transmission at one pose
    values : (42,) the error values (the Monte Carlo draws are centred on them)
    geometry : the machine; needed for the Monte Carlo method through the exact kinematics
    """
    s = transmission.sensitivity[0]
    U = np.asarray(spec.U, float)
    contrib = s * U[None, :]  # (6, 42) signed S_ij U_j
    summation = np.abs(contrib).sum(axis=1)  # the bound: Σ_j |S_ij| U_j
    statistical = statistical_uncertainty(s, U, spec.k)
    method = "summation" if spec.method == "summation" else "rss"
    share_p, share_r = _shares(np.abs(contrib.T) if method == "summation" else contrib.T, method)
    lines = [
        BudgetLine(name, float(U[j]), contrib[:, j], float(share_p[j]), float(share_r[j]))
        for j, name in enumerate(SOURCE_NAMES)
        if U[j] != 0
    ]
    lines.sort(key=lambda b: (-abs(b.share_position_pct), -abs(b.share_rotation_pct), b.source))
    mc = None
    if spec.method == "montecarlo":
        mc = montecarlo(spec, transmission, values, geometry)
    return UncertaintyResult(spec.method, spec.k, summation, statistical, tuple(lines), mc)


def montecarlo(
    spec: UncertaintySpec,
    transmission: Transmission,
    values: np.ndarray,
    geometry: Geometry | None,
) -> MonteCarloSummary:
    """Draw the sources and collect the tool's errors (see the module text)."""
    if spec.montecarlo_model == "exact" and geometry is None:
        raise DataError("the Monte Carlo method through the exact kinematics needs the geometry")
    rng = np.random.default_rng(spec.seed)
    u = np.asarray(spec.U, float) / spec.k
    active = np.flatnonzero(u > 0)
    rect = np.array([spec.distributions[j] == "rectangular" for j in active], dtype=bool)
    outputs = []
    done = 0
    while done < spec.samples:
        m = min(_CHUNK, spec.samples - done)
        z = rng.standard_normal((m, active.size))
        if rect.any():
            uniform = rng.uniform(-np.sqrt(3.0), np.sqrt(3.0), size=(m, int(rect.sum())))
            z[:, rect] = uniform
        draws = np.broadcast_to(np.asarray(values, float), (m, values.size)).copy()
        draws[:, active] += z * u[active]
        if spec.montecarlo_model == "exact":
            assert geometry is not None  # refused above
            outputs.append(
                exact_errors(geometry, transmission.poses, transmission.table_mm[0], draws)
            )
        else:
            outputs.append(draws @ transmission.sensitivity[0].T)
        done += m
    out = np.concatenate(outputs)
    length = np.linalg.norm(out[:, :3], axis=1)
    low, high = np.quantile(out, [0.025, 0.975], axis=0)
    plow, phigh = np.quantile(length, [0.025, 0.975])
    return MonteCarloSummary(
        spec.samples,
        spec.seed,
        spec.montecarlo_model,
        out.mean(axis=0),
        out.std(axis=0, ddof=1),
        low,
        high,
        float(length.mean()),
        float(length.std(ddof=1)),
        float(plow),
        float(phigh),
    )
