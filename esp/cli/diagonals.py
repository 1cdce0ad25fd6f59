"""``esp diagonals``: ISO 230-6 body and face diagonals predicted from the 21 components,
and checked against measured diagonal files."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import click

from esp.cli import options

__all__ = ["diagonals_command"]


def _parse_measured(items: Sequence[str]) -> dict[str, str]:
    out = {}
    for item in items:
        name, sep, path = item.partition("=")
        name = name.strip().upper().replace("_", "-")
        if not sep or not path.strip():
            raise click.BadParameter(
                f"expected NAME=FILE such as PPP=PPP.rtl, found {item!r}", param_hint="--measured"
            )
        if name in out:
            raise click.BadParameter(f"{name} is given twice", param_hint="--measured")
        out[name] = path.strip()
    return out


@click.command("diagonals")
@click.argument("machine_toml", type=click.Path(dir_okay=False, path_type=str))
@click.option("--faces", is_flag=True, help="Also the two diagonals of each face plane.")
@click.option(
    "--face-at",
    metavar="AXIS=MM,..",
    help="Where the third axis stands for the face diagonals (default: its low end).",
)
@click.option(
    "--step",
    type=options.Number("step"),
    metavar="MM",
    help="Target spacing along the diagonals (default: the measured files' step, "
    "else the longest diagonal in 20 steps).",
)
@click.option(
    "--measured",
    "measured",
    multiple=True,
    metavar="NAME=FILE",
    help="A measured diagonal (Laser10 linear file or CSV, µm), e.g. PPP=ppp.rtl.",
)
@click.option("--unit", metavar="U", help="Unit of the measured deviations (default µm).")
@click.option(
    "--measurement-u",
    "u_const",
    type=options.Number("uncertainty"),
    default=0.0,
    show_default=True,
    metavar="UM",
    help="Expanded uncertainty (k = 2) of the diagonal measurement, constant part (µm).",
)
@click.option(
    "--measurement-u-per-m",
    "u_per_m",
    type=options.Number("uncertainty per metre"),
    default=0.0,
    show_default=True,
    metavar="UM",
    help="Length-proportional part of that uncertainty (µm per metre of diagonal).",
)
@click.option("--json", "json_target", metavar="PATH|-", help="Write the result as JSON.")
@click.option(
    "--out",
    "out_dir",
    metavar="DIR",
    type=click.Path(file_okay=False, path_type=str),
    help="Write diagonals.json, diagonals.txt and diagonals.png into DIR.",
)
@click.option("--quiet", "-q", is_flag=True, help="Print nothing on the terminal but errors.")
def diagonals_command(
    machine_toml: str,
    faces: bool,
    face_at: str | None,
    step: float | None,
    measured: tuple[str, ...],
    unit: str | None,
    u_const: float,
    u_per_m: float,
    json_target: str | None,
    out_dir: str | None,
    quiet: bool,
) -> None:
    """ISO 230-6 diagonal displacement errors of the machine in MACHINE_TOML.

    Predicts, from the 21 components and the machine's model, the displacement error
    along the four body diagonals (PPP, NPP, PNP, PPN: P/N says whether X, Y, Z increase
    or decrease along the diagonal) and, with --faces, the face diagonals (XY-PP, XY-NP,
    ...), relative to each diagonal's start. With --measured files, reports measured minus
    predicted and whether the model explains the measurement: E_n = |difference| / U <= 1
    at every target, U combining the prediction's uncertainty ([uncertainty] table) and
    the measurement's (--measurement-u, --measurement-u-per-m).

    \b
    Examples:
      esp diagonals data/examples/gantry/machine.toml
      esp diagonals data/examples/gantry/machine.toml --faces --out gantry-diagonals
      esp diagonals data/examples/gantry/machine.toml \\
          --measured PPP=data/examples/gantry-diagonals/PPP.rtl \\
          --measured NPP=data/examples/gantry-diagonals/NPP.rtl --measurement-u 1.5
    """
    from esp.cli.compensate import parse_pairs
    from esp.cli.output import CommandOutputs
    from esp.config import load_machine
    from esp.core.errors import DataError
    from esp.core.evaluation import evaluate
    from esp.diagonals.model import (
        body_diagonals,
        check_diagonal,
        default_step,
        diagonal_targets,
        face_diagonals,
        predict_diagonal,
    )
    from esp.diagonals.text import diagonals_dict, diagonals_text
    from esp.io.load import load_profile

    face_pos = parse_pairs(face_at, "--face-at")
    files = _parse_measured(measured)
    machine = load_machine(machine_toml)
    outputs = CommandOutputs(list(machine.inputs) + list(files.values()), json_target, quiet)
    out = outputs.folder(out_dir, "--out") if out_dir else None

    diagonals = body_diagonals(machine)
    if faces or any("-" in n for n in files):
        diagonals += face_diagonals(machine, face_pos)
    by_name = {d.name: d for d in diagonals}
    unknown = [n for n in files if n not in by_name]
    if unknown:
        raise DataError(
            f"--measured {unknown[0]}: unknown diagonal; expected one of {', '.join(by_name)}"
        )
    profiles = {n: load_profile(Path(p), kind="linear", unit=unit) for n, p in files.items()}
    if step is None and profiles:
        first = next(iter(profiles.values()))
        if first.targets_mm.size < 2:
            raise DataError(f"{first.source}: a diagonal file needs at least 2 targets")
        step = float(first.targets_mm[1] - first.targets_mm[0])
    if step is None:
        step = default_step(diagonals)
    case = evaluate(machine).case()  # the one evaluation every diagonal reads
    predicted = []
    for d in diagonals:
        s = diagonal_targets(d, step)
        predicted.append((d, s, predict_diagonal(machine, d, s, evaluation=case)))
    checks = [
        check_diagonal(
            machine,
            by_name[n],
            prof,
            step,
            u_const,
            u_per_m,
            machine.analysis.direction,
            evaluation=case,
        )
        for n, prof in profiles.items()
    ]
    settings = {
        "prediction": machine.uncertainty is not None,
        "U_measurement_um": u_const,
        "U_measurement_per_m_um": u_per_m,
        "k": 2.0,
    }
    doc = {
        **diagonals_dict(machine, step, predicted, checks, settings),
        "warnings": list(machine.warnings),
    }
    text = diagonals_text(machine, step, predicted, checks, settings)
    with outputs:
        if out is not None:
            from esp.diagonals.plots import diagonals_figure
            from esp.report.profile_plots import save_png

            folder = outputs.stage_folder(out)
            doc = outputs.write_documents(folder, "diagonals", text, doc)
            fig = diagonals_figure(machine.name, predicted, {c.diagonal.name: c for c in checks})
            save_png(fig, folder / "diagonals.png")
            from esp.diagonals.text import write_diagonals_pdf

            write_diagonals_pdf(
                folder / "report.pdf", machine, checks, text, fig, outputs.provenance
            )
        outputs.finish(text=text, doc=doc, warnings=machine.warnings)
