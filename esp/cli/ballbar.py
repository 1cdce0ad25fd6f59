"""``esp ballbar``: the ISO 230-4 circular test of a ballbar file, its diagnosis in terms of
the machine's errors, a test report and verdicts against tolerances."""

from __future__ import annotations

import click

from esp.cli.options import Number, decision_options
from esp.core.values import Quantity

__all__ = ["ballbar_command"]

_RADIUS = Quantity("a radius", "mm", 0.0, 1e5, above_low=True)
_FEED = Quantity("a feed", "mm/min", 0.0, 1e6, above_low=True)
_SPEC = Quantity("a ballbar specification", "um", 0.0, 1e4, above_low=True)


@click.command("ballbar")
@click.argument("file", type=click.Path(dir_okay=False, path_type=str))
@click.option("--json", "json_target", metavar="PATH|-", help="Write the result as JSON.")
@click.option(
    "--out",
    "out_dir",
    metavar="DIR",
    type=click.Path(file_okay=False, path_type=str),
    help="Write report.pdf (the ISO 230-4 test report), ballbar.txt, ballbar.json and "
    "polar.png into DIR.",
)
@click.option("--radius", type=Number(_RADIUS), metavar="MM", help="Radius of an angle file (mm).")
@click.option("--plane", metavar="AB", help="Plane of an angle file (XY, YZ, ZX; default XY).")
@click.option("--feed", type=Number(_FEED), metavar="MM/MIN", help="Feed of the test.")
@click.option("--machine", metavar="TEXT", help="The machine tested.")
@click.option("--date", "test_date", metavar="TEXT", help="The date of the test.")
@click.option("--operator", metavar="TEXT", help="Who ran the test.")
@click.option("--ballbar", "instrument", metavar="TEXT", help="The ballbar (maker, serial).")
@click.option(
    "--calibration-u",
    type=Number(_SPEC),
    metavar="UM",
    help="Expanded uncertainty (k = 2) of the ballbar's calibrated length, µm.",
)
@click.option("--accuracy", type=Number(_SPEC), metavar="UM", help="The ballbar's accuracy ± (µm).")
@click.option(
    "--resolution", type=Number(_SPEC), metavar="UM", help="The ballbar's resolution (µm)."
)
@decision_options(
    "A tolerance in µm for F, G, Gb or H (repeatable): each circle's figure is decided against it.",
    "the ballbar's specification",
)
@click.option("--quiet", "-q", is_flag=True, help="Print nothing on the terminal but errors.")
@click.pass_context
def ballbar_command(
    ctx: click.Context,
    file: str,
    json_target: str | None,
    out_dir: str | None,
    radius: float | None,
    plane: str | None,
    feed: float | None,
    machine: str | None,
    test_date: str | None,
    operator: str | None,
    instrument: str | None,
    calibration_u: float | None,
    accuracy: float | None,
    resolution: float | None,
    tolerances: tuple[str, ...],
    rule: str,
    guard: float,
    quiet: bool,
) -> None:
    """Circular deviation G, circular hysteresis H and radial deviation F (ISO 230-4) of
    every circle in FILE, and the diagnosis: scale mismatch, scaling error (calibrated
    ballbar), out-of-squareness, servo mismatch, backlash per axis and end, lateral play,
    reversal spikes, stick-slip, straightness (bow), cyclic error -- each with its U and
    reported beyond its coverage of the noise (docs/ballbar.md).

    FILE is the lengths table of esp identify (docs/formats.md) or an angle table of a
    home-made ballbar (columns angle, deviation, optional direction; '# radius:' or
    --radius). '# key: value' lines state the test conditions; the options override
    them. With --tolerance, the exit code is 0 when every figure conforms, 1 when one
    does not, 3 when one is not decided (2: an error).

    \b
    Examples:
      esp ballbar data/examples/ballbar/circle-XY.csv
      esp ballbar data/examples/ballbar/circle-XY.csv --out circle-report
      esp ballbar data/examples/ballbar/circle-XY.csv --tolerance G=15 --rule guarded
      esp ballbar data/examples/ballbar/homemade.csv --radius 100 --feed 500
    """
    from esp.ballbar.analysis import circle_tests
    from esp.ballbar.text import ballbar_dict, ballbar_text
    from esp.ballbar.verdicts import decisions, parse_tolerances
    from esp.cli.output import CommandOutputs
    from esp.core.conformity import DecisionRule, exit_code

    limits = parse_tolerances(tolerances)
    decision_rule = DecisionRule("guarded" if rule == "guarded" else "simple", guard, key="--rule")
    outputs = CommandOutputs([file], json_target, quiet)
    out = outputs.folder(out_dir, "--out") if out_dir else None
    if out is not None:
        from esp.report.epoch import source_date_epoch

        source_date_epoch()  # a malformed SOURCE_DATE_EPOCH is refused before any work
    given = {
        "feed_mm_per_min": feed,
        "machine": machine,
        "date": test_date,
        "operator": operator,
        "ballbar": instrument,
        "calibration_U_um": calibration_u,
        "accuracy_um": accuracy,
        "resolution_um": resolution,
    }
    tests = circle_tests(file, radius_mm=radius, plane=plane, conditions=given)
    decided = decisions(tests, limits, decision_rule)
    doc = ballbar_dict(tests, decided)
    text = ballbar_text(tests, decided)
    with outputs:
        if out is not None:
            from esp.ballbar.plots import polar_figure
            from esp.ballbar.report import write_ballbar_report
            from esp.report.profile_plots import save_png

            folder = outputs.stage_folder(out)
            doc = outputs.write_documents(folder, "ballbar", text, doc)
            fig = polar_figure(tests)
            save_png(fig, folder / "polar.png")
            write_ballbar_report(folder, tests, decided, fig, provenance=outputs.provenance)
        outputs.finish(text=text, doc=doc)
    code = exit_code(decided)
    if code:
        ctx.exit(code)
