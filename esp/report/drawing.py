"""What every figure of esp shares when it is drawn, whatever it shows."""

from __future__ import annotations

import contextlib
import dataclasses
import functools
import io
import struct
import warnings
from collections.abc import Iterator
from pathlib import Path
from typing import Any

from esp.io.atomic import atomic_path

__all__ = [
    "FIGURE_FORMATS",
    "PNG_COMPRESS_LEVEL",
    "agg_canvas",
    "axes_class",
    "cached_layouts",
    "figure_format",
    "figure_texts",
    "flat_ticks",
    "png_bytes",
    "quick_font_lookup",
    "quiet_glyphs",
    "save_figure",
    "save_png",
    "text_renderer",
]

#: the formats a single figure (``--plot FILE``) is written in, by the suffix of its name
FIGURE_FORMATS = {".png": "png", ".pdf": "pdf"}

#: the zlib level of every PNG esp writes (:func:`png_bytes`): with each row stored as its
#: difference from the row above, level 1 of 9 encodes a report figure in about a third of
#: the time of the usual level 6 on the plain rows, in a file about a fifth larger
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


def save_png(fig: Any, path: str | Path, dpi: float) -> None:
    """Write ``fig`` to ``path`` as PNG at ``dpi`` (the pixel size is ``figsize * dpi``),
    atomically, with deterministic bytes (no software-version text) and without warnings
    about missing glyphs (:func:`quiet_glyphs`). A figure on matplotlib's Agg canvas is
    drawn on :func:`agg_canvas`'s, which writes each text as one bitmap. The pixels are
    matplotlib's (drawn by ``savefig`` as for its own PNG); the file is written by
    :func:`png_bytes`."""
    import numpy as np
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    if isinstance(fig.canvas, FigureCanvasAgg):
        agg_canvas(fig)
    raw = io.BytesIO()
    with quiet_glyphs():
        fig.savefig(raw, format="raw", dpi=dpi)
    drawn = fig.canvas.renderer  # the renderer the pixels were drawn with: their size
    shape = (int(drawn.height), int(drawn.width), 4)
    rgba = np.frombuffer(raw.getbuffer(), dtype=np.uint8).reshape(shape)
    with atomic_path(path) as tmp:
        Path(tmp).write_bytes(png_bytes(rgba, dpi))


def png_bytes(rgba: Any, dpi: float, level: int = PNG_COMPRESS_LEVEL) -> bytes:
    """The PNG file (ISO/IEC 15948:2004) of the pixels ``rgba`` (rows top first, uint8
    ``(height, width, 4)``) at ``dpi``: 8-bit RGB when every pixel is opaque (a figure
    on its white ground), else RGBA; every row filtered as its difference from the row
    above (filter type 2, "Up", 9.2), the whole compressed with zlib at ``level`` in one
    ``IDAT`` chunk; a ``pHYs`` chunk gives the resolution (pixels per metre, rounded as
    Pillow rounds it). No text chunk, no time: the same pixels give the same bytes."""
    import zlib

    import numpy as np

    pixels = np.ascontiguousarray(rgba, dtype=np.uint8)
    height, width, _ = pixels.shape
    opaque = bool((pixels[..., 3] == 255).all())
    channels, colour_type = (3, 2) if opaque else (4, 6)
    # "Up": each byte less the byte above it (the first row: less zero), modulo 256 as the
    # filter is; taken on the whole pixels (contiguous: quick), the alpha byte then left
    # out of each pixel of an opaque image by copying its first three bytes as one item
    up = np.empty_like(pixels)
    up[0] = pixels[0]
    np.subtract(pixels[1:], pixels[:-1], out=up[1:])
    rows = np.empty((height, width * channels + 1), dtype=np.uint8)
    rows[:, 0] = 2
    if opaque:
        triple = np.dtype([("rgb", "V3"), ("a", "u1")])
        body = rows[:, 1:].view("V3")  # each pixel of a row: three bytes
        body[...] = up.view(triple).reshape(height, width)["rgb"]
    else:
        rows[:, 1:] = up.reshape(height, width * 4)

    def chunk(kind: bytes, data: bytes) -> bytes:
        body = kind + data
        return struct.pack(">I", len(data)) + body + struct.pack(">I", zlib.crc32(body))

    per_metre = int(dpi / 0.0254 + 0.5)
    return b"".join(
        (
            b"\x89PNG\r\n\x1a\n",
            chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, colour_type, 0, 0, 0)),
            chunk(b"pHYs", struct.pack(">IIB", per_metre, per_metre, 1)),
            chunk(b"IDAT", zlib.compress(rows.tobytes(), level)),
            chunk(b"IEND", b""),
        )
    )


