"""The uncertainty budget of one error component: its contributions, their combination and
the expanded uncertainty (GUM; Longstaff 2002, eq. 3.17-3.21).

A budget is a list of standard uncertainties u_i, each with its degrees of freedom ν_i
(infinite for a value known exactly, n − 1 for a Type A evaluation from n runs), combined
in quadrature and expanded by a coverage factor k::

    u_c = sqrt(Σ u_i²),   U = k · u_c,   ν_eff = u_c⁴ / Σ (u_i⁴ / ν_i)

(GUM 5.1.2, 6.2.1 and G.4.1). :func:`type_a` and :func:`rectangular` are the two basic
evaluations of the thesis (eq. 3.17 and 3.18).

This module imports only the standard library.

References
----------
Longstaff, A. P. (2002), PhD thesis, University of Huddersfield, eq. 3.17-3.21.
JCGM 100:2008 (GUM), 4.2.3 (Type A), 4.3.7 (rectangular), 5.1.2 (combined standard
uncertainty), 6.2.1 (expanded uncertainty), G.4.1 (effective degrees of freedom).
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass
from typing import Any, NamedTuple

from esp.core.errors import DataError
from esp.core.uncertainty.checks import count, finite
from esp.core.uncertainty.gum import welch_satterthwaite

__all__ = ["UNITS", "ComponentUncertainty", "Contribution", "rectangular", "type_a"]

UNITS = ("um", "um/m")


class Contribution(NamedTuple):
    """One line of an uncertainty budget: a standard uncertainty ``u`` in ``unit`` with its
    degrees of freedom ``dof`` (``math.inf`` for a Type B value taken as exact; n − 1 for a
    Type A evaluation from n observations)."""

    name: str
    u: float
    unit: str
    dof: float = math.inf

    @property
    def type_a(self) -> bool:
        """Whether this is a Type A evaluation (finite degrees of freedom)."""
        return math.isfinite(self.dof)


def _dof(value: Any, where: str) -> float:
    if value is None:
        return math.inf
    if isinstance(value, bool):
        raise DataError(f"{where}: degrees of freedom must be a number, got {value!r}")
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise DataError(f"{where}: degrees of freedom must be a number, got {value!r}") from None
    if math.isnan(x) or x < 1.0:
        raise DataError(f"{where}: degrees of freedom must be >= 1 or infinite, got {value!r}")
    return x


@dataclass(frozen=True)
class ComponentUncertainty:
    """The expanded uncertainty of one error component, with its budget.

    Parameters
    ----------
    U : expanded uncertainty, >= 0, in ``unit``
    k : coverage factor, > 0 (2 for about 95 % with a normal distribution)
    unit : ``"um"`` (linear, straightness; valid along the axis) or ``"um/m"`` (angular,
        squareness; multiplied by the lever arm)
    model : the instrument model that made it (a key of
        :data:`esp.core.uncertainty.instruments.MODELS`), or a free label such as ``"given"``
    contributions : the budget, standard uncertainties in ``unit`` with their degrees of
        freedom, in the order of the thesis' formula. When given, ``U`` must equal
        ``k · sqrt(Σ u²)`` (eq. 3.19, 3.21); empty for a value given directly.

    References
    ----------
    Longstaff (2002), eq. 3.19 and 3.21; JCGM 100:2008, 5.1.2, 6.2.1 and G.4.1.
    """

    U: float
    k: float
    unit: str
    model: str
    contributions: tuple[Contribution, ...] = ()

    def __post_init__(self) -> None:
        U = finite("U", self.U, "nonneg", where="ComponentUncertainty")
        k = finite("k", self.k, "positive", where="ComponentUncertainty")
        if self.unit not in UNITS:
            raise DataError(f"ComponentUncertainty: unit must be 'um' or 'um/m', got {self.unit!r}")
        records = []
        for item in self.contributions:
            try:
                name, u, unit, *rest = item
            except (TypeError, ValueError):
                raise DataError(
                    f"ComponentUncertainty: a contribution must be (name, u, unit[, dof]), "
                    f"got {item!r}"
                ) from None
            if len(rest) > 1:
                raise DataError(
                    f"ComponentUncertainty: a contribution must be (name, u, unit[, dof]), "
                    f"got {item!r}"
                )
            u = finite(f"u of {name!r}", u, "nonneg", where="ComponentUncertainty")
            dof = _dof(rest[0] if rest else None, f"ComponentUncertainty: {name!r}")
            if unit != self.unit:
                raise DataError(
                    f"ComponentUncertainty: contribution {name!r} is in {unit!r} but the "
                    f"component is in {self.unit!r}"
                )
            records.append(Contribution(str(name), u, str(unit), dof))
        if records:
            expected = k * math.sqrt(math.fsum(r.u**2 for r in records))
            if not math.isclose(U, expected, rel_tol=1e-9, abs_tol=1e-12):
                raise DataError(
                    f"ComponentUncertainty: U = {U!r} does not equal k * sqrt(sum u^2) = "
                    f"{expected!r} of its contributions"
                )
        object.__setattr__(self, "U", U)
        object.__setattr__(self, "k", k)
        object.__setattr__(self, "contributions", tuple(records))

    @classmethod
    def from_budget(
        cls,
        model: str,
        unit: str,
        contributions: Iterable[tuple[str, float, str] | tuple[str, float, str, float]],
        k: float = 2.0,
    ) -> ComponentUncertainty:
        """Combine a budget: ``U = k · sqrt(Σ u²)`` (thesis eq. 3.19 and 3.21).

        ``contributions``: ``(name, u, unit)`` or ``(name, u, unit, dof)`` items."""
        k = finite("k", k, "positive", where=model)
        items = tuple(Contribution(*c) for c in contributions)
        for c in items:
            finite(f"u of {c.name!r}", c.u, "nonneg", where=model)
        U = k * math.sqrt(math.fsum(c.u**2 for c in items))
        return cls(U, k, unit, model, items)

    @property
    def u(self) -> float:
        """The combined standard uncertainty u_c = U / k, in ``unit``."""
        return self.U / self.k

    @property
    def dof(self) -> float:
        """The effective degrees of freedom of u_c by Welch-Satterthwaite (GUM G.4.1);
        ``math.inf`` when no contribution is of Type A."""
        return welch_satterthwaite((c.u, c.dof) for c in self.contributions)

    def ranked(self) -> tuple[Contribution, ...]:
        """The contributions, largest first (equal ones in budget order)."""
        return tuple(sorted(self.contributions, key=lambda c: -c.u))

    def as_dict(self) -> dict[str, Any]:
        """Plain values for JSON output (an infinite number of degrees of freedom is
        written as None)."""

        def dof(x: float) -> float | None:
            return None if math.isinf(x) else x

        return {
            "model": self.model,
            "U": self.U,
            "k": self.k,
            "u": self.u,
            "unit": self.unit,
            "dof": dof(self.dof),
            "contributions": [
                {"name": c.name, "u": c.u, "unit": c.unit, "dof": dof(c.dof)}
                for c in self.contributions
            ],
        }


def type_a(std: float, n: int) -> float:
    """Type A standard uncertainty of a mean: ``s / sqrt(n)`` (thesis eq. 3.17), with
    n − 1 degrees of freedom.

    Parameters
    ----------
    std : sample standard deviation s of the observations, >= 0
    n : number of observations, >= 2

    Raises
    ------
    DataError
        For a negative or non-finite ``std``, or ``n`` < 2 or not whole.

    References
    ----------
    Longstaff (2002), eq. 3.17; JCGM 100:2008, 4.2.3.

    Examples
    --------
    >>> type_a(2.0, 4)
    1.0
    """
    s = finite("std", std, "nonneg", where="type_a")
    n_obs = count("type_a", "n", n)
    if n_obs < 2:
        raise DataError(f"type_a: a standard deviation needs n >= 2 observations, got {n!r}")
    return s / math.sqrt(n_obs)


def rectangular(half_width: float) -> float:
    """Standard uncertainty of a rectangular distribution of half-width a: ``a / sqrt(3)``.

    The thesis' ``e / (2√3)`` terms are ``rectangular(e / 2)``.

    References
    ----------
    Longstaff (2002), eq. 3.18; JCGM 100:2008, 4.3.7.

    Examples
    --------
    >>> round(rectangular(3.0), 6)
    1.732051
    """
    return finite("half_width", half_width, "nonneg", where="rectangular") / math.sqrt(3.0)
