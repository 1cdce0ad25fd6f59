"""Measurement protocols (Freeman & Ford 2003, section 5): the paper's example 2·O_Cx, every
equation against the numeric first order, the round trip synthetic errors -> predicted
differences -> solve -> the same errors, the measured file, impossible requests."""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np
import pytest

import esp.core.kinematics as K
from esp.config.chain import load_chain
from esp.core.errors import ConfigError, DataError, ParseError
from esp.heads import build_protocol, head_from_chain, predict_differences, solve_protocol
from esp.heads.config import read_head_file
from esp.heads.measured import read_measured

sp = pytest.importorskip("sympy")

ROOT = Path(__file__).resolve().parent.parent
HEADS = ROOT / "data/examples/heads"
ANGLE = HEADS / "angle-head.toml"
FIG3 = HEADS / "angle-head-fig3.toml"
FORK_EXAMPLE = HEADS / "fork-head-example.toml"


@pytest.fixture(scope="module")
def angle_head():
    return head_from_chain(load_chain(ANGLE))


@pytest.fixture(scope="module")
def angle_protocol(angle_head):
    start = time.perf_counter()
    protocol = build_protocol(angle_head, assume_zero=["DY", "ThetaAv"])
    elapsed = time.perf_counter() - start
    assert elapsed < 20.0, f"the protocol search took {elapsed:.1f} s"
    return protocol


@pytest.fixture(scope="module")
def fork_protocol():
    spec = read_head_file(FORK_EXAMPLE)
    return build_protocol(spec.head, assume_zero=spec.protocol.assume_zero)


@pytest.mark.slow
def test_the_papers_example_two_ocx(angle_protocol):
    """Freeman & Ford (2003), section 5: X measured at A = 90°, C = 0 and at A = 270°,
    C = 180° differs by 2·O_Cx. esp's search finds exactly that test for O_Cx."""
    step = next(s for s in angle_protocol.steps if s.errors == ("Ocx",))
    test = angle_protocol.test(step.tests[0])
    assert test.axis == "X"
    assert dict(test.first) == {"A": 90.0, "C": 0.0}
    assert dict(test.second) == {"A": 270.0, "C": 180.0}
    assert sp.sympify(test.difference) == 2 * sp.Symbol("Ocx")
    assert step.solution["Ocx"] == f"{test.symbol}/2"
    # numerically, whatever the other errors (all eight, also those assumed zero)
    rng = np.random.default_rng(1)
    errors = {e: rng.normal(0, 50) for e in angle_protocol.head.chain.errors}
    errors["Ocx"] = 0.004
    errors["Ocy"] = -0.02
    errors["Oas"] = 0.01
    d = predict_differences(angle_protocol, errors)
    assert d[test.number] == pytest.approx(2 * 0.004 * 1000, abs=1e-9)


@pytest.mark.slow
def test_angle_head_protocol_identifies_every_other_error(angle_protocol):
    assert set(angle_protocol.identify) == {"Ocx", "ThetaCv", "ThetaCh", "Oas", "ThetaAs", "Ocy"}
    assert angle_protocol.searched == 360  # 16 settings: 120 pairs, 3 directions
    for t in angle_protocol.tests:
        assert t.first != t.second
        # no test holds an error assumed zero, or one identified later
        names = {str(s) for s in sp.sympify(t.difference).free_symbols}
        later = {u for s in angle_protocol.steps[t.step :] for u in s.errors}
        assert not names & {"DY", "ThetaAv"} and not names & later


@pytest.mark.slow
@pytest.mark.parametrize("which", ["angle", "fork"])
def test_every_equation_equals_the_numeric_first_order(which, angle_protocol, fork_protocol):
    """Each test's formula (sympy text, mm and rad), evaluated with random error values,
    equals the difference the numeric first order predicts (µm)."""
    protocol = angle_protocol if which == "angle" else fork_protocol
    head = protocol.head
    chain = head.chain
    rng = np.random.default_rng(4)
    errors = {e: float(rng.normal(0, 20)) for e in chain.errors}
    for e in protocol.assume_zero:
        errors[e] = 0.0
    predicted = predict_differences(protocol, errors)
    env = {sp.Symbol(n): v * chain.symbols[n].scale for n, v in head.parameters.items()}
    env.update({sp.Symbol(n): v * chain.symbols[n].scale for n, v in errors.items()})
    for t in protocol.tests:
        value_mm = float(sp.sympify(t.difference).subs(env))
        assert value_mm * 1000 == pytest.approx(predicted[t.number], abs=1e-9), t.equation
        # the sensitivities are the numeric coefficients
        again = sum(t.coefficients_um[e] * errors[e] for e in t.coefficients_um)
        assert again == pytest.approx(predicted[t.number], abs=1e-9)


