"""The kinematic corrections of an identified rotary table: where each axis line is.

A controller's kinematic description places each rotary axis by a line: a point and a
direction in machine coordinates at the zero setting. The identified location errors move
those lines (ISO 230-1:2012, 3.4.2; ISO 230-7:2015, 3.1: the axis average line). esp finds
each actual line from the identified table's exact chain, not from the symbols' meaning,
so that any table chain is served:

* the machine position of a workpiece point is T(θ)⁻¹ w; turning axis q alone from 0 to
  90° (every other axis at 0) moves every such position by G = T(θ_q)⁻¹ T(0), a rotation
  about the actual line of q in machine coordinates (the error motions, which have no
  constant part, left out: the line is the average line);
* the line's direction is the axis of G's rotation (its skew part), signed as the nominal
  one; its point is the solution of (I − R) x = t nearest the nominal reference point
  of q (the origin of q's joint frame at the zero setting, from the chain's steps before
  the joint).

The uncertainty of each coordinate is propagated from the covariance of the identified
location errors through the derivative of the line with respect to each (central
differences of the exact construction; the line is linear in them to first order; JCGM
100:2008, 5.1.2).

Controllers: LinuxCNC's ``xyzac-trt-kins`` and ``xyzbc-trt-kins`` (src/emc/kinematics/
trtfuncs.c) place the table's axes by positions only -- ``x-rot-point``,
``y-rot-point``, ``z-rot-point`` (a point on the C line) and ``y-offset``, ``z-offset``
(A) or ``x-offset``, ``z-offset`` (B) from it -- with the axes parallel to the machine's;
:func:`linuxcnc_parameters` gives them from the actual lines, and the tilts they cannot
hold are reported beside them.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from esp.core.devices.device import Device
from esp.core.devices.table import Table
from esp.core.kinematics import Chain, transforms
from esp.core.kinematics.chain import Revolute

__all__ = ["AxisLine", "axis_lines", "linuxcnc_lines", "linuxcnc_parameters"]

_AXES = {"x": np.array([1.0, 0.0, 0.0]), "y": np.array([0.0, 1.0, 0.0]), "z": np.eye(3)[2]}
#: the turn of one axis over which its line is found, degrees
TURN_DEG = 90.0


@dataclass(frozen=True)
class AxisLine:
    """One rotary axis' line at the zero setting, machine coordinates.

    ``point_mm`` is the point of the actual line nearest the nominal reference point
    ``nominal_point_mm``; ``direction`` and ``nominal_direction`` unit vectors;
    ``U_offset_um`` and ``U_tilt_urad`` the expanded uncertainties of the offset and the
    tilt along X, Y, Z (k of the identification)."""

    axis: str
    nominal_point_mm: tuple[float, float, float]
    nominal_direction: tuple[float, float, float]
    point_mm: tuple[float, float, float]
    direction: tuple[float, float, float]
    U_offset_um: tuple[float, float, float]
    U_tilt_urad: tuple[float, float, float]
    #: ``"table"`` (machine coordinates) or ``"head"`` (the head's base frame, the ram's)
    owner: str = "table"

    @property
    def offset_um(self) -> tuple[float, float, float]:
        d = 1000.0 * (np.array(self.point_mm) - np.array(self.nominal_point_mm))
        return (float(d[0]), float(d[1]), float(d[2]))

    @property
    def tilt_urad(self) -> tuple[float, float, float]:
        d = 1e6 * (np.array(self.direction) - np.array(self.nominal_direction))
        return (float(d[0]), float(d[1]), float(d[2]))


def _joint_frames(table: Device) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """Each joint's nominal reference point and direction at the zero setting (machine =
    workpiece frame there)."""
    chain = table.chain
    zero = {c: np.zeros(1) for c in chain.coordinates}
    out = {}
    for i, step in enumerate(chain.steps):
        if not isinstance(step, Revolute):
            continue
        sub = Chain(tuple(chain.steps[:i]), dict(chain.symbols))
        F = transforms(sub, zero, dict(table.parameters))[0]
        sign = -1.0 if step.axis.startswith("-") else 1.0
        axis = sign * _AXES[step.axis.lstrip("+-")]
        out[step.coordinate] = (F[:3, 3].copy(), F[:3, :3] @ axis)
    return out


def _lines(
    table: Device,
    error_sets: Sequence[Mapping[str, float]],
    q: str,
    ref: np.ndarray,
    nominal: np.ndarray,
) -> list[tuple[np.ndarray, np.ndarray]]:
    """The line (point, direction) of axis q for each set of error values, from one
    evaluation of the chain (two settings per set: q at 0 and at :data:`TURN_DEG`). A
    table's chain runs from the workpiece to the machine, so a workpiece point's machine
    position moves by T(θ)⁻¹ T(0); a head's from the ram to the tool, so a point carried
    by the tool moves by T(θ) T(0)⁻¹ in the ram's frame."""
    chain = table.chain
    k = len(error_sets)
    coords = {c: np.zeros(2 * k) for c in chain.coordinates}
    coords[q] = np.tile([0.0, TURN_DEG * np.pi / 180.0 / chain.symbols[q].scale], k)
    values = {
        e: np.repeat([float(errors.get(e, 0.0)) for errors in error_sets], 2) for e in chain.errors
    }
    T = transforms(chain, coords, dict(table.parameters), values)
    out = []
    for i in range(k):
        if isinstance(table, Table):
            G = np.linalg.inv(T[2 * i + 1]) @ T[2 * i]
        else:
            G = T[2 * i + 1] @ np.linalg.inv(T[2 * i])
        R, t = G[:3, :3], G[:3, 3]
        w = np.array([R[2, 1] - R[1, 2], R[0, 2] - R[2, 0], R[1, 0] - R[0, 1]])
        d = w / np.linalg.norm(w)
        if d @ nominal < 0:
            d = -d
        x0 = np.linalg.lstsq(np.eye(3) - R, t, rcond=None)[0]
        x0 = x0 - d * (d @ x0)  # exactly on the line, nearest the origin
        out.append((x0 + d * (d @ (ref - x0)), d))
    return out


