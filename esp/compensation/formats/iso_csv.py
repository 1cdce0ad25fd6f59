"""A plain CSV of the ISO 230-1 component errors, for controllers whose import tools map
columns (esp's own exchange format; no vendor defines it).

One file per axis, ``<axis>.csv``, with the columns ``position_mm`` and the six error
motions of that axis named after ISO 230-1:2012 (3.4): ``EXX_um, EYX_um, EZX_um`` (the
positioning error and the two straightnesses, µm) and ``EAX_urad, EBX_urad, ECX_urad``
(the rotations about X, Y, Z, µrad = µm/m); and ``squareness.csv`` with one row per
squareness (``component,iso,value_urad``: ``squareness.XY,EC0Y,4.5``). Lines starting with
``#`` are comments; a component that was not measured has empty cells. The values are
the errors as esp's engine uses them (actual - nominal; straightness with its set-up slope
removed); a compensation value is their negative. Resolution written: 0.001 µm and
0.001 µrad.

This module imports only numpy and the standard library.
"""

from __future__ import annotations

import csv
import io
from collections.abc import Mapping

import numpy as np

from esp.compensation.formats.base import Capabilities, Format, FormatSettings
from esp.compensation.model import CompensationSet, ComponentTable
from esp.core.errors import DataError, ParseError
from esp.core.names import ComponentName

__all__ = ["FORMATS", "SQUARENESS_FILE", "columns", "read", "write"]

SQUARENESS_FILE = "squareness.csv"
DECIMALS = 3
_ROT = {"X": "A", "Y": "B", "Z": "C"}


def columns(axis: str) -> list[tuple[str, str]]:
    """(column, component name) of the six error motions of ``axis``."""
    out = []
    for d in "XYZ":
        name = f"{axis}.linear" if d == axis else f"{axis}.straightness.{d}"
        out.append((f"E{d}{axis}_um", name))
    for d in "XYZ":
        out.append((f"E{_ROT[d]}{axis}_urad", f"{axis}.angular.{d}"))
    return out


def _fmt(value: float, decimals: int) -> str:
    return f"{round(float(value), decimals) + 0.0:.{decimals}f}"


def _iso_squareness(name: str) -> str:
    a, b = tuple(name.split(".")[1])  # the pair's two letters (ValueError if not two)
    third = next(n for n in "XYZ" if n not in (a, b))
    return f"E{_ROT[third]}0{b}"


def write(cset: CompensationSet, machine_name: str = "") -> dict[str, str]:
    """The text of ``X.csv``, ``Y.csv``, ``Z.csv`` (the axes with components) and
    ``squareness.csv``."""
    table = cset.component_table
    if table is None:
        raise DataError("the iso-csv format needs a component table")
    files = {}
    for axis in "XYZ":
        cols = columns(axis)
        present = [(c, n) for c, n in cols if n in table.curves]
        if not present:
            continue
        positions = table.curves[present[0][1]][0]
        for _, n in present[1:]:
            if not np.array_equal(table.curves[n][0], positions):
                raise DataError(f"{n}: the components of axis {axis} must share their table points")
        out = io.StringIO()
        out.write(
            f"# ISO 230-1 component errors of the {axis} axis"
            f"{' of ' + machine_name if machine_name else ''}\n"
        )
        out.write("# written by esp; error = actual - nominal, the compensation is its negative\n")
        out.write("# units: position mm, E?? um, EA?/EB?/EC? urad (um/m); empty = not measured\n")
        w = csv.writer(out, lineterminator="\n")
        w.writerow(["position_mm"] + [c for c, _ in cols])
        for i, p in enumerate(positions):
            row = [_fmt(p, 4)]
            for _, n in cols:
                row.append(_fmt(table.curves[n][1][i], DECIMALS) if n in table.curves else "")
            w.writerow(row)
        files[f"{axis}.csv"] = out.getvalue()
    out = io.StringIO()
    out.write("# squareness errors (ISO 230-1 location errors), urad = um/m\n")
    w = csv.writer(out, lineterminator="\n")
    w.writerow(["component", "iso", "value_urad"])
    for name in sorted(table.squareness):
        value = ComponentName.parse(name).iso_sign * table.squareness[name]  # in ISO signs
        w.writerow([name, _iso_squareness(name), _fmt(value, DECIMALS)])
    files[SQUARENESS_FILE] = out.getvalue()
    return files


