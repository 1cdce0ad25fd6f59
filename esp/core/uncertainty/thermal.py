"""Thermal drift of the measuring set-up during a test: the lookup of Longstaff (2002), table 3.2.

Table 3.2 (after Knapp, also table 4.1 of the thesis) gives the typical drift of a laser
set-up as a function of how long the test took:

===========  =================  ==============
duration     displacement (µm)  angle (µm/m)
===========  =================  ==============
 5 min       0                  0
15 min       1                  3
30 min       2                  5
60 min       5                  10
===========  =================  ==============

The thesis only says "thermal lookup". How durations off the rows are treated is decided
here, conservatively:

* ``rule="interpolate"`` (default): linear interpolation between the rows, 0 at and below
  5 min: the drift of the test's own duration (a 31-minute test drifts 2.1 µm, not the
  5 µm of the 60-minute row).
* ``rule="step"``: a duration takes the value of the first row at or above it (16 min
  counts as 30 min), the more cautious reading; a test shorter than 5 minutes takes the
  5-minute row (0).
* Beyond 60 minutes (either rule) the drift keeps growing at the rate of the last interval
  of the table (30 to 60 min: 0.1 µm/min and 1/6 µm/m per minute), from the 60-minute row.
  Holding the 60-minute value would understate the drift of a long test; a rate taken from
  the origin (5 µm / 60 min) would be smaller than the last interval's.

The value is used as it is by the instrument models (the thesis adds it to the budget as a
standard uncertainty, except for straightness, where it enters a rectangular term).

This module imports only the standard library.

References
----------
Longstaff, A. P. (2002). *Methods of evaluation of the positioning capability of Cartesian
and non-Cartesian machines* (PhD thesis, University of Huddersfield), section 3.14 and
table 3.2; section 4.01 and table 4.1 (the same figures as assumptions of Knapp's report to
ISO TC39/SC2).
"""

from __future__ import annotations

import math

from esp.core.errors import DataError

__all__ = ["THERMAL_DRIFT_TABLE", "THERMAL_QUANTITIES", "THERMAL_RULES", "thermal_drift"]

#: rows of table 3.2: (duration in minutes, displacement drift in µm, angle drift in µm/m)
THERMAL_DRIFT_TABLE: tuple[tuple[float, float, float], ...] = (
    (5.0, 0.0, 0.0),
    (15.0, 1.0, 3.0),
    (30.0, 2.0, 5.0),
    (60.0, 5.0, 10.0),
)

#: quantity -> (column of the table, unit of the value)
THERMAL_QUANTITIES: dict[str, tuple[int, str]] = {"displacement": (1, "um"), "angle": (2, "um/m")}

THERMAL_RULES = ("step", "interpolate")


def thermal_drift(
    duration_min: float, quantity: str = "displacement", rule: str = "interpolate"
) -> float:
    """The thermal drift of table 3.2 for a test that lasted ``duration_min`` minutes.

    Parameters
    ----------
    duration_min : duration of the test in minutes, >= 0
    quantity : ``"displacement"`` (µm, for linear and straightness set-ups) or ``"angle"``
        (µm/m, for angular set-ups)
    rule : ``"interpolate"`` (default, linear between rows) or ``"step"`` (the next row
        up); beyond 60 min both continue at the rate of the 30-60 min interval

    Returns
    -------
    float
        The drift, in µm for ``"displacement"``, in µm/m for ``"angle"``.

    Raises
    ------
    DataError
        For a negative or non-finite duration, an unknown quantity or rule.

    References
    ----------
    Longstaff (2002), section 3.14, table 3.2.

    Examples
    --------
    >>> thermal_drift(15)
    1.0
    >>> round(thermal_drift(31), 3)   # 2 + (31 - 30) * (5 - 2) / 30
    2.1
    >>> thermal_drift(16, "angle", "step")   # the next row up
    5.0
    >>> thermal_drift(90)   # 5 + (90 - 60) * (5 - 2) / 30
    8.0
    """
    if quantity not in THERMAL_QUANTITIES:
        raise DataError(
            f"unknown thermal drift quantity {quantity!r}; expected 'displacement' or 'angle'"
        )
    if rule not in THERMAL_RULES:
        raise DataError(f"unknown thermal drift rule {rule!r}; expected 'step' or 'interpolate'")
    try:
        d = float(duration_min)
    except (TypeError, ValueError):
        raise DataError(
            f"test duration must be a number of minutes, got {duration_min!r}"
        ) from None
    if not math.isfinite(d) or d < 0:
        raise DataError(f"test duration must be a finite number of minutes >= 0, got {d!r}")
    column = THERMAL_QUANTITIES[quantity][0]
    times = [row[0] for row in THERMAL_DRIFT_TABLE]
    values = [row[column] for row in THERMAL_DRIFT_TABLE]
    if d <= times[0]:
        return float(values[0])
    if d > times[-1]:
        rate = (values[-1] - values[-2]) / (times[-1] - times[-2])
        return float(values[-1] + (d - times[-1]) * rate)
    for i in range(1, len(times)):
        if d <= times[i]:
            if rule == "step":
                return float(values[i])
            frac = (d - times[i - 1]) / (times[i] - times[i - 1])
            return float(values[i - 1] + frac * (values[i] - values[i - 1]))
    raise AssertionError("unreachable")  # pragma: no cover
