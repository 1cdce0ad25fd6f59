"""The widths of strings in the PDF core fonts, read through public APIs.

The text pages are drawn in Helvetica (and Courier for preformatted text), core fonts every
PDF reader has, through matplotlib's PDF renderer with ``pdf.use14corefonts``. It shows such
a string without kerning, in WinAnsiEncoding (cp1252): the string advances by the sum of its
glyphs' widths. :func:`advance` gives that sum from the font's Adobe metrics (the AFM file
matplotlib ships, found by :func:`matplotlib.font_manager.findfont` as matplotlib finds it to
draw the string, read with :mod:`fontTools.afmLib`), each character's glyph named by the
Adobe Glyph List (:mod:`fontTools.agl`) and by the WinAnsi table (PDF 1.7, Annex D.2) where
the two differ. Wrapping measures text with it, and a right-aligned string is placed by it.
"""

from __future__ import annotations

import functools
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from matplotlib.font_manager import FontProperties

__all__ = ["MISSING_WIDTH", "advance", "core_font", "font_properties", "widths"]

#: the width (1/1000 of the size) counted for a character without a glyph in the font
MISSING_WIDTH = 600.0

#: the WinAnsi glyphs (PDF 1.7, Annex D.2) whose names the Adobe Glyph List gives
#: otherwise or not at all; every other character's glyph is named by that list
_WINANSI_NAMES = {
    "\u20ac": "Euro",
    "\u201a": "quotesinglbase",
    "\u0192": "florin",
    "\u201e": "quotedblbase",
    "\u02c6": "circumflex",
    "\u02dc": "tilde",
    "\u00a0": "space",
    "\u00a4": "currency",
    "\u00ad": "hyphen",
    "\u00b2": "twosuperior",
    "\u00b3": "threesuperior",
    "\u00b9": "onesuperior",
    "\u00bc": "onequarter",
    "\u00be": "threequarters",
}


def core_font(weight: str = "normal", mono: bool = False) -> str:
    """The core font of a string: Courier for monospace text, else Helvetica (bold for
    ``weight`` "bold")."""
    if mono:
        return "Courier"
    return "Helvetica-Bold" if weight == "bold" else "Helvetica"


@functools.cache
def font_properties(font: str, size: float) -> FontProperties:
    """The :class:`~matplotlib.font_manager.FontProperties` that make matplotlib draw a
    string in the core font ``font`` ("Helvetica", "Helvetica-Bold", "Courier") at
    ``size`` points (regular faces are "medium" in the fonts' metrics)."""
    from matplotlib.font_manager import FontProperties

    family = "Courier" if font == "Courier" else "Helvetica"
    weight = "bold" if font.endswith("-Bold") else "medium"
    return FontProperties(family=family, weight=weight, size=size)


@functools.cache
def widths(font: str) -> dict[str, float]:
    """The advance (1/1000 of the size) of every character cp1252 encodes, in the core
    font ``font`` ("Helvetica"), read from its metrics (the AFM file matplotlib draws it
    with)."""
    from fontTools import afmLib, agl
    from matplotlib.font_manager import findfont

    path = findfont(font_properties(font, 10.0), fontext="afm")
    afm = afmLib.AFM(path)
    table: dict[str, float] = {}
    for code in range(256):
        try:
            ch = bytes([code]).decode("cp1252")
        except UnicodeDecodeError:
            continue  # five codes WinAnsi leaves undefined
        name = _WINANSI_NAMES.get(ch) or agl.UV2AGL.get(ord(ch))
        table[ch] = float(afm[name][1]) if name and afm.has_char(name) else MISSING_WIDTH
    return table


def advance(text: str, font: str) -> float | None:
    """The advance of ``text`` in ``font``, in 1/1000 of the size: the sum of its glyphs'
    widths, without kerning (as the string is shown); None when cp1252 cannot encode the
    text (the core fonts cannot show it)."""
    try:
        return float(sum(map(widths(font).__getitem__, text)))
    except KeyError:  # the table holds every character cp1252 encodes, and only those
        return None
