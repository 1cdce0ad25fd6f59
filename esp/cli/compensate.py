"""``esp compensate``: compensation tables for CNC controllers, and the residual predicted
after the controller applies them."""

from __future__ import annotations

import functools
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Any

import click

from esp.cli.options import Number
from esp.compensation.formats import limit_names, option_choices
from esp.compensation.formats import names as format_names
from esp.core.limits import COMPENSATION_MAX_FILE_BYTES
from esp.core.values import Quantity

#: --max-file-mb: a file size in MiB, 0.001 MiB (about 1 KiB) to 1 GiB (a controller loads
#: kilobytes; the table-size limits keep every file far below the upper end)
FILE_MIB = Quantity("a file size", "MiB", 0.001, 1024.0)

__all__ = ["compensate_command", "parse_pairs", "write_format_folder"]


#: the largest whole number an option of a table list takes (an ISG list holds SGN32)
WHOLE_MAX = 2**31 - 1


def _number(text: str, quantity: str | Quantity = "number") -> float:
    """A number as every option reads it (:func:`esp.core.values.parse`: no ``1_000``,
    finite, within the range of ``quantity``); ValueError with the check's message
    otherwise."""
    from esp.core.values import ValueRefused, parse

    try:
        return parse(text, quantity)
    except ValueRefused as exc:
        raise ValueError(exc.message) from None


def _whole(text: str) -> int:
    """A whole number of decimal digits from 1 to :data:`WHOLE_MAX` (``int`` would take
    ``1_000``); ValueError otherwise."""
    t = text.strip()
    if not t.lstrip("+-").isdigit() or not t.isascii():
        raise ValueError(f"expected a whole number, found {t!r}")
    if len(t.lstrip("+-")) > 12 or not 1 <= int(t) <= WHOLE_MAX:
        raise ValueError(f"expected a whole number from 1 to {WHOLE_MAX}, found {t!r}")
    return int(t)


#: the axis letters an option may name: the linear axes, and a rotary table's
ALL_AXES = ("X", "Y", "Z", "A", "B", "C")


def parse_pairs(
    text: str | None,
    option: str,
    value_type: Callable[[str], Any] = float,
    keys: Sequence[str] = ("X", "Y", "Z"),
    quantity: str | Quantity = "number",
    bare: Sequence[str] | None = None,
) -> dict[str, Any]:
    """``"X=50,Y=25"`` -> ``{"X": 50.0, "Y": 25.0}``; a bare value applies to every key
    of ``bare`` (default: every key).
    ``float`` values go through the one value check (:func:`esp.core.values.parse`) with the
    range of ``quantity``; ``int`` values are whole numbers from 1 to :data:`WHOLE_MAX`. A
    key given twice, a key not in ``keys`` or a value refused is a
    :class:`click.BadParameter` naming ``option`` (one line, exit 2)."""
    if not text:
        return {}
    if value_type is float:
        value_type = functools.partial(_number, quantity=quantity)
    elif value_type is int:
        value_type = _whole
    text = text.strip()
    if "=" not in text and "," not in text:  # a bare value: every key
        try:
            value = value_type(text)
        except ValueError as exc:
            raise click.BadParameter(str(exc), param_hint=option) from None
        return {k: value for k in (keys if bare is None else bare)}
    out = {}
    for part in text.split(","):
        key, sep, raw = part.partition("=")
        key = key.strip()
        if not sep or key not in keys:
            raise click.BadParameter(
                f"expected KEY=VALUE pairs with KEY one of {', '.join(keys)}, "
                f"found {part.strip()!r}",
                param_hint=option,
            )
        if key in out:
            raise click.BadParameter(f"{key} is given twice", param_hint=option)
        try:
            out[key] = value_type(raw.strip())
        except ValueError as exc:
            raise click.BadParameter(f"{key}: {exc}", param_hint=option) from None
    return out


def write_format_folder(folder: Path, files: Mapping[str, str]) -> None:
    """Write the files of one format into ``folder``, a new subfolder of the staged
    ``--out`` folder, as a folder of its own with esp's marker (through its own
    :class:`~esp.io.outputs.Outputs`, as the report folders of ``esp batch`` are): the
    marker of ``--out`` lists the subfolder, and the subfolder's marker its files, so that
    the next run recognises the whole of ``--out`` as esp's and replaces it."""
    from esp.io.outputs import Outputs

    sub = Outputs()
    target = sub.folder(folder, "--out")
    with sub:
        staged = sub.stage_folder(target)
        for name, content in files.items():
            (staged / name).write_text(content, encoding="utf-8", newline="\n")


