"""One machine's row of a batch summary: its figures and its verdict (``esp batch``).

Verdict
    The figures of each machine are decided by :mod:`esp.volumetric.conformance` (the
    decisions ``esp analyse`` takes) against its tolerances: its own ``[tolerance]`` table
    (docs/configuration.md), with the thresholds of the command line taking over limit by
    limit -- ``max_volumetric_um`` for the volumetric accuracy (the worst tool case's,
    Longstaff 2002, 3.05, eq. 3.5), ``max_planar_um`` for every planar accuracy
    (3.05.4-3.05.5; over several tool cases the largest of each plane),
    ``max_uncertainty_um`` for the expanded volumetric uncertainty -- under the decision
    rule of the command line, else of the machine's table, else simple acceptance
    (ISO 14253-1:2017; ILAC-G8:09/2019). A machine passes when every figure conforms
    (simple acceptance: a value equal to its limit conforms), fails when one does not
    conform, and is ``not decided`` when none fails but one lies within the guard band.

    An uncertainty plan (an ``[uncertainty]`` table and no error data) has no volumetric
    accuracy: its row leaves the accuracy columns empty, shows the uncertainty, and the
    accuracy limits do not apply to it. Its verdict is ``"plan"`` (it neither passes
    nor fails, and counts as no failure in the exit code), unless an uncertainty limit is
    given: then it passes or fails on its uncertainty like any machine.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from esp.batch.naming import BatchItem
from esp.config.tolerance import Tolerances
from esp.core.conformity import DOES_NOT_CONFORM, NOT_DECIDED, Decision, DecisionRule
from esp.core.errors import DataError
from esp.core.machine import AXIS_NAMES

if TYPE_CHECKING:
    from esp.core.results import AnalysisResult

__all__ = [
    "NO_THRESHOLDS",
    "PLANES",
    "BatchRow",
    "Thresholds",
    "row_from_result",
]

#: the planes of the planar accuracy, in the order of the summary columns
PLANES = ("XY", "XZ", "YZ")


@dataclass(frozen=True)
class Thresholds:
    """Limits of the verdict in µm (None: not checked) and the decision rule of the
    command line (None: each machine's own, else simple acceptance)."""

    max_volumetric_um: float | None = None
    max_planar_um: float | None = None
    max_uncertainty_um: float | None = None
    rule: DecisionRule | None = None

    def __post_init__(self) -> None:
        for key in ("max_volumetric_um", "max_planar_um", "max_uncertainty_um"):
            value = getattr(self, key)
            if value is not None and not (math.isfinite(value) and value > 0):
                raise DataError(f"{key}: expected a positive number of µm, found {value!r}")

    def tolerances(self) -> Tolerances:
        """The thresholds as tolerances, to take over a machine's own."""
        return Tolerances(
            volumetric_um=self.max_volumetric_um,
            planar_all_um=self.max_planar_um,
            uncertainty_um=self.max_uncertainty_um,
            rule=self.rule,
        )


#: no threshold: every machine's own ``[tolerance]`` only
NO_THRESHOLDS = Thresholds()


@dataclass(frozen=True)
class BatchRow:
    """One row of the summary: a machine's figures and verdict, or why it failed.

    Lengths in µm, positions in mm. ``planar_um`` holds only the planes the analysis
    reports (one for a two-axis machine); ``decisions`` every figure decided against its
    tolerance (:class:`~esp.core.conformity.Decision`); ``error`` the one-line message
    when the machine could not be analysed (the other fields are then empty). ``plan``:
    an uncertainty plan (no error data), whose ``volumetric_um`` is None (no accuracy) and
    ``uncertainty_um`` the headline.
    """

    file: str
    folder: str
    path: str = ""
    name: str = ""
    configuration: str = ""
    volumetric_um: float | None = None
    volumetric_at_mm: Mapping[str, float] = field(default_factory=dict)
    planar_um: Mapping[str, float] = field(default_factory=dict)
    uncertainty_um: float | None = None
    decisions: tuple[Decision, ...] = ()
    error: str | None = None
    plan: bool = False
    #: why the configuration was not analysed (:data:`IDENTIFY_SKIPPED`), or None
    skipped: str | None = None

    @property
    def failures(self) -> tuple[str, ...]:
        """The figures that do not conform, as ``"volumetric 36.926 um > 30 um"``."""
        return tuple(_short(d) for d in self.decisions if d.verdict == DOES_NOT_CONFORM)

    @property
    def undecided(self) -> tuple[str, ...]:
        """The figures within the guard band, as ``"volumetric 10.0 um within 11.5 um ±
        2.0 um"``."""
        return tuple(_short(d) for d in self.decisions if d.verdict == NOT_DECIDED)

    @property
    def status(self) -> str:
        """``"pass"``, ``"fail"``, ``"not decided"``, ``"error"``, ``"plan"`` (an
        uncertainty plan that no limit applies to) or ``"skipped"`` (not analysed:
        :attr:`skipped` says why)."""
        if self.error is not None:
            return "error"
        if self.skipped is not None:
            return "skipped"
        if self.failures:
            return "fail"
        if self.undecided:
            return "not decided"
        return "plan" if self.plan and not self.decisions else "pass"

    @property
    def verdict(self) -> str:
        """``"pass"``, ``"fail: volumetric 36.926 um > 30 um; ..."``, ``"not decided:
        ..."`` or ``"error"``."""
        if self.status == "fail":
            return "fail: " + "; ".join(self.failures)
        if self.status == "not decided":
            return "not decided: " + "; ".join(self.undecided)
        if self.skipped is not None:
            return self.skipped
        return self.status

    @property
    def decisions_text(self) -> str:
        """Every decision with its verdict and risk, ``; ``-separated (the rule is in
        :attr:`rule_text`)."""
        from esp.volumetric.conformance import value_text

        return "; ".join(
            f"{_SHORT.get(d.quantity, d.quantity)} {value_text(d)} against "
            f"{d.tolerance:g} {d.unit}: {d.verdict} ({d.risk_text()})"
            for d in self.decisions
        )

    @property
    def rule_text(self) -> str:
        """The decision rule of the row's figures (that of its accuracies; a volumetric
        uncertainty alone is decided by simple acceptance)."""
        rules = [d.rule for d in self.decisions if d.quantity != "volumetric uncertainty"]
        rules = rules or [d.rule for d in self.decisions]
        return rules[0].name if rules else ""


#: how the summary names the decided figures
_SHORT = {
    "volumetric accuracy": "volumetric",
    "volumetric uncertainty": "uncertainty",
    **{f"planar accuracy {p}": f"planar {p}" for p in PLANES},
    **{f"range of the {a} error": f"range {a}" for a in AXIS_NAMES},
}


def _short(d: Decision) -> str:
    """``"volumetric 36.926 um > 30 um"``; within the guard band ``"volumetric 10.0 um
    within 11.5 um ± 2.0 um"`` (the figure rounded to its U when it has one)."""
    from esp.volumetric.conformance import value_text

    name = _SHORT.get(d.quantity, d.quantity)
    value = value_text(d).replace("µm", "um")
    if d.verdict == NOT_DECIDED:
        return f"{name} {value} within {d.tolerance:g} um ± {d.guard_band:.2g} um"
    return f"{name} {value} > {d.tolerance:g} um"


def _um(value: float) -> str:
    return f"{value + 0.0:.3f}"


def _mm(value: float) -> str:
    return f"{value + 0.0:.10g}"


def row_from_result(item: BatchItem, result: AnalysisResult, thresholds: Thresholds) -> BatchRow:
    """The summary row of an :class:`~esp.core.results.AnalysisResult`.

    The volumetric accuracy and its position are the worst tool case's; each planar
    accuracy is the largest of that plane over the reported tool cases; the uncertainty is
    the expanded volumetric uncertainty when the machine has an ``[uncertainty]`` table.
    An uncertainty plan has no accuracy, position or planar accuracies (module docstring).
    The decisions are :func:`esp.volumetric.conformance.decide_result`'s against the
    machine's tolerances with ``thresholds`` taking over; a guarded rule without U raises
    :class:`~esp.core.errors.ConfigError`.
    """
    from esp.report.words import is_plan
    from esp.volumetric.conformance import decide_result, tolerances_of

    decisions = decide_result(result, tolerances_of(result, thresholds.tolerances()))
    unc = result.uncertainty
    u_um = None if unc is None else unc.volumetric.value_um
    # what every row of an analysed machine says of it
    named: dict[str, Any] = {  # str values: Any lets them fill BatchRow's fields by name
        "file": item.file,
        "folder": item.folder,
        "path": item.path,
        "name": result.machine.name,
        "configuration": result.machine.configuration,
    }
    if is_plan(result):
        return BatchRow(**named, uncertainty_um=u_um, decisions=decisions, plan=True)
    worst = result.cases[result.worst].volumetric
    planar: dict[str, float] = {}
    for case in result.cases:
        for plane, extreme in case.planar.items():
            planar[plane] = max(planar.get(plane, -math.inf), extreme.value_um)
    return BatchRow(
        **named,
        volumetric_um=worst.value_um,
        volumetric_at_mm={a: float(worst.at[a]) for a in AXIS_NAMES},
        planar_um=planar,
        uncertainty_um=u_um,
        decisions=decisions,
    )
