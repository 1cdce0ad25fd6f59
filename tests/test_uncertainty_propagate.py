"""Volumetric uncertainty (Longstaff 2002, 3.14.7 and 4.01) and its Monte Carlo check."""

from __future__ import annotations

import math

import numpy as np
import pytest

from esp.config import machine_from_dict
from esp.core.analysis import analyse
from esp.core.errors import ConfigError
from esp.core.uncertainty.propagate import montecarlo_errors, volumetric_uncertainty

AXES3 = ("X", "Y", "Z")


def study(offset: float, method: str, with_errors: bool = False, **extra) -> dict:
    """The file set of thesis 4.01.2.1 as U curves on a 1 m wBMTt gantry (bottom X, middle
    Y, top Z): linear 0/4/8 µm at 0/500/1000 mm (8 µm/m), angular 4 µm/m, straightness a
    trapezoid that the end-point fit turns into 4 µm, squareness 10 µm/m."""
    comps = {}
    for a in AXES3:
        comps[f"{a}.linear"] = {"U": {"points": [[0, 0.0], [500, 4.0], [1000, 8.0]]}}
        for b in AXES3:
            if b != a:
                comps[f"{a}.straightness.{b}"] = {
                    "U": {"points": [[-0.001, 0], [0, 4], [500, 4], [1000, 4], [1000.001, 0]]}
                }
            comps[f"{a}.angular.{b}"] = {"U": 4.0}
    for p in ("XY", "XZ", "YZ"):
        comps[f"squareness.{p}"] = {"U": 10.0}
    data = {
        "machine": {
            "name": "4.01",
            "configuration": "wBMTt",
            "axes": {"bottom": "X", "middle": "Y", "top": "Z"},
        },
        # thesis tables 4.3/4.4 combine the U with the printed eq. 3.1 and its signs
        "analysis": {
            "straightness_fit": "endpoint",
            "direction": "forward",
            "model": "as-printed",
            "angle_convention": "thesis",
        },
        "axes": {a: {"travel": [0, 1000], "step": 50, "offset": offset} for a in AXES3},
        "uncertainty": {"method": method, "components": comps, **extra},
    }
    if with_errors:
        data["axes"]["X"]["errors"] = {"linear": {"points": [[0, 0.0], [1000, 12.0]]}}
    return data


def run(data: dict):
    return analyse(machine_from_dict(data, ".")).uncertainty


@pytest.mark.parametrize(
    "offset, method, printed",
    [
        (0.0, "pure-addition", 60.0),  # table 4.3, measured at the origin, 1 m³
        (500.0, "pure-addition", 43.0),  # table 4.3, measured centrally, 1 m³
        (0.0, "statistical", 26.2),  # table 4.4, measured at the origin, 1 m³
        (500.0, "statistical", 19.7),  # table 4.4, measured centrally, 1 m³
    ],
)
def test_thesis_tables_4_3_and_4_4(offset, method, printed):
    u = run(study(offset, method))
    assert round(u.volumetric.value_um, 1) == printed
    assert u.volumetric.at == {"X": 1000.0, "Y": 1000.0, "Z": 1000.0}


@pytest.mark.parametrize(
    "offset, method, printed",
    [(0.0, "pure-addition", 60.0), (500.0, "pure-addition", 43.0), (0.0, "statistical", 26.2)]
    + [(500.0, "statistical", 19.7)],
)
def test_thesis_1_m3_figures_hold_with_the_linear_u_held_along_the_axis(offset, method, printed):
    # the reading that reproduces the 0.3 m³ figures (linear U = 8 µm at every position)
    # gives the 1 m³ figures too: their maxima lie where the 0 -> 8 µm curve reaches 8
    data = study(offset, method)
    for a in AXES3:
        data["uncertainty"]["components"][f"{a}.linear"] = {"U": 8.0}
    assert round(run(data).volumetric.value_um, 1) == printed


def test_statistical_by_hand_at_the_far_corner():
    # eq. 3.1 at (1000, 1000, 1000), offsets 0: the U terms acting in each direction
    #   X: 8 (lin) 4 4 (strt) 4 4 4 (Φ_M(B)·T, Φ_M(M)·T, Φ_T(B)·M) 10 10 (squareness)
    #   Y: 8 4 4 4 4 10          Z: 8 4 4 4
    x2 = 64 + 16 + 16 + 16 + 16 + 16 + 100 + 100
    y2 = 64 + 16 + 16 + 16 + 16 + 100
    z2 = 64 + 16 + 16 + 16
    u = run(study(0.0, "statistical"))
    assert u.volumetric.value_um == pytest.approx(math.sqrt(x2 + y2 + z2))
    assert u.axes["X"].value_um == pytest.approx(math.sqrt(x2))
    assert u.axes["Z"].value_um == pytest.approx(math.sqrt(z2))
    # budget: each component's squares over the total; squareness.XY: 100 / 684
    shares = {b.component: b.share_pct for b in u.budget}
    assert shares["squareness.XY"] == pytest.approx(100 * 100 / (x2 + y2 + z2))
    assert sum(shares.values()) == pytest.approx(100.0)
    assert [b.share_pct for b in u.budget] == sorted((b.share_pct for b in u.budget), reverse=True)


