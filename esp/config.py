"""Read a machine description (``machine.toml``) into a :class:`esp.machine.Machine`.

The configuration is a user-facing contract; every key is documented in
``docs/configuration.md``. The reader is strict: an unknown key anywhere is refused with a
"did you mean" suggestion, and every problem raises :class:`esp.errors.ConfigError` naming
the dotted key (``axes.X.step``, ``axes.Y.errors.angular.Z``), what was expected and what
was found. Errors inside a data file (:class:`~esp.errors.ParseError`,
:class:`~esp.errors.DataError`) pass through unchanged.

Adding to the contract is meant to be a small change: a new top-level table is a name in
:data:`SECTIONS` and a ``_section_<name>`` method of the reader; a new kind of error source
is an entry of :data:`SOURCE_BUILDERS`.

References
----------
Longstaff (2002): 3.02-3.03 (configurations and B/M/T notation), 3.05 (datum), 3.07
eq. 3.6-3.9 (tool length and angles), 3.09 eq. 3.14-3.16 (mechanical angles γ), 3.10.1-3.10.5
(point of evaluation and compensation), 3.11-3.12 and figures 3.7-3.10 (the inputs of the
original program), 4.01.2.1 (straightness fit).
"""

from __future__ import annotations

import difflib
import math
import os
import re
import tomllib
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass, replace
from datetime import date, datetime, time
from pathlib import Path
from types import MappingProxyType
from typing import Any, NoReturn

from esp.angular import angular_from_linear, datum_index
from esp.errors import ConfigError, DataError
from esp.io.laser10 import kind_from_extension
from esp.io.load import load_profile
from esp.machine import (
    AXIS_NAMES,
    CONFIGURATIONS,
    ROLES,
    Analysis,
    Axis,
    Component,
    Machine,
    Tool,
)
from esp.names import ComponentName
from esp.profile import ErrorProfile
from esp.units import ANGLE_UNITS, DISPLACEMENT_UNITS, canonical_unit, engine_unit_for_kind

__all__ = ["SECTIONS", "SOURCE_BUILDERS", "load_machine", "machine_from_dict"]

#: the top-level tables, in the order they are read
SECTIONS = ("machine", "analysis", "axes", "squareness", "tool", "uncertainty")

_MACHINE_KEYS = ("name", "configuration", "axes", "serial", "location", "measured_by", "date")
_INFO_KEYS = ("serial", "location", "measured_by", "date")
_ANALYSIS_KEYS = (
    "point",
    "compensation",
    "direction",
    "datum",
    "straightness_fit",
    "extrapolate",
)
_AXIS_KEYS = ("travel", "simulate", "step", "offset", "errors")
_ERROR_KEYS = ("linear", "straightness", "angular", "mechanical")
_TOOL_KEYS = ("lengths", "orientation", "sweep")
#: thesis 3.12: 45° steps in the plane through the spindle axis, 90° steps about it
#: tilt is measured from the +T direction (eq. 3.6), so 0-180 covers a tool pointing either
#: way along the top axis; 45° steps as thesis 3.12 sets them
DEFAULT_SWEEP_TILT_DEG = (0.0, 45.0, 90.0, 135.0, 180.0)
DEFAULT_SWEEP_SPIN_DEG = (0.0, 90.0, 180.0, 270.0)

_POINTS = ("MCP", "TCP")
_COMPENSATIONS = ("none", "MCP", "TCP")
_DIRECTIONS = {"forward": "forward", "reverse": "backward", "mean": "mean"}
_DIRECTION_ALIASES = {"backward": "backward"}
_DATUMS = ("none", "negative", "centre")
_FITS = ("least-squares", "endpoint")
_CONFIGURATION_HINTS = {
    "BMTwt": "all axes carrying the workpiece is not modelled (thesis 3.03, 3.11)",
}

_TOML_WHERE = re.compile(r"\s*\((at line (\d+), column (\d+)|at end of document)\)\s*$")


# -- public API -------------------------------------------------------------------------


