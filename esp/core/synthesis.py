"""Volumetric synthesis: the total geometric displacement error of every direction over the
working volume, and from it the volumetric and planar accuracy, where they occur and which
components cause them.

Definitions (Longstaff 2002, 3.05): the total geometric displacement error of a direction
is the sum of the linear effects of all errors in that direction (the equation set of the
case, :mod:`esp.core.models.esp`); the volumetric error at a point is the vector sum of the three
(eq. 3.4); the volumetric accuracy is its maximum over the volume (eq. 3.5); planar error
and accuracy are the same for two directions (3.05.4-3.05.5). With a datum every total is
reported as ``e(p) - e(datum)`` (3.05; ESP-NOTES).

Evaluation is separable (:mod:`esp.core.grid`): each component is evaluated once on its own
axis' grid, each lever once on its axis' grid, and the 3-D field is only ever formed in
small blocks.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass

import numpy as np

from esp.core.errors import DataError
from esp.core.grid import PAIRS, Product, fold, scan, volumetric_peak
from esp.core.machine import AXIS_NAMES, Machine
from esp.core.models.bind import BoundModel, BoundTerm, bind_model
from esp.core.models.tool import SettingTerm, ToolCase, tool_cases
from esp.core.profile import ErrorProfile
from esp.core.results import (
    AxisExtremes,
    Breakdown,
    CaseResult,
    Extreme,
    TermValue,
)

__all__ = [
    "Synthesis",
    "case_result",
    "datum_point",
    "plane_of_motion",
    "tool_cases",
    "volumetric_extreme",
]

Progress = Callable[[int, int], None]


@dataclass
class Synthesis:
    """A machine prepared for evaluation: its bound model, its component curves, its grids.

    ``values`` optionally replaces the data of components by name: a callable of position
    (mm array -> array in the engine unit) or a number (a constant) -- the uncertainty
    propagation runs the same model with U in place of each error this way. With
    ``measured=False`` the components' curves are not measurements (uncertainties U) and are
    used exactly as given: no straightness slope removed, no sign convention applied, the
    mean of the runs.
    """

    machine: Machine
    model: BoundModel
    grids: dict[str, np.ndarray]
    functions: dict[str, Callable[[np.ndarray], np.ndarray] | float]
    warnings: list[str]
    #: the errors of a head or rotary table count (not for uncertainties: they are errors)
    setting_errors: bool = True

    @classmethod
    def prepare(
        cls, machine: Machine, values: Mapping | None = None, *, measured: bool = True
    ) -> Synthesis:
        model = bind_model(machine)
        grids = {a: machine.axes[a].grid_mm() for a in AXIS_NAMES}
        warnings = list(model.warnings)
        functions: dict[str, Callable | float] = {}
        analysis = machine.analysis
        for name in model.active + tuple(n for n in (values or {}) if n not in model.active):
            if values is not None and name in values:
                v = values[name]
                functions[name] = v if callable(v) else float(v)
                continue
            comp = machine.components.get(name)
            if comp is None:
                continue
            if comp.kind == "squareness":
                functions[name] = float(comp.value or 0.0)
                continue
            # every component but a squareness is a curve of its axis' position
            profile = comp.profile
            assert profile is not None and comp.axis is not None, name
            direction = analysis.direction
            if measured:
                if comp.kind == "straightness":
                    profile = profile.without_slope(analysis.straightness_fit)
                # the model's sign convention (angle_convention, from_linear angles)
                profile = profile.scaled(model.input_signs.get(name, 1.0))
            else:
                direction = "mean"
            # fix the direction and the extrapolation rule once; check the range here so
            # the message can name the component and the configuration key
            functions[name] = _curve(profile, direction, analysis.extrapolate)
            if profile.targets_mm.size > 1:
                lo, hi = float(profile.targets_mm[0]), float(profile.targets_mm[-1])
                g = grids[comp.axis]
                if g[0] < lo - 1e-9 or g[-1] > hi + 1e-9:
                    what = (
                        f"{name} ({comp.source}) is measured from {lo:g} to {hi:g} mm but "
                        f"axes.{comp.axis}.simulate runs from {g[0]:g} to {g[-1]:g} mm"
                    )
                    if not analysis.extrapolate:
                        raise DataError(
                            f"{what}; narrow the simulation range or set "
                            f"analysis.extrapolate = true to hold the end values"
                        )
                    warnings.append(f"{what}: end values held beyond the measured range")
        return cls(machine, model, grids, functions, warnings, setting_errors=measured)

    # -- terms ---------------------------------------------------------------------------

    def terms(self) -> list[BoundTerm]:
        """The bound terms whose component has data (or a replacement value)."""
        return [t for t in self.model.terms if t.component in self.functions]

    def _function(self, bt: BoundTerm) -> Callable[[np.ndarray], np.ndarray] | float:
        # a ComponentName hashes and compares like its text (esp.core.names): the same key
        return self.functions[str(bt.component)]

    def _constant(self, bt: BoundTerm) -> float:
        """The value of a term's component that is not a curve (a squareness)."""
        fn = self._function(bt)
        assert not callable(fn), f"{bt.component} is a curve, not a constant"
        return fn

    def component_at(self, bt: BoundTerm, x: np.ndarray | float) -> np.ndarray | float:
        """The value of the term's component at position(s) ``x`` (engine units)."""
        fn = self._function(bt)
        if callable(fn):
            return fn(np.asarray(x, dtype=float))
        return fn

    def term_value_um(self, bt: BoundTerm, point: Mapping[str, float], tool: ToolCase) -> float:
        """The value of one term at one point, in µm."""
        value = self.component_at(bt, point[bt.axis]) if bt.axis else self._constant(bt)
        lever = 0.0
        if bt.lever_axis:
            lever += bt.lever_sign * (point[bt.lever_axis] - bt.lever_offset_mm)
        if bt.tool_axis:
            lever += bt.tool_sign * tool.offset_mm[bt.tool_axis]
        if bt.is_angle:
            return float(bt.sign * value * lever / 1000.0)
        return float(bt.sign * value)

    def totals_at_um(self, points_mm: np.ndarray, tool: ToolCase) -> np.ndarray:
        """The total displacement error of each direction at many points, shape (N, 3) in
        µm for ``points_mm`` of shape (N, 3) (columns X, Y, Z; no datum)."""
        pts = np.asarray(points_mm, dtype=float).reshape(-1, 3)
        index = {a: i for i, a in enumerate(AXIS_NAMES)}
        out = np.zeros_like(pts)
        for bt in self.terms():
            if bt.axis:
                value = np.asarray(self.component_at(bt, pts[:, index[bt.axis]]), dtype=float)
            else:
                value = np.full(len(pts), float(self._constant(bt)))
            if bt.is_angle:
                lever = np.zeros(len(pts))
                if bt.lever_axis:
                    lever += bt.lever_sign * (pts[:, index[bt.lever_axis]] - bt.lever_offset_mm)
                if bt.tool_axis:
                    lever += bt.tool_sign * tool.offset_mm[bt.tool_axis]
                value = value * lever / 1000.0
            out[:, index[bt.direction]] += bt.sign * value
        for t in self.setting_terms_of(tool):
            for a in AXIS_NAMES:
                out[:, index[a]] += t.constant_um.get(a, 0.0)
                for j, c in t.per_mm.get(a, {}).items():
                    out[:, index[a]] += c * pts[:, index[j]]
        return out

    def totals_um(self, point: Mapping[str, float], tool: ToolCase) -> dict[str, float]:
        """The total displacement error of each direction at one point, in µm (no datum)."""
        totals = {a: 0.0 for a in AXIS_NAMES}
        for bt in self.terms():
            totals[bt.direction] += self.term_value_um(bt, point, tool)
        for t in self.setting_terms_of(tool):
            for a in AXIS_NAMES:
                totals[a] += t.value_um(a, point)
        return totals

    def setting_terms_of(self, tool: ToolCase) -> tuple[SettingTerm, ...]:
        """The errors of a servo head or rotary table at this tool case's setting (none
        when this Synthesis does not count them, :attr:`setting_errors`)."""
        return tool.setting_terms if self.setting_errors else ()

    def products(
        self,
        tool: ToolCase,
        datum: Mapping[str, float] | None,
        *,
        reference: ToolCase | None = None,
        grids: Mapping[str, np.ndarray] | None = None,
    ) -> list[Product]:
        """The separable products of every active term for one tool case, on ``grids``
        (default: the simulation grids). With a datum the error of the tool case
        ``reference`` (default: ``tool``) at the datum is subtracted
        (:class:`esp.core.evaluation.Evaluation` decides which)."""
        index = {a: i for i, a in enumerate(AXIS_NAMES)}
        grids = self.grids if grids is None else grids
        out: list[Product] = []
        for bt in self.terms():
            d = index[bt.direction]
            scale = float(bt.sign) * (1e-3 if bt.is_angle else 1.0)
            f: np.ndarray | None
            if bt.axis:
                fa, f = index[bt.axis], np.asarray(self.component_at(bt, grids[bt.axis]))
                if f.ndim == 0:
                    f = np.full(grids[bt.axis].shape, float(f))
            else:
                fa, f = None, None
                scale *= float(self._constant(bt))
            if not bt.is_angle:
                out.append(Product(d, scale, fa, f))
                continue
            if bt.lever_axis:
                c = index[bt.lever_axis]
                g = bt.lever_sign * (grids[bt.lever_axis] - bt.lever_offset_mm)
                out.append(Product(d, scale, fa, f, c, g))
            if bt.tool_axis:
                p = bt.tool_sign * tool.offset_mm[bt.tool_axis]
                if p != 0.0:
                    out.append(Product(d, scale * p, fa, f))
        for t in self.setting_terms_of(tool):
            for a in AXIS_NAMES:
                if t.constant_um.get(a, 0.0):
                    out.append(Product(index[a], t.constant_um[a]))
                for j, per_mm in t.per_mm.get(a, {}).items():
                    if per_mm:
                        out.append(Product(index[a], per_mm, c=index[j], g=grids[j]))
        if datum is not None:
            ref = self.totals_um(datum, reference or tool)
            out.extend(Product(index[a], -ref[a]) for a in AXIS_NAMES)
        return out

    def squared_products(self, tool: ToolCase) -> list[Product]:
        """Each term's square, separable as the term itself: (s·f(a)·g(c))² = s²·f²·g²
        (the root-sum-square combination of thesis 3.14.7); with the errors of a head or
        table setting, each one's square too: a constant c for a head, an affine
        c + Σ a_j·x_j for a table, whose square expands into products of at most two
        coordinates, exactly."""
        index = {a: i for i, a in enumerate(AXIS_NAMES)}
        out = []
        for bt in self.terms():
            d = index[bt.direction]
            scale = 1e-6 if bt.is_angle else 1.0
            if bt.axis:
                a = index[bt.axis]
                f = np.asarray(self.component_at(bt, self.grids[bt.axis]), dtype=float)
                f = np.broadcast_to(f, self.grids[bt.axis].shape) ** 2
            else:
                a, f = None, None
                scale *= float(self._constant(bt)) ** 2
            if not bt.is_angle:
                out.append(Product(d, scale, a, f))
                continue
            p = bt.tool_sign * tool.offset_mm[bt.tool_axis] if bt.tool_axis else 0.0
            if bt.lever_axis:
                g = bt.lever_sign * (self.grids[bt.lever_axis] - bt.lever_offset_mm) + p
                out.append(Product(d, scale, a, f, index[bt.lever_axis], g**2))
            elif p:
                out.append(Product(d, scale * p * p, a, f))
        for t in self.setting_terms_of(tool):
            for direction in AXIS_NAMES:
                dd = index[direction]
                c = t.constant_um.get(direction, 0.0)
                slopes = [(j, v) for j, v in t.per_mm.get(direction, {}).items() if v]
                out.append(Product(dd, c * c))
                for m, (j, aj) in enumerate(slopes):
                    x = self.grids[j]
                    out.append(Product(dd, 2.0 * c * aj, index[j], x))
                    out.append(Product(dd, aj * aj, index[j], x * x))
                    for k, ak in slopes[m + 1 :]:
                        out.append(Product(dd, 2.0 * aj * ak, index[j], x, index[k], self.grids[k]))
        return out

    def breakdown(
        self,
        label: str,
        point: Mapping[str, float],
        tool: ToolCase,
        datum: Mapping[str, float] | None,
        *,
        reference: ToolCase | None = None,
    ) -> Breakdown:
        """Every active term at ``point`` (relative to the datum when one is set, with the
        value of the tool case ``reference``, default ``tool``, there); terms whose only
        lever is a tool offset that this tool case does not have are left out."""
        # directions in X, Y, Z order, terms within a direction as printed
        ordered = sorted(self.terms(), key=lambda bt: AXIS_NAMES.index(bt.direction))
        # the tool cases whose offsets give a term a lever here: this one, and the
        # reference setting's when a datum refers the errors to it
        reference = reference or tool
        tools = [tool] if datum is None else [tool, reference]
        terms = [
            bt
            for bt in ordered
            if not (
                bt.is_angle
                and bt.lever_axis is None
                and (bt.tool_axis is None or all(t.offset_mm[bt.tool_axis] == 0.0 for t in tools))
            )
        ]
        values = []
        for bt in terms:
            v = self.term_value_um(bt, point, tool)
            if datum is not None:
                v -= self.term_value_um(bt, datum, reference)
            values.append(v)
        totals = {a: 0.0 for a in AXIS_NAMES}
        for bt, v in zip(terms, values, strict=True):
            totals[bt.direction] += v
        # the terms of a head or rotary table at this setting, less their value at the
        # datum with the reference setting when a datum is set
        head = []
        here = {t.component: t for t in self.setting_terms_of(tool)}
        there = {}
        if datum is not None:
            there = {t.component: t for t in self.setting_terms_of(reference)}
        for name in dict.fromkeys([*here, *there]):
            t = here.get(name) or there[name]
            for a in AXIS_NAMES:
                v = here[name].value_um(a, point) if name in here else 0.0
                if datum is not None and name in there:
                    v -= there[name].value_um(a, datum)
                if abs(v) > 1e-12:  # a term that does not act along this direction
                    head.append((a, t.component, t.source, t.symbol, v))
                    totals[a] += v
        records = []
        for bt, v in zip(terms, values, strict=True):
            total = totals[bt.direction]
            share = None if abs(total) < 1e-12 else 100.0 * v / total
            records.append(
                TermValue(bt.direction, bt.component, bt.iso, bt.source, bt.symbol, v, share)
            )
        for a, component, source, symbol, v in sorted(head, key=lambda h: AXIS_NAMES.index(h[0])):
            share = None if abs(totals[a]) < 1e-12 else 100.0 * v / totals[a]
            records.append(TermValue(a, component, "", source, symbol, v, share))
        vol = math.sqrt(sum(v * v for v in totals.values()))
        return Breakdown(label, dict(point), totals, vol, tuple(records))


