"""The tables of a compensation format, built from a machine.

Every correction is computed from the machine's one prepared evaluation
(:func:`esp.compensation.field.field`, the value of :func:`esp.errors_at`), so the tables
follow whichever model the machine's ``[analysis]`` selects: a table correcting the
components ``H`` in direction K holds ``-e_H,K``, the K error of the terms of ``H`` alone
(relative to the datum when one is set). Which table can hold a component is decided
numerically from the component's own error field (:func:`dependence`): a table of K over
the master axes M can hold the K part of a component only when that part varies with the
M coordinates alone.

* leadscrew tables (LinuxCNC, ``kw.ssfk``): parts that vary with the slave's own
  position only -- the linear positioning error; one curve per direction of motion from
  the forward and backward runs (the reversal, i.e. backlash, is in their difference);
* cross tables (``kw.crosscomp``): parts that vary with the one master's position only --
  the straightness of the master in the slave's direction, and a squareness whose lever is
  the master;
* plane tables (``kw.crosscomp2``): parts that vary with the two masters' positions only
  -- both straightnesses and the squareness terms in the slave's direction;
* component tables (ISG volumetric, plain CSV): the linear, straightness and angular
  components themselves and the squareness; the controller evaluates the model.

This module imports only numpy and the standard library.
"""

from __future__ import annotations

import math
from collections.abc import Collection, Mapping, Sequence
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

import numpy as np

from esp.compensation.field import Field, Fields, with_direction
from esp.compensation.model import (
    AxisTable,
    CompensationSet,
    ComponentTable,
    PlaneTable,
    RotaryTable,
)
from esp.core.errors import DataError
from esp.core.limits import COMPENSATION_MAX_PLANE_POINTS, COMPENSATION_MAX_TABLE_POINTS, refuse_if

if TYPE_CHECKING:
    from esp.core.machine import Component, Machine

__all__ = [
    "BuildOptions",
    "build",
    "component_fields",
    "dependence",
    "table_positions",
    "with_components",
    "with_direction",
]

AXES = ("X", "Y", "Z")
#: a field smaller than this (µm) anywhere on the check grid is taken as zero
ZERO_UM = 1e-9
#: points per axis of the grid on which dependence is checked
CHECK_POINTS = 5


@dataclass(frozen=True)
class BuildOptions:
    """How to build the tables.

    spacing_mm : table spacing per axis letter (default: the axis' ``step``)
    cross_masters : slave -> master for ``kw.crosscomp`` (default: the axis whose
        straightness in the slave's direction has the largest range)
    leave_uncorrected : accept components the format cannot hold (they stay in the
        residual) instead of refusing
    """

    spacing_mm: Mapping[str, float] | None = None
    cross_masters: Mapping[str, str] | None = None
    leave_uncorrected: bool = False


def with_components(machine: Machine, names: Sequence[str]) -> Machine:
    """The machine reduced to the named components (and no uncertainty table)."""
    keep = {n: c for n, c in machine.components.items() if str(n) in set(map(str, names))}
    return replace(machine, components=keep, uncertainty=None)


def _travel(machine: Machine, axis: str) -> tuple[float, float]:
    lo, hi = machine.axes[axis].travel_mm
    return float(lo), float(hi)


