"""The environment readings of a measurement file, read into the quantities an uncertainty
model needs: the test duration, the change and level of the machine temperature, and the
expansion coefficient of the scale.

A Laser10 file holds its environment in an ``ENVIRONMENT::`` section, one line per reading
with the values at the start and the end of the test (kept raw on
:attr:`esp.core.profile.ErrorProfile.environment`). This module only parses; what a model does
with the values is :mod:`esp.core.uncertainty.instruments`.

Lines used (keys compared without case, spaces or punctuation; a line's first two numbers
are its start and end values):

* ``Date Time : "10:46 Dec 12 2016" "11:01 Dec 12 2016"`` -> ``duration_min``, the first
  to the last date-time on the line (ISO ``2016-12-12 10:46`` is accepted too);
* ``Mat temp 1..n : start end ...`` -> ``temperature_change_degc`` (the largest
  |end − start| over the sensors) and ``max_difference_to_20_degc`` (the largest |T − 20|
  over the sensors' start and end values). A sensor reading 0 at start and end is taken
  as not fitted and skipped, and so is one whose start or end value is exactly -10
  (:data:`ABSENT_TEMPERATURE_DEGC`, the value Laser10 writes for a material sensor that is
  not connected: :func:`absent_sensors`);
* ``Exp coeff : start end ...`` -> ``expansion_coefficient_um_per_m_per_degc`` (the larger
  of the two);
* ``Air temp``, ``Air press``, ``Air humid : start end ...`` -> ``air_temperature_start_degc``
  and ``_end_degc``, ``air_pressure_start_kpa`` and ``_end_kpa`` (kPa; a pair between 500
  and 1200 is read as hPa), ``air_humidity_start_pct`` and ``_end_pct``: the air the laser's
  wavelength compensation measured, for the refraction term of an interferometer whose
  compensation was fixed at the start (:mod:`esp.core.uncertainty.refraction`). A reading
  outside -10 to 50 °C, 50 to 120 kPa or 0 to 100 % is not used, and the reason is kept.

The air temperature does not enter the machine's expansion: that is the material's.

This module imports only the standard library.
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable, Mapping
from datetime import datetime
from typing import Any

__all__ = [
    "ABSENT_TEMPERATURE_DEGC",
    "ENVIRONMENT_QUANTITIES",
    "absent_sensors",
    "date_times",
    "environment_quantities",
    "is_material_temperature",
    "numbers",
]

#: a material temperature of exactly this value (°C; written ``-10.000000``) marks a sensor
#: that is not connected: no machine is measured at -10 °C
ABSENT_TEMPERATURE_DEGC = -10.0

#: the quantities :func:`environment_quantities` can find
ENVIRONMENT_QUANTITIES = (
    "duration_min",
    "temperature_change_degc",
    "max_difference_to_20_degc",
    "expansion_coefficient_um_per_m_per_degc",
    "air_temperature_start_degc",
    "air_temperature_end_degc",
    "air_pressure_start_kpa",
    "air_pressure_end_kpa",
    "air_humidity_start_pct",
    "air_humidity_end_pct",
)

#: the air readings: normalised key -> (quantity stem, unit word)
_AIR = {
    "airtemp": "air_temperature",
    "airpress": "air_pressure",
    "airhumid": "air_humidity",
}

_MONTHS = {
    m: i + 1
    for i, m in enumerate(
        ("jan", "feb", "mar", "apr", "may", "jun", "jul", "aug", "sep", "oct", "nov", "dec")
    )
}
_TIME_DATE = re.compile(
    r"(\d{1,2}):(\d{2})(?::(\d{2}))?\s+([A-Za-z]{3})[A-Za-z]*\.?\s+(\d{1,2}),?\s+(\d{4})"
)
_ISO_DATE_TIME = re.compile(r"(\d{4})-(\d{2})-(\d{2})[T ](\d{1,2}):(\d{2})(?::(\d{2}))?")
_NUMBER = re.compile(r"[-+]?(?:\d+\.\d*|\.\d+|\d+)(?:[eE][-+]?\d+)?")


def _norm_key(key: Any) -> str:
    return re.sub(r"[^a-z0-9]", "", str(key).lower())


def _text(value: Any) -> str:
    """The raw fields of a reading as one string."""
    if isinstance(value, str):
        return value
    try:
        return " ".join(str(v) for v in value)
    except TypeError:
        return str(value)


def numbers(value: Any) -> list[float]:
    """The finite numbers written in a reading's fields, in order.

    Examples
    --------
    >>> numbers(("20.1", "20.4 C", "n/a"))
    [20.1, 20.4]
    """
    out = []
    for m in _NUMBER.findall(_text(value)):
        x = float(m)
        if math.isfinite(x):
            out.append(x)
    return out


def is_material_temperature(key: Any) -> bool:
    """Whether ``key`` names a material temperature sensor (``Mat temp``, ``Mat temp 2``)."""
    return re.fullmatch(r"mattemp\d*", _norm_key(key)) is not None


def absent_sensors(environment: Mapping[str, Any]) -> list[str]:
    """The keys of the material temperature lines whose start or end value is exactly
    :data:`ABSENT_TEMPERATURE_DEGC`: sensors that were not connected, whose values are not
    readings (they are neither averaged nor reported)."""
    return [
        key
        for key, value in environment.items()
        if is_material_temperature(key) and ABSENT_TEMPERATURE_DEGC in numbers(value)[:2]
    ]


def _at(
    text: str, pattern: re.Pattern[str], build: Callable[[re.Match[str]], datetime | None]
) -> list[tuple[int, datetime]]:
    found = []
    for m in pattern.finditer(text):
        try:
            stamp = build(m)
        except ValueError:
            continue
        if stamp is not None:
            found.append((m.start(), stamp))
    return found


def _from_time_date(m: re.Match) -> datetime | None:
    month = _MONTHS.get(m.group(4).lower())
    if month is None:
        return None
    return datetime(
        int(m.group(6)),
        month,
        int(m.group(5)),
        int(m.group(1)),
        int(m.group(2)),
        int(m.group(3) or 0),
    )


def _from_iso(m: re.Match) -> datetime:
    return datetime(
        int(m.group(1)),
        int(m.group(2)),
        int(m.group(3)),
        int(m.group(4)),
        int(m.group(5)),
        int(m.group(6) or 0),
    )


def date_times(value: Any) -> list[datetime]:
    """The date-times written in a reading's fields, in the order they are written.

    ``10:46 Dec 12 2016`` (the Laser10 form, seconds optional) and ``2016-12-12 10:46``
    (ISO 8601, ``T`` or a space between date and time); impossible dates are skipped.

    Examples
    --------
    >>> [d.isoformat() for d in date_times('"10:46 Dec 12 2016" "11:01 Dec 12 2016"')]
    ['2016-12-12T10:46:00', '2016-12-12T11:01:00']
    """
    text = _text(value)
    found = _at(text, _TIME_DATE, _from_time_date) + _at(text, _ISO_DATE_TIME, _from_iso)
    return [dt for _, dt in sorted(found, key=lambda item: item[0])]


def environment_quantities(
    environment: Mapping[str, Any],
) -> tuple[dict[str, float], dict[str, str]]:
    """What the uncertainty models can take from a file's environment readings.

    Parameters
    ----------
    environment : reading name -> its raw fields (a string or a sequence of strings), as
        :attr:`esp.core.profile.ErrorProfile.environment` holds them

    Returns
    -------
    (values, why) : tuple of dicts
        ``values`` maps each quantity of :data:`ENVIRONMENT_QUANTITIES` found to its value
        (minutes, °C, µm/(m·°C)); ``why`` maps each quantity not found to the reason, for
        a message that names what the file lacks.
    """
    by_key = {_norm_key(k): v for k, v in environment.items()}
    values: dict[str, float] = {}
    why: dict[str, str] = {}

    raw = by_key.get("datetime")
    if raw is None:
        why["duration_min"] = "no 'Date Time' line"
    else:
        stamps = date_times(raw)
        if len(stamps) < 2:
            why["duration_min"] = f"'Date Time' {_text(raw)!r} does not hold a start and an end"
        elif stamps[-1] < stamps[0]:
            why["duration_min"] = f"'Date Time' {_text(raw)!r} ends before it starts"
        else:
            values["duration_min"] = (stamps[-1] - stamps[0]).total_seconds() / 60.0

    sensors = [k for k in by_key if is_material_temperature(k)]
    absent = {_norm_key(k) for k in absent_sensors(environment)}
    pairs = []
    bad = []
    for key in sorted(sensors):
        nums = numbers(by_key[key])
        if len(nums) < 2:
            bad.append(key)
            continue
        if (nums[0] == 0.0 and nums[1] == 0.0) or key in absent:
            continue
        pairs.append((nums[0], nums[1]))
    if pairs:
        values["temperature_change_degc"] = max(abs(e - s) for s, e in pairs)
        values["max_difference_to_20_degc"] = max(
            max(abs(s - 20.0), abs(e - 20.0)) for s, e in pairs
        )
    else:
        if bad:
            reason = "the 'Mat temp' lines do not hold a start and an end value"
        elif absent:
            reason = (
                f"every 'Mat temp' sensor is absent (it reads {ABSENT_TEMPERATURE_DEGC:g}, "
                "the value written for a sensor that is not connected)"
            )
        else:
            reason = "no 'Mat temp' line with a start and an end value"
        why["temperature_change_degc"] = reason
        why["max_difference_to_20_degc"] = reason

    raw = by_key.get("expcoeff")
    nums = [] if raw is None else numbers(raw)
    if raw is None:
        why["expansion_coefficient_um_per_m_per_degc"] = "no 'Exp coeff' line"
    elif not nums:
        why["expansion_coefficient_um_per_m_per_degc"] = (
            f"'Exp coeff' {_text(raw)!r} holds no number"
        )
    else:
        values["expansion_coefficient_um_per_m_per_degc"] = max(abs(x) for x in nums[:2])

    for key, stem in _AIR.items():
        unit = {"air_temperature": "degc", "air_pressure": "kpa", "air_humidity": "pct"}[stem]
        names = (f"{stem}_start_{unit}", f"{stem}_end_{unit}")
        raw = by_key.get(key)
        nums = [] if raw is None else numbers(raw)
        if len(nums) < 2:
            reason = f"no '{key}' line with a start and an end value"
            why.update(dict.fromkeys(names, reason))
            continue
        pair = nums[:2]
        if stem == "air_pressure" and all(500.0 <= x <= 1200.0 for x in pair):
            pair = [x / 10.0 for x in pair]  # written in hPa (mbar)
        limits = {"air_temperature": (-10.0, 50.0), "air_pressure": (50.0, 120.0)}
        low, high = limits.get(stem, (0.0, 100.0))
        if not all(low <= x <= high for x in pair):
            reason = f"'{key}' {_text(raw)!r} is not an air reading esp understands"
            why.update(dict.fromkeys(names, reason))
            continue
        values[names[0]], values[names[1]] = pair
    return values, why
