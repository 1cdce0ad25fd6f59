"""Evaluate a separable error field over a 3-D grid without materialising it.

Every term of an ESP model is a product of at most two functions of one coordinate each
(a component of one axis times a lever along another). A direction's total error over the
grid is therefore a sum of outer products, which folds into three 2-D arrays::

    E_d[i, j, k] = P_xy[i, j] + P_xz[i, k] + P_yz[j, k]

The scan walks the grid in cache-sized blocks, forms the three directions' errors there,
and keeps running extremes with their indices: the minimum and maximum of each direction,
the maximum planar error of each plane and the maximum volumetric error (Longstaff 2002,
eq. 3.4-3.5 and 3.05.4-3.05.5). The cost is a few floating-point operations per point.

With ``squared=True`` the arrays hold sums of squared contributions (the root-sum-square
combination of thesis 3.14.7), and the per-direction, planar and volumetric figures are
their square roots.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["PAIRS", "FieldStats", "Product", "fold", "scan"]

#: the three planes as pairs of axis indices, in the order XY, XZ, YZ
PAIRS = ((0, 1), (0, 2), (1, 2))
_BLOCK_ELEMENTS = 1 << 15


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
    :data:`PAIRS` order, (value, index). ``volumetric``: (value, index).
    """

    minimum: tuple[tuple[float, tuple[int, int, int]], ...]
    maximum: tuple[tuple[float, tuple[int, int, int]], ...]
    planar: tuple[tuple[float, tuple[int, int, int]], ...]
    volumetric: tuple[float, tuple[int, int, int]]
    points: int


def fold(products, sizes: tuple[int, int, int]) -> list[list[np.ndarray]]:
    """Sum products into, per direction, the three pair arrays ``[P_xy, P_xz, P_yz]``."""
    out = [[np.zeros((sizes[a], sizes[b])) for a, b in PAIRS] for _ in range(3)]
    for p in products:
        parts = [(p.a, p.f), (p.c, p.g)]
        parts = [(ax, arr) for ax, arr in parts if ax is not None and arr is not None]
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


class _Best:
    """A running extreme with its flat position."""

    __slots__ = ("index", "value")

    def __init__(self, value: float):
        self.value = value
        self.index = (0, 0, 0)


def scan(pairs: list[list[np.ndarray]], squared: bool = False) -> FieldStats:
    """Scan the field given by :func:`fold`'s pair arrays and return its extremes."""
    nx, ny = pairs[0][0].shape
    nz = pairs[0][1].shape[1]
    rows_y = max(1, min(ny, _BLOCK_ELEMENTS // max(1, nz)))
    rows_x = max(1, min(nx, _BLOCK_ELEMENTS // max(1, nz * rows_y)))
    lo = [_Best(np.inf) for _ in range(3)]
    hi = [_Best(-np.inf) for _ in range(3)]
    plane = [_Best(-np.inf) for _ in range(3)]
    vol = _Best(-np.inf)

    def track(best: _Best, block: np.ndarray, origin, biggest: bool) -> None:
        flat = int(block.argmax() if biggest else block.argmin())
        value = float(block.flat[flat])
        if (value > best.value) if biggest else (value < best.value):
            i, j, k = np.unravel_index(flat, block.shape)
            best.value = value
            best.index = (int(i + origin[0]), int(j + origin[1]), int(k))

    for x0 in range(0, nx, rows_x):
        x1 = min(nx, x0 + rows_x)
        for y0 in range(0, ny, rows_y):
            y1 = min(ny, y0 + rows_y)
            shape = (x1 - x0, y1 - y0, nz)
            e = []
            for d in range(3):
                pxy, pxz, pyz = pairs[d]
                block = np.empty(shape)
                np.add(pxy[x0:x1, y0:y1, None], pxz[x0:x1, None, :], out=block)
                block += pyz[None, y0:y1, :]
                e.append(block)
            origin = (x0, y0)
            for d in range(3):
                if not squared:
                    track(lo[d], e[d], origin, biggest=False)
                track(hi[d], e[d], origin, biggest=True)
                if not squared:
                    np.square(e[d], out=e[d])
            sq = e  # squares from here on, in place
            s01 = sq[0] + sq[1]
            s02 = np.add(sq[0], sq[2], out=sq[0])
            s12 = np.add(sq[1], sq[2], out=sq[1])
            track(plane[0], s01, origin, biggest=True)
            track(plane[1], s02, origin, biggest=True)
            track(plane[2], s12, origin, biggest=True)
            # volumetric: x² + y² + z² = (x² + y²) + z²
            s01 += sq[2]
            track(vol, s01, origin, biggest=True)

    def root(best: _Best) -> tuple[float, tuple[int, int, int]]:
        return float(np.sqrt(max(best.value, 0.0))), best.index

    if squared:
        minimum = tuple((0.0, (0, 0, 0)) for _ in range(3))
        maximum = tuple(root(b) for b in hi)
    else:
        minimum = tuple((b.value, b.index) for b in lo)
        maximum = tuple((b.value, b.index) for b in hi)
    return FieldStats(
        minimum=minimum,
        maximum=maximum,
        planar=tuple(root(b) for b in plane),
        volumetric=root(vol),
        points=nx * ny * nz,
    )
