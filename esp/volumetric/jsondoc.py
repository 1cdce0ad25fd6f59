"""The JSON contracts of ``esp analyse``: ``esp.result/1`` (the grid) and ``esp.point/1``
(one point). Documented in ``docs/json.md``; the key order here is the documented one."""

from __future__ import annotations

import math
from collections.abc import Mapping

from esp.core.machine import AXIS_NAMES, Machine
from esp.core.names import ComponentName
from esp.core.results import (
    AnalysisResult,
    Breakdown,
    BudgetLine,
    PointResult,
    ToolCase,
    UncertaintyResult,
)
from esp.report.words import is_plan

__all__ = ["machine_dict", "point_dict", "result_dict", "uncertainty_dict"]


def _xyz(mapping: Mapping[str, float]) -> dict:
    return {a: mapping[a] for a in AXIS_NAMES}


def machine_dict(machine: Machine) -> dict:
    """Machine details, axes and inputs, as every report shows them."""
    components = []
    for name, comp in machine.components.items():
        entry: dict[str, object] = {
            "component": name,
            "iso": comp.iso,
            "kind": comp.kind,
            "description": ComponentName.parse(name).description,
            "unit": comp.unit,
            "source": comp.source,
        }
        if comp.kind == "squareness":
            entry["value"] = comp.value
        components.append(entry)
    return {
        "name": machine.name,
        **dict(machine.info),
        "configuration": machine.configuration,
        "notation": machine.notation,
        "description": machine.description,
        "roles": dict(machine.roles),
        "axes": {
            a: {
                "role": ax.role,
                "travel_mm": list(ax.travel_mm),
                "simulate_mm": list(ax.simulate_mm),
                "step_mm": ax.step_mm,
                "offset_mm": ax.offset_mm,
            }
            for a, ax in machine.axes.items()
        },
        "components": components,
        "source": machine.source,
    }


def _tool(tool: ToolCase) -> dict:
    out = {
        "length_mm": tool.length_mm,
        "tilt_deg": tool.tilt_deg,
        "spin_deg": tool.spin_deg,
        "offset_mm": _xyz(tool.offset_mm),
    }
    if tool.setting_deg:
        out["setting_deg"] = dict(tool.setting_deg)
    return out


def _terms(b: Breakdown) -> list[dict]:
    return [
        {
            "direction": t.direction,
            "component": t.component,
            "iso": t.iso,
            "source": t.source,
            "term": t.symbol,
            "value_um": t.value_um,
            "share_pct": t.share_pct,
        }
        for t in b.terms
    ]


def _analysis(result: AnalysisResult | PointResult) -> dict:
    a = result.machine.analysis
    return {
        "point": a.point,
        "compensation": a.compensation,
        "case": result.case,
        "equations": result.equations,
        "direction": a.direction,
        "datum": None if result.datum is None else _xyz(result.datum),
        "straightness_fit": a.straightness_fit,
        "extrapolate": a.extrapolate,
    }


def result_dict(result: AnalysisResult) -> dict:
    """The ``esp.result/1`` document of an analysis. An uncertainty plan (no error data,
    :func:`~esp.report.words.is_plan`) claims no accuracy: its cases hold only the tool and
    the grid, ``worst.accuracy_um`` is null and ``worst.uncertainty_um`` holds the
    headline, the expanded volumetric uncertainty."""
    plan = is_plan(result)
    cases = []
    for c in result.cases:
        if plan:
            cases.append({"tool": _tool(c.tool), "grid_points": c.points})
            continue
        cases.append(
            {
                "tool": _tool(c.tool),
                "volumetric": {"accuracy_um": c.volumetric.value_um, "at": _xyz(c.volumetric.at)},
                "planar": {
                    plane: {"accuracy_um": e.value_um, "at": _xyz(e.at)}
                    for plane, e in c.planar.items()
                },
                "axes": {
                    a: {
                        "min_um": e.minimum.value_um,
                        "min_at": _xyz(e.minimum.at),
                        "max_um": e.maximum.value_um,
                        "max_at": _xyz(e.maximum.at),
                        "range_um": e.range_um,
                    }
                    for a, e in c.axes.items()
                },
                "breakdown": [
                    {
                        "label": b.label,
                        "at": _xyz(b.at),
                        "errors_um": _xyz(b.errors_um),
                        "volumetric_um": b.volumetric_um,
                        "terms": _terms(b),
                    }
                    for b in c.breakdowns
                ],
                "grid_points": c.points,
            }
        )
    worst: dict[str, object] = {
        "case": result.worst,
        "accuracy_um": None if plan else result.cases[result.worst].volumetric.value_um,
    }
    if plan and result.uncertainty is not None:
        worst["uncertainty_um"] = result.uncertainty.volumetric.value_um
    doc = {
        "schema": "esp.result/1",
        "machine": machine_dict(result.machine),
        "analysis": {
            **_analysis(result),
            "case_description": result.case_description,
            "grid": dict(result.grid_sizes),
            "plane_of_motion": result.plane_of_motion,
            "active": list(result.active),
            "not_active": list(result.inactive),
            "ignored": list(result.ignored),
            "warnings": list(result.warnings),
            "plan": plan,
            "uncertainty_missing": [str(n) for n in result.uncertainty_missing],
        },
        "cases": cases,
        "worst": worst,
    }
    if result.uncertainty is not None:
        doc["uncertainty"] = uncertainty_dict(result.uncertainty)
    if result.sweep and not plan:
        doc["sweep"] = [
            {
                **_tool(e.tool),
                "accuracy_um": e.volumetric.value_um,
                "at": _xyz(e.volumetric.at),
            }
            for e in result.sweep
        ]
    from esp.volumetric.conformance import decisions_of

    decisions = decisions_of(result)  # ISO 14253-1 verdicts, when tolerances are given
    if decisions:
        doc["decisions"] = [d.as_dict() for d in decisions]
    return doc


