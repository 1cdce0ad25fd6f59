"""LinuxCNC joint compensation files (``[JOINT_n] COMP_FILE`` and ``COMP_FILE_TYPE``).

What the LinuxCNC documentation and its motion controller say (docs/compensation.md cites
the INI configuration chapter and the source files):

* one file per joint; every line holds three numbers separated by white space: the
  nominal (commanded) position, then two values whose meaning ``COMP_FILE_TYPE`` sets;
  values are in machine units (``[TRAJ] LINEAR_UNITS``, mm or inch);
* type 0: the actual position reached when moving in the positive direction, then when
  moving in the negative direction; the loader turns them into trims
  ``nominal - actual``;
* type 1: the trims themselves, ``nominal - actual``, for the positive and the negative
  direction (the loader's comment: ``forward_trim = nominal - forward``);
* the trim of the current direction of motion is interpolated linearly between the
  nominal positions and added to the joint's motor command; before the first and after the
  last nominal the end trim is held;
* nominal positions must increase strictly, at most 256 lines per joint
  (``EMCMOT_COMP_SIZE``); the loader stops at the first line that does not hold three
  numbers, so the file carries no comment lines;
* when a ``COMP_FILE`` is given, ``BACKLASH`` is not used: the reversal goes into the
  difference of the two columns.

A trim is esp's correction (µm, added to the command), so type 1 writes the corrections
and type 0 the nominal minus them.

This module imports only numpy and the standard library.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from esp.compensation.formats.base import Capabilities, Format, FormatSettings, Limits
from esp.compensation.model import AxisTable, CompensationSet
from esp.core.errors import DataError, ParseError

__all__ = ["FORMATS", "MAX_POINTS", "UNITS", "read", "write"]

#: EMCMOT_COMP_SIZE of the LinuxCNC motion controller
MAX_POINTS = 256
#: machine unit -> (µm per unit, decimals written)
UNITS = {"mm": (1000.0, 6), "inch": (25400.0, 7)}
README = "README.txt"


def _unit(units: str) -> tuple[float, int]:
    if units not in UNITS:
        raise DataError(f"--linuxcnc-units: expected one of {', '.join(UNITS)}, found {units!r}")
    return UNITS[units]


def _file_name(axis: str) -> str:
    return f"{axis}.comp"


def write(cset: CompensationSet, comp_type: int = 1, units: str = "mm") -> dict[str, str]:
    """The text of every file: one ``<axis>.comp`` per leadscrew table and a README.

    Raises
    ------
    DataError
        A table of more than :data:`MAX_POINTS` points, or nominal positions that do not
        increase strictly at the written resolution.
    """
    if comp_type not in (0, 1):
        raise DataError(f"--linuxcnc-type: expected 0 or 1, found {comp_type!r}")
    um_per_unit, decimals = _unit(units)
    files: dict[str, str] = {}
    lines_readme = [
        "LinuxCNC joint compensation files written by esp.",
        "",
        f"COMP_FILE_TYPE {comp_type}; values in {units} ([TRAJ] LINEAR_UNITS must be {units}).",
        "Each line: nominal position, then "
        + (
            "the actual position moving up and moving down."
            if comp_type == 0
            else "the trim (nominal - actual) moving up and moving down."
        ),
        "BACKLASH is not used when COMP_FILE is given: the reversal is in the two columns.",
        "Both columns are referred to one datum, so they differ by the measured reversal",
        "everywhere, the datum included.",
        "",
        "Add to the INI file, in the section of the joint that drives each axis:",
    ]
    for table in cset.axis_tables:
        if table.kind != "lead":
            continue
        n = table.positions_mm.size
        if n > MAX_POINTS:
            raise DataError(
                f"the {table.slave} table has {n} points; LinuxCNC takes at most {MAX_POINTS} "
                f"per joint (EMCMOT_COMP_SIZE): choose a larger --spacing"
            )
        nominal = np.round(table.positions_mm * 1000.0 / um_per_unit, decimals)
        if not np.all(np.diff(nominal) > 0):
            raise DataError(
                f"the {table.slave} table's nominal positions do not increase strictly at "
                f"{decimals} decimals of {units}"
            )
        fwd = table.forward_um / um_per_unit
        bwd = table.backward_um / um_per_unit
        if comp_type == 0:
            fwd, bwd = nominal - fwd, nominal - bwd
        # round first, then add 0.0 so that no "-0.000000" is written
        fwd, bwd = np.round(fwd, decimals) + 0.0, np.round(bwd, decimals) + 0.0
        rows = [
            f"{p:.{decimals}f} {f:.{decimals}f} {b:.{decimals}f}"
            for p, f, b in zip(nominal, fwd, bwd, strict=True)
        ]
        name = _file_name(table.slave)
        files[name] = "\n".join(rows) + "\n"
        lines_readme.append(f"  {table.slave}: COMP_FILE = {name}  COMP_FILE_TYPE = {comp_type}")
    files[README] = "\n".join(lines_readme) + "\n"
    return files


def _parse(text: str, path: str) -> np.ndarray:
    rows = []
    for number, line in enumerate(text.splitlines(), start=1):
        if not line.strip():
            continue
        fields = line.split()
        if len(fields) != 3:
            raise ParseError(path, number, f"expected three numbers, found {len(fields)} fields")
        try:
            row = [float(f) for f in fields]
        except ValueError:
            raise ParseError(
                path, number, f"expected three numbers, found {line.strip()!r}"
            ) from None
        if not all(np.isfinite(row)):
            raise ParseError(path, number, "expected finite numbers")
        rows.append(row)
    if len(rows) < 2:
        raise ParseError(path, None, f"expected at least 2 lines, found {len(rows)}")
    if len(rows) > MAX_POINTS:
        raise ParseError(path, None, f"{len(rows)} lines; LinuxCNC takes at most {MAX_POINTS}")
    data = np.array(rows)
    if not np.all(np.diff(data[:, 0]) > 0):
        raise ParseError(path, None, "nominal positions must increase strictly")
    return data


def read(files: Mapping[str, str], comp_type: int = 1, units: str = "mm") -> CompensationSet:
    """Read ``<axis>.comp`` texts back into leadscrew tables (corrections in µm)."""
    um_per_unit, _ = _unit(units)
    tables = []
    for name in sorted(files):
        if not name.endswith(".comp"):
            continue
        axis = name[: -len(".comp")]
        data = _parse(files[name], name)
        nominal, a, b = data[:, 0], data[:, 1], data[:, 2]
        if comp_type == 0:
            a, b = nominal - a, nominal - b
        tables.append(
            AxisTable(
                axis,
                axis,
                nominal * um_per_unit / 1000.0,
                a * um_per_unit,
                b * um_per_unit,
                "lead",
            )
        )
    return CompensationSet("linuxcnc", axis_tables=tuple(tables))


class LinuxCNC(Format):
    """LinuxCNC joint compensation files."""

    name = "linuxcnc"
    description = "LinuxCNC joint compensation files (COMP_FILE, nominal/forward/reverse)"
    load_words = (
        "name each axis' file as COMP_FILE (with COMP_FILE_TYPE) in the [JOINT_n] "
        "section of the INI file; README.txt in the folder has the lines"
    )
    order = 10
    capabilities = Capabilities(frozenset({"lead"}), bidirectional=True)

    def limits(self, settings: FormatSettings) -> Limits:
        return Limits(points_per_table=MAX_POINTS)

    def write(self, cset: CompensationSet, settings: FormatSettings) -> dict[str, str]:
        return write(cset, settings.linuxcnc_type, settings.linuxcnc_units)

    def read(self, files: Mapping[str, str], settings: FormatSettings) -> CompensationSet:
        return read(files, settings.linuxcnc_type, settings.linuxcnc_units)

    def resolution_um(self, settings: FormatSettings) -> float:
        um, decimals = _unit(settings.linuxcnc_units)
        return um * 10.0**-decimals


FORMATS = (LinuxCNC(),)
