"""Tests of esp.io.csvfile (and the CSV side of esp.io.load)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from esp.core.errors import DataError, ParseError
from esp.io.csvfile import parse_csv_profile, read_csv_profile
from esp.io.load import load_profile

DATA = Path(__file__).parent / "data"
PROFILE = DATA / "profile.csv"

HEADER = "target_mm,run,direction,deviation\n"
SIMPLE = HEADER + "0,1,forward,0.0\n100,1,forward,1.5\n100,2,backward,1.75\n0,2,backward,0.5\n"


def csv_error(text: str, **kwargs) -> ParseError:
    kwargs.setdefault("kind", "linear")
    with pytest.raises(ParseError) as info:
        parse_csv_profile(text, path="p.csv", **kwargs)
    return info.value


def test_fixture():
    p = read_csv_profile(PROFILE, "linear")
    assert p.kind == "linear"
    assert p.input_unit == "um"
    assert p.source == str(PROFILE)
    np.testing.assert_array_equal(p.targets_mm, [0.0, 100.0, 200.0])
    # runs 1 and 3 forward (3 is written '+'), run 2 backward listed from 200 down to 0
    np.testing.assert_array_equal(p.runs["forward"], [[0.0, 1.5, 2.25], [0.25, 1.25, 2.0]])
    np.testing.assert_array_equal(p.runs["backward"], [[0.5, 1.75, 2.75]])


def test_load_profile_dispatches_csv():
    p = load_profile(PROFILE, kind="straightness", axis="x", error_direction="z")
    assert (p.kind, p.axis, p.error_direction) == ("straightness", "X", "Z")


def test_kind_is_needed():
    with pytest.raises(ParseError, match="expected the error kind") as info:
        load_profile(PROFILE)
    assert info.value.path == str(PROFILE)


def test_kind_axis_from_comments():
    text = "# kind: angular\n# axis: Y\n# error direction: Z\n# unit: arcsec\n" + SIMPLE
    p = parse_csv_profile(text)
    assert (p.kind, p.axis, p.error_direction, p.input_unit) == ("angular", "Y", "Z", "arcsec")
    # 1.5 arcsec in µm/m: 1.5 * pi / 180 / 3600 * 1e6 = 7.27220...
    assert p.runs["forward"][0, 1] == pytest.approx(1.5 * math.pi / 180 / 3600 * 1e6)
    assert p.runs["forward"][0, 1] == pytest.approx(7.2722052, abs=1e-7)


def test_arguments_win_over_comments():
    text = "# kind: angular\n# axis: Y\n# unit: urad\n" + SIMPLE
    p = parse_csv_profile(text, kind="angular", unit="µrad", axis="X")
    assert p.axis == "X"
    assert p.input_unit == "urad"
    assert p.runs["forward"][0, 1] == 1.5


def test_a_unit_that_contradicts_the_comment_is_refused():
    text = "# kind: angular\n# axis: Y\n# unit: arcsec\n" + SIMPLE
    with pytest.raises(ParseError) as info:
        parse_csv_profile(text, kind="angular", unit="urad")
    assert info.value.line == 3  # the comment's line
    assert "states its deviations in arcsec" in info.value.message
    assert "read in urad" in info.value.message


def test_unit_comment_mm():
    p = parse_csv_profile("# unit: mm\n" + SIMPLE, kind="linear")
    assert p.runs["backward"][0, 1] == pytest.approx(1750.0)  # 1.75 mm = 1750 µm


def test_default_angular_unit_is_um_per_m():
    p = parse_csv_profile(SIMPLE, kind="angular")
    assert p.input_unit == "um/m"
    assert p.runs["forward"][0, 1] == 1.5


def test_columns_in_any_order_with_extra_columns_and_spacing():
    text = (
        "Run , Deviation , Note , Direction , Target_mm\n"
        '1, 0.0, "start, cold", fwd, 0\n1, 1.5, x, fwd, 100\n'
    )
    p = parse_csv_profile(text, kind="linear")
    np.testing.assert_array_equal(p.runs["forward"], [[0.0, 1.5]])
    assert p.directions == ("forward",)


def test_semicolon_delimiter_and_crlf_bom():
    text = "\ufeff" + SIMPLE.replace(",", ";").replace("\n", "\r\n")
    p = parse_csv_profile(text, kind="linear")
    np.testing.assert_array_equal(p.runs["backward"], [[0.5, 1.75]])


def test_negative_targets_sorted():
    text = HEADER + "0,1,-,0.0\n-100,1,-,1.0\n-200,1,-,2.0\n"
    p = parse_csv_profile(text, kind="linear")
    np.testing.assert_array_equal(p.targets_mm, [-200.0, -100.0, 0.0])
    np.testing.assert_array_equal(p.runs["backward"], [[2.0, 1.0, 0.0]])


def test_missing_column():
    err = csv_error("target_mm,run,deviation\n0,1,0\n")
    assert err.line == 1
    assert "missing direction" in err.message


def test_no_rows():
    assert "data row" in csv_error(HEADER).message
    assert "header row" in csv_error("# unit: um\n\n").message


def test_run_in_two_directions():
    err = csv_error(SIMPLE + "200,1,backward,3.0\n")
    assert err.line == 6
    assert "run 1 in one direction (forward at line 2)" in err.message


def test_duplicate_run_target():
    err = csv_error(SIMPLE + "100.0,2,backward,1.8\n")
    assert err.line == 6
    assert "again (first at line 4)" in err.message


def test_missing_run_target():
    err = csv_error(SIMPLE + "200,1,forward,3.0\n")
    assert "run 2 to hold every target" in err.message
    assert err.line == 4  # the first line of run 2


@pytest.mark.parametrize(
    ("row", "what"),
    [
        ("abc,1,forward,0", "target position"),
        ("0,1,forward,nan", "deviation"),
        ("0,1,forward,inf", "deviation"),
        ("0,1,forward,1e999", "finite"),
        ("0,one,forward,0", "run number"),
        ("0,0,forward,0", "run number"),
        ("0,1.5,forward,0", "run number"),
        ("0,1,sideways,0", "direction"),
        ("0,1,mean,0", "direction"),
        ("0,1,forward", "4 fields"),
        ("0,1,forward,0,9", "4 fields"),
    ],
)
def test_bad_rows(row, what):
    err = csv_error(HEADER + row + "\n")
    assert err.line == 2
    assert what in err.message
    assert str(err).startswith("p.csv:2: expected ")


def test_conflicting_unit_comments():
    err = csv_error("# unit: um\n# unit: mm\n" + SIMPLE)
    assert err.line == 2


def test_unknown_unit():
    err = csv_error("# unit: furlong\n" + SIMPLE)
    assert err.line == 1 and "unknown unit" in err.message  # the comment's line
    assert "does not fit" in csv_error(SIMPLE, unit="arcsec").message


def test_bad_kind_comment():
    err = csv_error("# kind: rotary\n" + SIMPLE, kind=None)
    assert err.line == 1


def test_bad_arguments():
    with pytest.raises(DataError):
        parse_csv_profile(SIMPLE, kind="volumetric")
    with pytest.raises(DataError):
        parse_csv_profile(SIMPLE, kind="linear", axis="W")


def test_example_in_the_format_documentation_parses():
    docs = Path(__file__).parent.parent / "docs" / "formats.md"
    blocks = docs.read_text(encoding="utf-8").split("```")[1::2]
    example = next(b for b in blocks if "target_mm,run,direction,deviation\n0," in b)
    p = parse_csv_profile(example)
    assert p.kind == "straightness"
    np.testing.assert_array_equal(p.runs["forward"], [[0.0, 0.62, 0.95]])
    np.testing.assert_array_equal(p.runs["backward"], [[0.05, 0.70, 1.10]])
