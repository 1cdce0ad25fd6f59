"""Many machines in one run: find their configurations, analyse each, write one report
folder per machine and a summary table with a pass/fail verdict against thresholds.

This is the library side of ``esp batch`` (``docs/reports.md``, "Many machines"). It sits
beside :mod:`esp.report` in the presentation layer: it calls the numeric core
(:func:`esp.config.load_machine`, :func:`esp.core.analysis.analyse`) and the report writer
(:func:`esp.volumetric.report.write_report`) and knows nothing about the terminal.

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

Report folders
    Each machine's report goes to ``OUT/<folder>``, where ``<folder>`` is the file's path
    relative to the deepest folder common to all the files found, without ``.toml``, its
    parts joined by ``__`` (``gantry/machine-tcp.toml`` -> ``gantry__machine-tcp``);
    characters other than ASCII letters, digits, ``.``, ``_`` and ``-`` become ``_`` and a
    name already taken (compared without regard to case) gets ``-2``, ``-3``, ... in the
    order of the rows.

Output folder
    The output folder follows :mod:`esp.io.outputs`: it is checked before any work (it
    must be new, empty, or a folder esp wrote holding only its report folders and summary
    files, each report folder holding only what esp wrote there; no machine configuration
    may lie inside it), everything is written into a staging folder beside it, and the
    staging folder replaces it once the summary is written. An interrupted batch leaves the
    earlier output folder as it was.

Failures
    A machine that cannot be analysed gets an error row and the others go on; so does a
    folder that cannot be searched. With several processes (``jobs`` > 1), a worker that
    the operating system kills (out of memory, say) takes the machines it was working on
    with it: they are analysed again, each in a fresh process of its own, and only a
    machine whose own process is killed again gets an error row.

Verdict
    A machine fails when its volumetric accuracy (the worst tool case's, Longstaff 2002,
    3.05, eq. 3.5) exceeds ``max_volumetric_um``, or any planar accuracy it reports
    (3.05.4-3.05.5; for several tool cases the largest of each plane) exceeds
    ``max_planar_um``, or its expanded volumetric uncertainty (when it has an
    ``[uncertainty]`` table) exceeds ``max_uncertainty_um``. A value equal to its threshold
    passes.

    An uncertainty plan (an ``[uncertainty]`` table and no error data) has no volumetric
    accuracy: its row leaves the accuracy columns empty, shows the uncertainty, and the
    accuracy thresholds do not apply to it. Its verdict is ``"plan"`` (it neither passes
    nor fails, and counts as no failure in the exit code), unless ``max_uncertainty_um`` is
    given: then it passes or fails on its uncertainty like any machine.
"""

from __future__ import annotations

import csv
import gc
import io
import math
import os
import re
import stat
import tomllib
import unicodedata
from collections.abc import Callable, Iterable, Mapping, Sequence
from concurrent.futures import FIRST_COMPLETED, Future, ProcessPoolExecutor, as_completed, wait
from concurrent.futures.process import BrokenProcessPool
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

from esp.core.errors import DataError, EspError
from esp.core.machine import AXIS_NAMES
from esp.io.atomic import write_text
from esp.io.outputs import Outputs, remove_stale
from esp.io.tomlfile import TOML_MAX_BYTES
from esp.report.words import one_line

if TYPE_CHECKING:
    from esp.core.results import AnalysisResult
from esp.report.workers import die_with_parent, start_pool, stop_pool, terminate_on_sigterm

__all__ = [
    "PLANES",
    "SUMMARY_COLUMNS",
    "SUMMARY_CSV",
    "SUMMARY_MD",
    "SUMMARY_PDF",
    "BatchItem",
    "BatchRow",
    "Thresholds",
    "analyse_item",
    "check_thresholds",
    "counts_text",
    "MAX_JOBS",
    "exit_code",
    "find_machines",
    "IDENTIFY_SKIPPED",
    "is_identify_config",
    "is_machine_config",
    "plan",
    "row_from_result",
    "run_batch",
    "summary_csv",
    "summary_markdown",
    "write_summary",
    "write_summary_pdf",
]

#: the planes of the planar accuracy, in the order of the summary columns
PLANES = ("XY", "XZ", "YZ")
SUMMARY_CSV = "summary.csv"
SUMMARY_MD = "summary.md"
SUMMARY_PDF = "summary.pdf"

