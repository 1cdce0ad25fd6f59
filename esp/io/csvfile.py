"""Read a measured error component from a plain "tidy" CSV file.

Any instrument's results can be brought in this way (API, Etalon, Keysight, Renishaw
CARTO/XCal-View exports): one row per reading, with a header row naming four columns,
in any order::

    # unit: um
    target_mm,run,direction,deviation
    0,1,forward,0.0
    250,1,forward,1.25
    250,2,backward,1.40
    0,2,backward,0.10

* ``target_mm``: nominal position in mm; ``run``: a whole number >= 1 naming the run;
  ``direction``: ``forward`` / ``backward`` (also ``+`` / ``-``, ``reverse``, ``fwd``,
  ``bwd``); ``deviation``: measured minus nominal, in the file's unit.
* Lines starting with ``#`` are comments. ``# unit: <unit>`` gives the unit of the
  deviations; ``# kind: <kind>``, ``# axis: <X|Y|Z>`` and ``# error_direction: <X|Y|Z>``
  may give the other properties. An argument to the reader wins over a comment, except
  the unit: a unit given that contradicts the ``# unit:`` comment is refused.
* The delimiter is a comma; a header with no comma but semicolons or tabs selects that
  delimiter. Other columns are ignored.

The checks are those of the Laser10 reader: every number parses and is finite, each run
has one direction, every run holds every target exactly once, there are two targets or
more (and at most :data:`~esp.io.laser10.MAX_READINGS` readings) at least 1 µm apart, and
every value lies within the plausibility limits of :mod:`esp.core.units` (targets within
±100 m, deviations within ±10 mm, angles within ±0.1 rad).

References
----------
ISO 230-2:2014, clause 2 (targets, runs, approach directions).
"""

from __future__ import annotations

import csv
import re
from pathlib import Path

import numpy as np

from esp.core.errors import DataError, ParseError
from esp.core.profile import ErrorProfile, normalise_direction
from esp.core.units import canonical_unit, flush_tiny
from esp.io.laser10 import (
    MAX_READINGS,
    MIN_TARGETS,
    check_axis,
    check_deviations,
    check_kind,
    check_spacing,
    convert_deviations,
    parse_position,
)
from esp.io.textfile import iter_lines, read_text

__all__ = ["COLUMNS", "parse_csv_profile", "read_csv_profile", "runs_table", "scan_table"]

#: the columns a profile CSV must have
COLUMNS = ("target_mm", "run", "direction", "deviation")
_FLOAT_RE = re.compile(r"^[+-]?(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[eE][+-]?[0-9]+)?$")
_INT_RE = re.compile(r"^\+?[0-9]{1,9}$")
_COMMENT_RE = re.compile(r"^#\s*([A-Za-z_][A-Za-z_ ]*?)\s*[:=]\s*(.*?)\s*$")
_COMMENT_KEYS = ("unit", "kind", "axis", "error_direction")


def _show(token: str) -> str:
    token = token.strip()
    if not token:
        return "nothing"
    return repr(token if len(token) <= 40 else token[:37] + "...")


def _float(token: str, path: str | Path | None, line: int, what: str) -> float:
    t = token.strip()
    if not _FLOAT_RE.match(t):
        raise ParseError(path, line, f"expected {what}, found {_show(token)}")
    value = float(t)
    if not np.isfinite(value):
        raise ParseError(path, line, f"expected {what} (a finite number), found {_show(token)}")
    return flush_tiny(value)  # below 1e-30 in size: 0 (esp.core.units.TINY)


def _delimiter(header: str) -> str:
    if "," in header:
        return ","
    if ";" in header:
        return ";"
    if "\t" in header:
        return "\t"
    return ","


def _row(text: str, delimiter: str) -> list[str]:
    return next(csv.reader([text], delimiter=delimiter, skipinitialspace=True), [])


