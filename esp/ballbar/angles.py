"""The angle table of a home-made ballbar: one reading a row, the angle of the bar and the
deviation of its length (docs/ballbar.md, "The angle file").

Tolerant of how such tables are written: columns separated by commas, semicolons, tabs
or spaces (with semicolons, a decimal comma is read as a point); the header names the
columns in any order and case, a unit in brackets allowed (``angle (deg)``, ``deviation
[nm]``); other columns are ignored; ``#`` lines are comments, ``# key: value`` lines state
the test conditions (:mod:`esp.ballbar.conditions`).

* ``angle`` (or ``angle_deg``): the angle θ of the bar in degrees, from the first axis of
  the plane towards the second; any turn (θ is taken modulo 360).
* ``deviation`` (or ``deviation_um``, ``deviation_nm``, ``deviation_mm``): the deviation of
  the measured length from the radius, outward positive; in µm unless the header or a
  ``# unit:`` line (um, nm, mm) says otherwise.
* ``direction`` (optional): ``ccw`` (θ increasing along the run) or ``cw``; without it a
  run's direction is that of its angles, and a file whose angles turn back once holds
  two runs, the second from the line where they turn.

The radius comes from ``--radius`` or a ``# radius:`` line (mm), the plane from
``--plane`` or a ``# plane:`` line (XY by default). A row that cannot be read is refused
at its file and line, with what was expected and what was found.
"""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np

from esp.ballbar.conditions import Conditions
from esp.ballbar.records import Circle, Run
from esp.core.errors import ConfigError, ParseError
from esp.identify.ballbar import DIRECTIONS, MIN_READINGS

__all__ = ["read_angles"]

_UNITS = {"um": 1.0, "µm": 1.0, "micron": 1.0, "nm": 1e-3, "mm": 1e3}
_DIRECTION_WORDS = {
    "ccw": "ccw",
    "counterclockwise": "ccw",
    "anticlockwise": "ccw",
    "cw": "cw",
    "clockwise": "cw",
}
_NUMBER = re.compile(r"^[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?$")
#: deviations beyond this many µm are refused (as every displacement esp reads)
_DEVIATION_LIMIT_UM = 1e4
_PLANES = ("XY", "YX", "YZ", "ZY", "ZX", "XZ")


def _split(line: str, sep: str | None) -> list[str]:
    return [c.strip() for c in (line.split(sep) if sep else line.split())]


def _column(name: str) -> tuple[str, str | None]:
    """A header cell as (name, unit in brackets or after an underscore, or None)."""
    m = re.match(r"^\s*([A-Za-z_µ]+?)\s*(?:[(\[]\s*([^)\]]*)\s*[)\]])?\s*$", name)
    if m is None:
        return name.strip().lower(), None
    base, unit = m.group(1).lower(), m.group(2)
    for suffix in ("_deg", "_um", "_nm", "_mm"):
        if base.endswith(suffix) and base != suffix:
            return base[: -len(suffix)], suffix[1:]
    return base, unit.strip().lower() if unit else None


def _unit_factor(path: Path, line: int | None, where: str, unit: str) -> float:
    factor = _UNITS.get(unit.strip().lower())
    if factor is None:
        raise ParseError(
            path, line, f"{where}: expected a unit of um, nm or mm, found {unit.strip()[:20]!r}"
        )
    return factor


def _runs_by_order(path: Path, lines: list[int], angle: np.ndarray) -> list[tuple[str, np.ndarray]]:
    """Without a direction column: one run in the sense of its angles, or two when the
    angles turn back once (the second from the line where they turn)."""
    step = (np.diff(angle) + 180.0) % 360.0 - 180.0
    turns: list[int] = []  # the first row of each new run
    last = -1  # the last step that moved
    for j, v in enumerate(step):
        if v == 0.0:
            continue
        if last >= 0 and np.sign(v) == -np.sign(step[last]):
            # the turning point ends the run before; a reading repeated there starts the next
            turns.append(last + 2)
        last = j
    if len(turns) > 1:
        raise ParseError(
            path,
            lines[turns[1]],
            "expected the angles to run one way in each run (two runs at most without a "
            "direction column), found them turning back a second time; add a direction "
            "column (ccw, cw)",
        )
    bounds = [0, *turns, angle.size]
    out = []
    for a, b in zip(bounds[:-1], bounds[1:], strict=True):
        idx = np.arange(a, b)
        s = np.sum(step[a : b - 1]) if b - a > 1 else 0.0
        out.append(("ccw" if s >= 0 else "cw", idx))
    return out


