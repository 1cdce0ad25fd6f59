"""ISO 230-2:2014 positioning statistics (esp.iso230.positioning), checked against hand
arithmetic."""

from __future__ import annotations

import json
import math
import subprocess
import sys

import numpy as np
import pytest

from esp.core.errors import DataError
from esp.core.profile import ErrorProfile
from esp.iso230.positioning import AXIS_KEYS, TARGET_KEYS, Iso230Result, iso230_2
from esp.report.jsonout import dumps

SQRT3 = math.sqrt(3.0)


def linear(targets, forward=None, backward=None, **kwargs) -> ErrorProfile:
    runs = {}
    if forward is not None:
        runs["forward"] = forward
    if backward is not None:
        runs["backward"] = backward
    return ErrorProfile("linear", targets, runs, **kwargs)


# --- the worked example --------------------------------------------------------------------
#
# Three targets (0, 100, 200 mm), three runs in each direction, deviations in µm.
#
#   forward (↑)  run 1:  0  2  4        backward (↓)  run 1: -2  1  2
#                run 2:  1  3  4                      run 2: -2  1  2
#                run 3:  2  4  7                      run 3: -2  4  2
#
# Means:      x̄↑ = (0+1+2)/3, (2+3+4)/3, (4+4+7)/3 = 1, 3, 5
#             x̄↓ = -6/3, (1+1+4)/3, 6/3            = -2, 2, 2
# Sample standard deviations (n - 1 = 2):
#   s↑: target 1: ((-1)² + 0² + 1²)/2 = 1 -> 1;  target 2: the same -> 1;
#       target 3: ((-1)² + (-1)² + 2²)/2 = 3 -> √3
#   s↓: target 1: 0;  target 2: ((-1)² + (-1)² + 2²)/2 = 3 -> √3;  target 3: 0
# Reversal Bi = x̄↑ - x̄↓ = 1-(-2), 3-2, 5-2 = 3, 1, 3
# R↑ = 4 s↑ = 4, 4, 4√3;  R↓ = 4 s↓ = 0, 4√3, 0
# Ri = max(2s↑ + 2s↓ + |Bi|, R↑, R↓):
#   target 1: max(2 + 0 + 3 = 5, 4, 0)            = 5     (the combined term wins)
#   target 2: max(2 + 2√3 + 1 = 6.464, 4, 4√3)    = 4√3   (R↓ wins)
#   target 3: max(2√3 + 0 + 3 = 6.464, 4√3, 0)    = 4√3   (R↑ wins)
# Axis:
#   B = max|Bi| = 3;  B_mean = (3 + 1 + 3)/3 = 7/3
#   R↑ = 4√3, R↓ = 4√3, R = max(5, 4√3, 4√3) = 4√3
#   E↑ = 5 - 1 = 4;  E↓ = 2 - (-2) = 4;  E = max(1,3,5,-2,2,2) - min(...) = 5 - (-2) = 7
#   x̄i = (1-2)/2, (3+2)/2, (5+2)/2 = -0.5, 2.5, 3.5;  M = 3.5 - (-0.5) = 4
#   A↑ = max(1+2, 3+2, 5+2√3) - min(1-2, 3-2, 5-2√3) = (5+2√3) - (-1) = 6 + 2√3
#   A↓ = max(-2+0, 2+2√3, 2+0) - min(-2-0, 2-2√3, 2-0) = (2+2√3) - (-2) = 4 + 2√3
#   A = max over both of x̄+2s - min over both of x̄-2s = (5+2√3) - (-2) = 7 + 2√3

WORKED_TARGETS = [0.0, 100.0, 200.0]
WORKED_FORWARD = [[0, 2, 4], [1, 3, 4], [2, 4, 7]]
WORKED_BACKWARD = [[-2, 1, 2], [-2, 1, 2], [-2, 4, 2]]


@pytest.fixture
def worked() -> Iso230Result:
    return iso230_2(
        linear(WORKED_TARGETS, WORKED_FORWARD, WORKED_BACKWARD, axis="X", source="x.rtl")
    )


