"""The terminal text of ``esp head``: a setting with its breakdown, a map's summary, a
measurement protocol and the errors it identifies."""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np

from esp.core.devices.head import Head
from esp.core.devices.head_evaluate import HeadEvaluation
from esp.heads.jsondoc import share_pct
from esp.heads.maps import ErrorMap
from esp.heads.protocol import Protocol

__all__ = ["render_map", "render_point", "render_protocol", "settings_text", "unit_text"]

AXES = ("X", "Y", "Z")
#: below this share of the largest |D| the second order is called negligible, %
NEGLIGIBLE_PCT = 1.0


_UNITS = {"um": "µm", "urad": "µrad", "um/m": "µm/m", "deg": "°"}


def unit_text(unit: str) -> str:
    """A unit as printed: ``um`` -> ``µm``, ``urad`` -> ``µrad``."""
    return _UNITS.get(unit, unit)


def _fmt(x: float, digits: int = 3) -> str:
    s = f"{x:.{digits}f}"
    return s[1:] if s.startswith("-") and float(s) == 0 else s


def _g(x: float) -> str:
    return f"{x:.6g}"


def settings_text(at: Mapping[str, float], unit: str = "") -> str:
    """``A=30, C=40`` (degrees)."""
    return ", ".join(f"{c}={_g(v)}{unit}" for c, v in at.items())


def _value(head: Head, name: str, value: float) -> str:
    unit = unit_text(head.unit(name))
    return f"{name} = {_g(value)}{unit}" if unit == "°" else f"{name} = {_g(value)} {unit}"


def _values_lines(head: Head) -> list[str]:
    lines = []
    params = [_value(head, n, v) for n, v in head.parameters.items()]
    if params:
        lines.append("parameters: " + ", ".join(params))
    errs = [_value(head, n, v) for n, v in head.errors.items() if v != 0]
    shown = ", ".join(errs) if errs else "all zero"
    if errs and len(errs) < len(head.errors):
        zero = [n for n, v in head.errors.items() if v == 0]
        shown += f" ({', '.join(zero)} zero)"
    lines.append("errors: " + shown)
    if any(v != 0 for v in head.mcp_mm):
        lines.append("MCP in the chain's frame: (" + ", ".join(_g(v) for v in head.mcp_mm) + ") mm")
    return lines


def _title(head: Head) -> list[str]:
    lines = [head.name]
    if head.chain.name != head.name:
        lines.append(f"chain: {head.chain.name}")
    return lines


def _row(label: str, v: np.ndarray, digits: int = 3) -> str:
    return f"{label:<22}" + "".join(f"{_fmt(float(v[k]), digits):>14}" for k in range(3))


def _breakdown(ev: HeadEvaluation, i: int) -> list[str]:
    if not ev.terms:
        return ["no error has a value: the error is zero"]
    first = ev.first_um[i]
    width = max(8, max(len(t.name) for t in ev.terms))
    lines = [
        "breakdown of the first-order error (µm; share of each direction's total, %)",
        f"  {'error':<{width}}  {'value':>18}" + "".join(f"{'D' + a:>11}{'%':>7}" for a in AXES),
    ]
    for t in ev.terms:
        value = f"{_g(t.value)} {unit_text(t.unit)}"
        cells = ""
        for k in range(3):
            s = share_pct(float(t.error_um[i, k]), float(first[k]))
            share = "" if s is None else f"{0.0 if abs(s) < 0.05 else s:.1f}"
            cells += f"{_fmt(float(t.error_um[i, k])):>11}{share:>7}"
        lines.append(f"  {t.name:<{width}}  {value:>18}" + cells)
    total = "".join(f"{_fmt(float(first[k])):>11}{'':>7}" for k in range(3))
    lines.append(f"  {'total':<{width}}  {'':>18}{total}".rstrip())
    return lines


