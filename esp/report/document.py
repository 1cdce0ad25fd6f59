"""The one document style of every PDF esp writes: a report a calibration laboratory can
put its name under.

Every command with ``--out`` builds its PDF here, in the same order:

1. a **title block** on page 1: what the document is, the machine's name (wrapped, never
   cut), and its serial, owner, measurement date, operator and laboratory, each shown when
   known (``[report]`` of ``machine.toml``, ``[machine]``, or the data files' USER-TEXT);
2. a **summary** of the headline figures, each with its uncertainty statement (U, k,
   coverage, method) beside it when an uncertainty was evaluated;
3. **sections** of text and tables: a heading is kept with its first lines (it moves to
   the next page with them), a table is split across pages with its header repeated and
   never leaves fewer than three rows under a header on a page (or it moves as a whole),
   a new section starts a new page only when the current one is more than 70 % full (no
   page holds a few stray lines), and every cell is wrapped in its column, never cut;
4. the **figures**, one per page at their own size, each with a caption;
5. a last page of **provenance** (:func:`provenance_pages`): the esp version, the command
   line, every data file with its size and SHA-256, its USER-TEXT and environment, and the
   configuration as given, so that the same document can be made again.

Every page, figure pages too, carries the footer ``page n of N`` with N the pages of the
whole PDF. The text pages are laid out as positioned strings (:class:`TextPage`) so that
tests read what a page says without parsing PDF. They are drawn in Helvetica (and Courier
for the configuration text), fonts every PDF reader has (not embedded, so quick to write
and small); a string their encoding cannot hold, and every formula, is drawn in the
embedded DejaVu Sans of the figures. All user text is drawn literally (never as mathtext)
and on one line per string. Widths are measured with the fonts' own metrics, so wrapping
keeps every string inside its column and the page.

The file is written with fixed metadata and no creation date: the same content gives the
same bytes (matplotlib's writer follows ``SOURCE_DATE_EPOCH``).
"""

from __future__ import annotations

import functools
import logging
import os
import re
import shlex
from collections.abc import Callable, Iterable, Iterator, Mapping, Sequence
from contextlib import ExitStack, contextmanager
from dataclasses import dataclass, field
from pathlib import Path, PurePath
from typing import TYPE_CHECKING, Any, cast

import matplotlib as mpl
from matplotlib.artist import Artist
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.font_manager import FontProperties
from matplotlib.path import Path as MplPath
from matplotlib.ticker import FixedFormatter
from matplotlib.transforms import IdentityTransform

from esp._version import __version__
from esp.core.text import one_line
from esp.io.atomic import atomic_path
from esp.report import pdftext
from esp.report.drawing import figure_texts, quiet_glyphs
from esp.report.epoch import source_date_epoch
from esp.report.tables import Column, Table

if TYPE_CHECKING:
    from matplotlib.backend_bases import RendererBase
    from matplotlib.backends.backend_pdf import PdfPages
    from matplotlib.text import Text
    from matplotlib.typing import RcKeyType

    from esp.core.machine import ReportInfo
    from esp.report.provenance import Provenance

__all__ = [
    "BODY",
    "FOOTER_BASE_IN",
    "MIN_TABLE_ROWS",
    "PAGE_LANDSCAPE_IN",
    "PAGE_PORTRAIT_IN",
    "SMALL",
    "Document",
    "Headline",
    "Layout",
    "TextPage",
    "add_footer",
    "core_encodable",
    "fit_page",
    "metadata",
    "provenance_pages",
    "render_text",
    "save_page",
    "string_width_in",
    "summary",
    "text_report",
    "title_fields",
    "user_text_value",
    "wrap",
    "write_document",
    "write_text_document",
]

#: A4 in inches
PAGE_PORTRAIT_IN = (8.27, 11.69)
PAGE_LANDSCAPE_IN = (11.69, 8.27)
MARGIN = 0.75
#: the room kept at the bottom of a text page for the footer (inches above the margin)
FOOTER = 0.45
#: the baseline of the footer, from the bottom of the page (inches)
FOOTER_BASE_IN = 0.32
#: the baseline of a figure's caption, from the bottom of the page (inches)
CAPTION_BASE_IN = 0.52
LEADING = 1.45
BODY = 9.5
SMALL = 8.3
MONO = 7.2
#: the fewest rows of a table under its header on a page (fewer: the table moves on)
MIN_TABLE_ROWS = 5
#: the fewest lines of a paragraph or preformatted block on a page (a shorter block moves)
MIN_BLOCK_LINES = 4
#: a new section starts a new page only when more than this fraction of the current one
#: is used
SECTION_BREAK = 0.7


# -- the fonts' metrics ------------------------------------------------------------------------

_CORE = {("sans", "normal"): "Helvetica", ("sans", "bold"): "Helvetica-Bold"}


def core_encodable(text: str) -> bool:
    """True when the PDF core fonts (WinAnsi, cp1252) can show ``text``."""
    try:
        text.encode("cp1252")
    except UnicodeEncodeError:
        return False
    return True


def string_width_in(text: str, size: float, weight: str = "normal", mono: bool = False) -> float:
    """The advance of ``text`` in inches at ``size`` points: from the core font's metrics
    (each character's WinAnsi glyph, :func:`esp.report.pdftext.advance`) when its encoding
    holds the text, which is how far the string reaches as drawn; else a generous
    estimate (DejaVu Sans is wider)."""
    if not text:
        return 0.0
    if mono:
        return len(text) * 0.6 * size / 72.0
    units = pdftext.advance(text, _CORE.get(("sans", weight), "Helvetica"))
    if units is not None:
        return units / 1000.0 * size / 72.0
    return len(text) * 0.62 * size / 72.0


def _split_word(word: str, width_in: float, size: float, weight: str, mono: bool) -> list[str]:
    """A word longer than its column, cut into pieces that fit (after a ``/``, ``_``,
    ``-`` or ``.`` where there is one, else anywhere)."""
    pieces = []
    rest = word
    while string_width_in(rest, size, weight, mono) > width_in and len(rest) > 1:
        n = len(rest)
        while n > 1 and string_width_in(rest[:n], size, weight, mono) > width_in:
            n -= 1
        cut = max((rest.rfind(c, 0, n) for c in "/_-."), default=-1)
        if cut >= n // 2:
            n = cut + 1
        pieces.append(rest[:n])
        rest = rest[n:]
    pieces.append(rest)
    return pieces


def wrap(
    text: str, width_in: float, size: float, weight: str = "normal", mono: bool = False
) -> list[str]:
    """``text`` (on one line first) broken into lines no wider than ``width_in``: at
    spaces, and within a word only when the word alone is wider. Nothing is cut off."""
    text = one_line(text)
    if string_width_in(text, size, weight, mono) <= width_in:
        return [text]
    lines: list[str] = []
    current = ""
    for word in text.split(" "):
        trial = f"{current} {word}" if current else word
        if string_width_in(trial, size, weight, mono) <= width_in:
            current = trial
            continue
        if current:
            lines.append(current)
        pieces = _split_word(word, width_in, size, weight, mono)
        lines.extend(pieces[:-1])
        current = pieces[-1]
    lines.append(current)
    return lines


