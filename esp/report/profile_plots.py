"""Figures of one error profile: every run of a file (``esp inspect --plot``) and its
ISO 230-2 mean deviations with their ±2s bands (``esp iso230-2 --plot``).

Figures are built on :class:`matplotlib.figure.Figure` with the Agg canvas (no pyplot,
no global state) and saved as PNG without the software-version text, so the same input
gives the same bytes. The file name in a title is drawn literally (a ``$`` is a dollar
sign) and on one line.
"""

from __future__ import annotations

from pathlib import Path, PurePath

import numpy as np
from matplotlib.axes import Axes
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from esp.core.profile import ErrorProfile
from esp.iso230.positioning import Iso230Result
from esp.report import drawing
from esp.report.words import one_line, unit_label

__all__ = ["iso230_figure", "profile_runs_figure", "save_figure", "save_png"]

_COLOURS = {"forward": "C0", "backward": "C3", "up": "C0", "down": "C3", "mean": "0.2"}
_FIGSIZE = (8.0, 4.8)
_DPI = 100


def _new_figure() -> tuple[Figure, Axes]:
    fig = Figure(figsize=_FIGSIZE, dpi=_DPI, layout="constrained")
    FigureCanvasAgg(fig)
    return fig, fig.add_subplot()


def _name(source: str | None) -> str:
    return one_line(PurePath(source).name) if source else "profile"


def _literal(fig: Figure) -> Figure:
    """Titles, labels and legends drawn as written, never as mathtext."""
    for ax in fig.axes:
        texts = [ax.title, ax.xaxis.label, ax.yaxis.label, *ax.texts]
        legend = ax.get_legend()
        if legend is not None:
            texts += legend.get_texts()
        for text in texts:
            text.set_parse_math(False)
    return fig


def profile_runs_figure(profile: ErrorProfile) -> Figure:
    """Every run of ``profile`` (thin lines) and the mean curves (thick) against position.

    Forward runs are solid, backward runs dashed, each direction in its own colour; the
    bidirectional mean is drawn when both directions were measured. The y axis is in the
    engine unit of the profile (µm, or µm/m for angular errors).
    """
    fig, ax = _new_figure()
    x = profile.targets_mm
    styles = {"forward": "-", "backward": "--"}
    for direction in profile.directions:
        runs = profile.runs[direction]
        colour = _COLOURS[direction]
        for k, run in enumerate(runs):
            ax.plot(
                x,
                run,
                styles[direction],
                color=colour,
                linewidth=0.7,
                alpha=0.6,
                label=f"{direction} runs ({runs.shape[0]})" if k == 0 else None,
            )
        ax.plot(
            x,
            profile.mean(direction),
            styles[direction],
            color=colour,
            linewidth=2.2,
            marker="o" if direction == "forward" else "s",
            markersize=3.5,
            label=f"{direction} mean",
        )
    if profile.is_bidirectional:
        ax.plot(
            x,
            profile.mean("mean"),
            ":",
            color=_COLOURS["mean"],
            linewidth=1.8,
            label="bidirectional mean",
        )
    ax.axhline(0.0, color="0.6", linewidth=0.6, zorder=0)
    ax.set_xlabel("position (mm)")
    ax.set_ylabel(f"deviation ({unit_label(profile.unit)})")
    axis = f", {profile.axis} axis" if profile.axis else ""
    ax.set_title(f"{_name(profile.source)}: {profile.name} ({profile.kind}{axis})")
    ax.grid(True, linewidth=0.4, alpha=0.5)
    ax.legend(loc="best", fontsize="small")
    return _literal(fig)


def iso230_figure(result: Iso230Result) -> Figure:
    """Mean deviation per direction with its ±2s band, against position (ISO 230-2 style).

    For each direction measured: x̄i↑ (or x̄i↓) as a line with markers, and the band
    x̄i ± 2 si shaded and bounded by thin lines; the bidirectional mean x̄i dotted when both
    directions exist. A box lists the axis figures (µm).
    """
    fig, ax = _new_figure()
    x = result.targets_mm
    curves = {"up": (result.mean_up, result.s_up), "down": (result.mean_down, result.s_down)}
    names = {"up": "up ↑ (forward)", "down": "down ↓ (backward)"}
    for arrow in result.directions:
        mean, s = curves[arrow]
        # both exist for every direction measured (Iso230Result's invariant)
        assert mean is not None and s is not None
        colour = _COLOURS[arrow]
        ax.fill_between(x, mean - 2.0 * s, mean + 2.0 * s, color=colour, alpha=0.15, linewidth=0)
        for band in (mean - 2.0 * s, mean + 2.0 * s):
            ax.plot(x, band, "-", color=colour, linewidth=0.6, alpha=0.8)
        ax.plot(
            x,
            mean,
            "-",
            color=colour,
            linewidth=1.8,
            marker="o" if arrow == "up" else "s",
            markersize=4,
            label=f"mean {names[arrow]}, ±2s band",
        )
    if result.mean_bidirectional is not None:
        ax.plot(
            x,
            result.mean_bidirectional,
            ":",
            color=_COLOURS["mean"],
            linewidth=1.5,
            label="bidirectional mean",
        )
    ax.axhline(0.0, color="0.6", linewidth=0.6, zorder=0)
    values = result.axis_values()
    width = max(len(k) for k in values)
    figures = "\n".join(f"{k.ljust(width)} = {v:8.3f} µm" for k, v in values.items())
    ax.text(
        1.02,
        1.0,
        figures,
        transform=ax.transAxes,
        va="top",
        ha="left",
        fontsize="small",
        family="monospace",
    )
    ax.set_xlabel("target position (mm)")
    ax.set_ylabel("positional deviation (µm)")
    axis = f"{result.axis} axis" if result.axis else "axis"
    ax.set_title(f"ISO 230-2 positioning, {axis}: {_name(result.source)}")
    ax.grid(True, linewidth=0.4, alpha=0.5)
    ax.legend(loc="best", fontsize="small")
    ax.margins(x=0.02)
    if np.ptp(x) == 0:
        ax.set_xlim(x[0] - 1.0, x[0] + 1.0)
    return _literal(fig)


def save_png(fig: Figure, path: str | Path) -> None:
    """Write ``fig`` to ``path`` as PNG (:func:`esp.report.drawing.save_png`)."""
    drawing.save_png(fig, path, _DPI)


def save_figure(fig: Figure, path: str | Path, fmt: str) -> None:
    """Write ``fig`` to ``path`` as PNG or PDF (:func:`esp.report.drawing.save_figure`)."""
    drawing.save_figure(fig, path, _DPI, fmt)
