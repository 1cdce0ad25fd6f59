"""What an ISO 230-2 test report states besides the figures: the test conditions, the
measurement uncertainty of each figure, and the decisions against tolerances
(docs/iso230-2.md, "Test conditions, uncertainty and verdicts").

**Test conditions** (ISO 230-2:2014, clause 7, the items a test report gives): from the
file -- the date and time of the start and end, the air temperature, pressure and humidity
and the material temperatures at the start and end, the expansion coefficient the
instrument normalised to 20 °C with, the runs and targets -- and from the user: feed, dwell,
instrument, the position of the measuring line, machine, operator.

**Uncertainty** (the contributors of ISO 230-2:2014, Annex A, and ISO/TR 230-9:2005, with
the instrument model of Longstaff (2002), 3.14.1, :func:`esp.core.uncertainty.instruments.
laser_linear`): the uncertainty u_L of a displacement measured by the laser over the
travel L combines

* the laser system's stated accuracy ±a (µm/m, with its environmental compensation),
  rectangular: a/√3 per metre (u_DEVICE);
* the beam's misalignment δ over L: the cosine error L(1 − cos atan(δ/L)), rectangular
  over its full width, /(2√3) (u_MISALIGNMENT);
* the environmental variation error EVE of a drift test when one is given, EVE/(2√3)
  (ISO 230-2:2014, Annex A), else the drift of table 3.2 of the thesis for the test's
  duration, interpolated (u_EVE);
* the machine temperature's change during the test, L·α·|ΔT|/(2√3), and the expansion
  coefficient's uncertainty, L·u(α)·|T − 20|max/(2√3) (u_M,MACHINE, u_E,MACHINE), the
  temperatures from the file;
* the material sensor's stated accuracy ±a_θ, L·α·a_θ/√3;
* with the laser's compensation fixed at the start (``air_compensation = "fixed"``), the
  air's change over the test from the file, L·|Δn|/(2√3) (Birch and Downs 1994); by default
  the laser's stated accuracy includes its compensation.

Then, with k = 2: U(A), U(E), U(M) = k·u_L (each is a span of deviations over the travel:
every term that grows with the length enters); U(B) = k·√(u_EVE² + u_s²), u_s the standard
deviation of the mean reversal at the target of the largest |B_i| (√(s↑²/n↑ + s↓²/n↓)): the
length terms cancel in a difference at one target; U(R) = k·u_EVE, the drift that inflates
the runs' scatter. The sampling variability of s itself (about 35 % of s for 5 runs) is
part of the statistic as ISO 230-2 defines it, not of U. Where an input is missing the
uncertainty is not evaluated, and the missing inputs are named.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from esp.core.conformity import Decision, DecisionRule, decide
from esp.core.conformity import parse_tolerances as parse_limits
from esp.core.environment import (
    absent_sensors,
    environment_quantities,
    is_material_temperature,
    numbers,
)
from esp.core.errors import ConfigError
from esp.core.profile import ErrorProfile
from esp.core.uncertainty.instruments import laser_linear
from esp.iso230.positioning import AXIS_KEYS, Iso230Result

__all__ = [
    "FigureUncertainty",
    "Iso230Uncertainty",
    "K",
    "LaserSetup",
    "decisions",
    "figure_budgets",
    "parse_tolerances",
    "conditions_of",
    "conditions_of_given",
    "uncertainty",
]

#: the coverage factor of every U stated here
K = 2.0
#: the thesis' u(α), µm/(m·°C) (Longstaff 2002, 3.14.1)
U_ALPHA_DEFAULT = 0.7
#: the figures by the group of contributors their U takes
_LENGTH = ("A", "A_up", "A_down", "E", "E_up", "E_down", "M")
_REVERSAL = ("B", "B_mean")
_REPEATABILITY = ("R", "R_up", "R_down")


@dataclass(frozen=True)
class LaserSetup:
    """What the user states of the measurement: the laser system's accuracy ± (µm/m),
    the beam's largest misalignment over the travel (mm), the material sensor's accuracy ±
    (°C), u(α) (µm/(m·°C)), and the environmental variation error EVE (µm) when a drift
    test measured it (ISO 230-2:2014, Annex A: u_EVE = EVE/(2√3)); without it, table 3.2
    of the thesis for the test's duration."""

    accuracy_um_per_m: float | None = None
    misalignment_mm: float | None = None
    material_sensor_degc: float | None = None
    u_alpha_um_per_m_per_degc: float = U_ALPHA_DEFAULT
    eve_um: float | None = None
    air_compensation: str = "included"


@dataclass(frozen=True)
class FigureUncertainty:
    """U (k = 2, µm) of one figure and its budget: (contributor, standard u in µm)."""

    figure: str
    expanded_um: float
    budget: tuple[tuple[str, float], ...]

    def as_dict(self) -> dict[str, Any]:
        return {
            "U_um": self.expanded_um,
            "k": K,
            "budget": [{"contributor": n, "u_um": u} for n, u in self.budget],
        }


