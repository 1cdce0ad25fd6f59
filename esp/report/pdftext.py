"""Strings in the PDF core fonts, written straight into a page's content stream.

matplotlib's PDF renderer shows a string in a core font (``pdf.use14corefonts``) as one
text object of its own, ``BT /F1 9.5 Tf x y Td (string) Tj ET``, without kerning; for
every string it finds the font anew, compares the graphics state and formats each number
through its generic writer. A text page holds thousands of such strings. Here they are
written as the same text objects, from the positions matplotlib computes, with the
numbers formatted as its writer formats them; the font's resource name is looked up once
per page and font, and the colour (with the opacity) is set through the renderer's
graphics state once per run of strings of the same colour. The glyphs land where
matplotlib put them, and a reader extracts the same strings.

The core fonts are shown through WinAnsiEncoding (cp1252; matplotlib declares it for every
core font it writes): a string is encoded so, and ``\\``, ``(`` and ``)`` are escaped
(PDF 1.7, 7.3.4.2). As in matplotlib's output no kerning is applied: a string advances by
the sum of its glyphs' widths, which :func:`advance` gives from the fonts' metrics (each
byte's WinAnsi glyph, by name), for right alignment and for measuring text to wrap it.
"""

from __future__ import annotations

import functools
from collections.abc import Iterable
from pathlib import Path

__all__ = ["MISSING_WIDTH", "advance", "core_font", "number", "show", "text_objects", "widths"]

#: the width (1/1000 of the size) counted for a character without a glyph in the font
MISSING_WIDTH = 600.0

#: the WinAnsi glyphs (PDF 1.7, Annex D.2) whose names matplotlib's table of Unicode to
#: glyph names lacks or gives otherwise; every other code's glyph is named by that table
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
def widths(font: str) -> dict[str, float]:
    """The advance (1/1000 of the size) of every character cp1252 encodes, in the core
    font ``font`` ("Helvetica"), read from its metrics (the AFM file matplotlib ships)."""
    import matplotlib as mpl
    from matplotlib._afm import AFM
    from matplotlib._mathtext_data import uni2type1

    path = Path(mpl.get_data_path()) / "fonts" / "pdfcorefonts" / f"{font}.afm"
    with path.open("rb") as fh:
        afm = AFM(fh)
    table: dict[str, float] = {}
    for code in range(256):
        try:
            ch = bytes([code]).decode("cp1252")
        except UnicodeDecodeError:
            continue  # five codes WinAnsi leaves undefined
        name = _WINANSI_NAMES.get(ch) or uni2type1.get(ord(ch))
        try:
            table[ch] = float(afm.get_width_from_char_name(name)) if name else MISSING_WIDTH
        except KeyError:
            table[ch] = MISSING_WIDTH
    return table


def advance(text: str, font: str) -> float | None:
    """The advance of ``text`` in ``font``, in 1/1000 of the size: the sum of its glyphs'
    widths, without kerning (as the string is shown); None when cp1252 cannot encode the
    text (the core fonts cannot show it)."""
    try:
        return float(sum(map(widths(font).__getitem__, text)))
    except KeyError:  # the table holds every character cp1252 encodes, and only those
        return None


def number(value: float) -> bytes:
    """A number as a PDF writes it: fixed point to 10 decimals, no trailing zeros (as
    matplotlib's writer does, so that positions are written alike)."""
    return (b"%.10f" % value).rstrip(b"0").rstrip(b".")


def show(text: str) -> bytes:
    """``text`` as a PDF string shown by ``Tj`` in a core font: encoded in cp1252
    (WinAnsiEncoding), with ``\\``, ``(`` and ``)`` escaped, and carriage returns and line
    feeds written as escapes (a reader may take them for one another)."""
    data = text.encode("cp1252")
    if b"\\" in data:
        data = data.replace(b"\\", b"\\\\")
    if b"(" in data or b")" in data:
        data = data.replace(b"(", b"\\(").replace(b")", b"\\)")
    if b"\r" in data or b"\n" in data:
        data = data.replace(b"\r", b"\\r").replace(b"\n", b"\\n")
    return b"(" + data + b")"


def text_objects(strings: Iterable[tuple[bytes, float, float, float, str]]) -> bytes:
    """``strings``, each (font resource name as written, e.g. ``b"/F1"``; size in points;
    x and y of the start of its baseline in points from the bottom left; text), each in a
    text object of its own as matplotlib writes one (``BT /F1 9.5 Tf x y Td (text) Tj
    ET``: a reader takes each for a string of its own), in the colour set before them."""
    line = b"BT %s %s Tf %s %s Td %s Tj ET\n"
    return b"".join(
        [
            line % (name, number(size), number(x), number(y), show(text))
            for name, size, x, y, text in strings
        ]
    )
