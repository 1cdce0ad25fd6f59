"""Positions handed to the library are taken as they are or refused: never reshaped into
other points, never NaN results, never a bare ValueError/TypeError/KeyError
(docs/reliability.md, "Positions given to the library")."""

from __future__ import annotations

import numpy as np
import pytest

import esp
from esp.core.errors import DataError, EspError
from esp.core.profile import ErrorProfile
from tests.conftest import build_machine


@pytest.fixture(scope="module")
def machine():
    # errors that differ from point to point, so a reshaped array gives other numbers
    return build_machine(
        {
            "X.linear": [(0.0, 0.0), (1000.0, 10.0)],
            "Y.linear": [(0.0, 0.0), (1000.0, -4.0)],
            "Z.linear": [(0.0, 0.0), (1000.0, 2.0)],
        }
    )


def test_errors_at_takes_n_by_3_and_one_point(machine):
    pts = np.array([[100.0, 200.0, 300.0], [500.0, 600.0, 700.0]])
    got = esp.errors_at(machine, pts)
    # linear errors: 10 µm/1000 mm along X, -4 along Y, 2 along Z
    assert got == pytest.approx(np.array([[1.0, -0.8, 0.6], [5.0, -2.4, 1.4]]))
    assert esp.errors_at(machine, [100.0, 200.0, 300.0]) == pytest.approx(got[:1])


@pytest.mark.parametrize(
    "points, found",
    [
        (np.array([[100.0, 200.0, 300.0], [500.0, 600.0, 700.0]]).T, "shape (3, 2)"),
        ([500.0, 750.0], "shape (2,)"),
        (500.0, "shape ()"),
        ([[1.0, 2.0, 3.0, 4.0]], "shape (1, 4)"),
        ([[1.0, 2.0], [3.0]], "list"),
        ([1 + 2j, 0.0, 0.0], "real numbers"),
        ("abc", "real numbers"),
        ([[True, False, True]], "real numbers"),
        ([[np.nan, 0.0, 0.0]], "found nan at index (0, 0)"),
        ([[0.0, 0.0, np.inf]], "found inf at index (0, 2)"),
        ([[0.0, 1500.0, 0.0]], "Y=1500 mm is outside axes.Y.travel"),
    ],
)
def test_errors_at_refuses_what_is_not_positions(machine, points, found):
    with pytest.raises(DataError, match="points_mm") as info:
        esp.errors_at(machine, points)
    assert found in str(info.value)
    assert isinstance(info.value, EspError) and isinstance(info.value, ValueError)


def test_a_position_within_rounding_of_the_travel_end_is_the_end(machine):
    """A diagonal's point computed from its distance written to six decimals may lie a few
    1e-7 mm beyond the travel: it is the end (the tolerance of a measured curve's range,
    1e-9 of the larger end), and its error is the end's (X linear: 10 µm at 1000 mm);
    a micrometre beyond is outside."""
    got = esp.errors_at(machine, [1000.0 + 5e-7, 0.0, 0.0])
    assert got[0, 0] == pytest.approx(10.0, abs=1e-6)
    with pytest.raises(DataError, match="X=1000 mm is outside axes.X.travel"):
        esp.errors_at(machine, [1000.001, 0.0, 0.0])


def test_errors_at_of_a_result_checks_the_same(machine):
    result = esp.analyse(machine)
    with pytest.raises(DataError, match=r"shape \(3, 2\)"):
        esp.errors_at(result, np.zeros((3, 2)))


@pytest.mark.parametrize(
    "at, found",
    [
        ({"X": 1.0, "Y": 1.0}, "missing Z"),
        ({"X": 1.0, "Y": 1.0, "Z": 1.0, "W": 2.0}, "unknown W"),
        ({"X": np.nan, "Y": 1.0, "Z": 1.0}, "found nan"),
        ({"X": 1j, "Y": 1.0, "Z": 1.0}, "real numbers"),
        ({"X": "1", "Y": 1.0, "Z": 1.0}, "real numbers"),
        ({"X": [1.0, 2.0], "Y": 1.0, "Z": 1.0}, "one position"),
        ([1.0, 2.0, 3.0], "a mapping"),
    ],
)
def test_evaluate_point_refuses_what_is_not_a_position(machine, at, found):
    with pytest.raises(DataError) as info:
        esp.evaluate_point(machine, at)
    assert found in str(info.value)


def test_evaluate_point_agrees_with_errors_at(machine):
    point = esp.evaluate_point(machine, {"X": 100.0, "Y": 200.0, "Z": 300.0})
    totals = point.cases[0].breakdown.errors_um
    got = esp.errors_at(machine, [100.0, 200.0, 300.0])[0]
    assert [totals[a] for a in "XYZ"] == pytest.approx(list(got))


@pytest.mark.parametrize("x", [[np.nan], [1j], "a", [[0.0, np.inf]]])
def test_profile_at_refuses_what_is_not_positions(x):
    profile = ErrorProfile.from_values("linear", [0.0, 100.0], [0.0, 1.0])
    assert profile.at([50.0]) == pytest.approx([0.5])
    with pytest.raises(DataError, match="positions_mm"):
        profile.at(x)
