"""First- and second-order error terms of a chain, numerically (numpy only).

:func:`sensitivities` gives ∂p/∂e, the derivative of the tool-tip position with respect to
each small error at zero errors, exactly (analytic derivatives of each elementary transform,
no finite differences). With the prefix rotations P_i (the product of the rotations of
Ψ_1 … Ψ_{i−1}) and the suffix points s_i = Ψ_i … Ψ_N · 0,

    ∂p/∂q = P_i · ∂(Ψ_i s_{i+1})/∂q

for a quantity q of the i-th transform: e_k for a translation along k, u_k × s_i for a
rotation about axis k, u_k × (s_{i+1} − pivot) for a small rotation of an error motion. The
chain rule through each quantity's expression (∂q/∂e, an exact tree derivative) gives
∂p/∂e. Cost: one pass over the chain and a few array operations per error-bearing
transform, so it suits the run time of an analysis.

:func:`taylor` gives the nominal position and the first- and second-order terms for given
error values by propagating truncated Taylor series in the errors' common scale λ through
the chain (Freeman & Ford 2003, section 4: products of more than ``order`` small
quantities dropped; exact trigonometry of the large angles). It is a second, independent
route to the first order.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from functools import lru_cache
from typing import Any

import numpy as np

from esp.core.kinematics.chain import Chain, Op, check_finite
from esp.core.kinematics.exact import BLOCK, _blocks, _evaluate, _pivot, _rotate_point
from esp.core.kinematics.expr import Expr, Jet

__all__ = ["Expansion", "sensitivities", "taylor"]


@lru_cache(maxsize=64)
def _gradients(chain: Chain) -> tuple[tuple[tuple[tuple[str, Expr], ...], ...], ...]:
    """For each op and each of its quantities: ((error, ∂q/∂error), ...)."""
    errors = set(chain.errors)
    out = []
    for op in chain.ops:
        per_q = []
        for e in op.q:
            per_q.append(tuple((n, e.diff(n)) for n in sorted(e.names() & errors)))
        out.append(tuple(per_q))
    return tuple(out)


def _unit_cross(k: int, w: list[Any]) -> list[Any]:
    """u_k × w."""
    zero = 0.0
    if k == 0:
        return [zero, -w[2], w[1]]
    if k == 1:
        return [w[2], zero, -w[0]]
    return [-w[1], w[0], zero]


def sensitivities(
    chain: Chain,
    coordinates: Mapping[str, Any] | None = None,
    parameters: Mapping[str, Any] | None = None,
    *,
    block: int = BLOCK,
) -> dict[str, np.ndarray]:
    """∂p/∂e at zero errors for every small error e of the chain, at N points.

    Parameters
    ----------
    chain : the chain
    coordinates, parameters : as :func:`esp.core.kinematics.position` (each in its unit)

    Returns
    -------
    dict error name -> ndarray (N, 3)
        The change of the tool-tip x, y, z in mm per unit of the error, in the error's own
        unit (mm/µm and mm/µrad for the default units), in the order of
        :attr:`Chain.errors`. The first-order error is Σ_e sensitivity_e · e.

    Notes
    -----
    Exact: equal to the derivative of :func:`esp.core.kinematics.position` at zero errors
    (tested against finite differences and against the symbolic derivation).
    """
    env, n = chain.environment(coordinates, parameters, None)
    names = chain.errors
    out = {e: np.zeros((n, 3)) for e in names}
    grads = _gradients(chain)
    with chain.named():
        for sl, sub in _blocks(env, n, block):
            _sensitivities_block(chain, grads, sub, sl, out)
    for e in names:  # per unit of the error's own unit
        out[e] *= chain.symbols[e].scale
    return out


def _is_zero(x: Any) -> bool:
    return isinstance(x, float) and x == 0.0


def _combine(terms: list[tuple[Any, Any]]) -> Any:
    """Σ a·b over the pairs, skipping those with a scalar zero; 0.0 if none is left."""
    total: Any = 0.0
    for a, b in terms:
        if _is_zero(a) or _is_zero(b):
            continue
        total = a * b if _is_zero(total) else total + a * b
    return total


def _prefix(P: list[list[Any]], local: list[Any]) -> list[Any]:
    """P · local, with P given by its three columns and every entry a float or an array."""
    return [_combine([(P[k][i], local[k]) for k in range(3)]) for i in range(3)]


def _sensitivities_block(
    chain: Chain, grads: Any, sub: Mapping[str, Any], sl: slice, out: dict[str, np.ndarray]
) -> None:
    """The sensitivities of one block of points into ``out[e][sl]``.

    Vectors are kept as three components, each a float while it is the same at every
    point (the levers of a Cartesian chain, the columns of a constant rotation) and an
    array only where it varies, so that constant terms cost nothing.
    """
    ops = chain.ops
    qs = [_evaluate(op, sub) for op in ops]
    needs = [any(g for g in grads[i]) for i in range(len(ops))]
    # backward: the points s_{i+1} (before op i) and s_i (after it) where needed
    after: list[list[Any] | None] = [None] * len(ops)
    here: list[list[Any] | None] = [None] * len(ops)
    p: list[Any] = [0.0, 0.0, 0.0]
    for i in range(len(ops) - 1, -1, -1):
        op = ops[i]
        if needs[i]:
            after[i] = p
        if op.kind == "T":
            p = [_combine([(1.0, p[k]), (1.0, _scalar(qs[i][k]))]) for k in range(3)]
        elif op.kind == "R":
            p = _rotate_point(op, qs[i], p)
        # an error motion is the identity at zero errors
        if needs[i]:
            here[i] = p
    # forward: the prefix rotation P (three columns) and the contributions
    P: list[list[Any]] = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
    acc: dict[str, list[Any]] = {e: [0.0, 0.0, 0.0] for e in chain.errors}
    for i, op in enumerate(ops):
        if needs[i]:
            if op.kind == "E":
                piv = _pivot(op, sub)
                w = [_combine([(1.0, after[i][k]), (-1.0, _scalar(piv[k]))]) for k in range(3)]  # type: ignore[index]
            for slot, pairs in enumerate(grads[i]):
                if not pairs:
                    continue
                if op.kind == "T" or (op.kind == "E" and slot < 3):
                    v = P[slot]  # the prefix image of e_slot
                elif op.kind == "R":
                    local = _unit_cross(op.axis, here[i])  # type: ignore[arg-type]
                    v = _prefix(P, [_combine([(float(op.sign), c)]) for c in local])
                else:
                    v = _prefix(P, _unit_cross(slot - 3, w))
                with np.errstate(all="ignore"):
                    for name, d in pairs:
                        g = d.evaluate(sub)
                        check_finite(g, op.keys[slot], d)
                        g = _scalar(g)
                        a = acc[name]
                        for k in range(3):
                            a[k] = _combine([(1.0, a[k]), (g, v[k])])
        if op.kind == "R":
            theta = op.sign * qs[i][0]
            c, s = _scalar(np.cos(theta)), _scalar(np.sin(theta))
            ii, jj = (op.axis + 1) % 3, (op.axis + 2) % 3
            Pi, Pj = P[ii], P[jj]
            P = list(P)
            P[ii] = [_combine([(c, Pi[r]), (s, Pj[r])]) for r in range(3)]
            P[jj] = [_combine([(-s, Pi[r]), (c, Pj[r])]) for r in range(3)]
    for e in chain.errors:
        for k in range(3):
            out[e][sl, k] = acc[e][k]


def _scalar(x: Any) -> Any:
    """A 0-d value as a Python float (so that zeros can be skipped), arrays unchanged."""
    return float(x) if np.ndim(x) == 0 else x


# -- Taylor series in the scale of the errors -----------------------------------------------


@dataclass(frozen=True)
class Expansion:
    """The tool tip p(λ e) = nominal + λ first + λ² second + O(λ³), each (N, 3) in mm."""

    nominal: np.ndarray
    first: np.ndarray
    second: np.ndarray | None


def _jet_apply(
    op: Op, env: Mapping[str, Jet], nominal_env: Mapping[str, Any], p: list[Jet], order: int
) -> list[Jet]:
    q = [e.jet(env, np) for e in op.q]
    for jet, key, e in zip(q, op.keys, op.q, strict=True):
        for c in jet.c:
            if not isinstance(c, int):
                check_finite(c, key, e)
    if op.kind == "T":
        return [p[k] + q[k] for k in range(3)]
    if op.kind == "R":
        theta = q[0] if op.sign > 0 else -q[0]
        c, s = theta.cos(np), theta.sin(np)
        i, j = (op.axis + 1) % 3, (op.axis + 2) % 3
        out = list(p)
        out[i] = c * p[i] - s * p[j]
        out[j] = s * p[i] + c * p[j]
        return out
    piv = [Jet.constant(v, order) for v in _pivot(op, nominal_env)]
    w = [p[k] - piv[k] for k in range(3)]
    r = q[3:]
    u = [r[1] * w[2] - r[2] * w[1], r[2] * w[0] - r[0] * w[2], r[0] * w[1] - r[1] * w[0]]
    v = [r[1] * u[2] - r[2] * u[1], r[2] * u[0] - r[0] * u[2], r[0] * u[1] - r[1] * u[0]]
    # exp([r]×) w = w + r×w + r×(r×w)/2 + O(λ³), since r vanishes at zero errors
    return [piv[k] + q[k] + w[k] + u[k] + v[k].scale(0.5) for k in range(3)]


def taylor(
    chain: Chain,
    coordinates: Mapping[str, Any] | None = None,
    parameters: Mapping[str, Any] | None = None,
    errors: Mapping[str, Any] | None = None,
    *,
    order: int = 2,
    block: int = BLOCK,
) -> Expansion:
    """Nominal position and the first- and second-order terms in the small errors.

    Every error e is replaced by λ e, the chain is propagated as truncated Taylor series in
    λ (exact trigonometry of the nominal angles, series of the small parts), and the
    coefficients of λ⁰, λ¹ and λ² are returned: the nominal tool tip, the first-order error
    (terms linear in one small error) and the second-order error (terms in products of two).

    Arguments as :func:`esp.core.kinematics.position`; ``order`` is 1 or 2.

    Returns
    -------
    Expansion
        ``nominal``, ``first`` and (order 2) ``second``, each (N, 3) in mm.
    """
    if order not in (1, 2):
        raise ValueError(f"order must be 1 or 2, found {order!r}")
    env, n = chain.environment(coordinates, parameters, errors)
    nominal = np.empty((n, 3))
    first = np.empty((n, 3))
    second = np.empty((n, 3)) if order == 2 else None
    err = set(chain.errors)
    with chain.named():
        for sl, sub in _blocks(env, n, block):
            _taylor_block(chain, sub, sl, err, order, (nominal, first, second))
    return Expansion(nominal, first, second)


def _taylor_block(
    chain: Chain, sub: Mapping[str, Any], sl: slice, err: set[str], order: int, outs: tuple
) -> None:
    """The Taylor coefficients of one block of points into ``outs``."""
    nominal, first, second = outs
    m = sl.stop - sl.start
    jets = {
        k: (Jet((0, v) + (0,) * (order - 1)) if k in err else Jet.constant(v, order))
        for k, v in sub.items()
    }
    nominal_env = {k: (0.0 if k in err else v) for k, v in sub.items()}
    p = [Jet.constant(np.zeros(m), order) for _ in range(3)]
    for op in reversed(chain.ops):
        p = _jet_apply(op, jets, nominal_env, p, order)
    for k in range(3):
        c = p[k]._pad(order)
        nominal[sl, k] = c[0]
        first[sl, k] = c[1]
        if second is not None:
            second[sl, k] = c[2]