def table_positions(
    machine: Machine,
    axis: str,
    spacing_mm: float,
    equidistant: bool = False,
    key: str = "--spacing",
) -> np.ndarray:
    """Table points along ``axis``: its travel from the low end in steps of
    ``spacing_mm``, the high end always included. ``equidistant`` formats refuse a spacing
    that does not divide the travel; a spacing given by ``--spacing`` larger than the
    travel is refused (the table would hold the two ends alone). More than
    :data:`esp.core.limits.COMPENSATION_MAX_TABLE_POINTS` points are refused before they are
    made, naming ``key`` (the option or configuration key that set the spacing)."""
    lo, hi = _travel(machine, axis)
    if not np.isfinite(spacing_mm) or spacing_mm <= 0:
        raise DataError(
            f"--spacing for {axis}: expected a positive length in mm, found {spacing_mm!r}"
        )
    if hi <= lo:
        raise DataError(
            f"axis {axis} does not move (travel {lo:g} to {hi:g} mm); no table can be made"
        )
    if key == "--spacing" and spacing_mm > (hi - lo) * (1 + 1e-12):
        # a spacing beyond the travel would leave a table of the two ends alone
        raise DataError(
            f"--spacing for {axis}: expected at most the axis' travel of {hi - lo:g} mm, "
            f"found {spacing_mm:g} mm"
        )
    n = (hi - lo) / spacing_mm
    count: float = n
    if n < 1e18:  # the points below: 0 to k steps, and the high end when it is not one
        steps = math.floor(n + 1e-9)
        count = steps + 1 + (hi - (lo + spacing_mm * steps) > 1e-9 * max(1.0, abs(hi)))
    refuse_if(
        count,
        COMPENSATION_MAX_TABLE_POINTS,
        key,
        f"a table along {axis} over its travel of {hi - lo:g} mm every {spacing_mm!r} mm: points",
        f"use a larger {key}",
    )
    k = int(np.floor(n + 1e-9))
    if equidistant and abs(n - round(n)) > 1e-9 * max(1.0, n):
        raise DataError(
            f"a spacing of {spacing_mm:g} mm does not divide the {axis} travel of {hi - lo:g} mm; "
            f"this format takes equidistant points only: choose a spacing that divides it"
        )
    pos = lo + spacing_mm * np.arange(k + 1, dtype=float)
    if hi - pos[-1] > 1e-9 * max(1.0, abs(hi)):
        pos = np.append(pos, hi)
    else:
        pos[-1] = hi
    return pos


def _check_grid(machine: Machine) -> tuple[dict[str, np.ndarray], np.ndarray]:
    grids = {a: np.linspace(*_travel(machine, a), CHECK_POINTS) for a in AXES}
    mesh = np.meshgrid(grids["X"], grids["Y"], grids["Z"], indexing="ij")
    return grids, np.stack([m.ravel() for m in mesh], axis=1)


def component_fields(machine: Machine, fields: Fields | None = None) -> dict[str, np.ndarray]:
    """Each component's own error field on a small check grid, shape (n, n, n, 3)
    (indexed [x, y, z, direction]), from the terms of that component alone."""
    full = (fields or Fields(machine))()
    _, pts = _check_grid(machine)
    shape = (CHECK_POINTS, CHECK_POINTS, CHECK_POINTS, 3)
    return {str(name): full.only([name])(pts).reshape(shape) for name in machine.components}


def dependence(field: np.ndarray) -> dict[str, set[str]]:
    """Direction -> the axes along which that direction of ``field`` varies (only the
    directions that are not zero)."""
    out: dict[str, set[str]] = {}
    for d, direction in enumerate(AXES):
        f = field[..., d]
        if np.max(np.abs(f)) <= ZERO_UM:
            continue
        out[direction] = {
            a for i, a in enumerate(AXES) if np.max(np.abs(np.diff(f, axis=i))) > ZERO_UM
        }
    return out


def _kind(name: str) -> str:
    parts = name.split(".")
    return parts[0] if parts[0] == "squareness" else parts[1]


def _spacing(machine: Machine, axis: str, options: BuildOptions) -> float:
    given = (options.spacing_mm or {}).get(axis)
    return float(given) if given is not None else float(machine.axes[axis].step_mm)


def _spacing_key(axis: str, options: BuildOptions) -> str:
    """The option or configuration key that sets the spacing of ``axis``'s tables."""
    return "--spacing" if (options.spacing_mm or {}).get(axis) is not None else f"axes.{axis}.step"


def _positions(machine: Machine, axis: str, options: BuildOptions) -> np.ndarray:
    """The table points of ``axis`` at its spacing (:func:`table_positions`)."""
    spacing = _spacing(machine, axis, options)
    return table_positions(machine, axis, spacing, key=_spacing_key(axis, options))


