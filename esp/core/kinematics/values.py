"""Values of a chain's symbols as a configuration gives them: numbers, numbers with a unit,
and files of error values. Shared by the head (:mod:`esp.core.devices.head`) and the rotary table
(:mod:`esp.core.devices.table`), whose ``parameters``, ``errors`` and ``errors_from`` read alike.

Every problem of a value is a :class:`esp.core.errors.ConfigError` naming the dotted key; of a
file of error values a :class:`esp.core.errors.ParseError` naming the file and line.
"""

from __future__ import annotations

import csv
import io
import os
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np

from esp.core.errors import ConfigError, ParseError
from esp.core.kinematics import units as kunits
from esp.core.kinematics.chain import Chain
from esp.core.kinematics.reader import load_chain
from esp.core.text import article, did_you_mean
from esp.core.values import Quantity, ValueRefused, check, check_symbol, config_number, parse, shown
from esp.io import jsonfile
from esp.io.textfile import read_utf8

__all__ = [
    "VALUE_LIMIT",
    "convert_unit",
    "coordinate_arrays",
    "errors_from",
    "chain_defaults",
    "chain_of_table",
    "finite_value",
    "name_and_description",
    "read_error_values",
    "same_file",
    "symbol_kind_message",
    "symbol_value",
]

#: the largest magnitude a parameter or error value may have, in its symbol's unit
VALUE_LIMIT = 1e9
#: the largest error-value file read
_MAX_BYTES = 1024 * 1024


def same_file(a: str | os.PathLike[str], b: str | os.PathLike[str]) -> bool:
    """Whether ``a`` and ``b`` name one file (``False`` if either cannot be found)."""
    try:
        return os.path.samefile(a, b)
    except OSError:
        return False


def finite_value(v: Any, key: str, limit: float = VALUE_LIMIT) -> float:
    """``v`` as a float: a number (not a bool), finite, of magnitude at most ``limit``."""
    return config_number(v, key, Quantity("a value", "", -limit, limit))


def symbol_value(v: Any, key: str, sym: Any, given: str | None = None) -> float:
    """``v``, in the unit of the chain symbol ``sym``, as a float when it is a finite number
    within the range of the symbol's kind and dimension (:func:`esp.core.values.check_symbol`);
    otherwise a :class:`~esp.core.errors.ConfigError` naming ``key``, the limit in the symbol's
    unit and the value as given."""
    try:
        return check_symbol(sym.kind, sym.unit, v, given=given)
    except ValueRefused as exc:
        raise ConfigError(key, exc.message) from None


def convert_unit(value: float, unit: Any, to_unit: str, key: str, name: str) -> float:
    """``value`` in ``unit`` expressed in ``to_unit`` (both of one dimension); ``name`` is
    the symbol, for the message."""
    u = kunits.canonical(unit) if isinstance(unit, str) else None
    if u is None:
        raise ConfigError(key, f"unknown unit {unit!r}; expected one of {', '.join(kunits.UNITS)}")
    if kunits.dimension_of(u) != kunits.dimension_of(to_unit):
        what = "a length" if kunits.dimension_of(to_unit) == kunits.LENGTH else "an angle"
        raise ConfigError(
            key,
            f"{u!r} is a unit of {kunits.dimension_of(u)}, but {name} is {what} "
            f"(its unit is {to_unit})",
        )
    return value * kunits.factor(u) / kunits.factor(to_unit)


def coordinate_arrays(
    angles: Any,
    coords: tuple[str, ...],
    *,
    member: str,
    owner: str,
    values: str = "values",
    limit: float = 1e6,
) -> tuple[dict[str, np.ndarray], int]:
    """Check the settings of a chain's coordinates: every one of ``coords`` given, as a
    number or a 1-D array, the arrays of one length N, finite and of magnitude at most
    ``limit``. Returns (coordinate -> float64 array (N,), N), numbers repeated N times.

    ``member``, ``owner`` and ``values`` word the messages ("not an axis of the table",
    "expected finite angles within ±1e+06, found 1e9"); the keys are ``angles.NAME``.
    """
    if not isinstance(angles, Mapping):
        raise ConfigError("angles", f"expected a mapping {member} -> {values}, found {angles!r}")
    listed = ", ".join(coords)
    for c in angles:
        if c not in coords:
            raise ConfigError(
                f"angles.{c}",
                f"not {article(member)} of the {owner}{did_you_mean(c, coords)} ({listed})",
            )
    out: dict[str, np.ndarray] = {}
    n = None
    for c in coords:
        if c not in angles:
            raise ConfigError(
                f"angles.{c}", f"missing: give every {member} of the {owner} ({listed})"
            )
        v = angles[c]
        if isinstance(v, bool | str | bytes) or v is None:
            raise ConfigError(f"angles.{c}", f"expected numbers, found {v!r}")
        try:
            arr = np.atleast_1d(np.asarray(v, dtype=float))
        except (TypeError, ValueError):
            raise ConfigError(f"angles.{c}", f"expected numbers, found {v!r}") from None
        if arr.ndim != 1 or arr.size == 0:
            raise ConfigError(f"angles.{c}", f"expected a number or a 1-D array, found {v!r}")
        with np.errstate(invalid="ignore"):
            bad = np.flatnonzero(~(np.abs(arr) <= limit))  # NaN compares false: caught too
        if bad.size:
            raise ConfigError(
                f"angles.{c}",
                f"expected finite {values} within ±{limit:g}, found {shown(arr[bad[0]])}",
            )
        out[c] = arr
        if arr.size != 1:
            if n is not None and n != arr.size:
                raise ConfigError(f"angles.{c}", f"{arr.size} values, but the others have {n}")
            n = arr.size
    n = n or 1
    return {c: (np.full(n, a[0]) if a.size == 1 else a) for c, a in out.items()}, n


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
        if not isinstance(value, str):
            raise ConfigError(
                f"{prefix}.{k}" if prefix else k, f"expected text, found {value!r}", source
            )
        out.append(value)
    return out[0], out[1]


def chain_defaults(chain: Chain) -> tuple[dict[str, float], dict[str, float], dict[str, str]]:
    """The chain's own values: (parameters, errors, origins). Every parameter must have a
    default; an error without one is zero (and has no origin)."""
    params: dict[str, float] = {}
    errors: dict[str, float] = {}
    origins: dict[str, str] = {}
    for n, s in chain.symbols.items():
        if s.value is not None and s.kind != "coordinate":  # a default within its range
            try:
                check_symbol(s.kind, s.unit, s.value)
            except ValueRefused as exc:
                raise ConfigError(f"symbols.{n}.value", exc.message, chain.source) from None
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
    return params, errors, origins


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
