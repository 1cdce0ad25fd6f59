"""The statistics of identification's fit (esp.identify.solve) on small linear problems whose
every figure is worked out by hand: the degrees of freedom, χ², the Birge ratio, the 97.5 %
limit of χ², the rank and the condition number of the weighted, column-scaled design.

The Birge ratio alone is a weak witness of the degrees of freedom (a band such as 0.6..1.4
accepts ν off by one or two), so ν is checked as an integer and R_B = sqrt(χ²/ν) to 1e-12.

The problem (u the standard uncertainty of every reading, residual r = (model - reading)/u):

* set 1, a line a + b·t read at t = 0, 1, 2 mm: readings 0, 3, 0 µm;
* set 2, a nuisance offset θ of its own read twice: readings 5, 7 µm.

Least squares, by hand: set 1 alone decides a and b, set 2 alone decides θ.
  t̄ = 1, ȳ = 1; b = Σ(t - t̄)(y - ȳ) / Σ(t - t̄)² = ((-1)(-1) + 0·2 + 1·(-1)) / 2 = 0; a = 1.
  residuals of set 1: 1 - 0, 1 - 3, 1 - 0 = 1, -2, 1 (over u)
  θ = (5 + 7)/2 = 6; residuals of set 2: 1, -1 (over u)
  χ² = (1 + 4 + 1 + 1 + 1) / u² = 8 / u²
  ν = readings - identified parameters = 5 - 3 = 2;  R_B = sqrt(χ²/ν) = 2/u.

The scaled design: columns of J = ∂r/∂(a, b, θ) divided by their length. a's column
(1, 1, 1, 0, 0)/u and b's (0, 1, 2, 0, 0)/u scale to (1, 1, 1)/√3 and (0, 1, 2)/√5, whose
inner product is ρ = 3/√15; θ's column is orthogonal to both. Jsᵀ Js = [[1, ρ, 0], [ρ, 1, 0],
[0, 0, 1]], eigenvalues 1 + ρ, 1, 1 - ρ: singular values sqrt(1 + ρ), 1, sqrt(1 - ρ) and the
condition number sqrt((1 + ρ) / (1 - ρ)) = 2.806 -- whatever the units of the columns.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pytest
from scipy.stats import chi2 as chi2_dist

from esp.identify.solve import IdentifyError, Parameters, fit, identifiability

T_MM = np.array([0.0, 1.0, 2.0])
LINE_UM = np.array([0.0, 3.0, 0.0])
OFFSET_UM = np.array([5.0, 7.0])
RHO = 3.0 / math.sqrt(15.0)
CONDITION = math.sqrt((1.0 + RHO) / (1.0 - RHO))


class LineSet:
    """Set 1: readings of a + b·t (+ extra coefficient columns), no nuisance parameters.
    ``columns`` maps each coefficient to its function of t (µm per unit of it)."""

    def __init__(self, u_um: float, columns: list[np.ndarray]) -> None:
        self.u_um = u_um
        self.columns = columns
        self.names: list[str] = []
        self.theta0 = np.zeros(0)
        self.where = [("line.csv", 2 + i) for i in range(T_MM.size)]

    def evaluate(
        self, c: np.ndarray, theta: np.ndarray, plan: bool
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        design = np.column_stack(self.columns)
        model = design @ c
        readings = np.zeros_like(LINE_UM) if plan else LINE_UM
        return (model - readings) / self.u_um, design / self.u_um, np.zeros((T_MM.size, 0))


class OffsetSet:
    """Set 2: an offset θ of its own, read twice; the coefficients do not enter."""

    def __init__(self, u_um: float, n_coefficients: int) -> None:
        self.u_um = u_um
        self.n = n_coefficients
        self.names = ["theta"]
        self.theta0 = np.zeros(1)
        self.where = [("offset.csv", 2 + i) for i in range(OFFSET_UM.size)]

    def evaluate(
        self, c: np.ndarray, theta: np.ndarray, plan: bool
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        readings = np.zeros_like(OFFSET_UM) if plan else OFFSET_UM
        r = (theta[0] - readings) / self.u_um
        return r, np.zeros((OFFSET_UM.size, self.n)), np.ones((OFFSET_UM.size, 1)) / self.u_um


def problem(
    u_um: float = 1.0, extra: dict[str, np.ndarray] | None = None, fixed: tuple[str, ...] = ()
) -> tuple[list[Any], Parameters]:
    """The two sets and the parameter layout: coefficients a, b (and ``extra``), then θ."""
    columns = {"a": np.ones_like(T_MM), "b": T_MM.copy(), **(extra or {})}
    names = (*columns, "theta")
    blocks = [LineSet(u_um, list(columns.values())), OffsetSet(u_um, len(columns))]
    free = np.array([n not in fixed for n in names])
    n = len(columns)  # each block's nuisance parameters start after the coefficients
    params = Parameters(names, np.zeros(len(names)), free, n, (n, n))
    return blocks, params


@pytest.mark.parametrize("u_um", [1.0, 0.5, 2.0])
def test_dof_chi2_and_birge_ratio_by_hand(u_um: float) -> None:
    blocks, params = problem(u_um)
    f = fit(blocks, params, "refuse", 1e-6)
    np.testing.assert_allclose(f.x, [1.0, 0.0, 6.0], atol=1e-9)
    np.testing.assert_allclose(np.abs(f.residuals) * u_um, [1, 2, 1, 1, 1], atol=1e-9)
    assert f.dof == 2  # 5 readings - 3 parameters, exactly
    assert f.chi2 == pytest.approx(8.0 / u_um**2, rel=1e-12)
    assert f.birge == pytest.approx(2.0 / u_um, rel=1e-12)
    # the 97.5 % quantile of χ²(2) is -2 ln(0.025) = 7.3778 (closed form for ν = 2)
    assert f.chi2_limit == pytest.approx(-2.0 * math.log(0.025), rel=1e-12)
    assert f.consistent is (8.0 / u_um**2 <= -2.0 * math.log(0.025))


def test_a_fixed_parameter_is_not_counted() -> None:
    """b fixed at 0 (its value at the solution anyway): the same χ², one parameter fewer:
    ν = 5 - 2 = 3, R_B = sqrt(8/3), the limit that of χ²(3)."""
    blocks, params = problem(fixed=("b",))
    f = fit(blocks, params, "refuse", 1e-6)
    assert f.dof == 3
    assert f.chi2 == pytest.approx(8.0, rel=1e-12)
    assert f.birge == pytest.approx(math.sqrt(8.0 / 3.0), rel=1e-12)
    assert f.chi2_limit == pytest.approx(chi2_dist.ppf(0.975, 3), rel=1e-9)
    # χ² = 8 lies below the 97.5 % quantile of χ²(3), 9.348
    assert f.consistent is True
    assert f.chi2_limit > 8.0


def test_unseen_directions_leave_the_dof_at_readings_minus_rank() -> None:
    """A coefficient c whose column repeats a's (a + c is one direction), and one, d, no
    reading sees: 5 free coefficients and θ, rank 3. Refused by default; with the
    minimum-norm choice ν = 5 - 3 = 2 and χ² = 8 as before (the fit is the same)."""
    extra = {"c": np.ones_like(T_MM), "d": np.zeros_like(T_MM)}
    blocks, params = problem(extra=extra)
    with pytest.raises(IdentifyError):
        fit(blocks, params, "refuse", 1e-6)
    f = fit(blocks, params, "minimum-norm", 1e-6)
    assert f.identifiability.rank == 3
    assert f.identifiability.parameters == 5
    assert f.identifiability.invisible == ("d",)
    assert f.dof == 2
    assert f.chi2 == pytest.approx(8.0, rel=1e-12)
    assert f.birge == pytest.approx(2.0, rel=1e-12)
    # the minimum-norm split of a + c = 1
    assert f.x[0] == pytest.approx(0.5) and f.x[2] == pytest.approx(0.5)


def design(u_um: float, b_unit: float = 1.0) -> np.ndarray:
    """The weighted Jacobian ∂r/∂(a, b, θ) of the problem, b's column in units ``b_unit``."""
    J = np.zeros((5, 3))
    J[:3, 0] = 1.0
    J[:3, 1] = T_MM * b_unit
    J[3:, 2] = 1.0
    return J / u_um


