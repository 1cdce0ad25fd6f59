"""``esp ballbar``: the ISO 230-4 circular test of a ballbar file, with a first-order
diagnosis in terms of the machine's error components."""

from __future__ import annotations

import click

__all__ = ["ballbar_command"]


@click.command("ballbar")
@click.argument("file", type=click.Path(dir_okay=False, path_type=str))
@click.option("--json", "json_target", metavar="PATH|-", help="Write the result as JSON.")
@click.option(
    "--out",
    "out_dir",
    metavar="DIR",
    type=click.Path(file_okay=False, path_type=str),
    help="Write ballbar.txt, ballbar.json and polar.png into DIR.",
)
@click.option("--quiet", "-q", is_flag=True, help="Print nothing on the terminal but errors.")
def ballbar_command(file: str, json_target: str | None, out_dir: str | None, quiet: bool) -> None:
    """Circular deviation, circular hysteresis and radial deviation (ISO 230-4) of every
    circle in FILE (the lengths table of esp identify, docs/formats.md), bidirectional
    where the file has both directions, and the diagnosis: scale difference and
    out-of-squareness of the plane's axes from the ellipse, backlash from the steps at the
    axis reversals (reported beyond 3 standard uncertainties of the noise it states).
    Readings that cannot be right are refused at their file and line.

    \b
    Examples:
      esp ballbar data/examples/identify/tool-ballbar/circle-XY.csv
      esp ballbar data/examples/identify/tool-ballbar/circle-XY.csv --out circle-report
    """
    from esp.cli.output import CommandOutputs
    from esp.identify.ballbar import ballbar_dict, ballbar_text, circle_tests, polar_figure

    outputs = CommandOutputs([file], json_target, quiet)
    out = outputs.folder(out_dir, "--out") if out_dir else None
    tests = circle_tests(file)
    doc = ballbar_dict(tests)
    text = ballbar_text(tests)
    with outputs:
        if out is not None:
            from esp.report.profile_plots import save_png

            folder = outputs.stage_folder(out)
            doc = outputs.write_documents(folder, "ballbar", text, doc)
            save_png(polar_figure(tests), folder / "polar.png")
        outputs.finish(text=text, doc=doc)
