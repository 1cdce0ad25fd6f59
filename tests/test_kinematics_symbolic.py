"""The symbolic derivation against published formulae: Loh et al. (2004) eq. 10 for the
SCMM, Freeman & Ford (2003) Table 2 for the angle head; and against an independent sympy
product of the published matrices."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

import esp.core.kinematics as K
from esp.config.chain import load_chain
from esp.core.errors import ConfigError

sp = pytest.importorskip("sympy")

ROOT = Path(__file__).resolve().parent.parent
LOH = ROOT / "data/examples/chains/loh-2004-scmm.toml"
HEAD = ROOT / "data/examples/heads/angle-head.toml"
FRAME_OFFSETS = ("a_Y", "b_Y", "c_Y", "c_X", "a_Z", "b_Z", "c_Z")


@pytest.fixture(scope="module")
def loh():
    return K.derive(load_chain(LOH), order=1)


@pytest.fixture(scope="module")
def head():
    return K.derive(load_chain(HEAD), order=1)


def S(names: str):
    return sp.symbols(names)


def loh_eq10(as_printed: bool = False):
    """Loh et al. (2004) eq. 10, transcribed term by term; ``as_printed`` keeps the
    misprint ε_z(X) + ε_z(X) + ε_z(Z) in the a(P) bracket of P_y."""
    x, y, z, a_P, b_P, c_P = S("x y z a_P b_P c_P")
    dx_X, dx_Y, dx_Z, dy_X, dy_Y, dy_Z, dz_X, dz_Y, dz_Z = S(
        "dx_X dx_Y dx_Z dy_X dy_Y dy_Z dz_X dz_Y dz_Z"
    )
    ex_X, ex_Y, ex_Z, ey_X, ey_Y, ey_Z, ez_X, ez_Y, ez_Z = S(
        "ex_X ex_Y ex_Z ey_X ey_Y ey_Z ez_X ez_Y ez_Z"
    )
    alpha_xy, alpha_xz, alpha_yz = S("alpha_xy alpha_xz alpha_yz")
    P_x = (
        x
        + a_P
        + (dx_X + dx_Y + dx_Z)
        + (alpha_xy + alpha_xz)
        + (ey_X + ey_Y) * z
        - (ez_X + ez_Y + ez_Z) * b_P
        + (ey_X + ey_Y + ey_Z) * c_P
    )
    second_ez = ez_X if as_printed else ez_Y
    P_y = (
        y
        + b_P
        + (dy_X + dy_Y + dy_Z)
        + alpha_yz
        - (ex_X + ex_Y) * z
        + (ez_X + second_ez + ez_Z) * a_P
        - (ex_X + ex_Y + ex_Z) * c_P
        + ez_Y * x
    )
    P_z = (
        z
        + c_P
        + (dz_X + dz_Y + dz_Z)
        - (ey_X + ey_Y + ey_Z) * a_P
        + (ex_X + ex_Y + ex_Z) * b_P
        - ey_Y * x
    )
    return {"X": P_x, "Y": P_y, "Z": P_z}


def _without_frame_offsets(expr):
    return sp.sympify(expr).subs({sp.Symbol(n): 0 for n in FRAME_OFFSETS})


def test_loh_eq10_reproduced_term_by_term(loh):
    """With the frame offsets a(Y), b(Y), c(Y), c(X), a(Z), b(Z), c(Z) zero -- as eq. 10
    tacitly takes them -- the derived P_x, P_y, P_z are eq. 10, once its misprint in P_y
    is corrected (ε_z(X) + ε_z(X) + ε_z(Z) must read ε_z(X) + ε_z(Y) + ε_z(Z))."""
    published = loh_eq10()
    errors = [sp.Symbol(e) for e in loh.chain.errors]
    for axis in "XYZ":
        derived = _without_frame_offsets(loh.nominal[axis] + loh.first_order[axis])
        assert sp.expand(derived - published[axis]) == 0, axis
        # term by term: the coefficient of every error
        for e in errors:
            mine = sp.expand(_without_frame_offsets(loh.first_terms[axis].get(e.name, 0)))
            theirs = sp.expand(published[axis]).coeff(e)
            assert sp.expand(mine - theirs) == 0, (axis, e)


def test_loh_eq10_misprint_in_p_y(loh):
    """As printed, P_y has ε_z(X) twice and no ε_z(Y) in the a(P) bracket: it differs from
    the derivation by (ε_z(X) − ε_z(Y))·a(P), and only by that."""
    printed = loh_eq10(as_printed=True)["Y"]
    derived = _without_frame_offsets(loh.nominal["Y"] + loh.first_order["Y"])
    ez_X, ez_Y, a_P = S("ez_X ez_Y a_P")
    assert sp.expand(printed - derived - (ez_X - ez_Y) * a_P) == 0


def test_loh_omissions_of_eq10(loh):
    """What eq. 10 leaves out, stated so: (1) the frame offsets of eq. 5-7, which add
    levers such as ε_y(Y)·(c(X) + c(Z)) to P_x; (2) the probe's rotations ε(P) of eq. 8,
    rightly, since they turn the probe frame about the tip itself."""
    ey_Y, c_X, c_Z = S("ey_Y c_X c_Z")
    assert sp.expand(loh.first_terms["X"]["ey_Y"] - (S("c_P") + c_X + c_Z + S("z"))) == 0
    for name in ("ex_P", "ey_P", "ez_P"):
        assert all(name not in loh.first_terms[a] for a in "XYZ")
    # and the nominal part carries the frame offsets too
    assert sp.expand(loh.nominal["X"] - (S("x") + S("a_P") + S("a_Y") + S("a_Z"))) == 0


@pytest.mark.slow
def test_loh_from_the_printed_matrices():
    """An independent route: multiply Loh's eq. 5-8 matrices (small-angle rotations of
    eq. 2, translation columns as printed) with every error scaled by λ, and take the
    λ¹ coefficient; it equals the derivation with the frame offsets kept."""
    chain = load_chain(LOH)
    lam = sp.Symbol("lambda_")
    sym = {n: sp.Symbol(n) for n in chain.symbols}

    def small(n):
        return lam * sym[n]

    def htm(axis_letter, translation):
        ex, ey, ez = (small(f"e{c}_{axis_letter}") for c in "xyz")
        return sp.Matrix(
            [
                [1, -ez, ey, translation[0]],
                [ez, 1, -ex, translation[1]],
                [-ey, ex, 1, translation[2]],
                [0, 0, 0, 1],
            ]
        )

    s = sym
    base_T_y = htm(
        "Y", (small("dx_Y") + s["a_Y"], s["y"] + small("dy_Y") + s["b_Y"], small("dz_Y") + s["c_Y"])
    )
    y_T_x = htm(
        "X", (s["x"] + small("dx_X") + small("alpha_xy"), small("dy_X"), small("dz_X") + s["c_X"])
    )
    x_T_z = htm(
        "Z",
        (
            small("dx_Z") + small("alpha_xz") + s["a_Z"],
            small("dy_Z") + small("alpha_yz") + s["b_Z"],
            s["z"] + small("dz_Z") + s["c_Z"],
        ),
    )
    z_T_p = htm("P", (s["a_P"], s["b_P"], s["c_P"]))
    T = base_T_y * y_T_x * x_T_z * z_T_p  # eq. 9
    derivation = K.derive(chain, order=1)
    for k, axis in enumerate("XYZ"):
        p = sp.expand(T[k, 3])
        assert sp.expand(p.coeff(lam, 0) - derivation.nominal[axis]) == 0
        assert sp.expand(p.coeff(lam, 1) - derivation.first_order[axis]) == 0


def test_loh_eq4_is_first_order_only():
    """Loh's eq. 4 writes E = T_rot·T_trans but prints the translation column δ; the
    product's column is T_rot·δ = δ + ε×δ, equal to eq. 4 only to first order."""
    ex, ey, ez, dx, dy, dz = S("ex ey ez dx dy dz")
    T_rot = sp.Matrix([[1, -ez, ey, 0], [ez, 1, -ex, 0], [-ey, ex, 1, 0], [0, 0, 0, 1]])
    T_trans = sp.Matrix([[1, 0, 0, dx], [0, 1, 0, dy], [0, 0, 1, dz], [0, 0, 0, 1]])
    column = (T_rot * T_trans)[:3, 3]
    assert sp.expand(column[0] - (dx - ez * dy + ey * dz)) == 0
    assert (T_trans * T_rot)[:3, 3] == sp.Matrix([dx, dy, dz])