def quick_font_lookup() -> None:
    """Let matplotlib's font manager keep the font it finds for a font's properties
    whatever their size: done once per process, before PDF pages or figures are drawn.

    matplotlib looks up the font of every text drawn on a PDF page twice (its metrics,
    and its name in the file), and each lookup first gathers eleven settings to key its
    own cache; and that cache is keyed by the size too, so that each new size scores every
    font of the system again, comparing file paths (several milliseconds per size). The
    size plays no part in the choice among scalable fonts (every font matplotlib lists
    is), so here a lookup is kept under the font's properties less its size, the
    settings the choice reads and the number of fonts known (a font added is looked up
    afresh); a list of fonts with a size that is not scalable keeps the size in the key.
    The font found is matplotlib's own: only how often it is searched for changes."""
    import os

    import matplotlib as mpl
    from matplotlib import font_manager

    manager = font_manager.fontManager
    if getattr(manager.findfont, "_esp_kept", False):
        return
    find = manager.findfont
    find_all = manager._find_fonts_by_props
    rc = mpl.rcParams
    stored: Any = dict.__getitem__  # the settings as stored: quicker than rcParams[...]
    names = [
        f"font.{k}"
        for k in (
            "family",
            "style",
            "variant",
            "weight",
            "stretch",
            "size",
            "serif",
            "sans-serif",
            "cursive",
            "fantasy",
            "monospace",
        )
    ]
    kept: dict[tuple, Any] = {}
    properties = font_manager.FontProperties

    def key(prop: Any, args: tuple) -> tuple | None:
        if type(prop) is not properties or prop.get_file() is not None:
            return None  # a pattern, a path or a file: as matplotlib does it
        fonts = (len(manager.ttflist), len(manager.afmlist))
        scalable = _all_scalable(manager, fonts)
        return (
            tuple(prop.get_family()),
            prop.get_style(),
            prop.get_variant(),
            prop.get_weight(),
            prop.get_stretch(),
            None if scalable else prop.get_size(),
            args,
            fonts,
            tuple(tuple(v) if isinstance(v, list) else v for v in (stored(rc, n) for n in names)),
            os.environ.get("MPL_IGNORE_SYSTEM_FONTS"),
        )

    def findfont(prop: Any, *args: Any, **kwargs: Any) -> Any:
        k = key(prop, ("one", args, tuple(sorted(kwargs.items()))))
        if k is None:
            return find(prop, *args, **kwargs)
        found = kept.get(k)
        if found is None:
            found = kept[k] = find(prop, *args, **kwargs)
        return found

    def find_fonts_by_props(prop: Any, *args: Any, **kwargs: Any) -> Any:
        k = key(prop, ("all", args, tuple(sorted(kwargs.items()))))
        if k is None:
            return find_all(prop, *args, **kwargs)
        found = kept.get(k)
        if found is None:
            found = kept[k] = tuple(find_all(prop, *args, **kwargs))
        return list(found)

    findfont._esp_kept = True  # type: ignore[attr-defined]
    manager.findfont = findfont  # type: ignore[method-assign]
    manager._find_fonts_by_props = find_fonts_by_props  # type: ignore[method-assign]
    font_manager.findfont = findfont  # the module's name for the manager's method


@functools.lru_cache(maxsize=8)
def _all_scalable(manager: Any, counts: tuple[int, int]) -> bool:
    """Whether every font ``manager`` lists (``counts`` of them) is scalable."""
    return all(f.size == "scalable" for f in (*manager.ttflist, *manager.afmlist))


def axes_class() -> Any:
    """The class of esp's axes: matplotlib's ``Axes``, less the ticks it makes and never
    draws, and less a transform made afresh for every artist it clips.

    matplotlib makes every new axes' first major and first minor tick of both axes (four
    objects of five artists each, most of the cost of making an axes), only to give them
    the axes' clip path and their settings. Here a tick list not made yet is left so: the
    clip path and the settings are kept and given to each tick when it is made (as they
    would have been given then), so that a tick is made only if something asks for one.
    And every line, text, bar or image added to an axes is clipped to its background
    rectangle, for which matplotlib composes the rectangle's transform anew each time;
    here the background keeps the one it composed while its place and its transform stay
    the same. What is drawn is the same."""
    if not _AXES:
        _AXES.append(_axes_class())
    return _AXES[0]


_AXES: list[Any] = []  # the class, made when first needed (matplotlib loads then)


