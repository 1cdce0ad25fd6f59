"""The ISO 230-2 figure of ``esp iso230-2 --plot`` and of its report: the mean deviation per
direction with its ±2s band against the target position, and the axis figures."""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from esp.iso230.positioning import Iso230Result
from esp.report.profile_plots import COLOURS, display_name, literal, new_figure

__all__ = ["iso230_figure"]


def iso230_figure(result: Iso230Result) -> Figure:
    """Mean deviation per direction with its ±2s band, against position (ISO 230-2 style).

    For each direction measured: x̄i↑ (or x̄i↓) as a line with markers, and the band
    x̄i ± 2 si shaded and bounded by thin lines; the bidirectional mean x̄i dotted when both
    directions exist. A box lists the axis figures (µm).
    """
    fig, ax = new_figure()
    # the axis figures in an axes of their own beside the plot, so that the layout makes
    # room for them on every page size (a text outside the plot's axes is not laid out)
    grid = fig.add_gridspec(1, 2, width_ratios=(3.3, 1.0))
    ax.set_subplotspec(grid[0])
    box = fig.add_subplot(grid[1])
    box.axis("off")
    x = result.targets_mm
    curves = {"up": (result.mean_up, result.s_up), "down": (result.mean_down, result.s_down)}
    names = {"up": "up ↑ (forward)", "down": "down ↓ (backward)"}
    for arrow in result.directions:
        mean, s = curves[arrow]
        # both exist for every direction measured (Iso230Result's invariant)
        assert mean is not None and s is not None
        colour = COLOURS[arrow]
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
            color=COLOURS["mean"],
            linewidth=1.5,
            label="bidirectional mean",
        )
    ax.axhline(0.0, color="0.6", linewidth=0.6, zorder=0)
    values = result.axis_values()
    width = max(len(k) for k in values)
    unit = result.value_label
    figures = "\n".join(f"{k.ljust(width)} = {v:8.3f} {unit}" for k, v in values.items())
    box.text(
        0.0,
        1.0,
        figures,
        transform=box.transAxes,
        va="top",
        ha="left",
        fontsize="small",
        family="monospace",
    )
    ax.set_xlabel(f"target position ({result.position_label})")
    ax.set_ylabel(f"positional deviation ({result.value_label})")
    axis = f"{result.axis} axis" if result.axis else "axis"
    ax.set_title(f"ISO 230-2 positioning, {axis}: {display_name(result.source)}")
    ax.grid(True, linewidth=0.4, alpha=0.5)
    ax.legend(loc="best", fontsize="small")
    ax.margins(x=0.02)
    if np.ptp(x) == 0:
        ax.set_xlim(x[0] - 1.0, x[0] + 1.0)
    return literal(fig)
