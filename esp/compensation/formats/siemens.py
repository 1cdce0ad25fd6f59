"""SINUMERIK interpolatory compensation: leadscrew / measuring-system error compensation
(LEC, ``$AA_ENC_COMP...``) and sag / angularity compensation (CEC, ``$AN_CEC...``), as
the part programs ``AX_EEC.INI`` and ``NC_CEC.INI`` that load the tables.

What the Siemens documentation (SINUMERIK Function Manual Extended Functions, K3
Compensations, "Interpolatory compensation"; cited in docs/compensation.md) says and how
esp reads it:

* LEC: per machine axis and measuring system ``e`` (esp writes the first, 0), the values
  ``$AA_ENC_COMP[e,N,AXi]`` at the points ``N`` = 0 ... k, equidistant from
  ``$AA_ENC_COMP_MIN[e,AXi]`` to ``$AA_ENC_COMP_MAX[e,AXi]`` every
  ``$AA_ENC_COMP_STEP[e,AXi]``; ``$AA_ENC_COMP_IS_MODULO[e,AXi]`` 1 repeats the table
  cyclically (rotary axes), 0 not; at most ``MD38000 $MA_MM_ENC_COMP_MAX_POINTS`` points
  (up to 200 on the SINUMERIK 808D, configured on the 840D sl); positions and values in mm
  (inch when the basic system is inch, not written by esp);
* LEC sign: "a positive compensation value causes the corresponding machine axis to move
  in the negative direction" (the value modifies the actual position value): the value is
  the axis' *error*, esp writes minus its correction;
* linear interpolation between the points; below the first and above the last point the
  first and last value stay active (not for modulo tables);
* a rotary axis (positions and values in degrees): with ``_IS_MODULO`` 1 the table repeats
  cyclically, the value at ``_MAX`` immediately followed by the value at ``_MIN``; for a
  360° axis ``_MIN`` 0 and ``_MAX`` 360 with both values given (the 808D Function Manual's
  example of a spindle's angular error, 0° to 360° every 30°); esp writes a rotary
  table's angular positioning error so, the first and last values equal;
* CEC: tables ``t`` with ``$AN_CEC[t,N]``, the base axis ``$AN_CEC_INPUT_AXIS[t]``, the
  compensation axis ``$AN_CEC_OUTPUT_AXIS[t]`` (``(AXi)``), ``_STEP``, ``_MIN``, ``_MAX``
  as for LEC, ``$AN_CEC_DIRECTION[t]`` (0 both directions of the base axis, 1 positive
  only, -1 negative only), ``$AN_CEC_MULT_BY_TABLE[t]`` (0: no multiplication; esp writes
  0) and ``$AN_CEC_IS_MODULO[t]``; the compensation values of an axis add up; at most
  ``MD18342 $MN_MM_CEC_MAX_POINTS[t]`` points per table (200 and 8 tables on the 828D);
* the documentation gives no sign statement for CEC values: esp writes the error by
  default, as for LEC, and ``cross_sign="correction"`` writes the negative (the same
  option as the ISG cross tables); check with one move on the machine.

esp writes a leadscrew table as LEC with the mean of the two directions of motion; with
``siemens-cec`` the difference of each direction from that mean goes into two CEC tables
of the axis over itself with ``_DIRECTION`` 1 and -1 (the documented use "position-
dependent backlash compensation ... using two tables"), and each cross table into one CEC
table of both directions.

This module imports only numpy and the standard library.
"""

from __future__ import annotations

import re
from collections.abc import Mapping

import numpy as np

from esp.compensation.formats.base import Capabilities, Format, FormatSettings, Limits
from esp.compensation.model import AxisTable, CompensationSet, RotaryTable
from esp.core.errors import DataError, ParseError

__all__ = ["CEC_FILE", "FORMATS", "LEC_FILE", "LIMITS", "read", "write"]