def load_machine(path: str | os.PathLike[str]) -> Machine:
    """Read a ``machine.toml`` file.

    Parameters
    ----------
    path : the configuration file; data files named in it are found relative to its folder

    Returns
    -------
    Machine

    Raises
    ------
    ConfigError
        The file is missing or unreadable (key ``"<file>"``), is not valid TOML (key
        ``"<toml>"``, with the line and column), or a key is unknown, missing or holds a
        value that does not fit (the dotted key).
    ParseError, DataError
        A data file named in the configuration cannot be read or used.
    """
    p = Path(path)
    try:
        raw = p.read_bytes()
    except FileNotFoundError:
        raise ConfigError("<file>", "no such configuration file", p) from None
    except IsADirectoryError:
        raise ConfigError("<file>", "is a folder, expected a machine.toml file", p) from None
    except OSError as exc:
        raise ConfigError("<file>", f"cannot be read: {exc.strerror or exc}", p) from None
    try:
        text = raw.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        found = f"byte {raw[exc.start]:#04x} at offset {exc.start}"
        raise ConfigError("<toml>", f"expected UTF-8 text, found {found}", p) from None
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ConfigError("<toml>", _toml_message(str(exc)), p) from None
    return machine_from_dict(data, p.parent, source=str(p))


def machine_from_dict(
    data: Mapping[str, Any], base_dir: str | os.PathLike[str], source: str | None = None
) -> Machine:
    """Build a :class:`~esp.machine.Machine` from the parsed content of a ``machine.toml``.

    For tests and what-if studies in code: ``data`` is what :func:`tomllib.loads` returns
    (plain dicts, lists, numbers and strings).

    Parameters
    ----------
    data : the configuration as nested mappings
    base_dir : the folder that relative data-file paths are resolved against
    source : the configuration file's name, used in error messages and kept as
        ``Machine.source``

    Raises
    ------
    ConfigError, ParseError, DataError
        As :func:`load_machine`.
    """
    return _Reader(Path(base_dir), source).machine(data)


# -- error sources ----------------------------------------------------------------------


@dataclass(frozen=True)
class _Slot:
    """Where an error source goes: its configuration key and the component it makes."""

    key: str  # e.g. "axes.X.errors.angular.Z"
    kind: str  # linear | straightness | angular | mechanical | squareness
    axis: str | None  # the moving axis
    about: str | None  # straightness direction, or the axis a rotation is about

    @property
    def profile_kind(self) -> str:
        """The kind of data: a mechanical angle is angular data (thesis 3.09)."""
        return "angular" if self.kind == "mechanical" else self.kind

    @property
    def name(self) -> ComponentName:
        """The component name (``X.linear``, ``X.angular.Z``, ``squareness.XY``)."""
        if self.kind == "squareness":
            return ComponentName.squareness(self.key[-2], self.key[-1])
        return ComponentName(self.kind, self.axis, self.about)


def _source_text(value: float, unit: str) -> str:
    return f"constant {value:g} {unit}"


def _build_file(reader: _Reader, table: Mapping[str, Any], slot: _Slot) -> Component:
    """A Laser10 or CSV data file, read by :func:`esp.io.load.load_profile`."""
    key = f"{slot.key}.file" if not isinstance(table, _Shorthand) else slot.key
    given = reader.string(table["file"], key)
    if not given.strip():
        reader.fail(key, f"expected a file path, found {given!r}")
    path = reader.base_dir / given
    if not path.exists():
        reader.fail(key, f"no such file {given!r} (looked for {str(path)!r})")
    if path.is_dir():
        reader.fail(key, f"{given!r} is a folder, expected a data file (at {str(path)!r})")
    options: dict[str, Any] = {"kind": slot.profile_kind, "axis": slot.axis}
    if slot.kind != "linear":
        options["error_direction"] = slot.about
    unit = reader.unit(table, slot)
    if unit is not None:
        options["unit"] = unit
    reader.inputs.append(str(path))
    try:
        profile = load_profile(path, **options)
    except OSError as exc:
        reader.fail(key, f"cannot read {given!r} (at {str(path)!r}): {exc.strerror or exc}")
    return Component(slot.name, slot.kind, slot.axis, slot.about, profile=profile, source=given)


def _inline_profile(slot: _Slot, positions, values, unit: str, text: str) -> ErrorProfile:
    """A profile written in the configuration.

    It is given as the same run in both directions, so that it applies whatever
    ``analysis.direction`` is chosen: an inline value has no direction of travel.
    """
    profile = ErrorProfile.from_values(
        slot.profile_kind,
        positions,
        values,
        unit,
        axis=slot.axis,
        error_direction=slot.about,
        source=text,
    )
    run = profile.runs["forward"]
    return replace(profile, runs={"forward": run, "backward": run})


