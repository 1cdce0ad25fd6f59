"""Exact evaluation of chains by homogeneous transforms, against hand computations."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

import esp.core.kinematics as K
from esp.config.chain import load_chain
from esp.core.kinematics.exact import rodrigues

ROOT = Path(__file__).resolve().parent.parent
HEAD = ROOT / "data/examples/heads/angle-head.toml"


def test_a_rotary_arm_by_hand():
    """C turns an arm of length L about z; the tip is (L cos C, L sin C, 0)."""
    chain = K.Chain([K.revolute("z", "C"), K.translate("L", 0, 0)], {"L": {"kind": "parameter"}})
    C = np.array([0.0, 30.0, 90.0, -135.0])
    p = K.position(chain, {"C": C}, {"L": 200.0})
    c = np.radians(C)
    np.testing.assert_allclose(p, np.c_[200 * np.cos(c), 200 * np.sin(c), 0 * c], atol=1e-12)
    # about -z the turn is the other way
    flipped = K.Chain([K.revolute("-z", "C"), K.translate("L", 0, 0)], {"L": "parameter"})
    q = K.position(flipped, {"C": C}, {"L": 200.0})
    np.testing.assert_allclose(q[:, 1], -p[:, 1], atol=1e-12)


def test_right_handed_rotations_about_each_axis():
    """A positive angle turns +y towards +z about x, +z towards +x about y, +x towards +y
    about z (the right-hand rule)."""
    cases = [("x", (0, 1, 0), (0, 0, 1)), ("y", (0, 0, 1), (1, 0, 0)), ("z", (1, 0, 0), (0, 1, 0))]
    for axis, start, end in cases:
        chain = K.Chain([K.rotate(axis, "deg(90)"), K.translate(*start)])
        np.testing.assert_allclose(K.position(chain)[0], end, atol=1e-15)


def test_error_motion_about_its_pivot_is_exact_for_a_large_angle():
    """A rotation by 0.3 rad about z through the pivot (P, 0, 0) moves the point (L, 0, 0)
    to (P + (L - P) cos θ, (L - P) sin θ, 0); the translation adds on top."""
    chain = K.Chain(
        [K.error_motion(tx="d", rz="th", pivot=("P", 0, 0)), K.translate("L", 0, 0)],
        {
            "P": {"kind": "parameter", "value": 40.0},
            "L": {"kind": "parameter", "value": 100.0},
            "d": {"kind": "error", "unit": "mm"},
            "th": {"kind": "error", "unit": "rad"},
        },
    )
    theta = 0.3
    p = K.position(chain, errors={"d": 0.5, "th": theta})[0]
    expected = (40 + 60 * math.cos(theta) + 0.5, 60 * math.sin(theta), 0.0)
    np.testing.assert_allclose(p, expected, rtol=1e-15, atol=1e-13)


def _expm(K3: np.ndarray) -> np.ndarray:
    """exp of a 3x3 matrix by its power series (40 terms), an independent reference."""
    out = np.eye(3)
    term = np.eye(3)
    for n in range(1, 40):
        term = term @ K3 / n
        out = out + term
    return out


@pytest.mark.parametrize(
    "r", [(0.2, -0.5, 0.7), (1e-5, 2e-5, -3e-5), (0.0, 0.0, 0.0), (1e-9, 0, 0)]
)
def test_rodrigues_is_the_exponential_of_the_rotation_vector(r):
    rx, ry, rz = r
    Kx = np.array([[0, -rz, ry], [rz, 0, -rx], [-ry, rx, 0]], dtype=float)
    a, b = rodrigues(np.float64(rx), np.float64(ry), np.float64(rz))
    R = np.eye(3) + a * Kx + b * Kx @ Kx
    np.testing.assert_allclose(R, _expm(Kx), atol=2e-16)
    np.testing.assert_allclose(R @ R.T, np.eye(3), atol=1e-15)


def test_position_equals_the_product_of_the_4x4_matrices():
    chain = load_chain(HEAD)
    rng = np.random.default_rng(3)
    at = {"A": rng.uniform(-180, 180, 40), "C": rng.uniform(-180, 180, 40)}
    errors = {n: rng.uniform(-500, 500) for n in chain.errors}
    T = K.transforms(chain, at, errors=errors)
    np.testing.assert_allclose(T[:, :3, 3], K.position(chain, at, errors=errors), atol=1e-13)
    R = T[:, :3, :3]
    np.testing.assert_allclose(
        R @ R.transpose(0, 2, 1), np.broadcast_to(np.eye(3), R.shape), atol=1e-14
    )
    np.testing.assert_allclose(np.linalg.det(R), 1.0, atol=1e-14)
    np.testing.assert_array_equal(T[:, 3], np.broadcast_to([0, 0, 0, 1.0], (40, 4)))


def test_tool_axis_points_from_the_tip_to_the_spindle():
    """The tip lies G along −(tool axis) from the A axis (Freeman & Ford's T(0, 0, −G))."""
    chain = load_chain(HEAD)
    rng = np.random.default_rng(5)
    at = {"A": rng.uniform(-90, 90, 10), "C": rng.uniform(-90, 90, 10)}
    errors = {n: chain.symbols[n].value for n in chain.errors}
    axis = K.tool_axis(chain, at, errors=errors)
    tip = K.position(chain, at, {"G": 20}, errors)
    pivot = K.position(chain, at, {"G": 0}, errors)
    np.testing.assert_allclose((pivot - tip) / 20, axis, atol=1e-14)
    np.testing.assert_allclose(K.tool_axis(chain, {"A": 0, "C": 0}), [[0, 0, 1]], atol=1e-15)


def test_blocks_and_broadcasting():
    chain = load_chain(ROOT / "data/examples/chains/gantry-wBMTt.toml")
    rng = np.random.default_rng(7)
    at = {"X": rng.uniform(0, 1000, 50), "Y": rng.uniform(0, 1000, 50), "Z": 25.0}
    errors = {"EBX": 30.0, "ECY": rng.uniform(-20, 20, 50), "EXX": 4.0}
    whole = K.position(chain, at, errors=errors)
    np.testing.assert_array_equal(whole, K.position(chain, at, errors=errors, block=7))
    np.testing.assert_array_equal(
        K.transforms(chain, at, errors=errors), K.transforms(chain, at, errors=errors, block=7)
    )
    one = K.position(chain, {"X": 1.0, "Y": 2.0, "Z": 3.0})
    assert one.shape == (1, 3)
    np.testing.assert_array_equal(one, [[1.0, 2.0, 3.0]])


def test_loh_eq5_carriage_matrix():
    """The y carriage of Loh et al. (2004) eq. 5: translation column (δx + a, y + δy + b,
    δz + c) exactly, rotation part I + [ε]× to first order (eq. 2)."""
    chain = K.Chain(
        [
            K.translate("a", "b", "c"),
            K.prismatic(
                "y", "y", {"tx": "dx", "ty": "dy", "tz": "dz", "rx": "ex", "ry": "ey", "rz": "ez"}
            ),
        ],
        {n: {"kind": "parameter", "value": v} for n, v in (("a", 1.5), ("b", -2.0), ("c", 7.0))},
    )
    eps = {"ex": 80.0, "ey": -40.0, "ez": 120.0}  # µrad
    delta = {"dx": 3.0, "dy": -5.0, "dz": 2.0}  # µm
    T = K.transforms(chain, {"y": 250.0}, errors={**eps, **delta})[0]
    np.testing.assert_allclose(
        T[:3, 3], [1.5 + 3e-3, 250.0 - 2.0 - 5e-3, 7.0 + 2e-3], rtol=0, atol=1e-13
    )
    ex, ey, ez = (eps[k] * 1e-6 for k in ("ex", "ey", "ez"))
    printed = np.array([[1, -ez, ey], [ez, 1, -ex], [-ey, ex, 1]])
    assert np.abs(T[:3, :3] - printed).max() < (ex**2 + ey**2 + ez**2)
