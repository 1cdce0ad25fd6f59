"""The residual error after compensation: the machine's error field with each table
applied as its controller applies it.

A controller adds its correction ``c(p)`` to the commanded axis positions, so the tool
reaches ``p + c(p) + e(p + c(p))``; the correction is some micrometres, the error varies
over millimetres, so to first order the residual is ``r(p) = e(p) + c(p)``. Here

* ``e`` is the machine's uncompensated error field (:func:`esp.compensation.field.field`,
  the value of :func:`esp.errors_at`: the machine's own model and datum), for each
  direction of approach the data hold (forward and backward runs, so that the reversal
  left by a single-direction table shows);
* ``c`` comes from the tables read back from the written files, so their unit, rounding
  and sign are those of the file, applied with the controller's interpolation: axis
  tables (LinuxCNC types 0/1, ISG ``kw.ssfk`` and ``kw.crosscomp``) linearly between their
  points, the forward or backward column of a leadscrew table by the direction of motion;
  plane tables (``kw.crosscomp2``) bilinearly; ends held beyond a table;
* a component table (ISG volumetric, ISO CSV) is the controller's own model evaluated
  with the values as written: ``c(p) = -E(p)``, ``E`` the machine's model with each
  column interpolated linearly along its axis (ISG ``GRID`` on a one-argument grid), ends
  held, nothing refitted (the straightness lines were removed before writing);
* with a datum, the compensated machine is referred to it as every error is, with one
  reference for every direction of approach: ``r_k(p) = e_k(p) + c_k(p) - c_ref(datum)``,
  ``ref`` the analysis direction (``e_ref`` is zero at the datum already; ``e_k`` of the
  other direction holds the reversal there, and so does ``r_k`` when no table corrects
  it).

Components the format cannot hold are left in ``e``. The volumetric accuracy before and
after is the largest ``|e|`` and ``|r|`` over the machine's simulation grid (thesis eq.
3.4-3.5), for each direction of approach.

This module imports only numpy and the standard library.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

import numpy as np
import numpy.typing as npt

from esp.compensation.field import Curve, Field, Fields, mesh_points
from esp.compensation.model import CompensationSet, ComponentTable, interpolate_hold
from esp.core.grid import PAIRS, FieldStats, scan
from esp.core.synthesis import datum_point

if TYPE_CHECKING:
    from esp.core.machine import Machine

__all__ = [
    "DirectionResidual",
    "Prediction",
    "controller_field",
    "correction_um",
    "grid_axes",
    "grid_points",
    "predict",
]

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


def grid_axes(machine: Machine, applied: CompensationSet | None = None) -> list[np.ndarray]:
    """The positions evaluated along X, Y and Z (mm): along each axis its simulation grid,
    the measured targets of its components and the table points of ``applied`` that lie
    within the simulation range. Both the measured curves and the tables are piecewise
    linear, so their largest difference along an axis lies on one of these positions."""
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
    return grids


def grid_points(machine: Machine, applied: CompensationSet | None = None) -> np.ndarray:
    """The points evaluated, shape (N, 3), columns X, Y, Z (mm): the mesh of
    :func:`grid_axes`."""
    return mesh_points(grid_axes(machine, applied))


def _held(positions: np.ndarray, values: np.ndarray) -> Curve:
    """The controller's curve of one component table column: linear between the written
    points, end values held beyond them (ISG ``GRID`` interpolation, see
    ``docs/compensation.md``)."""
    return lambda x: interpolate_hold(x, positions, values)


def controller_field(fields: Fields, table: ComponentTable) -> Field:
    """The error the controller computes from a component table: the machine's model
    evaluated with the values as written (no straightness line removed again, no other
    change), each column interpolated linearly along its axis, ends held. The controller
    knows no datum: the field is the model's whole value (``datum`` None)."""
    values: dict[str, Curve | float] = {
        name: _held(positions, v) for name, (positions, v) in table.curves.items()
    }
    values.update(table.squareness)
    return replace(fields().with_values(values), datum=None)


def correction_um(
    fields: Fields, applied: CompensationSet, points_mm: npt.ArrayLike, direction: str
) -> np.ndarray:
    """The correction ``c(p)`` the controller adds at ``points_mm`` (N, 3) for a motion in
    ``direction``, µm: axis tables linear between their points per direction, plane tables
    bilinear, ends held, the component table as :func:`controller_field` (its negative)."""
    pts = np.asarray(points_mm, dtype=float).reshape(-1, 3)
    corr = _table_correction_um(applied, [pts[:, k] for k in range(3)], direction)
    if applied.component_table is not None:
        corr -= controller_field(fields, applied.component_table)(pts)
    return corr


