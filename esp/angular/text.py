"""The terminal report of ``esp angular``: the set-up, then the angle per target in each
direction and their mean (from an :class:`~esp.core.angular.IndirectAngle`)."""

from __future__ import annotations

from pathlib import PurePath

from esp.core.angular import IndirectAngle
from esp.core.text import one_line
from esp.report.profile_text import format_table

__all__ = ["DIRECTION_WORDS", "angular_text", "file_name", "number_text"]

DIRECTION_WORDS = {"forward": "forward", "backward": "reverse", "mean": "bidirectional mean"}


def number_text(value: float) -> str:
    text = f"{value:.3f}"
    return "0.000" if text == "-0.000" else text


def file_name(source: str | None) -> str:
    return one_line(PurePath(source).name) if source else "-"


def angular_text(result: IndirectAngle) -> str:
    """The terminal summary: the set-up, then position / forward / backward / mean angle."""
    p = result.profile
    runs = ", ".join(f"{d} {p.run_count(d)}" for d in ("forward", "backward"))
    lines = [
        f"reference     {file_name(result.reference)}",
        f"shifted       {file_name(result.shifted)}, displaced by {result.displacement_mm:g} mm",
        f"datum         {result.datum_mm:g} mm ({DIRECTION_WORDS[result.direction]} angle "
        "zero there)",
        f"runs          {runs}",
        "method        angle = 1000 x (shifted - reference) / displacement, less its datum "
        "value (Longstaff 2002, 3.08.1)",
        "meaning       the slope of the axis' error along the displacement: the angle whose "
        "lever reproduces the difference of the two runs; a from_linear source in "
        "machine.toml reads it with the sign of that term in the machine's model "
        "(docs/conventions.md)",
        "",
        "angle (µm/m)",
    ]
    curves = {d: result.curve(d) for d in ("forward", "backward", "mean")}
    headers = ["position_mm", "forward", "backward", "mean"]
    rows = []
    for i, t in enumerate(result.targets_mm):
        row = [f"{float(t):.3f}"]
        row += ["-" if c is None else number_text(float(c[i])) for c in curves.values()]
        rows.append(row)
    lines.append(format_table(headers, rows, indent="  "))
    chosen = curves[result.direction]
    assert chosen is not None  # angular_from_linear refuses a direction without runs
    lines += [
        "",
        f"{DIRECTION_WORDS[result.direction]} angle from {number_text(float(chosen.min()))} to "
        f"{number_text(float(chosen.max()))} µm/m "
        f"(range {number_text(float(chosen.max() - chosen.min()))})",
    ]
    return "\n".join(lines) + "\n"
