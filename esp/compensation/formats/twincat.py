"""TwinCAT CNC / ISG kernel axis compensation lists: leadscrew error compensation
(``kw.ssfk.*``), cross compensation (``kw.crosscomp.*``) and plane compensation
(``kw.crosscomp2.*``).

What the Beckhoff documentation (TF5200 Axis compensation and its parameter reference,
cited in docs/compensation.md) says and how esp reads it:

* one ASCII list per axis, ``name value`` per line; ``#`` starts a comment line; the
  header ``kopf.achs_nr`` / ``kopf.log_achs_name`` names the axis (one example writes
  ``kopf.log_achs_nr``; the reader takes both);
* lengths in 0.1 µm when ``unit`` is 1 (0: encoder increments, not written by esp);
  values are integers (SGN32; REAL64 only from V3.1.3132.0);
* ``kw.ssfk``: table points ``table[i].setpoint`` (with ``interval`` 0, non-equidistant),
  ``kw_startpos``, ``kw_nr_max`` entries (at most ``kw.ssfk.max_points``, P-COMP-00059,
  default 1500), ``bilateral`` 1 with ``table[i].pos`` for motion in the positive and
  ``table[i].neg`` in the negative direction. The values are *position errors*: the
  documentation's worked example computes ``Δs = s_actual - s_setpoint``
  (19856.5 µm - 19866.7 µm = -102 × 0.1 µm), so esp writes the error, i.e. minus its
  correction; linear interpolation between points;
* ``kw.crosscomp``: in the list of the corrected (slave) axis, ``master_ax_nr`` the
  logical number of the master axis, ``last_index`` (``last_index`` + 1 entries,
  ``last_index`` < ``max_points``, P-COMP-00060, default 1001), ``table[i].setpoint`` the
  master's command positions and ``table[i].correction`` the "relative compensation
  value" for both directions of motion;
* ``kw.crosscomp2``: an equidistant grid over two master axes with one ``interval``,
  ``start_position_master1/2``, ``last_index_master1/2`` ((last1 + 1)(last2 + 1) <=
  ``max_points``, P-COMP-00061, default 10201), ``master1_ax_nr``, ``master2_ax_nr`` and
  ``table[j][i].correction`` with j along master 2.

The documentation does not say whether ``correction`` of the cross and plane tables is
the error or its negative. esp writes the error by default (the convention the leadscrew
table's worked example shows); ``cross_sign="correction"`` writes the negative.
Whatever is chosen, check the sign on the machine with one move before relying on it.

This module imports only numpy and the standard library.
"""

from __future__ import annotations

import re
from collections.abc import Mapping

import numpy as np

from esp.compensation.formats.base import Capabilities, Format, FormatSettings, Limits
from esp.compensation.model import AxisTable, CompensationSet, PlaneTable
from esp.core.errors import DataError, ParseError

__all__ = ["FORMATS", "LIMITS", "SIGNS", "read", "write"]

#: default table-size limits of the ISG kernel (P-COMP-00059, -00060, -00061)
LIMITS = {"ssfk": 1500, "crosscomp": 1001, "crosscomp2": 10201}
SIGNS = ("error", "correction")
_SGN32 = 2**31 - 1
_UNIT_UM = 0.1  # kw.*.unit = 1: metric, 0.1 µm


def _increments(values_um: np.ndarray, what: str) -> np.ndarray:
    """µm -> integer 0.1 µm, refusing what SGN32 cannot hold."""
    v = np.rint(np.asarray(values_um, dtype=float) / _UNIT_UM)
    if np.any(np.abs(v) > _SGN32):
        raise DataError(f"{what}: a value beyond the SGN32 range of the list")
    return v.astype(np.int64)


def _positions(positions_mm: np.ndarray, what: str) -> np.ndarray:
    """mm -> integer 0.1 µm; a position that is not a whole number of 0.1 µm is refused."""
    v = np.asarray(positions_mm, dtype=float) * 1e4
    if np.any(np.abs(v - np.rint(v)) > 1e-6):
        raise DataError(
            f"{what}: table positions must be whole multiples of 0.1 µm (kw.*.unit = 1); "
            f"choose a spacing in whole 0.1 µm"
        )
    return _increments(np.asarray(positions_mm) * 1000.0, what)