def _point_lines(ev: HeadEvaluation, i: int, order: int) -> list[str]:
    lines = [f"{'':<22}{'X':>14}{'Y':>14}{'Z':>14}"]
    lines.append(_row("nominal tip (mm)", ev.nominal_mm[i], 4))
    lines.append(_row("tool axis", ev.tool_axis[i], 6))
    lines.append(_row("first order (µm)", ev.first_um[i]))
    if order == 2 and ev.second_um is not None:
        lines.append(_row("second order (µm)", ev.second_um[i], 6))
        lines.append(_row("first + second (µm)", ev.first_um[i] + ev.second_um[i]))
    if np.all(np.isfinite(ev.exact_um[i])):
        lines.append(_row("exact (µm)", ev.exact_um[i]))
    lines.append(_row("tool axis tilt (µrad)", ev.tilt_urad[i]))
    d = float(np.linalg.norm(ev.error_um[i]))
    what = "first plus second order" if order == 2 else "first order"
    lines.append(f"|D| = {_fmt(d)} µm ({what})")
    return lines


def render_point(ev: HeadEvaluation, order: int, index: int = 0) -> str:
    """One setting: the values, the nominal tip and axis, the errors, the breakdown."""
    head = ev.head
    at = {c: float(v[index]) for c, v in ev.angles.items()}
    lines = _title(head) + _values_lines(head)
    lines.append(f"at: {settings_text(at, '°')}")
    lines.append("tool tip relative to the MCP, in the machine's axes")
    lines.append("")
    lines += _point_lines(ev, index, order)
    lines.append("")
    lines += _breakdown(ev, index)
    return "\n".join(lines) + "\n"


def render_map(m: ErrorMap) -> str:
    """A map's summary: grid, extremes and where, the second order against the first, and
    the breakdown at the largest |D|."""
    head = m.head
    lines = _title(head) + _values_lines(head)

    def span(v: np.ndarray) -> str:
        if v.size == 1:
            return f"{_g(v[0])}°"
        step = (v[-1] - v[0]) / (v.size - 1)
        return f"{_g(v[0])}° to {_g(v[-1])}° step {_g(step)}°"

    what = "first plus second order" if m.order == 2 else "first-order"
    lines.append(
        f"map: {m.names[0]} {span(m.rows)}, {m.names[1]} {span(m.cols)} "
        f"({m.rows.size * m.cols.size} settings), {what} error at the tool tip"
    )
    lines.append("")
    ext = m.extremes()
    lines.append(
        f"{'':<5}{'min (µm)':>12}  {'at':<22}{'max (µm)':>12}  {'at':<22}{'range (µm)':>11}"
    )
    for a in AXES:
        lo, hi = ext[a]["min"], ext[a]["max"]
        lines.append(
            f"{'D' + a:<5}{_fmt(lo.value_um):>12}  {settings_text(lo.at):<22}"
            f"{_fmt(hi.value_um):>12}  {settings_text(hi.at):<22}"
            f"{_fmt(hi.value_um - lo.value_um):>11}"
        )
    worst = ext["D"]["max"]
    lines.append("")
    lines.append(f"largest |D|: {_fmt(worst.value_um)} µm at {settings_text(worst.at)}")
    so = m.second_order_peak()
    ex = m.exact_residual_peak()
    pct = share_pct(so.value_um, worst.value_um)
    verdict = ""
    if pct is not None:
        enough = "enough" if pct < NEGLIGIBLE_PCT else "not enough"
        verdict = f" ({pct:.3g} % of the largest |D|: the first order is {enough})"
    lines.append(
        f"second-order terms: largest {so.value_um:.3g} µm at {settings_text(so.at)}{verdict}"
    )
    lines.append(
        f"exact chain minus first order: largest {ex.value_um:.3g} µm at {settings_text(ex.at)}"
    )
    lines.append("")
    i = m.worst_index()
    lines.append(f"at the largest |D| ({settings_text(m.at(i), '°')}):")
    lines += _point_lines(m.evaluation, i, m.order)
    lines.append("")
    lines += _breakdown(m.evaluation, i)
    return "\n".join(lines) + "\n"


