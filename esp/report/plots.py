"""Figures of an analysis: the inputs, the error maps, the terms at the worst point, the
tool sweep and the uncertainty.

Every builder takes a result of the library and returns a
:class:`matplotlib.figure.Figure` on the Agg canvas (no pyplot, no global state); the
bundle writer saves it as PNG and places it on a page of the PDF. The data behind the maps
(:class:`Plane`) is computed separately from the drawing so that it can be checked.

What the maps show follows Longstaff (2002): the total displacement error of a direction
is the sum of every term of the equation set over the volume (3.05, eq. 3.1-3.16); its
largest magnitude sets the direction's extremes; the volumetric error is the vector sum of
the three directions (eq. 3.4) and its maximum the volumetric accuracy (eq. 3.5). The thesis
shows such errors as surfaces over two axes (figures 4.20-4.28); here each is a coloured
map of a plane through the point of interest.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.colors import Normalize
from matplotlib.figure import Figure
from matplotlib.ticker import MaxNLocator

from esp.io.atomic import atomic_path
from esp.machine import AXIS_NAMES, Machine
from esp.profile import ErrorProfile
from esp.report.profile_plots import profile_runs_figure
from esp.report.profile_text import unit_label
from esp.results import AnalysisResult, Breakdown, CaseResult, Extreme, ToolCase
from esp.synthesis import error_field

__all__ = [
    "MAP_SAMPLES",
    "Plane",
    "PlaneSlicer",
    "budget_figure",
    "component_figure",
    "direction_maps_figure",
    "direction_planes",
    "map_surface",
    "montecarlo_figure",
    "plotted_components",
    "save_png",
    "sweep_figure",
    "terms_figure",
    "volumetric_plane",
    "volumetric_map_figure",
    "worst_extreme",
]

#: the number of samples along each axis of a drawn map: the grid values are resampled
#: bilinearly onto an even grid of this size and drawn as an image (quick to draw, small
#: in a PDF, whatever the grid)
MAP_SAMPLES = 256
DPI = 100
_DIRECTION_COLOURS = {"X": "C0", "Y": "C1", "Z": "C2"}
_SIGNED_CMAP = "RdBu_r"
_MAGNITUDE_CMAP = "viridis"
_DIRECTION_WORDS = {
    "mean": "bidirectional mean",
    "forward": "mean of the forward runs",
    "backward": "mean of the reverse runs",
}


def _figure(width_in: float, height_in: float) -> Figure:
    fig = Figure(figsize=(width_in, height_in), dpi=DPI, layout="constrained")
    FigureCanvasAgg(fig)
    return fig


def save_png(fig: Figure, path: str | Path, dpi: float = DPI) -> None:
    """Write ``fig`` to ``path`` as PNG, atomically and with deterministic bytes (no
    software-version text); ``dpi`` sets the pixel size (``figsize * dpi``)."""
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format="png", dpi=dpi, metadata={"Software": None})


def _at(point: Mapping[str, float]) -> str:
    return ", ".join(f"{a}={point[a]:g}" for a in AXIS_NAMES)


def _axis_label(machine: Machine, axis: str) -> str:
    return f"{axis} position, {machine.axes[axis].role} axis (mm)"


def _datum_note(result: AnalysisResult) -> str:
    return "" if result.datum is None else f", relative to the datum {_at(result.datum)}"


def _tool_note(tool: ToolCase) -> str:
    if tool.length_mm is None:
        return "at the MCP"
    if tool.tilt_deg is None:
        return "tool offset " + ", ".join(f"{a}={tool.offset_mm[a]:g}" for a in AXIS_NAMES) + " mm"
    return f"tool {tool.length_mm:g} mm, tilt {tool.tilt_deg:g}°, spin {tool.spin_deg:g}°"


# -- inputs -------------------------------------------------------------------------------


def plotted_components(result: AnalysisResult) -> tuple[str, ...]:
    """The active components that have data along an axis (every one but squareness), in
    the order X, Y, Z, then linear, straightness, angular, mechanical."""
    names = [
        n
        for n in result.active
        if n in result.machine.components and result.machine.components[n].profile is not None
    ]

    return tuple(sorted(names))


def _used_profile(machine: Machine, name: str) -> tuple[ErrorProfile, str]:
    """The profile of a component as the synthesis uses it, and a note on what was done."""
    comp = machine.components[name]
    profile = comp.profile
    if comp.kind == "straightness":
        fit = machine.analysis.straightness_fit
        return profile.without_slope(fit), f"slope removed by a {fit} line"
    return profile, ""


def component_figure(result: AnalysisResult, name: str) -> Figure:
    """One input component against position: every run (thin), the direction means, and
    the curve the synthesis uses (wide pale band), in the engine unit (µm or µm/m).

    Straightness is drawn with the set-up slope removed, as used (Longstaff 2002,
    4.01.2.1 c). A component with one value (an inline ``constant``) is drawn as a level
    line over the simulated range of its axis.
    """
    machine = result.machine
    comp = machine.components[name]
    profile, note = _used_profile(machine, name)
    direction = machine.analysis.direction
    unit = unit_label(profile.unit)
    title = f"{name} ({comp.iso}): {comp.name.description}"
    source = f"source: {comp.source}" + (f"; {note}" if note else "")
    axis = machine.axes[comp.axis]
    if profile.targets_mm.size == 1:
        fig = _figure(8.0, 4.8)
        ax = fig.add_subplot()
        value = float(profile.mean(direction)[0])
        lo, hi = axis.simulate_mm
        if hi <= lo:
            lo, hi = lo - 1.0, hi + 1.0
        ax.plot([lo, hi], [value, value], "-", color="0.2", linewidth=2.2, label="constant")
        ax.axhline(0.0, color="0.6", linewidth=0.6, zorder=0)
        ax.grid(True, linewidth=0.4, alpha=0.5)
        ax.legend(loc="best", fontsize="small")
        ax.set_ylabel(f"deviation ({unit})")
    else:
        fig = profile_runs_figure(profile)
        ax = fig.axes[0]
        used = profile.mean(direction) if direction in profile.directions + ("mean",) else None
        if used is not None:
            ax.plot(
                profile.targets_mm,
                used,
                "-",
                color="C1",
                linewidth=7.0,
                alpha=0.3,
                solid_capstyle="round",
                zorder=1,
                label=f"used: {_DIRECTION_WORDS.get(direction, direction)}",
            )
        # beside the plot: never over the data, and quicker to place than loc="best"
        ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize="small")
    ax.set_xlabel(_axis_label(machine, comp.axis))
    ax.set_title(f"{title}\n{source}", fontsize="medium")
    return fig


# -- maps -----------------------------------------------------------------------------------


@dataclass(frozen=True)
class Plane:
    """A plane of the simulation grid with one quantity on it.

    ``axes`` are the two axis letters spanning the plane (horizontal, vertical);
    ``grids_mm`` their positions; ``fixed`` the third axis and its position (mm);
    ``values_um`` has shape ``(len(grids_mm[0]), len(grids_mm[1]))``.
    """

    axes: tuple[str, str]
    grids_mm: tuple[np.ndarray, np.ndarray]
    fixed: tuple[str, float]
    values_um: np.ndarray

    def value_at(self, point: Mapping[str, float]) -> float:
        """The value at the grid node nearest to ``point``."""
        i = int(np.argmin(np.abs(self.grids_mm[0] - point[self.axes[0]])))
        j = int(np.argmin(np.abs(self.grids_mm[1] - point[self.axes[1]])))
        return float(self.values_um[i, j])


class PlaneSlicer:
    """Error fields of single planes, each computed once (:func:`esp.synthesis.error_field`
    with one axis pinned) and shared by every map that needs it."""

    def __init__(self, machine: Machine, tool: ToolCase):
        self.machine = machine
        self.tool = tool
        self._cache: dict[tuple[str, float], tuple[dict, dict]] = {}

    def errors(self, axis: str, position_mm: float) -> tuple[dict, dict]:
        key = (axis, float(position_mm))
        if key not in self._cache:
            self._cache[key] = error_field(self.machine, self.tool, fixed={axis: key[1]})
        return self._cache[key]

    def plane(self, fixed_axis: str, position_mm: float, direction: str | None) -> Plane:
        """The total error of ``direction`` (or the volumetric error when None) on the
        plane ``fixed_axis = position_mm``."""
        grids, errors = self.errors(fixed_axis, position_mm)
        k = AXIS_NAMES.index(fixed_axis)
        if direction is None:
            values = np.sqrt(sum(errors[a] ** 2 for a in AXIS_NAMES))  # eq. 3.4
        else:
            values = errors[direction]
        values = np.take(values, 0, axis=k)
        u, v = (a for a in AXIS_NAMES if a != fixed_axis)
        return Plane((u, v), (grids[u], grids[v]), (fixed_axis, float(position_mm)), values)


def worst_extreme(case: CaseResult, direction: str) -> tuple[str, Extreme]:
    """The extreme of a direction with the larger magnitude: ``("max", extreme)`` or
    ``("min", extreme)`` (the maximum when both are equal)."""
    ext = case.axes[direction]
    if abs(ext.minimum.value_um) > abs(ext.maximum.value_um):
        return "min", ext.minimum
    return "max", ext.maximum


def direction_planes(
    result: AnalysisResult, direction: str, slicer: PlaneSlicer | None = None
) -> tuple[str, Extreme, list[Plane]]:
    """The three faces through the largest error of ``direction`` in the worst tool case:
    the planes XY, XZ and YZ at the worst point's Z, Y and X. Returns the extreme's name
    (``"min"``/``"max"``), the extreme, and the planes."""
    case = result.cases[result.worst]
    slicer = slicer or PlaneSlicer(result.machine, case.tool)
    which, ext = worst_extreme(case, direction)
    planes = [slicer.plane(fixed, ext.at[fixed], direction) for fixed in ("Z", "Y", "X")]
    return which, ext, planes


def volumetric_plane(result: AnalysisResult, slicer: PlaneSlicer | None = None) -> Plane:
    """The volumetric error (eq. 3.4) on the plane through the worst point that spans the
    two axes of longest simulated range (ties broken towards keeping the bottom and
    middle axes, so the plane is normal to the top axis)."""
    machine = result.machine
    case = result.cases[result.worst]
    slicer = slicer or PlaneSlicer(machine, case.tool)
    rank = {machine.roles[r]: i for i, r in enumerate(("top", "middle", "bottom"))}

    def span(a: str) -> tuple[float, int]:
        lo, hi = machine.axes[a].simulate_mm
        return (hi - lo, rank[a])

    fixed = min(AXIS_NAMES, key=span)
    return slicer.plane(fixed, case.volumetric.at[fixed], None)


def map_surface(
    u: np.ndarray, v: np.ndarray, values: np.ndarray, samples: int = MAP_SAMPLES
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The grid values resampled bilinearly onto an even ``samples`` x ``samples`` grid for
    drawing as an image.

    Bilinear interpolation (linear along each axis in turn) between the computed nodes
    shows a coarse grid smoothly without inventing extremes: every drawn value lies
    between computed ones. Returns ``(u_even, v_even, values_even)``, indexed ``[u, v]``.
    """
    uf = np.linspace(float(u[0]), float(u[-1]), samples)
    vf = np.linspace(float(v[0]), float(v[-1]), samples)
    along_u = np.array([np.interp(uf, u, values[:, j]) for j in range(v.size)]).T
    fine = np.array([np.interp(vf, v, along_u[i, :]) for i in range(uf.size)])
    return uf, vf, fine


