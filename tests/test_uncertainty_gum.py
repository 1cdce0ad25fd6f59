"""The GUM's combination rules: Welch-Satterthwaite (G.4.1, eq. G.2b) and the coverage
factor from Student's t (table G.2), and the degrees of freedom of a component's budget."""

from __future__ import annotations

import math
from statistics import NormalDist

import pytest

from esp.core.environment import date_times, environment_quantities, numbers
from esp.core.errors import DataError
from esp.core.uncertainty import ComponentUncertainty, Contribution, coverage_factor
from esp.core.uncertainty.gum import student_t_two_sided, welch_satterthwaite

# JCGM 100:2008, table G.2: t_p(ν) for p = 68.27, 90, 95, 95.45, 99, 99.73 %
TABLE_G2 = {
    1: (1.84, 6.31, 12.71, 13.97, 63.66, 235.80),
    2: (1.32, 2.92, 4.30, 4.53, 9.92, 19.21),
    3: (1.20, 2.35, 3.18, 3.31, 5.84, 9.22),
    4: (1.14, 2.13, 2.78, 2.87, 4.60, 6.62),
    5: (1.11, 2.02, 2.57, 2.65, 4.03, 5.51),
    10: (1.05, 1.81, 2.23, 2.28, 3.17, 3.96),
    20: (1.03, 1.72, 2.09, 2.13, 2.85, 3.42),
    50: (1.01, 1.68, 2.01, 2.05, 2.68, 3.16),
    100: (1.005, 1.660, 1.984, 2.025, 2.626, 3.077),
    math.inf: (1.000, 1.645, 1.960, 2.000, 2.576, 3.000),
}
# 68.27, 95.45 and 99.73 % are the probabilities of ±1, 2 and 3 standard deviations
COVERAGES = tuple(
    2 * NormalDist().cdf(k) - 1 if k else p
    for k, p in ((1, 0), (0, 0.90), (0, 0.95), (2, 0), (0, 0.99), (3, 0))
)


@pytest.mark.parametrize("dof", list(TABLE_G2))
def test_coverage_factor_reproduces_gum_table_g2(dof):
    for p, printed in zip(COVERAGES, TABLE_G2[dof], strict=True):
        digits = 3 if dof in (100, math.inf) else 2
        assert round(coverage_factor(p, dof), digits) == pytest.approx(printed, abs=1e-9), p


def test_coverage_factor_truncates_fractional_degrees_of_freedom():
    # GUM G.4.1 note 1: ν_eff = 4.9 is taken as 4
    assert coverage_factor(0.95, 4.9) == coverage_factor(0.95, 4)
    # the quantile inverts the distribution function: to 1e-10 (scipy 1.10's quantile is
    # good to about 4e-11 in p, newer ones to rounding), far below the 3 digits k is quoted to
    assert student_t_two_sided(coverage_factor(0.95, 7), 7) == pytest.approx(0.95, abs=1e-10)


@pytest.mark.parametrize("t", [0.3, 1.0, 2.5, 12.7, 300.0])
def test_student_t_two_sided_closed_forms(t):
    # ν = 1 is the Cauchy distribution: P(|T| <= t) = (2/π) atan t; ν = 2 has
    # P(|T| <= t) = t / sqrt(2 + t²) (Abramowitz & Stegun 1964, 26.7.3, with θ = atan(t/√ν));
    # ν = ∞ is the normal distribution, 2Φ(t) - 1
    assert student_t_two_sided(t, 1) == pytest.approx(2 / math.pi * math.atan(t), rel=1e-12)
    assert student_t_two_sided(t, 2) == pytest.approx(t / math.sqrt(2 + t * t), rel=1e-12)
    normal = 2 * NormalDist().cdf(t) - 1
    assert student_t_two_sided(t, math.inf) == pytest.approx(normal, rel=1e-12)


@pytest.mark.parametrize("dof", [1, 2, 4, 10, 100])
def test_student_t_two_sided_matches_table_g2(dof):
    # the printed t_p(ν) are rounded to 2 (3) decimals: at them P(|T| <= t) lies within the
    # probability that the rounding half-step covers, checked here against 1e-3
    for p, printed in zip(COVERAGES, TABLE_G2[dof], strict=True):
        assert student_t_two_sided(printed, dof) == pytest.approx(p, abs=2e-3), (p, printed)
    assert student_t_two_sided(0.0, dof) == 0.0
    # it rises with t: a larger interval covers more
    assert student_t_two_sided(1.0, dof) < student_t_two_sided(1.1, dof)


def test_student_t_two_sided_refuses_non_positive_degrees_of_freedom():
    with pytest.raises(DataError, match="degrees of freedom"):
        student_t_two_sided(2.0, 0)


