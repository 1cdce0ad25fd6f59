"""The records of a ballbar circle as read: its runs and the circle."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from esp.ballbar.conditions import Conditions

__all__ = ["Circle", "Run"]


@dataclass(frozen=True)
class Run:
    """One direction of one circle: the angle θ of each reading (deg, in [0, 360), from
    the first axis of the plane towards the second) and the deviation of the measured
    length from the nominal radius (µm, outward positive), sorted by angle."""

    direction: str
    angle_deg: np.ndarray
    deviation_um: np.ndarray

    @property
    def sense(self) -> float:
        """+1 for ccw (θ increasing along the run), -1 for cw."""
        return 1.0 if self.direction == "ccw" else -1.0


@dataclass(frozen=True)
class Circle:
    """One ballbar circle: its plane (two axis letters, θ from the first), centre and
    radius (mm), its runs, the file it came from and the conditions it states."""

    name: str
    plane: str
    centre_mm: tuple[float, float, float]
    radius_mm: float
    runs: tuple[Run, ...]
    file: str
    conditions: Conditions
