"""Immutable result records of a synthesis. Rendering them (text, JSON, plots) lives in
:mod:`esp.report`; nothing here formats or prints."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

from esp.machine import Machine
from esp.models.tool import ToolCase

__all__ = [
    "AnalysisResult",
    "AxisExtremes",
    "BudgetLine",
    "Breakdown",
    "CaseResult",
    "Extreme",
    "MonteCarloSummary",
    "PointCase",
    "PointResult",
    "SweepEntry",
    "TermValue",
    "ToolCase",
    "UncertaintyResult",
]


@dataclass(frozen=True)
class Extreme:
    """A value in µm and the machine position (axis letter -> mm) where it occurs."""

    value_um: float
    at: Mapping[str, float]


@dataclass(frozen=True)
class AxisExtremes:
    """Algebraic minimum and maximum of one direction's total displacement error."""

    minimum: Extreme
    maximum: Extreme

    @property
    def range_um(self) -> float:
        return self.maximum.value_um - self.minimum.value_um


@dataclass(frozen=True)
class TermValue:
    """One term's contribution at a point: its value in µm and share of its direction's
    total in percent (None when that total is zero)."""

    direction: str
    component: str
    iso: str
    source: str
    symbol: str
    value_um: float
    share_pct: float | None


@dataclass(frozen=True)
class Breakdown:
    """Every active term at one extreme point, with the three totals."""

    label: str
    at: Mapping[str, float]
    errors_um: Mapping[str, float]
    volumetric_um: float
    terms: tuple[TermValue, ...]


@dataclass(frozen=True)
class CaseResult:
    """The extremes of one tool case over the grid, with breakdowns."""

    tool: ToolCase
    volumetric: Extreme
    planar: Mapping[str, Extreme]
    axes: Mapping[str, AxisExtremes]
    breakdowns: tuple[Breakdown, ...]
    points: int


@dataclass(frozen=True)
class SweepEntry:
    """The volumetric accuracy of one orientation and length of a head sweep."""

    tool: ToolCase
    volumetric: Extreme


@dataclass(frozen=True)
class BudgetLine:
    """One component of an uncertainty budget: its expanded uncertainty ``U`` (``unit``
    µm or µm/m, coverage factor of the analysis), the model it came from (``"direct"`` or
    an instrument model name) and its share in percent of the volumetric uncertainty at the
    point where that is largest."""

    component: str
    iso: str
    model: str
    U: float
    unit: str
    share_pct: float


@dataclass(frozen=True)
class MonteCarloSummary:
    """The distribution of the volumetric accuracy over Monte Carlo draws (GUM S1).

    ``values_um`` holds every draw's volumetric accuracy (for histograms)."""

    mean_um: float
    std_um: float
    interval_um: tuple[float, float]
    samples: int
    seed: int
    values_um: tuple[float, ...] = ()


@dataclass(frozen=True)
class UncertaintyResult:
    """The volumetric uncertainty of an analysis (thesis 3.14.7, 4.01.3-4.01.4).

    ``volumetric``: the largest expanded volumetric uncertainty over the volume and where;
    ``axes``: per direction the largest expanded uncertainty and where; ``budget`` sorted
    by share; ``montecarlo`` when that method ran; ``prior`` the Bayesian update of eq.
    3.22-3.24 when a prior is configured (prior_um, prior_u_um, accuracy_um, U_um,
    delta_U_um)."""

    method: str
    k: float
    volumetric: Extreme
    axes: Mapping[str, Extreme]
    budget: tuple[BudgetLine, ...]
    montecarlo: MonteCarloSummary | None = None
    prior: Mapping[str, float] | None = None


@dataclass(frozen=True)
class AnalysisResult:
    """The outcome of :func:`esp.analysis.analyse`.

    ``cases`` holds one result per reported tool case (per tool length with the worst
    orientation for a sweep); ``sweep`` every orientation of a sweep; ``worst`` the index
    in ``cases`` with the largest volumetric accuracy. ``plane_of_motion`` names the two
    moving axes when the third does not move (a two-axis machine); the cases then hold the
    planar accuracy of that plane only.
    """

    machine: Machine
    case: str
    case_description: str
    equations: str
    datum: Mapping[str, float] | None
    active: tuple[str, ...]
    inactive: tuple[str, ...]
    ignored: tuple[str, ...]
    warnings: tuple[str, ...]
    cases: tuple[CaseResult, ...]
    sweep: tuple[SweepEntry, ...] = ()
    worst: int = 0
    grid_sizes: Mapping[str, int] = field(default_factory=dict)
    plane_of_motion: str | None = None
    uncertainty: UncertaintyResult | None = None


@dataclass(frozen=True)
class PointCase:
    """The errors and every term at one point for one tool case."""

    tool: ToolCase
    breakdown: Breakdown


@dataclass(frozen=True)
class PointResult:
    """The outcome of :func:`esp.analysis.evaluate_point`."""

    machine: Machine
    case: str
    equations: str
    datum: Mapping[str, float] | None
    at: Mapping[str, float]
    cases: tuple[PointCase, ...]
    warnings: tuple[str, ...] = ()