@dataclass(frozen=True)
class Iso230Uncertainty:
    """The U of every figure, or None with the inputs that are missing."""

    figures: Mapping[str, FigureUncertainty] = field(default_factory=dict)
    missing: tuple[str, ...] = ()
    length_mm: float = 0.0

    def get(self, key: str) -> float | None:
        f = self.figures.get(key)
        return None if f is None else f.expanded_um

    def as_dict(self) -> dict[str, Any]:
        if self.missing:
            return {"evaluated": False, "missing": list(self.missing)}
        return {
            "evaluated": True,
            "k": K,
            "length_mm": self.length_mm,
            "figures": {k: v.as_dict() for k, v in self.figures.items()},
        }


def conditions_of(profile: ErrorProfile, given: Mapping[str, str | None]) -> list[tuple[str, str]]:
    """The test conditions as (label, text) pairs, the file's first, then ``given``
    (feed, dwell, instrument, measuring line, machine, operator; None left out)."""
    env = profile.environment
    out: list[tuple[str, str]] = []
    when = env.get("Date Time")
    found, _ = environment_quantities(env)
    if when:
        text = " to ".join(str(w) for w in when[:2])
        if "duration_min" in found:
            text += f" ({found['duration_min']:g} min)"
        out.append(("Date and time", text))
    # the air as esp.core.environment reads it (kPa, a reading esp does not understand
    # left out), the one reading of the file's environment
    for label, stem, unit in (
        ("Air temperature", "air_temperature", ("degc", "°C")),
        ("Air pressure", "air_pressure", ("kpa", "kPa")),
        ("Air humidity", "air_humidity", ("pct", "%")),
    ):
        start, end = found.get(f"{stem}_start_{unit[0]}"), found.get(f"{stem}_end_{unit[0]}")
        if start is not None and end is not None:
            out.append((label, f"{start:g} {unit[1]} at the start, {end:g} {unit[1]} at the end"))
    absent = set(absent_sensors(env))
    for key, value in env.items():
        if is_material_temperature(key) and key not in absent:
            vals = numbers(value)
            if len(vals) >= 2 and not (vals[0] == 0.0 and vals[1] == 0.0):
                out.append(
                    (
                        f"Material temperature ({key})",
                        f"{vals[0]:g} °C at the start, {vals[1]:g} °C at the end",
                    )
                )
    if "expansion_coefficient_um_per_m_per_degc" in found:
        a = found["expansion_coefficient_um_per_m_per_degc"]
        out.append(
            (
                "Expansion compensation",
                f"deviations normalised to 20 °C with an expansion coefficient of {a:g} µm/(m·°C)"
                if a
                else "none (α = 0)",
            )
        )
    out.extend(conditions_of_given(given))
    return out


def conditions_of_given(given: Mapping[str, str | None]) -> list[tuple[str, str]]:
    """The test conditions the user gives (feed, dwell, instrument, measuring line,
    machine, operator), as (label, text) pairs; None left out."""
    out: list[tuple[str, str]] = []
    labels = {
        "feed": "Feed",
        "dwell": "Dwell at each target",
        "instrument": "Instrument",
        "measuring_line": "Measuring line",
        "machine": "Machine",
        "operator": "Operator",
    }
    for key, label in labels.items():
        stated = given.get(key)
        if stated:
            out.append((label, str(stated)))
    return out