def _table(headers: Sequence[str], rows: Sequence[Sequence[str]], right: set[int]) -> list[str]:
    widths = [max(len(h), *(len(r[k]) for r in rows)) for k, h in enumerate(headers)]

    def line(cells: Sequence[str]) -> str:
        out = []
        for k, c in enumerate(cells):
            out.append(c.rjust(widths[k]) if k in right else c.ljust(widths[k]))
        return "  ".join(out).rstrip()

    return [line(headers), *(line(r) for r in rows)]


def render_protocol(
    protocol: Protocol,
    measured_um: Mapping[int, float] | None = None,
    identified: Mapping[str, float] | None = None,
) -> str:
    """The protocol as a table (test, error, measured difference, settings, equation,
    solution, sensitivity), then the identified errors when measured differences are
    given."""
    head = protocol.head
    coords = protocol.coordinates
    n_settings = len(protocol.angles) ** len(coords)
    angles = ", ".join(_g(a) for a in protocol.angles)
    lines = [f"{head.name}: measurement protocol"]
    lines.append(
        f"settings: {', '.join(coords)} each in {{{angles}}}°: {n_settings} settings, "
        f"{protocol.searched} differences searched"
    )
    lines.append("assumed zero: " + (", ".join(protocol.assume_zero) or "none"))
    if protocol.known:
        known = [_value(head, e, head.errors.get(e, 0.0)) for e in protocol.known]
        lines.append("known: " + ", ".join(known))
    lines.append("identified, in order: " + ", ".join(protocol.identify))
    lines.append("")
    headers = ["test", "error", "measure"]
    headers += [f"{c}1" for c in coords] + [f"{c}2" for c in coords]
    headers += ["equation (mm, rad)", "solution", "sensitivity"]
    rows = []
    for step in protocol.steps:
        for k, number in enumerate(step.tests):
            t = protocol.test(number)
            u = step.errors[k] if k < len(step.errors) else ""
            sens = t.coefficients_um.get(u, 0.0)
            solution = f"{u} = {step.solution[u]}" if u in step.solution else ""
            rows.append(
                [
                    str(t.number),
                    ", ".join(step.errors) if len(step.errors) > 1 else u,
                    t.symbol,
                    *(_g(t.first[c]) for c in coords),
                    *(_g(t.second[c]) for c in coords),
                    t.equation,
                    solution,
                    f"{sens:.4g} µm/{unit_text(head.unit(u))}",
                ]
            )
    right = {0} | set(range(3, 3 + 2 * len(coords))) | {len(headers) - 1}
    lines += _table(headers, rows, right)
    lines.append("")
    first = ", ".join(f"{c}1" for c in coords)
    second = ", ".join(f"{c}2" for c in coords)
    lines.append(
        f"dX_n (dY_n, dZ_n) is the X (Y, Z) error of the tool tip at ({first}) minus that at "
        f"({second}): the change of its measured position less the nominal change."
    )
    params = ", ".join(_value(head, n, v) for n, v in head.parameters.items())
    lines.append(
        "Formulae in mm and rad; sensitivity: µm of difference per unit of the error at "
        f"{params or 'the head'}."
    )
    if measured_um is not None and identified is not None:
        lines.append("")
        lines.append("identified errors")
        width = max(len(e) for e in identified)
        step_of = {u: s for s in protocol.steps for u in s.errors}
        for e, v in identified.items():
            s = step_of[e]
            tests = ", ".join(
                f"{protocol.test(n).symbol} = {_g(measured_um[n])} µm" for n in s.tests
            )
            unit = unit_text(head.unit(e))
            lines.append(f"  {e:<{width}}  {_g(v):>12} {unit:<7} from {tests}")
    return "\n".join(lines) + "\n"