@pytest.mark.parametrize("method", ["summation", "pure-addition"])
def test_summation_budget_adds_to_100(method):
    u = run(study(500.0, method))
    assert sum(b.share_pct for b in u.budget) == pytest.approx(100.0)


def test_planning_study_needs_no_error_data_and_errors_do_not_change_u():
    a = run(study(0.0, "statistical"))
    b = run(study(0.0, "statistical", with_errors=True))
    assert a.volumetric.value_um == pytest.approx(b.volumetric.value_um)


def test_montecarlo_at_one_point_agrees_with_the_statistical_method():
    # a single-point grid at (800, 600, 400), offsets 0: per direction k·s(draws) against
    # the root-sum-square of the U terms acting in that direction
    data = study(0.0, "montecarlo", samples=20000, seed=3)
    point = {"X": 800.0, "Y": 600.0, "Z": 400.0}
    machine = machine_from_dict(data, ".")
    draws = montecarlo_errors(machine, machine.uncertainty, point)
    assert draws.shape == (20000, 3)
    lin = {"X": 6.4, "Y": 4.8, "Z": 3.2}  # 8 µm/m · position
    # X: lin, 2 strt 4, Φ_M(B)·z, Φ_M(M)·z = 4·0.4, Φ_T(B)·y = 4·0.6, sqr XZ·z = 4, sqr XY·y = 6
    rss = {
        "X": math.sqrt(lin["X"] ** 2 + 32 + 2 * 1.6**2 + 2.4**2 + 4.0**2 + 6.0**2),
        # Y: lin, 2 strt, Φ_B(B)·z, Φ_B(M)·z = 1.6 each, sqr YZ·z = 4
        "Y": math.sqrt(lin["Y"] ** 2 + 32 + 2 * 1.6**2 + 4.0**2),
        # Z: lin, 2 strt, Φ_B(B)·y = 2.4
        "Z": math.sqrt(lin["Z"] ** 2 + 32 + 2.4**2),
    }
    rel = 3 / math.sqrt(2 * (20000 - 1))  # three standard errors of a standard deviation
    for d, axis in enumerate(AXES3):
        assert 2.0 * draws[:, d].std(ddof=1) == pytest.approx(rss[axis], rel=rel)
        assert abs(draws[:, d].mean()) < 3 * rss[axis] / 2 / math.sqrt(20000)


@pytest.mark.slow
def test_montecarlo_is_reproducible_with_its_seed():
    data = study(0.0, "montecarlo", samples=400, seed=11)
    a = run(data).montecarlo
    b = run(data).montecarlo
    assert np.array_equal(a.values_um, b.values_um) and a.seed == 11
    data["uncertainty"]["seed"] = 12
    c = run(data).montecarlo
    assert not np.array_equal(c.values_um, a.values_um)
    lo, hi = a.interval_um
    assert lo <= a.mean_um <= hi and a.samples == 400 and len(a.values_um) == 400


def test_montecarlo_distribution_is_centred_near_the_best_estimate():
    # all U zero but one: the volumetric accuracy of X.linear alone (12 µm at x = 1000)
    # varies with the X.linear draw: mean ~ 12, k·s ~ U of the end (8 µm)
    data = study(0.0, "montecarlo", with_errors=True, samples=4000, seed=5)
    data["uncertainty"]["components"] = {"X.linear": {"U": {"points": [[0, 0], [1000, 8.0]]}}}
    mc = run(data).montecarlo
    assert mc.mean_um == pytest.approx(12.0, abs=0.3)
    assert 2 * mc.std_um == pytest.approx(8.0, rel=0.06)


def test_prior_updates_the_result_by_eq_3_22_to_3_24():
    # planning study of X.linear only: U = 8 at x = 1000 -> u_cm = 4; errors give 12 µm.
    # prior y_pe = 10, u_pe = 3: γ = 3/4, y = 12·γ²/(1+γ²) + 10/(1+γ²) = 12·0.36 + 10·0.64
    # = 10.72; 1/u_c² = 1/16 + 1/9 -> u_c = 2.4, U = 4.8; ΔU = 8·(1 - sqrt(0.36)) = 3.2
    data = study(0.0, "statistical", with_errors=True, prior={"volumetric_um": 10.0, "u_um": 3.0})
    data["uncertainty"]["components"] = {"X.linear": {"U": {"points": [[0, 0], [1000, 8.0]]}}}
    p = run(data).prior
    assert p["accuracy_um"] == pytest.approx(10.72)
    assert p["U_um"] == pytest.approx(4.8)
    assert p["delta_U_um"] == pytest.approx(3.2)