def _check_sign(cross_sign: str) -> float:
    if cross_sign not in SIGNS:
        raise DataError(f"--cross-sign: expected one of {', '.join(SIGNS)}, found {cross_sign!r}")
    return -1.0 if cross_sign == "error" else 1.0


def write(
    cset: CompensationSet,
    axis_numbers: Mapping[str, int] | None = None,
    limits: Mapping[str, int] | None = None,
    cross_sign: str = "error",
) -> dict[str, str]:
    """The text of one list ``<axis>.lis`` per corrected axis.

    Raises
    ------
    DataError
        A table larger than the limits, a position that is not a whole 0.1 µm, an
        unequal spacing in a plane table.
    """
    numbers = {"X": 1, "Y": 2, "Z": 3, **(axis_numbers or {})}
    lim = {**LIMITS, **(limits or {})}
    sign = _check_sign(cross_sign)
    lists: dict[str, list[str]] = {}

    def body(axis: str) -> list[str]:
        if axis not in lists:
            lists[axis] = [
                "# axis compensation list written by esp",
                "# lengths in 0.1 um (unit 1); leadscrew values are position errors",
                f"# cross/plane values are written as the {cross_sign}",
                f"kopf.achs_nr {numbers[axis]}",
                f"kopf.log_achs_name {axis}",
            ]
        return lists[axis]

    for t in cset.axis_tables:
        n = t.positions_mm.size
        setpoints = _positions(t.positions_mm, f"{t.kind} table of {t.slave}")
        if t.kind == "lead":
            if n > lim["ssfk"]:
                raise DataError(
                    f"the {t.slave} leadscrew table has {n} points; kw.ssfk.max_points "
                    f"(P-COMP-00059) is {lim['ssfk']}: choose a larger --spacing"
                )
            pos = _increments(-t.forward_um, f"leadscrew table of {t.slave}")
            neg = _increments(-t.backward_um, f"leadscrew table of {t.slave}")
            lines = body(t.slave)
            lines += [
                "kw.ssfk.unit 1",
                "kw.ssfk.interval 0",
                f"kw.ssfk.kw_startpos {setpoints[0]}",
                f"kw.ssfk.kw_nr_max {n}",
                "kw.ssfk.bilateral 1",
            ]
            lines += [f"kw.ssfk.table[{i}].setpoint {v}" for i, v in enumerate(setpoints)]
            lines += [f"kw.ssfk.table[{i}].pos {v}" for i, v in enumerate(pos)]
            lines += [f"kw.ssfk.table[{i}].neg {v}" for i, v in enumerate(neg)]
        else:
            if n > lim["crosscomp"]:
                raise DataError(
                    f"the cross table of {t.slave} has {n} points; kw.crosscomp.max_points "
                    f"(P-COMP-00060) is {lim['crosscomp']}: choose a larger --spacing"
                )
            corr = _increments(sign * t.forward_um, f"cross table of {t.slave}")
            lines = body(t.slave)
            lines += [
                "kw.crosscomp.unit 1",
                f"kw.crosscomp.master_ax_nr {numbers[t.master]}",
                f"kw.crosscomp.last_index {n - 1}",
            ]
            lines += [f"kw.crosscomp.table[{i}].setpoint {v}" for i, v in enumerate(setpoints)]
            lines += [f"kw.crosscomp.table[{i}].correction {v}" for i, v in enumerate(corr)]
    for p in cset.plane_tables:
        a, b = p.masters
        na, nb = p.positions_a_mm.size, p.positions_b_mm.size
        if na * nb > lim["crosscomp2"]:
            raise DataError(
                f"the plane table of {p.slave} has {na} x {nb} = {na * nb} points; "
                f"kw.crosscomp2.max_points (P-COMP-00061) is {lim['crosscomp2']}: choose a "
                f"larger --spacing"
            )
        sa = _positions(p.positions_a_mm, f"plane table of {p.slave}")
        sb = _positions(p.positions_b_mm, f"plane table of {p.slave}")
        steps = np.concatenate([np.diff(sa), np.diff(sb)])
        if np.any(steps != steps[0]):
            raise DataError(
                f"the plane table of {p.slave} needs one spacing on {a} and {b} "
                f"(kw.crosscomp2.interval); its points are not equidistant"
            )
        corr = _increments(sign * p.values_um, f"plane table of {p.slave}")
        lines = body(p.slave)
        lines += [
            "kw.crosscomp2.unit 1",
            f"kw.crosscomp2.interval {steps[0]}",
            f"kw.crosscomp2.last_index_master1 {na - 1}",
            f"kw.crosscomp2.last_index_master2 {nb - 1}",
            f"kw.crosscomp2.start_position_master1 {sa[0]}",
            f"kw.crosscomp2.start_position_master2 {sb[0]}",
            f"kw.crosscomp2.master1_ax_nr {numbers[a]}",
            f"kw.crosscomp2.master2_ax_nr {numbers[b]}",
        ]
        lines += [
            f"kw.crosscomp2.table[{j}][{i}].correction {corr[j, i]}"
            for j in range(nb)
            for i in range(na)
        ]
    return {f"{axis}.lis": "\n".join(lines) + "\n" for axis, lines in sorted(lists.items())}


