"""Use of prior information to revise a measurement and its uncertainty (Longstaff 2002, 3.13.1).

After Phillips et al., a measurement y_m with combined standard uncertainty u_cm and a prior
estimate y_pe with standard deviation u_pe (from earlier measurements) combine into

    y = y_m · γ² / (1 + γ²) + y_pe · 1 / (1 + γ²),   γ = u_pe / u_cm      (eq. 3.22)
    1 / u_c² = 1 / u_cm² + 1 / u_pe²                                       (eq. 3.23)

and the expanded uncertainty U_m of the measurement alone is reduced by

    ΔU = U_m · (1 − sqrt(γ² / (γ² + 1)))                                   (eq. 3.24)

so that U_m − ΔU = k · u_c. Prior information can never increase the uncertainty.

Caveats (thesis 3.13.1 and 3.15): both the prior and the measurement distributions must be
Gaussian, and the prior must come from randomly sampled, comparable cases -- similar
machines in similar environments measured with similar set-ups. Data from a
temperature-controlled room, say, is no prior for a workshop machine. The thesis does not
apply this to the individual component uncertainties; it suggests applying eq. 3.24 to the
final figure of a machine with a history, once the prior has been judged appropriate.

This module imports only the standard library.

References
----------
Longstaff, A. P. (2002), section 3.13.1, equations 3.22-3.24, and section 3.15.
Phillips, S. D., et al., on the use of prior information in measurement uncertainty
(reference [80] of the thesis).
"""

from __future__ import annotations

import math

from esp.core.uncertainty.checks import finite

__all__ = ["bayes_gamma", "bayes_update", "expanded_change"]


def bayes_gamma(u_pe: float, u_cm: float) -> float:
    """γ = u_pe / u_cm, the ratio of eq. 3.22 (both standard uncertainties, > 0, same unit)."""
    return finite("u_pe", u_pe, "positive") / finite("u_cm", u_cm, "positive")


def bayes_update(y_m: float, u_cm: float, y_pe: float, u_pe: float) -> tuple[float, float]:
    """Best estimate and its standard uncertainty including prior information.

    Parameters
    ----------
    y_m : best estimate from the measurement alone
    u_cm : combined standard uncertainty of the measurement alone, > 0
    y_pe : best estimate from prior (historical) information
    u_pe : standard deviation of the prior distribution, > 0
        All four in one unit (µm or µm/m).

    Returns
    -------
    (y, u_c) : tuple of float
        ``y`` from eq. 3.22 (the inverse-variance weighted mean), ``u_c`` from eq. 3.23.

    Raises
    ------
    DataError
        For a non-finite value or an uncertainty that is not > 0.

    Notes
    -----
    Valid only for Gaussian prior and measurement distributions and a prior drawn at random
    from comparable machines, environments and set-ups (see the module notes).

    References
    ----------
    Longstaff (2002), eq. 3.22 and 3.23.

    Examples
    --------
    >>> y, u_c = bayes_update(10.0, 2.0, 4.0, 2.0)   # equal weights: midpoint, 2 / sqrt(2)
    >>> round(y, 9), round(u_c, 9)
    (7.0, 1.414213562)
    """
    ym = finite("y_m", y_m)
    ype = finite("y_pe", y_pe)
    ucm = finite("u_cm", u_cm, "positive")
    upe = finite("u_pe", u_pe, "positive")
    # γ²/(1+γ²) = u_pe²/(u_cm²+u_pe²) and 1/(1+γ²) = u_cm²/(u_cm²+u_pe²); written with
    # hypot so that a very large or very small γ neither overflows nor underflows.
    h = math.hypot(ucm, upe)
    y = ym * (upe / h) ** 2 + ype * (ucm / h) ** 2
    # eq. 3.23 solved for u_c: u_c = u_cm u_pe / sqrt(u_cm² + u_pe²)
    u_c = (ucm / h) * upe
    return y, u_c


def expanded_change(U_m: float, gamma: float) -> float:
    """ΔU, the reduction of an expanded uncertainty by prior information (eq. 3.24).

    Parameters
    ----------
    U_m : expanded uncertainty of the measurement alone, >= 0 (µm or µm/m)
    gamma : γ = u_pe / u_cm (see :func:`bayes_gamma`), >= 0

    Returns
    -------
    float
        ΔU = U_m (1 − sqrt(γ² / (γ² + 1))), in the unit of ``U_m``; 0 <= ΔU <= U_m. The
        revised expanded uncertainty is ``U_m - ΔU``.

    References
    ----------
    Longstaff (2002), eq. 3.24.

    Examples
    --------
    >>> round(expanded_change(10.0, 1.0), 6)   # 10 * (1 - sqrt(1/2))
    2.928932
    """
    um = finite("U_m", U_m, "nonneg")
    g = finite("gamma", gamma, "nonneg")
    if g == 0.0:
        return um
    # sqrt(γ²/(γ²+1)) = 1/sqrt(1 + 1/γ²), which stays finite for any γ > 0
    return um * (1.0 - 1.0 / math.hypot(1.0, 1.0 / g))
