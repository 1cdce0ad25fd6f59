"""One check for every number that enters esp: from a TOML file, a CSV or JSON file, or a
command-line option.

A number is accepted when it is a number (not a bool, not text), representable as a float
(TOML allows whole numbers of any length: ``step = 1`` followed by 400 zeros is refused here,
not left to overflow later), finite, and within the documented range of its quantity
(:data:`QUANTITIES`; the table is in ``docs/reliability.md``). A refusal names what was
expected and shows the value **as given**: the text of an option, the shortest decimal that
reads back as the float of a file (``10000.0001``, not ``10000``), the digits of an integer.

The symbols of a kinematic chain have a range by kind and dimension
(:data:`SYMBOL_LIMITS`): an error is a small deviation (at most 10 mm or 0.1 rad), a
parameter a length of a machine (at most 100 m) or a nominal angle (at most one turn).

This module imports only the standard library.
"""

from __future__ import annotations

import math
import numbers
import re
import sys
from dataclasses import dataclass
from typing import Any

from esp.core.errors import ConfigError, DataError

__all__ = [
    "FLOAT_MAX",
    "Given",
    "QUANTITIES",
    "SYMBOL_LIMITS",
    "Quantity",
    "ValueRefused",
    "check",
    "check_symbol",
    "config_number",
    "parse",
    "quantity_of_key",
    "shown",
    "symbol_limit",
    "written",
]

#: the largest finite float
FLOAT_MAX = sys.float_info.max

#: a decimal number as esp reads it from text: digits, an optional point and exponent; no
#: underscores (``1_000``), no hexadecimal, no words (the files refuse ``3_0`` alike)
_DECIMAL = re.compile(r"^[+-]?(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[eE][+-]?[0-9]+)?$")
_NON_FINITE = re.compile(r"^[+-]?(?:inf|infinity|nan)$", re.IGNORECASE)


def _g(x: float) -> str:
    """A limit as a message shows it (``100000``, ``0.1``, ``1e+09``)."""
    return f"{x:g}"


@dataclass(frozen=True)
class Quantity:
    """The range of a kind of number: ``low`` to ``high`` in ``unit``, ``low`` itself
    excluded when ``above_low``."""

    what: str
    unit: str
    low: float
    high: float
    above_low: bool = False

    def range_text(self) -> str:
        u = f" {self.unit}" if self.unit else ""
        if self.low == -self.high:
            return f"within ±{_g(self.high)}{u}"
        if self.above_low:
            return f"above {_g(self.low)} and at most {_g(self.high)}{u}"
        if self.low > 0:
            return f"of at least {_g(self.low)}{u} and at most {_g(self.high)}{u}"
        return f"from {_g(self.low)} to {_g(self.high)}{u}"

    def expected(self) -> str:
        return f"{self.what} {self.range_text()}"


#: every kind of number esp reads, with its range (docs/reliability.md)
QUANTITIES: dict[str, Quantity] = {
    "number": Quantity("a number", "", -FLOAT_MAX, FLOAT_MAX),
    # positions: targets, travels, offsets, datums, tool offsets, --at, --datum
    "position": Quantity("a position", "mm", -1e5, 1e5),
    # a key ending in _mm (esp.parallel): a length or a position of a machine
    "mm": Quantity("a length or position", "mm", -1e5, 1e5),
    # lengths of a machine: tool lengths, struts, radii, distances
    "length": Quantity("a length", "mm", 0.0, 1e5),
    "tool length": Quantity("a tool length", "mm", 0.0, 1e5),
    # a grid step or a target spacing: 1 µm to 100 m
    "step": Quantity("a step", "mm", 0.001, 1e5),
    # displacement errors (linear, straightness): µm
    "displacement": Quantity("a displacement error", "um", -1e4, 1e4),
    # angles (angular, mechanical, squareness): µm/m = µrad
    "angle": Quantity("an angle error", "um/m", -1e5, 1e5),
    # expanded uncertainties
    # expanded uncertainties: at most 1 mm, or 1 mm per metre (esp.config.uncertainty)
    "uncertainty": Quantity("an expanded uncertainty", "um", 0.0, 1e3),
    "uncertainty per metre": Quantity(
        "an expanded uncertainty per metre of length", "um/m", 0.0, 1e3
    ),
    # esp.config.uncertainty.K_MAX (t_99 % for one degree of freedom is 63.7)
    "coverage factor": Quantity("a coverage factor", "", 0.0, 100.0, above_low=True),
    # a nominal angle: tool tilt and spin, a pose
    "degrees": Quantity("an angle", "degrees", -360.0, 360.0),
    # pass/fail thresholds of esp batch
    "threshold": Quantity("a threshold", "um", 0.0, 1e7, above_low=True),
}

