"""What every figure of esp shares when it is drawn, whatever it shows."""

from __future__ import annotations

import contextlib
import warnings
from collections.abc import Iterator

__all__ = ["quiet_glyphs"]


@contextlib.contextmanager
def quiet_glyphs() -> Iterator[None]:
    """Draw without matplotlib's warning about a character its font lacks (a machine name
    in a script DejaVu Sans does not cover): the character is drawn as a box, and no
    warning reaches the user."""
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", message=r"Glyph \d+ .*missing from", category=UserWarning)
        yield
