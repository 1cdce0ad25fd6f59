"""The tool cases of an analysis: tool offsets from lengths and head angles.

Longstaff (2002) 3.07, eq. 3.6-3.9: a tool of length L tilted by α from the top axis and
spun by β about it has the offset P_T = L cos α, P_B = L sin α sin β, P_M = L sin α cos β
from the MCP (eq. 3.9, missing from the printed text, is P_M).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass

from esp.machine import AXIS_NAMES, Machine

__all__ = ["ToolCase", "tool_cases"]


@dataclass(frozen=True)
class ToolCase:
    """The tool of one evaluation: length and orientation (thesis 3.07) and the offset of
    the tool tip from the MCP along each machine axis (mm). All zero at the MCP."""

    length_mm: float | None
    tilt_deg: float | None
    spin_deg: float | None
    offset_mm: Mapping[str, float]


def _clean(value: float) -> float:
    """Round away floating-point dust (cos 90° = 6e-17) from tool offsets."""
    v = round(float(value), 9)
    return 0.0 if v == 0 else v


def tool_cases(machine: Machine) -> list[ToolCase]:
    """Every tool case to evaluate: one with no offset at the MCP, else every length with
    every orientation (or every explicit offset) of ``machine.tool``.

    Eq. 3.6-3.9: P_T = L cos α, P_B = L sin α sin β, P_M = L sin α cos β, with α the tilt
    from the top axis and β the spin about it.
    """
    zero = {a: 0.0 for a in AXIS_NAMES}
    tool = machine.tool
    if machine.analysis.point == "MCP" or tool is None:
        return [ToolCase(None, None, None, zero)]
    if tool.offsets_mm:
        cases = []
        for offset in tool.offsets_mm:
            vec = {a: _clean(offset.get(a, 0.0)) for a in AXIS_NAMES}
            length = math.sqrt(sum(v * v for v in vec.values()))
            cases.append(ToolCase(_clean(length), None, None, vec))
        return cases
    b, m, t = (machine.roles[r] for r in ("bottom", "middle", "top"))
    cases = []
    for length in tool.lengths_mm:
        for tilt, spin in tool.orientations_deg:
            alpha, beta = math.radians(tilt), math.radians(spin)
            vec = dict(zero)
            vec[t] = _clean(length * math.cos(alpha))
            vec[b] = _clean(length * math.sin(alpha) * math.sin(beta))
            vec[m] = _clean(length * math.sin(alpha) * math.cos(beta))
            cases.append(ToolCase(float(length), float(tilt), float(spin), vec))
    return cases