@click.command("compensate")
@click.argument("machine_toml", type=click.Path(dir_okay=False, path_type=str))
@click.option(
    "--format",
    "formats",
    multiple=True,
    required=True,
    type=click.Choice(format_names()),
    help="Controller format (repeat for several).",
)
@click.option(
    "--out",
    "out_dir",
    metavar="DIR",
    type=click.Path(file_okay=False, path_type=str),
    help="Write the tables into DIR/<format>/ (and, with --predict, the report).",
)
@click.option("--predict", is_flag=True, help="Predict the volumetric accuracy after compensation.")
@click.option(
    "--plot",
    "plot_path",
    metavar="OUT.png",
    type=click.Path(dir_okay=False, path_type=str),
    help="Write a PNG of the accuracy before and after per format (implies --predict).",
)
@click.option("--json", "json_target", metavar="PATH|-", help="Write the summary as JSON.")
@click.option(
    "--spacing",
    metavar="MM|X=..,Y=..,Z=..",
    help="Table spacing in mm, 0.001 mm up to the axis' travel, each axis once (default: "
    "each axis' step); a rotary table's axis in degrees (C=5, the default), dividing its "
    "turn.",
)
@click.option(
    "--leave-uncorrected",
    is_flag=True,
    help="Write the tables even when the format cannot hold some components; they stay "
    "in the residual.",
)
@click.option(
    "--linuxcnc-type",
    type=click.IntRange(0, 1),
    default=1,
    show_default=True,
    help="LinuxCNC COMP_FILE_TYPE.",
)
@click.option(
    "--linuxcnc-units",
    type=click.Choice(["mm", "inch"]),
    default="mm",
    show_default=True,
    help="LinuxCNC machine units.",
)
@click.option(
    "--axis-numbers",
    metavar="X=1,Y=2,Z=3",
    help="The controller's axis numbers: ISG logical axes, SINUMERIK AXn (default X=1, Y=2, Z=3).",
)
@click.option(
    "--cross",
    "cross_text",
    metavar="SLAVE=MASTER,..",
    help="twincat-cross: the master axis of each corrected axis, e.g. Y=X,Z=Y.",
)
@click.option(
    "--cross-sign",
    type=click.Choice(["error", "correction"]),
    default="error",
    show_default=True,
    help="ISG cross/plane tables and SINUMERIK CEC tables: write the error or its "
    "negative (the documentation does not say; check on the machine).",
)
@click.option(
    "--max-points",
    "max_points",
    metavar="NAME=N,..",
    help="Table limits configured in the controller: ISG ssfk, crosscomp, crosscomp2 "
    "(P-COMP-00059/60/61, default 1500, 1001, 10201); SINUMERIK lec (MD38000, default "
    "200), cec (MD18342, default 200), cec_tables (default 8).",
)
@click.option(
    "--format-option",
    "format_options",
    multiple=True,
    metavar="NAME=VALUE",
    help="A choice the controller's documentation leaves open (repeat for several): "
    + ", ".join(
        f"{k}={f'N (default {c[1]})' if c[0] == '<number>' else '|'.join(c)}"
        for k, c in option_choices().items()
    )
    + " (the first the default; docs/compensation.md).",
)
@click.option(
    "--max-records",
    type=click.IntRange(1, 2**31 - 1),
    help="isg-volumetric: vol_comp[i].max_records of the start-up list.",
)
@click.option(
    "--max-file-mb",
    "max_file_mb",
    type=Number(FILE_MIB),
    default=COMPENSATION_MAX_FILE_BYTES / 2**20,
    show_default=True,
    metavar="MB",
    help="Refuse a table file larger than MB MiB, 0.001 to 1024 (a controller loads "
    "kilobytes; docs/reliability.md).",
)
@click.option("--quiet", "-q", is_flag=True, help="Print nothing on the terminal but errors.")
def compensate_command(
    machine_toml: str,
    formats: tuple[str, ...],
    out_dir: str | None,
    predict: bool,
    plot_path: str | None,
    json_target: str | None,
    spacing: str | None,
    leave_uncorrected: bool,
    linuxcnc_type: int,
    linuxcnc_units: str,
    axis_numbers: str | None,
    cross_text: str | None,
    cross_sign: str,
    max_points: str | None,
    format_options: tuple[str, ...],
    max_records: int | None,
    max_file_mb: float,
    quiet: bool,
) -> None:
    """Compensation tables for the controller of the machine in MACHINE_TOML.

    Every value is computed from the machine's model (the one its [analysis] selects),
    relative to its datum, in the controller's unit, resolution and sign (see
    docs/compensation.md for each format's source). A format that cannot hold a component
    the model uses is refused unless --leave-uncorrected; a table beyond the controller's
    limits is refused, and so is a file larger than --max-file-mb (docs/reliability.md).

    \b
    Examples:
      esp compensate data/examples/gantry/machine.toml --format isg-volumetric --out comp
      esp compensate data/examples/gantry/machine.toml --format linuxcnc \\
          --leave-uncorrected --predict
      esp compensate data/examples/gantry/machine.toml --format twincat-plane \\
          --format isg-volumetric --leave-uncorrected --predict --out comp \\
          --plot before-after.png
      esp compensate data/examples/gantry/machine.toml --format siemens-cec \\
          --format fanuc --max-points cec_tables=12 --leave-uncorrected --predict
    """
    from esp.cli.output import CommandOutputs
    from esp.compensation.build import BuildOptions
    from esp.compensation.formats import FormatSettings, check_options
    from esp.compensation.text import compensation_dict, compensation_text
    from esp.compensation.workflow import compensate
    from esp.config import load_machine

    # a rotary table's axes (A, B, C) take a spacing in degrees and a number too
    spacing_mm = parse_pairs(
        spacing, "--spacing", quantity="step", keys=ALL_AXES, bare=("X", "Y", "Z")
    )
    numbers = parse_pairs(axis_numbers, "--axis-numbers", int, keys=ALL_AXES)
    cross = parse_pairs(cross_text, "--cross", str)
    limits = parse_pairs(max_points, "--max-points", int, keys=limit_names())
    chosen = {}
    for item in format_options:
        key, sep, value = item.partition("=")
        if not sep or key.strip() in chosen:
            raise click.BadParameter(
                f"expected NAME=VALUE, each NAME once, found {item!r}", param_hint="--format-option"
            )
        chosen[key.strip()] = value.strip()
    chosen = check_options(chosen)
    predict = predict or plot_path is not None
    machine = load_machine(machine_toml)
    outputs = CommandOutputs(machine.inputs, json_target, quiet)
    png_path = outputs.figure(plot_path, "--plot") if plot_path is not None else None
    out = outputs.folder(out_dir, "--out") if out_dir else None

    settings = FormatSettings(
        linuxcnc_type=linuxcnc_type,
        linuxcnc_units=linuxcnc_units,
        axis_numbers={"X": 1, "Y": 2, "Z": 3, **numbers},
        limits=limits,
        cross_sign=cross_sign,
        max_records=max_records,
        machine_name=machine.name,
        options=chosen,
    )
    options = BuildOptions(
        spacing_mm=spacing_mm, cross_masters=cross, leave_uncorrected=leave_uncorrected
    )
    done = compensate(
        machine,
        formats,
        options,
        settings,
        predict=predict,
        max_file_mb=max_file_mb,
    )
    results = [c.result for c in done.values()]
    written = {fmt: c.files for fmt, c in done.items()}
    doc = {**compensation_dict(machine, results), "warnings": list(machine.warnings)}
    text = compensation_text(machine, results)
    with outputs:
        if out is not None:
            folder = outputs.stage_folder(out)
            for fmt, files in written.items():
                write_format_folder(folder / fmt, files)
            if predict:
                doc = outputs.write_documents(folder, "compensation", text, doc)
            from esp.compensation.text import write_compensation_pdf

            write_compensation_pdf(
                folder / "report.pdf", machine, results, text, predict, outputs.provenance
            )
        if png_path is not None:
            from esp.compensation.plots import before_after_figure  # matplotlib

            fig = before_after_figure(
                machine.name, [r.prediction for r in results if r.prediction is not None]
            )  # --plot implies --predict: every result has its prediction
            outputs.save_figure(fig, png_path)
        outputs.finish(text=text, doc=doc, warnings=machine.warnings)
