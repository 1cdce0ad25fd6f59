"""Squareness and scale of a machine's axes from cheap measurements (``esp skew``): the
diagonals and sides of a square the machine made, or points of a part or plate, with their
uncertainty and the lines each firmware takes (docs/skew.md).

Modules: :mod:`~esp.skew.model` (the estimates and their uncertainty),
:mod:`~esp.skew.readings` (options and the points table), :mod:`~esp.skew.firmware`
(Marlin, Klipper, RepRapFirmware, µCNC, LinuxCNC), :mod:`~esp.skew.text`.
"""

from esp.skew.model import Caliper, Estimate, SkewResult, from_points, from_squares

__all__ = ["Caliper", "Estimate", "SkewResult", "from_points", "from_squares"]
