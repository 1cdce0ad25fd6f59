"""Immutable result records of a synthesis. Rendering them (text, JSON, plots) lives in
:mod:`esp.report`; nothing here formats or prints. A case's record carries the
:class:`esp.core.evaluation.Evaluation` it came from, so that every figure drawn from it (maps,
grid, point queries) is the same evaluation."""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

from esp.core.machine import Machine
from esp.core.models.tool import ToolCase
from esp.core.names import ComponentName

if TYPE_CHECKING:
    import numpy as np

    from esp.core.evaluation import Evaluation
    from esp.core.uncertainty.budget import Contribution

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
    component: str | ComponentName
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
    """The extremes of one tool case over the grid, with breakdowns; ``evaluation`` the
    evaluation they come from (left out of comparisons)."""

    tool: ToolCase
    volumetric: Extreme
    planar: Mapping[str, Extreme]
    axes: Mapping[str, AxisExtremes]
    breakdowns: tuple[Breakdown, ...]
    points: int
    evaluation: Evaluation | None = field(default=None, compare=False, repr=False)


@dataclass(frozen=True)
class SweepEntry:
    """The volumetric accuracy of one orientation and length of a head sweep."""

    tool: ToolCase
    volumetric: Extreme


@dataclass(frozen=True)
class BudgetLine:
    """One component of the uncertainty budget, evaluated where the budget is evaluated
    (:attr:`UncertaintyResult.budget_at`: the point, and tool case, of the largest
    volumetric uncertainty).

    ``U``: the component's expanded uncertainty *at that point* (a U given as a curve is
    read at the point's coordinate of the component's axis), in ``unit`` (µm, or µm/m for
    angles and squareness), with the component's own coverage factor ``k``; ``u`` = U / k,
    the standard uncertainty there; ``U_max`` the largest U along the axis (equal to ``U``
    for a constant). ``model``: ``"direct"`` or the instrument model's name;
    ``distribution``: ``"normal"`` or ``"rectangular"``; ``dof``: degrees of freedom of u
    (``math.inf`` for a value taken as exact, Type B; finite for a Type A evaluation);
    ``contribution_um``: the component's standard uncertainty contribution to the
    volumetric uncertainty at the point, sqrt(Σ (u · lever)²) over its terms, in µm (for
    the summation bound sqrt(Σ_d b_d²), b_d = |Σ u · lever| over its terms in direction d);
    ``contributors``: what makes u, each a standard uncertainty in ``unit`` with its degrees
    of freedom (an instrument model's budget; one line for a U given directly or by
    default), whose root-sum-square is u;
    ``share_pct``: its share in percent of the volumetric uncertainty there (statistical:
    of the sum of squares; summation: its part of each direction's bound projected on the
    bounds, never negative; pure addition: its signed projection on the direction
    totals)."""

    component: str
    iso: str
    model: str
    U: float
    unit: str
    share_pct: float
    k: float = 2.0
    u: float = 0.0
    U_max: float = 0.0
    distribution: str = "normal"
    dof: float = math.inf
    contribution_um: float = 0.0
    contributors: tuple[Contribution, ...] = ()

    @property
    def type_a(self) -> bool:
        """Whether the component's u has finite degrees of freedom (a Type A part)."""
        return math.isfinite(self.dof)


@dataclass(frozen=True)
class MonteCarloSummary:
    """The distribution of the volumetric accuracy over Monte Carlo draws (GUM S1).

    ``values_um`` holds every draw's volumetric accuracy (for histograms), a read-only
    array of ``samples`` values (left out of comparisons). ``grid_points``: the points of
    the analysis grid each draw is the maximum over; ``evaluated_points``: how many
    point-draws were evaluated one by one (the rest were excluded by the tile bounds);
    ``dtype``: the floating-point type of the evaluation (``"float32"`` or
    ``"float64"``); ``tool``: the tool case drawn."""

    mean_um: float
    std_um: float
    interval_um: tuple[float, float]
    samples: int
    seed: int
    values_um: Sequence[float] | np.ndarray = field(default=(), compare=False)
    grid_points: int = 0
    evaluated_points: int = field(default=0, compare=False)
    dtype: str = "float64"
    tool: ToolCase | None = None


