"""The residual error after compensation: the machine re-synthesised with a table applied
as the controller applies it.

A controller adds its correction ``c(p)`` to the commanded axis positions, so the tool
reaches ``p + c(p) + e(p + c(p))``; the correction is some micrometres, the error varies
over millimetres, so to first order the residual is ``r(p) = e(p) + c(p)``. Here

* ``e`` is the machine's error field (:func:`esp.errors_at`, the machine's own model and
  datum), for each direction of approach the data hold (forward and backward runs, so that
  the reversal left by a single-direction table shows);
* axis and plane tables contribute their values as the controller reads them: the table
  read back from the written files (so their unit, resolution and sign are those of the
  file), interpolated linearly (bilinearly on a plane) between points, end values held
  beyond the table, the forward or backward column by direction of motion;
* a component table is re-synthesised by the same model from the components read back
  from the file: ``c(p) = -e_table(p)`` (the controller is assumed to evaluate the ISO 230-1
  model of the same machine); straightness is used as the engine uses it (its least-squares
  or end-point line removed again on the table's points).

Components the format cannot hold are left in ``e``. The volumetric accuracy before and
after is the largest ``|e|`` and ``|r|`` over the machine's simulation grid (thesis eq.
3.4-3.5), for each direction of approach.

This module imports only numpy and the standard library.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, replace

import numpy as np

from esp.compensation.build import with_direction
from esp.compensation.model import CompensationSet, ComponentTable

__all__ = ["DirectionResidual", "Prediction", "grid_points", "predict", "table_machine"]

AXES = ("X", "Y", "Z")


@dataclass(frozen=True)
class DirectionResidual:
    """Before and after for one direction of approach (µm; points as axis -> mm)."""

    direction: str
    before_um: float
    before_at: Mapping[str, float]
    after_um: float
    after_at: Mapping[str, float]
    axes_before_um: Mapping[str, float]
    axes_after_um: Mapping[str, float]


@dataclass(frozen=True)
class Prediction:
    """The predicted volumetric accuracy before and after one format's tables."""

    format: str
    directions: tuple[DirectionResidual, ...]
    corrected: tuple[str, ...]
    uncorrected: tuple[str, ...]
    points: int
    resolution_um: float

    @property
    def before_um(self) -> float:
        return max(d.before_um for d in self.directions)

    @property
    def after_um(self) -> float:
        return max(d.after_um for d in self.directions)


def grid_points(machine, applied: CompensationSet | None = None) -> np.ndarray:
    """The points evaluated, shape (N, 3), columns X, Y, Z (mm): along each axis its
    simulation grid, the measured targets of its components and the table points of
    ``applied`` that lie within the simulation range. Both the measured curves and the
    tables are piecewise linear, so their largest difference along an axis lies on one of
    these positions."""
    extra: dict[str, list[np.ndarray]] = {a: [] for a in AXES}
    for comp in machine.components.values():
        profile = getattr(comp, "profile", None)
        if profile is not None and comp.axis in extra:
            extra[comp.axis].append(np.asarray(profile.targets_mm, dtype=float))
    if applied is not None:
        for t in applied.axis_tables:
            extra[t.master].append(t.positions_mm)
        for p in applied.plane_tables:
            extra[p.masters[0]].append(p.positions_a_mm)
            extra[p.masters[1]].append(p.positions_b_mm)
        if applied.component_table is not None:
            for name, (positions, _) in applied.component_table.curves.items():
                extra[name.split(".")[0]].append(positions)
    grids = []
    for a in AXES:
        g = machine.axes[a].grid_mm()
        lo, hi = float(g[0]), float(g[-1])
        parts = [g] + [x[(x >= lo) & (x <= hi)] for x in extra[a]]
        grids.append(np.unique(np.round(np.concatenate(parts), 9)))
    mesh = np.meshgrid(*grids, indexing="ij")
    return np.stack([m.ravel() for m in mesh], axis=1)


def table_machine(machine, table: ComponentTable):
    """The machine whose components are those of ``table`` (the model the controller
    evaluates), end values held beyond the table."""
    from esp.machine import Component
    from esp.names import ComponentName
    from esp.profile import ErrorProfile

    comps = {}
    for name, (positions, values) in table.curves.items():
        axis, kind = name.split(".")[0], name.split(".")[1]
        about = name.split(".")[2] if kind != "linear" else None
        profile = ErrorProfile.from_values(
            kind, positions, values, axis=axis, error_direction=about, source="table"
        )
        comps[name] = Component(
            ComponentName.parse(name), kind, axis, about, profile=profile, source="table"
        )
    for name, value in table.squareness.items():
        comps[name] = Component(
            ComponentName.parse(name),
            "squareness",
            None,
            name.split(".")[1],
            value=float(value),
            source="table",
        )
    analysis = replace(machine.analysis, direction="mean", extrapolate=True)
    return replace(machine, components=comps, analysis=analysis, uncertainty=None)


def _worst(field: np.ndarray, pts: np.ndarray) -> tuple[float, dict[str, float]]:
    norm = np.sqrt(np.sum(field * field, axis=1))
    i = int(np.argmax(norm))
    return float(norm[i]), {a: float(pts[i, k]) for k, a in enumerate(AXES)}


def _directions(machine) -> tuple[str, ...]:
    for comp in machine.components.values():
        profile = getattr(comp, "profile", None)
        if profile is not None and len(profile.directions) < 2:
            return (machine.analysis.direction,)
    return ("forward", "backward")


def predict(machine, applied: CompensationSet, resolution_um: float = 0.0) -> Prediction:
    """The residual of ``machine`` with the tables of ``applied`` (as read back from the
    written files) applied by the controller."""
    import esp

    pts = grid_points(machine, applied)
    correction = {d: np.zeros_like(pts) for d in ("forward", "backward", "mean")}
    for d, corr in correction.items():
        for t in applied.axis_tables:
            direction = d if t.kind == "lead" else "mean"
            corr[:, AXES.index(t.slave)] += t.correction_um(pts[:, AXES.index(t.master)], direction)
        for p in applied.plane_tables:
            a, b = p.masters
            corr[:, AXES.index(p.slave)] += p.correction_um(
                pts[:, AXES.index(a)], pts[:, AXES.index(b)]
            )
    if applied.component_table is not None:
        e_table = np.asarray(esp.errors_at(table_machine(machine, applied.component_table), pts))
        for corr in correction.values():
            corr -= e_table
    out = []
    for d in _directions(machine):
        before = np.asarray(esp.errors_at(with_direction(machine, d), pts), dtype=float)
        after = before + correction[d]
        b_um, b_at = _worst(before, pts)
        a_um, a_at = _worst(after, pts)
        out.append(
            DirectionResidual(
                d,
                b_um,
                b_at,
                a_um,
                a_at,
                {a: float(np.max(np.abs(before[:, k]))) for k, a in enumerate(AXES)},
                {a: float(np.max(np.abs(after[:, k]))) for k, a in enumerate(AXES)},
            )
        )
    return Prediction(
        applied.format,
        tuple(out),
        applied.corrected,
        applied.uncorrected,
        int(pts.shape[0]),
        resolution_um,
    )
