"""Servo heads, numerically: the angle head's first-order error three ways (the symbolic
derivation, central differences of the exact chain, the numeric sensitivities), the second
order, the fork head against a hand computation, the five-axis API, head files, maps."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

import esp.core.kinematics as K
from esp.config.chain import load_chain
from esp.core.errors import ConfigError, ParseError
from esp.heads import (
    error_map,
    evaluate_head,
    head_from_chain,
    head_from_dict,
    head_offsets,
    load_head,
)
from esp.heads.config import read_head_file
from esp.heads.maps import GridSpec

ROOT = Path(__file__).resolve().parent.parent
HEADS = ROOT / "data/examples/heads"
ANGLE = HEADS / "angle-head.toml"
FIG3 = HEADS / "angle-head-fig3.toml"
FORK = HEADS / "fork-head.toml"
FORK_EXAMPLE = HEADS / "fork-head-example.toml"

#: the error values of Freeman & Ford (2003) Fig. 3, with O_As and ThetaAvp made non-zero
#: so that every error of the chain is exercised
FIG3_ERRORS = {
    "ThetaAs": 100.0,
    "Oas": 0.003,
    "ThetaAv": 40.0,
    "DY": -30.0,
    "Ocx": 0.005,
    "Ocy": -0.015,
    "ThetaCh": 150.0,
    "ThetaCv": -50.0,
}


@pytest.fixture(scope="module")
def angle():
    return head_from_chain(load_chain(ANGLE)).with_values(FIG3_ERRORS, origin="test")


def _random_angles(n, seed):
    rng = np.random.default_rng(seed)
    return {"A": rng.uniform(-180, 180, n), "C": rng.uniform(-180, 180, n)}


# -- the angle head's first order, three ways ---------------------------------------------------


def test_angle_head_first_order_equals_central_differences_of_the_exact_chain(angle):
    """D(λ) = p(λ e) − p(0); (D(λ) − D(−λ)) / 2λ → the first order, with an O(λ²) error."""
    at = _random_angles(40, 2003)
    ev = evaluate_head(angle, at)
    chain, params = angle.chain, angle.values_in("parameter")
    lam = 1e-3
    plus = {e: lam * v for e, v in FIG3_ERRORS.items()}
    minus = {e: -lam * v for e, v in FIG3_ERRORS.items()}
    fd_um = (K.position(chain, at, params, plus) - K.position(chain, at, params, minus)) / (2 * lam)
    np.testing.assert_allclose(ev.first_um, fd_um * 1000.0, rtol=0, atol=1e-7)
    # and the terms sum to it
    np.testing.assert_allclose(sum(t.error_um for t in ev.terms), ev.first_um, atol=1e-12)


@pytest.mark.slow
def test_angle_head_first_order_equals_the_symbolic_derivation(angle):
    """esp's derived DX, DY, DZ (sympy, ``esp derive``) evaluated at random angles equal the
    numeric first order; each error's formula equals its numeric term."""
    sp = pytest.importorskip("sympy")
    derivation = K.derive(angle.chain, 1)
    at = _random_angles(25, 7)
    ev = evaluate_head(angle, at)
    chain = angle.chain
    # every symbol in the formula's units: mm and rad
    env = {n: v * chain.symbols[n].scale for n, v in angle.parameters.items()}
    names = sorted(chain.symbols)
    symbols = [sp.Symbol(n) for n in names]
    for k, axis in enumerate("XYZ"):
        for term in ev.terms:
            coefficient = derivation.first_terms[axis].get(term.name, 0)
            f = sp.lambdify(symbols, coefficient, "numpy")
            args = []
            for n in names:
                if n in at:
                    args.append(np.radians(at[n]))
                elif n in env:
                    args.append(env[n])
                else:
                    args.append(0.0)
            value_um = (
                np.broadcast_to(f(*args), (25,))
                * term.value
                * chain.symbols[term.name].scale
                * 1000.0
            )
            np.testing.assert_allclose(
                term.error_um[:, k], value_um, rtol=0, atol=1e-9, err_msg=(axis, term.name)
            )


def test_angle_head_first_order_equals_the_sensitivities(angle):
    at = _random_angles(20, 11)
    ev = evaluate_head(angle, at)
    sens = K.sensitivities(angle.chain, at, angle.values_in("parameter"))
    expected = sum(sens[e] * v for e, v in FIG3_ERRORS.items()) * 1000.0
    np.testing.assert_allclose(ev.first_um, expected, atol=1e-12)