def _star(ax, x: float, y: float) -> None:
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


def _draw_plane(ax, machine: Machine, plane: Plane, norm, cmap, mark, label: str):
    """One plane on ``ax``: a smooth colour map (bilinear between the grid nodes), a line
    when only one of its axes moves, a note when neither does. ``mark`` is the point to
    star. Returns ``(mappable, surface)``, both None unless a colour map was drawn."""
    (ua, va), (ug, vg) = plane.axes, plane.grids_mm
    fixed_axis, fixed_mm = plane.fixed
    ax.set_title(f"{ua}{va} plane at {fixed_axis} = {fixed_mm:g} mm", fontsize="medium")
    if ug.size > 1 and vg.size > 1:
        surface = map_surface(ug, vg, plane.values_um)
        uf, vf, fine = surface
        mappable = ax.imshow(
            fine.T,
            origin="lower",
            extent=(uf[0], uf[-1], vf[0], vf[-1]),
            aspect="auto",
            interpolation="nearest",
            cmap=cmap,
            norm=norm,
        )
        ax.set_xlabel(_axis_label(machine, ua))
        ax.set_ylabel(_axis_label(machine, va))
        _star(ax, mark[ua], mark[va])
        return mappable, surface
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
    fig = _figure(13.0, 4.6)
    axes = fig.subplots(1, 3)
    norm = _symmetric_norm(planes)
    label = f"{direction} error (µm)"
    drawn = [
        mappable
        for ax, p in zip(axes, planes, strict=True)
        for mappable, _ in [_draw_plane(ax, machine, p, norm, _SIGNED_CMAP, ext.at, label)]
        if mappable is not None
    ]
    if drawn:
        bar = fig.colorbar(drawn[0], ax=list(axes), shrink=0.9, pad=0.02)
        bar.set_label(f"total displacement error in {direction} (µm)")
    zero = case.axes[direction].minimum.value_um == case.axes[direction].maximum.value_um == 0
    headline = (
        f"{direction}-direction error: zero over the whole volume"
        if zero
        else f"{direction}-direction error over the faces through its {which}imum: "
        f"{ext.value_um:.3f} µm at {_at(ext.at)} mm (★)"
    )
    fig.suptitle(
        f"{headline}\n{machine.name}, {_tool_note(case.tool)}{_datum_note(result)}",
        fontsize="medium",
    )
    return fig