def test_instrument_component_matches_the_model_called_directly():
    from esp.core.uncertainty.instruments import square

    data = study(0.0, "statistical")
    data["uncertainty"]["components"] = {
        "squareness.XY": {
            "instrument": "square",
            "measuring_length_mm": 500.0,
            "edge_a_um": 1.0,
            "edge_b_um": 1.5,
            "squareness_um_per_m": 2.0,
        }
    }
    expected = square(
        measuring_length_mm=500.0, edge_a_um=1.0, edge_b_um=1.5, squareness_um_per_m=2.0, k=2.0
    )
    u = run(data)
    (line,) = u.budget
    assert (line.model, line.unit) == ("square", "um/m") and pytest.approx(expected.U) == line.U
    # squareness XY acts as BM_sqr·M in X: U·y/1000, largest at y = 1000
    assert u.volumetric.value_um == pytest.approx(expected.U)


@pytest.mark.parametrize(
    "component, key",
    [
        ({"X.linear": {"U": -1.0}}, 'uncertainty.components."X.linear".U'),
        (
            {"X.linear": {"instrument": "laser-nonsense"}},
            'uncertainty.components."X.linear".instrument',
        ),
        (
            {"squareness.XY": {"instrument": "square", "edge_a_um": 1.0}},
            'uncertainty.components."squareness.XY"',
        ),
        (
            {"X.linear": {"instrument": "laser-linear", "colour": 1}},
            'uncertainty.components."X.linear".colour',
        ),
        ({"X.lnear": {"U": 1.0}}, "uncertainty.components.X.lnear"),
        ({"X.linear": {}}, 'uncertainty.components."X.linear".U'),
    ],
)
def test_bad_uncertainty_config_names_the_key(component, key):
    data = study(0.0, "statistical")
    data["uncertainty"]["components"] = component
    with pytest.raises(ConfigError) as err:
        machine_from_dict(data, ".")
    assert err.value.key.startswith(key)


def test_bad_method_and_k():
    data = study(0.0, "statistical")
    data["uncertainty"]["method"] = "guess"
    with pytest.raises(ConfigError, match="uncertainty.method"):
        machine_from_dict(data, ".")
    data = study(0.0, "statistical", k=0)
    with pytest.raises(ConfigError, match="uncertainty.k"):
        machine_from_dict(data, ".")


def test_without_uncertainty_table_there_is_none():
    data = study(0.0, "statistical")
    del data["uncertainty"]
    assert analyse(machine_from_dict(data, ".")).uncertainty is None


def test_library_entry_point_matches_the_analysis():
    machine = machine_from_dict(study(500.0, "statistical"), ".")
    direct = volumetric_uncertainty(machine, machine.uncertainty)
    assert direct.volumetric.value_um == pytest.approx(
        run(study(500.0, "statistical")).volumetric.value_um
    )


def test_montecarlo_runs_on_the_worst_tool_case():
    # Z.angular.Y = 10 µm/m acts only through the tool (-Φ_M(T)·T_o in X, eq. 3.10); tool
    # lengths 0 and 500 mm along Z: the worst case is 500 mm with 10·500/1000 = 5 µm. With
    # a tiny U elsewhere the draws stay at 5 µm: they must be of that case, not of L = 0.
    data = study(0.0, "montecarlo", samples=300, seed=2)
    data["axes"]["Z"]["errors"] = {"angular": {"Y": {"constant": 10.0}}}
    data["analysis"]["point"] = "TCP"
    data["tool"] = {"lengths": [0, 500], "orientation": {"tilt": 0, "spin": 0}}
    # 0.01 µm/m of Z.angular.Y moves the 500 mm tool tip by 0.005 µm
    data["uncertainty"]["components"] = {"X.linear": {"U": 0.01}, "Z.angular.Y": {"U": 0.01}}
    res = analyse(machine_from_dict(data, "."))
    assert res.cases[res.worst].volumetric.value_um == pytest.approx(5.0)
    assert res.uncertainty.montecarlo.mean_um == pytest.approx(5.0, abs=0.01)


# -- issue 10, item 1: a U curve is used exactly as given ---------------------------------


def lone(component: str, U, **analysis) -> dict:
    """The study gantry (offsets 0) with one component's uncertainty only."""
    data = study(0.0, "statistical")
    data["analysis"] = {k: v for k, v in data["analysis"].items() if k in ("model",)}
    data["analysis"].update(analysis)
    data["uncertainty"]["components"] = {component: {"U": U}}
    return data


@pytest.mark.parametrize("fit", ["least-squares", "endpoint"])
@pytest.mark.parametrize("direction", ["mean", "forward", "backward"])
def test_straightness_u_curve_keeps_its_slope(fit, direction):
    # U of X.straightness.Y rising 0 -> 8 µm along X: a measurement's straightness would
    # lose this line to the slope removal; an uncertainty must not. Alone, it acts in Y
    # with lever 1: the volumetric U is 8 µm at X = 1000, and the budget says the same.
    data = lone(
        "X.straightness.Y",
        {"points": [[0, 0.0], [1000, 8.0]]},
        straightness_fit=fit,
        direction=direction,
    )
    u = run(data)
    assert u.volumetric.value_um == pytest.approx(8.0)
    assert u.volumetric.at["X"] == 1000.0
    (line,) = u.budget
    assert (line.U, line.U_max, line.share_pct) == (pytest.approx(8.0), 8.0, 100.0)
    assert line.contribution_um * u.k == pytest.approx(u.volumetric.value_um)


