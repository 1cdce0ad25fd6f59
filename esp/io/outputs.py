"""The outputs of one command: every target checked before any work, everything written
last, all or none.

A command names its inputs (the configuration and every data file it reads) and its
targets (files such as ``--json r.json`` or ``--plot x.png``, folders such as ``--out R``).
:class:`Outputs` refuses, before any work is done:

* a target that is one of the inputs (the same path, or the same file: device and inode,
  through any link), or a folder target that holds an input, is an ancestor of one, or is
  the current folder, the root or a mount point;
* a target that is a symbolic link, a file target that is a folder or not a regular file,
  whose folder path runs through a file (``afile/r.json``), that lies inside a folder
  target of the same command, or that is named twice;
* an existing file that esp did not write, or that changed since esp wrote it. esp
  recognises a single file of its own by the registry :data:`REGISTRY` in the file's
  folder, which records the name, size and SHA-256 of every file esp wrote there;
* an existing folder that esp did not write, or that holds anything esp did not write or
  that changed since: esp recognises its own folders by the marker file :data:`MARKER`,
  which records the size and SHA-256 of every file esp wrote there (at any depth) and
  every folder it made.

The outputs are then staged beside their targets (temporary names that start with a dot)
and moved into place together by :meth:`Outputs.commit`: every existing target is first
set aside, then every staged output moved in, then what was set aside removed. A failure
at any step (a file system that refuses the rename, a permission) puts every target back
as it was and removes everything staged: the outputs of one run are written all or none.

A staging or set-aside folder carries its owner (process id and start time) in its name;
the next run into the same place removes one whose owner is gone, never one of a run still
alive. Commits into one folder are serialised by a lock on that folder
(:func:`fcntl.flock`, where the system has it).
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import os
import re
import shutil
import socket
import tempfile
from collections.abc import Iterable, Iterator
from pathlib import Path
from types import TracebackType
from typing import NoReturn

from esp._version import __version__
from esp.core.errors import DataError

__all__ = [
    "MARKER",
    "MARKER_SCHEMA",
    "REGISTRY",
    "REGISTRY_SCHEMA",
    "Outputs",
    "is_esp_folder",
    "remove_stale",
]

#: the marker file esp writes into every folder it creates
MARKER = ".esp-folder.json"
MARKER_SCHEMA = "esp.folder/2"
_LEGACY_MARKER_SCHEMA = "esp.folder/1"  # names only, no sizes or hashes (esp 0.2)
#: the registry of the single files esp wrote in a folder (``--json r.json``, ``--plot``)
REGISTRY = ".esp-files.json"
REGISTRY_SCHEMA = "esp.files/1"
_STAGE = ".esp-stage-"
_OLD = ".esp-old-"
_OWNER = re.compile(r"^(\d+)\.(\d+)\.")  # pid.start. after the prefix
_CHUNK = 1 << 20


def _real(path: str | os.PathLike[str]) -> Path:
    return Path(os.path.realpath(os.path.abspath(path)))


def _inside(child: Path, parent: Path) -> bool:
    """True when ``child`` is ``parent`` or lies below it (both real paths)."""
    return child == parent or parent in child.parents


def _shown(names: list[str]) -> str:
    return ", ".join(names[:3]) + (" ..." if len(names) > 3 else "")


# -- what esp wrote: sizes and hashes --------------------------------------------------------


def _digest(path: Path) -> str:
    h = hashlib.sha256()
    with open(path, "rb") as fh:
        while chunk := fh.read(_CHUNK):
            h.update(chunk)
    return h.hexdigest()


def _record(path: Path) -> dict[str, object]:
    return {"size": path.stat().st_size, "sha256": _digest(path)}


def _same(path: Path, record: object) -> bool:
    """Whether the file at ``path`` is still the one ``record`` describes."""
    if not isinstance(record, dict):
        return False
    try:
        if path.is_symlink() or not path.is_file() or path.stat().st_size != record.get("size"):
            return False
        return _digest(path) == record.get("sha256")
    except OSError:
        return False


def _load_json(path: Path) -> object:
    """The JSON document at ``path``, or None when it is missing, a link, or unreadable
    (a crafted document nested too deeply for the parser included)."""
    if path.is_symlink() or not path.is_file():
        return None
    try:
        if path.stat().st_size > 64 << 20:
            return None
        return json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError, RecursionError):  # a crafted, deeply nested marker too
        return None


class _Listing:
    """What a folder's marker records: every file esp wrote (relative path -> size and
    SHA-256) and every folder it made; ``legacy`` for a marker of esp 0.2 (names only)."""

    def __init__(self, files: dict[str, object], folders: set[str], legacy: bool = False):
        self.files = files
        self.folders = folders
        self.legacy = legacy


def _read_marker(folder: Path) -> _Listing | None:
    """The listing of the marker of ``folder``, or None when it has no valid marker."""
    doc = _load_json(folder / MARKER)
    if not isinstance(doc, dict):
        return None
    if doc.get("schema") == _LEGACY_MARKER_SCHEMA:
        names = doc.get("files")
        if not isinstance(names, list) or not all(isinstance(f, str) for f in names):
            return None
        return _Listing({n: None for n in names}, set(), legacy=True)
    if doc.get("schema") != MARKER_SCHEMA:
        return None
    files, folders = doc.get("files"), doc.get("folders", [])
    if not isinstance(files, dict) or not isinstance(folders, list):
        return None
    if not all(isinstance(f, str) for f in folders):
        return None
    return _Listing(dict(files), set(folders))


def _survey(folder: Path, listing: _Listing) -> tuple[list[str], list[str]]:
    """What in ``folder`` esp did not write (entries its marker does not record, links) and
    what changed since esp wrote it (a recorded file of another size or hash), at any
    depth, as paths relative to ``folder``, sorted. A recorded file that is gone is
    neither: nothing of anyone's is lost by replacing the folder."""
    foreign: list[str] = []
    changed: list[str] = []

    def walk(path: Path, prefix: str) -> None:
        for entry in sorted(os.listdir(path)):
            rel = prefix + entry
            full = path / entry
            if rel == MARKER:
                continue
            if full.is_symlink():
                foreign.append(rel)
            elif full.is_dir():
                if listing.legacy and not prefix and entry in listing.files:
                    inner = _read_marker(full)  # an esp 0.2 report folder of a batch
                    if inner is None:
                        foreign.append(rel + "/")
                        continue
                    f, c = _survey(full, inner)
                    foreign.extend(rel + "/" + x for x in f)
                    changed.extend(rel + "/" + x for x in c)
                elif rel in listing.folders:
                    walk(full, rel + "/")
                else:
                    foreign.append(rel + "/")
            elif rel not in listing.files:
                foreign.append(rel)
            elif listing.legacy:
                changed.append(rel)  # esp 0.2 recorded no hash: it cannot be told apart
            elif not _same(full, listing.files[rel]):
                changed.append(rel)

    walk(folder, "")
    return foreign, changed