def volumetric_map_figure(result: AnalysisResult, slicer: PlaneSlicer | None = None) -> Figure:
    """The volumetric error (eq. 3.4) on the plane through the worst point, with labelled
    contour lines and the worst point starred."""
    machine = result.machine
    case = result.cases[result.worst]
    plane = volumetric_plane(result, slicer)
    fig = _figure(8.0, 6.0)
    ax = fig.add_subplot()
    peak = float(np.max(plane.values_um))
    norm = Normalize(vmin=0.0, vmax=peak if peak > 0 else 1.0)
    label = "volumetric error (µm)"
    mappable, surface = _draw_plane(
        ax, machine, plane, norm, _MAGNITUDE_CMAP, case.volumetric.at, label
    )
    if mappable is not None:
        uf, vf, fine = surface
        levels = MaxNLocator(nbins=7).tick_values(float(fine.min()), float(fine.max()))
        levels = levels[(levels > fine.min()) & (levels < fine.max())]
        if levels.size:
            lines = ax.contour(
                uf, vf, fine.T, levels=levels, colors="white", linewidths=0.7, alpha=0.9
            )
            ax.clabel(lines, fmt="%g", fontsize="small")
        bar = fig.colorbar(mappable, ax=ax, shrink=0.9, pad=0.02)
        bar.set_label(label)
    fixed_axis, fixed_mm = plane.fixed
    ax.set_title(
        f"Volumetric error on the {plane.axes[0]}{plane.axes[1]} plane at "
        f"{fixed_axis} = {fixed_mm:g} mm: worst {case.volumetric.value_um:.3f} µm at "
        f"{_at(case.volumetric.at)} mm (★)\n{machine.name}, {_tool_note(case.tool)}"
        f"{_datum_note(result)}",
        fontsize="medium",
    )
    return fig


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
                    f"{d}: {t.component} ({t.iso})  {t.symbol}",
                    t.value_um,
                    _DIRECTION_COLOURS[d],
                    share,
                )
            )
        rows.append((f"{d} total", b.errors_um[d], "0.3", ""))
    fig = _figure(11.0, max(3.6, 1.6 + 0.3 * len(rows)))
    ax = fig.add_subplot()
    y = np.arange(len(rows))[::-1]
    values = [r[1] for r in rows]
    ax.barh(y, values, color=[r[2] for r in rows], height=0.7)
    span = max((abs(v) for v in values), default=1.0) or 1.0
    for yi, (_, value, _, share) in zip(y, rows, strict=True):
        text = f"{value:.3f}" + (f" ({share})" if share else "")
        ax.text(
            value + (0.01 if value >= 0 else -0.01) * span,
            yi,
            text,
            va="center",
            ha="left" if value >= 0 else "right",
            fontsize="x-small",
        )
    ax.set_yticks(y, [r[0] for r in rows], fontsize="small")
    ax.axvline(0.0, color="0.4", linewidth=0.8)
    ax.set_xlim(
        -1.35 * span if min(values) < 0 else -0.05 * span,
        1.35 * span if max(values) > 0 else 0.05 * span,
    )
    ax.set_xlabel("contribution to the total displacement error (µm)")
    ax.grid(True, axis="x", linewidth=0.4, alpha=0.5)
    note = f"; {hidden} terms of zero value not shown" if hidden else ""
    case = result.cases[result.worst]
    # a figure title, centred on the page: the long term labels shift the axes right
    fig.suptitle(
        f"Terms at the worst point {_at(b.at)} mm: volumetric error {b.volumetric_um:.3f} µm\n"
        f"{result.machine.name}, {_tool_note(case.tool)}{_datum_note(result)}\n"
        f"bar labels: value in µm (share of the direction's total){note}",
        fontsize="medium",
    )
    return fig


