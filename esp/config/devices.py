"""Read the description files of the devices: a servo head (``HEAD.toml``, a ``[head]``
table) and a rotary table (``TABLE.toml``, a ``[table]`` table), into the
:class:`~esp.core.devices.head.Head` and :class:`~esp.core.devices.table.Table` of the core,
with their chain files (:mod:`esp.config.chain`), their files of error values and their
curve files (:mod:`esp.config.curves`).

A head::

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

A table::

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

The same tables can stand in another file (a ``machine.toml`` of a five-axis machine):
:func:`head_from_dict` and :func:`table_from_dict` read them with a key prefix for the
messages and let the caller allow keys of its own. Each value comes, by increasing
precedence, from the chain's default (``symbols.NAME.value``), the error files, the table,
and ``with_values`` (``--set`` on the command line); an error without a value is zero. A
curve (``file = ...``) can feed only an error in the error motion of a table's joint (a
component error motion, a function of that joint's angle); the location errors are
constants. Every problem is a :class:`esp.core.errors.ConfigError` naming the file and the
dotted key, or a :class:`esp.core.errors.ParseError` naming a data file and line.

See ``docs/heads.md`` and ``docs/rotary.md``.
"""

from __future__ import annotations

import csv
import io
import os
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass, replace
from pathlib import Path
from types import MappingProxyType
from typing import Any, Generic, TypeVar

from esp.config.chain import load_chain
from esp.config.curves import read_curve
from esp.core.devices.device import Device
from esp.core.devices.head import Head, check_head_chain, head_from_chain
from esp.core.devices.table import (
    Table,
    ToIdentify,
    check_table_chain,
    joint_of,
    setup_setting,
    table_from_chain,
)
from esp.core.devices.table_curves import Curve
from esp.core.errors import ConfigError, ParseError
from esp.core.kinematics import Chain
from esp.core.kinematics.values import convert_unit, finite_value, symbol_value
from esp.core.text import NAME_MAX_CHARS, TEXT_MAX_CHARS, article, did_you_mean, too_long
from esp.core.values import ValueRefused, check, check_symbol, parse, shown
from esp.io import jsonfile
from esp.io.textfile import read_utf8
from esp.io.tomlfile import read_toml_file

__all__ = [
    "ENTRY_KEYS",
    "HEAD_KEYS",
    "TABLE_KEYS",
    "chain_of_table",
    "errors_from",
    "head_from_dict",
    "load_head",
    "load_table",
    "name_and_description",
    "read_error_values",
    "same_file",
    "symbol_kind_message",
    "table_from_dict",
]

#: the keys of a ``[head]`` table
HEAD_KEYS = ("name", "description", "chain", "mcp", "parameters", "errors", "errors_from")
#: the keys of a ``[table]`` table
TABLE_KEYS = ("name", "description", "chain", "setup", "parameters", "errors", "errors_from")
#: the keys of a table error's entry: a constant ``{value, unit, scale}`` or a curve
#: ``{file, column, unit, scale, periodic}``
ENTRY_KEYS = ("value", "file", "column", "unit", "scale", "periodic")
#: the largest error-value file read
_MAX_BYTES = 1024 * 1024


def _join(prefix: str, name: str) -> str:
    return f"{prefix}.{name}" if prefix else name


def _expected(allowed: Iterable[str]) -> str:
    return "expected one of " + ", ".join(repr(a) for a in allowed)


# -- the values of a chain's symbols --------------------------------------------------------


def same_file(a: str | os.PathLike[str], b: str | os.PathLike[str]) -> bool:
    """Whether ``a`` and ``b`` name one file (``False`` if either cannot be found)."""
    try:
        return os.path.samefile(a, b)
    except OSError:
        return False


def chain_of_table(
    table: Any,
    *,
    prefix: str,
    allowed: tuple[str, ...],
    owner: str,
    base_dir: str | os.PathLike[str],
    source: str | None,
) -> tuple[Chain, str]:
    """Check the keys of a table that names a chain file (``[head]``, ``[table]``) and read
    that chain: (the chain, the file name as given). ``owner`` ("head") words the messages;
    the errors name ``source``, those of the chain file's content that file."""

    def key(name: str) -> str:
        return f"{prefix}.{name}" if prefix else name

    if not isinstance(table, Mapping):
        raise ConfigError(prefix or "<top>", f"expected a table, found {table!r}", source)
    for k in table:
        if k not in allowed:
            expected = ", ".join(repr(a) for a in allowed)
            raise ConfigError(
                key(k),
                f"unknown key {k!r}{did_you_mean(k, allowed)} (expected one of {expected})",
                source,
            )
    if "chain" not in table:
        raise ConfigError(
            key("chain"), f"required key is missing: the {owner}'s chain file", source
        )
    chain_ref = table["chain"]
    if not isinstance(chain_ref, str) or not chain_ref:
        raise ConfigError(
            key("chain"), f"expected the path of a chain file, found {chain_ref!r}", source
        )
    chain_path = Path(base_dir) / chain_ref
    if source is not None and same_file(chain_path, source):
        raise ConfigError(key("chain"), "names this file itself; expected a chain file", source)
    try:
        chain = load_chain(chain_path)
    except ConfigError as exc:
        if exc.key == "<file>":
            raise ConfigError(key("chain"), f"{chain_path}: {exc.message}", source) from None
        raise
    return chain, chain_ref


