"""Many machines in one run: find their configurations, analyse each, write one report
folder per machine and a summary table with a pass/fail verdict against thresholds.

This is the library side of ``esp batch`` (``docs/reports.md``, "Many machines"). It sits
beside :mod:`esp.report` in the presentation layer: it calls the numeric core
(:func:`esp.config.load_machine`, :func:`esp.core.analysis.analyse`) and the report writer
(:func:`esp.volumetric.report.write_report`) and knows nothing about the terminal.

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


The work is split by job: :mod:`esp.batch.discover` finds the configurations,
:mod:`esp.batch.naming` names their report folders, :mod:`esp.batch.rows` makes each
machine's row (its verdict from :mod:`esp.volumetric.conformance`, the decisions that
``esp analyse`` takes too), :mod:`esp.batch.summary` writes the summaries; this module
analyses the machines, in worker processes when asked, and re-exports the rest.
"""

from __future__ import annotations

import gc
import os
from collections.abc import Callable, Iterable, Sequence
from concurrent.futures import FIRST_COMPLETED, Future, ProcessPoolExecutor, as_completed, wait
from concurrent.futures.process import BrokenProcessPool
from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING

from esp.batch.discover import (
    IDENTIFY_SKIPPED,
    find_machines,
    is_identify_config,
    is_machine_config,
)
from esp.batch.naming import SUMMARY_CSV, SUMMARY_MD, SUMMARY_PDF, BatchItem, plan
from esp.batch.rows import (
    NO_THRESHOLDS,
    PLANES,
    BatchRow,
    Thresholds,
    row_from_result,
)
from esp.batch.summary import (
    SUMMARY_COLUMNS,
    counts_text,
    summary_csv,
    summary_markdown,
    write_summary,
    write_summary_pdf,
)
from esp.core.errors import DataError, EspError
from esp.io.outputs import Outputs, remove_stale
from esp.report.workers import die_with_parent, start_pool, stop_pool, terminate_on_sigterm

if TYPE_CHECKING:
    from esp.core.machine import Machine

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

#: the most worker processes a batch starts
MAX_JOBS = 256


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


def _with_thresholds(machine: Machine, thresholds: Thresholds) -> Machine:
    """``machine`` with the thresholds taking over its ``[tolerance]`` limits, so that its
    report decides what its summary row decides."""
    from esp.config.tolerance import Tolerances

    given = thresholds.tolerances()
    if given.empty and given.rule is None:
        return machine
    own = machine.tolerance
    base = own if isinstance(own, Tolerances) else Tolerances(source=machine.source)
    return replace(machine, tolerance=base.overridden_by(given))


def analyse_item(
    item: BatchItem,
    out_dir: str | os.PathLike[str],
    thresholds: Thresholds = NO_THRESHOLDS,
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
        machine = _with_thresholds(machine, thresholds)
        result = analyse(machine)
        row = row_from_result(item, result, thresholds)  # a refused rule: before the report
        bundle.write_report(result, folder, date=date)
        return row
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
    if lost:
        stop_pool(pool)  # a broken pool: its other workers are ended, not waited for
    else:
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
    thresholds: Thresholds = NO_THRESHOLDS,
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
    """0 when every machine passes (or is a plan), 1 when a figure does not conform, 3
    when none fails but one is not decided (within the guard band), 2 when any machine
    could not be analysed (2 wins, then 1, then 3)."""
    statuses = {r.status for r in rows}
    if "error" in statuses:
        return 2
    if "fail" in statuses:
        return 1
    return 3 if "not decided" in statuses else 0