def _finite_or_none(value: float) -> float | None:
    """A number, or None for an infinite one (degrees of freedom of a Type B value)."""
    return value if math.isfinite(value) else None


def _budget_line(b: BudgetLine, k: float) -> dict:
    entry = {
        "component": b.component,
        "iso": b.iso,
        "model": b.model,
        "U": b.U,
        "unit": b.unit,
        "share_pct": b.share_pct,
    }
    # added keys: the component's coverage factor, standard uncertainty, largest U along
    # its axis, distribution, degrees of freedom (null: infinite) and contribution (µm)
    extra = {
        "k": getattr(b, "k", k),
        "u": getattr(b, "u", None),
        "U_max": getattr(b, "U_max", None),
        "distribution": getattr(b, "distribution", None),
        "dof": getattr(b, "dof", None),
        "contribution_um": getattr(b, "contribution_um", None),
    }
    for key, value in extra.items():
        if key == "dof" and value is not None:
            entry[key] = _finite_or_none(value)
        elif value is not None:
            entry[key] = value
    # added key: what makes u, each a standard uncertainty in the component's unit (their
    # root-sum-square is u; sensitivity 1: every contributor is stated in that unit)
    entry["contributors"] = [
        {
            "name": c.name,
            "u": c.u,
            "unit": c.unit,
            "sensitivity": 1.0,
            "contribution": c.u,
            "dof": _finite_or_none(c.dof),
            "type": "A" if math.isfinite(c.dof) else "B",
        }
        for c in getattr(b, "contributors", ())
    ]
    return entry


def uncertainty_dict(u: UncertaintyResult) -> dict:
    """The ``uncertainty`` block of ``esp.result/1``."""
    doc = {
        "method": u.method,
        "k": u.k,
        "volumetric_um": u.volumetric.value_um,
        "at": _xyz(u.volumetric.at),
        "axes": {a: {"max_um": e.value_um, "at": _xyz(e.at)} for a, e in u.axes.items()},
        "budget": [_budget_line(b, u.k) for b in u.budget],
    }
    # added keys (schema unchanged): where the budget is evaluated and what it combines to
    doc["budget_at"] = _xyz(getattr(u, "budget_at", u.volumetric.at))
    # true for the summation method: the figures are bounds, not expanded variances
    doc["bound"] = u.method == "summation"
    # true when U is the same at every point (``at`` is then only the first grid point)
    doc["uniform"] = bool(getattr(u, "uniform", False))
    for key in ("u_um", "dof_eff", "coverage"):
        if getattr(u, key, None) is not None:
            doc[key] = _finite_or_none(getattr(u, key))
    if u.montecarlo is not None:
        mc = u.montecarlo
        montecarlo: dict[str, object] = {
            "mean_um": mc.mean_um,
            "std_um": mc.std_um,
            "interval_um": list(mc.interval_um),
            "samples": mc.samples,
            "seed": mc.seed,
        }
        doc["montecarlo"] = montecarlo
        # added keys: the grid points each draw is the maximum over, and the float type
        for key in ("grid_points", "dtype"):
            if getattr(mc, key, None):
                montecarlo[key] = getattr(mc, key)
    if u.prior is not None:
        doc["prior"] = dict(u.prior)
    return doc


def point_dict(result: PointResult) -> dict:
    """The ``esp.point/1`` document of a single-point evaluation."""
    return {
        "schema": "esp.point/1",
        "machine": {"name": result.machine.name, "configuration": result.machine.configuration},
        "analysis": _analysis(result),
        "warnings": list(result.warnings),
        "cases": [
            {
                "tool": _tool(pc.tool),
                "at": _xyz(pc.breakdown.at),
                "errors_um": _xyz(pc.breakdown.errors_um),
                "volumetric_um": pc.breakdown.volumetric_um,
                "terms": _terms(pc.breakdown),
            }
            for pc in result.cases
        ],
    }
