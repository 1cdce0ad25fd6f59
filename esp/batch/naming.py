"""The rows of a batch and the names of their report folders (``esp batch``).

Report folders
    Each machine's report goes to ``OUT/<folder>``, where ``<folder>`` is the file's path
    relative to the deepest folder common to all the files found, without ``.toml``, its
    parts joined by ``__`` (``gantry/machine-tcp.toml`` -> ``gantry__machine-tcp``);
    characters other than ASCII letters, digits, ``.``, ``_`` and ``-`` become ``_`` and a
    name already taken (compared without regard to case) gets ``-2``, ``-3``, ... in the
    order of the rows.

"""

from __future__ import annotations

import os
import re
import unicodedata
from collections.abc import Sequence
from dataclasses import dataclass

__all__ = ["SUMMARY_CSV", "SUMMARY_MD", "SUMMARY_PDF", "BatchItem", "plan"]

SUMMARY_CSV = "summary.csv"
SUMMARY_MD = "summary.md"
SUMMARY_PDF = "summary.pdf"
_MAX_FOLDER_CHARS = 100
_UNSAFE = re.compile(r"[^A-Za-z0-9._-]+")


@dataclass(frozen=True)
class BatchItem:
    """One machine of a batch.

    ``path``: the configuration as found (what :func:`esp.config.load_machine` is given,
    so messages name it that way); ``file``: its path relative to the common folder of the
    batch, with ``/`` separators (the ``file`` column); ``folder``: the name of its report
    folder inside the output folder. ``error``: for a folder that could not be searched,
    why (the item is then a row of its own, ``file`` ending in ``/``, and has no report).
    """

    path: str
    file: str
    folder: str
    error: str | None = None


def _safe_part(part: str) -> str:
    """An ASCII file-name part: accents dropped, other characters replaced by ``_``."""
    ascii_text = unicodedata.normalize("NFKD", part).encode("ascii", "ignore").decode("ascii")
    return _UNSAFE.sub("_", ascii_text)


def _folder_name(parts: Sequence[str]) -> str:
    stem = list(parts)
    if stem and stem[-1].lower().endswith(".toml"):
        stem[-1] = stem[-1][: -len(".toml")]
    name = "__".join(_safe_part(p) for p in stem)
    name = name.lstrip(".-")[:_MAX_FOLDER_CHARS]
    return name or "machine"


def plan(
    files: Sequence[str | os.PathLike[str]], unreadable: Sequence[tuple[str, str]] = ()
) -> list[BatchItem]:
    """The batch items of ``files`` in row order, with unique report folder names.

    Rows are sorted by the path relative to the deepest folder common to all files,
    compared part by part (a folder's files stay together). Folder names follow the rule
    of the module docstring; ``summary.csv`` and ``summary.md`` are never used as names.
    ``unreadable`` (from :func:`find_machines`): folders that could not be searched, each
    an item with its ``error`` and no report folder, sorted in among the files.
    """
    if not files and not unreadable:
        return []
    listed = [(os.fspath(f), None) for f in files] + [(p, m) for p, m in unreadable]
    absolute = [os.path.abspath(f) for f, _ in listed]
    # a folder that could not be searched counts as a folder, not as a file in one
    dirs = [
        a if m is not None else os.path.dirname(a)
        for a, (_, m) in zip(absolute, listed, strict=True)
    ]
    try:
        root = os.path.commonpath(dirs)
    except ValueError:  # different drives: no common folder
        root = ""
    entries = []
    for (given, error), full in zip(listed, absolute, strict=True):
        rel = os.path.relpath(full, root) if root else full.lstrip(os.sep)
        parts = tuple(p for p in re.split(r"[\\/]", rel) if p and p != ".")
        entries.append((parts, given, error))
    entries.sort(key=lambda e: (e[0], e[1]))
    taken = {SUMMARY_CSV.casefold(), SUMMARY_MD.casefold()}
    items = []
    for parts, given, error in entries:
        if error is not None:
            items.append(BatchItem(given, "/".join(parts) + "/", "", error))
            continue
        base = _folder_name(parts)
        name, n = base, 1
        while name.casefold() in taken:
            n += 1
            name = f"{base}-{n}"
        taken.add(name.casefold())
        items.append(BatchItem(given, "/".join(parts), name))
    return items
