"""Read and write Renishaw Laser10 text files (``.rtl``, ``.rta``, straightness).

No public specification of the format exists. The layout used here was reconstructed from
several independent open-source readers that agree with one another and from environment
lines of a real linear file; ``docs/formats.md`` says which parts are confirmed and which are
assumed. In short, a file is a sequence of sections, each opened by a line holding an
upper-case name followed by ``::``::

    HEADER::             File type, Owner, Version no
    TARGET DATA::        Target-count, Targets (wrapped until Flags), Flags
    USER-TEXT::          Machine, Serial No, Date, By, Axis, Location, ...
    RUNS::               Run-count (one-direction passes)
    DEVIATIONS::         Run Target Data: then "run target-index deviation" lines
    ENVIRONMENT::        Key : start end flag  (EQUIPMENT:: in some angular files)
    EOF::

The reader is tolerant of how a file is spelled (line ends, BOM, code page, spacing, wrapped
target lists, negative or descending targets) and strict about what decides the numbers:
the target count (two or more, and at most :data:`MAX_READINGS` readings), every (run,
target) pair exactly once, numbers that parse
and are finite, strictly monotonic targets at least 1 µm apart, indices in range, and the
plausibility limits of :mod:`esp.core.units` (targets within ±100 m, deviations within ±10 mm,
angles within ±0.1 rad).

Conventions (assumptions, see ``docs/formats.md``): odd runs are forward and even runs
backward, unless the second ``Flags`` field is 1 (unidirectional), when every run is forward;
the direction is the order of the file's target list. Deviations are measured minus nominal,
in µm for linear and straightness files; for angular files the unit is not settled between
readers and defaults to µm/m, overridable with ``unit``.

References
----------
ISO 230-2:2014, clause 2 (targets, runs, approach directions). Longstaff (2002), 3.11-3.12
(the original program read one error file per component).
"""

from __future__ import annotations

import re
import warnings
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import overload

import numpy as np
import numpy.typing as npt

from esp.core.environment import ABSENT_TEMPERATURE_DEGC, absent_sensors
from esp.core.errors import DataError, EspWarning, ParseError
from esp.core.profile import KINDS, ErrorProfile
from esp.core.text import NAME_MAX_CHARS, TEXT_MAX_CHARS, too_long
from esp.core.units import (
    MIN_SPACING_MM,
    POSITION_LIMIT_MM,
    beyond_limit,
    canonical_unit,
    engine_unit_for_kind,
    flush_tiny,
    limit_text,
    to_engine,
)
from esp.core.values import written
from esp.io.atomic import write_text
from esp.io.textfile import iter_lines, read_text

__all__ = [
    "EXTENSION_AXIS",
    "EXTENSION_KIND",
    "MAX_LINES",
    "MAX_READINGS",
    "MAX_SECTION_LINES",
    "MIN_TARGETS",
    "axis_from_extension",
    "axis_letter",
    "check_axis",
    "check_deviations",
    "check_kind",
    "check_spacing",
    "convert_deviations",
    "format_laser10",
    "kind_from_extension",
    "parse_laser10",
    "parse_position",
    "read_laser10",
    "record_sections",
    "write_laser10",
    "write_laser10_set",
]

#: file extension (lower case, with dot) -> error kind
EXTENSION_KIND = {
    ".rtl": "linear",
    ".rta": "angular",
    ".rts": "straightness",
    ".stx": "straightness",
    ".sty": "straightness",
    ".stz": "straightness",
}
#: straightness extensions of the original program that name the axis moved
EXTENSION_AXIS = {".stx": "X", ".sty": "Y", ".stz": "Z"}
#: kind -> (``File type``, ``Owner``) written in the HEADER section
_HEADER_OF_KIND = {
    "linear": ("rtl", "Linear"),
    "angular": ("rta", "Angular"),
    "straightness": ("rts", "Straightness"),
}
_REQUIRED_SECTIONS = ("TARGET DATA", "RUNS", "DEVIATIONS")
_READ_SECTIONS = ("HEADER", "TARGET DATA", "USER-TEXT", "RUNS", "DEVIATIONS", "ENVIRONMENT")

_SECTION_RE = re.compile(r"^\s*([A-Z][A-Z0-9 _\-]*?)\s*::(.*)$")
_FLOAT_RE = re.compile(r"^[+-]?(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[eE][+-]?[0-9]+)?$")
_INT_RE = re.compile(r"^\+?[0-9]{1,9}$")
_FIELD_RE = re.compile(r'"([^"]*)"|(\S+)')
_AXIS_RE = re.compile(r"^([XYZ])(?:[\s\-]*AXIS)?$", re.IGNORECASE)
_TARGETS_PER_LINE = 5
#: the fewest targets a measured profile may have: one target says nothing about how the
#: error varies along the axis (a constant error is written ``constant = ...``)
MIN_TARGETS = 2
#: the most readings (runs x targets) one file may hold: far above any measurement
#: (ISO 230-2 asks for 5 runs each way; a long axis has a few hundred targets), and low
#: enough that reading a file never takes more than a few hundred MB
MAX_READINGS = 200_000
#: the most non-blank lines of a section other than TARGET DATA and DEVIATIONS (which may
#: also hold MAX_READINGS values): a real file has a few USER-TEXT lines and about ten
#: ENVIRONMENT lines; the limit keeps the memory of reading a file at a few times its size
MAX_SECTION_LINES = 1000
#: the most lines of a file: room for MAX_READINGS deviations and as many targets, each on
#: a line of its own with a blank line after it
MAX_LINES = 1_000_000
_DECIMALS = 6


