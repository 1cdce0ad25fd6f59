"""The exceptions of esp.

The library raises these; only the command-line layer turns them into exit codes and
one-line messages. Every message names where the problem is (file and line, or the
configuration key), what was expected and what was found.
"""

from __future__ import annotations

from pathlib import Path

__all__ = ["ConfigError", "DataError", "EspError", "EspWarning", "ParseError"]


class EspError(Exception):
    """Base class of every error esp raises on bad input."""


class EspWarning(UserWarning):
    """Something in an input esp reads in a way the user should know of (a file that
    needed reading differently from what it says); the message names the file and line.
    The command line shows it as one line, ``esp: warning: ...``, and goes on."""


class ParseError(EspError, ValueError):
    """A data file does not hold what it must.

    Parameters
    ----------
    path : path of the file (or a name such as ``"<stdin>"``)
    line : 1-based line number, or None when the problem is not on one line
    message : what was expected and what was found
    """

    def __init__(self, path: str | Path | None, line: int | None, message: str):
        self.path = None if path is None else str(path)
        self.line = line
        self.message = message
        super().__init__(str(self))

    def __str__(self) -> str:
        where = self.path or "<input>"
        if self.line is not None:
            where = f"{where}:{self.line}"
        return f"{where}: {self.message}"


class ConfigError(EspError, ValueError):
    """A configuration value is missing or does not fit.

    Parameters
    ----------
    key : dotted key path, e.g. ``"axes.X.step"``
    message : what was expected and what was found
    path : the configuration file, when there is one
    """

    def __init__(self, key: str, message: str, path: str | Path | None = None):
        self.key = key
        self.message = message
        self.path = None if path is None else str(path)
        super().__init__(str(self))

    def __str__(self) -> str:
        where = f"{self.path}: " if self.path else ""
        return f"{where}{self.key}: {self.message}"


class DataError(EspError, ValueError):
    """Data that parsed but cannot be used as asked (a position outside the measured range,
    two files that do not correspond, too few runs for a statistic)."""