def _build_constant(reader: _Reader, table: Mapping[str, Any], slot: _Slot) -> Component:
    """One value, valid at every position (a one-target profile is constant everywhere)."""
    value = reader.number(table["constant"], f"{slot.key}.constant")
    unit = reader.unit(table, slot) or engine_unit_for_kind(slot.kind)
    text = _source_text(value, unit)
    if slot.kind == "squareness":
        value_um_per_m = value * ANGLE_UNITS[unit]
        return Component(slot.name, slot.kind, None, None, value=value_um_per_m, source=text)
    profile = _inline_profile(slot, [0.0], [value], unit, text)
    return Component(slot.name, slot.kind, slot.axis, slot.about, profile=profile, source=text)


def _build_points(reader: _Reader, table: Mapping[str, Any], slot: _Slot) -> Component:
    """A short curve written in the configuration: ``[[position_mm, value], ...]``."""
    key = f"{slot.key}.points"
    points = table["points"]
    if not isinstance(points, list) or not points:
        reader.fail(key, f"expected a list of [position_mm, value] pairs, found {points!r}")
    positions: list[float] = []
    values: list[float] = []
    for i, item in enumerate(points):
        if not isinstance(item, list) or len(item) != 2:
            reader.fail(f"{key}[{i}]", f"expected a pair [position_mm, value], found {item!r}")
        positions.append(reader.number(item[0], f"{key}[{i}][0]"))
        values.append(reader.number(item[1], f"{key}[{i}][1]"))
    if len(set(positions)) != len(positions):
        twice = next(p for p in positions if positions.count(p) > 1)
        reader.fail(key, f"expected each position once, found {twice:g} mm more than once")
    unit = reader.unit(table, slot) or engine_unit_for_kind(slot.kind)
    profile = _inline_profile(slot, positions, values, unit, "points")
    return Component(slot.name, slot.kind, slot.axis, slot.about, profile=profile, source="points")


def _data_path(reader: _Reader, given: str, key: str) -> Path:
    """An existing data file named in the configuration, relative to its folder."""
    if not given.strip():
        reader.fail(key, f"expected a file path, found {given!r}")
    path = reader.base_dir / given
    if not path.exists():
        reader.fail(key, f"no such file {given!r} (looked for {str(path)!r})")
    if path.is_dir():
        reader.fail(key, f"{given!r} is a folder, expected a data file (at {str(path)!r})")
    return path


def _build_from_linear(reader: _Reader, table: Mapping[str, Any], slot: _Slot) -> Component:
    """An angle derived on the fly from two linear positioning files (thesis 3.08.1).

    ``from_linear = [reference, shifted]``, ``displacement`` (mm, signed, from the reference
    line to the shifted one) and ``datum`` (a target, mm, where the angle is zero); ``unit``
    is the unit of the two linear files. The mean curve of ``analysis.direction`` is made
    zero at the datum (:func:`esp.angular.angular_from_linear`).
    """
    key = f"{slot.key}.from_linear"
    files = table["from_linear"]
    if not (isinstance(files, list) and len(files) == 2 and all(isinstance(f, str) for f in files)):
        reader.fail(key, f"expected two linear file paths [reference, shifted], found {files!r}")
    for name, what in (
        ("displacement", "signed mm from the reference line to the shifted one"),
        ("datum", "the target in mm where the angle is zero"),
    ):
        if name not in table:
            reader.fail(f"{slot.key}.{name}", f"required key is missing ({what})")
    displacement = reader.number(table["displacement"], f"{slot.key}.displacement")
    if displacement == 0:
        reader.fail(
            f"{slot.key}.displacement",
            "expected a non-zero distance between the two linear runs, found 0",
        )
    datum = reader.number(table["datum"], f"{slot.key}.datum")
    options: dict[str, Any] = {"kind": "linear", "axis": slot.axis}
    if "unit" in table:
        given_unit = reader.string(table["unit"], f"{slot.key}.unit")
        try:
            options["unit"] = canonical_unit(given_unit)
        except DataError:
            options["unit"] = None
        if options["unit"] not in DISPLACEMENT_UNITS:
            reader.fail(
                f"{slot.key}.unit",
                f"expected the unit of the two linear files ({', '.join(DISPLACEMENT_UNITS)}), "
                f"found {given_unit!r}",
            )
    profiles = []
    for i, given in enumerate(files):
        path = _data_path(reader, given, f"{key}[{i}]")
        implied = kind_from_extension(path)
        if implied not in (None, "linear"):
            reader.fail(
                f"{key}[{i}]",
                f"expected a linear positioning file, found {given!r} ({implied} data)",
            )
        reader.inputs.append(str(path))
        try:
            profiles.append(load_profile(path, **options))
        except OSError as exc:
            reader.fail(
                f"{key}[{i}]", f"cannot read {given!r} (at {str(path)!r}): {exc.strerror or exc}"
            )
    try:
        datum_index(profiles[0].targets_mm, datum)
    except DataError as exc:
        reader.fail(f"{slot.key}.datum", f"{exc} ({files[0]})")
    try:
        result = angular_from_linear(
            profiles[0],
            profiles[1],
            displacement,
            datum,
            reader.direction,
            error_direction=slot.about,
        )
    except DataError as exc:
        reader.fail(key, str(exc))
    text = f"from_linear {files[0]}, {files[1]} (D = {displacement:g} mm, datum {datum:g} mm)"
    profile = replace(result.profile, source=text)
    return Component(slot.name, slot.kind, slot.axis, slot.about, profile=profile, source=text)


