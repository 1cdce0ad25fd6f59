"""The terminal report of ``esp analyse``, in the layout of the original ESP reports
(Longstaff 2002, 4.03-4.04): machine details, configuration in words, active components
with their files, squareness, offsets, simulation set-up, per-axis extremes, volumetric
accuracy, and the breakdown of every extreme point; it ends with the headline (the
volumetric accuracy, where, and its uncertainty).

The tables are the ones the PDF draws (:mod:`esp.report.tables`), the words those of
:mod:`esp.report.words`; user text is shown on one line (:func:`~esp.report.words.one_line`).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

from esp._version import __version__
from esp.core.machine import AXIS_NAMES, Machine
from esp.core.models.tool import ToolCase
from esp.core.results import AnalysisResult, Breakdown, PointResult, UncertaintyResult
from esp.report import tables
from esp.report.words import (
    ANGLE_WORDS,
    METHOD_SHORT,
    METHOD_WORDS,
    UM,
    at_text,
    budget_point_words,
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

__all__ = [
    "breakdown_lines",
    "decision_block",
    "headline_lines",
    "render_point",
    "render_result",
    "stated_with",
]

RULE = "=" * 78


def _header(
    machine: Machine, case: str, words: str, equations: str, datum: Mapping[str, float] | None
) -> list[str]:
    a = machine.analysis
    info = "  ".join(
        f"{k.replace('_', ' ').capitalize()}: {one_line(v)}" for k, v in machine.info.items()
    )
    lines = [
        f"esp {__version__} -- volumetric error synthesis",
        "",
        f"Machine        : {one_line(machine.name)}" + (f"   {info}" if info else ""),
        f"Configuration  : {machine.configuration} ({machine.notation}): {machine.description}",
        f"Evaluation     : case {case}, {words} ({equations})",
        f"Data           : {runs_words(a.direction)}; straightness slope removed by a "
        f"{a.straightness_fit} line"
        + ("; end values held outside the measured range" if a.extrapolate else ""),
        "Datum          : "
        + ("none (raw synthesis)" if datum is None else f"errors relative to {at_text(datum)}"),
    ]
    if case in ANGLE_WORDS:
        lines.append(f"Angles         : {ANGLE_WORDS[case]}")
    return lines


def _inputs(result: AnalysisResult) -> list[str]:
    lines = ["", "Active error components"]
    table = tables.active_components_table(result)
    if table.rows:
        lines += tables.text_lines(table)
    elif is_plan(result):
        lines.append("  none: no error data (an uncertainty plan; its U are in the budget)")
    else:
        lines.append("  none: every component is zero")
    inactive = [str(n) for n in result.inactive if n.kind != "squareness"]
    if inactive:
        lines.append("Not active (zero): " + ", ".join(inactive))
    if result.ignored:
        ignored = ", ".join(str(n) for n in result.ignored)
        lines.append(f"Given but not used by case {result.case}: {ignored}")
    lines += ["", "Squareness"]
    lines += tables.text_lines(tables.squareness_table(result))
    lines += ["", "Axes and simulation"]
    lines += tables.text_lines(tables.axes_table(result))
    sizes = result.grid_sizes
    total = sizes["X"] * sizes["Y"] * sizes["Z"]
    lines.append(
        f"Simulation grid: {sizes['X']} x {sizes['Y']} x {sizes['Z']} = {total} points"
        + (
            f" per tool case, {len(result.sweep)} {swept_words(result)} swept"
            if result.sweep
            else ""
        )
    )
    setups = setup_words(result.machine)
    if setups:
        lines += ["", *setups]
    return lines


def _tool_line(tool: ToolCase) -> str:
    if tool.length_mm is None:
        return "Tool: none (evaluated at the MCP)"
    return f"Tool: {tool_words(tool)}"


def breakdown_lines(b: Breakdown, directions: Sequence[str] = AXIS_NAMES) -> list[str]:
    """The breakdown of one point: a line with the point and its errors, then the table."""
    errors = ", ".join(f"{a} {num(b.errors_um[a])}" for a in AXIS_NAMES)
    table = tables.breakdown_table(b, directions)
    return [
        f"Breakdown at {b.label} ({at_text(b.at)}): errors {errors} {UM}, volumetric "
        f"{num(b.volumetric_um)} {UM}",
        *(tables.text_lines(table) if table.rows else ["  no active term acts here"]),
    ]


def _uncertainty(u: UncertaintyResult, machine: Machine | None = None) -> list[str]:
    bound = " (an upper bound)" if u.method == "summation" else ""
    lines = [
        RULE,
        f"Measurement uncertainty: {METHOD_WORDS.get(u.method, u.method)}, k = {u.k:g}",
        f"Volumetric uncertainty{bound}: {u_text(u.volumetric.value_um)} {UM}, {u_where(u)}",
    ]
    for a, e in u.axes.items():  # U to two significant digits (GUM 7.2.6)
        lines.append(f"  {a} direction: {u_text(e.value_um)} {UM} at {at_text(e.at)}")
    if u.montecarlo is not None:
        mc = u.montecarlo
        lo, hi = mc.interval_um
        lines.append(
            f"Monte Carlo ({mc.samples} draws, seed {mc.seed}{montecarlo_grid_words(mc)}): "
            f"volumetric accuracy mean "
            f"{num(mc.mean_um)} {UM}, standard deviation {num(mc.std_um)} {UM}, "
            f"95 % interval [{num(lo)}, {num(hi)}] {UM}"
        )
    if u.prior is not None:
        p = u.prior
        lines.append(
            f"With the prior {p['prior_um']:g} ± {p['prior_u_um']:g} {UM} (eq. 3.22-3.24): "
            f"volumetric accuracy {num(p['accuracy_um'])} {UM}, U = {num(p['U_um'])} {UM} "
            f"(reduced by {num(p['delta_U_um'])} {UM})"
        )
    lines.append(f"Budget {budget_point_words(u)}")
    lines += tables.text_lines(tables.budget_table(u, machine))
    return lines


def headline_lines(result: AnalysisResult) -> list[str]:
    """The headline that ends the terminal report: the volumetric accuracy (of the worst
    tool case) and where, the tool case when there is one, and the uncertainty; for an
    uncertainty plan (no error data) the volumetric uncertainty, and no accuracy."""
    u = result.uncertainty
    if u is not None and is_plan(result):
        lines = [
            RULE,
            f"Volumetric uncertainty of {one_line(result.machine.name)}: "
            f"{uncertainty_headline(u)}, {u_where(u)}",
        ]
        tool = u.budget_tool
        if tool is not None and tool.length_mm is not None:
            lines.append(f"  {tool_short(tool)}")
        lines.append("  uncertainty plan: no error data, so no volumetric accuracy is evaluated")
        return lines
    worst = result.cases[result.worst]
    figure = (
        f"{num(worst.volumetric.value_um)} {UM}"
        if u is None
        else stated_with(worst.volumetric.value_um, u)
    )
    lines = [
        RULE,
        f"Volumetric accuracy of {one_line(result.machine.name)}: "
        f"{figure} at {at_text(worst.volumetric.at)}",
    ]
    if worst.tool.length_mm is not None:
        of = f" (the worst of {len(result.cases)} tool cases)" if len(result.cases) > 1 else ""
        lines.append(f"  {tool_short(worst.tool)}{of}")
    if u is None:
        lines.append(f"  uncertainty: {u_not_evaluated(result)}")
    else:
        lines.append(f"  uncertainty: {_u_words(u)}, {u_where(u)}")
    return lines


def _u_words(u: UncertaintyResult) -> str:
    """``U = 2.1 µm (k = 2, about 95 %, statistical)``: U rounded to two significant
    digits (GUM 7.2.6); the headline of :mod:`esp.report.words` when U is zero."""
    from esp.core.rounding import rounded

    if not u.volumetric.value_um > 0.0:
        return uncertainty_headline(u)
    _, u_text = rounded(0.0, u.volumetric.value_um)
    method = METHOD_SHORT.get(u.method, u.method)
    return f"U {_relation(u)} {u_text} {UM} ({_coverage(u)}, {method})"


def stated_with(value_um: float, u: UncertaintyResult, expanded_um: float | None = None) -> str:
    """A figure stated with its expanded uncertainty, both rounded to what U supports
    (GUM 7.2.6, :mod:`esp.core.rounding`): ``"33.9 µm, U = 2.1 µm (k = 2, about 95 %)"``;
    ``U ≤`` for the summation bound. ``expanded_um`` defaults to the volumetric U. A U
    that is not positive leaves the figure with three decimals and no U."""
    from esp.core.rounding import rounded

    expanded = u.volumetric.value_um if expanded_um is None else expanded_um
    if not expanded > 0.0:
        return f"{num(value_um)} {UM}"
    v_text, u_text = rounded(value_um, expanded)
    return f"{v_text} {UM}, U {_relation(u)} {u_text} {UM} ({_coverage(u)})"


def _relation(u: UncertaintyResult) -> str:
    return "≤" if u.method == "summation" else "="


def _coverage(u: UncertaintyResult) -> str:
    """``k = 2, about 95 %`` for a statistical U; a summation bound or a pure addition is
    no coverage interval, so only k is stated."""
    from esp.core.rounding import coverage_text

    if u.method in ("statistical", "montecarlo"):
        return coverage_text(u.k, u.coverage)
    return f"k = {u.k:g}"


def decision_block(result: AnalysisResult) -> list[str]:
    """The verdicts against the tolerances (ISO 14253-1), the rule and each risk named;
    nothing when no tolerance is given."""
    from esp.volumetric.conformance import decision_lines, decisions_of

    decisions = decisions_of(result)
    if not decisions:
        return []
    lines = [RULE, "Decisions against the tolerances (ISO 14253-1:2017):"]
    lines += [f"  {line}" for line in decision_lines(decisions)]
    return lines


def render_result(result: AnalysisResult) -> str:
    """The whole terminal report of an analysis."""
    m = result.machine
    lines = _header(m, result.case, result.case_description, result.equations, result.datum)
    lines += _inputs(result)
    plan = is_plan(result)
    if plan:
        lines += [
            "",
            "Uncertainty plan: no error data is given, so no volumetric accuracy is evaluated;",
            "the figures below are the uncertainty of the planned measurements.",
        ]
    if result.sweep and not plan:
        what = swept_words(result)
        lines += ["", f"Sweep of {what}: volumetric accuracy ({UM}) per {what[:-1]}"]
        lines += tables.text_lines(tables.sweep_table(result))
    for n, case in enumerate(() if plan else result.cases):
        lines += ["", RULE, _tool_line(case.tool)]
        lines += ["", f"Total displacement error ({UM})"]
        lines += tables.text_lines(tables.direction_extremes_table(case))
        worst = " (worst case)" if len(result.cases) > 1 and n == result.worst else ""
        volumetric = (
            f"Volumetric accuracy: {num(case.volumetric.value_um)} {UM} at "
            f"{at_text(case.volumetric.at)}{worst}"
        )
        planar = [
            f"Planar accuracy {plane}: {num(e.value_um)} {UM} at {at_text(e.at)}"
            for plane, e in case.planar.items()
        ]
        if result.plane_of_motion:
            fixed = next(a for a in AXIS_NAMES if a not in result.plane_of_motion)
            lines += ["", planar[0] + " (plane of motion)"]
            lines.append(
                volumetric.replace(
                    "Volumetric accuracy:",
                    f"Volumetric accuracy, with the error along {fixed} (which does not move):",
                )
            )
        else:
            lines += ["", volumetric, *planar]
        for b in case.breakdowns:
            lines.append("")
            if b.label.endswith(" min") or b.label.endswith(" max"):
                lines += breakdown_lines(b, directions=(b.label.split()[0],))
            elif b.label.startswith("planar "):
                lines += breakdown_lines(b, directions=tuple(b.label.split()[1]))
            else:
                lines += breakdown_lines(b)
    if result.uncertainty is not None:
        lines += [""] + _uncertainty(result.uncertainty, result.machine)
    lines += [""] + headline_lines(result)
    decided = decision_block(result)
    if decided:
        lines += [""] + decided
    return "\n".join(lines) + "\n"


def render_point(result: PointResult) -> str:
    """The terminal report of ``esp analyse --at``."""
    m = result.machine
    lines = [
        f"Machine: {one_line(m.name)} -- {m.configuration} ({m.notation}), case {result.case} "
        f"({result.equations})",
        "Datum: "
        + ("none" if result.datum is None else f"errors relative to {at_text(result.datum)}"),
    ]
    for pc in result.cases:
        lines += ["", _tool_line(pc.tool)]
        lines += breakdown_lines(pc.breakdown)
    return "\n".join(lines) + "\n"