def _listing_of(folder: Path) -> dict[str, object]:
    """The marker document of ``folder`` as it stands: every file and folder in it."""
    files: dict[str, object] = {}
    folders: list[str] = []
    for root, dirs, names in os.walk(folder):
        dirs.sort()
        rel_root = os.path.relpath(root, folder)
        prefix = "" if rel_root == "." else rel_root.replace(os.sep, "/") + "/"
        folders.extend(prefix + d for d in dirs)
        for name in sorted(names):
            if prefix or name != MARKER:
                files[prefix + name] = _record(Path(root, name))
    return {
        "schema": MARKER_SCHEMA,
        "written_by": f"esp {__version__}",
        "files": dict(sorted(files.items())),
        "folders": sorted(folders),
    }


def _write_marker(folder: Path, staging: bool = False) -> None:
    if staging:
        doc: dict[str, object] = {
            "schema": MARKER_SCHEMA,
            "written_by": f"esp {__version__}",
            "files": {},
            "folders": [],
            "staging": True,
            "owner": {"pid": os.getpid(), "start": _start_time(os.getpid()), "host": _host()},
        }
    else:
        doc = _listing_of(folder)
    (folder / MARKER).write_text(json.dumps(doc, indent=2) + "\n", encoding="utf-8")


def is_esp_folder(folder: str | os.PathLike[str]) -> bool:
    """True when ``folder`` carries esp's marker and holds nothing esp did not write and
    nothing changed since esp wrote it."""
    path = Path(folder)
    listing = _read_marker(path)
    if listing is None:
        return False
    foreign, changed = _survey(path, listing)
    return not foreign and not changed