LEC_FILE = "AX_EEC.INI"
CEC_FILE = "NC_CEC.INI"
#: mm, 6 decimals: 1 nm
DECIMALS = 6
#: default limits: LEC points per table (MD38000, 808D: 200), CEC points per table
#: (MD18342) and CEC tables (828D: 8 tables of 200 points)
LIMITS = {"lec": 200, "cec": 200, "cec_tables": 8}
SIGNS = ("error", "correction")
#: the linear axes; any other axis letter is a rotary axis, its table in degrees
LINEAR_AXES = ("X", "Y", "Z")


def _fmt(value: float) -> str:
    return f"{round(float(value), DECIMALS) + 0.0:.{DECIMALS}f}"


def _grid(positions_mm: np.ndarray, what: str) -> tuple[float, float, float]:
    """(min, step, max) of equidistant table points; DataError otherwise."""
    p = np.asarray(positions_mm, dtype=float)
    steps = np.diff(p)
    if np.any(np.abs(steps - steps[0]) > 1e-9 * max(1.0, float(np.max(np.abs(p))))):
        raise DataError(
            f"{what}: SINUMERIK tables take equidistant points (_STEP); choose a "
            f"--spacing that divides the travel"
        )
    return float(p[0]), float(steps[0]), float(p[-1])


def _sign(cross_sign: str) -> float:
    """Factor from esp's correction to the written CEC value."""
    if cross_sign not in SIGNS:
        raise DataError(f"--cross-sign: expected one of {', '.join(SIGNS)}, found {cross_sign!r}")
    return -1.0 if cross_sign == "error" else 1.0


def _lec(
    axis: str,
    positions: np.ndarray,
    values: np.ndarray,
    modulo: bool,
    numbers: Mapping[str, int],
    lim: Mapping[str, int],
    spacing: str,
) -> list[str]:
    """The LEC assignments of one axis: its values (mm or degrees, the error) at
    equidistant positions, ``_STEP``, ``_MIN``, ``_MAX`` and ``_IS_MODULO``."""
    n = positions.size
    if n > lim["lec"]:
        raise DataError(
            f"the {axis} LEC table has {n} points; MD38000 MM_ENC_COMP_MAX_POINTS was given "
            f"as {lim['lec']}: choose a larger --spacing{spacing} or give --max-points lec=N"
        )
    lo, step, hi = _grid(positions, f"LEC table of {axis}")
    ax = f"AX{numbers[axis]}"
    return [f"$AA_ENC_COMP[0,{i},{ax}]={_fmt(v)}" for i, v in enumerate(values)] + [
        f"$AA_ENC_COMP_STEP[0,{ax}]={_fmt(step)}",
        f"$AA_ENC_COMP_MIN[0,{ax}]={_fmt(lo)}",
        f"$AA_ENC_COMP_MAX[0,{ax}]={_fmt(hi)}",
        f"$AA_ENC_COMP_IS_MODULO[0,{ax}]={1 if modulo else 0}",
    ]


def _header(name: str, lines: list[str]) -> list[str]:
    return [f"%_N_{name}", "CHANDATA(1)", *lines]


