"""The PDF report of an analysis: what a calibration engineer hands to a customer.

Pages, in order (A4 portrait for text, A4 landscape for figures):

1. summary: the machine, the dates, the configuration in words, how it was evaluated,
   and the headline figures (volumetric accuracy and where, planar accuracies, the range
   of each direction, the uncertainty when there is one);
   followed by the contents (every section and figure with its page);
2. inputs: the active components with their sources, squareness, axes with offsets and
   simulation set-up, analysis settings, tool, warnings, the sweep, the uncertainty budget;
3. per tool case and direction, the extremes with the breakdown of every term there,
   then the volumetric and planar points (the layout of the original reports, Longstaff
   2002, 4.03-4.04 and appendices B-C as summarised in the design notes);
4. the figures, one per page.

The text pages are laid out here (:func:`text_pages`) as positioned strings, so tests can
read what a page says without parsing PDF; their tables are those of the terminal report
(:mod:`esp.report.tables`). They are drawn in Helvetica, one of the fonts every PDF reader
has (not embedded, so quick to write and small); a string that Helvetica's encoding cannot
hold, and every formula (the term symbols with Φ and γ), is drawn in the embedded DejaVu
Sans of the figures. All user text is drawn literally (never as mathtext) and on one line.

The file is written with fixed metadata and no creation date: the same result, date and
figures give the same bytes. The printed date follows ``SOURCE_DATE_EPOCH`` when it is set
(:func:`report_date`).
"""

from __future__ import annotations

import datetime as _dt
import logging
import textwrap
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path, PurePath
from typing import TYPE_CHECKING, Any

import matplotlib as mpl
from matplotlib.artist import Artist
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.font_manager import FontProperties
from matplotlib.path import Path as MplPath
from matplotlib.ticker import FixedFormatter
from matplotlib.transforms import IdentityTransform

from esp._version import __version__
from esp.core.machine import AXIS_NAMES
from esp.core.results import AnalysisResult, Breakdown, CaseResult
from esp.io.atomic import atomic_path
from esp.report import tables
from esp.report.drawing import figure_texts, quiet_glyphs
from esp.report.epoch import SOURCE_DATE_EPOCH_MAX, source_date_epoch
from esp.report.tables import Column, Table
from esp.report.words import (
    UM,
    at_text,
    budget_point_words,
    datum_words,
    grid_words,
    is_plan,
    montecarlo_grid_words,
    num,
    one_line,
    runs_words,
    setup_words,
    swept_words,
    tool_short,
    tool_words,
    uncertainty_headline,
)

if TYPE_CHECKING:
    from matplotlib.backends.backend_pdf import PdfPages
    from matplotlib.typing import RcKeyType

__all__ = [
    "PAGE_LANDSCAPE_IN",
    "PAGE_PORTRAIT_IN",
    "SOURCE_DATE_EPOCH_MAX",
    "TextPage",
    "add_footer",
    "pdf_metadata",
    "report_date",
    "source_date_epoch",
    "text_pages",
    "write_pdf",
]

#: A4 in inches
PAGE_PORTRAIT_IN = (8.27, 11.69)
PAGE_LANDSCAPE_IN = (11.69, 8.27)
_MARGIN = 0.75
_FOOTER = 0.45
#: the baseline of the footer, from the bottom of the page (inches)
FOOTER_BASE_IN = 0.32
_LEADING = 1.45
#: average advance of a character, as a fraction of the font size (wrapping, fitting)
_CHAR_EM = 0.53
_BODY = 9.5
_SMALL = 8.3


# -- the date ---------------------------------------------------------------------------------


def report_date(environ: Mapping[str, str] | None = None) -> str:
    """The date printed on a report, ISO ``YYYY-MM-DD``: from ``SOURCE_DATE_EPOCH`` (UTC)
    when set, so builds can be reproduced; else today. A malformed value is refused
    (:func:`source_date_epoch`)."""
    epoch = source_date_epoch(environ)
    if epoch is None:
        return _dt.date.today().isoformat()
    return _dt.datetime.fromtimestamp(epoch, tz=_dt.UTC).date().isoformat()


