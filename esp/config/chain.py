"""Read a chain file (``CHAIN.toml``) into a :class:`~esp.core.kinematics.chain.Chain`.

The format is documented in ``docs/kinematics.md``; the chain type and its numerics are
:mod:`esp.core.kinematics`, which reads no files. The reader is strict: an unknown key is
refused with a "did you mean" suggestion, every symbol must be declared with its kind, and
every problem raises :class:`esp.core.errors.ConfigError` naming the dotted key
(``steps[3].coordinate``, steps counted from 1; ``symbols.G.unit``).
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

from esp.core.errors import ConfigError
from esp.core.kinematics.chain import (
    SLOTS,
    Chain,
    ErrorMotion,
    Prismatic,
    Revolute,
    Rotate,
    Step,
    Translate,
    _axis,
    _pivot,
)
from esp.core.kinematics.expr import as_expr
from esp.core.text import NAME_MAX_CHARS, TEXT_MAX_CHARS, did_you_mean, too_long
from esp.core.values import config_number
from esp.io.tomlfile import read_toml_file

__all__ = ["STEP_KINDS", "chain_from_dict", "load_chain"]

TOP_KEYS = ("chain", "symbols", "definitions", "steps")
CHAIN_KEYS = ("name", "description", "reference")
#: step kind -> the keys a step of that kind may hold
STEP_KINDS: dict[str, tuple[str, ...]] = {
    "translate": ("translate", "note"),
    "rotate": ("rotate", "angle", "note"),
    "prismatic": ("prismatic", "coordinate", "errors", "pivot", "note"),
    "revolute": ("revolute", "coordinate", "errors", "pivot", "note"),
    "errors": ("errors", "pivot", "note"),
}


def _fail(key: str, message: str, source: str | None) -> ConfigError:
    return ConfigError(key, message, source)


def _keys(table: Any, key: str, allowed: tuple[str, ...], source: str | None) -> Mapping:
    if not isinstance(table, Mapping):
        raise _fail(key or "<top>", f"expected a table, found {table!r}", source)
    for k in table:
        if k not in allowed:
            raise _fail(
                f"{key}.{k}" if key else k,
                f"unknown key {k!r}{did_you_mean(k, allowed)} (expected one of "
                + ", ".join(repr(a) for a in allowed)
                + ")",
                source,
            )
    return table


def _text(value: Any, key: str, source: str | None, limit: int = TEXT_MAX_CHARS) -> str:
    if not isinstance(value, str):
        raise _fail(key, f"expected text, found {value!r}", source)
    message = too_long(value, limit)
    if message is not None:
        raise _fail(key, message, source)
    return value


def load_chain(path: str | Path) -> Chain:
    """Read a chain file.

    Raises
    ------
    ConfigError
        The file is missing or unreadable (key ``<file>``), not valid TOML (``<toml>``, with
        line and column), or a key is unknown, missing or holds a value that does not fit.
    """
    p = Path(path)
    data = read_toml_file(p, "chain")
    return chain_from_dict(data, source=str(p), default_name=p.stem)


def chain_from_dict(
    data: Mapping[str, Any], source: str | None = None, default_name: str = ""
) -> Chain:
    """Build a chain from the parsed content of a chain file (what :func:`tomllib.loads`
    returns)."""
    _keys(data, "", TOP_KEYS, source)
    info = _keys(data.get("chain", {}), "chain", CHAIN_KEYS, source)
    name = _text(info.get("name", default_name), "chain.name", source, NAME_MAX_CHARS)
    description = _text(info.get("description", ""), "chain.description", source)
    if "reference" in info:
        _text(info["reference"], "chain.reference", source)
    symbols = data.get("symbols", {})
    if not isinstance(symbols, Mapping):
        raise _fail("symbols", f"expected a table of symbols, found {symbols!r}", source)
    definitions = data.get("definitions", {})
    if not isinstance(definitions, Mapping):
        found = f"found {definitions!r}"
        raise _fail("definitions", f"expected a table name = expression, {found}", source)
    steps_raw = data.get("steps")
    if steps_raw is None or (isinstance(steps_raw, list) and not steps_raw):
        raise _fail("steps", "empty chain: expected at least one [[steps]] table", source)
    if not isinstance(steps_raw, list):
        raise _fail("steps", f"expected an array of tables [[steps]], found {steps_raw!r}", source)
    try:
        steps = [_step(s, f"steps[{i}]") for i, s in enumerate(steps_raw, 1)]
    except ConfigError as exc:
        raise ConfigError(exc.key, exc.message, source) from None
    return Chain(
        steps,
        symbols,
        name=name,
        description=description,
        definitions=definitions,
        strict=True,
        source=source,
    )


def _step(raw: Any, key: str) -> Step:
    if not isinstance(raw, Mapping):
        raise ConfigError(key, f"expected a table, found {raw!r}")
    present = [k for k in ("translate", "rotate", "prismatic", "revolute") if k in raw]
    if len(present) > 1:
        raise ConfigError(
            key, f"a step is one transform; found both {present[0]!r} and {present[1]!r}"
        )
    if present:
        kind = present[0]
    elif "errors" in raw:
        kind = "errors"
    else:
        found = ", ".join(repr(k) for k in raw) or "nothing"
        hints = [did_you_mean(k, STEP_KINDS) for k in raw]
        hint = next((h for h in hints if h), "")
        raise ConfigError(
            key,
            "expected one of the keys 'translate', 'rotate', 'prismatic', 'revolute', "
            f"'errors', found {found}{hint}",
        )
    allowed = STEP_KINDS[kind]
    for k in raw:
        if k not in allowed:
            raise ConfigError(
                f"{key}.{k}",
                f"unknown key {k!r} in a {kind} step{did_you_mean(k, allowed)} (expected one of "
                + ", ".join(repr(a) for a in allowed)
                + ")",
            )
    note = raw.get("note", "")
    if not isinstance(note, str):
        raise ConfigError(f"{key}.note", f"expected text, found {note!r}")
    message = too_long(note, TEXT_MAX_CHARS)
    if message is not None:
        raise ConfigError(f"{key}.note", message)
    if kind == "translate":
        v = raw["translate"]
        if isinstance(v, Mapping):
            _keys(v, f"{key}.translate", ("x", "y", "z"), None)
            xyz = [v.get(c, 0) for c in "xyz"]
        elif isinstance(v, list) and len(v) == 3:
            xyz = v
        else:
            raise ConfigError(
                f"{key}.translate", f"expected [x, y, z] or {{ x = ..., ... }}, found {v!r}"
            )
        for x, c in zip(xyz, "xyz", strict=True):
            if isinstance(x, int | float) and not isinstance(x, bool):  # mm, within ±100 m
                config_number(x, f"{key}.translate.{c}", "position")
        q = [as_expr(x, f"{key}.translate.{c}") for x, c in zip(xyz, "xyz", strict=True)]
        return Translate(q[0], q[1], q[2], note)
    if kind == "rotate":
        axis = _axis(raw["rotate"], f"{key}.rotate")
        if "angle" not in raw:
            raise ConfigError(f"{key}.angle", 'a rotation needs its angle (e.g. angle = "Yp")')
        return Rotate(axis, as_expr(raw["angle"], f"{key}.angle"), note)
    motion = _motion(raw, key) if "errors" in raw else None
    if "pivot" in raw and motion is None:
        raise ConfigError(f"{key}.pivot", "a pivot without errors does nothing")
    if kind == "errors":
        return motion  # type: ignore[return-value]
    axis = _axis(raw[kind], f"{key}.{kind}")
    coordinate = raw.get("coordinate")
    if coordinate is None:
        raise ConfigError(
            f"{key}.coordinate",
            f'a {kind} joint needs the coordinate that drives it (e.g. coordinate = "X")',
        )
    if not isinstance(coordinate, str):
        raise ConfigError(f"{key}.coordinate", f"expected a symbol name, found {coordinate!r}")
    cls = Prismatic if kind == "prismatic" else Revolute
    return cls(axis, coordinate, motion, note)


def _motion(raw: Mapping[str, Any], key: str) -> ErrorMotion:
    errs = raw["errors"]
    if not isinstance(errs, Mapping) or not errs:
        raise ConfigError(
            f"{key}.errors",
            f'expected a table of slots {", ".join(SLOTS)} (e.g. {{ tx = "dx_Y" }}), '
            f"found {errs!r}",
        )
    _keys(errs, f"{key}.errors", SLOTS, None)
    slots = {s: as_expr(v, f"{key}.errors.{s}") for s, v in errs.items()}
    pivot = _pivot(raw.get("pivot", [0, 0, 0]), f"{key}.pivot")
    return ErrorMotion(**slots, pivot=pivot, note=raw.get("note", ""))
