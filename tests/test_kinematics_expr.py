"""The safe expression parser of chain quantities: whitelist, values, exact derivatives,
Taylor jets, display round trip, sympy conversion."""

from __future__ import annotations

import math

import numpy as np
import pytest

from esp.core.errors import ConfigError
from esp.core.kinematics.expr import Jet, as_expr, check_name, parse_expr

ENV = {"G": 20.0, "e": 10.0, "Yp": math.radians(50), "a": 0.3, "b": -1.7}


@pytest.mark.parametrize(
    "text, expected",
    [
        ("20", 20.0),
        ("-e/tan(Yp)", -10.0 / math.tan(math.radians(50))),
        (
            "G*sin(Yp)*cos(a) - (e + 2)/b",
            20 * math.sin(math.radians(50)) * math.cos(0.3) + 12 / 1.7,
        ),
        ("deg(90)", math.pi / 2),
        ("pi/4 + +a", math.pi / 4 + 0.3),
        ("-(-a)", 0.3),
        ("1e-3*G", 0.02),
        ("a - (b - a)", 0.3 - (-1.7 - 0.3)),
        ("a/(b/a)", 0.3 / (-1.7 / 0.3)),
    ],
)
def test_values(text, expected):
    assert parse_expr(text, "k").evaluate(ENV) == pytest.approx(expected, rel=1e-14)


@pytest.mark.parametrize(
    "text, words",
    [
        ("G**2", "a power"),
        ("__import__('os')", "unknown function '__import__'"),
        ("os.system", "an attribute"),
        ("G if a else b", "'if'"),
        ("a < b", "a comparison"),
        ("'text'", "not a number"),
        ("sqrt(a)", "unknown function 'sqrt'"),
        ("sin(a, b)", "exactly one argument"),
        ("sin", "is a function"),
        ("deg(Yp)", "converts a number of degrees"),
        ("lambda: 1", "a lambda"),
        ("a[0]", "an index"),
        ("", "empty"),
        ("1 +", "cannot read"),
        ("(" * 300 + "a" + ")" * 300, ""),
        ("a" * 500, "longer than"),
        ("1j", "not a number"),
        ("True", "not a number"),
    ],
)
def test_refused(text, words):
    with pytest.raises(ConfigError) as info:
        parse_expr(text, "steps[1].angle")
    message = str(info.value)
    assert message.startswith("steps[1].angle: ")
    assert "\n" not in message
    assert words in message


def test_names_and_reserved_words():
    assert parse_expr("G*sin(Yp) + e", "k").names() == {"G", "Yp", "e"}
    assert check_name("dx_Y", "k") == "dx_Y"
    for bad in ("pi", "sin", "2x", "x-y", "", "if", None, "é"):
        with pytest.raises(ConfigError):
            check_name(bad, "symbols.x")


def test_as_expr_numbers():
    assert as_expr(3, "k").evaluate({}) == 3.0
    assert as_expr(np.float64(2.5), "k").evaluate({}) == 2.5
    for bad in (float("nan"), float("inf"), True, None, [1]):
        with pytest.raises(ConfigError):
            as_expr(bad, "k")


@pytest.mark.parametrize(
    "text",
    ["-e/tan(Yp)", "G*sin(Yp)*cos(a)", "a*b/(G - b)", "tan(a*b) - cos(-a)/G", "-(a - b)*(e/a)"],
)
def test_exact_derivative_against_finite_differences(text):
    expr = parse_expr(text, "k")
    for name in sorted(expr.names()):
        d = expr.diff(name).evaluate(ENV)
        h = 1e-6 * max(1.0, abs(ENV[name]))
        up = expr.evaluate({**ENV, name: ENV[name] + h})
        down = expr.evaluate({**ENV, name: ENV[name] - h})
        assert d == pytest.approx((up - down) / (2 * h), rel=1e-7, abs=1e-9), (text, name)
    assert expr.diff("absent").is_zero()


@pytest.mark.parametrize("text", ["-e/tan(Yp)", "G*sin(Yp)*cos(a)", "a*b/(G - b)", "tan(a) + 1"])
def test_display_round_trip(text):
    expr = parse_expr(text, "k")
    again = parse_expr(str(expr), "k")
    assert again.evaluate(ENV) == expr.evaluate(ENV)
    assert again == expr


def test_jets_are_taylor_coefficients():
    """c0 + c1 λ + c2 λ² of f(a + λ da), against a hand expansion and finite differences."""
    expr = parse_expr("G*sin(Yp + a)/cos(b) + tan(a*b)", "k")
    da, db = 0.01, -0.02
    env = {
        "G": Jet((20.0, 0.0, 0.0)),
        "Yp": Jet((ENV["Yp"], 0.0, 0.0)),
        "a": Jet((0.3, da, 0.0)),
        "b": Jet((-1.7, db, 0.0)),
    }
    c0, c1, c2 = expr.jet(env, np).c

    def f(lam):
        return expr.evaluate({**ENV, "a": 0.3 + lam * da, "b": -1.7 + lam * db})

    h = 1e-3
    assert c0 == pytest.approx(f(0.0), rel=1e-14)
    assert c1 == pytest.approx((f(h) - f(-h)) / (2 * h), rel=1e-6)
    assert c2 == pytest.approx((f(h) - 2 * f(0.0) + f(-h)) / (2 * h * h), rel=1e-4)


def test_jet_truncation_and_zero_placeholders():
    a = Jet((1.0, 2.0, 3.0))
    b = Jet((0, 1.0))
    prod = a * b
    assert prod.c == (0, 1.0, 2.0)
    assert (a / Jet((2.0,))).c == (0.5, 1.0, 1.5)
    assert Jet.constant(5.0, 2).c == (5.0, 0, 0)


def test_sympy_conversion_is_exact():
    sp = pytest.importorskip("sympy")
    syms = {n: sp.Symbol(n) for n in ("G", "e", "Yp", "a")}
    expr = parse_expr("-e/tan(Yp) + 0.1*G + deg(90)*a", "k").to_sympy(sp, syms)
    G, e, Yp, a = syms["G"], syms["e"], syms["Yp"], syms["a"]
    assert sp.simplify(expr - (-e / sp.tan(Yp) + G / 10 + sp.pi / 2 * a)) == 0
