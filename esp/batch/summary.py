"""The summary of a batch: ``summary.csv``, ``summary.md`` and ``summary.pdf``
(``esp batch``; the columns are documented in docs/reports.md)."""

from __future__ import annotations

import csv
import io
import os
from collections.abc import Iterable, Sequence
from pathlib import Path

from esp.batch.naming import SUMMARY_CSV, SUMMARY_MD
from esp.batch.rows import NO_THRESHOLDS, PLANES, BatchRow, Thresholds, _mm, _um
from esp.core.machine import AXIS_NAMES
from esp.io.atomic import write_text
from esp.report.words import one_line

__all__ = [
    "SUMMARY_COLUMNS",
    "counts_text",
    "summary_csv",
    "summary_markdown",
    "write_summary",
    "write_summary_pdf",
]

#: the columns of ``summary.csv``, in order (documented in ``docs/reports.md``)
SUMMARY_COLUMNS = (
    "file",
    "name",
    "configuration",
    "volumetric_um",
    "volumetric_X_mm",
    "volumetric_Y_mm",
    "volumetric_Z_mm",
    "planar_XY_um",
    "planar_XZ_um",
    "planar_YZ_um",
    "uncertainty_um",
    "verdict",
    "decision_rule",
    "decisions",
    "error",
    "report",
)


def _csv_record(row: BatchRow) -> dict[str, str]:
    at = row.volumetric_at_mm
    record = {
        "file": row.file,
        "name": row.name,
        "configuration": row.configuration,
        "volumetric_um": "" if row.volumetric_um is None else _um(row.volumetric_um),
        "uncertainty_um": "" if row.uncertainty_um is None else _um(row.uncertainty_um),
        "verdict": row.verdict,
        "decision_rule": row.rule_text,
        "decisions": row.decisions_text,
        "error": row.error or "",
        "report": "" if row.error is not None or row.skipped is not None else row.folder,
    }
    for a in AXIS_NAMES:
        record[f"volumetric_{a}_mm"] = _mm(at[a]) if a in at else ""
    for plane in PLANES:
        value = row.planar_um.get(plane)
        record[f"planar_{plane}_um"] = "" if value is None else _um(value)
    return record


def summary_csv(rows: Iterable[BatchRow]) -> str:
    """``summary.csv``: a header of :data:`SUMMARY_COLUMNS`, then one line per row."""
    buffer = io.StringIO()
    writer = csv.DictWriter(buffer, fieldnames=SUMMARY_COLUMNS, lineterminator="\n")
    writer.writeheader()
    for row in rows:
        writer.writerow(_csv_record(row))
    return buffer.getvalue()


def _cell(text: str) -> str:
    """A table cell: backslashes and pipes escaped and line breaks and other control
    characters shown escaped (:func:`esp.report.words.one_line`), so that neither a
    message nor a machine or file name can break the row."""
    return one_line(text.replace("\\", "\\\\").replace("|", "\\|"))


def _limits(thresholds: Thresholds) -> str:
    limits = thresholds.tolerances().limits_text()
    rule = thresholds.rule.name if thresholds.rule is not None else None
    parts = [] if limits == "none" else [limits]
    if rule is not None:
        parts.append(f"decision rule: {rule}")
    given = "; ".join(parts) if parts else "none on the command line"
    return f"{given} (with each machine's own [tolerance] table for what they leave open)"


def counts_text(rows: Sequence[BatchRow]) -> str:
    """``"3 machines: 1 pass, 1 fail, 1 error"``, ``", 1 not decided"`` when a figure lies
    within its guard band, ``", 1 plan"`` when there are
    uncertainty plans without a verdict, ``", 1 skipped"`` when configurations were not
    analysed (identify configurations)."""
    statuses = [r.status for r in rows]
    noun = "machine" if len(statuses) == 1 else "machines"
    plans = statuses.count("plan")
    undecided = statuses.count("not decided")
    skipped = statuses.count("skipped")
    return (
        f"{len(statuses)} {noun}: {statuses.count('pass')} pass, "
        f"{statuses.count('fail')} fail, {statuses.count('error')} error"
        + (f", {undecided} not decided" if undecided else "")
        + (f", {plans} plan" if plans else "")
        + (f", {skipped} skipped" if skipped else "")
    )


