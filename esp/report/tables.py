"""The tables of a report, built once and drawn by two renderers: the terminal text
(:func:`text_lines`) and the PDF (:mod:`esp.volumetric.pdf`).

A :class:`Table` is columns and rows of finished strings: the numbers are formatted here
(:func:`esp.report.words.num`), so the terminal and the PDF show the same digits. Each
column carries its alignment and its width on the PDF page; the terminal sizes columns to
their content.

The tables follow the layout of the original ESP reports (Longstaff 2002, 4.03-4.04):
the active components with their files, the axes with offsets and simulation set-up, the
extremes of each direction, and the breakdown of every extreme point into its terms.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

from esp.core.machine import AXIS_NAMES
from esp.report.words import (
    DEG,
    UM,
    UM_PER_M,
    iso_of,
    num,
    one_line,
    source_words,
    tool_words,
    unit_label,
    xyz_text,
)

if TYPE_CHECKING:
    from esp.core.machine import Machine
    from esp.core.results import AnalysisResult, Breakdown, CaseResult, UncertaintyResult

__all__ = [
    "Column",
    "Table",
    "active_components_table",
    "axes_table",
    "breakdown_table",
    "budget_table",
    "contributors_table",
    "direction_extremes_table",
    "headline_table",
    "squareness_table",
    "sweep_table",
    "text_lines",
    "tool_cases_table",
]


@dataclass(frozen=True)
class Column:
    """One column: its header, its alignment (``"left"`` or ``"right"``), its width on
    the PDF page (inches) and whether its cells are formulae (the term symbols, drawn in
    the PDF with the embedded font that has Greek letters)."""

    header: str
    align: str = "left"
    width_in: float = 1.0
    formula: bool = False


@dataclass(frozen=True)
class Table:
    """Columns and rows of strings (one string per column in every row)."""

    columns: tuple[Column, ...]
    rows: tuple[tuple[str, ...], ...]

    def __post_init__(self) -> None:
        for row in self.rows:
            if len(row) != len(self.columns):
                raise ValueError(f"a row of {len(row)} cells in a table of {len(self.columns)}")

    @property
    def headers(self) -> tuple[str, ...]:
        return tuple(c.header for c in self.columns)

    def column(self, header: str) -> tuple[str, ...]:
        """The cells of the column headed ``header``."""
        k = self.headers.index(header)
        return tuple(row[k] for row in self.rows)


def _table(columns: Sequence[Column], rows: Sequence[Sequence[object]]) -> Table:
    return Table(tuple(columns), tuple(tuple(one_line(c) for c in row) for row in rows))


def text_lines(table: Table, indent: str = "  ") -> list[str]:
    """The table as terminal lines: a header, then the rows, each column as wide as its
    widest cell, two spaces apart, no trailing spaces."""
    widths = [len(c.header) for c in table.columns]
    for row in table.rows:
        widths = [max(w, len(cell)) for w, cell in zip(widths, row, strict=True)]
    lines = []
    for row in (table.headers, *table.rows):
        cells = [
            cell.rjust(w) if col.align == "right" else cell.ljust(w)
            for cell, w, col in zip(row, widths, table.columns, strict=True)
        ]
        lines.append((indent + "  ".join(cells)).rstrip())
    return lines


# -- the tables of an analysis ----------------------------------------------------------------


def breakdown_table(breakdown: Breakdown, directions: Sequence[str] = AXIS_NAMES) -> Table:
    """Every term of a breakdown acting in ``directions``: direction, component, ISO 230-1
    name, term (its symbol in the equation set), value (µm) and share of its direction's
    total (%; empty when that total is zero)."""
    columns = (
        Column("dir", "left", 0.4),
        Column("component", "left", 1.55),
        Column("ISO", "left", 0.6),
        Column("term", "left", 2.05, formula=True),
        Column(f"value ({UM})", "right", 1.0),
        Column("share (%)", "right", 1.0),
    )
    rows = [
        (
            t.direction,
            t.component,
            t.iso,
            t.symbol,
            num(t.value_um),
            "" if t.share_pct is None else num(t.share_pct, 1),
        )
        for t in breakdown.terms
        if t.direction in directions
    ]
    if rows and not any(r[2] for r in rows):  # no term has an ISO name: no empty column
        wide = tuple(
            c if c.header != "term" else Column("term", "left", 2.65, True) for c in columns
        )
        return _table(wide[:2] + wide[3:], [r[:2] + r[3:] for r in rows])
    return _table(columns, rows)


def _dof_text(dof: float | None) -> str:
    """Degrees of freedom: ``∞`` for none stated (a U taken as exactly known), else the
    number (Welch-Satterthwaite's input, GUM G.4)."""
    if dof is None or dof == float("inf"):
        return "∞"
    return f"{dof:.3g}"


def budget_table(uncertainty: UncertaintyResult, machine: Machine | None = None) -> Table:
    """The uncertainty budget where it is evaluated (the point of the largest volumetric
    uncertainty, :func:`esp.report.words.budget_point_words`): component, ISO name,
    model, distribution, expanded uncertainty U there with its coverage factor k and unit,
    and share of the volumetric uncertainty (%)."""
    columns = (
        Column("component", "left", 1.45),
        Column("ISO", "left", 0.6),
        Column("model", "left", 1.45),
        Column("distribution", "left", 0.95),
        Column("U", "right", 0.7),
        Column("k", "right", 0.45),
        Column("ν", "right", 0.45),
        Column("unit", "left", 0.55),
        Column("share (%)", "right", 0.75),
    )
    rows = [
        (
            b.component,
            iso_of(machine, b.component) if machine is not None else b.iso,
            b.model,
            getattr(b, "distribution", "normal"),
            num(b.U),
            f"{getattr(b, 'k', uncertainty.k):g}",
            _dof_text(getattr(b, "dof", None)),
            unit_label(b.unit),
            num(b.share_pct, 1),
        )
        for b in uncertainty.budget
    ]
    return _table(columns, rows)


def contributors_table(uncertainty: UncertaintyResult) -> Table:
    """What makes each component's standard uncertainty u where the budget is evaluated:
    per component its contributors (an instrument model's budget, or the U given directly
    or by default), each a standard uncertainty in the component's unit with sensitivity 1
    and its degrees of freedom, then the component's u (their root-sum-square). Rows in the
    budget's order; the table splits over pages with its header repeated."""
    columns = (
        Column("component", "left", 1.45),
        Column("contributor", "left", 3.2),
        Column("type", "left", 0.45),
        Column("u", "right", 0.75),
        Column("c", "right", 0.35),
        Column("ν", "right", 0.45),
        Column("unit", "left", 0.55),
    )
    rows: list[tuple[str, ...]] = []
    for b in uncertainty.budget:
        parts = getattr(b, "contributors", ())
        for n, c in enumerate(parts):
            rows.append(
                (
                    b.component if n == 0 else "",
                    c.name,
                    "A" if c.dof != float("inf") else "B",
                    num(c.u),
                    "1",
                    _dof_text(c.dof),
                    unit_label(c.unit),
                )
            )
        if len(parts) > 1:
            rows.append(("", "combined (root-sum-square)", "", num(b.u), "", _dof_text(b.dof), ""))
    return _table(columns, rows)


def sweep_table(result: AnalysisResult) -> Table:
    """The volumetric accuracy of every orientation and length of a tool sweep, or of
    every setting of a servo head or rotary table."""
    if result.sweep and result.sweep[0].tool.setting_deg:
        names = list(result.sweep[0].tool.setting_deg)
        columns = tuple(Column(f"{n} ({DEG})", "right", 0.7) for n in names) + (
            Column(f"volumetric ({UM})", "right", 1.3),
            Column("   at X, Y, Z (mm)", "left", 2.2),
        )
        rows = [
            tuple(f"{(e.tool.setting_deg or {})[n]:g}" for n in names)
            + (num(e.volumetric.value_um), "   " + xyz_text(e.volumetric.at))
            for e in result.sweep
        ]
        return _table(columns, rows)
    columns = (
        Column("length (mm)", "right", 1.1),
        Column(f"tilt ({DEG})", "right", 0.8),
        Column(f"spin ({DEG})", "right", 0.8),
        Column(f"volumetric ({UM})", "right", 1.3),
        Column("   at X, Y, Z (mm)", "left", 2.2),
    )
    rows = [
        (
            f"{e.tool.length_mm:g}",
            f"{e.tool.tilt_deg:g}",
            f"{e.tool.spin_deg:g}",
            num(e.volumetric.value_um),
            "   " + xyz_text(e.volumetric.at),
        )
        for e in result.sweep
    ]
    return _table(columns, rows)


def direction_extremes_table(case: CaseResult) -> Table:
    """The algebraic minimum and maximum of each direction's total displacement error with
    where they occur, and the range (µm)."""
    columns = (
        Column("direction", "left", 0.8),
        Column(f"min ({UM})", "right", 0.85),
        Column("   at X, Y, Z (mm)", "left", 1.75),
        Column(f"max ({UM})", "right", 0.85),
        Column("   at X, Y, Z (mm)", "left", 1.75),
        Column(f"range ({UM})", "right", 0.8),
    )
    rows = [
        (
            d,
            num(e.minimum.value_um),
            "   " + xyz_text(e.minimum.at),
            num(e.maximum.value_um),
            "   " + xyz_text(e.maximum.at),
            num(e.range_um),
        )
        for d, e in case.axes.items()
    ]
    return _table(columns, rows)


def headline_table(case: CaseResult) -> Table:
    """The volumetric and planar accuracies of a tool case with where they occur."""
    columns = (
        Column("quantity", "left", 2.2),
        Column(f"value ({UM})", "right", 1.1),
        Column("   at X, Y, Z (mm)", "left", 3.4),
    )
    rows = [
        ("volumetric accuracy", num(case.volumetric.value_um), "   " + xyz_text(case.volumetric.at))
    ]
    for plane, e in case.planar.items():
        rows.append((f"planar accuracy {plane}", num(e.value_um), "   " + xyz_text(e.at)))
    return _table(columns, rows)


def tool_cases_table(result: AnalysisResult) -> Table:
    """The volumetric accuracy of every reported tool case."""
    columns = (
        Column("tool", "left", 4.4),
        Column(f"volumetric ({UM})", "right", 1.2),
        Column("   at X, Y, Z (mm)", "left", 1.2),
    )
    rows = [
        (tool_words(c.tool), num(c.volumetric.value_um), "   " + xyz_text(c.volumetric.at))
        for c in result.cases
    ]
    return _table(columns, rows)


def active_components_table(result: AnalysisResult) -> Table:
    """The active components with data along an axis (squareness has its own table): ISO
    230-1 name, component, description, source (file or inline value) and unit."""
    m = result.machine
    columns = (
        Column("ISO", "left", 0.6),
        Column("component", "left", 1.45),
        Column("description", "left", 2.35),
        Column("source", "left", 1.8),
        Column("unit", "left", 0.55),
    )
    rows = []
    for name in sorted(result.active):
        comp = m.components[name]
        if comp.kind == "squareness":
            continue
        rows.append(
            (
                comp.iso,
                str(name),
                comp.name.description,
                source_words(comp.source),
                unit_label(comp.unit),
            )
        )
    return _table(columns, rows)


def squareness_table(result: AnalysisResult) -> Table:
    """The squareness of each pair of axes (µm/m), whether given and used."""
    m = result.machine
    columns = (
        Column("axes", "left", 0.8),
        Column("ISO", "left", 1.0),
        Column(f"value ({UM_PER_M})", "right", 1.1),
        Column("   use", "left", 2.5),
    )
    rows = []
    for pair in ("XY", "XZ", "YZ"):
        comp = m.components.get(f"squareness.{pair}")
        if comp is None:
            rows.append((pair, "", "0", "   not given"))
            continue
        used = f"squareness.{pair}" in {str(n) for n in result.active}
        iso = iso_of(m, comp.name)
        rows.append((pair, iso, f"{comp.value:g}", "   " + ("used" if used else "not used")))
    return _table(columns, rows)


def axes_table(result: AnalysisResult) -> Table:
    """Each axis: role, travel, simulated range, step, offset (mm) and grid points."""
    m = result.machine
    columns = (
        Column("axis", "left", 0.5),
        Column("role", "left", 0.8),
        Column("travel (mm)", "left", 1.35),
        Column("simulated (mm)", "left", 1.35),
        Column("step (mm)", "right", 0.85),
        Column("offset (mm)", "right", 0.95),
        Column("points", "right", 0.9),
    )
    rows = []
    for name in AXIS_NAMES:
        ax = m.axes[name]
        rows.append(
            (
                name,
                ax.role,
                f"{ax.travel_mm[0]:g} to {ax.travel_mm[1]:g}",
                f"{ax.simulate_mm[0]:g} to {ax.simulate_mm[1]:g}",
                f"{ax.step_mm:g}",
                f"{ax.offset_mm:g}",
                str(result.grid_sizes.get(name, "")),
            )
        )
    return _table(columns, rows)
