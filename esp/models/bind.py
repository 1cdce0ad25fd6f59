"""Bind an equation set, written with the roles B, M and T, to one machine.

Binding turns every :class:`~esp.models.terms.Term` into a :class:`BoundTerm` that names
the machine's own component (``X.angular.Y``), the axis letter whose coordinate the
component is a function of, and the lever axis with its measurement offset. It also sorts
the machine's inputs into what the case uses (active), what it would use but was not given
(not active, hence zero), and what it was given but does not use (ignored), with warnings
where the thesis says an input is needed (Longstaff 2002, 3.10 and 3.12.1).
"""

from __future__ import annotations

from dataclasses import dataclass

from esp.machine import Component, Machine
from esp.models.esp import EquationSet, equation_set, evaluation_case
from esp.models.terms import Term
from esp.models.tool import tool_cases
from esp.names import ComponentName

__all__ = ["BoundModel", "BoundTerm", "bind_model"]


@dataclass(frozen=True)
class BoundTerm:
    """A term with machine axis letters.

    ``axis`` is the letter whose coordinate the component is a function of (None for
    squareness, a constant); ``lever_axis``/``lever_offset_mm`` give the coordinate part
    of the lever, ``tool_axis`` the tool-offset part. ``direction`` is a machine letter.
    """

    term: Term
    direction: str
    component: ComponentName
    axis: str | None
    lever_axis: str | None
    lever_sign: int
    lever_offset_mm: float
    tool_axis: str | None
    tool_sign: int

    @property
    def sign(self) -> int:
        return self.term.sign

    @property
    def is_angle(self) -> bool:
        return self.term.is_angle

    @property
    def source(self) -> str:
        return self.term.source

    @property
    def iso(self) -> str:
        return self.component.iso


@dataclass(frozen=True)
class BoundModel:
    """An equation set bound to a machine.

    ``terms`` holds every term of the set (active or not); ``active`` the names of the
    components that have data and are used; ``inactive`` the names used but absent (zero);
    ``ignored`` the names given but not used by this case; ``warnings`` one line each.
    """

    equations: EquationSet
    case: str
    case_description: str
    terms: tuple[BoundTerm, ...]
    active: tuple[str, ...]
    inactive: tuple[str, ...]
    ignored: tuple[str, ...]
    warnings: tuple[str, ...]

    def active_terms(self) -> tuple[BoundTerm, ...]:
        active = set(self.active)
        return tuple(t for t in self.terms if t.component in active)


def _component_name(term: Term, letter: dict[str, str], components: dict) -> ComponentName:
    a = letter[term.axis]
    if term.kind == "linear":
        return ComponentName("linear", a)
    b = letter[term.about]
    if term.kind == "squareness":
        return ComponentName.squareness(a, b)
    if term.kind == "mechanical":
        mech = ComponentName("mechanical", a, b)
        # the top axis has one set of angles: its angular data serve as its γ unless
        # mechanical data are given (thesis 3.09.1, 3.12.1)
        if term.axis == "T" and mech not in components:
            return ComponentName("angular", a, b)
        return mech
    return ComponentName(term.kind, a, b)


def bind_model(machine: Machine) -> BoundModel:
    """The equation set of the machine's case, bound to its axes, offsets and inputs."""
    analysis = machine.analysis
    case, _, words = evaluation_case(analysis.point, analysis.compensation)
    eqs = equation_set(machine.configuration, analysis.point, analysis.compensation)
    letter = {"B": machine.roles["bottom"], "M": machine.roles["middle"], "T": machine.roles["top"]}
    components: dict[str, Component] = dict(machine.components)
    bound = []
    for term in eqs.terms:
        name = _component_name(term, letter, components)
        lever_axis = letter[term.lever_axis] if term.lever_axis else None
        bound.append(
            BoundTerm(
                term=term,
                direction=letter[term.direction],
                component=name,
                axis=None if term.kind == "squareness" else letter[term.axis],
                lever_axis=lever_axis,
                lever_sign=term.lever_sign,
                lever_offset_mm=machine.axes[lever_axis].offset_mm if lever_axis else 0.0,
                tool_axis=letter[term.tool_axis] if term.tool_axis else None,
                tool_sign=term.tool_sign,
            )
        )
    used = list(dict.fromkeys(t.component for t in bound))
    active = tuple(n for n in used if n in components)
    inactive = tuple(n for n in used if n not in components)
    ignored = tuple(n for n in components if n not in set(used))
    # an absent input is worth a warning only where some tool case gives it a lever
    levered = {a for tc in tool_cases(machine) for a, v in tc.offset_mm.items() if v != 0.0}
    # ... and not for an axis that does not move (the missing axis of a two-axis machine)
    still = {a for a, ax in machine.axes.items() if ax.travel_mm[0] == ax.travel_mm[1]}
    tool_only = {
        t.component
        for t in bound
        if t.lever_axis is None and t.tool_axis in levered and t.is_angle and t.axis not in still
    }
    warnings = []
    if eqs.family == "tcp-compensated-mcp":
        for name in inactive:
            if name.kind == "mechanical" and name in tool_only:
                warnings.append(
                    f"{name} (mechanical angle γ) is needed by case {case} ({eqs.source}) "
                    f"to carry the tool offset, but is not given: taken as zero"
                )
    if eqs.family != "mcp":
        top = machine.roles["top"]
        for name in inactive:
            if name.kind == "angular" and name.axis == top and name in tool_only:
                warnings.append(
                    f"{name} (top-axis angle) acts through the tool offset in case {case} "
                    f"({eqs.source}) but is not given: taken as zero"
                )
    return BoundModel(
        equations=eqs,
        case=case,
        case_description=words,
        terms=tuple(bound),
        active=active,
        inactive=inactive,
        ignored=ignored,
        warnings=tuple(warnings),
    )
