"""Text and JSON renderings of one error profile: what a file holds (``esp inspect``) and
its ISO 230-2 positioning statistics (``esp iso230-2``).

Both take a result of the library (an :class:`~esp.profile.ErrorProfile` or an
:class:`~esp.iso230.Iso230Result`) and compute nothing new; the text tables and the JSON
objects show the same numbers.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import PurePath

from esp.io.environment import absent_sensors
from esp.iso230 import AXIS_KEYS, Iso230Result
from esp.profile import DIRECTIONS, ErrorProfile
from esp.report.words import one_line, unit_label

__all__ = [
    "AXIS_DESCRIPTIONS",
    "format_table",
    "inspect_text",
    "iso230_text",
    "profile_summary",
    "unit_label",
]

#: what each ISO 230-2 axis figure is, for the terminal table
AXIS_DESCRIPTIONS = {
    "A": "bidirectional accuracy of positioning",
    "A_up": "unidirectional accuracy of positioning, up (forward)",
    "A_down": "unidirectional accuracy of positioning, down (backward)",
    "B": "reversal value (largest |Bi|)",
    "B_mean": "mean reversal value",
    "E": "bidirectional systematic positional deviation",
    "E_up": "unidirectional systematic positional deviation, up",
    "E_down": "unidirectional systematic positional deviation, down",
    "M": "range of the mean bidirectional positional deviation",
    "R": "bidirectional positioning repeatability",
    "R_up": "unidirectional positioning repeatability, up",
    "R_down": "unidirectional positioning repeatability, down",
}


def _num(value: float | None, decimals: int = 3) -> str:
    if value is None:
        return "-"
    text = f"{value:.{decimals}f}"
    return "0." + "0" * decimals if text == "-0." + "0" * decimals else text


def format_table(headers: Sequence[str], rows: Sequence[Sequence[str]], indent: str = "") -> str:
    """Columns right-aligned under their headers, two spaces apart; no trailing spaces."""
    widths = [len(h) for h in headers]
    for row in rows:
        widths = [max(w, len(cell)) for w, cell in zip(widths, row, strict=True)]
    lines = []
    for row in [headers, *rows]:
        cells = [cell.rjust(w) for cell, w in zip(row, widths, strict=True)]
        lines.append((indent + "  ".join(cells)).rstrip())
    return "\n".join(lines)


def _display_name(source: str | None) -> str:
    return one_line(PurePath(source).name) if source else "<profile>"


# -- esp inspect ----------------------------------------------------------------------------


def profile_summary(profile: ErrorProfile) -> dict:
    """What a profile holds, as the JSON object of ``esp inspect --json``.

    Keys: ``file``, ``component``, ``kind``, ``axis``, ``error_direction``,
    ``unit`` (``{"engine", "file"}``), ``targets`` (``count``, ``first_mm``, ``last_mm``,
    ``positions_mm``), ``runs`` (``{"forward": n, "backward": n}``), ``metadata`` (the
    file's user text, as read), ``environment`` (``{name: {"start", "end"}}``, the first
    two fields of each environment line, as text; a material temperature sensor recorded
    as absent, :func:`esp.io.environment.absent_sensors`, has ``null`` for both and
    ``"absent": true``), ``mean`` (``position_mm`` and the mean
    curves ``forward``, ``backward`` and ``mean``, in the engine unit; a direction that
    was not measured is absent, and ``mean`` is then that direction's mean).
    """
    mean: dict[str, object] = {"position_mm": profile.targets_mm}
    for direction in profile.directions:
        mean[direction] = profile.mean(direction)
    mean["mean"] = profile.mean("mean")
    environment: dict[str, dict] = {}
    absent = set(absent_sensors(profile.environment))
    for name, fields in profile.environment.items():
        values = tuple(fields)
        if name in absent:  # a sensor not connected: its -10 is not a reading
            environment[name] = {"start": None, "end": None, "absent": True}
            continue
        environment[name] = {
            "start": values[0] if len(values) > 0 else None,
            "end": values[1] if len(values) > 1 else None,
        }
    return {
        "file": profile.source,
        "component": profile.name,
        "kind": profile.kind,
        "axis": profile.axis,
        "error_direction": profile.error_direction,
        "unit": {"engine": profile.unit, "file": profile.input_unit},
        "targets": {
            "count": int(profile.targets_mm.size),
            "first_mm": float(profile.targets_mm[0]),
            "last_mm": float(profile.targets_mm[-1]),
            "positions_mm": profile.targets_mm,
        },
        "runs": {d: profile.run_count(d) for d in DIRECTIONS},
        "metadata": dict(profile.metadata),
        "environment": environment,
        "mean": mean,
    }


def _positions(values) -> str:
    return ", ".join(f"{float(v):g}" for v in values)


def direction_words(profile: ErrorProfile) -> str:
    """The error direction of a profile in words: the direction given; for a linear
    error its own axis (the kind implies it); for a straightness or angular error whose
    file does not record it, ``not recorded`` with the directions the kind allows and
    the configuration key that names it."""
    if profile.error_direction is not None:
        return profile.error_direction
    axis = profile.axis
    if profile.kind == "linear":
        return f"{axis} (along the axis: a linear error)" if axis else "along the axis"
    if profile.kind not in ("straightness", "angular"):
        return "not recorded"
    if axis is None:
        return "not recorded in the file"
    others = [a for a in ("X", "Y", "Z") if a != axis]
    if profile.kind == "straightness":
        allowed = f"{others[0]} or {others[1]} for a straightness of {axis}"
        example = f"axes.{axis}.errors.straightness.{others[0]}"
    else:
        allowed = f"the axis of the rotation, X, Y or Z, for an angular error of {axis}"
        example = f"axes.{axis}.errors.angular.{others[0]}"
    return f"not recorded in the file: {allowed} (a configuration names it: {example})"


def _component_words(profile: ErrorProfile) -> str:
    if profile.error_direction is None and profile.kind in ("straightness", "angular"):
        what = "error direction" if profile.kind == "straightness" else "axis of the rotation"
        return f"{profile.axis or '?'}.{profile.kind} (the {what} is not recorded)"
    return profile.name


def inspect_text(profile: ErrorProfile) -> str:
    """The terminal summary of ``esp inspect``: the same content as :func:`profile_summary`."""
    s = profile_summary(profile)
    unit = unit_label(profile.unit)
    t = s["targets"]
    lines = [
        f"file             {_display_name(profile.source)}",
        f"component        {_component_words(profile)}",
        f"kind             {s['kind']}",
        f"axis             {s['axis'] or 'not recorded'}",
        f"error direction  {direction_words(profile)}",
        f"unit             {unit} (engine), {unit_label(s['unit']['file'])} (file)",
        f"targets          {t['count']}, from {t['first_mm']:g} to {t['last_mm']:g} mm",
        f"                 {_positions(t['positions_mm'])}",
        f"runs             forward {s['runs']['forward']}, backward {s['runs']['backward']}",
    ]
    if s["metadata"]:
        lines.append("")
        lines.append("metadata")
        width = max(len(one_line(k)) for k in s["metadata"])
        for key, value in s["metadata"].items():
            lines.append(f"  {one_line(key).ljust(width)}  {one_line(value)}".rstrip())
    if s["environment"]:
        lines.append("")
        lines.append("environment")
        rows = [
            ["absent" if v.get("absent") else one_line(v[k] or "-") for k in ("start", "end")]
            for v in s["environment"].values()
        ]
        rows = [[one_line(name), *row] for name, row in zip(s["environment"], rows, strict=True)]
        rows.insert(0, ["", "start", "end"])
        widths = [max(len(r[k]) for r in rows) for k in range(3)]
        for row in rows:
            cells = [cell.ljust(w) for cell, w in zip(row, widths, strict=True)]
            lines.append(("  " + "  ".join(cells)).rstrip())
    lines.append("")
    lines.append(f"mean deviation ({unit})")
    m = s["mean"]
    columns = ["position_mm", *[d for d in DIRECTIONS if d in m], "mean"]
    rows = []
    for i, position in enumerate(m["position_mm"]):
        row = [f"{float(position):.3f}"]
        row += [_num(float(m[c][i])) for c in columns[1:]]
        rows.append(row)
    lines.append(format_table(columns, rows, indent="  "))
    return "\n".join(lines) + "\n"


# -- esp iso230-2 ---------------------------------------------------------------------------


def iso230_text(result: Iso230Result) -> str:
    """The terminal report of ``esp iso230-2``: per-target table, axis figures, notes (µm)."""
    name = _display_name(result.source)
    axis = f", {result.axis} axis" if result.axis else ""
    runs = ", ".join(f"{d} {n}" for d, n in result.runs.items())
    kind = "bidirectional" if result.bidirectional else "unidirectional"
    lines = [
        f"ISO 230-2 positioning statistics: {name}{axis}",
        f"runs: {runs} ({kind}); deviations in µm; up = forward, down = backward",
        "",
    ]
    rows = result.target_rows()
    columns = [k for k in rows[0]]
    table = [[f"{row['position_mm']:.3f}", *[_num(row[c]) for c in columns[1:]]] for row in rows]
    lines.append(format_table(columns, table))
    lines.append("")
    lines.append("axis")
    values = result.axis_values()
    width = max(len(k) for k in values)
    numbers = {k: _num(v) for k, v in values.items()}
    num_width = max(len(v) for v in numbers.values())
    for key in AXIS_KEYS:
        if key in values:
            lines.append(
                f"  {key.ljust(width)}  {numbers[key].rjust(num_width)} µm  "
                f"{AXIS_DESCRIPTIONS[key]}"
            )
    if result.notes:
        lines.append("")
        lines.extend(f"note: {note}" for note in result.notes)
    return "\n".join(lines) + "\n"
