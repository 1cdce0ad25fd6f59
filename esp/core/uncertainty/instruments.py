"""Instrument models: the expanded uncertainty of one measured error component from what
is known about its measurement (Longstaff 2002, 3.14.1-3.14.6).

Each model turns the instrument's specification, the set-up, and quantities taken from the
data (measuring length, range of the readings, the largest angle, the scatter of the runs,
the test duration and temperatures) into a budget of standard uncertainties
(:class:`~esp.core.uncertainty.budget.ComponentUncertainty`), combined in quadrature and
multiplied by a coverage factor k (GUM; thesis eq. 3.19 and 3.21)::

    U = k · sqrt(Σ u_i²)

Set-up contributors are rectangular. The thesis writes most of them as ``e / (2·√3)``: a
one-sided effect of size e spans a rectangle of full width e, i.e. half-width a = e/2, and
eq. 3.18 gives u = a/√3 = e/(2√3). Contributors that change from run to run are evaluated
from the runs (Type A, eq. 3.17, with n − 1 degrees of freedom) when there are at least
five of them; the budget then carries its effective degrees of freedom (GUM G.4.1).

Units of the result (ESP-NOTES, "Uncertainty of a component"):

* linear (3.14.1) and straightness (3.14.5): U in µm, one value valid along the whole axis;
* angular (3.14.2-3.14.4) and squareness (3.14.6): U in µm/m, multiplied by the lever arm
  at a point exactly like the error it belongs to.

The thesis calls the linear result a figure "per metre"; here it is the µm of the given
measuring length (see :func:`laser_linear`). ``docs/uncertainty.md`` sets every model out
term by term beside the thesis' formula, with the reading chosen where the printed formula
does not fix its units. :func:`from_profile` takes the measurement-specific quantities from
a measured profile and its environment readings (:mod:`esp.core.environment`).

This module imports only numpy and the standard library.

References
----------
Longstaff, A. P. (2002). *Methods of evaluation of the positioning capability of Cartesian
and non-Cartesian machines* (PhD thesis, University of Huddersfield), sections 3.13
(eq. 3.17-3.21), 3.14.1-3.14.6 and table 3.2; after Knapp's report to ISO TC39/SC2
(reference [63] of the thesis).
JCGM 100:2008 (GUM), 4.2 (Type A), 4.3.7 (rectangular distribution), 5.1.2 (combined
standard uncertainty), 6.2.1 (expanded uncertainty), G.4.1 (effective degrees of freedom).
"""

from __future__ import annotations

import inspect
import math
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

import numpy as np

from esp.core.environment import environment_quantities
from esp.core.errors import DataError
from esp.core.profile import ErrorProfile
from esp.core.uncertainty.budget import ComponentUncertainty, type_a
from esp.core.uncertainty.checks import MissingParameter, count, finite, need, one_of
from esp.core.uncertainty.thermal import thermal_drift

if TYPE_CHECKING:
    from esp.core.uncertainty.spec import UncertaintySpec

__all__ = [
    "ALIGNMENT_MODELS",
    "CROSS_TALK_SHARE",
    "MODELS",
    "SCATTER_STATISTICS",
    "TYPE_A_MIN_RUNS",
    "angular_from_linear",
    "cross_talk_warning",
    "from_profile",
    "instrument_warnings",
    "laser_angular",
    "laser_linear",
    "laser_straightness",
    "level_differential",
    "run_scatter",
    "square",
]

#: 2·√3: the divisor of a one-sided rectangular effect of full width e (u = e / (2√3))
TWO_ROOT_3 = 2.0 * math.sqrt(3.0)

#: fewest runs per direction for the Type A evaluation (thesis 3.14.2, 3.14.3, 3.14.5:
#: "if the number of measurement runs is less than 5", after ISO 230-2)
TYPE_A_MIN_RUNS = 5

ALIGNMENT_MODELS = ("thesis", "cosine")
#: how a laser's air refraction enters :func:`laser_linear`
AIR_COMPENSATION = ("included", "fixed", "sensors")


def _run_term(
    model: str,
    *,
    quantity: str,
    unit: str,
    std_name: str,
    run_std: float | None,
    runs: int | None,
    duration_min: float | None,
    min_runs: int,
    thermal_rule: str,
) -> tuple[bool, float, float]:
    """Decide between Type A (``True``, s/√n with n − 1 degrees of freedom) and the thermal
    lookup (``False``, the drift, a Type B value taken as exact: infinite degrees of freedom).

    Type A when ``runs`` (runs per direction) is at least ``min_runs``; then ``run_std``
    is required. Otherwise the table 3.2 lookup, which needs ``duration_min``.
    """
    threshold = count(model, "type_a_min_runs", min_runs, smallest=2)
    n = 0 if runs is None else count(model, "runs", runs)
    if n >= threshold:
        s = need(model, std_name, run_std, f"standard deviation of the runs, {unit}")
        return True, type_a(s, n), float(n - 1)
    d = need(model, "duration_min", duration_min, "test duration in minutes, for table 3.2")
    return False, thermal_drift(d, quantity, thermal_rule), math.inf


# -- 3.14.1 linear positioning, laser interferometer ------------------------------------------


