"""Rotary tables: table_terms against the exact chain (finite differences of
esp.core.kinematics.position, and sensitivities), the affine form, the set-up setting, and
each ISO 230-7 error alone against a hand computation (docs/rotary.md)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from esp.config.devices import load_table
from esp.core.devices import table_terms, tip_chain
from esp.core.devices.table import TIP_PARAMETERS
from esp.core.kinematics import position, sensitivities, transforms

ROTARY = Path(__file__).resolve().parent.parent / "data" / "examples" / "rotary"
CHAINS = ("c-table.toml", "trunnion-ac.toml", "trunnion-bc.toml")

GEOMETRY = {
    "c-table.toml": {"x_C": 250.0, "y_C": -40.0, "z_C": 30.0},
    "trunnion-ac.toml": {
        "x_C": 300.0,
        "y_C": 5.0,
        "z_C": -20.0,
        "x_A": 280.0,
        "y_A": 0.0,
        "z_A": 110.0,
    },
    "trunnion-bc.toml": {
        "x_C": -15.0,
        "y_C": 200.0,
        "z_C": 0.0,
        "x_B": 0.0,
        "y_B": 190.0,
        "z_B": 120.0,
    },
}


def _table(name, seed=0, scale=5.0):
    """A shipped chain with a geometry and random values of every error (µm, µrad)."""
    table = load_table(ROTARY / name)
    rng = np.random.default_rng(seed)
    values = dict(GEOMETRY[name])
    values.update({e: float(rng.normal() * scale) for e in table.chain.errors})
    return table.with_values(values)


def _settings(table, n, seed):
    rng = np.random.default_rng(seed)
    angles = {c: rng.uniform(-180.0, 180.0, n) for c in table.coordinates}
    p = rng.uniform(-500.0, 500.0, (n, 3))
    return angles, p


def _exact_workpiece(table, angles, p, errors):
    """The tool tip at machine positions p, in the workpiece frame, exactly (mm)."""
    params = dict(table.parameters)
    params.update({k: p[:, i] for i, k in enumerate(TIP_PARAMETERS)})
    return position(tip_chain(table.chain), angles, params, errors)


def _errors_at(table, angles, n, scale=1.0):
    deg = {c: np.asarray(a, dtype=float) for c, a in angles.items()}
    return {e: v * scale for e, v in table.values_at(deg, n).items()}


def _exact_error_um(table, angles, p, scale):
    """Exact error of the tool relative to the workpiece, machine axes, µm, with every
    error scaled by ``scale`` (nominal rotation from the chain)."""
    n = p.shape[0]
    nominal = _exact_workpiece(table, angles, p, None)
    actual = _exact_workpiece(table, angles, p, _errors_at(table, angles, n, scale))
    R_wm = transforms(table.chain, angles, dict(table.parameters))[:, :3, :3]
    return np.einsum("nji,nj->ni", R_wm, actual - nominal) * 1000.0


@pytest.mark.parametrize("name", CHAINS)
def test_terms_equal_central_differences_of_the_exact_chain(name):
    table = _table(name, seed=1)
    angles, p = _settings(table, 9, seed=2)
    out = table_terms(table, angles)
    first = out.error_um(p)
    h = 1.0  # the errors are a few µm and µrad: the third order is far below 1e-9 µm
    central = (_exact_error_um(table, angles, p, h) - _exact_error_um(table, angles, p, -h)) / (
        2 * h
    )
    assert np.max(np.abs(first)) > 1.0
    np.testing.assert_allclose(first, central, atol=1e-7)


@pytest.mark.parametrize("name", CHAINS)
def test_each_term_equals_the_sensitivity_of_the_chain_at_the_tool_tip(name):
    """The affine form evaluated at p equals ∂x/∂e at the tip T(p), rotated, per error."""
    table = _table(name, seed=3)
    angles, p = _settings(table, 6, seed=4)
    out = table_terms(table, angles)
    params = dict(table.parameters)
    params.update({k: p[:, i] for i, k in enumerate(TIP_PARAMETERS)})
    sens = sensitivities(tip_chain(table.chain), angles, params)
    assert [t.name for t in out.terms] == list(table.chain.errors)
    for t in out.terms:
        expected = np.einsum("nij,nj->ni", out.rotation, sens[t.name]) * t.value[:, None] * 1e3
        np.testing.assert_allclose(t.error_um(p), expected, atol=1e-9)


@pytest.mark.parametrize("name", CHAINS)
def test_the_remainder_shrinks_as_the_square_of_the_errors(name):
    table = _table(name, seed=5, scale=50.0)
    angles, p = _settings(table, 5, seed=6)
    first = table_terms(table, angles).error_um(p)
    residuals = []
    for lam in (1.0, 0.5, 0.25):
        exact = _exact_error_um(table, angles, p, lam)
        residuals.append(np.max(np.abs(exact - lam * first)))
    assert residuals[0] > 1e-6  # a second order there is
    assert residuals[0] / residuals[1] == pytest.approx(4.0, rel=0.02)
    assert residuals[1] / residuals[2] == pytest.approx(4.0, rel=0.02)


@pytest.mark.parametrize("name", CHAINS)
def test_per_mm_is_a_small_rotation_and_the_rotation_is_the_chains(name):
    table = _table(name, seed=7)
    angles, _ = _settings(table, 5, seed=8)
    out = table_terms(table, angles)
    for t in out.terms:
        np.testing.assert_allclose(t.per_mm, -np.transpose(t.per_mm, (0, 2, 1)), atol=1e-12)
    R = out.rotation
    np.testing.assert_allclose(
        R @ np.transpose(R, (0, 2, 1)), np.broadcast_to(np.eye(3), R.shape), atol=1e-12
    )
    np.testing.assert_allclose(np.linalg.det(R), 1.0)
    frames = transforms(table.chain, angles, dict(table.parameters))
    np.testing.assert_allclose(R, np.transpose(frames[:, :3, :3], (0, 2, 1)), atol=1e-15)
    e = np.array([1.0, 2.0, 3.0])
    w = out.in_workpiece_frame(e)
    np.testing.assert_allclose(np.einsum("nij,nj->ni", R, w), np.broadcast_to(e, w.shape))


@pytest.mark.parametrize("name", CHAINS)
def test_zero_errors_give_zero(name):
    table = load_table(ROTARY / name).with_values(GEOMETRY[name])
    angles, p = _settings(table, 4, seed=9)
    out = table_terms(table, angles)
    assert out.terms == ()
    assert np.all(out.error_um(p) == 0.0)
    setup = table_terms(_with_setup(table, {c: 10.0 for c in table.coordinates}), angles)
    assert setup.terms == ()


@pytest.mark.parametrize("name", CHAINS)
def test_the_nominal_frames_coincide_at_the_zero_setting(name):
    table = load_table(ROTARY / name).with_values(GEOMETRY[name])
    frames = transforms(table.chain, {c: 0.0 for c in table.coordinates}, dict(table.parameters))
    np.testing.assert_allclose(frames[0], np.eye(4), atol=1e-12)


def test_the_sense_of_the_axes_is_iso_841():
    """A positive angle turns the tool right-handed relative to the workpiece, so the
    table turns the other way: at A = 90° the trunnion's table normal (workpiece +Z)
    points along machine +Y; at C = 90° the workpiece's +X points along machine -Y."""
    table = load_table(ROTARY / "trunnion-ac.toml").with_values(GEOMETRY["trunnion-ac.toml"])
    R = table_terms(table.with_values({"X0C": 1.0}), {"A": [90.0, 0.0], "C": [0.0, 90.0]}).rotation
    np.testing.assert_allclose(R[0] @ [0, 0, 1], [0, 1, 0], atol=1e-12)
    np.testing.assert_allclose(R[1] @ [1, 0, 0], [0, -1, 0], atol=1e-12)


