"""Synthetic measurements from a known machine through the exact 4×4 chain, for the
examples and the tests: the truth is a set of error curves, the measurements are what the
instruments would read of the machine's exact tool-tip positions
(:func:`esp.core.kinematics.position` on
:func:`esp.core.models.derived.cartesian_chain`), so that the identification, which uses
the first-order model, is checked against exact physics."""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import TYPE_CHECKING

import numpy as np

from esp.core.machine import Machine
from esp.core.names import AXIS_NAMES, ComponentName

if TYPE_CHECKING:
    from esp.core.kinematics.chain import Chain

__all__ = ["actual_positions", "commanded_for"]

Truth = Mapping[str, Callable[[np.ndarray], np.ndarray] | float]


def _chain(machine: Machine) -> Chain:
    from esp.core.models.derived import cartesian_chain

    letters = (machine.roles["bottom"], machine.roles["middle"], machine.roles["top"])
    return cartesian_chain(machine.configuration, letters, False)


def actual_positions(
    machine: Machine,
    truth: Truth,
    points_mm: np.ndarray,
    tool_mm: Mapping[str, float] | None = None,
) -> np.ndarray:
    """Where the tool tip really is (mm, workpiece frame) when the machine is commanded to
    ``points_mm`` (N, 3), with the errors ``truth`` (component name -> curve of its axis'
    position in µm or µrad, or a squareness in µm/m); ``tool_mm`` the tool offset from the
    MCP along X, Y, Z (default: none, the MCP)."""
    from esp.core.kinematics import position
    from esp.core.models.derived import error_symbol

    P = np.asarray(points_mm, dtype=float).reshape(-1, 3)
    chain = _chain(machine)
    errors: dict[str, np.ndarray | float] = {}
    for text, f in truth.items():
        n = ComponentName.parse(text)
        if n.kind == "squareness":
            errors[error_symbol("squareness", "", n.about)] = float(f)  # type: ignore[arg-type]
            continue
        assert n.axis is not None and callable(f)
        x = P[:, AXIS_NAMES.index(n.axis)]
        errors[error_symbol(n.kind, n.axis, n.about)] = np.asarray(f(x), dtype=float) * np.ones(
            len(P)
        )
    params = {f"{a}_off": machine.axes[a].offset_mm for a in AXIS_NAMES}
    params.update({f"P_{a}": float((tool_mm or {}).get(a, 0.0)) for a in AXIS_NAMES})
    coords = {a: P[:, i] for i, a in enumerate(AXIS_NAMES)}
    return position(chain, coords, params, errors)


def commanded_for(
    machine: Machine,
    truth: Truth,
    targets_mm: np.ndarray,
    tool_mm: Mapping[str, float] | None = None,
) -> np.ndarray:
    """The commanded positions that put the tool tip exactly at ``targets_mm`` (what a CMM
    reports when it probes a ball there), by fixed-point iteration."""
    T = np.asarray(targets_mm, dtype=float).reshape(-1, 3)
    P = T - np.array([float((tool_mm or {}).get(a, 0.0)) for a in AXIS_NAMES])
    for _ in range(20):
        step = T - actual_positions(machine, truth, P, tool_mm)
        P = P + step
        if np.max(np.abs(step)) < 1e-12:
            break
    return P
