"""``esp analyse``: the main job."""

from __future__ import annotations

import sys
from collections.abc import Callable, Mapping
from functools import partial
from pathlib import Path, PurePath
from typing import TYPE_CHECKING, Any

import click

from esp.cli import options
from esp.config.tolerance import GUARD_FRACTION
from esp.core.machine import AXIS_NAMES, Machine
from esp.core.units import flush_tiny
from esp.core.values import ValueRefused, parse

if TYPE_CHECKING:
    from esp.cli.output import CommandOutputs
    from esp.core.results import AnalysisResult

__all__ = ["analyse_command", "parse_point"]


def parse_point(text: str) -> dict[str, float]:
    """``"X=990,Y=360,Z=-5"`` -> ``{"X": 990.0, "Y": 360.0, "Z": -5.0}``; all three needed."""
    point: dict[str, float] = {}
    for part in text.replace(";", ",").split(","):
        if not part.strip():
            continue
        key, sep, value = part.partition("=")
        key = key.strip().upper()
        if not sep or key not in AXIS_NAMES:
            raise click.BadParameter(
                f"expected AXIS=mm pairs such as X=990,Y=360,Z=-5, found {part!r}"
            )
        if key in point:
            raise click.BadParameter(f"{key} is given twice")
        try:
            point[key] = flush_tiny(parse(value, "position"))  # below 1e-30: 0
        except ValueRefused as exc:
            raise click.BadParameter(f"{key}: {exc.message}") from None
    missing = [a for a in AXIS_NAMES if a not in point]
    if missing:
        raise click.BadParameter(f"missing {', '.join(missing)}; give X, Y and Z")
    return point


def _at_option(
    ctx: click.Context, param: click.Parameter, value: str | None
) -> dict[str, float] | None:
    """``--at`` parsed when the options are: a malformed point names the option."""
    if value is None:
        return None
    try:
        return parse_point(value)
    except click.BadParameter as exc:
        exc.ctx, exc.param = ctx, param
        raise


class _Progress:
    """A progress bar on standard error for long sweeps, only on a terminal."""

    def __init__(self, enabled: bool):
        self.enabled = enabled
        self.bar: Any = None  # click.progressbar's bar, once the work is long enough

    def __call__(self, done: int, total: int) -> None:
        if not self.enabled or total < 2:
            return
        if self.bar is None:
            self.bar = click.progressbar(length=total, label="evaluating", file=sys.stderr)
            self.bar.__enter__()
        self.bar.update(1)
        if done == total:
            self.bar.__exit__(None, None, None)
            self.bar = None