#: inline source tables: the key that selects the kind -> the builder of the component.
#: Every kind also accepts the options in :data:`SOURCE_OPTIONS`, and its own keys in
#: :data:`SOURCE_KEYS`; :data:`SOURCE_SLOT_KINDS` limits a kind to some components.
SOURCE_BUILDERS: dict[str, Callable[[_Reader, Mapping[str, Any], _Slot], Component]] = {
    "file": _build_file,
    "constant": _build_constant,
    "points": _build_points,
    "from_linear": _build_from_linear,
}
SOURCE_OPTIONS = ("unit",)
#: the keys a source kind accepts besides its own and :data:`SOURCE_OPTIONS`
SOURCE_KEYS: dict[str, tuple[str, ...]] = {"from_linear": ("displacement", "datum")}
#: source kinds that make sense only for some kinds of component
SOURCE_SLOT_KINDS: dict[str, tuple[str, ...]] = {"from_linear": ("angular", "mechanical")}
#: squareness is one number: only these source kinds make sense for it
_SQUARENESS_SOURCES = ("constant",)


class _Shorthand(dict):
    """A source written as a bare path string, seen as ``{file = path}``."""


# -- the reader -------------------------------------------------------------------------


def _join(prefix: str, name: str) -> str:
    return f"{prefix}.{name}" if prefix else name


def _suggest(word: str, options: Iterable[str]) -> str | None:
    """The option closest to ``word`` (case-insensitive match first, then difflib)."""
    options = list(options)
    for option in options:
        if option.lower() == str(word).lower():
            return option
    lowered = {o.lower(): o for o in options}
    close = difflib.get_close_matches(str(word).lower(), list(lowered), n=1, cutoff=0.6)
    return lowered[close[0]] if close else None


def _quoted(options: Iterable[str]) -> str:
    return ", ".join(repr(o) for o in options)


def _toml_message(message: str) -> str:
    """``"Invalid value (at line 2, column 5)"`` -> ``"invalid TOML at line 2, column 5: ..."``."""
    m = _TOML_WHERE.search(message)
    if not m:
        return f"invalid TOML: {message}"
    what = message[: m.start()]
    what = what[:1].lower() + what[1:]
    if m.group(2):
        return f"invalid TOML at line {m.group(2)}, column {m.group(3)}: {what}"
    return f"invalid TOML at the end of the file: {what}"


