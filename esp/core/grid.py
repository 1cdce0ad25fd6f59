"""Evaluate a separable error field over a 3-D grid without materialising it.

Every term of an ESP model is a product of at most two functions of one coordinate each
(a component of one axis times a lever along another). A direction's total error over the
grid is therefore a sum of outer products, which folds into three 2-D arrays::

    E_d[i, j, k] = P_xy[i, j] + P_xz[i, k] + P_yz[j, k]

From these, :func:`scan` finds the extremes of the field -- the minimum and maximum of each
direction, the maximum planar error of each plane and the maximum volumetric error
(Longstaff 2002, eq. 3.4-3.5 and 3.05.4-3.05.5) -- and the grid index of each;
:func:`volumetric_peak` finds the volumetric maximum alone (what a swept tool orientation
reports), and :func:`scan_all` evaluates every point (the reference).

The search is exact without visiting every point. The grid is cut into tiles (boxes of
about 32 x 32 x 32 points). Over a tile each 2-D array lies between its minimum and its
maximum on the tile's face, so ``E_d`` lies between the sum of the three minima and the sum
of the three maxima; those two numbers bound ``|E_d|``, hence each planar error and the
volumetric error, over the whole tile. For one quantity at a time, tiles are evaluated
point by point in decreasing order of their bound, and the search stops at the first tile
whose bound cannot beat (or tie) the running extreme: a smooth field is decided by a few
tiles out of thousands. Every evaluated tile updates every quantity.

Why the result is bit for bit that of evaluating every point (:func:`scan_all`):

* the bounds are computed with the same floating-point operations, in the same order, as
  the values (``(P_xy + P_xz) + P_yz``, then squares, then ``(x² + y²) + z²``). IEEE
  rounding is monotonic, so a bound computed from per-tile minima and maxima bounds every
  *computed* value in the tile, not only the exact real value;
* a tile is skipped only when its bound is below the running extreme, or equal to it while
  the tile's first point comes after the extreme's point in C order (i, then j, then k):
  such a tile can hold neither a larger value nor an earlier equal one;
* among equal values the point first in C order wins, as it does in the full walk.

A field that is nearly flat over the whole volume (noise, no trend) leaves most tiles'
bounds above the extreme. When the tiles still to evaluate exceed a quarter of all tiles,
the search walks the whole grid in blocks instead, so such a field costs about what the
full walk costs; a constant field is decided by its first tile (every other tile only
ties, later in C order).

With ``squared=True`` the arrays hold sums of squared contributions (the root-sum-square
combination of thesis 3.14.7); the per-direction, planar and volumetric figures are the
square roots of ``E_d``, ``E_p + E_q`` and ``(E_x + E_y) + E_z``, and only maxima are
reported.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from esp.core.errors import DataError

__all__ = ["PAIRS", "FieldStats", "Product", "fold", "scan", "scan_all", "volumetric_peak"]

#: the three planes as pairs of axis indices, in the order XY, XZ, YZ
PAIRS = ((0, 1), (0, 2), (1, 2))
#: the quantities of :class:`FieldStats`
QUANTITIES = ("minimum", "maximum", "planar", "volumetric")
_BLOCK_ELEMENTS = 1 << 15
#: points in a tile of the bounded search (about 32 x 32 x 32)
_TILE_ELEMENTS = 1 << 15
#: the search walks the whole grid once it would evaluate more than this share of tiles
_WALK_FRACTION = 0.25

NOT_FINITE = "the error field holds a value that is not finite (check the inputs)"

Index = tuple[int, int, int]
Found = tuple[float, Index]


@dataclass(frozen=True)
class Product:
    """One separable contribution to direction ``direction``: ``scale · f(x_a) · g(x_c)``.

    ``f`` is a 1-D array on the grid of axis ``a`` (or None for 1), ``g`` a 1-D array on
    the grid of axis ``c`` (or None for 1). ``a`` may equal ``c``.
    """

    direction: int
    scale: float
    a: int | None = None
    f: np.ndarray | None = None
    c: int | None = None
    g: np.ndarray | None = None


@dataclass(frozen=True)
class FieldStats:
    """Extremes of a field over the grid; indices are (i, j, k) into the axis grids.

    ``minimum``/``maximum``: per direction, (value, index). ``planar``: per plane in
    :data:`PAIRS` order, (value, index). ``volumetric``: (value, index). Among equal
    values the index is the first in C order (i, then j, then k). ``points``: the points of
    the grid; ``evaluated``: how many of them the search evaluated one by one (a
    diagnostic, left out of comparisons).
    """

    minimum: tuple[Found, ...]
    maximum: tuple[Found, ...]
    planar: tuple[Found, ...]
    volumetric: Found
    points: int
    evaluated: int = field(default=0, compare=False)


def fold(products: Iterable[Product], sizes: tuple[int, ...]) -> list[list[np.ndarray]]:
    """Sum products into, per direction, the three pair arrays ``[P_xy, P_xz, P_yz]``."""
    out = [[np.zeros((sizes[a], sizes[b])) for a, b in PAIRS] for _ in range(3)]
    for p in products:
        given = [(p.a, p.f), (p.c, p.g)]
        parts = [(ax, arr) for ax, arr in given if ax is not None and arr is not None]
        if len(parts) == 2 and parts[0][0] == parts[1][0]:
            parts = [(parts[0][0], parts[0][1] * parts[1][1])]
        arrays = out[p.direction]
        if not parts:
            arrays[0] += p.scale
        elif len(parts) == 1:
            ax, arr = parts[0]
            if ax == 2:
                arrays[1] += p.scale * arr[None, :]
            elif ax == 1:
                arrays[0] += p.scale * arr[None, :]
            else:
                arrays[0] += p.scale * arr[:, None]
        else:
            (a, fa), (c, gc) = sorted(parts, key=lambda t: t[0])
            arrays[PAIRS.index((a, c))] += p.scale * np.multiply.outer(fa, gc)
    return out


def _sizes(pairs: list[list[np.ndarray]]) -> tuple[int, int, int]:
    nx, ny = pairs[0][0].shape
    nz = pairs[0][1].shape[1]
    if min(nx, ny, nz) < 1:
        raise DataError(f"the grid has no points ({nx} x {ny} x {nz} positions)")
    return int(nx), int(ny), int(nz)


def _wanted(only: Iterable[str] | str | None) -> frozenset[str]:
    if only is None:
        return frozenset(QUANTITIES)
    names = frozenset((only,) if isinstance(only, str) else only)
    if not names or not names <= set(QUANTITIES):
        raise ValueError(f"only: expected some of {QUANTITIES}, got {only!r}")
    return names


def _check(
    lows: Sequence[Sequence[float]], highs: Sequence[Sequence[float]], squared: bool
) -> None:
    """Refuse a field that is not finite, or so large that its squares would overflow.

    ``lows``/``highs``: per direction, the minimum and maximum of each of its three arrays.
    ``|E_d|`` is at most the sum of the arrays' largest magnitudes (computed in the same
    order, rounding is monotonic), so when that bound, squared and summed over the three
    directions, is finite no step of the evaluation can overflow or give NaN.
    """
    lo = np.array(lows, dtype=float)
    hi = np.array(highs, dtype=float)
    if not (np.isfinite(lo).all() and np.isfinite(hi).all()):
        raise DataError(NOT_FINITE)
    size = np.maximum(-lo, hi)
    with np.errstate(over="ignore"):
        a = (size[:, 0] + size[:, 1]) + size[:, 2]
        total = (a[0] + a[1]) + a[2] if squared else (a[0] * a[0] + a[1] * a[1]) + a[2] * a[2]
    if not np.isfinite(total):
        raise DataError(
            "the error field is too large to evaluate in floating point "
            f"(values up to about {float(a.max()):.3g}; check the inputs)"
        )


def _result(wanted: frozenset[str], squared: bool, track: _Tracker) -> dict[str, Any]:
    """The wanted quantities from the running extremes ``best[(quantity, element)] =
    (key, index)``; the key of a minimum is the negated value, the keys of squared
    quantities are squares."""
    best = track.best

    def root(key: tuple[str, int]) -> Found:
        value, index = best[key]
        return float(np.sqrt(max(value, 0.0))), index

    def plain(key: tuple[str, int], sign: float) -> Found:
        value, index = best[key]
        return sign * value, index

    out: dict[str, Any] = {}
    if "minimum" in wanted:
        if squared:
            out["minimum"] = tuple((0.0, (0, 0, 0)) for _ in range(3))
        else:
            out["minimum"] = tuple(plain(("minimum", d), -1.0) for d in range(3))
    if "maximum" in wanted:
        out["maximum"] = tuple(
            root(("maximum", d)) if squared else plain(("maximum", d), 1.0) for d in range(3)
        )
    if "planar" in wanted:
        out["planar"] = tuple(root(("planar", k)) for k in range(3))
    if "volumetric" in wanted:
        out["volumetric"] = root(("volumetric", 0))
    return out


def _quantities(wanted: frozenset[str], squared: bool) -> list[tuple[str, int]]:
    """The running extremes to track, in search order (the most selective first)."""
    out: list[tuple[str, int]] = []
    if "volumetric" in wanted:
        out.append(("volumetric", 0))
    if "planar" in wanted:
        out += [("planar", k) for k in range(3)]
    if "maximum" in wanted:
        out += [("maximum", d) for d in range(3)]
    if "minimum" in wanted and not squared:
        out += [("minimum", d) for d in range(3)]
    return out


class _Tracker:
    """The running extremes of a set of quantities over evaluated boxes of the grid.

    Every quantity is kept as a key to maximise (a minimum as its negated value, exact in
    floating point) with the index of the first point, in C order, that reaches it.
    """

    def __init__(
        self, pairs: list[list[np.ndarray]], quantities: list[tuple[str, int]], squared: bool
    ) -> None:
        self.pairs = pairs
        self.squared = squared
        self.best: dict[tuple[str, int], tuple[float, Index]] = {
            q: (-np.inf, (0, 0, 0)) for q in quantities
        }
        kinds = {q[0] for q in quantities}
        self.extremes = [q for q in quantities if q[0] in ("minimum", "maximum")]
        self.planar = "planar" in kinds
        self.volumetric = "volumetric" in kinds
        # one workspace for the three directions and a sum, reused by every box (fresh
        # arrays of this size cost more in page faults than the arithmetic)
        self.work = np.empty((4, 0))
        self.evaluated = 0

    def offer(
        self, q: tuple[str, int], values: np.ndarray, origin: Index, smallest: bool = False
    ) -> None:
        flat = int(values.argmin() if smallest else values.argmax())
        value = float(values.flat[flat])
        key = -value if smallest else value
        best, at = self.best[q]
        if key < best:
            return
        i, j, k = np.unravel_index(flat, values.shape)
        index = (int(i) + origin[0], int(j) + origin[1], int(k) + origin[2])
        if key > best or index < at:
            self.best[q] = (key, index)

    def evaluate(self, x0: int, x1: int, y0: int, y1: int, z0: int, z1: int) -> None:
        """Evaluate the box [x0, x1) x [y0, y1) x [z0, z1) point by point."""
        origin = (x0, y0, z0)
        shape = (x1 - x0, y1 - y0, z1 - z0)
        n = shape[0] * shape[1] * shape[2]
        if n > self.work.shape[1]:
            self.work = np.empty((4, n))
        self.evaluated += n
        e0, e1, e2, s01 = (w[:n].reshape(shape) for w in self.work)
        e = [e0, e1, e2]
        for (pxy, pxz, pyz), block in zip(self.pairs, e, strict=True):
            np.add(pxy[x0:x1, y0:y1, None], pxz[x0:x1, None, z0:z1], out=block)
            block += pyz[None, y0:y1, z0:z1]
        for q in self.extremes:
            self.offer(q, e[q[1]], origin, smallest=q[0] == "minimum")
        if not (self.planar or self.volumetric):
            return
        sq = e if self.squared else [np.square(b, out=b) for b in e]
        np.add(sq[0], sq[1], out=s01)
        if self.planar:
            self.offer(("planar", 0), s01, origin)
            self.offer(("planar", 1), np.add(sq[0], sq[2], out=sq[0]), origin)
            self.offer(("planar", 2), np.add(sq[1], sq[2], out=sq[1]), origin)
        if self.volumetric:
            # x² + y² + z² = (x² + y²) + z²
            s01 += sq[2]
            self.offer(("volumetric", 0), s01, origin)


def _walk(track: _Tracker, sizes: tuple[int, int, int]) -> None:
    """Evaluate every point, in blocks of whole rows visited in C order."""
    nx, ny, nz = sizes
    rows_y = max(1, min(ny, _BLOCK_ELEMENTS // nz))
    rows_x = max(1, min(nx, _BLOCK_ELEMENTS // (nz * rows_y))) if rows_y == ny else 1
    for x0 in range(0, nx, rows_x):
        for y0 in range(0, ny, rows_y):
            track.evaluate(x0, min(nx, x0 + rows_x), y0, min(ny, y0 + rows_y), 0, nz)


def _every_point(pairs: list[list[np.ndarray]], squared: bool, wanted: frozenset[str]) -> _Tracker:
    """The extremes by evaluating every point: the reference of the bounded search."""
    sizes = _sizes(pairs)
    _check([[p.min() for p in d] for d in pairs], [[p.max() for p in d] for d in pairs], squared)
    track = _Tracker(pairs, _quantities(wanted, squared), squared)
    _walk(track, sizes)
    return track


def _tile_shape(sizes: tuple[int, int, int]) -> tuple[int, int, int]:
    """Tile sides of about :data:`_TILE_ELEMENTS` points, as cubic as the grid allows."""
    shape = [1, 1, 1]
    budget = float(_TILE_ELEMENTS)
    for left, a in zip((3, 2, 1), sorted(range(3), key=lambda a: sizes[a]), strict=True):
        side = max(1, min(sizes[a], round(budget ** (1.0 / left))))
        shape[a] = side
        budget = max(1.0, budget / side)
    return shape[0], shape[1], shape[2]


def _sum3(xy: np.ndarray, xz: np.ndarray, yz: np.ndarray) -> np.ndarray:
    """``(xy[i, j] + xz[i, k]) + yz[j, k]`` over (i, j, k): the order of the evaluation."""
    out = np.add(xy[:, :, None], xz[:, None, :])
    out += yz[None, :, :]
    return out


def _scores(
    pairs: list[list[np.ndarray]], starts: list[np.ndarray], wanted: frozenset[str], squared: bool
) -> dict[tuple[str, int], np.ndarray]:
    """Per quantity, an upper bound of its key over every tile (flat, tiles in C order)."""
    cuts = ((starts[0], starts[1]), (starts[0], starts[2]), (starts[1], starts[2]))
    lows, highs = [], []
    for arrays in pairs:
        lows.append(
            [
                np.minimum.reduceat(np.minimum.reduceat(p, r, axis=0), c, axis=1)
                for p, (r, c) in zip(arrays, cuts, strict=True)
            ]
        )
        highs.append(
            [
                np.maximum.reduceat(np.maximum.reduceat(p, r, axis=0), c, axis=1)
                for p, (r, c) in zip(arrays, cuts, strict=True)
            ]
        )
    _check([[t.min() for t in d] for d in lows], [[t.max() for t in d] for d in highs], squared)
    hi = [_sum3(*t) for t in highs]
    needs_lo = not squared and bool(wanted - {"maximum"})
    lo = [_sum3(*t) for t in lows] if needs_lo else []
    out: dict[tuple[str, int], np.ndarray] = {}
    for d in range(3):
        if "maximum" in wanted:
            out["maximum", d] = hi[d].ravel()
        if "minimum" in wanted and not squared:
            out["minimum", d] = np.negative(lo[d]).ravel()
    if squared:
        sq = hi
    elif not needs_lo:
        return out
    else:
        # |E| <= max(|lo|, |hi|) over the tile, and x -> x² rounds monotonically in |x|
        sq = [np.maximum(np.square(a), np.square(b)) for a, b in zip(lo, hi, strict=True)]
    if "planar" in wanted:
        for k, (p, q) in enumerate(PAIRS):
            out["planar", k] = (sq[p] + sq[q]).ravel()
    if "volumetric" in wanted:
        out["volumetric", 0] = ((sq[0] + sq[1]) + sq[2]).ravel()
    return out


def _bounded(pairs: list[list[np.ndarray]], squared: bool, wanted: frozenset[str]) -> _Tracker:
    """The extremes by the tile bounds (module docstring)."""
    sizes = _sizes(pairs)
    shape = _tile_shape(sizes)
    starts = [np.arange(0, n, t) for n, t in zip(sizes, shape, strict=True)]
    tiles = tuple(s.size for s in starts)
    scores = _scores(pairs, starts, wanted, squared)
    quantities = _quantities(wanted, squared)
    track = _Tracker(pairs, quantities, squared)
    done = np.zeros(int(np.prod(tiles)), dtype=bool)
    # beyond this many evaluated tiles the bounds do not prune: walk the grid instead
    limit = int(_WALK_FRACTION * done.size)

    # the first point of every tile, in C order of the tiles
    cx, cy, cz = (c.ravel() * side for c, side in zip(np.indices(tiles), shape, strict=True))

    def corner(t: int) -> Index:
        bx, by, bz = np.unravel_index(t, tiles)
        return int(bx) * shape[0], int(by) * shape[1], int(bz) * shape[2]

    def pending(score: np.ndarray, q: tuple[str, int]) -> list[int]:
        """The tiles not yet evaluated whose bound reaches the running extreme, best bound
        first, equal bounds in C order of the tiles (which is the order of their corners)."""
        key, at = track.best[q]
        earlier = (cx < at[0]) | (cx == at[0]) & ((cy < at[1]) | (cy == at[1]) & (cz < at[2]))
        found = np.flatnonzero(((score > key) | (score == key) & earlier) & ~done)
        return found[np.argsort(-score[found], kind="stable")].tolist()

    def evaluate(t: int) -> None:
        x0, y0, z0 = corner(t)
        track.evaluate(
            x0, min(sizes[0], x0 + shape[0]),
            y0, min(sizes[1], y0 + shape[1]),
            z0, min(sizes[2], z0 + shape[2]),
        )  # fmt: skip
        done[t] = True

    for q in quantities:
        score = scores[q]
        order = pending(score, q)
        position, evaluated, check = 0, 0, 1
        while position < len(order):
            t = order[position]
            position += 1
            key, at = track.best[q]
            bound = float(score[t])
            if bound < key or (bound == key and corner(t) > at):
                break  # no later tile can hold a larger value or an earlier equal one
            if done[t]:
                continue
            evaluate(t)
            evaluated += 1
            if evaluated == check:
                # after 1, 2, 4, ... tiles, count what is left with the extreme found so far
                check *= 2
                order, position = pending(score, q), 0
                if int(done.sum()) + len(order) > limit:
                    _walk(track, sizes)
                    return track
    return track


def _search(
    pairs: list[list[np.ndarray]],
    squared: bool,
    only: Iterable[str] | str | None = None,
    method: str = "bounds",
) -> tuple[dict[str, Any], _Tracker]:
    """The quantities named in ``only`` (default: all of :data:`QUANTITIES`) by one
    method, and the search's tracker."""
    wanted = _wanted(only)
    if method == "bounds":
        track = _bounded(pairs, squared, wanted)
    elif method == "full":
        track = _every_point(pairs, squared, wanted)
    else:
        raise ValueError(f"method: expected 'bounds' or 'full', got {method!r}")
    return _result(wanted, squared, track), track