@dataclass(frozen=True)
class UncertaintyResult:
    """The volumetric uncertainty of an analysis (thesis 3.14.7, 4.01.3-4.01.4; GUM 5.1.2,
    6.2, G.4).

    ``volumetric``: the largest expanded volumetric uncertainty over the volume and where;
    ``axes``: per direction the largest expanded uncertainty and where; ``k``: the
    coverage factor of these expanded figures (the configured ``k``, or t_p(ν_eff) for a
    configured ``coverage`` p); ``budget`` sorted by share, evaluated at ``budget_at``
    (the point of ``volumetric``) for the tool case ``budget_tool``; ``u_um``: the
    combined standard uncertainty there (volumetric / k); ``dof_eff``: its effective
    degrees of freedom by Welch-Satterthwaite (``math.inf`` when no component has finite
    degrees of freedom; None for the summation bound and pure addition, which are no
    variance);
    ``coverage``: the coverage probability k was chosen for, or None when k was given;
    ``montecarlo`` when that method ran; ``prior`` the Bayesian update of eq. 3.22-3.24
    when a prior is configured (prior_um, prior_u_um, accuracy_um, U_um, delta_U_um);
    ``uniform`` when U is the same at every point of the volume (``volumetric.at`` is then
    only the first grid point, no place where U is largest)."""

    method: str
    k: float
    volumetric: Extreme
    axes: Mapping[str, Extreme]
    budget: tuple[BudgetLine, ...]
    montecarlo: MonteCarloSummary | None = None
    prior: Mapping[str, float] | None = None
    u_um: float | None = None
    dof_eff: float | None = None
    coverage: float | None = None
    budget_tool: ToolCase | None = None
    uniform: bool = False

    def range_um(self, direction: str) -> float | None:
        """The expanded uncertainty of the range (max − min) of the error in ``direction``:
        √2 times the direction's largest U, the range being the difference of two values
        each known to at most that U, taken as independent (GUM 5.1.2). None when the
        direction has no U."""
        e = self.axes.get(direction)
        return None if e is None else math.sqrt(2.0) * e.value_um

    @property
    def budget_at(self) -> Mapping[str, float]:
        """The machine position where the budget is evaluated: the point of the largest
        volumetric uncertainty."""
        return self.volumetric.at


@dataclass(frozen=True)
class AnalysisResult:
    """The outcome of :func:`esp.core.analysis.analyse`.

    ``cases`` holds one result per reported tool case (per tool length with the worst
    orientation for a sweep); ``sweep`` every orientation of a sweep; ``worst`` the index
    in ``cases`` with the largest volumetric accuracy. ``plane_of_motion`` names the two
    moving axes when the third does not move (a two-axis machine); the cases then hold the
    planar accuracy of that plane only. ``uncertainty_missing`` names what the model uses
    and ``[uncertainty]`` gives no U for (components, and ``head.NAME`` / ``table.NAME``
    errors): with any, ``uncertainty`` is None (not evaluated), never a U that leaves them
    out.
    """

    machine: Machine
    case: str
    case_description: str
    equations: str
    datum: Mapping[str, float] | None
    active: tuple[ComponentName, ...]
    inactive: tuple[ComponentName, ...]
    ignored: tuple[str | ComponentName, ...]
    warnings: tuple[str, ...]
    cases: tuple[CaseResult, ...]
    sweep: tuple[SweepEntry, ...] = ()
    worst: int = 0
    grid_sizes: Mapping[str, int] = field(default_factory=dict)
    plane_of_motion: str | None = None
    uncertainty: UncertaintyResult | None = None
    uncertainty_missing: tuple[str, ...] = ()

    @property
    def evaluation(self) -> Evaluation:
        """The evaluation of the worst case (``cases[worst]``): what its maps, grid and
        point queries read."""
        found = self.cases[self.worst].evaluation
        assert found is not None, "a case of an analysis carries its evaluation"
        return found


@dataclass(frozen=True)
class PointCase:
    """The errors and every term at one point for one tool case, and the evaluation they
    come from (left out of comparisons)."""

    tool: ToolCase
    breakdown: Breakdown
    evaluation: Evaluation | None = field(default=None, compare=False, repr=False)


@dataclass(frozen=True)
class PointResult:
    """The outcome of :func:`esp.core.analysis.evaluate_point`."""

    machine: Machine
    case: str
    equations: str
    datum: Mapping[str, float] | None
    at: Mapping[str, float]
    cases: tuple[PointCase, ...]
    warnings: tuple[str, ...] = ()
