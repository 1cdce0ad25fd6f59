"""Figures of an analysis: the inputs, the error maps, the terms at the worst point, the
tool sweep and the uncertainty.

Every builder takes a result of the library and returns a
:class:`matplotlib.figure.Figure` on the Agg canvas (no pyplot, no global state), of one
size, A4 landscape (:data:`FIGURE_IN`), laid out by hand: the same figure is saved as PNG
and placed as a page of the PDF, with nothing computed again. The data behind the maps
(:class:`Plane`) is computed separately from the drawing so that it can be checked. User
text (a machine name, a file name) is drawn literally, never as mathtext, and on one line;
a title too long for the page is wrapped, then cut with "…".

What the maps show follows Longstaff (2002): the total displacement error of a direction
is the sum of every term of the equation set over the volume (3.05, eq. 3.1-3.16); its
largest magnitude sets the direction's extremes; the volumetric error is the vector sum of
the three directions (eq. 3.4) and its maximum the volumetric accuracy (eq. 3.5). The thesis
shows such errors as surfaces over two axes (figures 4.20-4.28); here each is a coloured
map of a plane through the point of interest.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any, cast

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.cm import ScalarMappable
from matplotlib.collections import LineCollection
from matplotlib.colors import Normalize
from matplotlib.figure import Figure
from matplotlib.font_manager import FontProperties
from matplotlib.lines import Line2D
from matplotlib.patches import Rectangle
from matplotlib.ticker import MaxNLocator

from esp.core.machine import AXIS_NAMES, Machine
from esp.core.names import ComponentName
from esp.core.results import AnalysisResult, Breakdown, ToolCase
from esp.report import drawing
from esp.report.drawing import figure_texts, quiet_glyphs
from esp.report.words import (
    DEG,
    RUNS_USED_SHORT,
    UM,
    at_text,
    budget_point_words,
    iso_of,
    num,
    one_line,
    source_words,
    tool_short,
    uncertainty_headline,
    unit_label,
)
from esp.volumetric.slices import (
    MAP_SAMPLES,
    Plane,
    PlaneSlicer,
    direction_planes,
    map_surface,
    volumetric_plane,
    worst_extreme,
)

if TYPE_CHECKING:
    pass

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.contour import ContourSet
    from matplotlib.text import Text

    from esp.core.machine import Component

__all__ = [
    "DPI",
    "FIGURE_IN",
    "MAP_SAMPLES",
    "Plane",
    "PlaneSlicer",
    "axis_inputs_figure",
    "budget_figure",
    "component_figure",
    "direction_maps_figure",
    "direction_planes",
    "input_axes",
    "map_surface",
    "montecarlo_figure",
    "plotted_components",
    "save_png",
    "sweep_figure",
    "terms_figure",
    "volumetric_plane",
    "volumetric_map_figure",
    "worst_breakdown",
    "worst_extreme",
]

#: the size of every figure of the report (inches): A4 landscape, the size of its PDF page
FIGURE_IN = (11.69, 8.27)
#: the resolution of the PNG files (pixels per inch): 1169 x 827 pixels
DPI = 100
_DIRECTION_COLOURS = {"X": "C0", "Y": "C1", "Z": "C2"}
_SIGNED_CMAP = "RdBu_r"
_MAGNITUDE_CMAP = "viridis"
_RUN_COLOURS = {"forward": "C0", "backward": "C3"}
_RUN_STYLES = {"forward": "-", "backward": "--"}
_RUN_LINESTYLES = {"forward": "solid", "backward": "dashed"}
_RUN_WORDS = {"forward": "forward", "backward": "reverse"}

# the frame of every figure (inches): the title block at the top, the footer band of the
# PDF page at the bottom
_LEFT = 0.55
_RIGHT = 0.3
_HEADLINE_BASE = 0.5
_HEADLINE_PT = 12.5
_SUBTITLE_PT = 10.0
_LINE_GAP = 0.24
_FOOTER_BAND = 0.55
#: the estimated advance of a character, as a fraction of the font size (conservative)
_CHAR_EM = 0.62


# -- the frame ------------------------------------------------------------------------------


def _new_figure() -> Figure:
    fig = Figure(figsize=FIGURE_IN, dpi=DPI)
    FigureCanvasAgg(fig)
    return fig


def _axes(fig: Figure, left: float, bottom: float, width: float, height: float) -> Axes:
    """Axes at a rectangle given in inches from the bottom left of the figure."""
    w, h = FIGURE_IN
    return fig.add_axes((left / w, bottom / h, width / w, height / h))


def _text_width_in(fig: Figure, text: str, size: float, weight: str = "normal") -> float:
    """The drawn width of ``text`` (inches) at ``size`` points (``fig`` is not used: every
    figure of the report has the same resolution)."""
    width = drawing.text_width_px(text, FontProperties(size=size, weight=weight), DPI)
    return width / DPI * 1.03  # PDF widths differ a little from hinted Agg ones


def _wrap(
    fig: Figure, text: str, size: float, width_in: float, weight: str = "normal"
) -> list[str]:
    """``text`` (one line) broken at spaces into lines no wider than ``width_in``; a word
    too long for a line is cut with "…". Lines are first filled by an estimate of the
    width of a character, then measured once each and shortened a word at a time."""
    measured: dict[str, float] = {}

    def width(line: str) -> float:
        if line not in measured:
            measured[line] = _text_width_in(fig, line, size, weight)
        return measured[line]

    words = one_line(text).split(" ")
    chars = max(8, int(width_in * 72 / (size * 0.55)))
    lines: list[str] = []
    while words:
        count, used = 0, -1
        while count < len(words) and used + 1 + len(words[count]) <= chars:
            used += 1 + len(words[count])
            count += 1
        count = max(1, count)
        while count > 1 and width(" ".join(words[:count])) > width_in:
            count -= 1
        lines.append(" ".join(words[:count]))
        words = words[count:]
    return [_cut(fig, line, size, width_in, weight, width) for line in lines]


def _cut(
    fig: Figure,
    line: str,
    size: float,
    width_in: float,
    weight: str = "normal",
    width: Callable[[str], float] | None = None,
) -> str:
    """``line`` cut with "…" to fit ``width_in``; ``width`` measures a line (inches) in
    this font if given (it may know ``line`` already)."""
    measure = width or (lambda s: _text_width_in(fig, s, size, weight))
    if measure(line) <= width_in:
        return line
    keep = max(1, int(width_in * 72 / (size * _CHAR_EM)))
    while keep > 1 and measure(line[:keep] + "…") > width_in:
        keep = max(1, keep - max(1, keep // 10))
    return line[:keep] + "…"


def _title(fig: Figure, headline: str, subtitle: str = "", max_lines: int = 3) -> int:
    """Write the title block: the headline in bold, then the subtitle, wrapped to the
    width of the page, at most ``max_lines`` lines in all (the last cut with "…").
    Returns the number of lines written."""
    width_in = FIGURE_IN[0] - _LEFT - _RIGHT
    lines = [(line, _HEADLINE_PT, "bold") for line in _wrap(fig, headline, _HEADLINE_PT, width_in)]
    if subtitle:
        lines += [
            (line, _SUBTITLE_PT, "normal") for line in _wrap(fig, subtitle, _SUBTITLE_PT, width_in)
        ]
    if len(lines) > max_lines:
        text, size, weight = lines[max_lines - 1]
        lines = lines[: max_lines - 1] + [
            (_cut(fig, text + " …", size, width_in, weight), size, weight)
        ]
    y = _HEADLINE_BASE
    for text, size, weight in lines:
        fig.text(
            _LEFT / FIGURE_IN[0],
            1 - y / FIGURE_IN[1],
            text,
            fontsize=size,
            fontweight=weight,
            ha="left",
            va="baseline",
            parse_math=False,
        )
        y += _LINE_GAP
    return len(lines)


def _literal(fig: Figure) -> Figure:
    """Every text of ``fig`` drawn literally (no mathtext): a ``$`` in a machine or file
    name is a dollar sign. (Tick labels are numbers or component names, never user text.)"""
    for text in figure_texts(fig):
        text.set_parse_math(False)
    return fig


def save_png(fig: Figure, path: str | Path, dpi: float = DPI) -> None:
    """Write ``fig`` to ``path`` as PNG (:func:`esp.report.drawing.save_png`), by default
    at the report's resolution."""
    drawing.save_png(fig, path, dpi)


