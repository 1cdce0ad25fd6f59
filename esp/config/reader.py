"""The checking primitives of the configuration reader (the file itself is read by
:func:`esp.io.tomlfile.read_toml_file`).

Every problem raises :class:`esp.core.errors.ConfigError` naming the dotted key (``axes.X.step``),
what was expected and what was found; an unknown key is refused with a "did you mean"
suggestion.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import replace
from pathlib import Path
from types import MappingProxyType
from typing import Any, NoReturn

from esp.core.errors import ConfigError
from esp.core.names import AXIS_NAMES
from esp.core.text import TEXT_MAX_CHARS, closest, too_long
from esp.core.units import POSITION_LIMIT_MM, flush_tiny
from esp.core.values import QUANTITIES, Quantity, ValueRefused, check

__all__ = [
    "Reader",
    "join",
    "quoted",
]


#: a top-level table that marks a file for another command -> what the file is and which
#: command reads it, for the message that refuses it as a machine file
OTHER_FILES = {
    "parallel_machine": (
        "a serial-parallel machine file ([parallel_machine]), not the file of a serial "
        "machine: run 'esp parallel FILE' on it (docs/parallel.md)"
    ),
    "chain": (
        "a kinematic chain file ([chain], [symbols], [[steps]]), not a machine file: "
        "'esp derive FILE' derives its formulae, 'esp head FILE' analyses a servo head "
        "written as one, and a machine file names a head or rotary-table chain with "
        "[head] or [table] file = ... (docs/kinematics.md, docs/heads.md)"
    ),
}
OTHER_FILES["steps"] = OTHER_FILES["symbols"] = OTHER_FILES["chain"]


def _is_table_file(value: Mapping[str, Any]) -> bool:
    """Whether the top of a file is that of a rotary table file (:mod:`esp.core.devices.table`):
    a ``[table]`` holding a chain, parameters or errors rather than ``file``/``angles``."""
    table = value.get("table")
    return isinstance(table, Mapping) and any(
        k in table for k in ("chain", "parameters", "errors", "errors_from")
    )


def join(prefix: str, name: str) -> str:
    return f"{prefix}.{name}" if prefix else name


def quoted(options: Iterable[str]) -> str:
    return ", ".join(repr(o) for o in options)


class Reader:
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
        if not key:  # the top of a file: is it a file of another command?
            other = next((n for n in value if n not in allowed and n in OTHER_FILES), None)
            if other is not None:
                self.fail(other, f"this is {OTHER_FILES[other]}")
        for name in value:
            if name not in allowed:
                hint = closest(name, allowed)
                did_you_mean = f"; did you mean {hint!r}?" if hint else ""
                self.fail(
                    join(key, name),
                    f"unknown key {name!r}{did_you_mean} (expected one of {quoted(allowed)})",
                )
        for name in required:
            if name not in value:
                if not key and _is_table_file(value):
                    self.fail(
                        name,
                        "required key is missing: this is a rotary table file ([table] with "
                        "its chain, parameters and errors), not a machine file; a machine "
                        "file names it with [table] file = ... (docs/rotary.md)",
                    )
                self.fail(join(key, name), "required key is missing")
        return value

    def number(self, value: Any, key: str, quantity: str | Quantity = "number") -> float:
        """A number within the range of ``quantity`` (:data:`esp.core.values.QUANTITIES`),
        refused by the one check of :mod:`esp.core.values` with the key and the value as given."""
        try:
            x = check(value, quantity)
        except ValueRefused as exc:
            self.fail(key, exc.message)
        return flush_tiny(x)  # below 1e-30 in size: 0 (esp.core.units.TINY)

    def position(self, value: Any, key: str, what: str = "a position") -> float:
        """A number of mm within ±:data:`esp.core.units.POSITION_LIMIT_MM` (±100 m)."""
        q = QUANTITIES["position"]
        return self.number(value, key, replace(q, what=what, high=POSITION_LIMIT_MM))

    def string(self, value: Any, key: str, limit: int = TEXT_MAX_CHARS) -> str:
        """A string of at most ``limit`` characters (:data:`esp.core.text.TEXT_MAX_CHARS`
        by default; :data:`~esp.core.text.NAME_MAX_CHARS` for a name): user text reaches
        reports, whose layout time grows with it, so its length is bounded where it is read."""
        if not isinstance(value, str):
            self.fail(key, f"expected a string, found {value!r}")
        message = too_long(value, limit)
        if message is not None:
            self.fail(key, message)
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
        message = f"expected one of {quoted(choices)}, found {value!r}"
        if isinstance(value, str):
            hint = closest(value, choices)
            if hint:
                message += f"; did you mean {hint!r}?"
        self.fail(key, message)

    def numbers(
        self, value: Any, key: str, quantity: str | Quantity = "number"
    ) -> tuple[float, ...]:
        """A non-empty list of numbers, each within the range of ``quantity``."""
        if not isinstance(value, list) or not value:
            self.fail(key, f"expected a non-empty list of numbers, found {value!r}")
        return tuple(self.number(v, f"{key}[{i}]", quantity) for i, v in enumerate(value))

    def interval(self, value: Any, key: str) -> tuple[float, float]:
        """``[low, high]`` in mm with low <= high."""
        if not isinstance(value, list) or len(value) != 2:
            self.fail(key, f"expected [low, high] in mm, found {value!r}")
        lo = self.position(value[0], f"{key}[0]")
        hi = self.position(value[1], f"{key}[1]")
        if lo > hi:
            self.fail(key, f"expected low <= high, found {value!r}")
        return lo, hi

    def xyz(self, value: Any, key: str, *, all_required: bool) -> Mapping[str, float]:
        """A table ``{ X = ..., Y = ..., Z = ... }`` of positions in mm, in X, Y, Z order."""
        if not isinstance(value, Mapping):
            self.fail(key, f"expected a table {{ X = ..., Y = ..., Z = ... }}, found {value!r}")
        table = self.table(value, key, AXIS_NAMES, AXIS_NAMES if all_required else ())
        return MappingProxyType(
            {n: self.position(table[n], f"{key}.{n}") if n in table else 0.0 for n in AXIS_NAMES}
        )
