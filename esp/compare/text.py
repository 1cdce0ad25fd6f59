"""The terminal summary, the JSON document and the PDF of ``esp compare``: every figure
rounded to what its uncertainty supports (:mod:`esp.core.rounding`, GUM 7.2.6) in the
text and the PDF, full precision in the JSON."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

from esp.compare.model import K_CHANGE, Comparison, Significance
from esp.core.rounding import coverage_text, rounded
from esp.core.text import one_line

if TYPE_CHECKING:
    from matplotlib.figure import Figure

    from esp.core.machine import Machine
    from esp.report.provenance import Provenance

__all__ = [
    "calibration",
    "compare_dict",
    "compare_text",
    "verdict",
    "write_compare_pdf",
    "calibration_fields",
]

SCHEMA = "esp.compare/1"
_UNIT = {"um": "µm", "um/m": "µm/m"}


def calibration(machine: Machine) -> dict[str, str]:
    """Who measured the calibration and when: ``name``, ``source``, ``date`` (``[machine]
    date``) and ``operator`` (``[report] operator``, else ``[machine] measured_by``), each
    ``""`` when not given."""
    report = machine.report
    operator = (report.operator if report is not None else None) or machine.info.get(
        "measured_by", ""
    )
    return {
        "name": machine.name,
        "source": machine.source or "",
        "date": str(machine.info.get("date", "")),
        "operator": str(operator or ""),
    }


def verdict(s: Significance | None) -> str:
    """``"significant"`` (En > 1), ``"not significant"`` (En <= 1) or ``"not evaluated"``."""
    if s is None or s.significant is None:
        return "not evaluated"
    return "significant" if s.significant else "not significant"


def _significance(s: Significance | None, at_mm: float | None = None) -> dict[str, Any] | None:
    if s is None:
        return None
    return {**s.as_dict(), "verdict": verdict(s), **({} if at_mm is None else {"at_mm": at_mm})}


def compare_dict(before: Machine, after: Machine, c: Comparison) -> dict[str, Any]:
    """The JSON contract of ``esp compare --json`` (schema ``esp.compare/1``; full
    precision)."""
    figures = {f.key: f for f in c.figures}

    def sig(key: str) -> dict[str, Any]:
        f = figures.get(key)
        if f is None:
            return {}
        s = f.significance
        return {
            "U_change_um": s.U,
            "En": s.En,
            "significant": s.significant,
            "significance": {**(_significance(s) or {}), "basis": f.basis},
        }

    field = dict(c.field)
    directions = field.get("directions")
    if isinstance(directions, Mapping):
        field["directions"] = {d: {**v, **sig(f"field.{d}")} for d, v in directions.items()}
    return {
        "schema": SCHEMA,
        "before": calibration(before),
        "after": calibration(after),
        "uncertainty": {
            "correlation": c.correlation,
            "k": K_CHANGE,
            "combination": "u(Δ)² = u_before² + u_after² - 2 r u_before u_after, U(Δ) = k u(Δ)",
            "En": "|Δ| / U(Δ); En <= 1 not significant",
            "before": _side(c, "before"),
            "after": _side(c, "after"),
        },
        "components": [
            {
                "component": x.name,
                "unit": x.unit,
                "max_abs_change": x.max_abs_change,
                "at_mm": x.at_mm,
                "U_change_at_max": x.U_at_max,
                "En": x.significance.En if x.significance is not None else None,
                "significant": x.significance.significant if x.significance else None,
                "significance": _significance(x.significance, x.significance_at_mm),
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
            **sig("volumetric"),
        },
        "planar": {
            plane: {
                "before_um": c.planar_before[plane],
                "after_um": c.planar_after.get(plane),
                "change_um": c.planar_after.get(plane, 0.0) - c.planar_before[plane],
                **sig(f"planar.{plane}"),
            }
            for plane in c.planar_before
        },
        "field_change": {**field, **sig("field")},
        "identical_inputs": c.identical_inputs,
        "unchanged": c.unchanged,
    }


def _side(c: Comparison, side: str) -> dict[str, Any]:
    """What one calibration's uncertainty gives: the volumetric U and its k, or why not."""
    f = c.figure("volumetric")
    why = c.not_evaluated.get(side)
    if f is None or why:
        return {"U_um": None, "k": None, "not_evaluated": why}
    s = f.significance
    if side == "before":
        return {"U_um": s.U_before, "k": s.k_before, "not_evaluated": None}
    return {"U_um": s.U_after, "k": s.k_after, "not_evaluated": None}


def _at(point: Mapping[str, float]) -> str:
    return ", ".join(f"{a}={point[a]:g}" for a in ("X", "Y", "Z"))