def _axis_label(machine: Machine, axis: str) -> str:
    return f"{axis} position, {machine.axes[axis].role} axis (mm)"


def _datum_note(result: AnalysisResult) -> str:
    return "" if result.datum is None else f", relative to the datum {at_text(result.datum)}"


def _name(result: AnalysisResult) -> str:
    return one_line(result.machine.name)


# -- inputs -------------------------------------------------------------------------------


def plotted_components(result: AnalysisResult) -> tuple[ComponentName, ...]:
    """The active components that have data along an axis (every one but squareness), in
    the order X, Y, Z, then linear, straightness, angular, mechanical."""
    names = [
        n
        for n in result.active
        if n in result.machine.components and result.machine.components[n].profile is not None
    ]
    return tuple(sorted(names))


def input_axes(result: AnalysisResult) -> tuple[str, ...]:
    """The axes with at least one plotted component, X, Y, Z order: one input figure each."""
    axes = {result.machine.components[n].axis for n in plotted_components(result)}
    return tuple(a for a in AXIS_NAMES if a in axes)


def _inline_kind(comp: Component) -> str | None:
    """``"constant"`` or ``"points"`` for a component written in the configuration (one
    curve, no runs), else None."""
    source = str(comp.source)
    if source.startswith("constant"):
        return "constant"
    if source == "points" or source.startswith("points ("):
        return "points"
    profile = comp.profile
    assert profile is not None  # a plotted component has data (plotted_components)
    runs = [r for d in profile.directions for r in profile.runs[d]]
    if len(runs) == 1 or (len(runs) == 2 and np.array_equal(runs[0], runs[1])):
        return "points"
    return None


def _drawn_range(machine: Machine, comp: Component) -> tuple[float, float]:
    """The positions (mm) a component is drawn over: its targets, or for one value (a
    constant) the simulated range of its axis, widened to 2 mm if that is a point."""
    assert comp.profile is not None and comp.axis is not None  # a plotted component
    x = comp.profile.targets_mm
    if x.size > 1:
        return float(x[0]), float(x[-1])
    lo, hi = machine.axes[comp.axis].simulate_mm
    if hi <= lo:
        lo, hi = lo - 1.0, hi + 1.0
    return float(lo), float(hi)


