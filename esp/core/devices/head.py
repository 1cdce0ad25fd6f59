"""A servo head: a kinematic chain with the values of its parameters and small errors.

A head is described by a chain file (``CHAIN.toml``, :mod:`esp.core.kinematics.reader`) and a
``[head]`` table that names it and gives the values::

    [head]
    name = "Angle head, Fig. 3 of Freeman & Ford (2003)"
    chain = "angle-head.toml"          # relative to the file holding this table
    mcp = [0, 0, 0]                    # the MCP in the chain's base frame, mm (optional)
    errors_from = ["identified.csv"]   # error values from files (optional)

    [head.parameters]                  # in each symbol's unit, or { value, unit }
    G = 20

    [head.errors]
    ThetaAs = 100                      # arcsec: the unit of ThetaAs in the chain file
    Ocx = { value = 5, unit = "um" }

The same table can stand in another file (a ``machine.toml`` of a five-axis machine):
:func:`head_from_dict` reads it with a key prefix for the messages and lets the caller
allow keys of its own. Each value comes, by increasing precedence, from the chain's
default (``symbols.NAME.value``), the error files, the table, and
:meth:`Head.with_values` (``--set`` on the command line); an error without a value is
zero. Every problem is a :class:`esp.core.errors.ConfigError` naming the dotted key, or a
:class:`esp.core.errors.ParseError` naming the file and line of an error-value file.

See ``docs/heads.md``.
"""

from __future__ import annotations

import os
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field, replace
from pathlib import Path
from types import MappingProxyType
from typing import Any

from esp.core.errors import ConfigError
from esp.core.kinematics import Chain, load_chain
from esp.core.kinematics.values import (
    chain_defaults,
    chain_of_table,
    convert_unit,
    errors_from,
    finite_value,
    name_and_description,
    read_error_values,
    symbol_kind_message,
    symbol_value,
)
from esp.core.text import did_you_mean
from esp.core.values import shown
from esp.io.tomlfile import read_toml_file

__all__ = [
    "HEAD_KEYS",
    "Head",
    "head_from_chain",
    "head_from_dict",
    "load_head",
    "read_error_values",
]

#: the keys of a ``[head]`` table
HEAD_KEYS = ("name", "description", "chain", "mcp", "parameters", "errors", "errors_from")


def _join(prefix: str, name: str) -> str:
    return f"{prefix}.{name}" if prefix else name


@dataclass(frozen=True)
class Head:
    """A head chain with every parameter and error value.

    Attributes
    ----------
    chain : the kinematic chain, base (the ram, the MCP frame) to the tool tip
    name : for reports
    parameters : every parameter of the chain -> its value, in the symbol's unit
    errors : every small error of the chain -> its value, in the symbol's unit (zero
        when nothing gives one)
    origins : name -> where its value came from (``"chain"``, ``"head"``, a file name,
        ``"--set"``); absent for an error that is zero because nothing gave it
    mcp_mm : the machine control point (where the head is mounted on the ram and the
        Cartesian errors refer to) in the chain's base frame, mm
    source : the file the head was read from, for messages
    inputs : every file read (the head file, the chain, the error files)
    """

    chain: Chain
    name: str
    parameters: Mapping[str, float]
    errors: Mapping[str, float]
    origins: Mapping[str, str] = field(default_factory=dict)
    mcp_mm: tuple[float, float, float] = (0.0, 0.0, 0.0)
    description: str = ""
    source: str | None = None
    inputs: tuple[str, ...] = ()

    @property
    def coordinates(self) -> tuple[str, ...]:
        """The head's axes (the chain's coordinates), base first."""
        return self.chain.coordinates

    def unit(self, name: str) -> str:
        """The unit of a symbol's values."""
        return self.chain.symbols[name].unit

    def with_values(self, values: Mapping[str, float], origin: str = "--set") -> Head:
        """A copy with some parameter and error values replaced (each in its symbol's unit).

        Raises
        ------
        ConfigError
            A name that is not a parameter or an error of the chain (key ``origin.NAME``).
        """
        params = dict(self.parameters)
        errors = dict(self.errors)
        origins = dict(self.origins)
        for n, v in values.items():
            sym = self.chain.symbols.get(n)
            key = f"{origin}.{n}" if origin != "--set" else n
            if sym is None or sym.kind == "coordinate":
                raise ConfigError(
                    key if origin != "--set" else f"--set {n}",
                    _not_a_value(self.chain, n),
                )
            x = symbol_value(v, key if origin != "--set" else f"--set {n}", sym)
            if sym.kind == "parameter":
                params[n] = x
            else:
                errors[n] = x
            origins[n] = origin
        return replace(
            self,
            parameters=MappingProxyType(params),
            errors=MappingProxyType(errors),
            origins=MappingProxyType(origins),
        )

    def values_in(self, kind: str) -> dict[str, float]:
        """parameters or errors as a plain dict (``kind`` ``"parameter"`` or ``"error"``)."""
        return dict(self.parameters if kind == "parameter" else self.errors)


def _not_a_value(chain: Chain, name: str) -> str:
    sym = chain.symbols.get(name)
    if sym is not None and sym.kind == "coordinate":
        return f"{name} is a coordinate of the head; give it with --at or a map grid"
    names = [n for n, s in chain.symbols.items() if s.kind != "coordinate"]
    return (
        f"not a parameter or error of the chain{did_you_mean(name, names)} "
        f"({', '.join(names) or 'none'})"
    )


