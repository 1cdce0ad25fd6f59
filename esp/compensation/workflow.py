"""The whole of ``esp compensate`` as one library function: for each format, build its
tables from the machine's model, write its files, refuse a file larger than allowed
before anything is written to disk, read the files back with the format's own reader
and, when asked, predict the residual with the tables as read back, applied as the
controller applies them.

This module imports only numpy and the standard library.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

from esp.compensation.build import BuildOptions, build
from esp.compensation.field import Fields
from esp.compensation.formats import FormatSettings, get
from esp.compensation.text import FormatResult
from esp.core.limits import COMPENSATION_MAX_FILE_BYTES, refuse_if

if TYPE_CHECKING:
    from esp.core.machine import Machine

__all__ = ["Compensation", "compensate"]


@dataclass(frozen=True)
class Compensation:
    """One format's outcome: its files (name -> text) and its result (the tables as read
    back, the resolution, the record count and, when predicted, the residual)."""

    files: dict[str, str]
    result: FormatResult


def compensate(
    machine: Machine,
    formats: Sequence[str],
    options: BuildOptions | None = None,
    settings: FormatSettings | None = None,
    *,
    predict: bool = False,
    max_file_mb: float = COMPENSATION_MAX_FILE_BYTES / 2**20,
    max_file_key: str = "--max-file-mb",
    fields: Fields | None = None,
) -> dict[str, Compensation]:
    """Format name -> its files and result, for each of ``formats`` (each once, in order).

    ``fields``: the machine's prepared fields (by default prepared here, once for every
    format's tables and prediction).

    Raises
    ------
    DataError
        An unknown format; a component the format cannot hold (unless
        ``options.leave_uncorrected``); a table beyond the format's limits; a file larger
        than ``max_file_mb`` MiB (named with ``max_file_key``, the option that raises it).
    """
    options = options or BuildOptions()
    settings = settings or FormatSettings(machine_name=machine.name)
    if machine.table is not None:
        # a rotary table's axes follow the linear ones (AX4, AX5 ...) unless numbered
        numbers = {"X": 1, "Y": 2, "Z": 3, **settings.axis_numbers}
        for q in machine.table.table.coordinates:
            numbers.setdefault(q, max(numbers.values()) + 1)
        settings = replace(settings, axis_numbers=numbers)
    fields = fields if fields is not None else Fields(machine)
    out: dict[str, Compensation] = {}
    for name in dict.fromkeys(formats):
        fmt = get(name)
        tables = build(machine, name, options, fields)
        files = fmt.write(tables, settings)
        for file_name, content in files.items():  # before anything is written
            size = len(content.encode("utf-8"))
            refuse_if(
                size,
                int(max_file_mb * 2**20),
                f"--format {name}",
                f"the file {name}/{file_name} of {size / 2**20:.1f} MiB: bytes",
                f"use a larger --spacing, or allow larger files with {max_file_key} "
                f"(now {max_file_mb:g})",
            )
        back = fmt.read(files, settings)  # what the controller will read
        chosen = [
            f"{key}={settings.option(key, choices[-1] if choices[0] == '<number>' else choices[0])}"
            for key, choices in fmt.format_options.items()
        ]
        notes = tables.notes + (
            ("choices the documentation leaves open: " + ", ".join(chosen),) if chosen else ()
        )
        back = replace(
            back,
            format=name,
            corrected=tables.corrected,
            uncorrected=tables.uncorrected,
            notes=notes,
        )
        prediction = fmt.predict(machine, back, settings, fields) if predict else None
        result = FormatResult(
            back, tuple(files), fmt.resolution_um(settings), prediction, fmt.records(tables)
        )
        out[name] = Compensation(files, result)
    return out