def _draw_component(ax: Axes, result: AnalysisResult, name: str | ComponentName) -> set[str]:
    """One input component on ``ax``: every run of both directions (thin), the direction
    means, and the curve the synthesis uses (wide, pale); for straightness also the line
    fitted to the bidirectional mean and removed as set-up misalignment (Longstaff 2002,
    4.01.2.1 c). A component written in the configuration is one curve (a constant a
    level line over the simulated range). Returns the legend keys drawn."""
    machine = result.machine
    comp = machine.components[name]
    profile = comp.profile
    assert profile is not None  # only components with data are drawn (plotted_components)
    direction = machine.analysis.direction
    fit = machine.analysis.straightness_fit
    x = profile.targets_mm
    keys: set[str] = set()
    inline = _inline_kind(comp)
    if inline is not None:
        curve = profile.mean("mean")
        if x.size == 1:
            lo, hi = _drawn_range(machine, comp)
            ax.plot([lo, hi], [curve[0], curve[0]], "-", color="0.15", linewidth=2.0)
            keys.add("constant")
        else:
            ax.plot(x, curve, "-", color="0.15", linewidth=1.6, marker="o", markersize=4)
            keys.add("given")
        used = curve
    else:
        for d in profile.directions:
            # every run of a direction: one artist of thin lines, each drawn as a line of
            # its own would be (the same dashes; overlaps darken)
            runs = LineCollection(
                [np.column_stack((x, run)) for run in profile.runs[d]],
                colors=_RUN_COLOURS[d],
                linewidths=0.6,
                linestyles=_RUN_LINESTYLES[d],
                alpha=0.55,
            )
            ax.add_collection(runs, autolim=True)
            ax.plot(x, profile.mean(d), _RUN_STYLES[d], color=_RUN_COLOURS[d], linewidth=1.6)
            keys |= {f"{d} runs", f"{d} mean"}
        used = profile.mean(direction if direction in profile.directions else "mean")
    if comp.kind == "straightness" and fit != "none" and x.size > 1:
        line = profile.slope_line(fit)
        ax.plot(x, line, ":", color="black", linewidth=1.3)
        keys.add("fit")
        used = used - line
    if x.size > 1:
        ax.plot(x, used, "-", color="C1", linewidth=6.0, alpha=0.35, solid_capstyle="round")
        keys.add("used")
    ax.axhline(0.0, color="0.6", linewidth=0.6, zorder=0)
    ax.grid(True, linewidth=0.4, alpha=0.5)
    return keys


def _legend_handles(keys: set[str], result: AnalysisResult) -> tuple[list, list[str]]:
    a = result.machine.analysis
    used = f"used: {RUNS_USED_SHORT.get(a.direction, a.direction)}"
    if "fit" in keys:
        used += " (straightness: less the line)"
    table = [
        ("forward runs", Line2D([], [], color="C0", linewidth=0.6, alpha=0.55), "forward runs"),
        ("forward mean", Line2D([], [], color="C0", linewidth=1.6), "forward mean"),
        (
            "backward runs",
            Line2D([], [], color="C3", linewidth=0.6, alpha=0.55, linestyle="--"),
            "reverse runs",
        ),
        (
            "backward mean",
            Line2D([], [], color="C3", linewidth=1.6, linestyle="--"),
            "reverse mean",
        ),
        (
            "given",
            Line2D([], [], color="0.15", linewidth=1.6, marker="o", markersize=4),
            "given in the configuration",
        ),
        ("constant", Line2D([], [], color="0.15", linewidth=2.0), "constant (configuration)"),
        (
            "fit",
            Line2D([], [], color="black", linewidth=1.3, linestyle=":"),
            f"{a.straightness_fit} line fitted and removed",
        ),
        ("used", Line2D([], [], color="C1", linewidth=6.0, alpha=0.35), used),
    ]
    handles = [h for k, h, _ in table if k in keys]
    labels = [label for k, _, label in table if k in keys]
    return handles, labels


def _panel_title(ax: Axes, comp: Component, width_in: float) -> None:
    """The lines above a panel: the component and its ISO 230-1 name in bold; its
    description, unit and source (file name or inline value) on one line, or the source
    on a line of its own when the three do not fit the panel's width (a file name is
    shown whole)."""
    fig = cast(Figure, ax.figure)
    head = _cut(fig, f"{comp.name} ({comp.iso})", 9.5, width_in, "bold")
    what = f"{comp.name.description} · {unit_label(comp.unit)}"
    words = f"{what} · {source_words(comp.source)}"
    small: dict[str, Any] = {"fontsize": 8.0, "color": "0.3"}
    lines: tuple[tuple[str, float, dict[str, Any]], ...]
    if _text_width_in(fig, words, 8.0) <= width_in:
        lines = ((head, 17.0, {"fontsize": 9.5, "fontweight": "bold"}), (words, 5.0, small))
    else:
        lines = (
            (head, 27.0, {"fontsize": 9.5, "fontweight": "bold"}),
            (_cut(fig, what, 8.0, width_in), 15.0, small),
            (source_words(comp.source), 5.0, small),
        )
    for text, up, style in lines:
        drawing.offset_text(ax, (0.0, 1.0), text, (0.0, up), ha="left", va="baseline", **style)


def _grid(n: int) -> tuple[int, int]:
    cols = min(3, max(1, n))
    return math.ceil(n / cols), cols


