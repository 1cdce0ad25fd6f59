"""``esp head``: a servo head's tool-tip errors over its angles, and measurement protocols
(Freeman & Ford 2003).

Without ``--protocol`` the command uses the numeric core only: neither sympy nor (without
``--out``) matplotlib is imported.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import TYPE_CHECKING, Any

import click

from esp.cli.derive import parse_values
from esp.cli.options import ModalCommand
from esp.core.values import Quantity, ValueRefused, check_symbol, parse

if TYPE_CHECKING:
    from esp.core.devices.head import Head
    from esp.heads.config import ProtocolSpec
    from esp.heads.maps import GridSpec

__all__ = ["head_command", "parse_grid", "parse_names"]


def parse_names(texts: tuple[str, ...], option: str) -> tuple[str, ...]:
    """``("DY,ThetaAv", "Oas")`` -> ``("DY", "ThetaAv", "Oas")``."""
    out: list[str] = []
    for text in texts:
        for part in text.replace(";", ",").split(","):
            name = part.strip()
            if not name:
                continue
            if name in out:
                raise click.BadParameter(f"{name} is given twice", param_hint=option)
            out.append(name)
    return tuple(out)


def parse_grid(text: str) -> list[GridSpec]:
    """``"A=-60:60:5,C=-60:60:5"`` -> grid specs (from:to:step, degrees).

    Each number goes through the one value check with its range and the count of each
    angle's values is bounded before any is made (:func:`esp.heads.maps.grid_axis`); a
    refusal is a :class:`click.BadParameter` naming ``--grid`` and the angle's field
    (``A.step``)."""
    from esp.core.errors import ConfigError
    from esp.heads.maps import SETTING_LIMIT, GridSpec, grid_axis

    setting = Quantity("a setting", "", -SETTING_LIMIT, SETTING_LIMIT)
    specs: list[GridSpec] = []
    for part in text.replace(";", ",").split(","):
        if not part.strip():
            continue
        name, sep, spec = part.partition("=")
        name = name.strip()
        fields = spec.split(":")
        if not sep or not name or len(fields) != 3:
            raise click.BadParameter(
                f"expected NAME=from:to:step such as A=-60:60:5, found {part.strip()!r}",
                param_hint="--grid",
            )
        if any(s.name == name for s in specs):
            raise click.BadParameter(f"{name} is given twice", param_hint="--grid")
        numbers: list[float] = []
        for field, value in zip(("from", "to", "step"), fields, strict=True):
            try:
                numbers.append(parse(value, setting if field != "step" else "number"))
            except ValueRefused as exc:
                raise click.BadParameter(
                    f"{name}.{field}: {exc.message}", param_hint="--grid"
                ) from None
        start, stop, step = numbers
        try:
            grid_axis(start, stop, step, name)  # its order, step and count, before the head
        except ConfigError as exc:
            raise click.BadParameter(f"{exc.key}: {exc.message}", param_hint="--grid") from None
        specs.append(GridSpec(name, start, stop, step))
    if not specs:
        raise click.BadParameter("expected NAME=from:to:step for each angle", param_hint="--grid")
    return specs


#: the protocol's angles, degrees (esp.heads.protocol refuses beyond 3600 degrees)
_PROTOCOL_ANGLE = Quantity("an angle", "degrees", -3600.0, 3600.0)


def _parse_angles(text: str) -> tuple[float, ...]:
    out = []
    for part in text.replace(";", ",").split(","):
        if not part.strip():
            continue
        try:
            v = parse(part, _PROTOCOL_ANGLE)
        except ValueRefused as exc:
            raise click.BadParameter(
                f"expected angles in degrees such as 0,90,180,270: {exc.message}",
                param_hint="--angles",
            ) from None
        out.append(v)
    return tuple(out)


def _check_names(
    head: Head, given: Mapping[str, float], kinds: tuple[str, ...], option: str
) -> None:
    """Every name in ``given`` is a symbol of the head of one of ``kinds``, a coordinate's
    value within the range of a coordinate (:func:`esp.core.values.check_symbol`; a
    parameter's or an error's is checked by :meth:`Head.with_values`, key ``--set NAME``);
    a refusal names ``option``."""
    import difflib

    symbols = head.chain.symbols
    allowed = [n for n, s in symbols.items() if s.kind in kinds]
    for name in given:
        if name in allowed:
            known = symbols[name]
            if known.kind == "coordinate":  # parameters and errors: Head.with_values
                try:  # the range of a coordinate, in its unit (esp.core.values.SYMBOL_LIMITS)
                    check_symbol(known.kind, known.unit, given[name])
                except ValueRefused as exc:
                    message = f"{name}: {exc.message}"
                    raise click.BadParameter(message, param_hint=option) from None
            continue
        sym = symbols.get(name)
        if sym is not None:
            where = "--at" if sym.kind == "coordinate" else "--set"
            raise click.BadParameter(
                f"{name} is a {sym.kind}; give it with {where}", param_hint=option
            )
        close = difflib.get_close_matches(name, allowed, n=1, cutoff=0.6)
        hint = f"; did you mean {close[0]!r}?" if close else ""
        what = " or ".join(f"{k}s" for k in kinds)
        raise click.BadParameter(
            f"{name} is not one of the head's {what}{hint} ({', '.join(allowed) or 'none'})",
            param_hint=option,
        )


_PROTOCOL_ONLY = ("assume_zero", "known", "identify", "angles_text", "measured_file", "do_protocol")


def _head_mode(given: Mapping[str, Any]) -> str:
    """The mode a command line of ``esp head`` selects: a protocol (``--protocol`` or
    ``--measured``), one setting (``--at``), or a map."""
    if given.get("do_protocol") or "measured_file" in given:
        return "protocol"
    return "point" if "at_text" in given else "map"


def _refusal(flag: str, mode: str) -> str:
    if mode == "protocol":
        return f"{flag} does not apply to --protocol"
    if flag in ("--assume-zero", "--known", "--identify", "--angles", "--measured"):
        return f"{flag} applies to --protocol only"
    if flag == "--grid":
        return "--at evaluates one setting; --grid a map: give one of them"
    return f"{flag} writes the report of a map; it does not apply to --at"


@click.command(
    "head",
    cls=ModalCommand,
    mode_of=_head_mode,
    modes={
        **{name: frozenset({"protocol"}) for name in _PROTOCOL_ONLY},
        "at_text": frozenset({"point"}),
        "grid_text": frozenset({"map"}),
        "out_dir": frozenset({"map"}),
        "order": frozenset({"map", "point"}),
    },
    refusal=_refusal,
)
@click.argument("head_toml", type=click.Path(dir_okay=False, path_type=str))
@click.option(
    "--at",
    "at_text",
    metavar="A=..,C=..",
    help="Evaluate one setting of the head's angles (degrees) instead of a map.",
)
@click.option(
    "--set",
    "set_text",
    metavar="NAME=V,...",
    help="Parameter and error values, each in its unit, over those of the file.",
)
@click.option(
    "--order",
    type=click.IntRange(1, 2),
    default=1,
    show_default=True,
    help="The order of the reported error: 1, or 2 to add the second-order terms.",
)
@click.option(
    "--grid",
    "grid_text",
    metavar="A=from:to:step,...",
    help="The map's grid (degrees); default the file's [map], else -60:60:2.5 for each angle.",
)
@click.option(
    "--protocol",
    "do_protocol",
    is_flag=True,
    help="Search the measurement protocol: differences of the tool tip between settings "
    "that isolate each error (imports sympy).",
)
@click.option(
    "--assume-zero",
    "assume_zero",
    multiple=True,
    metavar="NAMES",
    help="Errors the protocol assumes zero, comma-separated (instead of the file's).",
)
@click.option(
    "--known",
    multiple=True,
    metavar="NAMES",
    help="Errors known beforehand (instead of the file's); their values are the file's and --set.",
)
@click.option(
    "--identify",
    multiple=True,
    metavar="NAMES",
    help="Only these errors (default: every error neither assumed zero nor known).",
)
@click.option(
    "--angles",
    "angles_text",
    metavar="DEG,...",
    help="The settings of every axis for the protocol (default the file's, else 0,90,180,270).",
)
@click.option(
    "--measured",
    "measured_file",
    metavar="FILE",
    type=click.Path(dir_okay=False, path_type=str),
    help="Measured differences (CSV: test,difference_um) to solve the protocol for the errors.",
)
@click.option(
    "--json",
    "json_target",
    metavar="PATH|-",
    help="Write esp.head/1 (esp.protocol/1 with --protocol) to PATH, or '-' for standard output.",
)
@click.option(
    "--out",
    "out_dir",
    metavar="DIR",
    type=click.Path(file_okay=False, path_type=str),
    help="Write the map's report: surface and contour plots (PNG, one PDF), result.json.",
)
@click.option("--quiet", "-q", is_flag=True, help="Print nothing on the terminal but errors.")
def head_command(
    head_toml: str,
    at_text: str | None,
    set_text: str | None,
    order: int,
    grid_text: str | None,
    do_protocol: bool,
    assume_zero: tuple[str, ...],
    known: tuple[str, ...],
    identify: tuple[str, ...],
    angles_text: str | None,
    measured_file: str | None,
    json_target: str | None,
    out_dir: str | None,
    quiet: bool,
) -> None:
    """Tool-tip errors of the servo head described by HEAD_TOML, over its angles.

    HEAD_TOML names a head chain and gives its parameter and error values (or is a chain
    file itself: see docs/heads.md). Without options, an error map over a grid of the two
    angles: the extremes of DX, DY, DZ and |D| and where, the second-order terms against
    the first, the breakdown at the worst setting. --at evaluates one setting: the nominal
    tool tip and axis, the first-order (--order 2: and second-order) error and each error's
    share. --protocol searches the measurements that isolate each error (Freeman & Ford
    2003, section 5); --measured solves it for the errors.

    \b
    Examples:
      esp head data/examples/heads/angle-head-fig3.toml
      esp head data/examples/heads/angle-head-fig3.toml --at "A=30,C=40" --json -
      esp head data/examples/heads/angle-head-fig3.toml --out head-report
      esp head data/examples/heads/angle-head-fig3.toml --protocol
      esp head data/examples/heads/fork-head-example.toml --protocol \\
          --measured data/examples/heads/fork-head-measured.csv
    """
    from esp.cli.output import CommandOutputs
    from esp.heads.config import read_head_file

    at = parse_values(at_text, "--at") if at_text is not None else None
    values = parse_values(set_text, "--set") if set_text is not None else {}
    grid = parse_grid(grid_text) if grid_text is not None else None
    angles = _parse_angles(angles_text) if angles_text is not None else None
    zero = parse_names(assume_zero, "--assume-zero")
    known_names = parse_names(known, "--known")
    identify_names = parse_names(identify, "--identify")
    if measured_file is not None:
        do_protocol = True

    spec = read_head_file(head_toml)
    head = spec.head
    _check_names(head, values, ("parameter", "error"), "--set")
    if values:
        head = head.with_values(values)
    inputs = list(head.inputs) or [head_toml]
    if measured_file is not None:
        inputs.append(measured_file)
    outputs = CommandOutputs(inputs, json_target, quiet)
    out = outputs.folder(out_dir, "--out") if out_dir else None

    from esp.report.jsonout import dumps

    if do_protocol:
        text, doc = _protocol(
            head, spec.protocol, zero, known_names, identify_names, angles, measured_file
        )
    elif at is not None:
        _check_names(head, at, ("coordinate",), "--at")
        missing = [c for c in head.coordinates if c not in at]
        if missing:
            raise click.BadParameter(
                f"missing {', '.join(missing)}; give every angle of the head "
                f"({', '.join(head.coordinates)})",
                param_hint="--at",
            )
        from esp.core.devices.head_evaluate import evaluate_head
        from esp.heads.jsondoc import point_document
        from esp.heads.text import render_point

        ev = evaluate_head(head, at, order=order)
        text = render_point(ev, order)
        doc = point_document(ev, order)
    else:
        from esp.heads.jsondoc import map_document
        from esp.heads.maps import error_map
        from esp.heads.text import render_map

        if grid is not None:
            for g in grid:
                if g.name not in head.coordinates:
                    _check_names(head, {g.name: 0.0}, ("coordinate",), "--grid")
        m = error_map(
            head,
            grid if grid is not None else spec.grid,
            order=order,
            key="--grid" if grid is not None else "map",
        )
        text = render_map(m)
        doc = map_document(m)
    with outputs:
        if out is not None:
            from esp.heads.plots import write_head_report

            prov = outputs.provenance
            doc = {**doc, "provenance": prov.to_dict()}
            write_head_report(outputs.stage_folder(out), m, text, dumps(doc), provenance=prov)
        outputs.finish(text=text, doc=doc)


def _protocol(
    head: Head,
    spec: ProtocolSpec,
    zero: tuple[str, ...],
    known: tuple[str, ...],
    identify: tuple[str, ...],
    angles: tuple[float, ...] | None,
    measured_file: str | None,
) -> tuple[str, dict[str, Any]]:
    from esp.heads.jsondoc import protocol_document
    from esp.heads.measured import read_measured
    from esp.heads.protocol import build_protocol, solve_protocol
    from esp.heads.text import render_protocol

    protocol = build_protocol(
        head,
        angles=angles if angles is not None else spec.angles,
        assume_zero=zero or spec.assume_zero,
        known=known or spec.known,
        identify=identify or spec.identify,
    )
    measured = identified = None
    if measured_file is not None:
        measured = read_measured(measured_file, protocol)
        identified = solve_protocol(protocol, measured)
    return (
        render_protocol(protocol, measured, identified),
        protocol_document(protocol, measured, identified),
    )
