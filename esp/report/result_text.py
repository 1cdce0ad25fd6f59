"""The terminal report of ``esp analyse``, in the layout of the original ESP reports
(Longstaff 2002, 4.03-4.04): machine details, configuration in words, active components
with their files, squareness, offsets, simulation set-up, per-axis extremes, volumetric
accuracy, and the breakdown of every extreme point."""

from __future__ import annotations

from esp._version import __version__
from esp.machine import AXIS_NAMES, Machine
from esp.results import AnalysisResult, Breakdown, PointResult, ToolCase, UncertaintyResult

__all__ = ["render_point", "render_result"]

_KIND_WORD = {
    "linear": "Linear",
    "straightness": "Straightness",
    "angular": "Angular",
    "mechanical": "Mechanical",
    "squareness": "Squareness",
}
_DIRECTION_WORDS = {
    "mean": "mean of the forward and reverse runs",
    "forward": "forward runs",
    "backward": "reverse runs",
}


def _tidy(value: float, half_digit: float) -> float:
    """0.0 for a value that prints as zero, so that no '-0.000' appears."""
    return 0.0 if abs(value) < half_digit else value


def _at(point) -> str:
    return ", ".join(f"{a}={point[a]:g}" for a in AXIS_NAMES)


_ANGLE_WORDS = {
    "3.10.2": "Φ are the residual angles after compensation, from two linear runs (3.08)",
    "3.10.4": "Φ are the residual angles after compensation at the TCP, from two linear runs "
    "with a zero-length tool (3.08)",
    "3.10.5": "Φ are the residual angles at the MCP (angular data, from two linear runs); "
    "γ the mechanical angles carried by the tool (mechanical data, and the top axis' "
    "angular data)",
}


def _header(machine: Machine, case: str, words: str, equations: str, datum) -> list[str]:
    a = machine.analysis
    info = "  ".join(f"{k.replace('_', ' ').capitalize()}: {v}" for k, v in machine.info.items())
    lines = [
        f"esp {__version__} -- volumetric error synthesis",
        "",
        f"Machine        : {machine.name}" + (f"   {info}" if info else ""),
        f"Configuration  : {machine.configuration} ({machine.notation}): {machine.description}",
        f"Evaluation     : case {case}, {words} ({equations})",
        f"Data           : {_DIRECTION_WORDS.get(a.direction, a.direction)}; straightness slope "
        f"removed by {a.straightness_fit} fit"
        + ("; end values held outside the measured range" if a.extrapolate else ""),
        "Datum          : "
        + ("none (raw synthesis)" if datum is None else f"errors relative to {_at(datum)}"),
    ]
    if case in _ANGLE_WORDS:
        lines.append(f"Angles         : {_ANGLE_WORDS[case]}")
    return lines


def _inputs(result: AnalysisResult) -> list[str]:
    m = result.machine
    lines = ["", "Active error components"]
    for name in sorted(result.active):
        comp = m.components[name]
        tag = f"{_KIND_WORD[comp.kind]} [{comp.about or comp.axis}]"
        if comp.kind == "squareness":
            continue
        lines.append(f"  {tag:<18} {comp.iso:<5} {name.description:<38} {comp.source}")
    inactive = [str(n) for n in result.inactive if n.kind != "squareness"]
    if inactive:
        lines.append("Not active (zero): " + ", ".join(inactive))
    if result.ignored:
        ignored = ", ".join(str(n) for n in result.ignored)
        lines.append(f"Given but not used by case {result.case}: {ignored}")
    lines += ["", "Squareness (µm/m)"]
    for pair in ("XY", "XZ", "YZ"):
        comp = m.components.get(f"squareness.{pair}")
        value = "not active" if comp is None else f"{comp.value:g}"
        lines.append(f"  {pair}  {value}")
    lines += ["", "Axes  role    travel (mm)         simulate (mm)       step (mm)  offset (mm)"]
    for a in AXIS_NAMES:
        ax = m.axes[a]
        lines.append(
            f"  {a}   {ax.role:<7} {ax.travel_mm[0]:>8g} .. {ax.travel_mm[1]:<8g} "
            f"{ax.simulate_mm[0]:>8g} .. {ax.simulate_mm[1]:<8g} "
            f"{ax.step_mm:>9g}  {ax.offset_mm:>10g}"
        )
    sizes = result.grid_sizes
    total = sizes["X"] * sizes["Y"] * sizes["Z"]
    lines.append(
        f"Simulation grid: {sizes['X']} x {sizes['Y']} x {sizes['Z']} = {total} points"
        + (f" per tool case, {len(result.sweep)} orientations swept" if result.sweep else "")
    )
    return lines


def _tool_line(tool: ToolCase) -> str:
    off = ", ".join(f"{a}={tool.offset_mm[a]:g}" for a in AXIS_NAMES)
    if tool.length_mm is None:
        return "Tool: none (evaluated at the MCP)"
    if tool.tilt_deg is None:
        return f"Tool: offset {off} mm (length {tool.length_mm:g} mm)"
    return (
        f"Tool: length {tool.length_mm:g} mm, tilt {tool.tilt_deg:g} deg, spin "
        f"{tool.spin_deg:g} deg -> offset {off} mm"
    )


def _breakdown(b: Breakdown, directions=AXIS_NAMES) -> list[str]:
    errors = ", ".join(f"{a} {b.errors_um[a]:.3f}" for a in AXIS_NAMES)
    lines = [
        f"Breakdown at {b.label} ({_at(b.at)}): errors {errors} µm, volumetric "
        f"{b.volumetric_um:.3f} µm",
        "  dir  component            ISO    term                     value (µm)  share (%)",
    ]
    for t in b.terms:
        if t.direction not in directions:
            continue
        share = "" if t.share_pct is None else f"{_tidy(t.share_pct, 0.05):9.1f}"
        lines.append(
            f"  {t.direction:<4} {t.component:<20} {t.iso:<6} {t.symbol:<24} "
            f"{_tidy(t.value_um, 5e-4):10.3f}  {share}"
        )
    return lines