# -- layout -----------------------------------------------------------------------------------


@dataclass(frozen=True)
class _Text:
    x_in: float
    y_in: float  # baseline, from the top of the page
    text: str
    size: float
    weight: str = "normal"
    colour: str = "black"
    ha: str = "left"
    formula: bool = False
    mono: bool = False

    def shifted(self, dy: float) -> _Text:
        return _Text(
            self.x_in,
            self.y_in + dy,
            self.text,
            self.size,
            self.weight,
            self.colour,
            self.ha,
            self.formula,
            self.mono,
        )


@dataclass(frozen=True)
class _Rule:
    x0_in: float
    x1_in: float
    y_in: float
    width_pt: float = 0.6

    def shifted(self, dy: float) -> _Rule:
        return _Rule(self.x0_in, self.x1_in, self.y_in + dy, self.width_pt)


@dataclass
class TextPage:
    """One text page: strings and rules at positions in inches from the top left."""

    items: list = field(default_factory=list)
    #: the page's size (width, height) in inches
    size_in: tuple[float, float] = PAGE_PORTRAIT_IN

    def texts(self) -> list[str]:
        """Every string on the page, in the order laid out."""
        return [i.text for i in self.items if isinstance(i, _Text)]

    def lines(self) -> int:
        """The number of distinct baselines with text: the lines of content."""
        return len({round(i.y_in, 3) for i in self.items if isinstance(i, _Text) and i.text})


