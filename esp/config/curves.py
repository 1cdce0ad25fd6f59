"""Read a curve file: a component error motion of a rotary axis over its angle, one column
of a small CSV file (the format is described in :mod:`esp.core.devices.table_curves`, which
holds the :class:`~esp.core.devices.table_curves.Curve` and its interpolation; the reading is
here so that the core reads no files).

Every problem of the file is a :class:`esp.core.errors.ParseError` naming the file and line.
"""

from __future__ import annotations

import csv
import io
import os
from pathlib import Path

import numpy as np

from esp.core.devices.table_curves import TURN, Curve
from esp.core.errors import ConfigError, ParseError
from esp.core.kinematics import units as kunits
from esp.core.text import did_you_mean
from esp.core.values import Quantity, ValueRefused, parse, written
from esp.io.textfile import read_utf8

__all__ = ["ANGLE_COLUMN", "read_curve"]

#: the header of the angle column
ANGLE_COLUMN = "angle_deg"
#: the largest curve file read
MAX_BYTES = 1024 * 1024


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