def _inputs_figure(
    result: AnalysisResult, names: Sequence[str | ComponentName], headline: str
) -> Figure:
    machine = result.machine
    fig = _new_figure()
    a = machine.analysis
    _title(
        fig,
        headline,
        f"{_name(result)} · runs used: {RUNS_USED_SHORT.get(a.direction, a.direction)}",
        max_lines=2,
    )
    rows, cols = _grid(len(names))
    left, right, top, bottom = 0.85, 0.3, 2.0, 1.0
    hgap, vgap = 0.8, 1.05
    width = (FIGURE_IN[0] - left - right - (cols - 1) * hgap) / cols
    height = (FIGURE_IN[1] - top - bottom - (rows - 1) * vgap) / rows
    keys: set[str] = set()
    for k, name in enumerate(names):
        r, c = divmod(k, cols)
        ax = _axes(
            fig,
            left + c * (width + hgap),
            FIGURE_IN[1] - top - (r + 1) * height - r * vgap,
            width,
            height,
        )
        comp = machine.components[name]
        keys |= _draw_component(ax, result, name)
        _panel_title(ax, comp, width)
        ax.xaxis.set_major_locator(drawing.drawn_ticks_locator(6))
        ax.yaxis.set_major_locator(drawing.drawn_ticks_locator(5))
        ax.tick_params(labelsize=8)
        if (r + 1) * cols + c < len(names):  # a panel below shows the same positions
            ax.tick_params(labelbottom=False)
        else:
            ax.set_xlabel(f"{comp.axis} position (mm)", fontsize=9)
        ax.set_ylabel(f"deviation ({unit_label(comp.unit)})", fontsize=9)
    spans = [_drawn_range(machine, machine.components[n]) for n in names]
    lo, hi = min(s[0] for s in spans), max(s[1] for s in spans)
    pad = 0.02 * (hi - lo)
    for ax in fig.axes:  # one position axis for every panel of the figure
        ax.set_xlim(lo - pad, hi + pad)
    handles, labels = _legend_handles(keys, result)
    fig.legend(
        handles,
        labels,
        loc="upper left",
        bbox_to_anchor=(_LEFT / FIGURE_IN[0], 1 - 0.92 / FIGURE_IN[1]),
        ncol=min(4, len(labels)),
        fontsize=8.5,
        frameon=False,
        borderaxespad=0.0,
        handlelength=2.6,
    )
    return _literal(fig)


def axis_inputs_figure(result: AnalysisResult, axis: str) -> Figure:
    """Every plotted input component of one axis against position, one panel each (up to
    three per row): every run (thin), the direction means, the curve the synthesis uses
    (wide, pale), in the engine unit (µm or µm/m).

    Straightness shows the raw runs, the line fitted and removed (the set-up slope,
    Longstaff 2002, 4.01.2.1 c) and the result. A component written in the configuration
    (``points``, ``constant``) is one curve: no runs are invented for it.
    """
    names = [n for n in plotted_components(result) if result.machine.components[n].axis == axis]
    if not names:
        raise ValueError(f"no plotted input component of axis {axis}")
    role = result.machine.axes[axis].role
    return _inputs_figure(
        result,
        names,
        f"Inputs of the {axis} axis ({role}): every run, the means and the curve used",
    )


def component_figure(result: AnalysisResult, name: str) -> Figure:
    """One input component against position, drawn as in :func:`axis_inputs_figure`."""
    comp = result.machine.components[name]
    return _inputs_figure(result, [name], f"Input {name} ({comp.iso}) against position")


# -- maps -----------------------------------------------------------------------------------


def _star(ax: Axes, x: float, y: float) -> None:
    """Mark a point with a black star edged in white, drawn over the axes' edge too."""
    ax.plot(
        [x],
        [y],
        marker="*",
        markersize=16,
        color="black",
        markeredgecolor="white",
        markeredgewidth=1.0,
        linestyle="none",
        clip_on=False,
        zorder=10,
    )


def _draw_plane(
    ax: Axes,
    machine: Machine,
    plane: Plane,
    norm: Normalize,
    cmap: str,
    mark: Mapping[str, float],
    label: str,
) -> Any:
    """One plane on ``ax``: a smooth colour map (bilinear between the grid nodes), a line
    when only one of its axes moves, a note when neither does. ``mark`` is the point to
    star. Returns ``(mappable, surface)``, both None unless a colour map was drawn."""
    (ua, va), (ug, vg) = plane.axes, plane.grids_mm
    fixed_axis, fixed_mm = plane.fixed
    # at the top of the axes (y=1.0), where matplotlib would place it after measuring the
    # tick labels of both axes at every drawing: none is above the axes, and the y axis
    # shows its numbers whole (no offset text there to avoid)
    ax.set_title(f"{ua}{va} plane at {fixed_axis} = {fixed_mm:g} mm", fontsize=10.5, y=1.0)
    ax.ticklabel_format(axis="y", useOffset=False)
    if ug.size > 1 and vg.size > 1:
        surface = map_surface(ug, vg, plane.values_um)
        uf, vf, fine = surface
        # coloured once, at the samples: nearest sampling (PNG) then picks colours as it
        # would pick values, and no drawing colours the image again
        colours = ScalarMappable(norm=norm, cmap=cmap)
        ax.imshow(
            colours.to_rgba(fine.T, bytes=True),
            origin="lower",
            extent=(uf[0], uf[-1], vf[0], vf[-1]),
            aspect="auto",
            interpolation="none",  # PDF: the samples as they are; PNG: nearest
        )
        ax.set_xlabel(_axis_label(machine, ua))
        ax.set_ylabel(_axis_label(machine, va))
        ax.xaxis.set_major_locator(drawing.drawn_ticks_locator(5))
        ax.yaxis.set_major_locator(drawing.drawn_ticks_locator(6))
        _star(ax, mark[ua], mark[va])
        return colours, surface
    if ug.size > 1 or vg.size > 1:
        moving, grid = (ua, ug) if ug.size > 1 else (va, vg)
        ax.plot(grid, plane.values_um.reshape(-1), "-", color="0.2", linewidth=1.8)
        _star(ax, mark[moving], plane.value_at(mark))
        ax.set_xlabel(_axis_label(machine, moving))
        ax.set_ylabel(label)
        ax.grid(True, linewidth=0.4, alpha=0.5)
    else:
        ax.text(
            0.5,
            0.5,
            f"{ua} and {va} do not move:\nno map on this plane",
            ha="center",
            va="center",
            transform=ax.transAxes,
        )
        ax.set_xticks([])
        ax.set_yticks([])
    return None, None


def _symmetric_norm(planes: list[Plane]) -> Normalize:
    peak = max(float(np.max(np.abs(p.values_um))) for p in planes)
    peak = peak if peak > 0 else 1.0
    return Normalize(vmin=-peak, vmax=peak)