#: the range of a chain symbol by (kind, dimension), in mm or rad, and what it is called
SYMBOL_LIMITS: dict[tuple[str, str], tuple[float, str]] = {
    ("error", "length"): (10.0, "a length error"),
    ("error", "angle"): (0.1, "an angle error"),
    ("parameter", "length"): (1e5, "a length"),
    ("parameter", "angle"): (2.0 * math.pi, "a nominal angle"),
    ("coordinate", "length"): (1e5, "a position"),
    # a rotary axis may turn many times: 10⁶ degrees, as the coordinate grids allow
    ("coordinate", "angle"): (1e6 * math.pi / 180.0, "an angle"),
}


def symbol_limit(kind: str, dimension: str) -> tuple[float, str]:
    """(the largest magnitude in mm or rad, what it is) of a chain symbol of ``kind``
    (``"error"``, ``"parameter"``, ``"coordinate"``) and ``dimension`` (``"length"``,
    ``"angle"``)."""
    return SYMBOL_LIMITS[(kind, dimension)]


def check_symbol(kind: str, unit: str, value: Any, given: str | None = None) -> float:
    """``value``, in ``unit``, when it lies within the range of a chain symbol of ``kind``
    (:data:`SYMBOL_LIMITS`: an error at most 10 mm or 0.1 rad, a parameter at most 100 m
    or one turn); the limit is shown in ``unit`` and in mm or rad, and ``given`` (the text
    of the value as given, default ``value`` shown by :func:`shown`).

    Raises
    ------
    ValueRefused
        Not a finite number, or beyond the limit.
    """
    from esp.core.kinematics import units as kunits  # standard library only

    dimension = kunits.dimension_of(unit)
    limit_si, what = symbol_limit(kind, dimension)
    si_unit = "mm" if dimension == kunits.LENGTH else "rad"
    limit = limit_si / kunits.factor(unit)
    try:
        return check(value, Quantity(what, unit, -limit, limit), given=given)
    except ValueRefused as exc:
        if unit == si_unit:
            raise
        more = f" {unit} ({limit_si:g} {si_unit}), found"
        raise ValueRefused(exc.message.replace(f" {unit}, found", more, 1)) from None


class Given(float):
    """A float read from text by :func:`parse` that remembers the text, so that a later
    check (the range of a chain symbol, once the chain is known) shows it as given."""

    text: str

    def __new__(cls, value: float, text: str) -> Given:
        self = super().__new__(cls, value)
        self.text = text.strip()
        return self

    def __reduce__(self) -> tuple[type[Given], tuple[float, str]]:
        return (Given, (float(self), self.text))


class ValueRefused(DataError):
    """A number that is not accepted; ``message`` says what was expected and what found
    (without the place, which the caller adds)."""

    def __init__(self, message: str):
        self.message = message
        super().__init__(message)


def shown(value: Any) -> str:
    """``value`` as given: the text of an option (shortened past 40 characters), the
    shortest decimal that reads back as a float (``10000.0001``, ``1e-300``), the digits of
    an integer (its first digits and length past 20 digits)."""
    if isinstance(value, Given):
        return value.text
    if isinstance(value, str):
        t = value.strip()
        if not t:
            return "nothing"
        return repr(t if len(t) <= 40 else t[:37] + "...")
    if isinstance(value, bool):
        return repr(value)
    if isinstance(value, int):
        digits = str(abs(value))
        sign = "-" if value < 0 else ""
        if len(digits) <= 20:
            return f"{sign}{digits}"
        return f"a whole number of {len(digits)} digits ({sign}{digits[:6]}...)"
    if isinstance(value, float):
        return _shortest(value)
    try:
        return _shortest(float(value))  # numpy scalars
    except (TypeError, ValueError, OverflowError):
        text = repr(value)
        return text if len(text) <= 60 else text[:57] + "..."


