"""Uncertainty of the tool's errors: summation, statistical (GUM 5.1.2) and Monte Carlo
(GUM Supplement 1)."""

from __future__ import annotations

import numpy as np
import pytest

from esp.parallel.geometry import symmetric_geometry
from esp.parallel.kinematics import inverse
from esp.parallel.sources import SOURCE_NAMES
from esp.parallel.transmission import transmit
from esp.parallel.uncertainty import UncertaintySpec, propagate

PAPER = symmetric_geometry(400.0, 200.0, 300.0, 1000.0)
N = len(SOURCE_NAMES)


@pytest.fixture(scope="module")
def trans():
    return transmit(PAPER, inverse(PAPER, 300.0, 15.0, 10.0), (0.0, 0.0))


def _U(**named) -> np.ndarray:
    U = np.zeros(N)
    for name, value in named.items():
        U[SOURCE_NAMES.index(name.replace("__", "."))] = value
    return U


def test_two_sources_by_hand(trans):
    """U(e_x) = k √((s₁ U₁/k)² + (s₂ U₂/k)²); summation, a bound, |s₁| U₁ + |s₂| U₂."""
    U = _U(leg1__strut=4.0, leg2__slider__Z=3.0)
    s = trans.sensitivity[0]
    s1, s2 = s[0, SOURCE_NAMES.index("leg1.strut")], s[0, SOURCE_NAMES.index("leg2.slider.Z")]
    res = propagate(UncertaintySpec(U, k=2.0), trans, np.zeros(N))
    assert res.statistical[0] == pytest.approx(np.hypot(s1 * 4.0, s2 * 3.0))
    assert res.summation[0] == pytest.approx(abs(s1) * 4.0 + abs(s2) * 3.0)
    # no choice of signs of the two sources exceeds it, and one reaches it
    signed = [a * s1 * 4.0 + b * s2 * 3.0 for a in (-1, 1) for b in (-1, 1)]
    assert max(abs(v) for v in signed) == pytest.approx(res.summation[0])
    assert res.position_um == pytest.approx(np.linalg.norm(res.statistical[:3]))
    shares = {b.source: b.share_position_pct for b in res.budget}
    assert sum(shares.values()) == pytest.approx(100.0)
    assert list(shares) == sorted(shares, key=lambda n: -shares[n])


def test_summation_shares_add_up(trans):
    U = _U(leg1__strut=4.0, leg2__strut=4.0, table__X=2.0)
    res = propagate(UncertaintySpec(U, method="summation"), trans, np.zeros(N))
    assert sum(b.share_position_pct for b in res.budget) == pytest.approx(100.0)
    assert all(b.share_position_pct >= 0.0 for b in res.budget)
    assert res.position_um == pytest.approx(np.linalg.norm(res.summation[:3]))


def test_zero_uncertainty_gives_zero(trans):
    res = propagate(UncertaintySpec(np.zeros(N)), trans, np.zeros(N))
    assert not np.any(res.statistical) and not np.any(res.summation) and res.budget == ()


def test_statistical_scales_linearly(trans):
    U = _U(leg1__strut=4.0, leg3__axis__tilt=20.0, leg2__ball__y=5.0)
    a = propagate(UncertaintySpec(U), trans, np.zeros(N))
    b = propagate(UncertaintySpec(3 * U), trans, np.zeros(N))
    np.testing.assert_allclose(b.statistical, 3 * a.statistical)


@pytest.mark.slow
@pytest.mark.parametrize("distribution", ["normal", "rectangular"])
def test_montecarlo_matches_the_statistical_method(trans, distribution):
    """The Monte Carlo standard deviation times k equals the statistical U (the model is
    linear to a part in 10⁶ here); its mean is the error of the values."""
    U = _U(leg1__strut=4.0, leg2__slider__Z=3.0, leg3__ball__z=5.0, leg1__axis__tilt=20.0)
    values = _U(leg1__strut=60.0, leg2__strut=60.0, leg3__strut=60.0)
    spec = UncertaintySpec(
        U, method="montecarlo", samples=4000, seed=7, distributions=(distribution,) * N
    )
    res = propagate(spec, trans, values, PAPER)
    mc = res.montecarlo
    assert mc.model == "exact" and mc.samples == 4000
    np.testing.assert_allclose(2 * mc.std, res.statistical, rtol=0.06)
    expected = trans.sensitivity[0] @ values
    np.testing.assert_allclose(mc.mean, expected, atol=4 * mc.std.max() / np.sqrt(4000))
    assert mc.low[2] < expected[2] < mc.high[2]
    again = propagate(spec, trans, values, PAPER).montecarlo
    assert np.array_equal(again.mean, mc.mean)  # the seed fixes the draws


def test_montecarlo_linear_and_exact_agree(trans):
    U = _U(leg1__strut=4.0, leg2__slider__Z=3.0)
    exact = propagate(
        UncertaintySpec(U, method="montecarlo", samples=500, seed=3), trans, np.zeros(N), PAPER
    )
    linear = propagate(
        UncertaintySpec(U, method="montecarlo", samples=500, seed=3, montecarlo_model="linear"),
        trans,
        np.zeros(N),
    )
    np.testing.assert_allclose(exact.montecarlo.std, linear.montecarlo.std, rtol=1e-4, atol=1e-9)
