"""The one evaluation of a machine's error field that the compensation package uses.

:func:`field` prepares a machine once -- its one evaluation
(:class:`esp.core.evaluation.Evaluation` of its first tool case: bound model, component curves,
datum and datum rule) -- and returns a
:class:`Field`, a callable from points (N, 3) in mm to errors (N, 3) in µm that is reused
for every set of points. The tables (:mod:`esp.compensation.build`) and the residual
(:mod:`esp.compensation.predict`) evaluate nothing else:

* :meth:`Field.only` is the same prepared machine restricted to the terms of some of its
  components (the error a table of those components must cancel);
* :meth:`Field.with_values` is the same model with the component values replaced, e.g. by
  the tables read back from a controller's file (what the controller evaluates);
* :class:`Fields` holds one prepared field per direction of approach, so that a command
  writing several formats prepares each direction once. Every direction is referred to
  the same datum error, that of the analysis direction (``[analysis] direction``): the
  controller's position is the scale reading, so the error a table of one direction must
  cancel is that direction's error relative to the one reference, and the reversal at the
  datum (the difference of the two directions there) stays in it (ISO 230-2:2014,
  clause 2: the reversal value at a position is the difference of the mean unidirectional
  positional deviations of the two directions of approach).

This module imports only numpy.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass, replace

import numpy as np
import numpy.typing as npt

from esp.core.evaluation import evaluate
from esp.core.grid import fold
from esp.core.machine import AXIS_NAMES, Machine
from esp.core.models.tool import ToolCase
from esp.core.names import ComponentName
from esp.core.numerics import arithmetic
from esp.core.synthesis import Synthesis

__all__ = ["Field", "Fields", "field", "mesh_points", "mesh_values", "with_direction"]

#: a component's curve: positions along its axis (mm) -> values (engine units)
Curve = Callable[[np.ndarray], np.ndarray]


def with_direction(machine: Machine, direction: str) -> Machine:
    """The machine evaluated with the runs of one direction (``forward``, ``backward``,
    ``mean``)."""
    return replace(machine, analysis=replace(machine.analysis, direction=direction))


@dataclass(frozen=True, eq=False)
class Field:
    """A machine prepared for evaluation at many points.

    Calling it with points of shape (N, 3) (columns X, Y, Z in mm) gives the three total
    displacement errors in µm, shape (N, 3), relative to the datum when one is set: the
    value of :func:`esp.errors_at` for the same machine and its first tool case.
    """

    synthesis: Synthesis
    tool: ToolCase
    datum: Mapping[str, float] | None
    #: the tool case whose error at the datum is subtracted (the evaluation's datum rule)
    reference: ToolCase | None = None
    #: the synthesis whose error at the datum is subtracted, when it is not ``synthesis``:
    #: the analysis direction's, for a field of another direction of approach
    datum_synthesis: Synthesis | None = None

    def datum_error_um(self) -> np.ndarray:
        """The error subtracted from every total (µm, X, Y, Z): the reference case's error
        at the datum, in the analysis direction (zeros without a datum)."""
        if self.datum is None:
            return np.zeros(3)
        syn = self.datum_synthesis or self.synthesis
        with arithmetic():
            ref = syn.totals_um(self.datum, self.reference or self.tool)
        return np.array([ref[a] for a in AXIS_NAMES])

    def __call__(self, points_mm: npt.ArrayLike) -> np.ndarray:
        pts = np.asarray(points_mm, dtype=float).reshape(-1, 3)
        with arithmetic():
            errors = self.synthesis.totals_at_um(pts, self.tool)
        if self.datum is not None:
            errors -= self.datum_error_um()[None, :]
        return errors

    def pairs(self, grids: Sequence[npt.ArrayLike]) -> list[list[np.ndarray]]:
        """The field on the mesh ``grids[0] x grids[1] x grids[2]`` (X, Y, Z positions in
        mm) in the engine's separable form (:func:`esp.core.grid.fold`): per direction the
        three 2-D arrays ``[P_xy, P_xz, P_yz]`` whose sum ``P_xy[i, j] + P_xz[i, k] +
        P_yz[j, k]`` is the error at point (i, j, k), from the same prepared machine
        (each component evaluated once on its axis' grid). Fresh arrays on every call."""
        g = [np.asarray(x, dtype=float).ravel() for x in grids]
        syn = replace(self.synthesis, grids=dict(zip(AXIS_NAMES, g, strict=True)))
        with arithmetic():
            products = syn.products(self.tool, self.datum, reference=self.reference)
            pairs = fold(products, (g[0].size, g[1].size, g[2].size))
        if self.datum is not None and self.datum_synthesis is not None:
            # the products are referred to this direction's own datum error: refer them
            # to the analysis direction's instead
            own = replace(self, datum_synthesis=None).datum_error_um()
            shift = self.datum_error_um() - own
            for d in range(3):
                pairs[d][0] -= shift[d]
        return pairs

    def on_mesh(self, grids: Sequence[npt.ArrayLike]) -> np.ndarray:
        """``self(points)`` for the points of the mesh of ``grids`` (in the order of
        :func:`mesh_points`), formed from :meth:`pairs`: equal to the point evaluation to
        rounding (the terms are summed in another order)."""
        return mesh_values(self.pairs(grids))

    @property
    def components(self) -> tuple[str, ...]:
        """The components whose terms this field sums."""
        return tuple(str(n) for n in self.synthesis.functions)

    def only(self, names: Iterable[str | ComponentName]) -> Field:
        """The field of the named components alone: the same bound model and curves, only
        their terms (no errors of a head or rotary table setting, which no table holds)."""
        keep = set(map(str, names))

        def reduced(syn: Synthesis) -> Synthesis:
            functions = {k: v for k, v in syn.functions.items() if str(k) in keep}
            return replace(syn, functions=functions, setting_errors=False)

        ref = None if self.datum_synthesis is None else reduced(self.datum_synthesis)
        return Field(reduced(self.synthesis), self.tool, self.datum, self.reference, ref)

    def with_values(self, values: Mapping[str, Curve | float]) -> Field:
        """The same model evaluated with ``values`` in place of the components' data:
        component name -> a curve of its axis' position (engine units, the sign of the
        data as given, before the model's sign convention, which is applied here) or a
        number (a squareness). Components not named contribute nothing, nor does a head
        or rotary table setting. The values have no direction of approach: the field is
        referred to its own error at the datum."""
        signs = self.synthesis.model.input_signs
        functions: dict = {}
        for name, v in values.items():
            s = float(signs.get(name, 1.0))
            if callable(v):
                functions[str(name)] = v if s == 1.0 else _scaled(v, s)
            else:
                functions[str(name)] = float(v)
        syn = replace(self.synthesis, functions=functions, setting_errors=False)
        return Field(syn, self.tool, self.datum, self.reference)


def mesh_points(grids: Sequence[npt.ArrayLike]) -> np.ndarray:
    """The points of the mesh of three 1-D grids, shape (N, 3), X varying slowest."""
    mesh = np.meshgrid(*grids, indexing="ij")
    return np.stack([m.ravel() for m in mesh], axis=1)


def mesh_values(pairs: list[list[np.ndarray]]) -> np.ndarray:
    """The errors (N, 3) at the points of the mesh (in the order of :func:`mesh_points`)
    from the pair arrays of :meth:`Field.pairs`."""
    nx, ny = pairs[0][0].shape
    nz = pairs[0][1].shape[1]
    out = np.empty((nx, ny, nz, 3))
    for d in range(3):
        xy, xz, yz = pairs[d]
        out[..., d] = xy[:, :, None] + xz[:, None, :] + yz[None, :, :]
    return out.reshape(-1, 3)


def _scaled(fn: Curve, s: float) -> Curve:
    return lambda x: s * np.asarray(fn(x), dtype=float)


def field(machine: Machine) -> Field:
    """The machine prepared once for evaluation: the one evaluation of its first tool case
    (:func:`esp.core.evaluation.evaluate`), so its errors are :func:`esp.errors_at`'s."""
    case = evaluate(machine).case()
    return Field(case.synthesis, case.tool, case.datum, case.reference)


class Fields:
    """The fields of one machine per direction of approach, each prepared on first use,
    and the last errors evaluated in each direction (the formats of one command mostly
    share their points). Every direction is referred to the analysis direction's error at
    the datum (one datum for all directions, so that the reversal at the datum is kept)."""

    def __init__(self, machine: Machine) -> None:
        self.machine = machine
        self._by_direction: dict[str, Field] = {}
        self._last: dict[str, tuple[np.ndarray, list[list[np.ndarray]]]] = {}

    def pairs(self, direction: str, grids: Sequence[np.ndarray]) -> list[list[np.ndarray]]:
        """``self(direction).pairs(grids)``, kept (read-only) for the next call with the
        same grids (the formats of one command mostly share them)."""
        key = np.concatenate([[g.size for g in grids], *grids])
        last = self._last.get(direction)
        if last is not None and last[0].shape == key.shape and np.array_equal(last[0], key):
            return last[1]
        pairs = self(direction).pairs(grids)
        for arrays in pairs:
            for arr in arrays:
                arr.setflags(write=False)
        self._last[direction] = (key, pairs)
        return pairs

    def __call__(self, direction: str | None = None) -> Field:
        """The field with the runs of ``direction`` (default: the analysis' direction)."""
        d = direction or self.machine.analysis.direction
        if d not in self._by_direction:
            own = self.machine.analysis.direction
            if d == own:
                self._by_direction[d] = field(self.machine)
            else:
                reference = self(own).synthesis
                self._by_direction[d] = replace(
                    field(with_direction(self.machine, d)), datum_synthesis=reference
                )
        return self._by_direction[d]