def _shortest(x: float) -> str:
    """``x`` as the shortest decimal that reads back as it (:func:`repr`), with a plain
    exponent: ``400.0``, ``10000.0001``, ``1e-300``, ``2.5e-7``; past 12 digits the fewest
    significant digits with an exponent (``1e12``, not ``1000000000000.0``)."""
    if not math.isfinite(x):
        return repr(x)
    text = repr(x)
    text = re.sub(r"e\+?(-?)0*(\d)", r"e\1\2", text)
    if len(text.lstrip("-").removesuffix(".0")) <= 12:
        return text
    for digits in range(1, 18):
        short = re.sub(r"e\+?(-?)0*(\d)", r"e\1\2", f"{x:.{digits}g}")
        if float(short) == x:
            return short if len(short) < len(text) else text
    return text


def written(x: float) -> str:
    """A number read from a data file as the file most likely writes it: :func:`shown`
    without a trailing ``.0`` (``-10001``, ``10000.0001``, ``1e200``)."""
    return shown(float(x)).removesuffix(".0")


def check(value: Any, quantity: str | Quantity = "number", *, given: str | None = None) -> float:
    """``value`` as a float when it is a number within the range of ``quantity`` (a name of
    :data:`QUANTITIES` or a :class:`Quantity`); ``given`` is the text to show instead of
    ``value`` (``"'1e12'"``, ``"20 arcsec"``: the value as it was given).

    Raises
    ------
    ValueRefused
        A bool or non-number, an integer beyond float range, inf or NaN, a value outside
        the range; the message shows the value as given.
    """
    q = QUANTITIES[quantity] if isinstance(quantity, str) else quantity
    show = shown(value) if given is None else given
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise ValueRefused(f"expected a number, found {show}")
    try:
        x = float(value)
    except OverflowError:
        raise ValueRefused(f"expected {q.expected()}, found {show}") from None
    if not math.isfinite(x):
        raise ValueRefused(f"expected a finite number, found {show}")
    too_low = x <= q.low if q.above_low else x < q.low
    if too_low or x > q.high:
        raise ValueRefused(f"expected {q.expected()}, found {show}")
    return x


def parse(text: str, quantity: str | Quantity = "number") -> float:
    """A number read from ``text`` (an option, a CSV cell) as :func:`check` accepts it:
    decimal digits with an optional point and exponent, no underscores (``1_000``), no
    hexadecimal, no words."""
    q = QUANTITIES[quantity] if isinstance(quantity, str) else quantity
    t = text.strip() if isinstance(text, str) else text
    if not isinstance(t, str):
        return check(t, q)
    if _NON_FINITE.match(t):
        raise ValueRefused(f"expected a finite number, found {shown(text)}")
    if not _DECIMAL.match(t):
        raise ValueRefused(
            f"expected a number, found {shown(text)} (write decimal digits: 1000, 2.5, 1e3)"
        )
    return Given(check(float(t), q, given=shown(text)), t)


def config_number(
    value: Any, key: str, quantity: str | Quantity = "number", source: Any = None
) -> float:
    """:func:`check` for a configuration value: a refusal is a
    :class:`~esp.core.errors.ConfigError` naming ``key`` (and the file ``source``)."""
    try:
        return check(value, quantity)
    except ValueRefused as exc:
        raise ConfigError(key, exc.message, source) from None


def quantity_of_key(key: str) -> str:
    """The quantity a key's unit suffix names (esp puts the unit in the name:
    ``strut_mm``, ``R_mm``, ``alpha_deg``, ``strut_um``): ``"mm"`` for ``_mm``,
    ``"displacement"`` for ``_um``, ``"angle"`` for ``_urad``, ``"degrees"`` for ``_deg``,
    else ``"number"``."""
    last = key.rsplit(".", 1)[-1].split("[", 1)[0]
    for suffix, quantity in (
        ("_mm", "mm"),
        ("_um", "displacement"),
        ("_urad", "angle"),
        ("_deg", "degrees"),
    ):
        if last.endswith(suffix):
            return quantity
    return "number"