def _report_title(result: AnalysisResult) -> str:
    """What the report is: of the volumetric accuracy, or, for an uncertainty plan (no
    error data), of the volumetric uncertainty."""
    return "Volumetric uncertainty plan" if is_plan(result) else "Volumetric accuracy report"


def pdf_metadata(result: AnalysisResult) -> dict:
    """The document information of the PDF: fixed text, no creation date."""
    return {
        "Title": f"{_report_title(result)}: {one_line(result.machine.name)}",
        "Subject": f"{result.machine.configuration}, case {result.case}",
        "Creator": f"esp {__version__}",
        "Producer": f"esp {__version__}",
        "CreationDate": None,
    }


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


@dataclass(frozen=True)
class _Rule:
    x0_in: float
    x1_in: float
    y_in: float
    width_pt: float = 0.6


@dataclass
class TextPage:
    """One text page: strings and rules at positions in inches from the top left."""

    items: list = field(default_factory=list)

    def texts(self) -> list[str]:
        """Every string on the page, in the order laid out."""
        return [i.text for i in self.items if isinstance(i, _Text)]


def _chars(width_in: float, size: float) -> int:
    return max(4, int(width_in * 72.0 / (size * _CHAR_EM)))


def _fit(text: str, width_in: float, size: float) -> str:
    limit = _chars(width_in, size) - 1
    return text if len(text) <= limit else text[: max(1, limit - 1)] + "…"


class _Layout:
    """Places lines of text top to bottom, starting a new page when one is full. Every
    string is put on one line (:func:`~esp.report.words.one_line`) first."""

    def __init__(self) -> None:
        self.width, self.height = PAGE_PORTRAIT_IN
        self.left, self.right = _MARGIN, self.width - _MARGIN
        self.pages: list[TextPage] = []
        self.new_page()

    @property
    def text_width(self) -> float:
        return self.right - self.left

    def new_page(self) -> None:
        self.page = TextPage()
        self.pages.append(self.page)
        self.y = _MARGIN

    def ensure(self, height_in: float) -> None:
        if self.y + height_in > self.height - _MARGIN - _FOOTER and self.y > _MARGIN:
            self.new_page()

    def space(self, height_in: float) -> None:
        if self.y > _MARGIN:
            self.y += height_in

    def line(self, text: str, size: float = _BODY, weight="normal", colour="black") -> None:
        height = size * _LEADING / 72.0
        self.ensure(height)
        self.page.items.append(
            _Text(self.left, self.y + size / 72.0, one_line(text), size, weight, colour)
        )
        self.y += height

    def paragraph(self, text: str, size: float = _BODY, indent_in: float = 0.0, **kw) -> None:
        width = _chars(self.text_width - indent_in, size)
        for part in textwrap.wrap(one_line(text), width) or [""]:
            height = size * _LEADING / 72.0
            self.ensure(height)
            x = self.left + indent_in
            self.page.items.append(_Text(x, self.y + size / 72.0, part, size, **kw))
            self.y += height

    def heading(self, text: str, level: int = 1) -> None:
        size = {0: 20.0, 1: 13.0, 2: 10.5}[level]
        self.space({0: 0.0, 1: 0.22, 2: 0.12}[level])
        self.ensure(size * _LEADING / 72.0 + 4 * _BODY * _LEADING / 72.0)
        self.line(text, size=size, weight="bold")
        if level == 1:
            self.page.items.append(_Rule(self.left, self.right, self.y - 0.06, 0.8))
            self.y += 0.06

    def pairs(self, rows: Sequence[tuple[str, str]], key_in: float = 1.55) -> None:
        """Key and value side by side, the value wrapped in its column."""
        width = _chars(self.text_width - key_in, _BODY)
        for key, value in rows:
            lines = textwrap.wrap(one_line(value), width) or [""]
            for k, part in enumerate(lines):
                height = _BODY * _LEADING / 72.0
                self.ensure(height)
                base = self.y + _BODY / 72.0
                if k == 0:
                    self.page.items.append(_Text(self.left, base, key, _BODY, "bold", "0.25"))
                self.page.items.append(_Text(self.left + key_in, base, part, _BODY))
                self.y += height

    def table(self, table: Table, size=_SMALL) -> None:
        """A table with a bold header and a rule under it, repeated on each new page."""
        height = size * _LEADING / 72.0
        columns = table.columns

        def header() -> None:
            self.ensure(3 * height)
            self._row(table.headers, columns, size, "bold", header=True)
            self.page.items.append(
                _Rule(self.left, self.left + sum(c.width_in for c in columns), self.y - 0.04, 0.5)
            )
            self.y += 0.03

        header()
        for row in table.rows:
            if self.y + height > self.height - _MARGIN - _FOOTER:
                self.new_page()
                header()
            self._row(row, columns, size, "normal")

    def _row(self, cells, columns: Sequence[Column], size, weight, header=False) -> None:
        x = self.left
        base = self.y + size / 72.0
        for cell, col in zip(cells, columns, strict=True):
            text = _fit(one_line(cell), col.width_in, size)
            formula = col.formula and not header
            if col.align == "right":
                self.page.items.append(
                    _Text(x + col.width_in - 0.08, base, text, size, weight, ha="right")
                )
            else:
                self.page.items.append(_Text(x, base, text, size, weight, formula=formula))
            x += col.width_in
        self.y += size * _LEADING / 72.0