def scan_table(
    text: str, path: str | Path | None
) -> tuple[dict[str, tuple[int, str]], tuple[int, list[str]] | None, list[tuple[int, list[str]]]]:
    """The lines of a tidy CSV: its ``# key: value`` comments of :data:`_COMMENT_KEYS`
    (key -> (line, value); one value per key), its header row (line, lower-case names) and
    its data rows (line, fields), the delimiter chosen by the header.

    Raises
    ------
    ParseError
        A comment given twice with two values; more than :data:`MAX_READINGS` rows.
    """
    comments: dict[str, tuple[int, str]] = {}
    header: tuple[int, list[str]] | None = None
    delimiter = ","
    rows: list[tuple[int, list[str]]] = []
    for number, line_text in enumerate(iter_lines(text), start=1):
        stripped = line_text.strip()
        if not stripped:
            continue
        if stripped.startswith("#"):
            m = _COMMENT_RE.match(stripped)
            if m:
                key = re.sub(r"\s+", "_", m.group(1).strip().lower())
                if key in _COMMENT_KEYS:
                    value = m.group(2)
                    if key in comments and comments[key][1] != value:
                        first, old = comments[key]
                        raise ParseError(
                            path,
                            number,
                            f"expected one '# {key}:' value, found {value!r} here and "
                            f"{old!r} at line {first}",
                        )
                    comments.setdefault(key, (number, value))
            continue
        if header is None:
            delimiter = _delimiter(stripped)
            header = (number, [c.strip().lower() for c in _row(stripped, delimiter)])
            continue
        if len(rows) == MAX_READINGS:
            raise ParseError(path, number, f"expected at most {MAX_READINGS} readings, found more")
        rows.append((number, _row(stripped, delimiter)))

    return comments, header, rows


def runs_table(
    path: str | Path | None,
    header: tuple[int, list[str]] | None,
    rows: list[tuple[int, list[str]]],
    position: str = "target_mm",
    unit_word: str = "mm",
) -> tuple[np.ndarray, dict[str, list[list[float]]], dict[str, list[list[int]]]]:
    """The runs of a tidy table (:func:`scan_table`) whose positions are in the column
    ``position`` (``target_mm``; ``target_deg`` for a rotary axis, ``unit_word`` naming
    their unit in messages): the targets ascending, each direction's runs in order of their
    run numbers (raw deviations, as written) and the line of every value.

    Raises
    ------
    ParseError
        A missing or repeated column, a value that does not parse, a run in both
        directions, a (run, target) pair missing or repeated, fewer than two targets or two
        too close.
    """
    columns = (position, *COLUMNS[1:])
    if header is None:
        raise ParseError(
            path, None, f"expected a header row '{','.join(columns)}', found an empty table"
        )
    header_line, names = header
    missing = [c for c in columns if c not in names]
    if missing:
        raise ParseError(
            path,
            header_line,
            f"expected a header row with columns {', '.join(columns)} (missing "
            f"{', '.join(missing)}), found {', '.join(repr(n) for n in names) or 'nothing'}",
        )
    for name in columns:
        if names.count(name) > 1:
            raise ParseError(
                path, header_line, f"expected one column {name!r}, found {names.count(name)}"
            )
    col = {name: names.index(name) for name in columns}
    if not rows:
        raise ParseError(path, None, "expected at least one data row, found only the header")

    direction_of_run: dict[int, tuple[str, int]] = {}
    values: dict[tuple[int, float], tuple[float, int]] = {}
    for number, fields in rows:
        if len(fields) != len(names):
            raise ParseError(
                path,
                number,
                f"expected {len(names)} fields as in the header, found {len(fields)}",
            )
        target = parse_position(
            fields[col[position]].strip(),
            path,
            number,
            f"a target position in {unit_word}",
            unit_word,
        )
        run_text = fields[col["run"]].strip()
        if not _INT_RE.match(run_text) or int(run_text) < 1:
            raise ParseError(
                path, number, f"expected a run number (1 or more), found {_show(run_text)}"
            )
        run = int(run_text)
        dir_text = fields[col["direction"]]
        try:
            direction = normalise_direction(dir_text)
        except DataError:
            direction = "mean"
        if direction == "mean":
            raise ParseError(
                path,
                number,
                f"expected a direction forward, backward, + or -, found {_show(dir_text)}",
            )
        deviation = _float(fields[col["deviation"]], path, number, "a deviation")
        if run in direction_of_run and direction_of_run[run][0] != direction:
            first_dir, first_line = direction_of_run[run]
            raise ParseError(
                path,
                number,
                f"expected run {run} in one direction ({first_dir} at line {first_line}), "
                f"found {direction}",
            )
        direction_of_run.setdefault(run, (direction, number))
        if (run, target) in values:
            raise ParseError(
                path,
                number,
                f"expected each run and target once, found run {run} at {target:g} "
                f"{unit_word} again (first at line {values[run, target][1]})",
            )
        values[run, target] = (deviation, number)

    first_line_of: dict[float, int] = {}
    for (_run, t), (_value, number) in values.items():
        first_line_of[t] = min(number, first_line_of.get(t, number))
    targets = np.array(sorted(first_line_of), dtype=float)
    if targets.size < MIN_TARGETS:
        raise ParseError(
            path,
            rows[0][0],
            f"expected at least {MIN_TARGETS} targets (one target gives no curve along the "
            f"axis; write a constant error as 'constant = ...' in machine.toml), found "
            f"{targets.size} ({', '.join(f'{t:g}' for t in targets)} {unit_word})",
        )
    check_spacing(targets, [first_line_of[t] for t in targets], path, unit_word)
    runs: dict[str, list[list[float]]] = {"forward": [], "backward": []}
    lines: dict[str, list[list[int]]] = {"forward": [], "backward": []}
    for run in sorted(direction_of_run):
        direction, first_line = direction_of_run[run]
        row, row_lines = [], []
        for t in targets:
            if (run, t) not in values:
                raise ParseError(
                    path,
                    first_line,
                    f"expected run {run} to hold every target ({targets.size}), found no "
                    f"value at {t:g} {unit_word}",
                )
            row.append(values[run, t][0])
            row_lines.append(values[run, t][1])
        runs[direction].append(row)
        lines[direction].append(row_lines)
    return targets, runs, lines


