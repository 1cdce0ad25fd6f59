"""Identities of error components: :class:`ComponentName`.

A component is named after the axis that moves, the kind of error and what it is about::

    X.linear            linear positioning of X            ISO 230-1 EXX
    X.straightness.Y    straightness of X in the Y direction           EYX
    X.angular.Z         rotation of X about Z (yaw, pitch or roll)     ECX
    X.mechanical.Y      the mechanical angle γ of X about Y (thesis eq. 3.14-3.16)  EBX
    squareness.XY       squareness between X and Y (pair unordered)    EC0Y

The name is parsed once into a small value type; every layer reads its fields instead of
splitting strings. A :class:`ComponentName` compares equal to (and hashes like) its text,
so it is a drop-in key wherever a string name was used.

References
----------
ISO 230-1:2012, 3.4 (symbols of the error motions and the location errors); Longstaff
(2002) table 1.1 (the 21 geometric errors) and the nomenclature.
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["AXIS_NAMES", "COMPONENT_KINDS", "ComponentName", "all_component_names"]

AXIS_NAMES = ("X", "Y", "Z")
COMPONENT_KINDS = ("linear", "straightness", "angular", "mechanical", "squareness")
_ROTATION = {"X": "A", "Y": "B", "Z": "C"}


@dataclass(frozen=True, eq=False)
class ComponentName:
    """One error component's identity.

    Attributes
    ----------
    kind : one of :data:`COMPONENT_KINDS`
    axis : the axis that moves (``"X"``, ``"Y"``, ``"Z"``); None for squareness
    about : straightness: the direction of the deviation; angular and mechanical: the axis
        the rotation is about; squareness: the pair, letters in X, Y, Z order (``"XY"``);
        None for linear
    """

    kind: str
    axis: str | None = None
    about: str | None = None

    def __post_init__(self) -> None:
        k, a, b = self.kind, self.axis, self.about
        if k == "squareness":
            if a is not None or not isinstance(b, str) or len(b) != 2:
                raise ValueError(f"a squareness is named by a pair such as 'XY', found {b!r}")
            p, q = b[0], b[1]
            if p not in AXIS_NAMES or q not in AXIS_NAMES or p == q:
                raise ValueError(f"a squareness pair is two different axes, found {b!r}")
            object.__setattr__(self, "about", "".join(sorted(b, key=AXIS_NAMES.index)))
            return
        if k not in COMPONENT_KINDS:
            raise ValueError(f"unknown component kind {k!r}; expected one of {COMPONENT_KINDS}")
        if a not in AXIS_NAMES:
            raise ValueError(f"a {k} error needs a moving axis X, Y or Z, found {a!r}")
        if k == "linear":
            if b is not None:
                raise ValueError(f"a linear error has no direction of its own, found {b!r}")
        elif b not in AXIS_NAMES:
            raise ValueError(f"a {k} error needs a direction X, Y or Z, found {b!r}")
        elif k == "straightness" and b == a:
            raise ValueError(
                f"a deviation of {a} along {a} is its linear error, not a straightness"
            )

    # -- construction ---------------------------------------------------------------------

    @classmethod
    def parse(cls, text: str | ComponentName) -> ComponentName:
        """``"X.angular.Z"`` -> ``ComponentName("angular", "X", "Z")``; raises ValueError."""
        if isinstance(text, ComponentName):
            return text
        if not isinstance(text, str):
            raise ValueError(f"expected a component name such as 'X.linear', found {text!r}")
        parts = text.split(".")
        if len(parts) == 2 and parts[0] == "squareness":
            return cls("squareness", None, parts[1])
        if len(parts) == 2 and parts[1] == "linear":
            return cls("linear", parts[0])
        if len(parts) == 3 and parts[1] in COMPONENT_KINDS and parts[1] != "squareness":
            return cls(parts[1], parts[0], parts[2])
        raise ValueError(
            f"expected a component name such as 'X.linear', 'X.straightness.Y', "
            f"'X.angular.Z' or 'squareness.XY', found {text!r}"
        )

    @classmethod
    def squareness(cls, a: str, b: str) -> ComponentName:
        """The squareness of the unordered pair (a, b)."""
        return cls("squareness", None, a + b)

    # -- text -------------------------------------------------------------------------------

    def __str__(self) -> str:
        if self.kind == "squareness":
            return f"squareness.{self.about}"
        if self.kind == "linear":
            return f"{self.axis}.linear"
        return f"{self.axis}.{self.kind}.{self.about}"

    def __repr__(self) -> str:
        return f"ComponentName({str(self)!r})"

    def __format__(self, spec: str) -> str:
        return format(str(self), spec)

    def __eq__(self, other: object) -> bool:
        if isinstance(other, ComponentName | str):
            return str(self) == str(other)
        return NotImplemented

    def __hash__(self) -> int:
        return hash(str(self))

    def __lt__(self, other: ComponentName | str) -> bool:
        return self.sort_key < ComponentName.parse(other).sort_key

    # -- meaning --------------------------------------------------------------------------

    @property
    def sort_key(self) -> tuple[int, int, int]:
        """X, Y, Z; within an axis linear, straightness, angular, mechanical; then by the
        direction; squareness after every axis (XY, XZ, YZ)."""
        if self.kind == "squareness":
            pairs = ("XY", "XZ", "YZ")
            return (3, 0, pairs.index(self.about))
        axis = AXIS_NAMES.index(self.axis)
        about = -1 if self.about is None else AXIS_NAMES.index(self.about)
        return (axis, COMPONENT_KINDS.index(self.kind), about)

    @property
    def iso(self) -> str:
        """The ISO 230-1 symbol: ``EXX``, ``EYX``, ``ECX``; ``EC0Y`` for squareness.XY,
        ``EB0Z`` for XZ and ``EA0Z`` for YZ (the rotation about the third axis and the later
        axis of the pair, ISO 230-1:2012, 3.4.4). A mechanical angle γ shares the symbol of
        the rotation it measures mechanically."""
        about = self.about or ""
        if self.kind == "squareness":
            a, b = about[0], about[1]
            third = next(n for n in AXIS_NAMES if n not in (a, b))
            return f"E{_ROTATION[third]}0{b}"
        if self.kind == "linear":
            return f"E{self.axis}{self.axis}"
        if self.kind == "straightness":
            return f"E{about}{self.axis}"
        return f"E{_ROTATION[about]}{self.axis}"

    @property
    def iso_sign(self) -> int:
        """The factor from esp's value to the value of :attr:`iso`: +1, except for a
        squareness. esp's squareness is positive when the included angle of the pair is
        below 90° (docs/conventions.md); the ISO 230-1 location error E{t}0{b} turns the
        later letter b right-handed about the third axis t, so that ISO = ε(t, b, a) · esp:
        EC0Y = -S_XY, EB0Z = +S_XZ, EA0Z = -S_YZ."""
        if self.kind != "squareness":
            return 1
        a, b = (self.about or "XY")[0], (self.about or "XY")[1]
        t = next(n for n in AXIS_NAMES if n not in (a, b))
        i, j, k = (AXIS_NAMES.index(c) for c in (t, b, a))
        return (i - j) * (j - k) * (k - i) // 2

    @property
    def description(self) -> str:
        """Words: ``X-axis rotation about Z``."""
        about = self.about or ""
        if self.kind == "squareness":
            return f"squareness between {about[0]} and {about[1]}"
        if self.kind == "linear":
            return f"{self.axis}-axis linear positioning"
        if self.kind == "straightness":
            return f"{self.axis}-axis straightness in {self.about}"
        if self.kind == "mechanical":
            return f"{self.axis}-axis mechanical rotation about {self.about}"
        return f"{self.axis}-axis rotation about {self.about}"

    @property
    def is_angle(self) -> bool:
        """An angle (µm/m) that acts through a lever, or a displacement (µm)."""
        return self.kind in ("angular", "mechanical", "squareness")

    @property
    def unit(self) -> str:
        """The engine unit: ``"um"`` or ``"um/m"``."""
        return "um/m" if self.is_angle else "um"

    @property
    def profile_kind(self) -> str | None:
        """The kind of data file that holds it (a mechanical angle is angular data); None
        for squareness, which is one number."""
        if self.kind == "squareness":
            return None
        return "angular" if self.kind == "mechanical" else self.kind

    @property
    def pair(self) -> tuple[str, str] | None:
        """The two axes of a squareness, in X, Y, Z order."""
        if self.kind != "squareness" or self.about is None:
            return None
        return (self.about[0], self.about[1])


def all_component_names(mechanical: bool = True) -> tuple[ComponentName, ...]:
    """Every component of a three-axis machine, in :attr:`ComponentName.sort_key` order:
    the 21 geometric errors (with the 9 mechanical angles when ``mechanical``)."""
    names = []
    for a in AXIS_NAMES:
        names.append(ComponentName("linear", a))
        names += [ComponentName("straightness", a, b) for b in AXIS_NAMES if b != a]
        names += [ComponentName("angular", a, b) for b in AXIS_NAMES]
        if mechanical:
            names += [ComponentName("mechanical", a, b) for b in AXIS_NAMES]
    names += [ComponentName.squareness(*p) for p in ("XY", "XZ", "YZ")]
    return tuple(sorted(names, key=lambda n: n.sort_key))
