"""Synthetic measurements from a known machine through the exact 4×4 chain, for the
examples and the tests: the truth is a set of error curves, the measurements are what the
instruments would read of the machine's exact tool-tip positions
(:func:`esp.core.kinematics.position` on
:func:`esp.core.models.derived.cartesian_chain`), so that the identification, which uses
the first-order model, is checked against exact physics."""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import TYPE_CHECKING, Any

import numpy as np

from esp.core.machine import Machine
from esp.core.names import AXIS_NAMES, ComponentName

if TYPE_CHECKING:
    from esp.core.kinematics.chain import Chain

__all__ = ["actual_positions", "commanded_for", "probed_centres"]

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


def probed_centres(
    table: Any,
    errors: Mapping[str, Callable[[np.ndarray], np.ndarray] | float],
    angles_deg: Mapping[str, Any],
    sphere_mm: Any,
) -> np.ndarray:
    """Where a perfect machine finds the centre of a sphere fixed on a rotary table at
    ``sphere_mm`` (3,) in the workpiece frame, at N table settings (axis -> (N,) deg),
    exactly: T(θ)⁻¹ s of the table's 4×4 chain with the errors ``errors`` (symbol ->
    a constant, or a function of its joint's angle in degrees; in the symbol's unit);
    mm, (N, 3). With a set-up setting θ_s the workpiece frame is where the workpiece
    sits at θ_s: T_nominal(θ_s) T(θ_s)⁻¹ T(θ) (docs/rotary.md)."""
    from esp.core.devices.table import joint_of
    from esp.core.kinematics import transforms

    chain = table.chain
    joints = joint_of(chain)

    def frames(at: Mapping[str, np.ndarray], with_errors: bool) -> np.ndarray:
        n = len(next(iter(at.values())))
        values: dict[str, np.ndarray] = {}
        if with_errors:
            for name, f in errors.items():
                if callable(f):
                    values[name] = np.asarray(f(at[joints[name]]), dtype=float)
                else:
                    values[name] = np.full(n, float(f))
        coords = {c: at[c] * np.pi / 180.0 / chain.symbols[c].scale for c in chain.coordinates}
        return transforms(chain, coords, dict(table.parameters), values)

    at = {c: np.asarray(angles_deg[c], dtype=float) for c in chain.coordinates}
    T = frames(at, True)
    if table.setup_deg is not None:
        s_at = {c: np.array([float(table.setup_deg[c])]) for c in chain.coordinates}
        fix = frames(s_at, False)[0] @ np.linalg.inv(frames(s_at, True)[0])
        T = fix[None] @ T
    s = np.append(np.asarray(sphere_mm, dtype=float), 1.0)
    return np.einsum("nij,j->ni", np.linalg.inv(T), s)[:, :3]
