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

from collections.abc import Iterable, Sequence
from pathlib import Path, PurePath
from typing import TYPE_CHECKING, Any

from matplotlib.artist import Artist
from matplotlib.figure import Figure

from esp._version import __version__
from esp.core.machine import AXIS_NAMES
from esp.core.results import AnalysisResult, Breakdown, CaseResult, UncertaintyResult
from esp.core.rounding import rounded
from esp.report import document, tables
from esp.report.document import PAGE_LANDSCAPE_IN, PAGE_PORTRAIT_IN, Headline, TextPage
from esp.report.epoch import SOURCE_DATE_EPOCH_MAX, report_date, source_date_epoch
from esp.report.tables import Column, Table
from esp.report.words import (
    METHOD_SHORT,
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
    u_not_evaluated,
    u_text,
    u_where,
    uncertainty_headline,
)
from esp.volumetric.text import stated_with

if TYPE_CHECKING:
    from esp.report.provenance import Provenance

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

FOOTER_BASE_IN = document.FOOTER_BASE_IN


# -- the date ---------------------------------------------------------------------------------


def _report_title(result: AnalysisResult) -> str:
    """What the report is: of the volumetric accuracy, or, for an uncertainty plan (no
    error data), of the volumetric uncertainty."""
    return "Volumetric uncertainty plan" if is_plan(result) else "Volumetric accuracy report"


def pdf_metadata(result: AnalysisResult) -> dict[str, Any]:
    """The document information of the PDF: fixed text, no creation date."""
    return {
        "Title": f"{_report_title(result)}: {one_line(result.machine.name)}",
        "Subject": f"{result.machine.configuration}, case {result.case}",
        "Creator": f"esp {__version__}",
        "Producer": f"esp {__version__}",
        "CreationDate": None,
    }


# -- layout: the shared document builder (esp.report.document) ----------------------------------

_Text = document._Text
_Rule = document._Rule
_Layout = document.Layout
_BODY = document.BODY
_SMALL = document.SMALL
_core_encodable = document.core_encodable
_figure_texts = document.page_figure_texts
_render_text = document.render_text
_save_page = document.save_page
TextBlock = document.TextBlock


# -- content ------------------------------------------------------------------------------------


def uncertainty_terms(u: UncertaintyResult) -> str:
    """How an expanded uncertainty was stated: ``k = 2, 95 % coverage, statistical``."""
    parts = [f"k = {u.k:g}"]
    if u.coverage is not None:
        parts.append(f"{u.coverage * 100:g} % coverage")
    parts.append(METHOD_SHORT.get(u.method, u.method))
    return ", ".join(parts)


def uncertainty_statement(u: UncertaintyResult, value_um: float | None = None) -> str:
    """The uncertainty statement of a figure: ``U = 2.1 µm (k = 2, 95 % coverage,
    statistical)``; ``U ≤ ...`` for the summation bound."""
    relation = "≤" if u.method == "summation" else "="
    value = u.volumetric.value_um if value_um is None else value_um
    # two significant digits (GUM 7.2.6); "0" for a U that is zero
    return f"U {relation} {u_text(value)} {UM} ({uncertainty_terms(u)})"


def headlines(result: AnalysisResult) -> list[Headline]:
    """The figures of the summary: the volumetric accuracy (or, for a plan, uncertainty),
    the planar accuracies and the range of each direction, each with its uncertainty
    statement where one was evaluated."""
    unc = result.uncertainty
    if is_plan(result) and unc is not None:
        relation = "≤" if unc.method == "summation" else "="
        rows = [
            Headline(
                "Volumetric uncertainty",
                f"U {relation} {u_text(unc.volumetric.value_um)} {UM}",
                uncertainty_terms(unc),
            )
        ]
        for d, e in unc.axes.items():
            rows.append(
                Headline(
                    f"Uncertainty in {d}",
                    f"U {relation} {u_text(e.value_um)} {UM}",
                    uncertainty_terms(unc),
                )
            )
        return rows
    worst = result.cases[result.worst]
    rows = [
        Headline(
            "Volumetric accuracy",
            _to_u(worst.volumetric.value_um, unc.volumetric.value_um if unc else None),
            uncertainty_statement(unc) if unc is not None else None,
        )
    ]
    for plane, e in worst.planar.items():
        rows.append(Headline(f"Planar accuracy {plane}", f"{num(e.value_um)} {UM}", None))
    for d, ax in worst.axes.items():
        ur = unc.range_um(d) if unc is not None else None  # as the decisions take it
        rows.append(
            Headline(
                f"Range of the {d} error",
                _to_u(ax.range_um, ur),
                uncertainty_statement(unc, ur) if unc is not None and ur is not None else None,
            )
        )
    return rows


def _to_u(value_um: float, expanded_um: float | None) -> str:
    """A figure rounded to what its U supports (GUM 7.2.6), or with three decimals."""
    if expanded_um is not None and expanded_um > 0.0:
        return f"{rounded(value_um, expanded_um)[0]} {UM}"
    return f"{num(value_um)} {UM}"