# -- small helpers --------------------------------------------------------------------------


def kind_from_extension(path: str | Path | None) -> str | None:
    """The error kind implied by a Laser10 file extension, or None."""
    if path is None:
        return None
    return EXTENSION_KIND.get(Path(path).suffix.lower())


def axis_from_extension(path: str | Path | None) -> str | None:
    """The axis moved, for the ``.stx/.sty/.stz`` straightness extensions; else None."""
    if path is None:
        return None
    return EXTENSION_AXIS.get(Path(path).suffix.lower())


def _show(token: str, limit: int = 40) -> str:
    token = token.strip()
    if not token:
        return "nothing"
    if len(token) > limit:
        token = token[: limit - 3] + "..."
    return repr(token)


def _parse_float(token: str, path: str | Path | None, line: int, what: str) -> float:
    """A finite float, or ParseError ``expected <what>, found <token>``."""
    if not _FLOAT_RE.match(token):
        raise ParseError(path, line, f"expected {what}, found {_show(token)}")
    value = float(token)
    if not np.isfinite(value):
        raise ParseError(path, line, f"expected {what} (a finite number), found {_show(token)}")
    return flush_tiny(value)  # below 1e-30 in size: 0 (esp.core.units.TINY)


def parse_position(
    token: str,
    path: str | Path | None,
    line: int,
    what: str = "a target position in mm",
    unit_word: str = "mm",
) -> float:
    """A finite position in mm (or ``unit_word``) within
    ±:data:`esp.core.units.POSITION_LIMIT_MM`, or ParseError."""
    value = _parse_float(token, path, line, what)
    if abs(value) > POSITION_LIMIT_MM:
        raise ParseError(
            path,
            line,
            f"expected {what} within ±{POSITION_LIMIT_MM:g} {unit_word}, found {_show(token)}",
        )
    return value


def check_spacing(
    targets: npt.ArrayLike, lines: Sequence[int], path: str | Path | None, unit_word: str = "mm"
) -> None:
    """Sorted ``targets`` (mm, or ``unit_word``) at least
    :data:`esp.core.units.MIN_SPACING_MM` apart; else a ParseError at the line of the
    second of the two (``lines[i]`` is target i's line)."""
    t = np.asarray(targets, dtype=float)
    if t.size < 2:
        return
    gaps = np.diff(t)
    # 1e-6 relative: targets written with three decimals (1.000, 1.001) are 1 µm apart
    close = np.flatnonzero(np.abs(gaps) < MIN_SPACING_MM * (1 - 1e-6))
    if close.size:
        j = int(close[0]) + 1
        raise ParseError(
            path,
            lines[j],
            f"expected targets at least {MIN_SPACING_MM:g} {unit_word} apart, found "
            f"{t[j - 1]:.10g} and {t[j]:.10g} {unit_word}",
        )


def check_deviations(
    raw: np.ndarray,
    engine: np.ndarray,
    lines: npt.ArrayLike,
    kind: str,
    unit: str,
    path: str | Path | None,
) -> None:
    """Every deviation finite and within the plausibility limit of ``kind``; else a
    ParseError at its line. ``raw`` in the file's ``unit``, ``engine`` converted, ``lines``
    the line of each value (same shapes)."""
    bad = beyond_limit(engine, kind)
    if bad is not None:
        raise ParseError(
            path,
            int(np.asarray(lines).flat[bad]),
            f"expected {'an' if kind == 'angular' else 'a'} {kind} deviation within "
            f"{limit_text(kind, unit)}, found "
            f"{written(np.asarray(raw).flat[bad])} {unit}",
        )


def _parse_int(token: str, path: str | Path | None, line: int, what: str) -> int:
    if not _INT_RE.match(token.strip()):
        raise ParseError(path, line, f"expected {what}, found {_show(token)}")
    return int(token)


def _norm_key(key: str) -> str:
    """``"Target-count"`` -> ``"targetcount"``: spacing, case, ``-`` and ``_`` ignored."""
    return re.sub(r"[\s_\-]+", "", key).lower()


def _fields(value: str) -> tuple[str, ...]:
    """Whitespace-separated fields; a double-quoted string is one field, without quotes."""
    return tuple(q if q or not other else other for q, other in _FIELD_RE.findall(value))


def axis_letter(value: str | None) -> str | None:
    """``"X"``, ``"Y"`` or ``"Z"`` for texts such as ``x``, ``X axis``, ``Y-Axis``; else None."""
    if value is None:
        return None
    m = _AXIS_RE.match(value.strip())
    return m.group(1).upper() if m else None


