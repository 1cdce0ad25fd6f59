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
column of ones). Every ``T_c`` is separable (:mod:`esp.core.grid`), so it is never formed over
the whole grid.

**Tiles.** The grid is cut into tiles of about sqrt(2·P) points (P the grid's points).
For each tile, direction d and column c, the minimum and maximum of ``T_c,d`` over the tile
follow from the minima and maxima of its three pair arrays over the tile's faces. For a
draw ζ, ``E_d`` over the tile then lies within ``|Σ_c ζ_c·mid_c| + Σ_c |ζ_c|·rad_c`` of
zero (mid and rad the centre and half-range of each column's extremes) -- two matrix
products for a block of draws -- which bounds the volumetric error over the tile.

**The search.** Each draw evaluates its tile of largest bound; then one sweep visits every
tile once, in a fixed order (decreasing bound for |z| = 1), and evaluates it for the draws
whose bound of the tile exceeds their running maximum. A tile whose bound does not exceed
that value cannot hold the draw's maximum and is not evaluated for that draw. So each
tile's field is formed once per pass of draws (:data:`_PASS_ELEMENTS` bounds at a time),
and evaluated against every block of the pass that needs it. The bounds are computed with
the largest rounding error of the evaluation taken off, so each draw's value is the
maximum over every point of the grid up to that rounding (tested draw by draw against the
evaluation of every point, ``method="full"``, and against the whole field of each draw),
and a field that is flat over many tiles is decided by its first one.

**The same seed, the same values.** Draws come in blocks of :data:`_BLOCK`, block b from
the b-th seed spawned from the seed (``numpy.random.SeedSequence(seed).spawn``), the last
block drawn and searched whole. Which tiles a draw evaluates depends on its own values
only, and each tile is evaluated with one matrix product per block: the operations of a
block do not depend on the number of samples or on how blocks are grouped into passes. The
value of a draw is then recomputed at the point the search found, in float64 with
elementwise operations in a fixed order (:meth:`MonteCarloModel.values_at`): the matrix
products only locate the maximum. A BLAS that rounds a row of a product differently with
the number of rows or threads can move that point only between points whose values are
within the rounding of the evaluation (relative 2·10⁻⁶ in float32), and the value by at
most that: for a given seed the values are the same, bit for bit, whatever the number of
samples and the passes, and to that tolerance whatever the BLAS and its threads.

**Precision.** The search runs in float32 by default: the fields are a few tens of µm,
float32 keeps 7 significant digits, and the summary (printed to 0.001 µm) is unchanged
(shown in the tests and ``benchmarks/uncertainty.py``); ``dtype="float64"`` is available.
The values are the float64 sums of the pair arrays of the evaluation's type.

**Limits.** :data:`MONTECARLO_MAX_WORK` point-draws (samples × grid points) and
:data:`MONTECARLO_MAX_BYTES` of memory, checked before any work by
:func:`esp.core.uncertainty.propagate.check_uncertainty`.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterator, Mapping, Sequence
from dataclasses import dataclass, replace

import numpy as np

from esp.core.evaluation import MachineEvaluation, evaluate
from esp.core.grid import fold
from esp.core.machine import AXIS_NAMES, Machine
from esp.core.models.tool import ToolCase, tool_cases
from esp.core.results import MonteCarloSummary
from esp.core.synthesis import Synthesis
from esp.core.uncertainty.spec import UncertaintySpec, uncertainty_machine

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
#: draws per block: block b is drawn from the b-th seed spawned from the seed and searched
#: on its own, always in full (the last block too), so that a draw's value depends neither
#: on the number of samples nor on how the blocks are grouped into passes
_BLOCK = 1024
#: elements of the (tiles × draws) bounds of one pass over the tiles
_PASS_ELEMENTS = 1 << 23
#: elements of one (3 · tiles × draws) matrix product of the bounds
_BOUND_ELEMENTS = 1 << 18
#: elements of one (draws × 3 · tile points) evaluation
_EVAL_ELEMENTS = 1 << 20
#: bytes of tile fields kept through a pass (the tiles evaluated first)
_CACHE_BYTES = 32 << 20

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


@dataclass
class MonteCarloModel:
    """The field of one tool case as a linear function of the draws, tiled.

    Column 0 is the best estimate, then one column per component with an uncertainty
    (its u curve alone). ``pairs`` holds the pair arrays of every direction and column,
    points first: ``P_xy`` of shape (nx, ny, 3, columns), ``P_xz`` (nx, nz, 3, columns),
    ``P_yz`` (ny, nz, 3, columns), in the evaluation's floating-point type (so that a
    tile's field is formed with the columns innermost, in long contiguous runs); ``lo``/
    ``hi`` the minimum and maximum of each column's field over each tile, shape (columns,
    3, tiles), tiles in C order; ``shapes`` each component's distribution; ``sizes`` the
    grid, ``tile`` the tile sides.
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

    def tile_box(self, t: int) -> tuple[slice, slice, slice]:
        """The grid indices of tile ``t`` along X, Y and Z."""
        bx, by, bz = np.unravel_index(t, self.tiles)
        x, y, z = (
            slice(int(b) * s, min(n, (int(b) + 1) * s))
            for b, s, n in zip((bx, by, bz), self.tile, self.sizes, strict=True)
        )
        return x, y, z

    def tile_field(self, t: int) -> np.ndarray:
        """Every column's field over tile ``t``, shape (columns, 3 · points of the tile):
        the three directions one after the other, points in C order, summed in the
        engine's order ``(P_xy + P_xz) + P_yz`` (formed points first, with the columns
        innermost, then laid out for the matrix product)."""
        x, y, z = self.tile_box(t)
        pxy, pxz, pyz = self.pairs
        e = np.add(pxy[x, y, None], pxz[x, None, z])
        e += pyz[None, y, z]
        columns = e.shape[-1]
        out = np.empty((columns, 3, e.size // (3 * columns)), dtype=e.dtype)
        out[...] = e.reshape(-1, 3, columns).transpose(2, 1, 0)
        return out.reshape(columns, -1)

    def values_at(self, zeta: np.ndarray, index: tuple[np.ndarray, ...]) -> np.ndarray:
        """The volumetric error of each draw of ``zeta`` (augmented, one row per draw) at
        its grid point ``index`` (arrays i, j, k), µm: the pair arrays summed in float64
        as ``(P_xy + P_xz) + P_yz``, then ``Σ_c ζ_c · T_c`` column after column, then
        ``(x² + y²) + z²`` -- elementwise operations in a fixed order, the same whatever
        the number of draws, the machine's vector units or its BLAS."""
        i, j, k = index
        pxy, pxz, pyz = self.pairs
        t = pxy[i, j].astype(float) + pxz[i, k]
        t += pyz[j, k]
        z = np.asarray(zeta, dtype=float)
        e = z[:, 0, None] * t[:, :, 0]
        for c in range(1, t.shape[2]):
            e += z[:, c, None] * t[:, :, c]
        np.square(e, out=e)
        s = e[:, 0] + e[:, 1]
        s += e[:, 2]
        return np.sqrt(s)


def _tile_extremes(
    pairs: Sequence[np.ndarray], starts: Sequence[np.ndarray]
) -> tuple[np.ndarray, np.ndarray]:
    """The minimum and maximum of every column's field over every tile, shape (columns,
    3, tiles) with the tiles in C order, from the extremes of the pair arrays over the
    tiles' faces, summed in the order of :meth:`MonteCarloModel.tile_field` (rounding is
    monotonic, so they bound every computed value of the tile)."""
    cuts = ((starts[0], starts[1]), (starts[0], starts[2]), (starts[1], starts[2]))
    out = []
    for reduce in (np.minimum, np.maximum):
        faces = [
            reduce.reduceat(reduce.reduceat(p, r, axis=0), c, axis=1)
            for p, (r, c) in zip(pairs, cuts, strict=True)
        ]
        e = np.add(faces[0][:, :, None], faces[1][:, None, :])
        e += faces[2][None, :, :]
        columns = e.shape[-1]
        out.append(e.reshape(-1, 3, columns).transpose(2, 1, 0).astype(float))
    return out[0], out[1]


def montecarlo_model(
    machine: Machine,
    spec: UncertaintySpec,
    tool: ToolCase | None = None,
    grids: Mapping[str, np.ndarray] | None = None,
    dtype: str = "float64",
    prepared: MachineEvaluation | None = None,
) -> MonteCarloModel:
    """The linear model of the Monte Carlo method for one tool case, on the analysis grid
    (or on ``grids``, axis letter -> positions in mm), its pair arrays in ``dtype``.
    ``prepared`` is the analysis' own preparation of the machine (made here when not
    given)."""
    # the analysis' own evaluation of the case: its datum and its datum rule (on a machine
    # with a head or rotary table every setting is referred to the first setting's datum)
    prepared = prepared if prepared is not None else evaluate(machine)
    case = prepared.case(tool)
    tool, datum, reference = case.tool, case.datum, case.reference
    base = replace(prepared.synthesis, grids=dict(prepared.synthesis.grids))
    if grids is not None:
        base.grids.update({a: np.asarray(v, dtype=float) for a, v in grids.items()})
    g = base.grids
    sizes = (int(g["X"].size), int(g["Y"].size), int(g["Z"].size))
    names = tuple(spec.components)
    columns = len(names) + 1
    shapes2 = ((sizes[0], sizes[1]), (sizes[0], sizes[2]), (sizes[1], sizes[2]))
    pxy, pxz, pyz = (np.empty((*shape, 3, columns), dtype=dtype) for shape in shapes2)
    pairs = (pxy, pxz, pyz)
    for c in range(columns):
        if c == 0:
            products = base.products(tool, datum, reference=reference)
        else:
            syn = Synthesis.prepare(
                uncertainty_machine(machine, spec, {names[c - 1]}, standard=True),
                measured=False,
            )
            syn.grids.update(g)
            products = syn.products(tool, datum, reference=reference)
        for d, arrays in enumerate(fold(products, sizes)):
            for k, a in enumerate(arrays):
                pairs[k][:, :, d, c] = a
    tile = _tile_side_counts(sizes)
    starts = [np.arange(0, n, t) for n, t in zip(sizes, tile, strict=True)]
    lo, hi = _tile_extremes(pairs, starts)
    shapes = tuple(spec.components[n].distribution for n in names)
    return MonteCarloModel(names, shapes, pairs, sizes, tile, lo, hi)


def _pass_blocks(tiles: int) -> int:
    """Blocks of draws searched together in one pass over the tiles."""
    return max(1, _PASS_ELEMENTS // (tiles * _BLOCK))


def montecarlo_memory_bytes(machine: Machine, spec: UncertaintySpec, dtype: str = "float32") -> int:
    """An estimate of the memory the Monte Carlo evaluation of ``machine`` needs, bytes:
    the stacked pair arrays of every column, the tile extremes and the bound matrices, the
    draws kept, the bounds of one pass, its products and the tile fields kept through it."""
    nx, ny, nz = (machine.axes[a].grid_mm().size for a in AXIS_NAMES)
    sizes = (nx, ny, nz)
    columns = len(spec.components) + 1
    tile = _tile_side_counts(sizes)
    tiles = math.prod(-(-n // t) for n, t in zip(sizes, tile, strict=True))
    faces = sizes[0] * sizes[1] + sizes[0] * sizes[2] + sizes[1] * sizes[2]
    item = np.dtype(dtype).itemsize
    pairs = item * columns * 3 * faces + 8 * 3 * faces  # and one column of fold in float64
    extremes = (8 * 5 + 2 * item) * 3 * columns * tiles
    draws = 8 * spec.samples
    passed = _pass_blocks(tiles) * _BLOCK
    search = item * tiles * passed + (8 * columns + 32) * passed
    products = 3 * item * _BOUND_ELEMENTS + 4 * item * _EVAL_ELEMENTS
    return int(pairs + extremes + draws + search + products + _CACHE_BYTES)


# -- draws ------------------------------------------------------------------------------


def _draw(rng: np.random.Generator, shapes: Sequence[str], count: int) -> np.ndarray:
    """Standardised draws (mean 0, standard deviation 1), shape (count, n)."""
    z = np.empty((count, len(shapes)))
    for j, shape in enumerate(shapes):
        if shape == "rectangular":
            z[:, j] = rng.uniform(-math.sqrt(3.0), math.sqrt(3.0), size=count)
        else:
            z[:, j] = rng.standard_normal(count)
    return z


def _draw_blocks(spec: UncertaintySpec, shapes: Sequence[str]) -> Iterator[np.ndarray]:
    """The augmented draws ζ = (1, z) in blocks of :data:`_BLOCK`, block b from the b-th
    child of ``SeedSequence(seed).spawn`` (the children do not depend on how many are
    spawned): enough blocks to hold ``spec.samples`` draws, the last one whole. The first
    n draws of a seed are the same whatever the number of samples."""
    blocks = -(-spec.samples // _BLOCK)
    for child in np.random.SeedSequence(spec.seed).spawn(blocks):
        block = np.empty((_BLOCK, len(shapes) + 1))
        block[:, 0] = 1.0
        block[:, 1:] = _draw(np.random.default_rng(child), shapes, _BLOCK)
        yield block


# -- the search ---------------------------------------------------------------------------


class _Search:
    """The tile bounds and tile evaluations of one model in one floating-point type."""

    def __init__(self, model: MonteCarloModel, dtype: str) -> None:
        self.model = model
        self.dtype = np.dtype(dtype)
        columns, _, tiles = model.lo.shape
        self.count = tiles
        lo, hi = model.lo, model.hi
        reach = np.maximum(np.abs(lo), np.abs(hi))
        # the evaluation rounds by at most about columns · eps · Σ_c |ζ_c| max|T_c|, the
        # bounds computed in the same type by about twice that: the allowance covers both
        allowance = 4.0 * (columns + 4) * float(np.finfo(self.dtype).eps)

        def matrix(a: np.ndarray) -> np.ndarray:
            # (columns, 3, tiles) -> (columns, 3 · tiles), column d · tiles + t
            return np.ascontiguousarray(a.reshape(columns, -1), self.dtype)

        self.mid = matrix((hi + lo) / 2.0)
        self.rad = matrix((hi - lo) / 2.0 - allowance * reach)
        # the fixed order of the sweep: the tiles by their bound for |z| = 1 everywhere
        score = np.square(reach.sum(axis=0)).sum(axis=0)
        self.order = np.argsort(-score, kind="stable")
        self.evaluated = 0

    def bounds(self, zeta: np.ndarray, out: np.ndarray, top: np.ndarray) -> None:
        """For every tile and draw of ``zeta`` (augmented draws in ``self.dtype``), the
        square of the largest volumetric error the tile can hold beyond the rounding of
        the evaluation, into ``out`` of shape (tiles, draws); each draw's tile of largest
        bound (the first of equal ones) into ``top``.

        Per direction, E_d = Σ_c ζ_c T_c with T_c between lo_c and hi_c over the tile, so
        ``|E_d| <= |Σ_c ζ_c mid_c| + Σ_c |ζ_c| rad_c`` (mid and rad the centre and
        half-range of [lo, hi]: midpoint-radius interval arithmetic, Rump 1999, "Fast
        and parallel interval arithmetic", BIT 39); the allowance for rounding is taken
        off rad. Two matrix products per block of draws, then elementwise operations.
        """
        tiles = self.count
        step = max(1, _BOUND_ELEMENTS // self.mid.shape[1])
        for r0 in range(0, zeta.shape[0], step):
            z = zeta[r0 : r0 + step]
            peak = z @ self.mid
            np.abs(peak, out=peak)
            peak += np.abs(z) @ self.rad
            np.maximum(peak, 0.0, out=peak)
            np.square(peak, out=peak)
            s = peak[:, :tiles] + peak[:, tiles : 2 * tiles]
            s += peak[:, 2 * tiles :]
            top[r0 : r0 + step] = s.argmax(axis=1)
            out[:, r0 : r0 + step] = s.T

    def evaluate(
        self,
        t: int,
        m: np.ndarray,
        zeta: np.ndarray,
        rows: np.ndarray,
        state: tuple[np.ndarray, np.ndarray, np.ndarray],
    ) -> None:
        """Evaluate tile ``t`` (its field ``m``) for the draws ``rows`` of ``zeta``, all of
        one block: raise their running maxima and record where they are."""
        best, at_tile, at_point = state
        z = zeta[rows]
        n = m.shape[1] // 3
        step = max(1, _EVAL_ELEMENTS // m.shape[1])
        for r0 in range(0, rows.size, step):
            e = (z[r0 : r0 + step] @ m).reshape(-1, 3, n)
            np.square(e, out=e)
            s = e[:, 0] + e[:, 1]
            s += e[:, 2]
            r = rows[r0 : r0 + step]
            higher = np.flatnonzero(s.max(axis=1) > best[r])
            if higher.size:
                j = s[higher].argmax(axis=1)
                r = r[higher]
                best[r] = s[higher, j]
                at_tile[r] = t
                at_point[r] = j

    def point(self, at_tile: np.ndarray, at_point: np.ndarray) -> tuple[np.ndarray, ...]:
        """Grid indices (i, j, k) of the points ``at_point`` of the tiles ``at_tile``."""
        m = self.model
        b = np.unravel_index(at_tile, m.tiles)
        start = [bi * s for bi, s in zip(b, m.tile, strict=True)]
        side = [np.minimum(n - s0, s) for s0, s, n in zip(start, m.tile, m.sizes, strict=True)]
        k = at_point % side[2]
        j = (at_point // side[2]) % side[1]
        i = at_point // (side[2] * side[1])
        return start[0] + i, start[1] + j, start[2] + k


def _split_blocks(rows: np.ndarray, blocks: int) -> list[np.ndarray]:
    """``rows`` (sorted) cut at the block boundaries: the non-empty parts."""
    if blocks == 1 or rows[0] // _BLOCK == rows[-1] // _BLOCK:
        return [rows]
    edges = np.searchsorted(rows, np.arange(blocks + 1) * _BLOCK).tolist()
    return [rows[a:b] for a, b in zip(edges[:-1], edges[1:], strict=True) if b > a]


def _search_pass(search: _Search, zeta64: np.ndarray, kept: int, dense: bool) -> np.ndarray:
    """The volumetric accuracy of every draw of ``zeta64`` (whole blocks of augmented
    draws, float64), µm; the first ``kept`` draws are counted as evaluated.

    Each draw evaluates its tile of largest bound, then the sweep visits every tile once,
    in a fixed order, and evaluates it for the draws whose bound of the tile exceeds their
    running maximum. A draw's work depends on its own values only, and a tile's
    evaluation is one matrix product per block: the values do not depend on the other
    draws. Each tile is formed once per pass (twice when the first tiles of the draws do
    not fit in :data:`_CACHE_BYTES`). The value of each draw is then recomputed in float64
    at the point the search found (:meth:`MonteCarloModel.values_at`).
    """
    model = search.model
    zeta = zeta64.astype(search.dtype)
    count = zeta.shape[0]
    blocks = count // _BLOCK
    state = (
        np.full(count, -np.inf, dtype=search.dtype),
        np.zeros(count, dtype=np.intp),
        np.zeros(count, dtype=np.intp),
    )
    best = state[0]
    evaluated = 0

    def run(t: int, m: np.ndarray, rows: np.ndarray) -> None:
        nonlocal evaluated
        for r in _split_blocks(rows, blocks):
            search.evaluate(t, m, zeta, r, state)
        evaluated += int(np.searchsorted(rows, kept)) * (m.shape[1] // 3)

    if dense:
        everyone = np.arange(count)
        for t in range(search.count):
            run(t, model.tile_field(t), everyone)
    else:
        bound = np.empty((search.count, count), dtype=search.dtype)
        top = np.empty(count, dtype=np.intp)
        for b0 in range(0, count, _BLOCK):
            b1 = b0 + _BLOCK
            search.bounds(zeta[b0:b1], bound[:, b0:b1], top[b0:b1])
        # first, each draw's tile of largest bound, grouped by tile
        order = np.argsort(top, kind="stable")
        firsts, starts = np.unique(top[order], return_index=True)
        cache: dict[int, np.ndarray] = {}
        cached = 0
        for t, rows in zip(firsts, np.split(order, starts[1:]), strict=True):
            m = model.tile_field(int(t))
            run(int(t), m, rows)
            if cached + m.nbytes <= _CACHE_BYTES:
                cache[int(t)] = m
                cached += m.nbytes
        # then the sweep (a draw's first tile is done: its bound no longer counts)
        bound[top, np.arange(count)] = -np.inf
        for t in search.order.tolist():
            rows = np.flatnonzero(bound[t] > best)
            if rows.size:
                run(t, cache.pop(t) if t in cache else model.tile_field(t), rows)
    search.evaluated += evaluated
    return model.values_at(zeta64, search.point(state[1], state[2]))


def montecarlo_volumetric(
    machine: Machine,
    spec: UncertaintySpec,
    tool: ToolCase | None = None,
    progress: Progress | None = None,
    *,
    dtype: str = "float32",
    method: str = "bounds",
    prepared: MachineEvaluation | None = None,
) -> MonteCarloSummary:
    """The distribution of the volumetric accuracy over ``spec.samples`` draws.

    Parameters
    ----------
    machine, spec : the machine (its errors are the best estimate) and its uncertainty
    tool : the tool case drawn (default: the first of the machine)
    progress : called as ``progress(done, samples)`` after each pass over the tiles
    dtype : ``"float32"`` (default) or ``"float64"``: the type the search evaluates the
        field in (each draw's value is then recomputed in float64 at the point found)
    method : ``"bounds"`` (default: only the tiles each draw needs, see the module) or
        ``"full"`` (every point of the grid for every draw: the reference); the two give
        the same values up to rounding
    prepared : the analysis' preparation of the machine (:func:`esp.core.evaluation.evaluate`),
        so that the draws are of the very evaluation the analysis reported

    Returns
    -------
    MonteCarloSummary
        mean, standard deviation (n − 1) and the probabilistically symmetric 95 % coverage
        interval of the volumetric accuracy (µm), every draw's value, and how many
        point-draws were evaluated (for the ``samples`` draws; the rest of the last block
        is evaluated too and not counted).

    References
    ----------
    JCGM 101:2008, 5.9, 7.
    """
    if method not in ("bounds", "full"):
        raise ValueError(f"method: expected 'bounds' or 'full', got {method!r}")
    if tool is None:
        tool = prepared.tools[0] if prepared is not None else tool_cases(machine)[0]
    model = montecarlo_model(machine, spec, tool, dtype=dtype, prepared=prepared)
    search = _Search(model, dtype)
    per_pass = _pass_blocks(search.count)
    values = np.empty(spec.samples)
    done = 0
    draws = _draw_blocks(spec, model.shapes)
    while done < spec.samples:
        group = [block for _, block in zip(range(per_pass), draws, strict=False)]
        zeta = np.concatenate(group)
        kept = min(zeta.shape[0], spec.samples - done)
        # a square below the smallest float is zero for a maximum: not an error
        with np.errstate(under="ignore"):
            found = _search_pass(search, zeta, kept, dense=method == "full")
        values[done : done + kept] = found[:kept]
        done += kept
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
        evaluated_points=int(search.evaluated),
        dtype=search.dtype.name,
        tool=tool,
    )


def montecarlo_errors(
    machine: Machine,
    spec: UncertaintySpec,
    point: Mapping[str, float],
    tool: ToolCase | None = None,
) -> np.ndarray:
    """Monte Carlo draws of the three errors at one point, shape (samples, 3) in µm
    (float64, summed column after column in a fixed order; relative to the datum when one
    is set)."""
    tool = tool or tool_cases(machine)[0]
    grids = {a: np.array([float(point[a])]) for a in AXIS_NAMES}
    model = montecarlo_model(machine, spec, tool, grids)
    m = model.tile_field(0).T  # (3, columns)
    out = np.empty((spec.samples, 3))
    done = 0
    for block in _draw_blocks(spec, model.shapes):
        n = min(block.shape[0], spec.samples - done)
        e = block[:n, 0, None] * m[None, :, 0]
        for c in range(1, m.shape[1]):
            e += block[:n, c, None] * m[None, :, c]
        out[done : done + n] = e
        done += n
    return out
