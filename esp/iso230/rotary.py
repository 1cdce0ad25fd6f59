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

import csv
import io
import math
from collections.abc import Mapping
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from esp.core.errors import DataError, ParseError
from esp.core.units import ANGLE_UNITS, canonical_unit
from esp.core.values import Quantity, ValueRefused, parse
from esp.iso230.positioning import Iso230Result, statistics
from esp.iso230.statement import Iso230Uncertainty, figure_budgets

__all__ = [
    "RotarySetup",
    "is_rotary_file",
    "read_rotary",
    "rotary_iso230_2",
    "rotary_uncertainty",
]

_TARGET = Quantity("a target angle", "deg", -3600.0, 3600.0)
_DEVIATION = Quantity("a deviation", "arcsec", -36000.0, 36000.0)
_DIRECTIONS = {
    "forward": "forward",
    "fwd": "forward",
    "+": "forward",
    "up": "forward",
    "positive": "forward",
    "backward": "backward",
    "bwd": "backward",
    "-": "backward",
    "down": "backward",
    "reverse": "backward",
    "negative": "backward",
}
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
    """The runs of a rotary CSV (module docstring).

    Raises
    ------
    ParseError
        At the file and line: a missing column, a value that is not a number, an unknown
        direction or unit, a run in two directions, a run without a value at a target or
        with two.
    """
    p = Path(path)
    text = p.read_text(encoding="utf-8-sig")
    unit = "arcsec"
    axis = None
    header: list[str] | None = None
    rows: list[tuple[int, float, int, str, float]] = []
    for number, line in enumerate(text.splitlines(), start=1):
        stripped = line.strip()
        if not stripped:
            continue
        if stripped.startswith("#"):
            key, sep, value = stripped[1:].partition(":")
            key = key.strip().lower()
            if sep and key == "unit":
                try:
                    unit = canonical_unit(value.strip())
                except DataError as exc:
                    raise ParseError(p, number, str(exc)) from None
                if unit not in ANGLE_UNITS:
                    raise ParseError(
                        p,
                        number,
                        "expected an angle unit (arcsec, urad, mrad, deg), found "
                        f"{value.strip()!r}",
                    )
            elif sep and key == "axis":
                axis = value.strip().upper() or None
            continue
        delimiter = "," if "," in stripped else (";" if ";" in stripped else "\t")
        cells = next(csv.reader(io.StringIO(stripped), delimiter=delimiter))
        cells = [c.strip() for c in cells]
        if header is None:
            header = [c.lower() for c in cells]
            missing = [
                c for c in ("target_deg", "run", "direction", "deviation") if c not in header
            ]
            if missing:
                raise ParseError(
                    p,
                    number,
                    "expected the columns target_deg, run, direction, deviation; missing "
                    + ", ".join(missing),
                )
            continue
        col = {name: header.index(name) for name in ("target_deg", "run", "direction", "deviation")}
        if len(cells) < len(header):
            raise ParseError(p, number, f"expected {len(header)} fields, found {len(cells)}")
        try:
            target = parse(cells[col["target_deg"]], _TARGET)
            run_value = parse(cells[col["run"]], Quantity("a run number", "", 1.0, 1e6))
            deviation = parse(cells[col["deviation"]], "number")
        except ValueRefused as exc:
            raise ParseError(p, number, exc.message) from None
        if run_value != int(run_value):
            raise ParseError(p, number, f"expected a whole run number, found {cells[col['run']]!r}")
        direction = _DIRECTIONS.get(cells[col["direction"]].lower())
        if direction is None:
            raise ParseError(
                p,
                number,
                f"expected direction forward or backward, found {cells[col['direction']]!r}",
            )
        arcsec = deviation * ANGLE_UNITS[unit] * _ARCSEC_PER_URAD
        if not abs(arcsec) <= _DEVIATION.high:
            raise ParseError(
                p, number, f"expected a deviation within ±10°, found {cells[col['deviation']]!r}"
            )
        rows.append((number, target, int(run_value), direction, arcsec))
    if header is None or not rows:
        raise ParseError(
            p, None, "expected a header and rows of target_deg, run, direction, deviation"
        )
    targets = sorted({r[1] for r in rows})
    if len(targets) < 2:
        raise ParseError(p, None, "expected two targets or more")
    index = {t: i for i, t in enumerate(targets)}
    by_run: dict[int, tuple[str, dict[int, float], int]] = {}
    for number, target, run, direction, arcsec in rows:
        entry = by_run.setdefault(run, (direction, {}, number))
        if entry[0] != direction:
            raise ParseError(
                p, number, f"run {run} is {entry[0]} on line {entry[2]} and {direction} here"
            )
        if index[target] in entry[1]:
            raise ParseError(p, number, f"run {run} has a second value at {target:g}°")
        entry[1][index[target]] = arcsec
    runs: dict[str, list[list[float]]] = {}
    for run in sorted(by_run):
        direction, values, first = by_run[run]
        if len(values) != len(targets):
            absent = next(t for t in targets if index[t] not in values)
            raise ParseError(p, first, f"run {run} has no value at {absent:g}°")
        runs.setdefault(direction, []).append([values[i] for i in range(len(targets))])
    return RotaryRuns(
        np.array(targets),
        {d: np.array(v) for d, v in runs.items()},
        axis,
        str(p),
    )


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
