"""What every figure of esp shares when it is drawn, whatever it shows.

Figures are :class:`matplotlib.figure.Figure` objects on matplotlib's Agg canvas (no
pyplot, no global state), drawn and written through matplotlib's public API only: PNG
files by ``savefig`` (Pillow encodes them) without the software-version text, so that
the same figure gives the same bytes.
"""

from __future__ import annotations

import contextlib
import functools
import warnings
from collections.abc import Iterator
from pathlib import Path
from typing import Any

from esp.io.atomic import atomic_path

__all__ = [
    "FIGURE_FORMATS",
    "PNG_COMPRESS_LEVEL",
    "drawn_ticks_locator",
    "figure_format",
    "figure_texts",
    "offset_text",
    "quiet_glyphs",
    "save_figure",
    "save_png",
    "text_width_px",
]

#: the formats a single figure (``--plot FILE``) is written in, by the suffix of its name
FIGURE_FORMATS = {".png": "png", ".pdf": "pdf"}

#: the zlib level of every PNG esp writes (Pillow's ``compress_level``, 0-9): level 1
#: encodes a report figure in about three fifths of the time of the usual level 6, in a
#: file about a fifth larger
PNG_COMPRESS_LEVEL = 1


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


def offset_text(
    ax: Any, xy: tuple[float, float], text: str, offset_pt: tuple[float, float], **kw: Any
) -> Any:
    """A text of ``ax`` at ``xy`` (in the coordinates of ``kw["transform"]``, default the
    axes' fraction) moved by ``offset_pt`` (points), as ``ax.annotate(text, xy,
    xytext=offset_pt, textcoords="offset points")`` places it, drawn as a plain
    :class:`~matplotlib.text.Text`: an annotation works out its place anew at every
    drawing, in a few times the time a text takes."""
    from matplotlib.transforms import ScaledTranslation

    base = kw.pop("transform", ax.transAxes)
    dx, dy = offset_pt
    shift = ScaledTranslation(dx / 72.0, dy / 72.0, ax.get_figure().dpi_scale_trans)
    return ax.text(*xy, text, transform=base + shift, **kw)


def text_width_px(text: str, prop: Any, dpi: float) -> float:
    """The width (pixels) of ``text`` drawn on one line, literally (no mathtext), in the
    font of ``prop`` (:class:`~matplotlib.font_manager.FontProperties`) at ``dpi``, as the
    Agg renderer measures it."""
    with quiet_glyphs():
        width, _, _ = _measuring_renderer(float(dpi)).get_text_width_height_descent(
            text, prop, ismath=False
        )
    return float(width)


@functools.lru_cache(maxsize=4)
def _measuring_renderer(dpi: float) -> Any:
    """A small Agg renderer at ``dpi``, for measuring texts before a figure is drawn."""
    from matplotlib.backends.backend_agg import RendererAgg

    return RendererAgg(8, 8, dpi)


def drawn_ticks_locator(nbins: int) -> Any:
    """A :class:`~matplotlib.ticker.MaxNLocator` of ``nbins`` that gives only the ticks
    inside the axis's view (within a millionth of its span): the same ticks are drawn,
    but matplotlib builds no tick (two marks, a grid line and two labels) for the one or
    two steps beyond each end it would never draw."""
    return _in_view_locator_class()(nbins=nbins)


@functools.cache
def _in_view_locator_class() -> type:
    import numpy as np
    from matplotlib.ticker import MaxNLocator

    class InViewLocator(MaxNLocator):
        def tick_values(self, vmin: float, vmax: float) -> Any:
            locs = np.asarray(super().tick_values(vmin, vmax))
            lo, hi = min(vmin, vmax), max(vmin, vmax)
            slack = 1e-6 * (hi - lo)
            return locs[(locs >= lo - slack) & (locs <= hi + slack)]

    return InViewLocator


def save_png(fig: Any, path: str | Path, dpi: float) -> None:
    """Write ``fig`` to ``path`` as PNG at ``dpi`` (the pixel size is ``figsize * dpi``),
    atomically, with deterministic bytes (no software-version text) and without warnings
    about missing glyphs (:func:`quiet_glyphs`); compressed at :data:`PNG_COMPRESS_LEVEL`."""
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