#: the columns of ``summary.csv``, in order (documented in ``docs/reports.md``)
SUMMARY_COLUMNS = (
    "file",
    "name",
    "configuration",
    "volumetric_um",
    "volumetric_X_mm",
    "volumetric_Y_mm",
    "volumetric_Z_mm",
    "planar_XY_um",
    "planar_XZ_um",
    "planar_YZ_um",
    "uncertainty_um",
    "verdict",
    "error",
    "report",
)

#: the most worker processes a batch starts
MAX_JOBS = 256
_MAX_FOLDER_CHARS = 100
_UNSAFE = re.compile(r"[^A-Za-z0-9._-]+")


# -- discovery --------------------------------------------------------------------------


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


# -- naming -----------------------------------------------------------------------------


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


# -- one machine ------------------------------------------------------------------------


@dataclass(frozen=True)
class Thresholds:
    """Limits of the verdict in µm; None: not checked."""

    max_volumetric_um: float | None = None
    max_planar_um: float | None = None
    max_uncertainty_um: float | None = None

    def __post_init__(self) -> None:
        for key in ("max_volumetric_um", "max_planar_um", "max_uncertainty_um"):
            value = getattr(self, key)
            if value is not None and not (math.isfinite(value) and value > 0):
                raise DataError(f"{key}: expected a positive number of µm, found {value!r}")


@dataclass(frozen=True)
class BatchRow:
    """One row of the summary: a machine's figures and verdict, or why it failed.

    Lengths in µm, positions in mm. ``planar_um`` holds only the planes the analysis
    reports (one for a two-axis machine); ``failures`` the threshold checks that failed;
    ``error`` the one-line message when the machine could not be analysed (the other
    fields are then empty). ``plan``: an uncertainty plan (no error data), whose
    ``volumetric_um`` is None (no accuracy) and ``uncertainty_um`` the headline;
    ``checked``: whether any threshold applied to the row (a plan with none is ``"plan"``).
    """

    file: str
    folder: str
    path: str = ""
    name: str = ""
    configuration: str = ""
    volumetric_um: float | None = None
    volumetric_at_mm: Mapping[str, float] = field(default_factory=dict)
    planar_um: Mapping[str, float] = field(default_factory=dict)
    uncertainty_um: float | None = None
    failures: tuple[str, ...] = ()
    error: str | None = None
    plan: bool = False
    checked: bool = True
    #: why the configuration was not analysed (:data:`IDENTIFY_SKIPPED`), or None
    skipped: str | None = None

    @property
    def status(self) -> str:
        """``"pass"``, ``"fail"``, ``"error"``, ``"plan"`` (an uncertainty plan that no
        threshold applies to) or ``"skipped"`` (not analysed: :attr:`skipped` says why)."""
        if self.error is not None:
            return "error"
        if self.skipped is not None:
            return "skipped"
        if self.failures:
            return "fail"
        return "plan" if self.plan and not self.checked else "pass"

    @property
    def verdict(self) -> str:
        """``"pass"``, ``"fail: volumetric 36.926 um > 30 um; ..."`` or ``"error"``."""
        if self.status == "fail":
            return "fail: " + "; ".join(self.failures)
        if self.skipped is not None:
            return self.skipped
        return self.status


def _um(value: float) -> str:
    return f"{value + 0.0:.3f}"


def _mm(value: float) -> str:
    return f"{value + 0.0:.10g}"


def check_thresholds(
    volumetric_um: float | None,
    planar_um: Mapping[str, float],
    thresholds: Thresholds,
    uncertainty_um: float | None = None,
) -> tuple[str, ...]:
    """The failed checks as texts such as ``"volumetric 36.926 um > 30 um"``. A None
    volumetric accuracy (an uncertainty plan) or uncertainty is not checked."""
    failures = []
    limit = thresholds.max_volumetric_um
    if limit is not None and volumetric_um is not None and volumetric_um > limit:
        failures.append(f"volumetric {_um(volumetric_um)} um > {limit:g} um")
    limit = thresholds.max_planar_um
    if limit is not None:
        for plane in PLANES:
            value = planar_um.get(plane)
            if value is not None and value > limit:
                failures.append(f"planar {plane} {_um(value)} um > {limit:g} um")
    limit = thresholds.max_uncertainty_um
    if limit is not None and uncertainty_um is not None and uncertainty_um > limit:
        failures.append(f"uncertainty {_um(uncertainty_um)} um > {limit:g} um")
    return tuple(failures)


