"""Rendering of an identification: text, the JSON document ``esp.identify/1`` and the
figures (each identified curve with its band, the residuals of each measurement set).
Computation is in :mod:`esp.identify.run`; nothing here computes."""

from __future__ import annotations

import math
import os
from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Any

from esp.core.rounding import coverage_text
from esp.identify.axislines import linuxcnc_lines
from esp.identify.rotary import iso_notation
from esp.identify.run import Curve, IdentifyResult

if TYPE_CHECKING:
    from matplotlib.figure import Figure

    from esp.report.provenance import Provenance

__all__ = [
    "SCHEMA",
    "birge_verdict",
    "curves_figure",
    "identify_dict",
    "identify_text",
    "residuals_figure",
]

SCHEMA = "esp.identify/1"
_DPI = 100


def _num(v: float) -> float | None:
    return float(v) if math.isfinite(v) else None


def _readings(result: IdentifyResult) -> int:
    """The readings of the fitted sets: a row of a measurement file each (a ball's point,
    a ballbar's length, a distance from a station), one count throughout the report."""
    return sum(s.readings for s in result.sets if s.use == "fit")


def _calibrations(result: IdentifyResult) -> int:
    """The common calibration errors of the fitted sets (one residual each: their prior)."""
    return sum(1 for n in result.names if ".calibration." in n)


def _residuals_text(result: IdentifyResult) -> str:
    """The one count of readings, and how the residuals of the fit are made of them:
    ``"100 readings (301 residuals: 3 per point, 1 per artefact calibration)"``."""
    i = result.identifiability
    readings = _readings(result)
    cal = _calibrations(result)
    rows = i.readings - cal
    parts = []
    if rows != readings:
        parts.append("3 per point" if rows == 3 * readings else f"{rows} of the readings")
    elif cal:
        parts.append("1 per reading")
    if cal:
        parts.append("1 per artefact calibration")
    detail = f": {', '.join(parts)}" if parts else ""
    return f"{readings} readings ({i.readings} residuals{detail})"


def birge_verdict(result: IdentifyResult) -> str:
    """The Birge ratio of the fit in words: whether the readings agree with the model
    within their stated uncertainties (χ² within its 97.5 % quantile; docs/identify.md,
    "Uncertainty")."""
    if result.plan:
        return ""
    if result.dof <= 0 or not math.isfinite(result.birge):
        return "no degrees of freedom are left: the agreement of the readings cannot be tested"
    if result.consistent:
        return (
            "the readings agree with the model within their stated u "
            f"(Birge ratio {result.birge:.2f})"
        )
    return (
        "the readings scatter more than their stated u explain "
        f"(Birge ratio {result.birge:.2f}, χ² above its 97.5 % quantile): the stated "
        "uncertainties, or the basis, are too small, and so is every U of this report"
    )


def _identifiability(result: IdentifyResult) -> dict[str, Any]:
    i = result.identifiability
    return {
        "readings": _readings(result),
        "residuals": i.readings,
        "parameters": i.parameters,
        "rank": i.rank,
        "condition_number": _num(i.condition),
        "singular_values": [float(s) for s in i.singular_values],
        "not_seen": list(i.invisible),
        "combinations": [[{"name": n, "weight": w} for n, w in c] for c in i.combinations],
        "sentences": i.sentences(),
        "fixed": list(result.fixed),
        "null": result.null,
    }


