"""``esp compare``: two calibrations of one machine."""

from __future__ import annotations

import click

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
    help="Write compare.json, compare.txt and the figures into DIR.",
)
@click.option("--quiet", "-q", is_flag=True, help="Print nothing on the terminal but errors.")
def compare_command(
    before_toml: str, after_toml: str, json_target: str | None, out_dir: str | None, quiet: bool
) -> None:
    """Compare two calibrations of one machine, BEFORE_TOML and AFTER_TOML.

    Reports the change of every component (largest |after - before| and where), the
    volumetric and planar accuracy of each calibration and their change, and where the
    error field changed most. Two machines that are not the same machine (configuration,
    axes, travel or serial number differ) are refused.

    \b
    Examples:
      esp compare data/examples/gantry/machine.toml data/examples/gantry-2024/machine.toml
      esp compare data/examples/gantry/machine.toml data/examples/gantry-2024/machine.toml \\
          --out drift
    """
    from esp.cli.output import CommandOutputs
    from esp.compare.model import compare
    from esp.compare.text import compare_dict, compare_text
    from esp.config import load_machine

    before = load_machine(before_toml)
    after = load_machine(after_toml)
    outputs = CommandOutputs(list(before.inputs) + list(after.inputs), json_target, quiet)
    out = outputs.folder(out_dir, "--out") if out_dir else None
    result = compare(before, after)
    warnings = [f"before: {w}" for w in before.warnings] + [f"after: {w}" for w in after.warnings]
    doc = {**compare_dict(before, after, result), "warnings": warnings}
    text = compare_text(before, after, result)
    with outputs:
        if out is not None:
            from esp.compare.plots import changes_figure, curves_figure
            from esp.report.profile_plots import save_png

            folder = outputs.stage_folder(out)
            doc = outputs.write_documents(folder, "compare", text, doc)
            title = f"Change between two calibrations: {before.name}"
            changes = changes_figure(title, result)
            curves = curves_figure(title, result)
            save_png(changes, folder / "compare-components.png")
            save_png(curves, folder / "compare-curves.png")
            from esp.compare.text import write_compare_pdf

            write_compare_pdf(
                folder / "report.pdf",
                before,
                after,
                result,
                text,
                [changes, curves],
                outputs.provenance,
            )
        outputs.finish(text=text, doc=doc, warnings=warnings)