def summary_markdown(rows: Sequence[BatchRow], thresholds: Thresholds = NO_THRESHOLDS) -> str:
    """``summary.md``: the same rows as a Markdown table, linked to each report."""
    lines = [
        "# Volumetric accuracy summary",
        "",
        f"Thresholds: {_limits(thresholds)}.",
        "",
        counts_text(rows) + ".",
        "",
        "| file | machine | configuration | volumetric (µm) | at X, Y, Z (mm) | "
        "planar XY (µm) | planar XZ (µm) | planar YZ (µm) | uncertainty (µm) | verdict | "
        "decisions (rule, risk) | report |",
        "| --- | --- | --- | ---: | --- | ---: | ---: | ---: | ---: | --- | --- | --- |",
    ]
    for row in rows:
        rec = _csv_record(row)
        at = ", ".join(rec[f"volumetric_{a}_mm"] for a in AXIS_NAMES) if rec["report"] else ""
        verdict = f"error: {row.error}" if row.error is not None else row.verdict
        report = f"[{row.folder}]({row.folder}/report.pdf)" if rec["report"] else ""
        cells = [
            row.file,
            row.name,
            row.configuration,
            rec["volumetric_um"],
            at,
            rec["planar_XY_um"],
            rec["planar_XZ_um"],
            rec["planar_YZ_um"],
            rec["uncertainty_um"],
            verdict,
            f"{row.rule_text}: {row.decisions_text}" if row.decisions else "",
            report,
        ]
        lines.append("| " + " | ".join(_cell(c) for c in cells) + " |")
    return "\n".join(lines) + "\n"


def write_summary(
    rows: Sequence[BatchRow],
    out_dir: str | os.PathLike[str],
    thresholds: Thresholds = NO_THRESHOLDS,
) -> tuple[Path, Path]:
    """Write ``summary.csv`` and ``summary.md`` into ``out_dir`` (each atomically) and
    return their paths."""
    csv_path = Path(out_dir) / SUMMARY_CSV
    md_path = Path(out_dir) / SUMMARY_MD
    write_text(csv_path, summary_csv(rows))
    write_text(md_path, summary_markdown(rows, thresholds))
    return csv_path, md_path


def write_summary_pdf(
    rows: Sequence[BatchRow],
    path: str | os.PathLike[str],
    thresholds: Thresholds = NO_THRESHOLDS,
    date: str | None = None,
) -> int:
    """``summary.pdf``: the fleet summary document in the style of every esp report
    (:mod:`esp.report.document`): how many pass, fail, are plans or could not be
    analysed, the thresholds, then one row per machine (its file and name wrapped, its
    accuracies, uncertainty and verdict, the folder of its report). Returns the number of
    pages."""
    from esp.report.document import Document, Headline, summary
    from esp.report.epoch import report_date
    from esp.report.tables import Column, Table

    doc = Document("Fleet summary", f"{len(rows)} machine configuration(s)", date or report_date())
    statuses = [r.status for r in rows]
    lines = [Headline(word, str(statuses.count(word))) for word in ("pass", "fail", "error")]
    for word in ("not decided", "plan", "skipped"):
        if word in statuses:
            lines.append(Headline(word, str(statuses.count(word))))
    accuracies = [r for r in rows if r.volumetric_um is not None]
    if accuracies:
        worst = max(accuracies, key=lambda r: r.volumetric_um or 0.0)
        lines.append(
            Headline(
                f"Largest volumetric accuracy ({worst.name})",
                f"{_um(worst.volumetric_um or 0.0)} µm",
            )
        )
    summary(doc.lay, lines)
    doc.lay.paragraph(f"Thresholds: {_limits(thresholds)}.")
    doc.lay.paragraph(
        "Each machine's report is the report.pdf in its folder; the same rows are in "
        f"{SUMMARY_CSV} and {SUMMARY_MD}. Uncertainty: where a machine's [uncertainty] "
        "table gives one (its report states k and the method).",
        size=8.3,
        colour="0.3",
    )
    decided = [r for r in rows if r.decisions]
    if decided:  # the rule and each decision's risk (ISO 14253-1, JCGM 106)
        doc.section("Decisions against the tolerances")
        for row in decided:
            doc.lay.paragraph(f"{row.file}: {row.rule_text}. {row.decisions_text}.", size=8.3)
    doc.section("Machines")
    body = []
    for row in rows:
        rec = _csv_record(row)
        planar = ", ".join(
            f"{plane} {rec[f'planar_{plane}_um']}" for plane in PLANES if rec[f"planar_{plane}_um"]
        )
        verdict = f"error: {row.error}" if row.error is not None else row.verdict
        body.append(
            (
                f"{row.file}" + (f" ({row.name})" if row.name else ""),
                rec["volumetric_um"],
                planar,
                rec["uncertainty_um"],
                verdict,
                rec["report"],
            )
        )
    doc.lay.table(
        Table(
            (
                Column("file (machine)", "left", 1.9),
                Column("volumetric (µm)", "right", 0.85),
                Column("   planar (µm)", "left", 1.35),
                Column("U (µm)", "right", 0.6),
                Column("   verdict", "left", 0.8),
                Column("report", "left", 1.27),
            ),
            tuple(body),
        ),
        keep_whole=True,  # the last table: no page holding its tail alone
    )
    return doc.write(path)