@click.command("analyse")
@click.argument("machine_toml", type=click.Path(dir_okay=False, path_type=str))
@click.option(
    "--json", "json_target", metavar="PATH|-", help="Write the result as JSON ('-': stdout)."
)
@click.option(
    "--at",
    "point",
    metavar="X=..,Y=..,Z=..",
    callback=_at_option,
    help="Evaluate one machine position (mm) instead of the grid.",
)
@click.option(
    "--out",
    "out_dir",
    metavar="DIR",
    type=click.Path(file_okay=False, path_type=str),
    help="Write the report folder: report.pdf, PNG figures, result.json, extremes.csv, terms.csv.",
)
@click.option(
    "--grid-csv",
    is_flag=True,
    help="With --out, also write grid.csv, the error at every grid point (small grids only).",
)
@click.option(
    "--show",
    "show",
    multiple=True,
    metavar="FIGURE",
    help="Write one figure of the report (FIGURE.png, or a .png/.pdf path named after it) "
    "without the rest, and print its path; 'list' lists the figures. Repeatable.",
)
@click.option(
    "--tolerance",
    "tolerance_texts",
    multiple=True,
    metavar="QUANTITY=UM",
    help="Decide a figure against an upper limit in µm: volumetric=30, planar=25 (every "
    "plane), planar.XY=20, range.X=10, uncertainty=5. Repeatable; overrides the "
    "[tolerance] table of MACHINE_TOML limit by limit.",
)
@click.option(
    "--rule",
    type=click.Choice(["simple", "guarded"]),
    help="Decision rule (ISO 14253-1, ILAC-G8): simple acceptance, or guarded acceptance "
    "with a guard band w = U (needs an [uncertainty] table). Default: the [tolerance] "
    "table's rule, else simple.",
)
@click.option(
    "--guard",
    type=options.Number(GUARD_FRACTION),
    metavar="F",
    help="With --rule guarded: the guard band as a fraction F of U, 0 < F <= 3 (default 1).",
)
@click.option("--quiet", "-q", is_flag=True, help="Print nothing on the terminal but errors.")
def analyse_command(
    machine_toml: str,
    json_target: str | None,
    point: dict[str, float] | None,
    out_dir: str | None,
    grid_csv: bool,
    show: tuple[str, ...],
    tolerance_texts: tuple[str, ...],
    rule: str | None,
    guard: float | None,
    quiet: bool,
) -> None:
    """Synthesise the volumetric error of the machine described by MACHINE_TOML.

    Reads the error data the file names, applies the equation set of its configuration
    and case (Longstaff 2002, eq. 3.1-3.16), and reports per-axis extremes, volumetric
    and planar accuracy with where they occur, and every term's share there.

    \b
    Examples:
      esp analyse data/examples/gantry/machine.toml
      esp analyse data/examples/gantry/machine.toml --json result.json
      esp analyse data/examples/gantry/machine.toml --out gantry-report
      esp analyse data/examples/gantry/machine.toml --at "X=500,Y=750,Z=300" --json -
      esp analyse data/examples/gantry/machine.toml --show map-volumetric
      esp analyse data/examples/gantry/machine.toml --show list
      esp analyse data/examples/gantry/machine.toml --tolerance volumetric=40 --rule guarded

    With tolerances (the [tolerance] table of MACHINE_TOML, or --tolerance) the figures
    are decided by the rule (ISO 14253-1:2017, ILAC-G8:09/2019) and the exit code says how:
    0 every figure conforms (or no tolerance is given), 1 a figure does not conform, 3 none
    fails but one is not decided (within the guard band), 2 an error (2 wins, then 1, then
    3). A guarded rule where U is not evaluated is an error.
    """
    from esp.cli.output import CommandOutputs
    from esp.config import load_machine
    from esp.core.analysis import analyse, evaluate_point
    from esp.volumetric.jsondoc import point_dict, result_dict
    from esp.volumetric.text import render_point, render_result

    if grid_csv and not out_dir:
        raise click.UsageError("--grid-csv needs --out DIR")
    if out_dir and point is not None:
        raise click.UsageError("--out writes the report of the grid; it does not go with --at")
    if show and (out_dir or point is not None):
        other = "--out" if out_dir else "--at"
        raise click.UsageError(
            f"--show writes one figure of the report; it does not go with {other}"
        )
    if LIST in show and len(show) > 1:
        raise click.UsageError(f"--show {LIST} lists the figures; give it alone")
    machine = load_machine(machine_toml)
    if (tolerance_texts or rule is not None or guard is not None) and point is not None:
        raise click.UsageError(
            "--tolerance, --rule and --guard decide the figures of the grid; "
            "they do not go with --at"
        )
    machine = _with_tolerances(machine, tolerance_texts, rule, guard)
    if point is not None:
        for a in AXIS_NAMES:
            lo, hi = machine.axes[a].travel_mm
            if not lo - 1e-9 <= point[a] <= hi + 1e-9:
                raise click.BadParameter(
                    f"expected a position within axes.{a}.travel [{lo:g}, {hi:g}] mm, found "
                    f"{a}={point[a]:g}",
                    param_hint="'--at'",
                )
    # every output target is checked before any work, and written last, all or none
    outputs = CommandOutputs(machine.inputs, json_target, quiet)
    out = outputs.folder(out_dir, "--out") if out_dir else None
    if out is not None:
        from esp.report.epoch import source_date_epoch

        source_date_epoch()  # a malformed SOURCE_DATE_EPOCH is refused before any work
    if out is not None and grid_csv:
        from esp.volumetric.export import check_grid_csv

        check_grid_csv(machine)
    # (figure, path as given, checked target) of each --show, checked before any work
    shown = [
        (figure_name(v), show_path(v), outputs.figure(show_path(v), "--show"))
        for v in show
        if v != LIST
    ]
    if point is not None:
        at_point = evaluate_point(machine, point)
        with outputs:
            outputs.finish(
                text=partial(render_point, at_point),
                doc=partial(point_dict, at_point),
                warnings=at_point.warnings,
            )
        return
    progress = _Progress(enabled=not outputs.to_stdout and not quiet and sys.stderr.isatty())
    analysis = analyse(machine, progress=progress)
    from esp.core.conformity import exit_code
    from esp.volumetric.conformance import decisions_of

    decisions = decisions_of(analysis)  # a guarded rule without U is refused before writing
    if show:
        _show_figures(outputs, analysis, shown, partial(result_dict, analysis))
        click.get_current_context().exit(exit_code(decisions))
    with outputs:
        if out is not None:
            from esp.volumetric.report import write_report_files

            write_report_files(
                analysis,
                outputs.stage_folder(out),
                grid_csv=grid_csv,
                progress=lambda name: outputs.progress(f"writing {name}"),
                provenance=outputs.provenance,
            )
        outputs.finish(
            text=partial(render_result, analysis),
            doc=partial(result_dict, analysis),
            warnings=analysis.warnings,
        )
    click.get_current_context().exit(exit_code(decisions))


