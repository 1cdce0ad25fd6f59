"""``esp angular``: an angular error from two linear positioning files (indirect method)."""

from __future__ import annotations

from pathlib import Path, PurePath
from typing import TYPE_CHECKING

import click

from esp.cli import one_line, options
from esp.cli.output import CommandOutputs
from esp.core.angular import IndirectAngle, angular_from_linear
from esp.core.errors import DataError
from esp.core.units import MIN_SPACING_MM
from esp.io.laser10 import format_laser10, kind_from_extension
from esp.io.load import load_profile
from esp.report.profile_text import format_table

if TYPE_CHECKING:
    from esp.core.profile import ErrorProfile
    from esp.report.provenance import Provenance

__all__ = ["angular_command", "angular_text"]

_DIRECTION_WORDS = {"forward": "forward", "backward": "reverse", "mean": "bidirectional mean"}


def _num(value: float) -> str:
    text = f"{value:.3f}"
    return "0.000" if text == "-0.000" else text


def _name(source: str | None) -> str:
    return one_line(PurePath(source).name) if source else "-"


def angular_text(result: IndirectAngle) -> str:
    """The terminal summary: the set-up, then position / forward / backward / mean angle."""
    p = result.profile
    runs = ", ".join(f"{d} {p.run_count(d)}" for d in ("forward", "backward"))
    lines = [
        f"reference     {_name(result.reference)}",
        f"shifted       {_name(result.shifted)}, displaced by {result.displacement_mm:g} mm",
        f"datum         {result.datum_mm:g} mm ({_DIRECTION_WORDS[result.direction]} angle "
        "zero there)",
        f"runs          {runs}",
        "method        angle = 1000 x (shifted - reference) / displacement, less its datum "
        "value (Longstaff 2002, 3.08.1)",
        "meaning       the slope of the axis' error along the displacement: the angle whose "
        "lever reproduces the difference of the two runs; a from_linear source in "
        "machine.toml reads it with the sign of that term in the machine's model "
        "(docs/conventions.md)",
        "",
        "angle (µm/m)",
    ]
    curves = {d: result.curve(d) for d in ("forward", "backward", "mean")}
    headers = ["position_mm", "forward", "backward", "mean"]
    rows = []
    for i, t in enumerate(result.targets_mm):
        row = [f"{float(t):.3f}"]
        row += ["-" if c is None else _num(float(c[i])) for c in curves.values()]
        rows.append(row)
    lines.append(format_table(headers, rows, indent="  "))
    chosen = curves[result.direction]
    assert chosen is not None  # angular_from_linear refuses a direction without runs
    lines += [
        "",
        f"{_DIRECTION_WORDS[result.direction]} angle from {_num(float(chosen.min()))} to "
        f"{_num(float(chosen.max()))} µm/m (range {_num(float(chosen.max() - chosen.min()))})",
    ]
    return "\n".join(lines) + "\n"


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
    outputs = CommandOutputs([reference, shifted], json_target)
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
            _write_report(outputs.stage_folder(out), result, text, outputs.provenance)
        outputs.finish(text=text, doc=result.to_dict)


def _write_report(folder: Path, result: IndirectAngle, text: str, provenance: Provenance) -> None:
    """``report.pdf``, ``angular.png`` and ``result.json`` of ``--out``: the document in
    the style of every esp report (:mod:`esp.report.document`)."""
    from esp.report.document import (
        Document,
        Headline,
        summary,
        text_report,
        title_fields,
        user_text_value,
    )
    from esp.report.jsonout import dumps
    from esp.report.pdf import report_date
    from esp.report.profile_plots import profile_runs_figure, save_png

    (folder / "result.json").write_text(
        dumps({**result.to_dict(), "provenance": provenance.to_dict()}), encoding="utf-8"
    )
    fig = profile_runs_figure(result.profile)
    save_png(fig, folder / "angular.png")
    chosen = result.curve(result.direction)
    assert chosen is not None
    machine = user_text_value(provenance, ("machine", "machine name"))
    files = f"{_name(result.reference)} and {_name(result.shifted)}"
    doc = Document(
        "Angular error from two linear measurements",
        f"{machine}: {files}" if machine else files,
        report_date(),
        title_fields(provenance=provenance),
    )
    word = _DIRECTION_WORDS[result.direction]
    summary(
        doc.lay,
        [
            Headline(
                f"Range of the {word} angle", f"{_num(float(chosen.max() - chosen.min()))} µm/m"
            ),
            Headline("Smallest", f"{_num(float(chosen.min()))} µm/m"),
            Headline("Largest", f"{_num(float(chosen.max()))} µm/m"),
        ],
    )
    doc.lay.paragraph(
        "Uncertainty: not evaluated (the angle is derived from the two measurements as given).",
        size=8.3,
        colour="0.3",
    )
    head, _, rest = text.partition("\n\n")
    doc.section("Set-up")
    pairs = []
    for line in head.splitlines():
        key, _, value = line.partition(" ")
        pairs.append((key.capitalize(), value.strip()))
    doc.lay.pairs(pairs)
    doc.section("Angle at every target")
    text_report(doc.lay, rest.split("\n\nwritten ")[0], skip=1)
    doc.figure(fig, "the angle of every run against position")
    doc.write(folder / "report.pdf", provenance)