def laser_linear(
    *,
    measuring_length_mm: float,
    duration_min: float | None = None,
    temperature_change_degc: float | None = None,
    max_difference_to_20_degc: float | None = None,
    u_calibration_um_per_m: float | None = None,
    alignment_mm: float | None = None,
    expansion_coefficient_um_per_m_per_degc: float | None = None,
    u_expansion_coefficient_um_per_m_per_degc: float = 0.7,
    alignment_model: str = "thesis",
    thermal_rule: str = "interpolate",
    k: float = 2.0,
    air_compensation: str = "included",
    air_temperature_start_degc: float | None = None,
    air_temperature_end_degc: float | None = None,
    air_pressure_start_kpa: float | None = None,
    air_pressure_end_kpa: float | None = None,
    air_humidity_start_pct: float | None = None,
    air_humidity_end_pct: float | None = None,
    air_temperature_accuracy_degc: float | None = None,
    air_pressure_accuracy_kpa: float | None = None,
    air_humidity_accuracy_pct: float | None = None,
    abbe_offset_mm: float | None = None,
    abbe_angle_um_per_m: float | None = None,
) -> ComponentUncertainty:
    """Linear positioning error measured with a laser interferometer (thesis 3.14.1).

    Every term is evaluated in µm for the given measuring length L (L_m = L / 1000):

    ==========================  ===============================================  ===========
    contribution                implemented (µm)                                 thesis
    ==========================  ===============================================  ===========
    device                      u_cal · L_m                                      u(calib.)
    alignment (``"thesis"``)    (δ_mm / L_mm) / (2√3) · L_m                      (δ/L)/(2√3)
    alignment (``"cosine"``)    1000 · L_mm · (1 − cos atan(δ/L)) / (2√3)        --
    thermal drift               table 3.2, displacement column                   lookup
    temperature measurement     L_m · α · |ΔT| / (2√3)                           same
    expansion coefficient       L_m · u(α) · |T − 20|max / (2√3)                 same
    ==========================  ===============================================  ===========

    and, from the stated set-up (not in the thesis):

    ==========================  ===============================================
    air refraction, ``fixed``   L_mm · 10³ · |n(end) − n(start)| / (2√3): the air's change
                                over the test, n of Birch and Downs (1994), the start and
                                end air from the file's Air temp / press / humid lines
    air refraction, ``sensors`` L_mm · 10³ · √Σ (∂n/∂x · a_x / √3)², a_x the stated
                                accuracies of the air sensors, ∂n/∂x at the test's air
    Abbe                        offset_mm · angle_µm/m · 10⁻³ / √3: a beam offset from the
                                measuring line times the axis' largest pitch or yaw
    ==========================  ===============================================

    ``air_compensation = "included"`` (default) adds no refraction term: the laser's stated
    accuracy (``u_calibration_um_per_m``) includes its environmental compensation, as laser
    makers state it. U = k · sqrt(Σ u²). The two expansion terms are the thesis'
    u(workpiece expansion), kept apart in the budget. The thesis states the result "per
    metre" (Knapp's figures are for 1 m); the per-metre terms (device, alignment) are
    scaled by L_m here and the drift is an absolute displacement, so U is the µm of this
    measurement, valid along the axis. For L = 1 m both readings coincide.

    Parameters
    ----------
    measuring_length_mm : L, the measured length (span of the targets), > 0
    duration_min : test duration in minutes, for the table 3.2 lookup (from the file's
        ``Date Time``)
    temperature_change_degc : ΔT, change of the machine (material) temperature during the
        test, °C; the sign is ignored
    max_difference_to_20_degc : largest difference of the material temperature to 20 °C
        during the test, °C; the sign is ignored
    u_calibration_um_per_m : standard uncertainty of the laser's calibration (certificate,
        or the manufacturer's specification), µm/m; required, the thesis quotes no value
    alignment_mm : δ, the largest misalignment of the beam perpendicular to the axis, mm;
        required, the thesis quotes no value for 3.14.1 (1 mm is Knapp's figure for a square)
    expansion_coefficient_um_per_m_per_degc : α of the machine's scale (encoder) material,
        µm/(m·°C) (= ppm/°C; the file's ``Exp coeff``); required
    u_expansion_coefficient_um_per_m_per_degc : u(α), default 0.7 µm/(m·°C) (thesis 3.14.1,
        printed as "0.7°C"; only µm/(m·°C) makes the term a length)
    alignment_model : ``"thesis"`` (default: the formula as printed, the ratio δ/L of two
        lengths in mm read as µm/m) or ``"cosine"`` (the cosine error of a beam inclined by
        δ over L, ≈ δ²/(2L); see ``docs/uncertainty.md``)
    thermal_rule : ``"step"`` (default) or ``"interpolate"``, see
        :func:`~esp.core.uncertainty.thermal.thermal_drift`
    k : coverage factor, default 2
    air_compensation : ``"included"`` (default), ``"fixed"`` (the compensation set once,
        at the start) or ``"sensors"`` (continuous, the sensors' accuracies stated)
    air_temperature_start_degc ... air_humidity_end_pct : the air at the start and the end
        of the test (°C, kPa, %; from the file's environment), for ``"fixed"``; humidity
        may be missing (taken as 50 % and unchanged)
    air_temperature_accuracy_degc, air_pressure_accuracy_kpa, air_humidity_accuracy_pct :
        the air sensors' stated accuracies ±, for ``"sensors"``
    abbe_offset_mm, abbe_angle_um_per_m : the beam's offset from the line along which the
        axis' positioning is stated, and the axis' largest pitch or yaw about the
        perpendicular (µm/m); both or neither

    Returns
    -------
    ComponentUncertainty
        Unit ``"um"``, model ``"laser_linear"``.

    Raises
    ------
    DataError
        A required value missing, a negative length or uncertainty, a zero measuring
        length, an unknown alignment model or thermal rule.

    References
    ----------
    Longstaff (2002), section 3.14.1, table 3.2, eq. 3.18, 3.19, 3.21.
    """
    model = "laser_linear"
    L = finite("measuring_length_mm", measuring_length_mm, "positive", where=model)
    one_of(model, "alignment_model", alignment_model, ALIGNMENT_MODELS)
    one_of(model, "thermal_rule", thermal_rule, ("step", "interpolate"))
    u_cal = need(
        model,
        "u_calibration_um_per_m",
        u_calibration_um_per_m,
        "standard uncertainty of the laser calibration, um/m",
    )
    delta = need(
        model,
        "alignment_mm",
        alignment_mm,
        "largest misalignment of the beam perpendicular to the axis, mm",
    )
    duration = need(model, "duration_min", duration_min, "test duration in minutes")
    d_t = abs(
        need(
            model,
            "temperature_change_degc",
            temperature_change_degc,
            "change of the material temperature during the test, degC",
            "any",
        )
    )
    d_20 = abs(
        need(
            model,
            "max_difference_to_20_degc",
            max_difference_to_20_degc,
            "largest difference of the material temperature to 20 degC",
            "any",
        )
    )
    alpha = need(
        model,
        "expansion_coefficient_um_per_m_per_degc",
        expansion_coefficient_um_per_m_per_degc,
        "expansion coefficient of the scale material, um/(m degC)",
    )
    u_alpha = need(
        model,
        "u_expansion_coefficient_um_per_m_per_degc",
        u_expansion_coefficient_um_per_m_per_degc,
        "uncertainty of the expansion coefficient, um/(m degC)",
    )
    L_m = L / 1000.0
    u_device = u_cal * L_m
    if alignment_model == "thesis":
        # (alignment / measuring length) / (2√3), the ratio of two mm values read as µm/m,
        # scaled to the measuring length like every per-metre term
        u_align = (delta / L) / TWO_ROOT_3 * L_m
    else:
        # cosine error L (1 − cos θ), tan θ = δ / L, in µm; 1 − cos θ = 2 sin²(θ/2)
        theta = math.atan2(delta, L)
        u_align = 1000.0 * L * 2.0 * math.sin(theta / 2.0) ** 2 / TWO_ROOT_3
    u_drift = thermal_drift(duration, "displacement", thermal_rule)
    u_temp = L_m * alpha * d_t / TWO_ROOT_3
    u_coef = L_m * u_alpha * d_20 / TWO_ROOT_3
    budget = [
        ("device", u_device, "um"),
        ("alignment", u_align, "um"),
        ("thermal drift (table 3.2)", u_drift, "um"),
        ("workpiece expansion: temperature measurement", u_temp, "um"),
        ("workpiece expansion: expansion coefficient", u_coef, "um"),
    ]
    one_of(model, "air_compensation", air_compensation, AIR_COMPENSATION)
    if air_compensation == "fixed":
        from esp.core.uncertainty.refraction import refractive_index

        start = (
            need(
                model, "air_temperature_start_degc", air_temperature_start_degc, "air, degC", "any"
            ),
            need(model, "air_pressure_start_kpa", air_pressure_start_kpa, "air pressure, kPa"),
            50.0 if air_humidity_start_pct is None else air_humidity_start_pct,
        )
        end = (
            need(model, "air_temperature_end_degc", air_temperature_end_degc, "air, degC", "any"),
            need(model, "air_pressure_end_kpa", air_pressure_end_kpa, "air pressure, kPa"),
            start[2] if air_humidity_end_pct is None else air_humidity_end_pct,
        )
        change = abs(refractive_index(*end) - refractive_index(*start))
        budget.append(("air refraction: change over the test", L * 1e3 * change / TWO_ROOT_3, "um"))
    elif air_compensation == "sensors":
        from esp.core.uncertainty.refraction import sensitivities

        accuracy = (
            need(model, "air_temperature_accuracy_degc", air_temperature_accuracy_degc, "degC"),
            need(model, "air_pressure_accuracy_kpa", air_pressure_accuracy_kpa, "kPa"),
            need(model, "air_humidity_accuracy_pct", air_humidity_accuracy_pct, "%"),
        )
        air = (
            _mean_or(air_temperature_start_degc, air_temperature_end_degc, 20.0),
            _mean_or(air_pressure_start_kpa, air_pressure_end_kpa, 101.325),
            _mean_or(air_humidity_start_pct, air_humidity_end_pct, 50.0),
        )
        slopes = sensitivities(*air)
        u_n = math.sqrt(
            sum((sl * a / math.sqrt(3.0)) ** 2 for sl, a in zip(slopes, accuracy, strict=True))
        )
        budget.append(("air refraction: sensors", L * 1e3 * u_n, "um"))
    if (abbe_offset_mm is None) != (abbe_angle_um_per_m is None):
        raise MissingParameter(
            model,
            "abbe_angle_um_per_m" if abbe_angle_um_per_m is None else "abbe_offset_mm",
            "the Abbe term needs both the offset (mm) and the largest angle (um/m)",
        )
    if abbe_offset_mm is not None and abbe_angle_um_per_m is not None:
        u_abbe = abs(abbe_offset_mm) * abs(abbe_angle_um_per_m) * 1e-3 / math.sqrt(3.0)
        budget.append(("Abbe: beam offset times angle", u_abbe, "um"))
    return ComponentUncertainty.from_budget(model, "um", budget, k)


