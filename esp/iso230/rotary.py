"""ISO 230-2 for a rotary axis: the angular positioning deviations of a rotary calibrator's
runs (a reference indexer, a polygon and autocollimator, a laser's rotary calibrator), their
figures A, B, E, M and R in arcsec, the checks the standard's rotary test programme asks
for, and their uncertainty from the calibrator's stated accuracy (docs/iso230-2.md,
"Rotary axes").

The file (docs/formats.md, "A rotary axis' runs"): esp's tidy CSV with the column
``target_deg`` in place of ``target_mm`` and a ``# kind: rotary`` line::

    # kind: rotary
    # axis: C
    # unit: arcsec
    target_deg,run,direction,deviation
    0,1,forward,0.0
    30,1,forward,1.8

``direction`` ``forward`` (the positive sense of rotation, ISO 230-2's ↑) or ``backward``;
``deviation`` the measured minus the commanded angle in ``arcsec`` (default), ``urad``,
``um/m``, ``mrad`` or ``deg``. Every run holds a value at every target, once.

What the standard asks of a rotary test and esp checks in notes (ISO 230-2:2014, 3.3 and
the test programme for rotary axes): the principal positions 0°, 90°, 180° and 270° among
the targets of a test over a full turn; and, when both 0° and 360° are targets (the same
position of the axis), the difference of their mean deviations, which the runs' scatter
should explain.

Uncertainty: the calibrator's stated accuracy ±a (arcsec, rectangular, a/√3) and the
environmental variation over the test, EVE (arcsec, from a drift test, EVE/(2√3)); U(A),
U(E), U(M) = 2·√((a/√3)² + u_EVE²), U(B) = 2·√(u_EVE² + u_s²) with u_s the spread of the
mean reversal at the largest |B_i|, U(R) = 2·u_EVE (as for a linear axis,
:mod:`esp.iso230.statement`).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from esp.core.errors import DataError, ParseError
from esp.core.units import ANGLE_UNITS, canonical_unit
from esp.core.values import Quantity
from esp.iso230.positioning import Iso230Result, statistics
from esp.iso230.statement import Iso230Uncertainty, figure_budgets

__all__ = [
    "RotarySetup",
    "is_rotary_file",
    "read_rotary",
    "rotary_iso230_2",
    "rotary_uncertainty",
]

_DEVIATION = Quantity("a deviation", "arcsec", -36000.0, 36000.0)
#: arcsec per µm/m (= µrad)
_ARCSEC_PER_URAD = 1.0 / ANGLE_UNITS["arcsec"]
PRINCIPAL_DEG = (0.0, 90.0, 180.0, 270.0)


def is_rotary_file(text: str) -> bool:
    """Whether a CSV text declares ``# kind: rotary``."""
    for line in text.splitlines():
        stripped = line.strip()
        if stripped.startswith("#"):
            key, sep, value = stripped[1:].partition(":")
            if sep and key.strip().lower() == "kind" and value.strip().lower() == "rotary":
                return True
    return False


@dataclass(frozen=True)
class RotaryRuns:
    """A rotary axis' runs: targets in degrees, per direction (n, m) deviations in arcsec."""

    targets_deg: np.ndarray
    runs: Mapping[str, np.ndarray]
    axis: str | None
    source: str