def row_from_result(item: BatchItem, result: AnalysisResult, thresholds: Thresholds) -> BatchRow:
    """The summary row of an :class:`~esp.core.results.AnalysisResult`.

    The volumetric accuracy and its position are the worst tool case's; each planar
    accuracy is the largest of that plane over the reported tool cases; the uncertainty is
    the expanded volumetric uncertainty when the machine has an ``[uncertainty]`` table.
    An uncertainty plan has no accuracy, position or planar accuracies (module docstring).
    """
    from esp.report.words import is_plan

    unc = result.uncertainty
    u_um = None if unc is None else unc.volumetric.value_um
    # what every row of an analysed machine says of it
    named: dict[str, Any] = {  # str values: Any lets them fill BatchRow's fields by name
        "file": item.file,
        "folder": item.folder,
        "path": item.path,
        "name": result.machine.name,
        "configuration": result.machine.configuration,
    }
    if is_plan(result):
        return BatchRow(
            **named,
            uncertainty_um=u_um,
            failures=check_thresholds(None, {}, thresholds, u_um),
            plan=True,
            checked=thresholds.max_uncertainty_um is not None,
        )
    worst = result.cases[result.worst].volumetric
    planar: dict[str, float] = {}
    for case in result.cases:
        for plane, extreme in case.planar.items():
            planar[plane] = max(planar.get(plane, -math.inf), extreme.value_um)
    return BatchRow(
        **named,
        volumetric_um=worst.value_um,
        volumetric_at_mm={a: float(worst.at[a]) for a in AXIS_NAMES},
        planar_um=planar,
        uncertainty_um=u_um,
        failures=check_thresholds(worst.value_um, planar, thresholds, u_um),
    )


def _message(exc: BaseException, item: BatchItem) -> str:
    """One line for an exception: the EspError's own message, an OSError like the command
    line reports it, anything else with its type."""
    if isinstance(exc, EspError):
        text = str(exc)
    elif isinstance(exc, OSError):
        what = exc.strerror or str(exc)
        text = f"{exc.filename}: {what}" if exc.filename else what
    else:
        text = f"{item.path}: unexpected {type(exc).__name__}: {exc}"
    return " ".join(text.split())


def analyse_item(
    item: BatchItem,
    out_dir: str | os.PathLike[str],
    thresholds: Thresholds = Thresholds(),
    date: str | None = None,
    final_dir: str | os.PathLike[str] | None = None,
) -> BatchRow:
    """Analyse one machine and write its report folder ``out_dir/item.folder``.

    ``final_dir``: the output folder the report will end up in when ``out_dir`` is its
    staging folder; a machine that reads a file inside it is refused (committing the batch
    would replace that file).

    Never raises for a problem of this machine (``Exception``): the row then carries the
    message in ``error`` and no report folder is written or changed.
    """
    from esp.config import load_machine
    from esp.core.analysis import analyse
    from esp.volumetric import report as bundle

    if item.error is not None:
        return BatchRow(item.file, item.folder, item.path, error=item.error)
    if is_identify_config(item.path):
        return BatchRow(item.file, item.folder, item.path, skipped=IDENTIFY_SKIPPED)
    try:
        folder = Path(out_dir) / item.folder
        bundle.check_out_dir(folder)  # before any work: never replace a folder not ours
        machine = load_machine(item.path)
        if final_dir is not None:
            final = os.path.realpath(final_dir)
            for name in machine.inputs:
                real = os.path.realpath(name)
                if os.path.commonpath([real, final]) == final:
                    raise DataError(
                        f"{name}: an input of {item.path} lies inside the output folder "
                        f"{final_dir}; move it or choose another --out"
                    )
        result = analyse(machine)
        bundle.write_report(result, folder, date=date)
        return row_from_result(item, result, thresholds)
    except Exception as exc:  # one machine must not stop the others
        return BatchRow(item.file, item.folder, item.path, error=_message(exc, item))
    finally:
        # a report's figures are cycles of objects that only the collector frees: freed
        # after each machine, a process that reports one machine after another stays at
        # the memory of one report
        gc.collect()


# -- many machines ----------------------------------------------------------------------


def _killed_twice(item: BatchItem) -> BatchRow:
    return BatchRow(
        item.file,
        item.folder,
        item.path,
        error=(
            f"{item.path}: the process analysing it was killed twice (as the system does "
            "when memory runs out); check its grid steps and tool cases"
        ),
    )


