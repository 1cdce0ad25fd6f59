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

:func:`esp.io.etalon.parse_exchange` reads any file of this layout into its blocks (name
-> a value or a table) and knows nothing of compensation.

The values are the errors (as in :mod:`~esp.compensation.formats.isg_volumetric`); the
controller computes the correction with its kinematic model.

This module imports only numpy and the standard library.
"""

from __future__ import annotations

from collections.abc import Mapping

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
from esp.io.etalon import Block, parse_exchange

__all__ = ["FILE", "FORMATS", "Block", "parse_exchange", "read", "write"]

FILE = "etalon_exchange.txt"
OPTIONS = {"etalon-columns": ("argument-value", "value-argument")}


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
