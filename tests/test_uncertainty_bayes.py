"""Prior information, Longstaff (2002) 3.13.1, eq. 3.22-3.24: hand values and limits."""

from __future__ import annotations

import math

import pytest

from esp.core.errors import DataError
from esp.core.uncertainty import bayes_gamma, bayes_update, expanded_change


def test_bayes_update_by_hand():
    # γ = u_pe / u_cm = 4/3, γ² = 16/9, 1 + γ² = 25/9
    # y = 10 · (16/9)/(25/9) + 4 · 1/(25/9) = 10 · 16/25 + 4 · 9/25 = 6.4 + 1.44 = 7.84
    # 1/u_c² = 1/9 + 1/16 = 25/144  ->  u_c = 12/5 = 2.4
    y, u_c = bayes_update(10.0, 3.0, 4.0, 4.0)
    assert y == pytest.approx(7.84, rel=1e-12)
    assert u_c == pytest.approx(2.4, rel=1e-12)


def test_expanded_change_by_hand():
    # U_m = 6, γ = 4/3: ΔU = 6 (1 − sqrt((16/9) / (25/9))) = 6 (1 − 4/5) = 1.2
    assert expanded_change(6.0, 4.0 / 3.0) == pytest.approx(1.2, rel=1e-12)
    assert bayes_gamma(4.0, 3.0) == pytest.approx(4.0 / 3.0)


def test_expanded_change_agrees_with_the_revised_standard_uncertainty():
    # U_m − ΔU must equal k · u_c of eq. 3.23 when U_m = k · u_cm
    k = 2.0
    for u_cm, u_pe in [(3.0, 4.0), (1.0, 0.1), (0.2, 5.0), (2.0, 2.0)]:
        _, u_c = bayes_update(0.0, u_cm, 0.0, u_pe)
        U_m = k * u_cm
        assert U_m - expanded_change(U_m, bayes_gamma(u_pe, u_cm)) == pytest.approx(k * u_c)


def test_broad_prior_leaves_the_measurement_unchanged():
    # u_pe >> u_cm: γ -> ∞, y -> y_m and u_c -> u_cm, ΔU -> 0
    y, u_c = bayes_update(10.0, 1.0, 4.0, 1e6)
    assert y == pytest.approx(10.0, abs=1e-9)
    assert u_c == pytest.approx(1.0, rel=1e-9)
    assert expanded_change(2.0, 1e6) == pytest.approx(0.0, abs=1e-9)
    assert expanded_change(2.0, 1e300) == 0.0  # finite, no overflow


def test_sharp_prior_takes_over():
    # u_pe << u_cm: γ -> 0, y -> y_pe and u_c -> u_pe, ΔU -> U_m
    y, u_c = bayes_update(10.0, 1.0, 4.0, 1e-6)
    assert y == pytest.approx(4.0, abs=1e-9)
    assert u_c == pytest.approx(1e-6, rel=1e-9)
    assert expanded_change(2.0, 1e-9) == pytest.approx(2.0, rel=1e-9)
    assert expanded_change(2.0, 0.0) == 2.0


def test_prior_never_increases_the_uncertainty():
    for u_cm in (0.1, 1.0, 10.0):
        for u_pe in (0.01, 1.0, 100.0):
            _, u_c = bayes_update(1.0, u_cm, 2.0, u_pe)
            assert u_c <= min(u_cm, u_pe)
            assert 0.0 <= expanded_change(2 * u_cm, u_pe / u_cm) <= 2 * u_cm


@pytest.mark.parametrize(
    ("call", "match"),
    [
        (lambda: bayes_update(1.0, 0.0, 1.0, 1.0), "u_cm must be > 0"),
        (lambda: bayes_update(1.0, 1.0, 1.0, -1.0), "u_pe must be > 0"),
        (lambda: bayes_update(float("nan"), 1.0, 1.0, 1.0), "y_m must be a finite number"),
        (lambda: bayes_update("a", 1.0, 1.0, 1.0), "y_m must be a number"),
        (lambda: expanded_change(-1.0, 1.0), "U_m must be >= 0"),
        (lambda: expanded_change(1.0, -0.5), "gamma must be >= 0"),
        (lambda: bayes_gamma(1.0, 0.0), "u_cm must be > 0"),
        (lambda: bayes_gamma(True, 1.0), "u_pe must be a number, got True"),
    ],
)
def test_bad_input_is_a_data_error(call, match):
    with pytest.raises(DataError, match=match):
        call()


def test_symmetry_of_the_update():
    # swapping measurement and prior gives the same weighted mean and u_c
    a = bayes_update(3.0, 0.5, 7.0, 1.5)
    b = bayes_update(7.0, 1.5, 3.0, 0.5)
    assert a[0] == pytest.approx(b[0]) and a[1] == pytest.approx(b[1])
    assert math.isclose(a[0], (3.0 / 0.25 + 7.0 / 2.25) / (1 / 0.25 + 1 / 2.25))
