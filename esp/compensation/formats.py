"""One entry point per direction: a :class:`CompensationSet` to the files of its format
(:func:`write_files`) and the files back to a set (:func:`read_files`), with the format's
settings in one record (:class:`FormatSettings`).

This module imports only numpy and the standard library.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

from esp.compensation import isg_volumetric, iso_csv, linuxcnc, twincat
from esp.compensation.model import CompensationSet
from esp.core.errors import DataError

__all__ = ["FormatSettings", "read_files", "resolution_um", "write_files"]


@dataclass(frozen=True)
class FormatSettings:
    """The options of the formats (see each format module)."""

    linuxcnc_type: int = 1
    linuxcnc_units: str = "mm"
    axis_numbers: Mapping[str, int] = field(default_factory=lambda: {"X": 1, "Y": 2, "Z": 3})
    limits: Mapping[str, int] = field(default_factory=dict)
    cross_sign: str = "error"
    max_records: int | None = None
    machine_name: str = ""


def write_files(cset: CompensationSet, settings: FormatSettings | None = None) -> dict[str, str]:
    """File name -> text of every file of ``cset.format``."""
    s = settings or FormatSettings()
    fmt = cset.format
    if fmt == "linuxcnc":
        return linuxcnc.write(cset, s.linuxcnc_type, s.linuxcnc_units)
    if fmt.startswith("twincat-"):
        return twincat.write(cset, s.axis_numbers, s.limits, s.cross_sign)
    if fmt == "isg-volumetric":
        return isg_volumetric.write(cset, s.max_records)
    if fmt == "iso-csv":
        return iso_csv.write(cset, s.machine_name)
    raise DataError(f"unknown format {fmt!r}")


def read_files(
    fmt: str, files: Mapping[str, str], settings: FormatSettings | None = None
) -> CompensationSet:
    """The set the files of ``fmt`` hold, by the format's own reader."""
    s = settings or FormatSettings()
    if fmt == "linuxcnc":
        return linuxcnc.read(files, s.linuxcnc_type, s.linuxcnc_units)
    if fmt.startswith("twincat-"):
        return twincat.read(files, s.axis_numbers, s.cross_sign)
    if fmt == "isg-volumetric":
        return isg_volumetric.read(files)
    if fmt == "iso-csv":
        return iso_csv.read(files)
    raise DataError(f"unknown format {fmt!r}")


def resolution_um(fmt: str, settings: FormatSettings | None = None) -> float:
    """The smallest step of a written correction or displacement error (µm)."""
    s = settings or FormatSettings()
    if fmt == "linuxcnc":
        um, decimals = linuxcnc.UNITS[s.linuxcnc_units]
        return um * 10.0**-decimals
    if fmt.startswith("twincat-"):
        return 0.1
    if fmt == "isg-volumetric":
        return 1000.0 * 10.0**-isg_volumetric.DECIMALS_MM
    return 10.0**-iso_csv.DECIMALS