def scan(
    pairs: list[list[np.ndarray]], squared: bool = False, *, method: str = "bounds"
) -> FieldStats:
    """The extremes of the field given by :func:`fold`'s pair arrays.

    Parameters
    ----------
    pairs : per direction, the arrays ``[P_xy, P_xz, P_yz]`` of :func:`fold`
    squared : the arrays hold sums of squares (root-sum-square combination); only maxima
        are then reported, as square roots, and the minima are zero
    method : ``"bounds"`` (tile bounds, see the module) or ``"full"`` (every point, as
        :func:`scan_all`); both give the same result to the last bit

    Returns
    -------
    FieldStats
        values in the unit of the arrays (µm in the engine), indices into the axis grids;
        among equal values the first index in C order (i, then j, then k).

    Raises
    ------
    DataError
        when the arrays hold a value that is not finite, or one so large that its square
        overflows, or the grid has no points.

    Notes
    -----
    Each tile's bound comes from the minima and maxima of the three arrays over its faces;
    tiles are evaluated in decreasing order of their bound for one quantity at a time
    (volumetric, planar, maxima, minima), and every evaluated tile updates all the
    quantities. The search for a quantity stops at the first tile whose bound is below the
    running extreme (or equal to it with its first point later in C order). The module
    docstring says why this is exact, and when the search walks the whole grid instead.
    """
    found, track = _search(pairs, squared, None, method)
    sizes = _sizes(pairs)
    return FieldStats(**found, points=sizes[0] * sizes[1] * sizes[2], evaluated=track.evaluated)


def scan_all(pairs: list[list[np.ndarray]], squared: bool = False) -> FieldStats:
    """The extremes of the field of :func:`fold`'s pair arrays by evaluating every point.

    The reference for :func:`scan`, which returns the same result without visiting every
    point. The grid is walked in blocks of whole rows, each block formed with a few
    floating-point operations per point. Parameters, result and errors as :func:`scan`.
    """
    return scan(pairs, squared, method="full")


def volumetric_peak(
    pairs: list[list[np.ndarray]], squared: bool = False, *, method: str = "bounds"
) -> Found:
    """The maximum volumetric error of the field and its index, (value, (i, j, k)): what a
    swept tool orientation reports, found without the other extremes.

    Exactly ``scan(pairs, squared).volumetric``, for less work: only the volumetric bounds
    decide which tiles are evaluated, and only the volumetric error is formed in them.
    Parameters and errors as :func:`scan`.
    """
    found, _ = _search(pairs, squared, ("volumetric",), method)
    return found["volumetric"]
