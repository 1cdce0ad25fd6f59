"""Tidy CSV tables of measurements for ``esp identify`` (docs/formats.md, "Measurements
for identification").

One row per reading, a header row naming the columns (any order, other columns ignored),
``#`` comments, comma delimiter (semicolons or tabs when the header has no comma). Every
number must parse and be finite; a problem names the file and the line.
"""

from __future__ import annotations

import math
import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from esp.core.errors import ParseError
from esp.core.units import DISPLACEMENT_LIMIT_UM, POSITION_LIMIT_MM
from esp.core.values import Quantity, ValueRefused, check, written
from esp.io.textfile import read_text, split_lines

__all__ = ["Table", "read_table"]

_FLOAT = r"[+-]?(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[eE][+-]?[0-9]+)?"
_FLOAT_RE = re.compile(rf"^{_FLOAT}$")
#: a whole column of numbers, one a line: checked in one match before the row by row loop
_COLUMN_RE = re.compile(rf"(?:{_FLOAT}\n)*{_FLOAT}")
#: the most rows one measurement table may hold
MAX_ROWS = 1_000_000
#: columns of positions in mm without a unit suffix (``X``, ``cx``, ``X1``...)
_POSITION_COLUMNS = frozenset({"X", "Y", "Z", "x", "y", "z", "cx", "cy", "cz"})


@dataclass(frozen=True)
class Table:
    """Columns of one table: name -> array (numbers) or tuple of str (labels); ``lines``
    the 1-based line number of each row."""

    path: str
    columns: dict
    lines: np.ndarray

    def __len__(self) -> int:
        return int(self.lines.size)

    def has(self, name: str) -> bool:
        return name in self.columns

    def fail(self, row: int | None, message: str) -> ParseError:
        return ParseError(self.path, None if row is None else int(self.lines[row]), message)


def _show(token: str) -> str:
    token = token.strip()
    return repr(token) if token else "nothing"


def read_table(
    path: str | Path,
    numbers: tuple[str, ...],
    labels: tuple[str, ...] = (),
    optional: tuple[str, ...] = (),
    optional_labels: tuple[str, ...] = (),
) -> Table:
    """Read ``path``: ``numbers`` and ``labels`` columns are required, ``optional`` number
    columns are read when present. Raises :class:`ParseError` naming file and line."""
    p = Path(path)
    text = read_text(p)
    rows: list[tuple[int, list[str]]] = []
    header: list[str] | None = None
    delimiter = ","
    for number, line in enumerate(split_lines(text), start=1):
        s = line.strip()
        if not s or s.startswith("#"):
            continue
        if header is None:
            if "," not in s:
                delimiter = ";" if ";" in s else ("\t" if "\t" in s else ",")
            header = [h.strip() for h in s.split(delimiter)]
            for c in (*numbers, *labels, *optional, *optional_labels):
                if header.count(c) > 1:
                    raise ParseError(
                        p, number, f"expected one column {c!r}, found {header.count(c)}"
                    )
            missing = [c for c in (*numbers, *labels) if c not in header]
            if missing:
                raise ParseError(
                    p,
                    number,
                    f"expected a header with the columns {', '.join((*numbers, *labels))}, "
                    f"missing {', '.join(missing)} (found {', '.join(header)})",
                )
            continue
        rows.append((number, line.split(delimiter)))
        if len(rows) > MAX_ROWS:
            raise ParseError(p, number, f"expected at most {MAX_ROWS} rows")
    if header is None:
        raise ParseError(p, None, "expected a header row and readings, found no header")
    if not rows:
        raise ParseError(p, None, "expected readings after the header, found none")
    index = {h: i for i, h in enumerate(header)}
    wanted_numbers = list(numbers) + [c for c in optional if c in index]
    columns: dict = {c: np.empty(len(rows)) for c in wanted_numbers}
    labels = labels + tuple(c for c in optional_labels if c in index)
    if _read_columns(rows, len(header), index, wanted_numbers, labels, columns):
        return _plausible(Table(str(p), columns, np.array([n for n, _ in rows])))
    label_values: dict = {c: [] for c in labels}
    for r, (number, cells) in enumerate(rows):
        if len(cells) < len(header):
            raise ParseError(
                p, number, f"expected {len(header)} values as in the header, found {len(cells)}"
            )
        for c in wanted_numbers:
            token = cells[index[c]].strip()
            if not _FLOAT_RE.match(token):
                raise ParseError(p, number, f"column {c}: expected a number, found {_show(token)}")
            value = float(token)
            if not math.isfinite(value):
                raise ParseError(
                    p, number, f"column {c}: expected a finite number, found {_show(token)}"
                )
            columns[c][r] = value
        for c in labels:
            token = cells[index[c]].strip()
            if not token:
                raise ParseError(p, number, f"column {c}: expected a label, found nothing")
            label_values[c].append(token)
    for c in labels:
        columns[c] = tuple(label_values[c])
    return _plausible(Table(str(p), columns, np.array([n for n, _ in rows])))


def _limit(column: str) -> tuple[float, str, str] | None:
    """The plausibility limit of a number column by its unit suffix or name (the limits
    of :mod:`esp.core.units`, as for every measurement file), its unit and what it is, or
    None."""
    if column == "reading_um":  # a distance a tracker reads, not an error
        return POSITION_LIMIT_MM * 1000.0, "um", "a reading"
    if column.endswith("_um"):
        return DISPLACEMENT_LIMIT_UM, "um", "a deviation"
    if column.endswith("_mm") or column.rstrip("0123456789") in _POSITION_COLUMNS:
        return POSITION_LIMIT_MM, "mm", "a position or length"
    return None


def _plausible(table: Table) -> Table:
    """``table`` when every number of a column with a limit (:func:`_limit`) lies within
    it; else a ParseError at the first reading beyond it, naming file, line and column,
    so that an absurd reading never reaches the fit as an overflow or an implausible
    curve."""
    for c, values in table.columns.items():
        limit = _limit(c)
        if limit is None or isinstance(values, tuple):
            continue
        beyond = np.flatnonzero(np.abs(values) > limit[0])
        if beyond.size:
            r = int(beyond[0])
            try:  # the one value check words the refusal
                check(
                    float(values[r]),
                    Quantity(limit[2], limit[1], -limit[0], limit[0]),
                    given=written(values[r]),
                )
            except ValueRefused as exc:
                raise table.fail(r, f"column {c}: {exc.message}") from None
    return table


def _read_columns(
    rows: Sequence[tuple[int, Sequence[str]]],
    width: int,
    index: Mapping[str, int],
    numbers: Sequence[str],
    labels: Sequence[str],
    columns: dict[str, np.ndarray | tuple[str, ...]],
) -> bool:
    """Read every column at once when the whole table is well formed (True); False leaves
    the row by row loop to find and name the first bad cell."""
    if any(len(cells) < width for _, cells in rows):
        return False
    out: dict = {}
    for c in numbers:
        tokens = [cells[index[c]].strip() for _, cells in rows]
        if not _COLUMN_RE.fullmatch("\n".join(tokens)):
            return False
        values = np.array(list(map(float, tokens)))
        if not np.isfinite(values).all():
            return False
        out[c] = values
    for c in labels:
        tokens = [cells[index[c]].strip() for _, cells in rows]
        if not all(tokens):
            return False
        out[c] = tuple(tokens)
    columns.update(out)
    return True
