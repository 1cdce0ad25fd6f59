"""The one evaluation of a machine: every figure of an analysed case comes from here.

A machine is prepared for evaluation once (:class:`MachineEvaluation`: its bound model,
its component curves and grids, :class:`esp.core.synthesis.Synthesis`), and each analysed case
-- one tool, or one setting of a servo head or rotary table -- is an immutable
:class:`Evaluation` of it. The datum rule is decided here and nowhere else (Longstaff 2002,
3.05; ESP-NOTES "Datum"): with a datum every total displacement error is reported as
``e(p) - e_ref(datum)``, where ``e_ref`` is the case itself, except on a machine with a
servo head or a rotary table, where every setting is referred to the error at the datum
with the *first* setting, so that the head's and the table's own errors stay in the result
(docs/heads.md).

The headline extremes and their breakdowns (:meth:`Evaluation.case_result`), the point
queries (:meth:`Evaluation.errors_at`, :meth:`Evaluation.breakdown`) and the fields the
maps and the grid CSV draw (:meth:`Evaluation.field`) are methods of the same object, so
they cannot disagree; :class:`esp.core.results.CaseResult` carries the evaluation it came from.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from types import MappingProxyType

import numpy as np
import numpy.typing as npt

from esp.core.errors import DataError
from esp.core.grid import fold
from esp.core.machine import AXIS_NAMES, Machine
from esp.core.models.tool import ToolCase
from esp.core.numerics import arithmetic
from esp.core.positions import as_points_mm, point_mm
from esp.core.results import Breakdown, CaseResult, Extreme
from esp.core.synthesis import (
    Synthesis,
    case_result,
    datum_point,
    tool_cases,
    volumetric_extreme,
)

__all__ = ["TRAVEL_RELATIVE_TOLERANCE", "Evaluation", "MachineEvaluation", "evaluate"]

#: how far, relative to the larger end of its travel (at least 1 mm), a queried position
#: may lie beyond the end of its axis' travel and still count as the end: the rounding of a
#: position read from a file (a diagonal's point from its distance written to six
#: decimals), the same tolerance a measured curve's range allows
#: (:meth:`esp.core.profile.ErrorProfile.at`)
TRAVEL_RELATIVE_TOLERANCE = 1e-9


def _travel_tolerance_mm(lo: float, hi: float) -> float:
    return TRAVEL_RELATIVE_TOLERANCE * max(1.0, abs(lo), abs(hi))


@dataclass(frozen=True, eq=False)
class MachineEvaluation:
    """A machine prepared for evaluation once: the engine (``synthesis``), the datum and
    every tool case of the analysis (:func:`esp.core.synthesis.tool_cases`).

    :meth:`case` gives the :class:`Evaluation` of one of them, with the datum rule of the
    machine decided (module docstring)."""

    machine: Machine
    synthesis: Synthesis = field(repr=False)
    datum: Mapping[str, float] | None
    tools: tuple[ToolCase, ...]

    @property
    def refers_to_first_setting(self) -> bool:
        """Whether every case is referred to the datum error of the first setting (a
        machine with a servo head or a rotary table)."""
        return self.machine.head is not None or self.machine.table is not None

    def case(self, tool: ToolCase | None = None) -> Evaluation:
        """The evaluation of one tool case (default: the first)."""
        tool = self.tools[0] if tool is None else tool
        reference = self.tools[0] if self.refers_to_first_setting else tool
        return Evaluation(self, tool, reference)

    def cases(self) -> tuple[Evaluation, ...]:
        """The evaluation of every tool case, in the order of :attr:`tools`."""
        return tuple(self.case(t) for t in self.tools)

    def check_point(self, point: Mapping[str, float]) -> dict[str, float]:
        """The point as floats, refused (:class:`~esp.core.errors.DataError`) outside the travel
        of an axis or the measured range of a component that does not extrapolate, and when
        it is not one finite real position for each of X, Y, Z
        (:func:`esp.core.positions.point_mm`)."""
        machine = self.machine
        out = point_mm(point, AXIS_NAMES)
        for a in AXIS_NAMES:
            lo, hi = machine.axes[a].travel_mm
            tol = _travel_tolerance_mm(lo, hi)
            if not math.isfinite(out[a]) or not lo - tol <= out[a] <= hi + tol:
                raise DataError(f"{a}={out[a]:g} mm is outside axes.{a}.travel [{lo:g}, {hi:g}]")
        for name, fn in self.synthesis.functions.items():
            if callable(fn):
                comp = machine.components.get(name)
                if comp is not None and comp.axis:
                    fn(np.asarray([out[comp.axis]]))  # raises when outside the measured range
        return out

    def check_points(self, pts: np.ndarray) -> None:
        """Refuse (:class:`DataError`) a row of ``pts`` (N, 3) outside the travel of an axis,
        as :meth:`check_point` does for one point."""
        for i, a in enumerate(AXIS_NAMES):
            lo, hi = self.machine.axes[a].travel_mm
            tol = _travel_tolerance_mm(lo, hi)
            outside = (pts[:, i] < lo - tol) | (pts[:, i] > hi + tol)
            if outside.any():
                k = int(np.argmax(outside))
                raise DataError(
                    f"points_mm[{k}]: {a}={pts[k, i]:g} mm is outside axes.{a}.travel "
                    f"[{lo:g}, {hi:g}]"
                )


def evaluate(machine: Machine) -> MachineEvaluation:
    """Prepare ``machine`` for evaluation (its model bound, its curves read, its grids
    formed) once."""
    with arithmetic():
        syn = Synthesis.prepare(machine)
        return MachineEvaluation(machine, syn, datum_point(machine), tuple(tool_cases(machine)))


@dataclass(frozen=True, eq=False)
class Evaluation:
    """One analysed case: a machine at one tool case, relative to its datum.

    ``tool``: the tool case; ``reference``: the tool case whose error at the datum is
    subtracted (the case itself, or the first setting of a head or table). All errors in
    µm along the machine axes X, Y, Z; positions in mm."""

    machine_evaluation: MachineEvaluation = field(repr=False)
    tool: ToolCase
    reference: ToolCase

    @property
    def machine(self) -> Machine:
        return self.machine_evaluation.machine

    @property
    def synthesis(self) -> Synthesis:
        return self.machine_evaluation.synthesis

    @property
    def datum(self) -> Mapping[str, float] | None:
        return self.machine_evaluation.datum

    @property
    def grids(self) -> Mapping[str, np.ndarray]:
        """The simulation grid of each axis (mm), read-only."""
        out = {}
        for a, g in self.synthesis.grids.items():
            view = g.view()
            view.flags.writeable = False
            out[a] = view
        return MappingProxyType(out)

    def datum_error_um(self) -> dict[str, float] | None:
        """The error subtracted from every total: the reference case's error at the datum
        (None without a datum)."""
        if self.datum is None:
            return None
        with arithmetic():
            return self.synthesis.totals_um(self.datum, self.reference)

    # -- the headline ---------------------------------------------------------------------

    def case_result(self, breakdowns: bool = True) -> CaseResult:
        """The extremes of this case over the simulation grid (with every term at each of
        them when ``breakdowns``), carrying this evaluation."""
        with arithmetic():
            found = case_result(
                self.synthesis, self.tool, self.datum, breakdowns, reference=self.reference
            )
        return replace(found, evaluation=self)

    def volumetric_extreme(self) -> Extreme:
        """The volumetric accuracy of this case and where it occurs
        (``case_result().volumetric``, found with less work)."""
        with arithmetic():
            return volumetric_extreme(
                self.synthesis, self.tool, self.datum, reference=self.reference
            )

    # -- points -----------------------------------------------------------------------------

    def errors_at(self, points_mm: npt.ArrayLike) -> np.ndarray:
        """The three total displacement errors (µm) at many machine positions: ``points_mm``
        of shape (N, 3), columns X, Y, Z in mm; the result (N, 3), relative to the datum.
        One point of shape (3,) is taken as (1, 3); any other shape (a (3, N) array among
        them), a position that is not a finite real number, or one outside the travel of its
        axis raises :class:`~esp.core.errors.DataError`
        (:func:`esp.core.positions.as_points_mm`), as does a position outside a component's
        measured range unless the analysis allows extrapolation."""
        pts = as_points_mm(points_mm)
        self.machine_evaluation.check_points(pts)
        with arithmetic():
            errors = self.synthesis.totals_at_um(pts, self.tool)
            ref = self.datum_error_um()
            if ref is not None:
                errors -= np.array([ref[a] for a in AXIS_NAMES])[None, :]
        return errors

    def breakdown(self, label: str, point: Mapping[str, float]) -> Breakdown:
        """Every term at ``point`` with the three totals and the volumetric error there."""
        with arithmetic():
            return self.synthesis.breakdown(
                label, point, self.tool, self.datum, reference=self.reference
            )

    # -- fields -----------------------------------------------------------------------------

    def field(
        self, fixed: Mapping[str, float] | None = None
    ) -> tuple[dict[str, np.ndarray], dict[str, np.ndarray]]:
        """The error field of this case on the simulation grid, for maps and exports.

        Returns ``(grids, errors)``: ``grids`` maps each axis letter to its 1-D positions
        (mm); ``errors`` maps each direction letter to a 3-D array (µm) indexed
        ``[x, y, z]``. ``fixed`` pins axes to one position each (a slice), e.g.
        ``{"Z": 250.0}``; the grid of a pinned axis is then that single position. Meant for
        grids that fit in memory; the headline never forms the full field."""
        grids = {a: np.array(g, dtype=float) for a, g in self.synthesis.grids.items()}
        for a, value in (fixed or {}).items():
            grids[a] = np.array([float(value)])
        sizes = tuple(grids[a].size for a in AXIS_NAMES)
        with arithmetic():
            products = self.synthesis.products(
                self.tool, self.datum, reference=self.reference, grids=grids
            )
            pairs = fold(products, sizes)
            errors = {
                a: pairs[d][0][:, :, None] + pairs[d][1][:, None, :] + pairs[d][2][None, :, :]
                for d, a in enumerate(AXIS_NAMES)
            }
        return grids, errors