def direction_maps_figure(
    result: AnalysisResult, direction: str, slicer: PlaneSlicer | None = None
) -> Figure:
    """The total displacement error of ``direction`` on the three faces through its largest
    value (worst tool case), on one colour scale centred on zero, the point starred."""
    machine = result.machine
    case = result.cases[result.worst]
    which, ext, planes = direction_planes(result, direction, slicer)
    fig = _new_figure()
    zero = case.axes[direction].minimum.value_um == case.axes[direction].maximum.value_um == 0
    headline = (
        f"{direction}-direction error: zero over the whole volume"
        if zero
        else f"{direction}-direction error over the faces through its {which}imum: "
        f"{num(ext.value_um)} {UM} at {at_text(ext.at)} mm (★)"
    )
    _title(fig, headline, f"{_name(result)}, {tool_short(case.tool)}{_datum_note(result)}")
    left, gap, right = 0.85, 0.95, 0.3
    width = (FIGURE_IN[0] - left - right - 2 * gap) / 3
    bottom, top = 2.05, 1.5
    height = FIGURE_IN[1] - top - bottom
    norm = _symmetric_norm(planes)
    label = f"{direction} error ({UM})"
    drawn = []
    for k, p in enumerate(planes):
        ax = _axes(fig, left + k * (width + gap), bottom, width, height)
        mappable, _ = _draw_plane(ax, machine, p, norm, _SIGNED_CMAP, ext.at, label)
        if mappable is not None:
            drawn.append(mappable)
    if drawn:
        cax = _axes(fig, left + width + gap, 0.98, width, 0.16)
        bar = fig.colorbar(drawn[0], cax=cax, orientation="horizontal")
        bar.set_label(f"total displacement error in {direction} ({UM})")
    return _literal(fig)


def _label_points(lines: ContourSet, u: np.ndarray, v: np.ndarray) -> list[tuple[float, float]]:
    """One point per contour level where its label goes: the vertex of the level's lines
    farthest from the edges of the map (relative to its size), so that no label is cut."""
    span_u = float(u[-1] - u[0]) or 1.0
    span_v = float(v[-1] - v[0]) or 1.0
    points = []
    for path in lines.get_paths():
        xy = np.asarray(path.vertices)
        if len(xy) == 0:
            continue
        du = np.minimum(xy[:, 0] - u[0], u[-1] - xy[:, 0]) / span_u
        dv = np.minimum(xy[:, 1] - v[0], v[-1] - xy[:, 1]) / span_v
        k = int(np.argmax(np.minimum(du, dv)))
        points.append((float(xy[k, 0]), float(xy[k, 1])))
    return points


def _contour_labels_inside(ax: Axes, labels: Sequence[Text]) -> None:
    """Remove contour labels that would not lie wholly inside the axes."""
    renderer = ax.figure.canvas.get_renderer()  # type: ignore[attr-defined]  # Agg
    box = ax.get_window_extent(renderer)
    for text in list(labels):
        with quiet_glyphs():
            extent = text.get_window_extent(renderer)
        if (
            extent.x0 < box.x0 + 2
            or extent.x1 > box.x1 - 2
            or extent.y0 < box.y0 + 2
            or extent.y1 > box.y1 - 2
        ):
            text.remove()


def volumetric_map_figure(result: AnalysisResult, slicer: PlaneSlicer | None = None) -> Figure:
    """The volumetric error (eq. 3.4) on the plane through the worst point, with labelled
    contour lines and the worst point starred."""
    machine = result.machine
    case = result.cases[result.worst]
    plane = volumetric_plane(result, slicer)
    fig = _new_figure()
    fixed_axis, fixed_mm = plane.fixed
    _title(
        fig,
        f"Volumetric error on the {plane.axes[0]}{plane.axes[1]} plane at {fixed_axis} = "
        f"{fixed_mm:g} mm: worst {num(case.volumetric.value_um)} {UM} at "
        f"{at_text(case.volumetric.at)} mm (★)",
        f"{_name(result)}, {tool_short(case.tool)}{_datum_note(result)}",
    )
    left, bottom, top = 0.95, 1.2, 1.45
    width = FIGURE_IN[0] - left - 1.75
    ax = _axes(fig, left, bottom, width, FIGURE_IN[1] - top - bottom)
    ax.set_title("")
    peak = float(np.max(plane.values_um))
    norm = Normalize(vmin=0.0, vmax=peak if peak > 0 else 1.0)
    label = f"volumetric error ({UM})"
    mappable, surface = _draw_plane(
        ax, machine, plane, norm, _MAGNITUDE_CMAP, case.volumetric.at, label
    )
    ax.set_title("")
    if mappable is not None:
        uf, vf, fine = surface
        levels = MaxNLocator(nbins=7).tick_values(float(fine.min()), float(fine.max()))
        levels = levels[(levels > fine.min()) & (levels < fine.max())]
        if levels.size:
            lines = ax.contour(
                uf, vf, fine.T, levels=levels, colors="white", linewidths=0.7, alpha=0.9
            )
            labels = ax.clabel(lines, fmt="%g", fontsize=8.5, manual=_label_points(lines, uf, vf))
            _contour_labels_inside(ax, labels)
        cax = _axes(fig, left + width + 0.25, bottom, 0.2, FIGURE_IN[1] - top - bottom)
        bar = fig.colorbar(mappable, cax=cax)
        bar.set_label(label)
    return _literal(fig)


# -- terms, sweep, uncertainty ----------------------------------------------------------------

#: terms smaller than this (µm) are left out of the bar chart (they print as 0.000)
ZERO_TERM_UM = 0.0005