# -- content ------------------------------------------------------------------------------------


def _summary(lay: _Layout, result: AnalysisResult, date: str) -> None:
    m, a = result.machine, result.machine.analysis
    plan = is_plan(result)
    lay.heading(_report_title(result), level=0)
    lay.line(m.name, size=15.0, weight="bold")
    info = [
        f"{label} {one_line(m.info[key])}"
        for key, label in (
            ("serial", "Serial"),
            ("location", "Location"),
            ("measured_by", "Measured by"),
            ("date", "Measured on"),
        )
        if key in m.info
    ]
    if info:
        lay.paragraph(" · ".join(info))
    source = PurePath(m.source).name if m.source else "in code"
    lay.paragraph(f"Report date {date} · esp {__version__} · machine file {source}", colour="0.3")
    roles = ", ".join(f"{r} axis {m.roles[r]}" for r in ("bottom", "middle", "top"))
    lay.heading("Machine and evaluation")
    lay.pairs(
        [
            ("Configuration", f"{m.configuration} ({m.notation}): {m.description}; {roles}."),
            ("Evaluation", f"case {result.case}, {result.case_description} ({result.equations})"),
            (
                "Data used",
                f"{runs_words(a.direction)} of each file; "
                f"straightness slope removed by a {a.straightness_fit} line"
                + ("; end values held beyond the measured range" if a.extrapolate else ""),
            ),
            ("Datum", datum_words(result)),
            ("Volume", grid_words(result)),
        ]
    )
    worst = result.cases[result.worst]
    unc = result.uncertainty
    lay.heading("Headline figures")
    if plan and unc is not None:
        lay.line(f"Volumetric uncertainty  {uncertainty_headline(unc)}", size=14.0, weight="bold")
        where = f"largest at {at_text(unc.volumetric.at)} mm"
        if unc.budget_tool is not None and unc.budget_tool.length_mm is not None:
            where += f"; tool {tool_words(unc.budget_tool)}"
        lay.paragraph(where)
        lay.paragraph(
            "An uncertainty plan: no error data is given, so no volumetric accuracy is "
            "evaluated. The figures are the uncertainty that the planned measurements, with "
            "the components' U below, give the volumetric accuracy."
        )
    else:
        lay.line(
            f"Volumetric accuracy  {num(worst.volumetric.value_um)} {UM}",
            size=14.0,
            weight="bold",
        )
        where = f"at {at_text(worst.volumetric.at)} mm"
        if len(result.cases) > 1 or worst.tool.length_mm is not None:
            where += f"; tool {tool_words(worst.tool)}"
        lay.paragraph(where)
        lay.space(0.08)
        lay.table(tables.headline_table(worst))
        lay.space(0.12)
        lay.table(tables.direction_extremes_table(worst))
        if len(result.cases) > 1:
            lay.heading("Per tool length", level=2)
            lay.table(tables.tool_cases_table(result))
    lay.heading("Uncertainty", level=2)
    if unc is None:
        lay.paragraph("Not evaluated for this report.")
    else:
        bound = (
            " It is an upper bound: no choice of signs of the components' errors within "
            "their U gives a larger error."
            if unc.method == "summation"
            else ""
        )
        lay.paragraph(
            f"Volumetric uncertainty {uncertainty_headline(unc)}, largest at "
            f"{at_text(unc.volumetric.at)} mm. Per direction: "
            + ", ".join(f"{d} {num(e.value_um)} {UM}" for d, e in unc.axes.items())
            + "."
            + bound
        )
        mc = unc.montecarlo
        if mc is not None:
            lo, hi = mc.interval_um
            lay.paragraph(
                f"Monte Carlo ({mc.samples} draws, seed {mc.seed}{montecarlo_grid_words(mc)}): "
                f"volumetric accuracy mean "
                f"{num(mc.mean_um)} {UM}, standard deviation {num(mc.std_um)} {UM}, coverage "
                f"interval {num(lo)} to {num(hi)} {UM}."
            )
        if unc.prior is not None:
            p = unc.prior
            lay.paragraph(
                f"With the prior estimate {p['prior_um']:g} ± {p['prior_u_um']:g} {UM} from "
                f"comparable machines (Bayesian update, Longstaff 2002 eq. 3.22-3.24): "
                f"volumetric accuracy {num(p['accuracy_um'])} {UM}, U = {num(p['U_um'])} {UM}."
            )
    if result.warnings:
        lay.space(0.1)
        lay.paragraph(
            f"{len(result.warnings)} warning(s) were raised; they are listed with the inputs.",
            colour="C3",
        )