# -- Freeman & Ford (2003), the angle head -----------------------------------------------------


def table2():
    """Freeman & Ford (2003) Table 2: the direct transformation of the angle head."""
    G, e, Yp, A, C = S("G e Yp A C")
    sin, cos, tan = sp.sin, sp.cos, sp.tan
    X = (
        G * sin(Yp) * sin(A) * cos(C)
        - G * sin(Yp) * cos(A) * cos(Yp) * sin(C)
        + G * cos(Yp) * sin(Yp) * sin(C)
        + e * sin(C)
    )
    Y = (
        G * sin(Yp) * sin(A) * sin(C)
        + G * sin(Yp) * cos(A) * cos(Yp) * cos(C)
        - G * cos(Yp) * sin(Yp) * cos(C)
        - e * cos(C)
    )
    Z = -G * sin(Yp) * cos(A) * sin(Yp) - G * cos(Yp) * cos(Yp) - e / tan(Yp)
    return {"X": X, "Y": Y, "Z": Z}


def test_angle_head_nominal_equals_table2_symbolically(head):
    published = table2()
    for axis in "XYZ":
        assert sp.simplify(head.nominal[axis] - published[axis]) == 0, axis


def _table2_numbers(A_deg, C_deg, G=20.0, e=10.0, Yp_deg=50.0):
    a, c, y = np.radians(A_deg), np.radians(C_deg), math.radians(Yp_deg)
    X = (
        G * np.sin(y) * np.sin(a) * np.cos(c)
        - G * np.sin(y) * np.cos(a) * np.cos(y) * np.sin(c)
        + G * np.cos(y) * np.sin(y) * np.sin(c)
        + e * np.sin(c)
    )
    Y = (
        G * np.sin(y) * np.sin(a) * np.sin(c)
        + G * np.sin(y) * np.cos(a) * np.cos(y) * np.cos(c)
        - G * np.cos(y) * np.sin(y) * np.cos(c)
        - e * np.cos(c)
    )
    Z = -G * np.sin(y) * np.cos(a) * np.sin(y) - G * np.cos(y) ** 2 - e / np.tan(y) + 0 * a
    return np.c_[X, Y, Z]


