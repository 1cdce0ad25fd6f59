"""A rotary table: a kinematic chain from the workpiece to the table's mount, with the
values of its parameters and of its ISO 230-7 errors (constants, or curves over an angle).

A table file (``TABLE.toml``) names the chain and gives the values::

    [table]
    name = "A/C trunnion, example"
    chain = "trunnion-ac.toml"          # relative to this file
    errors_from = ["identified.csv"]    # constant error values from files (optional)
    setup = { A = 0, C = 0 }            # the workpiece is set up at this setting (optional)

    [table.parameters]                  # in each symbol's unit, or { value, unit }
    y_A = 0
    z_A = -150

    [table.errors]
    X0C = 4                             # a constant, in the symbol's unit (µm)
    A0C = { value = 3, unit = "arcsec" }
    ECC = { file = "C-positioning.csv", column = "ECC", unit = "arcsec" }
    EYA = { file = "A-motions.csv", column = "EYA", periodic = false }

The same table can stand in another file: :func:`table_from_dict` reads it with a key
prefix for messages and lets the caller allow keys of its own. A value comes, by
increasing precedence, from the chain's default (``symbols.NAME.value``), the files of
``errors_from``, the table, and :meth:`Table.with_values`; an error nothing gives a value
is zero. A curve (``file = ...``) can feed only an error in the error motion of a joint
(a component error motion, a function of that joint's angle); the location errors are
constants. Every problem is one :class:`esp.core.errors.ConfigError` naming the file and the
dotted key, or a :class:`esp.core.errors.ParseError` naming a data file and line.

See ``docs/rotary.md``.
"""

from __future__ import annotations

import os
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field, replace
from pathlib import Path
from types import MappingProxyType
from typing import Any

import numpy as np

from esp.core.devices.table_curves import Curve, read_curve
from esp.core.errors import ConfigError
from esp.core.kinematics import Chain, Prismatic, Revolute, load_chain
from esp.core.kinematics.values import (
    chain_defaults,
    chain_of_table,
    convert_unit,
    errors_from,
    finite_value,
    name_and_description,
    symbol_kind_message,
    symbol_value,
)
from esp.core.text import did_you_mean
from esp.core.values import shown
from esp.io.tomlfile import read_toml_file

__all__ = [
    "ENTRY_KEYS",
    "TABLE_KEYS",
    "TIP_PARAMETERS",
    "Table",
    "load_table",
    "table_from_chain",
    "table_from_dict",
]

#: the keys of a ``[table]`` table
TABLE_KEYS = ("name", "description", "chain", "setup", "parameters", "errors", "errors_from")
#: the keys of an error's entry: a constant ``{value, unit, scale}`` or a curve
#: ``{file, column, unit, scale, periodic}``
ENTRY_KEYS = ("value", "file", "column", "unit", "scale", "periodic")
#: the parameters esp appends to a table chain for the tool tip in the machine frame
TIP_PARAMETERS = ("esp_tip_x", "esp_tip_y", "esp_tip_z")
#: largest angle accepted, degrees
_MAX_ANGLE = 1e6


def _join(prefix: str, name: str) -> str:
    return f"{prefix}.{name}" if prefix else name


def _expected(allowed: Iterable[str]) -> str:
    return "expected one of " + ", ".join(repr(a) for a in allowed)