class _Reader:
    """Checks and converts one configuration; remembers where relative paths start."""

    def __init__(self, base_dir: Path, source: str | None):
        self.base_dir = base_dir
        #: analysis.direction, once read: the curve a derived angle is zero for at its datum
        self.direction = "mean"
        self.source = source
        #: every file read: the configuration and its data files
        self.inputs: list[str] = [source] if source else []

    # -- primitives ---------------------------------------------------------------------

    def fail(self, key: str, message: str) -> NoReturn:
        raise ConfigError(key, message, self.source)

    def table(
        self,
        value: Any,
        key: str,
        allowed: Iterable[str],
        required: Iterable[str] = (),
    ) -> Mapping[str, Any]:
        """``value`` as a table holding only ``allowed`` keys and every ``required`` one."""
        allowed = tuple(allowed)
        if not isinstance(value, Mapping):
            self.fail(key or "<top>", f"expected a table, found {value!r}")
        for name in value:
            if name not in allowed:
                hint = _suggest(name, allowed)
                did_you_mean = f"; did you mean {hint!r}?" if hint else ""
                self.fail(
                    _join(key, name),
                    f"unknown key {name!r}{did_you_mean} (expected one of {_quoted(allowed)})",
                )
        for name in required:
            if name not in value:
                self.fail(_join(key, name), "required key is missing")
        return value

    def number(self, value: Any, key: str) -> float:
        if isinstance(value, bool) or not isinstance(value, int | float):
            self.fail(key, f"expected a number, found {value!r}")
        x = float(value)
        if not math.isfinite(x):
            self.fail(key, f"expected a finite number, found {value!r}")
        return x

    def string(self, value: Any, key: str) -> str:
        if not isinstance(value, str):
            self.fail(key, f"expected a string, found {value!r}")
        return value

    def boolean(self, value: Any, key: str) -> bool:
        if not isinstance(value, bool):
            self.fail(key, f"expected true or false, found {value!r}")
        return value

    def choice(
        self,
        value: Any,
        key: str,
        choices: Iterable[str],
        aliases: Mapping[str, str] | None = None,
    ) -> str:
        """One of ``choices`` (or an alias of one), spelled exactly."""
        choices = tuple(choices)
        aliases = aliases or {}
        if isinstance(value, str) and value in aliases:
            return aliases[value]
        if isinstance(value, str) and value in choices:
            return value
        message = f"expected one of {_quoted(choices)}, found {value!r}"
        if isinstance(value, str):
            hint = _suggest(value, choices)
            if hint:
                message += f"; did you mean {hint!r}?"
        self.fail(key, message)

    def numbers(self, value: Any, key: str) -> tuple[float, ...]:
        """A non-empty list of numbers."""
        if not isinstance(value, list) or not value:
            self.fail(key, f"expected a non-empty list of numbers, found {value!r}")
        return tuple(self.number(v, f"{key}[{i}]") for i, v in enumerate(value))

    def interval(self, value: Any, key: str) -> tuple[float, float]:
        """``[low, high]`` in mm with low <= high."""
        if not isinstance(value, list) or len(value) != 2:
            self.fail(key, f"expected [low, high] in mm, found {value!r}")
        lo = self.number(value[0], f"{key}[0]")
        hi = self.number(value[1], f"{key}[1]")
        if lo > hi:
            self.fail(key, f"expected low <= high, found {value!r}")
        return lo, hi

    def xyz(self, value: Any, key: str, *, all_required: bool) -> Mapping[str, float]:
        """A table ``{ X = ..., Y = ..., Z = ... }`` of numbers, in X, Y, Z order."""
        if not isinstance(value, Mapping):
            self.fail(key, f"expected a table {{ X = ..., Y = ..., Z = ... }}, found {value!r}")
        table = self.table(value, key, AXIS_NAMES, AXIS_NAMES if all_required else ())
        return MappingProxyType(
            {n: self.number(table[n], f"{key}.{n}") if n in table else 0.0 for n in AXIS_NAMES}
        )

    def unit(self, table: Mapping[str, Any], slot: _Slot) -> str | None:
        """The canonical ``unit`` of an inline source, checked against its kind, or None."""
        if "unit" not in table:
            return None
        key = f"{slot.key}.unit"
        given = self.string(table["unit"], key)
        fitting = ANGLE_UNITS if engine_unit_for_kind(slot.kind) == "um/m" else DISPLACEMENT_UNITS
        try:
            unit = canonical_unit(given)
        except DataError:
            unit = None
        if unit not in fitting:
            what = "angle" if fitting is ANGLE_UNITS else "length"
            self.fail(
                key,
                f"expected a unit of {what} ({', '.join(fitting)}) for the {slot.kind} error "
                f"{slot.name}, found {given!r}",
            )
        return unit

    # -- error sources ------------------------------------------------------------------

    def component(self, value: Any, slot: _Slot, kinds: Iterable[str] | None = None) -> Component:
        """An error source: a path string, or an inline table selecting one source kind."""
        kinds = tuple(SOURCE_BUILDERS if kinds is None else kinds)
        unfit = [k for k in kinds if slot.kind not in SOURCE_SLOT_KINDS.get(k, (slot.kind,))]
        kinds = tuple(k for k in kinds if k not in unfit)
        if isinstance(value, Mapping):
            for k in unfit:
                if k in value:
                    self.fail(
                        f"{slot.key}.{k}",
                        f"is only for {' and '.join(SOURCE_SLOT_KINDS[k])} components, "
                        f"not the {slot.kind} error {slot.name}",
                    )
        if isinstance(value, str) and "file" in kinds:
            return SOURCE_BUILDERS["file"](self, _Shorthand(file=value), slot)
        if not isinstance(value, Mapping):
            forms = " or ".join(
                (["a file path"] if "file" in kinds else [])
                + [f"a table with {' or '.join(repr(k) for k in kinds)}"]
            )
            self.fail(slot.key, f"expected {forms}, found {value!r}")
        extra = tuple(dict.fromkeys(x for k in kinds for x in SOURCE_KEYS.get(k, ())))
        self.table(value, slot.key, kinds + SOURCE_OPTIONS + extra)
        chosen = [k for k in kinds if k in value]
        if len(chosen) != 1:
            found = "none" if not chosen else " and ".join(repr(k) for k in chosen)
            self.fail(slot.key, f"expected exactly one of {_quoted(kinds)}, found {found}")
        for name in value:
            if name in extra and name not in SOURCE_KEYS.get(chosen[0], ()):
                owner = next(k for k in kinds if name in SOURCE_KEYS.get(k, ()))
                self.fail(f"{slot.key}.{name}", f"only used with {owner!r}; remove it")
        return SOURCE_BUILDERS[chosen[0]](self, value, slot)

    # -- sections -----------------------------------------------------------------------

    def machine(self, data: Mapping[str, Any]) -> Machine:
        top = self.table(data, "", SECTIONS, required=("machine", "axes"))
        name, configuration, roles, info = self._section_machine(top["machine"])
        analysis = self._section_analysis(top.get("analysis", {}))
        self.direction = analysis.direction
        axes, components = self._section_axes(top["axes"], roles)
        components.update(self._section_squareness(top.get("squareness", {})))
        tool = self._section_tool(top["tool"]) if "tool" in top else None
        uncertainty = None
        if "uncertainty" in top:
            from esp.uncertainty.spec import parse_uncertainty

            uncertainty = parse_uncertainty(self, top["uncertainty"], components)
        self._check_datum(analysis, axes)
        if analysis.point == "TCP" and tool is None:
            self.fail("tool", "point = 'TCP' needs a [tool] table (lengths and orientation)")
        return Machine(
            name=name,
            configuration=configuration,
            roles=roles,
            axes=axes,
            components=components,
            analysis=analysis,
            tool=tool,
            info=info,
            source=self.source,
            uncertainty=uncertainty,
            inputs=tuple(dict.fromkeys(self.inputs)),
        )

    def _section_machine(self, value: Any):
        t = self.table(value, "machine", _MACHINE_KEYS, required=("name", "configuration", "axes"))
        name = self.string(t["name"], "machine.name")
        configuration = t["configuration"]
        if isinstance(configuration, str) and configuration in _CONFIGURATION_HINTS:
            self.fail(
                "machine.configuration",
                f"expected one of {_quoted(CONFIGURATIONS)}, found {configuration!r}: "
                f"{_CONFIGURATION_HINTS[configuration]}",
            )
        configuration = self.choice(configuration, "machine.configuration", CONFIGURATIONS)
        roles = self._roles(t["axes"])
        info: dict[str, str] = {}
        for k in _INFO_KEYS:
            if k not in t:
                continue
            v = t[k]
            if k == "date" and isinstance(v, date | datetime | time):
                info[k] = v.isoformat()
            else:
                info[k] = self.string(v, f"machine.{k}")
        return name, configuration, roles, info

    def _roles(self, value: Any) -> dict[str, str]:
        t = self.table(value, "machine.axes", ROLES, required=ROLES)
        roles = {r: self.choice(t[r], f"machine.axes.{r}", AXIS_NAMES) for r in ROLES}
        for letter in AXIS_NAMES:
            holders = [r for r in ROLES if roles[r] == letter]
            if len(holders) > 1:
                missing = [n for n in AXIS_NAMES if n not in roles.values()]
                self.fail(
                    "machine.axes",
                    f"expected X, Y and Z once each, found {letter!r} assigned to "
                    f"{' and '.join(holders)} (and {', '.join(missing)} to none)",
                )
        return roles

    def _section_analysis(self, value: Any) -> Analysis:
        t = self.table(value, "analysis", _ANALYSIS_KEYS)
        d = Analysis()
        point = self.choice(t.get("point", d.point), "analysis.point", _POINTS)
        compensation = self.choice(
            t.get("compensation", d.compensation), "analysis.compensation", _COMPENSATIONS
        )
        direction = self.choice(
            t.get("direction", "mean"),
            "analysis.direction",
            _DIRECTIONS,
            aliases={**_DIRECTIONS, **_DIRECTION_ALIASES},
        )
        datum = t.get("datum", d.datum)
        if isinstance(datum, Mapping):
            datum = self.xyz(datum, "analysis.datum", all_required=True)
        elif isinstance(datum, str):
            datum = self.choice(datum, "analysis.datum", _DATUMS)
        else:
            self.fail(
                "analysis.datum",
                f"expected one of {_quoted(_DATUMS)} or a table {{ X = ..., Y = ..., Z = ... }} "
                f"in mm, found {datum!r}",
            )
        fit = self.choice(
            t.get("straightness_fit", d.straightness_fit), "analysis.straightness_fit", _FITS
        )
        extrapolate = self.boolean(t.get("extrapolate", d.extrapolate), "analysis.extrapolate")
        return Analysis(
            point=point,
            compensation=compensation,
            direction=direction,
            datum=datum,
            straightness_fit=fit,
            extrapolate=extrapolate,
        )

    def _check_datum(self, analysis: Analysis, axes: Mapping[str, Axis]) -> None:
        if not isinstance(analysis.datum, Mapping):
            return
        for n in AXIS_NAMES:
            lo, hi = axes[n].travel_mm
            x = analysis.datum[n]
            if not lo <= x <= hi:
                self.fail(
                    f"analysis.datum.{n}",
                    f"expected a position within the travel of {n} [{lo:g}, {hi:g}] mm, "
                    f"found {x:g}",
                )

    def _section_axes(self, value: Any, roles: Mapping[str, str]):
        t = self.table(value, "axes", AXIS_NAMES, required=AXIS_NAMES)
        role_of = {letter: role for role, letter in roles.items()}
        axes: dict[str, Axis] = {}
        components: dict[str, Component] = {}
        for n in AXIS_NAMES:
            axes[n] = self._axis(n, role_of[n], t[n])
            components.update(self._axis_errors(n, t[n].get("errors", {})))
        return axes, components

    def _axis(self, n: str, role: str, value: Any) -> Axis:
        key = f"axes.{n}"
        t = self.table(value, key, _AXIS_KEYS, required=("travel",))
        travel = self.interval(t["travel"], f"{key}.travel")
        simulate = travel
        if "simulate" in t:
            simulate = self.interval(t["simulate"], f"{key}.simulate")
            if simulate[0] < travel[0] or simulate[1] > travel[1]:
                self.fail(
                    f"{key}.simulate",
                    f"expected a range within the travel [{travel[0]:g}, {travel[1]:g}] mm, "
                    f"found {t['simulate']!r}",
                )
        if "step" in t:
            step = self.number(t["step"], f"{key}.step")
            if step <= 0:
                self.fail(f"{key}.step", f"expected a step > 0 mm, found {t['step']!r}")
        elif travel[1] > travel[0]:
            self.fail(f"{key}.step", "required key is missing (the grid step in mm)")
        else:
            step = 0.0  # an axis that does not move: its grid is one point
        offset = self.number(t.get("offset", 0.0), f"{key}.offset")
        return Axis(n, role, travel, simulate, step, offset)

    def _axis_errors(self, n: str, value: Any) -> dict[str, Component]:
        key = f"axes.{n}.errors"
        t = self.table(value, key, _ERROR_KEYS)
        out: dict[str, Component] = {}
        if "linear" in t:
            slot = _Slot(f"{key}.linear", "linear", n, None)
            out[slot.name] = self.component(t["linear"], slot)
        others = tuple(a for a in AXIS_NAMES if a != n)
        for kind, letters in (
            ("straightness", others),
            ("angular", AXIS_NAMES),
            ("mechanical", AXIS_NAMES),
        ):
            if kind not in t:
                continue
            sub = t[kind]
            if not isinstance(sub, Mapping):
                what = "direction" if kind == "straightness" else "rotation axis"
                self.fail(
                    f"{key}.{kind}",
                    f"expected a table of {what} -> source such as "
                    f'{{ {letters[0]} = "file" }}, found {sub!r}',
                )
            if kind == "straightness" and n in sub:
                self.fail(
                    f"{key}.straightness.{n}",
                    f"a deviation of {n} along {n} is its linear error (errors.linear); "
                    f"expected {' or '.join(others)}",
                )
            self.table(sub, f"{key}.{kind}", letters)
            for about in letters:
                if about in sub:
                    slot = _Slot(f"{key}.{kind}.{about}", kind, n, about)
                    out[slot.name] = self.component(sub[about], slot)
        return out

    def _section_squareness(self, value: Any) -> dict[str, Component]:
        pairs = [a + b for a in AXIS_NAMES for b in AXIS_NAMES if a != b]
        t = self.table(value, "squareness", pairs)
        out: dict[str, Component] = {}
        for i, a in enumerate(AXIS_NAMES):
            for b in AXIS_NAMES[i + 1 :]:
                given = [p for p in (a + b, b + a) if p in t]
                if len(given) == 2:
                    self.fail(
                        f"squareness.{b + a}",
                        f"expected the pair {a}, {b} once, found it as both {a + b} and "
                        f"{b + a} (the pairs are unordered)",
                    )
                if not given:
                    continue
                slot = _Slot(f"squareness.{given[0]}", "squareness", None, None)
                v = t[given[0]]
                if isinstance(v, Mapping):
                    c = self.component(v, slot, kinds=_SQUARENESS_SOURCES)
                elif isinstance(v, int | float) and not isinstance(v, bool):
                    c = _build_constant(self, {"constant": v}, slot)
                else:
                    self.fail(
                        slot.key,
                        f"expected a number in um/m or a table {{ constant = ..., unit = ... }}, "
                        f"found {v!r}",
                    )
                out[c.name] = c
        return out

    def _section_tool(self, value: Any) -> Tool:
        t = self.table(value, "tool", _TOOL_KEYS)
        orientation = t.get("orientation", "sweep")
        expected = (
            "expected 'sweep', a table { tilt = deg, spin = deg } or "
            "{ offset = { X = mm, Y = mm, Z = mm } }"
        )
        if isinstance(orientation, str):
            if orientation != "sweep":
                hint = _suggest(orientation, ("sweep",))
                dym = f"; did you mean {hint!r}?" if hint else ""
                self.fail("tool.orientation", f"{expected}, found {orientation!r}{dym}")
            lengths = self._lengths(t)
            sweep = self.table(t.get("sweep", {}), "tool.sweep", ("tilt", "spin"))
            tilts = (
                self.numbers(sweep["tilt"], "tool.sweep.tilt")
                if "tilt" in sweep
                else DEFAULT_SWEEP_TILT_DEG
            )
            spins = (
                self.numbers(sweep["spin"], "tool.sweep.spin")
                if "spin" in sweep
                else DEFAULT_SWEEP_SPIN_DEG
            )
            pairs = tuple((a, b) for a in tilts for b in spins)
            return Tool(lengths_mm=lengths, orientations_deg=pairs, sweep=True)
        if not isinstance(orientation, Mapping):
            self.fail("tool.orientation", f"{expected}, found {orientation!r}")
        if "sweep" in t:
            self.fail("tool.sweep", "only used with orientation = 'sweep'; remove it")
        o = self.table(orientation, "tool.orientation", ("tilt", "spin", "offset"))
        if "offset" in o:
            if len(o) > 1:
                self.fail(
                    "tool.orientation",
                    f"expected either tilt and spin, or offset, found {', '.join(o)}",
                )
            if "lengths" in t:
                self.fail(
                    "tool.lengths",
                    "not used when tool.orientation gives an offset vector; remove it",
                )
            offset = self.xyz(o["offset"], "tool.orientation.offset", all_required=False)
            return Tool(lengths_mm=(), orientations_deg=(), offsets_mm=(offset,), sweep=False)
        self.table(o, "tool.orientation", ("tilt", "spin"), required=("tilt", "spin"))
        tilt = self.number(o["tilt"], "tool.orientation.tilt")
        spin = self.number(o["spin"], "tool.orientation.spin")
        return Tool(lengths_mm=self._lengths(t), orientations_deg=((tilt, spin),), sweep=False)

    def _lengths(self, t: Mapping[str, Any]) -> tuple[float, ...]:
        if "lengths" not in t:
            self.fail("tool.lengths", "required key is missing (tool lengths in mm)")
        lengths = self.numbers(t["lengths"], "tool.lengths")
        for i, x in enumerate(lengths):
            if x < 0:
                self.fail(f"tool.lengths[{i}]", f"expected a length >= 0 mm, found {x:g}")
        if len(set(lengths)) != len(lengths):
            self.fail("tool.lengths", f"expected each length once, found {t['lengths']!r}")
        return lengths
