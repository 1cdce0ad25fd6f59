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
read what a page says without parsing PDF. The file is written with fixed metadata and no
creation date: the same result, date and figures give the same bytes.
"""

from __future__ import annotations

import datetime as _dt
import os
import textwrap
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path, PurePath

from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.backends.backend_pdf import PdfPages
from matplotlib.figure import Figure
from matplotlib.lines import Line2D

from esp._version import __version__
from esp.io.atomic import atomic_path
from esp.machine import AXIS_NAMES
from esp.report.profile_text import unit_label
from esp.results import AnalysisResult, Breakdown, CaseResult, ToolCase

__all__ = [
    "PAGE_LANDSCAPE_IN",
    "PAGE_PORTRAIT_IN",
    "TextPage",
    "pdf_metadata",
    "report_date",
    "text_pages",
    "write_pdf",
]

#: A4 in inches
PAGE_PORTRAIT_IN = (8.27, 11.69)
PAGE_LANDSCAPE_IN = (11.69, 8.27)
_MARGIN = 0.75
_FOOTER = 0.45
_LEADING = 1.45
#: average advance of a character of DejaVu Sans, as a fraction of the font size (wrapping)
_CHAR_EM = 0.53
_BODY = 9.5
_SMALL = 8.3
_DIRECTION_WORDS = {
    "mean": "the bidirectional mean of the forward and reverse runs",
    "forward": "the mean of the forward runs",
    "backward": "the mean of the reverse runs",
}


def report_date(environ: Mapping[str, str] | None = None) -> str:
    """The date printed on a report, ISO ``YYYY-MM-DD``: from ``SOURCE_DATE_EPOCH``
    (seconds since 1970, UTC) when set, so builds can be reproduced; else today."""
    env = os.environ if environ is None else environ
    epoch = env.get("SOURCE_DATE_EPOCH", "").strip()
    if epoch:
        try:
            stamp = _dt.datetime.fromtimestamp(int(epoch), tz=_dt.UTC)
        except (ValueError, OverflowError, OSError):
            pass
        else:
            return stamp.date().isoformat()
    return _dt.date.today().isoformat()


def pdf_metadata(result: AnalysisResult) -> dict:
    """The document information of the PDF: fixed text, no creation date."""
    return {
        "Title": f"Volumetric accuracy report: {result.machine.name}",
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


@dataclass(frozen=True)
class _Column:
    header: str
    width_in: float
    align: str = "left"


def _chars(width_in: float, size: float) -> int:
    return max(4, int(width_in * 72.0 / (size * _CHAR_EM)))


def _fit(text: str, width_in: float, size: float) -> str:
    limit = _chars(width_in, size) - 1
    return text if len(text) <= limit else text[: max(1, limit - 1)] + "…"


class _Layout:
    """Places lines of text top to bottom, starting a new page when one is full."""

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
        self.page.items.append(_Text(self.left, self.y + size / 72.0, text, size, weight, colour))
        self.y += height

    def paragraph(self, text: str, size: float = _BODY, indent_in: float = 0.0, **kw) -> None:
        width = _chars(self.text_width - indent_in, size)
        for k, part in enumerate(textwrap.wrap(text, width) or [""]):
            height = size * _LEADING / 72.0
            self.ensure(height)
            x = self.left + indent_in
            self.page.items.append(_Text(x, self.y + size / 72.0, part, size, **kw))
            self.y += height
            del k

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
            lines = textwrap.wrap(value, width) or [""]
            for k, part in enumerate(lines):
                height = _BODY * _LEADING / 72.0
                self.ensure(height)
                base = self.y + _BODY / 72.0
                if k == 0:
                    self.page.items.append(_Text(self.left, base, key, _BODY, "bold", "0.25"))
                self.page.items.append(_Text(self.left + key_in, base, part, _BODY))
                self.y += height

    def table(self, columns: Sequence[_Column], rows: Sequence[Sequence[str]], size=_SMALL):
        """A table with a bold header and a rule under it, repeated on each new page."""
        height = size * _LEADING / 72.0

        def header() -> None:
            self.ensure(3 * height)
            self._row([c.header for c in columns], columns, size, "bold")
            self.page.items.append(
                _Rule(self.left, self.left + sum(c.width_in for c in columns), self.y - 0.04, 0.5)
            )
            self.y += 0.03

        header()
        for row in rows:
            if self.y + height > self.height - _MARGIN - _FOOTER:
                self.new_page()
                header()
            self._row(row, columns, size, "normal")

    def _row(self, cells, columns, size, weight) -> None:
        x = self.left
        base = self.y + size / 72.0
        for cell, col in zip(cells, columns, strict=True):
            text = _fit(str(cell), col.width_in, size)
            if col.align == "right":
                self.page.items.append(
                    _Text(x + col.width_in - 0.08, base, text, size, weight, ha="right")
                )
            else:
                self.page.items.append(_Text(x, base, text, size, weight))
            x += col.width_in
        self.y += size * _LEADING / 72.0


# -- content ------------------------------------------------------------------------------------


def _num(value: float | None, decimals: int = 3) -> str:
    if value is None:
        return ""
    text = f"{value:.{decimals}f}"
    return text[1:] if text.startswith("-") and float(text) == 0 else text


def _at(point: Mapping[str, float]) -> str:
    return ", ".join(f"{a}={point[a]:g}" for a in AXIS_NAMES)


def _xyz(point: Mapping[str, float]) -> str:
    return ", ".join(f"{point[a]:g}" for a in AXIS_NAMES)


def _tool_words(tool: ToolCase) -> str:
    if tool.length_mm is None:
        return "none: evaluated at the measurement centre point (MCP)"
    offset = ", ".join(f"{a}={tool.offset_mm[a]:g}" for a in AXIS_NAMES)
    if tool.tilt_deg is None:
        return f"offset {offset} mm (length {tool.length_mm:g} mm)"
    return (
        f"length {tool.length_mm:g} mm, tilt {tool.tilt_deg:g}°, spin {tool.spin_deg:g}° "
        f"(offset {offset} mm)"
    )


def _tool_short(tool: ToolCase) -> str:
    if tool.length_mm is None:
        return "at the MCP"
    if tool.tilt_deg is None:
        return "offset " + ", ".join(f"{a}={tool.offset_mm[a]:g}" for a in AXIS_NAMES) + " mm"
    return f"length {tool.length_mm:g} mm, tilt {tool.tilt_deg:g}°, spin {tool.spin_deg:g}°"


def _datum_words(result: AnalysisResult) -> str:
    datum = result.machine.analysis.datum
    if result.datum is None:
        return "none: the errors are the raw synthesis"
    name = f' ("{datum}")' if isinstance(datum, str) else ""
    return f"errors are relative to the point {_at(result.datum)} mm{name}"


def _grid_words(result: AnalysisResult) -> str:
    m = result.machine
    volume = "; ".join(
        f"{a} {m.axes[a].simulate_mm[0]:g} to {m.axes[a].simulate_mm[1]:g} mm" for a in AXIS_NAMES
    )
    s = result.grid_sizes
    n = s["X"] * s["Y"] * s["Z"]
    sweep = f" for each of {len(result.sweep)} tool orientations" if result.sweep else ""
    return f"{volume}; grid {s['X']} x {s['Y']} x {s['Z']} = {n} points{sweep}"


def _summary(lay: _Layout, result: AnalysisResult, date: str) -> None:
    m, a = result.machine, result.machine.analysis
    lay.heading("Volumetric accuracy report", level=0)
    lay.line(m.name, size=15.0, weight="bold")
    info = [
        f"{label} {m.info[key]}"
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
                f"{_DIRECTION_WORDS.get(a.direction, a.direction)} of each file; "
                f"straightness slope removed by a {a.straightness_fit} line"
                + ("; end values held beyond the measured range" if a.extrapolate else ""),
            ),
            ("Datum", _datum_words(result)),
            ("Volume", _grid_words(result)),
        ]
    )
    worst = result.cases[result.worst]
    lay.heading("Headline figures")
    lay.line(
        f"Volumetric accuracy  {_num(worst.volumetric.value_um)} µm",
        size=14.0,
        weight="bold",
    )
    where = f"at {_at(worst.volumetric.at)} mm"
    if len(result.cases) > 1 or worst.tool.length_mm is not None:
        where += f"; tool {_tool_words(worst.tool)}"
    lay.paragraph(where)
    lay.space(0.08)
    cols = [
        _Column("quantity", 2.2),
        _Column("value (µm)", 1.1, "right"),
        _Column("where (X, Y, Z in mm)", 3.4),
    ]
    rows = [["volumetric accuracy", _num(worst.volumetric.value_um), _xyz(worst.volumetric.at)]]
    for plane, e in worst.planar.items():
        rows.append([f"planar accuracy {plane}", _num(e.value_um), _xyz(e.at)])
    lay.table(cols, rows)
    lay.space(0.12)
    cols = [
        _Column("direction", 0.8),
        _Column("min (µm)", 0.85, "right"),
        _Column("at (X, Y, Z mm)", 1.7),
        _Column("max (µm)", 0.85, "right"),
        _Column("at (X, Y, Z mm)", 1.7),
        _Column("range (µm)", 0.87, "right"),
    ]
    rows = [
        [
            a_,
            _num(e.minimum.value_um),
            _xyz(e.minimum.at),
            _num(e.maximum.value_um),
            _xyz(e.maximum.at),
            _num(e.range_um),
        ]
        for a_, e in worst.axes.items()
    ]
    lay.table(cols, rows)
    if len(result.cases) > 1:
        lay.heading("Per tool length", level=2)
        cols = [
            _Column("tool", 4.4),
            _Column("volumetric (µm)", 1.2, "right"),
            _Column("at (X, Y, Z mm)", 1.15),
        ]
        lay.table(
            cols,
            [
                [_tool_words(c.tool), _num(c.volumetric.value_um), _xyz(c.volumetric.at)]
                for c in result.cases
            ],
        )
    unc = result.uncertainty
    lay.heading("Uncertainty", level=2)
    if unc is None:
        lay.paragraph("Not evaluated for this report.")
    else:
        lay.paragraph(
            f"Volumetric uncertainty U = {_num(unc.volumetric.value_um)} µm (k = {unc.k:g}, "
            f"{unc.method}), largest at {_at(unc.volumetric.at)} mm. Per direction: "
            + ", ".join(f"{d} {_num(e.value_um)} µm" for d, e in unc.axes.items())
            + "."
        )
        mc = unc.montecarlo
        if mc is not None:
            lo, hi = mc.interval_um
            lay.paragraph(
                f"Monte Carlo ({mc.samples} draws, seed {mc.seed}): volumetric accuracy mean "
                f"{_num(mc.mean_um)} µm, standard deviation {_num(mc.std_um)} µm, coverage "
                f"interval {_num(lo)} to {_num(hi)} µm."
            )
        if unc.prior is not None:
            p = unc.prior
            lay.paragraph(
                f"With the prior estimate {p['prior_um']:g} ± {p['prior_u_um']:g} µm from "
                f"comparable machines (Bayesian update, Longstaff 2002 eq. 3.22-3.24): "
                f"volumetric accuracy {_num(p['accuracy_um'])} µm, U = {_num(p['U_um'])} µm."
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
        [_Column("page", 0.6, "right"), _Column("   section or figure", 6.1)],
        [[str(page), "   " + title] for page, title in entries],
    )


def _inputs(lay: _Layout, result: AnalysisResult) -> None:
    m, a = result.machine, result.machine.analysis
    lay.new_page()
    lay.heading("Inputs")
    lay.heading("Active error components", level=2)
    cols = [
        _Column("ISO 230-1", 0.75),
        _Column("component", 1.45),
        _Column("description", 2.25),
        _Column("source", 1.77),
        _Column("unit", 0.55),
    ]
    rows = []
    for name in sorted(result.active):
        comp = m.components[name]
        if comp.kind == "squareness":
            continue
        rows.append([comp.iso, name, name.description, comp.source, unit_label(comp.unit)])
    if rows:
        lay.table(cols, rows)
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
    rows = []
    for pair in ("XY", "XZ", "YZ"):
        comp = m.components.get(f"squareness.{pair}")
        active = comp is not None and f"squareness.{pair}" in result.active
        value = f"{comp.value:g}" if comp is not None else "0 (not given)"
        rows.append(
            [
                pair,
                "" if comp is None else comp.iso,
                value + ("" if active or comp is None else " (not used)"),
            ]
        )
    lay.table([_Column("axes", 0.8), _Column("ISO 230-1", 1.0), _Column("value (µm/m)", 2.0)], rows)
    lay.heading("Axes and simulation", level=2)
    cols = [
        _Column("axis", 0.5),
        _Column("role", 0.8),
        _Column("travel (mm)", 1.35),
        _Column("simulated (mm)", 1.35),
        _Column("step (mm)", 0.85, "right"),
        _Column("offset (mm)", 0.95, "right"),
        _Column("points", 0.9, "right"),
    ]
    rows = []
    for name in AXIS_NAMES:
        ax = m.axes[name]
        rows.append(
            [
                name,
                ax.role,
                f"{ax.travel_mm[0]:g} to {ax.travel_mm[1]:g}",
                f"{ax.simulate_mm[0]:g} to {ax.simulate_mm[1]:g}",
                f"{ax.step_mm:g}",
                f"{ax.offset_mm:g}",
                str(result.grid_sizes.get(name, "")),
            ]
        )
    lay.table(cols, rows)
    lay.space(0.04)
    lay.paragraph(
        "The offset of an axis is the position at which the other axes' errors were "
        "measured; angular and squareness errors are levered from there.",
        size=_SMALL,
        colour="0.3",
    )
    lay.heading("Analysis settings", level=2)
    datum = a.datum if isinstance(a.datum, str) else _at(a.datum)
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
    if a.point == "MCP" or tool is None:
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
    if result.sweep:
        lay.heading("Tool sweep", level=2)
        cols = [
            _Column("length (mm)", 1.2, "right"),
            _Column("tilt (°)", 1.0, "right"),
            _Column("spin (°)", 1.0, "right"),
            _Column("volumetric (µm)", 1.4, "right"),
            _Column("   at (X, Y, Z mm)", 2.1),
        ]
        lay.table(
            cols,
            [
                [
                    f"{e.tool.length_mm:g}",
                    f"{e.tool.tilt_deg:g}",
                    f"{e.tool.spin_deg:g}",
                    _num(e.volumetric.value_um),
                    "   " + _xyz(e.volumetric.at),
                ]
                for e in result.sweep
            ],
        )
    unc = result.uncertainty
    if unc is not None and unc.budget:
        lay.heading("Uncertainty budget", level=2)
        cols = [
            _Column("component", 1.6),
            _Column("ISO 230-1", 0.8),
            _Column("model", 1.6),
            _Column("U", 0.9, "right"),
            _Column("unit", 0.7),
            _Column("share (%)", 1.1, "right"),
        ]
        lay.table(
            cols,
            [
                [
                    b.component,
                    b.iso,
                    b.model,
                    f"{b.U:.3g}",
                    unit_label(b.unit),
                    f"{b.share_pct:.1f}",
                ]
                for b in unc.budget
            ],
        )


_BREAKDOWN_COLUMNS = (
    _Column("dir", 0.4),
    _Column("component", 1.5),
    _Column("ISO", 0.6),
    _Column("term", 2.1),
    _Column("value (µm)", 1.0, "right"),
    _Column("share (%)", 1.0, "right"),
)


def _breakdown(lay: _Layout, b: Breakdown, title: str, directions=AXIS_NAMES) -> None:
    lay.heading(title, level=2)
    errors = ", ".join(f"{d} {_num(b.errors_um[d])}" for d in AXIS_NAMES)
    lay.paragraph(
        f"at {_at(b.at)} mm: errors {errors} µm; volumetric {_num(b.volumetric_um)} µm",
        size=_SMALL,
        colour="0.3",
    )
    rows = [
        [
            t.direction,
            t.component,
            t.iso,
            t.symbol,
            _num(t.value_um),
            "" if t.share_pct is None else _num(t.share_pct, 1),
        ]
        for t in b.terms
        if t.direction in directions
    ]
    if rows:
        lay.table(_BREAKDOWN_COLUMNS, rows)
    else:
        lay.paragraph("No active term acts in this direction.", size=_SMALL)


def _case(lay: _Layout, result: AnalysisResult, n: int, case: CaseResult) -> None:
    lay.new_page()
    title = "Extremes and their terms"
    if len(result.cases) > 1:
        title += f": tool case {n + 1} of {len(result.cases)}"
    lay.heading(title)
    if case.tool.length_mm is not None:
        lay.paragraph(f"Tool {_tool_words(case.tool)}.")
    by_label = {b.label: b for b in case.breakdowns}
    for d, e in case.axes.items():
        lay.heading(
            f"{d} direction: minimum {_num(e.minimum.value_um)} µm, maximum "
            f"{_num(e.maximum.value_um)} µm, range {_num(e.range_um)} µm",
            level=2,
        )
        for which in ("min", "max"):
            b = by_label.get(f"{d} {which}")
            if b is not None:
                word = "minimum" if which == "min" else "maximum"
                _breakdown(lay, b, f"   {d} {word}", directions=(d,))
    b = by_label.get("volumetric")
    if b is not None:
        _breakdown(lay, b, f"Volumetric accuracy {_num(case.volumetric.value_um)} µm")
    for plane, e in case.planar.items():
        b = by_label.get(f"planar {plane}")
        if b is not None:
            _breakdown(
                lay, b, f"Planar accuracy {plane}: {_num(e.value_um)} µm", directions=tuple(plane)
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
        for n, case in enumerate(result.cases):
            title = "Extremes and their terms"
            if len(result.cases) > 1:
                title += f", tool case {n + 1}: {_tool_short(case.tool)}"
            sections.append((len(lay.pages) + 1, title))
            _case(lay, result, n, case)
        return lay.pages, sections

    # twice: the first pass finds the page of every section and figure (the contents
    # only list them, so they take the same room whatever the numbers)
    placeholder = [(0, "Inputs")] + [(0, "")] * len(result.cases) + [(0, t) for t in figure_titles]
    pages, sections = lay_out(placeholder)
    first = len(pages) + 1
    contents = sections + [(first + k, f"Figure: {t}") for k, t in enumerate(figure_titles)]
    pages, _ = lay_out(contents)
    return pages


# -- rendering -----------------------------------------------------------------------------


def _footer(fig: Figure, result: AnalysisResult, date: str, page: int, total: int) -> None:
    width, height = fig.get_size_inches()
    y = 0.32 / height
    style = {"fontsize": 7.5, "color": "0.4", "parse_math": False}
    fig.text(
        _MARGIN / width,
        y,
        f"{result.machine.name} · volumetric accuracy report · {date}",
        ha="left",
        **style,
    )
    fig.text(1 - _MARGIN / width, y, f"page {page} of {total}", ha="right", **style)


def _render_text(page: TextPage) -> Figure:
    fig = Figure(figsize=PAGE_PORTRAIT_IN)
    FigureCanvasAgg(fig)
    width, height = PAGE_PORTRAIT_IN
    for item in page.items:
        if isinstance(item, _Text):
            fig.text(
                item.x_in / width,
                1 - item.y_in / height,
                item.text,
                fontsize=item.size,
                fontweight=item.weight,
                color=item.colour,
                ha=item.ha,
                va="baseline",
                parse_math=False,
            )
        else:
            y = 1 - item.y_in / height
            fig.add_artist(
                Line2D(
                    [item.x0_in / width, item.x1_in / width],
                    [y, y],
                    linewidth=item.width_pt,
                    color="0.35",
                    transform=fig.transFigure,
                )
            )
    return fig


def write_pdf(
    path: str | Path,
    result: AnalysisResult,
    figures: Iterable[Figure],
    figure_titles: Sequence[str],
    date: str,
) -> int:
    """Write the report to ``path`` (atomically) and return its number of pages.

    ``figures`` (one per title in ``figure_titles``, which the contents list) are
    placed one per A4 landscape page after the text; they may be produced lazily, e.g. by
    a generator that saves each as PNG first. Each figure is resized to the page and gets
    the footer.
    """
    pages = text_pages(result, date, figure_titles)
    total = len(pages) + len(figure_titles)
    count = 0
    with atomic_path(path) as tmp, PdfPages(tmp, metadata=pdf_metadata(result)) as pdf:
        for page in pages:
            count += 1
            fig = _render_text(page)
            _footer(fig, result, date, count, total)
            pdf.savefig(fig)
        for fig in figures:
            count += 1
            fig.set_size_inches(*PAGE_LANDSCAPE_IN)
            engine = fig.get_layout_engine()
            if engine is not None and hasattr(engine, "set"):
                bottom = 0.5 / PAGE_LANDSCAPE_IN[1]
                engine.set(rect=(0.03, bottom, 0.94, 1 - bottom - 0.04))
            _footer(fig, result, date, count, total)
            pdf.savefig(fig)
        if count != total:
            raise ValueError(f"{len(figure_titles)} figure titles but {count - len(pages)} figures")
    return count
