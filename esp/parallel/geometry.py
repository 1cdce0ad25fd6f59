"""The nominal geometry of a serial-parallel machine (Zhao, Fan et al. 2002, section 2).

Three vertical columns carry a slider each; a revolute joint on each slider carries a strut
of constant length; the struts end in ball joints on the spindle platform. The base frame
XYZ is the paper's (section 3, Fig. 2): Z vertical and up, X towards column 1, the origin
on the line through columns 2 and 3. In the symmetric layout of the paper the columns
stand at 120° on a circle of radius R centred at (R/2, 0): column 1 at (3R/2, 0), columns
2 and 3 at (0, ±√3 R/2).

A :class:`Leg` holds, in mm:

* ``joint_xy_mm`` -- where the column's line meets Z = 0; the revolute joint of the slider
  is at (X, Y, H) with H the slider height;
* ``axis`` -- the unit direction of the revolute joint's axis, horizontal (the paper's
  u_i, eq. 11); the strut swings in the vertical plane through the joint normal to it;
* ``ball_mm`` -- the ball joint's centre in the tool frame xyz (origin at the tool tip, z
  along the spindle towards the platform): the paper's b_i, eq. 2-3;
* ``strut_mm`` -- the strut length l_i, joint centre to ball centre.

The geometry is validated once, here: :class:`~esp.core.errors.ConfigError` names the key of a
value that does not make a machine.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import cast

import numpy as np

from esp.core.errors import ConfigError
from esp.core.values import shown

__all__ = ["LEGS", "Geometry", "Leg", "symmetric_geometry"]

#: the legs, numbered as in the paper
LEGS = (1, 2, 3)
#: the angular positions of the columns and ball joints of the symmetric layout (degrees)
_THETA_DEG = (0.0, 120.0, 240.0)


@dataclass(frozen=True)
class Leg:
    """One column, slider, revolute joint, strut and ball joint (lengths in mm)."""

    joint_xy_mm: tuple[float, float]
    axis: tuple[float, float]
    ball_mm: tuple[float, float, float]
    strut_mm: float

    @property
    def u(self) -> np.ndarray:
        """The revolute axis u_i as a 3-vector (horizontal)."""
        return np.array([self.axis[0], self.axis[1], 0.0])

    @property
    def radial(self) -> np.ndarray:
        """ρ_i = u_i × Z: the horizontal direction in the strut's plane (for the paper's
        layout it points from the column circle's centre to the column)."""
        return np.cross(self.u, [0.0, 0.0, 1.0])


@dataclass(frozen=True)
class Geometry:
    """The nominal machine: three legs, the table's reference point and limits.

    Attributes
    ----------
    legs : the three legs, in the order of the paper
    table_origin_mm : the X-Y table's reference point (where its errors are stated) in XYZ
        with the table at X = Y = 0; the lever of the table's angular errors is the tool
        tip's position relative to it
    slider_travel_mm : the stroke (H_min, H_max) of the sliders, or None for no limit
    layout : ``"symmetric"`` (built from R, r, h) or ``"explicit"`` (legs given one by one)
    R_mm, r_mm, h_mm : the parameters of the symmetric layout (None when explicit)
    """

    legs: tuple[Leg, Leg, Leg]
    table_origin_mm: tuple[float, float, float]
    slider_travel_mm: tuple[float, float] | None = None
    layout: str = "explicit"
    R_mm: float | None = None
    r_mm: float | None = None
    h_mm: float | None = None

    def __post_init__(self) -> None:
        _validate(self)

    @property
    def joints_mm(self) -> np.ndarray:
        """(3, 2): the X, Y of each column."""
        return np.array([leg.joint_xy_mm for leg in self.legs], dtype=float)

    @property
    def axes(self) -> np.ndarray:
        """(3, 3): u_i, one row per leg."""
        return np.array([leg.u for leg in self.legs])

    @property
    def radials(self) -> np.ndarray:
        """(3, 3): ρ_i = u_i × Z, one row per leg."""
        return np.array([leg.radial for leg in self.legs])

    @property
    def balls_mm(self) -> np.ndarray:
        """(3, 3): b_i in the tool frame, one row per leg."""
        return np.array([leg.ball_mm for leg in self.legs], dtype=float)

    @property
    def struts_mm(self) -> np.ndarray:
        """(3,): l_i."""
        return np.array([leg.strut_mm for leg in self.legs], dtype=float)

    @property
    def lever_mm(self) -> float:
        """The mean distance from the tool tip to the ball joints: the length that makes
        the Jacobian dimensionless for its condition number."""
        return float(np.mean(np.linalg.norm(self.balls_mm, axis=1)))