def write(
    cset: CompensationSet,
    axis_numbers: Mapping[str, int] | None = None,
    limits: Mapping[str, int] | None = None,
    cross_sign: str = "error",
    direction_tables: bool = False,
) -> dict[str, str]:
    """The text of ``AX_EEC.INI`` (LEC) and, with cross tables or ``direction_tables``,
    ``NC_CEC.INI`` (CEC).

    Raises
    ------
    DataError
        A table of more points than the limits, more CEC tables than allowed, points that
        are not equidistant.
    """
    numbers = {"X": 1, "Y": 2, "Z": 3, **(axis_numbers or {})}
    lim = {**LIMITS, **(limits or {})}
    sign = _sign(cross_sign)
    lec = ["; leadscrew error compensation (LEC) written by esp", "; values in mm are errors"]
    cec = [
        "; sag / angularity compensation (CEC) written by esp",
        f"; values in mm written as the {cross_sign}",
    ]
    cec_tables: list[tuple[str, str, np.ndarray, np.ndarray, int]] = []
    for t in cset.axis_tables:
        if t.kind == "lead":
            mean = t.values_um("mean")
            lec += _lec(t.slave, t.positions_mm, -mean / 1000.0, False, numbers, lim, "")
            if direction_tables and t.bilateral:
                cec_tables.append((t.slave, t.slave, t.positions_mm, t.forward_um - mean, 1))
                cec_tables.append((t.slave, t.slave, t.positions_mm, t.backward_um - mean, -1))
        else:
            cec_tables.append((t.slave, t.master, t.positions_mm, t.forward_um, 0))
    for r in cset.rotary_tables:
        # the error in degrees (the value is the error, as for a linear axis); a modulo
        # table from 0 to 360° with equal first and last values (K3, "compensation with
        # modulo function")
        degrees = -r.correction_urad * 1e-6 * 180.0 / np.pi
        lec += _lec(r.axis, r.positions_deg, degrees, r.modulo, numbers, lim, f" {r.axis}=DEG")
    if len(cec_tables) > lim["cec_tables"]:
        raise DataError(
            f"{len(cec_tables)} CEC tables; the control was given {lim['cec_tables']} "
            f"(828D: 8): give --max-points cec_tables=N"
        )
    for k, (slave, master, positions, values, direction) in enumerate(cec_tables):
        if positions.size > lim["cec"]:
            raise DataError(
                f"the CEC table of {slave} over {master} has {positions.size} points; "
                f"MD18342 MM_CEC_MAX_POINTS was given as {lim['cec']}: choose a larger "
                f"--spacing or give --max-points cec=N"
            )
        lo, step, hi = _grid(positions, f"CEC table of {slave} over {master}")
        cec += [f"$AN_CEC[{k},{i}]={_fmt(sign * v / 1000.0)}" for i, v in enumerate(values)]
        cec += [
            f"$AN_CEC_INPUT_AXIS[{k}]=(AX{numbers[master]})",
            f"$AN_CEC_OUTPUT_AXIS[{k}]=(AX{numbers[slave]})",
            f"$AN_CEC_STEP[{k}]={_fmt(step)}",
            f"$AN_CEC_MIN[{k}]={_fmt(lo)}",
            f"$AN_CEC_MAX[{k}]={_fmt(hi)}",
            f"$AN_CEC_DIRECTION[{k}]={direction}",
            f"$AN_CEC_MULT_BY_TABLE[{k}]=0",
            f"$AN_CEC_IS_MODULO[{k}]=0",
        ]
    files = {LEC_FILE: "\n".join(_header("AX_EEC_INI", lec) + ["M17"]) + "\n"}
    if cec_tables:
        files[CEC_FILE] = "\n".join(_header("NC_CEC_INI", cec) + ["M17"]) + "\n"
    return files


_ASSIGN = re.compile(r"^\$(A[AN]_[A-Z_]+)\[([^\]]+)\]\s*=\s*(\S+)$")


def _assignments(text: str, path: str) -> dict[tuple[str, tuple[str, ...]], tuple[str, int]]:
    """(variable, indices) -> (value, line) of every assignment of a part program."""
    out: dict[tuple[str, tuple[str, ...]], tuple[str, int]] = {}
    for number, raw in enumerate(text.splitlines(), start=1):
        line = raw.split(";", 1)[0].strip()
        if not line or line.startswith("%_N_") or line in ("CHANDATA(1)", "M17", "M30"):
            continue
        m = _ASSIGN.match(line.replace(" ", ""))
        if not m:
            raise ParseError(path, number, f"expected $VARIABLE[...]=value, found {line[:60]!r}")
        key = (m.group(1), tuple(s.strip() for s in m.group(2).split(",")))
        if key in out:
            raise ParseError(path, number, f"${key[0]}[{','.join(key[1])}] is given twice")
        out[key] = (m.group(3), number)
    return out


