"""A component error motion of a rotary axis over its angle: a curve read from a small CSV
file, interpolated linearly at the settings, periodic over one turn (numpy only).

The file::

    # C axis of the trunnion: angular positioning deviation, arcsec
    angle_deg,ECC,EXC
    0,0.0,0.4
    30,1.8,0.3
    ...
    330,-1.2,0.5

The first column is the axis angle in degrees (header ``angle_deg``), strictly increasing;
every other column holds one error's values at those angles (the table file names the
column and the unit). ``#`` lines are comments. A periodic curve spans less than one turn,
or exactly one when its last point repeats the first (360° is 0°): between its last point
and its first point plus 360° it is interpolated across the seam, and any angle is reduced
into its turn first. A curve of an axis with a limited travel (a trunnion's A) is given
``periodic = false``; it then holds only between its first and last angle, and a setting
outside them is refused.

ISO 230-7:2015 gives the error motions of an axis of rotation as functions of its angle;
ISO 230-2:2014 the angular positioning deviation at target positions over the axis' travel.
"""

from __future__ import annotations

import csv
import io
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from esp.core.errors import ConfigError, DataError, ParseError
from esp.core.kinematics import units as kunits
from esp.core.text import did_you_mean
from esp.core.values import Quantity, ValueRefused, parse, written
from esp.io.textfile import read_utf8

__all__ = ["ANGLE_COLUMN", "Curve", "read_curve"]

#: the header of the angle column
ANGLE_COLUMN = "angle_deg"
#: the largest curve file read
MAX_BYTES = 1024 * 1024
#: a turn, degrees
TURN = 360.0


@dataclass(frozen=True)
class Curve:
    """An error's values over the angle of its axis.

    Attributes
    ----------
    angles_deg : (M,) strictly increasing angles, degrees (M >= 2)
    values : (M,) the error's values there, in ``unit`` (scale already applied)
    unit : the unit of ``values`` (the unit of the chain symbol it feeds)
    periodic : interpolate across the seam between the last angle and the first + 360°
    source : where it came from, for messages (``"C-motions.csv:EXC"``)
    """

    angles_deg: np.ndarray
    values: np.ndarray
    unit: str
    periodic: bool = True
    source: str = ""

    def __post_init__(self) -> None:
        a = np.asarray(self.angles_deg, dtype=float)
        v = np.asarray(self.values, dtype=float)
        where = self.source or "curve"
        if a.ndim != 1 or v.shape != a.shape or a.size < 2:
            raise DataError(f"{where}: expected at least two angles with one value each")
        if not (np.all(np.isfinite(a)) and np.all(np.isfinite(v))):
            raise DataError(f"{where}: expected finite angles and values")
        if np.any(np.diff(a) <= 0):
            raise DataError(f"{where}: expected strictly increasing angles")
        if self.periodic and a[-1] - a[0] >= TURN:
            raise DataError(
                f"{where}: a periodic curve spans less than one turn, found "
                f"{written(a[0])}..{written(a[-1])} deg"
            )
        object.__setattr__(self, "angles_deg", a)
        object.__setattr__(self, "values", v)

    @property
    def range_deg(self) -> tuple[float, float]:
        """The first and last angle, degrees."""
        return float(self.angles_deg[0]), float(self.angles_deg[-1])

    def at(self, angles_deg: Any) -> np.ndarray:
        """The values at ``angles_deg`` (degrees, a number or an array), linearly
        interpolated; periodic curves reduce each angle into their turn first.

        Raises
        ------
        DataError
            A non-periodic curve asked for an angle outside its range.
        """
        x = np.asarray(angles_deg, dtype=float)
        a, v = self.angles_deg, self.values
        if self.periodic:
            x = a[0] + np.mod(x - a[0], TURN)
            xp = np.concatenate([a, [a[0] + TURN]])
            fp = np.concatenate([v, [v[0]]])
            return np.interp(x, xp, fp)
        lo, hi = self.range_deg
        outside = (x < lo - 1e-9) | (x > hi + 1e-9)
        if np.any(outside):
            bad = float(np.ravel(x)[np.argmax(np.ravel(outside))])
            raise DataError(
                f"{self.source or 'curve'}: {bad:g} deg is outside the curve's range "
                f"{lo:g}..{hi:g} deg (periodic = false: it is not extended)"
            )
        return np.interp(x, a, v)


#: a cell of a curve file: the values are checked again as the chain's (esp.core.values)
_CELL = Quantity("a number", "", -1e9, 1e9)


def _number(cell: str, path: Path, line: int, what: str) -> float:
    try:  # decimal digits only (no 1_000), finite, at most 1e9 in size
        return parse(cell, _CELL)
    except ValueRefused as exc:
        raise ParseError(path, line, f"{what}: {exc.message}") from None


