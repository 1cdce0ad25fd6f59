"""Serial-parallel machines: an X-Y table under a three-strut parallel platform
(Zhao, Fan et al. 2002).

The numeric core (numpy only):

* :mod:`~esp.parallel.geometry` -- the machine's nominal geometry;
* :mod:`~esp.parallel.kinematics` -- eq. 1-5: inverse and forward kinematics, and the exact
  assembly with the machine's deviations;
* :mod:`~esp.parallel.linkage` and :mod:`~esp.parallel.differential` -- the two error
  models of the paper (section 4), implemented independently;
  :mod:`~esp.parallel.printed` -- eq. 10-18 exactly as printed;
* :mod:`~esp.parallel.exact` -- the tool's exact error for given error values;
* :mod:`~esp.parallel.transmission` -- the matrices [J], [M], [N], the sensitivities and
  the distance from singularity at many poses;
* :mod:`~esp.parallel.uncertainty` -- summation, statistical and Monte Carlo propagation;
* :mod:`~esp.parallel.sweep` -- the error-range sweep and the workspace grid;
* :mod:`~esp.parallel.config`, :mod:`~esp.parallel.analysis`, :mod:`~esp.parallel.render`
  -- the machine file, what ``esp parallel`` computes, its text and JSON.

See ``docs/parallel.md``.
"""

from esp.parallel.analysis import PoseResult, SweepResult, analyse_pose, sweep
from esp.parallel.config import ParallelMachine, PoseSpec, load_parallel, parallel_from_dict
from esp.parallel.exact import exact_errors
from esp.parallel.geometry import Geometry, Leg, symmetric_geometry
from esp.parallel.kinematics import Poses, forward, inverse
from esp.parallel.sources import OUTPUTS, SOURCE_NAMES, SOURCES
from esp.parallel.transmission import MAX_CONDITION, MODELS, Transmission, transmit

__all__ = [
    "MAX_CONDITION",
    "MODELS",
    "OUTPUTS",
    "SOURCES",
    "SOURCE_NAMES",
    "Geometry",
    "Leg",
    "ParallelMachine",
    "PoseResult",
    "PoseSpec",
    "Poses",
    "SweepResult",
    "Transmission",
    "analyse_pose",
    "exact_errors",
    "forward",
    "inverse",
    "load_parallel",
    "parallel_from_dict",
    "sweep",
    "symmetric_geometry",
    "transmit",
]
