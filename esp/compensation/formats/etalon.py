"""The Etalon Exchange format ("Vendor" variant), which the TwinCAT CNC / ISG volumetric
compensation imports: every ISO 230-1 parameter in a block of its own.

What the Beckhoff documentation (TF5280 Volumetric Compensation, "Etalon Exchange
Format" and "Units of measure"; cited in docs/compensation.md) says and how esp reads it:

* similar to a Windows INI file; ``//`` starts a comment (to the end of the line);
* every parameter is a block that begins with its name in square brackets: position
  errors (``[C0Y]``) hold ``VALUE = number``; component errors (``[EXY]``, the X error
  of the Y axis as a function of Y) hold a lookup table ``Gridpoints = { ... }``, one
  record per line, closed by ``}``;
* parameter names as in the ISG CSV format (DIN ISO 230); units as for every format of
  the volumetric compensation: offsets in mm, angles in rad, arguments in mm;
* the records of the example are "argument value" (``-280.0 -0.001358635132``) while its
  comment says "Parameter argument": esp writes and reads argument first, as the numbers
  show (``etalon-columns=value-argument`` swaps them);
* Etalon offers a "Vendor" and a "Kinematic" variant; the ISG imports the "Vendor" one,
  which esp writes.

:func:`parse_exchange` reads any file of this layout into its blocks (name -> a value or
a table) and knows nothing of compensation, so that an Etalon file can later be read as
esp input too.

The values are the errors (as in :mod:`~esp.compensation.formats.isg_volumetric`); the
controller computes the correction with its kinematic model.

This module imports only numpy and the standard library.
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from esp.compensation.formats.base import Capabilities, Format, FormatSettings
from esp.compensation.formats.isg_volumetric import (
    DECIMALS_MM,
    DECIMALS_RAD,
    iso_symbol,
    name_of,
    scale,
)
from esp.compensation.model import CompensationSet, ComponentTable
from esp.core.errors import DataError, ParseError
from esp.core.names import ComponentName

__all__ = ["FILE", "FORMATS", "Block", "parse_exchange", "read", "write"]

FILE = "etalon_exchange.txt"
OPTIONS = {"etalon-columns": ("argument-value", "value-argument")}


@dataclass(frozen=True)
class Block:
    """One parameter of an exchange file: ``value`` (a position error) or ``table``
    (shape (n, 2): the records as written), and the line where it begins."""

    name: str
    line: int
    value: float | None = None
    table: np.ndarray | None = None


_HEADER = re.compile(r"^\[([A-Za-z0-9_]+)\]$")
_VALUE = re.compile(r"^VALUE\s*=\s*(\S+)$", re.IGNORECASE)
_GRID = re.compile(r"^Gridpoints\s*=\s*\{$", re.IGNORECASE)


def _number(text: str, path: str, line: int) -> float:
    try:
        value = float(text)
    except ValueError:
        raise ParseError(path, line, f"expected a number, found {text!r}") from None
    if not np.isfinite(value):
        raise ParseError(path, line, f"expected a finite number, found {text!r}")
    return value


def parse_exchange(text: str, path: str) -> dict[str, Block]:
    """The blocks of an exchange file by name, in file order; ParseError naming the file
    and line for anything else."""
    blocks: dict[str, Block] = {}
    name: str | None = None
    start = 0
    rows: list[list[float]] | None = None
    seen: dict[str, int] = {}
    for number, raw in enumerate(text.splitlines(), start=1):
        line = raw.split("//", 1)[0].strip()
        if not line:
            continue
        if rows is not None:  # inside Gridpoints = { ... }
            if line == "}":
                assert name is not None
                if len(rows) < 2:
                    raise ParseError(path, number, f"[{name}]: expected at least 2 records")
                blocks[name] = Block(name, start, table=np.array(rows))
                rows, name = None, None
                continue
            cells = line.split()
            if len(cells) != 2:
                raise ParseError(path, number, f"expected two numbers, found {line[:60]!r}")
            rows.append([_number(c, path, number) for c in cells])
            continue
        m = _HEADER.match(line)
        if m:
            if name is not None:
                raise ParseError(path, start, f"[{name}] holds neither VALUE nor Gridpoints")
            name, start = m.group(1), number
            if name in seen:
                raise ParseError(path, number, f"[{name}] is given twice (line {seen[name]})")
            seen[name] = number
            continue
        if name is None:
            raise ParseError(path, number, f"expected [PARAMETER], found {line[:60]!r}")
        m = _VALUE.match(line)
        if m:
            blocks[name] = Block(name, start, value=_number(m.group(1), path, number))
            name = None
            continue
        if _GRID.match(line):
            rows = []
            continue
        raise ParseError(path, number, f"expected VALUE = or Gridpoints = {{, found {line[:60]!r}")
    if rows is not None:
        raise ParseError(path, None, f"[{name}]: Gridpoints not closed by }}")
    if name is not None:
        raise ParseError(path, start, f"[{name}] holds neither VALUE nor Gridpoints")
    return blocks


def _fmt(value: float, decimals: int) -> str:
    return f"{round(float(value), decimals) + 0.0:.{decimals}f}"


def write(cset: CompensationSet, settings: FormatSettings | None = None) -> dict[str, str]:
    """The text of ``etalon_exchange.txt``: the squareness as position errors, every
    component as its lookup table."""
    s = settings or FormatSettings()
    table = cset.component_table
    if table is None:
        raise DataError("the etalon format needs a component table")
    swap = s.option("etalon-columns", "argument-value") == "value-argument"
    lines = [
        "// Etalon Exchange format (Vendor variant) written by esp",
        "// units: arguments and offsets in mm, angles in rad; values are errors",
    ]
    for name in sorted(table.squareness):
        value = ComponentName.parse(name).iso_sign * table.squareness[name] * 1e-6
        lines += [f"[{iso_symbol(name)}]", f"VALUE = {_fmt(value, DECIMALS_RAD)}"]
    for name in sorted(table.curves, key=iso_symbol):
        factor, decimals = scale(name)
        positions, values = table.curves[name]
        lines += [f"[{iso_symbol(name)}]", "Gridpoints = {"]
        for p, v in zip(positions, values, strict=True):
            cells = [_fmt(p, DECIMALS_MM), _fmt(v * factor, decimals)]
            lines.append("    " + " ".join(reversed(cells) if swap else cells))
        lines.append(f"}}  // end of {iso_symbol(name)}")
    return {FILE: "\n".join(lines) + "\n"}


def read(files: Mapping[str, str], settings: FormatSettings | None = None) -> CompensationSet:
    """Read ``etalon_exchange.txt`` back into a component table (esp's units)."""
    s = settings or FormatSettings()
    swap = s.option("etalon-columns", "argument-value") == "value-argument"
    if FILE not in files:
        raise ParseError(FILE, None, "missing")
    curves: dict[str, tuple[np.ndarray, np.ndarray]] = {}
    squareness: dict[str, float] = {}
    for symbol, block in parse_exchange(files[FILE], FILE).items():
        try:
            name = name_of(symbol)
        except DataError as exc:
            raise ParseError(FILE, block.line, str(exc)) from None
        if name.startswith("squareness"):
            if block.value is None:
                raise ParseError(FILE, block.line, f"[{symbol}] expects VALUE")
            squareness[name] = ComponentName.parse(name).iso_sign * block.value * 1e6
            continue
        if block.table is None:
            raise ParseError(FILE, block.line, f"[{symbol}] expects Gridpoints")
        t = block.table[:, ::-1] if swap else block.table
        if not np.all(np.diff(t[:, 0]) > 0):
            raise ParseError(FILE, block.line, f"[{symbol}]: arguments must increase strictly")
        curves[name] = (t[:, 0], t[:, 1] / scale(name)[0])
    return CompensationSet("etalon", component_table=ComponentTable(curves, squareness))


class Etalon(Format):
    """The Etalon Exchange format of the ISG volumetric compensation."""

    name = "etalon"
    description = (
        "Etalon Exchange format (Vendor variant), imported by the ISG volumetric compensation"
    )
    load_words = (
        "etalon_exchange.txt is an Etalon Exchange file (Vendor variant) for the ISG "
        "volumetric compensation (TF5280)"
    )
    order = 31
    capabilities = Capabilities(
        frozenset({"component"}),
        error_kinds=frozenset({"linear", "straightness", "angular", "squareness"}),
    )
    format_options = OPTIONS

    def write(self, cset: CompensationSet, settings: FormatSettings) -> dict[str, str]:
        return write(cset, settings)

    def read(self, files: Mapping[str, str], settings: FormatSettings) -> CompensationSet:
        return read(files, settings)

    def resolution_um(self, settings: FormatSettings) -> float:
        return 1000.0 * 10.0**-DECIMALS_MM


FORMATS = (Etalon(),)
