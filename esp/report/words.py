"""The words and number formats every rendering of a result shares: the terminal report,
the PDF, the figures and the tables.

One spelling of each unit (:data:`UM` is ``µm`` with the micro sign U+00B5, everywhere a
person reads it; JSON and CSV keys keep ASCII ``_um``), one way to print a number (no
``-0.000``), one way to name a point, a tool, a datum, the runs used and the method of an
uncertainty. User text (a machine name, a file name, a serial) goes through
:func:`one_line` before it reaches a line of text, so that a newline or another control
character in it cannot split a row.
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from typing import TYPE_CHECKING

from esp.core.machine import AXIS_NAMES
from esp.core.text import one_line

if TYPE_CHECKING:
    from esp.core.machine import Machine
    from esp.core.models.tool import ToolCase
    from esp.core.names import ComponentName
    from esp.core.results import AnalysisResult, MonteCarloSummary, UncertaintyResult

__all__ = [
    "ANGLE_WORDS",
    "DEG",
    "KIND_WORDS",
    "METHOD_SHORT",
    "METHOD_WORDS",
    "RUNS_USED",
    "RUNS_USED_SHORT",
    "UM",
    "UM_PER_M",
    "at_text",
    "budget_point_words",
    "datum_words",
    "grid_words",
    "is_plan",
    "num",
    "offset_text",
    "one_line",
    "runs_words",
    "source_words",
    "tool_short",
    "tool_words",
    "u_not_evaluated",
    "u_text",
    "u_where",
    "uncertainty_headline",
    "unit_label",
    "xyz_text",
]

#: micrometre, with the micro sign (U+00B5): the one spelling of every human-readable output
UM = "µm"
#: micrometre per metre (= µrad), the unit of angular and squareness errors
UM_PER_M = "µm/m"
DEG = "°"

_UNIT_LABELS = {"um": UM, "um/m": UM_PER_M, "urad": "µrad", "μm": UM, "μm/m": UM_PER_M}

KIND_WORDS = {
    "linear": "Linear",
    "straightness": "Straightness",
    "angular": "Angular",
    "mechanical": "Mechanical",
    "squareness": "Squareness",
}

#: ``analysis.direction``: which runs of each file the synthesis uses
RUNS_USED = {
    "mean": "the bidirectional mean of the forward and reverse runs",
    "forward": "the mean of the forward runs",
    "backward": "the mean of the reverse runs",
}
#: the same, short, for legends
RUNS_USED_SHORT = {
    "mean": "bidirectional mean",
    "forward": "mean of the forward runs",
    "backward": "mean of the reverse runs",
}

METHOD_WORDS = {
    "summation": "summation, an upper bound (per direction the sum of |sensitivity| x U, "
    "then the vector sum: no choice of signs of the components exceeds it)",
    "pure-addition": "pure addition (the printed model run with U in place of each error, "
    "terms added with their signs; Longstaff 2002, 4.01.3)",
    "statistical": "statistical (root-sum-square per direction, then the vector sum)",
    "montecarlo": "statistical, with a Monte Carlo distribution of the volumetric accuracy",
}
#: the same, short, for headlines
METHOD_SHORT = {
    "summation": "summation bound",
    "pure-addition": "pure addition, signs as printed",
    "statistical": "statistical",
    "montecarlo": "montecarlo",
}

#: what the angles of the compensated cases are (Longstaff 2002, 3.10.2-3.10.5)
ANGLE_WORDS = {
    "3.10.2": "Φ are the residual angles after compensation, from two linear runs (3.08)",
    "3.10.4": "Φ are the residual angles after compensation at the TCP, from two linear runs "
    "with a zero-length tool (3.08)",
    "3.10.5": "Φ are the residual angles at the MCP (angular data, from two linear runs); "
    "γ the mechanical angles carried by the tool (mechanical data, and the top axis' "
    "angular data)",
}


def unit_label(unit: str | None) -> str:
    """The unit as printed for people: ``"um"`` -> ``"µm"``, ``"um/m"`` -> ``"µm/m"``;
    ``"-"`` for none."""
    if unit is None:
        return "-"
    return _UNIT_LABELS.get(unit, unit)


def num(value: float | None, decimals: int = 3, empty: str = "") -> str:
    """``value`` with ``decimals`` places; never ``-0.000``; ``empty`` for None."""
    if value is None:
        return empty
    text = f"{value:.{decimals}f}"
    if text.startswith("-") and float(text) == 0:
        return text[1:]
    return text


def at_text(point: Mapping[str, float]) -> str:
    """``X=990, Y=360, Z=0`` (mm, shortest form)."""
    return ", ".join(f"{a}={point[a]:g}" for a in AXIS_NAMES)


def xyz_text(point: Mapping[str, float]) -> str:
    """``990, 360, 0``: a point in a column headed ``X, Y, Z (mm)``."""
    return ", ".join(f"{point[a]:g}" for a in AXIS_NAMES)


def offset_text(offset: Mapping[str, float], decimals: int = 3) -> str:
    """``X=114.907, Y=83.861, Z=0.000``: a tool offset (mm) in one number format, the
    three values with the same number of decimals -- the fewest, up to ``decimals``, that
    show each of them to ``decimals`` places (``X=0, Y=0, Z=150`` for a round offset).
    Never ``-0``.

    Examples
    --------
    >>> offset_text({"X": 114.90666, "Y": 83.86058, "Z": 0.0})
    'X=114.907, Y=83.861, Z=0.000'
    >>> offset_text({"X": 0.0, "Y": -0.0, "Z": 150.0})
    'X=0, Y=0, Z=150'
    >>> offset_text({"X": 12.5, "Y": 0.25, "Z": -1e-12})
    'X=12.50, Y=0.25, Z=0.00'
    """
    values = [float(offset[a]) for a in AXIS_NAMES]
    rounded = [round(v, decimals) for v in values]
    places = next(
        (
            d
            for d in range(decimals + 1)
            if all(round(v, d) == r for v, r in zip(values, rounded, strict=True))
        ),
        decimals,
    )
    return ", ".join(f"{a}={num(v, places)}" for a, v in zip(AXIS_NAMES, values, strict=True))


def source_words(source: object) -> str:
    """Where a component's data come from, for people, on one line: a file name as given,
    or an inline value with its unit spelled as everywhere else (``constant 5 µm/m``)."""
    text = one_line(source)
    match = re.fullmatch(r"constant (\S+) (\S+)(.*)", text)
    if match:
        value, unit, rest = match.groups()
        return f"constant {value} {unit_label(unit)}{rest}"
    return text


def runs_words(direction: str) -> str:
    """The runs the synthesis uses, in words."""
    return RUNS_USED.get(direction, direction)


def setting_text(tool: ToolCase) -> str:
    """The head or table angles of a tool case: ``A 90°, C 180°`` (empty without)."""
    if not tool.setting_deg:
        return ""
    return ", ".join(f"{n} {v:g}{DEG}" for n, v in tool.setting_deg.items())


def tool_words(tool: ToolCase) -> str:
    """A tool case in full: ``length 150 mm, tilt 45°, spin 90° (offset X=.., Y=.., Z=..
    mm)``, the head or table setting, or the MCP."""
    if tool.length_mm is None:
        return "none: evaluated at the measurement centre point (MCP)"
    offset = offset_text(tool.offset_mm)
    if tool.setting_deg:
        return f"setting {setting_text(tool)}: tool offset {offset} mm"
    if tool.tilt_deg is None:
        return f"offset {offset} mm (length {tool.length_mm:g} mm)"
    return (
        f"length {tool.length_mm:g} mm, tilt {tool.tilt_deg:g}{DEG}, spin "
        f"{tool.spin_deg:g}{DEG} (offset {offset} mm)"
    )


def tool_short(tool: ToolCase) -> str:
    """A tool case in a few words, for titles: ``at the MCP``, ``tool offset X=.. mm``,
    ``tool 150 mm, tilt 45°, spin 90°``."""
    if tool.length_mm is None:
        return "at the MCP"
    if tool.setting_deg:
        return f"setting {setting_text(tool)}"
    if tool.tilt_deg is None:
        return f"tool offset {offset_text(tool.offset_mm)} mm"
    return f"tool {tool.length_mm:g} mm, tilt {tool.tilt_deg:g}{DEG}, spin {tool.spin_deg:g}{DEG}"


def datum_words(result: AnalysisResult) -> str:
    """The datum of the errors of ``result``, in words."""
    if result.datum is None:
        return "none: the errors are the raw synthesis"
    datum = result.machine.analysis.datum
    name = f' ("{datum}")' if isinstance(datum, str) else ""
    return f"errors are relative to the point {at_text(result.datum)} mm{name}"


def grid_words(result: AnalysisResult) -> str:
    """The simulated volume and its grid, in words."""
    m = result.machine
    volume = "; ".join(
        f"{a} {m.axes[a].simulate_mm[0]:g} to {m.axes[a].simulate_mm[1]:g} mm" for a in AXIS_NAMES
    )
    s = result.grid_sizes
    n = s["X"] * s["Y"] * s["Z"]
    sweep = f" for each of {len(result.sweep)} {swept_words(result)}" if result.sweep else ""
    return f"{volume}; grid {s['X']} x {s['Y']} x {s['Z']} = {n} points{sweep}"


def swept_words(result: AnalysisResult) -> str:
    """What a sweep goes over: ``head settings``, ``table settings`` or ``tool
    orientations``."""
    m = result.machine
    if m.head is not None and m.table is not None:
        return "head and table settings"
    if m.head is not None:
        return "head settings"
    if m.table is not None:
        return "table settings"
    return "tool orientations"


def setup_words(machine: Machine) -> list[str]:
    """The servo head and rotary table of a five-axis machine, one line each (none
    without)."""
    lines = []
    for kind, setup in (("Servo head", machine.head), ("Rotary table", machine.table)):
        if setup is None:
            continue
        what = getattr(setup, kind == "Servo head" and "head" or "table")
        angles = "; ".join(
            f"{n} " + ", ".join(f"{v:g}" for v in values) + DEG
            for n, values in setup.angles_deg.items()
        )
        lines.append(
            f"{kind}: {what.name}, from {setup.source}; angles {angles}, every combination"
        )
    return lines


def iso_of(machine: Machine, name: str | ComponentName) -> str:
    """The ISO 230-1 symbol of a component on this machine: a squareness as the location
    error it is on this machine, with its sign (:func:`esp.core.models.bind.squareness_iso`);
    an error of a servo head or a rotary table (``head.ThetaAs``, ``table.X0C``) by its own
    symbol."""
    from esp.core.models.bind import squareness_iso
    from esp.core.names import ComponentName

    if isinstance(name, str) and name.startswith(("head.", "table.")):
        return name.split(".", 1)[1]
    name = ComponentName.parse(name)
    if name.kind == "squareness":
        return squareness_iso(name, machine.roles)
    return name.iso


def montecarlo_grid_words(mc: MonteCarloSummary) -> str:
    """``, on 120156 points of the analysis grid (float32)``, or nothing when the summary
    does not say."""
    points = getattr(mc, "grid_points", None)
    if not points:
        return ""
    dtype = getattr(mc, "dtype", None)
    return f", on {points} points of the analysis grid" + (f" ({dtype})" if dtype else "")


def is_plan(result: AnalysisResult) -> bool:
    """Whether ``result`` is an uncertainty plan: an ``[uncertainty]`` table and no error
    data (no active component, every error zero). Its reports headline the volumetric
    uncertainty and claim no accuracy."""
    return (
        result.uncertainty is not None
        and not result.active
        and all(c.volumetric.value_um == 0.0 for c in result.cases)
    )


def u_text(expanded_um: float) -> str:
    """An expanded uncertainty to two significant digits (GUM 7.2.6), ``"2.1"``; ``"0"``
    for a zero U (at a datum, where the error is zero by definition)."""
    from esp.core.rounding import rounded

    if not expanded_um > 0.0:
        return "0"
    return rounded(0.0, expanded_um)[1]


def uncertainty_headline(u: UncertaintyResult) -> str:
    """``U = 26 µm (k = 2, statistical)``; ``U ≤ 62 µm (k = 2, summation bound)`` for the
    bound: U to two significant digits (GUM 7.2.6)."""
    relation = "≤" if u.method == "summation" else "="
    return (
        f"U {relation} {u_text(u.volumetric.value_um)} {UM} "
        f"(k = {u.k:g}, {METHOD_SHORT.get(u.method, u.method)})"
    )


def u_where(u: UncertaintyResult, unit: str = "") -> str:
    """Where the volumetric U is largest (``"largest at X=0, Y=0, Z=600 mm"`` with
    ``unit = " mm"``), or that it is the same everywhere when it is
    (:attr:`~esp.core.results.UncertaintyResult.uniform`)."""
    if getattr(u, "uniform", False):
        return "the same at every point of the volume"
    return f"largest at {at_text(u.volumetric.at)}{unit}"


def u_not_evaluated(result: AnalysisResult, most: int = 4) -> str:
    """Why an analysis states no U: ``"not evaluated (no [uncertainty] table)"``, or
    ``"not evaluated (no U for X.linear, Y.linear, Z.linear, X.angular.Y and 15 more)"``
    when the table leaves out components the model uses (at most ``most`` named)."""
    missing = [str(n) for n in getattr(result, "uncertainty_missing", ())]
    if not missing:
        return "not evaluated (no [uncertainty] table)"
    names = ", ".join(missing[:most])
    if len(missing) > most:
        names += f" and {len(missing) - most} more"
    return f"not evaluated (no U for {names})"


def budget_point_words(uncertainty: UncertaintyResult) -> str:
    """Where the uncertainty budget is evaluated, and what it combines to there."""
    at = getattr(uncertainty, "budget_at", uncertainty.volumetric.at)
    words = f"at {at_text(at)} mm, the point of the largest volumetric uncertainty"
    tool = getattr(uncertainty, "budget_tool", None)
    if tool is not None and tool.length_mm is not None:
        words += f" ({tool_short(tool)})"
    u = getattr(uncertainty, "u_um", None)
    if u is not None and uncertainty.method == "summation":
        words += f"; the bound before expansion (Σ |c|·u per direction) {num(u)} {UM}"
    elif u is not None and uncertainty.method == "pure-addition":
        words += f"; the sum before expansion {num(u)} {UM}"
    elif u is not None:
        words += f"; combined standard uncertainty u = {u_text(u)} {UM}"
    dof = getattr(uncertainty, "dof_eff", None)
    if dof is not None and dof != float("inf"):
        words += f", effective degrees of freedom {dof:.1f} (Welch-Satterthwaite)"
    coverage = getattr(uncertainty, "coverage", None)
    if coverage is not None:
        words += f", k = {uncertainty.k:.3g} for a coverage probability of {coverage:g}"
    return words