def _read_registry(folder: Path) -> dict[str, object]:
    doc = _load_json(folder / REGISTRY)
    if not isinstance(doc, dict) or doc.get("schema") != REGISTRY_SCHEMA:
        return {}
    files = doc.get("files")
    return dict(files) if isinstance(files, dict) else {}


def _registry_text(folder: Path, written: dict[str, dict[str, object]]) -> str:
    """The registry of ``folder`` after the files ``written`` (name -> record) are in
    place: the earlier records of files still there and unchanged, and the new ones."""
    files = {
        name: rec
        for name, rec in _read_registry(folder).items()
        if name not in written and _same(folder / name, rec)
    }
    files.update(written)
    doc = {
        "schema": REGISTRY_SCHEMA,
        "written_by": f"esp {__version__}",
        "note": "the files esp wrote in this folder; esp replaces only these, and only "
        "while they are as it wrote them",
        "files": dict(sorted(files.items())),
    }
    return json.dumps(doc, indent=2) + "\n"


# -- owners of staging folders, and locks ----------------------------------------------------


def _proc_stat(pid: int) -> list[str] | None:
    """The fields of ``/proc/PID/stat`` after the command name (Linux), or None."""
    try:
        with open(f"/proc/{pid}/stat", encoding="ascii", errors="replace") as fh:
            stat = fh.read()
        return stat[stat.rindex(")") + 2 :].split()
    except (OSError, ValueError):
        return None


def _start_time(pid: int) -> int:
    """The start time of process ``pid`` in clock ticks since boot (Linux), else 0."""
    fields = _proc_stat(pid)
    try:
        return int(fields[19]) if fields is not None else 0
    except (ValueError, IndexError):
        return 0


def _host() -> str:
    try:
        return socket.gethostname()
    except OSError:  # pragma: no cover
        return ""


def _owner_prefix(target: Path, kind: str) -> str:
    pid = os.getpid()
    return f".{target.name}{kind}{pid}.{_start_time(pid)}."


def _alive(pid: int, start: int) -> bool:
    """Whether the process ``pid`` that started at ``start`` still runs."""
    if pid <= 0:
        return False
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        pass  # another user's process: it exists
    except OSError:  # pragma: no cover
        return True
    fields = _proc_stat(pid)
    if fields is not None and fields[:1] == ["Z"]:
        return False  # killed, not yet reaped
    return not (start and _start_time(pid) not in (0, start))  # a later process, same pid


def _owner_gone(entry: Path, rest: str) -> bool:
    """Whether the run that made the staging or set-aside folder ``entry`` (its name's
    tail after the prefix is ``rest``) is gone. A folder made by esp 0.2 has no owner in
    its name and counts as gone (that esp cleaned up the same way)."""
    match = _OWNER.match(rest)
    if match is None:
        return True
    doc = _load_json(entry / MARKER)
    if isinstance(doc, dict):
        owner = doc.get("owner")
        if isinstance(owner, dict) and owner.get("host") not in (None, _host()):
            return False  # a run on another machine sharing the folder: cannot tell
    return not _alive(int(match.group(1)), int(match.group(2)))


_HELD: dict[str, list[int]] = {}  # folder -> [fd, depth] of the locks this process holds


