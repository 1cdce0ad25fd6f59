"""Volumetric uncertainty (Longstaff 2002, 3.14.7 and 4.01) and its Monte Carlo check."""

from __future__ import annotations

import math

import pytest

from esp.analysis import analyse
from esp.config import machine_from_dict
from esp.errors import ConfigError
from esp.uncertainty.propagate import montecarlo_errors, volumetric_uncertainty

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
        (0.0, "summation", 60.0),  # table 4.3, measured at the origin, 1 m³
        (500.0, "summation", 43.0),  # table 4.3, measured centrally, 1 m³
        (0.0, "statistical", 26.2),  # table 4.4, measured at the origin, 1 m³
        (500.0, "statistical", 19.7),  # table 4.4, measured centrally, 1 m³
    ],
)
def test_thesis_tables_4_3_and_4_4(offset, method, printed):
    u = run(study(offset, method))
    assert round(u.volumetric.value_um, 1) == printed
    assert u.volumetric.at == {"X": 1000.0, "Y": 1000.0, "Z": 1000.0}


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


def test_summation_budget_adds_to_100():
    u = run(study(500.0, "summation"))
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


def test_montecarlo_is_reproducible_with_its_seed():
    data = study(0.0, "montecarlo", samples=400, seed=11)
    a = run(data).montecarlo
    b = run(data).montecarlo
    assert a.values_um == b.values_um and a.seed == 11
    data["uncertainty"]["seed"] = 12
    c = run(data).montecarlo
    assert c.values_um != a.values_um
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
    from esp.uncertainty.instruments import square

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
    data["uncertainty"]["components"] = {"X.linear": {"U": 0.01}}
    res = analyse(machine_from_dict(data, "."))
    assert res.cases[res.worst].volumetric.value_um == pytest.approx(5.0)
    assert res.uncertainty.montecarlo.mean_um == pytest.approx(5.0, abs=0.01)
