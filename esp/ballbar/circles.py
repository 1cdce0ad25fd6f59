"""Ballbar circles as read from a file: the lengths table of ``esp identify``
(:func:`esp.identify.ballbar.read_lengths`: positions, centre and length per reading) or
the angle table of a home-made ballbar (:mod:`esp.ballbar.angles`), both as
:class:`Circle`, with the test conditions their ``# key: value`` lines state
(:mod:`esp.ballbar.conditions`).
"""

from __future__ import annotations

from pathlib import Path

from esp.ballbar.conditions import read_conditions
from esp.ballbar.records import Circle, Run
from esp.core.errors import ConfigError
from esp.identify.ballbar import DIRECTIONS, MIN_READINGS, read_lengths
from esp.io.textfile import read_text, split_lines

__all__ = ["DIRECTIONS", "MIN_READINGS", "Circle", "Run", "read_circles"]


def _header(lines: list[str]) -> list[str] | None:
    for line in lines:
        s = line.strip().lstrip("\ufeff")
        if s and not s.startswith("#"):
            for sep in (",", ";", "\t"):
                if sep in s:
                    return [h.strip().lower() for h in s.split(sep)]
            return [h.strip().lower() for h in s.split()]
    return None


def read_circles(
    path: str | Path,
    *,
    radius_mm: float | None = None,
    plane: str | None = None,
) -> list[Circle]:
    """Every circle of a ballbar file: the lengths table of ``esp identify`` or, when its
    header names an ``angle`` column, the angle table (:func:`esp.ballbar.angles.read_angles`;
    ``radius_mm`` and ``plane`` there override the file's ``# radius:`` and ``# plane:``).
    Raises :class:`~esp.core.errors.ParseError` naming the file and line."""
    p = Path(path)
    lines = split_lines(read_text(p))
    conditions = read_conditions(p, lines)
    header = _header(lines)
    names = [h.split("(")[0].split("[")[0].strip() for h in header or ()]
    if "angle" in names or "angle_deg" in names:
        from esp.ballbar.angles import read_angles

        return [read_angles(p, lines, conditions, radius_mm=radius_mm, plane=plane)]
    for option, value in (("--radius", radius_mm), ("--plane", plane)):
        if value is not None:
            raise ConfigError(
                option,
                f"applies to an angle file; {p} is a lengths table, whose positions give "
                "the radius and the plane",
            )
    return [
        Circle(
            c.name,
            c.plane,
            c.centre_mm,
            c.radius_mm,
            tuple(Run(d, theta, dev) for d, theta, dev in c.runs),
            str(p),
            conditions,
        )
        for c in read_lengths(p)
    ]
