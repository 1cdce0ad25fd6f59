"""FANUC stored pitch error compensation: the parameters 3620-3624 (and 3605#0, 3626,
3627 for bidirectional compensation) and the pitch error data of each axis.

What the FANUC documents say (Series 0i-PB Parameter Manual B-63980EN/01, parameters
3620-3625; Technical Report A-77810E "Bidirectional pitch error compensation" for the
Series 16i/18i; cited in docs/compensation.md) and how esp reads them:

* compensation positions at equal intervals (3624) from the reference position, numbered
  for all axes together (the range of numbers is not in the documents read: esp allows
  0 to 1023 unless ``--max-points fanuc_points=N``); per axis the number of the
  reference position (3620), of the farthest position on the - side (3621) and on the +
  side (3622) and the magnification (3623): one unit of data is the detection unit times
  the magnification;
* the data are *incremental*: the value of position N is output for the section that ends
  at N (the rotary example: "for compensation position 60 set the same compensation value
  as for 68", the section before the reference being that of the last position of a
  turn); the compensation at the reference position is zero; the absolute compensation at
  a position is the sum of the values from the reference to it;
* bidirectional compensation (3605#0 = 1): a second set of data for travel in the
  negative direction from the number 3626, and 3627 the absolute compensation at the
  reference position when it is approached in the negative direction;
* a rotation axis (3625: the amount of travel per rotation): the farthest position on the
  - side is the reference position itself (3621 = 3620), the farthest on the + side the
  reference plus the travel per rotation over the interval (3622 = 3620 + 360/3624); the
  values of one rotation must add up to zero, or the error accumulates turn by turn, and
  the reference position takes the same value as the last (the 0i-PB example: 45°
  intervals, reference 60, positions 61 to 68, position 60 set as 68). esp writes the
  angular positioning table of a rotary table's axis so (a modulo table, whose first and
  last values are equal, so that its increments add up to zero exactly), its interval and
  travel in the detection unit of the axis; a rotary axis of limited travel (a tilting
  axis) as an axis of travel, in degrees. The compensation at the reference position is
  zero: a constant part of the table (its value at 0°) is not held, a shift of the
  axis' zero that the reference position sets.

Not in the documents read, offered as options (docs/compensation.md):

* ``fanuc-between``: between two positions, ``step`` (the value of a section is output
  when the axis reaches the section's far end in its direction of travel: the
  compensation changes stepwise at the positions, esp's default, what "output at the
  compensation position" describes) or ``linear`` (spread over the section);
* ``fanuc-sign``: ``correction`` (the data are added to the motion, esp's default) or
  ``error``;
* ``fanuc-detection-um``: the detection unit (default 1 µm, IS-B with a 1 µm detector);
  ``fanuc-detection-deg`` that of a rotary axis (default 0.001°, IS-B);
* the range of one value: ``--max-points fanuc_value=N`` (default 127, the range of a
  signed byte; older controls take -7 to 7).

The input/output file layout (``N10000P..`` for position 0, ``N3620A1P..`` for a
parameter of axis 1) is the parameter tape layout; enter the values on the parameter
screen if the control refuses the file.

This module imports only numpy and the standard library.
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from dataclasses import replace
from typing import TYPE_CHECKING

import numpy as np

from esp.compensation.formats.base import Capabilities, Format, FormatSettings, Limits
from esp.compensation.model import AxisTable, CompensationSet, RotaryTable
from esp.core.errors import DataError, ParseError

if TYPE_CHECKING:
    from esp.compensation.field import Fields
    from esp.compensation.predict import Prediction
    from esp.core.machine import Machine

__all__ = ["DATA_FILE", "FORMATS", "LIMITS", "PARAM_FILE", "read", "staircase", "write"]

DATA_FILE = "PITCH.TXT"
PARAM_FILE = "PARAM.TXT"
#: numbers for all axes together and units of one value (esp's defaults, not documented)
LIMITS = {"fanuc_points": 1024, "fanuc_value": 127}
OPTIONS = {
    "fanuc-between": ("step", "linear"),
    "fanuc-sign": ("correction", "error"),
    "fanuc-detection-um": ("<number>", "1"),
    "fanuc-detection-deg": ("<number>", "0.001"),
}
#: the width (mm) over which a step of the staircase is drawn for the prediction
STEP_MM = 1e-6


def _settings(settings: FormatSettings) -> tuple[float, float, str]:
    unit = float(settings.option("fanuc-detection-um", "1"))
    sign = -1.0 if settings.option("fanuc-sign", "correction") == "error" else 1.0
    return unit, sign, settings.option("fanuc-between", "step")


def _magnification(curves: list[np.ndarray], value_max: int) -> int:
    """The smallest magnification 1 to 100 (3623) whose incremental values fit."""
    for mag in range(1, 101):
        if all(np.max(np.abs(np.diff(np.rint(c / mag)))) <= value_max for c in curves):
            return mag
    raise DataError(
        f"a pitch error value beyond {value_max} units even with magnification 100 "
        f"(3623): choose a smaller --spacing or give --max-points fanuc_value=N"
    )


def write(cset: CompensationSet, settings: FormatSettings | None = None) -> dict[str, str]:
    """The text of ``PITCH.TXT`` (the pitch error data) and ``PARAM.TXT`` (3605#0,
    3620-3624, 3626, 3627 of each axis).

    Raises
    ------
    DataError
        More positions than ``fanuc_points``, points that are not equidistant, a value
        beyond ``fanuc_value`` units at magnification 100.
    """
    s = settings or FormatSettings()
    lim = {**LIMITS, **s.limits}
    unit, sign, _ = _settings(s)
    data: list[str] = []
    params: list[str] = []
    number = 0
    degree_unit = float(s.option("fanuc-detection-deg", "0.001"))
    for rt in sorted(cset.rotary_tables, key=lambda t: t.axis):
        lines, numbers = _rotary(rt, s, lim, sign, degree_unit, number)
        data += lines[0]
        params += lines[1]
        number += numbers
    for t in sorted(cset.axis_tables, key=lambda t: t.slave):
        if t.kind != "lead":
            continue
        p = t.positions_mm
        interval = _interval(p, 0.001, t.slave, "0.001 mm; choose another --spacing")
        ax = s.number(t.slave)
        r = 0  # the reference position: the table's first point (the datum's corner)
        bidirectional = t.bilateral
        curves = [sign * t.forward_um / unit] + (
            [sign * t.backward_um / unit] if bidirectional else []
        )
        mag = _magnification(curves, lim["fanuc_value"])
        first = number
        n = p.size
        used = n * len(curves)
        _check_numbers(number + used, lim)
        absolute = [np.rint(c / mag) for c in curves]
        reference = absolute[0][r]
        for k, a in enumerate(absolute):
            incremental = np.concatenate([[0.0], np.diff(a)])
            for i, v in enumerate(incremental):
                data.append(f"N{10000 + number + k * n + i}P{int(v)}")
        params += [
            f"N3605A{ax}P00000001" if bidirectional else f"N3605A{ax}P00000000",
            f"N3620A{ax}P{first + r}",
            f"N3621A{ax}P{first}",
            f"N3622A{ax}P{first + n - 1}",
            f"N3623A{ax}P{mag}",
            f"N3624A{ax}P{interval}",
        ]
        if bidirectional:
            params += [
                f"N3626A{ax}P{first + n}",
                f"N3627A{ax}P{int(absolute[1][r] - reference)}",
            ]
        params.append(f"(axis {t.slave}: position of {first + r} = {p[r]:.3f} mm)")
        number += used
    return {
        DATA_FILE: "%\n" + "\n".join(data) + "\n%\n",
        PARAM_FILE: "%\n" + "\n".join(params) + "\n%\n",
    }


def _interval(p: np.ndarray, unit: float, axis: str, words: str) -> int:
    """The interval (3624) of equidistant table positions ``p``, in units of ``unit``
    (0.001 mm, or the rotary axis' detection unit); DataError when the positions are not
    equidistant or the interval not a whole number of units (``words`` says which unit
    and which option to change)."""
    steps = np.diff(p)
    if np.any(np.abs(steps - steps[0]) > 1e-9 * max(1.0, float(np.max(np.abs(p))))):
        raise DataError(
            f"the {axis} table: FANUC pitch error compensation takes equidistant "
            f"positions (3624); choose a --spacing that divides the travel"
        )
    interval = steps[0] / unit
    if abs(interval - round(interval)) > 1e-6:
        raise DataError(f"the {axis} table: the interval (3624) must be a whole number of {words}")
    return int(round(interval))


def _check_numbers(needed: int, lim: Mapping[str, int]) -> None:
    """Refuse pitch error data that need more positions than the control numbers."""
    if needed > lim["fanuc_points"]:
        raise DataError(
            f"the pitch error data need {needed} positions; the control numbers "
            f"{lim['fanuc_points']} (0 to {lim['fanuc_points'] - 1}): choose a larger "
            f"--spacing or give --max-points fanuc_points=N"
        )


def _rotary(
    r: RotaryTable,
    s: FormatSettings,
    lim: Mapping[str, int],
    sign: float,
    unit_deg: float,
    number: int,
) -> tuple[tuple[list[str], list[str]], int]:
    """The pitch data and parameters of one rotary table (module docstring): ((data,
    parameters), the positions used)."""
    p = r.positions_deg
    interval = _interval(
        p,
        unit_deg,
        r.axis,
        f"{unit_deg:g}° (fanuc-detection-deg); choose another --spacing {r.axis}=DEG",
    )
    degrees = r.correction_urad * 1e-6 * 180.0 / np.pi
    curve = sign * degrees / unit_deg
    mag = _magnification([curve], lim["fanuc_value"])
    a = np.rint(curve / mag)
    n = p.size  # a modulo table: n - 1 sections of one rotation, positions first..first+n-1
    _check_numbers(number + n, lim)
    ax = s.number(r.axis)
    first = number
    incremental = np.concatenate([[0.0], np.diff(a)])
    if r.modulo:
        incremental[0] = incremental[-1]  # the reference takes the last section's value
    data = [f"N{10000 + first + i}P{int(v)}" for i, v in enumerate(incremental)]
    params = [
        f"N3605A{ax}P00000000",
        f"N3620A{ax}P{first}",
        f"N3621A{ax}P{first}",
        f"N3622A{ax}P{first + n - 1}",
        f"N3623A{ax}P{mag}",
        f"N3624A{ax}P{interval}",
    ]
    if r.modulo:
        params.append(f"N3625A{ax}P{int(round(360.0 / unit_deg))}")
    params.append(f"(axis {r.axis}: position of {first} = {p[0]:.3f} deg)")
    return (data, params), n


_LINE = re.compile(r"^N(\d+)(?:A(\d+))?P(-?\d+)$")


def _entries(text: str, path: str) -> dict[tuple[int, int], tuple[int, int]]:
    """(number, axis) -> (value, line); axis 0 for pitch data."""
    out: dict[tuple[int, int], tuple[int, int]] = {}
    for n, raw in enumerate(text.splitlines(), start=1):
        line = raw.strip()
        if not line or line == "%" or line.startswith("("):
            continue
        m = _LINE.match(line)
        if not m:
            raise ParseError(path, n, f"expected N<number>[A<axis>]P<value>, found {line[:60]!r}")
        key = (int(m.group(1)), int(m.group(2) or 0))
        if key in out:
            raise ParseError(path, n, f"N{key[0]} is given twice")
        out[key] = (int(m.group(3)), n)
    return out


def read(
    files: Mapping[str, str],
    settings: FormatSettings | None = None,
    origin_mm: Mapping[str, float] | None = None,
) -> CompensationSet:
    """Read ``PARAM.TXT`` and ``PITCH.TXT`` back into leadscrew tables (corrections in
    µm at the compensation positions; ``origin_mm`` the position of each axis' reference
    position, by default the one written in the parameter file's comment)."""
    s = settings or FormatSettings()
    unit, sign, _ = _settings(s)
    for name in (PARAM_FILE, DATA_FILE):
        if name not in files:
            raise ParseError(name, None, "missing")
    params = _entries(files[PARAM_FILE], PARAM_FILE)
    data = _entries(files[DATA_FILE], DATA_FILE)
    origins = dict(origin_mm or {})
    for m in re.finditer(r"\(axis (\w): position of \d+ = (-?[\d.]+) mm\)", files[PARAM_FILE]):
        origins.setdefault(m.group(1), float(m.group(2)))
    letter = {s.number(a): a for a in ("X", "Y", "Z", *s.axis_numbers)}
    degree_unit = float(s.option("fanuc-detection-deg", "0.001"))
    for m in re.finditer(r"\(axis (\w): position of \d+ = (-?[\d.]+) deg\)", files[PARAM_FILE]):
        origins.setdefault(m.group(1), float(m.group(2)))
    tables = []
    rotary = []

    def param(number: int, ax: int) -> int:
        if (number, ax) not in params:
            raise ParseError(PARAM_FILE, None, f"missing N{number}A{ax}")
        return params[(number, ax)][0]

    def pitch(number: int) -> float:
        if (10000 + number, 0) not in data:
            raise ParseError(DATA_FILE, None, f"missing N{10000 + number}")
        return float(data[(10000 + number, 0)][0])

    for ax in sorted({a for (_, a) in params if a}):
        axis = letter.get(ax)
        if axis is None:
            raise ParseError(PARAM_FILE, None, f"axis A{ax} is not one of --axis-numbers")
        ref, lo, hi = param(3620, ax), param(3621, ax), param(3622, ax)
        mag, interval = param(3623, ax), param(3624, ax)
        if not lo <= ref <= hi or mag < 1 or interval < 1:
            raise ParseError(PARAM_FILE, None, f"axis A{ax}: expected 3621 <= 3620 <= 3622")
        n = hi - lo + 1
        if axis not in ("X", "Y", "Z"):  # a rotary axis: degrees, µrad
            u_deg = mag * degree_unit * sign
            values = np.cumsum([0.0] + [pitch(lo + i) for i in range(1, n)]) * u_deg
            modulo = (3625, ax) in params
            if modulo and param(3625, ax) * degree_unit != 360.0 * 1.0:
                raise ParseError(PARAM_FILE, None, f"axis A{ax}: 3625 is not one rotation")
            if modulo and abs(values[-1] - values[0]) > 1e-9:
                raise ParseError(
                    PARAM_FILE, None, f"axis A{ax}: the values of one rotation do not add up to 0"
                )
            angles = origins.get(axis, 0.0) + np.arange(n) * interval * degree_unit
            rotary.append(RotaryTable(axis, angles, values * np.pi / 180.0 * 1e6, modulo))
            continue
        u = mag * unit * sign
        fwd = np.cumsum([pitch(lo + i) for i in range(n)])
        fwd = (fwd - fwd[ref - lo]) * u
        bwd = fwd
        if param(3605, ax) % 2 == 1:
            neg = param(3626, ax)
            b = np.cumsum([pitch(neg + i) for i in range(n)])
            bwd = (b - b[ref - lo] + param(3627, ax)) * u
        positions = origins.get(axis, 0.0) + (np.arange(n) - (ref - lo)) * interval / 1000.0
        tables.append(AxisTable(axis, axis, positions, fwd, bwd, "lead"))
    return CompensationSet("fanuc", axis_tables=tuple(tables), rotary_tables=tuple(rotary))


def staircase(table: AxisTable, width_mm: float = STEP_MM) -> AxisTable:
    """The table as the control applies it with ``fanuc-between=step``: moving in the
    positive direction the value of a section is reached at its upper position, moving in
    the negative direction at its lower one, the change drawn over ``width_mm``."""
    p, f, b = table.positions_mm, table.forward_um, table.backward_um
    pos, fwd, bwd = [p[0]], [f[0]], [b[0]]
    for i in range(1, p.size):
        # forward: the previous value up to just before p[i]; backward: the new value
        # from just after p[i-1]
        pos += [p[i - 1] + width_mm, p[i] - width_mm, p[i]]
        fwd += [f[i - 1], f[i - 1], f[i]]
        bwd += [b[i], b[i], b[i]]
    return AxisTable(table.slave, table.master, np.array(pos), np.array(fwd), np.array(bwd))


class Fanuc(Format):
    """FANUC stored pitch error compensation, bidirectional when the data have both
    directions."""

    name = "fanuc"
    description = "FANUC pitch error compensation, parameters 3620-3627 and pitch data"
    load_words = (
        "PARAM.TXT holds the parameters 3605#0 and 3620-3627 of each axis and PITCH.TXT the "
        "pitch error data; load them through the control's I/O or enter them on its screens"
    )
    order = 50
    capabilities = Capabilities(frozenset({"lead"}), bidirectional=True, rotary_modulo=True)
    zero_at_reference = True
    limit_defaults = LIMITS
    format_options = OPTIONS

    def limits(self, settings: FormatSettings) -> Limits:
        return Limits(
            points_per_table={**LIMITS, **settings.limits}["fanuc_points"], equidistant=True
        )

    def write(self, cset: CompensationSet, settings: FormatSettings) -> dict[str, str]:
        return write(cset, settings)

    def read(self, files: Mapping[str, str], settings: FormatSettings) -> CompensationSet:
        return read(files, settings)

    def resolution_um(self, settings: FormatSettings) -> float:
        return _settings(settings)[0]

    def predict(
        self,
        machine: Machine,
        applied: CompensationSet,
        settings: FormatSettings,
        fields: Fields | None = None,
    ) -> Prediction:
        """With ``fanuc-between=step`` the tables as a staircase (:func:`staircase`)."""
        from esp.compensation.predict import predict

        if _settings(settings)[2] == "step":
            applied = replace(
                applied,
                axis_tables=tuple(
                    staircase(t) if t.kind == "lead" else t for t in applied.axis_tables
                ),
            )
        return predict(machine, applied, self.resolution_um(settings), fields)


FORMATS = (Fanuc(),)
