"""The report folder of ``esp iso230-2 --out DIR``: an ISO 230-2 test report.

``report.pdf`` (the document style of every esp report, :mod:`esp.report.document`): the
title block (the axis and the file's USER-TEXT), the summary of the axis figures A, B, E,
M and R with their direction, how the test was run, the table of every target (mean
positional deviation, standard uncertainty and repeatability per direction, reversal
value), the error plot, then the provenance; with ``iso230.png`` (the error plot) and
``result.json`` (the statistics and the provenance). The figures are those of ISO 230-2:2014,
clauses 3 and 5 (via :func:`esp.iso230.positioning.iso230_2`).
"""

from __future__ import annotations

from pathlib import Path, PurePath
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from collections.abc import Sequence

    from esp.core.conformity import Decision
    from esp.iso230.positioning import Iso230Result
    from esp.iso230.statement import Iso230Uncertainty
    from esp.iso230.vdi3441 import Vdi3441Result
    from esp.report.document import Document
    from esp.report.provenance import Provenance

__all__ = ["iso230_document", "write_iso230_report"]

#: the ISO 230-2 figures in the summary: (key, figure, direction)
_SUMMARY = (
    ("A", "Accuracy of positioning A", "bidirectional"),
    ("A_up", "Accuracy of positioning A up", "up (forward)"),
    ("A_down", "Accuracy of positioning A down", "down (backward)"),
    ("B", "Reversal value B", "largest |B_i|"),
    ("B_mean", "Mean reversal value B mean", "mean of B_i"),
    ("E", "Systematic positional deviation E", "bidirectional"),
    ("E_up", "Systematic positional deviation E up", "up (forward)"),
    ("E_down", "Systematic positional deviation E down", "down (backward)"),
    ("M", "Mean bidirectional positional deviation M", "range"),
    ("R", "Repeatability of positioning R", "bidirectional"),
    ("R_up", "Repeatability of positioning R up", "up (forward)"),
    ("R_down", "Repeatability of positioning R down", "down (backward)"),
)

_HEADERS = {
    "position_mm": "target (mm)",
    "position_deg": "target (°)",
    "mean_up": "mean up ({u})",
    "mean_down": "mean down ({u})",
    "s_up": "s up ({u})",
    "s_down": "s down ({u})",
    "B": "B_i ({u})",
    "R_up": "R up ({u})",
    "R_down": "R down ({u})",
    "R": "R_i ({u})",
}


def _num(v: float | None) -> str:
    if v is None:
        return ""
    s = f"{v:.3f}"
    return s[1:] if s.startswith("-") and float(s) == 0 else s


