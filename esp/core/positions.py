"""Machine positions handed to the library, checked before any use.

The point queries of the library (:func:`esp.errors_at`, :func:`esp.evaluate_point`,
:meth:`esp.ErrorProfile.at`) take positions from a caller, not from a checked file. They
are taken as they are or refused with a :class:`~esp.core.errors.DataError` naming what
was expected and what arrived -- never reshaped into other points, never turned into NaN
results, never a bare ``ValueError``/``TypeError``/``KeyError``.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from esp.core.errors import DataError

__all__ = ["as_points_mm", "as_positions_mm", "point_mm"]


def _described(value: Any) -> str:
    """A short description of what arrived: its type, and its shape for an array."""
    if isinstance(value, np.ndarray):
        return f"an array of shape {value.shape} and dtype {value.dtype}"
    text = repr(value)
    if len(text) > 60:
        text = text[:57] + "..."
    return f"{type(value).__name__} {text}"


def _real_array(value: Any, what: str, expected: str) -> np.ndarray:
    """``value`` as a float array when it holds only real numbers (no bool, no complex, no
    text), else :class:`DataError`."""
    try:
        arr = np.asarray(value)
    except ValueError:  # ragged nesting
        raise DataError(f"{what}: expected {expected}, got {_described(value)}") from None
    if arr.dtype.kind == "O":
        try:
            arr = np.asarray(value, dtype=float)
        except (TypeError, ValueError):
            raise DataError(
                f"{what}: expected {expected}, of real numbers, got {_described(value)}"
            ) from None
    if arr.dtype.kind not in "iuf":
        raise DataError(f"{what}: expected {expected}, of real numbers, got {_described(value)}")
    return arr.astype(float)


def _finite(arr: np.ndarray, what: str, unit: str = "mm") -> None:
    bad = ~np.isfinite(arr)
    if not bad.any():
        return
    first = np.argwhere(bad)[0] if arr.ndim else np.zeros(0, dtype=int)
    at = ""
    if first.size == 1:
        at = f" at index {int(first[0])}"
    elif first.size > 1:
        at = f" at index {tuple(int(i) for i in first)}"
    raise DataError(f"{what}: expected finite positions in {unit}, found {arr[tuple(first)]}{at}")


def as_points_mm(value: Any, what: str = "points_mm") -> np.ndarray:
    """``value`` as an (N, 3) float array of X, Y, Z positions (mm): an (N, 3) array, or
    one (3,) point (returned as (1, 3)); finite and real. Anything else -- a (3, N) array,
    a point of two or four coordinates, a scalar, complex numbers, text, NaN or inf -- is a
    :class:`DataError` naming the shape or value that arrived."""
    expected = "positions of shape (N, 3) (columns X, Y, Z in mm) or one point of shape (3,)"
    arr = _real_array(value, what, expected)
    if arr.ndim == 1 and arr.shape[0] == 3:
        arr = arr.reshape(1, 3)
    elif arr.ndim != 2 or arr.shape[1] != 3:
        raise DataError(f"{what}: expected {expected}, got {_described(np.asarray(value))}")
    _finite(arr, what)
    return arr


def point_mm(value: Mapping[str, Any], axes: tuple[str, ...], what: str = "at") -> dict[str, float]:
    """``value``, a mapping of axis letter to position (mm), as floats: exactly the keys
    ``axes``, each a finite real number; anything else is a :class:`DataError`."""
    if not isinstance(value, Mapping):
        raise DataError(
            f"{what}: expected a mapping of {', '.join(axes)} to positions in mm, got "
            f"{_described(value)}"
        )
    missing = [a for a in axes if a not in value]
    unknown = [str(k) for k in value if k not in axes]
    if missing or unknown:
        found = ", ".join(repr(k) for k in value) or "nothing"
        raise DataError(
            f"{what}: expected a position for each of {', '.join(axes)}, found {found}"
            + (f" (missing {', '.join(missing)})" if missing else "")
            + (f" (unknown {', '.join(unknown)})" if unknown else "")
        )
    out: dict[str, float] = {}
    for a in axes:
        arr = _real_array(value[a], f"{what}[{a!r}]", "a position in mm")
        if arr.ndim != 0:
            raise DataError(
                f"{what}[{a!r}]: expected one position in mm, got {_described(value[a])}"
            )
        _finite(arr, f"{what}[{a!r}]")
        out[a] = float(arr)
    return out


def as_positions_mm(value: Any, what: str = "positions_mm") -> np.ndarray:
    """``value`` as a float array of positions along one axis (mm), any shape; finite and
    real, else :class:`DataError`."""
    arr = _real_array(value, what, "positions in mm")
    _finite(arr, what)
    return arr
