"""The printed equations against the rigid-body model: the signs the thesis implies, and
every printed term that differs from the derived one.

The printed equations (Longstaff 2002, eq. 3.1-3.3, 3.10-3.12, 3.14-3.16) give each angle a
sign of its own, implicit in the print: ``+Φ_M(B)·T`` in the B direction says that a
positive Φ_M(B) moves the tool towards +B when T grows. The rigid-body model reads every
angle as a right-handed rotation of the tool relative to the workpiece (ISO 230-1 signs,
``docs/conventions.md``). Setting the two tables side by side, term by term
(:func:`atoms`), gives for each angle the factor σ with

    thesis value = σ · ISO value,

taken from the MCP equations (which agree with the rigid body for every configuration,
up to these signs), or from the configuration's TCP equations for the angles that act only
through the tool. With σ applied, the printed terms that still differ are the printed
equations' physical errors (:func:`differences`): the missing bottom-axis tool levers of
eq. 3.11/3.15 and the mirrored tool offset of eq. 3.12/3.16.

This is what ``angle_convention = "thesis"`` uses to read data prepared for ESP in the
rigid-body model, and what the as-printed model uses to read ISO-signed data.
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from functools import lru_cache
from typing import TYPE_CHECKING

from esp.core.errors import ConfigError
from esp.core.models.derived import derive_terms
from esp.core.models.esp import equation_set
from esp.core.models.terms import Term

if TYPE_CHECKING:
    from esp.core.machine import Machine
    from esp.core.models.bind import BoundTerm
    from esp.core.names import ComponentName

__all__ = ["Atom", "Difference", "angle_signs", "atoms", "differences", "input_signs"]

_FAMILY_CASE = {
    "mcp": ("MCP", "none"),
    "tcp": ("TCP", "none"),
    "tcp-compensated-mcp": ("TCP", "MCP"),
}


@dataclass(frozen=True)
class Atom:
    """One part of a term: a component (in roles) acting in ``direction`` through one lever
    (``("coordinate", J)``, ``("tool", J)`` or ``None`` for a translation) with ``sign``."""

    direction: str
    kind: str
    axis: str
    about: str | None
    lever: tuple[str, str] | None
    sign: int

    @property
    def key(self) -> tuple:
        return (self.direction, self.kind, self.axis, self.about, self.lever)

    @property
    def angle(self) -> tuple[str, str | None]:
        """The angle this atom belongs to: (axis, about), γ and Φ of one rotation together."""
        return (self.axis, self.about)

    def text(self) -> str:
        """The atom in the thesis' notation: ``+Φ_M(B)·T``, ``-γ_T(M)·B_o``."""
        sign = "+" if self.sign > 0 else "-"
        if self.kind == "linear":
            comp = f"{self.axis}_lin"
        elif self.kind == "straightness":
            comp = f"{self.axis}_strt({self.about})"
        elif self.kind == "squareness":
            comp = f"{self.axis}{self.about}_sqr"
        else:
            comp = f"{'Φ' if self.kind == 'angular' else 'γ'}_{self.about}({self.axis})"
        if self.lever is None:
            return f"{sign}{comp}"
        where, j = self.lever
        return f"{sign}{comp}·{j}{'_o' if where == 'tool' else ''}"


def atoms(terms: Iterable[Term]) -> list[Atom]:
    """Every term split into its levers (``(T + T_o)`` is two atoms)."""
    out = []
    for t in terms:
        if not t.is_angle:
            out.append(Atom(t.direction, t.kind, t.axis, t.about, None, t.sign))
            continue
        if t.lever_axis:
            lever = ("coordinate", t.lever_axis)
            out.append(Atom(t.direction, t.kind, t.axis, t.about, lever, t.sign * t.lever_sign))
        if t.tool_axis:
            lever = ("tool", t.tool_axis)
            out.append(Atom(t.direction, t.kind, t.axis, t.about, lever, t.sign * t.tool_sign))
    return out


def _printed(configuration: str, family: str) -> list[Term]:
    point, compensation = _FAMILY_CASE[family]
    return list(equation_set(configuration, point, compensation).terms)


def _derived(configuration: str, letters: tuple[str, str, str], family: str) -> list[Term]:
    return list(derive_terms(configuration, letters, family).terms)


def _votes(printed: list[Atom], derived: list[Atom], carried: str) -> dict[tuple, Counter]:
    """Per angle, the count of printed atoms that agree (+1) or disagree (-1) with the
    rigid body; the tool levers along workpiece-carried axes (``carried``) do not vote."""
    by_key = {a.key: a for a in derived}
    votes: dict[tuple, Counter] = {}
    for a in printed:
        if a.kind not in ("angular", "mechanical"):
            continue
        if a.lever is not None and a.lever[0] == "tool" and a.lever[1] in carried:
            continue
        d = by_key.get(a.key)
        if d is not None:
            votes.setdefault(a.angle, Counter())[a.sign * d.sign] += 1
    return votes


@lru_cache(maxsize=64)
def angle_signs(configuration: str, letters: tuple[str, str, str]) -> Mapping[tuple, int]:
    """σ for every angle (axis role, about role) of a configuration whose printed equations
    give it a sign: thesis value = σ · ISO value.

    The MCP equations decide where they hold the angle (they agree with the rigid body);
    an angle that acts only through the tool takes the sign of the configuration's TCP
    equations (eq. 3.10-3.12) through the tool offsets along the axes that carry the tool:
    the print mirrors the offsets along the workpiece-carried axes (eq. 3.12, 3.16), so
    those do not vote.
    """
    carried = configuration[: configuration.index("w")]
    signs: dict[tuple, int] = {}
    for family in ("mcp", "tcp", "tcp-compensated-mcp"):
        votes = _votes(
            atoms(_printed(configuration, family)),
            atoms(_derived(configuration, letters, family)),
            carried,
        )
        for angle, count in votes.items():
            if angle not in signs:
                signs[angle] = 1 if count[1] >= count[-1] else -1
    return signs