@pytest.mark.parametrize("b_unit", [1.0, 1e-3, 1e4])
def test_condition_number_of_the_scaled_design(b_unit: float) -> None:
    """sqrt((1 + ρ)/(1 - ρ)), ρ = 3/√15, whatever the unit of b's column (the columns are
    scaled to unit length first); and numpy's condition number of the scaled design."""
    J = design(0.7, b_unit)
    ident, _ = identifiability(J, ("a", "b", "theta"), np.ones(3, dtype=bool), 1e-6)
    assert ident.rank == 3
    assert ident.condition == pytest.approx(CONDITION, rel=1e-12)
    np.testing.assert_allclose(
        ident.singular_values, [math.sqrt(1 + RHO), 1.0, math.sqrt(1 - RHO)], rtol=1e-12
    )
    scaled = J / np.linalg.norm(J, axis=0)
    assert ident.condition == pytest.approx(np.linalg.cond(scaled), rel=1e-12)
    assert ident.readings == 5 and ident.parameters == 3


def test_condition_number_over_the_identified_part_only() -> None:
    """With a column that repeats another, the condition number is that of the rank-3
    part: the largest over the smallest singular value above the tolerance. The scaled
    columns are a, a (each (1, 1, 1)/√3), b, θ: Jsᵀ Js has eigenvalues 0 and those of
    [[2, √2 ρ], [√2 ρ, 1]] and 1, i.e. (3 ± sqrt(1 + 8ρ²))/2."""
    J = np.column_stack([design(1.0)[:, 0], design(1.0)])
    ident, _ = identifiability(J, ("c", "a", "b", "theta"), np.ones(4, dtype=bool), 1e-6)
    assert ident.rank == 3
    root = math.sqrt(1.0 + 8.0 * RHO**2)
    big, small = (3.0 + root) / 2.0, (3.0 - root) / 2.0
    assert ident.condition == pytest.approx(math.sqrt(big / small), rel=1e-9)
    assert len(ident.combinations) == 1
    combo = dict(ident.combinations[0])
    assert set(combo) == {"c", "a"} and combo["c"] == pytest.approx(-combo["a"])