def read_angles(
    path: str | Path,
    lines: list[str],
    conditions: Conditions,
    *,
    radius_mm: float | None = None,
    plane: str | None = None,
) -> Circle:
    """The circle of an angle table (module docstring); ``lines`` are the file's lines."""
    p = Path(path)
    header: list[str] | None = None
    sep: str | None = None
    rows: list[tuple[int, list[str]]] = []
    for number, raw in enumerate(lines, start=1):
        s = raw.strip().lstrip("\ufeff")
        if not s or s.startswith("#"):
            continue
        if header is None:
            sep = next((c for c in (",", ";", "\t") if c in s), None)
            header = _split(s, sep)
            head_line = number
            continue
        rows.append((number, _split(s, sep)))
    assert header is not None  # the caller found the angle column in it
    cols = [_column(h) for h in header]
    names = [c[0] for c in cols]
    index: dict[str, int] = {}
    for want in ("angle", "deviation", "direction"):
        found = [k for k, n in enumerate(names) if n == want]
        if len(found) > 1:
            raise ParseError(p, head_line, f"expected one column {want!r}, found {len(found)}")
        if found:
            index[want] = found[0]
    if "deviation" not in index:
        raise ParseError(
            p,
            head_line,
            f"expected a header with the columns angle and deviation, found {', '.join(header)}",
        )
    unit = cols[index["deviation"]][1]
    file_unit = conditions.unit
    if unit is None:
        unit = file_unit or "um"
        factor = _unit_factor(p, conditions.line_of("unit"), "'# unit:'", unit)
    else:
        factor = _unit_factor(p, head_line, f"column {header[index['deviation']]}", unit)
        if file_unit is not None and _UNITS.get(file_unit.strip().lower()) != factor:
            raise ParseError(
                p,
                conditions.line_of("unit"),
                f"'# unit:' expected the unit of the deviation column ({unit}), found "
                f"{file_unit!r}",
            )
    angle_unit = cols[index["angle"]][1]
    if angle_unit not in (None, "deg", "°", "degree", "degrees"):
        raise ParseError(
            p, head_line, f"column angle: expected degrees (deg), found the unit {angle_unit!r}"
        )
    if not rows:
        raise ParseError(p, None, "expected readings after the header, found none")
    decimal_comma = sep == ";"
    width = max(index.values()) + 1
    angle = np.empty(len(rows))
    dev = np.empty(len(rows))
    dirs: list[str] = []
    for r, (number, cells) in enumerate(rows):
        if len(cells) < width:
            raise ParseError(
                p, number, f"expected at least {width} values as in the header, found {len(cells)}"
            )
        for column, out in (("angle", angle), ("deviation", dev)):
            token = cells[index[column]]
            text = token.replace(",", ".") if decimal_comma else token
            if not _NUMBER.match(text) or not math.isfinite(float(text)):
                raise ParseError(
                    p, number, f"column {column}: expected a number, found {token[:40]!r}"
                )
            out[r] = float(text)
        if abs(angle[r]) > 720.0:
            raise ParseError(
                p,
                number,
                f"column angle: expected degrees within ±720, found {cells[index['angle']][:40]}",
            )
        dev[r] *= factor
        if abs(dev[r]) > _DEVIATION_LIMIT_UM:
            raise ParseError(
                p,
                number,
                f"column deviation: expected a deviation within ±{_DEVIATION_LIMIT_UM:g} um, "
                f"found {cells[index['deviation']]} {unit}",
            )
        if "direction" in index:
            given = cells[index["direction"]]
            word = _DIRECTION_WORDS.get(given.lower())
            if word is None:
                raise ParseError(
                    p, number, f"column direction: expected ccw or cw, found {given[:40]!r}"
                )
            dirs.append(word)
    line_of = [n for n, _ in rows]
    if "direction" in index:
        groups = [(d, np.array([k for k, x in enumerate(dirs) if x == d])) for d in DIRECTIONS]
        groups = [(d, idx) for d, idx in groups if idx.size]
    else:
        groups = _runs_by_order(p, line_of, angle)
    radius = radius_mm if radius_mm is not None else conditions.radius_mm
    if radius is None:
        raise ParseError(
            p, None, "expected the radius of the circle: a '# radius: R mm' line or --radius"
        )
    name_plane = (plane or conditions.plane or "XY").strip().upper()
    if name_plane not in _PLANES:
        expected = f"expected one of {', '.join(_PLANES)}, found {name_plane[:10]!r}"
        if plane:
            raise ConfigError("--plane", expected)
        raise ParseError(p, conditions.line_of("plane"), f"'# plane:' {expected}")
    runs = []
    for d, idx in groups:
        if idx.size < MIN_READINGS:
            raise ParseError(
                p,
                line_of[int(idx[0])],
                f"the {d} run has {idx.size} readings; expected {MIN_READINGS} or more",
            )
        theta = angle[idx] % 360.0
        order = np.argsort(theta, kind="stable")
        same = np.flatnonzero(np.abs(np.diff(theta[order])) < 1e-9)
        if same.size:
            a, b = sorted((int(idx[order[same[0]]]), int(idx[order[same[0] + 1]])))
            raise ParseError(
                p,
                line_of[b],
                f"expected each angle once in the {d} run, found {theta[order][same[0]]:g} deg "
                f"again (also on line {line_of[a]})",
            )
        runs.append(Run(d, theta[order], dev[idx][order]))
    return Circle(
        p.stem,
        name_plane,
        (0.0, 0.0, 0.0),
        float(radius),
        tuple(runs),
        str(p),
        conditions.updated(radius_mm=float(radius), plane=name_plane),
    )