@pytest.mark.parametrize("which", ["angle", "fork"])
def test_round_trip(which, angle_protocol, fork_protocol):
    """Synthetic errors -> predicted differences -> solve -> the same errors."""
    protocol = angle_protocol if which == "angle" else fork_protocol
    chain = protocol.head.chain
    rng = np.random.default_rng(12)
    errors = {}
    for e in chain.errors:
        errors[e] = float(rng.normal(0, 0.01 if chain.symbols[e].unit == "mm" else 30))
    for e in protocol.assume_zero:
        errors[e] = 0.0
    measured = predict_differences(protocol, errors)
    identified = solve_protocol(protocol, measured)
    assert list(identified) == list(protocol.identify)
    for e, v in identified.items():
        assert v == pytest.approx(errors[e], abs=1e-9 * max(1.0, abs(errors[e]))), e


def test_round_trip_through_the_exact_chain(fork_protocol):
    """Measured by the exact chain (second order and beyond included), the identified
    values differ from the true ones by the second-order terms only."""
    head = fork_protocol.head
    chain, params = head.chain, head.values_in("parameter")
    truth = {e: 30.0 for e in chain.errors} | {"EY0S": 0.0}
    measured = {}
    for t in fork_protocol.tests:
        at = {c: np.array([t.first[c], t.second[c]]) for c in fork_protocol.coordinates}
        d = (K.position(chain, at, params, truth) - K.position(chain, at, params)) * 1000
        measured[t.number] = float(d[0, "XYZ".index(t.axis)] - d[1, "XYZ".index(t.axis)])
    identified = solve_protocol(fork_protocol, measured)
    for e, v in identified.items():
        assert v == pytest.approx(truth[e], abs=0.05), e  # 30 µrad: (3e-5)² × 400 mm ≈ 0.4 nm


def test_an_assumption_is_absorbed_as_the_protocol_says(angle_protocol):
    """With DY ≠ 0 but assumed zero, the identified O_As is O_As + G·DY (the combination
    the search names)."""
    errors = {"Oas": 0.002, "DY": 20.0}  # mm, arcsec
    identified = solve_protocol(angle_protocol, predict_differences(angle_protocol, errors))
    G = 20.0
    assert identified["Oas"] == pytest.approx(0.002 + G * 20.0 * np.pi / 648000, abs=1e-12)


@pytest.mark.slow
def test_known_errors_are_carried(angle_head):
    head = angle_head.with_values({"Oas": 0.004})
    protocol = build_protocol(head, assume_zero=["DY", "ThetaAv"], known=["Oas"])
    assert "Oas" not in protocol.identify and protocol.known == ("Oas",)
    errors = {"Oas": 0.004, "Ocy": -0.01, "ThetaAs": 50.0}
    identified = solve_protocol(protocol, predict_differences(protocol, errors))
    assert identified["Ocy"] == pytest.approx(-0.01, abs=1e-12)
    assert identified["ThetaAs"] == pytest.approx(50.0, abs=1e-9)
    assert any("Oas" in t.known for t in protocol.tests)


@pytest.mark.slow
def test_settings_of_other_angles(angle_head):
    protocol = build_protocol(angle_head, angles=[0, 90, 180], assume_zero=["DY", "ThetaAv"])
    assert protocol.searched == 3 * 36
    assert {v for t in protocol.tests for v in (*t.first.values(), *t.second.values())} <= {
        0.0,
        90.0,
        180.0,
    }
    errors = {"Ocx": 0.003, "ThetaCh": 10.0, "Ocy": 0.001}
    identified = solve_protocol(protocol, predict_differences(protocol, errors))
    assert identified["Ocx"] == pytest.approx(0.003, abs=1e-12)


# -- impossible requests ------------------------------------------------------------------------


@pytest.mark.slow
def test_confounded_errors_are_named(angle_head):
    with pytest.raises(DataError) as info:
        build_protocol(angle_head)
    message = str(info.value)
    assert "ThetaAs cannot be isolated" in message
    assert "ThetaAs - ThetaAv*cos(Yp)" in message and "--assume-zero" in message
    with pytest.raises(DataError, match=r"Oas and DY act only together, as DY\*G \+ Oas"):
        build_protocol(angle_head, assume_zero=["ThetaAv"])


def test_an_error_in_no_difference():
    """An offset of the whole head moves the tool tip the same at every setting."""
    chain = K.Chain(
        [
            K.error_motion(tz="dZ"),
            K.revolute("z", "C"),
            K.revolute("x", "A"),
            K.error_motion(ty="dY"),
            K.translate(0, 0, "-G"),
        ],
        {"G": {"kind": "parameter", "value": 100.0}},
    )
    with pytest.raises(DataError, match="dZ cannot be isolated: it moves the tool tip the same"):
        build_protocol(head_from_chain(chain))
    protocol = build_protocol(head_from_chain(chain), assume_zero=["dZ"])
    assert protocol.identify == ("dY",)