def _text(
    entries: Mapping[tuple[str, tuple[str, ...]], tuple[str, int]],
    name: str,
    index: tuple[str, ...],
    path: str,
) -> str:
    if (name, index) not in entries:
        raise ParseError(path, None, f"missing ${name}[{','.join(index)}]")
    return entries[(name, index)][0]


def _number(
    entries: Mapping[tuple[str, tuple[str, ...]], tuple[str, int]],
    name: str,
    index: tuple[str, ...],
    path: str,
) -> float:
    key = (name, index)
    if key not in entries:
        raise ParseError(path, None, f"missing ${name}[{','.join(index)}]")
    value, line = entries[key]
    try:
        out = float(value)
    except ValueError:
        raise ParseError(path, line, f"${name}: expected a number, found {value!r}") from None
    if not np.isfinite(out):
        raise ParseError(path, line, f"${name}: expected a finite number, found {value!r}")
    return out


def _points(lo: float, step: float, hi: float, path: str, what: str) -> np.ndarray:
    if step <= 0 or hi <= lo:
        raise ParseError(path, None, f"{what}: expected MIN < MAX and STEP > 0")
    n = (hi - lo) / step
    if abs(n - round(n)) > 1e-6:
        raise ParseError(path, None, f"{what}: STEP does not divide MAX - MIN")
    return lo + step * np.arange(round(n) + 1)


def _axis(text: str, numbers: Mapping[int, str], path: str) -> str:
    m = re.fullmatch(r"\(?AX(\d+)\)?", text)
    if not m or int(m.group(1)) not in numbers:
        raise ParseError(path, None, f"expected (AXn) of a known axis, found {text!r}")
    return numbers[int(m.group(1))]


def read(
    files: Mapping[str, str],
    axis_numbers: Mapping[str, int] | None = None,
    cross_sign: str = "error",
) -> CompensationSet:
    """Read ``AX_EEC.INI`` and ``NC_CEC.INI`` back into tables (corrections in µm); the
    CEC tables of an axis over itself with ``_DIRECTION`` 1 and -1 are added to the
    axis' leadscrew table per direction."""
    numbers = {"X": 1, "Y": 2, "Z": 3, **(axis_numbers or {})}
    letter = {v: k for k, v in numbers.items()}
    sign = _sign(cross_sign)
    lead: dict[str, list[np.ndarray]] = {}
    rotary: list[RotaryTable] = []
    if LEC_FILE in files:
        e = _assignments(files[LEC_FILE], LEC_FILE)
        for ax in sorted({idx[1] for name, idx in e if name == "AA_ENC_COMP_STEP"}):
            what = f"LEC of {ax}"
            slave = _axis(ax, letter, LEC_FILE)
            lo = _number(e, "AA_ENC_COMP_MIN", ("0", ax), LEC_FILE)
            step = _number(e, "AA_ENC_COMP_STEP", ("0", ax), LEC_FILE)
            hi = _number(e, "AA_ENC_COMP_MAX", ("0", ax), LEC_FILE)
            modulo = _number(e, "AA_ENC_COMP_IS_MODULO", ("0", ax), LEC_FILE) != 0
            p = _points(lo, step, hi, LEC_FILE, what)
            v = np.array(
                [_number(e, "AA_ENC_COMP", ("0", str(i), ax), LEC_FILE) for i in range(p.size)]
            )
            if slave not in LINEAR_AXES:  # a rotary axis: degrees, the error
                rotary.append(RotaryTable(slave, p, -v * np.pi / 180.0 * 1e6, modulo))
                continue
            if modulo:
                raise ParseError(LEC_FILE, None, f"{what}: a linear axis' table has no modulo")
            lead[slave] = [p, -v * 1000.0, -v * 1000.0]
    cross = []
    if CEC_FILE in files:
        e = _assignments(files[CEC_FILE], CEC_FILE)
        for t in sorted({int(idx[0]) for name, idx in e if name == "AN_CEC_STEP"}):
            k = (str(t),)
            master = _axis(_text(e, "AN_CEC_INPUT_AXIS", k, CEC_FILE), letter, CEC_FILE)
            slave = _axis(_text(e, "AN_CEC_OUTPUT_AXIS", k, CEC_FILE), letter, CEC_FILE)
            what = f"CEC table {t}"
            for name in ("AN_CEC_MULT_BY_TABLE", "AN_CEC_IS_MODULO"):
                if _number(e, name, k, CEC_FILE) != 0:
                    raise ParseError(CEC_FILE, e[(name, k)][1], f"{what}: esp reads ${name}=0")
            p = _points(
                _number(e, "AN_CEC_MIN", k, CEC_FILE),
                _number(e, "AN_CEC_STEP", k, CEC_FILE),
                _number(e, "AN_CEC_MAX", k, CEC_FILE),
                CEC_FILE,
                what,
            )
            v = sign * np.array(
                [_number(e, "AN_CEC", (str(t), str(i)), CEC_FILE) for i in range(p.size)]
            )
            direction = int(_number(e, "AN_CEC_DIRECTION", k, CEC_FILE))
            if direction == 0:
                cross.append(AxisTable(slave, master, p, v * 1000.0, v * 1000.0, "cross"))
                continue
            if master != slave or slave not in lead or not np.allclose(lead[slave][0], p):
                raise ParseError(
                    CEC_FILE, None, f"{what}: esp reads direction tables of an axis' own LEC"
                )
            lead[slave][1 if direction == 1 else 2] = lead[slave][1 if direction == 1 else 2] + (
                v * 1000.0
            )
    tables = [AxisTable(a, a, p, f, b, "lead") for a, (p, f, b) in sorted(lead.items())]
    return CompensationSet(
        "siemens", axis_tables=tuple(tables + cross), rotary_tables=tuple(rotary)
    )


