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
no terms chart and no sweep chart; a direction whose error is zero over the whole volume
has no map (:func:`skipped_figures` says which, for the text of the PDF).

The report is a list of figure specifications (:func:`figure_specs`). Each figure is
built once, at its one size (A4 landscape), saved as PNG and placed as a page of the PDF,
one after the other in this process. With ``jobs`` above 1 (where processes fork), a
plain pool of ``jobs - 1`` worker processes makes the PNG files while this process writes
the CSV files and the PDF (building each figure again for its page); the bytes of every
file are the same whatever the number of processes, and what a worker that died left
undone is made here.
"""

from __future__ import annotations

import contextlib
import multiprocessing
import os
import sys
import time
import warnings
from collections.abc import Callable, Iterable, Iterator, MutableMapping, Sequence
from concurrent.futures import Future, ProcessPoolExecutor
from concurrent.futures.process import BrokenProcessPool
from dataclasses import dataclass
from pathlib import Path

from matplotlib.figure import Figure

from esp.core.results import AnalysisResult
from esp.io.atomic import write_text
from esp.io.outputs import Outputs
from esp.report.jsonout import dumps
from esp.report.provenance import Provenance
from esp.report.words import is_plan
from esp.report.workers import die_with_parent, start_pool, stop_pool
from esp.volumetric import export, pdf, plots
from esp.volumetric.jsondoc import result_dict

__all__ = [
    "FigureSpec",
    "SkippedFigure",
    "check_out_dir",
    "figure_specs",
    "skipped_figures",
    "write_report",
    "write_report_files",
]

#: what a report's builder is told as each part is done: a short label (a file name)
Progress = Callable[[str], None]


@dataclass(frozen=True)
class FigureSpec:
    """One figure of the report: its PNG file name, its title in the PDF's list of figures,
    and how to draw it."""

    filename: str
    title: str
    build: Callable[[], Figure]


@dataclass(frozen=True)
class SkippedFigure:
    """A figure the report leaves out, and why, in words for the PDF's text: ``reason``
    is one line such as "Y direction: zero over the whole volume; no figure"."""

    filename: str
    title: str
    reason: str


def _zero_directions(result: AnalysisResult) -> list[str]:
    """The directions whose total error is zero everywhere in the worst tool case (the
    case the maps show): an axis the machine does not have, as the Y of a lathe."""
    if not result.active:
        return []
    case = result.cases[result.worst]
    return [
        d
        for d in ("X", "Y", "Z")
        if case.axes[d].minimum.value_um == case.axes[d].maximum.value_um == 0
    ]


def skipped_figures(result: AnalysisResult) -> list[SkippedFigure]:
    """The figures the report of ``result`` leaves out, in the order they would have had:
    the map of a direction whose error is zero over the whole volume (it would be a page
    of empty panels)."""
    return [
        SkippedFigure(
            f"map-{d}.png",
            f"{d}-direction error on the three faces through its largest value",
            f"{d} direction: zero over the whole volume; no figure",
        )
        for d in _zero_directions(result)
    ]


def figure_specs(result: AnalysisResult) -> list[FigureSpec]:
    """Every figure of the report of ``result``, in the order of the PDF. A result without
    error data (no active component: an uncertainty plan) has no maps and no terms; a
    direction zero over the whole volume has no map (:func:`skipped_figures`)."""
    slicer = plots.PlaneSlicer(result.evaluation)

    # the figure of one direction or axis, drawn when called (a closure per loop value)
    def direction_maps(d: str) -> Callable[[], Figure]:
        return lambda: plots.direction_maps_figure(result, d, slicer)

    def axis_inputs(axis: str) -> Callable[[], Figure]:
        return lambda: plots.axis_inputs_figure(result, axis)

    specs = []
    zero = _zero_directions(result)
    if result.active:
        specs += [
            FigureSpec(
                f"map-{d}.png",
                f"{d}-direction error on the three faces through its largest value",
                direction_maps(d),
            )
            for d in ("X", "Y", "Z")
            if d not in zero
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
    jobs: int = 1,
    progress: Progress | None = None,
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
    date : the report date printed in the PDF (default :func:`esp.report.epoch.report_date`)
    timings : if given, receives the seconds spent per part: ``"png <name>"`` (drawing
        and saving one figure as PNG, in whichever process did it), ``"pdf <name>"``
        (building the figure when this process did not, and its PDF page), ``"pdf"``
        (the PDF less the PNGs made in this process), ``"json"``, ``"csv"`` (with
        ``grid.csv``)
    jobs : the number of processes (1, the default: everything in this process); the
        files are the same byte for byte whatever it is
    progress : if given, called with a short label (the file name, e.g. ``"map-X.png"``)
        as each file or figure is done
    """
    outputs = Outputs(result.machine.inputs)
    out = outputs.folder(out_dir, "--out")
    with outputs:
        staged = outputs.stage_folder(out)
        write_report_files(
            result,
            staged,
            grid_csv=grid_csv,
            date=date,
            timings=timings,
            jobs=jobs,
            progress=progress,
        )
    return out