def test_worked_example_per_target(worked):
    np.testing.assert_allclose(worked.targets_mm, [0.0, 100.0, 200.0])
    np.testing.assert_allclose(worked.mean_up, [1, 3, 5])
    np.testing.assert_allclose(worked.mean_down, [-2, 2, 2])
    np.testing.assert_allclose(worked.s_up, [1, 1, SQRT3])
    np.testing.assert_allclose(worked.s_down, [0, SQRT3, 0], atol=1e-12)
    np.testing.assert_allclose(worked.B_i, [3, 1, 3])
    np.testing.assert_allclose(worked.R_up_i, [4, 4, 4 * SQRT3])
    np.testing.assert_allclose(worked.R_down_i, [0, 4 * SQRT3, 0], atol=1e-12)
    np.testing.assert_allclose(worked.R_i, [5, 4 * SQRT3, 4 * SQRT3])
    np.testing.assert_allclose(worked.mean_bidirectional, [-0.5, 2.5, 3.5])


def test_worked_example_axis(worked):
    expected = {
        "A": 7 + 2 * SQRT3,
        "A_up": 6 + 2 * SQRT3,
        "A_down": 4 + 2 * SQRT3,
        "B": 3.0,
        "B_mean": 7 / 3,
        "E": 7.0,
        "E_up": 4.0,
        "E_down": 4.0,
        "M": 4.0,
        "R": 4 * SQRT3,
        "R_up": 4 * SQRT3,
        "R_down": 4 * SQRT3,
    }
    got = worked.axis_values()
    assert list(got) == list(AXIS_KEYS)
    for key, value in expected.items():
        assert got[key] == pytest.approx(value, abs=1e-12), key


def test_worked_example_metadata_and_note(worked):
    assert worked.bidirectional
    assert dict(worked.runs) == {"up": 3, "down": 3}
    assert worked.axis == "X" and worked.source == "x.rtl" and worked.unit == "um"
    assert len(worked.notes) == 1
    assert "at least 5 runs" in worked.notes[0]
    assert "up 3" in worked.notes[0] and "down 3" in worked.notes[0]


def test_worked_example_json_contract(worked):
    d = json.loads(dumps(worked.to_dict()))
    assert list(d) == ["schema", "unit", "bidirectional", "runs", "axis", "targets", "notes"]
    assert d["schema"] == "esp.iso230-2/1"
    assert d["unit"] == "um"
    assert d["bidirectional"] is True
    assert d["runs"] == {"up": 3, "down": 3}
    assert list(d["axis"]) == list(AXIS_KEYS)
    assert d["axis"]["E"] == 7.0
    assert d["axis"]["A"] == pytest.approx(7 + 2 * SQRT3, abs=1e-6)
    assert [list(row) for row in d["targets"]] == [list(TARGET_KEYS)] * 3
    assert d["targets"][0] == {
        "position_mm": 0.0,
        "mean_up": 1.0,
        "mean_down": -2.0,
        "s_up": 1.0,
        "s_down": 0.0,
        "B": 3.0,
        "R_up": 4.0,
        "R_down": 0.0,
        "R": 5.0,
    }
    assert d["targets"][1]["R"] == pytest.approx(4 * SQRT3, abs=1e-6)


# --- each definition on tiny inputs -------------------------------------------------------


def test_standard_deviation_uses_n_minus_1():
    # two runs 0 and 2: mean 1, s = sqrt(((0-1)² + (2-1)²) / (2-1)) = sqrt(2), not 1
    r = iso230_2(linear([0.0], [[0.0], [2.0]]))
    assert r.s_up[0] == pytest.approx(math.sqrt(2.0))
    assert r.R_up == pytest.approx(4 * math.sqrt(2.0))


def test_reversal_sign_and_axis_value():
    # x̄↑ = 1, 0 ; x̄↓ = 0, 4  ->  Bi = +1, -4 ; B = max|Bi| = 4 ; B_mean = (1 - 4)/2 = -1.5
    r = iso230_2(linear([0.0, 10.0], [[1, 0], [1, 0]], [[0, 4], [0, 4]]))
    np.testing.assert_allclose(r.B_i, [1.0, -4.0])
    assert r.B == 4.0
    assert r.B_mean == -1.5