def test_second_order_residuals_shrink_with_the_errors(angle):
    """exact − first shrinks as λ², exact − first − second as λ³: the second order is the
    next term of the exact chain."""
    at = _random_angles(30, 5)
    residual1, residual2 = [], []
    for lam in (4.0, 2.0, 1.0):
        head = angle.with_values({e: lam * v for e, v in FIG3_ERRORS.items()}, "test")
        ev = evaluate_head(head, at, order=2)
        residual1.append(np.abs(ev.exact_um - ev.first_um).max())
        residual2.append(np.abs(ev.exact_um - ev.first_um - ev.second_um).max())
    assert residual1[0] > 1e-4  # not trivially zero
    for r, power in ((residual1, 2), (residual2, 3)):
        for a, b in zip(r, r[1:], strict=False):
            assert b / a == pytest.approx(2.0**-power, rel=0.1)


def test_zero_errors_give_zero_and_errors_add_linearly(angle):
    at = _random_angles(10, 3)
    zero = angle.with_values({e: 0.0 for e in FIG3_ERRORS}, "test")
    ev = evaluate_head(zero, at, order=2)
    assert not ev.terms
    assert np.all(ev.first_um == 0) and np.all(ev.exact_um == 0) and np.all(ev.second_um == 0)
    one = evaluate_head(zero.with_values({"Ocx": 0.005}, "test"), at)
    two = evaluate_head(zero.with_values({"Ocx": 0.010}, "test"), at)
    np.testing.assert_allclose(two.first_um, 2 * one.first_um, atol=1e-12)
    # O_Cx is a translation along x before the C rotation: (cos C, sin C, 0) × 5 µm
    c = np.radians(at["C"])
    np.testing.assert_allclose(one.first_um, 5.0 * np.c_[np.cos(c), np.sin(c), 0 * c], atol=1e-9)


def test_tool_axis_tilt_against_the_exact_chain(angle):
    at = _random_angles(15, 9)
    ev = evaluate_head(angle, at)
    chain, params = angle.chain, angle.values_in("parameter")
    lam = 1e-3
    plus = K.tool_axis(chain, at, params, {e: lam * v for e, v in FIG3_ERRORS.items()})
    minus = K.tool_axis(chain, at, params, {e: -lam * v for e, v in FIG3_ERRORS.items()})
    np.testing.assert_allclose(ev.tilt_urad, (plus - minus) / (2 * lam) * 1e6, atol=1e-3)
    # a tilt of a unit vector is perpendicular to it
    assert np.abs(np.sum(ev.tilt_urad * ev.tool_axis, axis=1)).max() < 1e-6


def test_angle_head_at_zero_points_down():
    head = head_from_chain(load_chain(ANGLE))
    ev = evaluate_head(head, {"A": 0.0, "C": 0.0})
    G, e, Yp = 20.0, 10.0, math.radians(50.0)
    np.testing.assert_allclose(ev.nominal_mm[0], [0.0, -e, -G - e / math.tan(Yp)], atol=1e-12)
    np.testing.assert_allclose(ev.tool_axis[0], [0.0, 0.0, 1.0], atol=1e-12)


# -- the fork head against a hand computation ---------------------------------------------------


@pytest.mark.parametrize(("A", "C"), [(0, 0), (30, 0), (0, 90), (30, 40), (-45, 135), (90, -60)])
def test_fork_head_nominal_by_hand(A, C):
    """C turns the fork about +Z, A tilts the spindle about the fork's +x; the tool tip is
    G below the A axis, the A axis H below the MCP:
    X = −G sin A sin C, Y = G sin A cos C, Z = −H − G cos A; the tool axis (tip into the
    spindle) is Rz(C)·(0, −sin A, cos A) = (sin A sin C, −sin A cos C, cos A)."""
    head = head_from_chain(load_chain(FORK))
    H, G = 150.0, 200.0
    a, c = math.radians(A), math.radians(C)
    ev = evaluate_head(head, {"A": A, "C": C})
    expected = [-G * math.sin(a) * math.sin(c), G * math.sin(a) * math.cos(c), -H - G * math.cos(a)]
    np.testing.assert_allclose(ev.nominal_mm[0], expected, atol=1e-12)
    axis = [math.sin(a) * math.sin(c), -math.sin(a) * math.cos(c), math.cos(a)]
    np.testing.assert_allclose(ev.tool_axis[0], axis, atol=1e-12)