def write_report_files(
    result: AnalysisResult,
    staged: Path,
    *,
    grid_csv: bool = False,
    date: str | None = None,
    timings: MutableMapping[str, float] | None = None,
    jobs: int = 1,
    progress: Progress | None = None,
    provenance: Provenance | None = None,
) -> None:
    """Write every file of the report of ``result`` into the folder ``staged`` (a staging
    folder of :class:`esp.io.outputs.Outputs`; see :func:`write_report`). ``provenance``
    (the command's, :attr:`esp.cli.output.CommandOutputs.provenance`) closes the PDF and
    ``result.json``; by default it is collected from the machine's inputs."""
    staged = Path(staged)
    if provenance is None and result.machine.inputs:
        provenance = pdf.report_provenance(result)
    date = date or pdf.report_date()  # a malformed SOURCE_DATE_EPOCH is refused first
    done = progress or (lambda label: None)
    if grid_csv:
        export.check_grid_csv(result.machine)
    with _timed(timings, "json"):
        doc = result_dict(result)
        if provenance is not None:
            doc = {**doc, "provenance": provenance.to_dict()}
        write_text(staged / "result.json", dumps(doc))
    done("result.json")
    specs = figure_specs(result)
    pool = _start_pool(jobs - 1, result, staged) if jobs > 1 and specs else None
    try:
        with _timed(timings, "csv"):
            _write_csv(result, staged, grid_csv)
        done("extremes.csv" if not grid_csv else "grid.csv")
        futures: list[Future] = []
        if pool is not None:
            with warnings.catch_warnings():
                # newer Pythons warn of forking beside threads; the workers only draw and write
                warnings.simplefilter("ignore", DeprecationWarning)
                futures = [pool.submit(_png_in_worker, k) for k in range(len(specs))]
        _write_pdf(result, staged, specs, date, timings, futures, done, provenance)
        done("report.pdf")
        if pool is not None:
            _finish(futures, specs, staged, timings, done)
    except BaseException:
        if pool is not None:
            stop_pool(pool)
            pool = None
        raise
    finally:
        if pool is not None:
            pool.shutdown(wait=True)


def _write_csv(result: AnalysisResult, staged: Path, grid_csv: bool) -> None:
    """``extremes.csv`` and ``terms.csv`` from the typed rows (the text
    :func:`esp.volumetric.frames.frame_csv` writes of the same rows, without loading pandas),
    and ``grid.csv`` on request."""
    for name, columns, rows in (
        ("extremes.csv", export.EXTREMES_COLUMNS, export.extremes_rows(result)),
        ("terms.csv", export.TERMS_COLUMNS, export.terms_rows(result)),
    ):
        write_text(staged / name, export.csv_text(columns, export.typed_rows(columns, rows)))
    if grid_csv:
        from esp.volumetric import frames  # pandas

        frames.write_grid_csv(result, staged / "grid.csv")