def name_and_description(
    table: Mapping[str, Any], chain: Chain, prefix: str, source: str | None
) -> tuple[str, str]:
    """The ``name`` and ``description`` of a table, the chain's by default."""
    out = []
    for k, default in (("name", chain.name), ("description", chain.description)):
        value = table.get(k, default)
        key = f"{prefix}.{k}" if prefix else k
        if not isinstance(value, str):
            raise ConfigError(key, f"expected text, found {value!r}", source)
        message = too_long(value, NAME_MAX_CHARS if k == "name" else TEXT_MAX_CHARS)
        if message is not None:
            raise ConfigError(key, message, source)
        out.append(value)
    return out[0], out[1]


def symbol_kind_message(chain: Chain, name: str, kind: str, group_prefix: str) -> str | None:
    """Why ``name`` cannot be given as ``kind`` (``"parameter"`` or ``"error"``) of
    ``chain``, or ``None`` if it can. ``group_prefix`` is the key of the table the groups
    stand in (``"head"``), for the hint where to give it instead."""
    sym = chain.symbols.get(name)
    if sym is not None and sym.kind == kind:
        return None
    if sym is not None:
        message = f"{name} is {article(sym.kind)} of the chain, not {article(kind)}"
        if sym.kind != "coordinate":
            group = f"{sym.kind}s"
            message += f"; give it in [{f'{group_prefix}.{group}' if group_prefix else group}]"
        return message
    names = [m for m, s in chain.symbols.items() if s.kind == kind]
    listed = ", ".join(names) or "none"
    return f"not {article(kind)} of the chain{did_you_mean(name, names)} ({listed})"


def errors_from(
    raw: Any, key: str, base: Path, chain: Chain
) -> tuple[dict[str, float], dict[str, str], list[str]]:
    """The error values of the files ``raw`` names (``errors_from``: a file name or a list,
    relative to ``base``): the values, their origins (the file names) and the paths read,
    later files overriding earlier ones."""
    files = [raw] if isinstance(raw, str) else raw
    if not isinstance(files, list) or not all(isinstance(f, str) and f for f in files):
        raise ConfigError(key, f"expected a file name or a list of file names, found {raw!r}")
    values: dict[str, float] = {}
    origins: dict[str, str] = {}
    inputs: list[str] = []
    for ref in files:
        path = base / ref
        read = read_error_values(path, chain)
        values.update(read)
        origins.update({n: Path(ref).name for n in read})
        inputs.append(str(path))
    return values, origins, inputs


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
    text = read_utf8(p, _MAX_BYTES, "file of error values")
    if p.suffix.lower() == ".json":
        return _error_values_json(p, text, chain)
    return _error_values_csv(p, text, chain)


def _error_value(
    p: Path, line: int | None, chain: Chain, name: str, value: Any, unit: Any
) -> float:
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
        x = parse(value) if isinstance(value, str) else check(value)
        text = value.strip() if isinstance(value, str) else shown(value)
        if unit not in (None, ""):
            x = convert_unit(x, str(unit), sym.unit, "unit", name)
            text = f"{text} {unit}"
        check_symbol(sym.kind, sym.unit, x, text)
    except ValueRefused as exc:
        raise ParseError(p, line, f"{name}: {exc.message}") from None
    except ConfigError as exc:
        raise ParseError(p, line, f"{name}: {exc.message}") from None
    return x


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
    for name in ("error", "value", "unit"):
        if cols.count(name) > 1:  # else the last one would win
            raise ParseError(p, hline, f"expected one column {name!r}, found {cols.count(name)}")
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
    doc = jsonfile.loads(text, p)  # nested at most JSON_MAX_DEPTH deep
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


# -- one reader for the two devices ---------------------------------------------------------

D = TypeVar("D", bound=Device)

