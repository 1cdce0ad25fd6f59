"""Read a machine description (``machine.toml``) into a :class:`esp.core.machine.Machine`.

The configuration is a user-facing contract; every key is documented in
``docs/configuration.md``. The reader is strict: an unknown key anywhere is refused with a
"did you mean" suggestion, and every problem raises :class:`esp.core.errors.ConfigError` naming
the dotted key (``axes.X.step``, ``axes.Y.errors.angular.Z``), what was expected and what
was found. Errors inside a data file (:class:`~esp.core.errors.ParseError`,
:class:`~esp.core.errors.DataError`) pass through unchanged.

A new top-level table is a name in :data:`SECTIONS` and a ``_section_<name>`` method of
:class:`MachineReader`; a new kind of error source is an entry of
:data:`esp.config.sources.SOURCE_BUILDERS`.

References
----------
Longstaff (2002): 3.02-3.03 (configurations and B/M/T notation), 3.05 (datum), 3.07
eq. 3.6-3.9 (tool length and angles), 3.09 eq. 3.14-3.16 (mechanical angles γ), 3.10.1-3.10.5
(point of evaluation and compensation), 3.11-3.12 and figures 3.7-3.10 (the inputs of the
original program), 4.01.2.1 (straightness fit).
"""

from __future__ import annotations

import math
import os
from collections.abc import Mapping, Sequence
from dataclasses import replace
from datetime import date, datetime, time
from pathlib import Path
from typing import Any

from esp.config.reader import Reader, quoted
from esp.config.sources import SQUARENESS_SOURCES, Slot, bare_constant, read_source
from esp.config.tolerance import read_tolerance
from esp.config.uncertainty import read_uncertainty
from esp.core.errors import ConfigError
from esp.core.machine import (
    AXIS_NAMES,
    CONFIGURATIONS,
    ROLES,
    Analysis,
    Axis,
    Component,
    ComponentName,
    HeadSetup,
    Machine,
    ReportInfo,
    TableSetup,
    Tool,
)
from esp.core.text import NAME_MAX_CHARS, closest
from esp.core.uncertainty.spec import PURE_ADDITION_MODEL
from esp.core.values import shown
from esp.io.tomlfile import read_toml_file

__all__ = [
    "ANALYSIS_KEYS",
    "AXIS_KEYS",
    "ERROR_KEYS",
    "MACHINE_KEYS",
    "MAX_GRID_POINTS",
    "MAX_PLANE_POINTS",
    "MAX_TOOL_ANGLE_DEG",
    "MAX_TOOL_CASES",
    "MAX_WORK_POINTS",
    "SECTIONS",
    "TOOL_KEYS",
    "MachineReader",
    "grid_count",
    "load_machine",
    "machine_from_dict",
]

# -- resource limits (docs/reliability.md): refused when the configuration is read, before
# any work, with the numbers and the key to change

#: grid points of one tool case (the product of the three axes' grid sizes); about 20 s
#: for the engine in the worst case (a field without trend visits every point)
MAX_GRID_POINTS = 2_000_000_000
#: points of the three coordinate planes of the grid together (nx·ny + nx·nz + ny·nz): the
#: engine keeps nine arrays of the planes' sizes, about 0.3 GB at this limit
MAX_PLANE_POINTS = 10_000_000
#: tool cases (tool lengths x orientations of a sweep)
MAX_TOOL_CASES = 10_000
#: grid points over all tool cases (points per case x tool cases)
MAX_WORK_POINTS = 10_000_000_000
#: the largest tilt or spin of a tool, degrees
MAX_TOOL_ANGLE_DEG = 360.0

SECTIONS = (
    "machine",
    "analysis",
    "axes",
    "squareness",
    "tool",
    "head",
    "table",
    "uncertainty",
    "tolerance",
    "report",
)
#: the keys of ``[report]``: who the report is for and by whom it is issued
REPORT_KEYS = ("serial", "owner", "operator", "laboratory")