def _write_pdf(
    result: AnalysisResult,
    staged: Path,
    specs: Sequence[FigureSpec],
    date: str,
    timings: MutableMapping[str, float] | None,
    futures: Sequence[Future],
    done: Progress,
    provenance: Provenance | None = None,
) -> None:
    """The PDF, its figure pages built one after the other; each figure is saved as PNG
    here first unless a worker makes it (``futures``, one per figure)."""

    def figures() -> Iterator[Figure]:
        for spec in specs:
            start = time.perf_counter()
            fig = spec.build()
            if not futures:
                plots.save_png(fig, staged / spec.filename)
                if timings is not None:
                    timings[f"png {spec.filename}"] = time.perf_counter() - start
                start = time.perf_counter()
            yield fig  # drawn on its PDF page before the generator resumes
            if timings is not None:
                timings[f"pdf {spec.filename}"] = time.perf_counter() - start
            if not futures:
                done(spec.filename)
            _raise_early(futures)

    start = time.perf_counter()
    pdf.write_pdf(
        staged / "report.pdf",
        result,
        figures(),
        [s.title for s in specs],
        date,
        provenance=provenance,
    )
    if timings is not None:
        made = sum(timings.get(f"png {s.filename}", 0.0) for s in specs) if not futures else 0.0
        timings["pdf"] = time.perf_counter() - start - made


# -- a plain pool of worker processes for the PNG files ----------------------------------------

#: in a worker process: the report it makes figures of, (result, staged folder, specs)
_WORKER: list = []


def _start_pool(workers: int, result: AnalysisResult, staged: Path) -> ProcessPoolExecutor | None:
    """A pool of ``workers`` forked processes, each holding the report (forked, not
    copied); None where processes do not fork (the report is then made here alone)."""
    if not sys.platform.startswith("linux") or multiprocessing.parent_process() is not None:
        return None  # inside a worker of esp batch --jobs, the cores are in use already
    try:
        return start_pool(
            workers,
            _worker_start,
            (os.getpid(), result, staged),
            mp_context=multiprocessing.get_context("fork"),
        )
    except (OSError, ValueError, RuntimeError):
        return None


def _worker_start(parent: int, result: AnalysisResult, staged: Path) -> None:
    die_with_parent(parent)
    _WORKER[:] = [result, staged, None]


def _png_in_worker(k: int) -> float:
    """In a worker: make the PNG of figure ``k``; returns the seconds it took."""
    result, staged, specs = _WORKER
    if specs is None:
        specs = _WORKER[2] = figure_specs(result)
    start = time.perf_counter()
    spec = specs[k]
    plots.save_png(spec.build(), staged / spec.filename)
    return time.perf_counter() - start


def _raise_early(futures: Sequence[Future]) -> None:
    """Raise the error of a worker's figure as soon as it is known (a dead worker is not
    an error: what it left is made here at the end)."""
    for future in futures:
        if future.done() and not future.cancelled():
            error = future.exception()
            if error is not None and not isinstance(error, BrokenProcessPool):
                raise error


def _finish(
    futures: list[Future],
    specs: Sequence[FigureSpec],
    staged: Path,
    timings: MutableMapping[str, float] | None,
    done: Progress,
) -> None:
    """After the PDF: wait for the workers' PNG files, raising the first error; a figure
    whose worker died is made here."""
    for spec, future in zip(specs, futures, strict=True):
        start = time.perf_counter()
        try:
            seconds = future.result()
        except BrokenProcessPool:
            plots.save_png(spec.build(), staged / spec.filename)
            seconds = time.perf_counter() - start
        if timings is not None:
            timings[f"png {spec.filename}"] = seconds
        done(spec.filename)
