"""The terminal summary and the JSON document of ``esp compensate``."""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from esp.compensation.formats import get, registry
from esp.compensation.model import CompensationSet
from esp.compensation.predict import Prediction

if TYPE_CHECKING:
    from esp.core.machine import Machine
    from esp.report.provenance import Provenance

__all__ = ["FormatResult", "compensation_dict", "compensation_text"]

SCHEMA = "esp.compensation/1"


@dataclass(frozen=True)
class FormatResult:
    """One format's tables (as read back from its files), its files and, with
    ``--predict``, the residual."""

    tables: CompensationSet
    files: tuple[str, ...]
    resolution_um: float
    prediction: Prediction | None = None
    record_count: int | None = None


def _at(point: Mapping[str, float]) -> str:
    return ", ".join(f"{a}={point[a]:g}" for a in ("X", "Y", "Z"))


def _table_rows(cset: CompensationSet) -> list[dict]:
    rows = []
    for t in cset.axis_tables:
        rows.append(
            {
                "kind": t.kind,
                "slave": t.slave,
                "masters": [t.master],
                "points": int(t.positions_mm.size),
                "range_mm": [float(t.positions_mm[0]), float(t.positions_mm[-1])],
                "forward_um": [float(t.forward_um.min()), float(t.forward_um.max())],
                "backward_um": [float(t.backward_um.min()), float(t.backward_um.max())],
                "components": list(t.components),
            }
        )
    for p in cset.plane_tables:
        rows.append(
            {
                "kind": "plane",
                "slave": p.slave,
                "masters": list(p.masters),
                "points": int(p.values_um.size),
                "range_mm": [
                    [float(p.positions_a_mm[0]), float(p.positions_a_mm[-1])],
                    [float(p.positions_b_mm[0]), float(p.positions_b_mm[-1])],
                ],
                "correction_um": [float(p.values_um.min()), float(p.values_um.max())],
                "components": list(p.components),
            }
        )
    if cset.component_table is not None:
        for name, (positions, values) in cset.component_table.curves.items():
            rows.append(
                {
                    "kind": "component",
                    "component": name,
                    "points": int(positions.size),
                    "range_mm": [float(positions[0]), float(positions[-1])],
                    "error": [float(np.min(values)), float(np.max(values))],
                }
            )
        for name, value in cset.component_table.squareness.items():
            rows.append({"kind": "squareness", "component": name, "error": [value, value]})
    for r in cset.rotary_tables:
        rows.append(
            {
                "kind": "rotary",
                "slave": r.axis,
                "masters": [r.axis],
                "points": int(r.positions_deg.size),
                "range_deg": [float(r.positions_deg[0]), float(r.positions_deg[-1])],
                "modulo": r.modulo,
                "correction_urad": [float(r.correction_urad.min()), float(r.correction_urad.max())],
                "components": [r.error] if r.error else [],
            }
        )
    return rows


def _prediction_dict(p: Prediction) -> dict[str, Any]:
    return {
        "points": p.points,
        "before_um": p.before_um,
        "after_um": p.after_um,
        "directions": [
            {
                "direction": d.direction,
                "before_um": d.before_um,
                "before_at": dict(d.before_at),
                "after_um": d.after_um,
                "after_at": dict(d.after_at),
                "axes_before_um": dict(d.axes_before_um),
                "axes_after_um": dict(d.axes_after_um),
            }
            for d in p.directions
        ],
    }


def compensation_dict(machine: Machine, results: Sequence[FormatResult]) -> dict[str, Any]:
    """The JSON contract of ``esp compensate --json`` (schema ``esp.compensation/1``):
    per format its files, tables (corrections in µm, the sign of a correction; component
    tables as errors in µm or µm/m), the components corrected and left, and with
    ``--predict`` the volumetric accuracy before and after per direction of approach."""
    formats = []
    for r in results:
        c = r.tables
        entry = {
            "format": c.format,
            "description": get(c.format).description,
            "files": list(r.files),
            "resolution_um": r.resolution_um,
            "tables": _table_rows(c),
            "corrected": list(c.corrected),
            "uncorrected": list(c.uncorrected),
            "notes": list(c.notes),
        }
        if r.record_count is not None:
            entry["records"] = r.record_count
        if r.prediction is not None:
            entry["prediction"] = _prediction_dict(r.prediction)
        formats.append(entry)
    return {
        "schema": SCHEMA,
        "machine": {"name": machine.name, "source": machine.source},
        "datum": machine.analysis.datum
        if isinstance(machine.analysis.datum, str)
        else dict(machine.analysis.datum),
        "formats": formats,
    }


def _range(values: Iterable[float]) -> str:
    lo, hi = (round(float(v), 3) + 0.0 for v in values)
    return f"{lo:+.3f} .. {hi:+.3f}"


