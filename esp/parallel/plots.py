"""Figures of ``esp parallel`` and its report folder (``--out DIR``).

Every builder takes a result of :mod:`esp.parallel.analysis` and returns a
:class:`matplotlib.figure.Figure` on the Agg canvas (no pyplot, no global state):

* :func:`sweep_figure` -- one case of the error-range sweep: (a) the tool tip's position
  errors, (b) its orientation errors against the swept error; the layout of Zhao, Fan et
  al. (2002), Fig. 5 (all sliding errors equal) and Fig. 6 (slider 1 only);
* :func:`workspace_figure` -- the tool tip's position error |e| over α and β at each
  z_T of the grid (and its statistical uncertainty when the file gives one);
* :func:`budget_figure` -- each source's contribution to the error at the pose and its
  share of the uncertainty.

:func:`write_parallel_report` writes them as PNG and as pages of one PDF, with
``result.json``. The bytes are deterministic: no software version or date in the PNG, no
creation date in the PDF; the date printed on the summary page follows
``SOURCE_DATE_EPOCH``.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from esp.parallel.analysis import PoseResult, SweepResult
from esp.parallel.render import render_text
from esp.parallel.sources import SOURCES
from esp.parallel.sweep import ErrorSweep, ErrorSweepCase, Workspace
from esp.report.drawing import save_png

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.text import Text

    from esp.report.document import Document
    from esp.report.provenance import Provenance

__all__ = [
    "budget_figure",
    "figure_files",
    "pdf_metadata",
    "parallel_document",
    "sweep_figure",
    "workspace_figure",
    "write_parallel_report",
]

DPI = 100
_UNIT = {"um": "µm", "urad": "µrad"}
_POS = ("e_x", "e_y", "e_z")
_ROT = ("ε_x", "ε_y", "ε_z")
_COLOURS = ("C0", "C1", "C2")
_SOURCE = {s.name: s for s in SOURCES}


def _figure(width_in: float, height_in: float) -> Figure:
    # fixed margins rather than a layout engine: the same look, several times faster
    fig = Figure(figsize=(width_in, height_in), dpi=DPI)
    FigureCanvasAgg(fig)
    return fig


def _text(ax_or_fig: Axes | Figure, *args: Any, **kwargs: Any) -> Text:
    return ax_or_fig.text(*args, parse_math=False, **kwargs)


def _case_title(sweep: ErrorSweep, case: ErrorSweepCase) -> str:
    if case.case == "all":
        return f"{sweep.source} of every leg equal (cf. Zhao, Fan et al. 2002, Fig. 5)"
    if case.case == "table":
        return f"{sweep.source} alone"
    fig = " (cf. Fig. 6)" if case.case == "1" else ""
    return f"{sweep.source} of leg {case.case} only{fig}"


def sweep_figure(result: PoseResult, sweep: ErrorSweep, case: ErrorSweepCase) -> Figure:
    """The tool's errors against the swept error for one case."""
    fig = _figure(10.0, 4.4)
    axes = fig.subplots(1, 2)
    fig.subplots_adjust(left=0.08, right=0.98, bottom=0.12, top=0.86, wspace=0.25)
    unit = _UNIT[sweep.unit]
    p = result.pose_spec
    for ax, labels, cols, yunit, tag in (
        (axes[0], _POS, slice(0, 3), "µm", "(a) tool tip position error"),
        (axes[1], _ROT, slice(3, 6), "µrad", "(b) tool orientation error"),
    ):
        for label, colour, series in zip(labels, _COLOURS, case.errors[:, cols].T, strict=True):
            ax.plot(case.values, series, color=colour, label=label, marker="o", markersize=3)
        ax.axhline(0.0, color="0.6", linewidth=0.6)
        ax.set_xlabel(f"swept error {sweep.source} ({unit})", parse_math=False)
        ax.set_ylabel(f"error ({yunit})", parse_math=False)
        ax.set_title(tag, parse_math=False, fontsize=10)
        ax.grid(True, linewidth=0.4, alpha=0.6)
        ax.legend(loc=_free_corner(case.errors[:, cols]), fontsize=8)
    fig.suptitle(
        f"{_case_title(sweep, case)}; z_T = {p.z_mm:g} mm, α = {p.alpha_deg:g}°, "
        f"β = {p.beta_deg:g}°; other sources at their values ({result.model} model)",
        fontsize=10,
        parse_math=False,
    )
    return fig


def _free_corner(series: np.ndarray) -> str:
    """The left corner away from where the curves start (a fixed rule: matplotlib's
    "best" placement is slow with many points)."""
    lo, hi = float(np.min(series)), float(np.max(series))
    start = float(np.mean(series[0]))
    return "lower left" if start > 0.5 * (lo + hi) else "upper left"


