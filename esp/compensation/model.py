"""The shared table model of every compensation format.

A controller corrects a machine in one of three ways, and every format esp writes is one
or more of them:

* an **axis table** (:class:`AxisTable`): a correction of one axis (the *slave*) as a
  function of the commanded position of one axis (the *master*); the leadscrew tables of
  LinuxCNC and of the ISG kernel (``kw.ssfk``) have master = slave and may hold one curve
  per direction of motion, the cross compensation (``kw.crosscomp``) corrects another axis;
* a **plane table** (:class:`PlaneTable`): a correction of one axis as a function of the
  commanded positions of two others, on an equidistant grid (``kw.crosscomp2``);
* a **component table** (:class:`ComponentTable`): the ISO 230-1 error components
  themselves, from which the controller computes the correction with its own kinematic
  model (the ISG volumetric compensation, or any controller importing the plain CSV).

Inside esp every correction is held in µm with the sign of a correction: the value is
*added* to the commanded position, so a correction is the negative of the error it
removes. Component tables hold errors (µm for linear and straightness, µm/m for angles
and squareness), like the engine. Each format module converts to and from the
controller's unit, resolution and sign at its boundary.

This module imports only numpy.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from types import MappingProxyType

import numpy as np
import numpy.typing as npt

from esp.core.errors import DataError

__all__ = [
    "AxisTable",
    "CompensationSet",
    "ComponentTable",
    "PlaneTable",
    "RotaryTable",
    "interpolate_hold",
    "max_difference_um",
]


def _array(values: npt.ArrayLike, what: str, ndim: int = 1) -> np.ndarray:
    a = np.array(values, dtype=float)
    if a.ndim != ndim:
        raise DataError(f"{what}: expected a {ndim}-D array, found shape {a.shape}")
    if not np.all(np.isfinite(a)):
        raise DataError(f"{what}: holds a value that is not a finite number")
    a.setflags(write=False)
    return a


def interpolate_hold(
    x_mm: npt.ArrayLike, positions_mm: np.ndarray, values: np.ndarray
) -> np.ndarray:
    """Linear interpolation between table points; beyond the first and last point the end
    value is held (how LinuxCNC's motion controller treats its table, see
    ``docs/compensation.md``, and esp's reading for the formats whose documentation does
    not say)."""
    return np.interp(np.asarray(x_mm, dtype=float), positions_mm, values)


@dataclass(frozen=True, eq=False)
class AxisTable:
    """A correction of ``slave`` as a function of the commanded position of ``master``.

    Parameters
    ----------
    slave, master : axis letters; equal for a leadscrew table
    positions_mm : shape (n,), strictly increasing table points of the master axis
    forward_um, backward_um : shape (n,), the correction added to the slave's command when
        the master moves in the positive / negative direction (equal for a table that
        serves both directions)
    kind : ``"lead"`` (master = slave) or ``"cross"``
    components : the error components this table corrects
    """

    slave: str
    master: str
    positions_mm: np.ndarray
    forward_um: np.ndarray
    backward_um: np.ndarray
    kind: str = "lead"
    components: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        where = f"{self.kind} table of {self.slave}"
        p = _array(self.positions_mm, f"{where}: positions")
        f = _array(self.forward_um, f"{where}: forward values")
        b = _array(self.backward_um, f"{where}: backward values")
        if p.size < 2 or f.shape != p.shape or b.shape != p.shape:
            raise DataError(
                f"{where}: expected at least 2 points and one value per point in each "
                f"direction, found {p.size} points, {f.size} and {b.size} values"
            )
        if not np.all(np.diff(p) > 0):
            raise DataError(f"{where}: table positions must increase strictly")
        object.__setattr__(self, "positions_mm", p)
        object.__setattr__(self, "forward_um", f)
        object.__setattr__(self, "backward_um", b)
        object.__setattr__(self, "components", tuple(str(c) for c in self.components))

    @property
    def bilateral(self) -> bool:
        """True when the two directions carry different values."""
        return not np.array_equal(self.forward_um, self.backward_um)

    def values_um(self, direction: str) -> np.ndarray:
        """The table values a motion in ``direction`` uses (``"mean"``: their average)."""
        if direction == "forward":
            return self.forward_um
        if direction == "backward":
            return self.backward_um
        return 0.5 * (self.forward_um + self.backward_um)

    def correction_um(self, master_mm: npt.ArrayLike, direction: str = "mean") -> np.ndarray:
        """The correction at the master positions, interpolated linearly, ends held."""
        return interpolate_hold(master_mm, self.positions_mm, self.values_um(direction))


@dataclass(frozen=True, eq=False)
class PlaneTable:
    """A correction of ``slave`` over the plane of two master axes, on a grid.

    ``values_um[j, i]`` is the correction at ``positions_a_mm[i]`` of ``masters[0]`` and
    ``positions_b_mm[j]`` of ``masters[1]`` (the first index runs along the second master,
    as in the ISG list ``kw.crosscomp2.table[j][i]``). Between grid points the correction
    is interpolated bilinearly; beyond the grid the edge values are held.
    """

    slave: str
    masters: tuple[str, str]
    positions_a_mm: np.ndarray
    positions_b_mm: np.ndarray
    values_um: np.ndarray
    components: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        where = f"plane table of {self.slave}"
        a = _array(self.positions_a_mm, f"{where}: positions of {self.masters[0]}")
        b = _array(self.positions_b_mm, f"{where}: positions of {self.masters[1]}")
        v = _array(self.values_um, f"{where}: values", ndim=2)
        if a.size < 2 or b.size < 2 or v.shape != (b.size, a.size):
            raise DataError(
                f"{where}: expected a grid of at least 2 x 2 points with one value each, "
                f"found {a.size} x {b.size} points and values of shape {v.shape}"
            )
        if not (np.all(np.diff(a) > 0) and np.all(np.diff(b) > 0)):
            raise DataError(f"{where}: grid positions must increase strictly")
        object.__setattr__(self, "masters", tuple(self.masters))
        object.__setattr__(self, "positions_a_mm", a)
        object.__setattr__(self, "positions_b_mm", b)
        object.__setattr__(self, "values_um", v)
        object.__setattr__(self, "components", tuple(str(c) for c in self.components))

    def correction_um(self, a_mm: npt.ArrayLike, b_mm: npt.ArrayLike) -> np.ndarray:
        """The correction at positions of the two masters, bilinear, edges held."""
        a = np.clip(np.asarray(a_mm, dtype=float), self.positions_a_mm[0], self.positions_a_mm[-1])
        b = np.clip(np.asarray(b_mm, dtype=float), self.positions_b_mm[0], self.positions_b_mm[-1])
        pa, pb, v = self.positions_a_mm, self.positions_b_mm, self.values_um
        i = np.clip(np.searchsorted(pa, a, side="right") - 1, 0, pa.size - 2)
        j = np.clip(np.searchsorted(pb, b, side="right") - 1, 0, pb.size - 2)
        ta = (a - pa[i]) / (pa[i + 1] - pa[i])
        tb = (b - pb[j]) / (pb[j + 1] - pb[j])
        return (
            v[j, i] * (1 - ta) * (1 - tb)
            + v[j, i + 1] * ta * (1 - tb)
            + v[j + 1, i] * (1 - ta) * tb
            + v[j + 1, i + 1] * ta * tb
        )


@dataclass(frozen=True, eq=False)
class ComponentTable:
    """Error components for a controller that synthesises the correction itself.

    ``curves`` maps a component name (``X.linear``, ``X.straightness.Y``,
    ``X.angular.Z``) to ``(positions_mm, values)`` along its axis, values in the engine's
    unit (µm, or µm/m for angles) and with the sign of an error; ``squareness`` maps
    ``squareness.XY`` etc. to a value in µm/m.
    """

    curves: Mapping[str, tuple[np.ndarray, np.ndarray]] = field(default_factory=dict)
    squareness: Mapping[str, float] = field(default_factory=dict)

    def __post_init__(self) -> None:
        curves = {}
        for name, (p, v) in self.curves.items():
            pa = _array(p, f"{name}: positions")
            va = _array(v, f"{name}: values")
            if pa.size < 2 or va.shape != pa.shape or not np.all(np.diff(pa) > 0):
                raise DataError(
                    f"{name}: expected at least 2 increasing positions with one value each"
                )
            curves[str(name)] = (pa, va)
        sq = {}
        for name, value in self.squareness.items():
            value = float(value)
            if not np.isfinite(value):
                raise DataError(f"{name}: not a finite number")
            sq[str(name)] = value
        object.__setattr__(self, "curves", MappingProxyType(curves))
        object.__setattr__(self, "squareness", MappingProxyType(sq))


@dataclass(frozen=True, eq=False)
class RotaryTable:
    """A correction of a rotary axis' angle as a function of its own commanded angle.

    Parameters
    ----------
    axis : the axis letter (the table chain's coordinate)
    positions_deg : shape (n,), strictly increasing commanded angles
    correction_urad : shape (n,), the correction added to the commanded angle (the
        negative of the angular positioning error), µrad
    modulo : the table repeats every turn: positions from 0 to 360°, the first and last
        values equal, any angle reduced into the turn; otherwise the end values are held
    error : the error it corrects (``table.ECC``)
    """

    axis: str
    positions_deg: np.ndarray
    correction_urad: np.ndarray
    modulo: bool
    error: str = ""

    def __post_init__(self) -> None:
        where = f"rotary table of {self.axis}"
        p = _array(self.positions_deg, f"{where}: positions")
        v = _array(self.correction_urad, f"{where}: values")
        if p.size < 2 or v.shape != p.shape:
            raise DataError(f"{where}: expected at least 2 points with one value each")
        if not np.all(np.diff(p) > 0):
            raise DataError(f"{where}: table positions must increase strictly")
        if self.modulo and not (
            p[0] == 0.0 and p[-1] == 360.0 and abs(v[0] - v[-1]) <= 1e-9 * max(1.0, abs(v[0]))
        ):
            raise DataError(
                f"{where}: a modulo table runs from 0 to 360° with equal first and last values"
            )
        object.__setattr__(self, "positions_deg", p)
        object.__setattr__(self, "correction_urad", v)

    def correction_at(self, angles_deg: npt.ArrayLike) -> np.ndarray:
        """The correction at commanded angles (µrad): linear between points, a modulo
        table each angle reduced into its turn, another the end values held."""
        a = np.asarray(angles_deg, dtype=float)
        if self.modulo:
            a = np.mod(a, 360.0)
        return interpolate_hold(a, self.positions_deg, self.correction_urad)


@dataclass(frozen=True, eq=False)
class CompensationSet:
    """Everything one format holds for one machine.

    ``corrected`` lists the components the tables correct, ``uncorrected`` the machine's
    components the format cannot hold (left in the residual), ``notes`` remarks for the
    reports, ``settings`` the format's parameters (resolution, unit, limits, ...).
    """

    format: str
    axis_tables: tuple[AxisTable, ...] = ()
    plane_tables: tuple[PlaneTable, ...] = ()
    component_table: ComponentTable | None = None
    #: the angular positioning corrections of a rotary table's axes
    rotary_tables: tuple[RotaryTable, ...] = ()
    corrected: tuple[str, ...] = ()
    uncorrected: tuple[str, ...] = ()
    notes: tuple[str, ...] = ()
    settings: Mapping[str, object] = field(default_factory=dict)

    def __post_init__(self) -> None:
        object.__setattr__(self, "axis_tables", tuple(self.axis_tables))
        object.__setattr__(self, "plane_tables", tuple(self.plane_tables))
        object.__setattr__(self, "rotary_tables", tuple(self.rotary_tables))
        object.__setattr__(self, "corrected", tuple(str(c) for c in self.corrected))
        object.__setattr__(self, "uncorrected", tuple(str(c) for c in self.uncorrected))
        object.__setattr__(self, "notes", tuple(self.notes))
        object.__setattr__(self, "settings", MappingProxyType(dict(self.settings)))


def max_difference_um(a: CompensationSet, b: CompensationSet) -> float:
    """The largest difference between the values of two sets holding the same tables
    (µm, or µm/m for angular components, µrad and degrees for rotary tables), for
    round-trip checks. Raises
    :class:`DataError` when the tables do not correspond."""
    worst = 0.0

    def diff(x: npt.ArrayLike, y: npt.ArrayLike, what: str) -> float:
        x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
        if x.shape != y.shape:
            raise DataError(f"{what}: shapes differ, {x.shape} and {y.shape}")
        return float(np.max(np.abs(x - y))) if x.size else 0.0

    key = lambda t: (t.kind, t.slave, t.master)  # noqa: E731
    ta, tb = sorted(a.axis_tables, key=key), sorted(b.axis_tables, key=key)
    if [key(t) for t in ta] != [key(t) for t in tb]:
        raise DataError("the two sets hold different axis tables")
    for x, y in zip(ta, tb, strict=True):
        what = f"{x.kind} table of {x.slave}"
        worst = max(
            worst,
            diff(x.positions_mm, y.positions_mm, what) * 1000.0,
            diff(x.forward_um, y.forward_um, what),
            diff(x.backward_um, y.backward_um, what),
        )
    pa = sorted(a.plane_tables, key=lambda t: t.slave)
    pb = sorted(b.plane_tables, key=lambda t: t.slave)
    if [(t.slave, t.masters) for t in pa] != [(t.slave, t.masters) for t in pb]:
        raise DataError("the two sets hold different plane tables")
    for px, py in zip(pa, pb, strict=True):
        what = f"plane table of {px.slave}"
        worst = max(
            worst,
            diff(px.positions_a_mm, py.positions_a_mm, what) * 1000.0,
            diff(px.positions_b_mm, py.positions_b_mm, what) * 1000.0,
            diff(px.values_um, py.values_um, what),
        )
    ra = sorted(a.rotary_tables, key=lambda t: t.axis)
    rb = sorted(b.rotary_tables, key=lambda t: t.axis)
    if [(t.axis, t.modulo) for t in ra] != [(t.axis, t.modulo) for t in rb]:
        raise DataError("the two sets hold different rotary tables")
    for rx, ry in zip(ra, rb, strict=True):
        what = f"rotary table of {rx.axis}"
        worst = max(
            worst,
            diff(rx.positions_deg, ry.positions_deg, what),
            diff(rx.correction_urad, ry.correction_urad, what),
        )
    ca, cb = a.component_table, b.component_table
    if (ca is None) != (cb is None):
        raise DataError("only one of the two sets holds a component table")
    if ca is not None and cb is not None:
        if set(ca.curves) != set(cb.curves) or set(ca.squareness) != set(cb.squareness):
            raise DataError("the two component tables hold different components")
        for name in ca.curves:
            worst = max(
                worst,
                diff(ca.curves[name][0], cb.curves[name][0], name) * 1000.0,
                diff(ca.curves[name][1], cb.curves[name][1], name),
            )
        for name in ca.squareness:
            worst = max(worst, abs(ca.squareness[name] - cb.squareness[name]))
    return worst
