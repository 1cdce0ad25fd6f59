"""``esp batch``: analyse many machines, one report folder each, and a summary with a
pass/fail verdict for CI."""

from __future__ import annotations

import sys
from typing import TYPE_CHECKING

import click

from esp.batch.run import MAX_JOBS
from esp.cli import one_line, options
from esp.config.tolerance import GUARD_FRACTION

if TYPE_CHECKING:
    from esp.batch.run import BatchRow

__all__ = ["batch_command", "result_line"]


def _stderr_is_terminal() -> bool:
    return sys.stderr.isatty()


def result_line(row: BatchRow) -> str:
    """One line per machine: ``ok   gantry/machine.toml  36.926 um  pass`` (with a U,
    rounded to it: ``10.0 um, U = 2.0 um``), for an uncertainty plan ``ok   study/plan.toml
    U = 26 um (uncertainty plan)  plan``, or
    ``err  broken/machine.toml  <message>``, or ``skip ident/machine.toml  skipped: ...``
    for a configuration not analysed; a line break or other control character in a
    file name or message is shown escaped (:func:`esp.cli.one_line`)."""
    if row.error is not None:
        return one_line(f"err  {row.file}  {row.error}")
    if row.skipped is not None:
        return one_line(f"skip {row.file}  {row.skipped}")
    from esp.core.rounding import rounded

    u_um = row.uncertainty_um
    has_u = u_um is not None and u_um > 0.0
    if row.plan:
        assert u_um is not None  # a plan's headline
        u_text = rounded(0.0, u_um)[1] if has_u else f"{u_um + 0.0:.3f}"
        return one_line(f"ok   {row.file}  U = {u_text} um (uncertainty plan)  {row.verdict}")
    assert row.volumetric_um is not None  # an analysed machine's accuracy
    if has_u:  # rounded to what U supports (GUM 7.2.6)
        assert u_um is not None
        v_text, u_text = rounded(row.volumetric_um, u_um)
        return one_line(f"ok   {row.file}  {v_text} um, U = {u_text} um  {row.verdict}")
    return one_line(f"ok   {row.file}  {row.volumetric_um + 0.0:.3f} um  {row.verdict}")


