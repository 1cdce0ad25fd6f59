"""The refractive index of air (Birch and Downs 1994, NIST water term, IAPWS-IF97), the air
readings of a Laser10 environment, and the refraction and Abbe terms of laser_linear."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from esp.core.environment import environment_quantities
from esp.core.errors import DataError
from esp.core.uncertainty.instruments import from_profile, laser_linear
from esp.core.uncertainty.refraction import (
    HE_NE_NM,
    refractive_index,
    saturation_pressure_pa,
    sensitivities,
)
from esp.io.load import load_profile

RTL = Path(__file__).resolve().parents[1] / "data" / "examples" / "gantry" / "X-linear.rtl"


def test_saturation_pressure_matches_the_iapws_verification_values():
    # IAPWS-IF97, table 35: T = 300 K -> 0.353658941e-2 MPa; 500 K -> 0.263889776e1 MPa
    assert saturation_pressure_pa(300.0 - 273.15) == pytest.approx(3536.58941, rel=1e-8)
    assert saturation_pressure_pa(500.0 - 273.15) == pytest.approx(2.63889776e6, rel=1e-8)


def test_standard_air_is_the_dispersion_formula_by_hand():
    """Dry air at 15 °C and 96 095.43 Pa·(1 + 0.003661·15)/(1 + 10⁻⁸(0.601 − 0.00972·15)p)
    is the reference air of the formula: n − 1 = (8342.54 + 2406147/(130 − σ²)
    + 15998/(38.9 − σ²))·10⁻⁸, σ = 1/0.632990577 µm⁻¹. At p = 101 325 Pa the pressure factor
    is p(1 + 10⁻⁸·0.4552·p)/(96095.43·1.054915)."""
    s2 = (1.0 / 0.632990577) ** 2
    ns = (8342.54 + 2406147.0 / (130.0 - s2) + 15998.0 / (38.9 - s2)) * 1e-8
    p = 101325.0
    factor = p * (1.0 + 1e-8 * (0.601 - 0.00972 * 15.0) * p) / (96095.43 * (1.0 + 0.003661 * 15.0))
    assert refractive_index(15.0, 101.325, 0.0, HE_NE_NM) - 1.0 == pytest.approx(
        ns * factor, rel=1e-12
    )


def test_the_nist_shop_floor_formula_agrees():
    """An independent reference: the shop-floor formula of the NIST Engineering Metrology
    Toolbox (Stone and Zimmerman, "Index of refraction of air", appendix B),
    n = 1 + 7.86e-4·p/(273 + t) − 1.5e-11·RH·(t² + 160), p in kPa, good to about 1e-7
    in a workshop's air. The implementation here agrees to 6e-8 over 15–30 °C,
    90–105 kPa and 0–75 % RH."""
    for t in np.linspace(15.0, 30.0, 7):
        for p in np.linspace(90.0, 105.0, 7):
            for rh in (0.0, 25.0, 50.0, 75.0):
                shop = 7.86e-4 * p / (273.0 + t) - 1.5e-11 * rh * (t * t + 160.0)
                assert refractive_index(t, p, rh) - 1.0 == pytest.approx(shop, abs=6e-8)


def test_sensitivities_are_the_known_rules_of_thumb():
    """About −1 ppm per °C, +0.27 ppm per hPa and −0.0085 ppm per % RH near 20 °C."""
    dt, dp, drh = sensitivities()
    assert dt * 1e6 == pytest.approx(-0.955, abs=0.01)
    assert dp * 1e6 == pytest.approx(2.68, abs=0.02)  # per kPa
    assert drh * 1e6 == pytest.approx(-0.0085, abs=0.0005)
    # linear in the pressure to 0.1 %: (n − 1)/p
    assert dp == pytest.approx((refractive_index(20.0, 101.325, 50.0) - 1.0) / 101.325, rel=3e-3)


def test_air_readings_of_the_gantry_file():
    values, _ = environment_quantities(load_profile(RTL).environment)
    assert values["air_temperature_start_degc"] == 20.18
    assert values["air_temperature_end_degc"] == 20.27
    assert values["air_pressure_start_kpa"] == 101.09
    assert values["air_humidity_end_pct"] == 43.9


def test_air_pressure_in_hpa_and_absurd_readings():
    values, why = environment_quantities(
        {"Air press": ("1010.9", "1010.8"), "Air temp": ("95", "96")}
    )
    assert values["air_pressure_start_kpa"] == pytest.approx(101.09)
    assert "air_temperature_start_degc" not in values
    assert "not an air reading" in why["air_temperature_start_degc"]


BASE = dict(
    measuring_length_mm=1000.0,
    duration_min=31.0,
    temperature_change_degc=0.1,
    max_difference_to_20_degc=0.09,
    u_calibration_um_per_m=0.29,
    alignment_mm=0.5,
    expansion_coefficient_um_per_m_per_degc=11.5,
)


def _term(c, name):
    return next(x.u for x in c.contributions if x.name == name)


def test_fixed_compensation_takes_the_airs_change_over_the_test():
    air = dict(
        air_temperature_start_degc=20.18,
        air_temperature_end_degc=20.27,
        air_pressure_start_kpa=101.09,
        air_pressure_end_kpa=101.08,
        air_humidity_start_pct=44.6,
        air_humidity_end_pct=43.9,
    )
    c = laser_linear(**BASE, air_compensation="fixed", **air)
    dn = refractive_index(20.27, 101.08, 43.9) - refractive_index(20.18, 101.09, 44.6)
    expected = 1000.0 * 1e3 * abs(dn) / (2.0 * math.sqrt(3.0))
    assert _term(c, "air refraction: change over the test") == pytest.approx(expected)
    assert expected == pytest.approx(0.0306, abs=0.001)
    # the air from the file, as every other environment quantity
    from_file = from_profile(
        "laser_linear",
        load_profile(RTL),
        u_calibration_um_per_m=0.29,
        alignment_mm=0.5,
        air_compensation="fixed",
    )
    assert _term(from_file, "air refraction: change over the test") == pytest.approx(expected)


def test_sensor_accuracies_and_abbe():
    c = laser_linear(
        **BASE,
        air_compensation="sensors",
        air_temperature_accuracy_degc=0.2,
        air_pressure_accuracy_kpa=0.1,
        air_humidity_accuracy_pct=6.0,
        abbe_offset_mm=20.0,
        abbe_angle_um_per_m=8.0,
    )
    dt, dp, drh = sensitivities(20.0, 101.325, 50.0)
    u_n = math.sqrt(
        sum((s * a / math.sqrt(3.0)) ** 2 for s, a in ((dt, 0.2), (dp, 0.1), (drh, 6.0)))
    )
    assert _term(c, "air refraction: sensors") == pytest.approx(1e6 * u_n)
    assert _term(c, "Abbe: beam offset times angle") == pytest.approx(
        20 * 8 * 1e-3 / math.sqrt(3.0)
    )
    # "included" adds nothing
    assert len(laser_linear(**BASE).contributions) == 5


def test_missing_inputs_are_named():
    with pytest.raises(DataError, match="air_pressure_accuracy_kpa"):
        laser_linear(**BASE, air_compensation="sensors", air_temperature_accuracy_degc=0.2)
    with pytest.raises(DataError, match="abbe_angle_um_per_m"):
        laser_linear(**BASE, abbe_offset_mm=10.0)
    with pytest.raises(DataError, match="air_compensation"):
        laser_linear(**BASE, air_compensation="guess")
