"""The Monte Carlo distribution of the volumetric accuracy (JCGM 101:2008, GUM Supplement 1),
on the analysis grid, with per-tile bounds so that each draw evaluates only the tiles that
can hold its maximum.

**The model drawn.** Every component's error is drawn as ``e(x) = measured(x) + z · u(x)``:
its measured curve (the best estimate, as the analysis uses it) plus one standardised
scalar ``z`` per component and draw (normal, or rectangular of the same standard deviation,
as the component's ``distribution`` says) times its standard uncertainty curve
u(x) = U(x) / k, with the component's own k. The deviation is fully correlated along the
axis (a calibration or set-up error shifts the whole curve); components are independent.
The volumetric accuracy of a draw is the largest volumetric error over the whole analysis
grid, relative to the datum when one is set, for one tool case.

**Linear in the draws.** The error field of a draw is ``E(p) = Σ_c ζ_c · T_c(p)`` with
``ζ = (1, z_1, ..., z_n)``: ``T_0`` the best-estimate field and ``T_c`` the field of
component c's u alone (the best estimate folded into the same matrix product as a
column of ones). Every ``T_c`` is separable (:mod:`esp.grid`), so it is never formed over
the whole grid.

**Tiles.** The grid is cut into tiles of about sqrt(2·P) points (P the grid's points).
For each tile, direction d and column c, the minimum and maximum of ``T_c,d`` over the tile
follow from the minima and maxima of its three pair arrays over the tile's faces. For a
draw ζ, ``E_d`` over the tile then lies between ``Σ_c min(ζ_c·lo_c, ζ_c·hi_c)`` and
``Σ_c max(ζ_c·lo_c, ζ_c·hi_c)`` -- a few matrix products for a batch of draws -- which
bounds the volumetric error over the tile. Each draw evaluates its tile of largest bound,
then, while any of its tiles' bound exceeds the largest value it has found, those tiles
(all of them when few are left, else its next best 4, 16, ... at a time); a tile whose
bound does not exceed that value cannot hold the draw's maximum and is not evaluated for
that draw. The bounds are computed in float64 and compared after deducting the largest
rounding error of the evaluation, so each draw's value is the maximum over every point of
the grid up to that rounding (tested draw by draw against the evaluation of every point,
``method="full"``), and a field that is flat over many tiles is decided by its first one.

**Precision.** The evaluation runs in float32 by default: the fields are a few tens of
µm, float32 keeps 7 significant digits, and the summary (printed to 0.001 µm) is unchanged
(shown in the tests and ``benchmarks/uncertainty.py``); ``dtype="float64"`` is available.

**Limits.** :data:`MONTECARLO_MAX_WORK` point-draws (samples × grid points) and
:data:`MONTECARLO_MAX_BYTES` of memory, checked before any work by
:func:`esp.uncertainty.propagate.check_uncertainty`.
"""

from __future__ import annotations

import math
from collections import OrderedDict
from collections.abc import Callable, Mapping
from dataclasses import dataclass

import numpy as np

from esp.grid import fold
from esp.machine import AXIS_NAMES, Machine
from esp.models.tool import ToolCase, tool_cases
from esp.results import MonteCarloSummary
from esp.synthesis import Synthesis, datum_point
from esp.uncertainty.spec import UncertaintySpec, uncertainty_machine

__all__ = [
    "MONTECARLO_MAX_BYTES",
    "MONTECARLO_MAX_WORK",
    "MonteCarloModel",
    "montecarlo_errors",
    "montecarlo_memory_bytes",
    "montecarlo_model",
    "montecarlo_volumetric",
]

#: the most point-draws (samples × grid points) a Monte Carlo evaluation may ask for
MONTECARLO_MAX_WORK = 10**12
#: the most memory a Monte Carlo evaluation may need (estimated before it starts)
MONTECARLO_MAX_BYTES = 1 << 30
#: draws are generated in blocks of this many, whatever the batch size, so that the same
#: seed gives the same draws
_RNG_BLOCK = 4096
#: elements of the (draws × tiles) arrays of one batch
_BATCH_ELEMENTS = 1 << 21
#: elements of one (draws × tile points) evaluation
_EVAL_ELEMENTS = 1 << 20
#: bytes of tile fields kept between draws
_CACHE_BYTES = 16 << 20

Progress = Callable[[int, int], None]


# -- the linear model ---------------------------------------------------------------------