def _mean_or(a: float | None, b: float | None, default: float) -> float:
    given = [x for x in (a, b) if x is not None]
    return sum(given) / len(given) if given else default


# -- 3.14.2 angular, differential precision levels --------------------------------------------


def level_differential(
    *,
    measuring_length_mm: float,
    max_angle_um_per_m: float,
    unit_uncertainty_um_per_m: float | None = None,
    footprint_length_mm: float | None = None,
    duration_min: float | None = None,
    run_std_um_per_m: float | None = None,
    runs: int | None = None,
    type_a_min_runs: int = TYPE_A_MIN_RUNS,
    thermal_rule: str = "interpolate",
    k: float = 2.0,
) -> ComponentUncertainty:
    """Angular error (pitch, roll) measured with two precision levels (thesis 3.14.2).

    ==============  ==========================================================  ==========
    contribution    implemented (µm/m)                                          thesis
    ==============  ==========================================================  ==========
    device          √2 · unit uncertainty                                       same
    alignment       0 (the thesis: negligible when the alignment is small)      same
    cross talk      |max angle| · L / footprint / (2√3)                         same
    thermal drift   s / √n if runs >= 5, else table 3.2 (angle column)          same
    ==============  ==========================================================  ==========

    U = k · sqrt(Σ u²), in µm/m.

    Parameters
    ----------
    measuring_length_mm : L, the measured axis stroke, > 0
    max_angle_um_per_m : the largest angle in the data, µm/m (sign ignored)
    unit_uncertainty_um_per_m : the manufacturer's uncertainty of one level, µm/m; required
    footprint_length_mm : the base length of the level, mm, > 0; required
    duration_min : test duration in minutes (table 3.2), needed unless Type A applies
    run_std_um_per_m : standard deviation s of the runs, µm/m, needed when Type A applies
    runs : number of runs per direction n (None: unknown, table 3.2 is used)
    type_a_min_runs : fewest runs for Type A, default 5 (thesis: "less than 5" -> lookup)
    thermal_rule : ``"step"`` (default) or ``"interpolate"``
    k : coverage factor, default 2

    Returns
    -------
    ComponentUncertainty
        Unit ``"um/m"``, model ``"level_differential"``.

    Notes
    -----
    The cross-talk term is printed with the stroke over the footprint, so it grows with the
    length of the axis: 300 µm/m over a 1 m stroke with a 150 mm base gives about
    577 µm/m. It is implemented as printed; see ``docs/uncertainty.md``.

    References
    ----------
    Longstaff (2002), section 3.14.2, table 3.2, eq. 3.17, 3.19, 3.21.
    """
    model = "level_differential"
    L = finite("measuring_length_mm", measuring_length_mm, "positive", where=model)
    max_angle = abs(finite("max_angle_um_per_m", max_angle_um_per_m, where=model))
    one_of(model, "thermal_rule", thermal_rule, ("step", "interpolate"))
    unit_u = need(
        model,
        "unit_uncertainty_um_per_m",
        unit_uncertainty_um_per_m,
        "the manufacturer's uncertainty of one level, um/m",
    )
    footprint = need(
        model,
        "footprint_length_mm",
        footprint_length_mm,
        "base length of the level, mm",
        "positive",
    )
    type_a_used, u_run, dof_run = _run_term(
        model,
        quantity="angle",
        unit="um/m",
        std_name="run_std_um_per_m",
        run_std=run_std_um_per_m,
        runs=runs,
        duration_min=duration_min,
        min_runs=type_a_min_runs,
        thermal_rule=thermal_rule,
    )
    u_device = math.sqrt(2.0) * unit_u
    u_cross = max_angle * L / footprint / TWO_ROOT_3
    return ComponentUncertainty.from_budget(
        model,
        "um/m",
        [
            ("device (two levels)", u_device, "um/m"),
            ("alignment (negligible)", 0.0, "um/m"),
            ("cross talk", u_cross, "um/m"),
            (_drift_name(type_a_used), u_run, "um/m", dof_run),
        ],
        k,
    )


