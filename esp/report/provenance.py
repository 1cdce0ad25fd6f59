"""The provenance of a command's outputs: what a calibration certificate needs to trace a
result back to its inputs and to regenerate it.

:func:`collect` reads every input once, hashes it (SHA-256) and keeps, for a Laser10 file,
what the file records about its measurement:

* **USER-TEXT** -- the machine, serial number, date, operator, axis, location, comment, as
  the file gives them (label, value);
* **ENVIRONMENT** (and **EQUIPMENT**) -- the air and material temperatures, air pressure
  and humidity, the environment factor and the expansion coefficient used, the date and
  time of the test, the laser and optics: one (quantity, value with unit) pair per line,
  the start and end values as the file writes them. A material temperature reading
  exactly -10 °C (:data:`esp.core.environment.ABSENT_TEMPERATURE_DEGC`, the value Laser10
  writes for a sensor that is not connected), or 0 at start and end (a sensor not fitted),
  is shown as ``absent``.

For each configuration (a ``.toml`` input) it keeps its text as given, so that the same
outputs can be regenerated from the record alone.

What is recorded, and nothing else, so that the same inputs and the same command give the
same bytes: no time of the run, no host, no absolute path that the user did not type. A
path is shown as the command line names it, and a file that a configuration names is shown
relative to that configuration's folder (as the configuration names it). The units of the
environment readings are those ``docs/formats.md`` gives for the Laser10 layout (°C, kPa,
%RH, µm/(m·°C)); the unit of the environment factor is not recorded by the file, so none
is shown.

This module imports only the standard library and :mod:`esp.io`.
"""

from __future__ import annotations

import hashlib
import os
import re
import sys
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import click

from esp._version import __version__

__all__ = [
    "InputRecord",
    "Provenance",
    "Reading",
    "collect",
    "command_line",
    "environment_lines",
    "readings",
]

#: the largest input hashed and read (larger than any input a command accepts)
_MAX_BYTES = 256 * 1024 * 1024

_LASER10_SUFFIXES = (".rtl", ".rta", ".rts", ".stx", ".sty", ".stz")


@dataclass(frozen=True)
class InputRecord:
    """One input of a command.

    Attributes
    ----------
    path : the file as the command line names it, or as its configuration names it
        (relative to the configuration's folder)
    sha256 : the SHA-256 of its bytes, in hexadecimal
    size_bytes : its size
    kind : ``"configuration"`` (a ``.toml`` file named on the command line), ``"toml"``
        (one a configuration includes), ``"laser10"``, ``"csv"``, or the file's suffix
        (``"json"``, ``"b5r"``); ``"file"`` when it has none
    user_text : the USER-TEXT fields of a Laser10 file, (label, value) as written; for a
        tidy CSV its ``# key: value`` comment lines (other comments under ``Text``)
    readings : the ENVIRONMENT and EQUIPMENT lines of a Laser10 file (:class:`Reading`)
    error_kind : the kind of a Laser10 file's data (``"linear"``, ``"angular"``,
        ``"straightness"``) as its extension names it, else ``""``
    """

    path: str
    sha256: str
    size_bytes: int
    kind: str
    user_text: tuple[tuple[str, str], ...] = ()
    readings: tuple[Reading, ...] = ()
    error_kind: str = ""

    @property
    def environment(self) -> tuple[tuple[str, str], ...]:
        """The readings as (quantity, value with unit), sentinels shown as ``"absent"``
        (:attr:`Reading.text`): what the JSON holds."""
        return tuple((r.quantity, r.text) for r in self.readings)

    def to_dict(self) -> dict[str, Any]:
        out: dict[str, Any] = {
            "path": self.path,
            "sha256": self.sha256,
            "size_bytes": self.size_bytes,
            "kind": self.kind,
        }
        if self.kind == "laser10":
            out["error_kind"] = self.error_kind or None
            out["user_text"] = _unique(self.user_text)
            out["environment"] = _unique(self.environment)
        elif self.user_text:
            out["user_text"] = _unique(self.user_text)
        return out


def _unique(pairs: tuple[tuple[str, str], ...]) -> dict[str, str]:
    """(label, value) pairs as a JSON object; a label written twice keeps both values,
    the second as ``label (2)``."""
    out: dict[str, str] = {}
    for label, value in pairs:
        key, n = label, 1
        while key in out:
            n += 1
            key = f"{label} ({n})"
        out[key] = value
    return out