def _directions_of(machine: Machine, names: Sequence[str]) -> tuple[str, ...]:
    """Forward and backward when every named component has runs in both, else the
    analysis direction alone."""
    for name in names:
        comp = machine.components[name]
        profile = getattr(comp, "profile", None)
        if profile is not None and len(profile.directions) < 2:
            return (machine.analysis.direction,)
    return ("forward", "backward")


def _line_points(machine: Machine, axis: str, positions: np.ndarray) -> np.ndarray:
    """Points along ``axis`` with the other axes at the low end of their travel."""
    pts = np.array([[_travel(machine, a)[0] for a in AXES]] * positions.size, dtype=float)
    pts[:, AXES.index(axis)] = positions
    return pts


def _lead_table(
    machine: Machine, fields: Fields, axis: str, names: list[str], positions: np.ndarray
) -> AxisTable:
    pts = _line_points(machine, axis, positions)
    d = AXES.index(axis)
    dirs = _directions_of(machine, names)
    values = {k: -fields(k).only(names)(pts)[:, d] for k in dirs}
    fwd = values.get("forward", values[dirs[0]])
    bwd = values.get("backward", values[dirs[0]])
    return AxisTable(axis, axis, positions, fwd, bwd, "lead", tuple(names))


def _cross_table(
    machine: Machine,
    full: Field,
    slave: str,
    master: str,
    names: Sequence[str],
    positions: np.ndarray,
) -> AxisTable:
    pts = _line_points(machine, master, positions)
    v = -full.only(names)(pts)[:, AXES.index(slave)]
    return AxisTable(slave, master, positions, v, v, "cross", tuple(names))


def _plane_table(
    machine: Machine,
    full: Field,
    slave: str,
    masters: tuple[str, str],
    names: Sequence[str],
    pos_a: np.ndarray,
    pos_b: np.ndarray,
) -> PlaneTable:
    a, b = masters
    pts = np.array([[_travel(machine, x)[0] for x in AXES]] * (pos_a.size * pos_b.size))
    bb, aa = np.meshgrid(pos_b, pos_a, indexing="ij")
    pts[:, AXES.index(a)] = aa.ravel()
    pts[:, AXES.index(b)] = bb.ravel()
    v = -full.only(names)(pts)[:, AXES.index(slave)].reshape(pos_b.size, pos_a.size)
    return PlaneTable(slave, (a, b), pos_a, pos_b, v, tuple(names))


def _default_cross_master(
    machine: Machine,
    slave: str,
    fields: Mapping[str, np.ndarray],
    candidates: Collection[str],
) -> str | None:
    best, best_range = None, 0.0
    for master in AXES:
        if master == slave:
            continue
        name = f"{master}.straightness.{slave}"
        if name in candidates:
            f = fields[name][..., AXES.index(slave)]
            r = float(np.ptp(f))
            if best is None or r > best_range:
                best, best_range = master, r
    return best


def _curve(machine: Machine, comp: Component, positions: np.ndarray) -> np.ndarray:
    """The component's values at ``positions`` as the engine uses them: the runs of the
    analysis direction, the straightness with its set-up slope removed."""
    a = machine.analysis
    profile = comp.profile
    if comp.kind == "straightness":
        profile = profile.without_slope(a.straightness_fit)  # type: ignore[union-attr]
    return np.asarray(profile.at(positions, direction=a.direction, extrapolate=a.extrapolate))  # type: ignore[union-attr]


def _component_table(
    machine: Machine, options: BuildOptions, used: set[str]
) -> tuple[ComponentTable, list[str]]:
    curves, squareness, held = {}, {}, []
    for name, comp in machine.components.items():
        name = str(name)
        if comp.kind == "squareness":
            squareness[name] = float(comp.value or 0.0)
            held.append(name)
        elif comp.kind in ("linear", "straightness", "angular"):
            positions = _positions(machine, comp.axis, options)  # type: ignore[arg-type]
            curves[name] = (positions, _curve(machine, comp, positions))
            held.append(name)
    return ComponentTable(curves, squareness), held