def _value(value: float, U: float | None, places: int = 2, sign: bool = False) -> str:
    """``value`` rounded to what ``U`` supports (GUM 7.2.6), else to ``places`` decimals."""
    if U is not None and U > 0.0:
        text, _ = rounded(value, U)
        return f"+{text}" if sign and not text.startswith("-") else text
    return f"{value:+.{places}f}" if sign else f"{value:.{places}f}"


def _u(U: float | None) -> str:
    if U is None:
        return "-"
    return rounded(U, U)[1] if U > 0.0 else "0"


def _en(s: Significance | None) -> str:
    return "-" if s is None or s.En is None else f"{s.En:.2f}"


def uncertainty_lines(c: Comparison) -> list[str]:
    """How the changes' uncertainty was obtained, or why it was not."""
    f = c.figure("volumetric")
    reason = f.significance.reason if f is not None else None
    evaluated = any(g.significance.U is not None for g in c.figures) or any(
        x.significance is not None and x.significance.U is not None for x in c.components
    )
    if not evaluated:
        why = reason or next(
            (x.significance.reason for x in c.components if x.significance is not None), None
        )
        return [
            "  uncertainty of the changes: not evaluated"
            + (f" ({why})" if why else "")
            + "; En not evaluated"
        ]
    r = f"r = {c.correlation:g}" + (" (independent)" if c.correlation == 0.0 else " (declared)")
    lines = [
        f"  uncertainty of a change: U(Δ) ({coverage_text(K_CHANGE)}) from both calibrations' "
        f"uncertainties, {r};",
        "  En = |Δ| / U(Δ): a change with En <= 1 is not significant (ISO 13528:2015, 9.7)",
    ]
    if reason:
        lines.append(f"  uncertainty of the accuracy changes: not evaluated ({reason})")
    return lines


def compare_text(before: Machine, after: Machine, c: Comparison) -> str:
    """The terminal summary: figures rounded to what their U supports (GUM 7.2.6)."""
    lines = ["esp compare: two calibrations of one machine"]
    for side, m in (("before", before), ("after ", after)):
        info = calibration(m)
        who = ", ".join(v for v in (info["date"], info["operator"]) if v)
        pad = " " * (len(side) - len(side.strip()) + 1)
        lines.append(
            f"  {side.strip()}:{pad}{one_line(m.name)} ({one_line(m.source)})"
            + (f", {one_line(who)}" if who else "")
        )
    if c.identical_inputs:
        lines.append(
            "  identical inputs (the same files, byte for byte): there is nothing to compare"
        )
    elif c.unchanged:
        lines.append("  no change: every component and the error field are the same in both")
    lines += uncertainty_lines(c)
    lines += [
        "",
        "accuracy (µm)            before      after     change     U(Δ)      En   change is",
    ]
    for fig in c.figures:
        if fig.before is None or fig.after is None:
            continue
        s = fig.significance
        label = "volumetric" if fig.key == "volumetric" else f"planar {fig.key.split('.')[1]}"
        lines.append(
            f"  {label:<18} {_value(fig.before, s.U_before):>10} "
            f"{_value(fig.after, s.U_after):>10} {_value(fig.change, s.U, sign=True):>10} "
            f"{_u(s.U):>8} {_en(s):>7}   {verdict(s)}"
        )
    f = c.field
    assert isinstance(f["at"], Mapping)  # field_change(): axis -> position (mm)
    max_um = f["max_um"]
    assert isinstance(max_um, float)  # field_change(): the largest |Δe| (µm)
    whole = c.figure("field")
    s_field = whole.significance if whole is not None else None
    lines += [
        "",
        f"largest change of the error field: {_value(max_um, _U(s_field))} µm "
        f"at {_at(f['at'])} (over {f['points']} points)",
    ]
    if s_field is not None:
        lines.append(f"  {_sig_text(s_field)}")
    directions = f["directions"]
    assert isinstance(directions, Mapping)  # field_change(): direction -> its largest change
    for a, d in directions.items():
        fa = c.figure(f"field.{a}")
        sa = fa.significance if fa is not None else None
        lines.append(
            f"  {a} direction: {_value(d['value_um'], _U(sa), sign=True)} µm at {_at(d['at'])}"
            + (f"; {_sig_text(sa)}" if sa is not None else "")
        )
    lines += [
        "",
        "change per component (after - before; linear and angular curves referred to their "
        "first common point; En the largest along the axis, and where):",
        "  component           max |change|     at mm     U(Δ)      En  En at mm"
        "   change is         range before   range after",
    ]
    only, missing = [], []
    for x in sorted(c.components, key=lambda x: (x.unit, -x.max_abs_change)):
        unit = _UNIT[x.unit]
        at = "-" if x.at_mm is None else f"{x.at_mm:g}"
        sx = x.significance
        if not x.present_before or not x.present_after:
            only.append(f"{x.name} (" + ("after" if x.present_after else "before") + ")")
        if sx is not None and sx.reason and "no U for" in sx.reason:
            missing.append(f"{x.name} ({sx.reason})")
        en_at = "-"
        if sx is not None and sx.En is not None and x.significance_at_mm is not None:
            en_at = f"{x.significance_at_mm:g}"
        U = x.U_at_max
        lines.append(
            f"  {x.name:<20} {_value(x.max_abs_change, U, 3):>8} {unit:<5} {at:>7} "
            f"{_u(U):>8} {_en(sx):>7} {en_at:>9}   {verdict(sx):<15} {x.range_before:12.3f} "
            f"{x.range_after:13.3f}"
        )
    if only:
        lines.append("  measured in one calibration only (zero in the other): " + ", ".join(only))
    if missing:
        lines.append("  En not evaluated: " + "; ".join(missing))
    return "\n".join(lines) + "\n"


