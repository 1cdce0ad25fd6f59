"""The file of measured differences that solves a protocol (``esp head --measured FILE``).

A small CSV, one row per test of the protocol::

    # angle head, protocol with DY and ThetaAv assumed zero
    test,axis,A1,C1,A2,C2,difference_um
    1,X,90,0,270,180,10.0
    2,Z,0,0,0,180,-4.85

* ``test`` (required): the test's number in the protocol;
* ``difference_um`` (required; or ``difference_mm``): the measured difference, the tool
  tip's error in the test's direction at the first setting minus that at the second (the
  measured position less the nominal one, at each setting);
* ``axis`` and the settings ``A1, C1, A2, C2`` (one column per head axis and setting,
  named after the head's coordinates) are optional; when present they must be those of the
  protocol's test, so that a file made for another protocol is refused.

Lines starting with ``#`` are comments. Every test of the protocol needs a row; a row for
a test the protocol does not hold, a repeated test, a number that does not parse or is not
finite is an error naming the file and line.
"""

from __future__ import annotations

import csv
import io
import os
from pathlib import Path

from esp.core.errors import DataError, ParseError
from esp.core.text import did_you_mean
from esp.core.values import ValueRefused, parse
from esp.heads.protocol import Protocol
from esp.io.textfile import read_utf8

__all__ = ["read_measured"]

_MAX_BYTES = 1024 * 1024


def _number(p: Path, line: int, column: str, text: str) -> float:
    try:  # a measured difference in µm: within ±10 mm, decimal digits only (no 1_000)
        return parse(text, "displacement")
    except ValueRefused as exc:
        raise ParseError(p, line, f"{column}: {exc.message}") from None


def read_measured(path: str | os.PathLike[str], protocol: Protocol) -> dict[int, float]:
    """The measured differences of a protocol's tests, µm.

    Raises
    ------
    ParseError
        The file cannot be read, its header lacks ``test`` or ``difference_um``, a row does
        not parse, names a test the protocol does not hold, repeats a test, or its axis or
        settings are not those of the protocol's test (file and line).
    DataError
        A test of the protocol has no row.
    """
    p = Path(path)
    text = read_utf8(p, _MAX_BYTES, "CSV file of measured differences")
    rows = [
        (i, line)
        for i, line in enumerate(text.splitlines(), 1)
        if line.strip() and not line.lstrip().startswith("#")
    ]
    if not rows:
        raise ParseError(p, None, "expected a header 'test,difference_um' and one row per test")
    settings_cols = [f"{c}{k}" for k in (1, 2) for c in protocol.coordinates]
    allowed = ("test", "axis", "difference_um", "difference_mm", *settings_cols)
    hline, header = rows[0]
    cols = [c.strip() for c in next(csv.reader([header]))]
    for c in cols:
        if c not in allowed:
            raise ParseError(
                p,
                hline,
                f"unknown column {c!r}{did_you_mean(c, allowed)} (expected test, difference_um and "
                f"optionally axis, {', '.join(settings_cols)})",
            )
    if len(set(cols)) != len(cols):
        raise ParseError(p, hline, "a column is named twice")
    if "test" not in cols:
        raise ParseError(p, hline, f"expected a column 'test', found {header!r}")
    value_cols = [c for c in cols if c.startswith("difference_")]
    if len(value_cols) != 1:
        raise ParseError(
            p, hline, f"expected one column 'difference_um' (or 'difference_mm'), found {header!r}"
        )
    value_col = value_cols[0]
    scale = 1000.0 if value_col == "difference_mm" else 1.0
    numbers = {t.number for t in protocol.tests}
    out: dict[int, float] = {}
    for line_no, line in rows[1:]:
        cells = [c.strip() for c in next(csv.reader(io.StringIO(line)))]
        if len(cells) != len(cols):
            raise ParseError(p, line_no, f"expected {len(cols)} columns, found {len(cells)}")
        row = dict(zip(cols, cells, strict=True))
        try:
            number = int(row["test"])
        except ValueError:
            raise ParseError(
                p, line_no, f"test: expected a test number, found {row['test']!r}"
            ) from None
        if number not in numbers:
            raise ParseError(
                p,
                line_no,
                f"test {number} is not in the protocol (tests 1 to {len(protocol.tests)}); the "
                "file does not match this protocol",
            )
        if number in out:
            raise ParseError(p, line_no, f"test {number} is given twice")
        test = protocol.test(number)
        if "axis" in row and row["axis"].upper() != test.axis:
            raise ParseError(
                p,
                line_no,
                f"test {number}: axis {row['axis']!r}, but the protocol's test {number} "
                f"measures {test.axis}; the file does not match this protocol",
            )
        for k, setting in ((1, test.first), (2, test.second)):
            for c in protocol.coordinates:
                col = f"{c}{k}"
                if col in row:
                    v = _number(p, line_no, col, row[col])
                    if abs(((v - setting[c]) + 180.0) % 360.0 - 180.0) > 1e-6:
                        raise ParseError(
                            p,
                            line_no,
                            f"test {number}: {col} = {v:g}, but the protocol's test {number} is "
                            f"at {col} = {setting[c]:g}; the file does not match this protocol",
                        )
        out[number] = _number(p, line_no, value_col, row[value_col]) * scale
    missing = [n for n in sorted(numbers) if n not in out]
    if missing:
        t = protocol.test(missing[0])
        more = f" (and {len(missing) - 1} more)" if len(missing) > 1 else ""
        raise DataError(
            f"{p}: test {t.number} ({t.symbol}) has no measured difference{more}; the protocol "
            f"has {len(protocol.tests)} tests"
        )
    return out