def test_u_curve_from_a_file_is_the_mean_of_its_runs_whatever_the_direction(tmp_path):
    # a U file with a forward run 0, 4, 8 and a backward run 0, 2, 4: the U is their mean
    # 0, 3, 6 for every analysis.direction (no run is chosen for an uncertainty)
    (tmp_path / "u.csv").write_text(
        "target_mm,run,direction,deviation\n"
        + "".join(
            f"{p},{r},{d},{v}\n"
            for r, d, vals in ((1, "forward", (0, 4, 8)), (2, "backward", (0, 2, 4)))
            for p, v in zip((0, 500, 1000), vals, strict=True)
        ),
        encoding="utf-8",
    )
    for direction in ("mean", "forward", "backward"):
        data = lone("X.linear", {"file": "u.csv"}, direction=direction)
        u = analyse(machine_from_dict(data, tmp_path)).uncertainty
        assert u.volumetric.value_um == pytest.approx(6.0)
        assert pytest.approx(6.0) == u.budget[0].U


# -- issue 10, item 2: the budget's U is the U where the budget is evaluated ----------------


def test_budget_u_is_the_u_at_the_budget_point():
    # X.linear U falls 8 -> 0 along X (largest at X = 0); X.straightness.Y rises 0 -> 10.
    # u² = (8 (1 - x/1000))² + (10 x/1000)² is largest at x = 1000 (100 > 64), where the
    # U of X.linear is 0 -- as its share says -- although its largest U is 8.
    data = lone("X.linear", {"points": [[0, 8.0], [1000, 0.0]]})
    data["uncertainty"]["components"]["X.straightness.Y"] = {
        "U": {"points": [[0, 0.0], [1000, 10.0]]}
    }
    u = run(data)
    assert u.budget_at["X"] == 1000.0 and u.volumetric.value_um == pytest.approx(10.0)
    lines = {b.component: b for b in u.budget}
    assert (lines["X.linear"].U, lines["X.linear"].U_max) == (0.0, 8.0)
    assert lines["X.linear"].share_pct == 0.0
    assert pytest.approx(10.0) == lines["X.straightness.Y"].U
    assert lines["X.straightness.Y"].share_pct == pytest.approx(100.0)


def test_budget_of_the_shipped_statistical_study_shows_every_u_at_its_point():
    # a U curve read anywhere but at the budget point would show U = 0.000 beside shares of
    # 2-9 %: every line with a share must show a U > 0, equal to the component's U at the
    # budget point, and the lines must add up to the total.
    from pathlib import Path

    from esp.config import load_machine

    path = Path(__file__).resolve().parent.parent / "data/examples/uncertainty-study"
    machine = load_machine(path / "machine-statistical.toml")
    u = analyse(machine).uncertainty
    assert u.budget_at == {"X": 1000.0, "Y": 1000.0, "Z": 1000.0}
    assert len(u.budget) == 21
    for b in u.budget:
        cu = machine.uncertainty.components[b.component]
        at = u.budget_at[cu.axis] if cu.axis else None
        assert pytest.approx(cu.U_at(at)) == b.U
        assert b.share_pct == 0.0 or b.U > 0, b.component
        assert b.u == pytest.approx(b.U / b.k) and b.k == 2.0
    expected = {"X.linear": 8.0, "X.straightness.Y": 4.0, "X.angular.Z": 4.0}
    assert {b.component: b.U for b in u.budget if b.component in expected} == expected
    total = math.sqrt(math.fsum(b.contribution_um**2 for b in u.budget))
    assert u.k * total == pytest.approx(u.volumetric.value_um)
    assert u.u_um == pytest.approx(total)


# -- issue 10, item 3: standard uncertainties combined, expanded once ---------------------


def three_linears(method: str = "statistical", **extra) -> dict:
    """Three constant linear uncertainties, each acting alone in its own direction (lever
    1): X.linear U = 6 µm with k = 3, Y.linear U = 3 µm with k = 2 and 4 degrees of
    freedom (a Type A part from five runs), Z.linear U = 2 µm (the table's k = 2)."""
    data = study(0.0, method, **extra)
    data["uncertainty"]["components"] = {
        "X.linear": {"U": 6.0, "k": 3.0},
        "Y.linear": {"U": 3.0, "k": 2.0, "dof": 4},
        "Z.linear": {"U": 2.0},
    }
    return data