def test_fork_head_error_terms_by_hand():
    """Each error alone, by hand, at A = 30°, C = 40°, with p = the nominal tip:
    E_A0C, E_B0C, E_C0C turn p about +X, +Y, +Z at the MCP (e × p); E_Y0A moves the A axis
    along the fork's y: Rz(C)·(0, 1, 0); E_A0A turns the spindle about the A axis:
    Rz(C)·Rx(A)·(0, G, 0); E_B0S tilts it about its carrier's y: Rz(C)·(−G, 0, 0)."""
    head = head_from_chain(load_chain(FORK))
    H, G = 150.0, 200.0
    A, C = 30.0, 40.0
    a, c = math.radians(A), math.radians(C)
    p = np.array(
        [-G * math.sin(a) * math.sin(c), G * math.sin(a) * math.cos(c), -H - G * math.cos(a)]
    )
    Rz = np.array([[math.cos(c), -math.sin(c), 0], [math.sin(c), math.cos(c), 0], [0, 0, 1]])
    Rx = np.array([[1, 0, 0], [0, math.cos(a), -math.sin(a)], [0, math.sin(a), math.cos(a)]])
    urad = 1e-6
    expected = {  # µm per unit (µrad or µm)
        "EA0C": np.cross([1, 0, 0], p) * urad * 1000,
        "EB0C": np.cross([0, 1, 0], p) * urad * 1000,
        "EC0C": np.cross([0, 0, 1], p) * urad * 1000,
        "EY0A": Rz @ [0, 1, 0],
        "EA0A": Rz @ Rx @ [0, G, 0] * urad * 1000,
        "EY0S": Rz @ Rx @ [0, 1, 0],
        "EB0S": Rz @ [-G, 0, 0] * urad * 1000,
        "EB0A": Rz @ [-G * math.cos(a), 0, 0] * urad * 1000,
    }
    ev = evaluate_head(head, {"A": A, "C": C})
    for name, value in expected.items():
        np.testing.assert_allclose(ev.sensitivity[name][0], value, atol=1e-12, err_msg=name)


# -- the five-axis API ------------------------------------------------------------------------


def test_head_offsets_vectorised_and_consistent(angle):
    at = _random_angles(50, 21)
    out = head_offsets(angle, at)
    assert out.offset_mm.shape == (50, 3) and out.error_um.shape == (50, 3)
    np.testing.assert_allclose(
        out.offset_mm, K.position(angle.chain, at, angle.values_in("parameter")), atol=1e-12
    )
    np.testing.assert_allclose(sum(t.error_um for t in out.terms), out.error_um, atol=1e-12)
    assert [t.name for t in out.terms] == list(FIG3_ERRORS)
    # one setting evaluated alone gives the same row
    single = head_offsets(angle, {"A": at["A"][7], "C": at["C"][7]})
    np.testing.assert_allclose(single.error_um[0], out.error_um[7], atol=1e-12)
    # a number broadcasts against an array
    mixed = head_offsets(angle, {"A": 30.0, "C": [0.0, 90.0]})
    assert mixed.offset_mm.shape == (2, 3)


def test_mcp_shifts_the_offset_not_the_error(tmp_path):
    text = f'[head]\nchain = "{FORK.as_posix()}"\nmcp = [0, 0, -150]\n'
    (tmp_path / "h.toml").write_text(text, encoding="utf-8")
    shifted, _ = load_head(tmp_path / "h.toml")
    plain = head_from_chain(load_chain(FORK))
    at = {"A": [0.0, 30.0], "C": [0.0, 40.0]}
    a, b = head_offsets(shifted, at), head_offsets(plain, at)
    np.testing.assert_allclose(a.offset_mm, b.offset_mm + [0, 0, 150.0], atol=1e-12)
    np.testing.assert_allclose(a.error_um, b.error_um, atol=1e-12)


def test_bad_angles_are_refused(angle):
    with pytest.raises(ConfigError, match=r"angles\.C: missing"):
        head_offsets(angle, {"A": 1.0})
    with pytest.raises(ConfigError, match=r"angles\.B: not a coordinate"):
        head_offsets(angle, {"A": 1.0, "C": 2.0, "B": 3.0})
    with pytest.raises(ConfigError, match=r"angles\.A: expected finite"):
        head_offsets(angle, {"A": float("nan"), "C": 2.0})
    with pytest.raises(ConfigError, match=r"angles\.C: 3 values"):
        head_offsets(angle, {"A": [1.0, 2.0], "C": [1.0, 2.0, 3.0]})


