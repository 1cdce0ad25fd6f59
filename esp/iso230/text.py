"""The terminal report of ``esp iso230-2``: the per-target table, the axis figures with what
each is (ISO 230-2:2014, 2.2-2.21) and the notes, from an
:class:`~esp.iso230.positioning.Iso230Result` (nothing is computed here)."""

from __future__ import annotations

from esp.iso230.positioning import AXIS_KEYS, Iso230Result
from esp.iso230.vdi3441 import Vdi3441Result
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


def iso230_text(result: Iso230Result) -> str:
    """The terminal report of ``esp iso230-2``: per-target table, axis figures, notes (µm)."""
    name = display_name(result.source)
    axis = f", {result.axis} axis" if result.axis else ""
    runs = ", ".join(f"{d} {n}" for d, n in result.runs.items())
    kind = "bidirectional" if result.bidirectional else "unidirectional"
    lines = [
        f"ISO 230-2 positioning statistics: {name}{axis}",
        f"runs: {runs} ({kind}); deviations in µm; up = forward, down = backward",
        "",
    ]
    rows = result.target_rows()
    columns = [k for k in rows[0]]
    table = [
        [f"{row['position_mm']:.3f}", *[number_text(row[c]) for c in columns[1:]]] for row in rows
    ]
    lines.append(format_table(columns, table))
    lines.append("")
    lines.append("axis")
    values = result.axis_values()
    width = max(len(k) for k in values)
    numbers = {k: number_text(v) for k, v in values.items()}
    num_width = max(len(v) for v in numbers.values())
    for key in AXIS_KEYS:
        if key in values:
            lines.append(
                f"  {key.ljust(width)}  {numbers[key].rjust(num_width)} µm  "
                f"{AXIS_DESCRIPTIONS[key]}"
            )
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