@dataclass(frozen=True)
class Provenance:
    """What a command's outputs were made from (:func:`collect`).

    Attributes
    ----------
    esp_version : the version of esp that made them
    command : the arguments after ``esp`` (the subcommand first)
    inputs : every input, in the order the command read them, each once
    configuration : (configuration file, its text as given) for each ``.toml`` input
    """

    esp_version: str
    command: tuple[str, ...]
    inputs: tuple[InputRecord, ...]
    configuration: tuple[tuple[str, str], ...]

    def to_dict(self) -> dict[str, Any]:
        """The JSON form: ``{"esp_version", "command", "inputs", "configuration"}``
        (``docs/json.md``)."""
        return {
            "esp_version": self.esp_version,
            "command": list(self.command),
            "inputs": [record.to_dict() for record in self.inputs],
            "configuration": [{"file": name, "text": text} for name, text in self.configuration],
        }


# -- environment lines -------------------------------------------------------------------------


def _norm(key: str) -> str:
    return re.sub(r"[^a-z0-9]", "", key.lower())


_FIELD = re.compile(r'"([^"]*)"|(\S+)')
_NUMBER = re.compile(r"^[-+]?(?:\d+\.\d*|\.\d+|\d+)(?:[eE][-+]?\d+)?$")

#: normalised key -> (quantity, unit) of the readings whose unit the layout implies
_QUANTITIES = {
    "airtemp": ("air temperature", "°C"),
    "airpress": ("air pressure", "kPa"),
    "airhumid": ("air humidity", "%RH"),
    "envfactor": ("environment factor", ""),
    "expcoeff": ("expansion coefficient", "µm/(m·°C)"),
}


def _fields(value: str) -> list[str]:
    return [m.group(1) if m.group(1) is not None else m.group(2) for m in _FIELD.finditer(value)]


def _with_unit(value: str, unit: str) -> str:
    return f"{value} {unit}" if unit else value


_CLOCK_DATE = re.compile(r"^(\d{1,2}:\d{2}(?::\d{2})?)\s+(.+)$")


@dataclass(frozen=True)
class Reading:
    """One ENVIRONMENT (or EQUIPMENT) line of a Laser10 file, as written.

    Attributes
    ----------
    quantity : what it is (``"air temperature"``, ``"material temperature 1"``, ``"date
        and time"``, ``"laser"``)
    unit : the unit the layout implies (``"°C"``, ``"kPa"``), ``""`` when the file does not
        say (the environment factor, a pressure not in kPa)
    start, end : the readings at the start and at the end of the measurement, as written;
        None for a line that is not a pair of readings (then :attr:`raw` holds it)
    absent : the pair is the sentinel of a sensor that was not connected
    raw : the value as written
    """

    quantity: str
    unit: str = ""
    start: str | None = None
    end: str | None = None
    absent: bool = False
    raw: str = ""

    @property
    def text(self) -> str:
        """``"20.69 °C (start), 20.68 °C (end)"``, ``"11.5 µm/(m·°C) (start and end)"``,
        ``"absent"``, or the value as written."""
        if self.absent:
            return "absent"
        if self.start is None or self.end is None:
            return self.raw
        if self.quantity == "date and time":
            return f"{self.start} (start), {self.end} (end)"
        if self.start == self.end:
            return f"{_with_unit(self.start, self.unit)} (start and end)"
        start, end = _with_unit(self.start, self.unit), _with_unit(self.end, self.unit)
        return f"{start} (start), {end} (end)"

    @property
    def compact(self) -> str:
        """The reading for a table whose header gives the unit: ``"20.69 / 20.68"`` (start
        / end), ``"11.5"`` (the same at both), ``"absent"``; a date and time of one day as
        ``"Mar 15 2023 08:30 / 09:01"``."""
        if self.absent:
            return "absent"
        if self.start is None or self.end is None:
            return self.raw
        if self.start == self.end:
            return self.start
        if self.quantity == "date and time":
            a, b = _CLOCK_DATE.match(self.start), _CLOCK_DATE.match(self.end)
            if a and b and a.group(2) == b.group(2):
                return f"{a.group(2)} {a.group(1)} / {b.group(1)}"
        return f"{self.start} / {self.end}"


def _pair(fields: list[str]) -> tuple[str, str] | None:
    """A reading's first two numbers, as written; None when the line does not start with
    two numbers."""
    if len(fields) < 2 or not all(_NUMBER.match(f) for f in fields[:2]):
        return None
    return fields[0], fields[1]


def _sensor_absent(start: float, end: float) -> bool:
    from esp.core.environment import ABSENT_TEMPERATURE_DEGC

    return ABSENT_TEMPERATURE_DEGC in (start, end) or (start == 0.0 and end == 0.0)


