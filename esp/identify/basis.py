"""The bases in which an unknown error component is written.

An unknown curve of axis ``a`` over its travel [lo, hi] is ``f(x) = Σ_j c_j φ_j(x)``, linear
in its coefficients ``c_j``, so that the first-order model stays linear in them (the
design matrix is the bound terms with φ_j in place of the data).

* ``legendre``, degree d: Legendre polynomials P_j(u) of u = (2x - lo - hi)/(hi - lo)
  (Abramowitz & Stegun 1964, 22.7.10: (j+1) P_{j+1} = (2j+1) u P_j - j P_{j-1}).
* ``bspline``, N interior knots: the cubic B-splines on N uniform interior knots with
  clamped ends, N + 4 functions (de Boor 1978, ch. IX, the Cox-de Boor recursion).

What a relative measurement can never see is left out of the basis, so that it is not
reported as unidentifiable every time (docs/identify.md):

* a linear, angular or mechanical error is zero at the low end of its travel (where a laser
  is zeroed): Legendre P_j(u) - P_j(-1) for j = 1..d; B-splines without the first (the only
  one non-zero at the low end);
* a straightness has no constant and no slope (ISO 230-1, 3.4.8: the least-squares
  reference straight line; esp removes the same slope from measured straightness): the
  functions (Legendre j >= 2, B-splines without the first two) are made exactly orthogonal
  to 1 and x on the targets at which the identified curve is written, so that the
  least-squares slope esp removes from the written profile is zero.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

__all__ = ["BASES", "Basis", "bspline_values", "legendre_values"]

BASES = ("legendre", "bspline")


def legendre_values(u: np.ndarray, degree: int) -> np.ndarray:
    """P_0..P_degree at u, shape (N, degree + 1), by the three-term recursion."""
    u = np.asarray(u, dtype=float)
    out = np.empty((u.size, degree + 1))
    out[:, 0] = 1.0
    if degree >= 1:
        out[:, 1] = u
    for j in range(1, degree):
        out[:, j + 1] = ((2 * j + 1) * u * out[:, j] - j * out[:, j - 1]) / (j + 1)
    return out


def bspline_values(u: np.ndarray, knots: int) -> np.ndarray:
    """The N + 4 cubic B-splines on [-1, 1] with N uniform interior knots, clamped
    (multiplicity 4 at each end), at u; shape (N, knots + 4). Cox-de Boor recursion; the
    right end belongs to the last interval."""
    u = np.clip(np.asarray(u, dtype=float), -1.0, 1.0)
    inner = np.linspace(-1.0, 1.0, knots + 2)
    t = np.concatenate([[-1.0] * 3, inner, [1.0] * 3])
    m = t.size - 1
    b = np.zeros((u.size, m))
    for i in range(m):
        if t[i] < t[i + 1]:
            b[:, i] = (u >= t[i]) & (u < t[i + 1])
    last = max(i for i in range(m) if t[i] < t[i + 1])
    b[u >= 1.0, last] = 1.0
    for p in range(1, 4):
        nb = np.zeros((u.size, m - p))
        for i in range(m - p):
            d1 = t[i + p] - t[i]
            d2 = t[i + p + 1] - t[i + 1]
            if d1 > 0:
                nb[:, i] += (u - t[i]) / d1 * b[:, i]
            if d2 > 0:
                nb[:, i] += (t[i + p + 1] - u) / d2 * b[:, i + 1]
        b = nb
    return b


@dataclass(frozen=True)
class Basis:
    """The functions φ_j of one unknown curve component.

    ``kind`` is the component's kind, ``travel_mm`` its axis' travel, ``targets_mm`` the
    positions the identified curve is written at (a straightness basis is orthogonal to 1
    and x on them). ``labels`` name the coefficients (``1`` .. ``d`` for Legendre P_j).
    """

    family: str
    size: int  # degree (legendre) or interior knots (bspline)
    kind: str
    travel_mm: tuple[float, float]
    targets_mm: tuple[float, ...]

    def _u(self, x_mm: npt.ArrayLike) -> np.ndarray:
        lo, hi = self.travel_mm
        return (2.0 * np.asarray(x_mm, dtype=float) - lo - hi) / (hi - lo)

    def _raw(self, x_mm: npt.ArrayLike) -> tuple[np.ndarray, list[int]]:
        u = self._u(x_mm).reshape(-1)
        if self.family == "legendre":
            values = legendre_values(u, self.size)
        else:
            values = bspline_values(u, self.size)
        first = 2 if self.kind == "straightness" else 1
        return values, list(range(first, values.shape[1]))

    @property
    def labels(self) -> tuple[str, ...]:
        _, keep = self._raw(np.array([self.travel_mm[0]]))
        prefix = "P" if self.family == "legendre" else "B"
        return tuple(f"{prefix}{j}" for j in keep)

    def values(self, x_mm: npt.ArrayLike) -> np.ndarray:
        """φ_j at positions x (mm), shape (N, len(labels)), in units of the component per
        unit coefficient."""
        values, keep = self._raw(x_mm)
        out = values[:, keep]
        if self.kind == "straightness":
            u = self._u(x_mm).reshape(-1)
            out = out - np.c_[np.ones_like(u), u] @ _line_of(self)
        else:
            start, _ = self._raw(np.array([self.travel_mm[0]]))
            out = out - start[:, keep]
        return out


@functools.cache
def _line_of(basis: Basis) -> np.ndarray:
    """The least-squares line of each straightness function on the basis' targets (2, n),
    computed once per basis."""
    values, keep = basis._raw(np.asarray(basis.targets_mm))
    t = basis._u(np.asarray(basis.targets_mm))
    G = np.c_[np.ones_like(t), t]
    coef, *_ = np.linalg.lstsq(G, values[:, keep], rcond=None)
    coef.setflags(write=False)
    return coef
