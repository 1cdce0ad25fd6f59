"""The exact (nonlinear) effect of error values on the tool: the reference of the error
models.

The controller commands the slider heights of the nominal inverse kinematics. With the
machine's actual geometry -- joints, struts, ball joints and axes off by the error values
-- the platform assembles somewhere else: :func:`esp.parallel.kinematics.assemble` finds
where, exactly. The table's error then moves the workpiece: the tool's pose is taken in
the actual table frame. The difference from the nominal pose is the tool's error, exact to
the precision of Newton's method (10⁻¹⁰ mm), with no linearisation.

Used by the tests (the first-order models must agree with a finite difference of this to
second order) and by the Monte Carlo option that propagates through the nonlinear model.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import numpy.typing as npt

from esp.parallel.geometry import Geometry
from esp.parallel.kinematics import Deviation, Poses, assemble, log_rotation, rotation_vector
from esp.parallel.sources import SOURCE_NAMES

__all__ = ["deviation_from_values", "exact_errors"]

_COL = {name: i for i, name in enumerate(SOURCE_NAMES)}


def _take(values: np.ndarray, names: list[str]) -> np.ndarray:
    return values[..., [_COL[n] for n in names]]


def deviation_from_values(values: npt.ArrayLike) -> tuple[Deviation, np.ndarray, np.ndarray]:
    """The geometric deviation of error values (..., 42) in µm and µrad, with the table's
    translation (..., 3) mm and rotation vector (..., 3) rad."""
    v = np.asarray(values, float)
    joint = np.stack(
        [
            _take(v, [f"leg{i}.joint.{c}" for c in "XYZ"])
            + _take(v, [f"leg{i}.slider.{c}" for c in "XYZ"])
            for i in (1, 2, 3)
        ],
        axis=-2,
    )
    ball = np.stack([_take(v, [f"leg{i}.ball.{c}" for c in "xyz"]) for i in (1, 2, 3)], axis=-2)
    axis = np.stack(
        [_take(v, [f"leg{i}.axis.tilt", f"leg{i}.axis.yaw"]) for i in (1, 2, 3)], axis=-2
    )
    strut = _take(v, [f"leg{i}.strut" for i in (1, 2, 3)])
    dev = Deviation(joint * 1e-3, axis * 1e-6, ball * 1e-3, strut * 1e-3)
    return (
        dev,
        _take(v, [f"table.{c}" for c in "XYZ"]) * 1e-3,
        _take(v, [f"table.{c}" for c in "ABC"]) * 1e-6,
    )


def exact_errors(
    geometry: Geometry,
    pose: Poses,
    table_mm: Sequence[float] | np.ndarray,
    values: npt.ArrayLike,
) -> np.ndarray:
    """The tool's exact error at one nominal pose for error values.

    Parameters
    ----------
    geometry : the nominal machine
    pose : one nominal pose (its slider heights are the commanded ones)
    table_mm : (2,) the X-Y table's position
    values : (M, 42) or (42,) error values in µm and µrad (:data:`SOURCE_NAMES` order)

    Returns
    -------
    ndarray (M, 6)
        e_x, e_y, e_z (µm) and ε_x, ε_y, ε_z (µrad), relative to the table, in XYZ.
    """
    v = np.atleast_2d(np.asarray(values, float))
    m = v.shape[0]
    dev, table_shift, table_turn = deviation_from_values(v)
    sliders = np.broadcast_to(pose.sliders_mm[0], (m, 3))
    found = assemble(
        geometry,
        sliders,
        start_tip_mm=pose.tip_mm[0],
        start_rotation=pose.rotation[0],
        deviation=dev,
    )
    origin = np.asarray(geometry.table_origin_mm, float) + np.array([*table_mm, 0.0])
    turn = rotation_vector(table_turn)  # (M, 3, 3)
    turn_t = np.swapaxes(turn, -1, -2)
    # the tool in the actual table frame, against the nominal tool in the nominal frame
    tip = np.einsum("mij,mj->mi", turn_t, found.tip_mm - origin - table_shift)
    e = tip - (pose.tip_mm[0] - origin)
    rel = turn_t @ found.rotation @ pose.rotation[0].T
    eps = log_rotation(rel)
    return np.concatenate([e * 1e3, eps * 1e6], axis=1)