def worst_breakdown(result: AnalysisResult) -> Breakdown:
    """The breakdown at the volumetric worst point of the worst tool case."""
    case = result.cases[result.worst]
    for b in case.breakdowns:
        if b.label == "volumetric":
            return b
    return case.breakdowns[0]


#: the largest pitch of the rows of a bar chart (inches): few bars stay slim, at the top
_MAX_ROW_IN = 0.5


def _bar_axes(fig: Figure, labels: Sequence[str], top: float, bottom: float) -> tuple[Axes, float]:
    """The axes of a horizontal bar chart of ``labels`` and its font size: the font
    shrinks with the number of rows (9 pt down to 6 pt), the axes start right of the
    widest label, and a few rows take no more than :data:`_MAX_ROW_IN` each (the chart
    then hangs from the top)."""
    room = FIGURE_IN[1] - top - bottom
    height = min(room, _MAX_ROW_IN * max(1, len(labels)) + 0.2)
    pitch_pt = height * 72 / max(1, len(labels))
    size = max(6.0, min(9.0, 0.8 * pitch_pt))
    widest = max((_text_width_in(fig, s, size) for s in labels), default=0.5)
    left = min(FIGURE_IN[0] / 2, widest + 0.3)
    ax = _axes(fig, left, bottom + room - height, FIGURE_IN[0] - left - 0.35, height)
    return ax, size


def terms_figure(result: AnalysisResult) -> Figure:
    """Horizontal bars of every term's contribution (µm) at the worst point, grouped by
    direction, each group ending in its total; the share of the direction's total is
    written beside each bar."""
    b = worst_breakdown(result)
    rows: list[tuple[str, float, str, str]] = []  # label, value, colour, share text
    hidden = 0
    for d in AXIS_NAMES:
        terms = [t for t in b.terms if t.direction == d]
        shown = [t for t in terms if abs(t.value_um) >= ZERO_TERM_UM]
        hidden += len(terms) - len(shown)
        shown.sort(key=lambda t: -abs(t.value_um))
        for t in shown:
            share = "" if t.share_pct is None else f"{t.share_pct:.0f} %"
            rows.append(
                (
                    f"{d}: {t.component} ({t.iso})  {t.symbol}" if t.iso else f"{d}: {t.component}",
                    t.value_um,
                    _DIRECTION_COLOURS[d],
                    share,
                )
            )
        rows.append((f"{d} total", b.errors_um[d], "0.3", ""))
    case = result.cases[result.worst]
    fig = _new_figure()
    note = f"; {hidden} terms of zero value not shown" if hidden else ""
    _title(
        fig,
        f"Terms at the worst point {at_text(b.at)} mm: volumetric error "
        f"{num(b.volumetric_um)} {UM}",
        f"{_name(result)}, {tool_short(case.tool)}{_datum_note(result)}. Bar labels: value "
        f"in {UM} (share of the direction's total){note}",
    )
    top, bottom = 1.4, 1.1
    labels = [r[0] for r in rows]
    ax, size = _bar_axes(fig, labels, top, bottom)
    y = np.arange(len(rows))[::-1]
    values = [r[1] for r in rows]
    ax.barh(y, values, color=[r[2] for r in rows], height=0.7)
    span = max((abs(v) for v in values), default=1.0) or 1.0
    negative_only = max(values) <= 0 < -min(values)
    for yi, (_, value, _, share) in zip(y, rows, strict=True):
        text = num(value) + (f" ({share})" if share else "")
        right = value > 0 or (value == 0 and not negative_only)  # the side with room
        ax.text(
            value + (0.01 if right else -0.01) * span,
            yi,
            text,
            va="center",
            ha="left" if right else "right",
            fontsize=size - 0.5,
        )
    ax.set_yticks(y, labels, fontsize=size)
    ax.set_ylim(-0.7, len(rows) - 0.3)
    ax.axvline(0.0, color="0.4", linewidth=0.8)
    ax.set_xlim(
        -1.35 * span if min(values) < 0 else -0.05 * span,
        1.35 * span if max(values) > 0 else 0.05 * span,
    )
    ax.set_xlabel(f"contribution to the total displacement error ({UM})")
    ax.grid(True, axis="x", linewidth=0.4, alpha=0.5)
    return _literal(fig)


def _setting_deg(tool: ToolCase) -> Mapping[str, float]:
    """The angles of a tool case of a servo head or rotary table sweep (each one has them)."""
    assert tool.setting_deg is not None
    return tool.setting_deg


def _orientation(tool: ToolCase) -> tuple[float, float]:
    """Tilt and spin of a tool case of an orientation sweep (each one has them)."""
    assert tool.tilt_deg is not None and tool.spin_deg is not None
    return tool.tilt_deg, tool.spin_deg