@dataclass
class _Work:
    """What one build shares between the kinds of table: the machine, its fields, each
    used component's dependence, and what is held so far."""

    machine: Machine
    options: BuildOptions
    fields: Fields
    full: Field
    own: dict[str, np.ndarray]
    deps: dict[str, dict[str, set[str]]]
    used: set[str]
    equidistant: bool
    bidirectional: bool
    masters_per_axis: int
    held: set[str]


def _lead_tables(w: _Work) -> list[AxisTable]:
    """Leadscrew tables: the parts that vary with the slave's own position only."""
    lead: dict[str, list[str]] = {a: [] for a in AXES}
    for name in sorted(w.used):
        d = w.deps[name]
        if _kind(name) == "linear" and all(v <= {k} for k, v in d.items()):
            for k in d:
                lead[k].append(name)
            w.held.add(name)
    tables = []
    for axis in AXES:
        if lead[axis]:
            key = _spacing_key(axis, w.options)
            spacing = _spacing(w.machine, axis, w.options)
            pos = table_positions(w.machine, axis, spacing, w.equidistant, key)
            table = _lead_table(w.machine, w.fields, axis, lead[axis], pos)
            if not w.bidirectional and table.bilateral:
                # one curve for both directions: the analysis direction's
                v = -w.full.only(lead[axis])(_line_points(w.machine, axis, pos))[
                    :, AXES.index(axis)
                ]
                table = replace(table, forward_um=v, backward_um=v)
            tables.append(table)
    return tables


def _candidates(w: _Work) -> list[str]:
    """The straightness and squareness components not held yet."""
    kinds = ("straightness", "squareness")
    return sorted(n for n in w.used if _kind(n) in kinds and n not in w.held)


def _cross_tables(w: _Work) -> list[AxisTable]:
    """Cross tables: the parts that vary with the one master's position only."""
    given = dict(w.options.cross_masters or {})
    for slave, master in given.items():
        if slave not in AXES or master not in AXES or slave == master:
            raise DataError(
                f"--cross {slave}={master}: expected SLAVE=MASTER, two different axes of X, Y, Z"
            )
    candidates = _candidates(w)
    if w.masters_per_axis > 1 and not given:
        return _cross_tables_any(w, candidates)
    masters = {
        s: given.get(s) or _default_cross_master(w.machine, s, w.own, candidates) for s in AXES
    }
    cross: dict[str, list[str]] = {a: [] for a in AXES}
    for name in candidates:
        d = w.deps[name]
        if all(masters.get(k) and v <= {masters[k]} for k, v in d.items()):
            for k in d:
                cross[k].append(name)
            w.held.add(name)
    tables = []
    for slave in AXES:
        m = masters[slave]
        if cross[slave] and m is not None:
            master = m
            key = _spacing_key(master, w.options)
            spacing = _spacing(w.machine, master, w.options)
            pos = table_positions(w.machine, master, spacing, w.equidistant, key)
            tables.append(_cross_table(w.machine, w.full, slave, master, cross[slave], pos))
    return tables


def _cross_tables_any(w: _Work, candidates: Sequence[str]) -> list[AxisTable]:
    """Cross tables when several may correct one axis: one table of each slave over each
    master, holding every component whose error in the slave's direction varies with that
    one master alone."""
    pairs: dict[tuple[str, str], list[str]] = {}
    for name in candidates:
        d = w.deps[name]
        if all(len(v) == 1 and v != {k} for k, v in d.items()):
            for k, v in d.items():
                pairs.setdefault((k, next(iter(v))), []).append(name)
            w.held.add(name)
    tables = []
    for (slave, master), names in sorted(pairs.items()):
        key = _spacing_key(master, w.options)
        spacing = _spacing(w.machine, master, w.options)
        pos = table_positions(w.machine, master, spacing, w.equidistant, key)
        tables.append(_cross_table(w.machine, w.full, slave, master, names, pos))
    return tables


