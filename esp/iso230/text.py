"""The terminal report of ``esp iso230-2``: the per-target table, the axis figures with what
each is (ISO 230-2:2014, 2.2-2.21) and the notes, from an
:class:`~esp.iso230.positioning.Iso230Result` (nothing is computed here)."""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

from esp.core.rounding import rounded
from esp.iso230.positioning import AXIS_KEYS, Iso230Result
from esp.iso230.vdi3441 import Vdi3441Result

if TYPE_CHECKING:
    from esp.core.conformity import Decision
    from esp.iso230.statement import Iso230Uncertainty
from esp.report.profile_text import display_name, format_table, number_text

__all__ = ["AXIS_DESCRIPTIONS", "iso230_text", "vdi_text"]

#: what each ISO 230-2 axis figure is, for the terminal table
AXIS_DESCRIPTIONS = {
    "A": "bidirectional accuracy of positioning",
    "A_up": "unidirectional accuracy of positioning, up (forward)",
    "A_down": "unidirectional accuracy of positioning, down (backward)",
    "B": "reversal value (largest |Bi|)",
    "B_mean": "mean reversal value",
    "E": "bidirectional systematic positional deviation",
    "E_up": "unidirectional systematic positional deviation, up",
    "E_down": "unidirectional systematic positional deviation, down",
    "M": "range of the mean bidirectional positional deviation",
    "R": "bidirectional positioning repeatability",
    "R_up": "unidirectional positioning repeatability, up",
    "R_down": "unidirectional positioning repeatability, down",
}


def iso230_text(
    result: Iso230Result,
    conditions: Sequence[tuple[str, str]] = (),
    u: Iso230Uncertainty | None = None,
    decided: Sequence[Decision] = (),
) -> str:
    """The terminal report of ``esp iso230-2``: per-target table, axis figures with their U
    (when evaluated), the test conditions, the decisions and the notes (µm)."""
    name = display_name(result.source)
    axis = f", {result.axis} axis" if result.axis else ""
    runs = ", ".join(f"{d} {n}" for d, n in result.runs.items())
    kind = "bidirectional" if result.bidirectional else "unidirectional"
    lines = [
        f"ISO 230-2 positioning statistics: {name}{axis}",
        f"runs: {runs} ({kind}); deviations in {result.value_label}; up = forward, down = backward",
        "",
    ]
    rows = result.target_rows()
    columns = [k for k in rows[0]]
    table = [
        [f"{row[result.position_key]:.3f}", *[number_text(row[c]) for c in columns[1:]]]
        for row in rows
    ]
    lines.append(format_table(columns, table))
    lines.append("")
    lines.append("axis")
    values = result.axis_values()
    width = max(len(k) for k in values)
    numbers = {k: number_text(v) for k, v in values.items()}
    num_width = max(len(v) for v in numbers.values())
    evaluated = u is not None and not u.missing
    for key in AXIS_KEYS:
        if key in values:
            big_u = u.get(key) if evaluated and u is not None else None
            unit = result.value_label
            shown = f"{numbers[key].rjust(num_width)} {unit}"
            if big_u is not None:
                v_text, u_text = rounded(values[key], big_u)
                shown = f"{v_text.rjust(num_width)} {unit}, U = {u_text} {unit}"
            lines.append(f"  {key.ljust(width)}  {shown}  {AXIS_DESCRIPTIONS[key]}")
    if u is not None:
        if evaluated:
            lines.append(
                f"U: k = 2, about 95 %, over the travel {result.position_text(u.length_mm)} "
                "(ISO 230-2 Annex A contributors; docs/iso230-2.md)"
            )
        else:
            lines.append("U: not evaluated (missing: " + "; ".join(u.missing) + ")")
    if conditions:
        lines.append("")
        lines.append("test conditions")
        cw = max(len(k) for k, _ in conditions)
        lines.extend(f"  {k.ljust(cw)}  {v}" for k, v in conditions)
    if decided:
        lines.append("")
        lines.append("decisions")
        for d in decided:
            value_text = (
                f"{rounded(d.value, d.expanded)[0]} {d.unit}"
                if d.expanded is not None
                else f"{d.value:.3f} {d.unit}"
            )
            lines.append(f"  {d.text(value_text)}")
    if result.notes:
        lines.append("")
        lines.extend(f"note: {note}" for note in result.notes)
    return "\n".join(lines) + "\n"


def vdi_text(vdi: Vdi3441Result) -> str:
    """The VDI/DGQ 3441 block printed after the ISO 230-2 table."""
    lines = ["", "VDI/DGQ 3441 (1977), µm:"]
    lines.append(f"  P  position uncertainty      {vdi.P:9.3f}")
    lines.append(f"  Pa positional deviation      {vdi.Pa:9.3f}")
    if vdi.U is not None:
        lines.append(f"  U  reversal span (max)       {vdi.U:9.3f}")
        lines.append(f"     reversal span (mean)      {vdi.U_mean:9.3f}")
    lines.append(f"  Ps positional scatter (max)  {vdi.Ps_max:9.3f}")
    lines.append(f"     positional scatter (mean) {vdi.Ps_mean:9.3f}")
    return "\n".join(lines) + "\n"
