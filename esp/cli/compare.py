"""``esp compare``: two calibrations of one machine."""

from __future__ import annotations

import click

from esp.cli.options import Number
from esp.core.values import Quantity

__all__ = ["compare_command"]


@click.command("compare")
@click.argument("before_toml", type=click.Path(dir_okay=False, path_type=str))
@click.argument("after_toml", type=click.Path(dir_okay=False, path_type=str))
@click.option("--json", "json_target", metavar="PATH|-", help="Write the comparison as JSON.")
@click.option(
    "--out",
    "out_dir",
    metavar="DIR",
    type=click.Path(file_okay=False, path_type=str),
    help="Write compare.json, compare.txt, report.pdf and the figures into DIR.",
)
@click.option(
    "--correlation",
    type=Number(Quantity("a correlation coefficient", "", 0.0, 1.0)),
    default=0.0,
    show_default=True,
    metavar="R",
    help="Correlation coefficient of the two calibrations' uncertainties, 0 to 1 (the same "
    "instrument, operator or set-up); 0: independent.",
)
@click.option("--quiet", "-q", is_flag=True, help="Print nothing on the terminal but errors.")
def compare_command(
    before_toml: str,
    after_toml: str,
    json_target: str | None,
    out_dir: str | None,
    correlation: float,
    quiet: bool,
) -> None:
    """Compare two calibrations of one machine, BEFORE_TOML and AFTER_TOML.

    Reports the change of every component (largest |after - before| and where), the
    volumetric and planar accuracy of each calibration and their change, and where the
    error field changed most, each change with its expanded uncertainty U(Δ) from both
    calibrations' [uncertainty] tables and its normalised error En = |Δ| / U(Δ): a change
    with En <= 1 is not significant. Two machines that are not the same machine (configuration,
    axes, travel or serial number differ) are refused.

    \b
    Examples:
      esp compare data/examples/gantry/machine.toml data/examples/gantry-2024/machine.toml
      esp compare data/examples/gantry/machine.toml data/examples/gantry-2024/machine.toml \\
          --out drift
      esp compare data/examples/gantry/machine.toml data/examples/gantry-2024/machine.toml \\
          --correlation 0.5
    """
    from esp.cli.output import CommandOutputs
    from esp.compare.model import compare
    from esp.compare.text import compare_dict, compare_text
    from esp.config import load_machine

    before = load_machine(before_toml)
    after = load_machine(after_toml)
    outputs = CommandOutputs(list(before.inputs) + list(after.inputs), json_target, quiet)
    out = outputs.folder(out_dir, "--out") if out_dir else None
    result = compare(before, after, correlation)
    warnings = [f"before: {w}" for w in before.warnings] + [f"after: {w}" for w in after.warnings]
    doc = {**compare_dict(before, after, result), "warnings": warnings}
    text = compare_text(before, after, result)
    with outputs:
        if out is not None:
            from esp.compare.plots import change_figure, changes_figure, curves_figure
            from esp.report.profile_plots import save_png

            folder = outputs.stage_folder(out)
            doc = outputs.write_documents(folder, "compare", text, doc)
            title = f"Change between two calibrations: {before.name}"
            changes = changes_figure(title, result)
            change = change_figure(title, result)
            curves = curves_figure(title, result)
            save_png(changes, folder / "compare-components.png")
            save_png(change, folder / "compare-change.png")
            save_png(curves, folder / "compare-curves.png")
            from esp.compare.text import write_compare_pdf

            write_compare_pdf(
                folder / "report.pdf",
                before,
                after,
                result,
                text,
                [changes, change, curves],
                outputs.provenance,
            )
        outputs.finish(text=text, doc=doc, warnings=warnings)
