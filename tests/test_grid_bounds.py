"""The bounded search of esp.core.grid against a brute-force evaluation of the full 3-D field.

The referee forms every point of the field with numpy, in the order of operations the
engine uses (``(P_xy + P_xz) + P_yz``, squares, ``(x² + y²) + z²``), and takes each extreme
with ``argmin``/``argmax`` over the whole array, which returns the first index in C order
among equal values. The search must return exactly that -- the same values to the last bit
and the same indices -- for any field, including fields full of ties.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import esp.core.grid as grid
from esp.core.errors import DataError
from esp.core.grid import PAIRS, FieldStats, Product, fold, scan, scan_all, volumetric_peak


def brute(pairs, squared: bool = False) -> FieldStats:
    """Every extreme of the field from the full 3-D arrays."""
    e = [np.add(pxy[:, :, None], pxz[:, None, :]) + pyz[None, :, :] for pxy, pxz, pyz in pairs]

    def first(values: np.ndarray, smallest: bool = False):
        flat = int(values.argmin() if smallest else values.argmax())
        index = tuple(int(v) for v in np.unravel_index(flat, values.shape))
        return float(values.flat[flat]), index

    def root(found):
        return float(np.sqrt(max(found[0], 0.0))), found[1]

    sq = e if squared else [x * x for x in e]
    if squared:
        minimum = tuple((0.0, (0, 0, 0)) for _ in range(3))
        maximum = tuple(root(first(x)) for x in e)
    else:
        minimum = tuple(first(x, smallest=True) for x in e)
        maximum = tuple(first(x) for x in e)
    planar = tuple(root(first(sq[p] + sq[q])) for p, q in PAIRS)
    volumetric = root(first((sq[0] + sq[1]) + sq[2]))
    return FieldStats(minimum, maximum, planar, volumetric, e[0].size)


def field(sizes, kind: str, seed: int, squared: bool = False):
    """Random pair arrays of one kind; non-negative when ``squared``."""
    rng = np.random.default_rng(seed)
    nx, ny, nz = sizes
    shapes = [(nx, ny), (nx, nz), (ny, nz)]

    def one(shape):
        if kind == "ties":  # few distinct values: extremes reached at many points
            return rng.integers(-2, 3, size=shape).astype(float)
        if kind == "scales":  # magnitudes from 1e-8 to 1e8: rounding matters
            return rng.normal(size=shape) * 10.0 ** rng.integers(-8, 9, size=shape)
        if kind == "smooth":
            i, j = np.indices(shape)
            return np.sin(i / 5.0 + rng.uniform(0, 6)) * np.cos(j / 7.0) * rng.uniform(1, 9)
        if kind == "constant":
            return np.full(shape, float(rng.integers(-3, 4)))
        return rng.normal(size=shape)

    pairs = [[one(s) for s in shapes] for _ in range(3)]
    return [[np.abs(a) for a in d] for d in pairs] if squared else pairs


@pytest.fixture
def tiles(monkeypatch):
    """Small tiles and blocks, so that small grids have many of each (ragged edges too)."""

    def set_(tile: int = 8, block: int = 24, walk: float = 0.25):
        monkeypatch.setattr(grid, "_TILE_ELEMENTS", tile)
        monkeypatch.setattr(grid, "_BLOCK_ELEMENTS", block)
        monkeypatch.setattr(grid, "_WALK_FRACTION", walk)

    set_()
    return set_


class Spy:
    """Counts the boxes evaluated point by point and the walks of the whole grid."""

    def __init__(self, monkeypatch):
        self.boxes = 0
        self.walks = 0
        evaluate, walk = grid._Tracker.evaluate, grid._walk

        def counted(tracker, *box):
            self.boxes += 1
            return evaluate(tracker, *box)

        def walked(*args):
            self.walks += 1
            return walk(*args)

        monkeypatch.setattr(grid._Tracker, "evaluate", counted)
        monkeypatch.setattr(grid, "_walk", walked)


# -- property: identical to the brute force, whatever the field -------------------------------


@settings(max_examples=200, deadline=None)
@given(
    # up to 14 points per axis: with small tiles, enough tiles for the visiting order to matter
    sizes=st.tuples(*[st.integers(1, 14)] * 3),
    kind=st.sampled_from(["ties", "scales", "smooth", "constant", "normal"]),
    seed=st.integers(0, 2**32 - 1),
    squared=st.booleans(),
    tile=st.integers(1, 40),
    block=st.integers(1, 60),
    walk=st.sampled_from([0.25, 10.0]),  # 10: never walk, every tile decided by its bound
)
@pytest.mark.slow
def test_identical_to_brute_force(sizes, kind, seed, squared, tile, block, walk):
    pairs = field(sizes, kind, seed, squared)
    expected = brute(pairs, squared)
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(grid, "_TILE_ELEMENTS", tile)
        mp.setattr(grid, "_BLOCK_ELEMENTS", block)
        mp.setattr(grid, "_WALK_FRACTION", walk)
        assert scan(pairs, squared) == expected
        assert scan_all(pairs, squared) == expected
        assert volumetric_peak(pairs, squared) == expected.volumetric
        for name in grid.QUANTITIES:  # each quantity searched alone
            for method in ("bounds", "full"):
                assert grid._search(pairs, squared, name, method)[0] == {
                    name: getattr(expected, name)
                }


@pytest.mark.parametrize("squared", [False, True])
def test_folded_model_identical_to_brute_force(squared, tiles):
    """Products of a model (constants, one-axis and two-axis terms) through fold."""
    rng = np.random.default_rng(3)
    sizes = (13, 1, 9)
    products = []
    for d in range(3):
        for a in range(3):
            for c in (None, 0, 1, 2):
                f = rng.normal(size=sizes[a])
                g = None if c is None else rng.normal(size=sizes[c])
                if squared:
                    f, g = f**2, (None if g is None else g**2)
                products.append(Product(d, abs(rng.normal()), a, f, c, g))
        products.append(Product(d, 0.25))
    pairs = fold(products, sizes)
    assert scan(pairs, squared) == brute(pairs, squared) == scan_all(pairs, squared)


# -- every tile visited: a deterministic field with its extremes moved through every tile ------


def _spike(pairs, direction: int, at, size: float):
    """Add ``size`` to the three pair arrays of ``direction`` at the point ``at``: the
    field there gains 3·size, every other point at most 2·size, so a large spike makes
    ``at`` the one extreme of its direction (and of the planar and volumetric errors)."""
    i, j, k = at
    pxy, pxz, pyz = pairs[direction]
    pxy[i, j] += size
    pxz[i, k] += size
    pyz[j, k] += size


@pytest.mark.parametrize(
    ("sizes", "tile", "walk"),
    [((13, 11, 11), 27, 10.0), ((13, 11, 11), 64, 0.25), ((21, 17, 19), 125, 10.0)],
)
def test_extremes_in_every_tile_are_found(sizes, tile, walk, tiles):
    """A random field with a maximum spike in one tile and a minimum spike in another, moved
    through every tile in turn; each time the search must return what the brute force over
    the whole field returns (values and first indices), with the grid walked when the
    bounds do not prune (0.25) and never walked (10)."""
    tiles(tile=tile, walk=walk)
    shape = grid._tile_shape(sizes)
    counts = [-(-n // t) for n, t in zip(sizes, shape, strict=True)]
    corners = [
        (bx * shape[0], by * shape[1], bz * shape[2])
        for bx in range(counts[0])
        for by in range(counts[1])
        for bz in range(counts[2])
    ]
    assert len(corners) > 20  # many tiles, or the test proves little
    rng = np.random.default_rng(13)
    base = field(sizes, "normal", seed=5)
    for n, corner in enumerate(corners):
        # a point inside the tile, not always its corner
        top = tuple(
            min(c + int(rng.integers(0, s)), m - 1)
            for c, s, m in zip(corner, shape, sizes, strict=True)
        )
        # the minimum in another tile, on no line through the maximum (every coordinate
        # differs, so the two spikes do not add up anywhere)
        other = corners[(7 * n + 3) % len(corners)]
        low = tuple(
            (t + 1) % m if c == t else c
            for c, t, m in (
                (min(c + s - 1, m - 1), t, m)
                for c, s, t, m in zip(other, shape, top, sizes, strict=True)
            )
        )
        pairs = [[a.copy() for a in d] for d in base]
        for d in range(3):
            _spike(pairs, d, top, 20.0 + d)
            _spike(pairs, d, low, -(60.0 + d))
        stats = scan(pairs)
        expected = brute(pairs)
        assert stats == expected, (corner, top, low)
        assert volumetric_peak(pairs) == expected.volumetric
        # the spikes are where they were put (the referee itself is not fooled)
        assert [expected.maximum[d][1] for d in range(3)] == [top] * 3
        assert [expected.minimum[d][1] for d in range(3)] == [low] * 3


def _decoys(tiles_n: int, truth: int, ahead: int) -> list[list[np.ndarray]]:
    """X along a line of ``tiles_n`` tiles of two points: tile ``truth`` holds the maximum
    2.0 (its bound, reached); the ``ahead`` tiles after it (cyclically) are decoys, whose
    bounds 2·(3 + r) rank above it but whose values are 0 (the maxima of ``P_xy`` and
    ``P_xz`` sit at different points); the rest reach 2·0.25 at most. Y and Z are zero."""
    n = 2 * tiles_n
    pxy = np.full((n, 1), 0.25)
    pxz = np.full((n, 1), 0.25)
    pxy[2 * truth : 2 * truth + 2] = pxz[2 * truth : 2 * truth + 2] = 1.0
    for r in range(ahead):
        t = (truth + 1 + r) % tiles_n
        b = 3.0 + r
        pxy[2 * t], pxz[2 * t] = b, -b
        pxy[2 * t + 1], pxz[2 * t + 1] = -b, b
    return _only_x(pxy, nz=1, pxz=pxz)


def test_extreme_at_every_rank_of_the_search_order(tiles):
    """The search visits tiles in decreasing order of their bound and re-sorts what is left
    after 1, 2, 4, ... tiles. Here the tile holding the maximum comes after 0 to 11 decoy
    tiles (bounds above it, values below it), at every place on the line in turn: however
    the visiting order and the re-sorting interleave, no tile may be passed over. The
    minimum is the mirror image. (A walk that steps by two through the sorted tiles ends
    its pass before the last pending tile and reports a decoy's 0.)"""
    tiles(tile=2, walk=10.0)  # tiles of 2 x 1 x 1 points, never walk the grid
    tiles_n = 12
    for truth in range(tiles_n):
        for ahead in range(tiles_n):
            pairs = _decoys(tiles_n, truth, ahead)
            stats = scan(pairs)
            assert stats.maximum[0] == (2.0, (2 * truth, 0, 0)), (truth, ahead)
            assert stats == brute(pairs)
            mirror = [[-a for a in d] for d in pairs]
            found = grid._search(mirror, False, "minimum")[0]["minimum"]
            assert found[0] == (-2.0, (2 * truth, 0, 0)), (truth, ahead)


def test_extremes_in_every_tile_at_the_default_tile_size():
    """The same at the production tile size: a grid of 70 x 66 x 66 points (27 tiles of
    about 32³), the maximum and the minimum of X in each tile in turn."""
    sizes = (70, 66, 66)
    shape = grid._tile_shape(sizes)
    counts = [-(-n // t) for n, t in zip(sizes, shape, strict=True)]
    base = field(sizes, "smooth", seed=8)
    corners = [
        (bx * shape[0], by * shape[1], bz * shape[2])
        for bx in range(counts[0])
        for by in range(counts[1])
        for bz in range(counts[2])
    ]
    assert len(corners) >= 8
    for n, corner in enumerate(corners):
        top = tuple(c + 1 for c in corner)
        low = corners[-1 - n]
        pairs = [[a.copy() for a in d] for d in base]
        _spike(pairs, 0, top, 50.0)
        if low != top:
            _spike(pairs, 0, low, -50.0)
        found = grid._search(pairs, False, ("minimum", "maximum"))[0]
        x = np.add(pairs[0][0][:, :, None], pairs[0][1][:, None, :]) + pairs[0][2][None, :, :]
        first_max = tuple(int(v) for v in np.unravel_index(int(x.argmax()), x.shape))
        first_min = tuple(int(v) for v in np.unravel_index(int(x.argmin()), x.shape))
        assert found["maximum"][0] == (float(x.max()), first_max) and first_max == top
        assert found["minimum"][0] == (float(x.min()), first_min)


# -- ties, written out ------------------------------------------------------------------------


def _only_x(pxy, nz: int, pxz=None):
    """A field whose X direction is pxy[i, j] (+ pxz[i, k]) and whose Y and Z are zero."""
    nx, ny = pxy.shape
    zero = [np.zeros((nx, ny)), np.zeros((nx, nz)), np.zeros((ny, nz))]
    first = [pxy, np.zeros((nx, nz)) if pxz is None else pxz, np.zeros((ny, nz))]
    return [first, zero, [a.copy() for a in zero]]


@pytest.mark.parametrize("method", ["bounds", "full"])
def test_constant_field_reports_the_first_point(method, tiles):
    pairs = [[np.full(s, v) for s in ((6, 5), (6, 4), (5, 4))] for v in (1.0, -2.0, 2.0)]
    stats = scan(pairs, method=method)
    # X = 3, Y = -6, Z = 6 everywhere: every extreme at the first point of the grid
    assert stats.minimum == ((3.0, (0, 0, 0)), (-6.0, (0, 0, 0)), (6.0, (0, 0, 0)))
    assert stats.maximum == stats.minimum
    assert stats.planar == tuple((np.sqrt(v), (0, 0, 0)) for v in (45.0, 45.0, 72.0))
    assert stats.volumetric == (9.0, (0, 0, 0))


def test_constant_field_needs_one_tile(tiles, monkeypatch):
    spy = Spy(monkeypatch)
    pairs = [[np.full(s, 1.5) for s in ((20, 20), (20, 20), (20, 20))] for _ in range(3)]
    stats = scan(pairs)
    assert stats.volumetric[1] == (0, 0, 0)
    assert (spy.boxes, spy.walks) == (1, 0)
    assert (stats.evaluated, stats.points) == (8, 8000)  # one tile of 2 x 2 x 2
    assert scan_all(pairs).evaluated == 8000


def test_tie_in_an_earlier_tile_but_later_point(tiles, monkeypatch):
    """X = 3 at (1, 0, *) and at (0, 5, *): (0, 5, 0) comes first in C order although
    (1, 0, 0) lies in the first tile; every tile is decided by its bound (no walk)."""
    tiles(tile=8, walk=10.0)  # tiles of 2 x 2 x 2
    spy = Spy(monkeypatch)
    pxy = np.zeros((4, 6))
    pxy[1, 0] = pxy[0, 5] = pxy[3, 5] = 3.0
    pxy[2, 2] = -3.0
    stats = scan(_only_x(pxy, nz=4))
    assert stats.maximum[0] == (3.0, (0, 5, 0))
    assert stats.minimum[0] == (-3.0, (2, 2, 0))
    assert stats.volumetric == (3.0, (0, 5, 0))
    assert stats.planar == ((3.0, (0, 5, 0)), (3.0, (0, 5, 0)), (0.0, (0, 0, 0)))
    assert spy.walks == 0
    assert stats == brute(_only_x(pxy, nz=4))


def test_symmetric_field_reports_the_first_of_mirror_points(tiles):
    """X = (i - 4)² + (k - 3)², symmetric about the centre: the maximum 25 is reached at
    (0, j, 0), (0, j, 6), (8, j, 0) and (8, j, 6) for every j; the minimum 0 at (4, j, 3)."""
    i = np.arange(9.0)
    k = np.arange(7.0)
    pxy = np.repeat(((i - 4.0) ** 2)[:, None], 5, axis=1)
    pxz = np.repeat(((k - 3.0) ** 2)[None, :], 9, axis=0)
    stats = scan(_only_x(pxy, nz=7, pxz=pxz))
    assert stats.maximum[0] == (25.0, (0, 0, 0))
    assert stats.minimum[0] == (0.0, (4, 0, 3))
    assert stats.volumetric == (25.0, (0, 0, 0))
    # Y and Z are zero everywhere: their extremes at the first point
    assert stats.minimum[1:] == stats.maximum[1:] == ((0.0, (0, 0, 0)), (0.0, (0, 0, 0)))


def test_plateau_spanning_tiles_and_blocks(tiles):
    """The maximum 7 on a plateau i in 3..8, j in 2..9 (all k): its first point (3, 2, 0);
    the minimum -1 only from i = 10 on, first at (10, 0, 0)."""
    pxy = np.zeros((12, 11))
    pxy[3:9, 2:10] = 7.0
    pxy[10:, :] = -1.0
    pairs = _only_x(pxy, nz=5)
    for method in ("bounds", "full"):
        stats = scan(pairs, method=method)
        assert stats.maximum[0] == (7.0, (3, 2, 0))
        assert stats.minimum[0] == (-1.0, (10, 0, 0))
        assert stats.volumetric == (7.0, (3, 2, 0))


def test_negative_zero_ties_zero(tiles):
    """-0.0 == 0.0: the first point in C order is reported, with its own sign. X is -0.0
    on the row (0, 0, k) (a sum of three -0.0) and +0.0 elsewhere."""
    pairs = _only_x(np.zeros((3, 4)), nz=2)
    pairs[0][0][0, 0] = -0.0
    pairs[0][1][:] = -0.0
    pairs[0][2][:] = -0.0
    stats = scan(pairs)
    assert stats.maximum[0] == stats.minimum[0] == (0.0, (0, 0, 0))
    assert np.signbit(stats.maximum[0][0]) and np.signbit(stats.minimum[0][0])
    assert stats == brute(pairs)


def test_bounds_round_like_the_values(tiles):
    """Floating-point addition is not associative: 2⁻⁵³ + 2⁻⁵³ + 1 is 1 + 2⁻⁵² summed left
    to right but 1 summed right to left. A bound summed in another order than the value
    would tie the point (0, 0, 0), whose value is exactly 1, and the point (1, 0, 0) that
    holds 1 + 2⁻⁵² would be skipped as a later tie."""
    tiles(tile=1, walk=10.0)  # one point per tile, never walk
    tiny = 2.0**-53
    one_axis = [[np.zeros((2, 1)), np.zeros((2, 1)), np.zeros((1, 1))] for _ in range(3)]
    pairs = [[a.copy() for a in d] for d in one_axis]
    pairs[0][0][1, 0] = pairs[0][1][1, 0] = tiny
    pairs[0][2][0, 0] = 1.0
    stats = scan(pairs)
    assert stats.maximum[0] == (1.0 + 2.0**-52, (1, 0, 0))
    assert grid._search(pairs, False, "maximum")[0]["maximum"] == stats.maximum
    assert stats == brute(pairs)
    # squared: (E_x + E_y) + E_z
    pairs = [[a.copy() for a in d] for d in one_axis]
    pairs[0][0][1, 0] = pairs[1][0][1, 0] = tiny
    pairs[2][2][0, 0] = 1.0
    stats = scan(pairs, squared=True)
    assert stats.volumetric == (np.sqrt(1.0 + 2.0**-52), (1, 0, 0))
    assert stats == brute(pairs, squared=True)
    # alone, so that no tile evaluated for another quantity can hide a wrong bound
    assert volumetric_peak(pairs, squared=True) == stats.volumetric


# -- the bounds prune ----------------------------------------------------------------------------


def _smooth(sizes):
    nx, ny, nz = sizes
    x, y, z = (np.linspace(0.0, 1.0, n) for n in sizes)
    pairs = []
    for d in range(3):
        w = 1.0 + d
        pairs.append(
            [
                np.sin(3 * w * x)[:, None] * np.cos(2 * y)[None, :] + x[:, None] * y[None, :],
                np.cos(w * x)[:, None] * z[None, :] ** 2,
                (y[:, None] - 0.3 * d) * np.sin(4 * z + d)[None, :],
            ]
        )
    return pairs


def test_smooth_field_is_decided_by_few_tiles(tiles, monkeypatch):
    tiles(tile=64)  # tiles of 4 x 4 x 4: 15 x 12 x 10 = 1800 tiles
    spy = Spy(monkeypatch)
    pairs = _smooth((60, 48, 40))
    stats = scan(pairs)
    assert spy.walks == 0
    assert spy.boxes < 1800 // 20
    assert stats == brute(pairs)


def test_volumetric_only_is_cheaper(tiles, monkeypatch):
    tiles(tile=64)
    pairs = _smooth((60, 48, 40))
    spy = Spy(monkeypatch)
    scan(pairs)
    everything = spy.boxes
    spy.boxes = 0
    assert volumetric_peak(pairs) == brute(pairs).volumetric
    assert spy.boxes < everything


def test_flat_noisy_field_walks_the_grid_once(tiles, monkeypatch):
    """Noise with no trend: the bounds cannot prune, the search walks the grid instead of
    evaluating tile after tile."""
    tiles(tile=64, block=200)
    spy = Spy(monkeypatch)
    pairs = field((40, 36, 30), "normal", seed=11)
    stats = scan(pairs)
    assert spy.walks == 1
    blocks = 40 * 36 * 30 // 200 + 40
    assert spy.boxes <= 1 + blocks
    assert stats == brute(pairs)


# -- options and bad input -----------------------------------------------------------------------


def test_method_is_checked():
    pairs = field((3, 3, 3), "normal", seed=1)
    assert scan(pairs, method="full") == scan(pairs) == scan_all(pairs)
    assert volumetric_peak(pairs, method="full") == volumetric_peak(pairs)
    with pytest.raises(ValueError, match="method"):
        scan(pairs, method="fast")
    with pytest.raises(ValueError, match="only"):
        grid._search(pairs, False, ("volume",))
    with pytest.raises(ValueError, match="only"):
        grid._search(pairs, False, ())


@pytest.mark.parametrize("method", ["bounds", "full"])
@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
@pytest.mark.parametrize("where", [(0, 0), (1, 2), (2, 1)])
@pytest.mark.parametrize("squared", [False, True])
def test_non_finite_input_is_refused(method, bad, where, squared):
    pairs = field((5, 4, 3), "normal", seed=2, squared=squared)
    pairs[where[0]][where[1]][-1, -1] = bad
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(DataError, match="not finite \\(check the inputs\\)"):
            scan(pairs, squared, method=method)


@pytest.mark.parametrize("method", ["bounds", "full"])
@pytest.mark.parametrize("squared", [False, True])
def test_values_whose_square_overflows_are_refused(method, squared):
    pairs = field((5, 4, 3), "normal", seed=2, squared=squared)
    # the X value squared, or the sum of the X and Y values, overflows at (2, 2, k)
    pairs[0][0][2, 2] = 1e308 if squared else 1e160
    pairs[1][0][2, 2] = 1e308 if squared else 1.0
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(DataError, match="too large"):
            scan(pairs, squared, method=method)


def test_large_but_safe_values_are_exact():
    """1e150 squares to 1e300: within range, no warning, and identical to the brute force."""
    pairs = field((6, 5, 4), "normal", seed=4)
    pairs[1][2] *= 1e150
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert scan(pairs) == brute(pairs)


def test_empty_grid_is_refused():
    pairs = [[np.zeros((0, 3)), np.zeros((0, 2)), np.zeros((3, 2))] for _ in range(3)]
    with pytest.raises(DataError, match="no points"):
        scan(pairs)