def sweep_figure(result: AnalysisResult) -> Figure:
    """The volumetric accuracy of every head orientation of a tool sweep, one bar group per
    orientation and one colour per tool length (thesis 3.12); the worst is starred."""
    entries = result.sweep
    orientations = list(dict.fromkeys((e.tool.tilt_deg, e.tool.spin_deg) for e in entries))
    lengths = list(dict.fromkeys(e.tool.length_mm for e in entries))
    fig = _figure(max(8.0, 1.5 + 0.45 * len(orientations) * max(1, len(lengths)) ** 0.5), 4.8)
    ax = fig.add_subplot()
    width = 0.8 / len(lengths)
    value = {(e.tool.length_mm, e.tool.tilt_deg, e.tool.spin_deg): e for e in entries}
    worst = max(entries, key=lambda e: e.volumetric.value_um)
    for k, length in enumerate(lengths):
        xs, hs = [], []
        for i, (tilt, spin) in enumerate(orientations):
            e = value.get((length, tilt, spin))
            if e is not None:
                xs.append(i - 0.4 + width * (k + 0.5))
                hs.append(e.volumetric.value_um)
        ax.bar(xs, hs, width=width * 0.95, color=f"C{k % 10}", label=f"tool length {length:g} mm")
    wi = orientations.index((worst.tool.tilt_deg, worst.tool.spin_deg))
    wk = lengths.index(worst.tool.length_mm)
    ax.plot(
        [wi - 0.4 + width * (wk + 0.5)],
        [worst.volumetric.value_um],
        marker="*",
        markersize=15,
        color="black",
        markeredgecolor="white",
        linestyle="none",
        label=f"worst: {worst.volumetric.value_um:.3f} µm",
    )
    ax.set_xticks(
        range(len(orientations)),
        [f"tilt {t:g}°\nspin {s:g}°" for t, s in orientations],
        fontsize="small",
    )
    ax.set_xlabel("head orientation (tilt from the top axis, spin about it)")
    ax.set_ylabel("volumetric accuracy (µm)")
    ax.grid(True, axis="y", linewidth=0.4, alpha=0.5)
    ax.legend(loc="lower right", fontsize="small")
    ax.set_title(
        f"Tool sweep: volumetric accuracy per orientation and tool length\n"
        f"{result.machine.name}; worst at {_at(worst.volumetric.at)} mm{_datum_note(result)}",
        fontsize="medium",
    )
    return fig