_LINE = re.compile(r"^([A-Za-z_][\w.\[\]]*)\s+(\S+)\s*(?:/\*.*\*/)?\s*$")
_INDEX = re.compile(r"\[(\d+)\]")


def _entries(text: str, path: str) -> dict[str, tuple[str, int]]:
    out: dict[str, tuple[str, int]] = {}
    for number, raw in enumerate(text.splitlines(), start=1):
        line = raw.strip()
        if not line or line.startswith("#"):
            continue
        m = _LINE.match(line)
        if not m:
            raise ParseError(path, number, f"expected 'name value', found {line[:60]!r}")
        if m.group(1) in out:
            raise ParseError(path, number, f"{m.group(1)} is given twice")
        out[m.group(1)] = (m.group(2), number)
    return out


def _int(entries: Mapping[str, tuple[str, int]], key: str, path: str) -> int:
    if key not in entries:
        raise ParseError(path, None, f"missing {key}")
    value, line = entries[key]
    try:
        return int(value)
    except ValueError:
        raise ParseError(path, line, f"{key}: expected an integer, found {value!r}") from None


def _series(
    entries: Mapping[str, tuple[str, int]], prefix: str, field: str, n: int, path: str
) -> np.ndarray:
    return np.array(
        [_int(entries, f"{prefix}.table[{i}].{field}", path) for i in range(n)], dtype=float
    )


def read(
    files: Mapping[str, str],
    axis_numbers: Mapping[str, int] | None = None,
    cross_sign: str = "error",
) -> CompensationSet:
    """Read ``<axis>.lis`` texts back into tables (corrections in µm)."""
    numbers = {"X": 1, "Y": 2, "Z": 3, **(axis_numbers or {})}
    letter = {v: k for k, v in numbers.items()}
    sign = _check_sign(cross_sign)
    axis_tables, plane_tables = [], []
    for path in sorted(files):
        if not path.endswith(".lis"):
            continue
        e = _entries(files[path], path)
        if "kopf.log_achs_name" in e:
            slave = e["kopf.log_achs_name"][0]
        else:
            nr = _int(e, "kopf.achs_nr" if "kopf.achs_nr" in e else "kopf.log_achs_nr", path)
            slave = letter.get(nr, str(nr))
        for prefix in ("kw.ssfk", "kw.crosscomp", "kw.crosscomp2"):
            if f"{prefix}.unit" in e and _int(e, f"{prefix}.unit", path) != 1:
                raise ParseError(
                    path, e[f"{prefix}.unit"][1], f"{prefix}.unit: esp reads 1 (0.1 µm)"
                )
        if "kw.ssfk.kw_nr_max" in e:
            n = _int(e, "kw.ssfk.kw_nr_max", path)
            if _int(e, "kw.ssfk.interval", path) != 0:
                raise ParseError(path, e["kw.ssfk.interval"][1], "esp reads interval 0 lists")
            setpoints = _series(e, "kw.ssfk", "setpoint", n, path)
            pos = _series(e, "kw.ssfk", "pos", n, path)
            bil = _int(e, "kw.ssfk.bilateral", path) if "kw.ssfk.bilateral" in e else 0
            neg = _series(e, "kw.ssfk", "neg", n, path) if bil else pos
            axis_tables.append(
                AxisTable(slave, slave, setpoints * 1e-4, -pos * _UNIT_UM, -neg * _UNIT_UM, "lead")
            )
        if "kw.crosscomp.last_index" in e:
            n = _int(e, "kw.crosscomp.last_index", path) + 1
            master_nr = _int(e, "kw.crosscomp.master_ax_nr", path)
            setpoints = _series(e, "kw.crosscomp", "setpoint", n, path)
            corr = sign * _series(e, "kw.crosscomp", "correction", n, path) * _UNIT_UM
            axis_tables.append(
                AxisTable(
                    slave,
                    letter.get(master_nr, str(master_nr)),
                    setpoints * 1e-4,
                    corr,
                    corr,
                    "cross",
                )
            )
        if "kw.crosscomp2.interval" in e:
            step = _int(e, "kw.crosscomp2.interval", path) * 1e-4
            na = _int(e, "kw.crosscomp2.last_index_master1", path) + 1
            nb = _int(e, "kw.crosscomp2.last_index_master2", path) + 1
            a0 = _int(e, "kw.crosscomp2.start_position_master1", path) * 1e-4
            b0 = _int(e, "kw.crosscomp2.start_position_master2", path) * 1e-4
            m1 = letter.get(_int(e, "kw.crosscomp2.master1_ax_nr", path))
            m2 = letter.get(_int(e, "kw.crosscomp2.master2_ax_nr", path))
            values = np.array(
                [
                    [_int(e, f"kw.crosscomp2.table[{j}][{i}].correction", path) for i in range(na)]
                    for j in range(nb)
                ],
                dtype=float,
            )
            plane_tables.append(
                PlaneTable(
                    slave,
                    (str(m1), str(m2)),
                    a0 + step * np.arange(na),
                    b0 + step * np.arange(nb),
                    sign * values * _UNIT_UM,
                )
            )
    fmt = "twincat-plane" if plane_tables else "twincat-cross"
    if not plane_tables and all(t.kind == "lead" for t in axis_tables):
        fmt = "twincat-lead"
    return CompensationSet(fmt, axis_tables=tuple(axis_tables), plane_tables=tuple(plane_tables))