def _drift_name(type_a_used: bool, what: str = "thermal drift") -> str:
    return f"{what} (Type A, s/sqrt(n))" if type_a_used else f"{what} (table 3.2)"


# -- 3.14.3 angular, laser interferometer with angular optics ---------------------------------


def laser_angular(
    *,
    measuring_length_mm: float,
    measurement_range_um_per_m: float,
    max_angle_um_per_m: float,
    beam_offset_mm: float | None = None,
    range_accuracy: float = 0.004,
    length_accuracy_um_per_m_per_m: float = 0.5,
    duration_min: float | None = None,
    run_std_um_per_m: float | None = None,
    runs: int | None = None,
    type_a_min_runs: int = TYPE_A_MIN_RUNS,
    thermal_rule: str = "interpolate",
    k: float = 2.0,
) -> ComponentUncertainty:
    """Angular error measured with a laser interferometer and angular optics (thesis 3.14.3).

    ==================  ==================================================  ===============
    contribution        implemented (µm/m)                                  thesis
    ==================  ==================================================  ===============
    device (×√2)        √2 · (R · 0.4 % + L_m · 0.5) / (2√3)                2·u²(device)
    alignment           0 (negligible when the alignment is small)          same
    cross talk          |max angle| · L / beam offset / (2√3)               same
    thermal drift       s / √n if runs >= 5, else table 3.2 (angle)         same
    ==================  ==================================================  ===============

    U = k · sqrt(2 u²(device) + u²(cross talk) + u²(drift)); the budget records the device
    line as √2 · u(device) so that U = k · sqrt(Σ u²) holds for it.

    The length accuracy is read as "0.5 µm/m per metre of travel" (the way interferometer
    angular accuracy is specified), so the term is L_m · 0.5 in µm/m; the printed
    "measurement length × 0.5 µm/m" would otherwise add a length to an angle.

    Parameters
    ----------
    measuring_length_mm : L, the measured axis stroke, > 0
    measurement_range_um_per_m : R, the range (max − min) of the angles in the data, µm/m
    max_angle_um_per_m : the largest angle in the data, µm/m (sign ignored)
    beam_offset_mm : distance between the two reflectors of the angular optics, mm, > 0;
        required (device specification)
    range_accuracy : fraction of the range, default 0.004 (0.4 %, quoted)
    length_accuracy_um_per_m_per_m : default 0.5 (quoted as 0.5 µm/m)
    duration_min, run_std_um_per_m, runs, type_a_min_runs, thermal_rule, k :
        as for :func:`level_differential`

    Returns
    -------
    ComponentUncertainty
        Unit ``"um/m"``, model ``"laser_angular"``.

    References
    ----------
    Longstaff (2002), section 3.14.3, table 3.2, eq. 3.17, 3.19, 3.21.
    """
    model = "laser_angular"
    L = finite("measuring_length_mm", measuring_length_mm, "positive", where=model)
    R = finite("measurement_range_um_per_m", measurement_range_um_per_m, "nonneg", where=model)
    max_angle = abs(finite("max_angle_um_per_m", max_angle_um_per_m, where=model))
    one_of(model, "thermal_rule", thermal_rule, ("step", "interpolate"))
    offset = need(
        model,
        "beam_offset_mm",
        beam_offset_mm,
        "distance between the reflectors of the angular optics, mm",
        "positive",
    )
    r_acc = finite("range_accuracy", range_accuracy, "nonneg", where=model)
    l_acc = finite(
        "length_accuracy_um_per_m_per_m", length_accuracy_um_per_m_per_m, "nonneg", where=model
    )
    type_a_used, u_run, dof_run = _run_term(
        model,
        quantity="angle",
        unit="um/m",
        std_name="run_std_um_per_m",
        run_std=run_std_um_per_m,
        runs=runs,
        duration_min=duration_min,
        min_runs=type_a_min_runs,
        thermal_rule=thermal_rule,
    )
    u_device = (R * r_acc + (L / 1000.0) * l_acc) / TWO_ROOT_3
    u_cross = max_angle * L / offset / TWO_ROOT_3
    return ComponentUncertainty.from_budget(
        model,
        "um/m",
        [
            ("device (x sqrt 2)", math.sqrt(2.0) * u_device, "um/m"),
            ("alignment (negligible)", 0.0, "um/m"),
            ("cross talk", u_cross, "um/m"),
            (_drift_name(type_a_used), u_run, "um/m", dof_run),
        ],
        k,
    )


