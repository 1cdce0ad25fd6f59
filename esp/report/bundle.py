"""The report folder of ``esp analyse --out DIR``: PDF, PNG figures, JSON and CSV.

The whole folder is built in a staging folder beside it and moved into place only when
every file is complete (:class:`esp.io.outputs.Outputs`); an existing report folder is
replaced only then, so a failure part-way leaves either the previous report or nothing.
A folder esp did not write, or one holding anything esp did not write there, is never
replaced.

Files (described in ``docs/reports.md``):

``report.pdf``, ``result.json`` (``esp.result/1``), ``extremes.csv``, ``terms.csv``,
``grid.csv`` (on request), and the figures: ``map-X.png``, ``map-Y.png``, ``map-Z.png``,
``map-volumetric.png``, ``terms.png``, ``sweep.png`` (tool sweeps),
``uncertainty-budget.png`` and ``uncertainty-montecarlo.png`` (when the result holds an
uncertainty), and ``input-X.png``, ``input-Y.png``, ``input-Z.png`` (the input components
of each axis that has one). A result without error data (an uncertainty plan) has no maps,
no terms chart and no sweep chart.

Each figure is built once, at its one size (A4 landscape), saved as PNG and placed as a
page of the PDF. When cores are free (:func:`report_jobs`) the PNG files and the CSV
files are made by worker processes while this process writes the PDF; the bytes of every
file are the same whatever the number of processes, and if the workers cannot be started
or die, this process makes what is missing itself.
"""

from __future__ import annotations

import contextlib
import gc
import multiprocessing
import os
import sys
import time
import warnings
from collections.abc import Callable, Iterable, Iterator, MutableMapping
from concurrent.futures import Future, ProcessPoolExecutor
from concurrent.futures.process import BrokenProcessPool
from dataclasses import dataclass
from pathlib import Path

from matplotlib.figure import Figure

from esp.core.results import AnalysisResult
from esp.io.atomic import write_text
from esp.io.outputs import Outputs
from esp.report import pdf
from esp.report.jsonout import dumps
from esp.report.words import is_plan
from esp.report.workers import die_with_parent
from esp.volumetric import export, plots
from esp.volumetric.jsondoc import result_dict

__all__ = [
    "MAX_JOBS",
    "FigureSpec",
    "check_out_dir",
    "figure_specs",
    "report_jobs",
    "write_report",
    "write_report_files",
]

#: the most processes a report uses
MAX_JOBS = 4


@dataclass(frozen=True)
class FigureSpec:
    """One figure of the report: its PNG file name, its title in the PDF's list of figures,
    and how to draw it."""

    filename: str
    title: str
    build: Callable[[], Figure]


def figure_specs(result: AnalysisResult) -> list[FigureSpec]:
    """Every figure of the report of ``result``, in the order of the PDF. A result without
    error data (no active component: an uncertainty plan) has no maps and no terms."""
    slicer = plots.PlaneSlicer(result.evaluation)

    # the figure of one direction or axis, drawn when called (a closure per loop value)
    def direction_maps(d: str) -> Callable[[], Figure]:
        return lambda: plots.direction_maps_figure(result, d, slicer)

    def axis_inputs(axis: str) -> Callable[[], Figure]:
        return lambda: plots.axis_inputs_figure(result, axis)

    specs = []
    if result.active:
        specs += [
            FigureSpec(
                f"map-{d}.png",
                f"{d}-direction error on the three faces through its largest value",
                direction_maps(d),
            )
            for d in ("X", "Y", "Z")
        ]
        specs.append(
            FigureSpec(
                "map-volumetric.png",
                "Volumetric error on the plane through the worst point",
                lambda: plots.volumetric_map_figure(result, slicer),
            )
        )
        specs.append(
            FigureSpec(
                "terms.png",
                "Term contributions at the worst point",
                lambda: plots.terms_figure(result),
            )
        )
    if result.sweep and not is_plan(result):
        specs.append(
            FigureSpec(
                "sweep.png",
                "Volumetric accuracy per tool orientation and length",
                lambda: plots.sweep_figure(result),
            )
        )
    unc = result.uncertainty
    if unc is not None:
        specs.append(
            FigureSpec(
                "uncertainty-budget.png", "Uncertainty budget", lambda: plots.budget_figure(result)
            )
        )
        if unc.montecarlo is not None:
            specs.append(
                FigureSpec(
                    "uncertainty-montecarlo.png",
                    "Monte Carlo distribution of the volumetric accuracy",
                    lambda: plots.montecarlo_figure(result),
                )
            )
    for axis in plots.input_axes(result):
        role = result.machine.axes[axis].role
        specs.append(
            FigureSpec(
                f"input-{axis}.png",
                f"Inputs of the {axis} axis ({role}) against position",
                axis_inputs(axis),
            )
        )
    return specs


