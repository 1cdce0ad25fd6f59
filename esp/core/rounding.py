"""Figures stated with their uncertainty, rounded to what the uncertainty supports.

A stated result gives its expanded uncertainty U to two significant digits and the value to
the same decimal place (JCGM 100:2008, the GUM, 7.2.6; EA-4/02 M:2022, 5.3). Rounding to two
digits follows the usual rules, except that U is rounded up when rounding to nearest would
lower it by more than 5 % (EA-4/02 M:2022, 5.3) -- with two significant digits that happens
only just above 10·10ⁿ, so in practice U is rounded to nearest. Values are rounded half away
from zero on their shortest decimal form, so that 0.125 reads 0.13 and not, through its
binary neighbour, 0.12.

Only what people read is rounded (headlines, text summaries, PDF pages); JSON and CSV keep
full precision. A figure with no uncertainty keeps the fixed number of decimals its
command uses.

>>> stated(33.937, 2.137, "µm")
'33.9 µm, U = 2.1 µm (k = 2, about 95 %)'
>>> rounded(0.1234, 0.0456)
('0.123', '0.046')
>>> rounded(1234.5, 87.0)
('1235', '87')
>>> rounded(1234.5, 870.0)
('1230', '870')

Standard library only.
"""

from __future__ import annotations

import math
from decimal import ROUND_CEILING, ROUND_HALF_UP, Decimal

__all__ = [
    "SIGNIFICANT_DIGITS",
    "coverage_text",
    "decimals",
    "rounded",
    "stated",
    "uncertainty_text",
]

#: significant digits of a stated uncertainty (GUM 7.2.6: "at most two")
SIGNIFICANT_DIGITS = 2


def _usable(expanded: float | None) -> bool:
    return expanded is not None and math.isfinite(expanded) and expanded > 0.0


def _round_uncertainty(expanded: float) -> Decimal:
    """U to two significant digits: to nearest, or up when nearest loses more than 5 %."""
    exact = Decimal(repr(float(expanded)))
    quantum = Decimal(1).scaleb(exact.adjusted() - SIGNIFICANT_DIGITS + 1)
    result = exact.quantize(quantum, rounding=ROUND_HALF_UP)
    if result < exact * Decimal("0.95"):
        result = exact.quantize(quantum, rounding=ROUND_CEILING)
    # 9.96 rounds to 10.0: still two significant digits, so one place fewer
    return result.quantize(Decimal(1).scaleb(result.adjusted() - SIGNIFICANT_DIGITS + 1))


def decimals(expanded: float) -> int:
    """Decimal places of a figure stated with expanded uncertainty ``expanded`` (negative:
    rounded to tens, hundreds ...).

    >>> decimals(2.137), decimals(0.0456), decimals(87.0), decimals(870.0), decimals(9.96)
    (1, 3, 0, -1, 0)
    """
    if not _usable(expanded):
        raise ValueError(f"an expanded uncertainty must be positive and finite, not {expanded!r}")
    return -_round_uncertainty(expanded).as_tuple().exponent  # type: ignore[operator]


def _text(value: Decimal, places: int) -> str:
    quantum = Decimal(1).scaleb(-places)
    text = f"{value.quantize(quantum, rounding=ROUND_HALF_UP):f}"
    if places < 0:  # quantize to tens keeps the exponent: write the digits out
        text = f"{int(value.quantize(quantum, rounding=ROUND_HALF_UP)):d}"
    return "0" + text[2:] if text.startswith("-0") and not text.strip("-0.") else text


def rounded(value: float, expanded: float) -> tuple[str, str]:
    """``(value, U)`` as texts: U to two significant digits, the value to the same decimal
    place (GUM 7.2.6).

    >>> rounded(22.921, 0.0)
    Traceback (most recent call last):
    ...
    ValueError: an expanded uncertainty must be positive and finite, not 0.0
    """
    places = decimals(expanded)
    u_text = _text(_round_uncertainty(expanded), places)
    return _text(Decimal(repr(float(value))), places), u_text


def coverage_text(k: float, probability: float | None = None) -> str:
    """``"k = 2, about 95 %"``: the coverage factor and, when known, the coverage
    probability (for k = 2 of a normal distribution, about 95 %, GUM 6.3.3).

    >>> coverage_text(2.0), coverage_text(2.52, 0.95), coverage_text(3.0)
    ('k = 2, about 95 %', 'k = 2.52, about 95 %', 'k = 3')
    """
    k_text = f"{k:.2f}".rstrip("0").rstrip(".")
    if probability is None and abs(k - 2.0) < 1e-12:
        probability = 0.95
    if probability is None:
        return f"k = {k_text}"
    return f"k = {k_text}, about {100.0 * probability:.0f} %"


def uncertainty_text(
    value: float,
    expanded: float,
    unit: str,
    k: float = 2.0,
    probability: float | None = None,
) -> str:
    """``"U = 2.1 µm (k = 2, about 95 %)"`` for a figure stated elsewhere."""
    _, u_text = rounded(value, expanded)
    return f"U = {u_text} {unit} ({coverage_text(k, probability)})"


def stated(
    value: float,
    expanded: float,
    unit: str,
    k: float = 2.0,
    probability: float | None = None,
) -> str:
    """A figure as a lab states it: ``"33.9 µm, U = 2.1 µm (k = 2, about 95 %)"``."""
    v_text, u_text = rounded(value, expanded)
    return f"{v_text} {unit}, U = {u_text} {unit} ({coverage_text(k, probability)})"