def identify_dict(result: IdentifyResult) -> dict[str, Any]:
    """The JSON document (docs/json.md, ``esp.identify/1``)."""
    doc: dict[str, Any] = {
        "schema": SCHEMA,
        "machine": result.machine_name,
        "plan": result.plan,
        "k": result.k,
        "identifiability": _identifiability(result),
        "components": [
            {
                "name": c.name,
                "key": c.key,
                "unit": c.unit,
                "coefficients": [
                    {"label": lab, "value": None if result.plan else v, "u": u}
                    for lab, v, u in c.coefficients
                ],
                **(
                    {"targets_deg": list(c.targets_mm), "axis": c.angle_axis}
                    if c.target_unit == "deg"
                    else {"targets_mm": list(c.targets_mm)}
                ),
                "values": None if result.plan else list(c.values),
                "U": list(c.U),
                "valuation": c.valuation,
            }
            for c in result.curves
        ],
        "parameters": [
            {"name": n, "value": None if result.plan else v, "u": u}
            for n, v, u in zip(result.names, result.values, result.u, strict=True)
        ],
        "largest_correlation": result.correlation_max,
        "axis_lines": [
            {
                "axis": line.axis,
                "nominal_point_mm": list(line.nominal_point_mm),
                "nominal_direction": list(line.nominal_direction),
                "point_mm": None if result.plan else list(line.point_mm),
                "direction": None if result.plan else list(line.direction),
                "offset_um": None if result.plan else list(line.offset_um),
                "tilt_urad": None if result.plan else list(line.tilt_urad),
                "U_offset_um": list(line.U_offset_um),
                "U_tilt_urad": list(line.U_tilt_urad),
            }
            for line in result.axis_lines
        ],
        "linuxcnc": None
        if result.linuxcnc is None
        else {"module": result.linuxcnc[0], "parameters": dict(result.linuxcnc[1])},
        "residuals_before_after": [
            {
                "set": name,
                "rms_nominal_um": a,
                "max_nominal_um": b,
                "rms_identified_um": c,
                "max_identified_um": d,
            }
            for name, a, b, c, d in result.before_after
        ],
        "sets": [
            {
                "name": s.name,
                "kind": s.kind,
                "use": s.use,
                "files": list(s.files),
                "readings": s.readings,
                "residuals": s.residuals,
                "rms_normalised": None if result.plan else s.rms_normalised,
                "max_normalised": None if result.plan else s.max_normalised,
                "max_residual_um": None if result.plan else s.max_residual_um,
                "worst_at": None if result.plan else {"file": s.worst_at[0], "line": s.worst_at[1]},
                "tool_mm": _tool_json(s.tool_mm),
            }
            for s in (*result.sets, *result.checks)
        ],
        "fit": None
        if result.plan
        else {
            "chi2": result.chi2,
            "dof": result.dof,
            "birge_ratio": _num(result.birge),
            "chi2_limit_97_5": _num(result.chi2_limit),
            "consistent": result.consistent,
        },
        "volumetric": None
        if result.volumetric is None
        else {
            "value_um": result.volumetric.value_um,
            "at_mm": dict(result.volumetric.at),
            "U_um": result.volumetric.U_um,
            "U_uncorrelated_um": result.volumetric.U_uncorrelated_um,
            "k": result.volumetric.k,
            "settings": [
                {
                    "setting_deg": dict(setting),
                    "value_um": v.value_um,
                    "at_mm": dict(v.at),
                    "U_um": v.U_um,
                    "U_uncorrelated_um": v.U_uncorrelated_um,
                }
                for setting, v in result.volumetric.settings
            ],
        },
        "expected_U_um": result.expected_u_um,
        "montecarlo": None
        if result.montecarlo is None
        else {
            "samples": result.montecarlo.samples,
            "seed": result.montecarlo.seed,
            "u_ratio_min": result.montecarlo.u_ratio_min,
            "u_ratio_max": result.montecarlo.u_ratio_max,
            "volumetric_U_um": _num(result.montecarlo.volumetric_U_um),
        },
        "residuals": [
            {"set": s, "file": f, "line": ln, "residual_um": r, "normalised": z}
            for s, f, ln, r, z in result.residuals
        ],
        "warnings": list(result.warnings),
    }
    return doc


def _tool_json(
    tool: Sequence[float] | Mapping[str, Sequence[float]] | None,
) -> list[float] | dict[str, list[float]] | None:
    """A set's tool offsets for JSON: None (the machine's), [x, y, z], or label -> [x, y, z]."""
    if tool is None:
        return None
    if isinstance(tool, Mapping):
        return {label: list(xyz) for label, xyz in tool.items()}
    return list(tool)


def _tool_text(tool: Sequence[float] | Mapping[str, Sequence[float]]) -> str:
    def xyz(v: Sequence[float]) -> str:
        return "(" + ", ".join(f"{c:g}" for c in v) + ") mm"

    if isinstance(tool, Mapping):
        return "tool offsets: " + ", ".join(f"{k} {xyz(v)}" for k, v in tool.items())
    return f"tool offset {xyz(tool)}"


