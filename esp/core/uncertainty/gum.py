"""The combination rules of the GUM that the budgets use: the effective degrees of
freedom of a combined standard uncertainty (Welch-Satterthwaite) and the coverage factor
for a stated coverage probability (Student's t).

* :func:`welch_satterthwaite` -- JCGM 100:2008, G.4.1, eq. G.2b:
  ν_eff = u_c⁴ / Σ (u_i⁴ / ν_i), with u_c² = Σ u_i² and ν_i = ∞ for a contribution known
  exactly (most Type B evaluations, G.4.3).
* :func:`coverage_factor` -- JCGM 100:2008, G.3.2 and G.4.1: k_p = t_p(ν_eff), the
  two-sided quantile of Student's t-distribution with ν_eff degrees of freedom, ν_eff
  truncated to the next lower integer (G.4.1, note 1); the normal quantile when ν_eff is
  infinite.

Student's t-distribution function and its inverse come from scipy, ``scipy.special.stdtr``
and ``scipy.special.stdtrit`` (the functions behind ``scipy.stats.t``, without the import
time of ``scipy.stats``), imported inside the two functions that need them so that
importing the core loads numpy only. Checked against GUM table G.2 in the tests.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from statistics import NormalDist

from esp.core.errors import DataError

__all__ = ["coverage_factor", "student_t_two_sided", "welch_satterthwaite"]


def welch_satterthwaite(parts: Iterable[tuple[float, float]]) -> float:
    """The effective degrees of freedom of a sum of independent contributions.

    Parameters
    ----------
    parts : pairs (u_i, ν_i): each contribution's standard uncertainty in the unit of the
        result (sensitivity included) and its degrees of freedom (``math.inf`` when known
        exactly); ν_i > 0

    Returns
    -------
    float
        ν_eff = (Σ u_i²)² / Σ (u_i⁴ / ν_i) (GUM eq. G.2b); ``math.inf`` when every
        contribution with a non-zero u has infinite degrees of freedom, or all are zero.

    Examples
    --------
    Two equal contributions, one with 4 degrees of freedom: ν_eff = (2u²)² / (u⁴/4) = 16.

    >>> welch_satterthwaite([(1.0, 4.0), (1.0, math.inf)])
    16.0
    """
    total = 0.0
    denominator = 0.0
    for u, dof in parts:
        if not dof > 0:
            raise DataError(f"degrees of freedom must be > 0, got {dof!r}")
        v = float(u) * float(u)
        total += v
        if math.isfinite(dof) and v > 0.0:
            denominator += v * v / dof
    if denominator == 0.0:
        return math.inf
    return total * total / denominator


def student_t_two_sided(t: float, dof: float) -> float:
    """P(|T| <= t) for Student's t with ``dof`` degrees of freedom (t >= 0).

    Computed as 1 - 2·P(T <= -t) from scipy's distribution function
    (``scipy.special.stdtr``); the normal distribution for infinite ``dof``.

    Examples
    --------
    >>> round(student_t_two_sided(2.776445, 4), 6)
    0.95
    """
    if not dof > 0:
        raise DataError(f"degrees of freedom must be > 0, got {dof!r}")
    if t <= 0.0:
        return 0.0
    if math.isinf(dof):
        return 1.0 - 2.0 * NormalDist().cdf(-t)
    from scipy.special import stdtr

    return 1.0 - 2.0 * float(stdtr(dof, -t))


def coverage_factor(coverage: float, dof: float = math.inf) -> float:
    """The coverage factor k_p = t_p(ν) for a two-sided coverage probability ``coverage``.

    Parameters
    ----------
    coverage : p, 0 < p < 1 (0.95 for 95 %, 0.9545 for the k = 2 of a normal
        distribution)
    dof : the (effective) degrees of freedom, >= 1, or ``math.inf``; a fractional value
        is truncated to the next lower integer (GUM G.4.1, note 1)

    Returns
    -------
    float
        t_p(ν) (GUM table G.2); the normal quantile z_p for infinite ν.

    References
    ----------
    JCGM 100:2008, G.3.2, G.4.1 and table G.2.

    Examples
    --------
    >>> round(coverage_factor(0.95, 4), 3)
    2.776
    >>> round(coverage_factor(0.95), 3)
    1.96
    """
    p = float(coverage)
    if not 0.0 < p < 1.0:
        raise DataError(f"a coverage probability must lie between 0 and 1, got {coverage!r}")
    if math.isinf(dof):
        return NormalDist().inv_cdf(0.5 + p / 2.0)
    nu = math.floor(dof)
    if nu < 1:
        raise DataError(f"degrees of freedom must be >= 1, got {dof!r}")
    from scipy.special import stdtrit

    # minus the lower (1 - p)/2 quantile: accurate also for p close to 1, where the upper
    # quantile's probability 0.5 + p/2 would lose digits
    return -float(stdtrit(nu, (1.0 - p) / 2.0))