def read_rotary(path: str | Path) -> RotaryRuns:
    """The runs of a rotary CSV (module docstring), read by the tidy CSV's own table reader
    (:func:`esp.io.csvfile.scan_table`, :func:`esp.io.csvfile.runs_table`) with the
    position column ``target_deg``.

    Raises
    ------
    ParseError
        At the file and line: a missing column, a value that is not a number, an unknown
        direction or unit, a run in two directions, a run without a value at a target or
        with two, a deviation beyond ±10°.
    """
    from esp.io.csvfile import runs_table, scan_table
    from esp.io.textfile import read_text

    p = Path(path)
    comments, header, rows = scan_table(read_text(p), p)
    if "kind" not in comments or comments["kind"][1].strip().lower() != "rotary":
        line = comments["kind"][0] if "kind" in comments else None
        raise ParseError(p, line, "expected a '# kind: rotary' line for a rotary axis' runs")
    unit = "arcsec"
    if "unit" in comments:
        line, stated = comments["unit"]
        try:
            unit = canonical_unit(stated)
        except DataError:
            unit = ""
        if unit not in ANGLE_UNITS:
            raise ParseError(
                p, line, f"expected an angle unit (arcsec, urad, mrad, deg), found {stated!r}"
            )
    axis = None
    if "axis" in comments:
        line, stated = comments["axis"]
        axis = stated.strip().upper()
        if len(axis) != 1 or not axis.isalpha():
            raise ParseError(p, line, f"expected an axis letter (A, B, C ...), found {stated!r}")
    targets, runs, lines = runs_table(p, header, rows, position="target_deg", unit_word="°")
    factor = ANGLE_UNITS[unit] * _ARCSEC_PER_URAD
    out = {}
    for direction, block in runs.items():
        if not block:
            continue
        values = np.asarray(block, dtype=float) * factor
        beyond = np.argwhere(np.abs(values) > _DEVIATION.high)
        if beyond.size:
            i, j = (int(k) for k in beyond[0])
            raise ParseError(
                p,
                lines[direction][i][j],
                f"expected a deviation within ±10° ({_DEVIATION.high:g} arcsec), found "
                f"{block[i][j]:g} {unit}",
            )
        out[direction] = values
    return RotaryRuns(targets, out, axis, str(p))


def rotary_iso230_2(data: RotaryRuns) -> Iso230Result:
    """ISO 230-2 figures of a rotary axis (arcsec), with the rotary test's notes."""
    result = statistics(
        data.targets_deg,
        data.runs,
        axis=data.axis,
        source=data.source,
        unit="arcsec",
        rotary=True,
    )
    notes = list(result.notes)
    t = data.targets_deg
    full_turn = t[-1] - t[0] >= 360.0 - 1e-9
    if full_turn:
        absent = [p for p in PRINCIPAL_DEG if not np.any(np.isclose(np.mod(t, 360.0), p))]
        if absent:
            notes.append(
                "ISO 230-2 asks a test over a full turn to include the principal positions "
                f"0°, 90°, 180° and 270°; missing: {', '.join(f'{p:g}°' for p in absent)}"
            )
        starts = np.isclose(t, t[0])
        ends = np.isclose(t, t[0] + 360.0)
        if np.any(ends):
            i, j = int(np.argmax(starts)), int(np.argmax(ends))
            for arrow, mean in (("up", result.mean_up), ("down", result.mean_down)):
                if mean is not None:
                    notes.append(
                        f"{t[0]:g}° and {t[j]:g}° are one position of the axis: their mean "
                        f"deviations ({arrow}) differ by {mean[j] - mean[i]:+.2f} arcsec"
                    )
    return replace(result, notes=tuple(notes))


@dataclass(frozen=True)
class RotarySetup:
    """The calibrator's stated accuracy ± and the environmental variation error, arcsec."""

    accuracy_arcsec: float | None = None
    eve_arcsec: float | None = None


def rotary_uncertainty(result: Iso230Result, setup: RotarySetup) -> Iso230Uncertainty:
    """U (k = 2, arcsec) of every figure of a rotary result (module docstring), or what
    is missing."""
    missing = []
    if setup.accuracy_arcsec is None:
        missing.append("the calibrator's accuracy (--calibrator-accuracy)")
    if setup.eve_arcsec is None:
        missing.append("the environmental variation error (--eve, arcsec)")
    if missing:
        return Iso230Uncertainty(missing=tuple(missing))
    assert setup.accuracy_arcsec is not None and setup.eve_arcsec is not None
    u_device = setup.accuracy_arcsec / math.sqrt(3.0)
    u_eve = setup.eve_arcsec / (2.0 * math.sqrt(3.0))
    device = ("calibrator accuracy (u_DEVICE)", u_device)
    eve = ("environmental variation error (u_EVE)", u_eve)
    figures = figure_budgets(result, [device, eve], eve)
    span = float(result.targets_mm[-1] - result.targets_mm[0])
    return Iso230Uncertainty(figures, (), span)