def test_reversal_changes_sign_when_directions_swap():
    fwd, bwd = [[1, 5], [3, 5]], [[0, 0], [0, 2]]
    a = iso230_2(linear([0.0, 10.0], fwd, bwd))
    b = iso230_2(linear([0.0, 10.0], bwd, fwd))
    np.testing.assert_allclose(b.B_i, -a.B_i)
    assert b.B_mean == pytest.approx(-a.B_mean)
    assert b.B == a.B and b.R == a.R and b.E == a.E and b.M == a.M and b.A == a.A


@pytest.mark.parametrize(
    ("fwd", "bwd", "expected"),
    [
        # s↑ = s↓ = 0 (identical runs), |B| = 3: combined term 0 + 0 + 3 = 3 wins over 0, 0
        ([[3], [3]], [[0], [0]], 3.0),
        # runs 0, 2 -> s↑ = √2, R↑ = 4√2 = 5.657; s↓ = 0, B = 1 - 1 = 0:
        # combined 2√2 + 0 + 0 = 2.828 < R↑ -> R↑ wins
        ([[0], [2]], [[1], [1]], 4 * math.sqrt(2.0)),
        # the same, mirrored: R↓ wins
        ([[1], [1]], [[0], [2]], 4 * math.sqrt(2.0)),
    ],
)
def test_bidirectional_repeatability_picks_largest(fwd, bwd, expected):
    r = iso230_2(linear([0.0], fwd, bwd))
    assert r.R_i[0] == pytest.approx(expected)
    assert r.axis_values()["R"] == pytest.approx(expected)


def test_systematic_deviation_spans_both_directions():
    # x̄↑ = 0, 1 ; x̄↓ = -3, -2 : E↑ = 1, E↓ = 1, E = 1 - (-3) = 4
    # x̄i = -1.5, -0.5 : M = 1  (M can be smaller than E)
    r = iso230_2(linear([0.0, 10.0], [[0, 1], [0, 1]], [[-3, -2], [-3, -2]]))
    assert (r.E_up, r.E_down, r.E) == (1.0, 1.0, 4.0)
    assert r.M == 1.0


def test_accuracy_uses_two_sigma_bands_of_both_directions():
    # ↑ runs 0, 2 at one target: x̄ = 1, s = √2;  ↓ runs 5, 5: x̄ = 5, s = 0
    # A↑ = (1 + 2√2) - (1 - 2√2) = 4√2 ; A↓ = 5 - 5 = 0 ; A = 5 - (1 - 2√2) = 4 + 2√2
    r = iso230_2(linear([0.0], [[0], [2]], [[5], [5]]))
    assert r.A_up == pytest.approx(4 * math.sqrt(2.0))
    assert r.A_down == pytest.approx(0.0)
    assert r.axis_values()["A"] == pytest.approx(4 + 2 * math.sqrt(2.0))


# ISO 230-2:2014, clause 2 (bidirectional accuracy of positioning of an axis):
#   A = max(x̄i↑ + 2si↑, x̄i↓ + 2si↓) − min(x̄i↑ − 2si↑, x̄i↓ − 2si↓)
# The two cases below put the extreme band edge in the ↓ direction at a target where s↓ > 0,
# so that a formula dropping the ↓ direction's 2s (on either side) gives another A.
#
# Targets 0 and 100 mm, three runs in each direction (n - 1 = 2).
#   ↑ target 1: 0, 1, 2 -> x̄ = 1, s = sqrt((1 + 0 + 1)/2) = 1
#     target 2: 1, 1, 1 -> x̄ = 1, s = 0
#   ↓ target 1: 2, 2, 2 -> x̄ = 2, s = 0
#     target 2: 4, 6, 8 -> x̄ = 6, s = sqrt((4 + 0 + 4)/2) = 2
# Upper band edges x̄ + 2s:  ↑ 3, 1;  ↓ 2, 6 + 4 = 10   -> the largest, 10, is ↓ at target 2
# Lower band edges x̄ - 2s:  ↑ -1, 1; ↓ 2, 6 - 4 = 2    -> the smallest, -1, is ↑ at target 1
# A = 10 - (-1) = 11   (with x̄↓ alone in the upper edge: 6 - (-1) = 7)
# A↑ = 3 - (-1) = 4;  A↓ = 10 - 2 = 8
# Bi = 1 - 2, 1 - 6 = -1, -5 -> B = 5;  E = 6 - 1 = 5
# Ri = max(2s↑ + 2s↓ + |Bi|, 4s↑, 4s↓): target 1 max(2 + 0 + 1, 4, 0) = 4,
#      target 2 max(0 + 4 + 5, 0, 8) = 9  -> R = 9
DOWN_HIGH_FORWARD = [[0, 1], [1, 1], [2, 1]]
DOWN_HIGH_BACKWARD = [[2, 4], [2, 6], [2, 8]]


