"""Floating-point arithmetic of the engine: trouble is an error, never a warning.

Inputs are checked at the boundary (parsers, the configuration reader, the profile), so a
floating-point overflow or invalid operation inside the engine means data beyond what esp
can compute with. :func:`arithmetic` turns it into a :class:`~esp.core.errors.DataError` with one
line, so no numpy warning and no inf or NaN ever reaches a result.
"""

from __future__ import annotations

import contextlib
from collections.abc import Iterator

import numpy as np

from esp.core.errors import DataError

__all__ = ["arithmetic"]


@contextlib.contextmanager
def arithmetic() -> Iterator[None]:
    """Run the enclosed numpy code with every floating-point error raised as DataError."""
    with np.errstate(all="raise"):
        try:
            yield
        except FloatingPointError as exc:
            raise DataError(
                f"the errors cannot be computed in floating point ({exc}); check the inputs "
                "for values far beyond a machine's (docs/reliability.md)"
            ) from None
