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

This module imports only numpy and the standard library.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from esp.core.errors import DataError

if TYPE_CHECKING:
    from esp.core.evaluation import Evaluation, MachineEvaluation
    from esp.core.machine import Component, Machine
    from esp.core.results import AnalysisResult, ToolCase

__all__ = [
    "Comparison",
    "ComponentChange",
    "check_same_evaluation",
    "check_same_machine",
    "compare",
    "component_change",
    "field_change",
    "identical_inputs",
]

AXES = ("X", "Y", "Z")


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
    ``positions_mm``, ``before``, ``after`` the curves compared.
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


def _kind(name: str) -> str:
    parts = str(name).split(".")
    return parts[0] if parts[0] == "squareness" else parts[1]


def _curve(machine: Machine, comp: Component, x: np.ndarray) -> np.ndarray:
    a = machine.analysis
    profile = comp.profile
    if comp.kind == "straightness":
        profile = profile.without_slope(a.straightness_fit)  # type: ignore[union-attr]
    return np.asarray(profile.at(x, direction=a.direction, extrapolate=a.extrapolate), dtype=float)  # type: ignore[union-attr]


def component_change(before: Machine, after: Machine, name: str) -> ComponentChange:
    """The change of component ``name`` from ``before`` to ``after`` (see the module
    docstring)."""
    cb, ca = before.components.get(name), after.components.get(name)
    kind = _kind(name)
    unit = "um" if kind in ("linear", "straightness") else "um/m"
    if kind == "squareness":
        vb = float(cb.value or 0.0) if cb is not None else 0.0
        va = float(ca.value or 0.0) if ca is not None else 0.0
        return ComponentChange(
            str(name), unit, abs(va - vb), None, vb, va, cb is not None, ca is not None
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
class Comparison:
    """The outcome of :func:`compare` (µm, positions as axis -> mm)."""

    components: tuple[ComponentChange, ...]
    volumetric_before: tuple[float, Mapping[str, float]]
    volumetric_after: tuple[float, Mapping[str, float]]
    planar_before: Mapping[str, float]
    planar_after: Mapping[str, float]
    field: Mapping[str, object]
    identical_inputs: bool = False

    @property
    def volumetric_change_um(self) -> float:
        return self.volumetric_after[0] - self.volumetric_before[0]

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


def compare(before: Machine, after: Machine) -> Comparison:
    """Compare two calibrations of one machine (raises :class:`DataError` for two
    machines, or for two evaluations that do not compare like with like)."""
    from esp.core.analysis import analyse
    from esp.core.evaluation import evaluate

    check_same_machine(before, after)
    check_same_evaluation(evaluate(before), evaluate(after))
    names = sorted(
        {str(n) for n in before.components} | {str(n) for n in after.components},
        key=lambda n: (n.startswith("squareness"), n),
    )
    changes = tuple(component_change(before, after, n) for n in names)
    rb, ra = analyse(before), analyse(after)
    vb, pb = _accuracy(rb)
    va, pa = _accuracy(ra)
    return Comparison(
        changes, vb, va, pb, pa, _worst_field_change(rb, ra), identical_inputs(before, after)
    )