def test_more_coefficients_than_the_line_has_points() -> None:
    """Coefficients of 1, t, t², t³ read at three points: the columns have rank 3, so with
    θ the rank is 4 of 5 free parameters. Refused by default; with the minimum-norm choice
    the cubic passes through the three readings (set 1 fitted exactly), χ² = 2 from set 2
    alone and ν = 5 readings - rank 4 = 1."""
    extra = {"c": T_MM**2, "d": T_MM**3}
    blocks, params = problem(extra=extra)
    with pytest.raises(IdentifyError):
        fit(blocks, params, "refuse", 1e-6)
    f = fit(blocks, params, "minimum-norm", 1e-6)
    assert f.identifiability.rank == 4  # 3 from the line, θ
    assert f.dof == 1
    assert f.chi2 == pytest.approx(2.0, rel=1e-9)
    assert f.birge == pytest.approx(math.sqrt(2.0), rel=1e-9)


def test_the_chi2_limit_at_one_degree_of_freedom() -> None:
    """ν = 1 is a degree of freedom like any other: the limit is the 97.5 % quantile of
    χ²(1), 5.0239 (the square of the normal 98.75 % quantile, 2.2414)."""
    blocks, params = problem(extra={"c": T_MM**2, "d": T_MM**3})
    f = fit(blocks, params, "minimum-norm", 1e-6)
    assert f.dof == 1
    assert f.chi2_limit == pytest.approx(chi2_dist.ppf(0.975, 1), rel=1e-9)
    assert f.chi2_limit == pytest.approx(2.241402727604947**2, rel=1e-9)
    assert f.consistent is True  # χ² = 2 < 5.02


