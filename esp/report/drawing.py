"""What every figure of esp shares when it is drawn, whatever it shows."""

from __future__ import annotations

import contextlib
import warnings
from collections.abc import Iterator
from pathlib import Path
from typing import Any

from esp.io.atomic import atomic_path

__all__ = [
    "FIGURE_FORMATS",
    "PNG_COMPRESS_LEVEL",
    "figure_format",
    "figure_texts",
    "quiet_glyphs",
    "save_figure",
    "save_png",
]

#: the formats a single figure (``--plot FILE``) is written in, by the suffix of its name
FIGURE_FORMATS = {".png": "png", ".pdf": "pdf"}

#: the zlib level of every PNG esp writes: 2 of 9 takes about half the time of the usual 6
#: to encode a report figure (a tenth of the time to draw and save it) and makes files about
#: a fifth larger; the pixels are the same
PNG_COMPRESS_LEVEL = 2


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


def save_png(fig: Any, path: str | Path, dpi: float) -> None:
    """Write ``fig`` to ``path`` as PNG at ``dpi`` (the pixel size is ``figsize * dpi``),
    atomically, with deterministic bytes (no software-version text) and without warnings
    about missing glyphs (:func:`quiet_glyphs`)."""
    with atomic_path(path) as tmp, quiet_glyphs():
        fig.savefig(
            tmp,
            format="png",
            dpi=dpi,
            metadata={"Software": None},
            pil_kwargs={"compress_level": PNG_COMPRESS_LEVEL},
        )


def figure_format(path: str | Path) -> str | None:
    """The format the suffix of ``path`` names (:data:`FIGURE_FORMATS`), or None."""
    return FIGURE_FORMATS.get(Path(path).suffix.lower())


def save_figure(fig: Any, path: str | Path, dpi: float, fmt: str) -> None:
    """Write ``fig`` to ``path`` in ``fmt`` (``"png"``, or ``"pdf"``: one page, fixed
    document information and no creation date), atomically, with deterministic bytes."""
    if fmt == "png":
        save_png(fig, path, dpi)
        return
    if fmt != "pdf":
        raise ValueError(f"expected a figure format of {sorted(FIGURE_FORMATS.values())}")
    from esp._version import __version__

    metadata = {"Creator": f"esp {__version__}", "Producer": f"esp {__version__}"}
    with atomic_path(path) as tmp, quiet_glyphs():
        fig.savefig(tmp, format="pdf", metadata={**metadata, "CreationDate": None})
