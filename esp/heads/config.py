"""A head file (``HEAD.toml``): the ``[head]`` table and the optional ``[map]`` and
``[protocol]`` tables::

    [head]
    chain = "angle-head.toml"
    # ... see esp.config.devices

    [map]                                  # the grid of the error map (degrees)
    A = { from = -60, to = 60, step = 2.5 }
    C = { from = -60, to = 60, step = 2.5 }

    [protocol]
    angles = [0, 90, 180, 270]             # the settings of every axis
    assume_zero = ["DY", "ThetaAv"]        # errors assumed zero
    known = []                             # errors known beforehand (values from [head])
    identify = []                          # the errors to identify (default: the others)

The reader is strict: an unknown key is refused with a suggestion, every problem is one
:class:`esp.core.errors.ConfigError` naming the file and the dotted key.
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from esp.config.devices import load_head
from esp.core.devices.head import Head
from esp.core.errors import ConfigError
from esp.core.text import did_you_mean
from esp.core.values import Quantity, ValueRefused, check
from esp.heads.maps import GridSpec
from esp.heads.protocol import DEFAULT_ANGLES

__all__ = ["FILE_KEYS", "HeadFile", "ProtocolSpec", "read_head_file"]

FILE_KEYS = ("head", "map", "protocol")
PROTOCOL_KEYS = ("angles", "assume_zero", "known", "identify")


@dataclass(frozen=True)
class ProtocolSpec:
    """The ``[protocol]`` table: the settings and the assumptions of a protocol."""

    angles: tuple[float, ...] = DEFAULT_ANGLES
    assume_zero: tuple[str, ...] = ()
    known: tuple[str, ...] = ()
    identify: tuple[str, ...] | None = None


@dataclass(frozen=True)
class HeadFile:
    """What a head file holds."""

    head: Head
    grid: tuple[GridSpec, ...] | None
    protocol: ProtocolSpec


def _fail(source: Any, key: str, message: str) -> ConfigError:
    return ConfigError(key, message, source)


def _table(value: Any, key: str, allowed: tuple[str, ...], source: Any) -> Mapping[str, Any]:
    if not isinstance(value, Mapping):
        raise _fail(source, key, f"expected a table, found {value!r}")
    for k in value:
        if k not in allowed:
            raise _fail(
                source,
                f"{key}.{k}",
                f"unknown key {k!r}{did_you_mean(k, allowed)} (expected one of "
                + ", ".join(repr(a) for a in allowed)
                + ")",
            )
    return value


#: a setting of a head's axis in a map or a protocol, in the coordinate's unit: the range
#: of the coordinates (esp.core.kinematics.values.coordinate_arrays)
_SETTING = Quantity("a setting of the axis", "", -1e6, 1e6)


def _number(value: Any, key: str, source: Any) -> float:
    try:
        return check(value, _SETTING)
    except ValueRefused as exc:
        raise _fail(source, key, exc.message) from None


def _names(value: Any, key: str, source: Any) -> tuple[str, ...]:
    if not isinstance(value, list) or not all(isinstance(v, str) for v in value):
        raise _fail(source, key, f"expected a list of error names, found {value!r}")
    return tuple(value)


def read_head_file(path: str | os.PathLike[str]) -> HeadFile:
    """Read a head file (or a chain file, as a head with the chain's default values).

    Raises
    ------
    ConfigError
        An unknown table or key, a grid that is not over the head's coordinates, a value
        that does not fit (key and file named).
    """
    head, rest = load_head(path)
    source = head.source
    if head.to_identify:
        unknown = next(iter(head.to_identify.values()))
        raise _fail(
            source,
            unknown.key,
            "an unknown to identify ({ identify = ... }): run 'esp identify' on a "
            "machine.toml with [identify] (docs/identify.md), then use the head file it writes",
        )
    for k in rest:
        if k not in FILE_KEYS:
            raise _fail(
                source,
                k,
                f"unknown table {k!r}{did_you_mean(k, FILE_KEYS)} (expected one of "
                + ", ".join(repr(a) for a in FILE_KEYS)
                + ")",
            )
    grid = None
    if "map" in rest:
        coords = head.coordinates
        table = _table(rest["map"], "map", coords, source)
        specs = []
        for c in sorted(coords):
            if c not in table:
                raise _fail(source, f"map.{c}", "missing: give the grid of every angle")
            entry = _table(table[c], f"map.{c}", ("from", "to", "step"), source)
            for k in ("from", "to", "step"):
                if k not in entry:
                    raise _fail(source, f"map.{c}.{k}", "required key is missing")
            start, stop, step = (
                _number(entry[k], f"map.{c}.{k}", source) for k in ("from", "to", "step")
            )
            axis = GridSpec(c, start, stop, step)
            try:
                axis.values()
            except ConfigError as exc:
                raise _fail(source, exc.key.replace(c, f"map.{c}", 1), exc.message) from None
            specs.append(axis)
        grid = tuple(specs)
    spec = ProtocolSpec()
    if "protocol" in rest:
        table = _table(rest["protocol"], "protocol", PROTOCOL_KEYS, source)
        angles: tuple[float, ...] = DEFAULT_ANGLES
        if "angles" in table:
            raw = table["angles"]
            if not isinstance(raw, list) or len(raw) < 2:
                raise _fail(
                    source, "protocol.angles", f"expected at least two angles, found {raw!r}"
                )
            angles = tuple(_number(v, f"protocol.angles[{i}]", source) for i, v in enumerate(raw))
        names = {
            k: _names(table[k], f"protocol.{k}", source)
            for k in ("assume_zero", "known", "identify")
            if k in table
        }
        for k, values in names.items():
            for n in values:
                sym = head.chain.symbols.get(n)
                if sym is None or sym.kind != "error":
                    what = f"{n} is a {sym.kind}, not" if sym else f"unknown name {n!r}: not"
                    raise _fail(
                        source,
                        f"protocol.{k}",
                        f"{what} a small error of the head{did_you_mean(n, head.chain.errors)} "
                        f"({', '.join(head.chain.errors)})",
                    )
        spec = ProtocolSpec(
            angles,
            names.get("assume_zero", ()),
            names.get("known", ()),
            names.get("identify") or None,
        )
    return HeadFile(head, grid, spec)