def setting_figure(result: AnalysisResult) -> Figure:
    """The volumetric accuracy at every setting of a servo head or rotary table: with two
    angles a grid of cells (first angle across, second up), each holding its value, the
    worst outlined; otherwise one marker per setting, the worst starred."""
    entries = result.sweep
    names = list(_setting_deg(entries[0].tool))
    worst = max(entries, key=lambda e: e.volumetric.value_um)
    fig = _new_figure()
    _title(
        fig,
        f"Volumetric accuracy per setting of {' and '.join(names)}; worst "
        f"{num(worst.volumetric.value_um)} {UM} ({tool_short(worst.tool)})",
        f"{_name(result)}; worst at {at_text(worst.volumetric.at)} mm{_datum_note(result)}",
    )
    left, bottom, top, right = 1.1, 1.1, 1.35, 1.6
    ax = _axes(fig, left, bottom, FIGURE_IN[0] - left - right, FIGURE_IN[1] - top - bottom)
    values = np.array([e.volumetric.value_um for e in entries])
    if len(names) == 2:
        xs = sorted({_setting_deg(e.tool)[names[0]] for e in entries})
        ys = sorted({_setting_deg(e.tool)[names[1]] for e in entries})
        grid = np.full((len(ys), len(xs)), np.nan)
        for e in entries:
            i = ys.index(_setting_deg(e.tool)[names[1]])
            j = xs.index(_setting_deg(e.tool)[names[0]])
            grid[i, j] = max(e.volumetric.value_um, np.nan_to_num(grid[i, j], nan=-np.inf))
        image = ax.imshow(grid, origin="lower", cmap="viridis", aspect="auto")
        colorbar = fig.colorbar(
            image, cax=_axes(fig, FIGURE_IN[0] - right + 0.25, bottom, 0.2, 4.0)
        )
        colorbar.set_label(f"volumetric accuracy ({UM})")
        lo, hi = float(np.nanmin(grid)), float(np.nanmax(grid))
        for i in range(len(ys)):
            for j in range(len(xs)):
                if np.isnan(grid[i, j]):
                    continue
                light = hi > lo and (grid[i, j] - lo) / (hi - lo) > 0.6
                ax.text(
                    j,
                    i,
                    num(grid[i, j], 1),
                    ha="center",
                    va="center",
                    fontsize=9,
                    color="black" if light else "white",
                )
        wi = ys.index(_setting_deg(worst.tool)[names[1]])
        wj = xs.index(_setting_deg(worst.tool)[names[0]])
        ax.add_patch(
            Rectangle((wj - 0.5, wi - 0.5), 1, 1, fill=False, edgecolor="red", linewidth=2.5)
        )
        ax.set_xticks(range(len(xs)), [f"{v:g}{DEG}" for v in xs])
        ax.set_yticks(range(len(ys)), [f"{v:g}{DEG}" for v in ys])
        ax.set_xlabel(f"{names[0]} ({DEG})")
        ax.set_ylabel(f"{names[1]} ({DEG})")
    else:
        x = np.arange(len(entries))
        ax.plot(x, values, "o-", color="C0", markersize=5, linewidth=1.0)
        k = entries.index(worst)
        ax.plot([k], [values[k]], marker="*", markersize=18, color="black", linestyle="none")
        labels = [", ".join(f"{v:g}" for v in _setting_deg(e.tool).values()) for e in entries]
        ax.set_xticks(x, labels, rotation=90, fontsize=7.5)
        ax.set_xlabel(f"setting ({', '.join(names)} in {DEG})")
        ax.set_ylabel(f"volumetric accuracy ({UM})")
        ax.grid(True, axis="y", linewidth=0.4, alpha=0.5)
    return _literal(fig)


def sweep_figure(result: AnalysisResult) -> Figure:
    """The volumetric accuracy of every head orientation of a tool sweep (thesis 3.12):
    orientations along the bottom, grouped by tilt and labelled by spin, one line of
    markers per tool length, the worst starred and named. The value axis spans the values
    (it does not start at zero), so that the differences between orientations show."""
    entries = result.sweep
    if entries[0].tool.setting_deg:
        return setting_figure(result)
    lengths = list(dict.fromkeys(e.tool.length_mm for e in entries))
    orientations = [_orientation(e.tool) for e in entries]
    tilts = sorted({t for t, _ in orientations})
    spins = {t: sorted({spin for tilt, spin in orientations if tilt == t}) for t in tilts}
    position: dict[tuple[float, float], float] = {}
    x = 0.0
    centres, separators = [], []
    for i, t in enumerate(tilts):
        if i:
            separators.append(x - 0.75)
            x += 0.5
        first = x
        for s in spins[t]:
            position[(t, s)] = x
            x += 1.0
        centres.append(((first + x - 1.0) / 2, t))
    worst = max(entries, key=lambda e: e.volumetric.value_um)
    values = np.array([e.volumetric.value_um for e in entries])
    lo, hi = float(values.min()), float(values.max())
    pad = 0.15 * (hi - lo) if hi > lo else max(0.01, 0.01 * abs(hi))

    fig = _new_figure()
    _title(
        fig,
        f"Tool sweep: volumetric accuracy per orientation and tool length; worst "
        f"{num(worst.volumetric.value_um)} {UM} ({tool_short(worst.tool)})",
        f"{_name(result)}; worst at {at_text(worst.volumetric.at)} mm{_datum_note(result)}",
    )
    left, bottom, top, legend_w = 0.95, 1.5, 1.35, 2.3
    width = FIGURE_IN[0] - left - legend_w - 0.3
    ax = _axes(fig, left, bottom, width, FIGURE_IN[1] - top - bottom)
    markers = "os^Dvp<>h"
    for k, length in enumerate(lengths):
        mine = [e for e in entries if e.tool.length_mm == length]
        label: str | None = f"tool length {length:g} mm"
        for t in tilts:
            group = sorted(
                (position[_orientation(e.tool)], e.volumetric.value_um)
                for e in mine
                if e.tool.tilt_deg == t
            )
            if not group:
                continue
            gx, gy = zip(*group, strict=True)
            ax.plot(
                gx,
                gy,
                "-",
                marker=markers[k % len(markers)],
                color=f"C{k % 10}",
                markersize=6,
                linewidth=1.2,
                label=label,
            )
            label = None
    wx = position[_orientation(worst.tool)]
    ax.plot(
        [wx],
        [worst.volumetric.value_um],
        marker="*",
        markersize=20,
        color="black",
        markeredgecolor="white",
        linestyle="none",
        zorder=10,
        label=f"worst: {num(worst.volumetric.value_um)} {UM}",
    )
    for sx in separators:
        ax.axvline(sx, color="0.6", linewidth=0.8, linestyle=":")
    ax.set_ylim(lo - pad, hi + pad)
    ax.set_xlim(-0.6, x - 0.4)
    ticks = sorted(position.items(), key=lambda kv: kv[1])
    pitch_in = width / max(1, len(ticks))
    ax.set_xticks(
        [p for _, p in ticks],
        [f"{s:g}{DEG}" for (_, s), _ in ticks],
        fontsize=9 if pitch_in >= 0.45 else 7.5,
        rotation=0 if pitch_in >= 0.45 else 90,
    )
    below = 20 if pitch_in >= 0.45 else 36  # points below the axis: under the tick labels
    for cx, t in centres:
        drawing.offset_text(
            ax,
            (cx, 0.0),
            f"tilt {t:g}{DEG}",
            (0.0, -below),
            transform=ax.get_xaxis_transform(),
            ha="center",
            va="top",
            fontsize=10,
            fontweight="bold",
        )
    ax.set_xlabel(
        "head orientation: spin about the top axis, grouped by tilt from it",
        labelpad=22,
    )
    ax.set_ylabel(f"volumetric accuracy ({UM}); the axis does not start at zero")
    ax.grid(True, axis="y", linewidth=0.4, alpha=0.5)
    ax.legend(
        loc="upper left",
        bbox_to_anchor=(1.02, 1.0),
        fontsize=9,
        frameon=False,
        borderaxespad=0.0,
        numpoints=1,
    )
    return _literal(fig)