_METHOD_WORDS = {
    "summation": "summation (the model run with U in place of each error)",
    "statistical": "statistical (root-sum-square per direction, then the vector sum)",
    "montecarlo": "statistical, with a Monte Carlo distribution of the volumetric accuracy",
}


def _uncertainty(u: UncertaintyResult) -> list[str]:
    lines = [
        "=" * 78,
        f"Measurement uncertainty: {_METHOD_WORDS[u.method]}, k = {u.k:g}",
        f"Volumetric uncertainty: {u.volumetric.value_um:.3f} µm at {_at(u.volumetric.at)}",
    ]
    for a, e in u.axes.items():
        lines.append(f"  {a} direction: {e.value_um:.3f} µm at {_at(e.at)}")
    if u.montecarlo is not None:
        mc = u.montecarlo
        lo, hi = mc.interval_um
        lines.append(
            f"Monte Carlo ({mc.samples} draws, seed {mc.seed}): volumetric accuracy mean "
            f"{mc.mean_um:.3f} µm, standard deviation {mc.std_um:.3f} µm, "
            f"95 % interval [{lo:.3f}, {hi:.3f}] µm"
        )
    if u.prior is not None:
        p = u.prior
        lines.append(
            f"With the prior {p['prior_um']:g} ± {p['prior_u_um']:g} µm (eq. 3.22-3.24): "
            f"volumetric accuracy {p['accuracy_um']:.3f} µm, U = {p['U_um']:.3f} µm "
            f"(reduced by {p['delta_U_um']:.3f} µm)"
        )
    lines += [
        "Budget at the point of the volumetric uncertainty",
        "  component            ISO    model                U          share (%)",
    ]
    for b in u.budget:
        lines.append(
            f"  {b.component:<20} {b.iso:<6} {b.model:<20} {b.U:8.3f} {b.unit:<5} "
            f"{b.share_pct:8.1f}"
        )
    return lines


def render_result(result: AnalysisResult) -> str:
    """The whole terminal report of an analysis."""
    m = result.machine
    lines = _header(m, result.case, result.case_description, result.equations, result.datum)
    lines += _inputs(result)
    for w in result.warnings:
        lines.append(f"warning: {w}")
    if result.sweep:
        lines += ["", "Head orientation sweep: volumetric accuracy (µm) per orientation"]
        lines.append("  length (mm)  tilt (deg)  spin (deg)  accuracy (µm)")
        for e in result.sweep:
            lines.append(
                f"  {e.tool.length_mm:>11g}  {e.tool.tilt_deg:>10g}  {e.tool.spin_deg:>10g}"
                f"  {e.volumetric.value_um:>13.3f}"
            )
    for n, case in enumerate(result.cases):
        lines += ["", "=" * 78, _tool_line(case.tool)]
        lines += ["", "Total displacement error (µm)"]
        lines.append("  axis        min  at                              max  at")
        for a, e in case.axes.items():
            lines.append(
                f"  {a}    {e.minimum.value_um:9.3f}  {_at(e.minimum.at):<26}"
                f" {e.maximum.value_um:9.3f}  {_at(e.maximum.at):<26} range {e.range_um:.3f}"
            )
        worst = " (worst case)" if len(result.cases) > 1 and n == result.worst else ""
        volumetric = (
            f"Volumetric accuracy: {case.volumetric.value_um:.3f} µm at "
            f"{_at(case.volumetric.at)}{worst}"
        )
        planar = [
            f"Planar accuracy {plane}: {e.value_um:.3f} µm at {_at(e.at)}"
            for plane, e in case.planar.items()
        ]
        if result.plane_of_motion:
            fixed = next(a for a in AXIS_NAMES if a not in result.plane_of_motion)
            lines += ["", planar[0] + " (plane of motion)"]
            lines.append(
                volumetric.replace(
                    "Volumetric accuracy:",
                    f"Volumetric accuracy, with the error along {fixed} (which does not move):",
                )
            )
        else:
            lines += ["", volumetric, *planar]
        for b in case.breakdowns:
            lines.append("")
            if b.label.endswith(" min") or b.label.endswith(" max"):
                lines += _breakdown(b, directions=(b.label.split()[0],))
            elif b.label.startswith("planar "):
                lines += _breakdown(b, directions=tuple(b.label.split()[1]))
            else:
                lines += _breakdown(b)
    if result.uncertainty is not None:
        lines += [""] + _uncertainty(result.uncertainty)
    if len(result.cases) > 1:
        w = result.cases[result.worst]
        lines += [
            "",
            f"Worst volumetric accuracy: {w.volumetric.value_um:.3f} µm ({_tool_line(w.tool)})",
        ]
    return "\n".join(lines) + "\n"


def render_point(result: PointResult) -> str:
    """The terminal report of ``esp analyse --at``."""
    m = result.machine
    lines = [
        f"Machine: {m.name} -- {m.configuration} ({m.notation}), case {result.case} "
        f"({result.equations})",
        "Datum: " + ("none" if result.datum is None else f"errors relative to {_at(result.datum)}"),
    ]
    for w in result.warnings:
        lines.append(f"warning: {w}")
    for pc in result.cases:
        lines += ["", _tool_line(pc.tool)]
        lines += _breakdown(pc.breakdown)
    return "\n".join(lines) + "\n"