def readings(
    environment: Iterable[tuple[str, str]], equipment: Iterable[tuple[str, str]] = ()
) -> tuple[Reading, ...]:
    """The ENVIRONMENT lines of a Laser10 file (key, raw value) as :class:`Reading`, then
    its EQUIPMENT lines (``Laser``, ``Optics``) as written."""
    out: list[Reading] = []
    for key, value in environment:
        norm = _norm(key)
        fields = _fields(value)
        pair = _pair(fields)
        if norm in _QUANTITIES:
            quantity, unit = _QUANTITIES[norm]
            if norm == "airpress" and pair and not 50.0 <= abs(float(pair[0])) <= 150.0:
                unit = ""  # not kPa: the file does not say which unit it is
            start, end = pair or (None, None)
            out.append(Reading(quantity, unit, start, end, raw=value))
        elif (m := re.fullmatch(r"mattemp(\d*)", norm)) is not None:
            quantity = f"material temperature {m.group(1)}".rstrip()
            absent = pair is not None and _sensor_absent(float(pair[0]), float(pair[1]))
            start, end = pair or (None, None)
            out.append(Reading(quantity, "°C", start, end, absent, value))
        elif norm == "datetime" and len(fields) >= 2:
            out.append(Reading("date and time", "", fields[0], fields[1], raw=value))
        else:
            out.append(Reading("date and time" if norm == "datetime" else key, raw=value))
    out.extend(Reading(key.lower(), raw=value) for key, value in equipment)
    return tuple(out)


def environment_lines(
    environment: Iterable[tuple[str, str]], equipment: Iterable[tuple[str, str]] = ()
) -> tuple[tuple[str, str], ...]:
    """The ENVIRONMENT lines of a Laser10 file (key, raw value) as (quantity, value with
    unit), then its EQUIPMENT lines (``Laser``, ``Optics``) as written
    (:func:`readings`, each as its :attr:`Reading.text`).

    Examples
    --------
    >>> environment_lines([("Air temp", "20.69 20.68 0")])
    (('air temperature', '20.69 °C (start), 20.68 °C (end)'),)
    >>> environment_lines([("Mat temp 1", "-10.0 -10.0 0")])
    (('material temperature 1', 'absent'),)
    """
    return tuple((r.quantity, r.text) for r in readings(environment, equipment))


# -- the inputs --------------------------------------------------------------------------------


def _read(path: str) -> bytes:
    from esp.io.textfile import read_regular_bytes

    return read_regular_bytes(path, _MAX_BYTES, "input")


def _is_laser10(path: str, data: bytes) -> bool:
    if Path(path).suffix.lower() in _LASER10_SUFFIXES:
        return True
    head = data[:4096].lstrip(b"\xef\xbb\xbf \t\r\n")
    return head.startswith(b"HEADER::") or b"DEVIATIONS::" in data[: 1 << 20]


def _record(path: str, shown: str, named: bool) -> tuple[InputRecord, str | None]:
    """The record of one input and, for a ``.toml`` file, its text."""
    data = _read(path)
    digest = hashlib.sha256(data).hexdigest()
    suffix = Path(path).suffix.lower()
    if suffix == ".toml":
        text = data.decode("utf-8", errors="replace")
        kind = "configuration" if named else "toml"
        return InputRecord(shown, digest, len(data), kind), text
    if _is_laser10(path, data):
        from esp.io.laser10 import kind_from_extension, record_sections
        from esp.io.textfile import decode_bytes

        try:
            text = decode_bytes(data, path)
        except Exception:  # not text: recorded by its hash alone
            text = ""
        sections = record_sections(text)
        lines = readings(sections["ENVIRONMENT"], sections["EQUIPMENT"])
        return InputRecord(
            shown,
            digest,
            len(data),
            "laser10",
            user_text=sections["USER-TEXT"],
            readings=lines,
            error_kind=kind_from_extension(path) or "",
        ), None
    kind = suffix[1:] if suffix else "file"
    if kind == "csv":
        return InputRecord(shown, digest, len(data), kind, user_text=_csv_comments(data)), None
    return InputRecord(shown, digest, len(data), kind), None


def _csv_comments(data: bytes) -> tuple[tuple[str, str], ...]:
    """The ``# key: value`` comment lines before the header of a tidy CSV (``unit``,
    ``kind``, ``axis``, what the instrument's software wrote), and its other comment
    lines joined under ``Text``: what the file records about its measurement."""
    pairs: list[tuple[str, str]] = []
    loose: list[str] = []
    text = data[: 64 * 1024].decode("utf-8", errors="replace").lstrip("\ufeff")
    for line in text.splitlines():
        stripped = line.strip()
        if not stripped:
            continue
        if not stripped.startswith("#"):
            break
        body = stripped.lstrip("#").strip()
        key, sep, value = body.partition(":")
        if sep and key.strip() and " " not in key.strip():
            pairs.append((key.strip(), value.strip()))
        elif body:
            loose.append(body)
    if loose:
        pairs.append(("Text", " ".join(loose)))
    return tuple(pairs)