def check_out_dir(out_dir: str | Path, inputs: Iterable[str | Path] = ()) -> Path:
    """The report folder as an absolute path, after checking it may be written (see
    :class:`esp.io.outputs.Outputs`): it does not exist, or it is empty, or esp wrote it
    and it holds nothing else; it is not the current folder, the root, or a folder that
    holds one of ``inputs``.

    Raises :class:`~esp.core.errors.DataError` otherwise, so that nothing the user keeps there
    is ever replaced.
    """
    return Outputs(inputs).folder(out_dir, "--out")


def report_jobs(tasks: int = MAX_JOBS) -> int:
    """The number of processes to make a report with: this one, plus one worker for
    each core that is free (the number of usable cores less the load average of the last
    minute, rounded), at most :data:`MAX_JOBS` and ``tasks``.

    1 -- everything in this process -- inside a worker process (``esp batch --jobs``
    already uses the cores) and where processes cannot be forked (only Linux forks them
    here: a forked worker starts at once and shares the analysis without copying it).
    """
    if multiprocessing.parent_process() is not None or not sys.platform.startswith("linux"):
        return 1
    try:
        cores = len(os.sched_getaffinity(0))
    except (AttributeError, OSError):
        cores = os.cpu_count() or 1
    try:
        load = os.getloadavg()[0]
    except (AttributeError, OSError):
        load = 0.0
    free = max(0, round(cores - load))
    return max(1, min(cores, 1 + free, MAX_JOBS, tasks))


@contextlib.contextmanager
def _timed(timings: MutableMapping[str, float] | None, key: str) -> Iterator[None]:
    start = time.perf_counter()
    try:
        yield
    finally:
        if timings is not None:
            timings[key] = timings.get(key, 0.0) + time.perf_counter() - start


def write_report(
    result: AnalysisResult,
    out_dir: str | Path,
    *,
    grid_csv: bool = False,
    date: str | None = None,
    timings: MutableMapping[str, float] | None = None,
    jobs: int | None = None,
) -> Path:
    """Write the report folder of ``result`` to ``out_dir`` and return its path.

    Parameters
    ----------
    result : the analysis
    out_dir : the folder to create; an existing one is replaced only if it is empty or an
        earlier esp report holding nothing else (see :func:`check_out_dir`), and only after
        everything is written
    grid_csv : also write ``grid.csv`` (refused above
        :data:`esp.volumetric.export.GRID_CSV_MAX_POINTS` points)
    date : the report date printed in the PDF (default :func:`esp.report.pdf.report_date`)
    timings : if given, receives the seconds spent per part: ``"png <name>"`` (drawing
        and saving one figure as PNG, in whichever process did it), ``"pdf <name>"``
        (building the figure when this process did not, and its PDF page), ``"pdf"``
        (the PDF less the PNGs made in this process), ``"json"``, ``"csv"`` (with
        ``grid.csv``)
    jobs : the number of processes (default :func:`report_jobs`); the files are the same
        byte for byte whatever it is
    """
    outputs = Outputs(result.machine.inputs)
    out = outputs.folder(out_dir, "--out")
    with outputs:
        staged = outputs.stage_folder(out)
        write_report_files(result, staged, grid_csv=grid_csv, date=date, timings=timings, jobs=jobs)
    return out


# -- the work of a report, in this process or in workers --------------------------------------
#
# The tasks are slot 0, the CSV files, and slot k + 1, the PNG of figure k. Whoever claims
# a slot first makes it: a worker (the tasks are queued CSV first, then the figures from the
# last), or this process (a figure as it draws its PDF page, from the first, when the
# workers would otherwise still be busy after the PDF -- see _take_here -- and after the
# PDF every slot still free). The claims live in an array the forked workers share.

_FREE, _WORKER, _HERE, _DONE = 0, 1, 2, 3

#: the cost of a figure's PNG made by a worker (building the figure, drawing and saving it)
#: and of a PDF page of a figure made here when a worker makes its PNG (building it again
#: and drawing the page), relative to each other, as measured on the shipped examples
#: (docs/performance.md); making a PNG here, beside its page, costs little more than the
#: drawing of the PNG, as the figure is built once
_PNG_COST, _PAGE_COST = 1.0, 0.55