def _contents(lay: _Layout, entries: Sequence[tuple[int, str]]) -> None:
    lay.heading("Contents", level=2)
    lay.table(
        Table(
            (Column("page", "right", 0.6), Column("   section or figure", "left", 6.1)),
            tuple((str(page), "   " + title) for page, title in entries),
        )
    )


def _inputs(lay: _Layout, result: AnalysisResult) -> None:
    m, a = result.machine, result.machine.analysis
    lay.new_page()
    lay.heading("Inputs")
    lay.heading("Active error components", level=2)
    table = tables.active_components_table(result)
    if table.rows:
        lay.table(table)
    elif is_plan(result):
        lay.paragraph("None: no error data (an uncertainty plan; its U are in the budget).")
    else:
        lay.paragraph("None: every component is zero.")
    inactive = [str(n) for n in result.inactive if n.kind != "squareness"]
    if inactive:
        lay.space(0.06)
        lay.paragraph("Not given (zero): " + ", ".join(inactive), size=_SMALL)
    if result.ignored:
        lay.paragraph(
            f"Given but not used by case {result.case}: " + ", ".join(map(str, result.ignored)),
            size=_SMALL,
        )
    lay.heading("Squareness", level=2)
    lay.table(tables.squareness_table(result))
    lay.heading("Axes and simulation", level=2)
    lay.table(tables.axes_table(result))
    lay.space(0.04)
    lay.paragraph(
        "The offset of an axis is the position at which the other axes' errors were "
        "measured; angular and squareness errors are levered from there.",
        size=_SMALL,
        colour="0.3",
    )
    lay.heading("Analysis settings", level=2)
    datum = a.datum if isinstance(a.datum, str) else at_text(a.datum)
    lay.pairs(
        [
            ("Point", f"{a.point} (compensation: {a.compensation})"),
            ("Runs used", a.direction),
            ("Datum", datum),
            ("Straightness fit", a.straightness_fit),
            ("Extrapolate", "yes" if a.extrapolate else "no"),
        ]
    )
    lay.heading("Tool", level=2)
    tool = m.tool
    if m.head is not None or m.table is not None:
        for line in setup_words(m):
            lay.paragraph(line + ".")
        if m.head is not None:
            lay.paragraph("The head carries the tool: each setting gives the tool offset.")
    if m.head is not None:
        pass
    elif a.point == "MCP" or tool is None:
        lay.paragraph(
            "None: the errors are evaluated at the measurement centre point (MCP)."
            + (" A [tool] table is given but not used at the MCP." if tool else "")
        )
    elif tool.offsets_mm:
        lay.paragraph(
            "Offsets (mm): "
            + "; ".join(", ".join(f"{k}={v:g}" for k, v in o.items()) for o in tool.offsets_mm)
        )
    else:
        kind = "every orientation swept, the worst reported per length" if tool.sweep else ""
        lay.paragraph(
            "Lengths " + ", ".join(f"{v:g}" for v in tool.lengths_mm) + " mm; orientations "
            "(tilt, spin in degrees) "
            + ", ".join(f"({t:g}, {s:g})" for t, s in tool.orientations_deg)
            + (f"; {kind}" if kind else "")
            + "."
        )
    if result.warnings:
        lay.heading("Warnings", level=2)
        for w in result.warnings:
            lay.paragraph("• " + w, size=_SMALL)
    if result.sweep and not is_plan(result):
        lay.heading(swept_words(result).capitalize(), level=2)
        lay.table(tables.sweep_table(result))
    unc = result.uncertainty
    if unc is not None and unc.budget:
        lay.heading("Uncertainty budget", level=2)
        lay.paragraph(f"Evaluated {budget_point_words(unc)}.", size=_SMALL, colour="0.3")
        lay.table(tables.budget_table(unc, result.machine))


