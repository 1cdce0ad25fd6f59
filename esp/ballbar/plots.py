"""The polar plot of ballbar circles: each direction's path about the least-squares circle
(the path G is taken over), magnified about a ring at a stated scale per division."""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import TYPE_CHECKING, cast

import numpy as np

from esp.ballbar.analysis import CircleTest, along_arc

if TYPE_CHECKING:
    from matplotlib.figure import Figure
    from matplotlib.projections.polar import PolarAxes

__all__ = ["DIVISIONS", "division_um", "polar_figure"]

#: the zero ring lies this many divisions from the centre of the plot; the outer edge twice
DIVISIONS = 5


def division_um(largest_um: float) -> float:
    """The scale per division (1, 2 or 5 × 10ⁿ µm) that shows ±``largest_um`` within
    four divisions of the ring.

    >>> division_um(3.2), division_um(9.0), division_um(0.03)
    (1.0, 5.0, 0.01)
    """
    need = max(abs(largest_um), 1e-6) / (DIVISIONS - 1)
    exponent = math.floor(math.log10(need))
    for m in (1.0, 2.0, 5.0, 10.0):
        s = m * 10.0**exponent
        if s >= need * (1 - 1e-9):
            return float(f"{s:.6g}")
    return float(f"{10.0 ** (exponent + 1):.6g}")


def polar_figure(tests: Sequence[CircleTest]) -> Figure:
    """One polar plot a circle: both directions, their scale per division in the title, the
    legend under the plot (away from the angle labels)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    n = len(tests)
    cols = min(2, n)
    rows = math.ceil(n / cols)
    fig = Figure(figsize=(4.6 * cols, 5.0 * rows), dpi=100, layout="constrained")
    FigureCanvasAgg(fig)
    for k, t in enumerate(tests):
        ax = cast("PolarAxes", fig.add_subplot(rows, cols, k + 1, projection="polar"))
        largest = max(max(abs(v) for v in d.residual_um) for d in t.directions)
        s = division_um(largest)
        ring = float(DIVISIONS)
        for m, d in enumerate(t.directions):
            th = np.radians(np.asarray(d.angle_deg))
            rr = ring + np.asarray(d.residual_um) / s
            if t.diagnosis.full_circle:
                th, rr = np.r_[th, th[0]], np.r_[rr, rr[0]]
            else:  # an arc: no line across its gap
                order = np.argsort(along_arc(np.degrees(th), t.diagnosis.arc_start_deg))
                th, rr = th[order], rr[order]
            label = f"{d.direction} ({'θ increasing' if d.direction == 'ccw' else 'θ decreasing'})"
            ax.plot(th, rr, linewidth=1.0, color=f"C{m}", label=label)
        grid = np.linspace(0, 2 * np.pi, 361)
        ax.plot(grid, np.full(grid.size, ring), color="0.35", linewidth=0.8, label="zero")
        ax.set_ylim(0, 2 * DIVISIONS)
        ax.set_yticks(np.arange(1, 2 * DIVISIONS + 1))
        ax.set_yticklabels(
            [
                _tick((i - DIVISIONS) * s) if i in (1, DIVISIONS, 2 * DIVISIONS - 1) else ""
                for i in range(1, 2 * DIVISIONS + 1)
            ],
            fontsize=6.5,
        )
        ax.set_rlabel_position(22.5)
        a, b = t.plane[0], t.plane[1]
        ax.set_xticks(np.radians(np.arange(0, 360, 45)))
        ax.set_xticklabels(
            [f"0° +{a}", "45°", f"90° +{b}", "135°", f"180° −{a}", "225°", f"270° −{b}", "315°"],
            fontsize=7.5,
        )
        ax.tick_params(axis="x", pad=2)
        ax.grid(linewidth=0.4, color="0.8")
        G = t.G_bidirectional_um if t.G_bidirectional_um is not None else t.G_um
        label_g = "G(b)" if t.G_bidirectional_um is not None else "G"
        ax.set_title(
            f"{t.name} ({t.plane}, R {t.radius_mm:g} mm): {label_g} {G:.2f} µm\n"
            f"scale {s:g} µm per division",
            fontsize=9,
        )
        ax.legend(
            fontsize=7,
            loc="upper center",
            bbox_to_anchor=(0.5, -0.08),
            ncol=3,
            frameon=False,
        )
    return fig


def _tick(value_um: float) -> str:
    return "0" if value_um == 0 else f"{value_um:+g} µm"