def symmetric_geometry(
    R_mm: float,
    r_mm: float,
    h_mm: float,
    strut_mm: float | Sequence[float],
    *,
    table_origin_mm: Sequence[float] | None = None,
    slider_travel_mm: Sequence[float] | None = None,
) -> Geometry:
    """The layout of Zhao, Fan et al. (2002), Fig. 2 and eq. 3.

    Parameters
    ----------
    R_mm : radius of the circle through the revolute joints R_i (the columns)
    r_mm : radius of the circle through the ball joints b_i on the platform
    h_mm : distance from the tool tip to the platform's centre, along the spindle
    strut_mm : the strut length l (all three), or the three lengths l_1, l_2, l_3
    table_origin_mm : the table's reference point; default the column circle's centre at
        Z = 0, (R/2, 0, 0)
    slider_travel_mm : (H_min, H_max), or None

    Returns
    -------
    Geometry
        Columns at (R/2, 0) + R (cos θ_i, sin θ_i), θ = 0°, 120°, 240°; revolute axes
        u_i = Z × (cos θ_i, sin θ_i, 0) (the paper's [u], eq. 11); balls at
        (r cos θ_i, r sin θ_i, h) in the tool frame (eq. 3).
    """
    for key, value in (("geometry.R_mm", R_mm), ("geometry.r_mm", r_mm), ("geometry.h_mm", h_mm)):
        if not math.isfinite(value):
            raise ConfigError(key, f"expected a finite length in mm, found {value!r}")
    if R_mm <= 0:
        raise ConfigError("geometry.R_mm", f"expected a radius > 0 mm, found {shown(R_mm)}")
    if r_mm <= 0:
        raise ConfigError("geometry.r_mm", f"expected a radius > 0 mm, found {shown(r_mm)}")
    struts = _three(strut_mm, "geometry.strut_mm")
    legs = []
    for theta_deg, strut in zip(_THETA_DEG, struts, strict=True):
        t = math.radians(theta_deg)
        c, s = _cos_sin(t)
        legs.append(
            Leg(
                joint_xy_mm=(R_mm / 2 + R_mm * c, R_mm * s),
                axis=(-s, c),
                ball_mm=(r_mm * c, r_mm * s, h_mm),
                strut_mm=strut,
            )
        )
    # a given origin or travel of another length is refused by Geometry's validation
    origin: tuple[float, float, float] = (R_mm / 2, 0.0, 0.0)
    if table_origin_mm is not None:
        origin = cast("tuple[float, float, float]", tuple(table_origin_mm))
    travel: tuple[float, float] | None = None
    if slider_travel_mm is not None:
        travel = cast("tuple[float, float]", tuple(slider_travel_mm))
    return Geometry((legs[0], legs[1], legs[2]), origin, travel, "symmetric", R_mm, r_mm, h_mm)


def _cos_sin(t: float) -> tuple[float, float]:
    """cos and sin with the exact zeros of 0°, 120°, 240° kept exact where they are."""
    c, s = math.cos(t), math.sin(t)
    return (0.0 if abs(c) < 1e-15 else c), (0.0 if abs(s) < 1e-15 else s)


def _three(value: float | Sequence[float], key: str) -> tuple[float, float, float]:
    if isinstance(value, (int, float)):
        return (float(value),) * 3
    values = tuple(float(v) for v in value)
    if len(values) != 3:
        raise ConfigError(key, f"expected one length or three, found {len(values)}")
    return values


def _validate(g: Geometry) -> None:
    """Refuse a geometry that does not make a machine (one line, naming the key)."""
    if len(g.legs) != 3:
        raise ConfigError("geometry.legs", f"expected three legs, found {len(g.legs)}")
    for i, leg in zip(LEGS, g.legs, strict=True):
        key = f"geometry.leg{i}"
        values = [*leg.joint_xy_mm, *leg.axis, *leg.ball_mm, leg.strut_mm]
        if not all(math.isfinite(v) for v in values):
            raise ConfigError(key, f"expected finite numbers, found {values!r}")
        if leg.strut_mm <= 0:
            raise ConfigError(
                f"{key}.strut_mm", f"expected a length > 0 mm, found {shown(leg.strut_mm)}"
            )
        norm = math.hypot(*leg.axis)
        if abs(norm - 1.0) > 1e-9:
            raise ConfigError(f"{key}.axis", f"expected a unit vector, found length {norm:.6g}")
    joints = g.joints_mm
    for a in range(3):
        for b in range(a + 1, 3):
            if np.linalg.norm(joints[a] - joints[b]) < 1e-6:
                raise ConfigError(
                    "geometry",
                    f"columns {a + 1} and {b + 1} stand at the same place "
                    f"({joints[a][0]:g}, {joints[a][1]:g}) mm",
                )
    balls = g.balls_mm
    # three distinct, non-collinear ball joints make a rigid platform triangle
    area2 = np.linalg.norm(np.cross(balls[1] - balls[0], balls[2] - balls[0]))
    span = max(np.linalg.norm(balls[a] - balls[b]) for a in range(3) for b in range(3))
    if span < 1e-6 or area2 < 1e-9 * span**2:
        raise ConfigError(
            "geometry", "the three ball joints are on one line (or one point): no platform"
        )
    if not all(math.isfinite(v) for v in g.table_origin_mm) or len(g.table_origin_mm) != 3:
        raise ConfigError(
            "geometry.table_origin_mm",
            f"expected three finite numbers, found {g.table_origin_mm!r}",
        )
    if g.slider_travel_mm is not None:
        if len(g.slider_travel_mm) != 2:
            raise ConfigError(
                "geometry.slider_travel_mm",
                f"expected [H_min, H_max], found {list(g.slider_travel_mm)!r}",
            )
        lo, hi = g.slider_travel_mm
        if not (math.isfinite(lo) and math.isfinite(hi)) or lo >= hi:
            raise ConfigError(
                "geometry.slider_travel_mm",
                f"expected [H_min, H_max] with H_min < H_max, found [{lo:g}, {hi:g}]",
            )