#: reads one entry of ``[*.parameters]`` or ``[*.errors]``: (the entry as given, its key,
#: the symbol, its kind, the chain, error -> the joint whose error motion holds it, the
#: folder of relative paths) -> a value in the symbol's unit, or a curve
Entry = Callable[[Any, str, str, str, Chain, Mapping[str, str], Path], "float | Curve | ToIdentify"]


@dataclass(frozen=True)
class _Form(Generic[D]):
    """What differs between the description of a head and of a table.

    Attributes
    ----------
    owner : the table's name (``head``) and the word of the messages
    keys : the keys the table may hold
    start : the device with the chain's own values
    check : refuses a chain the device cannot have (``check(chain, key, source)``)
    own : the device's own keys (``mcp``, ``setup``) -> its own fields
        (``own(table, prefix, chain)``)
    entry : reads one value (:data:`Entry`)
    curves : whether an error may be a curve over the angle of its joint
    """

    owner: str
    keys: tuple[str, ...]
    start: Callable[[Chain], D]
    check: Callable[[Chain, str, str | None], None]
    own: Callable[[Mapping[str, Any], str, Chain], dict[str, Any]]
    entry: Entry
    curves: bool = False


def _device_from_dict(
    form: _Form[D],
    table: Mapping[str, Any],
    *,
    base_dir: str | os.PathLike[str],
    source: str | None,
    prefix: str,
    allow: Iterable[str],
) -> D:
    """Read a ``[head]`` or ``[table]`` table (see :func:`head_from_dict`)."""
    chain, chain_ref = chain_of_table(
        table,
        prefix=prefix,
        allowed=form.keys + tuple(allow),
        owner=form.owner,
        base_dir=base_dir,
        source=source,
    )
    base = Path(base_dir)

    def fail(key: str, message: str) -> ConfigError:
        return ConfigError(key, message, source)

    try:
        form.check(chain, _join(prefix, "chain"), None)
    except ConfigError as exc:
        raise fail(exc.key, f"{chain_ref}: {exc.message}") from None
    start = form.start(chain)
    inputs = list(start.inputs)
    if source:
        inputs.insert(0, source)

    name, description = name_and_description(table, chain, prefix, source)
    try:
        own = form.own(table, prefix, chain)
    except ConfigError as exc:
        raise fail(exc.key, exc.message) from None

    params = dict(start.parameters)
    errors = dict(start.errors)
    origins = dict(start.origins)
    curves: dict[str, Curve] = {}
    axes: dict[str, str] = {}
    unknowns: dict[str, ToIdentify] = {}

    try:
        values, from_files, read = errors_from(
            table.get("errors_from", []), _join(prefix, "errors_from"), base, chain
        )
    except ConfigError as exc:
        raise fail(exc.key, exc.message) from None
    errors.update(values)
    origins.update(from_files)
    inputs.extend(read)

    joints = joint_of(chain) if form.curves else {}
    here = Path(source).name if source else form.owner
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
                x = form.entry(v, key, n, kind, chain, joints, base)
            except ConfigError as exc:
                raise fail(exc.key, exc.message) from None
            if isinstance(x, ToIdentify):
                unknowns[n] = x
                errors[n] = 0.0
                curves.pop(n, None)
                axes.pop(n, None)
                origins[n] = here
                continue
            unknowns.pop(n, None)
            if isinstance(x, Curve):
                curves[n] = x
                axes[n] = joints[n]
                errors.pop(n, None)
                origins[n] = x.source
                inputs.append(str(base / v["file"]))
                continue
            (params if kind == "parameter" else errors)[n] = x
            curves.pop(n, None)
            axes.pop(n, None)
            origins[n] = here

    if form.curves:
        own.update(curves=MappingProxyType(curves), curve_axes=MappingProxyType(axes))
    own["to_identify"] = MappingProxyType(unknowns)
    return replace(
        start,
        name=name,
        description=description,
        parameters=MappingProxyType(params),
        errors=MappingProxyType(errors),
        origins=MappingProxyType(origins),
        source=source,
        inputs=tuple(dict.fromkeys(inputs)),
        **own,
    )


