"""``esp iso230-2``: ISO 230-2 accuracy and repeatability of positioning of one axis."""

from __future__ import annotations

import re
from pathlib import Path

import click

from esp.cli import options
from esp.cli.output import CommandOutputs
from esp.core.errors import DataError
from esp.io.load import load_profile
from esp.io.textfile import read_text
from esp.iso230.positioning import iso230_2
from esp.iso230.text import iso230_text, vdi_text

__all__ = ["iso230_command"]

_KIND_COMMENT = re.compile(r"^\s*#\s*kind\s*[:=]", re.IGNORECASE | re.MULTILINE)


def _kind_for(path: Path) -> str | None:
    """The kind to ask the reader for: a CSV that does not declare its kind is read as
    linear (the only kind this command accepts), unless it shows that it is not
    positioning data (:func:`_not_positioning`); otherwise the file decides."""
    if path.suffix.lower() == ".csv":
        text = read_text(path)
        if not _KIND_COMMENT.search(text):
            _not_positioning(path, text)
            return "linear"
    return None


_COMMENT = re.compile(
    r"^\s*#\s*(axis|error_direction)\s*[:=]\s*(\S+)", re.IGNORECASE | re.MULTILINE
)
_OTHER_KIND = re.compile(r"straight|angular", re.IGNORECASE)


def _not_positioning(path: Path, text: str) -> None:
    """Refuse a CSV without a ``# kind:`` line that is not positioning data: one whose
    ``# error_direction:`` differs from its ``# axis:`` (a straightness or angular
    file), or whose name says straightness or angular. ``# kind: linear`` reads it as
    positioning data all the same."""
    comments = {m.group(1).lower(): m.group(2).strip().upper() for m in _COMMENT.finditer(text)}
    axis, about = comments.get("axis"), comments.get("error_direction")
    if about is not None and about != axis:
        found = f"'# error_direction: {about}'" + (f" for axis {axis}" if axis else "")
        why = f"it declares {found}, the direction of a straightness or angular error"
    elif (m := _OTHER_KIND.search(path.stem)) is not None:
        why = f"its name says {m.group(0).lower()}"
    else:
        return
    raise DataError(
        f"{path}: expected linear positioning data for ISO 230-2, found a file that is "
        f"not: {why}; add a '# kind: linear' line if it is positioning data"
    )


@click.command("iso230-2")
@click.argument("file", type=click.Path(dir_okay=False, path_type=Path))
@click.option(
    "--unit",
    metavar="U",
    callback=options.length_unit,
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
    help="Write a figure of the mean deviation per direction with its ±2s band (PNG, or "
    "PDF for a name ending in .pdf).",
)
@click.option(
    "--out",
    "out_dir",
    metavar="DIR",
    type=click.Path(file_okay=False, path_type=Path),
    help="Write an ISO 230-2 test report to the folder DIR: report.pdf (the figures A, B, "
    "E, M, R, the table of every target, the error plot, the provenance), iso230.png and "
    "result.json.",
)
@click.option(
    "--vdi3441",
    is_flag=True,
    help="Also the VDI/DGQ 3441 (1977) figures P, Pa, U and Ps (quoted by older "
    "acceptance documents).",
)
@click.option("--quiet", "-q", is_flag=True, help="Print nothing on the terminal but errors.")
def iso230_command(
    file: Path,
    unit: str | None,
    json_target: str | None,
    plot_path: Path | None,
    out_dir: Path | None = None,
    vdi3441: bool = False,
    quiet: bool = False,
) -> None:
    """ISO 230-2 accuracy and repeatability of positioning of a linear axis.

    FILE is a linear positioning file (Laser10 .rtl, or a tidy CSV with columns
    target_mm,run,direction,deviation, read as linear unless a '# kind:' line says
    otherwise) with at least 2 runs in each direction it holds;
    ISO 230-2 asks for 5. Forward runs are the standard's up (↑) approaches, backward runs
    its down (↓) approaches. Prints, in µm, the mean, standard deviation, reversal and
    repeatability at each target, and the axis figures A, B, E, M and R (with their
    unidirectional _up/_down forms). With --vdi3441 also the VDI/DGQ 3441 figures:
    position uncertainty P, positional deviation Pa, reversal span U (max and mean) and
    positional scatter Ps = 6 s (max and mean).

    \b
    Examples:
      esp iso230-2 data/examples/gantry/X-linear.rtl
      esp iso230-2 data/examples/gantry/X-linear.rtl --json - > X-iso230.json
      esp iso230-2 data/examples/gantry/X-linear.rtl --json X.json --plot X.png
      esp iso230-2 data/examples/gantry/X-linear.rtl --vdi3441
      esp iso230-2 data/examples/gantry/X-linear.rtl --out X-iso230-report
    """
    # every target is checked before the file is read, and written last, all or none
    outputs = CommandOutputs([file], json_target, quiet)
    png_path = outputs.figure(plot_path, "--plot") if plot_path is not None else None
    out = outputs.folder(out_dir, "--out") if out_dir is not None else None
    if out is not None:
        from esp.report.epoch import source_date_epoch

        source_date_epoch()  # a malformed SOURCE_DATE_EPOCH is refused before any work
    profile = load_profile(file, kind=_kind_for(file), unit=unit)
    result = iso230_2(profile)
    vdi = None
    if vdi3441:
        from esp.iso230.vdi3441 import vdi3441 as vdi_figures

        vdi = vdi_figures(profile)
    doc = result.to_dict()
    if vdi is not None:
        doc["vdi3441"] = vdi.to_dict()
    text = iso230_text(result) + (vdi_text(vdi) if vdi is not None else "")
    with outputs:
        if png_path is not None:
            from esp.iso230.plots import iso230_figure

            outputs.save_figure(iso230_figure(result), png_path)
        if out is not None:
            from esp.iso230.report import write_iso230_report
            from esp.report.jsonout import dumps

            prov = outputs.provenance
            write_iso230_report(
                outputs.stage_folder(out),
                result,
                dumps({**doc, "provenance": prov.to_dict()}),
                provenance=prov,
                vdi=vdi,
            )
        outputs.finish(text=text, doc=doc)
