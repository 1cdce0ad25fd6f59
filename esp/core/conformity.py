"""Decisions of conformity with a tolerance, taking the measurement uncertainty into account
(ISO 14253-1:2017; ILAC-G8:09/2019; JCGM 106:2012).

Every figure esp checks against a tolerance is one-sided: it must not exceed an upper
limit T (a volumetric or planar accuracy, the range of an error, an ISO 230-2 parameter).
A figure y stated with expanded uncertainty U = k·u is decided by one of two rules:

* **simple acceptance** (ILAC-G8:09/2019, 4.2.1; "shared risk"): y ≤ T conforms, y > T does
  not. The guard band is zero; at y = T the probability that the true value exceeds T is
  50 %.
* **guarded acceptance** (ISO 14253-1:2017, 5.2 and 5.3; ILAC-G8:09/2019, 4.2.2) with guard
  band w = f·U (f = 1 by default): y ≤ T − w conforms; y > T + w does not conform; between
  the two the measurement can prove neither, and the verdict is **not decided**. A guarded
  rule needs U: without it the decision is refused, never taken as simple.

With U known, every decision states the specific risk of its verdict (JCGM 106:2012, 9.3),
from the probability that the true value conforms, p_c = Φ((T − y)/u) for a normal
distribution of the measurand with standard uncertainty u = U/k (JCGM 106:2012, 7.3):
the probability of false acceptance 1 − p_c for a figure that conforms, of false rejection
p_c for one that does not, and p_c itself for one not decided.

Exit codes for scripts and CI (:func:`exit_code`): 0 every figure conforms, 1 one does not
conform, 3 none fails but one is not decided (2 stays the code of an error, and wins).

>>> rule = DecisionRule("guarded")
>>> decide("volumetric", 26.0, 30.0, rule, expanded=2.0, unit="µm").verdict
'conforms'
>>> decide("volumetric", 29.0, 30.0, rule, expanded=2.0, unit="µm").verdict
'not decided'
>>> decide("volumetric", 33.0, 30.0, rule, expanded=2.0, unit="µm").verdict
'does not conform'

Standard library only.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass
from typing import Any, Literal

from esp.core.errors import ConfigError

__all__ = [
    "CONFORMS",
    "DOES_NOT_CONFORM",
    "NOT_DECIDED",
    "RULES",
    "Decision",
    "DecisionRule",
    "decide",
    "exit_code",
    "parse_tolerances",
]

CONFORMS = "conforms"
DOES_NOT_CONFORM = "does not conform"
NOT_DECIDED = "not decided"

#: the decision rules by their name in configuration files and on the command line
RULES = ("simple", "guarded")


@dataclass(frozen=True)
class DecisionRule:
    """A decision rule: ``"simple"`` acceptance, or ``"guarded"`` acceptance with guard
    band w = ``guard_fraction``·U. ``key`` names where the rule was given (a configuration
    key or an option), for the message that refuses a guarded decision without U."""

    kind: Literal["simple", "guarded"] = "simple"
    guard_fraction: float = 1.0
    key: str = "tolerance.rule"

    def __post_init__(self) -> None:
        if self.kind not in RULES:
            raise ConfigError(self.key, f"expected one of {', '.join(RULES)}, found {self.kind!r}")
        fraction = self.guard_fraction
        if not (isinstance(fraction, int | float) and math.isfinite(fraction)) or not (
            0.0 < fraction <= 3.0
        ):
            raise ConfigError(
                self.key, f"guard band fraction of U must be in (0, 3], found {fraction!r}"
            )

    @property
    def name(self) -> str:
        """How the rule is named in text: ``"simple acceptance (ILAC-G8 4.2.1)"``,
        ``"guarded acceptance, w = U (ISO 14253-1)"``.

        >>> DecisionRule("guarded", 0.5).name
        'guarded acceptance, w = 0.5·U (ISO 14253-1:2017, ILAC-G8:09/2019 4.2.2)'
        """
        if self.kind == "simple":
            return "simple acceptance, w = 0 (ILAC-G8:09/2019 4.2.1)"
        w = "U" if self.guard_fraction == 1.0 else f"{self.guard_fraction:g}·U"
        return f"guarded acceptance, w = {w} (ISO 14253-1:2017, ILAC-G8:09/2019 4.2.2)"

    def as_dict(self) -> dict[str, Any]:
        return {"rule": self.kind, "guard_fraction": self.guard_fraction, "name": self.name}


def _phi(z: float) -> float:
    """The standard normal distribution function."""
    return 0.5 * math.erfc(-z / math.sqrt(2.0))


@dataclass(frozen=True)
class Decision:
    """One figure decided against its upper tolerance.

    ``guard_band`` is w in the figure's unit (0 for simple acceptance);
    ``probability_conforming`` is p_c (None without U); ``risk`` the specific risk of the
    verdict (false acceptance for ``"conforms"``, false rejection for ``"does not
    conform"``, p_c for ``"not decided"``), None without U."""

    quantity: str
    value: float
    tolerance: float
    unit: str
    rule: DecisionRule
    verdict: str
    expanded: float | None
    k: float
    guard_band: float
    probability_conforming: float | None

    @property
    def risk_name(self) -> str:
        return {
            CONFORMS: "probability of false acceptance",
            DOES_NOT_CONFORM: "probability of false rejection",
            NOT_DECIDED: "probability of conformity",
        }[self.verdict]

    @property
    def risk(self) -> float | None:
        p = self.probability_conforming
        if p is None:
            return None
        return {CONFORMS: 1.0 - p, DOES_NOT_CONFORM: p, NOT_DECIDED: p}[self.verdict]

    @property
    def passed(self) -> bool:
        return self.verdict == CONFORMS

    def risk_text(self) -> str:
        """``"probability of false acceptance 0.6 %"``, or that it is not known (no U)."""
        risk = self.risk
        if risk is None:
            return f"{self.risk_name} not known (no U)"
        if risk < 0.001:
            return f"{self.risk_name} < 0.1 %"
        return f"{self.risk_name} {100.0 * risk:.1f} %"

    def text(self, value_text: str | None = None) -> str:
        """One line: ``"volumetric 26.0 µm ≤ 30 µm − w: conforms (guarded acceptance, w =
        U ...; probability of false acceptance < 0.1 %)"``. ``value_text`` is the figure
        as the caller states it (rounded to its U); the default writes three decimals."""
        shown = value_text if value_text is not None else f"{self.value:.3f} {self.unit}"
        limit = f"{self.tolerance:g} {self.unit}"
        return (
            f"{self.quantity} {shown} against {limit}: {self.verdict} "
            f"({self.rule.name}; {self.risk_text()})"
        )

    def as_dict(self) -> dict[str, Any]:
        return {
            "quantity": self.quantity,
            "value": self.value,
            "tolerance": self.tolerance,
            "unit": self.unit,
            "verdict": self.verdict,
            "decision_rule": self.rule.as_dict(),
            "expanded_uncertainty": self.expanded,
            "k": self.k if self.expanded is not None else None,
            "guard_band": self.guard_band,
            "acceptance_limit": self.tolerance - self.guard_band,
            "rejection_limit": self.tolerance + self.guard_band,
            "probability_conforming": self.probability_conforming,
            "risk": {"name": self.risk_name, "value": self.risk},
        }


def decide(
    quantity: str,
    value: float,
    tolerance: float,
    rule: DecisionRule,
    *,
    expanded: float | None = None,
    k: float = 2.0,
    unit: str = "µm",
) -> Decision:
    """Decide ``value`` against the upper limit ``tolerance`` under ``rule``.

    ``expanded`` is U of the value (None or not positive: not evaluated). A guarded rule
    without U raises :class:`~esp.core.errors.ConfigError` naming ``rule.key``.

    Worked case, guarded with w = U = 2 µm against T = 30 µm, u = 1 µm: y = 27.5 µm is
    below T − w = 28 µm and conforms, with p_c = Φ(2.5) = 0.99379, so the probability of
    false acceptance is 0.6 %:

    >>> d = decide("volumetric", 27.5, 30.0, DecisionRule("guarded"), expanded=2.0)
    >>> d.verdict, round(d.risk, 5), d.risk_text()
    ('conforms', 0.00621, 'probability of false acceptance 0.6 %')
    """
    for name, figure in (("value", value), ("tolerance", tolerance)):
        if not math.isfinite(figure):
            raise ConfigError(rule.key, f"the {name} of {quantity} must be finite, not {figure}")
    if tolerance <= 0.0:
        raise ConfigError(
            rule.key, f"the tolerance of {quantity} must be positive, not {tolerance}"
        )
    u_expanded = float(expanded) if expanded is not None else math.nan
    has_u = math.isfinite(u_expanded) and u_expanded > 0.0
    if rule.kind == "guarded" and not has_u:
        simple = "--rule simple" if rule.key.startswith("--") else 'rule = "simple"'
        raise ConfigError(
            rule.key,
            f"guarded acceptance needs the expanded uncertainty of {quantity}, which is not "
            f"evaluated (add an [uncertainty] table, or use {simple})",
        )
    if not (math.isfinite(k) and k > 0.0):
        raise ConfigError(rule.key, f"the coverage factor of {quantity} must be positive, not {k}")
    guard = rule.guard_fraction * u_expanded if rule.kind == "guarded" else 0.0
    if value <= tolerance - guard:
        verdict = CONFORMS
    elif value > tolerance + guard:
        verdict = DOES_NOT_CONFORM
    else:
        verdict = NOT_DECIDED
    p_c = _phi((tolerance - value) / (u_expanded / k)) if has_u else None
    return Decision(
        quantity=quantity,
        value=float(value),
        tolerance=float(tolerance),
        unit=unit,
        rule=rule,
        verdict=verdict,
        expanded=u_expanded if has_u else None,
        k=float(k),
        guard_band=float(guard),
        probability_conforming=p_c,
    )


def exit_code(decisions: Iterable[Decision]) -> int:
    """0 every decision conforms (or there is none), 1 one does not conform, 3 none fails
    but one is not decided.

    >>> r = DecisionRule("guarded")
    >>> exit_code([decide("a", 1.0, 5.0, r, expanded=1.0), decide("b", 5.5, 5.0, r, expanded=1.0)])
    3
    """
    verdicts = {d.verdict for d in decisions}
    if DOES_NOT_CONFORM in verdicts:
        return 1
    if NOT_DECIDED in verdicts:
        return 3
    return 0


def parse_tolerances(
    given: Iterable[str], figures: Iterable[str], option: str = "--tolerance", unit: str = "µm"
) -> dict[str, float]:
    """``["G=15", "H=5"]`` as ``{"G": 15.0, "H": 5.0}``: upper limits of the ``figures``
    a command decides, each positive, finite and at most 10⁵ (in ``unit``); a bad one is
    refused naming ``option``.

    >>> parse_tolerances(["A=20"], ("A", "R"))
    {'A': 20.0}
    """
    names = tuple(figures)
    out: dict[str, float] = {}
    for item in given:
        key, sep, value = item.partition("=")
        key = key.strip()
        if not sep or key not in names:
            raise ConfigError(
                option,
                f"expected FIGURE={unit} with FIGURE one of {', '.join(names)}, found {item!r}",
            )
        try:
            number = float(value)
        except ValueError:
            number = math.nan
        if not (math.isfinite(number) and 0.0 < number <= 1e5):
            raise ConfigError(
                option,
                f"expected a positive tolerance in {unit} for {key}, found {value.strip()!r}",
            )
        out[key] = number
    return out