#: the report a forked worker works on: (specs, folder, result, grid_csv, claims)
_JOB: tuple | None = None


def _claim(claims, slot: int, who: int) -> bool:
    """Claim ``slot`` for ``who``; False when it is claimed already."""
    with claims.get_lock():
        if claims[slot] != _FREE:
            return False
        claims[slot] = who
        return True


def _take_here(claims, slot: int, pages_left: int, workers: int) -> bool:
    """Claim figure ``slot`` for this process, which is about to draw its PDF page with
    ``pages_left`` figure pages after it, when it is still free and the figures still
    queued for the ``workers`` would keep them busy longer than those pages keep this
    process; otherwise leave it to them."""
    with claims.get_lock():
        if claims[slot] != _FREE:
            return False
        queued = sum(1 for s in range(1, len(claims)) if s != slot and claims[s] == _FREE)
        if queued * _PNG_COST / workers <= pages_left * _PAGE_COST:
            return False
        claims[slot] = _HERE
        return True


def _write_csv(result: AnalysisResult, staged: Path, grid_csv: bool) -> None:
    from esp.volumetric import frames  # pandas

    frames.write_extremes_csv(result, staged / "extremes.csv")
    frames.write_terms_csv(result, staged / "terms.csv")
    if grid_csv:
        frames.write_grid_csv(result, staged / "grid.csv")


def _make(slot: int, specs, staged: Path, result, grid_csv: bool, fig=None) -> None:
    if slot == 0:
        _write_csv(result, staged, grid_csv)
    else:
        spec = specs[slot - 1]
        plots.save_png(fig if fig is not None else spec.build(), staged / spec.filename)


def _worker_task(slot: int) -> float | None:
    """In a worker: make ``slot`` unless this process took it; returns the seconds."""
    assert _JOB is not None
    specs, staged, result, grid_csv, claims = _JOB
    if not _claim(claims, slot, _WORKER):
        return None
    start = time.perf_counter()
    _make(slot, specs, staged, result, grid_csv)
    with claims.get_lock():
        claims[slot] = _DONE
    return time.perf_counter() - start


def _start_pool(
    workers: int, job: tuple, slots: list[int]
) -> tuple[ProcessPoolExecutor | None, list[Future]]:
    """Fork ``workers`` processes that share ``job`` and queue ``slots``; (None, []) when
    processes cannot be started here."""
    global _JOB
    _JOB = job
    pool = None
    try:
        pool = ProcessPoolExecutor(
            workers,
            mp_context=multiprocessing.get_context("fork"),
            initializer=die_with_parent,
            initargs=(os.getpid(),),
        )
        with warnings.catch_warnings():
            # newer Pythons warn of forking beside threads; the workers only draw and write
            warnings.simplefilter("ignore", DeprecationWarning)
            return pool, [pool.submit(_worker_task, slot) for slot in slots]
    except (OSError, ValueError, RuntimeError, BrokenProcessPool):
        if pool is not None:
            pool.shutdown(wait=True)
        return None, []
    finally:
        _JOB = None  # the workers are forked at the first submit and hold their own copy


def write_report_files(
    result: AnalysisResult,
    staged: Path,
    *,
    grid_csv: bool = False,
    date: str | None = None,
    timings: MutableMapping[str, float] | None = None,
    jobs: int | None = None,
) -> None:
    """Write every file of the report of ``result`` into the folder ``staged`` (a staging
    folder of :class:`esp.io.outputs.Outputs`; see :func:`write_report`)."""
    staged = Path(staged)
    date = date or pdf.report_date()  # a malformed SOURCE_DATE_EPOCH is refused first
    with _few_collections():
        _write_files(result, staged, grid_csv, date, timings, jobs)


#: a report was written in this process since the last full collection (see
#: :func:`_few_collections`)
_REPORTED: list[bool] = []


@contextlib.contextmanager
def _few_collections() -> Iterator[None]:
    """Collect cyclic garbage less often while the figures are drawn: every object alive
    now (the modules, the analysis) is set aside from the collector's scans
    (:func:`gc.freeze`, also before the workers are forked) and the youngest generation is
    collected after 20 000 allocations instead of 700. Drawing allocates many short-lived
    objects in cycles; this halves the time spent collecting them (docs/performance.md).
    Both are undone on the way out; a caller that froze objects itself keeps them frozen
    (nothing is frozen or unfrozen here then).

    A report leaves some 80 000 objects in cycles (its figures) that the collector, with
    its oldest generation set aside, would not reach for several reports: a process that
    writes one report after another (``esp batch`` with one process) would grow by tens
    of MB per report. So a report that follows another in the same process first collects
    everything (:func:`gc.collect`, a few tenths of a second), before anything is frozen;
    the first report of a process, the only one of ``esp analyse``, pays nothing, and the
    garbage of the last is left for the process's end."""
    threshold = gc.get_threshold()
    freeze = gc.get_freeze_count() == 0
    if _REPORTED:
        gc.collect()
    _REPORTED[:] = [True]
    if freeze:
        gc.freeze()
    gc.set_threshold(max(threshold[0], 20_000), *threshold[1:])
    try:
        yield
    finally:
        gc.set_threshold(*threshold)
        if freeze:
            gc.unfreeze()


