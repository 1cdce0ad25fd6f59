"""Reading a JSON document esp is given (a file of error values, a folder marker) with the
limits of the TOML reader: arrays and objects nested at most :data:`JSON_MAX_DEPTH` deep.

Python's JSON parser recurses once per level and ends in a ``RecursionError`` on a document
of ``[[[[...`` a few thousand levels deep; :func:`loads` refuses it with a
:class:`esp.core.errors.ParseError` naming the file instead.

This module imports only the standard library.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from esp.core.errors import ParseError

__all__ = ["JSON_MAX_DEPTH", "depth", "loads"]

#: the deepest nesting of arrays and objects a JSON document may have
JSON_MAX_DEPTH = 64


def depth(value: Any, limit: int = JSON_MAX_DEPTH) -> int:
    """The nesting depth of parsed JSON (a number or string is 0), counting no further
    than ``limit + 1`` and without recursion."""
    deepest = 0
    stack = [(value, 1)]
    while stack:
        item, level = stack.pop()
        if isinstance(item, dict | list):
            deepest = max(deepest, level)
            if level > limit:
                return level
            children = item.values() if isinstance(item, dict) else item
            stack.extend((c, level + 1) for c in children if isinstance(c, dict | list))
    return deepest


def loads(text: str, path: str | Path | None = None) -> Any:
    """The JSON document ``text``.

    Raises
    ------
    ParseError
        Not valid JSON (with the line), or nested deeper than :data:`JSON_MAX_DEPTH`.
    """
    too_deep = f"expected arrays and objects nested at most {JSON_MAX_DEPTH} deep, found deeper"
    try:
        doc = json.loads(text)
    except RecursionError:
        raise ParseError(path, None, too_deep) from None
    except ValueError as exc:
        raise ParseError(path, getattr(exc, "lineno", None), f"invalid JSON: {exc}") from None
    if depth(doc) > JSON_MAX_DEPTH:
        raise ParseError(path, None, too_deep)
    return doc
