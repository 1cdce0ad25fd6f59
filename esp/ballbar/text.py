"""The result of ``esp ballbar`` as a JSON document and as text."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from esp.ballbar.analysis import CircleTest
from esp.ballbar.diagnosis import Term
from esp.ballbar.verdicts import K, expanded_uncertainty
from esp.core.conformity import Decision
from esp.core.rounding import coverage_text, rounded

__all__ = [
    "SCHEMA",
    "ballbar_dict",
    "ballbar_text",
    "condition_pairs",
    "figure_text",
    "term_text",
]

SCHEMA = "esp.ballbar/2"


def figure_text(value: float, expanded: float | None, unit: str = "µm") -> str:
    """``"3.46 µm, U = 0.29 µm"`` rounded to U (GUM 7.2.6), or three decimals without U."""
    if expanded is None or not expanded > 0.0:
        return f"{value:.3f} {unit}"
    v, u = rounded(value, expanded)
    return f"{v} {unit}, U = {u} {unit}"


def term_text(t: Term) -> tuple[str, str]:
    """(value, verdict) of a diagnosis term: ``("+3.00 µm, U = 0.014 µm", "reported")``."""
    if t.value is None:
        return "not given", t.note
    if t.u is None or not t.u > 0.0:
        return f"{t.value:.3f} {t.unit}", t.note or "none"
    v, u = rounded(t.value, K * t.u)
    sign = "+" if t.value > 0 and not v.startswith("-") and float(v) != 0.0 else ""
    extra = f", period {t.extra['period_mm']:.4g} mm" if "period_mm" in t.extra else ""
    if t.reported:
        verdict = "reported"
    elif "threshold_um" in t.extra:
        verdict = f"none (below {t.extra['threshold_um']:.2g} {t.unit})"
    else:
        verdict = f"none (within {t.coverage:g} u)"
    return f"{sign}{v} {t.unit}, U = {u} {t.unit}{extra}", verdict


def condition_pairs(t: CircleTest) -> list[tuple[str, str]]:
    """The test conditions of a circle as (label, value), "not stated" where unknown."""
    c = t.conditions
    d = t.diagnosis
    directions = ", ".join(
        f"{r.direction} ({'angle increasing' if r.direction == 'ccw' else 'angle decreasing'})"
        for r in t.circle.runs
    )
    arc = "full circle" if d.full_circle else f"{d.arc_span_deg:.0f}° from {d.arc_start_deg:.0f}°"

    def given(v: object, unit: str = "") -> str:
        return "not stated" if v is None else f"{v:g}{unit}" if isinstance(v, float) else str(v)

    pairs = [
        ("Machine", given(c.machine)),
        ("Date", given(c.date)),
        ("Operator", given(c.operator)),
        ("Plane", f"{t.plane} (angle from +{t.plane[0]} towards +{t.plane[1]})"),
        ("Radius", f"{t.radius_mm:g} mm"),
        ("Arc", arc),
        ("Direction", directions),
        ("Feed", given(c.feed_mm_per_min, " mm/min")),
        ("Ballbar", given(c.ballbar)),
        (
            "Calibration",
            "length not calibrated (no U stated)"
            if c.calibration_U_um is None
            else f"length U = {c.calibration_U_um:g} µm (k = 2)",
        ),
        (
            "Transducer",
            ", ".join(
                s
                for s in (
                    f"accuracy ±{c.accuracy_um:g} µm" if c.accuracy_um is not None else "",
                    f"resolution {c.resolution_um:g} µm" if c.resolution_um is not None else "",
                )
                if s
            )
            or "accuracy and resolution not stated",
        ),
    ]
    pairs += [(k, v) for k, v in c.other]
    return pairs


def _iso_lines(t: CircleTest) -> list[str]:
    c = t.conditions
    UF = expanded_uncertainty("F", c)
    UG = expanded_uncertainty("G", c)
    out = []
    for d in t.directions:
        if UF:
            lo, hi = (rounded(v, UF)[0] for v in (d.F_min_um, d.F_max_um))
            span = f"{lo} .. {hi} µm (U = {rounded(0.0, UF)[1]} µm)"
        else:
            span = f"{d.F_min_um:+.3f} .. {d.F_max_um:+.3f} µm"
        out.append(
            f"  {d.direction:<4} radial deviation F {span}, "
            f"circular deviation G {figure_text(d.G_um, UG)}"
        )
    if t.G_bidirectional_um is not None and t.H_um is not None:
        out.append(
            f"  bidirectional circular deviation G(b) {figure_text(t.G_bidirectional_um, UG)}, "
            f"circular hysteresis H {figure_text(t.H_um, UG)}"
        )
    if UG is None:
        out.append(
            "  uncertainty of F, G, H: not evaluated (the ballbar's accuracy or resolution "
            "is not stated)"
        )
    else:
        out.append(f"  U with {coverage_text(K)}, from the ballbar's stated specification")
    return out


def ballbar_text(tests: Sequence[CircleTest], decided: Sequence[Decision] = ()) -> str:
    out = ["esp ballbar: ISO 230-4 circular tests", ""]
    for t in tests:
        centre = ", ".join(f"{v:g}" for v in t.circle.centre_mm)
        d = t.diagnosis
        arc = "" if d.full_circle else f", arc {d.arc_span_deg:.0f}° from {d.arc_start_deg:.0f}°"
        out.append(
            f"Circle {t.name} in {t.plane}, centre ({centre}) mm, radius {t.radius_mm:g} mm{arc}"
        )
        stated = [f"{k.lower()} {v}" for k, v in condition_pairs(t)[:3] if v != "not stated"]
        feed = t.conditions.feed_mm_per_min
        out.append(
            "  conditions: "
            + "; ".join(stated + [f"feed {feed:g} mm/min" if feed else "feed not stated"])
        )
        out += _iso_lines(t)
        out.append(
            f"  diagnosis (noise {d.noise_um:.3f} µm; U with k = 2; a term is reported "
            "beyond its coverage of u):"
        )
        width = max(len(term.label) for term in d.terms)
        for term in d.terms:
            value, verdict = term_text(term)
            out.append(f"    {term.label:<{width}}  {value}  {verdict}".rstrip())
        for note in d.notes:
            out.append(f"  note: {note}")
        out.append(
            f"  centre offset of the least-squares circle ({t.plane[0]}, {t.plane[1]}): "
            f"{t.centre_offset_um[0]:+.3f}, {t.centre_offset_um[1]:+.3f} µm"
        )
        out.append("")
    if decided:
        out.append("Decisions")
        for dec in decided:
            shown = figure_text(dec.value, dec.expanded, dec.unit).split(",")[0]
            out.append(f"  {dec.text(shown)}")
        out.append("")
    return "\n".join(out)


def ballbar_dict(tests: Sequence[CircleTest], decided: Sequence[Decision] = ()) -> dict[str, Any]:
    circles = []
    for t in tests:
        c = t.conditions
        d = t.diagnosis
        circles.append(
            {
                "name": t.name,
                "file": t.file,
                "plane": t.plane,
                "centre_mm": list(t.circle.centre_mm),
                "radius_mm": t.radius_mm,
                "arc": {"start_deg": d.arc_start_deg, "span_deg": d.arc_span_deg},
                "conditions": c.as_dict(),
                "directions": [
                    {
                        "direction": r.direction,
                        "F_max_um": r.F_max_um,
                        "F_min_um": r.F_min_um,
                        "G_um": r.G_um,
                    }
                    for r in t.directions
                ],
                "G_bidirectional_um": t.G_bidirectional_um,
                "H_um": t.H_um,
                "expanded_uncertainty_um": {
                    "F": expanded_uncertainty("F", c),
                    "G": expanded_uncertainty("G", c),
                    "H": expanded_uncertainty("H", c),
                    "k": K,
                },
                "centre_offset_um": list(t.centre_offset_um),
                "diagnosis": {
                    "noise_um": d.noise_um,
                    "terms": [term.as_dict() for term in d.terms],
                    "notes": list(d.notes),
                },
            }
        )
    return {
        "schema": SCHEMA,
        "circles": circles,
        "decisions": [dec.as_dict() for dec in decided],
    }
