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
uncertainty), and one ``input-<component>.png`` per active component with data.
"""

from __future__ import annotations

import contextlib
import time
from collections.abc import Callable, Iterable, Iterator, MutableMapping
from dataclasses import dataclass
from pathlib import Path

from matplotlib.figure import Figure

from esp.io.atomic import write_text
from esp.io.outputs import Outputs
from esp.report import export, pdf, plots
from esp.report.jsonout import dumps
from esp.report.result_json import result_dict
from esp.results import AnalysisResult

__all__ = [
    "FigureSpec",
    "check_out_dir",
    "figure_specs",
    "write_report",
    "write_report_files",
]


@dataclass(frozen=True)
class FigureSpec:
    """One figure of the report: its PNG file name, its title in the PDF's list of figures,
    and how to draw it."""

    filename: str
    title: str
    build: Callable[[], Figure]


def figure_specs(result: AnalysisResult) -> list[FigureSpec]:
    """Every figure of the report of ``result``, in the order of the PDF."""
    case = result.cases[result.worst]
    slicer = plots.PlaneSlicer(result.machine, case.tool)
    specs = [
        FigureSpec(
            f"map-{d}.png",
            f"{d}-direction error on the three faces through its largest value",
            lambda d=d: plots.direction_maps_figure(result, d, slicer),
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
            "terms.png", "Term contributions at the worst point", lambda: plots.terms_figure(result)
        )
    )
    if result.sweep:
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
    for name in plots.plotted_components(result):
        specs.append(
            FigureSpec(
                f"input-{str(name).replace('.', '-')}.png",
                f"Input {name} ({result.machine.components[name].iso}) against position",
                lambda name=name: plots.component_figure(result, name),
            )
        )
    return specs


def check_out_dir(out_dir: str | Path, inputs: Iterable[str | Path] = ()) -> Path:
    """The report folder as an absolute path, after checking it may be written (see
    :class:`esp.io.outputs.Outputs`): it does not exist, or it is empty, or esp wrote it
    and it holds nothing else; it is not the current folder, the root, or a folder that
    holds one of ``inputs``.

    Raises :class:`~esp.errors.DataError` otherwise, so that nothing the user keeps there
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
) -> Path:
    """Write the report folder of ``result`` to ``out_dir`` and return its path.

    Parameters
    ----------
    result : the analysis
    out_dir : the folder to create; an existing one is replaced only if it is empty or an
        earlier esp report holding nothing else (see :func:`check_out_dir`), and only after
        everything is written
    grid_csv : also write ``grid.csv`` (refused above
        :data:`esp.report.export.GRID_CSV_MAX_POINTS` points)
    date : the report date printed in the PDF (default :func:`esp.report.pdf.report_date`)
    timings : if given, receives the seconds spent per part: ``"png <name>"`` (drawing
        and saving one figure), ``"pdf <name>"`` (its PDF page), ``"pdf"`` (the whole PDF
        less the PNGs), ``"json"``, ``"csv"``, ``"grid csv"``
    """
    outputs = Outputs(result.machine.inputs)
    out = outputs.folder(out_dir, "--out")
    with outputs:
        staged = outputs.stage_folder(out)
        write_report_files(result, staged, grid_csv=grid_csv, date=date, timings=timings)
    return out


def write_report_files(
    result: AnalysisResult,
    staged: Path,
    *,
    grid_csv: bool = False,
    date: str | None = None,
    timings: MutableMapping[str, float] | None = None,
) -> None:
    """Write every file of the report of ``result`` into the folder ``staged`` (a staging
    folder of :class:`esp.io.outputs.Outputs`; see :func:`write_report`)."""
    if grid_csv:
        export.check_grid_csv(result.machine)
    date = date or pdf.report_date()
    with _timed(timings, "json"):
        write_text(staged / "result.json", dumps(result_dict(result)))
    with _timed(timings, "csv"):
        export.write_extremes_csv(result, staged / "extremes.csv")
        export.write_terms_csv(result, staged / "terms.csv")
    if grid_csv:
        with _timed(timings, "grid csv"):
            export.write_grid_csv(result, staged / "grid.csv")
    specs = figure_specs(result)

    def figures() -> Iterator[Figure]:
        for spec in specs:
            with _timed(timings, f"png {spec.filename}"):
                fig = spec.build()
                plots.save_png(fig, staged / spec.filename)
            start = time.perf_counter()
            yield fig  # drawn on its PDF page before the generator resumes
            if timings is not None:
                timings[f"pdf {spec.filename}"] = time.perf_counter() - start

    start = time.perf_counter()
    pdf.write_pdf(staged / "report.pdf", result, figures(), [s.title for s in specs], date)
    if timings is not None:
        # the PDF's own share: its text pages and the figure pages, not the PNGs
        pngs = sum(timings.get(f"png {s.filename}", 0.0) for s in specs)
        timings["pdf"] = time.perf_counter() - start - pngs
