"""A servo head: a kinematic chain with the values of its parameters and small errors.

A head is described by a chain file (``CHAIN.toml``, :mod:`esp.kinematics.reader`) and a
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
zero. Every problem is a :class:`esp.errors.ConfigError` naming the dotted key, or a
:class:`esp.errors.ParseError` naming the file and line of an error-value file.

See ``docs/heads.md``.
"""

from __future__ import annotations

import csv
import io
import json
import math
import os
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field, replace
from pathlib import Path
from types import MappingProxyType
from typing import Any

from esp.errors import ConfigError, ParseError
from esp.io.tomlfile import read_toml_file
from esp.kinematics import Chain, load_chain
from esp.kinematics import units as kunits
from esp.text import did_you_mean

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
#: the largest error-value file read
_MAX_BYTES = 1024 * 1024


def _a(word: str) -> str:
    return f"an {word}" if word[:1] in "aeiou" else f"a {word}"


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
            x = _finite(v, key)
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


def _finite(v: Any, key: str) -> float:
    if isinstance(v, bool) or not isinstance(v, int | float):
        raise ConfigError(key, f"expected a number, found {v!r}")
    x = float(v)
    if not math.isfinite(x):
        raise ConfigError(key, f"expected a finite number, found {v!r}")
    if abs(x) > 1e9:
        raise ConfigError(key, f"value out of range: {v!r}")
    return x


def _convert(value: float, unit: str, to_unit: str, key: str, name: str) -> float:
    """``value`` in ``unit`` expressed in ``to_unit`` (both of one dimension)."""
    u = kunits.canonical(unit)
    if u is None:
        raise ConfigError(key, f"unknown unit {unit!r}; expected one of {', '.join(kunits.UNITS)}")
    if kunits.dimension_of(u) != kunits.dimension_of(to_unit):
        raise ConfigError(
            key,
            f"{u!r} is a unit of {kunits.dimension_of(u)}, but {name} is "
            f"{'a length' if kunits.dimension_of(to_unit) == kunits.LENGTH else 'an angle'} "
            f"(its unit is {to_unit})",
        )
    return value * kunits.factor(u) / kunits.factor(to_unit)