def head_from_chain(chain: Chain, name: str | None = None) -> Head:
    """A head holding the chain's own default values (parameters must have one)."""
    params, errors, origins = chain_defaults(chain)
    inputs = (chain.source,) if chain.source else ()
    return Head(
        chain,
        name or chain.name,
        MappingProxyType(params),
        MappingProxyType(errors),
        MappingProxyType(origins),
        description=chain.description,
        source=chain.source,
        inputs=inputs,
    )


def _value_entry(raw: Any, key: str, name: str, chain: Chain) -> float:
    """A value: a number in the symbol's unit, or ``{ value = ..., unit = ... }``."""
    target = chain.symbols[name].unit
    if isinstance(raw, Mapping):
        for k in raw:
            if k not in ("value", "unit"):
                raise ConfigError(
                    f"{key}.{k}",
                    f"unknown key {k!r}{did_you_mean(k, ('value', 'unit'))} "
                    "(expected 'value' and optionally 'unit')",
                )
        if "value" not in raw:
            raise ConfigError(f"{key}.value", "required key is missing")
        x = finite_value(raw["value"], f"{key}.value")
        unit = raw.get("unit", target)
        if not isinstance(unit, str):
            raise ConfigError(f"{key}.unit", f"expected a unit such as 'um', found {unit!r}")
        x = convert_unit(x, unit, target, f"{key}.unit", name)
        return symbol_value(x, f"{key}.value", chain.symbols[name], f"{shown(raw['value'])} {unit}")
    return symbol_value(raw, key, chain.symbols[name])


def head_from_dict(
    table: Mapping[str, Any],
    *,
    base_dir: str | os.PathLike[str] = ".",
    source: str | None = None,
    prefix: str = "head",
    allow: Iterable[str] = (),
) -> Head:
    """Read a ``[head]`` table (see the module docstring).

    Parameters
    ----------
    table : the parsed table
    base_dir : where the relative paths of ``chain`` and ``errors_from`` start
    source : the file holding the table, for messages
    prefix : the table's dotted key in that file (``"head"``), for messages
    allow : further keys the caller reads itself (e.g. ``"angles"`` in a machine file);
        they are accepted and ignored here

    Raises
    ------
    ConfigError
        An unknown key (with a suggestion), a missing ``chain``, a value that is not a
        number, a unit that does not fit, a name that is not a parameter or error of the
        chain; the chain file's own errors name that file.
    ParseError
        An error-value file that does not read (file and line).
    """
    chain, chain_ref = chain_of_table(
        table,
        prefix=prefix,
        allowed=HEAD_KEYS + tuple(allow),
        owner="head",
        base_dir=base_dir,
        source=source,
    )
    base = Path(base_dir)

    def fail(key: str, message: str) -> ConfigError:
        return ConfigError(key, message, source)

    if not chain.coordinates:
        raise fail(_join(prefix, "chain"), f"{chain_ref}: the chain has no coordinate (no joint)")
    head = head_from_chain(chain)
    inputs = list(head.inputs)
    if source:
        inputs.insert(0, source)

    name, description = name_and_description(table, chain, prefix, source)
    mcp = (0.0, 0.0, 0.0)
    if "mcp" in table:
        raw = table["mcp"]
        key = _join(prefix, "mcp")
        if not isinstance(raw, list) or len(raw) != 3:
            raise fail(key, f"expected [x, y, z] in mm, found {raw!r}")
        try:
            mcp = tuple(finite_value(v, f"{key}[{i}]") for i, v in enumerate(raw))  # type: ignore[assignment]
        except ConfigError as exc:
            raise fail(exc.key, exc.message) from None

    params = dict(head.parameters)
    errors = dict(head.errors)
    origins = dict(head.origins)

    try:
        values, from_files, read = errors_from(
            table.get("errors_from", []), _join(prefix, "errors_from"), base, chain
        )
    except ConfigError as exc:
        raise fail(exc.key, exc.message) from None
    errors.update(values)
    origins.update(from_files)
    inputs.extend(read)

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
                x = _value_entry(v, key, n, chain)
            except ConfigError as exc:
                raise fail(exc.key, exc.message) from None
            (params if kind == "parameter" else errors)[n] = x
            origins[n] = Path(source).name if source else "head"

    return Head(
        chain,
        name,
        MappingProxyType(params),
        MappingProxyType(errors),
        MappingProxyType(origins),
        mcp_mm=mcp,
        description=description,
        source=source,
        inputs=tuple(dict.fromkeys(inputs)),
    )


def load_head(path: str | os.PathLike[str]) -> tuple[Head, dict[str, Any]]:
    """Read a ``HEAD.toml``: its ``[head]`` table and the rest of the file.

    A chain file (one with ``[[steps]]``) is read as a head with the chain's default
    values.

    Returns
    -------
    head : the head
    rest : the file's other top-level tables (``map``, ``protocol``), unchecked; see
        :func:`esp.heads.config.read_head_file` for the checked form
    """
    p = Path(path)
    data = read_toml_file(p, "head")
    if "steps" in data and "head" not in data:
        return head_from_chain(load_chain(p)), {}
    if "head" not in data:
        found = ", ".join(repr(k) for k in data) or "nothing"
        raise ConfigError(
            "head",
            "required table is missing: a head file has [head] with the chain file "
            f'(chain = "..."), or is itself a chain file with [[steps]]; found {found}',
            p,
        )
    head = head_from_dict(data["head"], base_dir=p.parent, source=str(p), prefix="head")
    rest = {k: v for k, v in data.items() if k != "head"}
    return head, rest


# -- error values from files ----------------------------------------------------------------
