"""The null space of an identification's design is named whole: exactly n - rank
combinations, independent, each in the null space (esp.identify.solve.identifiability;
docs/identify.md, "the identifiability of a plan")."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from esp.identify.solve import identifiability


@settings(max_examples=20, deadline=None, derandomize=True)
@given(
    n=st.integers(2, 9),
    unseen=st.integers(1, 4),
    extra_rows=st.integers(0, 4),
    seed=st.integers(0, 2**32 - 1),
    spread=st.floats(0.0, 4.0),
)
def test_every_direction_of_the_null_space_is_named_once(
    n: int, unseen: int, extra_rows: int, seed: int, spread: float
) -> None:
    """Random rank-deficient designs whose unseen directions mix parameters of very
    different weight (a null space drawn with rows over ``spread`` decades, so that the
    pivots of a reduced form are of all sizes): exactly n - rank combinations are named,
    as independent vectors, and the scaled design times each is ~0 -- with the weights as
    named, nothing of a combination left out."""
    k = min(unseen, n - 1)
    rng = np.random.default_rng(seed)
    N0 = rng.standard_normal((n, k)) * 10.0 ** rng.uniform(-spread, 0.0, (n, 1))
    Q = np.linalg.qr(N0)[0]
    rows = n - k + extra_rows
    J = rng.standard_normal((rows, n)) @ (np.eye(n) - Q @ Q.T)
    names = tuple(f"p{i}" for i in range(n))
    ident, _ = identifiability(J, names, np.ones(n, dtype=bool), 1e-9)
    assert not ident.invisible  # every column is seen (a zero column is named whole)
    assert ident.rank == n - k
    assert len(ident.combinations) == n - ident.rank
    V = np.zeros((n, k))
    for j, combo in enumerate(ident.combinations):
        for name, w in combo:
            V[int(name[1:]), j] = w
    assert np.linalg.matrix_rank(V, tol=1e-6) == k
    scaled = J / np.linalg.norm(J, axis=0)
    assert np.abs(scaled @ V).max() <= 1e-7 * np.abs(V).max()
