"""Load one measured error component from a data file of any supported format.

``.csv`` files are read as tidy profile CSV (:mod:`esp.io.csvfile`); every other file as a
Renishaw Laser10 text file (:mod:`esp.io.laser10`), whose kind follows from the explicit
``kind``, else the extension (``.rtl`` linear, ``.rta`` angular, ``.rts``/``.stx``/``.sty``/
``.stz`` straightness), else the file's HEADER.
"""

from __future__ import annotations

from pathlib import Path

from esp.core.profile import ErrorProfile
from esp.io.csvfile import read_csv_profile
from esp.io.laser10 import read_laser10

__all__ = ["load_profile"]


def load_profile(
    path: str | Path,
    kind: str | None = None,
    unit: str | None = None,
    axis: str | None = None,
    error_direction: str | None = None,
) -> ErrorProfile:
    """Read the error profile in ``path``, choosing the reader by extension.

    Parameters
    ----------
    path : a ``.csv`` file, or a Laser10 file (any other extension)
    kind : ``"linear"``, ``"straightness"`` or ``"angular"``. Wins over the extension and
        the file's own HEADER. A CSV file needs it (or a ``# kind:`` line).
    unit : unit of the file's deviations; default µm, or µm/m for angular
        (``"arcsec"``, ``"mrad"``, ``"urad"``, ``"um/m"`` are accepted for angles)
    axis : the axis moved (X, Y, Z); else ``.stx/.sty/.stz``, else USER-TEXT ``Axis``
        (Laser10), else ``# axis:`` (CSV)
    error_direction : direction of a straightness deviation, or the axis of rotation of
        an angular error

    Returns
    -------
    ErrorProfile
        In engine units: targets in mm, deviations in µm (µm/m for angular).

    Raises
    ------
    ParseError
        The file is missing, not text, malformed, or its kind cannot be told.
    DataError
        An argument is not valid.
    """
    if Path(path).suffix.lower() == ".csv":
        return read_csv_profile(path, kind, unit=unit, axis=axis, error_direction=error_direction)
    return read_laser10(path, kind=kind, unit=unit, axis=axis, error_direction=error_direction)