def _breakdown(lay: _Layout, b: Breakdown, title: str, directions=AXIS_NAMES) -> None:
    lay.heading(title, level=2)
    errors = ", ".join(f"{d} {num(b.errors_um[d])}" for d in AXIS_NAMES)
    lay.paragraph(
        f"at {at_text(b.at)} mm: errors {errors} {UM}; volumetric {num(b.volumetric_um)} {UM}",
        size=_SMALL,
        colour="0.3",
    )
    table = tables.breakdown_table(b, directions)
    if table.rows:
        lay.table(table)
    else:
        lay.paragraph("No active term acts in this direction.", size=_SMALL)


def _case(lay: _Layout, result: AnalysisResult, n: int, case: CaseResult) -> None:
    lay.new_page()
    title = "Extremes and their terms"
    if len(result.cases) > 1:
        title += f": tool case {n + 1} of {len(result.cases)}"
    lay.heading(title)
    if case.tool.length_mm is not None:
        lay.paragraph(f"Tool {tool_words(case.tool)}.")
    by_label = {b.label: b for b in case.breakdowns}
    for d, e in case.axes.items():
        lay.heading(
            f"{d} direction: minimum {num(e.minimum.value_um)} {UM}, maximum "
            f"{num(e.maximum.value_um)} {UM}, range {num(e.range_um)} {UM}",
            level=2,
        )
        for which in ("min", "max"):
            b = by_label.get(f"{d} {which}")
            if b is not None:
                word = "minimum" if which == "min" else "maximum"
                _breakdown(lay, b, f"   {d} {word}", directions=(d,))
    b = by_label.get("volumetric")
    if b is not None:
        _breakdown(lay, b, f"Volumetric accuracy {num(case.volumetric.value_um)} {UM}")
    for plane, extreme in case.planar.items():
        b = by_label.get(f"planar {plane}")
        if b is not None:
            _breakdown(
                lay,
                b,
                f"Planar accuracy {plane}: {num(extreme.value_um)} {UM}",
                directions=tuple(plane),
            )


def text_pages(
    result: AnalysisResult, date: str, figure_titles: Sequence[str] = ()
) -> list[TextPage]:
    """The text pages of the report: summary with the contents, inputs, then the extremes
    and breakdowns of every tool case. The contents list each section and each of
    ``figure_titles`` with its page (the figures follow the text pages, one per page)."""

    def lay_out(contents: Sequence[tuple[int, str]]) -> tuple[list[TextPage], list]:
        lay = _Layout()
        _summary(lay, result, date)
        _contents(lay, contents)
        sections = []
        sections.append((len(lay.pages) + 1, "Inputs"))  # each section opens a new page
        _inputs(lay, result)
        # an uncertainty plan has no errors: no pages of zero extremes
        for n, case in enumerate(() if is_plan(result) else result.cases):
            title = "Extremes and their terms"
            if len(result.cases) > 1:
                title += f", tool case {n + 1}: {tool_short(case.tool)}"
            sections.append((len(lay.pages) + 1, title))
            _case(lay, result, n, case)
        return lay.pages, sections

    # twice: the first pass finds the page of every section and figure (the contents
    # only list them, so they take the same room whatever the numbers)
    placeholder = (
        [(0, "Inputs")]
        + [(0, "")] * (0 if is_plan(result) else len(result.cases))
        + [(0, t) for t in figure_titles]
    )
    pages, sections = lay_out(placeholder)
    first = len(pages) + 1
    contents = sections + [(first + k, f"Figure: {t}") for k, t in enumerate(figure_titles)]
    pages, _ = lay_out(contents)
    return pages


