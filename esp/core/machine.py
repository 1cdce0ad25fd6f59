"""A machine as the synthesis sees it: configuration, axes, error components, tool.

Built by :func:`esp.config.load_machine` from a ``machine.toml``, or directly in code.
Everything here is an immutable record; nothing here computes errors.

Notation (Longstaff 2002, 3.02 and the nomenclature): the axes are Bottom, Middle and Top
(B, M, T); ``wBMTt`` means no axis carries the workpiece, ``BwMTt`` the bottom axis carries
it, ``BMwTt`` the bottom and middle axes carry it. Component names use the machine's own
axis letters: ``X.linear``, ``X.straightness.Y`` (X moving, deviation along Y),
``X.angular.Z`` (X moving, rotation about Z), ``X.mechanical.Y`` (the mechanical angle γ of
eq. 3.14-3.16), ``squareness.XY``.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Any

import numpy as np

from esp.core.errors import ConfigError
from esp.core.names import AXIS_NAMES, COMPONENT_KINDS, ComponentName
from esp.core.profile import ErrorProfile

__all__ = [
    "AXIS_NAMES",
    "COMPONENT_KINDS",
    "CONFIGURATIONS",
    "ROLES",
    "Analysis",
    "Axis",
    "Component",
    "ComponentName",
    "HeadSetup",
    "TableSetup",
    "Machine",
    "ReportInfo",
    "Tool",
    "describe_component",
    "iso_name",
    "squareness_name",
]

ROLES = ("bottom", "middle", "top")
#: configuration -> description in words (thesis 3.02-3.03, 3.11 and figure 3.7)
CONFIGURATIONS = {
    "wBMTt": "All axes associated with movement of the tool",
    "BwMTt": "Bottom axis carries the workpiece; middle and top axes move the tool",
    "BMwTt": "Bottom and middle axes carry the workpiece; top axis moves the tool",
    "BMTwt": "All axes carry the workpiece; the tool is fixed",
}


def squareness_name(a: str, b: str) -> ComponentName:
    """``squareness.XY`` for the unordered pair (a, b)."""
    return ComponentName.squareness(a, b)


def iso_name(component: str | ComponentName) -> str:
    """The ISO 230-1 symbol of a component (see :attr:`ComponentName.iso`)."""
    return ComponentName.parse(component).iso


def describe_component(name: str | ComponentName) -> str:
    """Words for a component: ``X.angular.Z`` -> ``X-axis rotation about Z``."""
    return ComponentName.parse(name).description


def _frozen(mapping: Mapping) -> Mapping:
    return MappingProxyType(dict(mapping))


@dataclass(frozen=True)
class Axis:
    """One linear axis of the machine.

    Parameters
    ----------
    name : ``"X"``, ``"Y"`` or ``"Z"``
    role : ``"bottom"``, ``"middle"`` or ``"top"``
    travel_mm : (low, high) travel limits; equal for an axis that does not move
    simulate_mm : (low, high) range evaluated, within the travel
    step_mm : grid step; the grid holds both ends (the last step may be shorter)
    offset_mm : the coordinate of this axis at which the other axes' errors were measured;
        the lever of every angular and squareness term along this axis is
        ``coordinate - offset_mm`` (ESP-NOTES: lever arms)
    """

    name: str
    role: str
    travel_mm: tuple[float, float]
    simulate_mm: tuple[float, float]
    step_mm: float
    offset_mm: float = 0.0

    def grid_mm(self) -> np.ndarray:
        """The positions evaluated, from the low to the high simulation limit.

        Steps of ``step_mm`` from the low end, and the high end always included (so the
        last interval may be shorter). An axis with zero length gives one point.
        """
        lo, hi = self.simulate_mm
        if hi <= lo:
            return np.array([float(lo)])
        n = int(np.floor((hi - lo) / self.step_mm + 1e-9))
        grid = lo + self.step_mm * np.arange(n + 1, dtype=float)
        if hi - grid[-1] > 1e-9 * max(1.0, abs(hi)):
            grid = np.append(grid, float(hi))
        else:
            grid[-1] = float(hi)
        return grid


@dataclass(frozen=True)
class Component:
    """One error component with its data.

    ``profile`` holds the data of linear, straightness, angular and mechanical
    components; ``value`` the squareness (µm/m). ``source`` says where the data came from,
    for reports (a path, ``"constant 4 um"``, ...). ``from_linear`` marks an angle derived
    from two linear runs (thesis 3.08.1): the coefficient of a lever, not a rotation.
    """

    name: ComponentName
    kind: str
    axis: str | None
    about: str | None
    profile: ErrorProfile | None = None
    value: float | None = None
    source: str = ""
    from_linear: bool = False

    def __post_init__(self) -> None:
        name = ComponentName.parse(self.name)
        if name.kind != self.kind or name.axis != self.axis:
            raise ValueError(f"component {name} is not a {self.kind} error of axis {self.axis}")
        object.__setattr__(self, "name", name)
        object.__setattr__(self, "about", name.about)

    @property
    def iso(self) -> str:
        return self.name.iso

    @property
    def unit(self) -> str:
        return self.name.unit


@dataclass(frozen=True)
class Tool:
    """The tool or probe, for evaluation at the TCP (thesis 3.06-3.07).

    Either ``offsets_mm`` holds explicit offset vectors (machine axis letter -> mm), or
    each length in ``lengths_mm`` is combined with every (tilt, spin) pair of
    ``orientations_deg``. The tilt α is measured from the spindle direction ``spindle``
    (a signed machine axis such as ``"-Z"``; None: against the top axis, ``-T``) and the
    spin β about it (see :func:`esp.core.models.tool.tool_cases`; thesis eq. 3.6-3.9 measure the
    tilt from +T). ``sweep`` is true when the orientations are a sweep whose worst case is
    reported.
    """

    lengths_mm: tuple[float, ...] = (0.0,)
    orientations_deg: tuple[tuple[float, float], ...] = ((0.0, 0.0),)
    offsets_mm: tuple[Mapping[str, float], ...] = ()
    sweep: bool = False
    spindle: str | None = None


@dataclass(frozen=True)
class HeadSetup:
    """A servo head on the ram of the machine (``[head]``, issue of five-axis machines).

    ``head`` is the :class:`esp.heads.Head` (its chain, parameter and error values; its
    base frame is the ram's, with x, y, z along the machine's X, Y, Z, and its MCP at the
    machine's MCP); ``angles_deg`` the head angles to sweep, coordinate -> values (every
    combination is one tool case); ``source`` the file the head came from, for reports.
    """

    head: Any
    angles_deg: Mapping[str, tuple[float, ...]]
    source: str = ""


@dataclass(frozen=True)
class TableSetup:
    """A rotary table carrying the workpiece (``[table]``).

    ``table`` is the :class:`esp.core.devices.Table` (its chain from the workpiece to its mount on
    the linear stack, in machine coordinates, with its ISO 230-7 errors);
    ``angles_deg`` the table angles to sweep, coordinate -> values (every combination is
    one setting); ``source`` the file the table came from, for reports.
    """

    table: Any
    angles_deg: Mapping[str, tuple[float, ...]]
    source: str = ""


@dataclass(frozen=True)
class Analysis:
    """How to evaluate.

    point : ``"MCP"`` or ``"TCP"``
    compensation : ``"none"``, ``"MCP"`` or ``"TCP"`` (thesis 3.10.1-3.10.5)
    direction : ``"forward"``, ``"backward"`` or ``"mean"`` -- which runs of the data
    datum : ``"none"``, ``"negative"``, ``"centre"``, or a mapping axis -> mm
    straightness_fit : ``"least-squares"``, ``"endpoint"``, or ``"none"`` (used as given)
    extrapolate : hold end values outside the measured range instead of refusing
    model : ``"rigid-body"`` (the term tables derived from the machine's kinematic chain,
        :mod:`esp.core.models.derived`) or ``"as-printed"`` (the equations as printed in
        Longstaff 2002, :mod:`esp.core.models.esp`)
    angle_convention : ``"iso230-1"`` (angles are right-handed rotations of the tool
        relative to the workpiece, ``docs/conventions.md``) or ``"thesis"`` (the signs the
        printed equations imply; converted to the ISO signs for the rigid-body model)
    """

    point: str = "MCP"
    compensation: str = "none"
    direction: str = "mean"
    datum: str | Mapping[str, float] = "none"
    straightness_fit: str = "least-squares"
    extrapolate: bool = False
    model: str = "rigid-body"
    angle_convention: str = "iso230-1"


@dataclass(frozen=True)
class ReportInfo:
    """Who a report is for and by whom it is issued (``[report]`` of ``machine.toml``):
    each field is shown in the title block of every document when given."""

    serial: str | None = None
    owner: str | None = None
    operator: str | None = None
    laboratory: str | None = None


@dataclass(frozen=True)
class Machine:
    """Everything the synthesis needs to know about one machine.

    ``axes`` maps the axis letter to its :class:`Axis`; ``roles`` maps ``"bottom"`` /
    ``"middle"`` / ``"top"`` to the axis letter; ``components`` maps the component name to
    its :class:`Component` (absent components are zero); ``info`` holds serial, location,
    measured_by and date when given; ``uncertainty`` the
    :class:`esp.core.uncertainty.spec.UncertaintySpec` of the ``[uncertainty]`` table, or None;
    ``inputs`` the paths of every file read to build it (the configuration and its data
    files), which no output may overwrite; ``warnings`` what the reader noticed (a tool
    not used at the MCP, an offset outside its travel); ``head`` the :class:`HeadSetup` of
    a machine that carries a servo head (``[head]``), ``table`` the :class:`TableSetup` of
    one whose workpiece sits on a rotary table (``[table]``), or None; ``report`` the
    :class:`ReportInfo` of ``[report]`` (serial, owner, operator, laboratory), or None;
    ``tolerance`` the ``esp.config.tolerance.Tolerances`` of ``[tolerance]``, or None.
    """

    name: str
    configuration: str
    roles: Mapping[str, str]
    axes: Mapping[str, Axis]
    components: Mapping[str | ComponentName, Component] = field(default_factory=dict)
    analysis: Analysis = field(default_factory=Analysis)
    tool: Tool | None = None
    info: Mapping[str, str] = field(default_factory=dict)
    source: str | None = None
    uncertainty: Any = None
    inputs: tuple[str, ...] = ()
    warnings: tuple[str, ...] = ()
    head: Any = None
    table: Any = None
    report: ReportInfo | None = None
    tolerance: Any = None

    def __post_init__(self) -> None:
        if self.configuration not in CONFIGURATIONS:
            raise ConfigError(
                "machine.configuration",
                f"expected one of {', '.join(CONFIGURATIONS)}, found {self.configuration!r}",
                self.source,
            )
        if set(self.roles) != set(ROLES) or sorted(self.roles.values()) != list(AXIS_NAMES):
            raise ConfigError(
                "machine.axes",
                f"expected bottom, middle and top assigned to X, Y and Z once each, "
                f"found {dict(self.roles)!r}",
                self.source,
            )
        object.__setattr__(self, "roles", _frozen(self.roles))
        object.__setattr__(self, "axes", _frozen(self.axes))
        object.__setattr__(self, "components", _frozen(self.components))
        object.__setattr__(self, "info", _frozen(self.info))

    @property
    def notation(self) -> str:
        """The configuration with the machine's axis letters, e.g. ``wXYZt`` or ``YXwZt``."""
        letters = {"B": self.roles["bottom"], "M": self.roles["middle"], "T": self.roles["top"]}
        return "".join(letters.get(c, c) for c in self.configuration)

    @property
    def description(self) -> str:
        return CONFIGURATIONS[self.configuration]
