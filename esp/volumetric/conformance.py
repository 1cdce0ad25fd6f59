"""The figures of an analysis decided against tolerances: the one place where ``esp
analyse`` and ``esp batch`` take their verdicts (ISO 14253-1:2017; ILAC-G8:09/2019).

Each figure is an upper-limited quantity, decided by :func:`esp.core.conformity.decide`
under the rule of the :class:`~esp.config.tolerance.Tolerances` (simple acceptance when
none is named), with the expanded uncertainty U esp evaluates for it:

* the **volumetric accuracy** (of the worst tool case, Longstaff 2002, 3.05, eq. 3.5), with
  the largest expanded volumetric uncertainty over the volume -- an upper bound of its U
  wherever the accuracy lies;
* each **planar accuracy** (3.05.4-3.05.5; over several tool cases the largest of the
  plane). esp evaluates no U for it, so it is decided by simple acceptance only: a guarded
  rule with a planar tolerance is refused;
* the **range of a direction's error** (largest minus smallest over the volume; over tool
  cases the largest), with U = √2 · U_d, U_d the largest expanded uncertainty of that
  direction's error: the U of the difference of two values each with U ≤ U_d and not
  negatively correlated (GUM 5.2.2, eq. 16 with r ≥ 0 gives at most √2 · U_d for
  r = 0);
* the **volumetric uncertainty** itself (a requirement on the measurement, ISO 14253-1
  names it the uncertainty of the test): U has no U of its own, so it is decided by
  simple acceptance whatever the rule.

An uncertainty plan (no error data) has only its uncertainty to decide.
"""

from __future__ import annotations

from dataclasses import replace

from esp.config.tolerance import PLANES, Tolerances
from esp.core.conformity import Decision, DecisionRule, decide
from esp.core.errors import ConfigError
from esp.core.machine import AXIS_NAMES
from esp.core.results import AnalysisResult
from esp.core.rounding import rounded
from esp.report.words import u_not_evaluated

__all__ = ["decide_result", "decision_lines", "decisions_of", "tolerances_of", "value_text"]

UNIT = "µm"


def tolerances_of(result: AnalysisResult, given: Tolerances | None = None) -> Tolerances:
    """The tolerances of the machine's ``[tolerance]`` table, with ``given`` (the command
    line) taking over limit by limit."""
    own = getattr(result.machine, "tolerance", None)
    base = own if isinstance(own, Tolerances) else Tolerances(source=result.machine.source)
    return base.overridden_by(given) if given is not None else base


def _decide(
    result: AnalysisResult,
    tolerances: Tolerances,
    quantity: str,
    value: float,
    limit: float,
    rule: DecisionRule,
    expanded: float | None,
) -> Decision:
    u = result.uncertainty
    k = u.k if u is not None else 2.0
    if rule.kind == "guarded" and expanded is None:
        simple = "--rule simple" if rule.key.startswith("--") else 'rule = "simple"'
        source = tolerances.source if rule.key.startswith("tolerance.") else None
        raise ConfigError(
            rule.key,
            f"guarded acceptance needs the expanded uncertainty of the {quantity}, which is "
            f"{u_not_evaluated(result)}: {_remedy(result)}, or decide by simple "
            f"acceptance ({simple})",
            source,
        )
    try:
        return decide(quantity, value, limit, rule, expanded=expanded, k=k, unit=UNIT)
    except ConfigError as exc:
        source = tolerances.source if exc.key.startswith("tolerance.") else None
        raise ConfigError(exc.key, exc.message, source) from None


def _no_u(tolerances: Tolerances, rule: DecisionRule, quantity: str) -> ConfigError:
    source = tolerances.source if rule.key.startswith("tolerance.") else None
    simple = "--rule simple" if rule.key.startswith("--") else 'rule = "simple"'
    return ConfigError(
        rule.key,
        f"guarded acceptance needs the expanded uncertainty of the {quantity}, which esp "
        "does not evaluate (it evaluates U for the volumetric accuracy and each direction's "
        f"error): decide it by simple acceptance ({simple}) or give no tolerance for it",
        source,
    )


def _remedy(result: AnalysisResult) -> str:
    if getattr(result, "uncertainty_missing", ()):
        return "give their U, or a default ([uncertainty] default)"
    return "add one"


def decide_result(result: AnalysisResult, tolerances: Tolerances) -> tuple[Decision, ...]:
    """Every figure of ``result`` that ``tolerances`` limits, decided (module docstring),
    in the order volumetric, planar, range, uncertainty. Raises
    :class:`~esp.core.errors.ConfigError` for a guarded rule where U is not evaluated."""
    from esp.report.words import is_plan

    rule = tolerances.decision_rule
    unc = result.uncertainty
    decisions: list[Decision] = []
    if not is_plan(result):
        cases = result.cases
        if tolerances.volumetric_um is not None:
            worst = cases[result.worst].volumetric.value_um
            expanded = unc.volumetric.value_um if unc is not None else None
            decisions.append(
                _decide(
                    result, tolerances, "volumetric accuracy", worst,
                    tolerances.volumetric_um, rule, expanded,
                )
            )  # fmt: skip
        for plane in PLANES:
            limit = tolerances.planar_limit(plane)
            values = [c.planar[plane].value_um for c in cases if plane in c.planar]
            if limit is None or not values:
                continue
            quantity = f"planar accuracy {plane}"
            if rule.kind == "guarded":
                raise _no_u(tolerances, rule, quantity)
            decisions.append(_decide(result, tolerances, quantity, max(values), limit, rule, None))
        for d in AXIS_NAMES:
            limit = tolerances.range_um.get(d)
            if limit is None:
                continue
            span = max(c.axes[d].range_um for c in cases)
            expanded = unc.range_um(d) if unc is not None else None
            decisions.append(
                _decide(result, tolerances, f"range of the {d} error", span, limit, rule, expanded)
            )
    if tolerances.uncertainty_um is not None and unc is not None:
        simple = replace(DecisionRule("simple"), key=rule.key)
        decisions.append(
            _decide(
                result, tolerances, "volumetric uncertainty", unc.volumetric.value_um,
                tolerances.uncertainty_um, simple, None,
            )
        )  # fmt: skip
    return tuple(decisions)


def decisions_of(result: AnalysisResult) -> tuple[Decision, ...]:
    """The decisions of ``result`` against its machine's tolerances (``[tolerance]``, with
    the command line's limits merged into the machine by the command); none without."""
    own = getattr(result.machine, "tolerance", None)
    if not isinstance(own, Tolerances) or own.empty:
        return ()
    return decide_result(result, own)


def value_text(decision: Decision) -> str:
    """The decided figure as text: rounded to its U (GUM 7.2.6) when it has one, else
    with three decimals."""
    if decision.expanded is not None:
        return f"{rounded(decision.value, decision.expanded)[0]} {decision.unit}"
    return f"{decision.value + 0.0:.3f} {decision.unit}"


def decision_lines(decisions: tuple[Decision, ...] | list[Decision]) -> list[str]:
    """One line per decision: the figure rounded to its U, the U it was decided with
    (``10.0 µm (U = 2.8 µm)``), the limit, the verdict, the rule and the risk."""
    lines = []
    for d in decisions:
        shown = value_text(d)
        if d.expanded is not None:
            shown += f" (U = {rounded(d.value, d.expanded)[1]} {d.unit})"
        lines.append(d.text(shown))
    return lines