def test_angle_head_exact_chain_equals_table2_at_random_angles():
    """G = 20 mm, e = 10 mm, Yp = 50° (the paper's section 4.1), random A and C."""
    chain = load_chain(HEAD)
    rng = np.random.default_rng(2003)
    A = rng.uniform(-180, 180, 200)
    C = rng.uniform(-180, 180, 200)
    p = K.position(chain, {"A": A, "C": C}, {"G": 20, "e": 10, "Yp": 50})
    np.testing.assert_allclose(p, _table2_numbers(A, C), rtol=0, atol=1e-12)


def test_the_papers_rotation_sign_is_forced_by_table2():
    """Read with right-handed matrices (R^k_t a positive turn about +k), the paper's chain
    does not give Table 2: the G terms of X and Y change sign. So the paper's R^k_t turns
    a point by −t (anticlockwise looking *up* the axis, from the origin towards +k)."""
    steps = []
    for step in load_chain(HEAD).steps:
        if isinstance(step, K.Rotate | K.Revolute):
            flipped = step.axis[1:] if step.axis.startswith("-") else "-" + step.axis
            if isinstance(step, K.Rotate):
                step = K.Rotate(flipped, step.angle)
            else:
                step = K.Revolute(flipped, step.coordinate)
        steps.append(step)
    symbols = {
        n: {"kind": s.kind, "unit": s.unit, "value": s.value}
        for n, s in load_chain(HEAD).symbols.items()
    }
    other = K.Chain(steps, symbols)
    A, C = np.array([30.0, -50.0]), np.array([40.0, 110.0])
    p = K.position(other, {"A": A, "C": C})
    assert not np.allclose(p, _table2_numbers(A, C), atol=1e-6)


