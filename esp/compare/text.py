"""The terminal summary and the JSON document of ``esp compare``."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

from esp.compare.model import Comparison
from esp.core.text import one_line

if TYPE_CHECKING:
    from matplotlib.figure import Figure

    from esp.core.machine import Machine
    from esp.report.provenance import Provenance

__all__ = ["compare_dict", "compare_text"]

SCHEMA = "esp.compare/1"
_UNIT = {"um": "µm", "um/m": "µm/m"}


def compare_dict(before: Machine, after: Machine, c: Comparison) -> dict[str, Any]:
    """The JSON contract of ``esp compare --json`` (schema ``esp.compare/1``)."""
    return {
        "schema": SCHEMA,
        "before": {
            "name": before.name,
            "source": before.source,
            "date": str(before.info.get("date", "")),
        },
        "after": {
            "name": after.name,
            "source": after.source,
            "date": str(after.info.get("date", "")),
        },
        "components": [
            {
                "component": x.name,
                "unit": x.unit,
                "max_abs_change": x.max_abs_change,
                "at_mm": x.at_mm,
                "range_before": x.range_before,
                "range_after": x.range_after,
                "present_before": x.present_before,
                "present_after": x.present_after,
            }
            for x in c.components
        ],
        "volumetric": {
            "before_um": c.volumetric_before[0],
            "before_at": dict(c.volumetric_before[1]),
            "after_um": c.volumetric_after[0],
            "after_at": dict(c.volumetric_after[1]),
            "change_um": c.volumetric_change_um,
        },
        "planar": {
            plane: {
                "before_um": c.planar_before[plane],
                "after_um": c.planar_after.get(plane),
                "change_um": c.planar_after.get(plane, 0.0) - c.planar_before[plane],
            }
            for plane in c.planar_before
        },
        "field_change": dict(c.field),
        "identical_inputs": c.identical_inputs,
        "unchanged": c.unchanged,
    }


def _at(point: Mapping[str, float]) -> str:
    return ", ".join(f"{a}={point[a]:g}" for a in ("X", "Y", "Z"))


def compare_text(before: Machine, after: Machine, c: Comparison) -> str:
    """The terminal summary."""
    lines = [
        "esp compare: two calibrations of one machine",
        f"  before: {one_line(before.name)} ({one_line(before.source)}) "
        f"{one_line(before.info.get('date', ''))}".rstrip(),
        f"  after:  {one_line(after.name)} ({one_line(after.source)}) "
        f"{one_line(after.info.get('date', ''))}".rstrip(),
    ]
    if c.identical_inputs:
        lines.append(
            "  identical inputs (the same files, byte for byte): there is nothing to compare"
        )
    elif c.unchanged:
        lines.append("  no change: every component and the error field are the same in both")
    lines += [
        "",
        "accuracy (µm)            before    after   change",
        f"  volumetric          {c.volumetric_before[0]:8.2f} {c.volumetric_after[0]:8.2f} "
        f"{c.volumetric_change_um:+8.2f}",
    ]
    for plane, vb in c.planar_before.items():
        va = c.planar_after.get(plane, float("nan"))
        lines.append(f"  planar {plane:<12} {vb:8.2f} {va:8.2f} {va - vb:+8.2f}")
    f = c.field
    assert isinstance(f["at"], Mapping)  # field_change(): axis -> position (mm)
    lines += [
        "",
        f"largest change of the error field: {f['max_um']:.2f} µm at {_at(f['at'])} "
        f"(over {f['points']} points)",
    ]
    directions = f["directions"]
    assert isinstance(directions, Mapping)  # field_change(): direction -> its largest change
    for a, d in directions.items():
        lines.append(f"  {a} direction: {d['value_um']:+.2f} µm at {_at(d['at'])}")
    lines += [
        "",
        "change per component (after - before; linear and angular curves referred to their "
        "first common point):",
        "  component            max |change|        at mm   range before   range after",
    ]
    for x in sorted(c.components, key=lambda x: (x.unit, -x.max_abs_change)):
        unit = _UNIT[x.unit]
        at = "-" if x.at_mm is None else f"{x.at_mm:g}"
        note = ""
        if not x.present_before or not x.present_after:
            note = "  (only " + ("after" if x.present_after else "before") + ")"
        lines.append(
            f"  {x.name:<20} {x.max_abs_change:8.3f} {unit:<5} {at:>10} {x.range_before:10.3f} "
            f"{x.range_after:12.3f}{note}"
        )
    return "\n".join(lines) + "\n"


def write_compare_pdf(
    path: str | Path,
    before: Machine,
    after: Machine,
    c: Comparison,
    text: str,
    figures: Sequence[Figure],
    provenance: Provenance | None = None,
) -> int:
    """``report.pdf`` of ``esp compare --out``: the before/after document of a service
    visit in the style of every esp report (:mod:`esp.report.document`): the accuracies
    before and after with their change, the change of the error field and of every
    component, the figures, the provenance. Returns the number of pages."""
    from esp.report.document import Headline, title_fields, write_text_document
    from esp.report.epoch import report_date

    rows = [
        Headline(
            "Volumetric accuracy before",
            f"{c.volumetric_before[0]:.3f} µm",
        ),
        Headline("Volumetric accuracy after", f"{c.volumetric_after[0]:.3f} µm"),
        Headline("Change", f"{c.volumetric_change_um:+.3f} µm"),
    ]
    dates = [str(m.info.get("date", "")) for m in (before, after)]
    note = (
        f"Before: {before.source or before.name}"
        + (f" ({dates[0]})" if dates[0] else "")
        + f"; after: {after.source or after.name}"
        + (f" ({dates[1]})" if dates[1] else "")
        + ". Uncertainty of the change: not evaluated."
    )
    return write_text_document(
        path,
        title="Comparison of two calibrations",
        name=after.name,
        date=report_date(),
        text=text,
        skip=1,
        headlines=rows,
        fields=title_fields(after.report, after.info, provenance),
        figures=[
            (figures[0], "the largest change of every component, after minus before"),
            (figures[1], "the curves of the components that changed most, before and after"),
        ][: len(figures)],
        provenance=provenance,
        note=note,
        section="Changes",
    )
