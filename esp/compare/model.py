"""Drift between two calibrations of one machine: the change of every component, of the
volumetric and planar accuracy, and of the error field over the volume.

Longstaff (2002) 4.02.3 compares two calibrations of the turning machine TM1 a year apart:
the X-axis pitch error kept its shape and range to within 1 µm/m, inside the instrument's
uncertainty. esp generalises this to every component and to the machine's error field:

* per component, the curves as the engine uses them (the analysis' direction of the runs,
  straightness with its set-up slope removed) are compared on the positions both
  calibrations measured (the union of their targets within the common range);
  linear and angular curves are referred to their value at the first common position, as
  their zero is the laser's (it is set at the start of each test), straightness to its
  fitted line; the change is ``after - before``, its largest magnitude and where; a
  component missing from one calibration counts as zero there;
* the volumetric and planar accuracy of each calibration from :func:`esp.analyse`;
* the change of the error field ``Δe(p) = e_after(p) - e_before(p)`` on the common
  simulation grid, from the very evaluations the two analyses report
  (:class:`esp.core.evaluation.Evaluation`): for the worst tool case of each calibration, its
  largest magnitude and where, and per direction. Since both accuracies are maxima over the
  same grid, ``|Δ volumetric| <= max |Δe|`` always holds (the triangle inequality): the
  two figures cannot contradict each other.

Two machines are the same machine when configuration, axis roles and travel agree (and the
serial numbers, when both give one); two evaluations compare like with like when they
evaluate the same case (point, compensation, model, sign convention, runs, straightness
fit, datum), the same tool cases or head/table settings, and the same grid. Anything else
is refused, naming what differs. Two calibrations read from identical inputs (the same
files, or byte-for-byte copies of every file) are flagged as such (``identical_inputs``), and
a comparison in which nothing changed says so (``unchanged``), so that ``esp compare A A``
is not mistaken for a comparison of two calibrations.

Each change is stated with its expanded uncertainty U(Δ) and its normalised error En
(:func:`change_significance`): the standard uncertainties of the two calibrations
(u = U / k, each with its own k, from each calibration's ``[uncertainty]`` table) are combined
for Δ = after - before (JCGM 100:2008, the GUM, 5.2.2, eq. 16, sensitivities -1 and +1)

    u(Δ)² = u_before² + u_after² - 2 r u_before u_after

with r the correlation coefficient of the two calibrations (0: independent, the default),
and expanded once, U(Δ) = k u(Δ) with k = 2 (GUM 6.2.1, 6.3.3); then
En = |Δ| / U(Δ) (ISO 13528:2015, 9.7; ISO/IEC 17043:2010, B.3.1.3). A change with En <= 1
is within what the two uncertainties explain: not significant. A side without a U (no
``[uncertainty]`` table, or one that gives no U for a component the figure depends on)
leaves U(Δ) and En not evaluated, never 0.

This module imports only numpy and the standard library.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from dataclasses import field as dataclass_field
from typing import TYPE_CHECKING, Any

import numpy as np

from esp.core.errors import DataError

if TYPE_CHECKING:
    from esp.core.evaluation import Evaluation, MachineEvaluation
    from esp.core.machine import Component, Machine
    from esp.core.results import AnalysisResult, ToolCase, UncertaintyResult

__all__ = [
    "K_CHANGE",
    "Comparison",
    "ComponentChange",
    "FigureChange",
    "Significance",
    "analysis_uncertainty",
    "change_significance",
    "check_correlation",
    "check_same_evaluation",
    "check_same_machine",
    "compare",
    "component_change",
    "field_change",
    "figure_changes",
    "identical_inputs",
]

AXES = ("X", "Y", "Z")

#: the coverage factor of U(Δ): about 95 % for a normal distribution (GUM 6.3.3), the level
#: at which En <= 1 is the criterion of ISO 13528:2015, 9.7
K_CHANGE = 2.0


@dataclass(frozen=True)
class Significance:
    """A change Δ with its expanded uncertainty and normalised error.

    ``change``: Δ = after - before; ``U_before``, ``U_after``: each calibration's expanded
    uncertainty of the figure with its coverage factor ``k_before``, ``k_after`` (None
    when that side states none); ``correlation``: the r used; ``U``: U(Δ) at ``k``
    (:data:`K_CHANGE`), None when not evaluated; ``En``: |Δ| / U(Δ), None when not
    evaluated; ``reason``: why not (which side has no U for what)."""

    change: float
    U_before: float | None
    U_after: float | None
    k_before: float
    k_after: float
    correlation: float
    U: float | None
    En: float | None
    k: float = K_CHANGE
    reason: str | None = None

    @property
    def significant(self) -> bool | None:
        """Whether the change exceeds what the uncertainties explain (En > 1); None when
        En is not evaluated."""
        return None if self.En is None else bool(self.En > 1.0)

    def as_dict(self) -> dict[str, Any]:
        return {
            "change": self.change,
            "U_before": self.U_before,
            "k_before": self.k_before,
            "U_after": self.U_after,
            "k_after": self.k_after,
            "correlation": self.correlation,
            "U": self.U,
            "k": self.k,
            "En": self.En,
            "significant": self.significant,
            "not_evaluated": self.reason,
        }


def check_correlation(r: float) -> float:
    """``r`` as a correlation coefficient of two calibrations: a number from 0 to 1 (two
    calibrations share error sources, the same instrument, operator or set-up; they do not
    oppose them). Raises :class:`DataError` otherwise."""
    try:
        value = float(r)
    except (TypeError, ValueError):
        value = math.nan
    if not (0.0 <= value <= 1.0):
        raise DataError(f"correlation: expected a correlation coefficient from 0 to 1, found {r!r}")
    return value


def change_significance(
    change: float,
    U_before: float | None,
    U_after: float | None,
    k_before: float = 2.0,
    k_after: float = 2.0,
    correlation: float = 0.0,
    *,
    k: float = K_CHANGE,
    reason: str | None = None,
) -> Significance:
    """The change Δ with U(Δ) and En (module docstring): u = U / k on each side, u(Δ)² =
    u_b² + u_a² - 2 r u_b u_a (GUM 5.2.2, eq. 16), U(Δ) = k u(Δ), En = |Δ| / U(Δ) (ISO
    13528:2015, 9.7). Not evaluated (U and En None, ``reason`` said) when a side has no U;
    when U(Δ) is 0 (both U zero, as at a laser's zero, or r = 1 with equal u), En is 0 for no
    change and not evaluated for a change.

    >>> s = change_significance(3.0, 2.0, 2.0)          # u = 1 and 1, r = 0
    >>> round(s.U, 6), round(s.En, 6), s.significant
    (2.828427, 1.06066, True)
    >>> round(change_significance(3.0, 2.0, 2.0, correlation=0.5).U, 6)
    2.0
    """
    r = check_correlation(correlation)
    if U_before is None or U_after is None:
        if reason is None:
            side = " and ".join(
                w for w, u in (("before", U_before), ("after", U_after)) if u is None
            )
            reason = f"no U {side}"
        return Significance(change, U_before, U_after, k_before, k_after, r, None, None, k, reason)
    ub, ua = U_before / k_before, U_after / k_after
    variance = max(ub * ub + ua * ua - 2.0 * r * ub * ua, 0.0)
    expanded = k * math.sqrt(variance)
    if expanded > 0.0:
        en: float | None = abs(change) / expanded
    elif change == 0.0:  # no change where nothing is uncertain (a laser's zero)
        en = 0.0
    else:
        en = None
        reason = reason or "U(Δ) = 0: the stated uncertainties cancel"
    return Significance(change, U_before, U_after, k_before, k_after, r, expanded, en, k, reason)


def check_same_machine(before: Machine, after: Machine) -> None:
    """Refuse two machines that are not one machine, with one line saying what differs."""
    if before.configuration != after.configuration:
        raise DataError(
            f"not the same machine: configuration {before.configuration} against "
            f"{after.configuration}"
        )
    if dict(before.roles) != dict(after.roles):
        raise DataError(
            f"not the same machine: axes {dict(before.roles)} against {dict(after.roles)}"
        )
    for a in AXES:
        tb, ta = tuple(before.axes[a].travel_mm), tuple(after.axes[a].travel_mm)
        if not np.allclose(tb, ta, atol=1e-9):
            raise DataError(f"not the same machine: axes.{a}.travel {list(tb)} against {list(ta)}")
    sb, sa = before.info.get("serial"), after.info.get("serial")
    if sb and sa and str(sb) != str(sa):
        raise DataError(f"not the same machine: serial {sb} against {sa}")


@dataclass(frozen=True)
class ComponentChange:
    """The change of one component between two calibrations.

    ``unit`` is ``"um"`` or ``"um/m"``; ``max_abs_change`` the largest |after - before|
    and ``at_mm`` the axis position where (None for a squareness); ``range_before`` and
    ``range_after`` the peak-to-peak of each curve (the value for a squareness);
    ``positions_mm``, ``before``, ``after`` the curves compared; ``U_change`` U(Δ) at each
    of those positions (empty when not evaluated); ``significance`` the change at the
    position of its largest En (``significance_at_mm``; at ``at_mm`` when En is not
    evaluated): the component changed significantly when En > 1 there.
    """

    name: str
    unit: str
    max_abs_change: float
    at_mm: float | None
    range_before: float
    range_after: float
    present_before: bool
    present_after: bool
    positions_mm: tuple[float, ...] = ()
    before: tuple[float, ...] = ()
    after: tuple[float, ...] = ()
    U_change: tuple[float, ...] = ()
    significance: Significance | None = None
    significance_at_mm: float | None = None

    @property
    def U_at_max(self) -> float | None:
        """U(Δ) where the change is largest (None when not evaluated)."""
        if not self.U_change:
            return self.significance.U if self.significance is not None else None
        return self.U_change[self.positions_mm.index(self.at_mm)]


def _kind(name: str) -> str:
    parts = str(name).split(".")
    return parts[0] if parts[0] == "squareness" else parts[1]


def _curve(machine: Machine, comp: Component, x: np.ndarray) -> np.ndarray:
    a = machine.analysis
    profile = comp.profile
    if comp.kind == "straightness":
        profile = profile.without_slope(a.straightness_fit)  # type: ignore[union-attr]
    return np.asarray(profile.at(x, direction=a.direction, extrapolate=a.extrapolate), dtype=float)  # type: ignore[union-attr]


def _component_u(machine: Machine, name: str) -> tuple[Any, str | None]:
    """The :class:`esp.core.uncertainty.spec.ComponentU` of component ``name``, or None with
    why (no ``[uncertainty]`` table, or no U for it)."""
    spec = machine.uncertainty
    if spec is None:
        return None, "no [uncertainty] table"
    found = {str(n): cu for n, cu in spec.components.items()}.get(str(name))
    return found, None if found is not None else f"no U for {name}"


def _sides_reason(rb: str | None, ra: str | None) -> str | None:
    parts = [f"{w}: {r}" for w, r in (("before", rb), ("after", ra)) if r]
    return "; ".join(parts) or None


def component_change(
    before: Machine, after: Machine, name: str, correlation: float = 0.0
) -> ComponentChange:
    """The change of component ``name`` from ``before`` to ``after`` with U(Δ) and En from
    each calibration's U of the component (read at each compared position for a U curve)
    and the correlation coefficient ``correlation`` of the two (see the module
    docstring)."""
    r = check_correlation(correlation)
    cb, ca = before.components.get(name), after.components.get(name)
    kind = _kind(name)
    unit = "um" if kind in ("linear", "straightness") else "um/m"
    (ub, why_b), (ua, why_a) = _component_u(before, name), _component_u(after, name)
    reason = _sides_reason(why_b, why_a)

    def significance(delta: float, at: float | None) -> Significance:
        return change_significance(
            delta,
            None if ub is None else ub.U_at(at),
            None if ua is None else ua.U_at(at),
            2.0 if ub is None else ub.coverage_k,
            2.0 if ua is None else ua.coverage_k,
            r,
            reason=reason,
        )

    if kind == "squareness":
        vb = float(cb.value or 0.0) if cb is not None else 0.0
        va = float(ca.value or 0.0) if ca is not None else 0.0
        return ComponentChange(
            str(name),
            unit,
            abs(va - vb),
            None,
            vb,
            va,
            cb is not None,
            ca is not None,
            significance=significance(va - vb, None),
        )
    axis = str(name).split(".")[0]
    lo, hi = (float(v) for v in before.axes[axis].travel_mm)
    targets = []
    for comp in (cb, ca):
        if comp is not None:
            t = np.asarray(comp.profile.targets_mm, dtype=float)  # type: ignore[union-attr]
            if t.size > 1:
                lo, hi = max(lo, float(t[0])), min(hi, float(t[-1]))
            targets.append(t)
    if hi < lo:
        raise DataError(f"{name}: the two calibrations measured no common range")
    x = np.unique(
        np.concatenate([np.array([lo, hi])] + [t[(t >= lo) & (t <= hi)] for t in targets])
    )
    yb = _curve(before, cb, x) if cb is not None else np.zeros_like(x)
    ya = _curve(after, ca, x) if ca is not None else np.zeros_like(x)
    if kind in ("linear", "angular", "mechanical"):
        yb, ya = yb - yb[0], ya - ya[0]
    d = ya - yb
    i = int(np.argmax(np.abs(d)))
    found = [significance(float(d[j]), float(x[j])) for j in range(x.size)]
    u_change: tuple[float, ...] = ()
    j = i
    if all(f.U is not None for f in found):
        u_change = tuple(float(f.U or 0.0) for f in found)
        en = [math.inf if f.En is None else f.En for f in found]
        j = int(np.argmax(en))
        if en[j] <= en[i]:  # the largest change is the most significant one: say it there
            j = i
    return ComponentChange(
        str(name),
        unit,
        float(abs(d[i])),
        float(x[i]),
        float(np.ptp(yb)),
        float(np.ptp(ya)),
        cb is not None,
        ca is not None,
        tuple(x.tolist()),
        tuple(yb.tolist()),
        tuple(ya.tolist()),
        u_change,
        found[j],
        float(x[j]),
    )


def _tool_key(tool: ToolCase) -> tuple:
    """What identifies a tool case across two calibrations (not its errors)."""
    return (
        tool.length_mm,
        tool.tilt_deg,
        tool.spin_deg,
        tuple(round(float(tool.offset_mm[a]), 9) for a in AXES),
        tuple(sorted((tool.setting_deg or {}).items())),
    )


def _describe_tools(tools: Sequence[ToolCase]) -> str:
    if len(tools) == 1 and not tools[0].setting_deg:
        t = tools[0]
        return "no tool" if t.length_mm is None else f"tool {dict(t.offset_mm)} mm"
    return f"{len(tools)} tool cases or settings"


def check_same_evaluation(before: MachineEvaluation, after: MachineEvaluation) -> None:
    """Refuse two evaluations (:class:`esp.core.evaluation.MachineEvaluation`) that do not
    compare like with like, with one line saying what differs (module docstring)."""
    mb, ma = before.machine, after.machine
    for key in (
        "point",
        "compensation",
        "model",
        "angle_convention",
        "direction",
        "straightness_fit",
    ):
        vb, va = getattr(mb.analysis, key), getattr(ma.analysis, key)
        if vb != va:
            raise DataError(
                f"not comparable: analysis.{key} is {vb!r} before and {va!r} after; "
                "compare two calibrations evaluated the same way"
            )
    case_b, case_a = before.synthesis.model.case, after.synthesis.model.case
    if case_b != case_a:
        raise DataError(f"not comparable: evaluation case {case_b} before and {case_a} after")
    db, da = before.datum, after.datum
    if (db is None) != (da is None) or (
        db is not None and da is not None and any(abs(db[a] - da[a]) > 1e-9 for a in AXES)
    ):
        raise DataError(f"not comparable: datum {db} before and {da} after")
    if (mb.head is None) != (ma.head is None) or (mb.table is None) != (ma.table is None):
        what = {True: "with", False: "without"}
        raise DataError(
            "not comparable: a machine "
            f"{what[mb.head is not None or mb.table is not None]} a head or rotary table "
            f"before and {what[ma.head is not None or ma.table is not None]} one after"
        )
    tb = [_tool_key(t) for t in before.tools]
    ta = [_tool_key(t) for t in after.tools]
    if tb != ta:
        raise DataError(
            f"not comparable: {_describe_tools(before.tools)} before and "
            f"{_describe_tools(after.tools)} after; compare the same tool or head/table "
            "settings"
        )
    for a in AXES:
        gb, ga = before.synthesis.grids[a], after.synthesis.grids[a]
        if gb.shape != ga.shape or not np.allclose(gb, ga, rtol=0.0, atol=1e-9):
            raise DataError(
                f"not comparable: the simulation grid of {a} differs ({gb.size} points "
                f"from {gb[0]:g} to {gb[-1]:g} mm before, {ga.size} from {ga[0]:g} to "
                f"{ga[-1]:g} mm after); give both the same axes.{a}.simulate and step"
            )


def _grid(grids: Mapping[str, np.ndarray]) -> np.ndarray:
    mesh = np.meshgrid(*(grids[a] for a in AXES), indexing="ij")
    return np.stack([m.ravel() for m in mesh], axis=1)


def field_change(before: Evaluation, after: Evaluation) -> dict[str, Any]:
    """The change of the error field between two evaluations of one case
    (:class:`esp.core.evaluation.Evaluation`) on their common simulation grid: the largest |Δe|
    (µm) and where, and the largest |Δe| of each direction."""
    pts = _grid(before.grids)
    delta = after.errors_at(pts) - before.errors_at(pts)
    norm = np.sqrt(np.sum(delta * delta, axis=1))
    i = int(np.argmax(norm))
    axes = {}
    for k, a in enumerate(AXES):
        j = int(np.argmax(np.abs(delta[:, k])))
        axes[a] = {
            "value_um": float(delta[j, k]),
            "at": {b: float(pts[j, m]) for m, b in enumerate(AXES)},
        }
    return {
        "max_um": float(norm[i]),
        "at": {a: float(pts[i, k]) for k, a in enumerate(AXES)},
        "vector_um": {a: float(delta[i, k]) for k, a in enumerate(AXES)},
        "directions": axes,
        "points": int(pts.shape[0]),
    }


def _worst_field_change(
    before_result: AnalysisResult, after_result: AnalysisResult
) -> dict[str, Any]:
    """The field change of the worst tool case of each calibration (one when both have the
    same), the larger of the two: it bounds the change of every accuracy reported."""
    eb, ea = before_result.evaluation, after_result.evaluation
    pb, pa = eb.machine_evaluation, ea.machine_evaluation
    keys = [_tool_key(t) for t in pb.tools]
    found = []
    for tool in dict.fromkeys([keys.index(_tool_key(eb.tool)), keys.index(_tool_key(ea.tool))]):
        found.append(field_change(pb.case(pb.tools[tool]), pa.case(pa.tools[tool])))
    return max(found, key=lambda f: f["max_um"])


@dataclass(frozen=True)
class FigureChange:
    """The change of one accuracy figure or of the error field, with its significance.

    ``key``: ``"volumetric"``, ``"planar.XY"`` ..., ``"field"`` (the largest |Δe|) or
    ``"field.X"`` ... (the largest change of a direction); ``label`` its name in words;
    ``before``, ``after`` the two figures (None for the field, which is a change);
    ``change`` after - before (for the field: |Δe|, or Δe of the direction);
    ``basis`` which U of each calibration is used (:func:`figure_changes`)."""

    key: str
    label: str
    before: float | None
    after: float | None
    change: float
    significance: Significance
    basis: str


@dataclass(frozen=True)
class Comparison:
    """The outcome of :func:`compare` (µm, positions as axis -> mm); ``figures`` the
    changes of the accuracies and of the error field with their U(Δ) and En,
    ``correlation`` the correlation coefficient of the two calibrations used."""

    components: tuple[ComponentChange, ...]
    volumetric_before: tuple[float, Mapping[str, float]]
    volumetric_after: tuple[float, Mapping[str, float]]
    planar_before: Mapping[str, float]
    planar_after: Mapping[str, float]
    field: Mapping[str, object]
    identical_inputs: bool = False
    figures: tuple[FigureChange, ...] = ()
    correlation: float = 0.0
    not_evaluated: Mapping[str, str | None] = dataclass_field(default_factory=dict)

    @property
    def volumetric_change_um(self) -> float:
        return self.volumetric_after[0] - self.volumetric_before[0]

    def figure(self, key: str) -> FigureChange | None:
        """The figure change of ``key`` (``"volumetric"``, ``"planar.XY"``, ``"field"``,
        ``"field.X"`` ...), or None."""
        return next((f for f in self.figures if f.key == key), None)

    @property
    def unchanged(self) -> bool:
        """Whether nothing changed: every component, the error field, the volumetric and
        every planar accuracy are exactly the same in both calibrations."""
        return (
            all(x.max_abs_change == 0.0 for x in self.components)
            and self.field.get("max_um") == 0.0
            and self.volumetric_change_um == 0.0
            and dict(self.planar_before) == dict(self.planar_after)
        )


def identical_inputs(before: Machine, after: Machine) -> bool:
    """Whether the two machines were read from identical inputs: as many files, each the
    same file or a byte-for-byte copy of its counterpart (False for machines built in code,
    which name no inputs)."""
    import filecmp
    import os

    if not before.inputs or len(before.inputs) != len(after.inputs):
        return False
    for a, b in zip(before.inputs, after.inputs, strict=True):
        try:
            if not (os.path.samefile(a, b) or filecmp.cmp(a, b, shallow=False)):
                return False
        except OSError:  # a file gone since it was read: not known to be identical
            return False
    return True


def _accuracy(
    result: AnalysisResult,
) -> tuple[tuple[float, dict[str, float]], dict[str, float]]:
    case = result.cases[result.worst]
    planar = {k: float(v.value_um) for k, v in case.planar.items()}
    return (float(case.volumetric.value_um), dict(case.volumetric.at)), planar


def analysis_uncertainty(result: AnalysisResult) -> tuple[UncertaintyResult | None, str | None]:
    """The volumetric uncertainty of an analysis when it is complete, or None and why: no
    ``[uncertainty]`` table, or no U for a component the model uses (an uncertainty that
    leaves out a component is not the uncertainty of the figure)."""
    missing = result.uncertainty_missing  # the analysis then evaluates no U
    if missing:
        return None, "no U for " + ", ".join(str(n) for n in missing)
    if result.uncertainty is None:
        return None, "no [uncertainty] table"
    return result.uncertainty, None


def figure_changes(
    before: AnalysisResult,
    after: AnalysisResult,
    field: Mapping[str, Any],
    correlation: float = 0.0,
) -> tuple[FigureChange, ...]:
    """The changes of the volumetric and planar accuracy and of the error field, each with
    U(Δ) and En from the two analyses' uncertainties (:func:`change_significance`).

    Each side's U is the largest over the volume that the analysis reports
    (:class:`esp.core.results.UncertaintyResult`): ``volumetric`` for the volumetric
    accuracy, for the largest |Δe| and, as a bound, for a planar accuracy (the vector sum of
    two directions never exceeds that of three at one point); ``axes[d]`` for the change of
    direction d. A U larger than the one at the figure's point makes En smaller: a change
    marked significant is so; one marked not significant is so at this bound."""
    r = check_correlation(correlation)
    ub, why_b = analysis_uncertainty(before)
    ua, why_a = analysis_uncertainty(after)
    reason = _sides_reason(why_b, why_a)
    kb = ub.k if ub is not None else 2.0
    ka = ua.k if ua is not None else 2.0

    def volumetric(u: UncertaintyResult | None) -> float | None:
        return None if u is None else float(u.volumetric.value_um)

    def direction(u: UncertaintyResult | None, d: str) -> float | None:
        return None if u is None else float(u.axes[d].value_um)

    def sig(change: float, b: float | None, a: float | None) -> Significance:
        return change_significance(change, b, a, kb, ka, r, reason=reason)

    vb, pb = _accuracy(before)
    va, pa = _accuracy(after)
    volume = "the volumetric U of each calibration"
    out = [
        FigureChange(
            "volumetric",
            "volumetric accuracy",
            vb[0],
            va[0],
            va[0] - vb[0],
            sig(va[0] - vb[0], volumetric(ub), volumetric(ua)),
            volume,
        )
    ]
    for plane, b in pb.items():
        a = pa.get(plane, 0.0)
        out.append(
            FigureChange(
                f"planar.{plane}",
                f"planar accuracy {plane}",
                b,
                a,
                a - b,
                sig(a - b, volumetric(ub), volumetric(ua)),
                "bound: " + volume,
            )
        )
    out.append(
        FigureChange(
            "field",
            "largest change of the error field",
            None,
            None,
            float(field["max_um"]),
            sig(float(field["max_um"]), volumetric(ub), volumetric(ua)),
            volume,
        )
    )
    for d in AXES:
        change = float(field["directions"][d]["value_um"])
        out.append(
            FigureChange(
                f"field.{d}",
                f"largest change in {d}",
                None,
                None,
                change,
                sig(change, direction(ub, d), direction(ua, d)),
                f"the largest U in {d} of each calibration",
            )
        )
    return tuple(out)


def compare(before: Machine, after: Machine, correlation: float = 0.0) -> Comparison:
    """Compare two calibrations of one machine; ``correlation`` the correlation coefficient
    r of their uncertainties, 0 to 1 (0: independent). Raises :class:`DataError` for two
    machines, for two evaluations that do not compare like with like, or for an r outside
    0 to 1."""
    from esp.core.analysis import analyse
    from esp.core.evaluation import evaluate

    r = check_correlation(correlation)
    check_same_machine(before, after)
    check_same_evaluation(evaluate(before), evaluate(after))
    names = sorted(
        {str(n) for n in before.components} | {str(n) for n in after.components},
        key=lambda n: (n.startswith("squareness"), n),
    )
    changes = tuple(component_change(before, after, n, r) for n in names)
    rb, ra = analyse(before), analyse(after)
    vb, pb = _accuracy(rb)
    va, pa = _accuracy(ra)
    field = _worst_field_change(rb, ra)
    return Comparison(
        changes,
        vb,
        va,
        pb,
        pa,
        field,
        identical_inputs(before, after),
        figure_changes(rb, ra, field, r),
        r,
        {"before": analysis_uncertainty(rb)[1], "after": analysis_uncertainty(ra)[1]},
    )