def _tile_side_counts(sizes: tuple[int, int, int]) -> tuple[int, int, int]:
    """Tile sides: about sqrt(2·P) points per tile (at least 64 where the grid allows),
    as cubic as the grid allows (the bound of a tile costs one column of a matrix product
    per draw, the evaluation of a tile a few per point: this balances the two)."""
    points = sizes[0] * sizes[1] * sizes[2]
    budget = float(min(max(math.sqrt(2.0 * points), 64.0), 4096.0))
    shape = [1, 1, 1]
    for left, a in zip((3, 2, 1), sorted(range(3), key=lambda a: sizes[a]), strict=True):
        side = max(1, min(sizes[a], round(budget ** (1.0 / left))))
        shape[a] = side
        budget = max(1.0, budget / side)
    return shape[0], shape[1], shape[2]


def _field(pairs) -> np.ndarray:
    """The three directions' field from pair arrays, shape (3, nx, ny, nz), summed in the
    engine's order ``(P_xy + P_xz) + P_yz``."""
    out = []
    for pxy, pxz, pyz in pairs:
        e = np.add(pxy[:, :, None], pxz[:, None, :])
        e += pyz[None, :, :]
        out.append(e)
    return np.stack(out)


@dataclass
class MonteCarloModel:
    """The field of one tool case as a linear function of the draws, tiled.

    Column 0 is the best estimate, then one column per component with an uncertainty
    (its u curve alone). ``pairs`` holds the pair arrays of every column and direction,
    stacked: ``P_xy`` of shape (columns, 3, nx, ny), ``P_xz`` (columns, 3, nx, nz),
    ``P_yz`` (columns, 3, ny, nz), in the evaluation's floating-point type; ``lo``/``hi``
    the minimum and maximum of each column's field over each tile, shape (columns, 3,
    tiles); ``shapes`` each component's distribution; ``sizes`` the grid, ``tile`` the tile
    sides.
    """

    names: tuple[str, ...]
    shapes: tuple[str, ...]
    pairs: tuple[np.ndarray, np.ndarray, np.ndarray]
    sizes: tuple[int, int, int]
    tile: tuple[int, int, int]
    lo: np.ndarray
    hi: np.ndarray

    @property
    def tiles(self) -> tuple[int, int, int]:
        nx, ny, nz = (-(-n // t) for n, t in zip(self.sizes, self.tile, strict=True))
        return nx, ny, nz

    @property
    def points(self) -> int:
        return self.sizes[0] * self.sizes[1] * self.sizes[2]

    @property
    def columns(self) -> int:
        return int(self.lo.shape[0])

    def tile_field(self, t: int) -> np.ndarray:
        """Every column's field over tile ``t``, shape (columns, 3 · points of the tile):
        the three directions one after the other, points in C order."""
        bx, by, bz = np.unravel_index(t, self.tiles)
        x, y, z = (
            slice(int(b) * s, min(n, (int(b) + 1) * s))
            for b, s, n in zip((bx, by, bz), self.tile, self.sizes, strict=True)
        )
        pxy, pxz, pyz = self.pairs
        e = np.add(pxy[:, :, x, y, None], pxz[:, :, x, None, z])
        e += pyz[:, :, None, y, z]
        return e.reshape(e.shape[0], -1)


def _tile_extremes(pairs, starts) -> tuple[np.ndarray, np.ndarray]:
    """The minimum and maximum of every column's field over every tile, shape (columns,
    3, tiles) with the tiles in C order, from the extremes of the pair arrays over the
    tiles' faces."""
    cuts = ((starts[0], starts[1]), (starts[0], starts[2]), (starts[1], starts[2]))
    out = []
    for reduce in (np.minimum, np.maximum):
        faces = [
            reduce.reduceat(reduce.reduceat(p, r, axis=2), c, axis=3)
            for p, (r, c) in zip(pairs, cuts, strict=True)
        ]
        e = np.add(faces[0][:, :, :, :, None], faces[1][:, :, :, None, :])
        e += faces[2][:, :, None, :, :]
        out.append(e.reshape(e.shape[0], 3, -1).astype(float))
    return out[0], out[1]


def montecarlo_model(
    machine: Machine,
    spec: UncertaintySpec,
    tool: ToolCase | None = None,
    grids: Mapping[str, np.ndarray] | None = None,
    dtype: str = "float64",
) -> MonteCarloModel:
    """The linear model of the Monte Carlo method for one tool case, on the analysis grid
    (or on ``grids``, axis letter -> positions in mm), its pair arrays in ``dtype``."""
    tool = tool or tool_cases(machine)[0]
    datum = datum_point(machine)
    base = Synthesis.prepare(machine)
    if grids is not None:
        base.grids.update({a: np.asarray(v, dtype=float) for a, v in grids.items()})
    g = base.grids
    sizes = (int(g["X"].size), int(g["Y"].size), int(g["Z"].size))
    names = tuple(spec.components)
    columns = len(names) + 1
    shapes2 = ((sizes[0], sizes[1]), (sizes[0], sizes[2]), (sizes[1], sizes[2]))
    pxy, pxz, pyz = (np.empty((columns, 3, *shape), dtype=dtype) for shape in shapes2)
    pairs = (pxy, pxz, pyz)
    for c in range(columns):
        if c == 0:
            products = base.products(tool, datum)
        else:
            syn = Synthesis.prepare(
                uncertainty_machine(machine, spec, {names[c - 1]}, standard=True),
                measured=False,
            )
            syn.grids.update(g)
            products = syn.products(tool, datum)
        for d, arrays in enumerate(fold(products, sizes)):
            for k, a in enumerate(arrays):
                pairs[k][c, d] = a
    tile = _tile_side_counts(sizes)
    starts = [np.arange(0, n, t) for n, t in zip(sizes, tile, strict=True)]
    lo, hi = _tile_extremes(pairs, starts)
    shapes = tuple(spec.components[n].distribution for n in names)
    return MonteCarloModel(names, shapes, pairs, sizes, tile, lo, hi)


def montecarlo_memory_bytes(machine: Machine, spec: UncertaintySpec, dtype: str = "float32") -> int:
    """An estimate of the memory the Monte Carlo evaluation of ``machine`` needs, bytes:
    the stacked pair arrays of every column, the tile bounds, the draws kept, one batch
    and the cache of tile fields."""
    nx, ny, nz = (machine.axes[a].grid_mm().size for a in AXIS_NAMES)
    sizes = (nx, ny, nz)
    columns = len(spec.components) + 1
    tile = _tile_side_counts(sizes)
    tiles = math.prod(-(-n // t) for n, t in zip(sizes, tile, strict=True))
    faces = sizes[0] * sizes[1] + sizes[0] * sizes[2] + sizes[1] * sizes[2]
    item = np.dtype(dtype).itemsize
    pairs = item * columns * 3 * faces + 8 * 3 * faces  # and one column of fold in float64
    bounds = 8 * 3 * 2 * columns * tiles
    draws = 8 * (spec.samples + _RNG_BLOCK * columns)
    batch = 8 * 8 * _BATCH_ELEMENTS
    return int(pairs + bounds + draws + batch + _CACHE_BYTES + 4 * item * _EVAL_ELEMENTS)


# -- draws ------------------------------------------------------------------------------


def _draw(rng: np.random.Generator, shapes, count: int) -> np.ndarray:
    """Standardised draws (mean 0, standard deviation 1), shape (count, n)."""
    z = np.empty((count, len(shapes)))
    for j, shape in enumerate(shapes):
        if shape == "rectangular":
            z[:, j] = rng.uniform(-math.sqrt(3.0), math.sqrt(3.0), size=count)
        else:
            z[:, j] = rng.standard_normal(count)
    return z


def _draw_blocks(spec: UncertaintySpec, shapes):
    """The augmented draws ζ = (1, z) in blocks of :data:`_RNG_BLOCK` (the last one cut
    short): the first n draws of a seed are the same whatever the number of samples."""
    rng = np.random.default_rng(spec.seed)
    done = 0
    while done < spec.samples:
        n = min(_RNG_BLOCK, spec.samples - done)
        block = np.empty((_RNG_BLOCK, len(shapes) + 1))
        block[:, 0] = 1.0
        block[:, 1:] = _draw(rng, shapes, _RNG_BLOCK)
        done += n
        yield block[:n]


# -- the search ---------------------------------------------------------------------------


class _Evaluator:
    """Evaluates tiles for sets of draws in one floating-point type, with a bounded cache
    of tile fields."""

    def __init__(self, model: MonteCarloModel, dtype):
        self.model = model
        self.dtype = np.dtype(dtype)
        self.cache: OrderedDict[int, np.ndarray] = OrderedDict()
        self.cached = 0
        self.evaluated = 0

    def matrix(self, t: int) -> np.ndarray:
        found = self.cache.get(t)
        if found is not None:
            self.cache.move_to_end(t)
            return found
        m = self.model.tile_field(t)
        self.cache[t] = m
        self.cached += m.nbytes
        while self.cached > _CACHE_BYTES and len(self.cache) > 1:
            _, old = self.cache.popitem(last=False)
            self.cached -= old.nbytes
        return m

    def peaks(self, t: int, zeta: np.ndarray) -> np.ndarray:
        """The largest squared volumetric error over tile ``t`` for each row of ``zeta``
        (augmented draws in ``self.dtype``), squares summed as ``(x² + y²) + z²``."""
        m = self.matrix(t)
        n = m.shape[1] // 3
        out = np.empty(zeta.shape[0], dtype=self.dtype)
        rows = max(1, _EVAL_ELEMENTS // m.shape[1])
        for r0 in range(0, zeta.shape[0], rows):
            e = (zeta[r0 : r0 + rows] @ m).reshape(-1, 3, n)
            np.square(e, out=e)
            s = e[:, 0] + e[:, 1]
            s += e[:, 2]
            out[r0 : r0 + rows] = s.max(axis=1)
        self.evaluated += zeta.shape[0] * n
        return out


def _bounds(model: MonteCarloModel, zeta: np.ndarray, dtype) -> np.ndarray:
    """For every draw and tile, the square of the largest volumetric error the tile can
    hold beyond the rounding of the evaluation, shape (draws, tiles).

    Per direction the tile's values lie between ``lower`` and ``upper`` (float64, from the
    columns' extremes over the tile); the evaluation in ``dtype`` may exceed them by its
    rounding, at most about ``columns · eps · Σ_c |ζ_c| max|T_c|``. A tile whose bound, less
    that allowance, does not exceed a draw's running maximum cannot raise it by more than
    the rounding: it is not evaluated. So every draw's value is the maximum over every
    point up to the rounding of the evaluation -- and a field that is flat over many tiles
    is decided by its first tile.
    """
    columns = model.lo.shape[0]
    tiles = model.lo.shape[2]
    lo = model.lo.reshape(columns, -1)
    hi = model.hi.reshape(columns, -1)
    z = zeta.astype(float)
    pos = np.maximum(z, 0.0)
    neg = np.minimum(z, 0.0)
    upper = pos @ hi + neg @ lo
    lower = pos @ lo + neg @ hi
    reach = np.abs(z) @ np.maximum(np.abs(lo), np.abs(hi))
    allowance = 4.0 * (columns + 4) * float(np.finfo(dtype).eps)
    peak = np.maximum(upper, -lower)
    peak -= allowance * reach
    np.maximum(peak, 0.0, out=peak)
    peak = peak.reshape(z.shape[0], 3, tiles)
    np.square(peak, out=peak)
    total = peak[:, 0] + peak[:, 1]
    total += peak[:, 2]
    return total


def _evaluate_pairs(ev: _Evaluator, zeta, best, open_, rows, tiles) -> None:
    """Evaluate the (draw, tile) pairs given, sorted by tile, one matrix product per
    tile; raise each draw's running maximum ``best`` and close the pairs."""
    edges = np.flatnonzero(np.diff(tiles)) + 1
    for r, c in zip(np.split(rows, edges), np.split(tiles, edges), strict=True):
        t = int(c[0])
        np.maximum.at(best, r, ev.peaks(t, zeta[r]))
        open_[r, t] = False


def _search_batch(
    model: MonteCarloModel, ev: _Evaluator, zeta: np.ndarray, dense: bool
) -> np.ndarray:
    """The largest squared volumetric error over the grid for each draw of ``zeta``.

    Round 1 evaluates each draw's tile of largest bound (grouped by tile). Then, while
    some draw has tiles whose bound exceeds its running maximum, either all of them are
    evaluated (when they are few: at most four per draw on average) or each draw's next
    best 4, 16, ... tiles; a tile whose bound does not exceed the draw's maximum is never
    evaluated for that draw.
    """
    count = zeta.shape[0]
    tiles = model.lo.shape[2]
    zeta = zeta.astype(ev.dtype)
    best = np.full(count, -np.inf, dtype=ev.dtype)
    if dense:
        for t in range(tiles):
            np.maximum(best, ev.peaks(t, zeta), out=best)
        return best
    bound = _bounds(model, zeta, ev.dtype)
    open_ = np.ones((count, tiles), dtype=bool)
    rows = np.arange(count)
    top = bound.argmax(axis=1)
    order = np.argsort(top, kind="stable")
    _evaluate_pairs(ev, zeta, best, open_, rows[order], top[order])
    active = rows
    per_draw = 4
    while True:
        candidates = open_[active] & (bound[active] > best[active, None])
        alive = candidates.any(axis=1)
        active, candidates = active[alive], candidates[alive]
        if not active.size:
            return best
        if candidates.sum() <= 4 * active.size or per_draw >= tiles:
            # the few tiles left: evaluate them all, grouped by tile
            tile_of, row_of = np.nonzero(candidates.T)
            _evaluate_pairs(ev, zeta, best, open_, active[row_of], tile_of)
            continue
        b = np.where(candidates, bound[active], -np.inf)
        pick = np.argpartition(-b, per_draw - 1, axis=1)[:, :per_draw]
        row_of = np.repeat(np.arange(active.size), per_draw)
        tile_of = pick.reshape(-1)
        keep = candidates[row_of, tile_of]
        row_of, tile_of = row_of[keep], tile_of[keep]
        order = np.argsort(tile_of, kind="stable")
        _evaluate_pairs(ev, zeta, best, open_, active[row_of[order]], tile_of[order])
        per_draw *= 4


def montecarlo_volumetric(
    machine: Machine,
    spec: UncertaintySpec,
    tool: ToolCase | None = None,
    progress: Progress | None = None,
    *,
    dtype: str = "float32",
    method: str = "bounds",
) -> MonteCarloSummary:
    """The distribution of the volumetric accuracy over ``spec.samples`` draws.

    Parameters
    ----------
    machine, spec : the machine (its errors are the best estimate) and its uncertainty
    tool : the tool case drawn (default: the first of the machine)
    progress : called as ``progress(done, samples)`` after each batch of draws
    dtype : ``"float32"`` (default) or ``"float64"``: the type the field is evaluated in
    method : ``"bounds"`` (default: only the tiles each draw needs, see the module) or
        ``"full"`` (every point of the grid for every draw: the reference); the two give
        the same values up to rounding

    Returns
    -------
    MonteCarloSummary
        mean, standard deviation (n − 1) and the probabilistically symmetric 95 % coverage
        interval of the volumetric accuracy (µm), every draw's value, and how many
        point-draws were evaluated.

    References
    ----------
    JCGM 101:2008, 5.9, 7.
    """
    if method not in ("bounds", "full"):
        raise ValueError(f"method: expected 'bounds' or 'full', got {method!r}")
    tool = tool or tool_cases(machine)[0]
    model = montecarlo_model(machine, spec, tool, dtype=dtype)
    ev = _Evaluator(model, dtype)
    tiles = model.lo.shape[2]
    batch = max(1, min(_RNG_BLOCK, _BATCH_ELEMENTS // (3 * tiles)))
    values = np.empty(spec.samples)
    done = 0
    for block in _draw_blocks(spec, model.shapes):
        for b0 in range(0, block.shape[0], batch):
            zeta = block[b0 : b0 + batch]
            # a square below the smallest float is zero for a maximum: not an error
            with np.errstate(under="ignore"):
                peak = _search_batch(model, ev, zeta, dense=method == "full")
            values[done : done + zeta.shape[0]] = np.sqrt(np.maximum(peak, 0.0))
            done += zeta.shape[0]
            if progress:
                progress(done, spec.samples)
    values.setflags(write=False)
    lo, hi = np.percentile(values, [2.5, 97.5])
    return MonteCarloSummary(
        mean_um=float(values.mean()),
        std_um=float(values.std(ddof=1)),
        interval_um=(float(lo), float(hi)),
        samples=int(spec.samples),
        seed=int(spec.seed),
        values_um=values,
        grid_points=model.points,
        evaluated_points=int(ev.evaluated),
        dtype=ev.dtype.name,
        tool=tool,
    )


def montecarlo_errors(
    machine: Machine, spec: UncertaintySpec, point, tool: ToolCase | None = None
) -> np.ndarray:
    """Monte Carlo draws of the three errors at one point, shape (samples, 3) in µm
    (float64; relative to the datum when one is set)."""
    tool = tool or tool_cases(machine)[0]
    grids = {a: np.array([float(point[a])]) for a in AXIS_NAMES}
    model = montecarlo_model(machine, spec, tool, grids)
    m = model.tile_field(0)
    out = np.empty((spec.samples, 3))
    done = 0
    for block in _draw_blocks(spec, model.shapes):
        out[done : done + block.shape[0]] = block @ m
        done += block.shape[0]
    return out
