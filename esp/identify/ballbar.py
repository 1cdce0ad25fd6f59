"""The lengths table of ballbar circles, as ``esp identify`` and ``esp ballbar`` read it
(docs/formats.md, "Measurements for identification"; the ISO 230-4 analysis and the
diagnosis are in :mod:`esp.ballbar`).

Per reading the commanded position ``X, Y, Z``, the nominal centre ``cx, cy, cz`` and
length ``length_mm``, the deviation of the measured length ``deviation_um`` and, for a
bidirectional test, the ``direction`` (``ccw``/``cw``). Each circle (``circle`` label) lies
in its own plane, with the angle θ measured from the first axis of the plane.

Every reading is checked when read (:func:`esp.core.values.check`): positions and centres
within ±100 m, the length above 0 and at most 100 m, deviations within ±10 mm; one centre
and one length per circle; each position at the stated length from the centre (within
:data:`LENGTH_TOLERANCE` of it, at least 1 µm) and in the plane of the centre; no position
twice in one run; ``direction`` ``ccw`` or ``cw`` (θ increasing or decreasing).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from esp.core.errors import ParseError
from esp.core.values import QUANTITIES, Quantity, ValueRefused, check, written
from esp.identify.tables import Table, read_table

__all__ = [
    "DIRECTIONS",
    "LENGTH_TOLERANCE",
    "MIN_READINGS",
    "LengthsCircle",
    "check_length",
    "read_lengths",
]

#: the positions lie at the stated length from the centre within this fraction of it
LENGTH_TOLERANCE = 1e-3
#: the direction labels: θ increasing (ccw) or decreasing (cw) along the run
DIRECTIONS = ("ccw", "cw")
#: the fewest readings of one run
MIN_READINGS = 8

_LENGTH = Quantity("a ballbar length", "mm", 0.0, 1e5, above_low=True)
_QUANTITY: dict[str, str | Quantity] = {
    "X": "position",
    "Y": "position",
    "Z": "position",
    "cx": "position",
    "cy": "position",
    "cz": "position",
    "length_mm": _LENGTH,
    "deviation_um": "displacement",
}


def _plane(D: np.ndarray) -> tuple[str, int, int]:
    spread = np.ptp(D, axis=0)
    order = np.argsort(-spread)[:2]
    i, j = sorted(int(k) for k in order)
    return "XYZ"[i] + "XYZ"[j], i, j


def _check_readings(table: Table) -> None:
    """Every number through the one value check, then the circle's own rules (module
    docstring); a refusal names the file, the line, what was expected and what found."""
    for column, quantity in _QUANTITY.items():
        q = QUANTITIES[quantity] if isinstance(quantity, str) else quantity
        values = np.asarray(table.columns[column], dtype=float)
        # the readings check() would refuse, found at once; check() words the refusal
        low = values <= q.low if q.above_low else values < q.low
        for r in np.flatnonzero(~np.isfinite(values) | low | (values > q.high))[:1]:
            try:
                check(float(values[r]), q, given=written(values[r]))
            except ValueRefused as exc:
                raise table.fail(int(r), f"column {column}: {exc.message}") from None
    if table.has("direction"):
        for r, d in enumerate(table.columns["direction"]):
            if d.lower() not in DIRECTIONS:
                raise table.fail(r, f"column direction: expected ccw or cw, found {d[:40]!r}")


def check_length(
    table: Table, name: str, idx: np.ndarray, P: np.ndarray, centre: np.ndarray, length: float
) -> float:
    """Refuse the first position of circle ``name`` (rows ``idx`` of ``P``, mm) that is not
    ``length`` mm from ``centre`` within :data:`LENGTH_TOLERANCE` of it (at least 1 µm),
    naming its file and line; return that tolerance (mm)."""
    tol = max(LENGTH_TOLERANCE * length, 1e-3)
    dist = np.sqrt(np.sum((P[idx] - centre) ** 2, axis=1))
    off = np.flatnonzero(np.abs(dist - length) > tol)
    if off.size:
        raise table.fail(
            int(idx[off[0]]),
            f"circle {name!r}: expected the position at length_mm {written(length)} mm "
            f"from the centre (within {tol:.3g} mm), found {dist[off[0]]:.6g} mm",
        )
    return tol


def _check_circle(
    table: Table,
    name: str,
    idx: np.ndarray,
    P: np.ndarray,
    C: np.ndarray,
    L: np.ndarray,
    runs: list[str],
) -> None:
    for k in idx[1:]:
        if not np.array_equal(C[k], C[idx[0]]):
            raise table.fail(
                int(k),
                f"circle {name!r}: expected one centre "
                f"({', '.join(written(v) for v in C[idx[0]])}) mm as on line "
                f"{int(table.lines[idx[0]])}, found ({', '.join(written(v) for v in C[k])})",
            )
        if L[k] != L[idx[0]]:
            raise table.fail(
                int(k),
                f"circle {name!r}: expected one length_mm {written(L[idx[0]])} as on line "
                f"{int(table.lines[idx[0]])}, found {written(L[k])}",
            )
    length = float(L[idx[0]])
    tol = check_length(table, name, idx, P, C[idx[0]], length)
    D = P[idx] - C[idx[0]]
    _, i, j = _plane(D)
    normal = 3 - i - j
    tilt = np.flatnonzero(np.abs(D[:, normal]) > tol)
    if tilt.size:
        k = int(idx[tilt[0]])
        axis = "XYZ"[normal]
        raise table.fail(
            k,
            f"circle {name!r}: expected the position in the plane {'XYZ'[i]}{'XYZ'[j]} of the "
            f"centre ({axis} = {written(C[k, normal])} mm, within {tol:.3g} mm), found "
            f"{axis} = {written(P[k, normal])} mm",
        )
    seen: dict[tuple[str, float, float, float], int] = {}
    for k in idx:
        key = (runs[k], *(round(float(v), 6) for v in P[k]))
        if key in seen:
            raise table.fail(
                int(k),
                f"circle {name!r}: expected each position once in a run, found "
                f"({', '.join(written(v) for v in P[k])}) mm again (also on line "
                f"{int(table.lines[seen[key]])})",
            )
        seen[key] = int(k)


@dataclass(frozen=True)
class LengthsCircle:
    """One circle of a lengths table: its name, plane (two axis letters, θ from the first),
    centre and length (mm), and per run (direction, θ in deg in [0, 360), deviation in µm),
    sorted by θ."""

    name: str
    plane: str
    centre_mm: tuple[float, float, float]
    radius_mm: float
    runs: tuple[tuple[str, np.ndarray, np.ndarray], ...]


def read_lengths(path: str | Path) -> list[LengthsCircle]:
    """Every circle of a lengths table, checked (module docstring); a refusal is a
    :class:`~esp.core.errors.ParseError` naming the file and line."""
    table = read_table(
        path,
        ("X", "Y", "Z", "cx", "cy", "cz", "length_mm", "deviation_um"),
        ("circle",),
        (),
        ("direction",),
    )
    _check_readings(table)
    P = np.column_stack([table.columns[c] for c in ("X", "Y", "Z")])
    C = np.column_stack([table.columns[c] for c in ("cx", "cy", "cz")])
    L = np.asarray(table.columns["length_mm"])
    dev = np.asarray(table.columns["deviation_um"])
    labels = table.columns["circle"]
    dirs = (
        tuple(d.lower() for d in table.columns["direction"])
        if table.has("direction")
        else ("ccw",) * len(table)
    )
    out = []
    for name in dict.fromkeys(labels):
        idx = np.array([i for i, g in enumerate(labels) if g == name])
        for d in dict.fromkeys(dirs[k] for k in idx):
            run = [k for k in idx if dirs[k] == d]
            if len(run) < MIN_READINGS:
                raise table.fail(
                    int(run[0]),
                    f"circle {name!r} has {len(run)} readings in direction {d}; expected "
                    f"{MIN_READINGS} or more",
                )
        _check_circle(table, str(name), idx, P, C, L, list(dirs))
        centre = C[idx[0]]
        D = P[idx] - centre
        plane, i, j = _plane(D)
        theta = np.degrees(np.arctan2(D[:, j], D[:, i])) % 360.0
        directions = [dirs[k] for k in idx]
        runs = []
        for d in dict.fromkeys(directions):
            m = np.array([x == d for x in directions])
            order = np.argsort(theta[m], kind="stable")
            runs.append((d, theta[m][order], dev[idx][m][order]))
        out.append(
            LengthsCircle(
                str(name),
                plane,
                (float(centre[0]), float(centre[1]), float(centre[2])),
                float(L[idx[0]]),
                tuple(runs),
            )
        )
    if not out:
        raise ParseError(path, None, "no circle found")
    return out