def _axes_class() -> Any:
    from matplotlib import axis as maxis
    from matplotlib.artist import Artist
    from matplotlib.axes import Axes
    from matplotlib.patches import Rectangle

    def clipped(base: Any) -> Any:
        class Clipped(base):  # type: ignore[misc, valid-type]
            def set_clip_path(self, path: Any, transform: Any = None) -> None:
                Artist.set_clip_path(self, path, transform)
                self._esp_clip = (path, transform)
                for name in ("majorTicks", "minorTicks"):
                    for tick in vars(self).get(name, ()):  # the ticks made so far
                        tick.set_clip_path(path, transform)
                self.stale = True

            def set_tick_params(self, which: str = "major", reset: bool = False, **kw: Any) -> None:
                if reset or which not in ("major", "minor", "both"):
                    super().set_tick_params(which, reset, **kw)
                    return
                # as matplotlib's, but a tick list not made yet is left unmade: its
                # settings are kept for when it is, as matplotlib keeps them for every
                # tick made later (making the first tick to set it costs more than an Axes
                # of esp's otherwise does: grid(False) in every clear() asked for it)
                translated = self._translate_tick_params(kw)
                made = vars(self)
                for kind, kept in (("major", self._major_tick_kw), ("minor", self._minor_tick_kw)):
                    if which in (kind, "both"):
                        kept.update(translated)
                        for tick in made.get(f"{kind}Ticks", ()):
                            tick._apply_params(**translated)
                if "label1On" in translated or "label2On" in translated:
                    self.offsetText.set_visible(
                        self._major_tick_kw.get("label1On", False)
                        or self._major_tick_kw.get("label2On", False)
                    )
                if "labelcolor" in translated:
                    self.offsetText.set_color(translated["labelcolor"])
                self.stale = True

            def _get_tick(self, major: bool) -> Any:
                tick = super()._get_tick(major)
                clip = vars(self).get("_esp_clip")
                if clip is not None:
                    tick.set_clip_path(*clip)
                return tick

        return Clipped

    x_axis, y_axis = clipped(maxis.XAxis), clipped(maxis.YAxis)

    class Background(Rectangle):
        _esp_kept: tuple[tuple, Any, Any] | None = None

        def get_transform(self) -> Any:
            # what matplotlib's composes the transform of (Rectangle.get_patch_transform
            # and the artist's own transform, compared as the same object)
            place = (
                self.get_x(),
                self.get_y(),
                self.get_width(),
                self.get_height(),
                self.angle,
                self.rotation_point,
                getattr(self, "_aspect_ratio_correction", 1.0),
            )
            own = Artist.get_transform(self)
            kept = self._esp_kept
            if kept is None or kept[0] != place or kept[1] is not own:
                kept = self._esp_kept = (place, own, super().get_transform())
            return kept[2]

    class EspAxes(Axes):
        def _gen_axes_patch(self) -> Any:
            return Background((0.0, 0.0), 1.0, 1.0)

        def _init_axis(self) -> None:
            # as matplotlib's Axes._init_axis, with the axes above
            self.xaxis = x_axis(self, clear=False)
            self.spines.bottom.register_axis(self.xaxis)
            self.spines.top.register_axis(self.xaxis)
            self.yaxis = y_axis(self, clear=False)
            self.spines.left.register_axis(self.yaxis)
            self.spines.right.register_axis(self.yaxis)

    return EspAxes


def agg_canvas(fig: Any) -> Any:
    """Put ``fig`` on an Agg canvas whose texts are drawn as one bitmap each, and return
    the canvas.

    matplotlib (from 3.11) lays out a text and then renders and composites its glyphs one
    by one, each through a few Python calls, and every figure measures its texts afresh:
    most of the time of a report figure's PNG went there. This canvas's renderer draws a
    plain text (no mathtext; esp draws none) as matplotlib did before: the font lays out
    the whole string once and renders it into one bitmap, which is composited once, at
    the text's angle. The bitmap and the measured size of each text (its string, font
    properties, resolution and hinting) are kept (:func:`_rendered_text`), so that a text
    every figure repeats -- tick labels, axis labels -- is laid out once per process. The
    glyphs are the same font at the same size and hinting; only their sub-pixel placement
    may differ from matplotlib's own.
    """
    if not _CANVAS:
        _CANVAS.append(_canvas_class())
    return _CANVAS[0](fig)


def text_renderer(dpi: float) -> Any:
    """A small renderer of :func:`agg_canvas`'s kind, for measuring texts at ``dpi``
    (``get_text_width_height_descent``) before a figure is drawn."""
    if not _CANVAS:
        _CANVAS.append(_canvas_class())
    return _RENDERER[0](8, 8, dpi)