def uncertainty(
    result: Iso230Result, profile: ErrorProfile, setup: LaserSetup
) -> Iso230Uncertainty:
    """The U of every figure of ``result`` (module docstring), or what is missing."""
    found, _ = environment_quantities(profile.environment)
    missing = []
    if setup.accuracy_um_per_m is None:
        missing.append("the laser's accuracy (--laser-accuracy)")
    if setup.misalignment_mm is None:
        missing.append("the beam's misalignment (--misalignment)")
    for key, what in (
        ("duration_min", "the test's duration (the file's Date Time)"),
        ("temperature_change_degc", "the material temperature (the file's Mat temp)"),
        ("expansion_coefficient_um_per_m_per_degc", "the expansion coefficient (Exp coeff)"),
    ):
        if key not in found:
            missing.append(what)
    if missing:
        return Iso230Uncertainty(missing=tuple(missing))
    assert setup.accuracy_um_per_m is not None and setup.misalignment_mm is not None
    length = float(result.targets_mm[-1] - result.targets_mm[0])
    alpha = float(found["expansion_coefficient_um_per_m_per_degc"])
    comp = laser_linear(
        measuring_length_mm=length,
        duration_min=found["duration_min"],
        temperature_change_degc=found["temperature_change_degc"],
        max_difference_to_20_degc=found["max_difference_to_20_degc"],
        u_calibration_um_per_m=setup.accuracy_um_per_m / math.sqrt(3.0),
        alignment_mm=setup.misalignment_mm,
        expansion_coefficient_um_per_m_per_degc=alpha,
        u_expansion_coefficient_um_per_m_per_degc=setup.u_alpha_um_per_m_per_degc,
        alignment_model="cosine",
        thermal_rule="interpolate",
        air_compensation=setup.air_compensation,
        **{k: v for k, v in found.items() if k.startswith("air_")},
    )
    names = {
        "device": "laser accuracy (u_DEVICE)",
        "alignment": "misalignment, cosine error (u_MISALIGNMENT)",
        "thermal drift (table 3.2)": "environmental variation over the test (u_EVE)",
        "workpiece expansion: temperature measurement": "machine temperature change (u_M,MACHINE)",
        "workpiece expansion: expansion coefficient": "expansion coefficient (u_E,MACHINE)",
        "air refraction: change over the test": "air's change over the test, compensation "
        "fixed at the start",
    }
    length_budget = [(names.get(c.name, c.name), float(c.u)) for c in comp.contributions]
    if setup.material_sensor_degc:
        length_budget.append(
            (
                "material temperature sensor",
                length / 1000.0 * alpha * setup.material_sensor_degc / math.sqrt(3.0),
            )
        )
    eve_name = names["thermal drift (table 3.2)"]
    if setup.eve_um is not None:
        eve_name = "environmental variation error, measured (u_EVE)"
        length_budget = [
            (eve_name, setup.eve_um / (2.0 * math.sqrt(3.0))) if "u_EVE" in n else (n, u)
            for n, u in length_budget
        ]
    eve = next(u for n, u in length_budget if "u_EVE" in n)
    figures = figure_budgets(result, length_budget, (eve_name, eve))
    return Iso230Uncertainty(figures, (), length)


def _reversal_spread(result: Iso230Result, key: str) -> tuple[str, float]:
    """The type A term of B (the spread of the mean reversal at the largest |B_i|, √(s↑²/n↑
    + s↓²/n↓)) or of B̄ (the mean of those squares over the m targets, divided by m)."""
    assert result.B_i is not None and result.s_up is not None and result.s_down is not None
    per = np.sqrt(result.s_up**2 / result.runs["up"] + result.s_down**2 / result.runs["down"])
    if key == "B":
        return "mean reversal at the largest |B_i| (type A)", float(
            per[int(np.argmax(np.abs(result.B_i)))]
        )
    return "mean of the reversals (type A)", float(np.sqrt(np.mean(per**2) / per.size))


def figure_budgets(
    result: Iso230Result,
    span_budget: Sequence[tuple[str, float]],
    eve: tuple[str, float],
) -> dict[str, FigureUncertainty]:
    """Each figure's U (k = 2) from its budget: A, E and M take ``span_budget`` (the
    instrument's terms over the travel), B and B̄ the environmental variation ``eve`` and
    the spread of the mean reversal, R the environmental variation alone (module
    docstring); shared by the linear and the rotary axis."""
    figures: dict[str, FigureUncertainty] = {}
    for key in result.axis_values():
        if key in _LENGTH:
            budget = list(span_budget)
        elif key in _REVERSAL:
            budget = [eve, _reversal_spread(result, key)]
        else:
            budget = [eve]
        u = math.sqrt(sum(x * x for _, x in budget))
        figures[key] = FigureUncertainty(key, K * u, tuple(budget))
    return figures


def parse_tolerances(given: Iterable[str], option: str = "--tolerance") -> dict[str, float]:
    """``["A=20", "R=6"]`` as ``{"A": 20.0, "R": 6.0}`` (µm, arcsec for a rotary axis), keys
    of ISO 230-2's axis figures (:func:`esp.core.conformity.parse_tolerances`)."""
    return parse_limits(given, AXIS_KEYS, option, unit="µm (arcsec for a rotary axis)")


def decisions(
    result: Iso230Result,
    tolerances: Mapping[str, float],
    rule: DecisionRule,
    u: Iso230Uncertainty,
) -> list[Decision]:
    """Each figure with a tolerance decided under ``rule`` (B_mean by its size)."""
    values = result.axis_values()
    out = []
    for key, limit in tolerances.items():
        if key not in values:
            raise ConfigError("--tolerance", f"{key} needs a direction this file does not hold")
        expanded = u.get(key)
        if rule.kind == "guarded" and expanded is None:
            raise ConfigError(
                rule.key,
                f"guarded acceptance needs the U of {key}, which is not evaluated: missing "
                + ("; ".join(u.missing) or "U")
                + "; or use --rule simple",
            )
        out.append(
            decide(
                key, abs(values[key]), limit, rule, expanded=expanded, k=K, unit=result.value_label
            )
        )
    return out