# -- 3.14.4 angular, from two linear measurements ---------------------------------------------


def angular_from_linear(
    *,
    U_linear_um: float | None = None,
    displacement_mm: float | None = None,
    u_displacement_mm: float | None = None,
    max_angle_um_per_m: float = 0.0,
    k: float = 2.0,
) -> ComponentUncertainty:
    """Angular error derived from two parallel linear measurements (thesis 3.14.4, 3.08.1).

    The angle is θ = Δe / d, the difference of the two linear errors over the distance d
    between the two measuring lines. The thesis gives

        u(lin) = U(linear) · √2 / 2,
        u(θ)/θ = sqrt((u(lin)/Δe)² + (u(d)/d)²),   U = k · θ · (u(θ)/θ).

    Multiplying the relative form by θ = Δe/d removes the division by Δe (which is zero
    where the two runs agree), so the budget is, in µm/m:

    ===================  =====================================
    linear measurements  1000 · u(lin)_µm / d_mm
    displacement         |θ|max · u(d) / d
    ===================  =====================================

    Parameters
    ----------
    U_linear_um : expanded uncertainty (k = 2) of one linear measurement, µm (for example
        ``laser_linear(...).U``); required
    displacement_mm : d, the distance between the two measuring lines, mm, > 0; required
    u_displacement_mm : standard uncertainty of d, mm; required
    max_angle_um_per_m : the largest angle of the derived profile, µm/m (sign ignored);
        default 0 (then only the first line counts)
    k : coverage factor, default 2

    Returns
    -------
    ComponentUncertainty
        Unit ``"um/m"``, model ``"angular_from_linear"``.

    Notes
    -----
    U(linear) · √2 / 2 is the standard uncertainty of the difference of two independent
    linear measurements whose U was stated with k = 2 (√2 · U/2).

    References
    ----------
    Longstaff (2002), section 3.14.4 (after eq. 3.20), section 3.08.1.
    """
    model = "angular_from_linear"
    U_lin = need(
        model, "U_linear_um", U_linear_um, "expanded uncertainty of one linear measurement, um"
    )
    d = need(
        model,
        "displacement_mm",
        displacement_mm,
        "distance between the two linear measuring lines, mm",
        "positive",
    )
    u_d = need(
        model,
        "u_displacement_mm",
        u_displacement_mm,
        "uncertainty of the distance between the measuring lines, mm",
    )
    theta = abs(finite("max_angle_um_per_m", max_angle_um_per_m, where=model))
    u_lin = U_lin * math.sqrt(2.0) / 2.0
    return ComponentUncertainty.from_budget(
        model,
        "um/m",
        [
            ("linear measurements", 1000.0 * u_lin / d, "um/m"),
            ("displacement", theta * u_d / d, "um/m"),
        ],
        k,
    )


# -- 3.14.5 straightness, short-range laser optics ---------------------------------------------


