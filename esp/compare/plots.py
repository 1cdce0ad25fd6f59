"""Figures of ``esp compare``: the largest change of every component with its U(Δ) (a change
within U(Δ), En <= 1, drawn faded), the change along the axis of the components that
changed most with the band ±U(Δ) around zero, and their curves before and after."""

from __future__ import annotations

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from esp.compare.model import Comparison, ComponentChange

__all__ = ["change_figure", "changes_figure", "curves_figure"]

_DPI = 100
_UNIT = {"um": "µm", "um/m": "µm/m"}


def _figure(w: float, h: float) -> Figure:
    fig = Figure(figsize=(w, h), dpi=_DPI, layout="constrained")
    FigureCanvasAgg(fig)
    return fig


#: transparency of a bar whose change is within its U(Δ) (En <= 1)
_FADED = 0.3


def _verdict(x: ComponentChange) -> bool | None:
    return None if x.significance is None else x.significance.significant


def changes_figure(title: str, c: Comparison) -> Figure:
    """Bars of max |after - before| per component: displacements (µm) on the left,
    angles and squareness (µm/m) on the right; a significant change (En > 1) solid, one
    within U(Δ) (En <= 1) faded, one whose En is not evaluated hatched grey; U(Δ) where the
    change is largest marked by a black tick."""
    from matplotlib.artist import Artist
    from matplotlib.patches import Patch

    fig = _figure(11.0, 4.8)
    grid = fig.add_gridspec(2, 2, height_ratios=(1.0, 0.07))
    axes = [fig.add_subplot(grid[0, k]) for k in range(2)]
    any_u = False
    for ax, unit in zip(axes, ("um", "um/m"), strict=True):
        items = [x for x in c.components if x.unit == unit]
        colour = "C1" if unit == "um" else "C4"
        y = np.arange(len(items))
        for k, x in enumerate(items):
            verdict = _verdict(x)
            if verdict is None:
                ax.barh(k, x.max_abs_change, color="0.75", hatch="//", edgecolor="0.5")
            else:
                ax.barh(k, x.max_abs_change, color=colour, alpha=1.0 if verdict else _FADED)
            U = x.U_at_max
            if U is not None:
                any_u = True
                ax.plot([U, U], [k - 0.42, k + 0.42], color="black", linewidth=1.6)
        ax.set_yticks(y, [x.name for x in items], fontsize="small")
        ax.invert_yaxis()
        ax.set_xlabel(f"largest |change| ({_UNIT[unit]})")
        ax.grid(True, axis="x", linewidth=0.4, alpha=0.5)
        ax.set_title(
            "displacement components" if unit == "um" else "angular components and squareness",
            fontsize="medium",
        )
    shown = {_verdict(x) for x in c.components}
    handles: list[Artist] = [
        h
        for verdict, h in (
            (True, Patch(color="0.3", label="significant (En > 1)")),
            (False, Patch(color="0.3", alpha=_FADED, label="not significant (En ≤ 1)")),
            (
                None,
                Patch(facecolor="0.75", hatch="//", edgecolor="0.5", label="En not evaluated"),
            ),
        )
        if verdict in shown
    ]
    if any_u:
        from matplotlib.lines import Line2D

        handles.append(Line2D([], [], color="black", label="U(Δ) where the change is largest"))
    if handles:  # in a row of its own below the plots, laid out with them
        key = fig.add_subplot(grid[1, :])
        key.axis("off")
        key.legend(handles=handles, loc="center", ncols=len(handles), fontsize="small")
    fig.suptitle(title, fontsize="medium", parse_math=False)
    return fig


def _most_significant(c: Comparison, unit: str, count: int) -> list[ComponentChange]:
    """The ``count`` components of ``unit`` with a curve, largest En first (largest change
    for those whose En is not evaluated, after them)."""
    items = [x for x in c.components if x.unit == unit and x.positions_mm]

    def key(x: ComponentChange) -> tuple[float, float]:
        en = x.significance.En if x.significance is not None else None
        return (-(en if en is not None else -1.0), -x.max_abs_change)

    return sorted(items, key=key)[:count]


def change_figure(title: str, c: Comparison, count: int = 3) -> Figure:
    """The change after - before along the axis of the ``count`` components of each unit
    with the largest En, with the band ±U(Δ) around zero: where the change leaves the band
    it is significant (En > 1)."""
    chosen = [_most_significant(c, unit, count) for unit in ("um", "um/m")]
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
            pos = np.asarray(x.positions_mm)
            delta = np.asarray(x.after) - np.asarray(x.before)
            if x.U_change:
                band = np.asarray(x.U_change)
                ax.fill_between(pos, -band, band, color="0.85", label="±U(Δ)", linewidth=0)
            ax.axhline(0.0, color="0.5", linewidth=0.6)
            ax.plot(pos, delta, color="C3", marker=".", markersize=3, label="after − before")
            s = x.significance
            if s is None or s.En is None:
                what = "En not evaluated"
            else:
                what = f"En = {s.En:.2f}, " + ("significant" if s.En > 1.0 else "not significant")
            ax.set_title(f"{x.name}: {what}", fontsize="small")
            ax.set_xlabel(f"{x.name.split('.')[0]} position (mm)")
            ax.set_ylabel(f"change ({_UNIT[x.unit]})")
            ax.grid(True, linewidth=0.4, alpha=0.5)
            ax.legend(fontsize="x-small")
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