class Sinumerik(Format):
    """LEC alone, or LEC with CEC tables (cross tables and the two directions)."""

    limit_defaults = LIMITS

    def __init__(self, name: str, description: str, cec: bool, order: int) -> None:
        self.name = name
        self.description = description
        self.order = order
        self.cec = cec
        self.load_words = (
            "run AX_EEC.INI (LEC, MD32700 ENC_COMP_ENABLE = 0 while loading)"
            + (" and NC_CEC.INI (CEC)" if cec else "")
            + " as part programs, then enable the compensation"
        )
        self.capabilities = Capabilities(
            frozenset({"lead", "cross"} if cec else {"lead"}),
            error_kinds=frozenset({"linear", "straightness", "squareness"} if cec else {"linear"}),
            bidirectional=cec,
            masters_per_axis=2 if cec else 1,
            rotary_modulo=True,
        )

    def limits(self, settings: FormatSettings) -> Limits:
        lim = {**LIMITS, **settings.limits}
        return Limits(
            points_per_table=lim["lec"],
            tables=lim["cec_tables"] if self.cec else None,
            equidistant=True,
        )

    def write(self, cset: CompensationSet, settings: FormatSettings) -> dict[str, str]:
        return write(cset, settings.axis_numbers, settings.limits, settings.cross_sign, self.cec)

    def read(self, files: Mapping[str, str], settings: FormatSettings) -> CompensationSet:
        return read(files, settings.axis_numbers, settings.cross_sign)

    def resolution_um(self, settings: FormatSettings) -> float:
        return 1000.0 * 10.0**-DECIMALS


FORMATS = (
    Sinumerik(
        "siemens-lec",
        "SINUMERIK leadscrew error compensation, $AA_ENC_COMP (one curve for both directions)",
        False,
        40,
    ),
    Sinumerik(
        "siemens-cec",
        "SINUMERIK LEC and sag/angularity compensation $AN_CEC (cross and direction tables)",
        True,
        41,
    ),
)
