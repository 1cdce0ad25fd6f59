"""Error transmission of the serial-parallel machine: the linkage analysis and the
differential vector method (Zhao, Fan et al. 2002, section 4) against each other, against
the exact nonlinear kinematics, and against hand computations."""

from __future__ import annotations

import math

import numpy as np
import pytest

from esp.core.errors import DataError
from esp.parallel.differential import differential_matrices
from esp.parallel.exact import exact_errors
from esp.parallel.geometry import symmetric_geometry
from esp.parallel.kinematics import inverse
from esp.parallel.linkage import linkage_matrices
from esp.parallel.printed import printed_matrices
from esp.parallel.sources import M_COLUMNS, N_COLUMNS, SOURCE_NAMES, SOURCES, engine_from_paper
from esp.parallel.transmission import condition_numbers, transmit

PAPER = symmetric_geometry(400.0, 200.0, 300.0, 1000.0)
TABLE = (35.0, -20.0)


def _col(name: str) -> int:
    return SOURCE_NAMES.index(name)


def _unit_vector(name: str, value: float = 1.0) -> np.ndarray:
    v = np.zeros(len(SOURCE_NAMES))
    v[_col(name)] = value
    return v


@pytest.fixture(scope="module")
def poses():
    z, a, b = np.meshgrid([250.0, 300.0], [-20.0, 0.0, 15.0], [-10.0, 10.0, 25.0], indexing="ij")
    return inverse(PAPER, z.ravel(), a.ravel(), b.ravel())


@pytest.fixture(scope="module")
def paper_pose():
    return inverse(PAPER, 300.0, 15.0, 10.0)


@pytest.fixture(scope="module")
def paper_sensitivity(paper_pose):
    return transmit(PAPER, paper_pose, TABLE).sensitivity[0]


def test_source_layout():
    assert len(M_COLUMNS) == 12 and len(N_COLUMNS) == 30
    assert SOURCE_NAMES == M_COLUMNS + N_COLUMNS
    # δA of eq. 12: [δR_1 δl_1 δR_2 δl_2 δR_3 δl_3]
    assert M_COLUMNS[:4] == ("leg1.joint.X", "leg1.joint.Y", "leg1.joint.Z", "leg1.strut")
    assert {s.unit for s in SOURCES} == {"um", "urad"}


def test_both_methods_agree(poses):
    """The two derivations, written independently, give the same [J], [M], [N] and
    sensitivities at every pose (to rounding)."""
    a = linkage_matrices(PAPER, poses, TABLE)
    b = differential_matrices(PAPER, poses, TABLE)
    for key in ("J", "M", "N", "S"):
        scale = max(1.0, float(np.max(np.abs(a[key]))))
        assert np.max(np.abs(a[key] - b[key])) < 1e-12 * scale, key


def test_transmit_reports_the_methods_difference(paper_pose):
    t = transmit(PAPER, paper_pose, TABLE)
    assert 0.0 <= t.methods_difference[0] < 1e-10


@pytest.mark.parametrize("seed", [1, 2])
def test_first_order_models_agree_with_the_exact_kinematics(paper_pose, paper_sensitivity, seed):
    """A finite difference of the exact nonlinear kinematics: the residual of the linear
    model is of second order -- it falls by 4 when the errors are halved."""
    rng = np.random.default_rng(seed)
    angular = np.array([s.unit == "urad" for s in SOURCES])
    direction = rng.normal(size=len(SOURCES)) * np.where(angular, 50.0, 20.0)
    residuals = []
    for scale in (1.0, 0.5, 0.25, 0.125):
        values = scale * direction
        exact = exact_errors(PAPER, paper_pose, TABLE, values)[0]
        linear = paper_sensitivity @ values
        residuals.append(float(np.max(np.abs(exact - linear))))
        assert residuals[-1] < 1e-3 * np.max(np.abs(linear))
    ratios = [residuals[i] / residuals[i + 1] for i in range(3)]
    print("residual (µm or µrad) at scale 1, 1/2, 1/4, 1/8:", residuals, "ratios", ratios)
    for r in ratios:
        assert 3.5 < r < 4.5


@pytest.mark.slow
def test_every_source_alone_against_the_exact_kinematics(paper_pose, paper_sensitivity):
    """One source at a time, by a central difference of the exact kinematics (the
    second-order part cancels): each column of the sensitivities."""
    h = 1.0  # µm or µrad
    for j, name in enumerate(SOURCE_NAMES):
        plus = exact_errors(PAPER, paper_pose, TABLE, _unit_vector(name, h))[0]
        minus = exact_errors(PAPER, paper_pose, TABLE, _unit_vector(name, -h))[0]
        central = (plus - minus) / (2 * h)
        np.testing.assert_allclose(central, paper_sensitivity[:, j], atol=1e-6, err_msg=name)


def test_zero_errors_give_zero(paper_pose, paper_sensitivity):
    zero = np.zeros(len(SOURCE_NAMES))
    assert np.all(paper_sensitivity @ zero == 0.0)
    assert np.max(np.abs(exact_errors(PAPER, paper_pose, TABLE, zero))) < 1e-6


def test_linearity(paper_sensitivity):
    rng = np.random.default_rng(5)
    v, w = rng.normal(size=(2, len(SOURCE_NAMES)))
    np.testing.assert_allclose(
        paper_sensitivity @ (2.5 * v - 0.7 * w),
        2.5 * (paper_sensitivity @ v) - 0.7 * (paper_sensitivity @ w),
        atol=1e-10,
    )