def test_rank_is_decided_relative_to_the_largest_singular_value() -> None:
    """Two unit columns at an angle ε: singular values sqrt(1 ± cos ε), ratio ≈ ε/2. With
    ε = 2e-5 the ratio is 1e-5: rank 2 under a tolerance of 1e-6, rank 1 (and one named
    combination) under 1e-4; the condition number is the ratio's inverse."""
    eps = 2e-5
    J = np.array([[1.0, math.cos(eps)], [0.0, math.sin(eps)], [0.0, 0.0]])
    small, _ = identifiability(J, ("p", "q"), np.ones(2, dtype=bool), 1e-6)
    ratio = math.sqrt((1 - math.cos(eps)) / (1 + math.cos(eps)))
    assert small.rank == 2 and not small.combinations
    assert small.condition == pytest.approx(1.0 / ratio, rel=1e-6)
    large, _ = identifiability(J, ("p", "q"), np.ones(2, dtype=bool), 1e-4)
    assert large.rank == 1
    assert large.condition == 1.0  # the largest over itself: the identified part alone
    assert len(large.combinations) == 1


def test_combinations_are_in_reduced_row_echelon_form() -> None:
    """Three copies of one column and one other: a null space of dimension 2, named as two
    combinations, each with weight 1 on its own pivot parameter and none on the other's
    pivot (so each names two parameters: its pivot and the one left free)."""
    a = np.array([1.0, 1.0, 1.0, 0.0])
    b = np.array([0.0, 1.0, 2.0, 3.0])
    J = np.column_stack([a, 2.0 * a, b, -a])
    ident, _ = identifiability(J, ("p", "q", "r", "s"), np.ones(4, dtype=bool), 1e-6)
    assert ident.rank == 2
    assert len(ident.combinations) == 2
    named = [dict(c) for c in ident.combinations]
    for combo in named:
        assert len(combo) == 2 and "r" not in combo
        assert sorted(abs(w) for w in combo.values()) == pytest.approx([1.0, 1.0])
    # the parameter left free is in both; each pivot in its own combination only
    shared = set(named[0]) & set(named[1])
    assert len(shared) == 1
    assert set(named[0]) | set(named[1]) == {"p", "q", "s"}


def test_sentences_name_each_combination() -> None:
    """A one-parameter combination cannot be told from zero; a longer one is named by its
    first four parameters and the count of the rest."""
    from esp.identify.solve import Identifiability

    five = tuple((f"p{i}", 1.0) for i in range(5))
    ident = Identifiability((1.0,), 1, 1.0, 7, 9, (), ((("q", 1.0),), five[:2], five))
    assert ident.sentences() == [
        "`q` cannot be told from zero",
        "`p0` and `p1` are one direction",
        "`p0`, `p1`, `p2` and `p3` and 1 more are one direction",
    ]


def test_sentences_name_an_unseen_component_once() -> None:
    """Every coefficient of a component unseen: one sentence with the key it was asked at;
    some of them only: one sentence per coefficient."""
    from esp.identify.solve import Identifiability

    keys = (("X.linear", "X.linear = 2", 2), ("Y.linear", "Y.linear = 2", 2))
    unseen = ("X.linear[1]", "X.linear[2]", "Y.linear[2]")
    ident = Identifiability((1.0,), 1, 1.0, 4, 9, unseen, (), keys)
    assert ident.sentences() == [
        "`X.linear` (X.linear = 2) is not seen by any reading",
        "`Y.linear[2]` is not seen by any reading",
    ]


