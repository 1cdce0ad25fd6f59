"""The blocked separable scan against a brute-force evaluation of the full 3-D field."""

from __future__ import annotations

import numpy as np
import pytest

import esp.core.grid as grid
from esp.core.grid import PAIRS, Product, fold, scan, scan_all


def _brute(products, sizes, squared=False):
    field = np.zeros((3, *sizes))
    for p in products:
        term = np.full(sizes, p.scale)
        for ax, arr in ((p.a, p.f), (p.c, p.g)):
            if ax is not None:
                shape = [1, 1, 1]
                shape[ax] = -1
                term = term * arr.reshape(shape)
        field[p.direction] += term
    sq = field if squared else field**2
    return field, sq


@pytest.mark.slow
@pytest.mark.parametrize("sizes", [(7, 5, 3), (1, 9, 4), (40, 33, 29), (3, 1, 1)])
@pytest.mark.parametrize("squared", [False, True])
def test_scan_matches_brute_force(sizes, squared, monkeypatch):
    monkeypatch.setattr(grid, "_BLOCK_ELEMENTS", 64)  # many blocks, ragged edges
    rng = np.random.default_rng(7)
    products = []
    for d in range(3):
        for a in range(3):
            for c in (None, 0, 1, 2):
                f = rng.normal(size=sizes[a])
                g = None if c is None else rng.normal(size=sizes[c])
                if squared:
                    f, g = f**2, (None if g is None else g**2)
                products.append(
                    Product(d, abs(rng.normal()) if squared else rng.normal(), a, f, c, g)
                )
        products.append(Product(d, 0.5))
    stats = scan(fold(products, sizes), squared=squared)
    # the bounded search and the full walk agree to the last bit, indices included
    assert stats == scan_all(fold(products, sizes), squared=squared)
    field, sq = _brute(products, sizes, squared)
    if not squared:
        for d in range(3):
            assert stats.minimum[d][0] == pytest.approx(field[d].min())
            assert stats.maximum[d][0] == pytest.approx(field[d].max())
            assert field[d][stats.minimum[d][1]] == pytest.approx(field[d].min())
            assert field[d][stats.maximum[d][1]] == pytest.approx(field[d].max())
    else:
        for d in range(3):
            assert stats.maximum[d][0] == pytest.approx(np.sqrt(sq[d].max()))
    vol = np.sqrt(sq.sum(axis=0))
    assert stats.volumetric[0] == pytest.approx(vol.max())
    assert vol[stats.volumetric[1]] == pytest.approx(vol.max())
    for k, (p, q) in enumerate(PAIRS):
        planar = np.sqrt(sq[p] + sq[q])
        assert stats.planar[k][0] == pytest.approx(planar.max())
        assert planar[stats.planar[k][1]] == pytest.approx(planar.max())
    assert stats.points == int(np.prod(sizes))


@pytest.mark.parametrize("method", ["bounds", "full"])
def test_zero_field_gives_zero(method):
    stats = scan(fold([], (4, 3, 2)), method=method)
    assert stats.volumetric == (0.0, (0, 0, 0))
    assert all(f == (0.0, (0, 0, 0)) for f in stats.minimum + stats.maximum + stats.planar)


def test_one_term_gives_exactly_its_values():
    """A single product 2·f(x)·g(z): X is 2·f[i]·g[k] at every (i, j, k), Y and Z zero."""
    f = np.array([1.0, -3.0, 2.0])
    g = np.array([0.5, 4.0])
    stats = scan(fold([Product(0, 2.0, 0, f, 2, g)], (3, 5, 2)))
    # 2·f·g over (i, k): [[1, 8], [-3, -24], [2, 16]]
    assert stats.minimum[0] == (-24.0, (1, 0, 1))
    assert stats.maximum[0] == (16.0, (2, 0, 1))
    assert stats.volumetric == (24.0, (1, 0, 1))
    assert stats.planar == ((24.0, (1, 0, 1)), (24.0, (1, 0, 1)), (0.0, (0, 0, 0)))