def laser_straightness(
    *,
    measurement_range_um: float,
    u_optical_reference_um: float = 3.0,
    range_fraction: float = 0.01,
    max_alignment_angle_deg: float = 1.0,
    duration_min: float | None = None,
    air_disturbance_um: float = 1.0,
    reduced_influence: float = 0.1,
    magnifying_factor: float = 36.0,
    number_of_beams: int = 4,
    run_std_um: float | None = None,
    runs: int | None = None,
    type_a_min_runs: int = TYPE_A_MIN_RUNS,
    thermal_rule: str = "interpolate",
    k: float = 2.0,
) -> ComponentUncertainty:
    """Straightness measured with a laser interferometer and short-range optics (3.14.5).

    ===========================  ================================================  =======
    contribution                 implemented (µm)                                  thesis
    ===========================  ================================================  =======
    device                       (u_ref + 1 % · R) / (2√3)                         same
    alignment                    (R − cos(1°) · R) / (2√3)                         same
    thermal drift + air          runs < 5: (drift + air · 0.1 · 36 · 4) / (2√3)    same
                                 runs >= 5: s / √n
    ===========================  ================================================  =======

    U = k · sqrt(Σ u²), in µm, valid along the axis. R is the range of the straightness
    readings (max − min), in µm.

    Parameters
    ----------
    measurement_range_um : R, the range of the readings, µm, >= 0. Take it from the data
        as read, before the slope is removed: the device sees the set-up slope too.
    u_optical_reference_um : default 3.0 µm (quoted)
    range_fraction : default 0.01 (1 % of the range, quoted)
    max_alignment_angle_deg : default 1.0° (quoted)
    duration_min : test duration in minutes (table 3.2, displacement), needed unless
        Type A applies
    air_disturbance_um : default 1.0 µm (quoted)
    reduced_influence : default 0.1 (the beam is not the reference; quoted)
    magnifying_factor : default 36.0 (optical arrangement; quoted)
    number_of_beams : default 4 (two forward, two return; quoted)
    run_std_um : standard deviation s of the runs, µm, needed when Type A applies
    runs, type_a_min_runs, thermal_rule, k : as for :func:`level_differential`

    Returns
    -------
    ComponentUncertainty
        Unit ``"um"``, model ``"laser_straightness"``.

    Notes
    -----
    With the defaults and no drift the air term is 14.4 / (2√3) = 4.16 µm, the 4.2 µm of
    the thesis' table 3.1. The device term at R = 300 µm is 6 / (2√3) = 1.73 µm, where
    table 3.1 has 1.1 µm (a reference uncertainty of about 0.8 µm would give 1.1).

    References
    ----------
    Longstaff (2002), section 3.14.5, tables 3.1 and 3.2, eq. 3.17, 3.19, 3.21.
    """
    model = "laser_straightness"
    R = finite("measurement_range_um", measurement_range_um, "nonneg", where=model)
    one_of(model, "thermal_rule", thermal_rule, ("step", "interpolate"))
    u_ref = finite("u_optical_reference_um", u_optical_reference_um, "nonneg", where=model)
    frac = finite("range_fraction", range_fraction, "nonneg", where=model)
    angle = finite("max_alignment_angle_deg", max_alignment_angle_deg, "nonneg", where=model)
    air = finite("air_disturbance_um", air_disturbance_um, "nonneg", where=model)
    reduced = finite("reduced_influence", reduced_influence, "nonneg", where=model)
    magnify = finite("magnifying_factor", magnifying_factor, "nonneg", where=model)
    beams = count(model, "number_of_beams", number_of_beams)
    type_a_used, u_run, dof_run = _run_term(
        model,
        quantity="displacement",
        unit="um",
        std_name="run_std_um",
        run_std=run_std_um,
        runs=runs,
        duration_min=duration_min,
        min_runs=type_a_min_runs,
        thermal_rule=thermal_rule,
    )
    if not type_a_used:
        # u_run is the table 3.2 drift; the thesis adds the air term and takes the sum as
        # the full width of a rectangular distribution
        u_run = (u_run + air * reduced * magnify * beams) / TWO_ROOT_3
    name = _drift_name(type_a_used, "thermal drift + air disturbance")
    u_device = (u_ref + frac * R) / TWO_ROOT_3
    # R − cos(θ) R = R (1 − cos θ) = R · 2 sin²(θ/2)
    u_align = R * 2.0 * math.sin(math.radians(angle) / 2.0) ** 2 / TWO_ROOT_3
    return ComponentUncertainty.from_budget(
        model,
        "um",
        [
            ("device", u_device, "um"),
            ("alignment", u_align, "um"),
            (name, u_run, "um", dof_run),
        ],
        k,
    )


# -- 3.14.6 squareness, mechanical square -----------------------------------------------------


def square(
    *,
    measuring_length_mm: float,
    edge_a_um: float | None = None,
    edge_b_um: float | None = None,
    squareness_um_per_m: float | None = None,
    alignment_mm: float = 1.0,
    alignment_model: str = "thesis",
    k: float = 2.0,
) -> ComponentUncertainty:
    """Squareness measured against a mechanical square (thesis 3.14.6).

    The device term is a length over the measuring length L; it is divided by L_m to give
    the angle the squareness is stated in:

    ===========================  ====================================================
    contribution                 implemented (µm/m)
    ===========================  ====================================================
    device                       sqrt(A² + B² + (sq · L_m / (2√3))²) / L_m
    alignment (``"thesis"``)     (δ_mm / L_mm) / (2√3), the ratio read as µm/m
    alignment (``"cosine"``)     10⁶ · (1 − cos atan(δ/L)) / (2√3)
    ===========================  ====================================================

    The thesis prints u(device) = sqrt(A² + B² + (sq · L / (2√3))²) in µm and the
    alignment as (δ / L) / (2√3); U = k · sqrt(u²(device) + u²(alignment)).

    Parameters
    ----------
    measuring_length_mm : L, the length of the square's edge used, mm, > 0
    edge_a_um, edge_b_um : standard uncertainties of the straightness of the square's edges
        A and B (calibration certificate), µm; required
    squareness_um_per_m : squareness of the square (calibration certificate), µm/m, taken
        as the full width of a rectangular distribution; required (sign ignored)
    alignment_mm : δ, uncertainty of the alignment, default 1 mm (Knapp, quoted)
    alignment_model : ``"thesis"`` (default) or ``"cosine"``, as for :func:`laser_linear`
    k : coverage factor, default 2

    Returns
    -------
    ComponentUncertainty
        Unit ``"um/m"``, model ``"square"``.

    References
    ----------
    Longstaff (2002), section 3.14.6, eq. 3.19, 3.21.
    """
    model = "square"
    L = finite("measuring_length_mm", measuring_length_mm, "positive", where=model)
    one_of(model, "alignment_model", alignment_model, ALIGNMENT_MODELS)
    a = need(model, "edge_a_um", edge_a_um, "uncertainty of edge A of the square, um")
    b = need(model, "edge_b_um", edge_b_um, "uncertainty of edge B of the square, um")
    sq = abs(
        need(
            model,
            "squareness_um_per_m",
            squareness_um_per_m,
            "squareness of the square from its certificate, um/m",
            "any",
        )
    )
    delta = finite("alignment_mm", alignment_mm, "nonneg", where=model)
    L_m = L / 1000.0
    device_um = math.sqrt(a**2 + b**2 + (sq * L_m / TWO_ROOT_3) ** 2)
    u_device = device_um / L_m
    if alignment_model == "thesis":
        u_align = (delta / L) / TWO_ROOT_3
    else:
        theta = math.atan2(delta, L)
        u_align = 1e6 * 2.0 * math.sin(theta / 2.0) ** 2 / TWO_ROOT_3
    return ComponentUncertainty.from_budget(
        model,
        "um/m",
        [("device", u_device, "um/m"), ("alignment", u_align, "um/m")],
        k,
    )