def test_unequal_coverage_factors_combine_as_standard_uncertainties():
    # u = 6/3 = 2, 3/2 = 1.5, 2/2 = 1 µm; u_c = sqrt(4 + 2.25 + 1) = sqrt(7.25) = 2.6926;
    # U = k u_c = 2 x 2.6926 = 5.385 µm (the root-sum-square of the U's, sqrt(49) = 7,
    # would overstate it). ν_eff = u_c⁴ / (1.5⁴ / 4) = 52.5625 / 1.265625 = 41.53.
    u = run(three_linears())
    assert u.u_um == pytest.approx(math.sqrt(7.25))
    assert u.volumetric.value_um == pytest.approx(2.0 * math.sqrt(7.25))
    assert u.k == 2.0 and u.coverage is None
    assert u.dof_eff == pytest.approx(52.5625 / 1.265625)
    lines = {b.component: b for b in u.budget}
    assert (lines["X.linear"].k, lines["X.linear"].u) == (3.0, 2.0)
    assert (lines["Y.linear"].dof, lines["Y.linear"].type_a) == (4.0, True)
    assert math.isinf(lines["Z.linear"].dof) and not lines["Z.linear"].type_a
    assert lines["X.linear"].share_pct == pytest.approx(100 * 4 / 7.25)
    assert all(b.distribution == "normal" for b in u.budget)


def test_coverage_probability_takes_k_from_student_t():
    # coverage 0.95 with ν_eff = 41.53 -> 41 (GUM G.4.1): t_95(41) = 2.0195 (t-table)
    u = run(three_linears(coverage=0.95))
    assert u.coverage == 0.95
    assert u.k == pytest.approx(2.0195, abs=1e-4)
    assert u.volumetric.value_um == pytest.approx(u.k * math.sqrt(7.25))
    assert u.axes["Y"].value_um == pytest.approx(u.k * 1.5)
    # without a Type A component ν_eff is infinite: k = z_95 = 1.960
    data = three_linears(coverage=0.95)
    del data["uncertainty"]["components"]["Y.linear"]["dof"]
    u = run(data)
    assert math.isinf(u.dof_eff) and u.k == pytest.approx(1.95996, abs=1e-5)


def test_prior_uses_the_coverage_factor_of_the_result():
    # u_cm = U / k of the result: with coverage 0.95 the k is t_95(41), not the table's 2
    data = three_linears(coverage=0.95, prior={"volumetric_um": 3.0, "u_um": 1.0})
    u = run(data)
    u_c = 1.0 / math.sqrt(1.0 / 7.25 + 1.0)  # eq. 3.23 with u_cm = sqrt(7.25), u_pe = 1
    assert u.prior["U_um"] == pytest.approx(u.k * u_c)


def test_instrument_with_a_type_a_part_carries_its_degrees_of_freedom():
    # X.angular.Y from two levels with five runs each way: its drift line is Type A with
    # 4 degrees of freedom; the component's ν = u_c⁴ / (u_A⁴ / 4) (GUM G.4.1)
    from esp.core.uncertainty.instruments import level_differential

    params = {
        "measuring_length_mm": 1000.0,
        "max_angle_um_per_m": 3.0,
        "unit_uncertainty_um_per_m": 1.0,
        "footprint_length_mm": 200.0,
        "run_std_um_per_m": 2.0,
        "runs": 5,
    }
    model = level_differential(**params)
    u_a = 2.0 / math.sqrt(5)
    u_c = model.u
    assert model.contributions[-1].dof == 4.0
    assert model.dof == pytest.approx(u_c**4 / (u_a**4 / 4.0))
    data = study(0.0, "statistical")
    data["uncertainty"]["components"] = {
        "X.angular.Y": {"instrument": "level-differential", **params}
    }
    (line,) = run(data).budget
    assert line.dof == pytest.approx(model.dof) and line.distribution == "rectangular"
    assert line.model == "level-differential" and pytest.approx(model.U) == line.U


def test_summation_expands_the_bound_of_standard_uncertainties():
    # summation with unequal k: k · Σ |c| · u; with one term per direction it is
    # k sqrt(Σ u²) again: 2 sqrt(7.25); no degrees of freedom for a bound
    u = run(three_linears(method="summation"))
    assert u.volumetric.value_um == pytest.approx(2.0 * math.sqrt(7.25))
    assert u.u_um == pytest.approx(math.sqrt(7.25))
    assert u.dof_eff is None


# -- issue 10, item 4: the 0.3 m³ figures of tables 4.3 and 4.4 ----------------------------


def cube_300(offset: float, method: str, model: str, datum: str = "none") -> dict:
    """A 300 mm cube from the origin of the study gantry, every component with the U of
    its 1 m measurement (table 4.2) held along the axis: linear 8 µm, straightness 4 µm,
    angular 4 µm/m, squareness 10 µm/m."""
    data = study(offset, method)
    for a in AXES3:
        data["axes"][a].update(travel=[0, 300], step=25)
        data["uncertainty"]["components"][f"{a}.linear"] = {"U": 8.0}
    data["analysis"] = {"model": model, "datum": datum}
    if model == "as-printed":
        data["analysis"]["angle_convention"] = "thesis"
    return data


