"""What ``esp skew`` reads: the lengths of a square as options, and a table of points.

Lengths (``--xy AC,BD,AD[,AB]``, mm): the option given again adds another reading of each
length, so that their scatter enters the uncertainty.

The points table (docs/skew.md, "Points"): a CSV file whose header names the columns
``x_nominal``, ``y_nominal`` (, ``z_nominal``) and ``x_measured``, ``y_measured``
(, ``z_measured``), in any order and case, in mm; separated by commas, semicolons or tabs;
other columns (a ``point`` label) are ignored; ``#`` lines are comments, and ``# kind:
made`` or ``# kind: probed`` says what was measured (``--kind`` overrides it). A row that
cannot be read is refused at its file and line.
"""

from __future__ import annotations

import re
from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np

from esp.core.errors import ConfigError, ParseError
from esp.core.values import Quantity as Range
from esp.core.values import ValueRefused, parse
from esp.skew.model import AXES, Kind, Length, PointSet, Square

__all__ = ["LENGTH", "read_points", "squares"]

#: a length of a square (mm)
LENGTH = Range("a length", "mm", 0.0, 1e4, above_low=True)
_COORD = Range("a coordinate", "mm", -1e5, 1e5)
_NAMES = ("AC", "BD", "AD", "AB")


def _lengths(text: str, option: str) -> list[float]:
    cells = [c.strip() for c in text.split(",")]
    if len(cells) not in (3, 4):
        raise ConfigError(option, f"expected AC,BD,AD or AC,BD,AD,AB in mm, found {text!r}")
    out = []
    for name, cell in zip(_NAMES, cells, strict=False):
        try:
            out.append(parse(cell, LENGTH))
        except ValueRefused as exc:
            raise ConfigError(option, f"{name}: {exc.message}") from None
    return out


def squares(given: Mapping[str, Sequence[str]], nominal_mm: float | None) -> list[Square]:
    """The squares of ``{"XY": ["AC,BD,AD", ...], ...}`` (each string one set of readings)."""
    out = []
    for plane, texts in given.items():
        if not texts:
            continue
        option = f"--{plane.lower()}"
        sets = [_lengths(t, option) for t in texts]
        sizes = {len(s) for s in sets}
        if len(sizes) > 1:
            raise ConfigError(option, "expected every reading to give AB, or none")
        cols = list(zip(*sets, strict=True))
        lengths = [Length(name, tuple(col)) for name, col in zip(_NAMES, cols, strict=False)]
        ab = lengths[3] if len(lengths) == 4 else None
        out.append(Square(plane, lengths[0], lengths[1], lengths[2], ab, nominal_mm))
    return out


def _split(line: str) -> list[str]:
    for sep in (";", "\t", ","):
        if sep in line:
            return [c.strip() for c in line.split(sep)]
    return [c.strip() for c in line.split()]


_HEADER = re.compile(r"^([xyz])[ _-]?(nominal|measured)$")


def read_points(
    path: str | Path, kind: Kind | None = None, point_u_um: float | None = None
) -> PointSet:
    """The points of ``path``.

    Raises
    ------
    ParseError
        No header, a missing column, a cell that is not a number, a kind esp does not know.
    """
    p = Path(path)
    try:
        text = p.read_text(encoding="utf-8-sig")
    except UnicodeDecodeError:
        raise ParseError(p, None, "expected a UTF-8 text file") from None
    columns: dict[tuple[str, str], int] | None = None
    file_kind: str | None = None
    rows: list[list[float]] = []
    lines: list[int] = []
    order: list[tuple[str, str]] = []
    for number, raw in enumerate(text.splitlines(), start=1):
        line = raw.strip()
        if not line:
            continue
        if line.startswith("#"):
            word, sep, value = line[1:].partition(":")
            if sep and word.strip().lower() == "kind":
                file_kind = value.strip().lower()
                if file_kind not in ("made", "probed"):
                    raise ParseError(
                        p, number, f"expected kind made or probed, found {value.strip()!r}"
                    )
            continue
        cells = _split(line)
        if columns is None:
            columns = {}
            for i, cell in enumerate(cells):
                m = _HEADER.match(re.sub(r"\s*[(\[].*[)\]]\s*$", "", cell).strip().lower())
                if m:
                    named = (m.group(1).upper(), m.group(2))
                    if named in columns:
                        raise ParseError(p, number, f"column {cell!r} appears twice")
                    columns[named] = i
            axes = [ax for ax in AXES if (ax, "nominal") in columns]
            for ax in AXES:
                if ((ax, "nominal") in columns) != ((ax, "measured") in columns):
                    raise ParseError(
                        p,
                        number,
                        f"expected both {ax.lower()}_nominal and {ax.lower()}_measured, "
                        f"found only one",
                    )
            if len(axes) < 2:
                raise ParseError(
                    p,
                    number,
                    "expected a header naming x_nominal, y_nominal (z_nominal) and "
                    f"x_measured, y_measured (z_measured), found {line!r}",
                )
            order = [(ax, w) for w in ("nominal", "measured") for ax in axes]
            continue
        values = []
        for key in order:
            i = columns[key]
            if i >= len(cells) or not cells[i]:
                raise ParseError(p, number, f"expected {key[0].lower()}_{key[1]}, found nothing")
            try:
                values.append(parse(cells[i], _COORD))
            except ValueRefused as exc:
                raise ParseError(p, number, f"{key[0].lower()}_{key[1]}: {exc.message}") from None
        rows.append(values)
        lines.append(number)
    if columns is None:
        raise ParseError(p, None, "expected a header and points, found none")
    chosen = kind or file_kind
    if chosen is None:
        raise ParseError(p, None, "expected '# kind: made' or '# kind: probed' (or --kind)")
    d = len(order) // 2
    data = np.array(rows, dtype=float).reshape(-1, 2 * d)
    axes_t = tuple(ax for ax, _ in order[:d])
    return PointSet(
        axes_t,
        data[:, :d],
        data[:, d:],
        "made" if chosen == "made" else "probed",
        str(p),
        tuple(lines),
        point_u_um,
    )