# -- rendering -----------------------------------------------------------------------------

_CORE_FAMILY = "Helvetica"
_CORE_WEIGHTS = {"normal": "medium", "bold": "bold"}  # the weights of Helvetica's AFM files


def _core_encodable(text: str) -> bool:
    """True when the PDF core fonts (WinAnsi, cp1252) can show ``text``."""
    try:
        text.encode("cp1252")
    except UnicodeEncodeError:
        return False
    return True


class TextBlock(Artist):
    """Strings at fixed positions (inches from the top left of the figure), drawn straight
    through the renderer without text layout: left- or right-aligned on their baseline,
    always literally (never mathtext).

    On a PDF page a string goes in Helvetica, a core font of every PDF reader, when its
    encoding can hold it and it is not a formula; every other string is drawn in the
    figure's embedded font (DejaVu Sans). Other renderers draw every string in DejaVu
    Sans.
    """

    def __init__(self, items: Sequence, height_in: float):
        super().__init__()
        self.items = list(items)
        self.height_in = height_in
        self._props: dict[tuple, FontProperties] = {}

    def _prop(self, size: float, weight: str, core: bool) -> FontProperties:
        key = (size, weight, core)
        if key not in self._props:
            if core:
                prop = FontProperties(
                    family=_CORE_FAMILY, weight=_CORE_WEIGHTS.get(weight, "medium"), size=size
                )
            else:
                prop = FontProperties(weight=weight, size=size)
            self._props[key] = prop
        return self._props[key]

    def _draw_items(self, renderer, items, core: bool) -> None:
        inch = renderer.points_to_pixels(72.0)
        gc = renderer.new_gc()
        try:
            for item in items:
                if isinstance(item, _Rule):
                    continue
                prop = self._prop(item.size, item.weight, core)
                gc.set_foreground(item.colour)
                x = item.x_in * inch
                y = (self.height_in - item.y_in) * inch
                if item.ha == "right":
                    width, _, _ = renderer.get_text_width_height_descent(
                        item.text, prop, ismath=False
                    )
                    x -= width
                renderer.draw_text(gc, x, y, item.text, prop, 0.0, ismath=False)
        finally:
            gc.restore()

    def draw(self, renderer) -> None:
        if not self.get_visible():
            return
        texts = [i for i in self.items if isinstance(i, _Text) and i.text]
        from matplotlib.backends.backend_pdf import RendererPdf  # loaded by then

        if isinstance(getattr(renderer, "_renderer", renderer), RendererPdf):
            core = [t for t in texts if not t.formula and _core_encodable(t.text)]
            embedded = [t for t in texts if t.formula or not _core_encodable(t.text)]
            with mpl.rc_context({"pdf.use14corefonts": True}):
                self._draw_items(renderer, core, core=True)
            with mpl.rc_context({"pdf.use14corefonts": False}):
                self._draw_items(renderer, embedded, core=False)
        else:
            self._draw_items(renderer, texts, core=False)
        inch = renderer.points_to_pixels(72.0)
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


def _footer_items(
    result: AnalysisResult, date: str, page: int, total: int, size_in: tuple[float, float]
) -> list[_Text]:
    width, height = size_in
    y = height - FOOTER_BASE_IN
    size, colour = 7.5, "0.4"
    return [
        _Text(
            _MARGIN,
            y,
            f"{one_line(result.machine.name)} · {_report_title(result).lower()} · {date}",
            size=size,
            colour=colour,
        ),
        _Text(width - _MARGIN, y, f"page {page} of {total}", size=size, colour=colour, ha="right"),
    ]