def _rows(text: str, path: str) -> tuple[tuple[int, list[str]], list[tuple[int, list[str]]]]:
    lines = [(i, line) for i, line in enumerate(text.splitlines(), start=1)]
    body = [(i, line) for i, line in lines if line.strip() and not line.lstrip().startswith("#")]
    if not body:
        raise ParseError(path, None, "no header line")
    reader = csv.reader([line for _, line in body])
    numbered = [(i, row) for (i, _), row in zip(body, reader, strict=True)]
    return numbered[0], numbered[1:]


def read(files: Mapping[str, str]) -> CompensationSet:
    """Read the CSV texts back into a component table (µm and µm/m)."""
    curves: dict[str, tuple[np.ndarray, np.ndarray]] = {}
    squareness: dict[str, float] = {}
    for path in sorted(files):
        text = files[path]
        if path == SQUARENESS_FILE:
            (line, header), rows = _rows(text, path)
            if header != ["component", "iso", "value_urad"]:
                raise ParseError(path, line, f"expected component,iso,value_urad, found {header}")
            for number, row in rows:
                if len(row) != 3 or not row[0].startswith("squareness."):
                    raise ParseError(path, number, f"expected a squareness row, found {row}")
                if _iso_squareness(row[0]) != row[1]:
                    raise ParseError(
                        path, number, f"{row[0]} is {_iso_squareness(row[0])}, not {row[1]}"
                    )
                try:
                    squareness[row[0]] = ComponentName.parse(row[0]).iso_sign * float(row[2])
                except ValueError:
                    raise ParseError(path, number, f"expected a number, found {row[2]!r}") from None
            continue
        if not path.endswith(".csv") or path[0] not in "XYZ" or len(path) != 5:
            continue
        axis = path[0]
        cols = columns(axis)
        (line, header), rows = _rows(text, path)
        expected = ["position_mm"] + [c for c, _ in cols]
        if header != expected:
            raise ParseError(path, line, f"expected the columns {','.join(expected)}")
        data = []
        for number, row in rows:
            if len(row) != len(expected):
                raise ParseError(path, number, f"expected {len(expected)} cells, found {len(row)}")
            try:
                data.append([float(c) if c.strip() else np.nan for c in row])
            except ValueError:
                raise ParseError(path, number, f"expected numbers, found {row}") from None
        arr = np.array(data, dtype=float)
        if np.any(np.isnan(arr[:, 0])):
            raise ParseError(path, None, "every row needs a position")
        for k, (_, name) in enumerate(cols, start=1):
            col = arr[:, k]
            if np.all(np.isnan(col)):
                continue
            if np.any(np.isnan(col)):
                raise ParseError(path, None, f"{name}: some rows are empty")
            curves[name] = (arr[:, 0], col)
    return CompensationSet("iso-csv", component_table=ComponentTable(curves, squareness))


class IsoCsv(Format):
    """esp's plain CSV of the ISO 230-1 components."""

    name = "iso-csv"
    description = "plain CSV of the ISO 230-1 component errors of each axis and the squareness"
    load_words = (
        "a plain CSV of the components with ISO 230-1 names, for a controller's "
        "import tool that maps columns"
    )
    order = 90
    capabilities = Capabilities(
        frozenset({"component"}),
        error_kinds=frozenset({"linear", "straightness", "angular", "squareness"}),
    )

    def write(self, cset: CompensationSet, settings: FormatSettings) -> dict[str, str]:
        return write(cset, settings.machine_name)

    def read(self, files: Mapping[str, str], settings: FormatSettings) -> CompensationSet:
        return read(files)

    def resolution_um(self, settings: FormatSettings) -> float:
        return 10.0**-DECIMALS


FORMATS = (IsoCsv(),)