@click.command("batch")
@click.argument(
    "paths", nargs=-1, required=True, metavar="PATH...", type=click.Path(exists=True, path_type=str)
)
@click.option(
    "--out",
    "out_dir",
    required=True,
    metavar="DIR",
    type=click.Path(file_okay=False, path_type=str),
    help="Folder for the report folders and summary.csv / summary.md (new, empty, or "
    "one esp wrote: it is replaced as a whole when the batch is done).",
)
@click.option(
    "--max-volumetric",
    type=options.Number("threshold"),
    metavar="UM",
    help="Tolerance of the volumetric accuracy, UM µm: a machine fails when it does not "
    "conform under the decision rule.",
)
@click.option(
    "--max-planar",
    type=options.Number("threshold"),
    metavar="UM",
    help="Tolerance of every planar accuracy, UM µm (decided by simple acceptance: esp "
    "evaluates no U for it).",
)
@click.option(
    "--max-uncertainty",
    type=options.Number("threshold"),
    metavar="UM",
    help="Fail a machine whose expanded volumetric uncertainty exceeds UM µm (machines with "
    "an [uncertainty] table; the one threshold an uncertainty plan is checked against).",
)
@click.option(
    "--rule",
    type=click.Choice(["simple", "guarded"]),
    help="Decision rule for every machine (ISO 14253-1, ILAC-G8): simple acceptance, or "
    "guarded acceptance with a guard band w = U (needs each machine's [uncertainty] table). "
    "Default: each machine's [tolerance] rule, else simple.",
)
@click.option(
    "--guard",
    type=options.Number(GUARD_FRACTION),
    metavar="F",
    help="With --rule guarded: the guard band as a fraction F of U, 0 < F <= 3 (default 1).",
)
@click.option(
    "--jobs",
    "-j",
    type=click.IntRange(min=1, max=MAX_JOBS),
    default=1,
    show_default=True,
    metavar="N",
    help="Machines analysed at once, each in its own process (1: in this process).",
)
@click.option(
    "--quiet",
    "-q",
    is_flag=True,
    help="Print nothing on the terminal but the machines that could not be analysed.",
)
@click.pass_context
def batch_command(
    ctx: click.Context,
    paths: tuple[str, ...],
    out_dir: str,
    max_volumetric: float | None,
    max_planar: float | None,
    max_uncertainty: float | None,
    rule: str | None,
    guard: float | None,
    jobs: int,
    quiet: bool,
) -> None:
    """Analyse every machine configuration in PATHS and write a report folder for each,
    with summary.csv and summary.md, into DIR.

    A PATH may be a machine.toml or a folder; folders are searched recursively for
    *.toml files that have a [machine] table (hidden folders and DIR are skipped). Each
    report goes to DIR/<path relative to the common folder, '/' written '__'>, e.g.
    DIR/gantry__machine-tcp. One machine that cannot be analysed, or a folder that
    cannot be searched, is an error row and does not stop the others; with --jobs, a
    machine whose process is killed (out of memory) is analysed again in a process of its
    own.

    DIR must be new, empty, or a folder an earlier esp batch wrote (holding nothing
    else); it is written all at once when the batch is done.

    An uncertainty plan (an [uncertainty] table and no error data) has no accuracy: its
    row shows the expanded volumetric uncertainty, --max-volumetric and --max-planar do
    not apply to it, and its verdict is "plan" unless --max-uncertainty is given.

    The thresholds are tolerances decided by the rule (ISO 14253-1:2017, ILAC-G8:09/2019),
    with each machine's own [tolerance] table for the limits they leave open; the summary
    names the rule and each decision's risk. A guarded rule where a machine's U is not
    evaluated makes that machine an error row.

    Exit code: 0 every machine passes (or is a plan, or has no tolerance), 1 a figure does
    not conform, 3 none fails but one is not decided (within the guard band), 2 a machine
    could not be analysed (2 wins, then 1, then 3).

    \b
    Examples:
      esp batch data/examples --out reports --max-volumetric 50
      esp batch data/examples/gantry --out reports --max-planar 40 --jobs 4
      esp batch data/examples/gantry --out reports --max-volumetric 50 --rule guarded
    """
    from esp.batch.run import (
        SUMMARY_CSV,
        Thresholds,
        counts_text,
        exit_code,
        find_machines,
        plan,
        run_batch,
    )
    from esp.config.tolerance import rule_from_options
    from esp.core.errors import DataError
    from esp.io.outputs import Outputs

    thresholds = Thresholds(
        max_volumetric, max_planar, max_uncertainty, rule=rule_from_options(rule, guard)
    )

    # the output folder is checked first (it may not hold a PATH), again with every
    # configuration found, and once more by run_batch before any machine is analysed
    Outputs(paths).folder(out_dir, "--out")
    unreadable: list[tuple[str, str]] = []
    files = find_machines(paths, skip=[out_dir], unreadable=unreadable)
    if not files and not unreadable:
        raise DataError(
            f"{', '.join(paths)}: no machine configuration found (a *.toml file with a "
            f"[machine] table)"
        )
    Outputs(files).folder(out_dir, "--out")
    items = plan(files, unreadable)

    if quiet:
        rows = run_batch(items, out_dir, thresholds, jobs=jobs)
        for row in rows:
            if row.error is not None:
                click.echo(result_line(row))
        ctx.exit(exit_code(rows))
    if _stderr_is_terminal():
        with click.progressbar(length=len(items), label="analysing", file=sys.stderr) as bar:
            rows = run_batch(items, out_dir, thresholds, jobs=jobs, on_done=lambda r: bar.update(1))
        for row in rows:
            click.echo(result_line(row))
    else:
        rows = run_batch(
            items, out_dir, thresholds, jobs=jobs, on_done=lambda r: click.echo(result_line(r))
        )
    shown = one_line(click.format_filename(out_dir))
    click.echo(f"{counts_text(rows)}; summary in {shown}/{SUMMARY_CSV}")
    ctx.exit(exit_code(rows))
