"""A synthesis model as data: a table of terms.

Every ESP equation (Longstaff 2002, eq. 3.1-3.3, 3.10-3.12, 3.14-3.16) is a sum, per
direction, of terms of one shape::

    contribution = sign x component(coordinate of the axis that carries it) x lever

where the lever is 1 for linear and straightness errors, and for angles and squareness

    lever_mm = coordinate_sign x (k - offset_K)  +  tool_sign x P_K'

with k the coordinate of a lever axis K (its measurement offset removed) and P_K' the
tool offset along K' (thesis eq. 3.6-3.9). Either part may be absent. Angles are in µm/m,
so ``angle x lever_mm / 1000`` is in µm.

The tables are written in the thesis' own notation, with the axes as roles B, M, T::

    +B.lin            B_lin
    +M.str(B)         M_strt(B): middle-axis straightness in the B direction
    +phi_M(B)*(T+To)  Φ_M(B) · (T + T_o): bottom-axis rotation about M, lever T plus tool T_o
    -gamma_T(M)*Bo    γ_T(M) · B_o: mechanical angle, tool lever only
    +sqr(BT)*T        BT_sqr · T

and parsed once into :class:`Term` records, so every term of a breakdown points at its
printed equation.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

__all__ = ["ROLE_LETTERS", "Term", "parse_terms"]

ROLE_LETTERS = ("B", "M", "T")


@dataclass(frozen=True)
class Term:
    """One term of a synthesis equation, in role notation.

    Attributes
    ----------
    direction : the direction the term acts in (``"B"``, ``"M"`` or ``"T"``)
    kind : ``"linear"``, ``"straightness"``, ``"angular"`` (Φ), ``"mechanical"`` (γ) or
        ``"squareness"``
    axis : the role of the axis whose error it is (whose coordinate the error is a
        function of); for squareness the first role of the pair
    about : straightness direction, rotation axis, or the second role of a squareness pair
    sign : +1 or -1 as printed
    lever_axis : role whose coordinate is the lever (``None`` when there is none)
    lever_sign : sign of the coordinate part of the lever
    tool_axis : role of the tool-offset component added to the lever (``None`` if none)
    tool_sign : sign of the tool part of the lever
    source : the equation, e.g. ``"eq. 3.10"``
    """

    direction: str
    kind: str
    axis: str
    about: str | None
    sign: int
    lever_axis: str | None = None
    lever_sign: int = 1
    tool_axis: str | None = None
    tool_sign: int = 1
    source: str = ""

    @property
    def is_angle(self) -> bool:
        """True when the component is an angle (µm/m) multiplied by a lever in mm."""
        return self.kind in ("angular", "mechanical", "squareness")

    @property
    def symbol(self) -> str:
        """The term as the thesis prints it, e.g. ``-Φ_M(T)·T_o``."""
        if self.kind == "linear":
            comp = f"{self.axis}_lin"
        elif self.kind == "straightness":
            comp = f"{self.axis}_strt({self.about})"
        elif self.kind == "angular":
            comp = f"Φ_{self.about}({self.axis})"
        elif self.kind == "mechanical":
            comp = f"γ_{self.about}({self.axis})"
        else:
            comp = f"{self.axis}{self.about}_sqr"
        parts = []
        if self.lever_axis:
            parts.append(("-" if self.lever_sign < 0 else "") + self.lever_axis)
        if self.tool_axis:
            s = "-" if self.tool_sign < 0 else ("+" if parts else "")
            parts.append(f"{s}{self.tool_axis}_o")
        lever = "".join(parts)
        if lever:
            lever = f"·({lever})" if len(parts) > 1 else f"·{lever}"
        return f"{'-' if self.sign < 0 else '+'}{comp}{lever}"


_TOKEN = re.compile(
    r"""(?P<sign>[+-])
        (?:
          (?P<lin>[BMT])\.lin
        | (?P<str>[BMT])\.str\((?P<strdir>[BMT])\)
        | (?P<ang>phi|gamma)_(?P<about>[BMT])\((?P<of>[BMT])\)
        | sqr\((?P<sq1>[BMT])(?P<sq2>[BMT])\)
        )
        (?:\*(?P<lever>\([^)]*\)|[BMT]o?))?
    """,
    re.VERBOSE,
)
_LEVER_PART = re.compile(r"(?P<sign>[+-]?)(?P<axis>[BMT])(?P<tool>o?)")


def _parse_lever(text: str) -> tuple[str | None, int, str | None, int]:
    inner = text.strip("()")
    lever_axis, lever_sign, tool_axis, tool_sign = None, 1, None, 1
    pos = 0
    for m in _LEVER_PART.finditer(inner):
        if m.start() != pos:
            raise ValueError(f"bad lever {text!r}")
        pos = m.end()
        sign = -1 if m.group("sign") == "-" else 1
        if m.group("tool"):
            tool_axis, tool_sign = m.group("axis"), sign
        else:
            lever_axis, lever_sign = m.group("axis"), sign
    if pos != len(inner):
        raise ValueError(f"bad lever {text!r}")
    return lever_axis, lever_sign, tool_axis, tool_sign


def parse_terms(direction: str, text: str, source: str) -> tuple[Term, ...]:
    """Parse one direction of an equation written in the notation of this module."""
    terms = []
    compact = "".join(text.split())
    pos = 0
    for m in _TOKEN.finditer(compact):
        if m.start() != pos:
            raise ValueError(f"cannot parse {compact[pos:]!r} in {source}")
        pos = m.end()
        sign = -1 if m.group("sign") == "-" else 1
        lever: tuple[str | None, int, str | None, int] = (None, 1, None, 1)
        if m.group("lever"):
            lever = _parse_lever(m.group("lever"))
        if m.group("lin"):
            kind, axis, about = "linear", m.group("lin"), None
        elif m.group("str"):
            kind, axis, about = "straightness", m.group("str"), m.group("strdir")
        elif m.group("ang"):
            kind = "angular" if m.group("ang") == "phi" else "mechanical"
            axis, about = m.group("of"), m.group("about")
        else:
            kind, axis, about = "squareness", m.group("sq1"), m.group("sq2")
        terms.append(Term(direction, kind, axis, about, sign, *lever, source=source))
    if pos != len(compact):
        raise ValueError(f"cannot parse {compact[pos:]!r} in {source}")
    return tuple(terms)