class Layout:
    """Places text and tables top to bottom, starting a new page when one is full.

    Every string is put on one line (:func:`~esp.core.text.one_line`) and wrapped to its width
    (:func:`wrap`). A heading is kept with what follows it: when the next line or table
    does not fit under it, the heading moves to the next page too.
    """

    def __init__(self, size_in: tuple[float, float] = PAGE_PORTRAIT_IN) -> None:
        self.width, self.height = size_in
        self.left, self.right = MARGIN, self.width - MARGIN
        self.pages: list[TextPage] = []
        self.page: TextPage = TextPage(size_in=size_in)
        self.y: float = MARGIN
        self._keep: tuple[int, float] | None = None  # (first item of the headings, their y)
        self.new_page()

    @property
    def text_width(self) -> float:
        return self.right - self.left

    @property
    def bottom(self) -> float:
        """The lowest baseline room on a text page, from the top (inches)."""
        return self.height - MARGIN - FOOTER

    def used(self) -> float:
        """The fraction of the current page's text area used."""
        return (self.y - MARGIN) / (self.bottom - MARGIN)

    def new_page(self) -> None:
        keep = self._keep
        moved: list = []
        height = 0.0
        if keep is not None and self.pages:
            start, y0 = keep
            if y0 > MARGIN + 1e-6:  # headings not at the top of their page: take them along
                moved = [i.shifted(MARGIN - y0) for i in self.page.items[start:]]
                del self.page.items[start:]
                height = self.y - y0
        self.page = TextPage(size_in=(self.width, self.height))
        self.pages.append(self.page)
        self.y = MARGIN
        self._keep = None
        if moved:
            self.page.items.extend(moved)
            self.y = MARGIN + height
            self._keep = (0, MARGIN)

    def ensure(self, height_in: float) -> None:
        """Start a new page unless ``height_in`` fits on this one."""
        if self.y + height_in > self.bottom and self.y > MARGIN:
            self.new_page()

    def section_break(self) -> None:
        """Before a new section: a new page when more than 70 % of this one is used, else a
        little space (so that no page holds only the tail of the section before)."""
        if self.used() > SECTION_BREAK:
            self.new_page()
        else:
            self.space(0.2)

    def space(self, height_in: float) -> None:
        if self.y > MARGIN:
            self.y += height_in

    def _put(self, text: str, size: float, x: float | None = None, **kw: Any) -> None:
        height = size * LEADING / 72.0
        self.ensure(height)
        self.page.items.append(
            _Text(self.left if x is None else x, self.y + size / 72.0, text, size, **kw)
        )
        self.y += height
        self._keep = None

    def line(
        self, text: str, size: float = BODY, weight: str = "normal", colour: str = "black"
    ) -> None:
        """One line of text, wrapped if it is wider than the page."""
        for part in wrap(text, self.text_width, size, weight):
            self._put(part, size, weight=weight, colour=colour)

    def _block(self, parts: Sequence[tuple[float, str]], size: float, **kw: Any) -> None:
        """Lines (x, text) of one block: a block of up to :data:`MIN_BLOCK_LINES` lines is
        kept on one page; a longer one leaves at least that many on each page it spans."""
        line = size * LEADING / 72.0
        n = len(parts)
        i = 0
        while i < n:
            fit = max(0, int((self.bottom - self.y) / line + 1e-9))
            if fit < min(n - i, MIN_BLOCK_LINES) and self.y > MARGIN + 1e-6:
                self.new_page()
                continue
            rest = n - i - fit
            if 0 < rest < MIN_BLOCK_LINES and fit - (MIN_BLOCK_LINES - rest) >= MIN_BLOCK_LINES:
                fit -= MIN_BLOCK_LINES - rest
            fit = max(fit, 1)
            for x, text in parts[i : i + fit]:
                self.page.items.append(_Text(x, self.y + size / 72.0, text, size, **kw))
                self.y += line
            self._keep = None
            i += fit
            if i < n:
                self.new_page()

    def paragraph(self, text: str, size: float = BODY, indent_in: float = 0.0, **kw: Any) -> None:
        weight = kw.get("weight", "normal")
        x = self.left + indent_in
        parts = wrap(text, self.text_width - indent_in, size, weight) or [""]
        self._block([(x, p) for p in parts], size, **kw)

    def preformatted(self, text: str, size: float = MONO) -> None:
        """Text as given, line by line, in Courier (a configuration file); a line wider
        than the page is wrapped, never cut."""
        parts = []
        for raw in text.expandtabs(4).splitlines() or [""]:
            indent = len(raw) - len(raw.lstrip(" "))
            x = self.left + indent * 0.6 * size / 72.0
            width = max(1.0, self.text_width - indent * 0.6 * size / 72.0)
            parts += [(x, p) for p in wrap(raw.strip(" "), width, size, mono=True) or [""]]
        self._block(parts, size, mono=True)

    def heading(self, text: str, level: int = 1) -> None:
        size = {0: 20.0, 1: 13.0, 2: 10.5}[level]
        self.space({0: 0.0, 1: 0.22, 2: 0.12}[level])
        self.ensure(size * LEADING / 72.0 + 4 * BODY * LEADING / 72.0)
        keep = self._keep if self._keep is not None else (len(self.page.items), self.y)
        for part in wrap(text, self.text_width, size, "bold"):
            self._put(part, size, weight="bold")
        if level == 1:
            self.page.items.append(_Rule(self.left, self.right, self.y - 0.06, 0.8))
            self.y += 0.06
        self._keep = keep if level > 0 else None

    def pairs(self, rows: Sequence[tuple[str, str]], key_in: float = 1.55) -> None:
        """Key and value side by side, both wrapped in their columns."""
        for key, value in rows:
            keys = wrap(key, key_in - 0.1, BODY, "bold")
            values = wrap(value, self.text_width - key_in, BODY) or [""]
            height = BODY * LEADING / 72.0
            self.ensure(height * min(len(values), 3))
            for k in range(max(len(keys), len(values))):
                self.ensure(height)
                base = self.y + BODY / 72.0
                if k < len(keys):
                    self.page.items.append(_Text(self.left, base, keys[k], BODY, "bold", "0.25"))
                if k < len(values):
                    self.page.items.append(_Text(self.left + key_in, base, values[k], BODY))
                self.y += height
            self._keep = None

    def aligned_pairs(
        self, pairs: Sequence[tuple[str, str]], indent_in: float = 0.0, size: float = SMALL
    ) -> None:
        """Name and value in two aligned columns, in plain text: the names as wide as
        the widest (at most 45 % of the line), the values wrapped in the rest."""
        left = self.left + indent_in
        room = self.text_width - indent_in
        key_in = min(0.45 * room, max(string_width_in(a, size) for a, _ in pairs) + 0.2)
        height = size * LEADING / 72.0
        for key, value in pairs:
            keys = wrap(key, key_in - 0.1, size)
            values = wrap(value, room - key_in, size) or [""]
            self.ensure(height * min(max(len(keys), len(values)), 3))
            for k in range(max(len(keys), len(values))):
                self.ensure(height)
                base = self.y + size / 72.0
                if k < len(keys):
                    self.page.items.append(_Text(left, base, keys[k], size))
                if k < len(values):
                    self.page.items.append(_Text(left + key_in, base, values[k], size))
                self.y += height
            self._keep = None

    def table(self, table: Table, size: float = SMALL, keep_whole: bool = False) -> None:
        """A table with a bold header and a rule under it. Cells are wrapped in their
        columns; the header is repeated on each page the table continues on; at least
        :data:`MIN_TABLE_ROWS` rows (or all, if fewer) stand under a header on a page. With
        ``keep_whole``, a table that would be split moves whole (with its heading) to the
        next page when it fits on one (the last table before the figures: no short page of
        its tail)."""
        columns = _fitted(table.columns, self.text_width)
        line = size * LEADING / 72.0
        header = [
            wrap(h, c.width_in - 0.08, size, "bold")
            for h, c in zip(table.headers, columns, strict=True)
        ]
        header_h = max(len(h) for h in header) * line + 0.03
        cells = [
            [wrap(v, c.width_in - 0.08, size) or [""] for v, c in zip(row, columns, strict=True)]
            for row in table.rows
        ]
        heights = [max(len(c) for c in row) * line for row in cells]
        n = len(cells)
        i = 0
        first = True
        while i < n or (first and n == 0):
            room = self.bottom - self.y - header_h
            k = _fit_count(heights, i, room)
            if k < min(MIN_TABLE_ROWS, n - i) and self.y > MARGIN + 1e-6 and first:
                self.new_page()  # the table (with its heading) moves to the next page
                first = False
                continue
            rest = n - i - k
            if keep_whole and first and rest > 0 and self.y > MARGIN + 1e-6:
                # the table would be split: it moves whole (with its heading) to the next
                # page when it fits there
                heading_h = self.y - self._keep[1] if self._keep is not None else 0.0
                if heading_h + header_h + sum(heights) <= self.bottom - MARGIN:
                    self.new_page()
                    first = False
                    continue
            if 0 < rest < MIN_TABLE_ROWS and k - (MIN_TABLE_ROWS - rest) >= MIN_TABLE_ROWS:
                k -= MIN_TABLE_ROWS - rest  # leave no orphan rows for the next page
            k = max(k, 1) if n else 0
            self._cells(header, columns, size, "bold", header=True)
            self.page.items.append(
                _Rule(self.left, self.left + sum(c.width_in for c in columns), self.y - 0.04, 0.5)
            )
            self.y += 0.03
            for row in cells[i : i + k]:
                self._cells(row, columns, size, "normal")
            i += k
            first = False
            self._keep = None
            if i < n:
                self.new_page()

    def _cells(
        self,
        cells: Sequence[Sequence[str]],
        columns: Sequence[Column],
        size: float,
        weight: str,
        header: bool = False,
    ) -> None:
        x = self.left
        line = size * LEADING / 72.0
        for lines, col in zip(cells, columns, strict=True):
            formula = col.formula and not header
            for k, text in enumerate(lines):
                base = self.y + size / 72.0 + k * line
                if col.align == "right":
                    self.page.items.append(
                        _Text(x + col.width_in - 0.08, base, text, size, weight, ha="right")
                    )
                else:
                    self.page.items.append(_Text(x, base, text, size, weight, formula=formula))
            x += col.width_in
        self.y += max(len(c) for c in cells) * line


def _fitted(columns: Sequence[Column], width_in: float) -> tuple[Column, ...]:
    """The columns, narrowed in proportion when together they are wider than the page."""
    total = sum(c.width_in for c in columns)
    if total <= width_in + 1e-9:
        return tuple(columns)
    f = width_in / total
    return tuple(Column(c.header, c.align, c.width_in * f, c.formula) for c in columns)


def _fit_count(heights: Sequence[float], start: int, room: float) -> int:
    used, k = 0.0, 0
    for h in heights[start:]:
        if used + h > room + 1e-9:
            break
        used += h
        k += 1
    return k


# -- the title block and the summary ------------------------------------------------------------


@dataclass(frozen=True)
class Headline:
    """One headline figure of the summary: what it is, its value with unit, and the
    statement of its uncertainty (e.g. ``"U = 2.1 µm (k = 2, 95 %, GUM)"``) or None when
    no uncertainty was evaluated."""

    label: str
    value: str
    uncertainty: str | None = None


#: the fields of the title block, in order: (key, label)
TITLE_FIELDS = (
    ("serial", "Serial"),
    ("owner", "Owner"),
    ("location", "Location"),
    ("date", "Measured on"),
    ("operator", "Operator"),
    ("laboratory", "Laboratory"),
)

#: USER-TEXT labels of the data files that give a field of the title block
_USER_TEXT_KEYS = {
    "serial": ("serial", "serial no", "serial number", "machine serial"),
    "owner": ("owner", "customer", "company"),
    "location": ("location", "site"),
    "date": ("date", "test date", "measured on"),
    "operator": ("operator", "measured by", "by", "user"),
    "laboratory": ("laboratory", "lab"),
}