def check_axis(name: str, value: str | None) -> str | None:
    """Return the axis letter of ``value`` (see :func:`axis_letter`); DataError if not X/Y/Z."""
    if value is None:
        return None
    letter = axis_letter(str(value))
    if letter is None:
        raise DataError(f"{name} must be X, Y or Z, got {value!r}")
    return letter


@overload
def check_kind(kind: str, path: str | Path | None = None) -> str: ...
@overload
def check_kind(kind: None, path: str | Path | None = None) -> None: ...
@overload
def check_kind(kind: str | None, path: str | Path | None = None) -> str | None: ...
def check_kind(kind: str | None, path: str | Path | None = None) -> str | None:
    """Return ``kind`` (lower case) if it is one of :data:`esp.core.profile.KINDS`, else
    DataError."""
    if kind is None:
        return None
    k = str(kind).strip().lower()
    if k not in KINDS:
        where = f" for {path}" if path is not None else ""
        raise DataError(f"unknown error kind {kind!r}{where}; expected one of {', '.join(KINDS)}")
    return k


def convert_deviations(
    values: np.ndarray, unit: str | None, kind: str, path: str | Path | None
) -> tuple[np.ndarray, str]:
    """Convert deviations from ``unit`` (default: the engine unit of ``kind``).

    Returns ``(values_in_engine_unit, canonical_unit)``; an unknown unit or one that does
    not fit the kind is a ParseError naming the file.
    """
    unit = unit if unit is not None else engine_unit_for_kind(kind)
    try:
        canonical = canonical_unit(unit)
        return to_engine(values, canonical, kind), canonical
    except DataError as exc:
        raise ParseError(path, None, str(exc)) from None


# -- sections -------------------------------------------------------------------------------


@dataclass
class _Section:
    name: str
    line: int
    lines: list[tuple[int, str]] = field(default_factory=list)

    def content(self) -> list[tuple[int, str]]:
        """(line number, stripped text) of each non-blank line."""
        return [(n, s.strip()) for n, s in self.lines if s.strip()]


def _line_limit(name: str) -> int:
    """The most non-blank lines the section ``name`` may hold (:data:`MAX_SECTION_LINES`;
    the targets and the deviations may also hold :data:`MAX_READINGS` values)."""
    if name in ("TARGET DATA", "DEVIATIONS"):
        return MAX_READINGS + MAX_SECTION_LINES
    return MAX_SECTION_LINES


def _sections(text: str, path: str | Path | None) -> dict[str, _Section]:
    """The sections esp reads, each with its non-blank lines; the lines of any other
    section are skipped without being kept, and a section holding more lines than
    :func:`_line_limit` is refused at its first line beyond it (the file is read line by
    line, so its size alone never decides the memory taken)."""
    lines = max(text.count("\n"), text.count("\r")) + 1  # CRLF, LF or CR line ends
    if lines > MAX_LINES:
        raise ParseError(
            path, None, f"expected at most {MAX_LINES} lines in a Laser10 file, found {lines}"
        )
    sections: dict[str, _Section] = {}
    names: list[str] = []  # every section seen, for the message of a missing one
    current: _Section | None = None
    kept = False  # whether the lines of the current section are kept
    for number, raw in enumerate(iter_lines(text), start=1):
        m = _SECTION_RE.match(raw) if "::" in raw else None
        if m:
            name = re.sub(r"\s+", " ", m.group(1).strip())
            if name == "EOF":
                break
            if name in sections:
                first = sections[name].line
                raise ParseError(
                    path,
                    number,
                    f"expected one {name}:: section, found a second one (the first is at "
                    f"line {first})",
                )
            if name not in names:
                names.append(name)
            current = _Section(name, number)
            kept = name in _READ_SECTIONS
            if kept:
                sections[name] = current
            raw = m.group(2)
        elif current is None:
            if raw.strip():
                raise ParseError(
                    path,
                    number,
                    f"expected a Laser10 section header such as HEADER::, found {_show(raw)}",
                )
            continue
        if kept and raw.strip():
            assert current is not None  # kept only inside a section
            limit = _line_limit(current.name)
            if len(current.lines) >= limit:
                raise ParseError(
                    path,
                    number,
                    f"expected at most {limit} lines in the {current.name}:: section (from "
                    f"line {current.line}), found more",
                )
            current.lines.append((number, raw))
    missing = [name for name in _REQUIRED_SECTIONS if name not in sections]
    if missing:
        found = ", ".join(f"{n}::" for n in names) or "none"
        raise ParseError(
            path,
            None,
            f"expected a {missing[0]}:: section (Laser10 files hold "
            f"{', '.join(s + '::' for s in _REQUIRED_SECTIONS)}), found sections: {found}",
        )
    return sections