_CANVAS: list[Any] = []  # the classes, made when first needed (matplotlib loads then)
_RENDERER: list[Any] = []


@functools.lru_cache(maxsize=4096)
def _rendered_text(text: str, prop: Any, dpi: float, flags: Any, aa: bool) -> tuple:
    """The bitmap of ``text`` in the font of ``prop`` (a copy no one changes) at ``dpi``,
    its offsets and its size (pixels): ``(image, x_offset, y_offset, width, height,
    descent)``, made as matplotlib's Agg renderer makes them and kept for the next figure
    (at most 4096 texts, a few MB: every text of a few reports)."""
    from matplotlib.font_manager import get_font

    font = get_font(_font_files(prop))
    font.clear()
    font.set_size(prop.get_size_in_points(), dpi)
    font.set_text(text, 0.0, flags=flags)
    width, height = font.get_width_height()
    descent = font.get_descent() / 64.0
    font.draw_glyphs_to_bitmap(antialiased=aa)
    xo, yo = (v / 64.0 for v in font.get_bitmap_offset())
    image = font.get_image()
    return image, xo, yo, width / 64.0, height / 64.0, descent


def _font_files(prop: Any) -> list[str]:
    """The font files matplotlib draws ``prop`` with (its family and fallbacks), looked up
    once per family, style, weight and stretch: matplotlib's font manager scores every
    font of the system again for each new size, though the size never changes the choice
    among scalable fonts (every font it lists)."""
    key = prop.copy()
    key.set_size(10.0)
    return list(_font_files_of(key))


@functools.lru_cache(maxsize=256)
def _font_files_of(prop: Any) -> tuple[str, ...]:
    from matplotlib.font_manager import fontManager

    return tuple(fontManager._find_fonts_by_props(prop))


@functools.lru_cache(maxsize=256)
def _font_height_metrics(prop: Any, dpi: float) -> tuple:
    """The ascent, descent and line gap (pixels) of the font of ``prop`` (a copy no one
    changes) at ``dpi``, read from its tables as matplotlib's text layout reads them
    (``matplotlib.text.Text._get_layout``), or three Nones when it has neither table."""
    from matplotlib.font_manager import get_font

    font: Any = get_font(_font_files(prop))  # its tables read by name, as matplotlib does
    for table_name, gap_key, ascent_key, descent_key in (
        ("OS/2", "sTypoLineGap", "sTypoAscender", "sTypoDescender"),
        ("hhea", "lineGap", "ascent", "descent"),
    ):
        table = font.get_sfnt_table(table_name)
        if table is None:
            continue
        units_per_em = font.get_sfnt_table("head")["unitsPerEm"]
        scale = 1 / units_per_em * prop.get_size_in_points() * dpi / 72
        return table[ascent_key] * scale, -table[descent_key] * scale, table[gap_key] * scale
    return None, None, None


def _canvas_class() -> Any:
    import math

    quick_font_lookup()  # the figures' texts: once per process, with the first canvas

    from matplotlib.backends.backend_agg import FigureCanvasAgg, RendererAgg, get_hinting_flag

    class Renderer(RendererAgg):
        def _text(self, s: str, prop: Any, aa: bool = True) -> tuple:
            key = prop.copy()  # the cache's key: a copy that no one changes
            return _rendered_text(s, key, float(self.dpi), get_hinting_flag(), bool(aa))

        def _get_font_height_metrics(self, prop):  # type: ignore[no-untyped-def]
            # what matplotlib's text layout reads from the font's tables, kept per font
            return _font_height_metrics(prop.copy(), float(self.dpi))

        def get_text_width_height_descent(self, s, prop, ismath):  # type: ignore[no-untyped-def]
            if ismath:
                return super().get_text_width_height_descent(s, prop, ismath)
            _, _, _, width, height, descent = self._text(s, prop)
            return width, height, descent

        def draw_text(self, gc, x, y, s, prop, angle, ismath=False, mtext=None):  # type: ignore[no-untyped-def]
            if ismath:
                return super().draw_text(gc, x, y, s, prop, angle, ismath, mtext)
            image, xo, yo, _, _, descent = self._text(s, prop, gc.get_antialiased())
            xd = descent * math.sin(math.radians(angle))
            yd = descent * math.cos(math.radians(angle))
            self._renderer.draw_text_image(
                image, round(x + xo + xd), round(y + yo + yd) + 1, angle, gc
            )
            return None

    class Canvas(FigureCanvasAgg):
        def get_renderer(self):  # type: ignore[no-untyped-def]
            w, h = self.get_width_height(physical=True)
            key = w, h, self.figure.dpi
            if self._lastKey != key:
                self.renderer = Renderer(w, h, self.figure.dpi)
                self._lastKey = key
            return self.renderer

    _RENDERER.append(Renderer)
    return Canvas