def _run_pooled(
    items: Sequence[BatchItem],
    indices: Sequence[int],
    args: tuple,
    workers: int,
    finished: Callable[[int, BatchRow], None],
) -> list[int]:
    """Analyse ``items[i]`` for every ``i`` of ``indices`` in one pool of ``workers``
    processes; return the indices lost because a worker died."""
    lost: list[int] = []
    pool = start_pool(workers, die_with_parent, (os.getpid(),))
    try:
        futures: dict[Future, int] = {}
        for n, i in enumerate(indices):
            try:
                futures[pool.submit(analyse_item, items[i], *args)] = i
            except BrokenProcessPool:  # a worker died before every machine was queued
                lost.extend(indices[n:])
                break
        for future in as_completed(futures):
            index = futures[future]
            try:
                row = future.result()
            except BrokenProcessPool:
                lost.append(index)
                continue
            except Exception as exc:  # pickling and other failures of the pool itself
                item = items[index]
                row = BatchRow(item.file, item.folder, item.path, error=_message(exc, item))
            finished(index, row)
    except BaseException:
        stop_pool(pool)
        raise
    pool.shutdown(wait=True)
    return sorted(lost)


def _run_alone(
    items: Sequence[BatchItem],
    indices: Sequence[int],
    args: tuple,
    workers: int,
    finished: Callable[[int, BatchRow], None],
) -> None:
    """Analyse each ``items[i]`` in a fresh process of its own, ``workers`` at once: a
    process that dies takes only its own machine, which then gets an error row."""
    queue = list(indices)
    running: dict[Future, tuple[int, ProcessPoolExecutor]] = {}
    try:
        while queue or running:
            while queue and len(running) < workers:
                index = queue.pop(0)
                pool = start_pool(1, die_with_parent, (os.getpid(),))
                running[pool.submit(analyse_item, items[index], *args)] = (index, pool)
            done, _ = wait(running, return_when=FIRST_COMPLETED)
            for future in sorted(done, key=lambda f: running[f][0]):
                index, pool = running.pop(future)
                item = items[index]
                try:
                    row = future.result()
                except BrokenProcessPool:
                    row = _killed_twice(item)
                    if item.folder:  # what the killed process left of its report
                        remove_stale(Path(args[0]) / item.folder)
                except Exception as exc:
                    row = BatchRow(item.file, item.folder, item.path, error=_message(exc, item))
                pool.shutdown(wait=True)
                finished(index, row)
    finally:
        for _index, pool in running.values():
            stop_pool(pool)


def _analyse_all(
    items: Sequence[BatchItem],
    staged: Path,
    final: Path | None,
    thresholds: Thresholds,
    date: str,
    jobs: int,
    finished: Callable[[int, BatchRow], None],
) -> None:
    args = (staged, thresholds, date, final)
    workers = min(jobs, len(items))
    if workers <= 1:
        for index, item in enumerate(items):
            finished(index, analyse_item(item, *args))
        return
    lost = _run_pooled(items, range(len(items)), args, workers, finished)
    if lost:
        _run_alone(items, lost, args, workers, finished)


def run_batch(
    items: Sequence[BatchItem],
    out_dir: str | os.PathLike[str],
    thresholds: Thresholds = Thresholds(),
    *,
    jobs: int = 1,
    on_done: Callable[[BatchRow], None] | None = None,
    inputs: Iterable[str | os.PathLike[str]] = (),
) -> list[BatchRow]:
    """Analyse every item, write its report folder and the summary files into
    ``out_dir``; return the rows in item order.

    The output folder is checked before any work and written all at once at the end (see
    the module docstring, "Output folder").

    Parameters
    ----------
    items : from :func:`plan`
    out_dir : the output folder (created when missing)
    thresholds : the verdict's limits
    jobs : processes to use, 1 to :data:`MAX_JOBS`; 1 analyses in this process, more
        uses a :class:`concurrent.futures.ProcessPoolExecutor` with up to ``jobs`` workers
        (and reruns the machines of a worker that is killed, see "Failures")
    on_done : called with each row as its machine finishes (in finishing order)
    inputs : further files the output folder must not hold (every item's configuration
        is one already)

    Raises
    ------
    DataError
        ``jobs`` is out of range, or ``out_dir`` may not be written (a file, a folder esp
        did not write, a folder holding files esp did not write or an input, the
        current folder).
    """
    from esp.report.epoch import report_date

    if not 1 <= jobs <= MAX_JOBS:
        raise DataError(f"jobs: expected 1 to {MAX_JOBS} processes, found {jobs}")
    outputs = Outputs([*inputs, *(i.path for i in items if i.error is None)])
    out = outputs.folder(out_dir, "--out")
    date = report_date()  # one date for every report of the run
    rows: dict[int, BatchRow] = {}

    def finished(index: int, row: BatchRow) -> None:
        rows[index] = row
        if on_done is not None:
            on_done(row)

    with terminate_on_sigterm(), outputs:
        staged = outputs.stage_folder(out)
        _analyse_all(items, staged, out, thresholds, date, jobs, finished)
        ordered = [rows[i] for i in range(len(items))]
        write_summary(ordered, staged, thresholds)
        write_summary_pdf(ordered, staged / SUMMARY_PDF, thresholds, date)
    return ordered