@dataclass(frozen=True)
class Table:
    """A table chain with the values of its parameters and errors.

    Attributes
    ----------
    chain : the kinematic chain from the workpiece (its base) to the table's mount on the
        linear axes (its tip: the origin of the machine frame); every coordinate drives a
        revolute joint
    name, description : for reports
    parameters : every parameter of the chain -> its value, in the symbol's unit
    errors : every small error of the chain given as a constant -> its value, in the
        symbol's unit (zero when nothing gives one); an error with a curve is not here
    curves : error -> :class:`~esp.core.devices.table_curves.Curve`, its values over the angle of
        ``curve_axes[error]``, in the symbol's unit
    curve_axes : error with a curve -> the coordinate of the joint whose error motion
        holds it
    setup_deg : the setting at which the workpiece is set up (coordinate -> degrees), or
        None: the workpiece frame is the nominal table's (``docs/rotary.md``)
    origins : name -> where its value came from (``"chain"``, a file name, ``"--set"``)
    source : the file the table was read from, for messages
    inputs : every file read (the table file, the chain, the value and curve files)
    """

    chain: Chain
    name: str
    parameters: Mapping[str, float]
    errors: Mapping[str, float]
    curves: Mapping[str, Curve] = field(default_factory=dict)
    curve_axes: Mapping[str, str] = field(default_factory=dict)
    setup_deg: Mapping[str, float] | None = None
    origins: Mapping[str, str] = field(default_factory=dict)
    description: str = ""
    source: str | None = None
    inputs: tuple[str, ...] = ()

    @property
    def coordinates(self) -> tuple[str, ...]:
        """The table's axes (the chain's coordinates), workpiece side first."""
        return self.chain.coordinates

    def unit(self, name: str) -> str:
        """The unit of a symbol's values."""
        return self.chain.symbols[name].unit

    def values_at(self, angles_deg: Mapping[str, np.ndarray], n: int) -> dict[str, np.ndarray]:
        """Every error of the chain -> its values (N,) at N settings (each coordinate ->
        (N,) degrees), in the symbol's unit: a constant repeated, a curve interpolated."""
        out: dict[str, np.ndarray] = {}
        for e in self.chain.errors:
            if e in self.curves:
                out[e] = np.asarray(self.curves[e].at(angles_deg[self.curve_axes[e]]), float)
            else:
                out[e] = np.full(n, float(self.errors.get(e, 0.0)))
        return out

    def with_values(self, values: Mapping[str, float], origin: str = "--set") -> Table:
        """A copy with some parameter and constant error values replaced (each in its
        symbol's unit); an error given a constant here loses its curve.

        Raises
        ------
        ConfigError
            A name that is not a parameter or an error of the chain, a value that is not a
            finite number (key ``origin.NAME``).
        """
        params = dict(self.parameters)
        errors = dict(self.errors)
        curves = dict(self.curves)
        axes = dict(self.curve_axes)
        origins = dict(self.origins)
        for n, v in values.items():
            key = f"--set {n}" if origin == "--set" else _join(origin, n)
            sym = self.chain.symbols.get(n)
            if sym is None or sym.kind == "coordinate":
                raise ConfigError(key, _not_a_value(self.chain, n))
            x = symbol_value(v, key, sym)
            if sym.kind == "parameter":
                params[n] = x
            else:
                errors[n] = x
                curves.pop(n, None)
                axes.pop(n, None)
            origins[n] = origin
        return replace(
            self,
            parameters=MappingProxyType(params),
            errors=MappingProxyType(errors),
            curves=MappingProxyType(curves),
            curve_axes=MappingProxyType(axes),
            origins=MappingProxyType(origins),
        )

    def with_setup(self, setup: Mapping[str, Any] | None, key: str = "setup") -> Table:
        """A copy whose workpiece is set up at ``setup`` (every axis -> degrees), or, with
        None, whose workpiece frame is the nominal table's.

        Raises
        ------
        ConfigError
            Not a mapping of every axis of the table to a finite angle (key ``setup.C``).
        """
        if setup is None:
            return replace(self, setup_deg=None)
        return replace(self, setup_deg=MappingProxyType(_setup(setup, key, self.coordinates)))


def _not_a_value(chain: Chain, name: str) -> str:
    sym = chain.symbols.get(name)
    if sym is not None and sym.kind == "coordinate":
        return f"{name} is an axis of the table; give its angles where the table is evaluated"
    names = [n for n, s in chain.symbols.items() if s.kind != "coordinate"]
    return (
        f"not a parameter or error of the chain{did_you_mean(name, names)} "
        f"({', '.join(names) or 'none'})"
    )


def _check_chain(chain: Chain, key: str, source: str | None) -> None:
    if not chain.coordinates:
        raise ConfigError(key, "the chain has no coordinate (no revolute joint)", source)
    for i, step in enumerate(chain.steps, 1):
        if isinstance(step, Prismatic):
            raise ConfigError(
                key,
                f"steps[{i}] is a prismatic joint ({step.coordinate}); a table chain holds "
                "only rotary axes (the linear axes are the machine's)",
                source,
            )
    for n in TIP_PARAMETERS:
        if n in chain.symbols:
            raise ConfigError(key, f"the symbol name {n!r} is reserved for the tool tip", source)


def _joint_of(chain: Chain) -> dict[str, str]:
    """error -> the coordinate of the one revolute joint whose error motion holds it."""
    out: dict[str, str] = {}
    seen: dict[str, set[str]] = {}
    for step in chain.steps:
        if isinstance(step, Revolute) and step.errors is not None:
            for expr in step.errors.slots().values():
                for n in expr.names():
                    if chain.symbols[n].kind == "error":
                        seen.setdefault(n, set()).add(step.coordinate)
    for n, coords in seen.items():
        if len(coords) == 1:
            out[n] = next(iter(coords))
    return out


def table_from_chain(chain: Chain, name: str | None = None) -> Table:
    """A table holding the chain's own default values (every parameter must have one).

    Raises
    ------
    ConfigError
        The chain has no revolute joint, holds a prismatic joint, uses a reserved name, or
        a parameter has no default value.
    """
    _check_chain(chain, "chain", chain.source)
    params, errors, origins = chain_defaults(chain)
    return Table(
        chain,
        name or chain.name,
        MappingProxyType(params),
        MappingProxyType(errors),
        MappingProxyType({}),
        MappingProxyType({}),
        None,
        MappingProxyType(origins),
        description=chain.description,
        source=chain.source,
        inputs=(chain.source,) if chain.source else (),
    )