def budget_figure(result: AnalysisResult) -> Figure:
    """The uncertainty budget: each component's share (%) of the volumetric uncertainty at
    the point where that is largest, with its expanded uncertainty U and model."""
    unc = result.uncertainty
    if unc is None:
        raise ValueError("the result holds no uncertainty")
    lines = sorted(unc.budget, key=lambda b: -b.share_pct)
    fig = _new_figure()
    _title(
        fig,
        f"Uncertainty budget: volumetric {uncertainty_headline(unc)} at "
        f"{at_text(unc.volumetric.at)} mm",
        f"{_name(result)}. Budget {budget_point_words(unc)}. Bar labels: share, the "
        f"expanded uncertainty U at that point, its k, distribution and model",
    )
    top, bottom = 1.3, 1.1
    labels = [f"{b.component} ({iso_of(result.machine, b.component)})" for b in lines]
    ax, size = _bar_axes(fig, labels or [""], top, bottom)
    y = np.arange(len(lines))[::-1]
    ax.barh(y, [b.share_pct for b in lines], color="C4", height=0.7)
    top_share = max((b.share_pct for b in lines), default=1.0)
    for yi, b in zip(y, lines, strict=True):
        ax.text(
            b.share_pct + 0.01 * max(1.0, top_share),
            yi,
            f"{b.share_pct:.1f} %  (U = {b.U:.3g} {unit_label(b.unit)}, k = "
            f"{getattr(b, 'k', unc.k):g}, {getattr(b, 'distribution', 'normal')}, {b.model})",
            va="center",
            fontsize=size - 0.5,
        )
    ax.set_yticks(y, labels, fontsize=size)
    ax.set_ylim(-0.7, max(1, len(lines)) - 0.3)
    ax.set_xlim(0, max(1.0, top_share) * 2.0)
    ax.set_xlabel("share of the volumetric uncertainty (%)")
    ax.grid(True, axis="x", linewidth=0.4, alpha=0.5)
    return _literal(fig)


def montecarlo_figure(result: AnalysisResult) -> Figure:
    """The distribution of the volumetric accuracy over the Monte Carlo draws (GUM
    Supplement 1, JCGM 101:2008): histogram, mean, coverage interval, and the accuracy of
    the measured data."""
    unc = result.uncertainty
    if unc is None or unc.montecarlo is None:
        raise ValueError("the result holds no Monte Carlo draws")
    mc = unc.montecarlo
    values = np.asarray(mc.values_um, dtype=float)
    fig = _new_figure()
    _title(
        fig,
        f"Monte Carlo: volumetric accuracy over {mc.samples} draws (seed {mc.seed}), "
        f"s = {num(mc.std_um)} {UM}",
        _name(result),
    )
    left, bottom, top, legend_w = 0.95, 1.1, 1.3, 3.2
    ax = _axes(
        fig,
        left,
        bottom,
        FIGURE_IN[0] - left - legend_w - 0.3,
        FIGURE_IN[1] - top - bottom,
    )
    if values.size:
        bins = min(80, max(10, int(math.sqrt(values.size))))
        ax.hist(values, bins=bins, color="C0", alpha=0.75, label=f"{values.size} draws")
    ax.axvline(mc.mean_um, color="black", linewidth=1.5, label=f"mean {num(mc.mean_um)} {UM}")
    lo, hi = mc.interval_um
    for edge in (lo, hi):
        ax.axvline(edge, color="C3", linestyle="--", linewidth=1.2)
    ax.axvspan(
        lo, hi, color="C3", alpha=0.08, label=f"coverage interval [{num(lo)}, {num(hi)}] {UM}"
    )
    measured = result.cases[result.worst].volumetric.value_um
    ax.axvline(
        measured,
        color="C2",
        linestyle=":",
        linewidth=1.8,
        label=f"from the measured data {num(measured)} {UM}",
    )
    ax.set_xlabel(f"volumetric accuracy ({UM})")
    ax.set_ylabel("number of draws")
    ax.grid(True, linewidth=0.4, alpha=0.5)
    ax.legend(loc="upper left", bbox_to_anchor=(1.02, 1.0), fontsize=9, frameon=False)
    return _literal(fig)