class SquareSet:
    """A nonlinear set: r = (c₁² - 4, c₂ - 1). From c₁ = 0.1 the Gauss-Newton step lands at
    c₁ ≈ 20 and raises the sum of squares, so the fit must damp its steps."""

    names: list[str] = []
    theta0 = np.zeros(0)
    where = [("square.csv", 2), ("square.csv", 3)]

    def evaluate(
        self, c: np.ndarray, theta: np.ndarray, plan: bool
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        r = np.array([c[0] ** 2 - 4.0, c[1] - 1.0])
        return r, np.array([[2.0 * c[0], 0.0], [0.0, 1.0]]), np.zeros((2, 0))


@pytest.mark.parametrize("start", [0.1, 0.01, 50.0])
def test_a_damped_fit_reaches_the_solution(start: float) -> None:
    params = Parameters(("c1", "c2"), np.array([start, 0.0]), np.ones(2, dtype=bool), 2, (2,))
    blocks: list[Any] = [SquareSet()]  # duck-typed blocks: evaluate, names, theta0, where
    f = fit(blocks, params, "refuse", 1e-6)
    np.testing.assert_allclose(f.x, [2.0, 1.0], atol=1e-5)
    assert f.chi2 < 1e-9 and f.dof == 0
    assert math.isnan(f.birge) and math.isnan(f.chi2_limit) and f.consistent is False


class VanishingSet:
    """r = (c₂, c₁·c₂): seen at the start (1, 1), where J = [[0, 1], [1, 1]]; one
    Gauss-Newton step (δ₂ = -1, δ₁ = 0) reaches r = 0 at (1, 0), where c₁'s column
    [0, c₂] is zero: no reading sees c₁ there any more."""

    names: list[str] = []
    theta0 = np.zeros(0)
    where = [("vanishing.csv", 2), ("vanishing.csv", 3)]

    def evaluate(
        self, c: np.ndarray, theta: np.ndarray, plan: bool
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        r = np.array([c[1], c[0] * c[1]])
        return r, np.array([[0.0, 1.0], [c[1], c[0]]]), np.zeros((2, 0))


def test_a_parameter_unseen_at_the_solution_is_refused() -> None:
    params = Parameters(("c1", "c2"), np.array([1.0, 1.0]), np.ones(2, dtype=bool), 2, (2,))
    blocks: list[Any] = [VanishingSet()]
    with pytest.raises(IdentifyError, match="not identifiable at the solution: `c1`"):
        fit(blocks, params, "refuse", 1e-6)
    f = fit(blocks, params, "minimum-norm", 1e-6)
    np.testing.assert_allclose(f.x, [1.0, 0.0], atol=1e-12)
    assert f.identifiability.invisible == ("c1",)
    assert f.dof == 1  # 2 readings, rank 1


class RosenbrockSet:
    """r = (10 (c₂ - c₁²), 1 - c₁) (Rosenbrock 1960): χ² = 0 at (1, 1) only, reached from
    (-1.2, 1) along a curved valley in some 60 damped steps -- more than the default cap."""

    names: list[str] = []
    theta0 = np.zeros(0)
    where = [("valley.csv", 2), ("valley.csv", 3)]

    def evaluate(
        self, c: np.ndarray, theta: np.ndarray, plan: bool
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        r = np.array([10.0 * (c[1] - c[0] ** 2), 1.0 - c[0]])
        return r, np.array([[-20.0 * c[0], 10.0], [-1.0, 0.0]]), np.zeros((2, 0))


def _valley() -> tuple[list[Any], Parameters]:
    params = Parameters(("c1", "c2"), np.array([-1.2, 1.0]), np.ones(2, dtype=bool), 2, (2,))
    return [RosenbrockSet()], params


def test_a_fit_that_reaches_its_cap_unconverged_is_refused() -> None:
    """50 steps end half way along the valley (near (0.7, 0.5), χ² about 0.08): refused with
    the count, the last step and the key that raises the cap, not reported as a fit."""
    blocks, params = _valley()
    with pytest.raises(IdentifyError) as info:
        fit(blocks, params, "refuse", 1e-6)
    message = str(info.value)
    assert "did not converge in 50 iterations" in message
    assert "identify.max_iterations" in message and "the last step moved" in message
    f = fit(blocks, params, "refuse", 1e-6, max_iterations=1000)
    np.testing.assert_allclose(f.x, [1.0, 1.0], atol=1e-7)
    assert 50 < f.iterations < 1000


def test_a_fit_converged_at_its_last_allowed_step_is_accepted() -> None:
    """``iterations`` is the pass whose convergence test stopped the fit, after
    ``iterations - 1`` steps: a cap of exactly that many steps converges (the test is made
    after the last step too), one step fewer does not."""
    blocks, params = _valley()
    steps = fit(blocks, params, "refuse", 1e-6, max_iterations=1000).iterations - 1
    f = fit(blocks, params, "refuse", 1e-6, max_iterations=steps)
    np.testing.assert_allclose(f.x, [1.0, 1.0], atol=1e-7)
    with pytest.raises(IdentifyError, match=f"did not converge in {steps - 1} iterations"):
        fit(blocks, params, "refuse", 1e-6, max_iterations=steps - 1)
