"""The outputs of one command: every target checked before any work, everything written
last, all or none.

A command names its inputs (the configuration and every data file it reads) and its
targets (files such as ``--json r.json``, folders such as ``--out R``). :class:`Outputs`
refuses, before any work is done:

* a target that is one of the inputs (the same path or the same file), or a folder
  target that holds an input, is an ancestor of one, or is the current folder or the root;
* a file target that is a folder or not a regular file, whose folder path runs through a
  file (``afile/r.json``), that lies inside a folder target of the same command, or that
  is named twice;
* an existing folder target that esp did not write: esp recognises its own folders by the
  marker file :data:`MARKER`, which lists the files it wrote there. A folder holding
  anything else (a note, a signed certificate) is never replaced; nor is one whose listed
  subfolders (the report folders inside the output folder of ``esp batch``) hold anything
  their own markers do not list.

The outputs are then staged beside their targets (temporary names that start with a dot)
and moved into place together by :meth:`Outputs.commit`; on any error every staged
output is removed and the targets are left as they were. A staging folder left behind by
a killed run carries the marker and a name only esp makes; the next run into the same
place removes it.
"""

from __future__ import annotations

import contextlib
import json
import os
import shutil
import tempfile
from collections.abc import Iterable
from pathlib import Path
from typing import NoReturn

from esp._version import __version__
from esp.errors import DataError

__all__ = ["MARKER", "MARKER_SCHEMA", "Outputs", "is_esp_folder", "remove_stale"]

#: the marker file esp writes into every folder it creates
MARKER = ".esp-folder.json"
MARKER_SCHEMA = "esp.folder/1"
_STAGE = ".esp-stage-"
_OLD = ".esp-old-"


def _real(path: str | os.PathLike[str]) -> Path:
    return Path(os.path.realpath(os.path.abspath(path)))


def _inside(child: Path, parent: Path) -> bool:
    """True when ``child`` is ``parent`` or lies below it (both real paths)."""
    return child == parent or parent in child.parents


def _read_marker(folder: Path) -> list[str] | None:
    """The files the marker of ``folder`` lists, or None when it has no valid marker."""
    marker = folder / MARKER
    if not marker.is_file() or marker.is_symlink():
        return None
    try:
        doc = json.loads(marker.read_text(encoding="utf-8"))
    except (OSError, ValueError, RecursionError):  # a crafted, deeply nested marker too
        return None
    if not isinstance(doc, dict) or doc.get("schema") != MARKER_SCHEMA:
        return None
    files = doc.get("files")
    if not isinstance(files, list) or not all(isinstance(f, str) for f in files):
        return None
    return files


def is_esp_folder(folder: str | os.PathLike[str]) -> bool:
    """True when ``folder`` carries esp's marker and holds nothing the marker does not list
    (nor does any listed subfolder hold anything its own marker does not list)."""
    path = Path(folder)
    files = _read_marker(path)
    if files is None:
        return False
    return not _foreign(path, files)


def _foreign(folder: Path, listed: Iterable[str], prefix: str = "") -> list[str]:
    """What in ``folder`` esp did not write: entries its marker does not list, and, in a
    listed subfolder (the report folders of ``esp batch``), whatever that folder's own
    marker does not list, at any depth. Paths relative to the top folder, sorted."""
    allowed = set(listed) | {MARKER}
    out = []
    for entry in sorted(os.listdir(folder)):
        path = folder / entry
        if entry not in allowed:
            out.append(prefix + entry)
        elif path.is_dir() and not path.is_symlink():
            inner = _read_marker(path)
            if inner is None:
                out.append(prefix + entry + "/")
            else:
                out.extend(_foreign(path, inner, f"{prefix}{entry}/"))
    return out


def _write_marker(folder: Path, staging: bool = False) -> None:
    files = sorted(e for e in os.listdir(folder) if e != MARKER)
    doc: dict[str, object] = {
        "schema": MARKER_SCHEMA,
        "written_by": f"esp {__version__}",
        "files": files,
    }
    if staging:
        doc["staging"] = True
    (folder / MARKER).write_text(json.dumps(doc, indent=2) + "\n", encoding="utf-8")


