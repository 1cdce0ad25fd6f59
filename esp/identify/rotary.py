"""The errors of a rotary table as unknowns of ``esp identify``, and the probed sphere.

A table file (docs/rotary.md) may give any of its errors as an unknown:

* a location error (``X0C``, ``B0A``: a constant of the axis line) ``{ identify = true }``,
  one coefficient in the error's unit;
* a component error motion (``EXC``, ``ECC``: a function of its axis' angle)
  ``{ identify = { basis = "fourier", order = N } }``, cos kθ and sin kθ for k = 1..N,
  or, for an axis of limited travel, ``{ basis = "legendre", degree = d }``, P_j of the
  angle over ``travel_deg`` (default: the range of ``[table].angles``) less its value at
  0°.

Neither basis has a constant: the constant part of an error motion is a location error,
the place of the axis line (ISO 230-7:2015, 3.1; ISO 230-1:2012, 3.4.2), or, for the
angular positioning error, a turn of the workpiece about the axis that an unknown sphere
position absorbs; esp identifies it as the location error it is.

The design matrix of an unknown is the table's exact first-order effect per unit of the
error (:func:`esp.core.devices.table_effects.unit_terms`, the derivatives of the chain)
times each basis function at the setting's angle: the same terms the analysis adds
(docs/rotary.md), so that there is no second model.

The probed sphere (``kind = "sphere"``; the measurement of Heidenhain's KinematicsOpt and
Siemens' CYCLE996): a sphere fixed on the table at an unknown position s (workpiece frame,
mm) is probed at a list of table settings θ_i, and the machine reports its centre m_i
(machine coordinates of the probe's ball centre, mm). The tool tip commanded to m is
really at m + e(m, θ) relative to the workpiece (e in µm, machine axes: the linear axes'
errors at the MCP m - T, T the probe's offset, and the table's at m), so the probe finds
the sphere where m + e/1000 + d/1000 = T(θ)⁻¹ s (T(θ) the nominal table transform, d an
unknown error of the probe's offset when ``probe = "unknown"``). The residual of a reading
is ``1000 (m_i - T(θ_i)⁻¹ s) + e(m_i, θ_i) + d``, linear in s, d and the coefficients.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from esp.core.devices.table import MAX_ANGLE, Table, joint_of
from esp.core.errors import ConfigError
from esp.core.names import AXIS_NAMES

__all__ = [
    "ANGLE_BASES",
    "AngleBasis",
    "DeviceErrorName",
    "axis_of_errors",
    "head_unknowns",
    "iso_notation",
    "setting_rows",
    "table_design",
    "table_known_um",
    "table_unknowns",
]

ANGLE_BASES = ("fourier", "legendre")
MAX_ORDER = 24
MAX_DEGREE = 12
#: the step of the angles an identified periodic error motion is written at, degrees
PERIODIC_STEP_DEG = 1.0


@dataclass(frozen=True, order=True)
class DeviceErrorName:
    """An error of the rotary table or the servo head, by its chain symbol:
    ``table.X0C``, ``head.ThetaAs``. ``axis`` is, for a table, the coordinate of the
    joint whose error motion holds it (None for a location error, and for a head's
    error)."""

    owner: str
    symbol: str
    axis: str | None = None

    def __str__(self) -> str:
        return f"{self.owner}.{self.symbol}"

    @property
    def kind(self) -> str:
        """``"location"`` (a constant) or ``"motion"`` (over the angle of ``axis``)."""
        return "location" if self.axis is None else "motion"


@dataclass(frozen=True)
class AngleBasis:
    """The functions φ_j of an unknown error motion over the angle of its axis (degrees):
    Fourier cos kθ, sin kθ (k = 1..size) or Legendre P_j(u) - P_j(u_0) (j = 1..size) of u
    over ``travel_deg``, u_0 that of 0° (of the low end when 0° is outside the travel)."""

    family: str
    size: int
    axis: str
    travel_deg: tuple[float, float]
    targets_deg: tuple[float, ...]

    @property
    def periodic(self) -> bool:
        return self.family == "fourier"

    @property
    def labels(self) -> tuple[str, ...]:
        if self.family == "fourier":
            return tuple(f"{w}{k}" for k in range(1, self.size + 1) for w in ("cos", "sin"))
        return tuple(f"P{j}" for j in range(1, self.size + 1))

    def values(self, angles_deg: Any) -> np.ndarray:
        """φ_j at the angles, shape (N, len(labels)), per unit coefficient."""
        a = np.asarray(angles_deg, dtype=float).reshape(-1)
        if self.family == "fourier":
            t = np.radians(a)[:, None] * np.arange(1, self.size + 1)[None, :]
            out = np.empty((a.size, 2 * self.size))
            out[:, 0::2] = np.cos(t)
            out[:, 1::2] = np.sin(t)
            return out
        from esp.identify.basis import legendre_values

        lo, hi = self.travel_deg
        zero = 0.0 if lo <= 0.0 <= hi else lo
        u = (2.0 * a - lo - hi) / (hi - lo)
        u0 = np.array([(2.0 * zero - lo - hi) / (hi - lo)])
        return legendre_values(u, self.size)[:, 1:] - legendre_values(u0, self.size)[:, 1:]


def axis_of_errors(table: Table) -> dict[str, str]:
    """error -> the axis it belongs to: an error motion its joint's, a location error the
    axis whose joint the chain's location step follows (docs/rotary.md: each axis' location
    errors stand after its joint)."""
    from esp.core.kinematics.chain import ErrorMotion, Revolute

    out = dict(joint_of(table.chain))
    last: str | None = None
    for step in table.chain.steps:
        if isinstance(step, Revolute):
            last = step.coordinate
        elif isinstance(step, ErrorMotion) and last is not None:
            for expr in step.slots().values():
                for n in expr.names():
                    if table.chain.symbols[n].kind == "error":
                        out.setdefault(n, last)
    return out


def iso_notation(symbol: str, motion: bool) -> str:
    """The ISO 230-1 name of a table error: a location error ``X0C`` is E_X0C, an error
    motion ``EXC`` (esp's symbol) E_XC."""
    return f"E_{symbol[1:]}" if motion and symbol.startswith("E") else f"E_{symbol}"


def head_unknowns(head: Any) -> list[tuple[DeviceErrorName, str]]:
    """The head's errors given as ``{ identify = true }``: (name, key) each, one
    coefficient in the error's unit (a head's errors are constants)."""
    return [(DeviceErrorName("head", symbol), u.key) for symbol, u in head.to_identify.items()]


def table_unknowns(
    table: Table, angles_deg: Mapping[str, tuple[float, ...]], targets: int
) -> list[tuple[DeviceErrorName, str, AngleBasis | None]]:
    """The table's errors given as ``{ identify = ... }``: (name, key, basis) each, the
    basis None for a location error (one coefficient).

    Raises
    ------
    ConfigError
        A basis that is not one of :data:`ANGLE_BASES` with its size, ``true`` for an error
        motion (it varies with the angle: give a basis), a basis for a location error (a
        constant), a travel that is not two increasing angles (key and table file).
    """
    joints = joint_of(table.chain)
    out: list[tuple[DeviceErrorName, str, AngleBasis | None]] = []
    for symbol, unknown in table.to_identify.items():
        key, spec = unknown.key, unknown.spec

        def fail(k: str, message: str) -> ConfigError:
            return ConfigError(k, message, table.source)

        axis = joints.get(symbol)
        name = DeviceErrorName("table", symbol, axis)
        if spec is True:
            if axis is not None:
                raise fail(
                    f"{key}.identify",
                    f"{symbol} is an error motion of {axis}, a function of its angle: give a "
                    '{ basis = "fourier", order = 3 } (or "legendre" with a degree for an '
                    "axis of limited travel)",
                )
            out.append((name, key, None))
            continue
        if not isinstance(spec, Mapping):
            raise fail(
                f"{key}.identify",
                "expected true (a location error) or a basis such as "
                f'{{ basis = "fourier", order = 3 }}, found {spec!r}',
            )
        if axis is None:
            raise fail(
                f"{key}.identify",
                f"{symbol} is a location error of the axis line, a constant: give identify = true",
            )
        family = spec.get("basis")
        if family not in ANGLE_BASES:
            raise fail(
                f"{key}.identify.basis",
                f"expected one of {', '.join(ANGLE_BASES)}, found {family!r}",
            )
        size_key, limit = ("order", MAX_ORDER) if family == "fourier" else ("degree", MAX_DEGREE)
        allowed = {"basis", size_key} | ({"travel_deg"} if family == "legendre" else set())
        for k in spec:
            if k not in allowed:
                raise fail(
                    f"{key}.identify.{k}",
                    f"unknown key {k!r} for basis {family!r} (expected "
                    f"{', '.join(sorted(allowed))})",
                )
        size = spec.get(size_key)
        if isinstance(size, bool) or not isinstance(size, int) or not 1 <= size <= limit:
            raise fail(
                f"{key}.identify.{size_key}",
                f"expected a whole number from 1 to {limit}, found {size!r}",
            )
        if family == "fourier":
            travel = (0.0, 360.0)
            step = PERIODIC_STEP_DEG
            targets_deg = tuple(float(v) for v in np.arange(0.0, 360.0, step))
        else:
            given = _travel(spec.get("travel_deg"), angles_deg.get(axis, ()))
            if given is None:
                raise fail(
                    f"{key}.identify.travel_deg",
                    f"expected the travel of {axis}, [low, high] in degrees (or several "
                    f"angles of {axis} in [table].angles), found {spec.get('travel_deg')!r}",
                )
            travel = given
            targets_deg = tuple(float(v) for v in np.linspace(travel[0], travel[1], targets))
        out.append((name, key, AngleBasis(family, size, axis, travel, targets_deg)))
    return out


def _travel(given: Any, angles: tuple[float, ...]) -> tuple[float, float] | None:
    if given is None:
        if len(angles) < 2 or max(angles) <= min(angles):
            return None
        return float(min(angles)), float(max(angles))
    ok = (
        isinstance(given, list)
        and len(given) == 2
        and all(isinstance(v, int | float) and not isinstance(v, bool) for v in given)
        and all(abs(float(v)) <= MAX_ANGLE for v in given)
        and float(given[0]) < float(given[1])
    )
    return (float(given[0]), float(given[1])) if ok else None


def table_design(
    table: Table,
    unknowns: list[tuple[DeviceErrorName, AngleBasis | None, slice]],
    size: int,
    angles_deg: Mapping[str, np.ndarray],
    tips_mm: np.ndarray,
) -> np.ndarray:
    """∂e/∂c of the table's unknowns at N settings and tool tips (N, 3) mm: (N, 3, size)
    µm per unit coefficient, the columns ``slice`` of each unknown filled."""
    from esp.core.devices.table_effects import unit_terms

    tips = np.asarray(tips_mm, dtype=float).reshape(-1, 3)
    out = np.zeros((len(tips), 3, size))
    if not unknowns:
        return out
    units = unit_terms(table, angles_deg, [u.symbol for u, _, _ in unknowns])
    setup = table.setup_deg
    for name, basis, sl in unknowns:
        form = units.forms[name.symbol]
        here = form.constant_um + np.einsum("nij,nj->ni", form.per_mm, tips)
        phi0: np.ndarray | None
        if basis is None:
            phi = np.ones((len(tips), 1))
            phi0 = np.ones(1)
        else:
            phi = basis.values(angles_deg[basis.axis])
            phi0 = basis.values([setup[basis.axis]])[0] if setup is not None else None
        block = here[:, :, None] * phi[:, None, :]
        if setup is not None and phi0 is not None:
            there = form.setup_constant_um + np.einsum("nij,nj->ni", form.setup_per_mm, tips)
            block = block - there[:, :, None] * phi0[None, None, :]
        out[:, :, sl] = block
    return out


def table_known_um(
    table: Table, angles_deg: Mapping[str, np.ndarray], tips_mm: np.ndarray
) -> np.ndarray:
    """The error (N, 3) µm of the table's known errors (the unknowns are zero in
    ``table``) at N settings and tool tips, machine axes."""
    from esp.core.devices.table_effects import table_terms

    return table_terms(table, angles_deg).error_um(np.asarray(tips_mm, dtype=float))


def nominal_transform(
    table: Table, angles_deg: Mapping[str, np.ndarray]
) -> tuple[np.ndarray, np.ndarray]:
    """R (N, 3, 3), t (N, 3) of the nominal table transform: workpiece = R @ machine + t."""
    from esp.core.kinematics import transforms

    coords = {
        c: np.asarray(angles_deg[c], dtype=float) * np.pi / 180.0 / table.chain.symbols[c].scale
        for c in table.coordinates
    }
    frames = transforms(table.chain, coords, dict(table.parameters))
    return frames[:, :3, :3], frames[:, :3, 3]


@dataclass(frozen=True)
class SettingRows:
    """The readings of a table taken at table settings: ``labels`` each row's group (a
    sphere, a path, a run), ``angles`` coordinate -> (N,) degrees, ``positions`` (N, 3)
    mm, machine coordinates (a sphere's centre as read, or the commanded tool tip)."""

    labels: tuple[str, ...]
    angles: dict[str, np.ndarray]
    positions: np.ndarray


def setting_rows(table_file: Any, coordinates: tuple[str, ...], group: str) -> SettingRows:
    """Check a table read at table settings (:func:`esp.identify.tables.read_table` with
    the columns ``group``, one per rotary axis (``coordinates``: the table's and the
    head's), X, Y, Z): angles within
    :data:`MAX_ANGLE`, each group seen from two settings or more.

    Raises
    ------
    ParseError
        Naming the file and line.
    """
    angles = {}
    for c in coordinates:
        a = np.asarray(table_file.columns[c], dtype=float)
        bad = np.flatnonzero(np.abs(a) > MAX_ANGLE)
        if bad.size:
            raise table_file.fail(
                int(bad[0]), f"column {c}: expected an angle in degrees, found {a[bad[0]]:g}"
            )
        angles[c] = a
    labels = tuple(table_file.columns[group])
    positions = np.column_stack([table_file.columns[a] for a in AXIS_NAMES]).astype(float)
    settings = np.column_stack([angles[c] for c in coordinates])
    for g in dict.fromkeys(labels):
        idx = np.array([i for i, s in enumerate(labels) if s == g])
        distinct = np.unique(np.round(settings[idx], 9), axis=0)
        if len(distinct) < 2:
            at = ", ".join(f"{c} = {settings[idx[0], j]:g}" for j, c in enumerate(coordinates))
            raise table_file.fail(
                int(idx[-1]),
                f"{group} {g!r} is seen from one setting ({at}); the table's errors need "
                "two settings or more",
            )
    return SettingRows(labels, angles, positions)


def check_travel(
    table_file: Any,
    angles: Mapping[str, np.ndarray],
    bases: list[AngleBasis],
) -> None:
    """Refuse a setting outside the travel of a Legendre basis of its axis (the basis is
    not defined there), naming the file and line."""
    for b in bases:
        if b.periodic:
            continue
        a = angles[b.axis]
        lo, hi = b.travel_deg
        bad = np.flatnonzero((a < lo - 1e-9) | (a > hi + 1e-9))
        if bad.size:
            i = int(bad[0])
            raise table_file.fail(
                i,
                f"{b.axis} = {a[i]:g} deg lies outside the travel {lo:g}..{hi:g} deg of the "
                f"error motions identified over {b.axis} (travel_deg)",
            )
