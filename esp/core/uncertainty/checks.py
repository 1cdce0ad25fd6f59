"""Checks of the values given to the uncertainty models: finite numbers, signs, whole
numbers, choices; a missing value raises :class:`MissingParameter`, which names it.

This module imports only the standard library.
"""

from __future__ import annotations

import math
from typing import Any

from esp.core.errors import DataError

__all__ = ["MissingParameter", "count", "finite", "need", "one_of"]


class MissingParameter(DataError):
    """A model was called without a value it needs (carries the parameter's ``name`` and
    ``what`` it is, so that a caller can say where it could have come from)."""

    def __init__(self, model: str, name: str, what: str):
        self.model = model
        self.name = name
        self.what = what
        super().__init__(f"{model}: {name} is required ({what})")


def finite(name: str, value: Any, minimum: str = "any", *, where: str | None = None) -> float:
    """``value`` as a finite float; ``minimum`` is ``"any"``, ``"nonneg"`` or ``"positive"``.

    Raises
    ------
    DataError
        naming ``where`` (when given) and ``name``, for a bool, a non-number, inf or NaN, or
        a value below the minimum.
    """
    what = name if where is None else f"{where}: {name}"
    if isinstance(value, bool):
        raise DataError(f"{what} must be a number, got {value!r}")
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise DataError(f"{what} must be a number, got {value!r}") from None
    if not math.isfinite(x):
        raise DataError(f"{what} must be a finite number, got {value!r}")
    if minimum == "positive" and x <= 0:
        raise DataError(f"{what} must be > 0, got {value!r}")
    if minimum == "nonneg" and x < 0:
        raise DataError(f"{what} must be >= 0, got {value!r}")
    return x


def need(model: str, name: str, value: Any, what: str, minimum: str = "nonneg") -> float:
    """A required value: :class:`MissingParameter` when None, else :func:`finite`."""
    if value is None:
        raise MissingParameter(model, name, what)
    return finite(name, value, minimum, where=model)


def count(model: str, name: str, value: Any, smallest: int = 0) -> int:
    """A whole number >= ``smallest`` (a float with no fractional part is accepted)."""
    if isinstance(value, bool):
        raise DataError(f"{model}: {name} must be a whole number, got {value!r}")
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise DataError(f"{model}: {name} must be a whole number, got {value!r}") from None
    if not math.isfinite(x) or x != int(x) or x < smallest:
        raise DataError(f"{model}: {name} must be a whole number >= {smallest}, got {value!r}")
    return int(x)


def one_of(model: str, name: str, value: str, allowed: tuple[str, ...]) -> str:
    """``value`` when it is one of ``allowed``."""
    if value not in allowed:
        raise DataError(f"{model}: unknown {name} {value!r}; expected one of {', '.join(allowed)}")
    return value
