"""Error sources of ``machine.toml``: where a component's data come from.

A source is a path (a Laser10 or CSV file, see :mod:`esp.io.load`) or an inline table
that selects one kind: ``file``, ``constant``, ``points``, ``from_linear`` (an angle
derived from two linear files, thesis 3.08.1) or ``etalon`` (one parameter of an Etalon
Exchange file, :mod:`esp.io.etalon`), each with the options ``unit`` and
``scale``. A new kind of source is an entry of :data:`SOURCE_BUILDERS`.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np

from esp.config.reader import Reader, quoted
from esp.core.angular import angular_from_linear, datum_index
from esp.core.errors import DataError
from esp.core.machine import Component
from esp.core.names import ComponentName
from esp.core.profile import ErrorProfile
from esp.core.units import (
    ANGLE_UNITS,
    DISPLACEMENT_UNITS,
    MIN_SPACING_MM,
    canonical_unit,
    engine_unit_for_kind,
    limit_for_kind,
    limit_text,
)
from esp.core.values import shown
from esp.io.etalon import read_exchange
from esp.io.laser10 import kind_from_extension
from esp.io.load import load_profile

__all__ = [
    "SOURCE_BUILDERS",
    "SOURCE_KEYS",
    "SOURCE_OPTIONS",
    "SOURCE_SLOT_KINDS",
    "SQUARENESS_SOURCES",
    "Slot",
    "bare_constant",
    "build_constant",
    "read_source",
    "source_unit",
]


@dataclass(frozen=True)
class Slot:
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


def _factor(kind: str, unit: str) -> float:
    """What one ``unit`` is in the engine unit of ``kind``."""
    table = ANGLE_UNITS if engine_unit_for_kind(kind) == "um/m" else DISPLACEMENT_UNITS
    return table[unit]


def _plausible(
    reader: Reader, value: float, key: str, slot: Slot, unit: str, given: Any = None
) -> float:
    """``value`` (in ``unit``) in the engine unit, refused beyond the plausibility limit of
    the slot's kind (:func:`esp.core.units.limit_for_kind`); the message shows ``given``, the
    value as the file gives it."""
    engine = value * _factor(slot.kind, unit)
    if not abs(engine) <= limit_for_kind(slot.kind):
        reader.fail(
            key,
            f"expected {'an' if slot.kind[0] in 'aeiou' else 'a'} {slot.kind} error within "
            f"{limit_text(slot.kind, unit)}, "
            f"found {shown(value if given is None else given)} {unit}",
        )
    return engine


def _build_file(reader: Reader, table: Mapping[str, Any], slot: Slot) -> Component:
    """A Laser10 or CSV data file, read by :func:`esp.io.load.load_profile`."""
    key = f"{slot.key}.file" if not isinstance(table, _Shorthand) else slot.key
    given = reader.string(table["file"], key)
    path = _data_path(reader, given, key)
    options: dict[str, Any] = {"kind": slot.profile_kind, "axis": slot.axis}
    if slot.kind != "linear":
        options["error_direction"] = slot.about
    unit = source_unit(reader, table, slot)
    if unit is not None:
        options["unit"] = unit
    reader.inputs.append(str(path))
    try:
        profile = load_profile(path, **options)
    except OSError as exc:
        reader.fail(key, f"cannot read {given!r} (at {str(path)!r}): {exc.strerror or exc}")
    return Component(slot.name, slot.kind, slot.axis, slot.about, profile=profile, source=given)


def _inline_profile(
    slot: Slot, positions: Sequence[float], values: Sequence[float], unit: str, text: str
) -> ErrorProfile:
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


def build_constant(reader: Reader, table: Mapping[str, Any], slot: Slot) -> Component:
    """One value, valid at every position (a one-target profile is constant everywhere)."""
    key = slot.key if isinstance(table, _Shorthand) else f"{slot.key}.constant"
    value = reader.number(table["constant"], key)
    unit = source_unit(reader, table, slot) or engine_unit_for_kind(slot.kind)
    engine = _plausible(reader, value, key, slot, unit, table["constant"])
    text = _source_text(value, unit)
    if slot.kind == "squareness":
        return Component(slot.name, slot.kind, None, None, value=engine, source=text)
    profile = _inline_profile(slot, [0.0], [value], unit, text)
    return Component(slot.name, slot.kind, slot.axis, slot.about, profile=profile, source=text)


def _build_points(reader: Reader, table: Mapping[str, Any], slot: Slot) -> Component:
    """A short curve written in the configuration: ``[[position_mm, value], ...]``."""
    key = f"{slot.key}.points"
    points = table["points"]
    if not isinstance(points, list) or not points:
        reader.fail(key, f"expected a list of [position_mm, value] pairs, found {points!r}")
    unit = source_unit(reader, table, slot) or engine_unit_for_kind(slot.kind)
    positions: list[float] = []
    values: list[float] = []
    for i, item in enumerate(points):
        if not isinstance(item, list) or len(item) != 2:
            reader.fail(f"{key}[{i}]", f"expected a pair [position_mm, value], found {item!r}")
        positions.append(reader.position(item[0], f"{key}[{i}][0]"))
        values.append(reader.number(item[1], f"{key}[{i}][1]"))
        _plausible(reader, values[-1], f"{key}[{i}][1]", slot, unit, item[1])
    if len(points) < 2:
        reader.fail(
            key,
            f"expected two [position_mm, value] pairs or more (one value is a constant error: "
            f"write it as 'constant = ...'), found {points!r}",
        )
    if len(set(positions)) != len(positions):
        twice = next(p for p in positions if positions.count(p) > 1)
        reader.fail(key, f"expected each position once, found {shown(twice)} mm more than once")
    order = sorted(range(len(positions)), key=positions.__getitem__)
    for a, b in zip(order, order[1:], strict=False):
        if positions[b] - positions[a] < MIN_SPACING_MM * (1 - 1e-6):
            reader.fail(
                f"{key}[{b}][0]",
                f"expected positions at least {MIN_SPACING_MM:g} mm apart, found "
                f"{positions[b]:.10g} mm and {positions[a]:.10g} mm ({key}[{a}][0])",
            )
    profile = _inline_profile(slot, positions, values, unit, "points")
    return Component(slot.name, slot.kind, slot.axis, slot.about, profile=profile, source="points")


def _data_path(reader: Reader, given: str, key: str) -> Path:
    """An existing data file named in the configuration, relative to its folder."""
    if not given.strip():
        reader.fail(key, f"expected a file path, found {given!r}")
    path = reader.base_dir / given
    if not path.exists():
        reader.fail(key, f"no such file {given!r} (looked for {str(path)!r})")
    if path.is_dir():
        reader.fail(key, f"{given!r} is a folder, expected a data file (at {str(path)!r})")
    return path


def _build_from_linear(reader: Reader, table: Mapping[str, Any], slot: Slot) -> Component:
    """An angle derived on the fly from two linear positioning files (thesis 3.08.1).

    ``from_linear = [reference, shifted]``, ``displacement`` (mm, signed, from the reference
    line to the shifted one) and ``datum`` (a target, mm, where the angle is zero); ``unit``
    is the unit of the two linear files. The mean curve of ``analysis.direction`` is made
    zero at the datum (:func:`esp.core.angular.angular_from_linear`).
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
    displacement = reader.position(table["displacement"], f"{slot.key}.displacement", "a distance")
    if abs(displacement) < MIN_SPACING_MM:
        reader.fail(
            f"{slot.key}.displacement",
            f"expected a distance between the two linear runs of at least {MIN_SPACING_MM:g} mm "
            f"in size, found {table['displacement']!r}",
        )
    datum = reader.position(table["datum"], f"{slot.key}.datum")
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
    return Component(
        slot.name, slot.kind, slot.axis, slot.about, profile=profile, source=text, from_linear=True
    )