def _key_values(section: _Section | None) -> list[tuple[int, str, str]]:
    """(line, key, value) of every ``Key : value`` line; lines without a colon are skipped."""
    if section is None:
        return []
    out = []
    for number, text in section.content():
        key, sep, value = text.partition(":")
        if sep:
            out.append((number, key.strip(), value.strip()))
    return out


def _kind_from_header(header: _Section | None, path: str | Path | None) -> tuple[str | None, str]:
    """The kind named by the HEADER (``File type``, else ``Owner``), and what was found."""
    by_type = {"rtl": "linear", "rta": "angular", "rts": "straightness"}
    by_type.update({ext[1:]: "straightness" for ext in EXTENSION_AXIS})
    found_kind: dict[str, tuple[str, int, str]] = {}
    seen = []
    for number, key, value in _key_values(header):
        k = _norm_key(key)
        if k == "filetype":
            seen.append(f"File type {value!r}")
            kind = by_type.get(value.strip().lower().lstrip("."))
            if kind:
                found_kind["filetype"] = (kind, number, value)
        elif k == "owner":
            seen.append(f"Owner {value!r}")
            word = value.strip().lower()
            for kind in KINDS:
                if re.search(rf"\b{kind}\b", word):
                    found_kind["owner"] = (kind, number, value)
                    break
    if "filetype" in found_kind and "owner" in found_kind:
        (k1, n1, v1), (k2, n2, v2) = found_kind["filetype"], found_kind["owner"]
        if k1 != k2:
            raise ParseError(
                path,
                n2,
                f"expected an Owner that agrees with File type {v1!r} (line {n1}), "
                f"found Owner {v2!r}",
            )
    for which in ("filetype", "owner"):
        if which in found_kind:
            return found_kind[which][0], ""
    return None, ", ".join(seen) or "no HEADER File type or Owner"


@dataclass
class _TargetData:
    targets: list[float]
    lines: list[int]
    count: int
    count_line: int
    targets_line: int
    flags: tuple[str, ...] | None


def _target_data(section: _Section, path: str | Path | None) -> _TargetData:
    targets: list[float] = []
    target_lines: list[int] = []
    seen: dict[str, int] = {}
    count = count_line = targets_line = None
    flags = None
    in_targets = False

    def once(key: str, number: int, label: str) -> None:
        if key in seen:
            raise ParseError(
                path,
                number,
                f"expected one {label} line in TARGET DATA, found a second one (the first "
                f"is at line {seen[key]})",
            )
        seen[key] = number

    def add_targets(number: int, text: str) -> None:
        for token in text.split():
            if len(targets) == MAX_READINGS:
                raise ParseError(
                    path, number, f"expected at most {MAX_READINGS} targets, found more"
                )
            targets.append(parse_position(token, path, number))
            target_lines.append(number)

    for number, text in section.content():
        if in_targets and ":" not in text:
            add_targets(number, text)
            continue
        in_targets = False
        key, sep, value = text.partition(":")
        if not sep:
            raise ParseError(
                path, number, f"expected 'Key : value' in TARGET DATA, found {_show(text)}"
            )
        k = _norm_key(key)
        if k == "targetcount":
            once(k, number, "Target-count")
            count = _parse_int(value, path, number, "a Target-count (a whole number)")
            count_line = number
            if count > MAX_READINGS:
                raise ParseError(
                    path, number, f"expected at most {MAX_READINGS} targets, found {count}"
                )
            if count < MIN_TARGETS:
                raise ParseError(
                    path,
                    number,
                    f"expected a Target-count of {MIN_TARGETS} or more (one target gives no "
                    f"curve along the axis; write a constant error as 'constant = ...' in "
                    f"machine.toml), found {count}",
                )
        elif k == "targets":
            once(k, number, "Targets")
            targets_line = number
            in_targets = True
            add_targets(number, value)
        elif k == "flags":
            once(k, number, "Flags")
            flags = tuple(value.split())
    if count is None:
        raise ParseError(
            path, section.line, "expected a Target-count line in TARGET DATA, found none"
        )
    if targets_line is None:
        raise ParseError(path, section.line, "expected a Targets line in TARGET DATA, found none")
    if len(targets) != count:
        raise ParseError(
            path,
            targets_line,
            f"expected {count} targets (Target-count at line {count_line}), found {len(targets)}",
        )
    t = np.asarray(targets)
    if t.size > 1:
        steps = np.diff(t)
        direction = np.sign(steps[0])
        bad = np.flatnonzero(~(np.sign(steps) == direction) | (steps == 0))
        if bad.size:
            j = int(bad[0]) + 1
            order = "increasing" if direction > 0 else "decreasing"
            if direction == 0:
                message = (
                    f"expected strictly monotonic targets, found {written(targets[j])} twice "
                    f"(targets {j} and {j + 1})"
                )
            else:
                message = (
                    f"expected strictly {order} targets, found target {j + 1} = "
                    f"{targets[j]:g} after {targets[j - 1]:g}"
                )
            raise ParseError(path, target_lines[j], message)
        ascending = np.argsort(t)
        check_spacing(t[ascending], [target_lines[i] for i in ascending], path)
    assert count_line is not None  # read with the count
    return _TargetData(targets, target_lines, count, count_line, targets_line, flags)