@pytest.mark.parametrize("model", ["as-printed", "rigid-body"])
@pytest.mark.parametrize(
    "offset, printed, at",
    [
        # table 4.4, 0.3 m³, measured at the origin: at (0, 300, 300), levers 0.3 m:
        # X² = 8² + 2·4² + 3·1.2² + 2·3² = 118.32, Y² = 64 + 32 + 2·1.2² + 3² = 107.88,
        # Z² = 64 + 32 + 1.2² = 97.44; sqrt(323.64) = 17.99
        (0.0, 18.0, {"X": 0.0, "Y": 300.0, "Z": 300.0}),
        # measured centrally: at the origin every lever is -0.5 m: X² = 64 + 32 + 3·2² +
        # 2·5² = 158, Y² = 64 + 32 + 2·2² + 5² = 129, Z² = 64 + 32 + 2² = 100; sqrt(387)
        (500.0, 19.7, {"X": 0.0, "Y": 0.0, "Z": 0.0}),
    ],
)
def test_thesis_table_4_4_for_the_0_3_m3_volume(model, offset, printed, at):
    # the statistical method squares every term: the model's signs do not matter
    u = run(cube_300(offset, "statistical", model))
    assert round(u.volumetric.value_um, 1) == printed
    assert u.volumetric.at == at


@pytest.mark.parametrize("offset", [0.0, 500.0])
def test_thesis_table_4_3_for_the_0_3_m3_volume(offset):
    # pure addition with the printed eq. 3.1, errors referred to a datum at the origin:
    # the constant terms cancel against the datum and the levers become the coordinates,
    # whatever the offsets. At (0, 300, 300): X = 3·1.2 + 2·3 = 9.6, Y = 2·1.2 + 3 = 5.4,
    # Z = -1.2 µm; sqrt(92.16 + 29.16 + 1.44) = sqrt(122.76) = 11.08 (table 4.3: 11.1)
    u = run(cube_300(offset, "pure-addition", "as-printed", datum="negative"))
    assert round(u.volumetric.value_um, 1) == 11.1
    assert u.volumetric.value_um == pytest.approx(math.sqrt(122.76))


@pytest.mark.parametrize("model", ["as-printed", "rigid-body"])
@pytest.mark.parametrize("offset", [0.0, 500.0])
def test_summation_bound_with_a_datum_for_the_0_3_m3_volume(model, offset):
    # the bound referred to the datum at the origin: each term less its datum value, then
    # its absolute value. Linear and straightness U are constant (they cancel); each
    # angular and squareness term is U times its lever's travel from the origin, >= 0 in
    # the cube: X = 3·4·0.3 + 2·10·0.3 = 9.6, Y = 2·1.2 + 3 = 5.4, Z = 1.2 (pure addition
    # had -1.2: the same square) at (0, 300, 300): sqrt(122.76) = 11.08, whatever the
    # offsets and the model's signs
    u = run(cube_300(offset, "summation", model, datum="negative"))
    assert u.volumetric.value_um == pytest.approx(math.sqrt(122.76))
    assert u.axes["Z"].value_um == pytest.approx(1.2)
    assert all(b.share_pct >= 0.0 for b in u.budget)


# -- issue 17, item 3: summation is a bound -------------------------------------------------


@pytest.mark.parametrize("model", ["rigid-body", "as-printed"])
@pytest.mark.parametrize("convention", ["iso230-1", "thesis"])
def test_summation_is_the_bound_at_the_far_corner_whatever_the_signs(model, convention):
    # the planning study (1 m wBMTt, offsets 0): at (1000, 1000, 1000) every lever is 1 m
    # and every term is U times 1, whatever its sign in the model:
    #   X: 8 (lin) + 4 + 4 (strt) + 4 + 4 + 4 (angles) + 10 + 10 (squareness) = 48
    #   Y: 8 + 4 + 4 + 4 + 4 + 10 = 34        Z: 8 + 4 + 4 + 4 = 20
    # sqrt(48² + 34² + 20²) = sqrt(3860) = 62.129 µm. Adding with the signs gave 48.2 µm
    # (rigid-body, ISO 230-1) or 60.0 µm (printed signs): both are below the bound.
    data = study(0.0, "summation")
    data["analysis"].update(model=model, angle_convention=convention)
    u = run(data)
    assert u.volumetric.value_um == pytest.approx(math.sqrt(3860.0))
    assert u.volumetric.at == {"X": 1000.0, "Y": 1000.0, "Z": 1000.0}
    assert {a: e.value_um for a, e in u.axes.items()} == pytest.approx(
        {"X": 48.0, "Y": 34.0, "Z": 20.0}
    )
    # shares: Σ_d b_c,d·B_d / V², each >= 0; squareness.XY acts in X only with 10 µm:
    # 10 · 48 / 3860; X.linear acts in X with 8: 8 · 48 / 3860
    shares = {b.component: b.share_pct for b in u.budget}
    assert all(v >= 0.0 for v in shares.values())
    assert sum(shares.values()) == pytest.approx(100.0)
    assert shares["squareness.XY"] == pytest.approx(100 * 480 / 3860)
    assert shares["X.linear"] == pytest.approx(100 * 384 / 3860)