class TwinCAT(Format):
    """The ISG axis compensation lists: leadscrew alone, with cross or with plane tables."""

    limit_defaults = LIMITS

    load_words = "the .lis files are the ISG axis compensation lists (kw.ssfk.*) of each axis"
    capabilities = Capabilities(frozenset({"lead"}), bidirectional=True)

    def __init__(
        self, name: str, description: str, load_words: str, tables: frozenset[str], order: int
    ) -> None:
        self.name = name
        self.description = description
        self.load_words = load_words
        self.order = order
        kinds = {"linear"} | ({"straightness", "squareness"} if len(tables) > 1 else set())
        self.capabilities = Capabilities(tables, error_kinds=frozenset(kinds), bidirectional=True)

    def limits(self, settings: FormatSettings) -> Limits:
        lim = {**LIMITS, **settings.limits}
        return Limits(
            points_per_table=lim["ssfk"],
            plane_points=lim["crosscomp2"] if "plane" in self.capabilities.tables else None,
            equidistant="plane" in self.capabilities.tables,
        )

    def write(self, cset: CompensationSet, settings: FormatSettings) -> dict[str, str]:
        return write(cset, settings.axis_numbers, settings.limits, settings.cross_sign)

    def read(self, files: Mapping[str, str], settings: FormatSettings) -> CompensationSet:
        return read(files, settings.axis_numbers, settings.cross_sign)

    def resolution_um(self, settings: FormatSettings) -> float:
        return _UNIT_UM


FORMATS = (
    TwinCAT(
        "twincat-lead",
        "TwinCAT CNC / ISG leadscrew error compensation lists (kw.ssfk.*)",
        "the .lis files are the ISG axis compensation lists (kw.ssfk.*) of each axis",
        frozenset({"lead"}),
        20,
    ),
    TwinCAT(
        "twincat-cross",
        "TwinCAT CNC / ISG leadscrew and cross compensation (kw.ssfk, kw.crosscomp)",
        "the .lis files are the ISG leadscrew lists (kw.ssfk.*) and cross "
        "compensation lists (kw.crosscomp.*)",
        frozenset({"lead", "cross"}),
        21,
    ),
    TwinCAT(
        "twincat-plane",
        "TwinCAT CNC / ISG leadscrew and plane compensation (kw.ssfk, kw.crosscomp2)",
        "the .lis files are the ISG leadscrew lists (kw.ssfk.*) and plane "
        "compensation lists (kw.crosscomp2.*)",
        frozenset({"lead", "plane"}),
        22,
    ),
)