def _plane_tables(w: _Work) -> list[PlaneTable]:
    """Plane tables: the parts that vary with the two masters' positions only."""
    plane: dict[str, list[str]] = {a: [] for a in AXES}
    for name in _candidates(w):
        d = w.deps[name]
        if all(k not in v for k, v in d.items()):
            for k in d:
                plane[k].append(name)
            w.held.add(name)
    tables = []
    machine, options = w.machine, w.options
    for slave in AXES:
        if not plane[slave]:
            continue
        a, b = (x for x in AXES if x != slave)
        spacing = min(_spacing(machine, a, options), _spacing(machine, b, options))
        key = _spacing_key(a if spacing == _spacing(machine, a, options) else b, options)
        pos_a = table_positions(machine, a, spacing, equidistant=True, key=key)
        pos_b = table_positions(machine, b, spacing, equidistant=True, key=key)
        refuse_if(
            pos_a.size * pos_b.size,
            COMPENSATION_MAX_PLANE_POINTS,
            key,
            f"a plane table of {slave} over {a} and {b} every {spacing!r} mm: "
            f"{pos_a.size} x {pos_b.size} points",
            f"use a larger {key}",
        )
        tables.append(_plane_table(machine, w.full, slave, (a, b), plane[slave], pos_a, pos_b))
    return tables


#: the default step of a rotary table's angular positioning table, degrees
ROTARY_STEP_DEG = 5.0


def rotary_tables(machine: Machine, options: BuildOptions) -> list[RotaryTable]:
    """The angular positioning correction of each axis of the machine's rotary table
    whose positioning error (``ECC`` of C: the slot of its error motion about its own
    axis, :func:`esp.core.devices.table.positioning_error`) is not zero: minus the error,
    µrad, every ``--spacing`` degrees (default :data:`ROTARY_STEP_DEG`). An error that is
    a constant or a periodic curve gives a modulo table over 0..360° (the spacing must
    divide the turn); a curve of limited travel a table over its range.

    Raises
    ------
    DataError
        A spacing that does not divide the turn or the travel.
    """
    from esp.core.devices.table import positioning_error

    if machine.table is None:
        return []
    table = machine.table.table
    out = []
    for q in table.coordinates:
        found = positioning_error(table.chain, q)
        if found is None:
            continue
        symbol, sign = found
        curve = table.curves.get(symbol)
        value = float(table.errors.get(symbol, 0.0))
        if curve is None and value == 0.0:
            continue
        step = float((options.spacing_mm or {}).get(q, ROTARY_STEP_DEG))
        if curve is None or curve.periodic:
            lo, hi, modulo = 0.0, 360.0, True
        else:
            (lo, hi), modulo = curve.range_deg, False
        count = (hi - lo) / step
        if abs(count - round(count)) > 1e-9 or round(count) < 1:
            raise DataError(
                f"--spacing {q}={step:g}: a table of {q} runs from {lo:g} to {hi:g}° "
                f"({'one turn' if modulo else 'its travel'}); give a step that divides it"
            )
        positions = np.linspace(lo, hi, int(round(count)) + 1)
        values = curve.at(positions) if curve is not None else np.full(positions.size, value)
        if modulo:
            values[-1] = values[0]  # 360° is 0°
        scale = table.chain.symbols[symbol].scale / 1e-6  # the symbol's unit -> µrad
        out.append(RotaryTable(q, positions, -sign * values * scale, modulo, f"table.{symbol}"))
    return out


def _setting_notes(machine: Machine, fields: Fields, rotary: bool) -> list[str]:
    """On a machine with a servo head or a rotary table: the field is that of its first
    setting (esp.compensation.field), which the report must say, and the head's or
    table's own errors are not in any table of the linear axes (a rotary table's angular
    positioning tables, when written, are not in the prediction)."""
    setting = fields().tool.setting_deg
    owners = [o for o in ("head", "table") if getattr(machine, o) is not None]
    if not owners or setting is None:
        return []
    at = ", ".join(f"{a} = {v:g}°" for a, v in setting.items())
    which = " and ".join(owners)
    rotary_words = (
        "; the rotary tables correct the table's angular positioning, which the prediction "
        "leaves out"
        if rotary
        else ""
    )
    return [
        f"predicted at the first setting of the {which} ({at}): the tables of the linear "
        f"axes are predicted; the {which}'s own errors stay in the predicted residual"
        f"{rotary_words}, and the other settings are not predicted (esp analyse gives every "
        "setting)"
    ]