def test_one_component_gives_exactly_its_term(paper_pose):
    t = transmit(PAPER, paper_pose, TABLE)
    v = _unit_vector("leg2.strut", 7.0)
    np.testing.assert_allclose(t.errors(v)[0], 7.0 * t.sensitivity[0][:, _col("leg2.strut")])


def test_equal_slider_errors_lift_the_platform_without_turning_it(paper_pose, paper_sensitivity):
    """Every slider up by δ: the platform translates by δ along Z (hand result)."""
    v = sum(_unit_vector(f"leg{i}.slider.Z", 10.0) for i in (1, 2, 3))
    np.testing.assert_allclose(paper_sensitivity @ v, [0, 0, 10.0, 0, 0, 0], atol=1e-10)


def test_table_errors_by_hand(paper_pose, paper_sensitivity):
    """The table moves the workpiece: the tool relative to it moves by −δO_P; a table
    rotation ε_P moves it by −ε_P × p (p from the table's reference point to the tool tip)
    and turns it by −ε_P."""
    np.testing.assert_allclose(
        paper_sensitivity @ _unit_vector("table.X", 3.0), [-3.0, 0, 0, 0, 0, 0], atol=1e-12
    )
    p_mm = paper_pose.tip_mm[0] - (np.array(PAPER.table_origin_mm) + [*TABLE, 0.0])
    eps = np.array([0.0, 0.0, 10.0])  # µrad about Z
    expected = np.concatenate([-np.cross(eps, p_mm) * 1e-3, -eps])
    np.testing.assert_allclose(
        paper_sensitivity @ _unit_vector("table.C", 10.0), expected, atol=1e-12
    )


def test_joint_and_slider_errors_enter_alike(paper_sensitivity):
    for i in (1, 2, 3):
        for c in "XYZ":
            np.testing.assert_array_equal(
                paper_sensitivity[:, _col(f"leg{i}.joint.{c}")],
                paper_sensitivity[:, _col(f"leg{i}.slider.{c}")],
            )


def test_strut_error_by_hand_at_the_level_pose():
    """Level platform, struts equal: all three struts longer by δ move the platform down by
    δ / sin(elevation), cos(elevation) = (R − r) / l."""
    pose = inverse(PAPER, 300.0, 0.0, 0.0)
    s = transmit(PAPER, pose).sensitivity[0]
    v = sum(_unit_vector(f"leg{i}.strut", 60.0) for i in (1, 2, 3))
    sin_e = math.sqrt(1 - (200.0 / 1000.0) ** 2)
    np.testing.assert_allclose(s @ v, [0, 0, -60.0 / sin_e, 0, 0, 0], atol=1e-9)


def test_the_printed_model_differs_where_the_doc_says(paper_pose):
    """As printed: δl with the opposite sign; the parts of joint, ball and table errors
    across the strut planes dropped; no axis or table-rotation terms."""
    exact = linkage_matrices(PAPER, paper_pose, TABLE)
    printed = printed_matrices(PAPER, paper_pose, TABLE)
    se, sp = exact["S"][0], printed["S"][0]
    # the printed [J] is the exact one with the strut rows negated
    np.testing.assert_allclose(printed["J"][0][:3], -exact["J"][0][:3])
    np.testing.assert_allclose(printed["J"][0][3:], exact["J"][0][3:])
    for i in (1, 2, 3):
        np.testing.assert_allclose(
            sp[:, _col(f"leg{i}.strut")], -se[:, _col(f"leg{i}.strut")], atol=1e-12
        )
        assert not np.any(sp[:, _col(f"leg{i}.axis.tilt")])
    # exact: a joint displaced along its axis u_i moves the platform; printed: it does not
    u1 = PAPER.axes[0]
    lateral = u1[0] * sp[:, _col("leg1.joint.X")] + u1[1] * sp[:, _col("leg1.joint.Y")]
    assert np.max(np.abs(lateral)) < 1e-12
    lateral_exact = u1[0] * se[:, _col("leg1.joint.X")] + u1[1] * se[:, _col("leg1.joint.Y")]
    assert np.max(np.abs(lateral_exact)) > 0.1
    # printed: a table translation does not give −δO_P
    assert not np.allclose(
        engine_from_paper(printed["S"])[0][:, _col("table.X")], [-1, 0, 0, 0, 0, 0]
    )


def test_condition_number_is_dimensionless_and_small_at_the_papers_pose(paper_pose):
    t = transmit(PAPER, paper_pose, TABLE)
    assert 3.0 < t.condition[0] < 5.0
    jac = t.J.copy()
    kappa, smallest = condition_numbers(jac, PAPER.lever_mm)
    assert kappa[0] == pytest.approx(t.condition[0]) and smallest[0] > 0.1


def test_near_singular_pose_is_refused():
    """Struts almost horizontal at the level pose: every strut line and every plane line
    lies almost in one horizontal plane, and the platform is nearly free to tilt."""
    flat = symmetric_geometry(400.0, 200.0, 300.0, 200.0001)
    pose = inverse(flat, 300.0, 0.0, 0.0)
    with pytest.raises(
        DataError, match=r"near-singular .* condition number of \[J\] .* > limit 1000"
    ):
        transmit(flat, pose)
    loose = transmit(flat, pose, max_condition=1e9)
    assert loose.condition[0] > 1000
    # the condition number grows without bound as the struts flatten
    k = [
        transmit(
            symmetric_geometry(400, 200, 300, 200 + d),
            inverse(symmetric_geometry(400, 200, 300, 200 + d), 0, 0, 0),
            max_condition=1e12,
        ).condition[0]
        for d in (1.0, 0.01, 0.0001)
    ]
    assert k[0] < k[1] < k[2]