# -- from a measured profile ------------------------------------------------------------------

#: model name -> (function, thesis section, profile kinds it accepts)
MODELS: dict[str, tuple[Callable[..., ComponentUncertainty], str, tuple[str, ...]]] = {
    "laser_linear": (laser_linear, "3.14.1", ("linear",)),
    "level_differential": (level_differential, "3.14.2", ("angular",)),
    "laser_angular": (laser_angular, "3.14.3", ("angular",)),
    "angular_from_linear": (angular_from_linear, "3.14.4", ("angular",)),
    "laser_straightness": (laser_straightness, "3.14.5", ("straightness",)),
    "square": (square, "3.14.6", ("straightness",)),
}

SCATTER_STATISTICS = ("max", "pooled")

#: the share of a component's variance (Σ u²) above which its cross-talk term is named in
#: a warning: the term as printed grows with the stroke over the beam offset or footprint
#: and can exceed the angle measured many times (``docs/uncertainty.md``)
CROSS_TALK_SHARE = 0.5

#: model -> (thesis section, the parameter that sets its cross-talk term, in words)
_CROSS_TALK = {
    "laser_angular": ("3.14.3", "beam_offset_mm", "beam offset"),
    "level_differential": ("3.14.2", "footprint_length_mm", "footprint length"),
}


def cross_talk_warning(
    component: str, budget: ComponentUncertainty, key: str, instrument: str | None = None
) -> str | None:
    """A warning when the cross-talk term makes most of an angular instrument model's U
    (more than :data:`CROSS_TALK_SHARE` of Σ u²), else None.

    The term is ``|θ|max · L / beam offset / (2√3)`` (3.14.3; footprint length for the
    levels, 3.14.2), implemented as the thesis prints it: over a 1 m stroke with a 50 mm
    beam offset it is 5.8 times the largest angle measured. The warning names the
    component, its U, the share, and the key that sets the term, so that a U that rules
    the volumetric uncertainty does not pass without a word.

    Parameters
    ----------
    component : the component's name (``X.angular.Y``)
    budget : its instrument model's budget
    key : the configuration table of the component (``uncertainty.components."X.angular.Y"``)
    instrument : the instrument as the configuration names it (``laser-angular``); default
        the model's name

    Examples
    --------
    >>> b = laser_angular(measuring_length_mm=1000.0, measurement_range_um_per_m=10.0,
    ...                   max_angle_um_per_m=15.0, beam_offset_mm=50.0, duration_min=30.0)
    >>> print(cross_talk_warning("X.angular.Y", b, 'uncertainty.components."X.angular.Y"'))
    ... # doctest: +ELLIPSIS
    X.angular.Y: the laser_angular model gives U = 173.5 µm/m (k = 2), 100 % of its ...
    """
    if budget.model not in _CROSS_TALK:
        return None
    section, parameter, words = _CROSS_TALK[budget.model]
    total = math.fsum(c.u**2 for c in budget.contributions)
    cross = next((c for c in budget.contributions if c.name == "cross talk"), None)
    if cross is None or total <= 0.0:
        return None
    share = cross.u**2 / total
    if share <= CROSS_TALK_SHARE:
        return None
    unit = "µm/m" if budget.unit == "um/m" else "µm"
    return (
        f"{component}: the {instrument or budget.model} model gives U = {budget.U:.1f} {unit} "
        f"(k = {budget.k:g}), {share * 100:.0f} % of its variance from the cross-talk term "
        f"|θ|max · L / {words} / (2√3) (Longstaff 2002, {section}, as printed; it grows with "
        f"the stroke over the {words}, see docs/uncertainty.md): check {key}.{parameter}, "
        f"or give the largest angle as {key}.max_angle_um_per_m, or give U directly"
    )


def instrument_warnings(spec: UncertaintySpec) -> tuple[str, ...]:
    """:func:`cross_talk_warning` for every component of an ``[uncertainty]`` table
    (:class:`esp.core.uncertainty.spec.UncertaintySpec`) whose U an instrument model made."""
    out = []
    for name, cu in spec.components.items():
        if cu.budget is None:
            continue
        table = cu.key.removesuffix(".instrument") or f'uncertainty.components."{name}"'
        warning = cross_talk_warning(str(name), cu.budget, table, cu.model)
        if warning is not None:
            out.append(warning)
    return tuple(out)