def _value_u(value: float, expanded: float, signed: bool = False) -> tuple[str, str]:
    """A value and its U as read: U to two significant digits, the value to the same
    decimal place (GUM 7.2.6; :mod:`esp.core.rounding`); without a usable U, 4 digits."""
    from esp.core.rounding import rounded

    if not (math.isfinite(expanded) and expanded > 0):
        return f"{value:{'+' if signed else ''}.4g}", f"{expanded:.3g}"
    v, u = rounded(value, expanded)
    if signed and not v.startswith("-") and v.strip("0.") != "":
        v = "+" + v
    return v, u


def _u_text(expanded: float) -> str:
    return _value_u(0.0, expanded)[1]


#: the units of a set's common calibration errors, by the last part of their name
_CALIBRATION_UNITS = {
    "length": "um",
    "scale": "um/m",
    "probe_x": "um",
    "probe_y": "um",
    "probe_z": "um",
}


def _calibration_lines(result: IdentifyResult, set_name: str) -> list[str]:
    """The set's common calibration errors: the estimate and its standard uncertainty."""
    out = []
    prefix = f"{set_name}.calibration."
    for n, v, u in zip(result.names, result.values, result.u, strict=True):
        if n.startswith(prefix):
            what = n[len(prefix) :]
            unit = _CALIBRATION_UNITS.get(what, "")
            value = "" if result.plan else f"estimate {_value_u(v, 2 * u, signed=True)[0]} {unit}, "
            kind = next((t.kind for t in result.sets if t.name == set_name), "")
            if what.startswith("probe_"):
                thing = f"the probe's offset along {what[-1].upper()}"
            elif kind == "rtest":
                thing = "the sensors' gain"
            else:
                thing = f"the artefact's {what}"
            out.append(
                f"calibration of {thing}, common to its readings: {value}u = {_u_text(u)} {unit}"
            )
    return out


def _axis_line_lines(result: IdentifyResult) -> list[str]:
    """The kinematic corrections: each table and head axis' line at the zero setting, its
    offset and tilt with their U, LinuxCNC's parameters, and the measurement's residuals
    with the nominal and the identified table or head."""
    if not result.axis_lines:
        return []
    cover = coverage_text(result.k)
    out: list[str] = []
    for owner, frame in (("table", "machine coordinates"), ("head", "the head's base frame")):
        lines = [line for line in result.axis_lines if line.owner == owner]
        if not lines:
            continue
        out.append("")
        out.append(f"Axis lines of the {owner} at the zero setting, {frame} (U at {cover})")
        for line in lines:
            if result.plan:
                out.append(
                    f"  {line.axis}: offset U ({_triple_u(line.U_offset_um)}) um, "
                    f"tilt U ({_triple_u(line.U_tilt_urad)}) urad"
                )
                continue
            p = ", ".join(f"{v:.4f}" for v in line.point_mm)
            d = ", ".join(f"{v:.7f}" for v in line.direction)
            out.append(
                f"  {line.axis}: point ({p}) mm, offset "
                f"({_triple(line.offset_um, line.U_offset_um)}) um, "
                f"U ({_triple_u(line.U_offset_um)}) um"
            )
            out.append(
                f"     direction ({d}), tilt ({_triple(line.tilt_urad, line.U_tilt_urad)}) "
                f"urad, U ({_triple_u(line.U_tilt_urad)}) urad"
            )
    held = [c.name for c in result.curves if c.device and _fixed(result, c)]
    if held:
        out.append(
            f"  with {', '.join(held)} held at their fixed values (identify.fix): the lines "
            "are as certain as those values, which the readings do not see"
        )
    if result.linuxcnc is not None and not result.plan:
        module, params = result.linuxcnc
        out.append(f"  LinuxCNC {module} (positions only; the tilts above are not held):")
        out.extend(f"    {line}" for line in linuxcnc_lines(module, params))
    for name, rms0, max0, rms1, max1 in result.before_after:
        out.append(
            f"  {name}: residuals rms {rms0:.3g} um (largest {max0:.3g} um) with the nominal "
            f"errors of the table and head, {rms1:.3g} um (largest {max1:.3g} um) with the "
            "identified ones"
        )
    return out


