"""Figures of one error profile: every run of a file (``esp inspect --plot``), and the
figure helpers the other figures of a profile share (the ISO 230-2 figure is
:mod:`esp.iso230.plots`).

Figures are built on :class:`matplotlib.figure.Figure` with the Agg canvas (no pyplot,
no global state) and saved as PNG without the software-version text, so the same input
gives the same bytes. The file name in a title is drawn literally (a ``$`` is a dollar
sign) and on one line.
"""

from __future__ import annotations

from pathlib import Path, PurePath

from matplotlib.axes import Axes
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from esp.core.profile import ErrorProfile
from esp.report import drawing
from esp.report.words import one_line, unit_label

__all__ = [
    "COLOURS",
    "display_name",
    "literal",
    "new_figure",
    "profile_runs_figure",
    "save_figure",
    "save_png",
]

COLOURS = {"forward": "C0", "backward": "C3", "up": "C0", "down": "C3", "mean": "0.2"}
_FIGSIZE = (8.0, 4.8)
_DPI = 100


def new_figure() -> tuple[Figure, Axes]:
    fig = Figure(figsize=_FIGSIZE, dpi=_DPI, layout="constrained")
    FigureCanvasAgg(fig)
    return fig, fig.add_subplot()


def display_name(source: str | None) -> str:
    return one_line(PurePath(source).name) if source else "profile"


def literal(fig: Figure) -> Figure:
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
    fig, ax = new_figure()
    x = profile.targets_mm
    styles = {"forward": "-", "backward": "--"}
    for direction in profile.directions:
        runs = profile.runs[direction]
        colour = COLOURS[direction]
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
            color=COLOURS["mean"],
            linewidth=1.8,
            label="bidirectional mean",
        )
    ax.axhline(0.0, color="0.6", linewidth=0.6, zorder=0)
    ax.set_xlabel("position (mm)")
    ax.set_ylabel(f"deviation ({unit_label(profile.unit)})")
    axis = f", {profile.axis} axis" if profile.axis else ""
    # a component named only when the file says which one (a straightness or angular
    # file need not record its error direction)
    named = profile.kind == "linear" or (profile.axis and profile.error_direction)
    component = f": {profile.name}" if named else ""
    ax.set_title(f"{display_name(profile.source)}{component} ({profile.kind}{axis})")
    ax.grid(True, linewidth=0.4, alpha=0.5)
    ax.legend(loc="best", fontsize="small")
    return literal(fig)


def save_png(fig: Figure, path: str | Path) -> None:
    """Write ``fig`` to ``path`` as PNG (:func:`esp.report.drawing.save_png`)."""
    drawing.save_png(fig, path, _DPI)


def save_figure(fig: Figure, path: str | Path, fmt: str) -> None:
    """Write ``fig`` to ``path`` as PNG or PDF (:func:`esp.report.drawing.save_figure`)."""
    drawing.save_figure(fig, path, _DPI, fmt)