@pytest.mark.parametrize("p, dof", [(0.0, 4), (1.0, 4), (0.95, 0.5), (1.5, math.inf)])
def test_coverage_factor_refuses_what_has_no_meaning(p, dof):
    with pytest.raises(DataError):
        coverage_factor(p, dof)


def test_welch_satterthwaite_by_hand():
    # u = 2 (ν = ∞), 1.5 (ν = 4), 1 (ν = 9): u_c² = 7.25;
    # ν_eff = 7.25² / (1.5⁴/4 + 1/9) = 52.5625 / (1.265625 + 0.111111) = 38.18
    nu = welch_satterthwaite([(2.0, math.inf), (1.5, 4.0), (1.0, 9.0)])
    assert nu == pytest.approx(52.5625 / (1.265625 + 1 / 9))
    # one Type A part alone keeps its own degrees of freedom; all Type B: infinite
    assert welch_satterthwaite([(3.0, 5.0)]) == pytest.approx(5.0)
    assert welch_satterthwaite([(1.0, math.inf), (0.0, 2.0)]) == math.inf
    with pytest.raises(DataError):
        welch_satterthwaite([(1.0, 0.0)])


def test_welch_satterthwaite_accepts_one_degree_of_freedom_and_fewer() -> None:
    """GUM G.2b holds for any ν_i > 0 (a Type A part from two readings has ν = 1; a Type B
    part judged by G.4.2's relative uncertainty of u can have ν below 1): nothing between
    0 and 1 is refused. By hand: u = 1 (ν = 1/2) and u = 2 (ν = 1): u_c² = 1 + 4 = 5,
    ν_eff = 5² / (1⁴/0.5 + 2⁴/1) = 25 / 18."""
    assert welch_satterthwaite([(1.0, 1.0)]) == 1.0
    assert welch_satterthwaite([(1.0, 0.5), (2.0, 1.0)]) == pytest.approx(25.0 / 18.0, rel=1e-15)
    assert welch_satterthwaite([(1.0, 1e-3)]) == pytest.approx(1e-3, rel=1e-15)


def test_component_degrees_of_freedom_from_its_budget():
    c = ComponentUncertainty.from_budget(
        "test", "um", [("a", 3.0, "um"), ("b", 4.0, "um", 9)], k=2.0
    )
    # u_c = 5, ν = 5⁴ / (4⁴ / 9) = 625 · 9 / 256 = 21.97
    assert c.dof == pytest.approx(625 * 9 / 256)
    assert c.contributions[1] == Contribution("b", 4.0, "um", 9.0)
    assert c.contributions[1].type_a and not c.contributions[0].type_a
    assert c.as_dict()["contributions"][1]["dof"] == 9.0
    with pytest.raises(DataError, match="degrees of freedom"):
        ComponentUncertainty(2.0, 2.0, "um", "x", (("a", 1.0, "um", 0.5),))


# -- the environment readings of a file (esp.core.environment) ---------------------------


def test_environment_readings_by_hand():
    env = {
        "Date Time": ('"10:46 Dec 12 2016"', '"12:01 Dec 12 2016"'),
        "Mat temp 1": ("20.1", "20.4"),
        "Mat temp 2": ("19.0", "19.9"),
        "Mat temp 3": ("0", "0"),  # not fitted
        "Air temp": ("25.0", "30.0"),  # the laser's, not the machine's
        "Exp coeff": ("11.5", "11.7"),
    }
    values, why = environment_quantities(env)
    assert values == {
        "duration_min": 75.0,
        "temperature_change_degc": pytest.approx(0.9),  # sensor 2: 19.9 - 19.0
        "max_difference_to_20_degc": pytest.approx(1.0),  # sensor 2 at the start
        "expansion_coefficient_um_per_m_per_degc": 11.7,
        # the air, kept apart for the refraction term
        "air_temperature_start_degc": 25.0,
        "air_temperature_end_degc": 30.0,
    }
    assert set(why) == {
        "air_pressure_start_kpa",
        "air_pressure_end_kpa",
        "air_humidity_start_pct",
        "air_humidity_end_pct",
    }


def test_environment_says_what_is_missing():
    values, why = environment_quantities({"Mat temp 1": ("n/a",), "Exp coeff": ("-",)})
    assert values == {}
    assert why["duration_min"] == "no 'Date Time' line"
    assert "do not hold a start and an end" in why["temperature_change_degc"]
    assert "holds no number" in why["expansion_coefficient_um_per_m_per_degc"]


def test_environment_parsers():
    assert numbers(("1e3", "x", "-2.5", "inf")) == [1000.0, -2.5]
    stamps = date_times("2016-12-12T10:46 then 11:02:30 Dec 12 2016, Feb 30 2016 10:00")
    assert [s.isoformat() for s in stamps] == ["2016-12-12T10:46:00", "2016-12-12T11:02:30"]