def build(
    machine: Machine, fmt: str, options: BuildOptions | None = None, fields: Fields | None = None
) -> CompensationSet:
    """The tables of format ``fmt`` (a name of :func:`esp.compensation.formats.registry`)
    for ``machine``: the kinds of table its
    :class:`~esp.compensation.formats.base.Capabilities` name, with the correction values
    unrounded (each format rounds when it writes). ``fields``: the machine's prepared
    fields, shared by the formats of one command (by default prepared here).

    Raises
    ------
    DataError
        A component the format cannot hold, unless ``options.leave_uncorrected``; a
        spacing the format cannot take; a table position outside a component's measured
        range (unless the analysis allows extrapolation).
    """
    from esp.compensation.formats import FormatSettings, get

    options = options or BuildOptions()
    fmt_obj = get(fmt)
    caps = fmt_obj.capabilities
    rotary_axes = machine.table.table.coordinates if machine.table is not None else ()
    for axis in sorted(options.spacing_mm or {}):
        if axis not in AXES and axis not in rotary_axes:
            raise DataError(
                f"--spacing {axis}: the machine has no axis {axis} "
                f"(its axes: {', '.join((*AXES, *rotary_axes))})"
            )
    for axis in sorted(options.spacing_mm or {}):  # a spacing given: counted before any work
        lo, hi = _travel(machine, axis) if axis in AXES else (0.0, 0.0)
        if hi > lo:  # an axis that does not move has no table (refused if one is asked)
            table_positions(machine, axis, _spacing(machine, axis, options))
    fields = fields if fields is not None else Fields(machine)
    own = component_fields(machine, fields)
    deps = {n: dependence(f) for n, f in own.items()}
    used = {n for n, d in deps.items() if d}  # components that move the tool in this model
    unused = sorted(set(own) - used)
    notes = []
    if unused:
        notes.append("not used by the machine's model (no error anywhere): " + ", ".join(unused))
    w = _Work(
        machine,
        options,
        fields,
        fields(),
        own,
        deps,
        used,
        fmt_obj.limits(FormatSettings()).equidistant,
        caps.bidirectional,
        caps.masters_per_axis,
        set(),
    )
    axis_tables: list[AxisTable] = []
    plane_tables: list[PlaneTable] = []
    component_table = None
    if "component" in caps.tables:
        component_table, names = _component_table(machine, options, used)
        w.held |= set(names)
    if "lead" in caps.tables:
        axis_tables += _lead_tables(w)
    if "cross" in caps.tables:
        axis_tables += _cross_tables(w)
    if "plane" in caps.tables:
        plane_tables += _plane_tables(w)
    rotary = rotary_tables(machine, options)
    if rotary and not caps.rotary_modulo:
        notes.append(
            "the rotary table's angular positioning errors ("
            + ", ".join(t.error for t in rotary)
            + ") are not in this format's tables (siemens-lec, siemens-cec and fanuc write them)"
        )
        rotary = []
    w.held |= {t.error for t in rotary}
    uncorrected = sorted(used - w.held)
    if uncorrected and not options.leave_uncorrected:
        shown = ", ".join(uncorrected[:4]) + (" ..." if len(uncorrected) > 4 else "")
        raise DataError(
            f"--format {fmt} cannot hold {len(uncorrected)} of the machine's components "
            f"({shown}); add --leave-uncorrected to write the tables anyway and keep them "
            f"in the residual, or choose a format that holds them (isg-volumetric)"
        )
    notes += _setting_notes(machine, fields, bool(rotary))
    return CompensationSet(
        format=fmt,
        axis_tables=tuple(axis_tables),
        plane_tables=tuple(plane_tables),
        component_table=component_table,
        rotary_tables=tuple(rotary),
        corrected=tuple(sorted(w.held)),
        uncorrected=tuple(uncorrected),
        notes=tuple(notes),
    )