def _table_correction_um(
    applied: CompensationSet, coords: Sequence[np.ndarray], direction: str
) -> np.ndarray:
    """The axis and plane tables' correction at the points whose coordinates are
    ``coords`` (three arrays of one shape), µm, shape (N, 3)."""
    corr = np.zeros((coords[0].size, 3))
    for t in applied.axis_tables:
        d = direction if t.kind == "lead" else "mean"
        corr[:, AXES.index(t.slave)] += t.correction_um(coords[AXES.index(t.master)], d)
    for p in applied.plane_tables:
        a, b = (AXES.index(x) for x in p.masters)
        corr[:, AXES.index(p.slave)] += p.correction_um(coords[a], coords[b])
    return corr


def _add_tables(
    pairs: list[list[np.ndarray]],
    applied: CompensationSet,
    grids: Sequence[np.ndarray],
    direction: str,
) -> None:
    """Add the axis and plane tables' correction on the mesh of ``grids`` to the pair
    arrays ``pairs`` (in place): a table of one master is a 1-D array on its grid, a plane
    table a 2-D array on its two masters' grids, each interpolated once per position."""
    for t in applied.axis_tables:
        d = direction if t.kind == "lead" else "mean"
        m = AXES.index(t.master)
        v = t.correction_um(grids[m], d)
        arrays = pairs[AXES.index(t.slave)]
        if m == 0:
            arrays[0] += v[:, None]
        elif m == 1:
            arrays[0] += v[None, :]
        else:
            arrays[1] += v[None, :]
    for p in applied.plane_tables:
        a, b = (AXES.index(x) for x in p.masters)
        v = p.correction_um(grids[a][:, None], grids[b][None, :])  # [i along a, j along b]
        arrays = pairs[AXES.index(p.slave)]
        if a < b:
            arrays[PAIRS.index((a, b))] += v
        else:
            arrays[PAIRS.index((b, a))] += v.T


def _residual(stats: FieldStats) -> tuple[float, tuple[int, int, int], dict[str, float]]:
    value, index = stats.volumetric
    axes = {a: float(max(-stats.minimum[k][0], stats.maximum[k][0])) for k, a in enumerate(AXES)}
    i, j, k = (int(n) for n in index)
    return float(value), (i, j, k), axes


def _where(grids: Sequence[np.ndarray], index: tuple[int, int, int]) -> dict[str, float]:
    return {a: float(grids[k][index[k]]) for k, a in enumerate(AXES)}


def _directions(machine: Machine) -> tuple[str, ...]:
    for comp in machine.components.values():
        profile = getattr(comp, "profile", None)
        if profile is not None and len(profile.directions) < 2:
            return (machine.analysis.direction,)
    return ("forward", "backward")


def predict(
    machine: Machine,
    applied: CompensationSet,
    resolution_um: float = 0.0,
    fields: Fields | None = None,
) -> Prediction:
    """The residual of ``machine`` with the tables of ``applied`` (as read back from the
    written files) applied by the controller. ``fields``: the machine's prepared fields,
    shared with the tables' build (by default prepared here)."""
    fields = fields if fields is not None else Fields(machine)
    grids = grid_axes(machine, applied)
    datum = datum_point(machine)
    at_datum = _point(datum) if datum is not None else None
    component = None
    if applied.component_table is not None:  # the same for every direction: once
        controller = controller_field(fields, applied.component_table)
        component = controller.pairs(grids)
        shift = controller(at_datum)[0] if at_datum is not None else np.zeros(3)
    c_datum = None
    if at_datum is not None:
        # the compensated machine's errors relative to the datum, as every error, with the
        # one reference of every direction: the correction at the datum in the analysis
        # direction (r(p) = e(p) + c(p) - c_ref(datum); not each direction's own, which
        # would hide the reversal at the datum)
        reference = machine.analysis.direction
        c_datum = _table_correction_um(applied, list(at_datum.T), reference)[0]
        if component is not None:
            c_datum = c_datum - shift
    out = []
    for d in _directions(machine):
        before = fields.pairs(d, grids)
        after = [[arr.copy() for arr in arrays] for arrays in before]
        _add_tables(after, applied, grids, d)
        if component is not None:
            for k in range(3):
                for i in range(3):
                    after[k][i] -= component[k][i]
        if c_datum is not None:
            for k in range(3):
                after[k][0] -= c_datum[k]
        b_um, b_index, b_axes = _residual(scan(before))
        a_um, a_index, a_axes = _residual(scan(after))
        out.append(
            DirectionResidual(
                d,
                b_um,
                _where(grids, b_index),
                a_um,
                _where(grids, a_index),
                b_axes,
                a_axes,
            )
        )
    return Prediction(
        applied.format,
        tuple(out),
        applied.corrected,
        applied.uncorrected,
        int(np.prod([g.size for g in grids])),
        resolution_um,
    )


def _point(p: Mapping[str, float]) -> np.ndarray:
    return np.array([[float(p[a]) for a in AXES]])
