"""The before/after figure of ``esp compensate --predict``: the predicted volumetric
accuracy of the machine without and with each format's tables, and the largest error of
each direction after compensation."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from esp.compensation.predict import Prediction

__all__ = ["before_after_figure"]

_DPI = 100


def before_after_figure(machine_name: str, predictions: Sequence[Prediction]) -> Figure:
    """Two panels: left, the volumetric accuracy before and after per format (worst
    direction of approach); right, the largest |error| of each direction after."""
    fig = Figure(figsize=(10.0, 4.6), dpi=_DPI, layout="constrained")
    FigureCanvasAgg(fig)
    ax1, ax2 = fig.subplots(1, 2, width_ratios=[1.2, 1.0])
    names = [p.format for p in predictions]
    x = np.arange(len(names))
    before = [p.before_um for p in predictions]
    after = [p.after_um for p in predictions]
    b1 = ax1.bar(x - 0.2, before, 0.4, label="before", color="0.6")
    b2 = ax1.bar(x + 0.2, after, 0.4, label="after (predicted)", color="C0")
    for bars in (b1, b2):
        for bar in bars:
            ax1.annotate(
                f"{bar.get_height():.1f}",
                (bar.get_x() + bar.get_width() / 2, bar.get_height()),
                ha="center",
                va="bottom",
                fontsize="small",
            )
    ax1.set_xticks(x, names, rotation=20, ha="right")
    ax1.set_ylabel("volumetric accuracy (µm)")
    ax1.set_title("before and after compensation", fontsize="medium")
    ax1.legend(fontsize="small")
    ax1.grid(True, axis="y", linewidth=0.4, alpha=0.5)

    width = 0.8 / 3
    for k, axis in enumerate(("X", "Y", "Z")):
        vals = [max(d.axes_after_um[axis] for d in p.directions) for p in predictions]
        ax2.bar(x + (k - 1) * width, vals, width, label=f"{axis} direction", color=f"C{k}")
    ax2.set_xticks(x, names, rotation=20, ha="right")
    ax2.set_ylabel("largest |error| after (µm)")
    ax2.set_title("residual per direction", fontsize="medium")
    ax2.legend(fontsize="small")
    ax2.grid(True, axis="y", linewidth=0.4, alpha=0.5)
    fig.suptitle(
        f"Predicted residual after compensation: {machine_name}",
        fontsize="medium",
        parse_math=False,
    )
    return fig