def budget_figure(result: AnalysisResult) -> Figure:
    """The uncertainty budget: each component's share (%) of the volumetric uncertainty at
    the point where that is largest, with its expanded uncertainty U and model."""
    unc = result.uncertainty
    if unc is None:
        raise ValueError("the result holds no uncertainty")
    lines = sorted(unc.budget, key=lambda b: -b.share_pct)
    fig = _figure(9.0, max(3.6, 1.6 + 0.3 * len(lines)))
    ax = fig.add_subplot()
    y = np.arange(len(lines))[::-1]
    ax.barh(y, [b.share_pct for b in lines], color="C4", height=0.7)
    for yi, b in zip(y, lines, strict=True):
        ax.text(
            b.share_pct + 0.5,
            yi,
            f"{b.share_pct:.1f} %  (U = {b.U:.3g} {unit_label(b.unit)}, {b.model})",
            va="center",
            fontsize="x-small",
        )
    ax.set_yticks(y, [f"{b.component} ({b.iso})" for b in lines], fontsize="small")
    top = max((b.share_pct for b in lines), default=1.0)
    ax.set_xlim(0, max(1.0, top) * 1.6)
    ax.set_xlabel("share of the volumetric uncertainty (%)")
    ax.grid(True, axis="x", linewidth=0.4, alpha=0.5)
    ax.set_title(
        f"Uncertainty budget ({unc.method}, k = {unc.k:g}): volumetric U = "
        f"{unc.volumetric.value_um:.3f} µm at {_at(unc.volumetric.at)} mm\n"
        f"{result.machine.name}",
        fontsize="medium",
    )
    return fig


