"""Draw docs/images/conventions.png, the figure of docs/conventions.md.

Run from the repository root: ``python docs/make_conventions_figure.py``. Deterministic:
the same bytes on every run (Agg, no dates in the metadata).
"""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.patches import Arc, FancyArrowPatch  # noqa: E402

OUT = Path(__file__).resolve().parent / "images" / "conventions.png"


def arrow(ax, start, end, colour="0.15", width=1.6, style="-|>", **kw):
    ax.add_patch(
        FancyArrowPatch(
            start, end, arrowstyle=style, mutation_scale=14, color=colour, lw=width, **kw
        )
    )


def text(ax, x, y, s, **kw):
    kw.setdefault("fontsize", 9)
    ax.text(x, y, s, parse_math=False, **kw)


def _p(x, y, z):
    """An oblique view: X to the right, Z up, Y into the page (up and to the right)."""
    return (x + 0.55 * y, z + 0.4 * y)


def rotations(ax):
    """Panel (a): an axis' six error motions and the lever of its angles."""
    ax.set_title("(a) error motions of axis X and the lever of its angles", fontsize=10)
    y0, z0 = 1.0, 0.6
    # the measurement line of X: along X, through the offsets of the later axes (Y0, Z0)
    a, b = _p(0.3, y0, z0), _p(6.5, y0, z0)
    ax.plot([a[0], b[0]], [a[1], b[1]], color="0.55", lw=1.2, ls="--")
    text(ax, *_p(2.4, y0, z0 - 0.5), "measurement line of X (Y = Y0, Z = Z0)", color="0.35")
    pivot = _p(1.6, y0, z0)
    ax.plot(*pivot, "o", color="C3", zorder=5)
    text(ax, pivot[0] - 0.45, pivot[1] + 0.25, "pivot", color="C3")
    # the lever, along the chain from the workpiece to the tool: the later axes, then P
    y, z = 4.2, 3.2
    c1 = _p(1.6, y, z0)
    arrow(ax, pivot, c1, colour="C0")
    text(
        ax, (pivot[0] + c1[0]) / 2 + 0.15, (pivot[1] + c1[1]) / 2 - 0.3, "(Y - Y0) e_Y", color="C0"
    )
    c2 = _p(1.6, y, z)
    arrow(ax, c1, c2, colour="C0")
    text(ax, c2[0] - 1.45, (c1[1] + c2[1]) / 2 + 0.3, "(Z - Z0) e_Z", color="C0")
    tip = _p(2.6, y, z - 0.6)
    arrow(ax, c2, tip, colour="C2")
    text(ax, tip[0] + 0.12, tip[1] + 0.1, "+ P: the tool tip", color="C2")
    arrow(ax, pivot, tip, colour="C3", ls=":")
    text(ax, (pivot[0] + tip[0]) / 2 + 0.75, (pivot[1] + tip[1]) / 2 - 0.2, "lever r", color="C3")
    # the machine axes and a right-handed rotation about +Z
    o = (7.0, 2.6)
    for d, name in (((1.2, 0, 0), "+X"), ((0, 1.6, 0), "+Y"), ((0, 0, 1.2), "+Z")):
        e = _p(*d)
        arrow(ax, o, (o[0] + e[0], o[1] + e[1]))
        text(ax, o[0] + e[0] + 0.05, o[1] + e[1] + 0.05, name)
    centre = (o[0], o[1] + 0.85)
    ax.add_patch(Arc(centre, 1.1, 0.45, theta1=200, theta2=520 - 180, color="C1", lw=1.4))
    arrow(
        ax, (centre[0] - 0.25, centre[1] - 0.2), (centre[0] - 0.1, centre[1] - 0.225), colour="C1"
    )
    text(ax, o[0] - 0.6, o[1] - 0.6, "ECX > 0: right-handed about +Z", color="C1")
    text(
        ax,
        0.2,
        -0.55,
        "displacement at the tip = δ + ε × r\n"
        "δ = (EXX, EYX, EZX) along +X, +Y, +Z; ε = (EAX, EBX, ECX) about +X, +Y, +Z",
        fontsize=8.5,
    )
    ax.set_xlim(0, 9.6)
    ax.set_ylim(-0.8, 5.2)


def squareness(ax):
    """Panel (b): the sign of a squareness."""
    ax.set_title("(b) squareness S_XY > 0 (X before Y in the stack)", fontsize=10)
    o = (1.0, 0.8)
    arrow(ax, o, (6.0, 0.8))
    text(ax, 6.1, 0.7, "+X\n(earlier axis)")
    arrow(ax, o, (1.0, 5.0), colour="0.6")
    text(ax, 0.55, 5.1, "nominal +Y", color="0.45")
    arrow(ax, o, (2.3, 5.0), colour="C0")
    text(ax, 2.4, 5.0, "actual +Y motion", color="C0")
    ax.add_patch(Arc(o, 2.4, 2.4, theta1=72.8, theta2=90, color="C1", lw=1.6))
    text(ax, 1.1, 2.3, "S_XY", color="C1")
    text(ax, 2.0, 1.3, "included angle < 90°", color="0.3")
    text(
        ax,
        0.3,
        -0.35,
        "moving +Y by (Y - Y0) moves the tool\nby S_XY · (Y - Y0) towards +X",
        fontsize=9,
    )
    ax.set_xlim(0, 9)
    ax.set_ylim(-0.8, 5.6)


def main() -> None:
    fig = plt.figure(figsize=(10.0, 4.2), dpi=100)
    axes = fig.subplots(1, 2, gridspec_kw={"width_ratios": [1.15, 1.0]})
    for ax in axes:
        ax.set_aspect("equal")
        ax.axis("off")
    rotations(axes[0])
    squareness(axes[1])
    fig.subplots_adjust(left=0.02, right=0.98, top=0.9, bottom=0.04, wspace=0.08)
    OUT.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(OUT, metadata={"Software": None})
    plt.close(fig)


if __name__ == "__main__":
    main()
