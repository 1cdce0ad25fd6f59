"""Which files of a batch are machine configurations (``esp batch``, docs/reports.md).

Discovery
    A path given explicitly as a file is always taken as a machine configuration. Folders
    are searched recursively for files named ``*.toml`` whose top level holds a
    ``[machine]`` table (the one table every ``machine.toml`` must have); other TOML files
    (``pyproject.toml``, ...) are skipped. A ``*.toml`` that cannot be read or is not valid
    TOML cannot be classified and is kept, so that a broken configuration is reported
    rather than silently left out. Hidden folders and files (name starting with ``.``) and
    the output folder are not searched; symbolic links to folders are not followed. A
    configuration with an ``[identify]`` table (the input of ``esp identify``) is listed
    with a ``skipped`` row saying so, not analysed.

"""

from __future__ import annotations

import os
import stat
import tomllib
from collections.abc import Iterable
from pathlib import Path

from esp.core.errors import DataError
from esp.io.tomlfile import TOML_MAX_BYTES

__all__ = ["IDENTIFY_SKIPPED", "find_machines", "is_identify_config", "is_machine_config"]


def is_machine_config(path: str | os.PathLike[str]) -> bool:
    """True when ``path`` is to be analysed as a machine configuration.

    That is: its top level holds a ``[machine]`` table, or it cannot be read or parsed as
    TOML (it may be a broken ``machine.toml``; analysing it reports why). A valid TOML file
    without a ``machine`` table is not a machine configuration, nor is one with an
    ``[identify]`` table (the input of ``esp identify``, docs/identify.md).
    """
    try:
        info = os.stat(path)
        if not stat.S_ISREG(info.st_mode) or info.st_size > TOML_MAX_BYTES:
            return True  # not read here: the analysis reports what is wrong with it
        data = tomllib.loads(Path(path).read_bytes().decode("utf-8-sig"))
    except (OSError, UnicodeDecodeError, tomllib.TOMLDecodeError, RecursionError):
        return True
    return isinstance(data.get("machine"), dict) and "identify" not in data


#: the verdict of a configuration batch does not analyse: the input of ``esp identify``
IDENTIFY_SKIPPED = "skipped: an identify configuration ([identify] table); run esp identify"


def is_identify_config(path: str | os.PathLike[str]) -> bool:
    """True when ``path`` is a valid TOML file with ``[machine]`` and ``[identify]`` tables:
    the input of ``esp identify`` (docs/identify.md), which ``esp batch`` lists as skipped
    rather than analyses."""
    try:
        info = os.stat(path)
        if not stat.S_ISREG(info.st_mode) or info.st_size > TOML_MAX_BYTES:
            return False
        data = tomllib.loads(Path(path).read_bytes().decode("utf-8-sig"))
    except (OSError, UnicodeDecodeError, tomllib.TOMLDecodeError, RecursionError):
        return False
    return isinstance(data.get("machine"), dict) and isinstance(data.get("identify"), dict)


def find_machines(
    paths: Iterable[str | os.PathLike[str]],
    skip: Iterable[str | os.PathLike[str]] = (),
    unreadable: list[tuple[str, str]] | None = None,
) -> list[Path]:
    """The machine configurations named by ``paths``, each once, sorted.

    Parameters
    ----------
    paths : files (always taken) and folders (searched recursively for ``*.toml`` files
        that :func:`is_machine_config` or :func:`is_identify_config` accepts -- the latter
        become ``skipped`` rows; hidden folders and files are left out)
    skip : folders not to search, such as the output folder
    unreadable : when given, a folder that cannot be searched is appended to it as
        ``(path, message)`` and the search goes on; when None it is an error

    Returns
    -------
    list of Path
        As found (a folder given as a relative path gives relative paths), sorted by
        their absolute paths; the same file reached twice is listed once.

    Raises
    ------
    DataError
        A path does not exist or is neither a file nor a folder, or (without
        ``unreadable``) a folder cannot be searched.
    """
    skipped = {os.path.realpath(s) for s in skip}
    found: dict[str, Path] = {}

    def add(path: str) -> None:
        found.setdefault(os.path.normcase(os.path.abspath(path)), Path(os.path.normpath(path)))

    def walk_error(exc: OSError) -> None:
        message = f"{exc.filename}: the folder cannot be searched: {exc.strerror or exc}"
        if unreadable is None:
            raise DataError(message)
        unreadable.append((os.fspath(exc.filename), message))

    for given in paths:
        given = os.fspath(given)
        if os.path.isfile(given):
            add(given)
            continue
        if not os.path.isdir(given):
            what = (
                "no such file or folder"
                if not os.path.lexists(given)
                else (
                    "expected a machine configuration or a folder, found a device, pipe or "
                    "socket (or a broken link)"
                )
            )
            raise DataError(f"{given}: {what}")
        if os.path.realpath(given) in skipped:
            continue
        for folder, dirs, files in os.walk(given, onerror=walk_error):
            dirs[:] = sorted(
                d
                for d in dirs
                if not d.startswith(".")
                and os.path.realpath(os.path.join(folder, d)) not in skipped
            )
            for name in sorted(files):
                path = os.path.join(folder, name)
                if (
                    not name.startswith(".")
                    and name.lower().endswith(".toml")
                    and os.path.isfile(path)
                    and (is_machine_config(path) or is_identify_config(path))
                ):
                    add(path)
    return [found[k] for k in sorted(found)]