def montecarlo_figure(result: AnalysisResult) -> Figure:
    """The distribution of the volumetric accuracy over the Monte Carlo draws (GUM
    Supplement 1, JCGM 101:2008): histogram, mean, coverage interval, and the accuracy of
    the measured data."""
    unc = result.uncertainty
    if unc is None or unc.montecarlo is None:
        raise ValueError("the result holds no Monte Carlo draws")
    mc = unc.montecarlo
    values = np.asarray(mc.values_um, dtype=float)
    fig = _figure(8.0, 4.8)
    ax = fig.add_subplot()
    if values.size:
        bins = min(80, max(10, int(math.sqrt(values.size))))
        ax.hist(values, bins=bins, color="C0", alpha=0.75, label=f"{values.size} draws")
    ax.axvline(mc.mean_um, color="black", linewidth=1.5, label=f"mean {mc.mean_um:.3f} µm")
    lo, hi = mc.interval_um
    for edge in (lo, hi):
        ax.axvline(edge, color="C3", linestyle="--", linewidth=1.2)
    ax.axvspan(lo, hi, color="C3", alpha=0.08, label=f"coverage interval [{lo:.3f}, {hi:.3f}] µm")
    measured = result.cases[result.worst].volumetric.value_um
    ax.axvline(
        measured,
        color="C2",
        linestyle=":",
        linewidth=1.8,
        label=f"from the measured data {measured:.3f} µm",
    )
    ax.set_xlabel("volumetric accuracy (µm)")
    ax.set_ylabel("number of draws")
    ax.grid(True, linewidth=0.4, alpha=0.5)
    ax.legend(loc="best", fontsize="small")
    ax.set_title(
        f"Monte Carlo: volumetric accuracy over {mc.samples} draws (seed {mc.seed}), "
        f"s = {mc.std_um:.3f} µm\n{result.machine.name}",
        fontsize="medium",
    )
    return fig