def _umask() -> int:
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


def _open_permissions(folder: Path) -> None:
    """Give a staged folder and everything in it the modes of ordinary new files
    (temporary names are created private to the user)."""
    umask = _umask()
    for root, dirs, files in os.walk(folder):
        for d in dirs:
            os.chmod(os.path.join(root, d), 0o777 & ~umask)
        for f in files:
            os.chmod(os.path.join(root, f), 0o666 & ~umask)
    folder.chmod(0o777 & ~umask)


def _unfinished(folder: Path) -> bool:
    """Whether ``folder`` (named as esp names its staging and set-aside folders) is what a
    run killed while making it leaves: empty, or holding nothing but a marker that does
    not read. Nothing else can be in it then, so nothing of anyone's is lost."""
    try:
        entries = os.listdir(folder)
    except OSError:
        return False
    return all(e == MARKER and not (folder / e).is_symlink() for e in entries)


def _remove_stale(target: Path) -> None:
    """Remove staging and set-aside folders a killed run left beside ``target``: those
    carrying esp's marker, and those a run was killed in before its marker was complete
    (:func:`_unfinished`)."""
    parent = target.parent
    if not parent.is_dir():
        return
    for prefix in (f".{target.name}{_STAGE}", f".{target.name}{_OLD}"):
        for entry in parent.iterdir():
            if (
                entry.name.startswith(prefix)
                and entry.is_dir()
                and not entry.is_symlink()
                and (_read_marker(entry) is not None or _unfinished(entry))
            ):
                shutil.rmtree(entry, ignore_errors=True)


def remove_stale(target: str | os.PathLike[str]) -> None:
    """Remove the staging and set-aside folders that a killed run left beside the folder
    target ``target`` (each carries esp's marker; nothing else is touched)."""
    _remove_stale(Path(os.path.abspath(target)))