def _with_tolerances(
    machine: Machine, texts: tuple[str, ...], rule: str | None, guard: float | None
) -> Machine:
    """``machine`` with the limits and rule of the command line merged over its
    ``[tolerance]`` table (the reports decide against ``machine.tolerance``)."""
    if not texts and rule is None and guard is None:
        return machine
    from dataclasses import replace

    from esp.config.tolerance import Tolerances, parse_tolerance_options, rule_from_options

    given = replace(parse_tolerance_options(texts), rule=rule_from_options(rule, guard))
    own = machine.tolerance
    base = own if isinstance(own, Tolerances) else Tolerances(source=machine.source)
    return replace(machine, tolerance=base.overridden_by(given))


#: ``--show list``: list the figures instead of writing one
LIST = "list"


def figure_name(value: str) -> str:
    """The figure a ``--show`` value names: its file name without its suffix (``map-X``,
    ``map-X.pdf``, ``figs/terms.png`` -> ``map-X``, ``map-X``, ``terms``). No figure's
    name holds a dot."""
    return PurePath(value).stem


def show_path(value: str) -> str:
    """Where a ``--show`` value writes its figure: the value itself when it has a suffix
    (``.png`` or ``.pdf``; another is refused by the output gate), else the value with
    ``.png`` added."""
    return value if PurePath(value).suffix else f"{value}.png"


def _show_figures(
    outputs: CommandOutputs,
    analysis: AnalysisResult,
    shown: list[tuple[str, str, Path]],
    doc: Callable[[], Mapping[str, Any]],
) -> None:
    """``--show``: write the named figures of the report of ``analysis`` (the same
    figures as ``--out`` writes, drawn the same way) and print their paths, or list
    the figures (``--show list``); the JSON (``--json``) is written as usual."""
    from esp.core.errors import DataError
    from esp.core.text import closest
    from esp.volumetric import plots
    from esp.volumetric.report import figure_specs, skipped_figures

    specs = {PurePath(spec.filename).stem: spec for spec in figure_specs(analysis)}
    skipped = {PurePath(s.filename).stem: s.reason for s in skipped_figures(analysis)}
    if not shown:  # --show list
        with outputs:
            width = max((len(name) for name in specs), default=0)
            listing = "".join(f"{name:<{width}}  {spec.title}\n" for name, spec in specs.items())
            outputs.finish(
                text=listing or "this report has no figures\n",
                doc=doc,
                warnings=analysis.warnings,
            )
        return
    for name, _given, _target in shown:
        if name in skipped:
            raise DataError(f"--show {name}: this report has no such figure: {skipped[name]}")
        if name not in specs:
            starting = [n for n in specs if n.lower().startswith(name.lower())]
            hint = starting[0] if len(starting) == 1 else closest(name, list(specs))
            did_you_mean = f"; did you mean {hint!r}?" if hint else ""
            raise DataError(
                f"--show {name}: expected a figure of this report{did_you_mean} (one of "
                f"{', '.join(specs) or 'none: this report has no figures'}; --show list "
                f"gives their titles)"
            )
    with outputs:
        for name, _given, target in shown:
            outputs.progress(f"drawing {name}")
            outputs.save_figure(specs[name].build(), target, dpi=plots.DPI)
        outputs.finish(
            text="".join(f"{given}\n" for _name, given, _target in shown),
            doc=doc,
            warnings=analysis.warnings,
        )
    if outputs.to_stdout and not outputs.quiet:  # standard output holds the JSON
        for _name, given, _target in shown:
            click.echo(f"esp: figure written to {given}", err=True)