#: below this (µm, µrad) a coordinate of an axis line is not a figure: the offset along the
#: line itself and the change of its direction's length are of second order
_LINE_FLOOR = 1e-2


def _triple(values: Sequence[float], U: Sequence[float]) -> str:
    return ", ".join(
        "0" if u < _LINE_FLOOR else _value_u(v, u, signed=True)[0]
        for v, u in zip(values, U, strict=True)
    )


def _triple_u(U: Sequence[float]) -> str:
    return ", ".join("0" if u < _LINE_FLOOR else _u_text(u) for u in U)


def identify_text(result: IdentifyResult) -> str:
    """The report as text."""
    i = result.identifiability
    title = "plan" if result.plan else "identification"
    out = [f"esp identify ({title}): {result.machine_name}", ""]
    out.append("Identifiability")
    out.append(
        f"  {_residuals_text(result)}, {i.parameters} free parameters, rank {i.rank}, "
        f"condition number {i.condition:.3g}"
    )
    sv = i.singular_values
    if sv:
        out.append(f"  singular values (scaled): largest {sv[0]:.4g}, smallest {sv[-1]:.4g}")
    if result.fixed:
        out.append(f"  fixed by the user: {', '.join(result.fixed)}")
    for sentence in i.sentences():
        out.append(f"  - {sentence}")
    if i.identifiable:
        out.append("  every free parameter is identifiable")
    out.append("")
    out.append("Sets")
    for s in (*result.sets, *result.checks):
        line = f"  {s.name:<14} {s.kind:<20} {s.readings:>6} readings"
        if not result.plan:
            line += (
                f"  rms {s.rms_normalised:.3g} u, max {s.max_normalised:.3g} u "
                f"({s.max_residual_um:+.4g} um, {s.worst_at[0]}:{s.worst_at[1]})"
            )
        if s.use == "check":
            line += "  [check, not fitted]"
        out.append(line)
        if s.tool_mm is not None:
            out.append(f"    {_tool_text(s.tool_mm)}")
        out.extend(f"    {line}" for line in _calibration_lines(result, s.name))
    k = result.k
    cover = coverage_text(k)
    if not result.plan:
        out.append("")
        out.append(
            f"Fit: chi2 = {result.chi2:.5g} for {result.dof} degrees of freedom: "
            f"{birge_verdict(result)}"
        )
    out.append("")
    out.append(
        f"Components (U at {cover}{', expected' if result.plan else ''}; valuation: how "
        "well the readings determine each alone, 1 = independently, near 0 = confounded)"
    )
    for c in result.curves:
        unit = _unit(c)
        seen = "" if c.valuation is None else f"  valuation {c.valuation:.2f}"
        if _fixed(result, c):
            held = f"{c.values[0]:g} {unit}" if not c.targets_mm else "its start"
            out.append(f"  {c.name:<20} fixed at {held} (identify.fix): not identified")
            continue
        if not c.targets_mm:
            if result.plan:
                out.append(f"  {c.name:<20} U {_u_text(c.U[0])} {unit}{seen}")
            else:
                value, U = _value_u(c.values[0], c.U[0], signed=True)
                out.append(f"  {c.name:<20} {value} {unit}  U {U} {unit}{seen}")
            continue
        if result.plan:
            out.append(f"  {c.name:<20} U up to {_u_text(max(c.U))} {unit}{seen}")
            continue
        U_max = max(c.U)
        span = _value_u(max(c.values) - min(c.values), U_max)[0]
        lo, U = _value_u(min(c.values), U_max, signed=True)
        hi = _value_u(max(c.values), U_max, signed=True)[0]
        out.append(
            f"  {c.name:<20} range {span} {unit}, from {lo} to {hi}; U up to {U} {unit}{seen}"
        )
    out.append(f"  largest correlation between coefficients: {result.correlation_max:.3f}")
    out.extend(_axis_line_lines(result))
    if result.volumetric is not None:
        v = result.volumetric
        at = ", ".join(f"{a} {x:g}" for a, x in v.at.items())
        value, U = _value_u(v.value_um, v.U_um)
        out.append("")
        out.append(
            f"Volumetric accuracy {value} um at ({at}) mm, U = {U} um "
            f"({coverage_text(v.k)}; correlations kept; "
            f"{_u_text(v.U_uncorrelated_um)} um if they were dropped)"
        )
        if v.settings:
            axes = list(v.settings[0][0])
            out.append(
                "  per setting (" + ", ".join(f"{a} deg" for a in axes) + "): volumetric "
                "accuracy and its U, each referred to the datum with the first setting"
            )
            for setting, there in v.settings:
                at = ", ".join(f"{a} {setting[a]:g}" for a in axes)
                value, U = _value_u(there.value_um, there.U_um)
                out.append(f"    {at}: {value} um, U = {U} um")
    if result.expected_u_um is not None:
        out.append("")
        out.append(
            f"Largest expected U of a displacement error over the volume: "
            f"{_u_text(result.expected_u_um)} um ({cover})"
        )
    if result.montecarlo is not None:
        m = result.montecarlo
        out.append("")
        out.append(
            f"Monte Carlo: {m.samples} re-fits (seed {m.seed}); spread / stated u of the "
            f"coefficients from {m.u_ratio_min:.3g} to {m.u_ratio_max:.3g}; volumetric U "
            f"{_u_text(m.volumetric_U_um)} um ({cover})"
        )
    if result.warnings:
        out.append("")
        out.extend(f"warning: {w}" for w in result.warnings)
    return "\n".join(out) + "\n"