def head_from_chain(chain: Chain, name: str | None = None) -> Head:
    """A head holding the chain's own default values (parameters must have one)."""
    params: dict[str, float] = {}
    errors: dict[str, float] = {}
    origins: dict[str, str] = {}
    for n, s in chain.symbols.items():
        if s.kind == "parameter":
            if s.value is None:
                raise ConfigError(
                    f"parameters.{n}",
                    f"no value: give one, or a default (symbols.{n}.value)",
                    chain.source,
                )
            params[n] = s.value
            origins[n] = "chain"
        elif s.kind == "error":
            errors[n] = 0.0 if s.value is None else s.value
            if s.value is not None:
                origins[n] = "chain"
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
        x = _finite(raw["value"], f"{key}.value")
        unit = raw.get("unit", target)
        if not isinstance(unit, str):
            raise ConfigError(f"{key}.unit", f"expected a unit such as 'um', found {unit!r}")
        return _convert(x, unit, target, f"{key}.unit", name)
    return _finite(raw, key)


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
    allowed = HEAD_KEYS + tuple(allow)

    def fail(key: str, message: str) -> ConfigError:
        return ConfigError(key, message, source)

    if not isinstance(table, Mapping):
        raise fail(prefix or "<top>", f"expected a table, found {table!r}")
    for k in table:
        if k not in allowed:
            raise fail(
                _join(prefix, k),
                f"unknown key {k!r}{did_you_mean(k, allowed)} (expected one of "
                + ", ".join(repr(a) for a in allowed)
                + ")",
            )
    if "chain" not in table:
        raise fail(_join(prefix, "chain"), "required key is missing: the head's chain file")
    chain_ref = table["chain"]
    if not isinstance(chain_ref, str) or not chain_ref:
        raise fail(
            _join(prefix, "chain"), f"expected the path of a chain file, found {chain_ref!r}"
        )
    base = Path(base_dir)
    chain_path = base / chain_ref
    if source is not None and _same_file(chain_path, source):
        raise fail(_join(prefix, "chain"), "names this file itself; expected a chain file")
    try:
        chain = load_chain(chain_path)
    except ConfigError as exc:
        if exc.key == "<file>":
            raise fail(_join(prefix, "chain"), f"{chain_path}: {exc.message}") from None
        raise
    if not chain.coordinates:
        raise fail(_join(prefix, "chain"), f"{chain_ref}: the chain has no coordinate (no joint)")
    head = head_from_chain(chain)
    inputs = list(head.inputs)
    if source:
        inputs.insert(0, source)

    name = table.get("name", chain.name)
    if not isinstance(name, str):
        raise fail(_join(prefix, "name"), f"expected text, found {name!r}")
    description = table.get("description", chain.description)
    if not isinstance(description, str):
        raise fail(_join(prefix, "description"), f"expected text, found {description!r}")
    mcp = (0.0, 0.0, 0.0)
    if "mcp" in table:
        raw = table["mcp"]
        key = _join(prefix, "mcp")
        if not isinstance(raw, list) or len(raw) != 3:
            raise fail(key, f"expected [x, y, z] in mm, found {raw!r}")
        try:
            mcp = tuple(_finite(v, f"{key}[{i}]") for i, v in enumerate(raw))  # type: ignore[assignment]
        except ConfigError as exc:
            raise fail(exc.key, exc.message) from None

    params = dict(head.parameters)
    errors = dict(head.errors)
    origins = dict(head.origins)

    files = table.get("errors_from", [])
    if isinstance(files, str):
        files = [files]
    if not isinstance(files, list) or not all(isinstance(f, str) and f for f in files):
        raise fail(
            _join(prefix, "errors_from"),
            f"expected a file name or a list of file names, found {table.get('errors_from')!r}",
        )
    for ref in files:
        path = base / ref
        values = read_error_values(path, chain)
        errors.update(values)
        origins.update({n: Path(ref).name for n in values})
        inputs.append(str(path))

    for group, kind in (("parameters", "parameter"), ("errors", "error")):
        raw = table.get(group, {})
        gkey = _join(prefix, group)
        if not isinstance(raw, Mapping):
            raise fail(gkey, f"expected a table of name = value, found {raw!r}")
        for n, v in raw.items():
            key = f"{gkey}.{n}"
            sym = chain.symbols.get(n)
            if sym is None or sym.kind != kind:
                names = [m for m, s in chain.symbols.items() if s.kind == kind]
                if sym is not None:
                    message = f"{n} is {_a(sym.kind)} of the chain, not {_a(kind)}"
                    if sym.kind != "coordinate":
                        message += f"; give it in [{_join(prefix, sym.kind + 's')}]"
                else:
                    message = (
                        f"not {_a(kind)} of the chain{did_you_mean(n, names)} "
                        f"({', '.join(names) or 'none'})"
                    )
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


def _same_file(a: Path, b: str | os.PathLike[str]) -> bool:
    try:
        return os.path.samefile(a, b)
    except OSError:
        return False


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


def read_error_values(path: str | os.PathLike[str], chain: Chain) -> dict[str, float]:
    """Error values from a file, each converted into its symbol's unit.

    * CSV (``.csv``): a header ``error,value`` or ``error,value,unit``, then one row per
      error; lines starting with ``#`` are comments; without a unit column (or with an
      empty cell) the value is in the symbol's unit.
    * JSON (``.json``): the document ``esp head --protocol --measured ... --json`` writes
      (schema ``esp.protocol/1``): its ``identified`` values.

    Raises
    ------
    ParseError
        The file is missing or unreadable, a row does not hold a known error and a finite
        number, an error is given twice (file and line).
    """
    p = Path(path)
    try:
        size = p.stat().st_size
        if not p.is_file():
            raise ParseError(p, None, "expected a file of error values, found a folder or device")
        if size > _MAX_BYTES:
            raise ParseError(p, None, f"expected at most {_MAX_BYTES} bytes, found {size}")
        text = p.read_bytes().decode("utf-8-sig")
    except FileNotFoundError:
        raise ParseError(p, None, "no such file of error values") from None
    except UnicodeDecodeError:
        raise ParseError(p, None, "expected UTF-8 text") from None
    except OSError as exc:
        raise ParseError(p, None, f"cannot be read: {exc.strerror or exc}") from None
    if p.suffix.lower() == ".json":
        return _error_values_json(p, text, chain)
    return _error_values_csv(p, text, chain)


