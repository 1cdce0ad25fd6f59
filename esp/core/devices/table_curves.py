"""A component error motion of a rotary axis over its angle: a curve given at some angles,
interpolated linearly at the settings, periodic over one turn (numpy only).

It is read (:func:`esp.config.curves.read_curve`) from a small CSV file::

    # C axis of the trunnion: angular positioning deviation, arcsec
    angle_deg,ECC,EXC
    0,0.0,0.4
    30,1.8,0.3
    ...
    330,-1.2,0.5

The first column is the axis angle in degrees (header ``angle_deg``), strictly increasing;
every other column holds one error's values at those angles (the table file names the
column and the unit). ``#`` lines are comments. A periodic curve spans less than one turn,
or exactly one when its last point repeats the first (360° is 0°): between its last point
and its first point plus 360° it is interpolated across the seam, and any angle is reduced
into its turn first. A curve of an axis with a limited travel (a trunnion's A) is given
``periodic = false``; it then holds only between its first and last angle, and a setting
outside them is refused.

ISO 230-7:2015 gives the error motions of an axis of rotation as functions of its angle;
ISO 230-2:2014 the angular positioning deviation at target positions over the axis' travel.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from esp.core.errors import DataError
from esp.core.values import written

__all__ = ["TURN", "Curve"]

#: a turn, degrees
TURN = 360.0


@dataclass(frozen=True)
class Curve:
    """An error's values over the angle of its axis.

    Attributes
    ----------
    angles_deg : (M,) strictly increasing angles, degrees (M >= 2)
    values : (M,) the error's values there, in ``unit`` (scale already applied)
    unit : the unit of ``values`` (the unit of the chain symbol it feeds)
    periodic : interpolate across the seam between the last angle and the first + 360°
    source : where it came from, for messages (``"C-motions.csv:EXC"``)
    """

    angles_deg: np.ndarray
    values: np.ndarray
    unit: str
    periodic: bool = True
    source: str = ""

    def __post_init__(self) -> None:
        a = np.asarray(self.angles_deg, dtype=float)
        v = np.asarray(self.values, dtype=float)
        where = self.source or "curve"
        if a.ndim != 1 or v.shape != a.shape or a.size < 2:
            raise DataError(f"{where}: expected at least two angles with one value each")
        if not (np.all(np.isfinite(a)) and np.all(np.isfinite(v))):
            raise DataError(f"{where}: expected finite angles and values")
        if np.any(np.diff(a) <= 0):
            raise DataError(f"{where}: expected strictly increasing angles")
        if self.periodic and a[-1] - a[0] >= TURN:
            raise DataError(
                f"{where}: a periodic curve spans less than one turn, found "
                f"{written(a[0])}..{written(a[-1])} deg"
            )
        object.__setattr__(self, "angles_deg", a)
        object.__setattr__(self, "values", v)

    @property
    def range_deg(self) -> tuple[float, float]:
        """The first and last angle, degrees."""
        return float(self.angles_deg[0]), float(self.angles_deg[-1])

    def at(self, angles_deg: Any) -> np.ndarray:
        """The values at ``angles_deg`` (degrees, a number or an array), linearly
        interpolated; periodic curves reduce each angle into their turn first.

        Raises
        ------
        DataError
            A non-periodic curve asked for an angle outside its range.
        """
        x = np.asarray(angles_deg, dtype=float)
        a, v = self.angles_deg, self.values
        if self.periodic:
            x = a[0] + np.mod(x - a[0], TURN)
            xp = np.concatenate([a, [a[0] + TURN]])
            fp = np.concatenate([v, [v[0]]])
            return np.interp(x, xp, fp)
        lo, hi = self.range_deg
        outside = (x < lo - 1e-9) | (x > hi + 1e-9)
        if np.any(outside):
            bad = float(np.ravel(x)[np.argmax(np.ravel(outside))])
            raise DataError(
                f"{self.source or 'curve'}: {bad:g} deg is outside the curve's range "
                f"{lo:g}..{hi:g} deg (periodic = false: it is not extended)"
            )
        return np.interp(x, a, v)
