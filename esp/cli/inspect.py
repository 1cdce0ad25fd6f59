"""``esp inspect``: what a measurement file holds, with an optional plot of every run.

matplotlib is imported only when ``--plot`` asks for the figure."""

from __future__ import annotations

from functools import partial
from pathlib import Path

import click

from esp.cli import options
from esp.cli.output import CommandOutputs
from esp.core.profile import KINDS
from esp.io.load import load_profile
from esp.report.profile_text import inspect_text, profile_summary

__all__ = ["inspect_command"]


@click.command("inspect")
@click.argument("file", type=click.Path(dir_okay=False, path_type=Path))
@click.option(
    "--kind",
    type=click.Choice(KINDS),
    help="Kind of error in FILE; default: from the extension, the file's header or its "
    "'# kind:' line (a CSV needs one of these).",
)
@click.option(
    "--unit",
    metavar="U",
    callback=options.unit,
    help="Unit of the deviations in FILE (um, nm, mm, in for linear and straightness; "
    "um/m, urad, mrad, arcsec for angular), for a file that does not state it; default: the "
    "format's (µm, or µm/m for angles). A unit that contradicts the file's '# unit:' line "
    "is refused.",
)
@click.option(
    "--plot",
    "plot_path",
    metavar="OUT.png",
    type=click.Path(dir_okay=False, path_type=Path),
    help="Write a figure of every run and the mean curves against position (PNG, or PDF "
    "for a name ending in .pdf).",
)
@click.option(
    "--json",
    "json_target",
    metavar="PATH|-",
    help="Write the summary as JSON to PATH, or to standard output with '-' "
    "(the text summary is then not printed).",
)
def inspect_command(
    file: Path,
    kind: str | None,
    unit: str | None,
    plot_path: Path | None,
    json_target: str | None,
) -> None:
    """Show what a measurement file holds.

    Reads FILE (Laser10 .rtl, .rta, .rts, .stx/.sty/.stz, or a tidy CSV with columns
    target_mm,run,direction,deviation) and prints its kind, axis, error direction, unit,
    targets, runs per direction, the file's user text and environment readings (start and
    end), and the mean deviation per direction at each target, in esp's units (µm, or
    µm/m for angular errors).

    \b
    Examples:
      esp inspect data/examples/gantry/X-linear.rtl
      esp inspect data/examples/turning-centre/Xpitch.rta --plot Xpitch.png
      esp inspect data/examples/gantry/X-linear.rtl --json -
      esp inspect data/examples/csv/Y-straightness-Z.csv --kind straightness

    A Laser10 file states no unit: give --unit (e.g. --unit arcsec) for an angular file
    written in another unit than µm/m; a unit that contradicts a CSV's `# unit:` line is
    refused.
    """
    # every target is checked before the file is read, and written last, all or none
    outputs = CommandOutputs([file], json_target)
    png_path = outputs.figure(plot_path, "--plot") if plot_path is not None else None
    profile = load_profile(file, kind=kind, unit=unit)
    with outputs:
        if png_path is not None:
            from esp.report.profile_plots import profile_runs_figure  # matplotlib

            outputs.save_figure(profile_runs_figure(profile), png_path)
        outputs.finish(text=partial(inspect_text, profile), doc=partial(profile_summary, profile))
