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
    "IDENTIFY_MAX_DESIGN_BYTES",
    "IDENTIFY_MAX_SVD_FLOPS",
    "LIMITS",
    "design_work",
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
#: memory of the design matrix of ``esp identify`` (and ``--plan``) with its working
#: copies (:func:`design_work`): 1 GiB
IDENTIFY_MAX_DESIGN_BYTES = 1024**3
#: floating-point operations of one SVD of that design matrix (:func:`design_work`), taken
#: once by ``--plan`` and once or more per Gauss-Newton step by the fit: 10¹¹, some tens of
#: seconds on one core (a tracker of 1000 stations × 4 positions needs about 8·10¹¹)
IDENTIFY_MAX_SVD_FLOPS = 1e11

#: every resource limit of esp: name -> (value, what it bounds), as docs/reliability.md
#: lists them
LIMITS: dict[str, tuple[float, str]] = {
    "DIAGONAL_MAX_TARGETS": (DIAGONAL_MAX_TARGETS, "targets along one diagonal"),
    "COMPENSATION_MAX_TABLE_POINTS": (COMPENSATION_MAX_TABLE_POINTS, "points of an axis table"),
    "COMPENSATION_MAX_PLANE_POINTS": (COMPENSATION_MAX_PLANE_POINTS, "points of a plane table"),
    "COMPENSATION_MAX_FILE_BYTES": (COMPENSATION_MAX_FILE_BYTES, "bytes of a table file"),
    "HEAD_MAP_MAX_SETTINGS": (HEAD_MAP_MAX_SETTINGS, "settings of a head map"),
    "IDENTIFY_MAX_DESIGN_BYTES": (IDENTIFY_MAX_DESIGN_BYTES, "bytes of an identification's design"),
    "IDENTIFY_MAX_SVD_FLOPS": (IDENTIFY_MAX_SVD_FLOPS, "operations of an identification's SVD"),
}


def design_work(rows: int, columns: int) -> tuple[float, float]:
    """The memory (bytes) and the floating-point operations of the identifiability SVD of a
    weighted design matrix of ``rows`` residuals by ``columns`` parameters, before it is
    built (``esp.identify.solve``).

    Memory: the stacked matrix is built from blocks of full width (two copies), its free and
    its column-scaled columns (two more) and the QR's input with the residuals (one more):
    five copies of rows × columns doubles, and the right singular vectors, columns² (the
    left ones as well when rows < columns, whose null space needs the full SVD).
    Operations: the R-SVD of a tall m × n matrix, singular values and right vectors,
    2mn² + 11n³ (Golub & Van Loan 2013, Figure 8.6.1), with n the smaller and m the larger
    dimension; a wide matrix's full SVD (every right vector) adds 4mn² for the left."""
    m, n = float(max(rows, columns)), float(min(rows, columns))
    values = 5.0 * rows * columns + float(columns) ** 2
    flops = 2.0 * m * n**2 + 11.0 * n**3
    if rows < columns:
        values += float(rows) ** 2
        flops += 4.0 * m * n**2
    return 8.0 * values, flops


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
    source: str | None = None,
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
    source : the configuration file the key is in (named first in the message)

    Raises
    ------
    DataError, ConfigError
        ``key: <what> = <estimate>, above the limit of <limit>: <advice>``.
    """
    if not estimate > limit:
        return
    message = f"{what} = {_count(estimate)}, above the limit of {_count(limit)}: {advice}"
    if config:
        raise ConfigError(key, message, source)
    raise DataError(f"{key}: {message}")