class Outputs:
    """The targets of one command run.

    Parameters
    ----------
    inputs : every file the command reads; no target may be one of them, and no folder
        target may hold one

    Use :meth:`file` and :meth:`folder` to check each target as soon as the options are
    known (before any work), then :meth:`write_file` / :meth:`stage_file` /
    :meth:`stage_folder` to produce them, then :meth:`commit`. As a context manager it
    commits on success and discards everything staged on an exception.
    """

    def __init__(self, inputs: Iterable[str | os.PathLike[str]] = ()):
        self.inputs = tuple(_real(p) for p in inputs)
        self._files: dict[Path, tuple[Path, str]] = {}  # real target -> (given, option)
        self._folders: dict[Path, tuple[Path, str]] = {}
        self._staged_files: list[tuple[Path, Path]] = []  # (temporary, target)
        self._staged_folders: list[tuple[Path, Path]] = []

    # -- checks ---------------------------------------------------------------------------

    def _fail(self, option: str, given: str | os.PathLike[str], message: str) -> NoReturn:
        raise DataError(f"{option} {os.fspath(given)}: {message}")

    def _check_parent_chain(self, path: Path, option: str, given) -> None:
        """The nearest existing ancestor of ``path`` must be a writable folder."""
        for parent in path.parents:
            if parent.exists():
                if not parent.is_dir():
                    self._fail(option, given, f"{parent} is a file, not a folder")
                if not os.access(parent, os.W_OK | os.X_OK):
                    self._fail(option, given, f"cannot write in {parent} (permission denied)")
                return
            if parent.is_symlink():
                self._fail(option, given, f"{parent} is a broken link")

    def _check_not_input(self, real: Path, option: str, given) -> None:
        for inp in self.inputs:
            same = real == inp
            if not same and real.exists() and inp.exists():
                with contextlib.suppress(OSError):
                    same = os.path.samefile(real, inp)
            if same:
                self._fail(option, given, "is one of this command's inputs; it is not written over")

    def file(self, path: str | os.PathLike[str], option: str) -> Path:
        """Check a file target and return its absolute path."""
        given = Path(path)
        if not os.fspath(path):
            self._fail(option, "''", "expected a file name")
        target = Path(os.path.abspath(given))
        real = _real(given)
        self._check_not_input(real, option, path)
        if given.is_symlink() and not given.exists():
            self._fail(option, path, "is a broken link")
        if real.exists():
            if real.is_dir():
                self._fail(option, path, "is a folder; expected a file name")
            if not real.is_file():
                self._fail(option, path, "exists and is not a regular file")
        self._check_parent_chain(target, option, path)
        if real in self._files:
            other = self._files[real][1]
            self._fail(option, path, f"is also the target of {other}")
        for folder, (_, other) in self._folders.items():
            if _inside(real, folder):
                self._fail(option, path, f"lies inside the folder of {other}")
        self._files[real] = (target, option)
        return target

    def folder(self, path: str | os.PathLike[str], option: str) -> Path:
        """Check a folder target and return its absolute path."""
        given = Path(path)
        if not os.fspath(path):
            self._fail(option, "''", "expected a folder name")
        target = Path(os.path.abspath(given))
        real = _real(given)
        if real.parent == real:
            self._fail(option, path, "is the root folder; a report needs a folder of its own")
        cwd = _real(os.getcwd())
        if _inside(cwd, real):
            what = "the current folder" if cwd == real else "an ancestor of the current folder"
            self._fail(option, path, f"is {what}; choose a new folder for the output")
        for inp in self.inputs:
            if _inside(inp, real):
                self._fail(option, path, f"holds an input of this command ({inp.name})")
        if given.is_symlink():
            self._fail(option, path, "is a symbolic link; choose a new folder")
        if real.exists():
            if not real.is_dir():
                self._fail(option, path, "exists and is not a folder")
            entries = os.listdir(real)
            if entries:
                listed = _read_marker(real)
                if listed is None:
                    self._fail(
                        option,
                        path,
                        f"the folder exists and esp did not write it (no {MARKER}); "
                        "it is not replaced: choose a new or empty folder",
                    )
                foreign = _foreign(real, listed)
                if foreign:
                    shown = ", ".join(foreign[:3]) + (" ..." if len(foreign) > 3 else "")
                    self._fail(
                        option,
                        path,
                        f"holds files esp did not write ({shown}); it is not replaced: "
                        "move them or choose another folder",
                    )
            if not os.access(real, os.W_OK | os.X_OK):
                self._fail(option, path, "cannot write in this folder (permission denied)")
        self._check_parent_chain(target, option, path)
        if real in self._folders:
            self._fail(option, path, f"is also the target of {self._folders[real][1]}")
        for f, (_, other) in self._files.items():
            if _inside(f, real):
                self._fail(option, path, f"holds the target of {other}")
        self._folders[real] = (target, option)
        return target

    # -- staging ----------------------------------------------------------------------------

    def write_file(self, path: str | os.PathLike[str], data: bytes | str) -> None:
        """Stage the content of a checked file target (moved into place by :meth:`commit`)."""
        target = Path(os.path.abspath(path))
        if _real(target) not in self._files:
            raise ValueError(f"{target} was not checked as a file target")
        target.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(prefix=f".{target.name}.", suffix=".tmp", dir=target.parent)
        tmp_path = Path(tmp)
        self._staged_files.append((tmp_path, target))
        try:
            with os.fdopen(fd, "wb") as fh:
                fh.write(data.encode("utf-8") if isinstance(data, str) else data)
        except OSError as exc:  # a full disk names no file: name the target
            raise OSError(exc.errno, exc.strerror, exc.filename or str(target)) from exc
        tmp_path.chmod(0o666 & ~_umask())

    def stage_file(self, path: str | os.PathLike[str]) -> Path:
        """A temporary path beside a checked file target, for a writer that takes a path
        (a figure's ``savefig``); the file written there is moved into place by
        :meth:`commit`, or removed by :meth:`discard`."""
        target = Path(os.path.abspath(path))
        if _real(target) not in self._files:
            raise ValueError(f"{target} was not checked as a file target")
        target.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(prefix=f".{target.name}.", suffix=".tmp", dir=target.parent)
        os.close(fd)
        tmp_path = Path(tmp)
        self._staged_files.append((tmp_path, target))
        tmp_path.chmod(0o666 & ~_umask())
        return tmp_path

    def stage_folder(self, path: str | os.PathLike[str]) -> Path:
        """An empty staging folder for a checked folder target; fill it, then commit."""
        target = Path(os.path.abspath(path))
        if _real(target) not in self._folders:
            raise ValueError(f"{target} was not checked as a folder target")
        target.parent.mkdir(parents=True, exist_ok=True)
        _remove_stale(target)
        staged = Path(tempfile.mkdtemp(prefix=f".{target.name}{_STAGE}", dir=target.parent))
        self._staged_folders.append((staged, target))  # discarded on any error from here
        _write_marker(staged, staging=True)  # so that a killed run's folder is known as esp's
        return staged

    def commit(self) -> None:
        """Move every staged output into place: files, then folders (an earlier esp folder
        is set aside and removed only once the new one is in place).

        The folder targets are checked again first, since the work may have taken minutes:
        one that now holds anything esp did not write (a file the user put there, a folder
        made meanwhile) stops the commit before anything is moved, and everything staged is
        discarded (:class:`~esp.errors.DataError`)."""
        try:
            for _, target in self._staged_folders:
                _check_replaceable(target)
        except DataError:
            self.discard()
            raise
        for tmp, target in self._staged_files:
            os.replace(tmp, target)
        self._staged_files.clear()
        for staged, target in self._staged_folders:
            _write_marker(staged)
            _open_permissions(staged)
            _replace_folder(staged, target)
        self._staged_folders.clear()

    def discard(self) -> None:
        """Remove everything staged; the targets stay as they were."""
        for tmp, _ in self._staged_files:
            with contextlib.suppress(FileNotFoundError):
                tmp.unlink()
        for staged, _ in self._staged_folders:
            shutil.rmtree(staged, ignore_errors=True)
        self._staged_files.clear()
        self._staged_folders.clear()

    def __enter__(self) -> Outputs:
        return self

    def __exit__(self, exc_type, exc, tb) -> None:
        if exc_type is None:
            self.commit()
        else:
            self.discard()


