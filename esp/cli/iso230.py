"""``esp iso230-2``: ISO 230-2 accuracy and repeatability of positioning of one axis."""

from __future__ import annotations

import re
from pathlib import Path

import click

from esp.cli.output import emit_json
from esp.io.load import load_profile
from esp.io.textfile import read_text
from esp.iso230 import iso230_2
from esp.report.profile_plots import iso230_figure, save_png
from esp.report.profile_text import iso230_text

__all__ = ["iso230_command"]

_KIND_COMMENT = re.compile(r"^\s*#\s*kind\s*[:=]", re.IGNORECASE | re.MULTILINE)


def _kind_for(path: Path) -> str | None:
    """The kind to ask the reader for: a CSV that does not declare its kind is read as
    linear (the only kind this command accepts); otherwise the file decides."""
    if path.suffix.lower() == ".csv" and not _KIND_COMMENT.search(read_text(path)):
        return "linear"
    return None


@click.command("iso230-2")
@click.argument("file", type=click.Path(dir_okay=False, path_type=Path))
@click.option(
    "--unit",
    metavar="U",
    help="Unit of the deviations in FILE (um, nm, mm, in); default: the format's (µm).",
)
@click.option(
    "--json",
    "json_target",
    metavar="PATH|-",
    help="Write the statistics as JSON to PATH, or to standard output with '-' "
    "(the table is then not printed).",
)
@click.option(
    "--plot",
    "plot_path",
    metavar="OUT.png",
    type=click.Path(dir_okay=False, path_type=Path),
    help="Write a PNG of the mean deviation per direction with its ±2s band.",
)
def iso230_command(
    file: Path, unit: str | None, json_target: str | None, plot_path: Path | None
) -> None:
    """ISO 230-2 accuracy and repeatability of positioning of a linear axis.

    FILE is a linear positioning file (Laser10 .rtl, or a tidy CSV with columns
    target_mm,run,direction,deviation, read as linear unless a '# kind:' line says
    otherwise) with at least 2 runs in each direction it holds;
    ISO 230-2 asks for 5. Forward runs are the standard's up (↑) approaches, backward runs
    its down (↓) approaches. Prints, in µm, the mean, standard deviation, reversal and
    repeatability at each target, and the axis figures A, B, E, M and R (with their
    unidirectional _up/_down forms).

    \b
    Examples:
      esp iso230-2 data/examples/gantry/X-linear.rtl
      esp iso230-2 data/examples/gantry/X-linear.rtl --json - > X-iso230.json
      esp iso230-2 data/examples/gantry/X-linear.rtl --json X.json --plot X.png
    """
    profile = load_profile(file, kind=_kind_for(file), unit=unit)
    result = iso230_2(profile)
    figure = iso230_figure(result) if plot_path is not None else None
    if json_target:
        emit_json(result.to_dict(), json_target)
    if figure is not None:
        save_png(figure, plot_path)
    if json_target != "-":
        click.echo(iso230_text(result), nl=False)
