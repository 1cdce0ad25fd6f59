"""Reading a TOML file esp is given: a machine configuration, a chain, a head, a table or a
serial-parallel machine.

Every file goes through the same checks before its content is used: it exists and is a
regular file (not a folder, device or pipe), it is no larger than :data:`TOML_MAX_BYTES`, it
is UTF-8 (a byte-order mark is allowed), it is valid TOML, and its tables and arrays are
nested no deeper than :data:`TOML_MAX_DEPTH`. A problem raises
:class:`esp.core.errors.ConfigError` with the key ``"<file>"`` (the file itself) or ``"<toml>"``
(its text, with the line and column where TOML gives them).
"""

from __future__ import annotations

import os
import re
import stat
import tomllib
from pathlib import Path
from typing import Any

from esp.core.errors import ConfigError

__all__ = ["TOML_MAX_BYTES", "TOML_MAX_DEPTH", "read_toml_file", "toml_message"]

#: the largest TOML file esp reads
TOML_MAX_BYTES = 1024 * 1024
#: the deepest nesting of tables and arrays a TOML file may have
TOML_MAX_DEPTH = 16

_TOML_WHERE = re.compile(r"\s*\((at line (\d+), column (\d+)|at end of document)\)\s*$")


def toml_message(message: str) -> str:
    """tomllib's ``"Invalid value (at line 2, column 5)"`` as
    ``"invalid TOML at line 2, column 5: invalid value"``."""
    m = _TOML_WHERE.search(message)
    if not m:
        return f"invalid TOML: {message}"
    what = message[: m.start()]
    what = what[:1].lower() + what[1:]
    if m.group(2):
        return f"invalid TOML at line {m.group(2)}, column {m.group(3)}: {what}"
    return f"invalid TOML at the end of the file: {what}"


def _depth(value: Any, limit: int) -> int:
    """The nesting depth of parsed TOML, counting no further than ``limit + 1``."""
    if limit < 0 or not isinstance(value, dict | list):
        return 0
    children = value.values() if isinstance(value, dict) else value
    return 1 + max((_depth(v, limit - 1) for v in children), default=0)


def read_toml_file(path: str | os.PathLike[str], what: str = "configuration") -> dict[str, Any]:
    """The content of the TOML file ``path``, as plain dicts, lists, numbers and strings.

    ``what`` names the kind of file in messages (``"no such chain file"``).

    Raises
    ------
    ConfigError
        The file is missing, not a regular file, larger than :data:`TOML_MAX_BYTES` or
        unreadable (key ``"<file>"``); it is not UTF-8, not valid TOML, or nested deeper
        than :data:`TOML_MAX_DEPTH` (key ``"<toml>"``).
    """
    p = Path(path)
    try:
        info = os.stat(p)
    except FileNotFoundError:
        raise ConfigError("<file>", f"no such {what} file", p) from None
    except OSError as exc:
        raise ConfigError("<file>", f"cannot be read: {exc.strerror or exc}", p) from None
    if stat.S_ISDIR(info.st_mode):
        raise ConfigError("<file>", f"is a folder, expected a {what} file", p)
    if not stat.S_ISREG(info.st_mode):
        raise ConfigError("<file>", f"expected a regular {what} file, found a device or pipe", p)
    if info.st_size > TOML_MAX_BYTES:
        raise ConfigError(
            "<file>", f"expected at most {TOML_MAX_BYTES} bytes, found {info.st_size}", p
        )
    try:
        raw = p.read_bytes()
    except OSError as exc:
        raise ConfigError("<file>", f"cannot be read: {exc.strerror or exc}", p) from None
    try:
        text = raw.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        found = f"byte {raw[exc.start]:#04x} at offset {exc.start}"
        raise ConfigError("<toml>", f"expected UTF-8 text, found {found}", p) from None
    too_deep = f"expected tables nested at most {TOML_MAX_DEPTH} deep, found deeper"
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ConfigError("<toml>", toml_message(str(exc)), p) from None
    except RecursionError:
        raise ConfigError("<toml>", too_deep, p) from None
    if _depth(data, TOML_MAX_DEPTH) > TOML_MAX_DEPTH:
        raise ConfigError("<toml>", too_deep, p)
    return data
