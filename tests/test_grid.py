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


def _random_products(rng, sizes, squared, first=False, last=None):
    """Products of every kind in each direction: one factor along each axis, and two
    factors along two axes or the same one; a random constant before them (``first``) and
    the constant ``last`` after them. Squared: every factor and coefficient non-negative,
    as in a sum of squares."""
    products = []
    for d in range(3):
        if first:
            products.append(Product(d, rng.normal()))
        for a in range(3):
            for c in (None, 0, 1, 2):
                f = rng.normal(size=sizes[a])
                g = None if c is None else rng.normal(size=sizes[c])
                if squared:
                    f, g = f**2, (None if g is None else g**2)
                products.append(
                    Product(d, abs(rng.normal()) if squared else rng.normal(), a, f, c, g)
                )
        if last is not None:
            products.append(Product(d, last))
    return products


@pytest.mark.slow
@pytest.mark.parametrize("sizes", [(7, 5, 3), (1, 9, 4), (40, 33, 29), (3, 1, 1)])
@pytest.mark.parametrize("squared", [False, True])
def test_scan_matches_brute_force(sizes, squared, monkeypatch):
    monkeypatch.setattr(grid, "_BLOCK_ELEMENTS", 64)  # many blocks, ragged edges
    products = _random_products(np.random.default_rng(7), sizes, squared, last=0.5)
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


def _field_of(pairs):
    """The 3-D field of each direction from fold's pair arrays."""
    return np.stack([xy[:, :, None] + xz[:, None, :] + yz[None, :, :] for xy, xz, yz in pairs])


@pytest.mark.parametrize("squared", [False, True])
def test_fold_gives_the_field_of_the_products(squared):
    """Every kind of product -- a constant, one factor along each axis, two factors along
    two axes (in either order) or along the same axis -- folded, then summed back to the
    3-D field, is the field of the products evaluated at every point (fast, small grid)."""
    sizes = (4, 3, 5)
    rng = np.random.default_rng(21)
    products = _random_products(rng, sizes, squared, first=True)
    field, _ = _brute(products, sizes)
    np.testing.assert_allclose(_field_of(fold(products, sizes)), field, rtol=1e-12, atol=1e-12)


def test_an_axis_without_its_array_is_a_factor_of_one():
    """``Product(d, s, a, None, c, g)``: f is 1 (the docstring's "or None for 1"), so the
    product is s·g(x_c) alone, whichever of the two slots is left empty."""
    g = np.array([1.0, -2.0, 4.0])
    sizes = (2, 3, 4)
    alone = _field_of(fold([Product(1, 3.0, 1, g)], sizes))
    assert alone[1, 0, :, 0].tolist() == [3.0, -6.0, 12.0]
    for p in (Product(1, 3.0, 0, None, 1, g), Product(1, 3.0, 1, g, 2, None)):
        np.testing.assert_array_equal(_field_of(fold([p], sizes)), alone)
