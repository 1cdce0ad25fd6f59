"""JSON rendering shared by every command: plain types, rounded floats, stable bytes."""

from __future__ import annotations

import json
import math
from collections.abc import Mapping
from typing import Any

import numpy as np

from esp.core.names import ComponentName

__all__ = ["dumps", "plain"]

#: decimals kept in JSON output: 1e-6 of the unit (1 pm for µm values)
DECIMALS = 6


def plain(obj: Any) -> Any:
    """Turn numpy scalars/arrays, tuples and mappings into JSON-ready Python values.

    Floats are rounded to :data:`DECIMALS` places (so the same input gives the same bytes
    across platforms); ``-0.0`` becomes ``0.0``; NaN and infinity become ``None``.
    """
    if isinstance(obj, ComponentName):
        return str(obj)
    if isinstance(obj, Mapping):
        return {str(k): plain(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [plain(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return [plain(v) for v in obj.tolist()]
    if isinstance(obj, (bool, np.bool_)):
        return bool(obj)
    if isinstance(obj, (int, np.integer)):
        return int(obj)
    if isinstance(obj, (float, np.floating)):
        f = float(obj)
        if not math.isfinite(f):
            return None
        f = round(f, DECIMALS)
        return 0.0 if f == 0 else f
    return obj


def dumps(obj: Any) -> str:
    """The JSON text of ``obj`` (indented, key order as built, trailing newline)."""
    return json.dumps(plain(obj), indent=2, ensure_ascii=False, allow_nan=False) + "\n"