def _load(
    path: str | os.PathLike[str], form: _Form[D], *, others: bool
) -> tuple[D, dict[str, Any]]:
    """Read a description file: its ``[owner]`` table and the rest of the file (refused
    unless ``others``), or a chain file (one with ``[[steps]]``) as a device with the
    chain's default values."""
    p = Path(path)
    owner = form.owner
    data = read_toml_file(p, owner)
    if "steps" in data and owner not in data:
        return form.start(load_chain(p)), {}
    if owner not in data:
        found = ", ".join(repr(k) for k in data) or "nothing"
        raise ConfigError(
            owner,
            f"required table is missing: a {owner} file has [{owner}] with the chain file "
            f'(chain = "..."), or is itself a chain file with [[steps]]; found {found}',
            p,
        )
    if not others:
        for k in data:
            if k != owner:
                raise ConfigError(
                    k,
                    f"unknown table {k!r}{did_you_mean(k, [owner])} (a {owner} file holds "
                    f"[{owner}])",
                    p,
                )
    device = _device_from_dict(
        form, data[owner], base_dir=p.parent, source=str(p), prefix=owner, allow=()
    )
    return device, {k: v for k, v in data.items() if k != owner}


# -- a head ---------------------------------------------------------------------------------


def _head_value_entry(raw: Any, key: str, name: str, chain: Chain) -> float:
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


def _head_entry(
    raw: Any, key: str, name: str, kind: str, chain: Chain, joints: Mapping[str, str], base: Path
) -> float | ToIdentify:
    """A value, or for an error an unknown for ``esp identify``, ``{ identify = true }``
    (a head's errors are constants)."""
    if isinstance(raw, Mapping) and "identify" in raw:
        if kind != "error":
            raise ConfigError(
                f"{key}.identify", "a parameter is given, not identified: give its value"
            )
        _entry_keys(raw, key, ("identify",))
        if raw["identify"] is not True:
            raise ConfigError(
                f"{key}.identify",
                f"expected true (a head's error is a constant), found {raw['identify']!r}",
            )
        return ToIdentify(key, True)
    return _head_value_entry(raw, key, name, chain)


def _head_own(table: Mapping[str, Any], prefix: str, chain: Chain) -> dict[str, Any]:
    """``mcp``: the MCP in the chain's base frame, mm."""
    if "mcp" not in table:
        return {}
    raw = table["mcp"]
    key = _join(prefix, "mcp")
    if not isinstance(raw, list) or len(raw) != 3:
        raise ConfigError(key, f"expected [x, y, z] in mm, found {raw!r}")
    x, y, z = (finite_value(v, f"{key}[{i}]") for i, v in enumerate(raw))
    return {"mcp_mm": (x, y, z)}


_HEAD = _Form("head", HEAD_KEYS, head_from_chain, check_head_chain, _head_own, _head_entry)


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
    return _device_from_dict(
        _HEAD, table, base_dir=base_dir, source=source, prefix=prefix, allow=allow
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
    return _load(path, _HEAD, others=True)


# -- a rotary table -------------------------------------------------------------------------


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
    joints: Mapping[str, str],
    base: Path,
) -> Curve:
    """``{ file, column, unit, scale, periodic }``: a curve over the angle of the joint whose
    error motion holds ``name``."""
    _entry_keys(raw, key, ("file", "column", "unit", "scale", "periodic"))
    if name not in joints:
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


def _table_entry(
    raw: Any, key: str, name: str, kind: str, chain: Chain, joints: Mapping[str, str], base: Path
) -> float | Curve | ToIdentify:
    """A constant ``{ value, unit, scale }`` (a parameter: ``{ value, unit }``), or, for an
    error, a curve ``{ file, column, unit, scale, periodic }`` or an unknown for ``esp
    identify``, ``{ identify = ... }`` (checked there: :mod:`esp.identify.rotary`)."""
    if isinstance(raw, Mapping) and "identify" in raw:
        if kind != "error":
            raise ConfigError(
                f"{key}.identify", "a parameter is given, not identified: give its value"
            )
        _entry_keys(raw, key, ("identify",))
        return ToIdentify(key, raw["identify"])
    if isinstance(raw, Mapping) and "file" in raw:
        if kind != "error":
            raise ConfigError(f"{key}.file", "a parameter is a number, not a curve from a file")
        return _curve_entry(raw, key, name, chain, joints, base)
    return _value_entry(raw, key, name, chain, allow_scale=kind == "error")


def _table_own(table: Mapping[str, Any], prefix: str, chain: Chain) -> dict[str, Any]:
    """``setup``: the setting at which the workpiece is set up."""
    if "setup" not in table:
        return {}
    setup = setup_setting(table["setup"], _join(prefix, "setup"), chain.coordinates)
    return {"setup_deg": MappingProxyType(setup)}


_TABLE = _Form(
    "table", TABLE_KEYS, table_from_chain, check_table_chain, _table_own, _table_entry, True
)


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
    return _device_from_dict(
        _TABLE, table, base_dir=base_dir, source=source, prefix=prefix, allow=allow
    )


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
    return _load(path, _TABLE, others=False)[0]