def _with_setup(table, setup):
    return table.with_setup(setup)


# -- each error alone, by hand ------------------------------------------------------------

X_C, Y_C, Z_C = 250.0, -40.0, 30.0


def _c_table(**errors):
    table = load_table(ROTARY / "c-table.toml").with_values(GEOMETRY["c-table.toml"])
    return table.with_values(errors)


def test_x0c_alone_displaces_the_table_and_the_workpiece_with_it():
    """X0C = 10 µm: the C axis line, and the table turning about it, sit 10 µm along +X;
    the workpiece on the table is 10 µm along +X at every C, so the tool relative to the
    workpiece is displaced by -10 µm along machine X, anywhere on the table."""
    out = table_terms(_c_table(X0C=10.0), {"C": [0.0, 90.0, 180.0]})
    for p in ([0.0, 0.0, 0.0], [X_C + 100.0, Y_C, Z_C + 50.0], [-300.0, 20.0, 400.0]):
        np.testing.assert_allclose(out.error_um(p), [[-10, 0, 0]] * 3, atol=1e-9)
    # seen in the workpiece frame, the same error turns with the table: +C' = -C
    np.testing.assert_allclose(
        out.in_workpiece_frame(out.error_um([0.0, 0.0, 0.0])),
        [[-10, 0, 0], [0, -10, 0], [10, 0, 0]],
        atol=1e-9,
    )


