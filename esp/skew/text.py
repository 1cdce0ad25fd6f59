"""The terminal summary and the JSON document of ``esp skew``."""

from __future__ import annotations

import math
from typing import Any

from esp.core.rounding import stated
from esp.skew.firmware import Block, FirmwareLines
from esp.skew.model import Estimate, SkewResult

__all__ = ["skew_dict", "skew_text"]

#: the travel over which a squareness is also shown as a displacement (mm)
OVER_MM = 100.0


def _estimate_line(e: Estimate) -> str:
    figure = stated(e.value_um_per_m, e.expanded_um_per_m, "µm/m", e.k)
    if e.quantity.kind == "squareness":
        over = e.value * OVER_MM
        extra = f"; {over:+.3f} mm over {OVER_MM:g} mm of {e.quantity.name[1]}"
    else:
        extra = ""
    verdict = "" if e.significant else "  (within its U: not shown to differ from 0)"
    return f"  {str(e.quantity):<15} {figure}{extra}{verdict}"


def skew_text(result: SkewResult, firmware: FirmwareLines) -> str:
    """The terminal summary: the readings, each estimate with its U, the firmware lines."""
    out: list[str] = []
    if result.source == "square":
        cal = result.caliper
        assert cal is not None
        out.append(
            f"Squares the machine made, measured with a caliper of resolution "
            f"{cal.resolution_mm:g} mm and accuracy ± {cal.accuracy_mm:g} mm"
        )
        for plane in result.planes:
            sq = plane.square
            n = len(sq.ac.readings_mm)
            reads = f", {n} readings each" if n > 1 else ""
            ab = (
                f"AB {plane.ab_mm:.3f} (from AC, BD, AD)"
                if plane.ab_computed
                else f"AB {plane.ab_mm:.3f}"
            )
            out.append(
                f"  {sq.plane}: AC {sq.ac.mean_mm:.3f}  BD {sq.bd.mean_mm:.3f}  "
                f"AD {sq.ad.mean_mm:.3f}  {ab} mm{reads}; included angle "
                f"{plane.angle_deg:.4f}° between +{sq.plane[0]} and +{sq.plane[1]}"
            )
            if sq.nominal_mm is not None:
                out.append(f"      nominal side {sq.nominal_mm:g} mm")
    else:
        pts = result.points
        assert pts is not None
        what = "a part the machine made" if pts.kind == "made" else "an artefact the machine probed"
        out.append(
            f"{len(pts.nominal_mm)} points of {what} ({pts.path}), axes {''.join(pts.axes)}; "
            f"scatter about the fit {result.residual_um:.1f} µm "
            f"({result.residual_dof} degrees of freedom)"
        )
    out.append("")
    for e in result.estimates:
        out.append(_estimate_line(e))
    for w in result.warnings:
        out.append(f"  warning: {w}")
    out.append("")
    out.append("For the firmware (the whole correction: measure with any earlier one cleared):")
    for block in firmware.blocks:
        out.extend(_block_lines(block))
    return "\n".join(out).rstrip() + "\n"


def _block_lines(block: Block) -> list[str]:
    lines = [f"  {block.title}"]
    lines += [f"    {ln}" for ln in block.lines]
    lines += [f"    note: {n}" for n in block.notes]
    return lines


def _num(x: float) -> float | None:
    return x if math.isfinite(x) else None


def skew_dict(result: SkewResult, firmware: FirmwareLines) -> dict[str, Any]:
    """The JSON document (``esp.skew/1``): full precision, ratios in µm/m."""
    doc: dict[str, Any] = {
        "schema": "esp.skew/1",
        "source": result.source,
        "kind": result.kind,
        "estimates": [
            {
                "quantity": e.quantity.kind,
                "name": e.quantity.name,
                "value_um_per_m": e.value_um_per_m,
                "u_um_per_m": e.u * 1e6,
                "dof": _num(e.dof),
                "k": e.k,
                "U_um_per_m": e.expanded_um_per_m,
                "significant": e.significant,
            }
            for e in result.estimates
        ],
        "warnings": list(result.warnings),
    }
    if result.caliper is not None:
        doc["caliper"] = {
            "resolution_mm": result.caliper.resolution_mm,
            "accuracy_mm": result.caliper.accuracy_mm,
        }
    if result.planes:
        doc["squares"] = [
            {
                "plane": p.square.plane,
                "AC_mm": list(p.square.ac.readings_mm),
                "BD_mm": list(p.square.bd.readings_mm),
                "AD_mm": list(p.square.ad.readings_mm),
                "AB_mm": list(p.square.ab.readings_mm) if p.square.ab is not None else None,
                "AB_used_mm": p.ab_mm,
                "AB_computed": p.ab_computed,
                "nominal_mm": p.square.nominal_mm,
                "angle_deg": p.angle_deg,
                "parallelogram_misfit_mm": p.parallelogram_misfit_mm,
            }
            for p in result.planes
        ]
    if result.points is not None:
        doc["points"] = {
            "path": result.points.path,
            "axes": "".join(result.points.axes),
            "count": int(len(result.points.nominal_mm)),
            "residual_um": result.residual_um,
            "residual_dof": result.residual_dof,
            "point_u_um": result.points.point_u_um,
        }
    doc["matrix"] = result.matrix().tolist()
    doc["firmware_values"] = firmware.values
    doc["firmware"] = [
        {"firmware": b.firmware, "title": b.title, "lines": list(b.lines), "notes": list(b.notes)}
        for b in firmware.blocks
    ]
    return doc