def cached_layouts(fig: Any) -> Any:
    """Let every text of ``fig`` keep its layout for the next time it is measured or
    drawn, and return ``fig``.

    matplotlib lays a text out afresh each time it is measured (to place an axis label, to
    keep a contour label inside its axes) and each time it is drawn, on the PNG and again
    on the PDF page; each layout looks up the font and reads its tables. Here each text's
    layout is kept (:func:`_layout`) under what it depends on -- the string, the font
    properties, the angle, the alignments, the line spacing, the resolution, the kind of
    renderer and the settings its measures read -- so that a layout the figures repeat
    (tick labels, axis labels, titles) is made once per renderer kind in a process. A
    layout is the same tuple matplotlib computes; only where it is computed changes. A
    text with mathtext or TeX is laid out by matplotlib each time.
    """
    for text in _all_texts(fig):
        if "_get_layout" not in vars(text):
            text._get_layout = _CachedLayout(text)
    return fig


def _all_texts(fig: Any) -> list[Any]:
    """Every text ``fig`` draws, found where matplotlib keeps them (quicker than walking
    every artist): the figure's and each legend's, and of each axes its texts (notes),
    its contour labels, titles, axis labels and offsets, the labels of :func:`flat_ticks`
    and those of matplotlib's ticks made so far."""
    from matplotlib.text import Text

    texts = list(fig.texts)
    legends = list(fig.legends)
    for ax in fig.axes:
        texts += [*ax.texts, ax.title, ax._left_title, ax._right_title]
        for axis in (ax.xaxis, ax.yaxis):
            texts += [axis.label, axis.offsetText]
            for name in ("majorTicks", "minorTicks"):
                for tick in vars(axis).get(name, ()):  # made already: not made here
                    texts += [tick.label1, tick.label2]
        for artist in ax.artists:
            for part in getattr(artist, "parts", ()):
                if isinstance(part, Text):
                    texts.append(part)
                elif isinstance(getattr(part, "label", None), Text):  # flat tick labels
                    texts.append(part.label)
        for collection in ax.collections:  # a contour set's labels
            texts += getattr(collection, "labelTexts", [])
        legend = ax.get_legend()
        if legend is not None:
            legends.append(legend)
    for legend in legends:
        texts += [*legend.get_texts(), legend.get_title()]
    return texts


class _CachedLayout:
    """The ``_get_layout`` of one text (:func:`cached_layouts`): matplotlib's own, kept."""

    __slots__ = ("text",)

    def __init__(self, text: Any):
        self.text = text

    def __call__(self, renderer: Any) -> Any:
        import matplotlib as mpl
        from matplotlib.text import Text
        from matplotlib.transforms import Bbox

        text = self.text
        string = text._get_wrapped_text()
        if text.get_usetex() or (text.get_parse_math() and "$" in string):
            return Text._get_layout(text, renderer)  # type: ignore[attr-defined]
        rc = mpl.rcParams
        get = dict.__getitem__  # the settings as stored: quicker than rcParams[...]
        prop = text.get_fontproperties()
        key = (
            string,
            # the font's properties as matplotlib compares them (FontProperties.__hash__)
            tuple(prop.get_family()),
            prop.get_slant(),
            prop.get_variant(),
            prop.get_weight(),
            prop.get_stretch(),
            prop.get_size(),
            prop.get_file(),
            prop.get_math_fontfamily(),
            float(text.get_rotation()),
            text.get_rotation_mode(),
            text.get_horizontalalignment(),
            text.get_verticalalignment(),
            text._get_multialignment(),
            text._linespacing,
            float(text.get_figure(root=True).dpi),
            type(renderer),
            type(getattr(renderer, "_renderer", None)),  # what the PDF's wrapper holds
            getattr(renderer, "dpi", None),
            get(rc, "pdf.use14corefonts"),
            get(rc, "text.hinting"),
            get(rc, "text.hinting_factor"),
            get(rc, "text.kerning_factor"),
        )
        layout = _LAYOUTS.get(key)
        if layout is None:
            layout = Text._get_layout(text, renderer)  # type: ignore[attr-defined]
            if len(_LAYOUTS) >= _LAYOUTS_MAX:
                _LAYOUTS.clear()
            _LAYOUTS[key] = layout
        bbox, lines, corner = layout
        # a fresh box each time: the caller may move it
        return Bbox(bbox.get_points().copy()), lines, corner