def test_angle_head_first_order_against_finite_differences():
    chain = load_chain(HEAD)
    rng = np.random.default_rng(12)
    at = {"A": rng.uniform(-60, 60, 30), "C": rng.uniform(-60, 60, 30)}
    sens = K.sensitivities(chain, at)
    for e in chain.errors:
        h = 1.0  # arcsec or mm: both small
        if chain.symbols[e].unit == "mm":
            h = 1e-4
        fd = (K.position(chain, at, errors={e: h}) - K.position(chain, at, errors={e: -h})) / (
            2 * h
        )
        np.testing.assert_allclose(sens[e], fd, rtol=1e-6, atol=1e-12, err_msg=e)


def test_the_papers_protocol_example_two_ocx(head):
    """Freeman & Ford (2003) section 5: X measured at A = 90°, C = 0 and at A = 270°,
    C = 180° differs by 2·O_Cx. The derived DX gives exactly that, whatever the other
    errors."""
    A, C = S("A C")
    dx = head.first_order["X"]
    difference = dx.subs({A: sp.pi / 2, C: 0}) - dx.subs({A: 3 * sp.pi / 2, C: sp.pi})
    assert sp.simplify(difference - 2 * sp.Symbol("Ocx")) == 0


@pytest.mark.slow
def test_formulae_read_back_with_sympify():
    for path in (LOH, HEAD):
        derivation = K.derive(load_chain(path), order=2)
        doc = derivation.to_dict()
        for part in ("nominal", "first_order", "second_order"):
            for axis in "XYZ":
                expr = getattr(derivation, part)[axis]
                assert sp.sympify(doc[part][axis]) == expr, (path.name, part, axis)


def test_names_sympy_cannot_read_back_are_refused():
    chain = K.Chain([K.translate(0, 0, "S")], {"S": {"kind": "parameter", "value": 1}})
    with pytest.raises(ConfigError, match=r"symbols\.S: the name 'S' means something else"):
        K.derive(chain)
    assert K.position(chain)[0, 2] == 1.0  # the numeric core does not care


def test_second_order_terms_of_a_tilted_arm():
    """A hand computation: an arm of length L along z, tilted by the small angles a about x
    and then b about y: tip = Ry(b) Rx(a) (0, 0, L). To second order
    x = L b, y = −L a, z = L (1 − a²/2 − b²/2); second-order x has no a·b term, and y none."""
    chain = K.Chain(
        [K.rotate("y", "b"), K.rotate("x", "a"), K.translate(0, 0, "L")],
        {"a": "error", "b": "error", "L": {"kind": "parameter", "value": 100}},
    )
    d = K.derive(chain, order=2)
    a, b, L = S("a b L")
    assert sp.expand(d.first_order["X"] - L * b) == 0
    assert sp.expand(d.first_order["Y"] + L * a) == 0
    assert d.first_order["Z"] == 0
    assert sp.expand(d.second_order["Z"] + L * a**2 / 2 + L * b**2 / 2) == 0
    assert sp.expand(d.second_order["X"]) == 0
    assert sp.expand(d.second_order["Y"]) == 0


@pytest.mark.slow
def test_tidy_gives_the_forms_simplify_chose():
    """The protocol's solutions as sympy.simplify wrote them (recorded from the shipped
    heads), reached without importing sympy.physics; each equal to what it was given."""
    from esp.core.kinematics.symbolic import tidy

    G, e, Yp, Ocx, ThetaCv, EA0C, dX_4, dX_5, dY_7, dZ_2 = sp.symbols(
        "G e Yp Ocx ThetaCv EA0C dX_4 dX_5 dY_7 dZ_2"
    )
    cases = [
        ((-ThetaCv * e + dZ_2) / e, "-ThetaCv + dZ_2/e"),  # expanded: shorter
        ((-2 * Ocx + dX_5) / (2 * sp.cos(Yp)), "(-Ocx + dX_5/2)/cos(Yp)"),  # 2 moved up
        ((-2 * EA0C * G + dY_7) / (2 * G), "-EA0C + dY_7/(2*G)"),
        ((2 * Ocx - dX_4) / (2 * G), "(Ocx - dX_4/2)/G"),
        (dX_4 / (2 * G * sp.cos(Yp)), "dX_4/(2*G*cos(Yp))"),  # already shortest
        (sp.Integer(-2), "-2"),
    ]
    for given, written in cases:
        out = tidy(given)
        assert str(out) == written
        assert sp.simplify(out - given) == 0