MACHINE_KEYS = ("name", "configuration", "axes", "serial", "location", "measured_by", "date")
INFO_KEYS = ("serial", "location", "measured_by", "date")
ANALYSIS_KEYS = (
    "point",
    "compensation",
    "direction",
    "datum",
    "straightness_fit",
    "extrapolate",
    "model",
    "angle_convention",
)
AXIS_KEYS = ("travel", "simulate", "step", "offset", "errors")
ERROR_KEYS = ("linear", "straightness", "angular", "mechanical")
TOOL_KEYS = ("lengths", "orientation", "sweep", "spindle")
#: thesis 3.12: 45° steps in the plane through the spindle axis, 90° steps about it; the
#: tilt is measured from the spindle direction, so 0-90° is the hemisphere a head can hold
DEFAULT_SWEEP_TILT_DEG = (0.0, 45.0, 90.0)
DEFAULT_SWEEP_SPIN_DEG = (0.0, 90.0, 180.0, 270.0)

_POINTS = ("MCP", "TCP")
_COMPENSATIONS = ("none", "MCP", "TCP")
_DIRECTIONS = {"forward": "forward", "reverse": "backward", "mean": "mean"}
_DIRECTION_ALIASES = {"backward": "backward"}
_DATUMS = ("none", "negative", "centre")
_FITS = ("least-squares", "endpoint", "none")
MODELS = ("rigid-body", "as-printed")
ANGLE_CONVENTIONS = ("iso230-1", "thesis")
_SPINDLES = tuple(s + a for a in AXIS_NAMES for s in "+-")


def load_machine(path: str | os.PathLike[str]) -> Machine:
    """Read a ``machine.toml`` file.

    Parameters
    ----------
    path : the configuration file; data files named in it are found relative to its folder

    Returns
    -------
    Machine

    Raises
    ------
    ConfigError
        The file is missing, not a regular file or unreadable (key ``"<file>"``), is not
        valid TOML (key ``"<toml>"``, with the line and column), or a key is unknown,
        missing or holds a value that does not fit (the dotted key).
    ParseError, DataError
        A data file named in the configuration cannot be read or used.
    """
    p = Path(path)
    return machine_from_dict(read_toml_file(p), p.parent, source=str(p))


def machine_from_dict(
    data: Mapping[str, Any],
    base_dir: str | os.PathLike[str],
    source: str | None = None,
    *,
    identify: bool = False,
) -> Machine:
    """Build a :class:`~esp.core.machine.Machine` from the parsed content of a ``machine.toml``.

    For tests and what-if studies in code: ``data`` is what :func:`tomllib.loads` returns
    (plain dicts, lists, numbers and strings).

    Parameters
    ----------
    data : the configuration as nested mappings
    base_dir : the folder that relative data-file paths are resolved against
    source : the configuration file's name, used in error messages and kept as
        ``Machine.source``
    identify : accept a rotary table with errors to identify (``{ identify = ... }``;
        :mod:`esp.identify`), which are zero in the machine returned

    Raises
    ------
    ConfigError, ParseError, DataError
        As :func:`load_machine`.
    """
    reader = MachineReader(Path(base_dir), source)
    reader.identify = identify
    return reader.machine(data)


def _settings(setup: HeadSetup | TableSetup | None) -> int:
    """The number of settings of a head or table (1 without one)."""
    if setup is None:
        return 1
    n = 1
    for values in setup.angles_deg.values():
        n *= len(values)
    return n