def _U(s: Significance | None) -> float | None:
    return None if s is None else s.U


def _sig_text(s: Significance) -> str:
    if s.En is None:
        return f"U(Δ) and En {verdict(s)}"
    return f"U(Δ) = {_u(s.U)} µm, En = {_en(s)}: {verdict(s)}"


def _headline_u(U: float | None, k: float) -> str | None:
    return None if U is None else f"U = {_u(U)} µm ({coverage_text(k)})"


def calibration_fields(before: Machine, after: Machine) -> list[tuple[str, str]]:
    """The title block of a comparison: the machine's serial, and each calibration's date,
    operator and name."""
    fields = []
    serial = (before.report.serial if before.report is not None else None) or before.info.get(
        "serial"
    )
    if serial:
        fields.append(("Serial", str(serial)))
    for label, m in (("Before", before), ("After", after)):
        info = calibration(m)
        parts = [info["date"] or "date not given", info["operator"] or "operator not given"]
        parts.append(info["name"])
        fields.append((label, one_line(", ".join(parts))))
    return fields


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
    visit in the style of every esp report (:mod:`esp.report.document`): both calibrations
    in the title block, the accuracies before and after with their U and the change with
    U(Δ) and En, the change of the error field and of every component, the figures, the
    provenance. Returns the number of pages."""
    from esp.report.document import Headline, write_text_document
    from esp.report.epoch import report_date

    f = c.figure("volumetric")
    s = f.significance if f is not None else None
    U_b, U_a = (s.U_before, s.U_after) if s is not None else (None, None)
    k_b, k_a = (s.k_before, s.k_after) if s is not None else (2.0, 2.0)
    change_u = None
    if s is not None and s.U is not None:
        change_u = f"U(Δ) = {_u(s.U)} µm ({coverage_text(s.k)}), En = {_en(s)}: {verdict(s)}"
    rows = [
        Headline(
            "Volumetric accuracy before",
            f"{_value(c.volumetric_before[0], U_b, 3)} µm",
            _headline_u(U_b, k_b),
        ),
        Headline(
            "Volumetric accuracy after",
            f"{_value(c.volumetric_after[0], U_a, 3)} µm",
            _headline_u(U_a, k_a),
        ),
        Headline(
            "Change",
            f"{_value(c.volumetric_change_um, s.U if s else None, 3, sign=True)} µm",
            change_u,
        ),
    ]
    r = f"r = {c.correlation:g}" + (" (independent)" if c.correlation == 0.0 else " (declared)")
    if s is not None and s.U is not None:
        note = (
            f"Uncertainty of a change: U(Δ) = k·√(u_before² + u_after² − 2r·u_before·u_after), "
            f"k = {K_CHANGE:g}, {r} (GUM 5.2.2); En = |Δ| / U(Δ), a change with En ≤ 1 is "
            "within the uncertainties, not significant (ISO 13528:2015, 9.7)."
        )
    else:
        why = s.reason if s is not None and s.reason else "no uncertainty"
        note = f"Uncertainty of the change: not evaluated ({why}); En not evaluated."
    captions = [
        "the largest change of every component, after minus before; faded: within U(Δ)",
        "the change along the axis of the components with the largest En, with ±U(Δ)",
        "the curves of the components that changed most, before and after",
    ]
    return write_text_document(
        path,
        title="Comparison of two calibrations",
        name=after.name,
        date=report_date(),
        text=text,
        skip=1,
        headlines=rows,
        fields=calibration_fields(before, after),
        figures=list(zip(figures, captions, strict=False)),
        provenance=provenance,
        note=note,
        section="Changes",
    )