def axis_lines(
    table: Device,
    location: Mapping[str, float],
    covariance: np.ndarray,
    k: float,
) -> list[AxisLine]:
    """The actual line of every axis of ``table`` (a rotary table, or a servo head: its
    lines in its base frame, the ram's) with the errors ``location`` (symbol -> value in
    its unit; the others the device's constants), and the expanded uncertainty of its
    coordinates from ``covariance`` (of the values of ``location``, in its order) at
    coverage factor ``k``."""
    names = list(location)
    curves = getattr(table, "curves", {})
    errors = {e: float(v) for e, v in table.errors.items() if e not in curves}
    errors.update(location)
    frames = _joint_frames(table)
    out = []
    for q in table.coordinates:
        ref, nominal = frames[q]
        h = 1.0  # one unit of each error: the line is linear in them to first order
        sets = [errors]
        for name in names:
            sets += [
                dict(errors, **{name: errors[name] + h}),
                dict(errors, **{name: errors[name] - h}),
            ]
        found = _lines(table, sets, q, ref, nominal)
        point, direction = found[0]
        J = np.zeros((6, len(names)))
        for j in range(len(names)):
            (p1, d1), (p0, d0) = found[1 + 2 * j], found[2 + 2 * j]
            J[:3, j] = 1000.0 * (p1 - p0) / (2 * h)
            J[3:, j] = 1e6 * (d1 - d0) / (2 * h)
        var = np.einsum("ij,jk,ik->i", J, covariance, J) if names else np.zeros(6)
        U = k * np.sqrt(np.maximum(var, 0.0))
        out.append(
            AxisLine(
                q,
                _three(ref),
                _three(nominal),
                _three(point),
                _three(direction),
                _three(U[:3]),
                _three(U[3:]),
            )
        )
    return out


def _three(v: Sequence[float] | np.ndarray) -> tuple[float, float, float]:
    return (float(v[0]), float(v[1]), float(v[2]))


def linuxcnc_parameters(lines: Sequence[AxisLine]) -> tuple[str, dict[str, float]] | None:
    """The module and the HAL parameters of LinuxCNC's trunnion kinematics for the lines
    of a C table on a tilting A (``xyzac-trt-kins``) or B (``xyzbc-trt-kins``) cradle
    whose nominal lines are parallel to Z and to X or Y; None for another table. The
    C line is placed at its point at the reference height (``z-rot-point``), the tilting
    axis by its point in the plane of the C line normal to it; the parameters hold no
    tilt (reported by :attr:`AxisLine.tilt_urad`)."""
    by = {line.axis: line for line in lines}
    if set(by) not in ({"A", "C"}, {"B", "C"}):
        return None
    c = by["C"]
    tilt = by["A"] if "A" in by else by["B"]
    along = 0 if "A" in by else 1
    if not (
        np.allclose(np.abs(c.nominal_direction), (0, 0, 1))
        and np.allclose(np.abs(tilt.nominal_direction), np.eye(3)[along])
    ):
        return None
    z_ref = c.nominal_point_mm[2]
    cp, cd = np.array(c.point_mm), np.array(c.direction)
    on_c = cp + cd * (z_ref - cp[2]) / cd[2]
    tp, td = np.array(tilt.point_mm), np.array(tilt.direction)
    at = tp + td * (on_c[along] - tp[along]) / td[along]
    params = {"x-rot-point": on_c[0], "y-rot-point": on_c[1], "z-rot-point": on_c[2]}
    if along == 0:
        module = "xyzac-trt-kins"
        params.update({"y-offset": at[1] - on_c[1], "z-offset": at[2] - on_c[2]})
    else:
        module = "xyzbc-trt-kins"
        params.update({"x-offset": at[0] - on_c[0], "z-offset": at[2] - on_c[2]})
    return module, {k: float(v) for k, v in params.items()}


def linuxcnc_lines(module: str, params: Mapping[str, float]) -> list[str]:
    """``setp`` lines of a HAL file for LinuxCNC's trunnion kinematics (mm, to 0.1 µm)."""
    return [f"setp {module}.{name} {value:.4f}" for name, value in params.items()]
