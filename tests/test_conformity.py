"""Decisions against tolerances (esp.core.conformity) on worked cases: a value inside,
outside and within the guard band, for each rule, with the risks written out by hand."""

from __future__ import annotations

import math

import pytest

from esp.core.conformity import (
    CONFORMS,
    DOES_NOT_CONFORM,
    NOT_DECIDED,
    DecisionRule,
    decide,
    exit_code,
)
from esp.core.errors import ConfigError

T_UM = 30.0
U_UM = 2.0  # k = 2, so u = 1 µm


def phi(z: float) -> float:
    # the standard normal distribution function, written out independently of the module
    return 0.5 * (1.0 + math.erf(z / math.sqrt(2.0)))


@pytest.mark.parametrize(
    ("value_um", "verdict"),
    [
        (26.0, CONFORMS),
        (28.0, CONFORMS),
        (28.5, NOT_DECIDED),
        (30.0, NOT_DECIDED),
        (32.0, NOT_DECIDED),
        (32.01, DOES_NOT_CONFORM),
        (40.0, DOES_NOT_CONFORM),
    ],
)
def test_guarded_with_w_equal_u(value_um: float, verdict: str) -> None:
    # ISO 14253-1: conformance zone up to T - U = 28, non-conformance beyond T + U = 32
    d = decide("volumetric", value_um, T_UM, DecisionRule("guarded"), expanded=U_UM)
    assert d.verdict == verdict
    assert d.guard_band == pytest.approx(2.0)
    assert d.probability_conforming == pytest.approx(phi((T_UM - value_um) / 1.0))


@pytest.mark.parametrize(
    ("value_um", "verdict"),
    [
        (28.9, CONFORMS),
        (29.0, CONFORMS),
        (29.5, NOT_DECIDED),
        (31.0, NOT_DECIDED),
        (31.2, DOES_NOT_CONFORM),
    ],
)
def test_guarded_with_half_u(value_um: float, verdict: str) -> None:
    d = decide("planar XY", value_um, T_UM, DecisionRule("guarded", 0.5), expanded=U_UM)
    assert d.verdict == verdict
    assert d.guard_band == pytest.approx(1.0)


@pytest.mark.parametrize(
    ("value_um", "verdict"),
    [(20.0, CONFORMS), (30.0, CONFORMS), (30.001, DOES_NOT_CONFORM), (45.0, DOES_NOT_CONFORM)],
)
def test_simple_acceptance(value_um: float, verdict: str) -> None:
    d = decide("volumetric", value_um, T_UM, DecisionRule("simple"), expanded=U_UM)
    assert d.verdict == verdict
    assert d.guard_band == 0.0


def test_simple_acceptance_at_the_limit_risks_half() -> None:
    # at y = T the true value exceeds T with probability 1/2 (ILAC-G8 4.2.1)
    d = decide("volumetric", T_UM, T_UM, DecisionRule("simple"), expanded=U_UM)
    assert d.verdict == CONFORMS
    assert d.risk == pytest.approx(0.5)
    assert d.risk_text() == "probability of false acceptance 50.0 %"


def test_risks_by_verdict_worked() -> None:
    # y = 27.5: p_c = Φ(2.5) = 0.993790; false acceptance 0.621 %
    d = decide("volumetric", 27.5, T_UM, DecisionRule("guarded"), expanded=U_UM)
    assert d.risk == pytest.approx(1.0 - 0.9937903, abs=1e-6)
    # y = 33: p_c = Φ(-3) = 0.0013499: the risk of a false rejection
    d = decide("volumetric", 33.0, T_UM, DecisionRule("guarded"), expanded=U_UM)
    assert d.verdict == DOES_NOT_CONFORM
    assert d.risk == pytest.approx(0.0013499, abs=1e-6)
    assert "false rejection" in d.risk_text()
    # k other than 2 changes u: U = 3, k = 3 gives u = 1 as well
    d3 = decide("volumetric", 27.5, T_UM, DecisionRule("simple"), expanded=3.0, k=3.0)
    assert d3.probability_conforming == pytest.approx(phi(2.5))


def test_guarded_without_u_is_refused_not_simple() -> None:
    rule = DecisionRule("guarded", key="tolerance.rule")
    for missing in (None, 0.0, math.nan):
        with pytest.raises(ConfigError, match="tolerance.rule: guarded acceptance needs"):
            decide("volumetric", 10.0, T_UM, rule, expanded=missing)
    # the way out is named as the rule was given: in the table, or on the command line
    with pytest.raises(ConfigError, match='use rule = "simple"'):
        decide("volumetric", 10.0, T_UM, rule)
    with pytest.raises(ConfigError, match=r"^--rule: .*use --rule simple\)$"):
        decide("volumetric", 10.0, T_UM, DecisionRule("guarded", key="--rule"))


def test_simple_without_u_states_no_risk() -> None:
    d = decide("volumetric", 10.0, T_UM, DecisionRule("simple"))
    assert d.verdict == CONFORMS
    assert d.risk is None and d.expanded is None
    assert d.risk_text() == "probability of false acceptance not known (no U)"
    assert d.as_dict()["k"] is None


def test_bad_rules_and_tolerances_are_refused() -> None:
    with pytest.raises(ConfigError, match="expected one of simple, guarded"):
        DecisionRule("strict")  # type: ignore[arg-type]
    for fraction in (0.0, -1.0, math.inf, 4.0):
        with pytest.raises(ConfigError, match="guard band fraction"):
            DecisionRule("guarded", fraction)
    with pytest.raises(ConfigError, match="must be positive"):
        decide("volumetric", 1.0, 0.0, DecisionRule())
    with pytest.raises(ConfigError, match="must be finite"):
        decide("volumetric", math.nan, 1.0, DecisionRule())


def test_exit_codes() -> None:
    r = DecisionRule("guarded")
    ok = decide("a", 1.0, 5.0, r, expanded=1.0)
    undecided = decide("b", 5.5, 5.0, r, expanded=1.0)
    bad = decide("c", 9.0, 5.0, r, expanded=1.0)
    assert exit_code([]) == 0
    assert exit_code([ok]) == 0
    assert exit_code([ok, undecided]) == 3
    assert exit_code([undecided, bad, ok]) == 1


def test_dict_and_text() -> None:
    d = decide("volumetric", 26.0, T_UM, DecisionRule("guarded"), expanded=U_UM, unit="µm")
    doc = d.as_dict()
    assert doc["acceptance_limit"] == pytest.approx(28.0)
    assert doc["rejection_limit"] == pytest.approx(32.0)
    assert doc["verdict"] == "conforms"
    assert doc["decision_rule"]["rule"] == "guarded"
    assert d.text("26.0 µm").startswith("volumetric 26.0 µm against 30 µm: conforms (guarded")