_ROTATION = {"X": "A", "Y": "B", "Z": "C"}


def etalon_symbol(slot: Slot) -> str:
    """The ISO 230-1 parameter name of a slot as an Etalon Exchange file spells it:
    ``EXX`` (X.linear), ``EYX`` (X.straightness.Y), ``ECX`` (X.angular.Z), ``C0Y``
    (squareness.XY, ISO 230-1 EC0Y without the leading E)."""
    if slot.kind == "squareness":
        a, b = slot.key[-2], slot.key[-1]
        second = max(a, b, key="XYZ".index)
        third = next(n for n in "XYZ" if n not in (a, b))
        return f"{_ROTATION[third]}0{second}"
    assert slot.axis is not None
    if slot.kind == "linear":
        return f"E{slot.axis}{slot.axis}"
    assert slot.about is not None
    if slot.kind == "straightness":
        return f"E{slot.about}{slot.axis}"
    return f"E{_ROTATION[slot.about]}{slot.axis}"


def _build_etalon(reader: Reader, table: Mapping[str, Any], slot: Slot) -> Component:
    """One parameter of an Etalon Exchange file (LaserTRACER results; the layout of the
    Beckhoff TF5280 "Etalon Exchange Format" page, docs/formats.md): offsets and arguments
    in mm, angles in rad, the values errors. A table's values hold one direction of
    travel, applied to both; squareness is converted from ISO 230-1 EC0Y-style position
    errors with the sign of docs/conventions.md."""
    key = f"{slot.key}.etalon"
    if "unit" in table:
        reader.fail(
            f"{slot.key}.unit", "an Etalon Exchange file gives its units (mm, rad): remove it"
        )
    given = reader.string(table["etalon"], key)
    path = _data_path(reader, given, key)
    reader.inputs.append(str(path))
    try:
        blocks = read_exchange(path)
    except OSError as exc:
        reader.fail(key, f"cannot read {given!r} (at {str(path)!r}): {exc.strerror or exc}")
    symbol = etalon_symbol(slot)
    if symbol not in blocks:
        reader.fail(key, f"expected a [{symbol}] block for {slot.name} in {given!r}, found none")
    block = blocks[symbol]
    text = f"{given} [{symbol}]"
    if slot.kind == "squareness":
        if block.value is None:
            reader.fail(
                key, f"{given}:{block.line}: expected [{symbol}] VALUE = ..., found a table"
            )
        engine = _plausible(reader, slot.name.iso_sign * block.value * 1e6, key, slot, "um/m")
        return Component(slot.name, slot.kind, None, None, value=engine, source=text)
    if block.table is None:
        reader.fail(key, f"{given}:{block.line}: expected [{symbol}] Gridpoints = {{...}}")
    positions, values = block.table[:, 0], block.table[:, 1]
    if not np.all(np.diff(positions) > 0):
        reader.fail(key, f"{given}:{block.line}: expected [{symbol}] arguments that increase")
    factor, unit = (1e3, "um") if slot.kind in ("linear", "straightness") else (1e6, "um/m")
    for v in values:
        _plausible(reader, float(v) * factor, key, slot, unit)
    profile = _inline_profile(slot, list(positions), list(values * factor), unit, text)
    return Component(slot.name, slot.kind, slot.axis, slot.about, profile=profile, source=text)