#: the layouts kept (:class:`_CachedLayout`): at most this many, a few MB
_LAYOUTS_MAX = 8192
_LAYOUTS: dict[tuple, Any] = {}


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


def flat_ticks(fig: Any) -> Any:
    """Draw the ticks of every numeric axis of ``fig`` as a few plain artists, and return
    ``fig``.

    matplotlib makes each tick an object of five artists (two marks, a grid line, two
    labels), created and drawn one by one: for a figure of six panels, most of its
    drawing time. Here, once the limits are final, each axis whose ticks come from a
    locator and a plain number formatter gets the same marks as one line of markers, its
    grid lines as one line, and its labels as texts, at the places, sizes, pads and
    colours matplotlib would give them (read from one tick made as matplotlib makes them,
    kept for the axes of the same settings); the axis label is placed below (beside) those
    texts as matplotlib places it. What matplotlib's own ticks would draw differently is
    left to them: fixed labels (categories), rotated labels, ticks on both sides, an offset
    or a scale written beside the axis, and minor ticks. A colour bar is flattened like
    any axes: call this once the figure is complete.
    """
    from matplotlib.axis import XAxis
    from matplotlib.ticker import FixedFormatter, NullLocator, ScalarFormatter

    for ax in fig.axes:
        for axis in (ax.xaxis, ax.yaxis):
            locator = axis.get_major_locator()
            formatter = axis.get_major_formatter()
            if (
                isinstance(locator, NullLocator)
                or isinstance(formatter, FixedFormatter)
                or not isinstance(formatter, ScalarFormatter)
                or not isinstance(axis.get_minor_locator(), NullLocator)
                or not hasattr(axis, "_get_tick_boxes_siblings")
                or axis.get_scale() != "linear"
            ):
                continue
            _flatten(ax, axis, isinstance(axis, XAxis), locator, formatter, NullLocator)
    return fig


def _minus(label: str) -> str:
    """``label`` with the minus sign of the moment (``axes.unicode_minus``: the PDF pages
    draw "-", their core font has no U+2212)."""
    import matplotlib as mpl

    return label if mpl.rcParams["axes.unicode_minus"] else label.replace("\N{MINUS SIGN}", "-")


def _flatten(ax: Any, axis: Any, is_x: bool, locator: Any, formatter: Any, null: Any) -> None:
    import numpy as np
    from matplotlib import markers
    from matplotlib.lines import Line2D

    lo, hi = sorted(axis.get_view_interval())
    locs = np.asarray(locator(), dtype=float)
    labels = formatter.format_ticks(locs)
    if formatter.get_offset():
        return  # an offset or a scale beside the axis: matplotlib's ticks write it
    tick = _tick_props(axis)
    if tick.other_side or tick.rotation != 0 or tick.direction != "out":
        return
    tol = 1e-10 * max(abs(lo), abs(hi), hi - lo)
    keep = [k for k, v in enumerate(locs) if lo - tol <= v <= hi + tol]
    locs = locs[keep]
    labels = [labels[k] for k in keep]
    axis.set_major_locator(null())  # matplotlib's ticks no longer drawn
    for spine in ax.spines.values():
        if spine.axis is axis and spine.spine_type in ("left", "right", "bottom", "top"):
            # a spine placed for the first time remakes its axis's tick lists: placed now
            spine.get_spine_transform()
    for made in ("majorTicks", "minorTicks"):
        if made not in vars(axis):
            # none to draw (null locators) and none made: an empty list, made now, spares
            # the tick matplotlib would make to measure the axis's spines
            setattr(axis, made, [])
    zorder = axis.get_zorder()
    pad = tick.pad_pt
    marker: Any
    if is_x:
        transform = ax.get_xaxis_transform()
        text_transform, va, ha = ax.get_xaxis_text1_transform(pad)
        marker = markers.TICKDOWN
        mark_xy = (locs, np.zeros_like(locs))
    else:
        transform = ax.get_yaxis_transform()
        text_transform, va, ha = ax.get_yaxis_text1_transform(pad)
        marker = markers.TICKLEFT
        mark_xy = (np.zeros_like(locs), locs)
    parts: list[Any] = []
    if tick.grid is not None and locs.size:
        color, linewidth, linestyle, alpha = tick.grid
        across = np.tile([0.0, 1.0, np.nan], locs.size)
        along = np.repeat(locs, 3)
        lines = Line2D(
            *((along, across) if is_x else (across, along)),
            transform=transform,
            color=color,
            linewidth=linewidth,
            linestyle=linestyle,
            alpha=alpha,
        )
        lines.set_clip_path(ax.patch)
        parts.append(lines)
    if tick.mark is not None and locs.size:
        size, width, color, alpha = tick.mark
        parts.append(
            Line2D(
                *mark_xy,
                transform=transform,
                linestyle="none",
                marker=marker,
                markersize=size,
                markeredgewidth=width,
                color=color,
                alpha=alpha,
                clip_on=False,
            )
        )
    labels_artist = None
    if tick.label is not None and locs.size:
        font, color, alpha = tick.label
        labels_artist = _TickLabels(
            [((float(v), 0.0) if is_x else (0.0, float(v))) for v in locs],
            list(labels),
            transform=text_transform,
            va=va,
            ha=ha,
            fontproperties=font,
            color=color,
            alpha=alpha,
            clip_on=False,
            parse_math=False,
        )
        parts.append(labels_artist)
    ticks = _ticks_artist(parts)
    ticks.set_zorder(zorder)
    ax.add_artist(ticks)  # among ax.artists: ax.lines and ax.texts hold only the drawing
    fig = ax.get_figure(root=False)
    for part in [*parts, *([labels_artist.label] if labels_artist is not None else [])]:
        part.set_figure(fig)
        part.axes = ax

    def boxes(renderer: Any) -> tuple[list[Any], list[Any]]:
        # where matplotlib measures its tick labels to place the axis label
        return (labels_artist.boxes(renderer) if labels_artist is not None else []), []

    axis._get_tick_boxes_siblings = boxes


