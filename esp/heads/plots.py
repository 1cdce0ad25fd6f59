"""Figures of ``esp head`` and its report folder (``--out DIR``).

Every builder takes an :class:`esp.heads.ErrorMap` and returns a
:class:`matplotlib.figure.Figure` on the Agg canvas (no pyplot, no global state):

* :func:`surface_figure` -- DX, DY, DZ and |D| as surfaces over the two angles (the
  presentation of Freeman & Ford 2003, Fig. 3);
* :func:`contour_figure` -- the same as filled contour maps, the extremes marked;
* :func:`second_order_figure` -- the size of the second-order terms and of the exact
  chain's departure from the first order, over the same grid;
* :func:`terms_figure` -- each error's contribution at the setting of the largest |D|.

:func:`write_head_report` writes them as PNG and as pages of one PDF after the text
summary, with ``result.json``. The bytes are deterministic: no software version or date in
the PNG, no creation date in the PDF; the date on the summary pages follows
``SOURCE_DATE_EPOCH``.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.backends.backend_pdf import PdfPages
from matplotlib.figure import Figure

from esp._version import __version__
from esp.heads.maps import ErrorMap
from esp.heads.text import unit_text
from esp.report.drawing import save_png

__all__ = [
    "contour_figure",
    "figure_files",
    "pdf_metadata",
    "second_order_figure",
    "summary_pages",
    "surface_figure",
    "terms_figure",
    "write_head_report",
]

DPI = 100
_LABELS = ("DX", "DY", "DZ", "|D|")
_COLOURS = ("C0", "C1", "C2")


def _figure(width_in: float, height_in: float) -> Figure:
    fig = Figure(figsize=(width_in, height_in), dpi=DPI)
    FigureCanvasAgg(fig)
    return fig


def _quantities(m: ErrorMap) -> list[np.ndarray]:
    err = m.error_um
    return [err[..., 0], err[..., 1], err[..., 2], m.magnitude_um]


def _order_words(m: ErrorMap) -> str:
    return "first- plus second-order" if m.order == 2 else "first-order"


def _title(m: ErrorMap, what: str) -> str:
    return f"{m.head.name}: {what}"


def _mesh(m: ErrorMap) -> tuple[np.ndarray, np.ndarray]:
    """X (first angle) and Y (second angle) over the grid, shape (n1, n2)."""
    return np.meshgrid(m.rows, m.cols, indexing="ij")


def surface_figure(m: ErrorMap) -> Figure:
    """DX, DY, DZ and |D| (µm) as surfaces over the two angles."""
    fig = _figure(11.0, 8.5)
    fig.subplots_adjust(left=0.0, right=0.97, bottom=0.03, top=0.9, wspace=0.0, hspace=0.1)
    a1, a2 = _mesh(m)
    for k, (label, values) in enumerate(zip(_LABELS, _quantities(m), strict=True)):
        ax = fig.add_subplot(2, 2, k + 1, projection="3d")
        ax.plot_surface(
            a1,
            a2,
            values,
            cmap="viridis",
            rcount=min(values.shape[0], 25),
            ccount=min(values.shape[1], 25),
            linewidth=0.25,
            edgecolor="0.25",
            antialiased=False,
        )
        ax.set_xlabel(f"{m.names[0]} (°)", parse_math=False, fontsize=8)
        ax.set_ylabel(f"{m.names[1]} (°)", parse_math=False, fontsize=8)
        ax.set_zlabel(f"{label} (µm)", parse_math=False, fontsize=8)
        ax.tick_params(labelsize=7)
        ax.view_init(elev=28, azim=-58)
        lo, hi = float(values.min()), float(values.max())
        ax.set_title(f"{label}: {lo:.3f} to {hi:.3f} µm", parse_math=False, fontsize=9)
        if hi - lo < 1e-9 * max(1.0, abs(hi)):
            ax.set_zlim(lo - 0.5, hi + 0.5)
    fig.suptitle(
        _title(m, f"{_order_words(m)} error of the tool tip over {m.names[0]} and {m.names[1]}"),
        fontsize=11,
        parse_math=False,
    )
    return fig


def _extent(v: np.ndarray) -> tuple[float, float]:
    if v.size == 1:
        return float(v[0]) - 0.5, float(v[0]) + 0.5
    return float(v[0]), float(v[-1])


def _contours(
    ax, m: ErrorMap, values: np.ndarray, label: str, fig: Figure, cmap: str, signed: bool = False
) -> None:
    """Filled contours with labelled lines; ``signed``: a diverging map, white at zero."""
    from matplotlib.ticker import MaxNLocator

    a1, a2 = _mesh(m)
    lo, hi = float(values.min()), float(values.max())
    if signed:
        top = max(abs(lo), abs(hi))
        lo, hi = -top, top
    if hi - lo < 1e-12 * max(1.0, abs(hi)) or min(values.shape) < 2:
        image = ax.imshow(
            values.T,
            origin="lower",
            aspect="auto",
            cmap=cmap,
            extent=[*_extent(m.rows), *_extent(m.cols)],
            vmin=lo - 0.5 if hi == lo else lo,
            vmax=hi + 0.5 if hi == lo else hi,
        )
        fig.colorbar(image, ax=ax, label=f"{label} (µm)", fraction=0.05, pad=0.02)
        return
    levels = MaxNLocator(nbins=16 if signed else 12, symmetric=signed).tick_values(lo, hi)
    filled = ax.contourf(a1, a2, values, levels=levels, cmap=cmap)
    lines = ax.contour(a1, a2, values, levels=levels[1:-1:2], colors="k", linewidths=0.4)
    ax.clabel(lines, fontsize=6, fmt="%g")
    bar = fig.colorbar(filled, ax=ax, fraction=0.05, pad=0.02)
    bar.set_label(f"{label} (µm)", parse_math=False)
    bar.ax.tick_params(labelsize=7)


def _mark(ax, m: ErrorMap, index: int, marker: str) -> None:
    at = m.at(index)
    ax.plot(
        at[m.names[0]],
        at[m.names[1]],
        marker=marker,
        color="w",
        markeredgecolor="k",
        markersize=8,
        linestyle="none",
        clip_on=False,
        zorder=5,
    )


def contour_figure(m: ErrorMap) -> Figure:
    """DX, DY, DZ and |D| as contour maps (DX, DY, DZ white at zero); the minimum (▽) and
    maximum (△) marked."""
    fig = _figure(11.0, 8.5)
    fig.subplots_adjust(left=0.07, right=0.95, bottom=0.07, top=0.9, wspace=0.42, hspace=0.32)
    quantities = _quantities(m)
    for k, (label, values) in enumerate(zip(_LABELS, quantities, strict=True)):
        ax = fig.add_subplot(2, 2, k + 1)
        _contours(ax, m, values, label, fig, "RdBu_r" if k < 3 else "viridis", signed=k < 3)
        flat = values.ravel()
        marks = [("max", int(np.argmax(flat)), "^")]
        if k < 3:
            marks.insert(0, ("min", int(np.argmin(flat)), "v"))
        title = []
        for kind, idx, marker in marks:
            _mark(ax, m, idx, marker)
            title.append(f"{kind} {flat[idx]:.3f} µm")
        ax.set_title(f"{label}: " + ", ".join(title), parse_math=False, fontsize=9)
        ax.set_xlabel(f"{m.names[0]} (°)", parse_math=False)
        ax.set_ylabel(f"{m.names[1]} (°)", parse_math=False)
    fig.suptitle(
        _title(m, f"{_order_words(m)} error of the tool tip (µm); ▽ minimum, △ maximum"),
        fontsize=11,
        parse_math=False,
    )
    return fig


def second_order_figure(m: ErrorMap) -> Figure:
    """|second-order terms| and |exact − first order| over the grid (µm)."""
    fig = _figure(11.0, 4.8)
    fig.subplots_adjust(left=0.07, right=0.94, bottom=0.12, top=0.82, wspace=0.45)
    peak = float(m.magnitude_um.max())
    panels = (
        ("|second-order terms|", np.linalg.norm(m.second_um, axis=-1)),
        ("|exact − first order|", np.linalg.norm(m.exact_minus_first_um, axis=-1)),
    )
    for k, (label, values) in enumerate(panels):
        ax = fig.add_subplot(1, 2, k + 1)
        _contours(ax, m, values, label, fig, "magma")
        _mark(ax, m, int(np.argmax(values.ravel())), "^")
        top = float(values.max())
        pct = f" ({100 * top / peak:.3g} % of the largest |D|)" if peak > 0 else ""
        ax.set_title(f"{label}: largest {top:.3g} µm{pct}", parse_math=False, fontsize=8.5)
        ax.set_xlabel(f"{m.names[0]} (°)", parse_math=False)
        ax.set_ylabel(f"{m.names[1]} (°)", parse_math=False)
    fig.suptitle(
        _title(m, "how far the second order and the exact chain depart from the first order"),
        fontsize=11,
        parse_math=False,
    )
    return fig


def terms_figure(m: ErrorMap) -> Figure:
    """Each error's first-order contribution to DX, DY, DZ at the largest |D|."""
    ev = m.evaluation
    i = m.worst_index()
    at = m.at(i)
    fig = _figure(10.0, 5.2)
    fig.subplots_adjust(left=0.16, right=0.97, bottom=0.11, top=0.86)
    ax = fig.add_subplot(1, 1, 1)
    terms = list(ev.terms)
    if terms:
        terms.sort(key=lambda t: float(np.linalg.norm(t.error_um[i])))
        y = np.arange(len(terms))
        height = 0.8 / 3
        for d, colour in enumerate(_COLOURS):
            ax.barh(
                y + (d - 1) * height,
                [float(t.error_um[i, d]) for t in terms],
                height=height,
                color=colour,
                label=_LABELS[d],
            )
        labels = [f"{t.name} = {t.value:g} {unit_text(t.unit)}" for t in terms]
        ax.set_yticks(y, labels, fontsize=8)
        ax.axvline(0.0, color="0.4", linewidth=0.6)
        ax.legend(loc="lower right", fontsize=8)
    else:
        ax.text(0.5, 0.5, "no error has a value", ha="center", va="center", parse_math=False)
        ax.set_yticks([])
    ax.set_xlabel("contribution to the tool tip error (µm)", parse_math=False)
    ax.grid(True, axis="x", linewidth=0.4, alpha=0.6)
    e = ev.first_um[i]
    where = ", ".join(f"{c} = {v:g}°" for c, v in at.items())
    ax.set_title(
        f"first order at the largest |D| ({where}): D = ({e[0]:.3f}, {e[1]:.3f}, {e[2]:.3f}) µm",
        fontsize=10,
        parse_math=False,
    )
    fig.suptitle(_title(m, "terms of the first-order error"), fontsize=11, parse_math=False)
    return fig