# -- head files -------------------------------------------------------------------------------


def test_shipped_head_files_read():
    fig3 = read_head_file(FIG3)
    assert fig3.head.parameters == {"G": 20.0, "e": 10.0, "Yp": 50.0}
    assert fig3.head.errors["ThetaCv"] == -50.0
    assert fig3.protocol.assume_zero == ("DY", "ThetaAv")
    assert [g.name for g in fig3.grid] == ["A", "C"]
    fork = read_head_file(FORK_EXAMPLE)
    # { value, unit } converts into the chain's unit: -0.025 mrad in µrad
    assert fork.head.errors["EA0A"] == pytest.approx(-25.0)
    assert fork.head.unit("EA0A") == "urad"


def test_a_chain_file_is_a_head_with_its_defaults():
    head, rest = load_head(ANGLE)
    assert rest == {} and head.errors["ThetaAs"] == 100.0 and head.origins["G"] == "chain"


def test_values_precedence_and_error_files(tmp_path):
    (tmp_path / "e.csv").write_text(
        "# identified\nerror,value,unit\nOcx,5,um\nThetaCh,10,\n", encoding="utf-8"
    )
    doc = {
        "schema": "esp.protocol/1",
        "identified": {"Ocy": {"value": -7.0, "unit": "um", "step": 1}},
    }
    (tmp_path / "i.json").write_text(json.dumps(doc), encoding="utf-8")
    table = {
        "chain": str(ANGLE),
        "errors_from": ["e.csv", "i.json"],
        "errors": {"ThetaCh": 20, "DY": {"value": 1, "unit": "urad"}},
        "parameters": {"G": {"value": 0.03, "unit": "m"}},
    }
    head = head_from_dict(table, base_dir=tmp_path, source="h.toml")
    assert head.errors["Ocx"] == pytest.approx(0.005)  # mm, the chain's unit
    assert head.errors["Ocy"] == pytest.approx(-0.007)
    assert head.errors["ThetaCh"] == 20.0  # the table wins over the file
    assert head.errors["DY"] == pytest.approx(1e-6 * 648000 / math.pi)  # arcsec
    assert head.parameters["G"] == pytest.approx(30.0)
    assert head.errors["ThetaAs"] == 100.0  # the chain's default
    assert head.origins["Ocx"] == "e.csv" and head.origins["ThetaCh"] == "h.toml"
    assert str(tmp_path / "e.csv") in head.inputs
    over = head.with_values({"ThetaCh": 5.0})
    assert over.errors["ThetaCh"] == 5.0 and over.origins["ThetaCh"] == "--set"


@pytest.mark.parametrize(
    ("table", "fragment"),
    [
        ({"chain": "x"} | {"erors": {}}, "head.erors: unknown key 'erors'; did you mean 'errors'?"),
        ({}, "head.chain: required key is missing"),
        ({"errors": {"Ocz": 1}}, "head.errors.Ocz: not an error of the chain; did you mean 'Ocy'?"),
        ({"errors": {"G": 1}}, "head.errors.G: G is a parameter of the chain, not an error"),
        ({"parameters": {"A": 1}}, "head.parameters.A: A is a coordinate of the chain"),
        ({"errors": {"Ocx": "5"}}, "head.errors.Ocx: expected a number"),
        ({"errors": {"Ocx": {"value": 5, "unit": "arcsec"}}}, "'arcsec' is a unit of angle"),
        (
            {"errors": {"Ocx": {"value": 5, "unti": "um"}}},
            "unknown key 'unti'; did you mean 'unit'?",
        ),
        ({"errors": {"Ocx": float("inf")}}, "expected a finite number"),
        ({"mcp": [0, 0]}, "head.mcp: expected [x, y, z]"),
        ({"errors_from": 3}, "head.errors_from: expected a file name"),
    ],
)
def test_bad_head_tables(table, fragment):
    table = {"chain": str(ANGLE)} | table if "chain" not in table and table else table
    if table.get("chain") == "x":
        table["chain"] = str(ANGLE)
    with pytest.raises(ConfigError) as info:
        head_from_dict(table, source="h.toml")
    assert fragment in str(info.value)
    assert "\n" not in str(info.value)