_SHOWN_UNITS = {"um": "µm", "urad": "µrad", "um/m": "µm/m"}


def _unit(c: Curve) -> str:
    """The unit a component is shown in: a table's error in its symbol's unit (µm or
    µrad), an axis' curve in µm or µrad, a squareness in µm/m."""
    if c.device:
        return c.unit
    return "um" if c.unit == "um" else "urad" if c.targets_mm else "um/m"


def curves_figure(result: IdentifyResult) -> Figure:
    """Each identified curve with its band ± U; squareness values as error bars."""
    import numpy as np
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    curves = [c for c in result.curves if c.targets_mm]
    # the constants, one panel per unit: squareness (µm/m), a table's location errors
    # (µm, µrad)
    groups: dict[str, list[Curve]] = {}
    for c in result.curves:
        if not c.targets_mm and not _fixed(result, c):  # a fixed value is not identified
            groups.setdefault(_unit(c), []).append(c)
    n = len(curves) + len(groups)
    cols = 3 if n > 2 else n
    rows = max(1, math.ceil(n / cols))
    fig = Figure(figsize=(4.0 * cols, 2.6 * rows + 0.5), dpi=_DPI, layout="constrained")
    FigureCanvasAgg(fig)
    axes = np.atleast_1d(fig.subplots(rows, cols, squeeze=False)).ravel()
    cover = f"k = {result.k:g}"
    band = f"± U ({cover})"
    for ax, c in zip(axes, curves, strict=False):
        t = np.asarray(c.targets_mm)
        v = np.zeros_like(t) if result.plan else np.asarray(c.values)
        U = np.asarray(c.U)
        ax.fill_between(t, v - U, v + U, color="C0", alpha=0.2, linewidth=0, label=band)
        if not result.plan:
            ax.plot(t, v, color="C0", linewidth=1.3, label="identified")
        ax.set_title(f"{c.name}, band ± U ({cover})", fontsize=8)
        if c.target_unit == "deg":
            ax.set_xlabel(f"{c.angle_axis} (deg)", fontsize=8)
        else:
            ax.set_xlabel(f"{c.name.split('.')[0]} (mm)", fontsize=8)
        ax.set_ylabel(_SHOWN_UNITS.get(_unit(c), _unit(c)), fontsize=8)
        ax.tick_params(labelsize=7)
        ax.grid(True, linewidth=0.3)
    for ax, (unit, group) in zip(axes[len(curves) :], groups.items(), strict=False):
        x = np.arange(len(group))
        vals = [0.0 if result.plan else c.values[0] for c in group]
        ax.errorbar(x, vals, yerr=[c.U[0] for c in group], fmt="o", color="C0", capsize=3)
        ax.set_xticks(x, [c.name.split(".")[1] for c in group], fontsize=8)
        what = (
            "location errors"
            if group[0].on_table
            else "head errors"
            if group[0].on_head
            else "squareness"
        )
        ax.set_title(f"{what}, bars ± U ({cover})", fontsize=8)
        ax.set_ylabel(_SHOWN_UNITS.get(unit, unit), fontsize=8)
        ax.axhline(0.0, color="0.5", linewidth=0.5)
        ax.grid(True, linewidth=0.3)
    for ax in axes[n:]:
        ax.set_visible(False)
    fig.suptitle(
        f"{result.machine_name}: identified components, each with ± U ({cover})", fontsize=10
    )
    return fig


