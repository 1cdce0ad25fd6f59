"""The figure of ``esp diagonals``: the predicted displacement error along each diagonal,
and, where a measurement was given, the measured values and the band of the combined
expanded uncertainty about the prediction (a measured point outside the band has
E_n > 1)."""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from esp.diagonals.model import Diagonal, DiagonalCheck

__all__ = ["diagonals_figure"]

_DPI = 100


def diagonals_figure(
    machine_name: str,
    predicted: Sequence[tuple[Diagonal, np.ndarray, np.ndarray]],
    checks: Mapping[str, DiagonalCheck],
) -> Figure:
    """One panel per diagonal, two columns."""
    n = len(predicted)
    cols = 2 if n > 1 else 1
    rows = math.ceil(n / cols)
    fig = Figure(figsize=(10.0, 2.9 * rows + 0.6), dpi=_DPI, layout="constrained")
    FigureCanvasAgg(fig)
    axes = np.atleast_1d(fig.subplots(rows, cols, squeeze=False)).ravel()
    for ax, (d, s, v) in zip(axes, predicted, strict=False):
        ax.plot(s, v, color="C0", linewidth=1.4, label="predicted (21 components)")
        c = checks.get(d.name)
        if c is not None:
            if c.U_um is not None:
                ax.fill_between(
                    c.s_mm,
                    c.predicted_um - c.U_um,
                    c.predicted_um + c.U_um,
                    color="C0",
                    alpha=0.15,
                    linewidth=0,
                    label="± U (k = 2)",
                )
            ax.plot(c.s_mm, c.measured_um, "o", color="C3", markersize=3.5, label="measured")
            if c.En is not None:
                bad = c.En > 1.0
                if np.any(bad):
                    ax.plot(
                        c.s_mm[bad],
                        c.measured_um[bad],
                        "x",
                        color="k",
                        markersize=7,
                        label="E_n > 1",
                    )
        start = ", ".join(f"{x:g}" for x in d.start_mm)
        end = ", ".join(f"{x:g}" for x in d.end_mm)
        ax.set_title(f"{d.name}: ({start}) to ({end}) mm", fontsize="small", parse_math=False)
        ax.set_xlabel("distance along the diagonal (mm)")
        ax.set_ylabel("displacement error (µm)")
        ax.grid(True, linewidth=0.4, alpha=0.5)
        ax.legend(fontsize="x-small", loc="best")
    for ax in axes[n:]:
        ax.set_visible(False)
    fig.suptitle(
        f"Diagonal displacement errors (ISO 230-6): {machine_name}",
        fontsize="medium",
        parse_math=False,
    )
    return fig