def _curve(
    profile: ErrorProfile, direction: str, extrapolate: bool
) -> Callable[[np.ndarray], np.ndarray]:
    def at(x: np.ndarray) -> np.ndarray:
        return profile.at(x, direction=direction, extrapolate=extrapolate)

    return at


def datum_point(machine: Machine) -> dict[str, float] | None:
    datum = machine.analysis.datum
    if isinstance(datum, str):
        if datum == "none":
            return None
        if datum == "negative":
            return {a: float(machine.axes[a].travel_mm[0]) for a in AXIS_NAMES}
        if datum == "centre":
            return {a: float(sum(machine.axes[a].travel_mm) / 2.0) for a in AXIS_NAMES}
        raise DataError(f"unknown datum {datum!r}; expected none, negative, centre or a point")
    return {a: float(datum[a]) for a in AXIS_NAMES}


def _at(grids: Mapping[str, np.ndarray], index: tuple[int, int, int]) -> dict[str, float]:
    return {a: float(grids[a][i]) for a, i in zip(AXIS_NAMES, index, strict=True)}


def plane_of_motion(grids: Mapping[str, np.ndarray]) -> str | None:
    """The two axes that move when exactly one axis is held at a single position (a
    two-axis machine such as a turning centre, thesis 4.02), else None."""
    moving = [a for a in AXIS_NAMES if grids[a].size > 1]
    return "".join(moving) if len(moving) == 2 else None