def _fixed(result: IdentifyResult, c: Curve) -> bool:
    """Every coefficient of the component held by ``identify.fix``: not identified."""
    names = {c.name if not label else f"{c.name}[{label}]" for label, _, _ in c.coefficients}
    return bool(names) and names <= set(result.fixed)


def table_axes(result: IdentifyResult) -> list[str]:
    """The table axes with identified errors, in the order of their first error."""
    return list(dict.fromkeys(c.table_axis for c in result.curves if c.table_axis))


def axis_figure(result: IdentifyResult, axis: str) -> Figure:
    """One rotary axis: its identified error motions against the angle with their bands
    ± U, and its location errors as a table in ISO 230-1 notation (value, U, valuation)."""
    import numpy as np
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    mine = [c for c in result.curves if c.table_axis == axis]
    motions = [c for c in mine if c.targets_mm]
    location = [c for c in mine if not c.targets_mm]
    cover = f"k = {result.k:g}"
    n = len(motions) + (1 if location else 0)
    cols = 2 if n > 1 else 1
    rows = max(1, math.ceil(n / cols))
    fig = Figure(figsize=(4.6 * cols, 2.8 * rows + 0.5), dpi=_DPI, layout="constrained")
    FigureCanvasAgg(fig)
    axes = np.atleast_1d(fig.subplots(rows, cols, squeeze=False)).ravel()
    for ax, c in zip(axes, motions, strict=False):
        t = np.asarray(c.targets_mm)
        v = np.zeros_like(t) if result.plan else np.asarray(c.values)
        U = np.asarray(c.U)
        ax.fill_between(t, v - U, v + U, color="C0", alpha=0.2, linewidth=0, label=f"± U ({cover})")
        if not result.plan:
            ax.plot(t, v, color="C0", linewidth=1.3, label="identified")
        symbol = c.name.split(".", 1)[1]
        ax.set_title(f"{iso_notation(symbol, True)} ({symbol}), band ± U ({cover})", fontsize=8)
        ax.set_xlabel(f"{axis} (deg)", fontsize=8)
        ax.set_ylabel(_SHOWN_UNITS.get(_unit(c), _unit(c)), fontsize=8)
        ax.tick_params(labelsize=7)
        ax.grid(True, linewidth=0.3)
    if location:
        ax = axes[len(motions)]
        ax.axis("off")
        cells = []
        for c in location:
            symbol = c.name.split(".", 1)[1]
            unit = _SHOWN_UNITS.get(_unit(c), _unit(c))
            if _fixed(result, c):
                shown, big_u = f"fixed at {c.values[0]:g}", "-"
            elif result.plan:
                shown, big_u = "", _u_text(c.U[0])
            else:
                shown, big_u = _value_u(c.values[0], c.U[0], signed=True)
            seen = "" if c.valuation is None else f"{c.valuation:.2f}"
            cells.append(
                [
                    iso_notation(symbol, False),
                    f"{shown} {unit}".strip(),
                    big_u if big_u == "-" else f"{big_u} {unit}",
                    seen,
                ]
            )
        table = ax.table(
            cellText=cells,
            colLabels=["location error", "value", f"U ({cover})", "valuation"],
            loc="upper center",
            cellLoc="left",
        )
        table.auto_set_font_size(False)
        table.set_fontsize(8)
        table.scale(1.0, 1.3)
        ax.set_title(f"location errors of {axis} (ISO 230-1)", fontsize=8)
    for ax in axes[n:]:
        ax.set_visible(False)
    fig.suptitle(f"{result.machine_name}: rotary axis {axis}", fontsize=10)
    return fig


