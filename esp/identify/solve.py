"""Identifiability, the fit and the covariance of what is identified.

All three work on the weighted Jacobian J (residuals divided by their standard
uncertainty) with its columns scaled to unit length (equilibration, so that the singular
values compare parameters of different units; Golub & Van Loan 2013, 3.5.2):

* identifiability: the singular values of the scaled J, its rank (singular values above
  ``rank_tolerance`` times the largest), its condition number, and a basis of its null
  space (the right singular vectors of the singular values below the rank tolerance) in
  reduced form, each vector one combination of named parameters the
  data cannot see (Golub & Van Loan 2013, 5.4.1);
* the fit: Gauss-Newton on the whole parameter vector (coefficients and nuisance
  parameters together, the linear part solved jointly), each step the least-squares
  solution of the linearised problem by the SVD (of the triangle of a QR when J is
  tall) -- for ``null = "minimum-norm"`` the truncated-SVD pseudo-inverse, the
  minimum-norm step (Golub & Van Loan 2013, 5.5.1) --
  damped by Levenberg-Marquardt filter factors until the sum of squares does not grow
  (Moré 1978; Nocedal & Wright 2006, 10.3);
* the covariance: C = (Jᵀ J)⁻¹ from the stated uncertainties (JCGM 100:2008, 5.2 and
  annex H.3 for least squares), the pseudo-inverse on the identifiable subspace for the
  minimum-norm choice; the Birge ratio R_B = sqrt(χ²/ν) (Birge 1932) and the test of χ²
  against its 97.5 % quantile say whether the residuals are larger than the stated
  uncertainties explain.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from esp.core.errors import ConfigError, DataError
from esp.core.text import closest
from esp.identify.config import MAX_ITERATIONS
from esp.identify.model import Block, Engine

__all__ = ["Fit", "Identifiability", "IdentifyError", "Parameters", "fit", "identifiability"]


class IdentifyError(DataError):
    """The measurements cannot identify what was asked (named combinations)."""


@dataclass(frozen=True)
class Parameters:
    """The layout of the parameter vector: coefficients first, then each block's nuisance
    parameters; ``free`` marks those not fixed by ``fix = [...]``."""

    names: tuple[str, ...]
    x0: np.ndarray
    free: np.ndarray  # bool
    n_coefficients: int
    offsets: tuple[int, ...]  # start of each block's nuisance parameters
    keys: tuple[tuple[str, str, int], ...] = ()  # (component, its key, its coefficients)

    def split(self, x: np.ndarray, k: int, blocks: list[Block]) -> np.ndarray:
        start = self.offsets[k]
        return x[start : start + len(blocks[k].names)]


def layout(
    engine: Engine, blocks: list[Block], fix: tuple[str, ...], source: str | None
) -> Parameters:
    names = list(engine.coefficient_names)
    x0 = [0.0] * len(names)
    offsets = []
    for b in blocks:
        offsets.append(len(names))
        names.extend(b.names)
        x0.extend(float(v) for v in b.theta0)
    free = np.ones(len(names), dtype=bool)
    index = {n: i for i, n in enumerate(names)}
    components = {str(u.name): engine.slices[str(u.name)] for u in engine.unknowns}
    for i, f in enumerate(fix):
        if f in index:
            free[index[f]] = False
        elif f in components:
            free[components[f]] = False
        else:
            hint = closest(f, names)
            dym = f"; did you mean {hint!r}?" if hint else ""
            raise ConfigError(f"identify.fix[{i}]", f"unknown parameter {f!r}{dym}", source)
    keys = tuple((str(u.name), u.key, len(u.coefficient_names)) for u in engine.unknowns)
    return Parameters(tuple(names), np.array(x0), free, engine.size, tuple(offsets), keys)


def evaluate(
    blocks: list[Block], params: Parameters, x: np.ndarray, plan: bool = False
) -> tuple[np.ndarray, np.ndarray]:
    """The stacked weighted residuals and Jacobian (all parameters) at x."""
    n_c = params.n_coefficients
    c = x[:n_c]
    rs, Js = [], []
    for k, b in enumerate(blocks):
        theta = params.split(x, k, blocks)
        r, Jc, Jt = b.evaluate(c, theta, plan)
        J = np.zeros((r.size, x.size))
        J[:, :n_c] = Jc
        start = params.offsets[k]
        J[:, start : start + theta.size] = Jt
        rs.append(r)
        Js.append(J)
    return np.concatenate(rs), np.vstack(Js)


@dataclass(frozen=True)
class Identifiability:
    """What the data can see: singular values (descending) of the weighted, column-scaled
    Jacobian of the free parameters, its rank and condition number, the parameters no
    reading depends on (``invisible``), and the unidentifiable combinations, each a list of
    (name, weight) with the weights of one null-space vector."""

    singular_values: tuple[float, ...]
    rank: int
    condition: float
    parameters: int
    readings: int
    invisible: tuple[str, ...]
    combinations: tuple[tuple[tuple[str, float], ...], ...]
    keys: tuple[tuple[str, str, int], ...] = ()  # (component, its key, its coefficients)

    @property
    def identifiable(self) -> bool:
        return not self.invisible and not self.combinations

    def sentences(self) -> list[str]:
        """One sentence per unseen parameter group and combination, in esp's names: the
        coefficients of one component that no reading sees are one sentence, with the key
        the component was asked at."""
        out = []
        keys = {name: (key, n) for name, key, n in self.keys}
        groups: dict[str, list[str]] = {}
        for name in self.invisible:
            head, _, label = name.partition("[")
            groups.setdefault(head if label else name, []).append(name)
        for head, names in groups.items():
            key, n = keys.get(head, ("", 0))
            if key and len(names) == n:  # the whole component
                out.append(f"`{head}` ({key}) is not seen by any reading")
            else:
                out.extend(f"`{name}` is not seen by any reading" for name in names)
        for combo in self.combinations:
            shown = [f"`{n}`" for n, _ in combo[:4]]
            more = f" and {len(combo) - 4} more" if len(combo) > 4 else ""
            if len(combo) == 1:
                out.append(f"{shown[0]} cannot be told from zero")
            else:
                out.append(f"{', '.join(shown[:-1])} and {shown[-1]}{more} are one direction")
        return out


def _reduced_null(N: np.ndarray) -> np.ndarray:
    """A basis of the column space of N (n × k, orthonormal columns: the null space) in
    reduced form, as k rows: each row has weight 1 on its own pivot parameter and 0 on the
    other rows' pivots, so that each names one direction a reading cannot see.

    The k pivots are chosen by a QR factorisation of Nᵀ with column pivoting (Golub & Van
    Loan 2013, 5.4.2): the chosen k × k block of N is as well conditioned as the greedy
    choice allows and never singular for a basis of rank k, so exactly k independent rows
    come out, however small a pivot is (no threshold decides their number)."""
    from scipy.linalg import qr

    k = N.shape[1]
    if k == 0:
        return np.zeros((0, N.shape[0]))
    _, _, piv = qr(N.T, pivoting=True, mode="economic")
    pivots = piv[:k]
    # B = N (N[pivots])⁻¹ spans the same space, with the identity on the pivots
    B = np.linalg.solve(N[pivots].T, N.T)
    B[:, pivots] = np.eye(k)
    return B


def identifiability(
    J: np.ndarray,
    names: tuple[str, ...],
    free: np.ndarray,
    tolerance: float,
    null_space: bool = True,
    r: np.ndarray | None = None,
    keys: tuple[tuple[str, str, int], ...] = (),
) -> tuple[Identifiability, dict[str, Any]]:
    """The identifiability of the free parameters from the weighted Jacobian J; with the
    residuals ``r``, ``info["g"]`` is Uᵀ r (the residuals in the left singular basis)."""
    idx = np.flatnonzero(free)
    Jf = J[:, idx]
    norms = np.linalg.norm(Jf, axis=0)
    zero = norms <= 1e-12 * max(1.0, float(norms.max(initial=0.0)))
    invisible = tuple(names[idx[i]] for i in np.flatnonzero(zero))
    keep = np.flatnonzero(~zero)
    scale = norms[keep]
    Js = Jf[:, keep] / scale
    g = None
    if Js.shape[0] > Js.shape[1] + 1:
        # the R-SVD: a Householder QR of the tall matrix (with r as one more column, so
        # that Qᵀ r comes with it and Q is never formed), then the SVD of its small
        # triangle (Chan 1982; Golub & Van Loan 2013, 5.3.3 and 8.6.3)
        n = Js.shape[1]
        M = Js if r is None else np.column_stack([Js, r])
        R = np.asarray(np.linalg.qr(M, mode="r"))
        Ur, s, Vt = np.linalg.svd(R[:n, :n])
        if r is not None:
            g = Ur.T @ R[:n, n]
    else:
        U, s, Vt = np.linalg.svd(Js, full_matrices=False)
        if r is not None:
            g = U.T @ r
    big = s > tolerance * (s[0] if s.size else 0.0)
    rank = int(big.sum())
    condition = float(s[0] / s[rank - 1]) if rank else float("inf")
    combos = []
    if rank < keep.size and null_space:
        # the null space: right singular vectors beyond the rank, and for m < n the
        # directions that no reading spans
        Vfull = Vt if Js.shape[0] >= Js.shape[1] else np.linalg.svd(Js, full_matrices=True)[2]
        N = Vfull[rank:].T
        # back to parameter units is not needed to name them: the weights are per scaled
        # parameter, which says how strongly each takes part; every one of the n - rank
        # directions is named (its weights below 1e-9 of its largest are round-off)
        for v in _reduced_null(N):
            w = v / np.abs(v).max()
            order = np.argsort(-np.abs(w))
            combo = tuple((names[idx[keep[i]]], float(w[i])) for i in order if abs(w[i]) > 1e-9)
            combos.append(combo)
    info = {
        "idx": idx,
        "keep": keep,
        "scale": scale,
        "g": g,
        "s": s,
        "Vt": Vt,
        "rank": rank,
    }
    return (
        Identifiability(
            tuple(float(v) for v in s),
            rank,
            condition,
            int(idx.size),
            int(J.shape[0]),
            invisible,
            tuple(combos),
            keys,
        ),
        info,
    )


@dataclass(frozen=True)
class Fit:
    """The fitted parameter vector, its covariance (zero rows for fixed or invisible
    parameters), residuals and χ² statistics."""

    x: np.ndarray
    covariance: np.ndarray
    residuals: np.ndarray  # weighted
    chi2: float
    dof: int
    birge: float
    chi2_limit: float
    consistent: bool
    iterations: int
    identifiability: Identifiability


def _covariance(info: Mapping[str, Any], n: int) -> np.ndarray:
    rank = info["rank"]
    V = info["Vt"][:rank].T / info["s"][:rank]
    Cs = V @ V.T
    C = np.zeros((n, n))
    cols = info["idx"][info["keep"]]
    C[np.ix_(cols, cols)] = Cs / np.outer(info["scale"], info["scale"])
    return C


#: the fit stops when the next Gauss-Newton step would move the parameters by less than
#: this share of their standard uncertainty (its predicted fall of χ² is the square)
STEP_TOLERANCE = 1e-5


def fit(
    blocks: list[Block],
    params: Parameters,
    null: str,
    tolerance: float,
    max_iterations: int = MAX_ITERATIONS,
) -> Fit:
    """Fit the parameters to the readings (see the module docstring). Raises
    :class:`IdentifyError` when the data cannot see a combination and ``null`` is
    ``"refuse"``, and when ``max_iterations`` steps end short of the convergence test
    (the next Gauss-Newton step still :data:`STEP_TOLERANCE` or more)."""
    from scipy.special import gammaincinv

    x = params.x0.copy()
    r, J = evaluate(blocks, params, x)
    ident, info = identifiability(J, params.names, params.free, tolerance, r=r, keys=params.keys)
    m = r.size
    if m < ident.parameters and null == "refuse":
        files = ", ".join(dict.fromkeys(b.where[0][0] for b in blocks))
        raise IdentifyError(
            f"{files}: too few readings: {m} residuals for {ident.parameters} free parameters "
            f"(coefficients, placements, centres, stations)"
        )
    if not ident.identifiable and null == "refuse":
        raise IdentifyError(
            "not identifiable: "
            + "; ".join(ident.sentences())
            + " (fix a parameter of each with identify.fix = [...], or choose "
            'identify.null = "minimum-norm"; docs/identify.md)'
        )
    cost = float(r @ r)
    iterations = 0
    info_i = info
    damping = 0.0
    last_step = float("nan")
    for iterations in range(1, max_iterations + 1):  # noqa: B007
        rank = info_i["rank"]
        s, Vt = info_i["s"], info_i["Vt"]
        s_r = s[:rank]
        g = info_i["g"][:rank]
        if iterations > 1 and float(g @ g) < STEP_TOLERANCE**2:
            # the Gauss-Newton step would lower χ² by g·g and move the parameters by
            # about sqrt(g·g) of their standard uncertainty: converged
            break
        accepted = False
        # Levenberg-Marquardt filter factors s²/(s² + λ) on the (truncated) SVD step:
        # λ = 0 is the Gauss-Newton (minimum-norm) step; λ grows until the sum of squares
        # falls (Moré 1978, eq. 2.3)
        for lam in (damping, *(s_r[0] ** 2 * 10.0**e for e in range(-8, 3, 2))):
            if lam < damping:
                continue
            step_s = -(Vt[:rank].T @ (g * s_r / (s_r**2 + lam)))
            step = np.zeros_like(x)
            step[info_i["idx"][info_i["keep"]]] = step_s / info_i["scale"]
            trial = x + step
            r_t, J_t = evaluate(blocks, params, trial)
            if float(r_t @ r_t) <= cost * (1 + 1e-12) + 1e-300:
                accepted = True
                damping = lam / 100.0 if lam > 0 else 0.0
                break
        if not accepted:
            break
        x, r, J = trial, r_t, J_t
        last_step = float(np.linalg.norm(step_s))
        improvement = cost - float(r @ r)
        cost = float(r @ r)
        if np.max(np.abs(step_s), initial=0.0) < 1e-9 or improvement <= 1e-12 * max(cost, 1e-30):
            break
        _, info_i = identifiability(J, params.names, params.free, tolerance, null_space=False, r=r)
    else:
        # every step taken: converged only if the step from the last point passes the test
        g = info_i["g"][: info_i["rank"]]
        next_step = float(np.sqrt(g @ g))
        if not next_step < STEP_TOLERANCE:
            raise IdentifyError(
                f"the fit did not converge in {max_iterations} "
                f"iteration{'' if max_iterations == 1 else 's'}: the last step "
                f"moved the parameters by {last_step:.3g} and the next would move them by "
                f"{next_step:.3g} standard uncertainties (converged below {STEP_TOLERANCE:g}); "
                "raise identify.max_iterations, or start nearer the solution"
            )
    # r and J are those at x: the last accepted trial (or the start)
    ident, info = identifiability(J, params.names, params.free, tolerance, keys=params.keys)
    if not ident.identifiable and null == "refuse":
        # seen at the start but not at the solution: refused as well, never truncated
        raise IdentifyError(
            "not identifiable at the solution: "
            + "; ".join(ident.sentences())
            + " (fix a parameter of each with identify.fix = [...], or choose "
            'identify.null = "minimum-norm"; docs/identify.md)'
        )
    C = _covariance(info, x.size)
    chi2 = float(r @ r)
    dof = int(m - ident.rank)
    birge = float(np.sqrt(chi2 / dof)) if dof > 0 else float("nan")
    # the 97.5 % quantile of χ²(ν): 2 P⁻¹(ν/2, 0.975), P the regularised lower incomplete
    # gamma function (Abramowitz & Stegun 1964, 26.4.19)
    limit = float(2.0 * gammaincinv(dof / 2.0, 0.975)) if dof > 0 else float("nan")
    consistent = bool(dof > 0 and chi2 <= limit)
    return Fit(x, C, r, chi2, dof, birge, limit, consistent, iterations, ident)


def plan_covariance(
    blocks: list[Block], params: Parameters, tolerance: float
) -> tuple[Identifiability, np.ndarray]:
    """Identifiability and the expected covariance from the design alone (no readings)."""
    r, J = evaluate(blocks, params, params.x0, plan=True)
    ident, info = identifiability(J, params.names, params.free, tolerance, keys=params.keys)
    return ident, _covariance(info, params.x0.size)