def title_fields(
    report: ReportInfo | None = None,
    info: Mapping[str, str] | None = None,
    provenance: Provenance | None = None,
) -> list[tuple[str, str]]:
    """The (label, value) fields of a title block, each shown when known: from the
    ``[report]`` table (``report``: an object with ``serial``, ``owner``, ``operator``,
    ``laboratory``), else from ``[machine]`` (``info``: serial, location, measured_by,
    date), else from the USER-TEXT of the data files of ``provenance`` (when every file
    that gives the field gives the same value)."""
    known: dict[str, str] = {}
    if report is not None:
        for key, _ in TITLE_FIELDS:
            value = getattr(report, key, None)
            if value:
                known[key] = str(value)
    for key, source in (
        ("serial", "serial"),
        ("location", "location"),
        ("operator", "measured_by"),
        ("date", "date"),
    ):
        if info and source in info and key not in known:
            known[key] = str(info[source])
    if provenance is not None:
        for key, labels in _USER_TEXT_KEYS.items():
            if key in known:
                continue
            values = {
                value.strip()
                for record in getattr(provenance, "inputs", ())
                for label, value in getattr(record, "user_text", ())
                if label.strip().lower().rstrip(":") in labels and value.strip()
            }
            if len(values) == 1:
                known[key] = values.pop()
    return [(label, known[key]) for key, label in TITLE_FIELDS if key in known]


def user_text_value(provenance: Provenance | None, labels: Sequence[str]) -> str | None:
    """The value the data files' USER-TEXT gives under one of ``labels`` (compared without
    case), when every file that gives one gives the same; else None."""
    values = {
        value.strip()
        for record in getattr(provenance, "inputs", ())
        for label, value in getattr(record, "user_text", ())
        if label.strip().lower().rstrip(":") in labels and value.strip()
    }
    return values.pop() if len(values) == 1 else None


def title_block(
    lay: Layout,
    title: str,
    name: str,
    fields: Sequence[tuple[str, str]] = (),
    note: str | None = None,
) -> None:
    """Page 1: what the document is, the machine's name, and the fields known."""
    lay.heading(title, level=0)
    lay.line(name, size=15.0, weight="bold")
    if fields:
        lay.space(0.04)
        lay.pairs(list(fields), key_in=1.3)
    if note:
        lay.paragraph(note, colour="0.3")


def summary(lay: Layout, headlines: Sequence[Headline], heading: str = "Summary") -> None:
    """The headline figures, each with its uncertainty statement beside it."""
    lay.heading(heading)
    if not headlines:
        return
    has_u = any(h.uncertainty for h in headlines)
    columns = [Column("figure", "left", 2.4), Column("value", "right", 1.3)]
    if has_u:
        columns.append(Column("   uncertainty", "left", 3.07))
    rows = []
    for h in headlines:
        row = [h.label, h.value]
        if has_u:
            row.append("   " + (h.uncertainty or "not evaluated"))
        rows.append(tuple(row))
    lay.table(Table(tuple(columns), tuple(rows)), size=BODY)


# -- a terminal report as document sections -------------------------------------------------

_NUMBER = re.compile(r"^[-+]?(\d+\.?\d*|\.\d+)(e[-+]?\d+)?( ?[^\s\d]{1,6})?$", re.IGNORECASE)


def _cells(line: str) -> list[str]:
    return [c for c in re.split(r"\s{2,}", line.strip()) if c]


def _indent(line: str) -> int:
    return len(line) - len(line.lstrip(" "))