@dataclass(frozen=True)
class Difference:
    """A printed term that differs from the rigid-body model (σ applied).

    ``printed`` and ``derived`` are the atoms in the thesis' notation ("" when absent);
    ``why`` says what kind of difference it is.
    """

    configuration: str
    family: str
    source: str
    direction: str
    printed: str
    derived: str
    why: str


def differences(
    configuration: str, family: str, letters: tuple[str, str, str] = ("X", "Y", "Z")
) -> list[Difference]:
    """Every printed term of one equation set that differs from the rigid-body table, after
    reading the printed angles with their σ (:func:`angle_signs`).

    ``letters`` fix the handedness of (B, M, T); the list is the same for every assignment
    (a left-handed one flips σ and the derived signs together).
    """
    point, compensation = _FAMILY_CASE[family]
    source = equation_set(configuration, point, compensation).source
    carried = configuration[: configuration.index("w")]
    sigma = angle_signs(configuration, letters)
    printed = atoms(_printed(configuration, family))
    derived = atoms(_derived(configuration, letters, family))

    def in_thesis_signs(a: Atom) -> Atom:
        s = sigma.get(a.angle, 1) if a.kind in ("angular", "mechanical") else 1
        return Atom(a.direction, a.kind, a.axis, a.about, a.lever, a.sign * s)

    derived = [in_thesis_signs(a) for a in derived]
    p_by = {a.key: a for a in printed}
    d_by = {a.key: a for a in derived}
    out = []
    for key in list(dict.fromkeys([*p_by, *d_by])):
        p, d = p_by.get(key), d_by.get(key)
        if p is not None and d is not None and p.sign == d.sign:
            continue
        either = p or d
        assert either is not None  # the key is one of p_by's or d_by's
        lever = either.lever
        if p is not None and d is not None:
            why = "opposite sign to the rigid body"
            if lever and lever[0] == "tool" and lever[1] in carried:
                why += f": the print reverses the tool offset along {lever[1]}, which carries "
                why += "the workpiece"
        elif p is None:
            why = "missing from the print"
            if lever and lever[0] == "tool":
                why += f": the angle turns the tool offset along {lever[1]} as it turns "
                why += "every lever after its axis in the chain"
        else:
            why = "no such lever in a rigid body"
        direction = either.direction
        out.append(
            Difference(
                configuration,
                family,
                source,
                direction,
                p.text() if p else "",
                d.text() if d else "",
                why,
            )
        )
    return out


def input_signs(
    machine: Machine,
    family: str,
    bound: Sequence[BoundTerm],
    active: Sequence[ComponentName],
) -> dict[ComponentName, float]:
    """The factor each active component's data are read with (only those that are -1).

    * ``angle_convention = "thesis"`` with the rigid-body model: angles and mechanical
      angles by σ (thesis -> ISO); with the as-printed model and ``"iso230-1"``: by σ too
      (ISO -> thesis). BMTwt has no printed equations, hence no thesis signs.
    * an angle derived from two linear runs (``from_linear``, thesis 3.08.1) is the
      coefficient of the lever along the displacement in its own axis' direction; the
      rigid-body model reads it with the sign of that term.
    """
    analysis = machine.analysis
    rigid = analysis.model == "rigid-body"
    letters = tuple(machine.roles[r] for r in ("bottom", "middle", "top"))
    role_of = {v: k[0].upper() for k, v in machine.roles.items()}
    out: dict = {}
    convert = (analysis.angle_convention == "thesis") == rigid
    if convert and any(n.kind in ("angular", "mechanical") for n in active):
        if machine.configuration == "BMTwt":
            raise ConfigError(
                "analysis.angle_convention",
                f"the thesis prints no equations for {machine.configuration}, so it implies no "
                "signs; give the angles in ISO 230-1 signs (angle_convention = 'iso230-1')",
                machine.source,
            )
        sigma = angle_signs(machine.configuration, letters)
        for name in active:
            if name.kind in ("angular", "mechanical"):
                s = sigma.get((role_of[name.axis], role_of[name.about]), 1)  # type: ignore[index]
                if s < 0:
                    out[name] = -1.0
    if rigid:
        for name in active:
            comp = machine.components.get(name)
            if comp is None or not getattr(comp, "from_linear", False):
                continue
            out.pop(name, None)
            out.update(_from_linear_sign(machine, name, bound))
    return out


def _from_linear_sign(
    machine: Machine, name: ComponentName, bound: Sequence[BoundTerm]
) -> dict[ComponentName, float]:
    """The sign of the term by which a from_linear angle of axis K about R enters the
    K direction, levered by the third axis J (the axis the two runs were displaced along)."""
    k, r = name.axis, name.about
    key = f"axes.{k}.errors.{name.kind}.{r}.from_linear"
    if k == r:
        raise ConfigError(
            key,
            f"two linear runs of {k} cannot measure its rotation about itself (a roll); "
            "measure it directly",
            machine.source,
        )
    (j,) = [a for a in ("X", "Y", "Z") if a not in (k, r)]
    for bt in bound:
        if bt.component == name and bt.direction == k and bt.lever_axis == j:
            return {name: -1.0} if bt.sign * bt.lever_sign < 0 else {}
    raise ConfigError(
        key,
        f"two linear runs of {k} displaced along {j} measure how the {k} error changes with "
        f"{j}; in the rigid-body model of {machine.configuration} no angle of {k} about {r} "
        f"is levered by {j} (see docs/conventions.md)",
        machine.source,
    )