def add_footer(fig: Figure, result: AnalysisResult, date: str, page: int, total: int) -> Artist:
    """Add the footer of a PDF page (machine, report, date, page number) to ``fig`` and
    return its artist (remove it to reuse the figure without the footer)."""
    size = tuple(fig.get_size_inches())
    block = TextBlock(_footer_items(result, date, page, total, size), size[1])
    fig.add_artist(block)
    return block


def _render_text(page: TextPage) -> Figure:
    fig = Figure(figsize=PAGE_PORTRAIT_IN, dpi=72)
    FigureCanvasAgg(fig)
    fig.add_artist(TextBlock(page.items, PAGE_PORTRAIT_IN[1]))
    return fig


#: the settings every PDF page is drawn with: Helvetica, a core font, for the text its
#: encoding holds (figures too), and "-" for minus signs (the core fonts have no U+2212)
_PDF_RC: dict[RcKeyType, Any] = {"pdf.use14corefonts": True, "axes.unicode_minus": False}


def _figure_texts(fig: Figure) -> list:
    """The texts of a figure that may hold words (titles, labels, legends, notes, the
    labels of categorical ticks); numeric tick labels are left out (always encodable)."""
    texts = figure_texts(fig)
    for ax in fig.axes:
        for axis in (ax.xaxis, ax.yaxis):
            if isinstance(axis.get_major_formatter(), FixedFormatter):
                texts += axis.get_ticklabels()
    return texts


class _Embedded:
    """Draws one text with the embedded font of the figure (its characters are beyond the
    core fonts' encoding): the instance's ``draw`` for the time of one PDF page."""

    def __init__(self, text):
        self.text = text
        self.draw = text.draw

    def __call__(self, renderer):
        with mpl.rc_context({"pdf.use14corefonts": False}):
            self.draw(renderer)


def _save_page(pdf: PdfPages, fig: Figure) -> None:
    """Save ``fig`` as a page, in Helvetica where its encoding holds the text (quick to
    write, and the font of the text pages) and in the embedded DejaVu Sans elsewhere."""
    log = logging.getLogger("matplotlib.font_manager")
    level = log.level
    # Helvetica's regular face is "Medium" in its metrics: matplotlib would say so once
    log.setLevel(logging.ERROR)
    with mpl.rc_context(_PDF_RC), quiet_glyphs():
        wrapped = []
        for text in _figure_texts(fig):
            if not _core_encodable(text.get_text()):
                text.draw = _Embedded(text)
                wrapped.append(text)
        try:
            pdf.savefig(fig)
        finally:
            log.setLevel(level)
            for text in wrapped:
                del text.draw


def write_pdf(
    path: str | Path,
    result: AnalysisResult,
    figures: Iterable[Figure],
    figure_titles: Sequence[str],
    date: str,
) -> int:
    """Write the report to ``path`` (atomically) and return its number of pages.

    ``figures`` (one per title in ``figure_titles``, which the contents list) are placed
    one per page, at their own size (the report's figures are A4 landscape), after the
    text; they may be produced lazily, e.g. by a generator that saves each as PNG first.
    Each gets the footer for its page, removed again after the page is written.
    """
    # the PDF backend (with fontTools, a quarter of a second) loads only here: a report's
    # worker processes, forked before, draw PNGs and never need it
    from matplotlib.backends.backend_pdf import PdfPages

    source_date_epoch()  # the PDF writer reads it too: refuse a malformed one first
    pages = text_pages(result, date, figure_titles)
    total = len(pages) + len(figure_titles)
    count = 0
    with atomic_path(path) as tmp, PdfPages(tmp, metadata=pdf_metadata(result)) as pdf:
        for page in pages:
            count += 1
            fig = _render_text(page)
            add_footer(fig, result, date, count, total)
            _save_page(pdf, fig)
        for fig in figures:
            count += 1
            footer = add_footer(fig, result, date, count, total)
            try:
                _save_page(pdf, fig)
            finally:
                footer.remove()
        if count != total:
            raise ValueError(f"{len(figure_titles)} figure titles but {count - len(pages)} figures")
    return count