def test_the_signed_sum_of_the_default_model_is_below_the_bound():
    # issue 17: the default (rigid-body, ISO 230-1) model run with +U in place of every
    # error gave the old "summation" 48.2 µm. At the far corner its terms are those of the
    # bound with three angular terms negative: X 48 - 2·4 = 40, Y 34 - 2·2·4 = 18, Z 20;
    # sqrt(40² + 18² + 20²) = sqrt(2324) = 48.21 µm < sqrt(3860) = 62.13 µm (the bound).
    from esp import errors_at
    from esp.core.uncertainty.spec import uncertainty_machine

    data = study(0.0, "summation")
    data["analysis"] = {"straightness_fit": "none"}  # the U curves exactly as given
    machine = machine_from_dict(data, ".")
    plus = uncertainty_machine(machine, machine.uncertainty)
    (e,) = errors_at(plus, [[1000.0, 1000.0, 1000.0]])
    assert e == pytest.approx([40.0, 18.0, 20.0])
    assert math.hypot(*e) == pytest.approx(math.sqrt(2324.0))
    assert round(math.hypot(*e), 1) == 48.2
    bound = run(data).volumetric.value_um
    assert bound == pytest.approx(math.sqrt(3860.0)) and math.hypot(*e) < bound


def test_summation_does_not_depend_on_the_angle_convention():
    # the same machine, angle_convention flipped: identical figures to the last bit
    results = []
    for convention in ("iso230-1", "thesis"):
        data = study(500.0, "summation")
        data["analysis"] = {"angle_convention": convention}
        results.append(run(data))
    a, b = results
    assert a.volumetric == b.volumetric and dict(a.axes) == dict(b.axes)
    assert a.budget == b.budget


def test_pure_addition_needs_the_printed_model():
    data = study(0.0, "pure-addition")
    data["analysis"]["model"] = "rigid-body"
    with pytest.raises(ConfigError) as err:
        machine_from_dict(data, ".")
    assert err.value.key == "uncertainty.method" and "found 'rigid-body'" in str(err.value)
    data = study(0.0, "pure-addition", coverage=0.95)
    with pytest.raises(ConfigError, match="uncertainty.coverage"):
        machine_from_dict(data, ".")
    # a machine built in code is refused by the library entry point too
    from dataclasses import replace

    machine = machine_from_dict(study(0.0, "pure-addition"), ".")
    machine = replace(machine, analysis=replace(machine.analysis, model="rigid-body"))
    with pytest.raises(ConfigError) as err:
        volumetric_uncertainty(machine, machine.uncertainty)
    assert err.value.key == "uncertainty.method"


def sign_grid(point: str, datum: str) -> dict:
    """A small planning study (3 x 3 x 3 points, 0/500/1000 mm) whose levers change sign:
    offsets X 200, Y 0, Z 700 mm; every component with its own U, X.linear a curve
    0 -> 8 µm; straightness used as given, so that an error machine with the same values
    runs the same model."""
    comps = {}
    for n, a in enumerate(AXES3):
        comps[f"{a}.linear"] = {"U": 2.0 + n}
        for m, b in enumerate(AXES3):
            if b != a:
                comps[f"{a}.straightness.{b}"] = {"U": 1.0 + 0.5 * m + n}
            comps[f"{a}.angular.{b}"] = {"U": 3.0 + m + 2 * n}
    comps["X.linear"] = {"U": {"points": [[0, 0.0], [1000, 8.0]]}}
    for n, p in enumerate(("XY", "XZ", "YZ")):
        comps[f"squareness.{p}"] = {"U": 6.0 + 2 * n}
    data = {
        "machine": {
            "name": "signs",
            "configuration": "wBMTt",
            "axes": {"bottom": "X", "middle": "Y", "top": "Z"},
        },
        "analysis": {"point": point, "datum": datum, "straightness_fit": "none"},
        "axes": {
            a: {"travel": [0, 1000], "step": 500, "offset": off}
            for a, off in zip(AXES3, (200.0, 0.0, 700.0), strict=True)
        },
        "uncertainty": {"method": "summation", "components": comps},
    }
    if point == "TCP":
        data["tool"] = {"lengths": [150], "orientation": {"tilt": 30, "spin": 40}}
    return data


def _scaled(function, sign: float):
    if callable(function):
        return lambda x: sign * function(x)
    return sign * function


def _on_nodes(function, nodes: np.ndarray):
    """A component's function read once at the grid nodes (the points and the datum all
    lie on them), for speed; exact at the nodes."""
    if not callable(function):
        return function
    values = np.asarray(function(nodes), dtype=float)
    return lambda x: np.interp(x, nodes, values)


