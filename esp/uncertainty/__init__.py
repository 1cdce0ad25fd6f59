"""Measurement uncertainty of the error components (Longstaff 2002, 3.13-3.14).

* :mod:`esp.uncertainty.instruments` -- one model per instrument (3.14.1-3.14.6) giving a
  :class:`ComponentUncertainty` with its budget; :func:`from_profile` takes the
  measurement-specific quantities from a measured :class:`~esp.profile.ErrorProfile`.
* :mod:`esp.uncertainty.thermal` -- the thermal drift lookup of table 3.2.
* :mod:`esp.uncertainty.bayes` -- revision with prior information (3.13.1, eq. 3.22-3.24).

Everything here imports only numpy and the standard library.
"""

from esp.uncertainty.bayes import bayes_gamma, bayes_update, expanded_change
from esp.uncertainty.instruments import (
    MODELS,
    TYPE_A_MIN_RUNS,
    ComponentUncertainty,
    Contribution,
    angular_from_linear,
    from_profile,
    laser_angular,
    laser_linear,
    laser_straightness,
    level_differential,
    rectangular,
    run_scatter,
    square,
    type_a,
)
from esp.uncertainty.thermal import THERMAL_DRIFT_TABLE, thermal_drift

__all__ = [
    "MODELS",
    "THERMAL_DRIFT_TABLE",
    "TYPE_A_MIN_RUNS",
    "ComponentUncertainty",
    "Contribution",
    "angular_from_linear",
    "bayes_gamma",
    "bayes_update",
    "expanded_change",
    "from_profile",
    "laser_angular",
    "laser_linear",
    "laser_straightness",
    "level_differential",
    "rectangular",
    "run_scatter",
    "square",
    "thermal_drift",
    "type_a",
]