def test_x0c_alone_with_the_workpiece_set_up_at_c_0():
    """Set up at C = 0, the workpiece is where the controller believes it; turning the
    table by -C about the line at x_C + 10 µm instead of x_C moves each workpiece point by
    (I - Rz(-C))·(10 µm, 0, 0): at C = 90° by (10, 10, 0) µm, at 180° by (20, 0, 0) µm.
    The tool relative to the workpiece: the opposite."""
    table = _with_setup(_c_table(X0C=10.0), {"C": 0.0})
    out = table_terms(table, {"C": [0.0, 90.0, 180.0, 270.0]})
    for p in ([0.0, 0.0, 0.0], [X_C + 100.0, Y_C - 30.0, Z_C + 50.0]):
        np.testing.assert_allclose(
            out.error_um(p), [[0, 0, 0], [-10, -10, 0], [-20, 0, 0], [-10, 10, 0]], atol=1e-9
        )


def test_y0c_alone_with_the_workpiece_set_up_at_c_90():
    """Set up at C = 90°: nothing there; at C = 270° (a half turn further) the workpiece
    has moved by 2·(0, 10, 0) µm relative to where a turn about the nominal line puts it."""
    table = _with_setup(_c_table(Y0C=10.0), {"C": 90.0})
    out = table_terms(table, {"C": [90.0, 270.0]})
    np.testing.assert_allclose(
        out.error_um([10.0, 20.0, 30.0]), [[0, 0, 0], [0, -20, 0]], atol=1e-9
    )


def test_ezc_alone_is_an_axial_displacement_everywhere():
    """EZC = 3 µm: the table rises by 3 µm: the tool relative to the workpiece -3 µm in Z
    at every C and everywhere on the table."""
    out = table_terms(_c_table(EZC=3.0), {"C": [0.0, 45.0, 135.0]})
    for p in ([0.0, 0.0, 0.0], [X_C + 100.0, Y_C + 70.0, Z_C + 200.0]):
        np.testing.assert_allclose(out.error_um(p), [[0, 0, -3]] * 3, atol=1e-9)


@pytest.mark.parametrize("c_deg", [0.0, 90.0, 210.0])
def test_a0c_alone_is_levered_by_the_height_above_the_table(c_deg):
    """A0C = 20 µrad: the C axis line, and the table square to it, lean about +X; a
    workpiece point h above the reference point moves by A0C × h·Z = -A0C·h along Y, so
    the tool relative to the workpiece by +A0C·h along Y (20 µrad × 150 mm = 3 µm); off
    the axis by y, the tilt moves it by -A0C·y along Z."""
    out = table_terms(_c_table(A0C=20.0), {"C": [c_deg]})
    h = 150.0
    np.testing.assert_allclose(out.error_um([X_C, Y_C, Z_C + h]), [[0, 3.0, 0]], atol=1e-9)
    np.testing.assert_allclose(out.error_um([X_C + 80.0, Y_C, Z_C]), [[0, 0, 0]], atol=1e-9)
    y = 100.0
    np.testing.assert_allclose(out.error_um([X_C, Y_C + y, Z_C]), [[0, 0, -2.0]], atol=1e-9)


def test_ecc_alone_turns_the_tool_further_in_the_sense_of_c():
    """ECC = 10 µrad (the table reaches C + ECC): a tool r = 200 mm along +X from the C
    axis moves relative to the workpiece by ECC·r = 2 µm along +Y (right-handed about +Z,
    the sense of C), at any C."""
    out = table_terms(_c_table(ECC=10.0), {"C": [0.0, 123.0]})
    np.testing.assert_allclose(
        out.error_um([X_C + 200.0, Y_C, Z_C + 40.0]), [[0, 2.0, 0]] * 2, atol=1e-9
    )