@pytest.mark.parametrize("point, datum", [("MCP", "none"), ("TCP", "centre")])
def test_no_choice_of_signs_exceeds_the_summation_bound(point, datum):
    # Brute force, independent of the bound's own evaluation: the error model
    # (Synthesis.totals_at_um, what esp.errors_at runs) with one component at +U at a time
    # gives c_i,d(p)·U_i(p) at every grid point (datum-relative, tool offsets included);
    # the bound is the sum of their absolute values. Every k is 2: k·Σ |c|·u = Σ |c|·U.
    from esp import errors_at
    from esp.core.synthesis import Synthesis, datum_point, tool_cases
    from esp.core.uncertainty.spec import uncertainty_machine

    machine = machine_from_dict(sign_grid(point, datum), ".")
    u = volumetric_uncertainty(machine, machine.uncertainty)
    plus = uncertainty_machine(machine, machine.uncertainty)  # every error = +U
    grid = [0.0, 500.0, 1000.0]
    points = np.array([[x, y, z] for x in grid for y in grid for z in grid])
    syn = Synthesis.prepare(plus)
    tool, ref = tool_cases(plus)[0], datum_point(plus)
    names = list(syn.functions)  # the components that act in this case
    base = {n: _on_nodes(f, np.array(grid)) for n, f in syn.functions.items()}

    def model(signs: dict) -> np.ndarray:
        """The error model with component n's error = signs[n]·U_n (others absent)."""
        fns = {n: _scaled(base[n], s) for n, s in signs.items()}
        run = Synthesis(plus, syn.model, syn.grids, fns, [], setting_errors=False)
        e = run.totals_at_um(points, tool)
        if ref is not None:
            e -= np.array(list(run.totals_um(ref, tool).values()))
        return e

    np.testing.assert_allclose(model(dict.fromkeys(names, 1.0)), errors_at(plus, points))
    alone = {n: model({n: 1.0}) for n in names}
    bound = sum(np.abs(t) for t in alone.values())
    volumetric = np.sqrt((bound**2).sum(axis=1))
    assert u.volumetric.value_um == pytest.approx(volumetric.max(), rel=1e-12)
    for d, a in enumerate(AXES3):
        assert u.axes[a].value_um == pytest.approx(bound[:, d].max(), rel=1e-12)
    # random signs of the error inputs: the model run with ±U per component
    rng = np.random.default_rng(17)
    for _ in range(24):
        e = model(dict(zip(names, rng.choice([-1.0, 1.0], size=len(names)), strict=True)))
        assert np.all(np.abs(e) <= bound + 1e-9)
        assert np.sqrt((e**2).sum(axis=1)).max() <= u.volumetric.value_um + 1e-9
    # the bound is reached: the signs of the sensitivities in X at the point of the
    # largest X bound give exactly that bound there
    p = int(bound[:, 0].argmax())
    e = model({n: 1.0 if alone[n][p, 0] >= 0 else -1.0 for n in names})
    assert e[p, 0] == pytest.approx(bound[p, 0], rel=1e-12)
    assert all(b.share_pct >= 0.0 for b in u.budget)
    assert sum(b.share_pct for b in u.budget) == pytest.approx(100.0)


# -- issue 30: the edges of the budget and of pure addition ---------------------------------


@pytest.mark.parametrize("method", ["statistical", "summation", "pure-addition"])
def test_a_budget_of_zero_uncertainties_has_zero_shares(method: str) -> None:
    """Every U zero (a planning study before any uncertainty is known): the volumetric U is
    0 and every share 0 %, not a division of 0 by 0."""
    data = three_linears(method)
    for component in data["uncertainty"]["components"].values():
        component["U"] = 0.0
    u = run(data)
    assert u.volumetric.value_um == 0.0 and u.u_um == 0.0
    assert [(b.share_pct, b.contribution_um) for b in u.budget] == [(0.0, 0.0)] * 3


def test_pure_addition_takes_a_direction_s_largest_magnitude_whatever_its_sign() -> None:
    """The 0.3 m³ cube of table 4.3 (measured at the origin, datum there): the constant
    terms cancel against the datum, and each direction is its angular and squareness terms,
    U times the lever's travel from the origin with the printed eq. 3.1's signs. X = 3·4
    µm/m·0.3 m + 2·10 µm/m·0.3 m is positive, 0 at the origin to 9.6 µm at (·, 300, 300);
    Z is one term, X.angular.X (4 µm/m) with lever Y, negative: 0 at Y = 0 to -1.2 µm at
    Y = 300. The figure of a direction is its largest magnitude: 9.6 from X's maximum, 1.2
    from Z's minimum (the maximum alone would give 0, the minimum alone 0 for X)."""
    u = run(cube_300(0.0, "pure-addition", "as-printed", datum="negative"))
    assert u.axes["X"].value_um == pytest.approx(9.6)
    assert (u.axes["X"].at["Y"], u.axes["X"].at["Z"]) == (300.0, 300.0)
    assert u.axes["Z"].value_um == pytest.approx(1.2)
    assert u.axes["Z"].at["Y"] == 300.0


def test_shares_do_not_depend_on_the_size_of_the_uncertainties() -> None:
    """The three linears with every U a tenth (u = 0.2, 0.15, 0.1 µm; Σ u² = 0.0725 µm², below
    1 µm²): the shares are those of the full-size budget, 100 · (4, 2.25, 1) / 7.25 %."""
    data = three_linears()
    for component in data["uncertainty"]["components"].values():
        component["U"] /= 10.0
    shares = {b.component: b.share_pct for b in run(data).budget}
    assert shares == pytest.approx(
        {"X.linear": 400 / 7.25, "Y.linear": 225 / 7.25, "Z.linear": 100 / 7.25}, rel=1e-12
    )