def run_scatter(profile: ErrorProfile, statistic: str = "max") -> tuple[float | None, int]:
    """The standard deviation of a profile's runs and the run count for eq. 3.17.

    Parameters
    ----------
    profile : the measured component
    statistic : ``"max"`` (default): the largest sample standard deviation (n − 1) of the
        runs at one target, over all targets and directions -- ISO 230-2's s_i at the worst
        position, since U is applied at every position of the axis. ``"pooled"``: the
        pooled standard deviation of every run about its direction's mean curve,
        sqrt(Σ (x − x̄)² / Σ (n_d − 1)) over all targets and directions.

    Returns
    -------
    (s, n) : tuple
        ``n`` is the smallest number of runs over the directions measured (ISO 230-2 asks
        for five runs in each direction); ``s`` is None when ``n`` < 2. The unit of ``s``
        is the profile's (µm or µm/m).

    References
    ----------
    Longstaff (2002), eq. 3.17 and section 3.13.2; ISO 230-2:2014, 2.19 (estimator of the
    unidirectional standard uncertainty of positioning at a position).
    """
    one_of("run_scatter", "statistic", statistic, SCATTER_STATISTICS)
    directions = profile.directions
    n = min(profile.run_count(d) for d in directions)
    if n < 2:
        return None, n
    if statistic == "max":
        s = max(float(np.max(np.std(profile.runs[d], axis=0, ddof=1))) for d in directions)
    else:
        ss = 0.0
        dof = 0
        for d in directions:
            r = profile.runs[d]
            ss += float(np.sum((r - r.mean(axis=0)) ** 2))
            dof += r.shape[1] * (r.shape[0] - 1)
        s = math.sqrt(ss / dof)
    return s, n


# environment of a Laser10 file: keys compared without case, spaces or punctuation


def from_profile(model: str, profile: ErrorProfile, **params: Any) -> ComponentUncertainty:
    """Run an instrument model with the quantities it needs taken from a measured profile.

    Taken from the profile, unless given in ``params`` (a value given always wins):

    =================================  ==========================================================
    measuring_length_mm                ``profile.span_mm`` (last target − first)
    measurement_range_um[_per_m]       max − min of the bidirectional mean curve
    max_angle_um_per_m                 max |bidirectional mean|
    runs                               fewest runs over the directions measured
    run_std_um[_per_m]                 :func:`run_scatter` with ``statistic`` (default
                                       ``"max"``; pass ``statistic="pooled"`` to pool)
    duration_min                       ``Date Time`` of ``profile.environment``
    temperature_change_degc            ``Mat temp`` lines (largest end − start)
    max_difference_to_20_degc          ``Mat temp`` lines (largest |T − 20|)
    expansion_coefficient_...          ``Exp coeff``
    =================================  ==========================================================

    Type A (eq. 3.17) is used by the models that allow it when ``runs`` >= 5, i.e. when
    every direction measured has at least five runs; s/√n is then taken with the largest s
    and the smallest n, which is conservative when the directions differ.

    Parameters
    ----------
    model : a key of :data:`MODELS`
    profile : the measured component, of a kind the model accepts (linear for
        ``laser_linear``; angular for the three angular models; straightness for
        ``laser_straightness`` and ``square``, the latter using only the span). Give a
        straightness profile as read, before slope removal.
    **params : any keyword parameter of the model, plus ``statistic``

    Raises
    ------
    DataError
        Unknown model or parameter, a profile of the wrong kind, or a value the model needs
        that neither ``params`` nor the profile gives (the message names the parameter and
        what the environment lacked).

    References
    ----------
    Longstaff (2002), sections 3.14.1-3.14.6 and 3.14.7 (the data file supplies the
    measurement-specific quantities).
    """
    if model not in MODELS:
        raise DataError(f"unknown uncertainty model {model!r}; expected one of {', '.join(MODELS)}")
    func, section, kinds = MODELS[model]
    where = f" ({profile.source})" if profile.source else ""
    if profile.kind not in kinds:
        raise DataError(
            f"{model} (thesis {section}) needs a {' or '.join(kinds)} profile, but "
            f"{profile.name}{where} is {profile.kind}"
        )
    params = dict(params)
    statistic = params.pop("statistic", "max")
    accepted = set(inspect.signature(func).parameters)
    unknown = sorted(set(params) - accepted)
    if unknown:
        raise DataError(
            f"{model}: unknown parameter(s) {', '.join(unknown)}; expected some of "
            f"{', '.join(sorted(accepted | {'statistic'}))}"
        )

    derived: dict[str, Any] = {}
    mean = profile.mean("mean")
    span = profile.span_mm
    if "measuring_length_mm" in accepted:
        derived["measuring_length_mm"] = span
    for name in ("measurement_range_um", "measurement_range_um_per_m"):
        if name in accepted:
            derived[name] = float(np.max(mean) - np.min(mean))
    if "max_angle_um_per_m" in accepted:
        derived["max_angle_um_per_m"] = float(np.max(np.abs(mean)))
    if "runs" in accepted:
        s, n = run_scatter(profile, statistic)
        derived["runs"] = n
        for name in ("run_std_um", "run_std_um_per_m"):
            if name in accepted and s is not None:
                derived[name] = s
    env_values, env_why = environment_quantities(profile.environment)
    for name, value in env_values.items():
        if name in accepted:
            derived[name] = value
    derived.update(params)
    if derived.get("measuring_length_mm", 1.0) == 0.0 and "measuring_length_mm" not in params:
        raise DataError(
            f"{model}: {profile.name}{where} has a zero measuring length (a single target); "
            "give measuring_length_mm"
        )
    try:
        return func(**derived)
    except MissingParameter as exc:
        if exc.name in env_why:
            raise DataError(
                f"{model}: {exc.name} is required ({exc.what}) and {profile.name}{where} does "
                f"not give it: {env_why[exc.name]}; give {exc.name}"
            ) from None
        raise
