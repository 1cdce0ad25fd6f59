"""``esp angular``: an angular error from two linear positioning files (indirect method)."""

from __future__ import annotations

from pathlib import Path

import click

from esp.angular.report import write_angular_report
from esp.angular.text import angular_text
from esp.cli import one_line, options
from esp.cli.output import CommandOutputs
from esp.core.angular import angular_from_linear
from esp.core.errors import DataError
from esp.core.profile import ErrorProfile
from esp.core.units import MIN_SPACING_MM
from esp.io.laser10 import format_laser10, kind_from_extension
from esp.io.load import load_profile

__all__ = ["angular_command"]


def _load_linear(path: Path, unit: str | None) -> ErrorProfile:
    """A linear positioning file; a file whose extension names another kind is refused."""
    implied = kind_from_extension(path)
    if implied is not None and implied != "linear":
        raise DataError(
            f"{path}: expected a linear positioning file (.rtl or .csv), found "
            f"{implied} data ({path.suffix})"
        )
    return load_profile(path, kind="linear", unit=unit)


@click.command("angular")
@click.argument("reference", type=click.Path(dir_okay=False, path_type=Path))
@click.argument("shifted", type=click.Path(dir_okay=False, path_type=Path))
@click.option(
    "--displacement",
    "displacement_mm",
    type=options.Number("position", MIN_SPACING_MM, "a non-zero distance in mm"),
    required=True,
    metavar="D_MM",
    help="Signed distance (mm) from the line of REFERENCE to the line of SHIFTED, along "
    "the axis that amplifies the angle.",
)
@click.option(
    "--datum",
    "datum_mm",
    type=options.Number("position"),
    required=True,
    metavar="P_MM",
    help="A target (mm) where the angle is taken as zero.",
)
@click.option(
    "--direction",
    type=click.Choice(["forward", "reverse", "mean"]),
    default="mean",
    show_default=True,
    help="The mean curve made exactly zero at the datum (every run keeps its own angles).",
)
@click.option(
    "--unit",
    metavar="U",
    callback=options.length_unit,
    help="Unit of the deviations in both files (um, nm, mm, in); default µm.",
)
@click.option(
    "-o",
    "--output",
    "output",
    metavar="OUT.rta",
    type=click.Path(dir_okay=False, path_type=Path),
    help="Write the angle of every run as a Laser10 angular file (µm/m).",
)
@click.option(
    "--json",
    "json_target",
    metavar="PATH|-",
    help="Write the angles as JSON to PATH, or to standard output with '-' "
    "(the table is then not printed).",
)
@click.option(
    "--out",
    "out_dir",
    metavar="DIR",
    type=click.Path(file_okay=False, path_type=Path),
    help="Write a report to the folder DIR: report.pdf (the set-up, the angle at every "
    "target, its figure, the provenance), angular.png and result.json.",
)
@click.option("--quiet", "-q", is_flag=True, help="Print nothing on the terminal but errors.")
def angular_command(
    reference: Path,
    shifted: Path,
    displacement_mm: float,
    datum_mm: float,
    direction: str,
    unit: str | None,
    output: Path | None,
    json_target: str | None,
    out_dir: Path | None = None,
    quiet: bool = False,
) -> None:
    """Angular error of an axis from two of its linear positioning measurements.

    REFERENCE is the linear file measured on the line with (nominally) no angular effect,
    SHIFTED the same axis measured on a parallel line displaced by D_MM. At every target
    and for every run j the angle is 1000 x (SHIFTED_j - REFERENCE_j) / D_MM in µm/m, less
    its value at the datum (Longstaff 2002, 3.08.1). On a machine with volumetric
    compensation this measures the residual slope the models need at the MCP.

    Both files must hold the same targets and the same number of runs in each direction;
    the datum must be one of the targets and D_MM must not be zero.

    \b
    Examples (in data/examples/turning-centre):
      esp angular Xpos_z0.rtl Xpos_z800.rtl --displacement -800 --datum -560
      esp angular Xpos_z0.rtl Xpos_z800.rtl --displacement -800 --datum -560 -o Xpitch-residual.rta
      esp angular Xpos_z0.rtl Xpos_z800.rtl --displacement -800 --datum 0 --json -
      esp angular Xpos_z0.rtl Xpos_z800.rtl --displacement -800 --datum -560 --out pitch
    """
    # every target is checked before the files are read, and written last, all or none
    outputs = CommandOutputs([reference, shifted], json_target, quiet)
    rta_path = outputs.file(output, "--output") if output is not None else None
    out = outputs.folder(out_dir, "--out") if out_dir is not None else None
    if out is not None:
        from esp.report.epoch import source_date_epoch

        source_date_epoch()  # a malformed SOURCE_DATE_EPOCH is refused before any work
    if output is not None:
        implied = kind_from_extension(output)
        if implied is not None and implied != "angular":
            raise DataError(
                f"--output {output}: the extension {output.suffix!r} is for {implied} data; "
                "expected an angular file name such as OUT.rta"
            )
    ref, sh = (_load_linear(path, unit) for path in (reference, shifted))
    result = angular_from_linear(ref, sh, displacement_mm, datum_mm, direction)
    text = angular_text(result)
    if output is not None:
        text += f"\nwritten {one_line(output)}\n"
    with outputs:
        if rta_path is not None:
            outputs.write_file(rta_path, format_laser10(result.profile))
        if out is not None:
            write_angular_report(outputs.stage_folder(out), result, text, outputs.provenance)
        outputs.finish(text=text, doc=result.to_dict)