#: inline source tables: the key that selects the kind -> the builder of the component.
#: Every kind also accepts the options in :data:`SOURCE_OPTIONS`, and its own keys in
#: :data:`SOURCE_KEYS`; :data:`SOURCE_SLOT_KINDS` limits a kind to some components.
SOURCE_BUILDERS: dict[str, Callable[[Reader, Mapping[str, Any], Slot], Component]] = {
    "file": _build_file,
    "constant": build_constant,
    "points": _build_points,
    "from_linear": _build_from_linear,
    "etalon": _build_etalon,
}
SOURCE_OPTIONS = ("unit", "scale")
#: the keys a source kind accepts besides its own and :data:`SOURCE_OPTIONS`
SOURCE_KEYS: dict[str, tuple[str, ...]] = {"from_linear": ("displacement", "datum")}
#: source kinds that make sense only for some kinds of component
SOURCE_SLOT_KINDS: dict[str, tuple[str, ...]] = {"from_linear": ("angular", "mechanical")}
#: squareness is one number: only these source kinds make sense for it
SQUARENESS_SOURCES = ("constant", "etalon")


class _Shorthand(dict):
    """A source written as a bare path string, seen as ``{file = path}``, or as a bare
    number, seen as ``{constant = number}``: messages name the slot's key itself."""


def bare_constant(reader: Reader, value: Any, slot: Slot) -> Component:
    """A source written as a bare number (``squareness.XY = 4.5``)."""
    return build_constant(reader, _Shorthand(constant=value), slot)