@pytest.mark.parametrize(
    ("text", "fragment"),
    [
        (
            "error,value\nOcxx,1\n",
            ":2: 'Ocxx' is not a small error of the chain; did you mean 'Ocx'?",
        ),
        ("error,value\nOcx,1\nOcx,2\n", ":3: Ocx is given twice"),
        ("error,value,value\nOcx,1,2\n", ":1: expected one column 'value', found 2"),
        ("error,value\nOcx,abc\n", ":2: Ocx: expected a number"),
        ("error,value\nOcx,nan\n", ":2: Ocx: expected a finite number"),
        ("name,value\nOcx,1\n", ":1: expected a header 'error,value[,unit]'"),
        ("error,value,unit\nOcx,1,deg\n", "'deg' is a unit of angle"),
        ("", "expected a header"),
    ],
)
def test_bad_error_files(tmp_path, text, fragment):
    (tmp_path / "e.csv").write_text(text, encoding="utf-8")
    with pytest.raises(ParseError) as info:
        head_from_dict({"chain": str(ANGLE), "errors_from": "e.csv"}, base_dir=tmp_path)
    assert fragment in str(info.value)


def test_bad_head_file_tables(tmp_path):
    def read(text):
        (tmp_path / "h.toml").write_text(f'[head]\nchain = "{ANGLE.as_posix()}"\n{text}', "utf-8")
        return read_head_file(tmp_path / "h.toml")

    cases = [
        ("[mapp]\n", "mapp: unknown table 'mapp'; did you mean 'map'?"),
        ("[map]\nA = { from = 0, to = 1, step = 1 }\n", "map.C: missing"),
        ("[map]\nB = 1\n", "map.B: unknown key 'B'"),
        (
            "[map]\nA = { from = 0, to = 1, step = 0 }\nC = { from = 0, to = 1, step = 1 }\n",
            "map.A.step: expected a step above zero",
        ),
        ("[protocol]\nassume_zero = ['DYY']\n", "protocol.assume_zero: unknown name 'DYY'"),
        ("[protocol]\nangels = [0, 90]\n", "did you mean 'angles'?"),
        ("[protocol]\nangles = [0]\n", "protocol.angles: expected at least two angles"),
    ]
    for text, fragment in cases:
        with pytest.raises(ConfigError) as info:
            read(text)
        assert fragment in str(info.value), text


# -- maps -------------------------------------------------------------------------------------


def test_map_extremes_and_where(angle):
    grid = [GridSpec("A", -60, 60, 15), GridSpec("C", -60, 60, 20)]
    m = error_map(angle, grid, order=1)
    assert m.shape == (9, 7)
    A, C = np.meshgrid(m.rows, m.cols, indexing="ij")
    ev = evaluate_head(angle, {"A": A.ravel(), "C": C.ravel()}, order=2)
    np.testing.assert_allclose(m.error_um.reshape(-1, 3), ev.first_um, atol=1e-12)
    ext = m.extremes()
    for k, axis in enumerate("XYZ"):
        i = int(np.argmax(ev.first_um[:, k]))
        assert ext[axis]["max"].value_um == ev.first_um[i, k]
        assert ext[axis]["max"].at == {"A": A.ravel()[i], "C": C.ravel()[i]}
    d = np.linalg.norm(ev.first_um, axis=1)
    assert ext["D"]["max"].value_um == pytest.approx(d.max())
    assert m.second_order_peak().value_um == pytest.approx(
        np.linalg.norm(ev.second_um, axis=1).max()
    )
    # order 2 reports first plus second
    m2 = error_map(angle, grid, order=2)
    np.testing.assert_allclose(m2.error_um.reshape(-1, 3), ev.first_um + ev.second_um, atol=1e-12)


def test_map_default_grid_is_the_papers():
    m = error_map(head_from_chain(load_chain(ANGLE)))
    assert m.names == ("A", "C")
    assert m.rows[0] == -60 and m.rows[-1] == 60 and m.cols.size == 49


def test_map_needs_two_angles():
    chain = K.Chain(
        [K.revolute("x", "A"), K.translate(0, 0, "-G")], {"G": {"kind": "parameter", "value": 1.0}}
    )
    with pytest.raises(ConfigError, match="a map is over two angles"):
        error_map(head_from_chain(chain))