def _run_count(section: _Section, path: str | Path | None) -> tuple[int, int]:
    """The Run-count and its line."""
    found = None
    for number, key, value in _key_values(section):
        if _norm_key(key) == "runcount":
            if found is not None:
                raise ParseError(
                    path,
                    number,
                    f"expected one Run-count line in RUNS, found a second one (the first is "
                    f"at line {found[0]})",
                )
            n = _parse_int(value, path, number, "a Run-count (a whole number)")
            if n < 1:
                raise ParseError(path, number, f"expected a Run-count of 1 or more, found {n}")
            found = (number, n)
    if found is None:
        raise ParseError(path, section.line, "expected a Run-count line in RUNS, found none")
    return found[1], found[0]


def _deviations(
    section: _Section, path: str | Path | None, run_count: int, target_count: int
) -> tuple[np.ndarray, np.ndarray]:
    """The deviations as an array (run, target) in the file's target order, and the line
    of each."""
    seen: dict[tuple[int, int], int] = {}
    values: dict[tuple[int, int], float] = {}
    for number, text in section.content():
        fields = text.split()
        if ":" in text and not _INT_RE.match(fields[0]):
            continue  # a key line such as "Run Target Data:"
        if len(fields) != 3:
            raise ParseError(
                path,
                number,
                f"expected 'run target deviation' (3 fields), found {len(fields)} field"
                f"{'s' if len(fields) != 1 else ''}: {_show(text)}",
            )
        run_text, target_text, value_text = fields
        run = _parse_int(run_text, path, number, f"a run number (1 to {run_count})")
        if not 1 <= run <= run_count:
            raise ParseError(
                path,
                number,
                f"expected a run number from 1 to {run_count} (Run-count), found {run}",
            )
        target = _parse_int(target_text, path, number, f"a target index (1 to {target_count})")
        if not 1 <= target <= target_count:
            raise ParseError(
                path,
                number,
                f"expected a target index from 1 to {target_count} (Target-count), found {target}",
            )
        value = _parse_float(value_text, path, number, "a deviation")
        if (run, target) in seen:
            raise ParseError(
                path,
                number,
                f"expected each run and target once, found run {run} target {target} again "
                f"(first at line {seen[run, target]})",
            )
        seen[run, target] = number
        values[run, target] = value
    if len(values) != run_count * target_count:
        # the first missing pair is found within len(values) + 1 steps
        for run in range(1, run_count + 1):
            for target in range(1, target_count + 1):
                if (run, target) not in values:
                    raise ParseError(
                        path,
                        section.line,
                        f"expected a deviation for run {run} at target {target} "
                        f"(Run-count {run_count} x Target-count {target_count} = "
                        f"{run_count * target_count} values), found none in DEVIATIONS "
                        f"({len(values)} values)",
                    )
    out = np.empty((run_count, target_count))
    lines = np.empty((run_count, target_count), dtype=int)
    for (run, target), value in values.items():
        out[run - 1, target - 1] = value
        lines[run - 1, target - 1] = seen[run, target]
    return out, lines


def _check_text_lengths(section: _Section | None, path: str | Path | None) -> None:
    """Refuse (ParseError at its line) a key longer than :data:`esp.core.text.NAME_MAX_CHARS`
    or a value or loose text longer than :data:`~esp.core.text.TEXT_MAX_CHARS`, and loose
    USER-TEXT lines that join into more: the file's text reaches the reports."""
    if section is None:
        return
    loose = 0
    checks: list[tuple[str, str | int, int]]
    for number, text in section.content():
        key, sep, value = text.partition(":")
        if sep and key.strip():
            checks = [
                ("key", key.strip(), NAME_MAX_CHARS),
                ("value", value.strip(), TEXT_MAX_CHARS),
            ]
        else:
            loose += len(text) + (2 if loose else 0)  # joined with "; "
            checks = [("text without a key (all such lines joined)", loose, TEXT_MAX_CHARS)]
        for what, part, limit in checks:
            message = too_long(part, limit)
            if message is not None:
                raise ParseError(path, number, f"{section.name} {what}: {message}")


def _user_text(section: _Section | None) -> dict[str, str]:
    """USER-TEXT as key -> value, original keys; lines without a colon go to ``Text``."""
    metadata: dict[str, str] = {}
    loose: list[str] = []
    if section is None:
        return metadata
    for _number, text in section.content():
        key, sep, value = text.partition(":")
        if sep and key.strip():
            metadata[key.strip()] = value.strip()
        else:
            loose.append(text)
    if loose:
        metadata.setdefault("Text", "; ".join(loose))
    return metadata


def _environment(section: _Section | None) -> dict[str, tuple[str, ...]]:
    return {key: _fields(value) for _n, key, value in _key_values(section) if key}


