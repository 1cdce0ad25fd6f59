"""Error maps of a head over a grid of its two angles (numpy only).

Freeman & Ford (2003, section 4.2, Fig. 3) plot the first-order tool-tip error of the
angle head against A_p and C_p from −60° to 60°. :func:`error_map` evaluates the first-
and second-order errors and the exact error on such a grid, and :class:`ErrorMap`
summarises it: the algebraic minimum and maximum of DX, DY, DZ, the largest |D| and where
they occur, and how far the second order (and the exact chain) departs from the first.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from esp.core.devices.head import Head
from esp.core.devices.head_evaluate import HeadEvaluation, evaluate_head
from esp.core.errors import ConfigError
from esp.core.limits import HEAD_MAP_MAX_SETTINGS, refuse_if
from esp.core.values import Quantity, ValueRefused, check, written

__all__ = [
    "DEFAULT_RANGE",
    "MAX_AXIS_VALUES",
    "MAX_SETTINGS",
    "SETTING_LIMIT",
    "ErrorMap",
    "Extreme",
    "GridSpec",
    "error_map",
    "grid_axis",
]

#: the default grid of each angle: from, to, step (degrees): the paper's Fig. 3 range
DEFAULT_RANGE = (-60.0, 60.0, 2.5)
#: the most settings a map may hold (:data:`esp.core.limits.HEAD_MAP_MAX_SETTINGS`)
MAX_SETTINGS = HEAD_MAP_MAX_SETTINGS
#: the most values of one angle of a map (docs/reliability.md, "Resource limits")
MAX_AXIS_VALUES = 100_000
#: the largest magnitude of a grid's from and to, in the coordinate's unit: the settings a
#: head accepts (:attr:`esp.core.devices.device.Device.limit`)
SETTING_LIMIT = 1e6
AXES = ("X", "Y", "Z")


@dataclass(frozen=True)
class GridSpec:
    """One axis of a map: from, to, step, in the coordinate's unit."""

    name: str
    start: float
    stop: float
    step: float

    def values(self) -> np.ndarray:
        return grid_axis(self.start, self.stop, self.step, self.name)


def grid_axis(
    start: float, stop: float, step: float, key: str = "grid", limit: float = SETTING_LIMIT
) -> np.ndarray:
    """start, start + step, …, stop (stop included when the step divides the span).

    Each number goes through the one value check (:func:`esp.core.values.check`): from and
    to finite and within ±``limit``, the step finite and above zero; the count of values is
    estimated before any is made and refused beyond :data:`MAX_AXIS_VALUES` (a step of
    1e-308 gives more values than a float counts).

    Raises
    ------
    ConfigError
        Key ``KEY.from``, ``KEY.to`` or ``KEY.step``: a value that is not a finite number in
        its range, from above to, a step not above zero, too many values.
    """
    setting = Quantity("a setting", "", -limit, limit)
    try:
        start = check(start, setting)
    except ValueRefused as exc:
        raise ConfigError(f"{key}.from", exc.message) from None
    try:
        stop = check(stop, setting)
    except ValueRefused as exc:
        raise ConfigError(f"{key}.to", exc.message) from None
    try:
        step = check(step, "number")
    except ValueRefused as exc:
        raise ConfigError(f"{key}.step", exc.message) from None
    if stop < start:
        raise ConfigError(
            f"{key}.to", f"expected from <= to, found from {written(start)} > to {written(stop)}"
        )
    if step <= 0:
        raise ConfigError(f"{key}.step", f"expected a step above zero, found {written(step)}")
    # a float estimate first: (stop - start) / step may be far beyond any integer's reach
    estimate = np.floor((stop - start) / step + 1e-9) + 1.0
    refuse_if(
        estimate,
        MAX_AXIS_VALUES,
        f"{key}.step",
        f"values from {written(start)} to {written(stop)} in steps of {written(step)}",
        "use a larger step",
        config=True,
    )
    return start + step * np.arange(int(estimate))


@dataclass(frozen=True)
class Extreme:
    """A value and the setting where it occurs."""

    value_um: float
    at: Mapping[str, float]


