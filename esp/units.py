"""Unit conversions at the boundary of the library.

Inside esp, positions are in mm, displacement errors in µm and angles (and squareness)
in µm/m, which equals µrad. Files, configuration and command-line options may use other
units; they are converted here, once, and never inside the models.
"""

from __future__ import annotations

import math

import numpy as np

from esp.errors import DataError

__all__ = [
    "ANGLE_UNITS",
    "DISPLACEMENT_UNITS",
    "canonical_unit",
    "engine_unit_for_kind",
    "to_engine",
]

#: factor that turns one unit into µm
DISPLACEMENT_UNITS: dict[str, float] = {"um": 1.0, "mm": 1000.0, "nm": 0.001, "in": 25400.0}

#: factor that turns one unit into µm/m (= µrad)
ANGLE_UNITS: dict[str, float] = {
    "um/m": 1.0,
    "urad": 1.0,
    "mrad": 1000.0,
    "arcsec": math.pi / (180.0 * 3600.0) * 1e6,
    "deg": math.pi / 180.0 * 1e6,
}

_ALIASES = {
    "µm": "um",
    "micron": "um",
    "microns": "um",
    "µm/m": "um/m",
    "um/m": "um/m",
    "µrad": "urad",
    "microrad": "urad",
    "mm/m": "mrad",
    "um/mm": "mrad",
    "µm/mm": "mrad",
    "arc-sec": "arcsec",
    "arcsecond": "arcsec",
    "arcseconds": "arcsec",
    "sec": "arcsec",
    '"': "arcsec",
}


def canonical_unit(unit: str) -> str:
    """Return the canonical spelling of ``unit`` (``"µm"`` -> ``"um"``), or raise DataError."""
    u = unit.strip()
    u = _ALIASES.get(u, _ALIASES.get(u.lower(), u.lower()))
    if u not in DISPLACEMENT_UNITS and u not in ANGLE_UNITS:
        known = ", ".join(sorted(DISPLACEMENT_UNITS) + sorted(ANGLE_UNITS))
        raise DataError(f"unknown unit {unit!r}; expected one of {known}")
    return u


def engine_unit_for_kind(kind: str) -> str:
    """The unit esp computes in for a component kind: µm for translations, µm/m for angles."""
    return "um/m" if kind in ("angular", "mechanical", "squareness") else "um"


def to_engine(values, unit: str, kind: str) -> np.ndarray:
    """Convert ``values`` given in ``unit`` to the engine unit of ``kind``.

    Raises DataError when the unit does not fit the kind (an angle given in µm, say).
    """
    u = canonical_unit(unit)
    target = engine_unit_for_kind(kind)
    table = ANGLE_UNITS if target == "um/m" else DISPLACEMENT_UNITS
    if u not in table:
        expected = ", ".join(sorted(table))
        raise DataError(f"unit {unit!r} does not fit a {kind} error; expected one of {expected}")
    return np.asarray(values, dtype=float) * table[u]