# -- reading a [table] ----------------------------------------------------------------------


def table_from_dict(
    table: Mapping[str, Any],
    *,
    base_dir: str | os.PathLike[str] = ".",
    source: str | None = None,
    prefix: str = "table",
    allow: Iterable[str] = (),
) -> Table:
    """Read a ``[table]`` table (see the module docstring).

    Parameters
    ----------
    table : the parsed table
    base_dir : where the relative paths of ``chain``, ``errors_from`` and curve files start
    source : the file holding the table, for messages
    prefix : the table's dotted key in that file (``"table"``), for messages
    allow : further keys the caller reads itself (e.g. ``"angles"`` in a machine file);
        they are accepted and ignored here

    Raises
    ------
    ConfigError
        An unknown key (with a suggestion), a missing ``chain``, a value that is not a
        finite number, a unit that does not fit, a name that is not a parameter or error of
        the chain, a curve for a location error, a set-up setting that is not over the
        table's axes; the chain file's own errors name that file.
    ParseError
        An error-value or curve file that does not read (file and line).
    """
    chain, chain_ref = chain_of_table(
        table,
        prefix=prefix,
        allowed=TABLE_KEYS + tuple(allow),
        owner="table",
        base_dir=base_dir,
        source=source,
    )
    base = Path(base_dir)

    def fail(key: str, message: str) -> ConfigError:
        return ConfigError(key, message, source)

    try:
        _check_chain(chain, _join(prefix, "chain"), None)
    except ConfigError as exc:
        raise fail(exc.key, f"{chain_ref}: {exc.message}") from None
    start = table_from_chain(chain)
    inputs = list(start.inputs)
    if source:
        inputs.insert(0, source)

    name, description = name_and_description(table, chain, prefix, source)

    setup = None
    if "setup" in table:
        try:
            setup = _setup(table["setup"], _join(prefix, "setup"), chain.coordinates)
        except ConfigError as exc:
            raise fail(exc.key, exc.message) from None

    params = dict(start.parameters)
    errors = dict(start.errors)
    origins = dict(start.origins)
    curves: dict[str, Curve] = {}
    axes: dict[str, str] = {}

    try:
        values, from_files, read = errors_from(
            table.get("errors_from", []), _join(prefix, "errors_from"), base, chain
        )
    except ConfigError as exc:
        raise fail(exc.key, exc.message) from None
    errors.update(values)
    origins.update(from_files)
    inputs.extend(read)

    joint_of = _joint_of(chain)
    here = Path(source).name if source else "table"
    for group, kind in (("parameters", "parameter"), ("errors", "error")):
        raw = table.get(group, {})
        gkey = _join(prefix, group)
        if not isinstance(raw, Mapping):
            raise fail(gkey, f"expected a table of name = value, found {raw!r}")
        for n, v in raw.items():
            key = f"{gkey}.{n}"
            message = symbol_kind_message(chain, n, kind, prefix)
            if message is not None:
                raise fail(key, message)
            try:
                if isinstance(v, Mapping) and "file" in v:
                    if kind != "error":
                        raise ConfigError(
                            f"{key}.file", "a parameter is a number, not a curve from a file"
                        )
                    curve = _curve_entry(v, key, n, chain, joint_of, base)
                    curves[n] = curve
                    axes[n] = joint_of[n]
                    errors.pop(n, None)
                    origins[n] = curve.source
                    inputs.append(str(base / v["file"]))
                    continue
                x = _value_entry(v, key, n, chain, allow_scale=kind == "error")
            except ConfigError as exc:
                raise fail(exc.key, exc.message) from None
            (params if kind == "parameter" else errors)[n] = x
            curves.pop(n, None)
            axes.pop(n, None)
            origins[n] = here

    return Table(
        chain,
        name,
        MappingProxyType(params),
        MappingProxyType(errors),
        MappingProxyType(curves),
        MappingProxyType(axes),
        None if setup is None else MappingProxyType(setup),
        MappingProxyType(origins),
        description=description,
        source=source,
        inputs=tuple(dict.fromkeys(inputs)),
    )


def _setup(raw: Any, key: str, coords: tuple[str, ...]) -> dict[str, float]:
    if not isinstance(raw, Mapping):
        raise ConfigError(
            key, f"expected the set-up setting, e.g. {{ {coords[0]} = 0 }}, found {raw!r}"
        )
    for c in raw:
        if c not in coords:
            raise ConfigError(
                f"{key}.{c}",
                f"not an axis of the table{did_you_mean(c, coords)} ({', '.join(coords)})",
            )
    out = {}
    for c in coords:
        if c not in raw:
            raise ConfigError(
                f"{key}.{c}", f"missing: give the set-up angle of every axis ({', '.join(coords)})"
            )
        out[c] = finite_value(raw[c], f"{key}.{c}", _MAX_ANGLE)
    return out