@dataclass(frozen=True)
class ErrorMap:
    """A head's tool-tip error over a grid of its two angles.

    Attributes
    ----------
    names : the two coordinates, rows first
    rows, cols : (n1,), (n2,) their values (degrees)
    evaluation : the head evaluated at every setting, rows × cols flattened (row-major),
        with the second-order terms
    order : the order of the reported error: 1 (first) or 2 (first plus second)
    """

    names: tuple[str, str]
    rows: np.ndarray
    cols: np.ndarray
    evaluation: HeadEvaluation
    order: int

    @property
    def head(self) -> Head:
        return self.evaluation.head

    @property
    def shape(self) -> tuple[int, int]:
        return (self.rows.size, self.cols.size)

    def grid(self, values: np.ndarray) -> np.ndarray:
        """(N, ...) values over the settings as (n1, n2, ...)."""
        return values.reshape(self.shape + values.shape[1:])

    @property
    def error_um(self) -> np.ndarray:
        """(n1, n2, 3) the reported error (first order, or first plus second)."""
        return self.grid(self.evaluation.error_um)

    @property
    def first_um(self) -> np.ndarray:
        return self.grid(self.evaluation.first_um)

    @property
    def second_um(self) -> np.ndarray:
        """(n1, n2, 3) the second-order terms: the second-order minus the first-order error."""
        assert self.evaluation.second_um is not None
        return self.grid(self.evaluation.second_um)

    @property
    def exact_minus_first_um(self) -> np.ndarray:
        return self.grid(self.evaluation.exact_um - self.evaluation.first_um)

    @property
    def magnitude_um(self) -> np.ndarray:
        """(n1, n2) |D| of the reported error."""
        return np.linalg.norm(self.error_um, axis=-1)

    def at(self, flat_index: int) -> dict[str, float]:
        i, j = np.unravel_index(flat_index, self.shape)
        return {self.names[0]: float(self.rows[i]), self.names[1]: float(self.cols[j])}

    def _extreme(self, values: np.ndarray, kind: str) -> Extreme:
        flat = values.ravel()
        k = int(np.argmin(flat) if kind == "min" else np.argmax(flat))
        return Extreme(float(flat[k]), self.at(k))

    def extremes(self) -> dict[str, dict[str, Extreme]]:
        """``{"X": {"min", "max"}, "Y": …, "Z": …, "D": {"max"}}`` of the reported error."""
        err = self.error_um
        out = {
            a: {"min": self._extreme(err[..., k], "min"), "max": self._extreme(err[..., k], "max")}
            for k, a in enumerate(AXES)
        }
        out["D"] = {"max": self._extreme(self.magnitude_um, "max")}
        return out

    def worst_index(self) -> int:
        """The flat index of the setting with the largest |D|."""
        return int(np.argmax(self.magnitude_um.ravel()))

    def second_order_peak(self) -> Extreme:
        """The largest |second-order term| (vector magnitude) and where."""
        return self._extreme(np.linalg.norm(self.second_um, axis=-1), "max")

    def exact_residual_peak(self) -> Extreme:
        """The largest |exact − first order| and where."""
        return self._extreme(np.linalg.norm(self.exact_minus_first_um, axis=-1), "max")


def error_map(
    head: Head,
    grid: Sequence[GridSpec] | Mapping[str, Any] | None = None,
    *,
    order: int = 1,
    key: str = "map",
) -> ErrorMap:
    """Evaluate a two-axis head over a grid of its angles.

    Parameters
    ----------
    head : a head with exactly two coordinates
    grid : two :class:`GridSpec`, or coordinate -> 1-D values (degrees); default each
        coordinate from −60° to 60° in steps of 2.5° (Freeman & Ford 2003, Fig. 3), the
        coordinates in alphabetical order
    order : the order of the reported error (the second-order terms are always evaluated)
    key : where the grid comes from, for the messages: the head file's ``map`` table (a
        ConfigError), or the command-line option ``--grid`` (a DataError for a grid beyond
        :data:`MAX_SETTINGS`, a ConfigError keyed ``--grid A.step`` for an axis
        :func:`grid_axis` refuses)

    Raises
    ------
    ConfigError
        A head without exactly two coordinates, a grid that does not name them, an axis
        :func:`grid_axis` refuses, or too many settings.
    """
    coords = head.coordinates
    if len(coords) != 2:
        raise ConfigError(
            "map",
            f"a map is over two angles; this head has {len(coords)} coordinate(s) "
            f"({', '.join(coords)}): evaluate single settings with --at",
        )
    if grid is None:
        grid = [GridSpec(c, *DEFAULT_RANGE) for c in sorted(coords)]
    if isinstance(grid, Mapping):
        axes = [(str(n), np.asarray(v, dtype=float).ravel()) for n, v in grid.items()]
    else:
        where = "map." if key == "map" else f"{key} "
        axes = [
            (g.name, grid_axis(g.start, g.stop, g.step, f"{where}{g.name}", head.limit))
            for g in grid
        ]
    names = [n for n, _ in axes]
    if sorted(names) != sorted(coords) or len(names) != 2:
        raise ConfigError(
            "map",
            f"expected a grid of the head's two angles {coords[0]} and {coords[1]}, "
            f"found {', '.join(names) or 'none'}",
        )
    (n1, rows), (n2, cols) = axes
    refuse_if(
        rows.size * cols.size,
        MAX_SETTINGS,
        key,
        f"a map of {rows.size} ({n1}) x {cols.size} ({n2}) settings",
        f"use larger steps in {key}",
        config=key == "map",
    )
    R, C = np.meshgrid(rows, cols, indexing="ij")
    ev = evaluate_head(head, {n1: R.ravel(), n2: C.ravel()}, order=2, exact=True)
    return ErrorMap((n1, n2), rows, cols, replace(ev, order=order), order)