def figure_files(m: ErrorMap) -> list[tuple[str, Callable[[], Figure]]]:
    """(file name, builder) of every figure of the report, in order."""
    return [
        ("surfaces.png", lambda: surface_figure(m)),
        ("contours.png", lambda: contour_figure(m)),
        ("second-order.png", lambda: second_order_figure(m)),
        ("terms.png", lambda: terms_figure(m)),
    ]


_LINES_PER_PAGE = 70
#: characters per line of the text pages
_WIDTH = 110


def summary_pages(text: str, date: str) -> list[Figure]:
    """The text summary on A4 portrait pages (monospaced)."""
    import textwrap

    lines = []
    for line in text.rstrip("\n").split("\n"):
        indent = " " * (len(line) - len(line.lstrip()) + 4)
        lines.extend(textwrap.wrap(line, _WIDTH, subsequent_indent=indent) or [""])
    chunks = [lines[i : i + _LINES_PER_PAGE] for i in range(0, len(lines), _LINES_PER_PAGE)]
    pages = []
    for n, chunk in enumerate(chunks, start=1):
        fig = _figure(8.27, 11.69)
        fig.text(
            0.05,
            0.97,
            "\n".join(chunk),
            family="monospace",
            fontsize=7.2,
            va="top",
            parse_math=False,
        )
        fig.text(
            0.5,
            0.02,
            f"esp {__version__} head, {date}, page {n} of {len(chunks)}",
            ha="center",
            fontsize=7,
            color="0.4",
            parse_math=False,
        )
        pages.append(fig)
    return pages