def read_curve(
    path: str | os.PathLike[str],
    *,
    column: str | None = None,
    prefer: str | None = None,
    unit: str,
    to_unit: str,
    scale: float = 1.0,
    periodic: bool = True,
) -> Curve:
    """Read one column of a curve file (see the module docstring).

    Parameters
    ----------
    path : the CSV file
    column : the header of the value column; when omitted, the column named ``prefer``
        (the error's symbol), or the only value column of the file
    prefer : see ``column``
    unit : the unit of the values in the file
    to_unit : the unit of the chain symbol the curve feeds (same dimension as ``unit``)
    scale : a factor applied to every value (``-1`` for data of the opposite sign)
    periodic : see :class:`Curve`

    Raises
    ------
    ParseError
        The file is missing or unreadable, the header is not ``angle_deg,...``, the column
        is not there, a cell is not a finite number, the angles do not increase, a periodic
        curve spans more than a turn (file and line).
    ConfigError
        ``unit`` is not a unit, or not of the dimension of ``to_unit`` (key ``unit``).
    """
    p = Path(path)
    factor = _unit_factor(unit, to_unit) * float(scale)
    text = read_utf8(p, MAX_BYTES, "curve file")
    rows = [
        (i, line)
        for i, line in enumerate(text.splitlines(), 1)
        if line.strip() and not line.lstrip().startswith("#")
    ]
    if not rows:
        raise ParseError(p, None, f"expected a header '{ANGLE_COLUMN},...' and rows, found none")
    hline, header = rows[0]
    cols = [c.strip() for c in next(csv.reader([header]))]
    if not cols or cols[0].lower() != ANGLE_COLUMN:
        raise ParseError(
            p, hline, f"expected the first column {ANGLE_COLUMN!r} (degrees), found {header!r}"
        )
    names = cols[1:]
    if not names:
        raise ParseError(p, hline, "expected at least one value column after the angle")
    for i, n in enumerate(names):
        if not n:
            raise ParseError(p, hline, f"column {i + 2} has no name")
        if n in names[:i]:
            raise ParseError(p, hline, f"column {n!r} appears twice")
    if column is None and prefer in names:
        column = prefer
    if column is None:
        if len(names) != 1:
            raise ParseError(
                p, hline, f"the file has {len(names)} value columns ({', '.join(names)}); name one"
            )
        column = names[0]
    if column not in names:
        raise ParseError(
            p,
            hline,
            f"no column {column!r}{did_you_mean(column, names)} (columns: {', '.join(names)})",
        )
    k = cols.index(column)
    angles: list[float] = []
    values: list[float] = []
    lines: list[int] = []
    for line_no, line in rows[1:]:
        cells = [c.strip() for c in next(csv.reader(io.StringIO(line)))]
        if len(cells) != len(cols):
            raise ParseError(p, line_no, f"expected {len(cols)} columns, found {len(cells)}")
        a = _number(cells[0], p, line_no, ANGLE_COLUMN)
        if angles and a <= angles[-1]:
            raise ParseError(
                p,
                line_no,
                f"expected increasing angles, found {written(a)} after {written(angles[-1])} "
                f"(line {lines[-1]})",
            )
        angles.append(a)
        values.append(_number(cells[k], p, line_no, column) * factor)
        lines.append(line_no)
    if len(angles) < 2:
        raise ParseError(p, None, f"expected at least two rows of {column}, found {len(angles)}")
    if periodic:
        span = angles[-1] - angles[0]
        if abs(span - TURN) <= 1e-9:
            if abs(values[-1] - values[0]) > 1e-9 * max(1.0, abs(values[0])):
                raise ParseError(
                    p,
                    lines[-1],
                    f"{angles[-1]:g} deg is the setting {angles[0]:g} deg (line {lines[0]}) "
                    f"but {column} differs there ({values[-1] / factor:g} against "
                    f"{values[0] / factor:g}); give one of the two rows",
                )
            angles.pop()
            values.pop()
        elif span > TURN:
            raise ParseError(
                p,
                lines[-1],
                f"a periodic curve spans at most one turn, found "
                f"{written(angles[0])}..{written(angles[-1])} "
                "deg (give periodic = false for an axis that turns further)",
            )
    return Curve(
        np.array(angles),
        np.array(values),
        to_unit,
        periodic,
        f"{p.name}:{column}",
    )


def _unit_factor(unit: str, to_unit: str) -> float:
    u = kunits.canonical(unit)
    if u is None:
        raise ConfigError(
            "unit", f"unknown unit {unit!r}; expected one of {', '.join(kunits.UNITS)}"
        )
    if kunits.dimension_of(u) != kunits.dimension_of(to_unit):
        raise ConfigError(
            "unit",
            f"{u!r} is a unit of {kunits.dimension_of(u)}, but the error is "
            f"{'a length' if kunits.dimension_of(to_unit) == kunits.LENGTH else 'an angle'} "
            f"(its unit is {to_unit})",
        )
    return kunits.factor(u) / kunits.factor(to_unit)