def exit_code(rows: Iterable[BatchRow]) -> int:
    """0 when every machine passes, 1 when a threshold fails, 2 when any machine could not
    be analysed (2 wins over 1)."""
    statuses = {r.status for r in rows}
    if "error" in statuses:
        return 2
    return 1 if "fail" in statuses else 0


# -- summary files ----------------------------------------------------------------------


def _csv_record(row: BatchRow) -> dict[str, str]:
    at = row.volumetric_at_mm
    record = {
        "file": row.file,
        "name": row.name,
        "configuration": row.configuration,
        "volumetric_um": "" if row.volumetric_um is None else _um(row.volumetric_um),
        "uncertainty_um": "" if row.uncertainty_um is None else _um(row.uncertainty_um),
        "verdict": row.verdict,
        "error": row.error or "",
        "report": "" if row.error is not None or row.skipped is not None else row.folder,
    }
    for a in AXIS_NAMES:
        record[f"volumetric_{a}_mm"] = _mm(at[a]) if a in at else ""
    for plane in PLANES:
        value = row.planar_um.get(plane)
        record[f"planar_{plane}_um"] = "" if value is None else _um(value)
    return record


def summary_csv(rows: Iterable[BatchRow]) -> str:
    """``summary.csv``: a header of :data:`SUMMARY_COLUMNS`, then one line per row."""
    buffer = io.StringIO()
    writer = csv.DictWriter(buffer, fieldnames=SUMMARY_COLUMNS, lineterminator="\n")
    writer.writeheader()
    for row in rows:
        writer.writerow(_csv_record(row))
    return buffer.getvalue()


def _cell(text: str) -> str:
    """A table cell: backslashes and pipes escaped and line breaks and other control
    characters shown escaped (:func:`esp.report.words.one_line`), so that neither a
    message nor a machine or file name can break the row."""
    return one_line(text.replace("\\", "\\\\").replace("|", "\\|"))


def _limits(thresholds: Thresholds) -> str:
    parts = []
    if thresholds.max_volumetric_um is not None:
        parts.append(f"volumetric accuracy ≤ {thresholds.max_volumetric_um:g} µm")
    if thresholds.max_planar_um is not None:
        parts.append(f"every planar accuracy ≤ {thresholds.max_planar_um:g} µm")
    if thresholds.max_uncertainty_um is not None:
        parts.append(f"volumetric uncertainty ≤ {thresholds.max_uncertainty_um:g} µm")
    return "; ".join(parts) if parts else "none (every machine analysed passes)"


def counts_text(rows: Sequence[BatchRow]) -> str:
    """``"3 machines: 1 pass, 1 fail, 1 error"``, and ``", 1 plan"`` when there are
    uncertainty plans without a verdict, ``", 1 skipped"`` when configurations were not
    analysed (identify configurations)."""
    statuses = [r.status for r in rows]
    noun = "machine" if len(statuses) == 1 else "machines"
    plans = statuses.count("plan")
    skipped = statuses.count("skipped")
    return (
        f"{len(statuses)} {noun}: {statuses.count('pass')} pass, "
        f"{statuses.count('fail')} fail, {statuses.count('error')} error"
        + (f", {plans} plan" if plans else "")
        + (f", {skipped} skipped" if skipped else "")
    )


