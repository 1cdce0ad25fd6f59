"""The report folder of ``esp ballbar --out DIR``: an ISO 230-4 test report.

``report.pdf`` (the document style of every esp report, :mod:`esp.report.document`): the
title block, the summary (F, G, G(b), H with their U where the ballbar's specification
gives one), the test conditions, the ISO 230-4 figures of every direction, the diagnosis
with its units, the verdicts against the tolerances given, the polar plot and the
provenance. ``ballbar.txt``, ``ballbar.json`` and ``polar.png`` are written beside it by
the command.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path, PurePath
from typing import TYPE_CHECKING

from esp.ballbar.analysis import CircleTest
from esp.ballbar.text import condition_pairs, figure_text, term_text
from esp.ballbar.verdicts import K, expanded_uncertainty
from esp.core.conformity import Decision
from esp.core.rounding import coverage_text

if TYPE_CHECKING:
    from matplotlib.figure import Figure

    from esp.report.document import Document, Headline
    from esp.report.provenance import Provenance

__all__ = ["ballbar_document", "write_ballbar_report"]


def _name(tests: Sequence[CircleTest]) -> str:
    machines = {t.conditions.machine for t in tests if t.conditions.machine}
    files = dict.fromkeys(PurePath(t.file).name for t in tests)
    head = f"{machines.pop()}: " if len(machines) == 1 else ""
    return head + ", ".join(files)


def _headline(label: str, value: float, U: float | None) -> Headline:
    from esp.report.document import Headline

    shown = figure_text(value, U).split(", ")
    return Headline(label, shown[0], f"{shown[1]} ({coverage_text(K)})" if U else None)


def ballbar_document(
    tests: Sequence[CircleTest],
    decided: Sequence[Decision],
    date: str,
    provenance: Provenance | None = None,
) -> Document:
    """The :class:`~esp.report.document.Document` of the circles (its figure is added by
    the caller)."""
    from esp.report.document import Document, summary, title_fields
    from esp.report.tables import Column, Table

    fields = title_fields(provenance=provenance)
    known = {label for label, _ in fields}
    for label, value in (
        ("Measured on", {t.conditions.date for t in tests if t.conditions.date}),
        ("Operator", {t.conditions.operator for t in tests if t.conditions.operator}),
    ):
        if label not in known and len(value) == 1:
            fields.append((label, value.pop()))
    doc = Document("ISO 230-4 circular test report", _name(tests), date, fields)
    lay = doc.lay
    lines = []
    for t in tests:
        c = t.conditions
        UG, UF = expanded_uncertainty("G", c), expanded_uncertainty("F", c)
        pre = f"{t.name}: " if len(tests) > 1 else ""

        for d in t.directions:
            lines.append(_headline(f"{pre}circular deviation G {d.direction}", d.G_um, UG))
        if t.G_bidirectional_um is not None and t.H_um is not None:
            lines.append(_headline(f"{pre}bidirectional G(b)", t.G_bidirectional_um, UG))
            lines.append(_headline(f"{pre}circular hysteresis H", t.H_um, UG))
        lines.append(_headline(f"{pre}radial deviation |F| largest", t.F_um, UF))
    summary(lay, lines)
    if all(expanded_uncertainty("G", t.conditions) is None for t in tests):
        lay.paragraph(
            "Uncertainty: not evaluated (the ballbar's accuracy or resolution is not stated "
            "in the file or the options).",
            size=8.3,
            colour="0.3",
        )
    else:
        lay.paragraph(
            "U of G, G(b) and H: of the difference of two readings, from the ballbar's "
            "stated accuracy (rectangular) and resolution; U of F adds the calibration U of "
            "its length; k = 2. The machine's own scatter is part of what is measured, not "
            "of U (docs/ballbar.md).",
            size=8.3,
            colour="0.3",
        )
    for t in tests:
        doc.section(f"Circle {t.name}: the test" if len(tests) > 1 else "The test")
        lay.pairs(condition_pairs(t) + [("Data file", PurePath(t.file).name)])
        lay.pairs([("Standard", "ISO 230-4:2022 (circular tests for NC machine tools)")])
        doc.section("ISO 230-4 figures")
        UG, UF = expanded_uncertainty("G", t.conditions), expanded_uncertainty("F", t.conditions)
        rows = []
        for d in t.directions:
            rows.append(("radial deviation F max", d.direction, figure_text(d.F_max_um, UF)))
            rows.append(("radial deviation F min", d.direction, figure_text(d.F_min_um, UF)))
            rows.append(("circular deviation G", d.direction, figure_text(d.G_um, UG)))
        if t.G_bidirectional_um is not None and t.H_um is not None:
            rows.append(
                (
                    "bidirectional circular deviation G(b)",
                    "both",
                    figure_text(t.G_bidirectional_um, UG),
                )
            )
            rows.append(("circular hysteresis H", "both", figure_text(t.H_um, UG)))
        lay.table(
            Table(
                (
                    Column("figure", "left", 3.0),
                    Column("direction", "left", 1.0),
                    Column("value", "left", 2.77),
                ),
                tuple(rows),
            )
        )
        lay.paragraph(
            "F: deviation of the path from the nominal radius about the ballbar's pivot; G: "
            "least radial separation of two concentric circles (about the least-squares "
            "centre) enclosing the path of one direction; G(b): the same for both "
            "directions; H: the largest radial difference between the two directions' paths "
            "(ISO 230-4:2022, clause 3)."
            + ("" if t.diagnosis.full_circle else " On a partial arc these are the arc's."),
            size=8.3,
            colour="0.3",
        )
        doc.section("Diagnosis")
        diag = t.diagnosis
        lay.table(
            Table(
                (
                    Column("term", "left", 2.9),
                    Column("value (U with k = 2)", "left", 2.2),
                    Column("finding", "left", 1.67),
                ),
                tuple((term.label, *term_text(term)) for term in diag.terms),
            )
        )
        lay.paragraph(
            f"Noise of one reading (standard deviation) {diag.noise_um:.3f} µm, away from the "
            "reversals. A term "
            "is reported beyond its coverage of its standard uncertainty u (4 u; 5 u for the "
            "cyclic error, searched over its period; a spike beyond 5 times the scatter near "
            "its reversal). Definitions and signatures: docs/ballbar.md.",
            size=8.3,
            colour="0.3",
        )
        for note in diag.notes:
            lay.paragraph("Note: " + note, size=8.3)
    if decided:
        doc.section("Verdicts")
        lay.paragraph(f"Decision rule: {decided[0].rule.name}.")
        lay.table(
            Table(
                (
                    Column("figure", "left", 1.5),
                    Column("value", "right", 0.9),
                    Column("tolerance", "right", 0.9),
                    Column("   verdict", "left", 1.3),
                    Column("risk", "left", 2.17),
                ),
                tuple(
                    (
                        dec.quantity,
                        figure_text(dec.value, dec.expanded, dec.unit).split(",")[0],
                        f"{dec.tolerance:g} {dec.unit}",
                        "   " + dec.verdict,
                        dec.risk_text(),
                    )
                    for dec in decided
                ),
            )
        )
    return doc


def write_ballbar_report(
    folder: str | Path,
    tests: Sequence[CircleTest],
    decided: Sequence[Decision],
    figure: Figure,
    date: str | None = None,
    provenance: Provenance | None = None,
) -> None:
    """Write ``report.pdf`` into ``folder`` (staged by :class:`esp.io.outputs.Outputs`)."""
    from esp.report.epoch import report_date

    doc = ballbar_document(tests, decided, date or report_date(), provenance)
    doc.figure(
        figure,
        "each direction's path about the least-squares circle, magnified about the zero "
        "ring at the scale per division stated over each plot",
    )
    doc.write(Path(folder) / "report.pdf", provenance)