@contextlib.contextmanager
def _locked(folders: Iterable[Path]) -> Iterator[None]:
    """Hold an exclusive lock on each folder (``flock`` on the folder itself: nothing is
    created), in a fixed order so that two runs cannot wait on each other; a lock this
    process holds already is taken again without waiting. Where locks are not available
    (no ``fcntl``, a file system that refuses them) the work goes on unlocked."""
    try:
        import fcntl
    except ImportError:  # pragma: no cover - not on POSIX
        yield
        return
    taken: list[str] = []
    try:
        for folder in sorted({os.path.realpath(f) for f in folders}):
            if folder in _HELD:
                _HELD[folder][1] += 1
                taken.append(folder)
                continue
            try:
                fd = os.open(folder, os.O_RDONLY)
            except OSError:
                continue
            try:
                fcntl.flock(fd, fcntl.LOCK_EX)
            except OSError:
                os.close(fd)
                continue
            _HELD[folder] = [fd, 1]
            taken.append(folder)
        yield
    finally:
        for folder in reversed(taken):
            held = _HELD[folder]
            held[1] -= 1
            if held[1] == 0:
                del _HELD[folder]
                with contextlib.suppress(OSError):
                    fcntl.flock(held[0], fcntl.LOCK_UN)
                os.close(held[0])


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
    whose owner is gone and that carry esp's marker, or that the run was killed in before
    its marker was complete (:func:`_unfinished`). A folder of a run still alive is kept."""
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
                and _owner_gone(entry, entry.name[len(prefix) :])
            ):
                shutil.rmtree(entry, ignore_errors=True)


def remove_stale(target: str | os.PathLike[str]) -> None:
    """Remove the staging and set-aside folders that a killed run left beside the folder
    target ``target`` (each carries esp's marker and names a run that is gone; nothing
    else is touched)."""
    target = Path(os.path.abspath(target))
    with _locked([target.parent] if target.parent.is_dir() else []):
        _remove_stale(target)


# -- the outputs of one run ------------------------------------------------------------------


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


def _remove(path: Path) -> None:
    if path.is_dir() and not path.is_symlink():
        shutil.rmtree(path, ignore_errors=True)
    else:
        with contextlib.suppress(FileNotFoundError):
            path.unlink()


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

    def _check_parent_chain(self, path: Path, option: str, given: str | os.PathLike[str]) -> None:
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

    def _check_not_input(self, real: Path, option: str, given: str | os.PathLike[str]) -> None:
        for inp in self.inputs:
            same = real == inp
            if not same and real.exists() and inp.exists():
                with contextlib.suppress(OSError):
                    same = os.path.samefile(real, inp)
            if same:
                self._fail(option, given, "is one of this command's inputs; it is not written over")

    def file(self, path: str | os.PathLike[str], option: str) -> Path:
        """Check a file target and return its path (its folder resolved)."""
        given = Path(path)
        if not os.fspath(path):
            self._fail(option, "''", "expected a file name")
        real = _real(given)
        self._check_not_input(real, option, path)
        if given.is_symlink():
            what = "a broken link" if not given.exists() else "a symbolic link"
            self._fail(option, path, f"is {what}; choose another name")
        if real.name in (MARKER, REGISTRY):
            self._fail(option, path, "is a name esp keeps for its own records")
        if real.exists():
            if real.is_dir():
                self._fail(option, path, "is a folder; expected a file name")
            if not real.is_file():
                self._fail(option, path, "exists and is not a regular file")
            record = _read_registry(real.parent).get(real.name)
            if record is None:
                self._fail(
                    option,
                    path,
                    f"the file exists and esp did not write it (it is not in {REGISTRY}); "
                    "it is not replaced: remove it or choose another name",
                )
            if not _same(real, record):
                self._fail(
                    option,
                    path,
                    "the file changed since esp wrote it; it is not replaced: remove it or "
                    "choose another name",
                )
        self._check_parent_chain(real, option, path)
        if real in self._files:
            other = self._files[real][1]
            self._fail(option, path, f"is also the target of {other}")
        for folder, (_, other) in self._folders.items():
            if _inside(real, folder):
                self._fail(option, path, f"lies inside the folder of {other}")
        self._files[real] = (given, option)
        return real

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
            if os.path.ismount(real):
                self._fail(
                    option,
                    path,
                    "is a mount point; esp replaces its output folder as a whole, which a "
                    "mount point cannot be: choose a new folder inside it",
                )
            self._check_folder_content(real, option, path)
            if not os.access(real, os.W_OK | os.X_OK):
                self._fail(option, path, "cannot write in this folder (permission denied)")
        self._check_parent_chain(target, option, path)
        if real in self._folders:
            self._fail(option, path, f"is also the target of {self._folders[real][1]}")
        for f, (_, other) in self._files.items():
            if _inside(f, real):
                self._fail(option, path, f"holds the target of {other}")
        self._folders[real] = (given, option)
        return target

    def _check_folder_content(self, real: Path, option: str, path: str | os.PathLike[str]) -> None:
        if not os.listdir(real):
            return
        listing = _read_marker(real)
        if listing is None:
            self._fail(
                option,
                path,
                f"the folder exists and esp did not write it (no {MARKER}); "
                "it is not replaced: choose a new or empty folder",
            )
        problem = _problem(real, listing)
        if problem:
            self._fail(option, path, f"{problem}; it is not replaced: {_REMEDY}")

    # -- staging ----------------------------------------------------------------------------

    def _checked_file(self, path: str | os.PathLike[str]) -> Path:
        target = _real(path)
        if target not in self._files:
            raise ValueError(f"{target} was not checked as a file target")
        return target

    def _temporary(self, target: Path) -> Path:
        target.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(prefix=f".{target.name}.", suffix=".tmp", dir=target.parent)
        tmp_path = Path(tmp)
        self._staged_files.append((tmp_path, target))  # discarded on any error from here
        os.close(fd)
        tmp_path.chmod(0o666 & ~_umask())
        return tmp_path

    def write_file(self, path: str | os.PathLike[str], data: bytes | str) -> None:
        """Stage the content of a checked file target (moved into place by :meth:`commit`)."""
        target = self._checked_file(path)
        tmp = self._temporary(target)
        try:
            tmp.write_bytes(data.encode("utf-8") if isinstance(data, str) else data)
        except OSError as exc:  # a full disk names no file: name the target
            raise OSError(exc.errno, exc.strerror, exc.filename or str(target)) from exc

    def stage_file(self, path: str | os.PathLike[str]) -> Path:
        """A temporary path beside a checked file target, for a writer that takes a path
        (a figure's ``savefig``); the file written there is moved into place by
        :meth:`commit`, or removed by :meth:`discard`."""
        return self._temporary(self._checked_file(path))

    def stage_folder(self, path: str | os.PathLike[str]) -> Path:
        """An empty staging folder for a checked folder target; fill it, then commit."""
        target = Path(os.path.abspath(path))
        if _real(target) not in self._folders:
            raise ValueError(f"{target} was not checked as a folder target")
        target.parent.mkdir(parents=True, exist_ok=True)
        with _locked([target.parent]):
            _remove_stale(target)
            staged = Path(tempfile.mkdtemp(prefix=_owner_prefix(target, _STAGE), dir=target.parent))
        self._staged_folders.append((staged, target))  # discarded on any error from here
        _write_marker(staged, staging=True)  # so that a killed run's folder is known as esp's
        return staged

    def commit(self) -> None:
        """Move every staged output into place, all or none.

        The targets are checked again first, since the work may have taken minutes: a
        folder that now holds anything esp did not write (a file the user put there, a
        folder made meanwhile), or a file that appeared or changed, stops the commit before
        anything is moved (:class:`~esp.core.errors.DataError`). Then every existing target is
        set aside, every staged output moved in, and what was set aside removed; if any
        step fails, every target is put back as it was. Everything staged is removed on
        failure."""
        parents = [t.parent for _, t in self._staged_folders + self._staged_files]
        try:
            with _locked(parents):
                for _, target in self._staged_folders:
                    _check_replaceable(target)
                for _, target in self._staged_files:
                    _check_file_replaceable(target)
                for staged, _ in self._staged_folders:
                    _write_marker(staged)
                    _open_permissions(staged)
                self._stage_registries()
                self._swap()
        except BaseException:
            self.discard()
            raise
        self._staged_files.clear()
        self._staged_folders.clear()

    def _stage_registries(self) -> None:
        """Stage the registry of each folder that receives a single file, recording it."""
        by_folder: dict[Path, dict[str, dict[str, object]]] = {}
        for tmp, target in self._staged_files:
            by_folder.setdefault(target.parent, {})[target.name] = _record(tmp)
        for folder, written in by_folder.items():
            registry = folder / REGISTRY
            if registry.is_symlink() or (registry.exists() and not registry.is_file()):
                raise DataError(f"{registry}: is not a regular file; nothing was written")
            fd, name = tempfile.mkstemp(prefix=f".{REGISTRY}.", suffix=".tmp", dir=folder)
            staged = Path(name)
            self._staged_files.append((staged, registry))
            with os.fdopen(fd, "w", encoding="utf-8") as fh:
                fh.write(_registry_text(folder, written))
            staged.chmod(0o666 & ~_umask())

    def _swap(self) -> None:
        """Set every existing target aside, move every staged output in, then remove what
        was set aside; on any failure undo every step done so far."""
        moves = [(s, t, True) for s, t in self._staged_folders]
        moves += [(s, t, False) for s, t in self._staged_files]
        aside: list[tuple[Path, Path]] = []  # (set-aside, target)
        placed: list[tuple[Path, Path]] = []  # (target, staged it came from)
        try:
            for _staged, target, is_folder in moves:
                if not os.path.lexists(target):
                    continue
                old = Path(tempfile.mkdtemp(prefix=_owner_prefix(target, _OLD), dir=target.parent))
                old.rmdir()
                os.replace(target, old)
                aside.append((old, target))
                if is_folder and _unwritten(old):  # written to in the instant since the check
                    raise DataError(
                        f"{target}: changed while esp replaced it; it was left as it is"
                    )
            for staged, target, _ in moves:
                os.replace(staged, target)
                placed.append((target, staged))
        except BaseException:
            for target, staged in reversed(placed):  # back to staging, removed by discard
                with contextlib.suppress(OSError):
                    os.replace(target, staged)
            for old, target in reversed(aside):
                with contextlib.suppress(OSError):
                    os.replace(old, target)
            raise
        for old, _ in aside:
            _remove(old)

    def discard(self) -> None:
        """Remove everything staged; the targets stay as they were."""
        for tmp, _ in self._staged_files:
            _remove(tmp)
        for staged, _ in self._staged_folders:
            shutil.rmtree(staged, ignore_errors=True)
        self._staged_files.clear()
        self._staged_folders.clear()

    def __enter__(self) -> Outputs:
        return self

    def __exit__(
        self,
        exc_type: type[BaseException] | None,
        exc: BaseException | None,
        tb: TracebackType | None,
    ) -> None:
        if exc_type is None:
            self.commit()
        else:
            self.discard()


_REMEDY = "move them or choose another folder"


def _problem(folder: Path, listing: _Listing) -> str:
    """Why the esp folder ``folder`` may not be replaced, or '' when it may."""
    foreign, changed = _survey(folder, listing)
    parts = []
    if foreign:
        parts.append(f"holds files esp did not write ({_shown(foreign)})")
    if changed:
        if listing.legacy:
            parts.append(
                f"was written by esp 0.2, which recorded no sizes or hashes, so the files "
                f"({_shown(changed)}) cannot be told from files edited since"
            )
        else:
            parts.append(f"holds files changed since esp wrote them ({_shown(changed)})")
    return "; ".join(parts)


def _unwritten(folder: Path) -> list[str]:
    """What in an existing folder esp did not write or changed since (everything, without
    its marker)."""
    entries = sorted(os.listdir(folder))
    if not entries:
        return []
    listing = _read_marker(folder)
    if listing is None:
        return entries
    foreign, changed = _survey(folder, listing)
    return foreign + changed


def _check_replaceable(target: Path) -> None:
    """Refuse to replace ``target`` if it now holds anything esp did not write."""
    if target.is_symlink() or (target.exists() and not target.is_dir()):
        raise DataError(f"{target}: became a file or link during the run; nothing was written")
    if target.is_dir():
        foreign = _unwritten(target)
        if foreign:
            raise DataError(
                f"{target}: files esp did not write appeared in it during the run "
                f"({_shown(foreign)}); nothing was written"
            )


def _check_file_replaceable(target: Path) -> None:
    """Refuse to replace ``target`` if it appeared or changed during the run."""
    if target.name == REGISTRY or not os.path.lexists(target):
        return
    if target.is_symlink() or not target.is_file():
        raise DataError(f"{target}: became a folder or link during the run; nothing was written")
    if not _same(target, _read_registry(target.parent).get(target.name)):
        raise DataError(
            f"{target}: the file was made or changed during the run, not by esp; "
            "nothing was written: remove it or choose another name"
        )