def summary_markdown(rows: Sequence[BatchRow], thresholds: Thresholds = Thresholds()) -> str:
    """``summary.md``: the same rows as a Markdown table, linked to each report."""
    lines = [
        "# Volumetric accuracy summary",
        "",
        f"Thresholds: {_limits(thresholds)}.",
        "",
        counts_text(rows) + ".",
        "",
        "| file | machine | configuration | volumetric (µm) | at X, Y, Z (mm) | "
        "planar XY (µm) | planar XZ (µm) | planar YZ (µm) | uncertainty (µm) | verdict | report |",
        "| --- | --- | --- | ---: | --- | ---: | ---: | ---: | ---: | --- | --- |",
    ]
    for row in rows:
        rec = _csv_record(row)
        at = ", ".join(rec[f"volumetric_{a}_mm"] for a in AXIS_NAMES) if rec["report"] else ""
        verdict = f"error: {row.error}" if row.error is not None else row.verdict
        report = f"[{row.folder}]({row.folder}/report.pdf)" if rec["report"] else ""
        cells = [
            row.file,
            row.name,
            row.configuration,
            rec["volumetric_um"],
            at,
            rec["planar_XY_um"],
            rec["planar_XZ_um"],
            rec["planar_YZ_um"],
            rec["uncertainty_um"],
            verdict,
            report,
        ]
        lines.append("| " + " | ".join(_cell(c) for c in cells) + " |")
    return "\n".join(lines) + "\n"


def write_summary(
    rows: Sequence[BatchRow],
    out_dir: str | os.PathLike[str],
    thresholds: Thresholds = Thresholds(),
) -> tuple[Path, Path]:
    """Write ``summary.csv`` and ``summary.md`` into ``out_dir`` (each atomically) and
    return their paths."""
    csv_path = Path(out_dir) / SUMMARY_CSV
    md_path = Path(out_dir) / SUMMARY_MD
    write_text(csv_path, summary_csv(rows))
    write_text(md_path, summary_markdown(rows, thresholds))
    return csv_path, md_path


def write_summary_pdf(
    rows: Sequence[BatchRow],
    path: str | os.PathLike[str],
    thresholds: Thresholds = Thresholds(),
    date: str | None = None,
) -> int:
    """``summary.pdf``: the fleet summary document in the style of every esp report
    (:mod:`esp.report.document`): how many pass, fail, are plans or could not be
    analysed, the thresholds, then one row per machine (its file and name wrapped, its
    accuracies, uncertainty and verdict, the folder of its report). Returns the number of
    pages."""
    from esp.report.document import Document, Headline, summary
    from esp.report.epoch import report_date
    from esp.report.tables import Column, Table

    doc = Document("Fleet summary", f"{len(rows)} machine configuration(s)", date or report_date())
    statuses = [r.status for r in rows]
    lines = [Headline(word, str(statuses.count(word))) for word in ("pass", "fail", "error")]
    for word in ("plan", "skipped"):
        if word in statuses:
            lines.append(Headline(word, str(statuses.count(word))))
    accuracies = [r for r in rows if r.volumetric_um is not None]
    if accuracies:
        worst = max(accuracies, key=lambda r: r.volumetric_um or 0.0)
        lines.append(
            Headline(
                f"Largest volumetric accuracy ({worst.name})",
                f"{_um(worst.volumetric_um or 0.0)} µm",
            )
        )
    summary(doc.lay, lines)
    doc.lay.paragraph(f"Thresholds: {_limits(thresholds)}.")
    doc.lay.paragraph(
        "Each machine's report is the report.pdf in its folder; the same rows are in "
        f"{SUMMARY_CSV} and {SUMMARY_MD}. Uncertainty: where a machine's [uncertainty] "
        "table gives one (its report states k and the method).",
        size=8.3,
        colour="0.3",
    )
    doc.section("Machines")
    body = []
    for row in rows:
        rec = _csv_record(row)
        planar = ", ".join(
            f"{plane} {rec[f'planar_{plane}_um']}" for plane in PLANES if rec[f"planar_{plane}_um"]
        )
        verdict = f"error: {row.error}" if row.error is not None else row.verdict
        body.append(
            (
                f"{row.file}" + (f" ({row.name})" if row.name else ""),
                rec["volumetric_um"],
                planar,
                rec["uncertainty_um"],
                verdict,
                rec["report"],
            )
        )
    doc.lay.table(
        Table(
            (
                Column("file (machine)", "left", 1.9),
                Column("volumetric (µm)", "right", 0.85),
                Column("   planar (µm)", "left", 1.35),
                Column("U (µm)", "right", 0.6),
                Column("   verdict", "left", 0.8),
                Column("report", "left", 1.27),
            ),
            tuple(body),
        ),
        keep_whole=True,  # the last table: no page holding its tail alone
    )
    return doc.write(path)