def test_exc_and_ebc_alone_are_displacement_and_tilt_of_the_table():
    out = table_terms(_c_table(EXC=2.0), {"C": [0.0, 77.0]})
    np.testing.assert_allclose(out.error_um([1.0, 2.0, 3.0]), [[-2.0, 0, 0]] * 2, atol=1e-9)
    # EBC = 10 µrad: the table turned about +Y at the reference point; a point h above it
    # moves by EBC·h along +X; the tool relative to the workpiece by -EBC·h
    out = table_terms(_c_table(EBC=10.0), {"C": [0.0, 77.0]})
    np.testing.assert_allclose(out.error_um([X_C, Y_C, Z_C + 100.0]), [[-1.0, 0, 0]] * 2, atol=1e-9)


TRUNNION = GEOMETRY["trunnion-ac.toml"]


def _trunnion(**errors):
    table = load_table(ROTARY / "trunnion-ac.toml").with_values(TRUNNION)
    return table.with_values(errors)


def test_y0c_of_the_trunnion_turns_with_the_cradle():
    """Y0C = 10 µm: the C line sits 10 µm along +Y of the cradle; at A the cradle's +Y is
    Rx(-A)·Y in the machine (the cradle turns by -A): the tool relative to the workpiece
    is -10 µm along it: (0, -10, 0) at A = 0, (0, 0, 10) at A = 90°, (0, 0, -10) at -90°."""
    out = table_terms(_trunnion(Y0C=10.0), {"A": [0.0, 90.0, -90.0], "C": [0.0, 40.0, 300.0]})
    np.testing.assert_allclose(
        out.error_um([50.0, 60.0, 70.0]), [[0, -10, 0], [0, 0, 10], [0, 0, -10]], atol=1e-9
    )


def test_eaa_alone_is_levered_by_the_height_above_the_a_axis():
    """EAA = 10 µrad (the cradle reaches A + EAA): the tool relative to the workpiece turns
    further about +X through the A axis: a tool 200 mm above the A axis moves by
    EAA × (0, 0, 200 mm) = (0, -2, 0) µm."""
    out = table_terms(_trunnion(EAA=10.0), {"A": [0.0, 30.0], "C": [0.0, 0.0]})
    p = [TRUNNION["x_A"] + 55.0, TRUNNION["y_A"], TRUNNION["z_A"] + 200.0]
    np.testing.assert_allclose(out.error_um(p), [[0, -2.0, 0]] * 2, atol=1e-9)


def test_c0a_alone_is_levered_along_the_a_axis():
    """C0A = 10 µrad: the A line (and the cradle) turned about +Z at the reference point:
    a point 100 mm along +X from it moves by C0A × (100, 0, 0) = (0, 1, 0) µm; the tool
    relative to the workpiece by (0, -1, 0), at any A."""
    out = table_terms(_trunnion(C0A=10.0), {"A": [0.0, 75.0], "C": [0.0, 200.0]})
    p = [TRUNNION["x_A"] + 100.0, TRUNNION["y_A"], TRUNNION["z_A"]]
    np.testing.assert_allclose(out.error_um(p), [[0, -1.0, 0]] * 2, atol=1e-9)


# -- the set-up setting against the exact chain ---------------------------------------------


@pytest.mark.parametrize("name", ["c-table.toml", "trunnion-ac.toml"])
def test_setup_terms_equal_the_exact_chain_referred_to_the_setup(name):
    """The workpiece frame set up at θ_s: x' = T0(θ_s)·T(θ_s)⁻¹·T(θ)·p (T = the chain's
    transform with the errors, T0 without); its first order equals table_terms."""
    table = _table(name, seed=11)
    setup = {c: v for c, v in zip(table.coordinates, (35.0, -60.0), strict=False)}
    table = _with_setup(table, setup)
    angles, p = _settings(table, 7, seed=12)
    out = table_terms(table, angles)
    params = dict(table.parameters)

    def exact(scale):
        n = p.shape[0]
        errors = _errors_at(table, angles, n, scale)
        s_deg = {c: np.array([v]) for c, v in setup.items()}
        s_errors = {e: v * scale for e, v in table.values_at(s_deg, 1).items()}
        T = transforms(table.chain, angles, params, errors)
        Ts = transforms(table.chain, s_deg, params, s_errors)[0]
        T0s = transforms(table.chain, s_deg, params)[0]
        M = T0s @ np.linalg.inv(Ts) @ T
        ph = np.concatenate([p, np.ones((n, 1))], axis=1)
        return np.einsum("nij,nj->ni", M, ph)[:, :3]

    R_wm = transforms(table.chain, angles, params)[:, :3, :3]
    central = (exact(1.0) - exact(-1.0)) / 2.0
    np.testing.assert_allclose(
        out.error_um(p), np.einsum("nji,nj->ni", R_wm, central) * 1e3, atol=1e-7
    )
    at_setup = table_terms(table, {c: [v] for c, v in setup.items()})
    np.testing.assert_allclose(at_setup.error_um(p[0]), [[0.0, 0.0, 0.0]], atol=1e-9)