def test_accuracy_when_the_down_direction_holds_the_maximum_band_edge():
    r = iso230_2(linear([0.0, 100.0], DOWN_HIGH_FORWARD, DOWN_HIGH_BACKWARD))
    np.testing.assert_allclose(r.mean_down, [2.0, 6.0])
    np.testing.assert_allclose(r.s_down, [0.0, 2.0], atol=1e-12)
    np.testing.assert_allclose(r.s_up, [1.0, 0.0], atol=1e-12)
    got = r.axis_values()
    expected = {"A": 11.0, "A_up": 4.0, "A_down": 8.0, "B": 5.0, "E": 5.0, "R": 9.0}
    for key, value in expected.items():
        assert got[key] == pytest.approx(value, abs=1e-12), key


# The mirror image: every deviation negated (means negate, standard deviations stay).
#   ↑ x̄ = -1, -1, s = 1, 0;   ↓ x̄ = -2, -6, s = 0, 2
# Upper band edges x̄ + 2s:  ↑ 1, -1;  ↓ -2, -6 + 4 = -2  -> the largest, 1, is ↑ at target 1
# Lower band edges x̄ - 2s:  ↑ -3, -1; ↓ -2, -6 - 4 = -10 -> the smallest, -10, is ↓ at target 2
# A = 1 - (-10) = 11   (with x̄↓ alone in the lower edge: 1 - (-6) = 7)
# A↑ = 1 - (-3) = 4;  A↓ = -2 - (-10) = 8


def test_accuracy_when_the_down_direction_holds_the_minimum_band_edge():
    forward = [[-v for v in row] for row in DOWN_HIGH_FORWARD]
    backward = [[-v for v in row] for row in DOWN_HIGH_BACKWARD]
    r = iso230_2(linear([0.0, 100.0], forward, backward))
    np.testing.assert_allclose(r.mean_down, [-2.0, -6.0])
    np.testing.assert_allclose(r.s_down, [0.0, 2.0], atol=1e-12)
    got = r.axis_values()
    for key, value in {"A": 11.0, "A_up": 4.0, "A_down": 8.0, "R": 9.0}.items():
        assert got[key] == pytest.approx(value, abs=1e-12), key


def test_unidirectional_forward_only_omits_other_keys():
    # runs 0, 2 and 2, 4 : x̄↑ = 1, 3 ; s↑ = √2, √2 ; E↑ = 2 ; R↑ = 4√2 ;
    # A↑ = (3 + 2√2) - (1 - 2√2) = 2 + 4√2
    r = iso230_2(linear([0.0, 50.0], [[0, 2], [2, 4]]))
    assert not r.bidirectional
    assert r.directions == ("up",)
    assert r.axis_values() == pytest.approx(
        {"A_up": 2 + 4 * math.sqrt(2.0), "E_up": 2.0, "R_up": 4 * math.sqrt(2.0)}
    )
    assert r.B is None and r.B_i is None and r.mean_down is None and r.R is None
    d = r.to_dict()
    assert d["bidirectional"] is False
    assert d["runs"] == {"up": 2}
    assert list(d["axis"]) == ["A_up", "E_up", "R_up"]
    assert list(d["targets"][0]) == ["position_mm", "mean_up", "s_up", "R_up"]
    assert any("unidirectional" in note for note in r.notes)