def _error_value(p: Path, line: int | None, chain: Chain, name: str, value: Any, unit: Any):
    errors = chain.errors
    sym = chain.symbols.get(name)
    if sym is None or sym.kind != "error":
        raise ParseError(
            p,
            line,
            f"{name!r} is not a small error of the chain{did_you_mean(name, errors)} "
            f"({', '.join(errors)})",
        )
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise ParseError(p, line, f"{name}: expected a number, found {value!r}") from None
    if isinstance(value, bool) or not math.isfinite(x) or abs(x) > 1e9:
        raise ParseError(p, line, f"{name}: expected a finite number, found {value!r}")
    if unit in (None, ""):
        return x
    try:
        return _convert(x, str(unit), sym.unit, "unit", name)
    except ConfigError as exc:
        raise ParseError(p, line, f"{name}: {exc.message}") from None


def _error_values_csv(p: Path, text: str, chain: Chain) -> dict[str, float]:
    rows = [
        (i, line)
        for i, line in enumerate(text.splitlines(), 1)
        if line.strip() and not line.lstrip().startswith("#")
    ]
    if not rows:
        raise ParseError(p, None, "expected a header 'error,value[,unit]' and rows, found none")
    hline, header = rows[0]
    cols = [c.strip().lower() for c in next(csv.reader([header]))]
    for required in ("error", "value"):
        if required not in cols:
            raise ParseError(p, hline, f"expected a header 'error,value[,unit]', found {header!r}")
    unknown = [c for c in cols if c not in ("error", "value", "unit")]
    if unknown:
        raise ParseError(
            p,
            hline,
            f"unknown column {unknown[0]!r}{did_you_mean(unknown[0], ('error', 'value', 'unit'))} "
            "(expected error, value and optionally unit)",
        )
    out: dict[str, float] = {}
    for line_no, line in rows[1:]:
        cells = [c.strip() for c in next(csv.reader(io.StringIO(line)))]
        if len(cells) != len(cols):
            raise ParseError(p, line_no, f"expected {len(cols)} columns, found {len(cells)}")
        row = dict(zip(cols, cells, strict=True))
        name = row["error"]
        if name in out:
            raise ParseError(p, line_no, f"{name} is given twice")
        out[name] = _error_value(p, line_no, chain, name, row["value"], row.get("unit"))
    return out


def _error_values_json(p: Path, text: str, chain: Chain) -> dict[str, float]:
    try:
        doc = json.loads(text)
    except ValueError as exc:
        raise ParseError(p, getattr(exc, "lineno", None), f"invalid JSON: {exc}") from None
    if not isinstance(doc, Mapping) or doc.get("schema") != "esp.protocol/1":
        raise ParseError(p, None, "expected the esp.protocol/1 document of 'esp head --measured'")
    identified = doc.get("identified")
    if not isinstance(identified, Mapping) or not identified:
        raise ParseError(
            p, None, "the document holds no identified values (run it with --measured FILE)"
        )
    out: dict[str, float] = {}
    for name, entry in identified.items():
        if not isinstance(entry, Mapping):
            raise ParseError(p, None, f"identified.{name}: expected {{value, unit}}")
        out[name] = _error_value(p, None, chain, name, entry.get("value"), entry.get("unit"))
    return out