# -- curves over the angle ---------------------------------------------------------------


@pytest.mark.slow
def test_the_example_curves_enter_at_each_setting():
    """The trunnion example: each curve term equals the same table with that error a
    constant equal to the curve's value at the setting."""
    table = load_table(ROTARY / "trunnion.toml")
    angles = {"A": np.array([-115.0, 0.0, 37.5]), "C": np.array([352.5, -7.5, 725.0])}
    out = table_terms(table, angles)
    names = {t.name for t in out.terms}
    assert {"ECC", "EXC", "EAA", "EYA", "X0C", "EXA"} <= names
    ecc = next(t for t in out.terms if t.name == "ECC")
    # 352.5° and -7.5° are one setting: halfway between the rows at 345° and 0° (= 360°)
    c = table.curves["ECC"]
    half = 0.5 * (c.values[-1] + c.values[0])
    np.testing.assert_allclose(ecc.value[:2], [half, half])
    np.testing.assert_allclose(ecc.value[2], c.at(5.0))
    for t in out.terms:
        if t.name not in table.curves:
            continue
        for i in range(3):
            one = table.with_values({t.name: float(t.value[i])})
            single = table_terms(one, {k: [v[i]] for k, v in angles.items()})
            ref = next(s for s in single.terms if s.name == t.name)
            np.testing.assert_allclose(ref.constant_um[0], t.constant_um[i], atol=1e-12)
            np.testing.assert_allclose(ref.per_mm[0], t.per_mm[i], atol=1e-12)
    assert table.unit("ECC") == "urad"


def test_a_curve_of_limited_travel_refuses_an_angle_outside_it():
    from esp.core.errors import DataError

    table = load_table(ROTARY / "trunnion.toml")
    with pytest.raises(DataError, match=r"trunnion-A-motions.csv:EYA: 130 deg is outside"):
        table_terms(table, {"A": [0.0, 130.0], "C": [0.0, 0.0]})


def test_the_worked_example_of_the_docs():
    """docs/rotary.md: the trunnion example at A = 30°, C = 45°, at the workpiece point
    (360, 0, 50) mm (workpiece coordinates)."""
    table = load_table(ROTARY / "trunnion.toml")
    angles = {"A": [30.0], "C": [45.0]}
    T = transforms(table.chain, angles, dict(table.parameters))[0]
    p = (np.linalg.inv(T) @ [360.0, 0.0, 50.0, 1.0])[:3]
    np.testing.assert_allclose(p, [342.426, -61.742, 77.912], atol=5e-4)
    out = table_terms(table, angles)
    np.testing.assert_allclose(out.error_um(p)[0], [-6.283, -5.112, 2.305], atol=5e-4)
    np.testing.assert_allclose(out.constant_um[0], [-7.276, -9.265, 3.379], atol=5e-4)
    w = out.per_mm[0]
    np.testing.assert_allclose(
        1e3 * np.array([w[2, 1], w[0, 2], w[1, 0]]), [22.917, -0.997, 17.343], atol=5e-4
    )
    terms = {t.name: t.error_um(p)[0] for t in out.terms}
    np.testing.assert_allclose(terms["Y0C"], [0.0, 7.794, -4.5], atol=5e-4)
    np.testing.assert_allclose(terms["EAA"], [0.0, 0.828, -2.314], atol=5e-4)
    exact = _exact_error_um(table, angles, p[None, :], 1.0)[0]
    np.testing.assert_allclose(exact, [-6.283, -5.112, 2.305], atol=5e-4)
    setup = table_terms(_with_setup(table, {"A": 0.0, "C": 0.0}), angles)
    np.testing.assert_allclose(setup.error_um(p)[0], [1.179, -12.150, -4.187], atol=5e-4)