def _decisions(lay: _Layout, result: AnalysisResult) -> None:
    """The verdicts against the tolerances (ISO 14253-1:2017), each with its rule and
    risk; nothing without tolerances."""
    from esp.volumetric.conformance import decision_lines, decisions_of

    decisions = decisions_of(result)
    if not decisions:
        return
    lay.heading("Decisions against the tolerances", level=2)
    for line, d in zip(decision_lines(decisions), decisions, strict=True):
        colour = {"conforms": "0.0", "does not conform": "C3"}.get(d.verdict, "C1")
        lay.paragraph(line, colour=colour)


def _summary(
    lay: _Layout, result: AnalysisResult, date: str, provenance: Provenance | None = None
) -> None:
    m, a = result.machine, result.machine.analysis
    plan = is_plan(result)
    source = PurePath(m.source).name if m.source else "in code"
    document.title_block(
        lay,
        _report_title(result),
        m.name,
        document.title_fields(getattr(m, "report", None), m.info, provenance),
        f"Report date {date} · esp {__version__} · machine file {source}",
    )
    document.summary(lay, headlines(result))
    if result.uncertainty is None:
        lay.paragraph(
            f"Uncertainty: {u_not_evaluated(result)}.",
            size=_SMALL,
            colour="0.3",
        )
    _decisions(lay, result)
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
    lay.heading("Headline figures and where")
    if plan and unc is not None:
        lay.line(f"Volumetric uncertainty  {uncertainty_headline(unc)}", size=14.0, weight="bold")
        where = u_where(unc, " mm")
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
            "Volumetric accuracy  "
            + (
                stated_with(worst.volumetric.value_um, unc)
                if unc is not None
                else f"{num(worst.volumetric.value_um)} {UM}"
            ),
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
    if unc is not None:
        lay.heading("Uncertainty", level=2)
        bound = (
            " It is an upper bound: no choice of signs of the components' errors within "
            "their U gives a larger error."
            if unc.method == "summation"
            else ""
        )
        lay.paragraph(
            f"Volumetric uncertainty {uncertainty_headline(unc)}, {u_where(unc, ' mm')}. "
            "Per direction: "
            + ", ".join(f"{d} {u_text(e.value_um)} {UM}" for d, e in unc.axes.items())
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
    """The contents, in two columns side by side when one would not fit on the rest of
    the page (so that it never spills a few lines onto a page of its own)."""
    lay.heading("Contents", level=2)
    rows = [(str(page), "   " + title) for page, title in entries]
    line = _SMALL * 1.45 / 72.0
    if (len(rows) + 1) * line + 0.05 > lay.bottom - lay.y and len(rows) > 6:
        half = (len(rows) + 1) // 2
        left, right = rows[:half], rows[half:] + [("", "")] * (2 * half - len(rows))
        lay.table(
            Table(
                (
                    Column("page", "right", 0.45),
                    Column("   section or figure", "left", 2.95),
                    Column("page", "right", 0.45),
                    Column("   section or figure", "left", 2.92),
                ),
                tuple((a, b, c, d) for (a, b), (c, d) in zip(left, right, strict=True)),
            )
        )
        return
    lay.table(
        Table(
            (Column("page", "right", 0.6), Column("   section or figure", "left", 6.1)),
            tuple(rows),
        )
    )


def _inputs(lay: _Layout, result: AnalysisResult) -> None:
    m, a = result.machine, result.machine.analysis
    lay.section_break()
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
        lay.paragraph("Not active (zero): " + ", ".join(inactive), size=_SMALL)
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
            + "; ".join(", ".join(f"{k}={v:.3f}" for k, v in o.items()) for o in tool.offsets_mm)
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


def _has_budget(result: AnalysisResult) -> bool:
    return result.uncertainty is not None and bool(result.uncertainty.budget)


def _budget(lay: _Layout, result: AnalysisResult) -> None:
    """The uncertainty budget, a section of its own: its table is kept whole with its
    heading where it fits on a page."""
    unc = result.uncertainty
    assert unc is not None
    lay.section_break()
    lay.heading("Uncertainty budget")
    lay.paragraph(f"Evaluated {budget_point_words(unc)}.", size=_SMALL, colour="0.3")
    lay.table(tables.budget_table(unc, result.machine), keep_whole=True)
    lay.heading("What makes each component's uncertainty", level=2)
    lay.paragraph(
        "Each contributor is a standard uncertainty in the component's unit (sensitivity c = "
        "1); type A from the runs of its file, type B from what is stated. Their "
        "root-sum-square is the component's u = U / k.",
        size=_SMALL,
        colour="0.3",
    )
    lay.table(tables.contributors_table(unc))


def _breakdown(
    lay: _Layout, b: Breakdown, title: str, directions: Sequence[str] = AXIS_NAMES
) -> None:
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


def _case(lay: _Layout, result: AnalysisResult, n: int, case: CaseResult) -> str:
    lay.section_break()
    title = "Extremes and their terms"
    if len(result.cases) > 1:
        title += f": tool case {n + 1} of {len(result.cases)}"
    lay.heading(title)
    heading = document.wrap(title, lay.text_width, 13.0, "bold")[0]
    if case.tool.length_mm is not None:
        lay.paragraph(f"Tool {tool_words(case.tool)}.")
    lay.paragraph(
        "share: the term's signed share of its direction's error at the point (the shares "
        "of a direction add up to 100 %; terms of opposite sign can make a share above "
        "100 % or below 0 %).",
        size=_SMALL,
        colour="0.3",
    )
    by_label = {b.label: b for b in case.breakdowns}
    for d, e in case.axes.items():
        found = [by_label.get(f"{d} {which}") for which in ("min", "max")]
        if all(b is not None and not tables.breakdown_table(b, (d,)).rows for b in found):
            lay.heading(f"{d} direction: no active term acts in it; zero over the whole volume", 2)
            continue
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
    return heading


def _page_of(lay: _Layout, heading: str, start: int) -> int:
    """The number of the page (from 1) where the section ``heading`` begins, looking from
    the page ``start`` (from 1) on."""
    for k in range(max(0, start - 1), len(lay.pages)):
        for item in lay.pages[k].items:
            if isinstance(item, _Text) and item.text == heading and item.weight == "bold":
                return k + 1
    return start


def text_pages(
    result: AnalysisResult,
    date: str,
    figure_titles: Sequence[str] = (),
    provenance: Provenance | None = None,
) -> list[TextPage]:
    """The text pages of the report: summary with the contents, inputs, then the extremes
    and breakdowns of every tool case. The contents list each section and each of
    ``figure_titles`` with its page (the figures follow the text pages, one per page)."""

    cases = () if is_plan(result) else result.cases  # a plan: no pages of zero extremes
    titles = ["Inputs"] + (["Uncertainty budget"] if _has_budget(result) else [])
    for n, case in enumerate(cases):
        title = "Extremes and their terms"
        if len(result.cases) > 1:
            title += f", tool case {n + 1}: {tool_short(case.tool)}"
        titles.append(title)

    def lay_out(contents: Sequence[tuple[int, str]]) -> tuple[list[TextPage], list]:
        lay = _Layout()
        _summary(lay, result, date, provenance)
        _contents(lay, contents)
        start = len(lay.pages)
        _inputs(lay, result)
        pages = [_page_of(lay, "Inputs", start)]
        if _has_budget(result):
            start = len(lay.pages)
            _budget(lay, result)
            pages.append(_page_of(lay, "Uncertainty budget", start))
        for n, case in enumerate(cases):
            start = len(lay.pages)
            heading = _case(lay, result, n, case)
            pages.append(_page_of(lay, heading, start))
        return lay.pages, list(zip(pages, titles, strict=True))

    # twice: the first pass finds the page of every section and figure (the contents
    # only list them, so they take the same room whatever the numbers)
    placeholder = [(0, t) for t in titles] + [(0, f"Figure: {t}") for t in figure_titles]
    pages, sections = lay_out(placeholder)
    first = len(pages) + 1
    contents = sections + [(first + k, f"Figure: {t}") for k, t in enumerate(figure_titles)]
    pages, _ = lay_out(contents)
    return pages


# -- rendering ----------------------------------------------------------------------------------


def _footer_text(result: AnalysisResult, date: str) -> str:
    return f"{one_line(result.machine.name)} · {_report_title(result).lower()} · {date}"


def _footer_items(
    result: AnalysisResult, date: str, page: int, total: int, size_in: tuple[float, float]
) -> list:
    return document.footer_items(_footer_text(result, date), page, total, size_in)


def add_footer(fig: Figure, result: AnalysisResult, date: str, page: int, total: int) -> Artist:
    """Add the footer of a PDF page (machine, report, date, page number) to ``fig`` and
    return its artist (remove it to reuse the figure without the footer)."""
    return document.add_footer(fig, _footer_text(result, date), page, total)


def report_provenance(result: AnalysisResult) -> Any:
    """The provenance of the files ``result`` was read from, under the command being run
    (none outside a command), for a caller that passes none."""
    from esp.report.provenance import collect, command_line

    return collect(result.machine.inputs, command_line())


def write_pdf(
    path: str | Path,
    result: AnalysisResult,
    figures: Iterable[Figure],
    figure_titles: Sequence[str],
    date: str,
    provenance: Provenance | None = None,
) -> int:
    """Write the report to ``path`` (atomically) and return its number of pages.

    ``figures`` (one per title in ``figure_titles``, which the contents list) are placed
    one per page, at their own size (the report's figures are A4 landscape), after the
    text, each captioned with its title; they may be produced lazily, e.g. by a generator
    that saves each as PNG first. The last page is the provenance (``provenance``, an
    :class:`esp.report.provenance.Provenance`) when it is given. Every page carries
    ``page n of N``.
    """
    source_date_epoch()  # the PDF writer reads it too: refuse a malformed one first
    if provenance is None and result.machine.inputs:
        provenance = report_provenance(result)
    pages = text_pages(result, date, figure_titles, provenance=provenance)
    return document.write_document(
        path,
        pages,
        footer=_footer_text(result, date),
        meta=pdf_metadata(result),
        figures=figures,
        captions=figure_titles,
        provenance=provenance,
    )