@dataclasses.dataclass(frozen=True)
class _TickProps:
    """What :func:`_flatten` reads of one major tick of an axis, as matplotlib makes it."""

    other_side: bool  # a mark or a label on the far side (top, right)
    rotation: float  # of the labels, degrees
    direction: str  # of the marks: "in", "out" or "inout"
    pad_pt: float  # from the axis to its labels (the pad and the mark's length)
    grid: tuple | None  # colour, line width, line style, alpha; None: no grid
    mark: tuple | None  # marker size, edge width, colour, alpha; None: no marks
    label: tuple | None  # font properties, colour, alpha; None: no labels


def _tick_props(axis: Any) -> _TickProps:
    """The properties of a major tick of ``axis``: read from its first tick where it has
    made one, else from a tick made as matplotlib makes it, kept for every axis of the same
    kind, tick settings (``tick_params``, ``grid``) and rcParams of ticks, grid and fonts
    (making a tick costs about a third of making an axes)."""
    made = vars(axis).get("majorTicks")
    if made:
        return _props_of(made[0])
    key = _tick_key(axis)
    if key is None:
        return _props_of(axis.get_major_ticks(1)[0])
    props = _TICK_PROPS.get(key)
    if props is None:
        if len(_TICK_PROPS) >= _TICK_PROPS_MAX:
            _TICK_PROPS.clear()
        props = _TICK_PROPS[key] = _props_of(axis.get_major_ticks(1)[0])
    return props


def _props_of(tick: Any) -> _TickProps:
    grid, mark, label = tick.gridline, tick.tick1line, tick.label1
    return _TickProps(
        other_side=bool(tick.tick2line.get_visible() or tick.label2.get_visible()),
        rotation=float(label.get_rotation()),
        direction=str(tick.get_tickdir()),
        pad_pt=float(tick.get_pad() + tick.get_tick_padding()),
        grid=(
            (grid.get_color(), grid.get_linewidth(), grid.get_linestyle(), grid.get_alpha())
            if grid.get_visible()
            else None
        ),
        mark=(
            (mark.get_markersize(), mark.get_markeredgewidth(), mark.get_color(), mark.get_alpha())
            if mark.get_visible()
            else None
        ),
        label=(
            (label.get_fontproperties().copy(), label.get_color(), label.get_alpha())
            if label.get_visible()
            else None
        ),
    )


def _tick_key(axis: Any) -> tuple | None:
    """What a new major tick of ``axis`` is made from (its class, its tick settings, the
    rcParams a tick reads), hashable; None when a setting cannot be compared."""
    import matplotlib as mpl

    rc = mpl.rcParams
    name = axis.axis_name
    names = _TICK_RC.get(name)
    if names is None:
        prefixes = (f"{name}tick.", "grid.", "font.", "axes.grid", "_internal.")
        names = _TICK_RC[name] = tuple(k for k in rc if k.startswith(prefixes))
    stored: Any = dict.__getitem__  # the settings as stored: quicker than rcParams[...]
    key = (
        type(axis),
        tuple(sorted((k, _frozen(v)) for k, v in axis._major_tick_kw.items())),
        tuple(_frozen(stored(rc, k)) for k in names),
    )
    try:
        hash(key)
    except TypeError:
        return None
    return key


