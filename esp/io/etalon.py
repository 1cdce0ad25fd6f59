"""The Etalon Exchange file layout (the INI-like text that Etalon's LaserTRACER software
exports and the ISG volumetric compensation of TwinCAT (TF5280) imports), read into its
blocks without any meaning attached.

Layout (Beckhoff TF5280 Volumetric Compensation, "Etalon Exchange Format"): ``//`` starts
a comment to the end of the line; every parameter is a block that begins with its name in
square brackets; a position error holds ``VALUE = number``, a component error holds a
lookup table ``Gridpoints = { ... }`` with one record of two numbers per line, closed by
``}``. What the blocks mean (ISO 230-1 names, units, sign) is for the reader that uses
them: :mod:`esp.compensation.formats.etalon`.

This module imports only numpy and the standard library (besides esp's errors).
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from esp.core.errors import ParseError

__all__ = ["Block", "parse_exchange", "read_exchange"]


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


def read_exchange(path: str | Path) -> dict[str, Block]:
    """The blocks of the exchange file at ``path`` (:func:`parse_exchange`); OSError when
    it cannot be read, ParseError naming the file and line when it is not of the layout."""
    p = Path(path)
    try:
        text = p.read_text(encoding="utf-8-sig")
    except UnicodeDecodeError:
        raise ParseError(str(p), None, "expected a text file (UTF-8), found binary data") from None
    return parse_exchange(text, str(p))
