"""``esp iso230-2``: ISO 230-2 accuracy and repeatability of positioning of one axis."""

from __future__ import annotations

import re
from pathlib import Path

import click

from esp.cli import options
from esp.cli.output import CommandOutputs
from esp.core.errors import DataError
from esp.core.values import Quantity
from esp.io.load import load_profile
from esp.io.textfile import read_text
from esp.iso230.positioning import iso230_2
from esp.iso230.text import iso230_text, vdi_text

__all__ = ["iso230_command"]

_PPM = Quantity("an accuracy", "um/m", 0.0, 1e3, above_low=True)
_MISALIGN = Quantity("a misalignment", "mm", 0.0, 100.0)
_SENSOR = Quantity("a sensor accuracy", "degC", 0.0, 10.0)
_EVE = Quantity("an environmental variation error", "um", 0.0, 1e3)
_ARCSEC = Quantity("an angular accuracy", "arcsec", 0.0, 3600.0, above_low=True)

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
@click.option(
    "--laser-accuracy",
    type=options.Number(_PPM),
    metavar="UM/M",
    help="The laser system's stated accuracy ± with its environmental compensation "
    "(µm/m): with --misalignment, gives each figure's U.",
)
@click.option(
    "--misalignment",
    type=options.Number(_MISALIGN),
    metavar="MM",
    help="The beam's largest offset from the axis over the travel (mm).",
)
@click.option(
    "--material-sensor",
    type=options.Number(_SENSOR),
    metavar="DEGC",
    help="The material temperature sensor's stated accuracy ± (°C).",
)
@click.option(
    "--eve",
    type=options.Number(_EVE),
    metavar="UM",
    help="The environmental variation error of a drift test over the test's duration "
    "(µm; default: the thesis' table 3.2 for the file's duration).",
)
@click.option(
    "--calibrator-accuracy",
    type=options.Number(_ARCSEC),
    metavar="ARCSEC",
    help="A rotary axis: the rotary calibrator's stated accuracy ± (arcsec); with --eve "
    "in arcsec, each figure's U.",
)
@click.option(
    "--air-compensation",
    type=click.Choice(["included", "fixed"]),
    default="included",
    show_default=True,
    help="How the laser compensated the air: within its stated accuracy, or fixed at the "
    "start (the air's change over the test, from the file, then enters U).",
)
@click.option("--feed", metavar="TEXT", help="Test condition: the feed (e.g. '2000 mm/min').")
@click.option("--dwell", metavar="TEXT", help="Test condition: the dwell at each target.")
@click.option("--instrument", metavar="TEXT", help="Test condition: the instrument.")
@click.option(
    "--measuring-line", metavar="TEXT", help="Test condition: where the measuring line lies."
)
@click.option("--machine", metavar="TEXT", help="Test condition: the machine.")
@click.option("--operator", metavar="TEXT", help="Test condition: who ran the test.")
@options.decision_options(
    "A tolerance for an axis figure (A, B, E, M, R or a one-direction form; repeatable), in "
    "µm, or arcsec for a rotary axis: exit 0 conforms, 1 does not, 3 not decided.",
    "U",
)
@click.option("--quiet", "-q", is_flag=True, help="Print nothing on the terminal but errors.")
@click.pass_context
def iso230_command(
    ctx: click.Context,
    file: Path,
    unit: str | None,
    json_target: str | None,
    plot_path: Path | None,
    out_dir: Path | None = None,
    vdi3441: bool = False,
    laser_accuracy: float | None = None,
    misalignment: float | None = None,
    material_sensor: float | None = None,
    eve: float | None = None,
    calibrator_accuracy: float | None = None,
    air_compensation: str = "included",
    feed: str | None = None,
    dwell: str | None = None,
    instrument: str | None = None,
    measuring_line: str | None = None,
    machine: str | None = None,
    operator: str | None = None,
    tolerances: tuple[str, ...] = (),
    rule: str = "simple",
    guard: float = 1.0,
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

    The test conditions the file records (date and time, air and material temperatures,
    expansion compensation) are listed with those given as options. With --laser-accuracy
    and --misalignment (and the file's duration and temperatures), each figure is stated
    with its U (ISO 230-2 Annex A contributors, docs/iso230-2.md); with --tolerance, each
    figure is decided under --rule.

    A CSV with '# kind: rotary' and a target_deg column holds a rotary axis' runs: its
    figures are in arcsec, with --calibrator-accuracy and --eve (arcsec) for their U.

    \b
    Examples:
      esp iso230-2 data/examples/gantry/X-linear.rtl
      esp iso230-2 data/examples/gantry/X-linear.rtl --json - > X-iso230.json
      esp iso230-2 data/examples/gantry/X-linear.rtl --json X.json --plot X.png
      esp iso230-2 data/examples/gantry/X-linear.rtl --vdi3441
      esp iso230-2 data/examples/gantry/X-linear.rtl --out X-iso230-report
      esp iso230-2 data/examples/gantry/X-linear.rtl --laser-accuracy 0.5 --misalignment 0.5
      esp iso230-2 data/examples/gantry/X-linear.rtl --tolerance A=16 --tolerance R=6
      esp iso230-2 data/examples/rotary/C-positioning.csv --calibrator-accuracy 1 --eve 0.5
    """
    from esp.core.conformity import DecisionRule, exit_code
    from esp.iso230.statement import (
        LaserSetup,
        conditions_of,
        conditions_of_given,
        decisions,
        parse_tolerances,
        uncertainty,
    )

    limits = parse_tolerances(tolerances)
    decision_rule = DecisionRule("guarded" if rule == "guarded" else "simple", guard, key="--rule")
    # every target is checked before the file is read, and written last, all or none
    outputs = CommandOutputs([file], json_target, quiet)
    png_path = outputs.figure(plot_path, "--plot") if plot_path is not None else None
    out = outputs.folder(out_dir, "--out") if out_dir is not None else None
    if out is not None:
        from esp.report.epoch import source_date_epoch

        source_date_epoch()  # a malformed SOURCE_DATE_EPOCH is refused before any work
    from esp.iso230.rotary import is_rotary_file

    rotary = file.suffix.lower() == ".csv" and file.is_file() and is_rotary_file(read_text(file))
    given = {
        "feed": feed,
        "dwell": dwell,
        "instrument": instrument,
        "measuring_line": measuring_line,
        "machine": machine,
        "operator": operator,
    }
    if rotary:
        from esp.iso230.rotary import (
            RotarySetup,
            read_rotary,
            rotary_iso230_2,
            rotary_uncertainty,
        )

        linear_only = {
            "--laser-accuracy": laser_accuracy,
            "--misalignment": misalignment,
            "--material-sensor": material_sensor,
            "--unit": unit,
            "--vdi3441": vdi3441 or None,
            "--air-compensation": None if air_compensation == "included" else air_compensation,
        }
        for option, value in linear_only.items():
            if value is not None:
                raise DataError(
                    f"{option}: applies to a linear axis; {file} holds a rotary axis "
                    "(its '# unit:' line states the unit; --calibrator-accuracy and --eve "
                    "give its U)"
                )
        runs = read_rotary(file)
        result = rotary_iso230_2(runs)
        conditions = conditions_of_given(given)
        stated_u = rotary_uncertainty(result, RotarySetup(calibrator_accuracy, eve))
        profile = None
    else:
        if calibrator_accuracy is not None:
            raise DataError(
                f"--calibrator-accuracy: applies to a rotary axis ('# kind: rotary'); {file} "
                "holds a linear axis"
            )
        profile = load_profile(file, kind=_kind_for(file), unit=unit)
        result = iso230_2(profile)
        conditions = conditions_of(profile, given)
        stated_u = uncertainty(
            result,
            profile,
            LaserSetup(
                laser_accuracy,
                misalignment,
                material_sensor,
                eve_um=eve,
                air_compensation=air_compensation,
            ),
        )
    decided = decisions(result, limits, decision_rule, stated_u)
    vdi = None
    if vdi3441 and profile is not None:
        from esp.iso230.vdi3441 import vdi3441 as vdi_figures

        vdi = vdi_figures(profile)
    doc = result.to_dict()
    doc["conditions"] = [{"item": k, "value": v} for k, v in conditions]
    doc["uncertainty"] = stated_u.as_dict()
    doc["decisions"] = [d.as_dict() for d in decided]
    if vdi is not None:
        doc["vdi3441"] = vdi.to_dict()
    text = iso230_text(result, conditions, stated_u, decided) + (
        vdi_text(vdi) if vdi is not None else ""
    )
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
                conditions=conditions,
                u=stated_u,
                decided=decided,
            )
        outputs.finish(text=text, doc=doc)
    code = exit_code(decided)
    if code:
        ctx.exit(code)
