"""The tool cases of an analysis: tool offsets from lengths and head angles.

Longstaff (2002) 3.07, eq. 3.6-3.9: a tool of length L tilted by α from the top axis and
spun by β about it has the offset P_T = L cos α, P_B = L sin α sin β, P_M = L sin α cos β
from the MCP (eq. 3.9, missing from the printed text, is P_M). esp measures the tilt from
the spindle direction s (``[tool] spindle``, by default against the top axis, -T: the tool
points down a ram whose positive motion is up), so that tilts 0-90° sweep the hemisphere a
head can hold: P = L (cos α · s + sin α (cos β · u + sin β · v)), with (u, v) the two other
role axes in the order (M, B) for a spindle along T -- eq. 3.6-3.9 with s = +T --, (M, T)
along B and (B, T) along M.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np

from esp.core.machine import AXIS_NAMES, Machine

__all__ = ["SettingTerm", "ToolCase", "head_cases", "tool_cases"]


@dataclass(frozen=True)
class SettingTerm:
    """One error of a servo head or a rotary table at one setting of its angles.

    Its first-order contribution to the tool tip's error (µm, machine axes) at machine
    coordinates x is ``constant_um[d] + Σ_j per_mm[d][j] · x_j`` for each direction d: a
    head's error is a constant over the linear axes, a rotary table's is affine in them
    (the table is a rigid body at a fixed setting).
    """

    component: str  # "head.ThetaAs", "table.X0C"
    source: str  # where it comes from, for reports
    symbol: str
    value: float
    unit: str
    constant_um: Mapping[str, float]
    per_mm: Mapping[str, Mapping[str, float]] = field(default_factory=dict)

    def value_um(self, direction: str, point: Mapping[str, float]) -> float:
        """The contribution along ``direction`` at the machine coordinates ``point``."""
        v = self.constant_um.get(direction, 0.0)
        for j, c in self.per_mm.get(direction, {}).items():
            v += c * point[j]
        return v


@dataclass(frozen=True)
class ToolCase:
    """The tool of one evaluation: length and orientation (thesis 3.07) and the offset of
    the tool tip from the MCP along each machine axis (mm). All zero at the MCP.

    On a machine with a servo head (``[head]``), one setting of the head: ``setting_deg``
    its angles, ``offset_mm`` the head's nominal tool offset there, and ``setting_terms``
    the head's own errors at the tool tip (:class:`SettingTerm`).
    """

    length_mm: float | None
    tilt_deg: float | None
    spin_deg: float | None
    offset_mm: Mapping[str, float]
    setting_deg: Mapping[str, float] | None = None
    setting_terms: tuple[SettingTerm, ...] = ()


def _clean(value: float) -> float:
    """Round away floating-point dust (cos 90° = 6e-17) from tool offsets."""
    v = round(float(value), 9)
    return 0.0 if v == 0 else v


def tool_cases(machine: Machine) -> list[ToolCase]:
    """Every tool case to evaluate: one with no offset at the MCP, else every length with
    every orientation (or every explicit offset) of ``machine.tool``.

    The offset of length L at tilt α (from the spindle direction s) and spin β (about it)
    is L (cos α · s + sin α (cos β · u + sin β · v)) (module docstring; thesis eq. 3.6-3.9
    with s = +T).
    """
    if machine.head is not None or machine.table is not None:
        return setting_cases(machine)
    return tool_cases_without_settings(machine)


def tool_cases_without_settings(machine: Machine) -> list[ToolCase]:
    """The tool cases of ``[tool]`` alone (:func:`tool_cases` without head or table)."""
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
    s_axis, s_sign = spindle_axis(machine)
    u, v = _perpendicular(machine, s_axis)
    cases = []
    for length in tool.lengths_mm:
        for tilt, spin in tool.orientations_deg:
            alpha, beta = math.radians(tilt), math.radians(spin)
            vec = dict(zero)
            vec[s_axis] = _clean(s_sign * length * math.cos(alpha))
            vec[u] = _clean(length * math.sin(alpha) * math.cos(beta))
            vec[v] = _clean(length * math.sin(alpha) * math.sin(beta))
            cases.append(ToolCase(float(length), float(tilt), float(spin), vec))
    return cases


def _combinations(angles_deg: Mapping[str, tuple[float, ...]]) -> dict[str, np.ndarray]:
    """Every combination of the angles (the first coordinate in the outer loop)."""
    names = list(angles_deg)
    grids = np.meshgrid(*(np.asarray(angles_deg[n], dtype=float) for n in names), indexing="ij")
    return {n: g.ravel() for n, g in zip(names, grids, strict=True)}


def setting_cases(machine: Machine) -> list[ToolCase]:
    """One tool case per setting of the machine's servo head and rotary table: every
    combination of their angles, the table in the outer loop. A head gives the tool offset
    and its own errors (:func:`head_cases`), a table its errors, affine in the tool tip's
    position (:func:`table_terms_at`)."""
    heads = head_cases(machine) if machine.head is not None else None
    if machine.table is None:
        return heads or []
    if heads is None:
        heads = tool_cases_without_settings(machine)
    tables = table_terms_at(machine)
    cases = []
    for setting, terms in tables:
        for h in heads:
            p = h.offset_mm
            shifted = tuple(_at_tool(t, p) for t in terms)
            deg = {**setting, **(h.setting_deg or {})}
            cases.append(
                ToolCase(h.length_mm, h.tilt_deg, h.spin_deg, p, deg, shifted + h.setting_terms)
            )
    return cases


def _at_tool(term: SettingTerm, offset_mm: Mapping[str, float]) -> SettingTerm:
    """A table term as a function of the machine coordinates: the tool tip is at the
    coordinates plus the tool offset, so per_mm · offset joins the constant."""
    constant = {
        d: term.constant_um.get(d, 0.0)
        + sum(c * offset_mm[j] for j, c in term.per_mm.get(d, {}).items())
        for d in AXIS_NAMES
    }
    return SettingTerm(
        term.component, term.source, term.symbol, term.value, term.unit, constant, term.per_mm
    )


def table_terms_at(machine: Machine) -> list[tuple[dict[str, float], tuple[SettingTerm, ...]]]:
    """Per table setting: its angles and each table error's term, affine in the tool tip's
    machine position (:func:`esp.core.devices.table_effects.table_terms`)."""
    from esp.core.devices.table_effects import table_terms

    setup = machine.table
    angles = _combinations(setup.angles_deg)
    out = table_terms(setup.table, angles)
    settings = []
    for i in range(out.size):
        terms = tuple(
            SettingTerm(
                f"table.{t.name}",
                f"table {setup.source}",
                t.name,
                float(np.asarray(t.value).reshape(-1)[i if np.size(t.value) > 1 else 0]),
                t.unit,
                {a: float(t.constant_um[i, k]) for k, a in enumerate(AXIS_NAMES)},
                {
                    d: {j: float(t.per_mm[i, k, m]) for m, j in enumerate(AXIS_NAMES)}
                    for k, d in enumerate(AXIS_NAMES)
                },
            )
            for t in out.terms
        )
        settings.append(({n: float(angles[n][i]) for n in angles}, terms))
    return settings


def head_cases(machine: Machine) -> list[ToolCase]:
    """One tool case per head setting: every combination of ``machine.head.angles_deg``
    (the first coordinate in the outer loop), with the head's nominal tool offset from the
    MCP and its own first-order error there
    (:func:`esp.core.devices.head_evaluate.head_offsets`)."""
    from esp.core.devices.head_evaluate import head_offsets

    setup = machine.head
    angles = _combinations(setup.angles_deg)
    out = head_offsets(setup.head, angles)
    cases = []
    for i in range(out.offset_mm.shape[0]):
        vec = {a: _clean(out.offset_mm[i, k]) for k, a in enumerate(AXIS_NAMES)}
        terms = tuple(
            SettingTerm(
                f"head.{t.name}",
                f"head {setup.source}",
                t.name,
                float(t.value),
                t.unit,
                {a: float(t.error_um[i, k]) for k, a in enumerate(AXIS_NAMES)},
            )
            for t in out.terms
        )
        length = _clean(math.sqrt(sum(v * v for v in vec.values())))
        setting = {n: float(angles[n][i]) for n in angles}
        cases.append(ToolCase(length, None, None, vec, setting, terms))
    return cases


def spindle_axis(machine: Machine) -> tuple[str, int]:
    """The spindle direction of the machine's tool as (axis letter, sign): ``[tool]
    spindle``, or against the top axis when it is not given."""
    given = machine.tool.spindle if machine.tool is not None else None
    if given:
        return given[1], (-1 if given[0] == "-" else 1)
    return machine.roles["top"], -1


def _perpendicular(machine: Machine, axis: str) -> tuple[str, str]:
    """The axes of spin 0° and 90° about a spindle along ``axis``: the other two roles in
    the order middle, bottom, top (for a spindle along T: M then B, as eq. 3.8-3.9)."""
    order = [machine.roles[r] for r in ("middle", "bottom", "top")]
    u, v = (a for a in order if a != axis)
    return u, v
