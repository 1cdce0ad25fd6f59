"""The resource limits of the commands, in one place, and the one check that refuses work
beyond them before it is done.

Each command knows its work from its options and configuration before doing any of it: the
targets along a diagonal, the points of a compensation table, the settings of a head map,
the bytes of a table file. :func:`refuse_if` compares such an estimate with its limit and
refuses (:class:`~esp.core.errors.DataError`, one line on the command line, exit code 2) with
the number found, the limit and the key or option to change, before any memory is taken.
``docs/reliability.md`` ("Resource limits") lists every limit with its number and why.

The limits of the analysis grid (``esp.config.machine``), of the data files
(``esp.io.textfile``, ``esp.io.laser10``), of ``grid.csv`` (``esp.volumetric.export``) and of
the Monte Carlo method (``esp.core.uncertainty.montecarlo``) stay beside the code they bound;
:data:`LIMITS` names them all, for the documentation and its test.

This module imports only the standard library.
"""

from __future__ import annotations

import math

from esp.core.errors import ConfigError, DataError

__all__ = [
    "COMPENSATION_MAX_FILE_BYTES",
    "COMPENSATION_MAX_PLANE_POINTS",
    "COMPENSATION_MAX_TABLE_POINTS",
    "DIAGONAL_MAX_TARGETS",
    "HEAD_MAP_MAX_SETTINGS",
    "LIMITS",
    "refuse_if",
]

#: targets along one diagonal of ``esp diagonals`` (each target is a point of the model,
#: its uncertainty and its figure): 10⁵ take about 80 MB and a few seconds
DIAGONAL_MAX_TARGETS = 100_000
#: points of one axis table of ``esp compensate`` (its travel divided by the spacing, both
#: ends included): 10⁵, a 100 m axis every millimetre
COMPENSATION_MAX_TABLE_POINTS = 100_000
#: points of one plane table (``twincat-plane``), the product of its two axes' points
COMPENSATION_MAX_PLANE_POINTS = 1_000_000
#: the size of one file ``esp compensate`` writes, unless ``--max-file-mb`` raises it:
#: controllers load tables of kilobytes; a table of many megabytes is a spacing mistake
COMPENSATION_MAX_FILE_BYTES = 4 * 1024 * 1024
#: settings of one head map (``esp head --grid``, ``[map]``): each takes about 1.3 kB
#: while the map is evaluated, so 2.5·10⁵ settings about 0.35 GB and some seconds
HEAD_MAP_MAX_SETTINGS = 250_000

#: every resource limit of esp: name -> (value, what it bounds), as docs/reliability.md
#: lists them
LIMITS: dict[str, tuple[float, str]] = {
    "DIAGONAL_MAX_TARGETS": (DIAGONAL_MAX_TARGETS, "targets along one diagonal"),
    "COMPENSATION_MAX_TABLE_POINTS": (COMPENSATION_MAX_TABLE_POINTS, "points of an axis table"),
    "COMPENSATION_MAX_PLANE_POINTS": (COMPENSATION_MAX_PLANE_POINTS, "points of a plane table"),
    "COMPENSATION_MAX_FILE_BYTES": (COMPENSATION_MAX_FILE_BYTES, "bytes of a table file"),
    "HEAD_MAP_MAX_SETTINGS": (HEAD_MAP_MAX_SETTINGS, "settings of a head map"),
}


def _count(value: float) -> str:
    """A count as a message shows it: exact up to 10⁹, else three digits and a power."""
    if not math.isfinite(value):  # a count beyond floating point: a step of 1e-320
        return "more than 1e+308"
    if value == int(value) and abs(value) < 1e9:
        return f"{int(value)}"
    return f"{value:.3g}"


def refuse_if(
    estimate: float,
    limit: float,
    key: str,
    what: str,
    advice: str,
    *,
    config: bool = False,
) -> None:
    """Refuse work whose ``estimate`` exceeds ``limit``, before it is done.

    Parameters
    ----------
    estimate : the size of the work (points, settings, bytes), counted from the options
        and the configuration without doing it
    limit : the limit of that size (one of this module's constants, or an option's value)
    key : the option or configuration key that sets the size (``--step``, ``axes.X.step``)
    what : what is counted, with how: ``"a diagonal of 1900 mm in steps of 1e-09 mm"``
    advice : what to change: ``"use a larger --step"``
    config : raise :class:`~esp.core.errors.ConfigError` for ``key`` (a configuration key)
        instead of :class:`~esp.core.errors.DataError` (an option)

    Raises
    ------
    DataError, ConfigError
        ``key: <what> = <estimate>, above the limit of <limit>: <advice>``.
    """
    if not estimate > limit:
        return
    message = f"{what} = {_count(estimate)}, above the limit of {_count(limit)}: {advice}"
    if config:
        raise ConfigError(key, message)
    raise DataError(f"{key}: {message}")
