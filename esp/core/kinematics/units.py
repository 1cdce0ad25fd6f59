"""Units of the symbols of a kinematic chain.

Inside the chain every length is in mm and every angle in radians; a symbol's ``unit`` says
in which unit its values are given (in a chain file, on the command line, to
:func:`esp.core.kinematics.position`) and is converted once, at that boundary.
"""

from __future__ import annotations

import math

__all__ = ["ANGLE", "DEFAULT_UNITS", "LENGTH", "UNITS", "canonical", "dimension_of", "factor"]

LENGTH = "length"
ANGLE = "angle"

#: unit -> (dimension, factor to mm or rad)
UNITS: dict[str, tuple[str, float]] = {
    "mm": (LENGTH, 1.0),
    "um": (LENGTH, 1e-3),
    "nm": (LENGTH, 1e-6),
    "m": (LENGTH, 1e3),
    "in": (LENGTH, 25.4),
    "deg": (ANGLE, math.pi / 180.0),
    "rad": (ANGLE, 1.0),
    "mrad": (ANGLE, 1e-3),
    "urad": (ANGLE, 1e-6),
    "um/m": (ANGLE, 1e-6),
    "arcsec": (ANGLE, math.pi / (180.0 * 3600.0)),
}

_ALIASES = {
    "µm": "um",
    "µrad": "urad",
    "µm/m": "um/m",
    "degree": "deg",
    "degrees": "deg",
    "°": "deg",
    "arc-sec": "arcsec",
    "arcsecond": "arcsec",
    "arcseconds": "arcsec",
    '"': "arcsec",
    "mm/m": "mrad",
}

#: the unit a symbol gets when its file does not give one, by kind and dimension
DEFAULT_UNITS = {
    ("coordinate", LENGTH): "mm",
    ("coordinate", ANGLE): "deg",
    ("parameter", LENGTH): "mm",
    ("parameter", ANGLE): "deg",
    ("error", LENGTH): "um",
    ("error", ANGLE): "urad",
}


def canonical(unit: str) -> str | None:
    """The canonical spelling of ``unit``, or None if it is not a unit of a chain."""
    if not isinstance(unit, str):
        return None
    u = unit.strip()
    u = _ALIASES.get(u, _ALIASES.get(u.lower(), u))
    return u if u in UNITS else None


def dimension_of(unit: str) -> str:
    return UNITS[unit][0]


def factor(unit: str) -> float:
    """The factor that turns a value in ``unit`` into mm or rad."""
    return UNITS[unit][1]
