"""The terminal summary and the JSON document of ``esp diagonals``."""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from esp.diagonals.model import Diagonal, DiagonalCheck

if TYPE_CHECKING:
    from matplotlib.figure import Figure

    from esp.core.machine import Machine
    from esp.report.provenance import Provenance

__all__ = ["diagonals_dict", "diagonals_text", "verdict"]

SCHEMA = "esp.diagonals/1"


def verdict(checks: Sequence[DiagonalCheck]) -> bool | None:
    """True when every checked diagonal is explained, False when one is not, None when
    nothing could be judged (no check, or no uncertainty)."""
    judged = [c.explained for c in checks if c.explained is not None]
    if not checks or len(judged) < len(checks):
        return None if not judged else (False if False in judged else None)
    return all(judged)


def _pt(p: Iterable[float]) -> list[float]:
    return [float(v) for v in p]


def diagonals_dict(
    machine: Machine,
    step_mm: float,
    predicted: Sequence[tuple[Diagonal, np.ndarray, np.ndarray]],
    checks: Sequence[DiagonalCheck],
    settings: Mapping[str, float | bool],
) -> dict[str, Any]:
    """The JSON contract of ``esp diagonals --json`` (schema ``esp.diagonals/1``)."""
    return {
        "schema": SCHEMA,
        "machine": {"name": machine.name, "source": machine.source},
        "step_mm": step_mm,
        "value": "displacement error along the diagonal, relative to its start (µm)",
        "diagonals": [
            {
                "name": d.name,
                "start_mm": _pt(d.start_mm),
                "end_mm": _pt(d.end_mm),
                "length_mm": d.length_mm,
                "s_mm": s.tolist(),
                "predicted_um": v.tolist(),
            }
            for d, s, v in predicted
        ],
        "checks": [
            {
                "name": c.diagonal.name,
                "file": c.source,
                "s_mm": c.s_mm.tolist(),
                "measured_um": c.measured_um.tolist(),
                "predicted_um": c.predicted_um.tolist(),
                "difference_um": c.difference_um.tolist(),
                "u_prediction_um": None
                if c.u_prediction_um is None
                else c.u_prediction_um.tolist(),
                "u_measurement_um": c.u_measurement_um.tolist(),
                "U_um": None if c.U_um is None else c.U_um.tolist(),
                "En": None if c.En is None else c.En.tolist(),
                "max_abs_difference_um": c.max_abs_difference_um,
                "max_En": c.max_En,
                "explained": c.explained,
            }
            for c in checks
        ],
        "criterion": "E_n = |measured - predicted| / U <= 1 at every target, "
        "U = 2 sqrt(u_prediction^2 + u_measurement^2)",
        "uncertainty": settings,
        "verdict": verdict(checks) if checks else None,
    }


def diagonals_text(
    machine: Machine,
    step_mm: float,
    predicted: Sequence[tuple[Diagonal, np.ndarray, np.ndarray]],
    checks: Sequence[DiagonalCheck],
    settings: Mapping[str, float | bool],
) -> str:
    """The terminal summary."""
    lines = [f"esp diagonals: {machine.name}" + (f" ({machine.source})" if machine.source else "")]
    r = {a: machine.axes[a].simulate_mm for a in ("X", "Y", "Z")}
    lines.append(
        "volume: "
        + ", ".join(f"{a} {lo:g} to {hi:g}" for a, (lo, hi) in r.items())
        + f" mm; targets every {step_mm:g} mm"
    )
    lines.append("predicted displacement error along each diagonal, relative to its start (µm):")
    lines.append("  diagonal  from                 to                    length mm   min      max")
    for d, _, v in predicted:
        start = "(" + ", ".join(f"{x:g}" for x in d.start_mm) + ")"
        end = "(" + ", ".join(f"{x:g}" for x in d.end_mm) + ")"
        lines.append(
            f"  {d.name:<8}  {start:<20} {end:<20} {d.length_mm:9.1f} {v.min():8.2f} {v.max():8.2f}"
        )
    if checks:
        lines += ["", "measured - predicted:"]
        lines.append(
            "  diagonal  file                    max|diff| µm  at s mm   U there µm"
            "   max E_n  explained"
        )
        for c in checks:
            i = c.worst_index
            U = "-" if c.U_um is None else f"{c.U_um[i]:.2f}"
            en = "-" if c.max_En is None else f"{c.max_En:.2f}"
            ex = {True: "yes", False: "NO", None: "not judged"}[c.explained]
            name = c.source.replace("\\", "/").rsplit("/", 1)[-1]
            lines.append(
                f"  {c.diagonal.name:<8}  {name:<22} {c.max_abs_difference_um:12.2f} "
                f"{c.s_mm[i]:9.1f} {U:>11} {en:>9}  {ex}"
            )
        lines.append(
            "  uncertainty: prediction from "
            + (
                "the [uncertainty] table"
                if settings.get("prediction")
                else "nothing (no [uncertainty] table)"
            )
            + f"; measurement U = {settings['U_measurement_um']:g} µm + "
            f"{settings['U_measurement_per_m_um']:g} µm/m × s (k = 2)"
        )
        explained = verdict(checks)
        if explained is True:
            lines.append(
                "verdict: the 21-component model explains the measured diagonals "
                "(E_n <= 1 at every target)"
            )
        elif explained is False:
            bad = [c.diagonal.name for c in checks if c.explained is False]
            lines.append(
                f"verdict: the 21-component model does NOT explain {', '.join(bad)} within the "
                "combined uncertainty (E_n > 1)"
            )
        else:
            lines.append(
                "verdict: not judged; give the measurement uncertainty (--measurement-u) or an "
                "[uncertainty] table"
            )
    return "\n".join(lines) + "\n"


def write_diagonals_pdf(
    path: str | Path,
    machine: Machine,
    checks: Sequence[DiagonalCheck],
    text: str,
    figure: Figure,
    provenance: Provenance | None = None,
) -> int:
    """``report.pdf`` of ``esp diagonals --out`` in the style of every esp report
    (:mod:`esp.report.document`): the verdict, the predicted and measured diagonals, the
    figure, the provenance. Returns the number of pages."""
    from esp.report.document import Headline, title_fields, write_text_document
    from esp.report.epoch import report_date

    rows = []
    for c in checks:
        i = c.worst_index
        U = None if c.U_um is None else f"U = {c.U_um[i]:.2f} µm there (k = 2)"
        rows.append(
            Headline(
                f"{c.diagonal.name}: largest |measured - predicted|",
                f"{c.max_abs_difference_um:.2f} µm",
                U,
            )
        )
    v = verdict(checks)
    note = {
        True: "Verdict: the 21-component model explains the measured diagonals (E_n <= 1).",
        False: "Verdict: the 21-component model does not explain every measured diagonal "
        "within the combined uncertainty (E_n > 1).",
        None: "Verdict: not judged (no measured diagonal, or no uncertainty given).",
    }[v]
    return write_text_document(
        path,
        title="Diagonal displacement test",
        name=machine.name,
        date=report_date(),
        text=text,
        skip=1,
        headlines=rows,
        fields=title_fields(getattr(machine, "report", None), machine.info, provenance),
        figures=[(figure, "the predicted (and measured) error along each diagonal")],
        provenance=provenance,
        note=note,
        section="Diagonals",
    )