def case_result(
    syn: Synthesis,
    tool: ToolCase,
    datum: Mapping[str, float] | None,
    breakdowns: bool,
    *,
    reference: ToolCase | None = None,
) -> CaseResult:
    """The extremes of one tool case over the grid, with the breakdowns at each when
    ``breakdowns`` (a swept orientation needs only its volumetric accuracy). ``reference``:
    the tool case whose error at the datum is subtracted (default ``tool``; see
    :class:`esp.core.evaluation.Evaluation`, which is how the analysis calls this)."""
    products = syn.products(tool, datum, reference=reference)
    stats = scan(fold(products, tuple(syn.grids[a].size for a in AXIS_NAMES)))
    g = syn.grids
    axes = {
        a: AxisExtremes(
            Extreme(stats.minimum[i][0], _at(g, stats.minimum[i][1])),
            Extreme(stats.maximum[i][0], _at(g, stats.maximum[i][1])),
        )
        for i, a in enumerate(AXIS_NAMES)
    }
    # with one axis not moving only the plane of motion has a planar accuracy
    only = plane_of_motion(g)
    planar = {
        AXIS_NAMES[p] + AXIS_NAMES[q]: Extreme(stats.planar[k][0], _at(g, stats.planar[k][1]))
        for k, (p, q) in enumerate(PAIRS)
        if only is None or AXIS_NAMES[p] + AXIS_NAMES[q] == only
    }
    volumetric = Extreme(stats.volumetric[0], _at(g, stats.volumetric[1]))
    records: list[Breakdown] = []
    if breakdowns:

        def breakdown(label: str, at: Mapping[str, float]) -> Breakdown:
            return syn.breakdown(label, at, tool, datum, reference=reference)

        records.append(breakdown("volumetric", volumetric.at))
        for plane, ext in planar.items():
            records.append(breakdown(f"planar {plane}", ext.at))
        for a, extremes in axes.items():
            records.append(breakdown(f"{a} min", extremes.minimum.at))
            records.append(breakdown(f"{a} max", extremes.maximum.at))
    return CaseResult(tool, volumetric, planar, axes, tuple(records), stats.points)


def volumetric_extreme(
    syn: Synthesis,
    tool: ToolCase,
    datum: Mapping[str, float] | None,
    *,
    reference: ToolCase | None = None,
) -> Extreme:
    """The volumetric accuracy of one tool case and where it occurs, found without the
    other extremes (what a swept orientation reports; thesis 3.12). Identical to
    ``case_result(...).volumetric``."""
    sizes = tuple(syn.grids[a].size for a in AXIS_NAMES)
    value, index = volumetric_peak(fold(syn.products(tool, datum, reference=reference), sizes))
    return Extreme(value, _at(syn.grids, index))
