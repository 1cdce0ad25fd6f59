"""The uncertainty of the ISO 230-4 figures from the ballbar's stated specification, and
their decisions against tolerances (:mod:`esp.core.conformity`).

Assumptions (docs/ballbar.md, "Uncertainty and verdicts"): one reading's transducer error
has the standard uncertainty u_t = √((a/√3)² + (r/√12)²) from the stated accuracy ±a
(rectangular) and resolution r (rectangular over one step), independent from reading to
reading; G, G(b) and H are each the difference of two readings of one test, in which the
error of the bar's calibrated length cancels: U = k √2 u_t. F is one reading against the
nominal radius, so the bar's length calibration enters: U = k √(u_t² + (U_cal/2)²). k = 2.
The machine's own scatter (its repeatability) is part of what is measured, not of U; the
bar's thermal expansion is taken as compensated by its software. Where the specification
needed is not stated, U is not evaluated, and a guarded decision is refused.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping

from esp.ballbar.analysis import CircleTest
from esp.ballbar.conditions import Conditions
from esp.core.conformity import Decision, DecisionRule, decide
from esp.core.conformity import parse_tolerances as parse_limits
from esp.core.errors import ConfigError

__all__ = ["FIGURES", "K", "decisions", "expanded_uncertainty", "parse_tolerances"]

#: the coverage factor of the stated U
K = 2.0
#: the figures a tolerance may be given for: key -> what it is
FIGURES = {
    "F": "radial deviation F (largest |F|)",
    "G": "circular deviation G (each direction)",
    "Gb": "bidirectional circular deviation G(b)",
    "H": "circular hysteresis H",
}


def _u_transducer(c: Conditions) -> float | None:
    if c.accuracy_um is None and c.resolution_um is None:
        return None
    a = c.accuracy_um or 0.0
    r = c.resolution_um or 0.0
    return math.hypot(a / math.sqrt(3.0), r / math.sqrt(12.0))


def expanded_uncertainty(figure: str, conditions: Conditions) -> float | None:
    """U (k = 2, µm) of ``figure`` (a key of :data:`FIGURES`), or None where the
    specification it needs is not stated (module docstring)."""
    u_t = _u_transducer(conditions)
    if u_t is None or u_t <= 0.0:
        return None
    if figure == "F":
        if conditions.calibration_U_um is None:
            return None
        return K * math.hypot(u_t, conditions.calibration_U_um / 2.0)
    return K * math.sqrt(2.0) * u_t


def parse_tolerances(given: Iterable[str], option: str = "--tolerance") -> dict[str, float]:
    """``["G=15", "H=5"]`` as ``{"G": 15.0, "H": 5.0}`` (µm), keys of :data:`FIGURES`
    (:func:`esp.core.conformity.parse_tolerances`)."""
    return parse_limits(given, FIGURES, option)


def decisions(
    tests: list[CircleTest], tolerances: Mapping[str, float], rule: DecisionRule
) -> list[Decision]:
    """Every figure with a tolerance, of every circle, decided under ``rule``."""
    out = []
    for t in tests:
        for key, limit in tolerances.items():
            U = expanded_uncertainty(key, t.conditions)
            values: list[tuple[str, float]] = []
            if key == "F":
                values = [("F", t.F_um)]
            elif key == "G":
                values = [(f"G {d.direction}", d.G_um) for d in t.directions]
            elif t.G_bidirectional_um is None or t.H_um is None:
                raise ConfigError(
                    "--tolerance",
                    f"{key} needs both directions; circle {t.name!r} of {t.file} has one",
                )
            elif key == "Gb":
                values = [("G(b)", t.G_bidirectional_um)]
            else:
                values = [("H", t.H_um)]
            if rule.kind == "guarded" and U is None:
                need = "its calibration U and " if key == "F" else ""
                raise ConfigError(
                    rule.key,
                    f"guarded acceptance needs the U of {key}, which is not evaluated for "
                    f"circle {t.name!r}: state the ballbar's {need}accuracy or resolution "
                    "(header lines '# calibration_U:', '# accuracy:', '# resolution:', or "
                    "the options --calibration-u, --accuracy, --resolution), or use --rule "
                    "simple",
                )
            for name, value in values:
                out.append(decide(f"{t.name}: {name}", value, limit, rule, expanded=U, k=K))
    return out
