"""``esp parallel``: error transmission of a serial-parallel machine (Zhao, Fan et al. 2002)."""

from __future__ import annotations

import difflib
from functools import partial
from typing import TYPE_CHECKING

import click

from esp.core.values import ValueRefused, parse, shown

if TYPE_CHECKING:
    from esp.parallel.config import PoseSpec

__all__ = ["parallel_command", "parse_pose"]

_POSE_KEYS = ("z", "alpha", "beta", "x", "y")


def parse_pose(text: str) -> dict[str, float]:
    """``"z=300,alpha=15,beta=10"`` -> ``{"z": 300.0, "alpha": 15.0, "beta": 10.0}``; ``x``
    and ``y`` (the table's position, mm) may be added. Keys may be left out when the
    machine file has a ``[pose]`` to fill them from."""
    pose: dict[str, float] = {}
    for part in text.replace(";", ",").split(","):
        if not part.strip():
            continue
        key, sep, value = part.partition("=")
        key = key.strip().lower()
        if not sep:
            raise click.BadParameter(
                f"expected key=value pairs such as z=300,alpha=15,beta=10, found {part.strip()!r}",
                param_hint="'--pose'",
            )
        if key not in _POSE_KEYS:
            close = difflib.get_close_matches(key, list(_POSE_KEYS), n=1, cutoff=0.5)
            hint = f"; did you mean {close[0]!r}?" if close else ""
            raise click.BadParameter(
                f"unknown key {key!r} (expected z, alpha, beta and optionally x, y){hint}",
                param_hint="'--pose'",
            )
        if key in pose:
            raise click.BadParameter(f"{key} is given twice", param_hint="'--pose'")
        try:
            pose[key] = parse(value, "position" if key in ("x", "y", "z") else "degrees")
        except ValueRefused as exc:
            raise click.BadParameter(f"{key}: {exc.message}", param_hint="'--pose'") from None
        if key in ("alpha", "beta") and not abs(pose[key]) < 90.0:
            # the platform's tilts lie within ±90° (Zhao, Fan et al. 2002, eq. 1)
            raise click.BadParameter(
                f"{key}: expected an angle within ±90 degrees, 90 excluded (eq. 1), "
                f"found {shown(pose[key])}",
                param_hint="'--pose'",
            )
    if not pose:
        raise click.BadParameter(
            "expected z=..,alpha=..,beta=.. (mm and degrees)", param_hint="'--pose'"
        )
    return pose


@click.command("parallel")
@click.argument("machine_toml", type=click.Path(dir_okay=False, path_type=str))
@click.option(
    "--pose",
    "pose_text",
    metavar="z=..,alpha=..,beta=..",
    help="The pose: z_T (mm), α and β (degrees), optionally the table's x and y (mm); "
    "keys left out come from the file's [pose].",
)
@click.option(
    "--sweep",
    "do_sweep",
    is_flag=True,
    help="Also sweep one error over its range (Fig. 5 and 6 of the paper) and the workspace "
    "grid, with the worst case and where.",
)
@click.option(
    "--model",
    type=click.Choice(["exact", "as-printed"]),
    default=None,
    help="The error model (default the file's, else exact); as-printed is eq. 10-18 as "
    "printed in the paper.",
)
@click.option(
    "--json",
    "json_target",
    metavar="PATH|-",
    help="Write the esp.parallel/1 document ('-': standard output, the text is then not printed).",
)
@click.option(
    "--out",
    "out_dir",
    metavar="DIR",
    type=click.Path(file_okay=False, path_type=str),
    help="Write the plots (PNG and one PDF) and result.json to a new folder.",
)
@click.option("--quiet", "-q", is_flag=True, help="Print nothing on the terminal but errors.")
def parallel_command(
    machine_toml: str,
    pose_text: str | None,
    do_sweep: bool,
    model: str | None,
    json_target: str | None,
    out_dir: str | None,
    quiet: bool,
) -> None:
    """Error transmission of the serial-parallel machine described by MACHINE_TOML.

    An X-Y table under a three-strut platform (Zhao, Fan et al. 2002): prints the pose and
    its slider heights, the matrices [J], [J]^-1, [M] and [N] (eq. 12-18), the tool tip's
    position errors (e_x, e_y, e_z) and orientation errors (ε_x, ε_y, ε_z) for the error
    values of the file with each source's share, and their uncertainty. See
    docs/parallel.md.

    \b
    Examples:
      esp parallel data/examples/parallel/machine.toml
      esp parallel data/examples/parallel/machine.toml --pose "z=300,alpha=15,beta=10"
      esp parallel data/examples/parallel/machine.toml --sweep --json -
      esp parallel data/examples/parallel/machine.toml --sweep --out parallel-report
    """
    from esp.cli.output import CommandOutputs

    pose_keys = parse_pose(pose_text) if pose_text is not None else {}
    outputs = CommandOutputs([machine_toml], json_target, quiet)
    out = outputs.folder(out_dir, "--out") if out_dir else None

    from esp.parallel.analysis import analyse_pose, sweep
    from esp.parallel.config import load_parallel
    from esp.parallel.render import document, render_text
    from esp.report.jsonout import dumps

    machine = load_parallel(machine_toml)
    pose = _pose(pose_keys, machine.pose)
    result = analyse_pose(machine, pose, model)
    swept = sweep(result) if do_sweep else None
    doc = document(result, swept)
    with outputs:
        if out is not None:
            from esp.parallel.plots import write_parallel_report

            prov = outputs.provenance
            doc = {**doc, "provenance": prov.to_dict()}
            write_parallel_report(
                outputs.stage_folder(out), result, swept, dumps(doc), provenance=prov
            )
        outputs.finish(text=partial(render_text, result, swept), doc=doc)


def _pose(keys: dict[str, float], default: PoseSpec | None) -> PoseSpec | None:
    """The pose of ``--pose``, its missing keys taken from the file's ``[pose]``."""
    from esp.core.errors import DataError
    from esp.parallel.config import PoseSpec

    if not keys:
        return default
    missing = [k for k in ("z", "alpha", "beta") if k not in keys]
    if missing and default is None:
        raise DataError(
            f"--pose: missing {', '.join(missing)} and the file has no [pose] to take them from"
        )
    table = default.table_mm if default is not None else (0.0, 0.0)
    return PoseSpec(
        keys.get("z", default.z_mm if default else 0.0),
        keys.get("alpha", default.alpha_deg if default else 0.0),
        keys.get("beta", default.beta_deg if default else 0.0),
        (keys.get("x", table[0]), keys.get("y", table[1])),
    )
