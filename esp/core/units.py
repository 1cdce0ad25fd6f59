"""Unit conversions and plausibility limits at the boundary of the library.

Inside esp, positions are in mm, displacement errors in µm and angles (and squareness)
in µm/m, which equals µrad. Files, configuration and command-line options may use other
units; they are converted here, once, and never inside the models.

Every number that enters esp is also checked against a plausibility limit of its unit
(``docs/reliability.md`` gives the reasons): a value beyond it is not a geometric error of
a machine tool or a CMM but a unit mistake, a corrupt file or an attack, and would give
overflowing sums or a meaningless accuracy. The readers refuse it with the file and line
or the configuration key (:func:`beyond_limit`, :func:`limit_text`).
"""

from __future__ import annotations

import math
from typing import overload

import numpy as np
import numpy.typing as npt

from esp.core.errors import DataError

__all__ = [
    "ANGLE_LIMIT_UM_PER_M",
    "ANGLE_UNITS",
    "DISPLACEMENT_LIMIT_UM",
    "DISPLACEMENT_UNITS",
    "MIN_SPACING_MM",
    "POSITION_LIMIT_MM",
    "TINY",
    "beyond_limit",
    "canonical_unit",
    "engine_unit_for_kind",
    "flush_tiny",
    "limit_for_kind",
    "limit_text",
    "to_engine",
]

#: the largest position esp accepts, mm (±100 m): targets, travels, offsets, datums,
#: tool lengths and offsets
POSITION_LIMIT_MM = 100_000.0
#: the largest displacement error (linear, straightness), µm (10 mm)
DISPLACEMENT_LIMIT_UM = 10_000.0
#: the largest angle (angular, mechanical, squareness), µm/m (0.1 rad, about 5.7°)
ANGLE_LIMIT_UM_PER_M = 100_000.0
#: the smallest distance between two targets, and the smallest grid step, mm (1 µm)
MIN_SPACING_MM = 0.001
#: numbers smaller than this in size are read as 0 (in any unit: 1e-30 µm is 1e-36 m);
#: products of a few of them would underflow, which the engine treats as an error
TINY = 1e-30

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


def to_engine(values: npt.ArrayLike, unit: str, kind: str) -> np.ndarray:
    """Convert ``values`` given in ``unit`` to the engine unit of ``kind``.

    Raises DataError when the unit does not fit the kind (an angle given in µm, say). A
    value too large for floating point after conversion becomes ``inf``, without a warning:
    the caller checks the result against :func:`limit_for_kind`.
    """
    u = canonical_unit(unit)
    target = engine_unit_for_kind(kind)
    table = ANGLE_UNITS if target == "um/m" else DISPLACEMENT_UNITS
    if u not in table:
        expected = ", ".join(sorted(table))
        raise DataError(f"unit {unit!r} does not fit a {kind} error; expected one of {expected}")
    with np.errstate(over="ignore"):
        return np.asarray(values, dtype=float) * table[u]


@overload
def flush_tiny(values: float) -> float: ...
@overload
def flush_tiny(values: npt.ArrayLike) -> np.ndarray: ...
def flush_tiny(values: float | npt.ArrayLike) -> float | np.ndarray:
    """``values`` with every number smaller than :data:`TINY` in size made exactly 0: a
    float for a float, a new float array for anything else."""
    if isinstance(values, float | int) and not isinstance(values, bool):
        return 0.0 if abs(values) < TINY else float(values)
    out = np.array(values, dtype=float)
    with np.errstate(invalid="ignore"):
        out[np.abs(out) < TINY] = 0.0
    return out


def limit_for_kind(kind: str) -> float:
    """The plausibility limit of an error of ``kind`` in its engine unit: µm for linear
    and straightness (:data:`DISPLACEMENT_LIMIT_UM`), µm/m for angular, mechanical and
    squareness (:data:`ANGLE_LIMIT_UM_PER_M`)."""
    if engine_unit_for_kind(kind) == "um/m":
        return ANGLE_LIMIT_UM_PER_M
    return DISPLACEMENT_LIMIT_UM


def beyond_limit(values_engine: npt.ArrayLike, kind: str) -> int | None:
    """The flat index of the first value (in the engine unit of ``kind``) that is not
    finite or lies beyond :func:`limit_for_kind`, or None when all are plausible."""
    v = np.asarray(values_engine, dtype=float).reshape(-1)
    with np.errstate(invalid="ignore"):
        bad = ~(np.abs(v) <= limit_for_kind(kind))  # NaN compares false: caught too
    hits = np.flatnonzero(bad)
    return int(hits[0]) if hits.size else None


def limit_text(kind: str, unit: str | None = None) -> str:
    """The limit as a message shows it, in ``unit`` (default the engine unit), with the
    engine value when they differ: ``"±10000 um"``, ``"±0.393701 in (10000 um)"``."""
    engine = engine_unit_for_kind(kind)
    limit = limit_for_kind(kind)
    u = engine if unit is None else canonical_unit(unit)
    table = ANGLE_UNITS if engine == "um/m" else DISPLACEMENT_UNITS
    if u == engine or u not in table:
        return f"±{limit:g} {engine}"
    return f"±{limit / table[u]:g} {u} ({limit:g} {engine})"
