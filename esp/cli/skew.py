"""``esp skew``: squareness and scale of a machine's axes from a square it made or points of
a part or plate, with their U and the lines each firmware takes."""

from __future__ import annotations

import click

from esp.cli.options import Number
from esp.core.values import Quantity

__all__ = ["skew_command"]

_SIDE = Quantity("a side", "mm", 0.0, 1e4, above_low=True)
_CALIPER = Quantity("a caliper figure", "mm", 0.0, 10.0)
_POINT_U = Quantity("an uncertainty", "um", 0.0, 1e4, above_low=True)
_FIRMWARE = ("marlin", "klipper", "reprapfirmware", "ucnc", "linuxcnc", "esp")


@click.command("skew")
@click.argument("points", required=False, type=click.Path(dir_okay=False, path_type=str))
@click.option(
    "--xy",
    multiple=True,
    metavar="AC,BD,AD[,AB]",
    help="The diagonals AC, BD and the side AD (and AB) of a square made in XY, mm; "
    "repeat for more readings.",
)
@click.option("--xz", multiple=True, metavar="AC,BD,AD[,AB]", help="The same for a square in XZ.")
@click.option("--yz", multiple=True, metavar="AC,BD,AD[,AB]", help="The same for a square in YZ.")
@click.option(
    "--side",
    type=Number(_SIDE),
    metavar="MM",
    help="The side the square was commanded with: gives each axis' scale from AD and AB.",
)
@click.option(
    "--resolution",
    type=Number(_CALIPER),
    default=0.01,
    show_default=True,
    metavar="MM",
    help="Resolution of the caliper or rule.",
)
@click.option(
    "--accuracy",
    type=Number(_CALIPER),
    default=0.02,
    show_default=True,
    metavar="MM",
    help="Maximum permissible error (±) of the caliper or rule.",
)
@click.option(
    "--kind",
    type=click.Choice(["made", "probed"]),
    help="POINTS of a part the machine made (measured elsewhere) or of an artefact the "
    "machine probed (default: the file's '# kind:' line).",
)
@click.option(
    "--point-u",
    type=Number(_POINT_U),
    metavar="UM",
    help="Expanded uncertainty (k = 2) of a measured coordinate of POINTS, µm (default: "
    "from the points' scatter about the fit).",
)
@click.option(
    "--firmware",
    "firmware",
    multiple=True,
    type=click.Choice(_FIRMWARE),
    help="Show only these firmware's lines (repeatable; default all).",
)
@click.option("--json", "json_target", metavar="PATH|-", help="Write the result as JSON.")
@click.option("--quiet", "-q", is_flag=True, help="Print nothing on the terminal but errors.")
def skew_command(
    points: str | None,
    xy: tuple[str, ...],
    xz: tuple[str, ...],
    yz: tuple[str, ...],
    side: float | None,
    resolution: float,
    accuracy: float,
    kind: str | None,
    point_u: float | None,
    firmware: tuple[str, ...],
    json_target: str | None,
    quiet: bool,
) -> None:
    """Squareness of each plane and scale of each axis, with U, from what a workshop can
    measure without a laser: the diagonals AC, BD and the side AD of a square the machine
    printed or cut (corners as Marlin names them: A at the origin, D along the first axis,
    B along the second), or POINTS, a table of nominal and measured coordinates of a part
    the machine made or a plate it probed. Prints the lines Marlin (M852), Klipper
    (SET_SKEW), RepRapFirmware (M556), µCNC ($37, $39), LinuxCNC (matrixkins) and an esp
    machine.toml take (docs/skew.md).

    \b
    Examples:
      esp skew --xy 141.84,141.04,100.02
      esp skew --xy 141.84,141.04,100.02 --xy 141.83,141.05,100.01 --side 100
      esp skew data/examples/skew/plate-probed.csv
      esp skew data/examples/skew/plate-probed.csv --firmware linuxcnc --json skew.json
    """
    from esp.cli.output import CommandOutputs
    from esp.core.errors import ConfigError
    from esp.skew.firmware import firmware_lines
    from esp.skew.model import Caliper, from_points, from_squares
    from esp.skew.readings import read_points, squares
    from esp.skew.text import skew_dict, skew_text

    given = {"XY": xy, "XZ": xz, "YZ": yz}
    has_square = any(given.values())
    if points is not None and has_square:
        raise ConfigError("POINTS", "expected either a points file or --xy/--xz/--yz, found both")
    if points is None and not has_square:
        raise ConfigError(
            "--xy", "expected the lengths of a square (--xy, --xz, --yz) or a points file"
        )
    if points is not None and side is not None:
        raise ConfigError("--side", "applies to a square's lengths, not to a points file")
    if points is None and (kind is not None or point_u is not None):
        raise ConfigError(
            "--kind" if kind is not None else "--point-u", "applies to a points file only"
        )
    chosen = tuple(firmware) or _FIRMWARE
    outputs = CommandOutputs([points] if points else [], json_target, quiet)
    if points is not None:
        result = from_points(
            read_points(points, "made" if kind == "made" else "probed" if kind else None, point_u)
        )
    else:
        result = from_squares(squares(given, side), Caliper(resolution, accuracy))
    lines = firmware_lines(result, chosen)
    text = skew_text(result, lines)
    doc = skew_dict(result, lines)
    with outputs:
        outputs.finish(text=text, doc=doc, warnings=result.warnings)