def _frozen(value: Any) -> Any:
    return tuple(_frozen(v) for v in value) if isinstance(value, list) else value


#: the tick properties made (:func:`_tick_props`), by :func:`_tick_key`: a report needs a
#: few; at most this many are kept, as the other caches here are bounded
_TICK_PROPS_MAX = 256
_TICK_PROPS: dict[tuple, _TickProps] = {}
#: the rcParams a tick of an axis ("x", "y") reads, by the axis's name
_TICK_RC: dict[str, tuple[str, ...]] = {}


def _tick_labels_class() -> Any:
    import matplotlib.colors as mcolors
    from matplotlib.artist import Artist
    from matplotlib.text import Text

    class TickLabels(Artist):
        """The labels of one axis of :func:`flat_ticks`, drawn as one artist: one text
        (:attr:`label`) holds what they share (font, colour, alignment, transform) and is
        set to each number and place in turn, each number written with the minus sign of
        the moment it is measured or drawn. Each label is laid out and drawn as
        matplotlib's ``Text.draw`` draws a text, with one graphics context for them all,
        so that no text object is made or drawn per tick."""

        def __init__(self, places: list[tuple[float, float]], labels: list[str], **kw: Any):
            super().__init__()
            self.places = places
            self.labels = labels
            self.label: Any = Text(0.0, 0.0, "", **kw)

        def _set(self, k: int, minus: bool) -> None:
            text = self.label
            text._x, text._y = self.places[k]  # as set_position, without marking stale
            label = self.labels[k]
            text._text = label if minus else label.replace("\N{MINUS SIGN}", "-")

        def boxes(self, renderer: Any) -> list[Any]:
            """The box of each label in display coordinates."""
            minus = bool(_stored_rc("axes.unicode_minus"))
            out = []
            for k in range(len(self.labels)):
                self._set(k, minus)
                out.append(self.label.get_window_extent(renderer))
            return out

        def draw(self, renderer: Any) -> None:
            text = self.label
            if not self.get_visible() or not text.get_visible() or not self.labels:
                return
            minus = bool(_stored_rc("axes.unicode_minus"))
            text._renderer = renderer
            trans = text.get_transform()
            _, height = renderer.get_canvas_width_height()
            flip = renderer.flipy()
            gc = renderer.new_gc()
            gc.set_foreground(mcolors.to_rgba(text.get_color()), isRGBA=True)
            gc.set_alpha(text.get_alpha())
            gc.set_url(text.get_url())
            gc.set_antialiased(text._antialiased)
            gc.set_snap(text.get_snap())
            text._set_gc_clip(gc)
            angle = text.get_rotation()
            prop = text.get_fontproperties()
            for k in range(len(self.labels)):
                self._set(k, minus)
                if not text._text:
                    continue
                _, info, _ = text._get_layout(renderer)
                posx, posy = trans.transform((text._x, text._y))
                for line, _, (x, y) in info:
                    x, y = x + posx, y + posy
                    if flip:
                        y = height - y
                    renderer.draw_text(
                        gc,
                        x,
                        y,
                        line,
                        prop,
                        angle,
                        ismath=False,
                        mtext=text if len(info) == 1 else None,
                    )
            gc.restore()
            self.stale = False

    return TickLabels


def _stored_rc(name: str) -> Any:
    import matplotlib as mpl

    stored: Any = dict.__getitem__  # the setting as stored: quicker than rcParams[...]
    return stored(mpl.rcParams, name)


def _ticks_artist(parts: list[Any]) -> Any:
    """One artist drawing ``parts`` (the grid lines, the marks and the labels of one
    axis) in that order."""
    if not _TICKS:
        from matplotlib.artist import Artist

        class Ticks(Artist):
            def __init__(self, parts: list[Any]):
                super().__init__()
                self.parts = parts

            def get_children(self) -> list[Any]:
                return list(self.parts)

            def draw(self, renderer: Any) -> None:
                if not self.get_visible():
                    return
                for part in self.parts:
                    part.draw(renderer)
                self.stale = False

        _TICKS.append(Ticks)
    return _TICKS[0](parts)


_TICKS: list[Any] = []


def _TickLabels(*args: Any, **kwargs: Any) -> Any:
    if not _TICK_LABELS:
        _TICK_LABELS.append(_tick_labels_class())
    return _TICK_LABELS[0](*args, **kwargs)


_TICK_LABELS: list[Any] = []  # the class, made when first needed (matplotlib loads then)