def iso230_document(
    result: Iso230Result,
    date: str,
    provenance: Provenance | None = None,
    vdi: Vdi3441Result | None = None,
    conditions: Sequence[tuple[str, str]] = (),
    u: Iso230Uncertainty | None = None,
    decided: Sequence[Decision] = (),
) -> Document:
    """The :class:`~esp.report.document.Document` of an ISO 230-2 result (its figure is
    added by the caller): with the test conditions, each figure's U when evaluated and the
    decisions against tolerances (:mod:`esp.iso230.statement`)."""
    from esp.core.rounding import rounded
    from esp.iso230.text import AXIS_DESCRIPTIONS
    from esp.report.document import (
        Document,
        Headline,
        summary,
        title_fields,
        user_text_value,
    )
    from esp.report.tables import Column, Table

    name = PurePath(result.source).name if result.source else "positioning test"
    kind = "rotary axis" if result.rotary else "linear axis"
    axis = f"{result.axis} axis" if result.axis else kind
    found = user_text_value(provenance, ("machine", "machine name"))
    machine = f"{found}, " if found else ""
    doc = Document(
        "ISO 230-2 positioning test report",
        f"{machine}{axis}: {name}",
        date,
        title_fields(provenance=provenance),
    )
    lay = doc.lay
    values = result.axis_values()
    evaluated = u is not None and not u.missing
    unit = result.value_label

    verdicts = {d.quantity: d.verdict for d in decided}

    def headline(key: str, figure: str) -> Headline:
        big_u = u.get(key) if evaluated and u is not None else None
        verdict = verdicts.get(key)
        if big_u is None:
            return Headline(figure, f"{_num(values[key])} {unit}", verdict)
        v_text, u_text = rounded(values[key], big_u)
        said = f"U = {u_text} {unit} (k = 2, about 95 %)" + (f"; {verdict}" if verdict else "")
        return Headline(figure, f"{v_text} {unit}", said)

    lines = [
        headline(key, figure)
        for key, figure, _ in _SUMMARY
        if key in values and key in ("A", "A_up", "A_down", "B", "E", "M", "R")
    ]
    summary(lay, lines)
    if evaluated and u is not None:
        lay.paragraph(
            f"U: expanded uncertainty, k = 2 (about 95 %), from the contributors of ISO "
            f"230-2:2014 Annex A over the travel of {result.position_text(u.length_mm)} (the "
            "budget below).",
            size=8.3,
            colour="0.3",
        )
    else:
        missing = "; ".join(u.missing) if u is not None else "no instrument stated"
        lay.paragraph(f"Uncertainty: not evaluated (missing: {missing}).", size=8.3, colour="0.3")
    doc.section("The test")
    runs = ", ".join(
        f"{n} {d} ({'forward' if d == 'up' else 'backward'})" for d, n in result.runs.items()
    )
    kind = "bidirectional" if result.bidirectional else "unidirectional"
    lay.pairs(
        [
            ("Axis", axis),
            ("Data file", name),
            ("Runs", f"{runs}; {kind}"),
            (
                "Targets",
                f"{len(result.targets_mm)}, from {result.targets_mm[0]:g} to "
                f"{result.position_text(result.targets_mm[-1])}",
            ),
            (
                "Standard",
                "ISO 230-2:2014; up are the forward runs, down the backward runs; deviations in "
                + unit,
            ),
            *conditions,
        ]
    )
    if min(result.runs.values()) < 5:
        lay.paragraph(
            "ISO 230-2 asks for 5 runs in each direction; fewer were measured.", colour="C3"
        )
    for note in result.notes:
        lay.paragraph("Note: " + note, size=8.3)
    doc.section("Axis figures")
    lay.table(
        Table(
            (
                Column("figure", "left", 2.9),
                Column("", "left", 0.65),
                Column(f"value ({unit})", "right", 1.0),
                Column(f"U ({unit})", "right", 0.8),
                Column("   direction", "left", 2.0),
            ),
            tuple(
                (
                    figure,
                    key,
                    _num(values[key]),
                    f"{u.get(key):.2f}" if evaluated and u is not None and u.get(key) else "",
                    "   " + direction,
                )
                for key, figure, direction in _SUMMARY
                if key in values
            ),
        )
    )
    lay.paragraph(
        "; ".join(f"{k}: {AXIS_DESCRIPTIONS[k]}" for k in ("A", "B", "E", "M", "R") if k in values)
        + ".",
        size=8.3,
        colour="0.3",
    )
    if evaluated and u is not None:
        lay.heading("Measurement uncertainty", level=2)
        budgets: dict[tuple, list[str]] = {}
        for key, fu in u.figures.items():
            budgets.setdefault(fu.budget, []).append(key)
        budget_rows = []
        for budget, keys in budgets.items():
            for i, (name, std) in enumerate(budget):
                budget_rows.append((", ".join(keys) if i == 0 else "", name, f"{std:.3f}"))
        lay.table(
            Table(
                (
                    Column("figures", "left", 2.5),
                    Column("contributor", "left", 3.2),
                    Column(f"u ({unit})", "right", 0.9),
                ),
                tuple(budget_rows),
            )
        )
        lay.paragraph(
            "U is twice the root-sum-square of the u. A, E and M are spans over the "
            "travel: every term of the instrument enters. B is a difference at one target "
            "(the terms that grow with the travel cancel; its type A term is the spread of "
            "the mean reversal). R is the runs' scatter, which the environmental variation "
            "inflates; the sampling variability of s itself belongs to the statistic as "
            "ISO 230-2 defines it.",
            size=8.3,
            colour="0.3",
        )
    if decided:
        lay.heading("Decisions against tolerances", level=2)
        for d in decided:
            value_text = (
                f"{rounded(d.value, d.expanded)[0]} {unit}"
                if d.expanded is not None
                else f"{d.value:.3f} {unit}"
            )
            lay.paragraph(d.text(value_text), size=8.6)
    if vdi is not None:
        lay.heading("VDI/DGQ 3441 (1977)", level=2)
        rows: list[tuple[str, str, float | None]] = [
            ("P", "position uncertainty", vdi.P),
            ("Pa", "positional deviation", vdi.Pa),
        ]
        if vdi.U is not None:
            rows += [("U", "reversal span (max)", vdi.U), ("U", "reversal span (mean)", vdi.U_mean)]
        rows += [("Ps", "positional scatter (max)", vdi.Ps_max)]
        rows += [("Ps", "positional scatter (mean)", vdi.Ps_mean)]
        lay.table(
            Table(
                (
                    Column("", "left", 0.6),
                    Column("figure", "left", 3.0),
                    Column("value (µm)", "right", 1.0),
                ),
                tuple((a, b, _num(c)) for a, b, c in rows),
            )
        )
    doc.section("Every target")
    targets = result.target_rows()
    keys = list(targets[0])
    width = 6.77 / len(keys)
    lay.table(
        Table(
            tuple(Column(_HEADERS.get(k, k).format(u=unit), "right", width) for k in keys),
            tuple(
                (f"{row[result.position_key]:.3f}", *(_num(row[k]) for k in keys[1:]))
                for row in targets
            ),
        )
    )
    lay.paragraph(
        "mean: mean positional deviation; s: estimator of the standard uncertainty of "
        "positioning; R up, R down: repeatability of positioning, 4 s; R_i: bidirectional "
        "repeatability, the largest of R up, R down and 2 s up + 2 s down + |B_i|; B_i: "
        "reversal value, mean up minus mean down.",
        size=8.3,
        colour="0.3",
    )
    return doc


def write_iso230_report(
    folder: str | Path,
    result: Iso230Result,
    json_text: str,
    date: str | None = None,
    provenance: Provenance | None = None,
    vdi: Vdi3441Result | None = None,
    conditions: Sequence[tuple[str, str]] = (),
    u: Iso230Uncertainty | None = None,
    decided: Sequence[Decision] = (),
) -> list[str]:
    """Write ``report.pdf``, ``iso230.png`` and ``result.json`` into ``folder`` (a staging
    folder of :class:`esp.io.outputs.Outputs`); return the file names written."""
    from esp.iso230.plots import iso230_figure
    from esp.report.epoch import report_date
    from esp.report.profile_plots import save_png

    folder = Path(folder)
    date = date or report_date()
    (folder / "result.json").write_text(json_text, encoding="utf-8")
    fig = iso230_figure(result)
    save_png(fig, folder / "iso230.png")
    doc = iso230_document(result, date, provenance, vdi, conditions, u, decided)
    doc.figure(
        fig,
        "the mean positional deviation of each direction with its ±2s band, and the "
        "bidirectional mean",
    )
    doc.write(folder / "report.pdf", provenance)
    return ["result.json", "iso230.png", "report.pdf"]