def _warn_absent_sensors(
    section: _Section | None, environment: Mapping[str, tuple[str, ...]], path: str | Path | None
) -> None:
    """Warn of each material temperature sensor the file records as absent
    (:func:`esp.core.environment.absent_sensors`), with its line."""
    absent = set(absent_sensors(environment))
    for number, key, value in _key_values(section):
        if key in absent:
            warnings.warn(
                EspWarning(
                    f"{path or '<input>'}:{number}: {key} reads {value}: "
                    f"{ABSENT_TEMPERATURE_DEGC:g} is the value written for a material "
                    f"temperature sensor that is not connected; recorded as absent, not "
                    f"used as a temperature"
                ),
                stacklevel=3,
            )


def _zero_reverse_runs(raw: np.ndarray) -> str | None:
    """Which runs of a file flagged unidirectional are the reverse runs it does not have,
    filled with zeros by its writer: ``"even"`` when the file holds an even number of runs
    and every second one (2, 4, ...) is exactly 0 at every target, as a bidirectional file
    places its reverse runs; ``"last"`` when the second half is; None when neither is, or
    when the other runs are all 0 as well. Real readings are never exactly 0 at every
    target of a run (the datum target at most). At least two runs must be zero (a
    Run-count of 4 or more): one run of zeros beside one real run is too little to tell."""
    n = raw.shape[0]
    if n < 4 or n % 2:
        return None
    halves = (("even", raw[1::2], raw[0::2]), ("last", raw[n // 2 :], raw[: n // 2]))
    for which, zero, kept in halves:
        if np.all(zero == 0.0) and np.any(kept != 0.0):
            return which
    return None


def _is_unidirectional(flags: tuple[str, ...] | None) -> bool:
    """Assumed meaning of ``Flags``: a second field of 1 marks a unidirectional test."""
    return flags is not None and len(flags) >= 2 and flags[1] == "1"


# -- public API -----------------------------------------------------------------------------


def parse_laser10(
    text: str,
    path: str | Path | None = None,
    kind: str | None = None,
    unit: str | None = None,
    axis: str | None = None,
    error_direction: str | None = None,
) -> ErrorProfile:
    """Parse the text of a Laser10 file into an :class:`ErrorProfile`.

    Parameters
    ----------
    text : the whole file (any line ends, an optional BOM)
    path : the file's name, for messages and the profile's ``source``; its extension
        does not matter here (see :func:`read_laser10`)
    kind : ``"linear"``, ``"straightness"`` or ``"angular"``; None takes it from the
        HEADER ``File type`` (rtl, rta, rts, stx/sty/stz) or ``Owner`` line
    unit : unit of the file's deviations; default µm for linear and straightness, µm/m
        for angular. Angular files may need ``"arcsec"``, ``"mrad"`` or ``"urad"``
    axis : the axis moved; None takes USER-TEXT ``Axis`` when it is X, Y or Z
    error_direction : for straightness the direction of the deviation, for angular the
        axis of the rotation (X, Y, Z); not in the file, so only from the caller

    Returns
    -------
    ErrorProfile
        Targets ascending in mm (a descending file is reversed with all its runs);
        deviations in µm (linear, straightness) or µm/m (angular); odd runs forward and
        even runs backward, or all forward for a unidirectional file.

    Raises
    ------
    ParseError
        With the line, when the file does not hold a complete, consistent data set.
    DataError
        When an argument is not valid (unknown kind, axis not X/Y/Z).
    """
    kind = check_kind(kind, path)
    axis = check_axis("axis", axis)
    error_direction = check_axis("error_direction", error_direction)
    sections = _sections(text, path)
    if kind is None:
        kind, seen = _kind_from_header(sections.get("HEADER"), path)
        if kind is None:
            raise ParseError(
                path,
                None,
                "expected the error kind from the file extension (.rtl, .rta, .rts, "
                ".stx/.sty/.stz), a HEADER File type or Owner, or given explicitly, "
                f"found {seen}",
            )
    td = _target_data(sections["TARGET DATA"], path)
    run_count, run_line = _run_count(sections["RUNS"], path)
    if run_count * td.count > MAX_READINGS:
        raise ParseError(
            path,
            run_line,
            f"expected at most {MAX_READINGS} readings, found Run-count {run_count} x "
            f"Target-count {td.count} = {run_count * td.count}",
        )
    raw, lines = _deviations(sections["DEVIATIONS"], path, run_count, td.count)
    for name in ("HEADER", "USER-TEXT", "ENVIRONMENT"):
        _check_text_lengths(sections.get(name), path)
    metadata = _user_text(sections.get("USER-TEXT"))
    environment = _environment(sections.get("ENVIRONMENT"))
    _warn_absent_sensors(sections.get("ENVIRONMENT"), environment, path)

    values, input_unit = convert_deviations(raw, unit, kind, path)
    check_deviations(raw, values, lines, kind, input_unit, path)
    targets = np.asarray(td.targets, dtype=float)
    if targets.size > 1 and targets[1] < targets[0]:
        targets = targets[::-1]
        values = values[:, ::-1]
    if _is_unidirectional(td.flags):
        zeros = _zero_reverse_runs(raw)
        if zeros is not None:
            shown = {
                "even": f"runs 2, 4, ..., {run_count}",
                "last": f"runs {run_count // 2 + 1} to {run_count}",
            }[zeros]
            warnings.warn(
                EspWarning(
                    f"{path or '<input>'}:{run_line}: Flags {' '.join(td.flags or ())} marks a "
                    f"unidirectional test, but {shown} of Run-count {run_count} are all "
                    f"exactly 0 (the reverse runs the test does not have, as some writers "
                    f"fill them): read as a unidirectional test of {run_count // 2} runs, "
                    f"the zero runs left out"
                ),
                stacklevel=2,
            )
            values = values[0::2] if zeros == "even" else values[: run_count // 2]
        runs = {"forward": values}
    else:
        runs = {"forward": values[0::2], "backward": values[1::2]}
    converted = {direction: block for direction, block in runs.items() if block.shape[0]}
    if axis is None:
        axis = next((axis_letter(v) for k, v in metadata.items() if _norm_key(k) == "axis"), None)
    return ErrorProfile(
        kind=kind,
        targets_mm=targets,
        runs=converted,
        axis=axis,
        error_direction=error_direction,
        input_unit=input_unit,
        metadata=metadata,
        environment=environment,
        source=None if path is None else str(path),
    )


def read_laser10(
    path: str | Path,
    kind: str | None = None,
    unit: str | None = None,
    axis: str | None = None,
    error_direction: str | None = None,
) -> ErrorProfile:
    """Read a Laser10 file; see :func:`parse_laser10` for the arguments.

    The kind comes from, in order: ``kind``; the extension (``.rtl`` linear, ``.rta``
    angular, ``.rts/.stx/.sty/.stz`` straightness); the HEADER. The axis comes from
    ``axis``; then ``.stx/.sty/.stz`` (straightness of X, Y, Z); then USER-TEXT ``Axis``.
    """
    text = read_text(path)
    if kind is None:
        kind = kind_from_extension(path)
    if axis is None:
        axis = axis_from_extension(path)
    return parse_laser10(
        text, path=path, kind=kind, unit=unit, axis=axis, error_direction=error_direction
    )


def _check_text(what: str, value: str, key: bool = False) -> str:
    value = str(value).strip()
    if "\n" in value or "\r" in value:
        raise DataError(
            f"{what} {value!r} cannot be written to a Laser10 file: it holds a line end"
        )
    if key and (not value or ":" in value):
        raise DataError(
            f"{what} {value!r} cannot be written to a Laser10 file: expected a non-empty "
            "name without ':'"
        )
    return value


def _quote(fieldtext: str) -> str:
    if '"' in fieldtext:
        raise DataError(
            f"environment field {fieldtext!r} cannot be written to a Laser10 file: it holds '\"'"
        )
    if "\n" in fieldtext or "\r" in fieldtext:
        raise DataError(f"environment field {fieldtext!r} holds a line end")
    if not fieldtext or any(c.isspace() for c in fieldtext):
        return f'"{fieldtext}"'
    return fieldtext


def _number(value: float) -> str:
    text = f"{value:.{_DECIMALS}f}"
    return "0." + "0" * _DECIMALS if text == "-0." + "0" * _DECIMALS else text


def format_laser10(profile: ErrorProfile) -> str:
    """The text of a Laser10 file holding ``profile``.

    Targets ascending; deviations in the engine unit (µm, or µm/m for angular: the
    reader's default, so the file reads back without a ``unit``), with six decimals.
    Forward and backward runs are interleaved (run 1 forward, run 2 backward, ...), each
    backward run listing its targets in descending order as instruments do; a profile
    with forward runs only is written as a unidirectional file (``Flags: 0 1 2 0``).

    Raises
    ------
    DataError
        The profile has fewer than :data:`MIN_TARGETS` targets (the reader would refuse
        the file), its forward runs alone hold runs of zeros the reader would leave out
        (:func:`_zero_reverse_runs`), the runs cannot be interleaved (backward runs only,
        or run counts differing by more than one forward run), or metadata/environment
        text cannot be written.
    """
    forward = profile.runs.get("forward")
    backward = profile.runs.get("backward")
    where = f" of {profile.source}" if profile.source else ""
    if profile.targets_mm.size < MIN_TARGETS:
        raise DataError(
            f"cannot write the profile{where} as a Laser10 file: expected {MIN_TARGETS} "
            f"targets or more, found {profile.targets_mm.size}"
        )
    if backward is None:
        assert forward is not None  # a profile holds at least one run
        if _zero_reverse_runs(forward) is not None:
            raise DataError(
                f"cannot write the profile{where} as a Laser10 file: half of its "
                f"{forward.shape[0]} forward runs are exactly 0 at every target, and would "
                f"be read back as the empty reverse runs some writers add to a "
                f"unidirectional test; leave the zero runs out or write it as CSV"
            )
        order = [forward[i] for i in range(forward.shape[0])]
        flags = "0 1 2 0"
    else:
        nf = 0 if forward is None else forward.shape[0]
        nb = backward.shape[0]
        if not (nf == nb or nf == nb + 1):
            raise DataError(
                f"cannot write the profile{where} as a Laser10 file: it alternates forward "
                f"and backward runs, so needs as many forward runs as backward runs (or one "
                f"more), found {nf} forward and {nb} backward"
            )
        assert forward is not None  # nf >= nb >= 1: a profile keeps no empty run block
        order = []
        for i in range(nf):
            order.append(forward[i])
            if i < nb:
                order.append(backward[i])
        flags = "0 0 2 0"
    file_type, owner = _HEADER_OF_KIND[profile.kind]
    targets = profile.targets_mm
    n = targets.size
    out = [
        "HEADER::",
        f"File type  : {file_type}",
        f"Owner      : {owner}",
        "Version no : 1.0",
        "",
        "TARGET DATA::",
        "Filetype  : ISO",
        f"Target-count: {n}",
        "Targets :",
    ]
    for start in range(0, n, _TARGETS_PER_LINE):
        out.append("  ".join(_number(t) for t in targets[start : start + _TARGETS_PER_LINE]))
    out += [f"Flags: {flags}", "", "USER-TEXT::"]
    for key, value in profile.metadata.items():
        out.append(f"{_check_text('metadata key', key, key=True)}: {_check_text('value', value)}")
    out += ["", "RUNS::", f"Run-count: {len(order)}", "", "DEVIATIONS::", "Run Target Data:"]
    bidirectional = backward is not None
    for r, row in enumerate(order, start=1):
        indices = range(n, 0, -1) if bidirectional and r % 2 == 0 else range(1, n + 1)
        out.extend(f"{r} {j} {_number(row[j - 1])}" for j in indices)
    out += ["", "ENVIRONMENT::"]
    for key, fields in profile.environment.items():
        k = _check_text("environment key", key, key=True)
        out.append(f"{k} : {' '.join(_quote(str(f)) for f in fields)}".rstrip())
    out += ["EOF::", ""]
    return "\n".join(out)


def write_laser10(path: str | Path, profile: ErrorProfile) -> None:
    """Write ``profile`` to ``path`` as a Laser10 file, atomically (see :mod:`esp.io.atomic`).

    Raises DataError when the extension names another kind (an angular profile to
    ``.rtl``) or the profile cannot be written (see :func:`format_laser10`).
    """
    implied = kind_from_extension(path)
    if implied is not None and implied != profile.kind:
        raise DataError(
            f"{path}: the extension {Path(path).suffix!r} is for {implied} data, "
            f"but the profile is {profile.kind}"
        )
    write_text(path, format_laser10(profile))


def write_laser10_set(folder: str | Path, profiles: Mapping[str, ErrorProfile]) -> list[Path]:
    """Write each profile of ``profiles`` (file name -> profile) into ``folder`` (created
    if needed) with :func:`write_laser10`; return the paths in the mapping's order."""
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    written = []
    for name, profile in profiles.items():
        write_laser10(folder / name, profile)
        written.append(folder / name)
    return written


def record_sections(text: str) -> dict[str, tuple[tuple[str, str], ...]]:
    """The ``Key : value`` lines of the sections that describe a Laser10 file rather than
    hold its data -- ``USER-TEXT``, ``ENVIRONMENT`` and ``EQUIPMENT`` -- as (key, value)
    pairs in the order written, for the provenance of a report
    (:mod:`esp.report.provenance`).

    Tolerant where :func:`parse_laser10` is strict: it never raises, and a section that is
    missing gives no pairs. USER-TEXT lines without a colon are joined under ``Text``, as
    :func:`parse_laser10` keeps them.

    Examples
    --------
    >>> sections = record_sections("USER-TEXT::\\nBy: A. User\\nENVIRONMENT::\\nAir temp : 20 21 0")
    >>> sections["USER-TEXT"], sections["ENVIRONMENT"], sections["EQUIPMENT"]
    ((('By', 'A. User'),), (('Air temp', '20 21 0'),), ())
    """
    wanted = ("USER-TEXT", "ENVIRONMENT", "EQUIPMENT")
    found: dict[str, list[tuple[str, str]]] = {name: [] for name in wanted}
    loose: list[str] = []
    current: str | None = None
    for raw in iter_lines(text):
        m = _SECTION_RE.match(raw) if "::" in raw else None
        if m:
            current = re.sub(r"\s+", " ", m.group(1).strip())
            if current == "EOF":
                break
            raw = m.group(2)
        if current not in found or not raw.strip():
            continue
        key, sep, value = raw.strip().partition(":")
        if sep and key.strip():
            if len(found[current]) < MAX_SECTION_LINES:
                found[current].append((key.strip(), value.strip()))
        elif current == "USER-TEXT":
            loose.append(raw.strip())
    if loose:
        found["USER-TEXT"].append(("Text", "; ".join(loose)))
    return {name: tuple(pairs) for name, pairs in found.items()}