def residuals_figure(result: IdentifyResult) -> Figure:
    """The normalised residual (residual / u) of every reading, one panel per set."""
    import numpy as np
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    names = list(dict.fromkeys(r[0] for r in result.residuals))
    n = max(1, len(names))
    fig = Figure(figsize=(8.0, 1.9 * n + 0.6), dpi=_DPI, layout="constrained")
    FigureCanvasAgg(fig)
    axes = np.atleast_1d(fig.subplots(n, 1, squeeze=False)).ravel()
    for ax, name in zip(axes, names, strict=False):
        z = np.array([r[4] for r in result.residuals if r[0] == name])
        ax.plot(np.arange(1, z.size + 1), z, ".", markersize=2.5, color="C0", label="residual")
        ax.axhline(2.0, color="C3", linewidth=0.6, label="± 2 u (k = 2, about 95 %)")
        ax.axhline(-2.0, color="C3", linewidth=0.6)
        ax.set_title(f"{name}: residual of each reading in units of its stated u", fontsize=9)
        ax.set_xlabel(f"residual number in set {name} (in the order of its file)", fontsize=8)
        ax.set_ylabel("residual / u (1)", fontsize=8)
        ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.0, 1.0))
        ax.tick_params(labelsize=7)
        ax.grid(True, linewidth=0.3)
    return fig


def write_pdf(
    path: str | os.PathLike[str],
    result: IdentifyResult,
    figures: Sequence[Figure | None],
    provenance: Provenance | None = None,
    date: str | None = None,
) -> int:
    """The report as PDF in the document style of every esp report
    (:mod:`esp.report.document`): the title block, the summary (the volumetric accuracy
    with its uncertainty statement, the fit), the sections of the text report with their
    tables, each figure on a page of its own with a caption, then the provenance when it
    is given; fixed document information (no creation date), so that the bytes are
    reproducible. Returns the number of pages."""
    from esp.report.document import Document, Headline, summary, text_report, title_fields
    from esp.report.epoch import report_date

    title = "Identification plan" if result.plan else "Identification report"
    doc = Document(
        title, result.machine_name, date or report_date(), title_fields(provenance=provenance)
    )
    lines = []
    v = result.volumetric
    if v is not None:
        value, U = _value_u(v.value_um, v.U_um)
        lines.append(
            Headline(
                "Volumetric accuracy",
                f"{value} µm",
                f"U = {U} µm ({coverage_text(v.k)}; least squares, correlations kept)",
            )
        )
    if result.expected_u_um is not None:
        lines.append(
            Headline(
                "Largest expected U of a displacement error",
                f"U = {_u_text(result.expected_u_um)} µm",
                coverage_text(result.k),
            )
        )
    summary(doc.lay, lines)
    verdict = birge_verdict(result)
    doc.lay.paragraph(
        f"{_residuals_text(result)}. " + (verdict[0].upper() + verdict[1:] + "." if verdict else "")
    )
    doc.section("Identification")
    text_report(doc.lay, identify_text(result).replace(" um", " µm"), skip=1)
    cover = coverage_text(result.k)
    captions = [
        f"the identified components against position or angle, each with its band ± U ({cover})"
    ]
    captions.append(
        "the residuals of each set, in units of their stated standard uncertainty u, with "
        "the lines ± 2 u (k = 2, about 95 %)"
    )
    captions += [
        f"rotary axis {axis}: its error motions against the angle with their bands ± U "
        f"({cover}) and its location errors in ISO 230-1 notation"
        for axis in table_axes(result)
    ]
    for fig, caption in zip(figures, captions, strict=False):
        if fig is None:  # a plan has no residuals
            continue
        # the page's caption and title block say what the figure's own title says (for its
        # PNG); a title kept would sit over the top row's titles once laid out on the page
        fig.suptitle("")
        doc.figure(fig, caption)
    return doc.write(path, provenance)