def parse_csv_profile(
    text: str,
    path: str | Path | None = None,
    kind: str | None = None,
    unit: str | None = None,
    axis: str | None = None,
    error_direction: str | None = None,
) -> ErrorProfile:
    """Parse a tidy profile CSV (``target_mm,run,direction,deviation``).

    Parameters
    ----------
    text : the whole file
    path : for messages and the profile's ``source``
    kind : ``"linear"``, ``"straightness"`` or ``"angular"``; needed, from here or a
        ``# kind:`` comment
    unit : unit of the deviations. When the file has a ``# unit:`` comment too, the two
        must name the same unit (a ParseError at the comment's line otherwise: a unit asked
        for that contradicts the file's would silently rescale every deviation); with
        neither, µm (linear, straightness) or µm/m (angular)
    axis, error_direction : X, Y or Z; win over ``# axis:`` / ``# error_direction:``

    Returns
    -------
    ErrorProfile
        Targets ascending in mm; each direction's runs in order of their run numbers;
        deviations in µm or µm/m.

    Raises
    ------
    ParseError
        A missing column or kind, a value that does not parse, a run in both directions,
        a (run, target) pair missing or repeated.
    DataError
        An argument is not valid (unknown kind, axis not X/Y/Z).
    """
    kind = check_kind(kind, path)
    axis = check_axis("axis", axis)
    error_direction = check_axis("error_direction", error_direction)
    comments, header, rows = scan_table(text, path)

    if kind is None:
        if "kind" in comments:
            line, value = comments["kind"]
            try:
                kind = check_kind(value, path)
            except DataError as exc:
                raise ParseError(path, line, str(exc)) from None
        else:
            raise ParseError(
                path,
                None,
                "expected the error kind (linear, straightness or angular) for a CSV "
                "profile, given by the configuration or a '# kind:' line, found none",
            )
    for key in ("axis", "error_direction"):
        if key in comments and (axis if key == "axis" else error_direction) is None:
            line, value = comments[key]
            try:
                letter = check_axis(key, value)
            except DataError as exc:
                raise ParseError(path, line, str(exc)) from None
            if key == "axis":
                axis = letter
            else:
                error_direction = letter
    if "unit" in comments:
        line, stated = comments["unit"]
        try:  # a unit the comment names must be known and fit the kind: say where it is
            convert_deviations(np.zeros(0), stated, kind, path)
        except ParseError as exc:
            raise ParseError(path, line, exc.message) from None
        if unit is not None:
            asked = convert_deviations(np.zeros(0), unit, kind, path)[1]
            if asked != canonical_unit(stated):
                raise ParseError(
                    path,
                    line,
                    f"the file states its deviations in {stated.strip()} ('# unit:') but they "
                    f"are to be read in {unit}; expected the same unit, or none given",
                )
        unit = stated

    targets, runs, lines = runs_table(path, header, rows)
    converted: dict[str, np.ndarray] = {}
    input_unit = None
    for direction, block in runs.items():
        if block:
            raw = np.asarray(block, dtype=float)
            converted[direction], input_unit = convert_deviations(raw, unit, kind, path)
            check_deviations(raw, converted[direction], lines[direction], kind, input_unit, path)
    return ErrorProfile(
        kind=kind,
        targets_mm=targets,
        runs=converted,
        axis=axis,
        error_direction=error_direction,
        input_unit=input_unit,
        source=None if path is None else str(path),
    )


def read_csv_profile(
    path: str | Path,
    kind: str | None,
    unit: str | None = None,
    axis: str | None = None,
    error_direction: str | None = None,
) -> ErrorProfile:
    """Read a tidy profile CSV file; see :func:`parse_csv_profile`."""
    return parse_csv_profile(
        read_text(path),
        path=path,
        kind=kind,
        unit=unit,
        axis=axis,
        error_direction=error_direction,
    )
