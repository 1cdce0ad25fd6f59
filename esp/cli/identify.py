"""``esp identify``: the machine's error components identified from indirect measurements
(ball plates, ballbars and machine checking gauges, diagonals, tracking interferometers;
probed spheres, R-tests and ballbars on rotary axes), with their identifiability and
uncertainty (docs/identify.md)."""

from __future__ import annotations

import click

__all__ = ["identify_command"]


@click.command("identify")
@click.argument("machine_toml", type=click.Path(dir_okay=False, path_type=str))
@click.option(
    "--plan",
    is_flag=True,
    help="Identifiability and expected uncertainties of a proposed plan (files of positions "
    "only; nothing is fitted).",
)
@click.option(
    "--montecarlo",
    type=click.IntRange(2, 10000),
    metavar="N",
    help="Also re-fit N simulated data sets (JCGM 101) and compare their spread.",
)
@click.option(
    "--seed", type=click.IntRange(0), default=1, show_default=True, help="Monte Carlo seed."
)
@click.option("--json", "json_target", metavar="PATH|-", help="Write the result as JSON.")
@click.option(
    "--out",
    "out_dir",
    metavar="DIR",
    type=click.Path(file_okay=False, path_type=str),
    help="Write the identified machine (machine.toml and CSV profiles) and the report "
    "(identify.txt, identify.json, identify.pdf, identify.png, residuals.png) into DIR.",
)
@click.option(
    "--suggest",
    type=click.IntRange(1, 100),
    metavar="N",
    help="With --plan: the N best extra probings of the plan's probed sphere, from the "
    "settings of [table].angles, with the rank and the U of the table's errors each gives.",
)
@click.option("--quiet", "-q", is_flag=True, help="Print nothing on the terminal but errors.")
def identify_command(
    machine_toml: str,
    plan: bool,
    suggest: int | None,
    montecarlo: int | None,
    seed: int,
    json_target: str | None,
    out_dir: str | None,
    quiet: bool,
) -> None:
    """Identify the components marked { identify = ... } in MACHINE_TOML from the
    measurement sets of its [identify] table.

    The identifiability comes first: the singular values of the weighted design matrix,
    its rank and condition number, and every combination the data cannot see, named in
    esp's component names. Such combinations are refused (exit 2) unless identify.fix
    fixes them or identify.null = "minimum-norm" is chosen; --plan prints its report
    and then refuses them the same way. The identified curves come
    with their expanded uncertainty from the stated uncertainties of the readings, and
    the volumetric accuracy with its uncertainty from the full covariance. A fit far
    beyond the stated uncertainties (Birge ratio above 3 and chi2 above its 99.9 %
    quantile) is refused unless identify.inconsistent = "accept"; a design too large to
    solve is refused before it is built.

    \b
    Examples:
      esp identify data/examples/identify/cmm-ballplate/machine.toml
      esp identify data/examples/identify/cmm-ballplate/machine.toml --out cmm-identified
      esp analyse cmm-identified/machine.toml
      esp identify data/examples/identify/tool-ballbar/machine.toml --plan
      esp identify data/examples/identify/trunnion-spheres/machine.toml --out trunnion
      esp identify data/examples/identify/trunnion-spheres/machine.toml --plan --suggest 3
    """
    from pathlib import Path

    from esp.cli.output import CommandOutputs
    from esp.identify.config import load_problem
    from esp.identify.render import identify_dict, identify_text
    from esp.identify.run import identify
    from esp.identify.run import plan as plan_of

    if plan and montecarlo:
        raise click.BadParameter("a plan has no readings to re-fit", param_hint="--montecarlo")
    if suggest and not plan:
        raise click.BadParameter(
            "suggests extra probings of a plan: give --plan too", param_hint="--suggest"
        )
    problem = load_problem(machine_toml)
    outputs = CommandOutputs(problem.inputs, json_target, quiet)
    out = outputs.folder(out_dir, "--out") if out_dir else None
    result = plan_of(problem) if plan else identify(problem, montecarlo or 0, seed)
    # the fit's warnings (a Birge ratio beyond its limit, a minimum-norm choice) go to
    # standard error and the JSON as the machine's do; a plan's unseen combinations are its
    # report (and its refusal below), not warnings
    warnings = problem.machine.warnings if plan else result.warnings
    doc = {**identify_dict(result), "warnings": list(warnings)}
    text = identify_text(result)
    if suggest:
        from dataclasses import asdict

        from esp.identify.suggest import suggest as suggest_of
        from esp.identify.suggest import suggestion_lines

        now, found = suggest_of(problem, suggest)
        text += "\n".join(suggestion_lines(now, found)) + "\n"
        doc["suggestions"] = {
            "as_planned": asdict(now) if now else None,
            "extra": [asdict(g) for g in found],
        }
    with outputs:
        if out is not None:
            from esp.identify.render import (
                axis_figure,
                curves_figure,
                residuals_figure,
                table_axes,
                write_pdf,
            )
            from esp.identify.write import write_identified
            from esp.report.profile_plots import save_png

            folder = outputs.stage_folder(out)
            curves = curves_figure(result)
            save_png(curves, folder / "identify.png")
            residuals = None  # a plan has no residuals
            if not plan:
                write_identified(folder, problem, result, Path(out))
                residuals = residuals_figure(result)
                save_png(residuals, folder / "residuals.png")
            axes = []
            for axis in table_axes(result):
                axes.append(axis_figure(result, axis))
                save_png(axes[-1], folder / f"axis-{axis}.png")
            doc = outputs.write_documents(folder, "identify", text, doc)
            write_pdf(
                folder / "identify.pdf", result, [curves, residuals, *axes], outputs.provenance
            )
        outputs.finish(text=text, doc=doc, warnings=warnings)
    ident = result.identifiability
    if plan and not ident.identifiable and problem.null == "refuse":
        # the report above says what the plan sees; a plan that cannot see what is asked
        # fails as identify would, so that a script comparing plans sees it
        from esp.identify.solve import IdentifyError

        raise IdentifyError(
            "the plan cannot see: "
            + "; ".join(ident.sentences())
            + " (add a pose, station or tool offset, fix with identify.fix = [...], or choose "
            'identify.null = "minimum-norm"; docs/identify.md)'
        )
