"""One measured error component of one axis, as a function of that axis' position.

An :class:`ErrorProfile` holds what a Laser10 file (or a tidy CSV, or a constant in the
configuration) says about one error component: its kind, the axis that moved, the
direction of the error, the nominal targets and the deviation of every run in each
direction. Values are always held in the engine's units (µm for linear and straightness,
µm/m for angular); conversion from the file's unit happens when the profile is made.

References
----------
Longstaff (2002), section 1.03 and table 1.1 (the 21 geometric errors); section 4.01.2.1
(straightness slope removal by least-squares or end-point fit); ISO 230-2:2014 clause 2
(forward/backward runs, mean deviation per direction).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from types import MappingProxyType
from typing import Any

import numpy as np
import numpy.typing as npt

from esp.core.errors import DataError
from esp.core.positions import as_positions_mm
from esp.core.units import (
    POSITION_LIMIT_MM,
    beyond_limit,
    engine_unit_for_kind,
    flush_tiny,
    limit_text,
    to_engine,
)
from esp.core.values import written

__all__ = ["DIRECTIONS", "KINDS", "ErrorProfile", "normalise_direction"]

KINDS = ("linear", "straightness", "angular")
DIRECTIONS = ("forward", "backward")
#: the shortest span of a profile of several targets, mm (below it the slope of a
#: straightness fit is not defined in floating point); the readers ask for more
_MIN_SPAN_MM = 1e-6
_DIRECTION_ALIASES = {
    "forward": "forward",
    "fwd": "forward",
    "+": "forward",
    "up": "forward",
    "backward": "backward",
    "reverse": "backward",
    "bwd": "backward",
    "back": "backward",
    "-": "backward",
    "down": "backward",
    "mean": "mean",
    "bidirectional": "mean",
}


def normalise_direction(direction: str) -> str:
    """Return ``"forward"``, ``"backward"`` or ``"mean"`` for any accepted spelling."""
    d = _DIRECTION_ALIASES.get(str(direction).strip().lower())
    if d is None:
        raise DataError(f"unknown direction {direction!r}; expected forward, reverse or mean")
    return d


def _frozen(mapping: Mapping | None) -> Mapping:
    return MappingProxyType(dict(mapping or {}))


@dataclass(frozen=True, eq=False)
class ErrorProfile:
    """Measured deviations of one error component along one axis.

    Parameters
    ----------
    kind : ``"linear"``, ``"straightness"`` or ``"angular"``
    targets_mm : shape (n,), nominal positions in mm, strictly increasing
    runs : ``{"forward": (r_f, n), "backward": (r_b, n)}`` deviations in the engine unit
        (µm, or µm/m for angular). A direction may be absent; at least one run is needed.
        Column j belongs to ``targets_mm[j]`` whatever order the runs were taken in.
    axis : the axis that moved (``"X"``, ``"Y"``, ``"Z"``), when known
    error_direction : for straightness the direction of the deviation, for angular the
        axis the rotation is about; None for linear or when not known
    input_unit : the unit of the source, for reports
    metadata : the file's user text (machine, serial, date, by, axis, location, ...)
    environment : the file's environment readings, name -> tuple of the raw fields
    source : where the data came from (a path, or a description such as ``"constant"``)

    Targets and deviations smaller than :data:`esp.core.units.TINY` (1e-30) in size are held
    as 0.

    Raises
    ------
    DataError
        A target or deviation is not finite or lies beyond its plausibility limit
        (:data:`esp.core.units.POSITION_LIMIT_MM`, :func:`esp.core.units.limit_for_kind`), the
        targets do not increase, or several targets span less than 1e-6 mm. The readers
        check the same limits first, with the file's line or the configuration key.
    """

    kind: str
    targets_mm: np.ndarray
    runs: Mapping[str, np.ndarray]
    axis: str | None = None
    error_direction: str | None = None
    input_unit: str | None = None
    metadata: Mapping[str, str] = field(default_factory=dict)
    environment: Mapping[str, tuple[str, ...]] = field(default_factory=dict)
    source: str | None = None

    def __post_init__(self) -> None:
        where = f" in {self.source}" if self.source else ""
        if self.kind not in KINDS:
            raise DataError(f"unknown error kind {self.kind!r}{where}; expected one of {KINDS}")
        targets = flush_tiny(np.asarray(self.targets_mm, dtype=float).reshape(-1))
        if targets.size < 1 or not np.all(np.isfinite(targets)):
            raise DataError(f"targets must be finite numbers{where}, got {targets!r}")
        if np.abs(targets).max() > POSITION_LIMIT_MM:
            far = float(targets[np.argmax(np.abs(targets))])
            raise DataError(
                f"expected targets within ±{POSITION_LIMIT_MM:g} mm{where}, found {written(far)} mm"
            )
        if targets.size > 1 and not np.all(np.diff(targets) > 0):
            raise DataError(f"targets must be strictly increasing{where}, got {targets!r}")
        if targets.size > 1 and not targets[-1] - targets[0] >= _MIN_SPAN_MM:
            raise DataError(
                f"expected targets spanning at least {_MIN_SPAN_MM:g} mm{where}, found "
                f"{targets[0]:g} to {targets[-1]:g} mm"
            )
        targets.setflags(write=False)
        runs: dict[str, np.ndarray] = {}
        for name, values in self.runs.items():
            if name not in DIRECTIONS:
                raise DataError(f"unknown run direction {name!r}{where}")
            arr = flush_tiny(np.asarray(values, dtype=float))
            if arr.ndim == 1:
                arr = arr.reshape(1, -1)
            if arr.ndim != 2 or arr.shape[1] != targets.size:
                raise DataError(
                    f"{name} runs{where} must have shape (runs, {targets.size}), got {arr.shape}"
                )
            if arr.shape[0] == 0:
                continue
            if not np.all(np.isfinite(arr)):
                raise DataError(f"{name} runs{where} hold a value that is not a finite number")
            bad = beyond_limit(arr, self.kind)
            if bad is not None:
                raise DataError(
                    f"expected {self.kind} deviations within {limit_text(self.kind)}{where}, "
                    f"found {written(arr.flat[bad])} {engine_unit_for_kind(self.kind)} in the "
                    f"{name} runs"
                )
            arr.setflags(write=False)
            runs[name] = arr
        if not runs:
            raise DataError(f"no runs{where}: at least one run is needed")
        object.__setattr__(self, "targets_mm", targets)
        object.__setattr__(self, "runs", _frozen(runs))
        object.__setattr__(self, "metadata", _frozen(self.metadata))
        object.__setattr__(self, "environment", _frozen(self.environment))

    # -- construction -------------------------------------------------------------------

    @classmethod
    def from_values(
        cls,
        kind: str,
        targets_mm: npt.ArrayLike,
        values: npt.ArrayLike,
        unit: str | None = None,
        **kwargs: Any,
    ) -> ErrorProfile:
        """A profile with one curve (used as a single forward run), converted from ``unit``.

        ``targets_mm`` may be in any order; they are sorted with their values.
        """
        t = np.asarray(targets_mm, dtype=float).reshape(-1)
        v = np.asarray(values, dtype=float).reshape(-1)
        if t.shape != v.shape:
            raise DataError(f"{t.size} targets but {v.size} values")
        order = np.argsort(t, kind="stable")
        unit = unit or engine_unit_for_kind(kind)
        v = to_engine(v[order], unit, kind)
        return cls(kind, t[order], {"forward": v.reshape(1, -1)}, input_unit=unit, **kwargs)

    # -- what it holds --------------------------------------------------------------------

    @property
    def unit(self) -> str:
        """The unit of the deviations held: ``"um"`` or ``"um/m"``."""
        return engine_unit_for_kind(self.kind)

    @property
    def directions(self) -> tuple[str, ...]:
        """The directions that have runs, forward first."""
        return tuple(d for d in DIRECTIONS if d in self.runs)

    @property
    def is_bidirectional(self) -> bool:
        return len(self.directions) == 2

    @property
    def span_mm(self) -> float:
        """The measured length: last target minus first."""
        return float(self.targets_mm[-1] - self.targets_mm[0])

    @property
    def name(self) -> str:
        """Component name in esp's notation (``X.linear``, ``X.straightness.Y``, ...)."""
        axis = self.axis or "?"
        if self.kind == "linear":
            return f"{axis}.linear"
        return f"{axis}.{self.kind}.{self.error_direction or '?'}"

    def run_count(self, direction: str) -> int:
        d = normalise_direction(direction)
        return int(self.runs[d].shape[0]) if d in self.runs else 0

    # -- curves ---------------------------------------------------------------------------

    def mean(self, direction: str = "mean") -> np.ndarray:
        """Mean deviation at each target, shape (n,).

        ``"forward"`` / ``"backward"`` (alias ``"reverse"``): the mean over the runs of that
        direction. ``"mean"``: the bidirectional mean, the average of the two direction
        means (ISO 230-2:2014, 2.13); with equal run counts this is the mean of all runs.
        A profile measured in one direction only gives that direction's mean for ``"mean"``.
        """
        d = normalise_direction(direction)
        if d == "mean":
            return np.mean([self.runs[k].mean(axis=0) for k in self.directions], axis=0)
        if d not in self.runs:
            where = f" {self.source}" if self.source else ""
            raise DataError(f"profile{where} has no {d} runs (it has {', '.join(self.directions)})")
        return self.runs[d].mean(axis=0)

    def at(
        self, positions_mm: npt.ArrayLike, direction: str = "mean", extrapolate: bool = False
    ) -> np.ndarray:
        """The mean deviation at any positions, by linear interpolation between targets.

        Outside the measured targets this raises :class:`DataError` unless
        ``extrapolate`` is true; then the end value is held (ESP-NOTES: between and beyond
        targets). A single-target profile is a constant, valid everywhere. Positions that
        are not finite real numbers raise :class:`DataError`
        (:func:`esp.core.positions.as_positions_mm`).
        """
        x = as_positions_mm(positions_mm)
        curve = self.mean(direction)
        if curve.size == 1:
            return np.full(x.shape, float(curve[0]))
        lo, hi = float(self.targets_mm[0]), float(self.targets_mm[-1])
        if not extrapolate and x.size:
            tol = 1e-9 * max(1.0, abs(lo), abs(hi))
            xmin, xmax = float(np.min(x)), float(np.max(x))
            if xmin < lo - tol or xmax > hi + tol:
                bad = xmin if xmin < lo - tol else xmax
                where = f"{self.source}: " if self.source else ""
                raise DataError(
                    f"{where}{self.name} is measured from {lo:g} to {hi:g} mm but is needed at "
                    f"{bad:g} mm; allow extrapolation to hold the end value"
                )
        return np.interp(x, self.targets_mm, curve)

    def slope_line(self, fit: str = "least-squares") -> np.ndarray:
        """The straight line fitted to the bidirectional mean, evaluated at the targets.

        ``fit``: ``"least-squares"`` (ordinary least squares), ``"endpoint"`` (the line
        through the first and last mean values), Longstaff (2002) 4.01.2.1 c; or ``"none"``
        (no line: a straightness that is already processed, or from a model).
        """
        y = self.mean("mean")
        t = self.targets_mm
        if t.size < 2 or fit == "none":
            return np.zeros_like(y)
        if fit == "endpoint":
            slope = (y[-1] - y[0]) / (t[-1] - t[0])
            return y[0] + slope * (t - t[0])
        if fit in ("least-squares", "least_squares", "lsq"):
            tc = t - t.mean()
            slope = float(np.dot(tc, y - y.mean()) / np.dot(tc, tc))
            return y.mean() + slope * tc
        raise DataError(
            f"unknown straightness fit {fit!r}; expected least-squares, endpoint or none"
        )

    def without_slope(self, fit: str = "least-squares") -> ErrorProfile:
        """A copy with the set-up misalignment removed from every run.

        One line, fitted to the bidirectional mean, is subtracted from all runs, so the
        scatter between runs is kept. Squareness is never taken from the removed slope.
        """
        if fit == "none":
            return self
        line = self.slope_line(fit)
        runs = {d: r - line for d, r in self.runs.items()}
        for d, r in runs.items():
            bad = beyond_limit(r, self.kind)
            if bad is None:
                continue
            where = f"{self.source}: " if self.source else ""
            key = (
                f"axes.{self.axis}.errors.straightness.{self.error_direction}"
                if self.axis and self.error_direction
                else "the straightness"
            )
            j = bad % self.targets_mm.size
            raise DataError(
                f"{where}{key}: the slope removal (analysis.straightness_fit = {fit!r}) makes "
                f"the {d} deviation at {written(self.targets_mm[j])} mm "
                f"{written(r.flat[bad])} um (from {written(self.runs[d].flat[bad])} "
                f"um as given), beyond the limit {limit_text(self.kind)}: the value comes "
                "from the line the fit removes; check the data, or set "
                "analysis.straightness_fit = 'none'"
            )
        return replace(self, runs=runs)

    def scaled(self, factor: float) -> ErrorProfile:
        """A copy with every deviation multiplied by ``factor`` (``-1`` for data measured
        with the opposite sign convention)."""
        if factor == 1.0:
            return self
        runs = {d: r * factor for d, r in self.runs.items()}
        return replace(self, runs=runs)