def pdf_metadata(m: ErrorMap) -> dict:
    """The PDF's document information: fixed text, no creation date."""
    return {
        "Title": f"esp head: {m.head.name}",
        "Creator": f"esp {__version__}",
        "Producer": f"esp {__version__}",
        "CreationDate": None,
    }


def write_head_report(
    folder: str | Path, m: ErrorMap, text: str, json_text: str, date: str | None = None
) -> list[str]:
    """Write ``result.json``, ``summary.txt``, every figure as PNG and ``head.pdf`` (the
    text summary, then the figures) into ``folder`` (a staging folder of
    :class:`esp.io.outputs.Outputs`); return the file names written."""
    from esp.report.pdf import report_date

    folder = Path(folder)
    date = date or report_date()
    (folder / "result.json").write_text(json_text, encoding="utf-8")
    (folder / "summary.txt").write_text(text, encoding="utf-8")
    written = ["result.json", "summary.txt"]
    figures = []
    for name, build in figure_files(m):
        fig = build()
        save_png(fig, folder / name, DPI)
        written.append(name)
        figures.append(fig)
    with PdfPages(folder / "head.pdf", metadata=pdf_metadata(m)) as pdf:
        for page in summary_pages(text, date):
            pdf.savefig(page)
        for fig in figures:
            fig.set_size_inches(11.69, 8.27)
            pdf.savefig(fig)
    written.append("head.pdf")
    return written