def test_unidirectional_backward_only_gives_down_keys():
    r = iso230_2(linear([0.0, 50.0], backward=[[0, 2], [2, 4]]))
    assert list(r.axis_values()) == ["A_down", "E_down", "R_down"]
    assert list(r.to_dict()["targets"][1]) == ["position_mm", "mean_down", "s_down", "R_down"]
    assert r.to_dict()["runs"] == {"down": 2}


def test_five_runs_carry_no_note_four_runs_do():
    five = iso230_2(linear([0.0, 1.0], [[0, 1]] * 5, [[0, 1]] * 5))
    assert five.notes == ()
    four = iso230_2(linear([0.0, 1.0], [[0, 1]] * 4, [[0, 1]] * 5))
    assert len(four.notes) == 1
    assert "up 4" in four.notes[0] and "down" not in four.notes[0]


def test_one_run_in_a_direction_is_refused():
    p = linear([0.0, 1.0], [[0, 1], [0, 1]], [[0, 1]], source="short.rtl")
    with pytest.raises(DataError, match=r"short\.rtl: .*at least 2 runs.*backward \(down\).* 1"):
        iso230_2(p)


@pytest.mark.parametrize("kind", ["straightness", "angular"])
def test_non_linear_profile_is_refused(kind):
    p = ErrorProfile(kind, [0.0, 1.0], {"forward": [[0, 1], [0, 1]]}, axis="X", source="f")
    with pytest.raises(DataError, match=rf"defined for linear .*{kind}"):
        iso230_2(p)


# --- properties ------------------------------------------------------------------------------


def test_identical_runs_give_zero_spread():
    # every run the same: s = 0, R = |B|, A = E
    fwd = [[1.0, 2.0, -1.0]] * 3
    bwd = [[0.0, 2.5, -1.0]] * 3
    r = iso230_2(linear(WORKED_TARGETS, fwd, bwd))
    np.testing.assert_allclose(r.s_up, 0.0, atol=1e-12)
    np.testing.assert_allclose(r.R_i, np.abs(r.B_i))
    assert r.axis_values()["A"] == pytest.approx(r.E)
    assert r.A_up == pytest.approx(r.E_up)


def test_zero_deviations_give_zero_figures():
    r = iso230_2(linear(WORKED_TARGETS, np.zeros((5, 3)), np.zeros((5, 3))))
    assert all(v == 0.0 for v in r.axis_values().values())


def test_offset_moves_means_only():
    # adding 10 µm to every deviation shifts the means and nothing else
    base = iso230_2(linear(WORKED_TARGETS, WORKED_FORWARD, WORKED_BACKWARD))
    moved = iso230_2(
        linear(
            WORKED_TARGETS,
            np.add(WORKED_FORWARD, 10.0),
            np.add(WORKED_BACKWARD, 10.0),
        )
    )
    np.testing.assert_allclose(moved.mean_up, base.mean_up + 10.0)
    np.testing.assert_allclose(moved.mean_bidirectional, base.mean_bidirectional + 10.0)
    for key, value in base.axis_values().items():
        assert moved.axis_values()[key] == pytest.approx(value, abs=1e-12), key


def test_figures_scale_linearly():
    # every figure is a linear, positively homogeneous function of the deviations
    base = iso230_2(linear(WORKED_TARGETS, WORKED_FORWARD, WORKED_BACKWARD))
    scaled = iso230_2(
        linear(WORKED_TARGETS, np.multiply(WORKED_FORWARD, 2.5), np.multiply(WORKED_BACKWARD, 2.5))
    )
    for key, value in base.axis_values().items():
        assert scaled.axis_values()[key] == pytest.approx(2.5 * value), key


def test_result_is_immutable(worked):
    with pytest.raises(AttributeError):
        worked.A = 0.0
    with pytest.raises(ValueError):
        worked.mean_up[0] = 0.0


@pytest.mark.slow
def test_core_imports_no_plotting_or_cli():
    code = (
        "import sys, esp.iso230.positioning; "
        "print(sorted(m for m in ('matplotlib', 'pandas', 'click') if m in sys.modules))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "[]"
