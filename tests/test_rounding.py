"""Figures rounded to what their uncertainty supports (GUM 7.2.6; EA-4/02 5.3)."""

from __future__ import annotations

import math

import pytest

from esp.core.rounding import coverage_text, decimals, rounded, stated


@pytest.mark.parametrize(
    ("value", "expanded", "expected"),
    [
        (33.937, 2.137, ("33.9", "2.1")),  # the headline
        (33.937, 0.0456, ("33.937", "0.046")),
        (22.921, 0.35, ("22.92", "0.35")),
        (0.125, 0.011, ("0.125", "0.011")),
        (0.125, 0.11, ("0.13", "0.11")),  # half away from zero on the decimal form
        (-0.04, 0.51, ("-0.04", "0.51")),
        (-0.004, 0.51, ("0.00", "0.51")),  # no "-0.00"
        (1234.5, 870.0, ("1230", "870")),
        (5.0, 9.96, ("5", "10")),  # U rounds up a decade: two digits, no decimals
        (5.0, 1.049, ("5.0", "1.0")),  # nearest loses 4.7 %: kept
    ],
)
def test_rounded(value: float, expanded: float, expected: tuple[str, str]) -> None:
    assert rounded(value, expanded) == expected


def test_decimals() -> None:
    assert [decimals(u) for u in (2.1, 0.021, 21.0, 210.0)] == [1, 3, 0, -1]


@pytest.mark.parametrize("bad", [0.0, -1.0, math.nan, math.inf])
def test_no_uncertainty_no_rounding(bad: float) -> None:
    with pytest.raises(ValueError, match="positive and finite"):
        rounded(1.0, bad)


def test_stated_and_coverage() -> None:
    assert stated(33.937, 2.137, "µm") == "33.9 µm, U = 2.1 µm (k = 2, about 95 %)"
    assert stated(12.3456, 0.4, "µm/m", k=2.37, probability=0.95) == (
        "12.35 µm/m, U = 0.40 µm/m (k = 2.37, about 95 %)"
    )
    assert coverage_text(1.0) == "k = 1"
