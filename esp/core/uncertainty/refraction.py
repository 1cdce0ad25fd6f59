"""The refractive index of air for a laser interferometer's wavelength, and its change with
the air's temperature, pressure and humidity.

A laser interferometer counts wavelengths in air, λ_air = λ_vac / n; an error δn of the
index its compensation uses is a length error of δn per unit length (1e-6 = 1 µm/m). The
index is the updated Edlén equation of Birch and Downs (Metrologia 30 (1993) 155 and the
correction in Metrologia 31 (1994) 315), with the water-vapour term's temperature factor
292.75/(t + 273.15) of the NIST Engineering Metrology Toolbox's "modified Edlén" form, and
the saturation vapour pressure of water of IAPWS-IF97 (region 4, the saturation-pressure
equation):

    σ = 1/λ_vac (µm⁻¹)
    (n − 1)_s · 10⁸ = 8342.54 + 2 406 147 / (130 − σ²) + 15 998 / (38.9 − σ²)
    (n − 1)_tp = p (n − 1)_s / 96 095.43 · (1 + 10⁻⁸ (0.601 − 0.00972 t) p) / (1 + 0.003661 t)
    n = 1 + (n − 1)_tp − 10⁻¹⁰ · 292.75 / (t + 273.15) · (3.7345 − 0.0401 σ²) · p_v

with t in °C, p and the water-vapour partial pressure p_v = RH/100 · p_sat(t) in Pa.

Standard library only.
"""

from __future__ import annotations

import math

__all__ = ["HE_NE_NM", "refractive_index", "saturation_pressure_pa", "sensitivities"]

#: the vacuum wavelength of a helium-neon laser, nm
HE_NE_NM = 632.990577

# IAPWS-IF97, the saturation-pressure equation (region 4): n1 .. n10
_N = (
    0.11670521452767e4,
    -0.72421316703206e6,
    -0.17073846940092e2,
    0.12020824702470e5,
    -0.32325550322333e7,
    0.14915108613530e2,
    -0.48232657361591e4,
    0.40511340542057e6,
    -0.23855557567849,
    0.65017534844798e3,
)


def saturation_pressure_pa(t_degc: float) -> float:
    """The saturation vapour pressure of water at ``t_degc`` (Pa), IAPWS-IF97 eq. 30.

    >>> round(saturation_pressure_pa(20.0))
    2339
    """
    n = _N
    T = t_degc + 273.15
    theta = T + n[8] / (T - n[9])
    a = theta * theta + n[0] * theta + n[1]
    b = n[2] * theta * theta + n[3] * theta + n[4]
    c = n[5] * theta * theta + n[6] * theta + n[7]
    return 1e6 * (2.0 * c / (-b + math.sqrt(b * b - 4.0 * a * c))) ** 4


def refractive_index(
    t_degc: float, p_kpa: float, rh_pct: float, wavelength_nm: float = HE_NE_NM
) -> float:
    """n of air at ``t_degc``, ``p_kpa`` and relative humidity ``rh_pct`` for the vacuum
    wavelength ``wavelength_nm`` (module docstring).

    >>> round((refractive_index(20.0, 101.325, 50.0) - 1.0) * 1e6, 2)
    271.37
    """
    sigma2 = (1000.0 / wavelength_nm) ** 2
    ns = (8342.54 + 2406147.0 / (130.0 - sigma2) + 15998.0 / (38.9 - sigma2)) * 1e-8
    p = p_kpa * 1000.0
    x = (1.0 + 1e-8 * (0.601 - 0.00972 * t_degc) * p) / (1.0 + 0.003661 * t_degc)
    ntp = p * ns * x / 96095.43
    pv = rh_pct / 100.0 * saturation_pressure_pa(t_degc)
    water = 1e-10 * 292.75 / (t_degc + 273.15) * (3.7345 - 0.0401 * sigma2) * pv
    return 1.0 + ntp - water


def sensitivities(
    t_degc: float = 20.0, p_kpa: float = 101.325, rh_pct: float = 50.0
) -> tuple[float, float, float]:
    """∂n/∂t (per °C), ∂n/∂p (per kPa) and ∂n/∂RH (per %) at the given air, by central
    differences of :func:`refractive_index`.

    >>> [round(s * 1e6, 4) for s in sensitivities()]
    [-0.9547, 2.6836, -0.0085]
    """
    h_t, h_p, h_rh = 0.01, 0.01, 0.1
    dt = (
        refractive_index(t_degc + h_t, p_kpa, rh_pct)
        - refractive_index(t_degc - h_t, p_kpa, rh_pct)
    ) / (2 * h_t)
    dp = (
        refractive_index(t_degc, p_kpa + h_p, rh_pct)
        - refractive_index(t_degc, p_kpa - h_p, rh_pct)
    ) / (2 * h_p)
    drh = (
        refractive_index(t_degc, p_kpa, rh_pct + h_rh)
        - refractive_index(t_degc, p_kpa, rh_pct - h_rh)
    ) / (2 * h_rh)
    return dt, dp, drh
