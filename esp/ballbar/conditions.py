"""The test conditions of a ballbar file: ``# key: value`` comment lines of its header,
and the options that add to or override them (docs/ballbar.md, "Test conditions").

Known keys (compared without case; spaces, hyphens and underscores alike):

=================  ==============================================================
``machine``        the machine tested
``date``           the date of the test
``operator``       who ran it
``plane``          the plane of the circle (XY, YZ, ZX; the angle file's)
``radius``         the radius (mm; the angle file's)
``unit``           the unit of the deviations (um, nm, mm; the angle file's)
``feed``           the feed along the path (mm/min)
``ballbar``        the instrument (maker, serial)
``calibration_u``  the expanded uncertainty (k = 2) of the ballbar's calibrated length (µm)
``accuracy``       the limit ± of the ballbar transducer's error (µm)
``resolution``     the resolution of its readings (µm)
=================  ==============================================================

Every other ``# key: value`` line is kept and shown as given.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

from esp.core.errors import ParseError

__all__ = ["Conditions", "read_conditions"]

_LINE = re.compile(r"^\s*#\s*([A-Za-z][A-Za-z0-9 _\-]*?)\s*[:=]\s*(.*?)\s*$")
_NUMBER = re.compile(r"^([+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?)\s*(.*)$")

#: numeric keys: (field, the units accepted after the number, the unit it is stated in,
#: the least and largest value)
_NUMERIC: dict[str, tuple[str, tuple[str, ...], str, float, float]] = {
    "radius": ("radius_mm", ("", "mm"), "mm", 0.0, 1e5),
    "feed": ("feed_mm_per_min", ("", "mm/min"), "mm/min", 0.0, 1e6),
    "calibration_u": ("calibration_U_um", ("", "um", "µm"), "um", 0.0, 1e4),
    "accuracy": ("accuracy_um", ("", "um", "µm"), "um", 0.0, 1e4),
    "resolution": ("resolution_um", ("", "um", "µm"), "um", 0.0, 1e4),
}
_TEXT = {"machine", "date", "operator", "plane", "unit", "ballbar"}


def _key(raw: str) -> str:
    return re.sub(r"[\s\-]+", "_", raw.strip().lower())


@dataclass(frozen=True)
class Conditions:
    """What a ballbar test was run under, as far as it is stated (None: not stated)."""

    machine: str | None = None
    date: str | None = None
    operator: str | None = None
    plane: str | None = None
    unit: str | None = None
    ballbar: str | None = None
    radius_mm: float | None = None
    feed_mm_per_min: float | None = None
    #: expanded uncertainty (k = 2) of the ballbar's calibrated length (µm)
    calibration_U_um: float | None = None
    #: limit ± of the transducer's error over its range (µm)
    accuracy_um: float | None = None
    resolution_um: float | None = None
    #: every other ``# key: value`` line, as given
    other: tuple[tuple[str, str], ...] = field(default=())
    #: the file line of each key read from the file (for messages)
    lines: tuple[tuple[str, int], ...] = field(default=())

    def updated(self, **given: Any) -> Conditions:
        """These conditions with the values of ``given`` that are not None (options)."""
        return replace(self, **{k: v for k, v in given.items() if v is not None})

    def line_of(self, key: str) -> int | None:
        return dict(self.lines).get(key)

    def as_dict(self) -> dict[str, Any]:
        return {
            "machine": self.machine,
            "date": self.date,
            "operator": self.operator,
            "ballbar": self.ballbar,
            "feed_mm_per_min": self.feed_mm_per_min,
            "calibration_U_um": self.calibration_U_um,
            "accuracy_um": self.accuracy_um,
            "resolution_um": self.resolution_um,
            "other": dict(self.other),
        }


def _number(path: Path, line: int, key: str, text: str) -> float:
    name, units, unit, low, high = _NUMERIC[key]
    m = _NUMBER.match(text)
    if m is None or m.group(2).strip().lower() not in units:
        raise ParseError(path, line, f"'# {key}:' expected a number in {unit}, found {text[:40]!r}")
    value = float(m.group(1))
    if not (math.isfinite(value) and low < value <= high):
        raise ParseError(
            path,
            line,
            f"'# {key}:' expected a value above {low:g} and at most {high:g} {unit}, "
            f"found {m.group(1)}",
        )
    return value


def read_conditions(path: str | Path, lines: list[str]) -> Conditions:
    """The conditions stated by the ``# key: value`` lines of ``lines`` (the lines of
    ``path``, 1-based in order); a bad number is refused at its line."""
    p = Path(path)
    values: dict[str, Any] = {}
    other: list[tuple[str, str]] = []
    where: list[tuple[str, int]] = []
    for number, raw in enumerate(lines, start=1):
        m = _LINE.match(raw)
        if m is None:
            continue
        key, text = _key(m.group(1)), m.group(2)
        if key in _NUMERIC:
            values[_NUMERIC[key][0]] = _number(p, number, key, text)
        elif key in _TEXT:
            values[key] = text
        elif key == "kind":
            continue
        else:
            other.append((m.group(1).strip(), text))
            continue
        where.append((key, number))
    return Conditions(**values, other=tuple(other), lines=tuple(where))
