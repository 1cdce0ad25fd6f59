"""Measurement uncertainty of the error components (Longstaff 2002, 3.13-3.14) and of the
volumetric accuracy synthesised from them.

* :mod:`esp.core.uncertainty.budget` -- the budget of one component
  (:class:`ComponentUncertainty`, :class:`Contribution`), :func:`type_a`,
  :func:`rectangular`.
* :mod:`esp.core.uncertainty.gum` -- the GUM's effective degrees of freedom
  (Welch-Satterthwaite) and coverage factor from Student's t.
* :mod:`esp.core.uncertainty.instruments` -- one model per instrument (3.14.1-3.14.6);
  :func:`from_profile` takes the measurement-specific quantities from a measured
  :class:`~esp.core.profile.ErrorProfile` (its environment readings parsed by
  :mod:`esp.core.environment`).
* :mod:`esp.core.uncertainty.thermal` -- the thermal drift lookup of table 3.2.
* :mod:`esp.core.uncertainty.spec` -- the ``[uncertainty]`` table as records.
* :mod:`esp.core.uncertainty.propagate` -- the volumetric uncertainty and its budget;
  :mod:`esp.core.uncertainty.montecarlo` -- the Monte Carlo distribution of the accuracy.
* :mod:`esp.core.uncertainty.bayes` -- revision with prior information (3.13.1, eq. 3.22-3.24).

Everything here imports only numpy and the standard library.
"""

from esp.core.uncertainty.bayes import bayes_gamma, bayes_update, expanded_change
from esp.core.uncertainty.budget import ComponentUncertainty, Contribution, rectangular, type_a
from esp.core.uncertainty.gum import coverage_factor, welch_satterthwaite
from esp.core.uncertainty.instruments import (
    MODELS,
    TYPE_A_MIN_RUNS,
    angular_from_linear,
    from_profile,
    laser_angular,
    laser_linear,
    laser_straightness,
    level_differential,
    run_scatter,
    square,
)
from esp.core.uncertainty.thermal import THERMAL_DRIFT_TABLE, thermal_drift

__all__ = [
    "MODELS",
    "THERMAL_DRIFT_TABLE",
    "TYPE_A_MIN_RUNS",
    "ComponentUncertainty",
    "Contribution",
    "angular_from_linear",
    "bayes_gamma",
    "bayes_update",
    "coverage_factor",
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
    "welch_satterthwaite",
]