@pytest.mark.parametrize(
    ("kwargs", "exc", "fragment"),
    [
        (
            {"assume_zero": ["DYY"]},
            ConfigError,
            "--assume-zero: unknown error 'DYY'; did you mean 'DY'?",
        ),
        ({"assume_zero": ["G"]}, ConfigError, "G is a parameter of the head, not a small error"),
        ({"known": ["Ocq"]}, ConfigError, "--known: unknown error"),
        ({"assume_zero": ["DY"], "identify": ["DY"]}, ConfigError, "DY is assumed zero"),
        ({"angles": [0]}, ConfigError, "at least two distinct angles"),
        ({"angles": [0, 90, 90]}, ConfigError, "an angle is given twice"),
        ({"assume_zero": ["DY"], "known": ["DY"]}, ConfigError, "also assumed zero"),
    ],
)
def test_bad_requests(angle_head, kwargs, exc, fragment):
    with pytest.raises(exc) as info:
        build_protocol(angle_head, **kwargs)
    assert fragment in str(info.value)


# -- the measured file ------------------------------------------------------------------------


def test_shipped_measured_file_solves(fork_protocol):
    measured = read_measured(HEADS / "fork-head-measured.csv", fork_protocol)
    identified = solve_protocol(fork_protocol, measured)
    # make_data.py: the head's actual errors; EA0A holds EA0A + EY0S/G; 0.1 µm reading steps
    actual = {"EA0C": 17.3, "EB0C": -8.6, "EC0C": 23.1, "EY0A": 6.4, "EB0A": 13.7, "EB0S": 9.2}
    actual["EA0A"] = -21.9 + 1.5 / 200.0 * 1000
    for e, v in actual.items():
        assert identified[e] == pytest.approx(v, abs=0.3), e


@pytest.mark.parametrize(
    ("text", "exc", "fragment"),
    [
        ("test,difference_um\n1,3\n", DataError, "test 2 (dZ_2) has no measured difference"),
        ("test,difference_um\n9,3\n", ParseError, ":2: test 9 is not in the protocol"),
        ("test,difference_um\n1,3\n1,4\n", ParseError, ":3: test 1 is given twice"),
        ("test,axis,difference_um\n1,X,3\n", ParseError, "measures Y; the file does not match"),
        ("test,A1,C1,A2,C2,difference_um\n1,90,0,90,90,3\n", ParseError, "C2 = 90, but"),
        ("test,value\n1,3\n", ParseError, "unknown column 'value'"),
        ("test,difference_um\n1,abc\n", ParseError, "difference_um: expected a number"),
        ("test,difference_um\n1,inf\n", ParseError, "expected a finite number"),
        ("test,difference_um\n1\n", ParseError, "expected 2 columns, found 1"),
        ("", ParseError, "expected a header"),
    ],
)
def test_bad_measured_files(tmp_path, fork_protocol, text, exc, fragment):
    path = tmp_path / "m.csv"
    path.write_text(text, encoding="utf-8")
    with pytest.raises(exc) as info:
        read_measured(path, fork_protocol)
    assert fragment in str(info.value)
    assert "\n" not in str(info.value)


def test_measured_in_mm_and_settings_modulo_360(tmp_path, fork_protocol):
    rows = ["test,A1,C1,A2,C2,difference_mm"]
    for t in fork_protocol.tests:
        first = [t.first["A"] - 360, t.first["C"]]
        rows.append(
            f"{t.number},{first[0]:g},{first[1]:g},{t.second['A']:g},{t.second['C']:g},0.001"
        )
    path = tmp_path / "m.csv"
    path.write_text("\n".join(rows) + "\n", encoding="utf-8")
    measured = read_measured(path, fork_protocol)
    assert set(measured.values()) == {1.0}


def test_three_errors_that_act_together():
    """c moves the tip as a and b together: no pair is confounded, the three are; the
    message gives the change that moves nothing."""
    chain = K.Chain(
        [
            K.revolute("z", "C"),
            K.error_motion(tx="a"),
            K.error_motion(ty="b"),
            K.error_motion(tx="c", ty="c"),
            K.revolute("x", "A"),
            K.translate(0, 0, "-G"),
        ],
        {"G": {"kind": "parameter", "value": 100.0}},
    )
    with pytest.raises(DataError) as info:
        build_protocol(head_from_chain(chain))
    message = str(info.value)
    assert "a cannot be isolated: changing a by 1 um, b by 1 um, c by -1 um together" in message
    protocol = build_protocol(head_from_chain(chain), assume_zero=["c"])
    assert set(protocol.identify) == {"a", "b"}
