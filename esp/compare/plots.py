"""Figures of ``esp compare``: the largest change of every component, and the curves of
the components that changed most, before and after."""

from __future__ import annotations

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from esp.compare.model import Comparison

__all__ = ["changes_figure", "curves_figure"]

_DPI = 100
_UNIT = {"um": "µm", "um/m": "µm/m"}


def _figure(w: float, h: float) -> Figure:
    fig = Figure(figsize=(w, h), dpi=_DPI, layout="constrained")
    FigureCanvasAgg(fig)
    return fig


def changes_figure(title: str, c: Comparison) -> Figure:
    """Bars of max |after - before| per component: displacements (µm) on the left,
    angles and squareness (µm/m) on the right."""
    fig = _figure(11.0, 4.6)
    axes = fig.subplots(1, 2)
    for ax, unit in zip(axes, ("um", "um/m"), strict=True):
        items = [x for x in c.components if x.unit == unit]
        names = [x.name for x in items]
        values = [x.max_abs_change for x in items]
        y = np.arange(len(items))
        ax.barh(y, values, color="C1" if unit == "um" else "C4")
        ax.set_yticks(y, names, fontsize="small")
        ax.invert_yaxis()
        ax.set_xlabel(f"largest |change| ({_UNIT[unit]})")
        ax.grid(True, axis="x", linewidth=0.4, alpha=0.5)
        ax.set_title(
            "displacement components" if unit == "um" else "angular components and squareness",
            fontsize="medium",
        )
    fig.suptitle(title, fontsize="medium", parse_math=False)
    return fig


def curves_figure(title: str, c: Comparison, count: int = 3) -> Figure:
    """Before and after curves of the ``count`` components of each unit that changed
    most (squareness has no curve)."""
    chosen = []
    for unit in ("um", "um/m"):
        items = [x for x in c.components if x.unit == unit and x.positions_mm]
        items.sort(key=lambda x: -x.max_abs_change)
        chosen.append(items[:count])
    cols = max(1, max(len(r) for r in chosen))
    fig = _figure(3.6 * cols, 6.2)
    axes = np.atleast_2d(fig.subplots(2, cols, squeeze=False))
    for r, items in enumerate(chosen):
        for k in range(cols):
            ax = axes[r, k]
            if k >= len(items):
                ax.set_visible(False)
                continue
            x = items[k]
            ax.plot(x.positions_mm, x.before, color="0.4", label="before")
            ax.plot(x.positions_mm, x.after, color="C3", label="after")
            ax.set_title(
                f"{x.name}: max change {x.max_abs_change:.2f} {_UNIT[x.unit]}", fontsize="small"
            )
            ax.set_xlabel(f"{x.name.split('.')[0]} position (mm)")
            ax.set_ylabel(_UNIT[x.unit])
            ax.grid(True, linewidth=0.4, alpha=0.5)
            ax.legend(fontsize="x-small")
    fig.suptitle(title, fontsize="medium", parse_math=False)
    return fig