def source_unit(reader: Reader, table: Mapping[str, Any], slot: Slot) -> str | None:
    """The canonical ``unit`` of an inline source, checked against its kind, or None."""
    if "unit" not in table:
        return None
    key = f"{slot.key}.unit"
    given = reader.string(table["unit"], key)
    fitting = ANGLE_UNITS if engine_unit_for_kind(slot.kind) == "um/m" else DISPLACEMENT_UNITS
    try:
        unit = canonical_unit(given)
    except DataError:
        unit = None
    if unit not in fitting:
        what = "angle" if fitting is ANGLE_UNITS else "length"
        reader.fail(
            key,
            f"expected a unit of {what} ({', '.join(fitting)}) for the {slot.kind} error "
            f"{slot.name}, found {given!r}",
        )
    return unit


# -- error sources ------------------------------------------------------------------


def read_source(
    reader: Reader, value: Any, slot: Slot, kinds: Iterable[str] | None = None
) -> Component:
    """An error source: a path string, or an inline table selecting one source kind."""
    kinds = tuple(SOURCE_BUILDERS if kinds is None else kinds)
    unfit = [k for k in kinds if slot.kind not in SOURCE_SLOT_KINDS.get(k, (slot.kind,))]
    kinds = tuple(k for k in kinds if k not in unfit)
    if isinstance(value, Mapping):
        for k in unfit:
            if k in value:
                reader.fail(
                    f"{slot.key}.{k}",
                    f"is only for {' and '.join(SOURCE_SLOT_KINDS[k])} components, "
                    f"not the {slot.kind} error {slot.name}",
                )
    if isinstance(value, Mapping) and "identify" in value:
        reader.fail(
            f"{slot.key}.identify",
            "this component is to be identified from measurements: run 'esp identify' on "
            "this file (docs/identify.md), then analyse the machine.toml it writes",
        )
    if isinstance(value, str) and "file" in kinds:
        return SOURCE_BUILDERS["file"](reader, _Shorthand(file=value), slot)
    if not isinstance(value, Mapping):
        forms = " or ".join(
            (["a file path"] if "file" in kinds else [])
            + [f"a table with {' or '.join(repr(k) for k in kinds)}"]
        )
        reader.fail(slot.key, f"expected {forms}, found {value!r}")
    extra = tuple(dict.fromkeys(x for k in kinds for x in SOURCE_KEYS.get(k, ())))
    reader.table(value, slot.key, kinds + SOURCE_OPTIONS + extra)
    chosen = [k for k in kinds if k in value]
    if len(chosen) != 1:
        found = "none" if not chosen else " and ".join(repr(k) for k in chosen)
        reader.fail(slot.key, f"expected exactly one of {quoted(kinds)}, found {found}")
    for name in value:
        if name in extra and name not in SOURCE_KEYS.get(chosen[0], ()):
            owner = next(k for k in kinds if name in SOURCE_KEYS.get(k, ()))
            reader.fail(f"{slot.key}.{name}", f"only used with {owner!r}; remove it")
    component = SOURCE_BUILDERS[chosen[0]](reader, value, slot)
    if "scale" in value:
        component = _scaled(reader, component, value["scale"], f"{slot.key}.scale")
    return component


def _scaled(reader: Reader, component: Component, given: Any, key: str) -> Component:
    """The component with its values multiplied by ``scale`` (e.g. -1 for data measured
    with the opposite sign, docs/conventions.md)."""
    factor = reader.number(given, key)
    if factor == 0:
        reader.fail(key, "expected a non-zero factor (such as -1 or 1), found 0")
    if abs(factor) > 1000 or abs(factor) < 1e-3:
        reader.fail(key, f"expected a factor between 0.001 and 1000 in size, found {shown(given)}")
    source = f"{component.source} (scale {factor:g})"
    if component.profile is None:
        value = float(component.value or 0.0) * factor
        if not abs(value) <= limit_for_kind(component.kind):
            reader.fail(
                key,
                f"the scaled value {value:g} um/m lies beyond the plausibility limit "
                f"{limit_text(component.kind)}",
            )
        return replace(component, value=value, source=source)
    try:
        profile = component.profile.scaled(factor)
    except DataError as exc:
        reader.fail(key, f"scaled by {factor:g}: {exc}")
    return replace(component, profile=profile, source=source)


# -- sections -----------------------------------------------------------------------