def _write_files(result, staged: Path, grid_csv: bool, date: str, timings, jobs) -> None:
    if grid_csv:
        export.check_grid_csv(result.machine)
    with _timed(timings, "json"):
        write_text(staged / "result.json", dumps(result_dict(result)))
    specs = figure_specs(result)
    jobs = report_jobs(len(specs) + 1) if jobs is None else max(1, int(jobs))
    pool: ProcessPoolExecutor | None = None
    futures: list[Future] = []
    claims = None
    if jobs > 1:
        claims = multiprocessing.get_context("fork").Array("b", len(specs) + 1)
        slots = [0, *range(len(specs), 0, -1)]  # the CSV files, then the last figure first
        pool, futures = _start_pool(jobs - 1, (specs, staged, result, grid_csv, claims), slots)
        if pool is None:
            claims = None

    def here(slot: int) -> bool:
        return claims is None or _take_here(claims, slot, len(specs) - slot, jobs - 1)

    try:
        if claims is None:
            with _timed(timings, "csv"):
                _write_csv(result, staged, grid_csv)

        def figures() -> Iterator[Figure]:
            for k, spec in enumerate(specs):
                start = time.perf_counter()
                fig = spec.build()
                if here(k + 1):  # not taken by a worker: made here, from this figure
                    _make(k + 1, specs, staged, result, grid_csv, fig)
                    if timings is not None:
                        timings[f"png {spec.filename}"] = time.perf_counter() - start
                    start = time.perf_counter()
                yield fig  # drawn on its PDF page before the generator resumes
                if timings is not None:
                    timings[f"pdf {spec.filename}"] = time.perf_counter() - start
                _raise_early(futures)

        start = time.perf_counter()
        pdf.write_pdf(staged / "report.pdf", result, figures(), [s.title for s in specs], date)
        if timings is not None:
            made = sum(timings.get(f"png {s.filename}", 0.0) for s in specs)
            timings["pdf"] = time.perf_counter() - start - made
        if claims is not None:
            _finish(futures, claims, specs, staged, result, grid_csv, timings)
    finally:
        if pool is not None:
            if claims is not None:
                with claims.get_lock():  # on an error: the workers skip what is left
                    for slot in range(len(claims)):
                        if claims[slot] == _FREE:
                            claims[slot] = _HERE
            pool.shutdown(wait=True)


def _raise_early(futures: list[Future]) -> None:
    """Raise the error of a worker's task as soon as it is known (a dead worker is not an
    error: its tasks are made here at the end)."""
    for future in futures:
        if future.done() and not future.cancelled():
            error = future.exception()
            if error is not None and not isinstance(error, BrokenProcessPool):
                raise error


def _finish(futures, claims, specs, staged, result, grid_csv, timings) -> None:
    """After the PDF: make here every slot no worker has taken, then wait for the workers.
    The error of a worker's task is raised here; what a dead worker left undone is made
    here."""
    key = ["csv", *(f"png {s.filename}" for s in specs)]
    for slot in range(len(claims)):
        if _claim(claims, slot, _HERE):
            start = time.perf_counter()
            _make(slot, specs, staged, result, grid_csv)
            if timings is not None:
                timings[key[slot]] = time.perf_counter() - start
    broken = False
    for slot, future in zip([0, *range(len(specs), 0, -1)], futures, strict=True):
        try:
            seconds = future.result()
        except BrokenProcessPool:
            broken = True
            continue
        if seconds is not None and timings is not None:
            timings[key[slot]] = seconds
    if broken:  # a worker died: make here what the workers had not finished
        for slot in range(len(claims)):
            if claims[slot] == _WORKER:
                start = time.perf_counter()
                _make(slot, specs, staged, result, grid_csv)
                claims[slot] = _DONE
                if timings is not None:
                    timings[key[slot]] = time.perf_counter() - start
