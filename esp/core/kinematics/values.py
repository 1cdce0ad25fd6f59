"""Values of a chain's symbols: numbers in a symbol's unit, numbers with a unit converted
into it, the chain's own defaults and the settings of its coordinates. Shared by the head
(:mod:`esp.core.devices.head`) and the rotary table (:mod:`esp.core.devices.table`); the
``[head]`` and ``[table]`` tables of the description files and their files of error values
are read by :mod:`esp.config.devices` (the core reads no files).

Every problem of a value is a :class:`esp.core.errors.ConfigError` naming the dotted key.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from esp.core.errors import ConfigError
from esp.core.kinematics import units as kunits
from esp.core.kinematics.chain import Chain
from esp.core.text import article, did_you_mean
from esp.core.values import Quantity, ValueRefused, check_symbol, config_number, shown

__all__ = [
    "VALUE_LIMIT",
    "chain_defaults",
    "convert_unit",
    "coordinate_arrays",
    "finite_value",
    "symbol_value",
]

#: the largest magnitude a parameter or error value may have, in its symbol's unit
VALUE_LIMIT = 1e9


def finite_value(v: Any, key: str, limit: float = VALUE_LIMIT) -> float:
    """``v`` as a float: a number (not a bool), finite, of magnitude at most ``limit``."""
    return config_number(v, key, Quantity("a value", "", -limit, limit))


def symbol_value(v: Any, key: str, sym: Any, given: str | None = None) -> float:
    """``v``, in the unit of the chain symbol ``sym``, as a float when it is a finite number
    within the range of the symbol's kind and dimension (:func:`esp.core.values.check_symbol`);
    otherwise a :class:`~esp.core.errors.ConfigError` naming ``key``, the limit in the symbol's
    unit and the value as given."""
    try:
        return check_symbol(sym.kind, sym.unit, v, given=given)
    except ValueRefused as exc:
        raise ConfigError(key, exc.message) from None


def convert_unit(value: float, unit: Any, to_unit: str, key: str, name: str) -> float:
    """``value`` in ``unit`` expressed in ``to_unit`` (both of one dimension); ``name`` is
    the symbol, for the message."""
    u = kunits.canonical(unit) if isinstance(unit, str) else None
    if u is None:
        raise ConfigError(key, f"unknown unit {unit!r}; expected one of {', '.join(kunits.UNITS)}")
    if kunits.dimension_of(u) != kunits.dimension_of(to_unit):
        what = "a length" if kunits.dimension_of(to_unit) == kunits.LENGTH else "an angle"
        raise ConfigError(
            key,
            f"{u!r} is a unit of {kunits.dimension_of(u)}, but {name} is {what} "
            f"(its unit is {to_unit})",
        )
    return value * kunits.factor(u) / kunits.factor(to_unit)


def coordinate_arrays(
    angles: Any,
    coords: tuple[str, ...],
    *,
    member: str,
    owner: str,
    values: str = "values",
    limit: float = 1e6,
) -> tuple[dict[str, np.ndarray], int]:
    """Check the settings of a chain's coordinates: every one of ``coords`` given, as a
    number or a 1-D array, the arrays of one length N, finite and of magnitude at most
    ``limit``. Returns (coordinate -> float64 array (N,), N), numbers repeated N times.

    ``member``, ``owner`` and ``values`` word the messages ("not an axis of the table",
    "expected finite angles within ±1e+06, found 1e9"); the keys are ``angles.NAME``.
    """
    if not isinstance(angles, Mapping):
        raise ConfigError("angles", f"expected a mapping {member} -> {values}, found {angles!r}")
    listed = ", ".join(coords)
    for c in angles:
        if c not in coords:
            raise ConfigError(
                f"angles.{c}",
                f"not {article(member)} of the {owner}{did_you_mean(c, coords)} ({listed})",
            )
    out: dict[str, np.ndarray] = {}
    n = None
    for c in coords:
        if c not in angles:
            raise ConfigError(
                f"angles.{c}", f"missing: give every {member} of the {owner} ({listed})"
            )
        v = angles[c]
        if isinstance(v, bool | str | bytes) or v is None:
            raise ConfigError(f"angles.{c}", f"expected numbers, found {v!r}")
        try:
            arr = np.atleast_1d(np.asarray(v, dtype=float))
        except (TypeError, ValueError):
            raise ConfigError(f"angles.{c}", f"expected numbers, found {v!r}") from None
        if arr.ndim != 1 or arr.size == 0:
            raise ConfigError(f"angles.{c}", f"expected a number or a 1-D array, found {v!r}")
        with np.errstate(invalid="ignore"):
            bad = np.flatnonzero(~(np.abs(arr) <= limit))  # NaN compares false: caught too
        if bad.size:
            raise ConfigError(
                f"angles.{c}",
                f"expected finite {values} within ±{limit:g}, found {shown(arr[bad[0]])}",
            )
        out[c] = arr
        if arr.size != 1:
            if n is not None and n != arr.size:
                raise ConfigError(f"angles.{c}", f"{arr.size} values, but the others have {n}")
            n = arr.size
    n = n or 1
    return {c: (np.full(n, a[0]) if a.size == 1 else a) for c, a in out.items()}, n


def chain_defaults(chain: Chain) -> tuple[dict[str, float], dict[str, float], dict[str, str]]:
    """The chain's own values: (parameters, errors, origins). Every parameter must have a
    default; an error without one is zero (and has no origin)."""
    params: dict[str, float] = {}
    errors: dict[str, float] = {}
    origins: dict[str, str] = {}
    for n, s in chain.symbols.items():
        if s.value is not None and s.kind != "coordinate":  # a default within its range
            try:
                check_symbol(s.kind, s.unit, s.value)
            except ValueRefused as exc:
                raise ConfigError(f"symbols.{n}.value", exc.message, chain.source) from None
        if s.kind == "parameter":
            if s.value is None:
                raise ConfigError(
                    f"parameters.{n}",
                    f"no value: give one, or a default (symbols.{n}.value)",
                    chain.source,
                )
            params[n] = s.value
            origins[n] = "chain"
        elif s.kind == "error":
            errors[n] = 0.0 if s.value is None else s.value
            if s.value is not None:
                origins[n] = "chain"
    return params, errors, origins
