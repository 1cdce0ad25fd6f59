"""What every figure of esp shares when it is drawn, whatever it shows."""

from __future__ import annotations

import contextlib
import warnings
from collections.abc import Iterator
from typing import Any

__all__ = ["figure_texts", "quiet_glyphs"]


@contextlib.contextmanager
def quiet_glyphs() -> Iterator[None]:
    """Draw without matplotlib's warning about a character its font lacks (a machine name
    in a script DejaVu Sans does not cover): the character is drawn as a box, and no
    warning reaches the user."""
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", message=r"Glyph \d+ .*missing from", category=UserWarning)
        yield


def figure_texts(fig: Any) -> list[Any]:
    """The texts of ``fig`` that may hold words: the figure's texts and legends, and of
    each axes its texts, title, axis labels and legend. Tick labels are left to the
    caller (which ones matter depends on why it asks)."""
    texts = list(fig.texts)
    for legend in fig.legends:
        texts += legend.get_texts()
    for ax in fig.axes:
        texts += [*ax.texts, ax.title, ax.xaxis.label, ax.yaxis.label]
        legend = ax.get_legend()
        if legend is not None:
            texts += legend.get_texts()
    return texts