def workspace_figure(result: PoseResult, ws: Workspace) -> Figure:
    """|e| over (α, β) at the lowest, middle and highest z_T of the grid, and U(e) below.

    (The platform's error transmission does not change with z_T -- raising the platform
    and its sliders together changes no strut direction -- so only the table's angular
    errors, through their lever, make the columns differ.)"""
    z_index = np.unique(np.linspace(0, ws.z_mm.size - 1, min(3, ws.z_mm.size)).round().astype(int))
    rows = 2 if ws.uncertainty is not None else 1
    fig = _figure(3.2 * len(z_index) + 1.2, 3.2 * rows + 0.6)
    axes = np.atleast_2d(fig.subplots(rows, len(z_index), squeeze=False))
    fig.subplots_adjust(left=0.07, right=0.95, bottom=0.08, top=0.9, wspace=0.25, hspace=0.35)
    quantities = [("|e| (µm)", np.linalg.norm(ws.errors[:, :3], axis=1))]
    if ws.uncertainty is not None:
        quantities.append(("U(e), statistical (µm)", np.linalg.norm(ws.uncertainty[:, :3], axis=1)))
    a, b = ws.alpha_deg, ws.beta_deg
    extent = [
        b[0] - _half(b),
        b[-1] + _half(b),
        a[0] - _half(a),
        a[-1] + _half(a),
    ]
    for r, (label, values) in enumerate(quantities):
        grid = ws.grid(values)
        finite = grid[np.isfinite(grid)]
        lo, hi = float(finite.min()), float(finite.max())
        if hi - lo < 1e-9 * max(1.0, abs(hi)):
            lo, hi = lo - 0.5, hi + 0.5
        image = None
        for c, zi in enumerate(z_index):
            ax = axes[r, c]
            image = ax.imshow(
                grid[zi],
                origin="lower",
                extent=extent,
                aspect="auto",
                cmap="viridis",
                vmin=lo,
                vmax=hi,
                interpolation="nearest",
            )
            ax.set_title(f"z_T = {ws.z_mm[zi]:g} mm", fontsize=9, parse_math=False)
            ax.set_xlabel("β (°)", parse_math=False)
            if c == 0:
                ax.set_ylabel("α (°)", parse_math=False)
        assert image is not None  # the grid has at least one z_T, so one column
        fig.colorbar(image, ax=list(axes[r]), label=label, shrink=0.9, fraction=0.04, pad=0.02)
    excluded = f"; {len(ws.excluded)} poses left out (white)" if ws.excluded else ""
    fig.suptitle(
        f"Tool tip position error over the workspace for the file's error values "
        f"({result.model} model){excluded}",
        fontsize=10,
        parse_math=False,
    )
    return fig


def _half(axis: np.ndarray) -> float:
    return 0.5 * float(axis[1] - axis[0]) if axis.size > 1 else 0.5


def budget_figure(result: PoseResult) -> Figure:
    """Contributions to e at the pose, and the shares of U(e) when there is one."""
    unc = result.uncertainty
    fig = _figure(10.0, 5.2)
    axes = fig.subplots(1, 2 if unc is not None else 1, squeeze=False)[0]
    fig.subplots_adjust(left=0.13, right=0.98, bottom=0.11, top=0.88, wspace=0.45)
    active = [j for j in range(len(SOURCES)) if result.values[j] != 0]
    ax = axes[0]
    if active:
        order = sorted(active, key=lambda j: np.linalg.norm(result.contributions[j, :3]))
        y = np.arange(len(order))
        height = 0.8 / 3
        for d, (label, colour) in enumerate(zip(_POS, _COLOURS, strict=True)):
            ax.barh(
                y + (d - 1) * height,
                result.contributions[order, d],
                height=height,
                color=colour,
                label=label,
            )
        ax.set_yticks(y, [SOURCES[j].name for j in order], fontsize=8)
        ax.axvline(0.0, color="0.4", linewidth=0.6)
        ax.legend(loc="lower right", fontsize=8)
    else:
        _text(ax, 0.5, 0.5, "no error values in the file", ha="center", va="center")
        ax.set_yticks([])
    ax.set_xlabel("contribution to the tool tip position error (µm)", parse_math=False)
    e = result.errors[:3]
    ax.set_title(
        f"Error at the pose: e = ({e[0]:.2f}, {e[1]:.2f}, {e[2]:.2f}) µm",
        fontsize=10,
        parse_math=False,
    )
    ax.grid(True, axis="x", linewidth=0.4, alpha=0.6)
    if unc is not None:
        ax = axes[1]
        lines = [b for b in unc.budget if b.share_position_pct != 0][:15][::-1]
        ax.barh(np.arange(len(lines)), [b.share_position_pct for b in lines], color="C4")
        ax.set_yticks(np.arange(len(lines)), [b.source for b in lines], fontsize=8)
        ax.set_xlabel(f"share of U(e) (%), {unc.method}", parse_math=False)
        ax.set_title(
            f"U(e) = {unc.position_um:.2f} µm (k = {unc.k:g}): the 15 largest shares",
            fontsize=10,
            parse_math=False,
        )
        ax.grid(True, axis="x", linewidth=0.4, alpha=0.6)
    p = result.pose_spec
    fig.suptitle(
        f"{result.machine.name}: z_T = {p.z_mm:g} mm, α = {p.alpha_deg:g}°, β = {p.beta_deg:g}°",
        fontsize=10,
        parse_math=False,
    )
    return fig