def _entry_keys(raw: Mapping[str, Any], key: str, allowed: tuple[str, ...]) -> None:
    for k in raw:
        if k not in allowed:
            raise ConfigError(
                f"{key}.{k}", f"unknown key {k!r}{did_you_mean(k, allowed)} ({_expected(allowed)})"
            )


def _scale(raw: Mapping[str, Any], key: str) -> float:
    s = finite_value(raw.get("scale", 1.0), f"{key}.scale")
    if s == 0.0:
        raise ConfigError(f"{key}.scale", "expected a non-zero factor (1, or -1 to flip a sign)")
    return s


def _value_entry(raw: Any, key: str, name: str, chain: Chain, *, allow_scale: bool) -> float:
    """A value: a number in the symbol's unit, or ``{ value, unit, scale }``."""
    target = chain.symbols[name].unit
    if not isinstance(raw, Mapping):
        return symbol_value(raw, key, chain.symbols[name])
    allowed = ("value", "unit", "scale") if allow_scale else ("value", "unit")
    for k in raw:
        if k in ("column", "periodic") and allow_scale:
            raise ConfigError(f"{key}.{k}", f"{k!r} belongs to a curve: give file = ... too")
    _entry_keys(raw, key, allowed)
    if "value" not in raw:
        hint = " (or file = ... for a curve over the angle)" if allow_scale else ""
        raise ConfigError(f"{key}.value", f"required key is missing{hint}")
    x = finite_value(raw["value"], f"{key}.value")
    x = convert_unit(x, raw.get("unit", target), target, f"{key}.unit", name)
    if allow_scale:
        x *= _scale(raw, key)
    given = f"{shown(raw['value'])} {raw.get('unit', target)}"
    return symbol_value(x, f"{key}.value", chain.symbols[name], given)


def _curve_entry(
    raw: Mapping[str, Any],
    key: str,
    name: str,
    chain: Chain,
    joint_of: Mapping[str, str],
    base: Path,
) -> Curve:
    """``{ file, column, unit, scale, periodic }``: a curve over the angle of the joint whose
    error motion holds ``name``."""
    _entry_keys(raw, key, ("file", "column", "unit", "scale", "periodic"))
    if name not in joint_of:
        raise ConfigError(
            f"{key}.file",
            f"{name} is not in the error motion of one rotary joint of the chain, so it "
            "cannot vary with an angle: give it a constant value",
        )
    ref = raw["file"]
    if not isinstance(ref, str) or not ref:
        raise ConfigError(f"{key}.file", f"expected the path of a curve file, found {ref!r}")
    column = raw.get("column")
    if column is not None and not isinstance(column, str):
        raise ConfigError(f"{key}.column", f"expected a column header, found {column!r}")
    periodic = raw.get("periodic", True)
    if not isinstance(periodic, bool):
        raise ConfigError(f"{key}.periodic", f"expected true or false, found {periodic!r}")
    target = chain.symbols[name].unit
    unit = raw.get("unit", target)
    scale = _scale(raw, key)
    try:
        return read_curve(
            base / ref,
            column=column,
            prefer=name,
            unit=unit,
            to_unit=target,
            scale=scale,
            periodic=periodic,
        )
    except ConfigError as exc:
        raise ConfigError(f"{key}.{exc.key}", exc.message) from None


# -- reading a table file -------------------------------------------------------------------


def load_table(path: str | os.PathLike[str]) -> Table:
    """Read a table file (``TABLE.toml``: a ``[table]`` table), or a chain file (one with
    ``[[steps]]``) as a table with the chain's default values.

    Raises
    ------
    ConfigError
        The file is missing, unreadable or not TOML (keys ``<file>``, ``<toml>``; see
        :func:`esp.io.tomlfile.read_toml_file`), holds a table other than ``[table]``, or
        anything :func:`table_from_dict` refuses.
    ParseError
        An error-value or curve file that does not read.
    """
    p = Path(path)
    data = read_toml_file(p, "table")
    if "steps" in data and "table" not in data:
        return table_from_chain(load_chain(p))
    if "table" not in data:
        found = ", ".join(repr(k) for k in data) or "nothing"
        raise ConfigError(
            "table",
            "required table is missing: a table file has [table] with the chain file "
            f'(chain = "..."), or is itself a chain file with [[steps]]; found {found}',
            p,
        )
    for k in data:
        if k != "table":
            raise ConfigError(
                k,
                f"unknown table {k!r}{did_you_mean(k, ['table'])} (a table file holds [table])",
                p,
            )
    return table_from_dict(data["table"], base_dir=p.parent, source=str(p), prefix="table")