def _text_table(run: Sequence[str]) -> Table:
    """A run of aligned lines as a table: the first line the header; a line with fewer
    cells than the widest is padded at the front when it is indented deeper (the header
    of a matrix, over its row labels), else at the end."""
    base = min(_indent(line) for line in run)
    rows = [_cells(line) for line in run]
    n = max(len(r) for r in rows)
    padded = []
    for line, cells in zip(run, rows, strict=True):
        missing = n - len(cells)
        if missing and _indent(line) > base:
            cells = [""] * missing + cells
        else:
            cells = cells + [""] * missing
        padded.append(tuple(cells))
    header, body = padded[0], padded[1:]
    widths = []
    aligns = []
    for k in range(n):
        column = [r[k] for r in body]
        numeric = sum(1 for c in column if _NUMBER.match(c)) >= max(1, len(column) // 2)
        aligns.append("right" if numeric and k > 0 else "left")
        widest = max(string_width_in(c, SMALL) for c in (header[k], *column))
        widths.append(widest + 0.22)
    return Table(
        tuple(Column(h, a, w) for h, a, w in zip(header, aligns, widths, strict=True)),
        tuple(body),
    )


def _pair_run(lines: Sequence[str], start: int) -> list[str]:
    """The indented lines from ``start`` on that hold two cells each (a name, two spaces
    or more, its value) at the same indent: a list the terminal aligns in two columns."""
    first = lines[start]
    if _indent(first) == 0 or len(_cells(first)) != 2:
        return []
    run = []
    for line in lines[start:]:
        if _indent(line) != _indent(first) or len(_cells(line)) != 2:
            break
        run.append(line)
    return run


def text_report(lay: Layout, text: str, skip: int = 0) -> None:
    """Lay out a terminal report (after its first ``skip`` lines) as document sections:
    an unindented line over indented ones is a heading; a run of two or more lines whose
    cells are aligned in columns (two spaces or more between them) is a table with its
    first line as header; a run of indented lines of two cells each is set in two aligned
    columns; every other line is a paragraph, indented as in the text."""
    lines = text.rstrip("\n").split("\n")[skip:]
    k = 0
    while k < len(lines):
        line = lines[k]
        if not line.strip():
            lay.space(0.06)
            k += 1
            continue
        nxt = lines[k + 1] if k + 1 < len(lines) else ""
        aligned = len(_cells(line)) >= 3 and len(_cells(nxt)) == len(_cells(line))
        if _indent(line) == 0 and nxt.strip() and _indent(nxt) > 0 and not aligned:
            lay.heading(line.strip().rstrip(":"), level=2)
            k += 1
            continue
        run = [line]
        head = len(_cells(line))
        if head >= 2:
            j = k + 1
            while j < len(lines) and lines[j].strip() and len(_cells(lines[j])) >= 3:
                if _indent(lines[j]) == 0 and _indent(line) > 0:
                    break
                run.append(lines[j])
                j += 1
            width = len(_cells(run[1])) if len(run) >= 2 else 0
            matrix = head == width - 1 and len(run) >= 2 and _indent(line) > _indent(run[1])
            cells = _cells(line)
            numbered = sum(1 for c in cells[1:] if re.search(r"\d", c)) * 2 >= len(cells) - 1
            if len(run) >= 2 and width >= 3 and (matrix or (head == width and not numbered)):
                # the last table (a closing line or two may follow): kept whole, so that
                # no page holds only its tail
                last = sum(1 for rest in lines[j:] if rest.strip()) <= 2
                lay.table(_text_table(run), keep_whole=last)
                k = j
                continue
        pair_run = _pair_run(lines, k)
        if len(pair_run) >= 2:
            pairs = [cast(tuple[str, str], tuple(_cells(p))) for p in pair_run]
            lay.aligned_pairs(pairs, min(_indent(line), 8) * 0.07)
            k += len(pair_run)
            continue
        indent = min(_indent(line), 8) * 0.07
        deeper = nxt.strip() and _indent(nxt) > _indent(line) and len(_cells(nxt)) >= 3
        lay.paragraph(
            line.strip(),
            size=SMALL if _indent(line) else BODY,
            indent_in=indent,
            weight="bold" if deeper else "normal",
        )
        k += 1


def write_text_document(
    path: str | Path,
    *,
    title: str,
    name: str,
    date: str,
    text: str,
    skip: int = 1,
    headlines: Sequence[Headline] = (),
    fields: Sequence[tuple[str, str]] = (),
    figures: Sequence[tuple[Figure, str]] = (),
    provenance: Provenance | None = None,
    note: str | None = None,
    section: str = "Results",
) -> int:
    """Write the document of a command whose content is its terminal report: the title
    block, the summary of ``headlines`` (and ``note``), the report's sections
    (:func:`text_report`), the ``figures`` (figure, caption), the provenance. Returns the
    number of pages."""
    doc = Document(title, name, date, fields or title_fields(provenance=provenance))
    summary(doc.lay, headlines)
    if note:
        doc.lay.paragraph(note, size=SMALL, colour="0.3")
    doc.section(section)
    text_report(doc.lay, text, skip=skip)
    for fig, caption in figures:
        doc.figure(fig, caption)
    return doc.write(path, provenance)


# -- provenance -------------------------------------------------------------------------------


def _mb(size: int) -> str:
    return f"{size:,}".replace(",", " ")


def provenance_pages(provenance: Provenance) -> list[TextPage]:
    """The last pages of a document: what it was made from (an
    :class:`esp.report.provenance.Provenance`: the esp version, the command, every data
    file with its kind, size, SHA-256, USER-TEXT and environment, and the configuration
    files as given). When the configuration would leave only its last lines on a page of
    their own, it is set smaller, or starts on a new page, whichever takes the fewest
    pages without a short last page."""
    best: list[TextPage] = []
    best_key: tuple[int, bool] | None = None
    for new_page in (False, True):
        for mono in (MONO, 6.4, 5.7):
            pages = _provenance_pages(provenance, mono, new_page)
            key = (len(pages), len(pages) > 1 and pages[-1].lines() < 15)
            if best_key is None or key < best_key:
                best, best_key = pages, key
            if not key[1]:
                break
        if best_key is not None and not best_key[1]:
            break
    return best


def _provenance_pages(provenance: Provenance, mono: float, new_page: bool) -> list[TextPage]:
    lay = Layout()
    lay.heading("Provenance")
    command = tuple(getattr(provenance, "command", ()) or ())
    lay.pairs(
        [
            ("esp version", str(getattr(provenance, "esp_version", __version__))),
            ("Command", shlex.join(command) if command else "not recorded"),
        ]
    )
    lay.paragraph(
        "The same command on files with the same SHA-256 and the same configuration makes "
        "this document again, byte for byte (with the same SOURCE_DATE_EPOCH).",
        size=SMALL,
        colour="0.3",
    )
    inputs = tuple(getattr(provenance, "inputs", ()) or ())
    lay.heading("Files read", level=2)
    if inputs:
        lay.table(
            Table(
                (
                    Column("file", "left", 2.2),
                    Column("kind", "left", 0.75),
                    Column("bytes", "right", 0.55),
                    Column("  SHA-256", "left", 3.27),
                ),
                tuple(
                    (
                        str(r.path),
                        str(r.kind),
                        _mb(int(r.size_bytes)),
                        "  " + str(r.sha256),
                    )
                    for r in inputs
                ),
            ),
            size=6.5,  # a SHA-256 on one line
        )
    else:
        lay.paragraph("None.")
    _environment(lay, inputs)
    _user_text(lay, inputs)
    configuration = tuple(getattr(provenance, "configuration", ()) or ())
    for k, (name, text) in enumerate(configuration):
        if new_page and k == 0 and lay.y > MARGIN + 1e-6:
            lay.new_page()
        lay.heading(f"Configuration as given: {name}", level=2)
        lay.preformatted(str(text).rstrip("\n"), size=mono)
    return lay.pages


def _short_names(paths: Sequence[str]) -> dict[str, str]:
    """Each path by the fewest of its last parts that tell it from the others
    (``X-linear.rtl``; ``gantry/X-linear.rtl`` and ``gantry-2024/X-linear.rtl`` when two
    folders hold files of one name)."""
    parts = {p: PurePath(p).parts or (p,) for p in paths}
    out: dict[str, str] = {}
    for p, own in parts.items():
        for n in range(1, len(own) + 1):
            tail = own[-n:]
            if all(q == p or parts[q][-n:] != tail for q in parts):
                break
        out[p] = str(PurePath(*tail)) if tail else p
    return out


def _column_width(cells: Iterable[str], header: str, size: float, least_in: float) -> float:
    """The width a column needs for its longest cell (and the longest word of its header),
    at least ``least_in``."""
    words = header.split()
    needed = max(
        [string_width_in(c, size) for c in cells]
        + [string_width_in(w, size, "bold") for w in words]
        + [0.0]
    )
    return max(least_in, needed + 0.14)


def _environment(lay: Layout, inputs: Sequence[Any]) -> None:
    """The environment of each data file, a row each: every reading as the file records it
    at the start and the end of the measurement (:class:`esp.report.provenance.Reading`),
    the unit in the header. Files with more kinds of reading than fit across the page are
    listed a reading a row."""
    rows = [r for r in inputs if getattr(r, "environment", ())]
    if not rows:
        return
    size = 7.0
    short = _short_names([str(r.path) for r in inputs])
    lay.heading("Environment recorded with the data", level=2)
    structured = all(getattr(r, "readings", ()) for r in rows)
    if structured:
        table = {id(r): {q.quantity: q for q in r.readings} for r in rows}
        quantities = list(dict.fromkeys(q.quantity for r in rows for q in r.readings))
        units = {}
        for q in quantities:
            found = {table[id(r)][q].unit for r in rows if q in table[id(r)]}
            units[q] = found.pop() if len(found) == 1 else ""
        headers = [f"{q} ({units[q]})" if units[q] else q for q in quantities]
        body = [
            (
                short[r.path],
                *(
                    (
                        table[id(r)][q].compact
                        if units[q] or not table[id(r)][q].unit
                        else table[id(r)][q].text
                    )
                    if q in table[id(r)]
                    else "absent"
                    for q in quantities
                ),
            )
            for r in rows
        ]
        widths = [
            _column_width([row[k + 1] for row in body], h, size, 0.55)
            for k, h in enumerate(headers)
        ]
        file_in = min(1.9, _column_width([row[0] for row in body], "file", size, 0.8))
        if file_in + sum(widths) <= lay.text_width + 1e-9:
            lay.paragraph(
                "Each reading as the file records it at the start / at the end of the "
                "measurement; one value: the same at both; absent: no sensor connected.",
                size=SMALL,
                colour="0.3",
            )
            columns = (Column("file", "left", file_in),) + tuple(
                Column(h, "right" if units[q] else "left", w)
                for h, q, w in zip(headers, quantities, widths, strict=True)
            )
            lay.table(Table(columns, tuple(body)), size=size)
            return
    lay.table(
        Table(
            (Column("file", "left", 2.2), Column("quantity", "left", 2.8), Column("value")),
            tuple((short[r.path], q, v) for r in rows for q, v in r.environment),
        ),
        size=size,
    )


def _user_text(lay: Layout, inputs: Sequence[Any]) -> None:
    """The USER-TEXT of the data files: what every file says alike once, then per file
    what differs: a row per file with a column per label when a few labels differ, else a
    row per label."""
    rows = [r for r in inputs if getattr(r, "user_text", ())]
    if not rows:
        return
    size = 7.0
    short = _short_names([str(r.path) for r in inputs])
    texts = [dict(r.user_text) for r in rows]
    labels = list(dict.fromkeys(label for r in rows for label, _ in r.user_text))
    common = [
        label
        for label in labels
        if len(rows) > 1 and all(label in t for t in texts) and len({t[label] for t in texts}) == 1
    ]
    lay.heading("USER-TEXT of the data files", level=2)
    if common:
        lay.paragraph("The same in every file:", size=SMALL, colour="0.3")
        lay.pairs([(label, texts[0][label]) for label in common])
    own_labels = [label for label in labels if label not in common]
    once = all(len({label for label, _ in r.user_text}) == len(r.user_text) for r in rows)
    if not own_labels:
        return
    if once and len(own_labels) <= 4:
        body = tuple(
            (short[r.path], *(t.get(label, "") for label in own_labels))
            for r, t in zip(rows, texts, strict=True)
        )
        file_in = min(1.9, _column_width([row[0] for row in body], "file", size, 0.8))
        widths = [
            _column_width([row[k + 1] for row in body], label, size, 0.5)
            for k, label in enumerate(own_labels)
        ]
        # the widest column (a comment, as a rule) takes what the others leave
        room = lay.text_width - file_in - sum(widths)
        widest = max(range(len(widths)), key=lambda k: widths[k])
        widths[widest] = max(1.0, widths[widest] + room) if room < 0 else widths[widest] + room
        columns = (Column("file", "left", file_in),) + tuple(
            Column(label, "left", w) for label, w in zip(own_labels, widths, strict=True)
        )
        lay.table(Table(columns, body), size=size)
        return
    body2: list[tuple[str, str, str]] = []
    for r in rows:
        own = [(label, value) for label, value in r.user_text if label not in common]
        body2 += [(short[r.path] if k == 0 else "", lb, v) for k, (lb, v) in enumerate(own)]
    lay.table(
        Table(
            (
                Column("file", "left", 2.0),
                Column("label", "left", 1.6),
                Column("text", "left", 3.17),
            ),
            tuple(body2),
        ),
        size=size,
    )


# -- rendering --------------------------------------------------------------------------------


@contextmanager
def _rc_all(settings: Mapping[RcKeyType, Any]) -> Iterator[None]:
    """Settings of matplotlib's for the time of the block (:func:`_rc` for each)."""
    with ExitStack() as stack:
        for key, value in settings.items():
            stack.enter_context(_rc(key, value))
        yield


@contextmanager
def _rc(key: RcKeyType, value: Any) -> Iterator[None]:
    """One setting of matplotlib's for the time of the block (what ``rc_context`` does for
    it, without copying every setting on the way in)."""
    old = mpl.rcParams[key]
    if old == value:
        yield
        return
    mpl.rcParams[key] = value
    try:
        yield
    finally:
        mpl.rcParams[key] = old


class TextBlock(Artist):
    """Strings at fixed positions (inches from the top left of the figure), drawn through
    the renderer's :meth:`~matplotlib.backend_bases.RendererBase.draw_text` without text
    layout: left- or right-aligned on their baseline, always literally (never mathtext).

    On a PDF page (drawn by :func:`save_page`, which sets :attr:`core` for the page) a
    string goes in Helvetica (Courier for preformatted text), core fonts of every PDF
    reader, when their encoding can hold it and it is not a formula, whatever font the rest
    of the page is drawn in; every other string is drawn in the embedded font (DejaVu Sans).
    Elsewhere every string is drawn in DejaVu Sans.
    """

    def __init__(self, items: Sequence, height_in: float):
        super().__init__()
        self.items = list(items)
        self.height_in = height_in
        #: True while drawn on a PDF page: the core fonts are used where they can be
        self.core = False

    def _draw_items(self, renderer: RendererBase, items: Sequence[_Text], core: bool) -> None:
        inch = cast(float, renderer.points_to_pixels(72.0))  # a float, the stubs say ArrayLike
        gc = renderer.new_gc()
        try:
            for item in items:
                x = item.x_in * inch
                y = (self.height_in - item.y_in) * inch
                if core:
                    font = pdftext.core_font(item.weight, item.mono)
                    prop = pdftext.font_properties(font, item.size)
                    if item.ha == "right":  # shown unkerned: its advance is its width
                        x -= (pdftext.advance(item.text, font) or 0.0) * item.size / 1000.0
                else:
                    prop = _embedded_prop(item.size, item.weight, item.mono)
                    if item.ha == "right":
                        width, _, _ = renderer.get_text_width_height_descent(
                            item.text, prop, ismath=False
                        )
                        x -= width
                gc.set_foreground(item.colour)
                renderer.draw_text(gc, x, y, item.text, prop, 0.0, ismath=False)
        finally:
            gc.restore()

    def draw(self, renderer: RendererBase) -> None:
        if not self.get_visible():
            return
        texts = [i for i in self.items if isinstance(i, _Text) and i.text]
        if self.core:
            core = [t for t in texts if not t.formula and core_encodable(t.text)]
            embedded = [t for t in texts if t.formula or not core_encodable(t.text)]
            if core:
                with _rc("pdf.use14corefonts", True):
                    self._draw_items(renderer, core, core=True)
            if embedded:
                with _rc("pdf.use14corefonts", False):
                    self._draw_items(renderer, embedded, core=False)
        else:
            self._draw_items(renderer, texts, core=False)
        inch = cast(float, renderer.points_to_pixels(72.0))  # a float, the stubs say ArrayLike
        gc = renderer.new_gc()
        try:
            gc.set_foreground("0.35")
            for rule in (i for i in self.items if isinstance(i, _Rule)):
                gc.set_linewidth(rule.width_pt)
                y = (self.height_in - rule.y_in) * inch
                path = MplPath([[rule.x0_in * inch, y], [rule.x1_in * inch, y]])
                renderer.draw_path(gc, path, IdentityTransform())
        finally:
            gc.restore()
        self.stale = False


@functools.cache
def _embedded_prop(size: float, weight: str, mono: bool) -> FontProperties:
    """The font of a string drawn in the embedded font: DejaVu Sans (Mono)."""
    family = "DejaVu Sans Mono" if mono else "DejaVu Sans"
    return FontProperties(family=family, weight=weight, size=size)


def footer_items(left: str, page: int, total: int, size_in: tuple[float, float]) -> list[_Text]:
    """The footer of a page: ``left`` (what the document is) and ``page n of N``."""
    width, height = size_in
    y = height - FOOTER_BASE_IN
    size, colour = 7.5, "0.4"
    label = f"page {page} of {total}"
    room = width - 2 * MARGIN - string_width_in(label, size) - 0.3
    text = wrap(left, room, size)[0]
    if text != one_line(left):
        text = text.rstrip() + " …"
    return [
        _Text(MARGIN, y, text, size=size, colour=colour),
        _Text(width - MARGIN, y, label, size=size, colour=colour, ha="right"),
    ]


def add_footer(fig: Figure, left: str, page: int, total: int, caption: str | None = None) -> Artist:
    """Add the footer of a PDF page (``left``, ``page n of N``), and on a figure page its
    ``caption``, to ``fig``; return the artist (remove it to reuse the figure)."""
    size = tuple(fig.get_size_inches())
    items = footer_items(left, page, total, size)
    if caption:
        width, height = size
        for k, part in enumerate(reversed(wrap(caption, width - 2 * MARGIN, 8.0)[:2])):
            items.append(_Text(MARGIN, height - CAPTION_BASE_IN - k * 0.16, part, 8.0, "normal"))
    block = TextBlock(items, size[1])
    fig.add_artist(block)
    return block


#: the band at the bottom of a figure page kept for its caption and footer (inches)
CAPTION_BAND_IN = 0.8


def _squeeze(fig: Figure, f: float) -> None:
    """Map the figure's content (its axes and figure texts) from [0, 1] to [f, 1] in
    height: the band below is left free."""
    for ax in fig.axes:
        box = ax.get_position(original=True)
        ax.set_position((box.x0, f + box.y0 * (1 - f), box.width, box.height * (1 - f)))
    for text in fig.texts:
        if text.get_transform() == fig.transFigure:
            x, y = text.get_position()
            text.set_position((x, f + y * (1 - f)))


def _suptitle_at(fig: Figure, top: float) -> None:
    """Put the figure's title (placed in figure units, not in the layout's rect), when it
    has one aligned at its top, at ``top``: given again with its place, its font and its
    colour, so that the layout engine leaves it there (as for any title given a place)."""
    text = fig.get_suptitle()
    if not text:
        return
    title = next((t for t in fig.texts if t.get_text() == text), None)
    if title is None or title.get_verticalalignment() != "top":
        return
    fig.suptitle(
        text,
        x=title.get_position()[0],
        y=top,
        ha=title.get_horizontalalignment(),
        va="top",
        fontproperties=title.get_fontproperties(),
        color=title.get_color(),
    )


def fit_page(fig: Figure) -> None:
    """Make a figure a page with a free band at the bottom for its caption and footer
    (:data:`CAPTION_BAND_IN`): a figure of about the proportions of A4 is set to A4
    (landscape or portrait) and its content drawn above the band; any other keeps its
    size and grows by the band, its content unchanged above it. A figure laid out by a
    layout engine is laid out again above the band."""
    width, height = (float(v) for v in fig.get_size_inches())
    size = PAGE_PORTRAIT_IN if height > width else PAGE_LANDSCAPE_IN
    a4 = abs((width / height) / (size[0] / size[1]) - 1.0) < 0.12
    engine = fig.get_layout_engine()
    if a4:
        fig.set_size_inches(*size)
        new_height = size[1]
        f = CAPTION_BAND_IN / new_height
    else:
        new_height = height + CAPTION_BAND_IN
        fig.set_size_inches(width, new_height)
        f = CAPTION_BAND_IN / new_height
    if engine is not None:
        from matplotlib.layout_engine import ConstrainedLayoutEngine, TightLayoutEngine

        # a quarter inch of white at the top and the sides: a figure laid out tight to its
        # edges (right for its PNG) would touch the edges of its page
        width_in = float(fig.get_size_inches()[0])
        side, top = 0.25 / width_in, 1.0 - 0.25 / new_height
        if isinstance(engine, ConstrainedLayoutEngine):
            engine.set(rect=(side, f, 1.0 - 2 * side, top - f))
        elif isinstance(engine, TightLayoutEngine):
            engine.set(rect=(side, f, 1.0 - side, top))
        _suptitle_at(fig, top)
        # laid out once here, on the figure's own canvas, and then left as it is: the PDF
        # page draws these positions (laid out again while the page is written, they could
        # differ in their last digits from one report to the next in one process)
        engine.execute(fig)
        fig.set_layout_engine("none")
        for ax in fig.axes:
            # the solver's positions rounded to a millionth of the page (well below a
            # printed dot): the last digits it leaves can differ from one report to the
            # next in one process, and the page's bytes with them
            box = ax.get_position(original=True)
            x0, y0, w, h = (round(float(v), 6) for v in box.bounds)
            ax.set_position((x0, y0, w, h))
        return
    _squeeze(fig, f)


def render_text(page: TextPage) -> Figure:
    """A matplotlib figure of one text page."""
    fig = Figure(figsize=page.size_in, dpi=72)
    FigureCanvasAgg(fig)
    fig.add_artist(TextBlock(page.items, page.size_in[1]))
    return fig


#: the settings every PDF page is drawn with: Helvetica, a core font, for the text its
#: encoding holds (figures too), and "-" for minus signs (the core fonts have no U+2212)
_PDF_RC: dict[RcKeyType, Any] = {"pdf.use14corefonts": True, "axes.unicode_minus": False}


def page_figure_texts(fig: Figure) -> list[Text]:
    """The texts of a figure that may hold words (titles, labels, legends, notes, the
    labels of categorical ticks); numeric tick labels are left out (always encodable)."""
    texts = figure_texts(fig)
    for ax in fig.axes:
        for axis in (ax.xaxis, ax.yaxis):
            if isinstance(axis.get_major_formatter(), FixedFormatter):
                texts += axis.get_ticklabels()
    return texts


def _needs_embedded(text: Text) -> bool:
    """True for a text the PDF page draws in the embedded font: monospace (Courier, the
    core font of monospace text, spaces its lines more tightly than the figure was laid
    out for) or beyond the core fonts' encoding."""
    mono = any("mono" in f.lower() for f in text.get_fontfamily())
    return mono or not core_encodable(text.get_text())


def core_fonts_hold(fig: Figure) -> bool:
    """True when every text of ``fig`` that may hold words (:func:`page_figure_texts`) can
    be drawn in the core fonts: the page is then drawn in Helvetica; else the whole figure
    is drawn in its embedded font (DejaVu Sans), as on screen."""
    return not any(_needs_embedded(t) for t in page_figure_texts(fig) if t.get_text())


def save_page(pdf: PdfPages, fig: Figure) -> None:
    """Save ``fig`` as a page: in Helvetica (quick to write, and the font of the text
    pages) when the core fonts' encoding holds all its words (:func:`core_fonts_hold`),
    else in the embedded DejaVu Sans; every text is measured in the font it is drawn in.
    The strings of a text page, a caption and a footer (:class:`TextBlock`) choose their
    font one by one: the core fonts where they can, as they were wrapped by their widths."""
    log = logging.getLogger("matplotlib.font_manager")
    level = log.level
    # Helvetica's regular face is "Medium" in its metrics: matplotlib would say so once
    log.setLevel(logging.ERROR)
    settings = dict(_PDF_RC)
    if not core_fonts_hold(fig):
        settings["pdf.use14corefonts"] = False
    blocks = [a for a in fig.artists if isinstance(a, TextBlock)]
    for block in blocks:
        block.core = True
    try:
        with _rc_all(settings), quiet_glyphs():
            pdf.savefig(fig)
    finally:
        log.setLevel(level)
        for block in blocks:
            block.core = False


def metadata(title: str, subject: str | None = None) -> dict[str, Any]:
    """The document information of a PDF: fixed text, no creation date."""
    meta: dict[str, Any] = {"Title": one_line(title)}
    if subject:
        meta["Subject"] = one_line(subject)
    meta.update(
        {"Creator": f"esp {__version__}", "Producer": f"esp {__version__}", "CreationDate": None}
    )
    return meta


def write_document(
    path: str | os.PathLike[str],
    pages: Sequence[TextPage],
    *,
    footer: str,
    meta: Mapping[str, Any],
    figures: Iterable[Figure] = (),
    captions: Sequence[str] = (),
    provenance: Provenance | None = None,
) -> int:
    """Write a document to ``path`` (atomically) and return its number of pages: the text
    ``pages``, then ``figures`` (one per caption in ``captions``, at their own size, each
    captioned ``Figure k: caption``; they may be produced lazily), then the provenance
    pages when ``provenance`` is given. Every page gets the footer ``footer`` and
    ``page n of N``, N counting every page."""
    from matplotlib.backends.backend_pdf import PdfPages

    source_date_epoch()  # the PDF writer reads it too: refuse a malformed one first
    tail = provenance_pages(provenance) if provenance is not None else []
    total = len(pages) + len(captions) + len(tail)
    count = 0
    with (
        _older_objects_left_out(),
        atomic_path(Path(path)) as tmp,
        PdfPages(tmp, metadata=dict(meta)) as pdf,
    ):
        for page in pages:
            count += 1
            fig = render_text(page)
            add_footer(fig, footer, count, total)
            save_page(pdf, fig)
        shown = 0
        for fig in figures:
            count += 1
            if shown >= len(captions):
                raise ValueError(f"{len(captions)} figure titles but more figures")
            caption = f"Figure {shown + 1}: {captions[shown]}"
            shown += 1
            artist = add_footer(fig, footer, count, total, caption)
            try:
                save_page(pdf, fig)
            finally:
                artist.remove()
        if shown != len(captions):
            raise ValueError(f"{len(captions)} figure titles but {shown} figures")
        for page in tail:
            count += 1
            fig = render_text(page)
            add_footer(fig, footer, count, total)
            save_page(pdf, fig)
    return count


@contextmanager
def _older_objects_left_out() -> Iterator[None]:
    """While a document is written, the objects that exist before it (the modules of
    numpy and matplotlib, the analysis) are left out of the garbage collector's passes
    (``gc.freeze``), and handed back to it afterwards (``gc.unfreeze``), error or not.
    The objects the document makes are collected as usual. A full pass over the older
    ones came once or twice in every report, some 60 ms each; a batch's collection between
    machines still sees every object. Objects another caller has frozen stay as they are
    (nothing is frozen or handed back then)."""
    import gc

    if gc.get_freeze_count():
        yield
        return
    gc.freeze()
    try:
        yield
    finally:
        gc.unfreeze()


class Document:
    """One document: its title block, then what the caller lays out on :attr:`lay`
    (:meth:`Layout.heading`, :meth:`Layout.table`, ... and :meth:`section`), then its
    figures (:meth:`figure`), then the provenance; :meth:`write` writes it.

    Parameters
    ----------
    title : what the document is ("ISO 230-2 positioning test report")
    name : the machine's (or the object's) name
    date : the report date (:func:`esp.report.epoch.report_date`)
    fields : the title block's (label, value) fields (:func:`title_fields`)
    note : a grey line under the title block (the input file, the esp version)
    """

    def __init__(
        self,
        title: str,
        name: str,
        date: str,
        fields: Sequence[tuple[str, str]] = (),
        note: str | None = None,
    ) -> None:
        self.title, self.name, self.date = title, one_line(name), date
        self.lay = Layout()
        self._figures: list[tuple[str, Callable[[], Figure] | Figure]] = []
        base = f"Report date {date} · esp {__version__}"
        title_block(self.lay, title, name, fields, f"{base} · {note}" if note else base)

    def section(self, title: str) -> None:
        """A new section: on a new page when more than 70 % of this one is used."""
        self.lay.section_break()
        self.lay.heading(title)

    def figure(self, fig: Figure | Callable[[], Figure], caption: str) -> None:
        """Add a figure (or a function that builds it) after the text, with its caption."""
        self._figures.append((caption, fig))

    @property
    def footer(self) -> str:
        return f"{self.name} · {self.title.lower()} · {self.date}"

    def write(
        self,
        path: str | os.PathLike[str],
        provenance: Provenance | None = None,
        subject: str | None = None,
    ) -> int:
        """Write the PDF to ``path`` (atomically); return its number of pages."""

        def figures() -> Iterable[Figure]:
            for _, fig in self._figures:
                page = fig() if callable(fig) and not isinstance(fig, Figure) else fig
                fit_page(page)  # its PNG, if any, is written already
                yield page

        return write_document(
            path,
            self.lay.pages,
            footer=self.footer,
            meta=metadata(f"{self.title}: {self.name}", subject),
            figures=figures(),
            captions=[c for c, _ in self._figures],
            provenance=provenance,
        )