def compensation_text(machine: Machine, results: Sequence[FormatResult]) -> str:
    """The terminal summary."""
    lines = [f"esp compensate: {machine.name}" + (f" ({machine.source})" if machine.source else "")]
    for r in results:
        c = r.tables
        lines += ["", f"format {c.format}: {get(c.format).description}"]
        lines.append(f"  files: {', '.join(r.files)}")
        lines.append(f"  resolution: {r.resolution_um:g} µm")
        if r.record_count is not None:
            lines.append(
                f"  records: {r.record_count} ({get(c.format).records_setting} must be at "
                f"least this)"
            )
        rows = _table_rows(c)
        if rows:
            lines.append(
                "  tables (corrections in µm are added to the command; "
                "component tables hold errors):"
            )
        for row in rows:
            if row["kind"] in ("lead", "cross"):
                extra = (
                    f"forward {_range(row['forward_um'])}  backward {_range(row['backward_um'])}"
                    if row["kind"] == "lead"
                    else f"correction {_range(row['forward_um'])}"
                )
                lines.append(
                    f"    {row['kind']:<5} {row['slave']} from {row['masters'][0]}: "
                    f"{row['points']} points {row['range_mm'][0]:g} to "
                    f"{row['range_mm'][1]:g} mm, {extra}"
                )
            elif row["kind"] == "plane":
                a, b = row["masters"]
                lines.append(
                    f"    plane {row['slave']} over {a}{b}: {row['points']} points, "
                    f"correction {_range(row['correction_um'])}"
                )
            elif row["kind"] == "rotary":
                lo, hi = row["range_deg"]
                turn = "modulo, every turn" if row["modulo"] else "ends held"
                lines.append(
                    f"    rotary {row['slave']}: {row['points']} points {lo:g} to {hi:g}° "
                    f"({turn}), correction {_range(row['correction_urad'])} µrad"
                )
            elif row["kind"] == "component":
                unit = "µm/m" if ".angular." in row["component"] else "µm"
                lines.append(
                    f"    {row['component']:<18} {row['points']} points, error "
                    f"{_range(row['error'])} {unit}"
                )
            else:
                lines.append(f"    {row['component']:<18} {row['error'][0]:+.3f} µm/m")
        lines.append(f"  corrects: {', '.join(c.corrected) if c.corrected else 'nothing'}")
        if c.uncorrected:
            lines.append(f"  left uncorrected ({len(c.uncorrected)}): {', '.join(c.uncorrected)}")
        for note in c.notes:
            lines.append(f"  note: {note}")
        p = r.prediction
        if p is not None:
            lines.append(f"  predicted volumetric accuracy over {p.points} points (µm):")
            lines.append("    direction   before   after   where after")
            for d in p.directions:
                lines.append(
                    f"    {d.direction:<10} {d.before_um:7.2f} {d.after_um:7.2f}"
                    f"   {_at(d.after_at)}"
                )
    return "\n".join(lines) + "\n"


def load_words(fmt: str) -> str:
    """How the files of ``fmt`` are loaded into the controller (one sentence)."""
    formats = registry()
    return formats[fmt].load_words if fmt in formats else ""


def write_compensation_pdf(
    path: str | Path,
    machine: Machine,
    results: Sequence[FormatResult],
    text: str,
    predicted: bool,
    provenance: Provenance | None = None,
) -> int:
    """``report.pdf`` of ``esp compensate --out`` in the style of every esp report
    (:mod:`esp.report.document`): what was written, per format (files, tables, what each
    corrects and leaves), the predicted residual with ``--predict``, how to load it, the
    provenance. Returns the number of pages."""
    from esp.report.document import Headline, title_fields, write_text_document
    from esp.report.epoch import report_date

    rows = []
    for r in results:
        p = r.prediction
        if p is not None:
            rows.append(Headline(f"{r.tables.format}: accuracy before", f"{p.before_um:.2f} µm"))
            rows.append(Headline(f"{r.tables.format}: predicted after", f"{p.after_um:.2f} µm"))
        else:
            rows.append(Headline(f"{r.tables.format}: files written", f"{len(r.files)}"))
    load = "; ".join(f"{r.tables.format}: {load_words(r.tables.format)}" for r in results)
    note = (
        ("" if predicted else "No prediction (run with --predict for the residual). ")
        + "How to load: "
        + load
        + "."
    )
    return write_text_document(
        path,
        title="Compensation tables",
        name=machine.name,
        date=report_date(),
        text=text,
        skip=1,
        headlines=rows,
        fields=title_fields(getattr(machine, "report", None), machine.info, provenance),
        provenance=provenance,
        note=note,
        section="What was written",
    )
