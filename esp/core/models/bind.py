"""Bind an equation set, written with the roles B, M and T, to one machine.

Binding turns every :class:`~esp.core.models.terms.Term` into a :class:`BoundTerm` that names
the machine's own component (``X.angular.Y``), the axis letter whose coordinate the
component is a function of, and the lever axis with its measurement offset. It also sorts
the machine's inputs into what the case uses (active), what it would use but was not given
(not active, hence zero), and what it was given but does not use (ignored), with warnings
where the thesis says an input is needed (Longstaff 2002, 3.10 and 3.12.1).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

from esp.core.machine import Component, Machine
from esp.core.models.derived import CHAIN_ORDER, derive_terms
from esp.core.models.esp import EquationSet, equation_set, evaluation_case
from esp.core.models.signs import input_signs
from esp.core.models.terms import Term
from esp.core.models.tool import tool_cases
from esp.core.names import ComponentName

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
    iso_symbol: str = ""

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
        """The ISO 230-1 symbol (:func:`squareness_iso` for a squareness)."""
        return self.iso_symbol or self.component.iso

    @property
    def symbol(self) -> str:
        """The term as written in its source: the thesis' notation for a printed term
        (``-Φ_M(T)·T_o``), ISO 230-1 symbols and machine letters for a derived one
        (``+EBX·(Z+P_Z)``, lever coordinates measured from their offsets)."""
        if not self.term.source.startswith("rigid-body"):
            return self.term.symbol
        t = self.term
        comp = f"S_{self.component.about}" if t.kind == "squareness" else self.component.iso
        if t.kind == "mechanical":
            comp = "γ" + comp
        parts = []
        if self.lever_axis:
            parts.append(("-" if self.lever_sign < 0 else "") + self.lever_axis)
        if self.tool_axis:
            s = "-" if self.tool_sign < 0 else ("+" if parts else "")
            parts.append(f"{s}P_{self.tool_axis}")
        lever = "".join(parts)
        if lever:
            lever = f"·({lever})" if len(parts) > 1 else f"·{lever}"
        return f"{'-' if t.sign < 0 else '+'}{comp}{lever}"


@dataclass(frozen=True)
class BoundModel:
    """An equation set bound to a machine.

    ``terms`` holds every term of the set (active or not); ``active`` the names of the
    components that have data and are used; ``inactive`` the names used but absent (zero);
    ``ignored`` the names given but not used by this case; ``warnings`` one line each;
    ``input_signs`` the factor (-1) by which the data of a component are multiplied to read
    them in the model's convention (``angle_convention``, ``from_linear`` angles), for the
    components that need one.
    """

    equations: EquationSet
    case: str
    case_description: str
    terms: tuple[BoundTerm, ...]
    active: tuple[ComponentName, ...]
    inactive: tuple[ComponentName, ...]
    ignored: tuple[str | ComponentName, ...]
    warnings: tuple[str, ...]
    input_signs: dict = field(default_factory=dict)


def _component_name(
    term: Term, letter: dict[str, str], components: dict, last: str
) -> ComponentName:
    a = letter[term.axis]
    if term.kind == "linear":
        return ComponentName("linear", a)
    assert term.about is not None, term  # every kind but linear has an `about`
    b = letter[term.about]
    if term.kind == "squareness":
        return ComponentName.squareness(a, b)
    if term.kind == "mechanical":
        mech = ComponentName("mechanical", a, b)
        # the axis nearest the tool has one set of angles (no coordinate levers them, so
        # compensation at the MCP leaves them): its angular data serve as its γ unless
        # mechanical data are given (thesis 3.09.1, 3.12.1: the top axis)
        if term.axis == last and mech not in components:
            return ComponentName("angular", a, b)
        return mech
    return ComponentName(term.kind, a, b)


def squareness_iso(name: ComponentName, roles: Mapping[str, str]) -> str:
    """The ISO 230-1 location error a squareness is on this machine, with its sign.

    esp's squareness S_EL (docs/conventions.md) tilts the later axis L of the pair (in
    bottom -> middle -> top order) towards +E; in ISO 230-1 that is the orientation error of
    L's reference line about the third axis t, E{t}0L, positive right-handed about +t. A
    right-handed rotation θ about +t turns e_L into e_L + θ (e_t × e_L), so S_EL = ε(t, L, E)
    · E{t}0L: e.g. S_XY = -EC0Y when Y is the later axis, S_XY = +EC0X when X is.
    """
    order = [roles[r] for r in ("bottom", "middle", "top")]
    assert name.about is not None, name  # a squareness is about its pair of axes
    a, b = name.about[0], name.about[1]
    earlier, later = (a, b) if order.index(a) < order.index(b) else (b, a)
    third = next(n for n in "XYZ" if n not in (a, b))
    i, j, k = ("XYZ".index(c) for c in (third, later, earlier))
    sign = (i - j) * (j - k) * (k - i) // 2
    rotation = {"X": "A", "Y": "B", "Z": "C"}[third]
    return f"{'' if sign > 0 else '-'}E{rotation}0{later}"


def bind_model(machine: Machine) -> BoundModel:
    """The equation set of the machine's case, bound to its axes, offsets and inputs."""
    analysis = machine.analysis
    case, family, words = evaluation_case(analysis.point, analysis.compensation)
    letter = {"B": machine.roles["bottom"], "M": machine.roles["middle"], "T": machine.roles["top"]}
    letters = (letter["B"], letter["M"], letter["T"])
    if analysis.model == "as-printed":
        eqs = equation_set(machine.configuration, analysis.point, analysis.compensation)
    else:
        axes = machine.axes
        offsets = (axes["X"].offset_mm, axes["Y"].offset_mm, axes["Z"].offset_mm)
        table = derive_terms(machine.configuration, letters, family, offsets)
        eqs = EquationSet(table.source, machine.configuration, family, table.terms)
    last = CHAIN_ORDER[machine.configuration][-1]
    components: dict[str | ComponentName, Component] = dict(machine.components)
    bound = []
    for term in eqs.terms:
        name = _component_name(term, letter, components, last)
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
                iso_symbol=squareness_iso(name, machine.roles) if name.kind == "squareness" else "",
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
        nearest = letter[last]
        for name in inactive:
            if name.kind == "angular" and name.axis == nearest and name in tool_only:
                warnings.append(
                    f"{name} (an angle of the axis nearest the tool) acts through the tool "
                    f"offset in case {case} ({eqs.source}) but is not given: taken as zero"
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
        input_signs=input_signs(machine, family, tuple(bound), active),
    )