def figure_files(
    result: PoseResult, sweep: SweepResult | None
) -> list[tuple[str, Callable[[], Figure]]]:
    """(file name, builder) of every figure of the report, in order."""
    specs: list[tuple[str, Callable[[], Figure]]] = [("budget.png", lambda: budget_figure(result))]
    if sweep is not None:
        # the figure of one case, drawn when called (a closure per loop value)
        def case_figure(case: ErrorSweepCase) -> Callable[[], Figure]:
            return lambda: sweep_figure(result, sweep.error, case)

        for case in sweep.error.cases:
            name = (
                "all"
                if case.case == "all"
                else ("table" if case.case == "table" else f"leg{case.case}")
            )
            specs.append((f"sweep-{name}.png", case_figure(case)))
        specs.append(("workspace.png", lambda: workspace_figure(result, sweep.workspace)))
    return specs


_CAPTIONS = {
    "budget.png": "each source's contribution to the tool tip's error at the pose, and the "
    "largest shares of its uncertainty",
    "workspace.png": "the tool tip's position error |e| over α and β at each z_T of the grid",
}


def _caption(name: str) -> str:
    if name in _CAPTIONS:
        return _CAPTIONS[name]
    case = name.removeprefix("sweep-").removesuffix(".png")
    which = {"all": "every leg's error equal", "table": "the table's error"}.get(
        case, f"the error of {case.replace('leg', 'leg ')} only"
    )
    return f"the error sweep, {which}: the tool tip's position and orientation errors"


def parallel_document(
    result: PoseResult,
    sweep: SweepResult | None,
    date: str,
    provenance: Provenance | None = None,
) -> Document:
    """The document of ``esp parallel`` (:class:`esp.report.document.Document`): the
    summary (the tool tip's position and orientation errors at the pose with their
    uncertainty statements), the sections of the text report as tables, then the figures
    and the provenance."""
    from esp.report.document import Document, Headline, summary, text_report, title_fields

    doc = Document(
        "Serial-parallel machine error report",
        result.machine.name,
        date,
        title_fields(provenance=provenance),
    )
    e = float(np.linalg.norm(result.errors[:3]))
    eps = float(np.linalg.norm(result.errors[3:]))
    unc = result.uncertainty

    def statement(value: float, unit: str) -> str | None:
        if unc is None:
            return None
        relation = "≤" if unc.method == "summation" else "="
        return f"U {relation} {value:.3f} {unit} (k = {unc.k:g}, {unc.method})"

    p = result.pose_spec
    lines = [
        Headline(
            "Tool tip position error |e|",
            f"{e:.3f} µm",
            statement(unc.position_um, "µm") if unc is not None else None,
        ),
        Headline(
            "Orientation error |ε|",
            f"{eps:.3f} µrad",
            statement(unc.rotation_urad, "µrad") if unc is not None else None,
        ),
    ]
    if sweep is not None and sweep.workspace is not None:
        for w in sweep.workspace.worst:
            if w.quantity == "|e|":
                lines.append(
                    Headline(
                        "Largest |e| over the workspace",
                        f"{abs(w.value):.3f} µm",
                        None,
                    )
                )
    summary(doc.lay, lines)
    doc.lay.paragraph(
        f"At the pose z_T = {p.z_mm:g} mm, α = {p.alpha_deg:g}°, β = {p.beta_deg:g}°, "
        f"{result.model} model."
        + ("" if unc is not None else " Uncertainty: not evaluated (no [uncertainty] table).")
    )
    doc.section("Analysis")
    text_report(doc.lay, render_text(result, sweep), skip=1)
    doc.lay.paragraph(
        "% of |e| and % of |ε|: each source's contribution projected on the total "
        "(c·e/|e|²); the shares add up to 100 %, a source acting against the total has a "
        "negative share. % of U(e): each source's share of the variance (statistical) or "
        "of the sum (summation).",
        size=8.3,
        colour="0.3",
    )
    return doc


def pdf_metadata(result: PoseResult) -> dict[str, Any]:
    """The PDF's document information: fixed text, no creation date."""
    from esp.report.document import metadata

    return metadata(f"Serial-parallel machine error report: {result.machine.name}")


def write_parallel_report(
    folder: str | Path,
    result: PoseResult,
    sweep: SweepResult | None,
    json_text: str,
    date: str | None = None,
    provenance: Provenance | None = None,
) -> list[str]:
    """Write ``result.json``, every figure as PNG and ``parallel.pdf`` (the document of
    :func:`parallel_document`, then the figures, then the provenance) into ``folder`` (a
    staging folder of :class:`esp.io.outputs.Outputs`); return the file names written."""
    from esp.report.epoch import report_date

    folder = Path(folder)
    date = date or report_date()
    (folder / "result.json").write_text(json_text, encoding="utf-8")
    written = ["result.json"]
    doc = parallel_document(result, sweep, date, provenance)
    for name, build in figure_files(result, sweep):
        fig = build()
        save_png(fig, folder / name, DPI)
        written.append(name)
        doc.figure(fig, _caption(name))
    doc.write(folder / "parallel.pdf", provenance)
    written.append("parallel.pdf")
    return written