class MachineReader(Reader):
    """Reads the sections of one ``machine.toml`` into a :class:`~esp.core.machine.Machine`."""

    #: accept a rotary table with errors to identify (:func:`machine_from_dict`)
    identify = False

    def machine(self, data: Mapping[str, Any]) -> Machine:
        if isinstance(data, Mapping) and "identify" in data:
            self.fail(
                "identify",
                "this file describes an identification: run 'esp identify' on it "
                "(docs/identify.md), then analyse the machine.toml it writes",
            )
        top = self.table(data, "", SECTIONS, required=("machine", "axes"))
        name, configuration, roles, info = self._section_machine(top["machine"])
        analysis = self._section_analysis(top.get("analysis", {}))
        self.direction = analysis.direction
        axes, components = self._section_axes(top["axes"], roles)
        components.update(self._section_squareness(top.get("squareness", {})))
        tool = self._section_tool(top["tool"]) if "tool" in top else None
        head = self._section_head(top["head"]) if "head" in top else None
        table = self._section_table(top["table"]) if "table" in top else None
        if head is not None and table is not None:
            shared = [c for c in head.head.coordinates if c in table.table.coordinates]
            if shared:
                self.fail(
                    "head",
                    f"the head and the table both have an axis {shared[0]}: a setting names "
                    "each axis once; write one of the chains with another coordinate name",
                )
        if head is not None:
            if tool is not None:
                self.fail("tool", "the servo head of [head] carries the tool; remove [tool]")
            if analysis.point != "TCP":
                self.fail(
                    "analysis.point",
                    "a servo head ([head]) puts the tool tip away from the MCP: expected 'TCP', "
                    f"found {analysis.point!r}",
                )
        report = self._section_report(top["report"]) if "report" in top else None
        uncertainty = None
        if "uncertainty" in top:
            uncertainty = read_uncertainty(
                self,
                top["uncertainty"],
                components,
                {
                    "head": head.head if head is not None else None,
                    "table": table.table if table is not None else None,
                },
            )
        tolerance = read_tolerance(self, top["tolerance"]) if "tolerance" in top else None
        self._check_datum(analysis, axes)
        self._check_work(axes, tool, analysis, _settings(head) * _settings(table))
        if analysis.point == "TCP" and tool is None and head is None:
            self.fail("tool", "point = 'TCP' needs a [tool] table (lengths and orientation)")
        if (
            uncertainty is not None
            and uncertainty.method == "pure-addition"
            and analysis.model != "as-printed"
        ):
            self.fail("uncertainty.method", PURE_ADDITION_MODEL.format(model=analysis.model))
        if analysis.model == "as-printed" and configuration == "BMTwt":
            self.fail(
                "analysis.model",
                "the thesis prints no equations for BMTwt (all axes carry the workpiece, "
                "3.03); use model = 'rigid-body'",
            )
        warnings = []
        if tool is not None and analysis.point == "MCP":
            warnings.append(
                "[tool] is given but analysis.point = 'MCP': the errors are evaluated without "
                "the tool; set analysis.point = 'TCP' to evaluate at the tool tip"
            )
        for n in AXIS_NAMES:
            lo, hi = axes[n].travel_mm
            off = axes[n].offset_mm
            if not lo <= off <= hi:
                warnings.append(
                    f"axes.{n}.offset = {off:g} mm lies outside the travel [{lo:g}, {hi:g}] mm: "
                    "the other axes' errors are levered from a line the axis never reaches"
                )
        return Machine(
            name=name,
            configuration=configuration,
            roles=roles,
            axes=axes,
            components=components,
            analysis=analysis,
            tool=tool,
            info=info,
            source=self.source,
            uncertainty=uncertainty,
            inputs=tuple(dict.fromkeys(self.inputs)),
            warnings=tuple(warnings),
            head=head,
            table=table,
            report=report,
            tolerance=tolerance,
        )

    def _section_report(self, value: Any) -> ReportInfo:
        """``[report]``: serial, owner, operator and laboratory, each a string, each shown
        in the title block of the documents when given."""
        t = self.table(value, "report", REPORT_KEYS)
        return ReportInfo(
            **{k: self.string(t[k], f"report.{k}", NAME_MAX_CHARS) for k in REPORT_KEYS if k in t}
        )

    def _setting_angles(
        self, value: Any, key: str, coordinates: Sequence[str]
    ) -> dict[str, tuple[float, ...]]:
        """``angles = { A = [...], C = [...] }``: the angles of every coordinate of a head
        or table, in degrees; every combination is one setting."""
        if value is None:
            self.fail(
                key, f"required key is missing (the angles to sweep: {', '.join(coordinates)})"
            )
        t = self.table(value, key, tuple(coordinates), required=tuple(coordinates))
        return {c: self._angles(t[c], f"{key}.{c}") for c in coordinates}

    def _section_head(self, value: Any) -> HeadSetup:
        """``[head]``: a servo head on the ram, from a head file (``file``) or inline (the
        keys of a head file's ``[head]``, docs/heads.md), and its ``angles``."""
        from esp.config.devices import head_from_dict, load_head

        if not isinstance(value, Mapping):
            self.fail("head", f"expected a table, found {value!r}")
        if "file" in value:
            self.table(value, "head", ("file", "angles"))
            given = self.string(value["file"], "head.file")
            path = self.base_dir / given
            head, _ = load_head(path)
            source = given
        else:
            head = head_from_dict(
                value, base_dir=self.base_dir, source=self.source, prefix="head", allow=("angles",)
            )
            source = "[head]"
        self.inputs.extend(str(p) for p in head.inputs)
        self._refuse_unknowns(head)
        angles = self._setting_angles(value.get("angles"), "head.angles", head.coordinates)
        return HeadSetup(head, angles, source)

    def _refuse_unknowns(self, device: Any) -> None:
        """A head or table with errors to identify is read only by ``esp identify``."""
        if device.to_identify and not self.identify:
            unknown = next(iter(device.to_identify.values()))
            raise ConfigError(
                unknown.key,
                "an unknown to identify ({ identify = ... }): run 'esp identify' on a "
                "machine.toml with [identify] (docs/identify.md), then analyse the "
                "machine.toml it writes",
                device.source,
            )

    def _section_table(self, value: Any) -> TableSetup:
        """``[table]``: a rotary table carrying the workpiece, from a table file (``file``)
        or inline (docs/rotary.md), and its ``angles``."""
        from esp.config.devices import load_table, table_from_dict

        if not isinstance(value, Mapping):
            self.fail("table", f"expected a table, found {value!r}")
        if "file" in value:
            self.table(value, "table", ("file", "angles"))
            given = self.string(value["file"], "table.file")
            table = load_table(self.base_dir / given)
            source = given
        else:
            table = table_from_dict(
                value, base_dir=self.base_dir, source=self.source, prefix="table", allow=("angles",)
            )
            source = "[table]"
        self.inputs.extend(str(p) for p in table.inputs)
        self._refuse_unknowns(table)
        coordinates = table.chain.coordinates
        angles = self._setting_angles(value.get("angles"), "table.angles", coordinates)
        return TableSetup(table, angles, source)

    def _section_machine(self, value: Any) -> tuple[str, str, dict[str, str], dict[str, str]]:
        t = self.table(value, "machine", MACHINE_KEYS, required=("name", "configuration", "axes"))
        name = self.string(t["name"], "machine.name", NAME_MAX_CHARS)
        configuration = self.choice(t["configuration"], "machine.configuration", CONFIGURATIONS)
        roles = self._roles(t["axes"])
        info: dict[str, str] = {}
        for k in INFO_KEYS:
            if k not in t:
                continue
            v = t[k]
            if k == "date" and isinstance(v, date | datetime | time):
                info[k] = v.isoformat()
            else:
                info[k] = self.string(v, f"machine.{k}", NAME_MAX_CHARS)
        return name, configuration, roles, info

    def _roles(self, value: Any) -> dict[str, str]:
        t = self.table(value, "machine.axes", ROLES, required=ROLES)
        roles = {r: self.choice(t[r], f"machine.axes.{r}", AXIS_NAMES) for r in ROLES}
        for letter in AXIS_NAMES:
            holders = [r for r in ROLES if roles[r] == letter]
            if len(holders) > 1:
                missing = [n for n in AXIS_NAMES if n not in roles.values()]
                self.fail(
                    "machine.axes",
                    f"expected X, Y and Z once each, found {letter!r} assigned to "
                    f"{' and '.join(holders)} (and {', '.join(missing)} to none)",
                )
        return roles

    def _section_analysis(self, value: Any) -> Analysis:
        t = self.table(value, "analysis", ANALYSIS_KEYS)
        d = Analysis()
        point = self.choice(t.get("point", d.point), "analysis.point", _POINTS)
        compensation = self.choice(
            t.get("compensation", d.compensation), "analysis.compensation", _COMPENSATIONS
        )
        direction = self.choice(
            t.get("direction", "mean"),
            "analysis.direction",
            _DIRECTIONS,
            aliases={**_DIRECTIONS, **_DIRECTION_ALIASES},
        )
        datum = t.get("datum", d.datum)
        if isinstance(datum, Mapping):
            datum = self.xyz(datum, "analysis.datum", all_required=True)
        elif isinstance(datum, str):
            datum = self.choice(datum, "analysis.datum", _DATUMS)
        else:
            self.fail(
                "analysis.datum",
                f"expected one of {quoted(_DATUMS)} or a table {{ X = ..., Y = ..., Z = ... }} "
                f"in mm, found {datum!r}",
            )
        fit = self.choice(
            t.get("straightness_fit", d.straightness_fit), "analysis.straightness_fit", _FITS
        )
        extrapolate = self.boolean(t.get("extrapolate", d.extrapolate), "analysis.extrapolate")
        model = self.choice(t.get("model", d.model), "analysis.model", MODELS)
        convention = self.choice(
            t.get("angle_convention", d.angle_convention),
            "analysis.angle_convention",
            ANGLE_CONVENTIONS,
        )
        return Analysis(
            point=point,
            compensation=compensation,
            direction=direction,
            datum=datum,
            straightness_fit=fit,
            extrapolate=extrapolate,
            model=model,
            angle_convention=convention,
        )

    def _check_datum(self, analysis: Analysis, axes: Mapping[str, Axis]) -> None:
        if not isinstance(analysis.datum, Mapping):
            return
        for n in AXIS_NAMES:
            lo, hi = axes[n].travel_mm
            x = analysis.datum[n]
            if not lo <= x <= hi:
                self.fail(
                    f"analysis.datum.{n}",
                    f"expected a position within the travel of {n} [{lo:g}, {hi:g}] mm, "
                    f"found {shown(x)}",
                )

    def _check_work(
        self, axes: Mapping[str, Axis], tool: Tool | None, analysis: Analysis, settings: int = 1
    ) -> None:
        """Refuse a grid or a set of tool cases beyond the resource limits, before any work:
        :data:`MAX_PLANE_POINTS`, :data:`MAX_GRID_POINTS`, :data:`MAX_WORK_POINTS`."""
        sizes = {n: grid_count(axes[n]) for n in AXIS_NAMES}
        nx, ny, nz = (sizes[n] for n in AXIS_NAMES)
        shown = " x ".join(f"{sizes[n]} ({n})" for n in AXIS_NAMES)
        # the keys to change: the steps of the axes with the most points first
        steps = sorted((n for n in AXIS_NAMES if sizes[n] > 1), key=lambda n: -sizes[n])
        keys = " or ".join(f"axes.{n}.step" for n in steps[:2]) or "axes.X.step"
        points = nx * ny * nz
        if points > MAX_GRID_POINTS:
            self.fail(
                f"axes.{steps[0]}.step",
                f"a grid of {shown} = {points:.3g} points, above the limit of "
                f"{MAX_GRID_POINTS:.3g} points per tool case: increase {keys}",
            )
        plane = nx * ny + nx * nz + ny * nz
        if plane > MAX_PLANE_POINTS:
            self.fail(
                f"axes.{steps[0]}.step",
                f"a grid of {shown} points has {plane:.3g} points in its three coordinate "
                f"planes, above the limit of {MAX_PLANE_POINTS:.3g} (about "
                f"{72 * plane / 1e9:.2g} GB of memory): increase {keys}",
            )
        cases = 1
        if tool is not None and analysis.point == "TCP":
            cases = len(tool.offsets_mm) or len(tool.lengths_mm) * len(tool.orientations_deg)
        cases *= settings
        if cases > MAX_TOOL_CASES:
            self.fail(
                "head.angles" if settings > 1 else "tool",
                f"{cases} tool cases (head and table settings x tools), above the limit of "
                f"{MAX_TOOL_CASES}: give fewer angles",
            )
        if points * cases > MAX_WORK_POINTS:
            self.fail(
                "tool" if cases > 1 else f"axes.{steps[0]}.step",
                f"{cases} tool cases x {points:.3g} grid points = {points * cases:.3g} points "
                f"to evaluate, above the limit of {MAX_WORK_POINTS:.3g}: use fewer tool "
                f"lengths or orientations, or increase {keys}",
            )

    def _section_axes(
        self, value: Any, roles: Mapping[str, str]
    ) -> tuple[dict[str, Axis], dict[str | ComponentName, Component]]:
        t = self.table(value, "axes", AXIS_NAMES, required=AXIS_NAMES)
        role_of = {letter: role for role, letter in roles.items()}
        axes: dict[str, Axis] = {}
        components: dict[str | ComponentName, Component] = {}
        for n in AXIS_NAMES:
            axes[n] = self._axis(n, role_of[n], t[n])
            components.update(self._axis_errors(n, t[n].get("errors", {})))
        return axes, components

    def _axis(self, n: str, role: str, value: Any) -> Axis:
        key = f"axes.{n}"
        t = self.table(value, key, AXIS_KEYS, required=("travel",))
        travel = self.interval(t["travel"], f"{key}.travel")
        simulate = travel
        if "simulate" in t:
            simulate = self.interval(t["simulate"], f"{key}.simulate")
            if simulate[0] < travel[0] or simulate[1] > travel[1]:
                self.fail(
                    f"{key}.simulate",
                    f"expected a range within the travel [{travel[0]:g}, {travel[1]:g}] mm, "
                    f"found {t['simulate']!r}",
                )
        if "step" in t:
            step = self.number(t["step"], f"{key}.step", "step")
        elif travel[1] > travel[0]:
            self.fail(f"{key}.step", "required key is missing (the grid step in mm)")
        else:
            step = 0.0  # an axis that does not move: its grid is one point
        offset = self.position(t.get("offset", 0.0), f"{key}.offset")
        return Axis(n, role, travel, simulate, step, offset)

    def _axis_errors(self, n: str, value: Any) -> dict[str | ComponentName, Component]:
        key = f"axes.{n}.errors"
        t = self.table(value, key, ERROR_KEYS)
        out: dict[str | ComponentName, Component] = {}
        if "linear" in t:
            slot = Slot(f"{key}.linear", "linear", n, None)
            out[slot.name] = read_source(self, t["linear"], slot)
        others = tuple(a for a in AXIS_NAMES if a != n)
        for kind, letters in (
            ("straightness", others),
            ("angular", AXIS_NAMES),
            ("mechanical", AXIS_NAMES),
        ):
            if kind not in t:
                continue
            sub = t[kind]
            if not isinstance(sub, Mapping):
                what = "direction" if kind == "straightness" else "rotation axis"
                self.fail(
                    f"{key}.{kind}",
                    f"expected a table of {what} -> source such as "
                    f'{{ {letters[0]} = "file" }}, found {sub!r}',
                )
            if kind == "straightness" and n in sub:
                self.fail(
                    f"{key}.straightness.{n}",
                    f"a deviation of {n} along {n} is its linear error (errors.linear); "
                    f"expected {' or '.join(others)}",
                )
            self.table(sub, f"{key}.{kind}", letters)
            for about in letters:
                if about in sub:
                    slot = Slot(f"{key}.{kind}.{about}", kind, n, about)
                    out[slot.name] = read_source(self, sub[about], slot)
        return out

    def _section_squareness(self, value: Any) -> dict[str | ComponentName, Component]:
        pairs = [a + b for a in AXIS_NAMES for b in AXIS_NAMES if a != b]
        t = self.table(value, "squareness", pairs)
        out: dict[str | ComponentName, Component] = {}
        for i, a in enumerate(AXIS_NAMES):
            for b in AXIS_NAMES[i + 1 :]:
                given = [p for p in (a + b, b + a) if p in t]
                if len(given) == 2:
                    self.fail(
                        f"squareness.{b + a}",
                        f"expected the pair {a}, {b} once, found it as both {a + b} and "
                        f"{b + a} (the pairs are unordered)",
                    )
                if not given:
                    continue
                slot = Slot(f"squareness.{given[0]}", "squareness", None, None)
                v = t[given[0]]
                if isinstance(v, Mapping):
                    c = read_source(self, v, slot, kinds=SQUARENESS_SOURCES)
                elif isinstance(v, int | float) and not isinstance(v, bool):
                    c = bare_constant(self, v, slot)
                else:
                    self.fail(
                        slot.key,
                        f"expected a number in um/m or a table {{ constant = ..., unit = ... }}, "
                        f"found {v!r}",
                    )
                out[c.name] = c
        return out

    def _section_tool(self, value: Any) -> Tool:
        t = self.table(value, "tool", TOOL_KEYS)
        spindle = None
        if "spindle" in t:
            given = t["spindle"]
            text = given.strip().upper() if isinstance(given, str) else given
            if isinstance(text, str) and text in AXIS_NAMES:
                text = "+" + text
            spindle = self.choice(text, "tool.spindle", _SPINDLES)
        tool = self._tool(t)
        return replace(tool, spindle=spindle)

    def _tool(self, t: Mapping[str, Any]) -> Tool:
        orientation = t.get("orientation", "sweep")
        expected = (
            "expected 'sweep', a table { tilt = deg, spin = deg } or "
            "{ offset = { X = mm, Y = mm, Z = mm } }"
        )
        if isinstance(orientation, str):
            if orientation != "sweep":
                hint = closest(orientation, ("sweep",))
                dym = f"; did you mean {hint!r}?" if hint else ""
                self.fail("tool.orientation", f"{expected}, found {orientation!r}{dym}")
            lengths = self._lengths(t)
            sweep = self.table(t.get("sweep", {}), "tool.sweep", ("tilt", "spin"))
            tilts = (
                self._angles(sweep["tilt"], "tool.sweep.tilt")
                if "tilt" in sweep
                else DEFAULT_SWEEP_TILT_DEG
            )
            spins = (
                self._angles(sweep["spin"], "tool.sweep.spin")
                if "spin" in sweep
                else DEFAULT_SWEEP_SPIN_DEG
            )
            self._check_tool_cases(len(lengths), len(tilts), len(spins))
            pairs = tuple((a, b) for a in tilts for b in spins)
            return Tool(lengths_mm=lengths, orientations_deg=pairs, sweep=True)
        if not isinstance(orientation, Mapping):
            self.fail("tool.orientation", f"{expected}, found {orientation!r}")
        if "sweep" in t:
            self.fail("tool.sweep", "only used with orientation = 'sweep'; remove it")
        o = self.table(orientation, "tool.orientation", ("tilt", "spin", "offset"))
        if "offset" in o:
            if len(o) > 1:
                self.fail(
                    "tool.orientation",
                    f"expected either tilt and spin, or offset, found {', '.join(o)}",
                )
            if "lengths" in t:
                self.fail(
                    "tool.lengths",
                    "not used when tool.orientation gives an offset vector; remove it",
                )
            if "spindle" in t:
                self.fail(
                    "tool.spindle",
                    "not used when tool.orientation gives an offset vector; remove it",
                )
            offset = self.xyz(o["offset"], "tool.orientation.offset", all_required=False)
            return Tool(lengths_mm=(), orientations_deg=(), offsets_mm=(offset,), sweep=False)
        self.table(o, "tool.orientation", ("tilt", "spin"), required=("tilt", "spin"))
        tilt = self._angle(o["tilt"], "tool.orientation.tilt")
        spin = self._angle(o["spin"], "tool.orientation.spin")
        lengths = self._lengths(t)
        self._check_tool_cases(len(lengths), 1, 1)
        return Tool(lengths_mm=lengths, orientations_deg=((tilt, spin),), sweep=False)

    def _lengths(self, t: Mapping[str, Any]) -> tuple[float, ...]:
        if "lengths" not in t:
            self.fail("tool.lengths", "required key is missing (tool lengths in mm)")
        if isinstance(t["lengths"], list) and len(t["lengths"]) > MAX_TOOL_CASES:
            self.fail(
                "tool.lengths",
                f"expected at most {MAX_TOOL_CASES} tool lengths, found {len(t['lengths'])}",
            )
        raw = t["lengths"]
        if not isinstance(raw, list) or not raw:
            self.fail("tool.lengths", f"expected a non-empty list of lengths in mm, found {raw!r}")
        lengths = tuple(
            self.number(v, f"tool.lengths[{i}]", "tool length") for i, v in enumerate(raw)
        )
        if len(set(lengths)) != len(lengths):
            self.fail("tool.lengths", f"expected each length once, found {t['lengths']!r}")
        return lengths

    def _angle(self, value: Any, key: str) -> float:
        """An angle in degrees within ±360°."""
        return self.number(value, key, "degrees")

    def _angles(self, value: Any, key: str) -> tuple[float, ...]:
        """A non-empty list of angles in degrees within ±360°, at most
        :data:`MAX_TOOL_CASES` of them."""
        if isinstance(value, list) and len(value) > MAX_TOOL_CASES:
            self.fail(key, f"expected at most {MAX_TOOL_CASES} angles, found {len(value)}")
        return self.numbers(value, key, "degrees")

    def _check_tool_cases(self, lengths: int, tilts: int, spins: int) -> None:
        """Refuse more tool cases (lengths x orientations) than :data:`MAX_TOOL_CASES`,
        naming the key that sets the most of them."""
        cases = lengths * tilts * spins
        if cases <= MAX_TOOL_CASES:
            return
        if tilts * spins > 1:
            key = "tool.sweep.tilt" if tilts >= spins else "tool.sweep.spin"
            if lengths > tilts * spins:
                key = "tool.lengths"
        else:
            key = "tool.lengths"
        self.fail(
            key,
            f"{lengths} tool length{'s' if lengths != 1 else ''} x {tilts * spins} "
            f"orientation{'s' if tilts * spins != 1 else ''} ({tilts} tilt x {spins} spin) "
            f"= {cases} tool cases, above the limit of {MAX_TOOL_CASES}: use fewer",
        )


def grid_count(axis: Axis) -> int:
    """The number of positions :meth:`esp.core.machine.Axis.grid_mm` gives, without making
    them: steps of ``step_mm`` from the low simulation limit, and the high limit."""
    lo, hi = axis.simulate_mm
    if hi <= lo:
        return 1
    n = math.floor((hi - lo) / axis.step_mm + 1e-9)
    last = lo + axis.step_mm * n
    return n + 1 + (1 if hi - last > 1e-9 * max(1.0, abs(hi)) else 0)