def _shown_paths(inputs: Sequence[str], command: Sequence[str]) -> list[tuple[str, str, bool]]:
    """(path as read, path as shown, named on the command line) of each input, each file
    once (the first time it is read).

    A file the command line names is shown as given; any other file relative to the
    folder of the last configuration named on the command line before it (as that
    configuration names it), or as read when there is none."""
    tokens = {os.path.normpath(t) for t in command}
    seen: set[str] = set()
    anchor: str | None = None
    out = []
    for path in inputs:
        real = os.path.realpath(path)
        if real in seen:
            continue
        seen.add(real)
        named = os.path.normpath(path) in tokens
        if named:
            shown = path
            if path.lower().endswith(".toml"):
                anchor = os.path.dirname(path) or "."
        elif anchor is not None and os.path.isabs(path) == os.path.isabs(anchor):
            shown = os.path.relpath(path, anchor)
        else:  # no configuration before it, or one named by an absolute path: as read
            shown = path
        out.append((path, Path(shown).as_posix(), named))
    return out


def collect(inputs: Iterable[str | os.PathLike[str]], command: Sequence[str]) -> Provenance:
    """The provenance of a run that read ``inputs`` (in order; each file is read once,
    a file named twice is recorded once) under the command line ``command`` (the
    arguments after ``esp``).

    Raises
    ------
    ParseError
        An input is no longer a readable regular file.
    """
    names = [os.fspath(p) for p in inputs]
    records = []
    configuration = []
    for path, shown, named in _shown_paths(names, command):
        record, text = _record(path, shown, named)
        records.append(record)
        if text is not None:
            configuration.append((shown, text))
    return Provenance(
        esp_version=__version__,
        command=tuple(command),
        inputs=tuple(records),
        configuration=tuple(configuration),
    )


def command_line() -> tuple[str, ...]:
    """The arguments after ``esp`` of the command being run.

    When esp runs as a program (``esp ...``, ``python -m esp ...``) they are the
    arguments as given (:data:`sys.argv`); when a command is invoked from Python (a test,
    :class:`click.testing.CliRunner`), they are rebuilt from the parsed parameters: the
    subcommand, its arguments, then each option given on the command line, in the order
    the command declares them. Empty outside a command."""
    ctx = click.get_current_context(silent=True)
    if ctx is None:
        return ()
    chain = []
    here: click.Context | None = ctx
    while here is not None:
        chain.append(here)
        here = here.parent
    chain.reverse()
    names = [c.info_name or "" for c in chain[1:]]
    argv = list(sys.argv[1:])
    program = Path(sys.argv[0]).name if sys.argv else ""
    if program in ("esp", "esp.exe", "__main__.py") and names and names[0] in argv:
        return tuple(argv)
    parts: list[str] = []
    for c in chain[1:]:
        parts.append(c.info_name or "")
        parts.extend(_given_parameters(c))
    return tuple(parts)


def _shown_value(value: Any) -> str:
    if isinstance(value, Mapping):  # an option its callback parsed (``--at X=..,Y=..``)
        return ",".join(f"{k}={_shown_value(v)}" for k, v in value.items())
    if isinstance(value, float):
        return f"{value:g}" if float(f"{value:g}") == value else repr(value)
    return os.fspath(value) if isinstance(value, os.PathLike) else str(value)


def _given_parameters(ctx: click.Context) -> list[str]:
    """The arguments, then the options given on the command line, of one command."""
    from click.core import ParameterSource

    arguments: list[str] = []
    options: list[str] = []
    for param in ctx.command.params:
        name = param.name or ""
        value = ctx.params.get(name)
        if isinstance(param, click.Argument):
            values = value if isinstance(value, (tuple, list)) else (value,)
            arguments.extend(_shown_value(v) for v in values if v is not None)
            continue
        if not isinstance(param, click.Option) or value is None:
            continue
        if ctx.get_parameter_source(name) is not ParameterSource.COMMANDLINE:
            continue
        longest = max(param.opts, key=len)
        if param.is_flag and not param.count:
            if value or not param.secondary_opts:
                options.append(longest)
            else:
                options.append(max(param.secondary_opts, key=len))
        elif param.count:
            options.extend([longest] * int(value))
        elif param.multiple:
            for v in value:
                options.append(longest)
                options.extend(
                    _shown_value(x) for x in (v if isinstance(v, (tuple, list)) else (v,))
                )
        else:
            options.append(longest)
            options.extend(
                _shown_value(x) for x in (value if isinstance(value, (tuple, list)) else (value,))
            )
    return arguments + options
