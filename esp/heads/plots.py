"""Figures of ``esp head`` and its report folder (``--out DIR``).

Every builder takes an :class:`esp.heads.ErrorMap` and returns a
:class:`matplotlib.figure.Figure` on the Agg canvas (no pyplot, no global state):

* :func:`surface_figure` -- DX, DY, DZ and |D| as surfaces over the two angles (the
  presentation of Freeman & Ford 2003, Fig. 3);
* :func:`contour_figure` -- the same as filled contour maps, the extremes marked;
* :func:`second_order_figure` -- the size of the second-order terms and of the exact
  chain's departure from the first order, over the same grid;
* :func:`terms_figure` -- each error's contribution at the setting of the largest |D|.

:func:`write_head_report` writes them as PNG and, with the document of
:func:`head_document` (the shared style of :mod:`esp.report.document`), as ``head.pdf``,
with ``result.json``. The bytes are deterministic: no software version or date in the
PNG, no creation date in the PDF; the date printed follows ``SOURCE_DATE_EPOCH``.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from esp.heads.maps import ErrorMap
from esp.heads.text import unit_text
from esp.report.drawing import save_png

if TYPE_CHECKING:
    from matplotlib.axes import Axes

    from esp.core.devices.head import Head
    from esp.report.document import Document
    from esp.report.provenance import Provenance

__all__ = [
    "contour_figure",
    "figure_files",
    "pdf_metadata",
    "second_order_figure",
    "head_document",
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
    ax: Axes,
    m: ErrorMap,
    values: np.ndarray,
    label: str,
    fig: Figure,
    cmap: str,
    signed: bool = False,
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
            extent=(*_extent(m.rows), *_extent(m.cols)),
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


def _mark(ax: Axes, m: ErrorMap, index: int, marker: str) -> None:
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


def _span(v: np.ndarray) -> str:
    if v.size == 1:
        return f"{v[0]:g}°"
    step = (v[-1] - v[0]) / (v.size - 1)
    return f"{v[0]:g}° to {v[-1]:g}° step {step:g}°"


def _fixed(x: float, digits: int = 3) -> str:
    s = f"{x:.{digits}f}"
    return s[1:] if s.startswith("-") and float(s) == 0 else s


def _head_values(head: Head) -> list[tuple[str, str]]:
    def value(name: str, v: float) -> str:
        unit = unit_text(head.unit(name))
        return f"{name} = {v:.6g}{unit}" if unit == "°" else f"{name} = {v:.6g} {unit}"

    rows = []
    if head.chain.name != head.name:
        rows.append(("Chain", head.chain.name))
    params = [value(n, v) for n, v in head.parameters.items()]
    if params:
        rows.append(("Parameters", ", ".join(params)))
    errs = [value(n, v) for n, v in head.errors.items() if v != 0]
    zero = [n for n, v in head.errors.items() if v == 0]
    rows.append(("Errors", ", ".join(errs) if errs else "all zero"))
    if errs and zero:
        rows.append(("Zero", ", ".join(zero)))
    if any(v != 0 for v in head.mcp_mm):
        rows.append(("MCP", "(" + ", ".join(f"{v:g}" for v in head.mcp_mm) + ") mm, chain frame"))
    return rows


def head_document(
    m: ErrorMap, date: str, provenance: Provenance | None = None
) -> tuple[Document, dict[str, str]]:
    """The document of a head's error map (:class:`esp.report.document.Document`): the
    summary (largest |D|, the range of each direction, the second order against the
    first), the head and its errors, the extremes, the setting of the largest |D| with the
    breakdown of its error, then the figures with captions."""
    from esp.heads.jsondoc import share_pct
    from esp.heads.text import NEGLIGIBLE_PCT, settings_text
    from esp.report.document import Document, Headline, title_fields
    from esp.report.tables import Column, Table

    head = m.head
    ev = m.evaluation
    doc = Document("Servo head error map", head.name, date, title_fields(provenance=provenance))
    lay = doc.lay
    ext = m.extremes()
    worst = ext["D"]["max"]
    so = m.second_order_peak()
    ex = m.exact_residual_peak()
    pct = share_pct(so.value_um, worst.value_um)
    lines = [
        Headline("Largest |D|", f"{_fixed(worst.value_um)} µm", None),
    ]
    for a in ("X", "Y", "Z"):
        lo, hi = ext[a]["min"], ext[a]["max"]
        lines.append(Headline(f"Range of D{a}", f"{_fixed(hi.value_um - lo.value_um)} µm"))
    lines.append(Headline("Largest second-order term", f"{so.value_um:.3g} µm"))
    from esp.report.document import summary

    summary(lay, lines)
    lay.paragraph(f"The largest |D| is at {settings_text(worst.at, '°')}.")
    if pct is not None:
        enough = "enough" if pct < NEGLIGIBLE_PCT else "not enough"
        lay.paragraph(
            f"The second-order terms reach {pct:.3g} % of the largest |D|: the first order "
            f"is {enough} (below {NEGLIGIBLE_PCT:g} % counts as enough). The exact chain "
            f"departs from the first order by at most {ex.value_um:.3g} µm "
            f"(at {settings_text(ex.at, '°')})."
        )
    lay.paragraph(
        "Uncertainty: not evaluated (esp head evaluates the errors as given).",
        size=8.3,
        colour="0.3",
    )
    doc.section("Head and errors")
    what = "first plus second order" if m.order == 2 else "first order"
    lay.pairs(
        _head_values(head)
        + [
            (
                "Map",
                f"{m.names[0]} {_span(m.rows)}, {m.names[1]} {_span(m.cols)} "
                f"({m.rows.size * m.cols.size} settings), {what} error at the tool tip",
            )
        ]
    )
    doc.section("Extremes over the map")
    rows = []
    for a in ("X", "Y", "Z"):
        lo, hi = ext[a]["min"], ext[a]["max"]
        rows.append(
            (
                "D" + a,
                _fixed(lo.value_um),
                "   " + settings_text(lo.at, "°"),
                _fixed(hi.value_um),
                "   " + settings_text(hi.at, "°"),
                _fixed(hi.value_um - lo.value_um),
            )
        )
    lay.table(
        Table(
            (
                Column("", "left", 0.5),
                Column("min (µm)", "right", 0.95),
                Column("   at", "left", 1.5),
                Column("max (µm)", "right", 0.95),
                Column("   at", "left", 1.5),
                Column("range (µm)", "right", 1.0),
            ),
            tuple(rows),
        )
    )
    i = m.worst_index()
    doc.section(f"At the largest |D| ({settings_text(m.at(i), '°')})")
    lay.paragraph("The tool tip relative to the MCP, in the machine's axes.", size=8.3)

    def row(label: str, v: np.ndarray, digits: int = 3) -> tuple[str, ...]:
        return (label, *(_fixed(float(v[k]), digits) for k in range(3)))

    point = [row("nominal tip (mm)", ev.nominal_mm[i], 4), row("tool axis", ev.tool_axis[i], 6)]
    point.append(row("first order (µm)", ev.first_um[i]))
    if m.order == 2 and ev.second_um is not None:
        point.append(row("second order (µm)", ev.second_um[i], 6))
        point.append(row("first + second (µm)", ev.first_um[i] + ev.second_um[i]))
    if np.all(np.isfinite(ev.exact_um[i])):
        point.append(row("exact (µm)", ev.exact_um[i]))
    point.append(row("tool axis tilt (µrad)", ev.tilt_urad[i]))
    lay.table(
        Table(
            (Column("", "left", 2.0),) + tuple(Column(a, "right", 1.2) for a in ("X", "Y", "Z")),
            tuple(point),
        )
    )
    lay.heading("Breakdown of the first-order error", level=2)
    if not ev.terms:
        lay.paragraph("No error has a value: the error is zero.")
    else:
        first = ev.first_um[i]
        body = []
        for t in ev.terms:
            cells: list[str] = [t.name, f"{t.value:.6g} {unit_text(t.unit)}"]
            for k in range(3):
                share = share_pct(float(t.error_um[i, k]), float(first[k]))
                cells.append(_fixed(float(t.error_um[i, k])))
                cells.append("" if share is None else f"{0.0 if abs(share) < 0.05 else share:.1f}")
            body.append(tuple(cells))
        body.append(("total", "", *(c for k in range(3) for c in (_fixed(float(first[k])), ""))))
        columns = [Column("error", "left", 1.1), Column("value", "right", 1.1)]
        for a in ("X", "Y", "Z"):
            columns += [Column(f"D{a} (µm)", "right", 0.85), Column("share %", "right", 0.67)]
        lay.table(Table(tuple(columns), tuple(body)))
        lay.paragraph(
            "share: the error's signed share of its direction's total at this setting (the "
            "shares of a direction add up to 100 %; errors of opposite sign can make a "
            "share above 100 % or below 0 %).",
            size=8.3,
            colour="0.3",
        )
    captions = {
        "surfaces.png": "DX, DY, DZ and |D| over the two angles (as Freeman & Ford 2003, Fig. 3)",
        "contours.png": "the same as contour maps, the minimum and maximum of each marked",
        "second-order.png": "the second-order terms and the exact chain's departure from "
        "the first order",
        "terms.png": "each error's first-order contribution at the setting of the largest |D|",
    }
    return doc, captions


def pdf_metadata(m: ErrorMap) -> dict[str, Any]:
    """The PDF's document information: fixed text, no creation date."""
    from esp.report.document import metadata

    return metadata(f"Servo head error map: {m.head.name}")


def write_head_report(
    folder: str | Path,
    m: ErrorMap,
    text: str,
    json_text: str,
    date: str | None = None,
    provenance: Provenance | None = None,
) -> list[str]:
    """Write ``result.json``, ``summary.txt``, every figure as PNG and ``head.pdf`` (the
    document of :func:`head_document`, then the figures, then the provenance) into
    ``folder`` (a staging folder of :class:`esp.io.outputs.Outputs`); return the file
    names written."""
    from esp.report.epoch import report_date

    folder = Path(folder)
    date = date or report_date()
    (folder / "result.json").write_text(json_text, encoding="utf-8")
    (folder / "summary.txt").write_text(text, encoding="utf-8")
    written = ["result.json", "summary.txt"]
    doc, captions = head_document(m, date, provenance)
    for name, build in figure_files(m):
        fig = build()
        save_png(fig, folder / name, DPI)
        written.append(name)
        doc.figure(fig, captions.get(name, name))
    doc.write(folder / "head.pdf", provenance)
    written.append("head.pdf")
    return written