def _unwritten(folder: Path) -> list[str]:
    """What in an existing folder esp did not write (everything, without its marker)."""
    entries = sorted(os.listdir(folder))
    if not entries:
        return []
    listed = _read_marker(folder)
    return entries if listed is None else _foreign(folder, listed)


def _check_replaceable(target: Path) -> None:
    """Refuse to replace ``target`` if it now holds anything esp did not write."""
    if target.is_symlink() or (target.exists() and not target.is_dir()):
        raise DataError(f"{target}: became a file or link during the run; nothing was written")
    if target.is_dir():
        foreign = _unwritten(target)
        if foreign:
            shown = ", ".join(foreign[:3]) + (" ..." if len(foreign) > 3 else "")
            raise DataError(
                f"{target}: files esp did not write appeared in it during the run ({shown}); "
                "nothing was written"
            )


def _replace_folder(staged: Path, target: Path) -> None:
    """Move ``staged`` to ``target``; an existing (checked) esp folder is set aside first
    and removed after, or put back if the move fails or it holds, once set aside, anything
    esp did not write."""
    if not target.exists():
        os.replace(staged, target)
        return
    old = Path(tempfile.mkdtemp(prefix=f".{target.name}{_OLD}", dir=target.parent))
    old.rmdir()
    os.replace(target, old)
    if _unwritten(old):  # written to in the instant since the check: keep it
        os.replace(old, target)
        shutil.rmtree(staged, ignore_errors=True)
        raise DataError(f"{target}: changed while esp replaced it; it was left as it is")
    try:
        os.replace(staged, target)
    except BaseException:
        os.replace(old, target)
        raise
    shutil.rmtree(old, ignore_errors=True)
