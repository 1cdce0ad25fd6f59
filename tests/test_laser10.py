"""Tests of esp.io.laser10 (and the Laser10 side of esp.io.load)."""

from __future__ import annotations

import math
import shutil
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from esp.core.errors import DataError, ParseError
from esp.core.profile import ErrorProfile
from esp.io.laser10 import (
    axis_letter,
    format_laser10,
    parse_laser10,
    read_laser10,
    write_laser10,
)
from esp.io.load import load_profile

DATA = Path(__file__).parent / "data"
LINEAR = DATA / "linear_bidir.rtl"
ANGULAR = DATA / "angular.rta"
STRAIGHTNESS = DATA / "straightness.stx"
WRAPPED = DATA / "wrapped_descending.rtl"

#: one arc second in µm/m (= µrad): pi / 180 / 3600 rad, times 1e6
ARCSEC_IN_UM_PER_M = math.pi / 180.0 / 3600.0 * 1e6


def linear_text() -> str:
    return LINEAR.read_text(encoding="utf-8")


def line_of(text: str, fragment: str) -> int:
    """1-based number of the first line of ``text`` that contains ``fragment``."""
    for number, line in enumerate(text.split("\n"), start=1):
        if fragment in line:
            return number
    raise AssertionError(f"{fragment!r} not in text")


def replace_once(text: str, old: str, new: str) -> str:
    assert text.count(old) == 1, old
    return text.replace(old, new)


def assert_same_profile(a: ErrorProfile, b: ErrorProfile, atol: float = 0.0) -> None:
    assert a.kind == b.kind
    np.testing.assert_allclose(a.targets_mm, b.targets_mm, rtol=0, atol=atol)
    assert a.directions == b.directions
    for d in a.directions:
        assert a.runs[d].shape == b.runs[d].shape
        np.testing.assert_allclose(a.runs[d], b.runs[d], rtol=0, atol=atol)
    assert dict(a.metadata) == dict(b.metadata)
    assert dict(a.environment) == dict(b.environment)


# -- the fixtures -----------------------------------------------------------------------------


def test_linear_bidirectional_fixture():
    p = read_laser10(LINEAR)
    assert p.kind == "linear"
    assert p.axis == "X"
    assert p.error_direction is None
    assert p.input_unit == "um"
    assert p.source == str(LINEAR)
    np.testing.assert_array_equal(p.targets_mm, [0.0, 250.0, 500.0, 750.0, 1000.0])
    # runs 1 and 3 forward, as listed
    np.testing.assert_array_equal(
        p.runs["forward"], [[0.00, 1.25, 2.50, 3.05, 4.10], [0.10, 1.35, 2.45, 3.15, 4.00]]
    )
    # runs 2 and 4 are listed from target 5 down to target 1; placed by index
    np.testing.assert_array_equal(
        p.runs["backward"], [[0.40, 1.70, 2.90, 3.55, 4.60], [0.50, 1.60, 3.00, 3.65, 4.50]]
    )
    assert dict(p.metadata) == {
        "Machine": "Example mill",
        "Serial No": "12345",
        "Date": "12/12/2016",
        "By": "A. User",
        "Axis": "X",
        "Location": "Workshop",
    }
    assert p.environment["Air temp"] == ("20.337280", "20.384956", "0")
    assert p.environment["Env factor"] == ("0.31641096", "0.31641067")
    assert p.environment["Mat temp 1"] == ("20.1", "20.2", "1")
    assert p.environment["Date Time"] == ("10:46 Dec 12 2016", "11:01 Dec 12 2016")
    assert len(p.environment) == 8


def test_angular_fixture_default_unit_is_um_per_m():
    p = read_laser10(ANGULAR)
    assert p.kind == "angular"
    assert p.axis == "Y"
    assert p.input_unit == "um/m"
    np.testing.assert_array_equal(p.targets_mm, [0.0, 200.0, 400.0, 600.0])
    np.testing.assert_array_equal(p.runs["forward"], [[0.0, 1.5, -2.0, 3.0]])
    np.testing.assert_array_equal(p.runs["backward"], [[0.2, 1.1, -1.8, 3.4]])
    # the EQUIPMENT section is not environment
    assert dict(p.environment) == {}


def test_angular_in_arcsec_is_converted():
    p = read_laser10(ANGULAR, unit="arcsec")
    assert p.input_unit == "arcsec"
    assert abs(ARCSEC_IN_UM_PER_M - 4.8481368) < 1e-7
    np.testing.assert_allclose(
        p.runs["forward"],
        [[0.0, 1.5 * ARCSEC_IN_UM_PER_M, -2.0 * ARCSEC_IN_UM_PER_M, 3.0 * ARCSEC_IN_UM_PER_M]],
        rtol=1e-12,
    )
    np.testing.assert_allclose(p.runs["backward"][0, 3], 3.4 * 4.8481368, rtol=1e-8)


def test_angular_in_mrad_and_urad():
    # 1 mrad = 1 µm/mm = 1000 µm/m
    np.testing.assert_allclose(read_laser10(ANGULAR, unit="mrad").runs["forward"][0, 1], 1500.0)
    np.testing.assert_allclose(read_laser10(ANGULAR, unit="urad").runs["forward"][0, 1], 1.5)


def test_straightness_unidirectional_fixture():
    p = read_laser10(STRAIGHTNESS, error_direction="y")
    assert p.kind == "straightness"
    assert p.axis == "X"  # from .stx
    assert p.error_direction == "Y"
    assert p.directions == ("forward",)  # Flags 0 1 2 0: every run forward
    np.testing.assert_array_equal(
        p.runs["forward"],
        [[0.0, 0.5, 0.9, 1.2], [0.1, 0.6, 1.0, 1.1], [0.0, 0.4, 0.8, 1.3]],
    )
    assert p.environment["Air temp"] == ("20.1", "20.2", "0")


def test_wrapped_descending_negative_targets():
    p = read_laser10(WRAPPED)
    assert p.axis == "Z"  # "Axis:z"
    # listed 0, -100, ..., -1100; stored ascending
    np.testing.assert_array_equal(p.targets_mm, np.arange(-1100.0, 1.0, 100.0))
    # run 1 has 0.1 * (index - 1) at file index 1..12, index 1 being 0 mm
    np.testing.assert_allclose(p.runs["forward"][0], 0.1 * np.arange(12)[::-1], atol=1e-12)
    np.testing.assert_allclose(p.runs["backward"][0], 0.1 * np.arange(12)[::-1] + 0.05, atol=1e-12)
    # the value at -1100 mm (file index 12) is 1.10
    assert p.at(-1100.0, "forward") == pytest.approx(1.10)


@pytest.mark.parametrize(
    "encode",
    [
        pytest.param(
            lambda t: b"\xef\xbb\xbf" + t.replace("\n", "\r\n").encode("utf-8"), id="utf8-bom-crlf"
        ),
        pytest.param(lambda t: t.replace("\n", "\r\n").encode("latin-1"), id="latin1-crlf"),
        pytest.param(
            lambda t: b"\xef\xbb\xbf" + t.replace("\n", "\r\n").encode("latin-1"),
            id="bom-latin1-crlf",
        ),
        pytest.param(lambda t: t.replace("\n", "\r").encode("cp1252"), id="cp1252-cr"),
    ],
)
def test_bom_crlf_latin1(tmp_path, encode):
    text = replace_once(linear_text(), "Location: Workshop", "Location: Werkstatt M\u00fcller")
    path = tmp_path / "x.rtl"
    path.write_bytes(encode(text))
    p = read_laser10(path)
    assert p.metadata["Location"] == "Werkstatt M\u00fcller"
    assert_same_profile(p, _with_location(read_laser10(LINEAR), "Werkstatt M\u00fcller"))


def _with_location(p: ErrorProfile, location: str) -> ErrorProfile:
    from dataclasses import replace

    metadata = dict(p.metadata)
    metadata["Location"] = location
    return replace(p, metadata=metadata)


def test_spacing_around_colons_and_targets_on_the_key_line():
    text = linear_text()
    text = replace_once(text, "Target-count: 5", "Target-count   :   5")
    text = replace_once(
        text,
        "Targets :\n0.000000  250.000000  500.000000  750.000000  1000.000000",
        "Targets:0 250\n  500\n\n750 1000",
    )
    text = replace_once(text, "Run-count:4", "  Run-count :4  ")
    p = parse_laser10(text, kind="linear")
    np.testing.assert_array_equal(p.targets_mm, [0, 250, 500, 750, 1000])
    assert p.run_count("forward") == 2


def test_odd_run_count_bidirectional():
    text = linear_text()
    text = replace_once(text, "Run-count:4", "Run-count:3")
    lines = [ln for ln in text.split("\n") if not ln.startswith("4   ")]
    p = parse_laser10("\n".join(lines), kind="linear")
    assert p.run_count("forward") == 2
    assert p.run_count("backward") == 1


def test_axis_letter():
    assert axis_letter("x") == "X"
    assert axis_letter(" Y axis ") == "Y"
    assert axis_letter("Z-Axis") == "Z"
    assert axis_letter("A") is None
    assert axis_letter("X1") is None
    assert axis_letter(None) is None


def test_user_text_axis_key_in_any_case():
    text = replace_once(linear_text(), "Axis: X", "AXIS :  y axis")
    assert parse_laser10(text, kind="linear").axis == "Y"


def test_user_text_axis_that_is_not_xyz_gives_none():
    text = replace_once(linear_text(), "Axis: X", "Axis: C rotary")
    assert parse_laser10(text, kind="linear").axis is None


def test_explicit_axis_wins():
    assert read_laser10(LINEAR, axis="Y").axis == "Y"
    assert read_laser10(STRAIGHTNESS, axis="Z").axis == "Z"
    with pytest.raises(DataError, match="X, Y or Z"):
        read_laser10(LINEAR, axis="Q")


# -- kind inference and load_profile --------------------------------------------------------


@pytest.mark.parametrize(
    ("source", "name", "kind", "axis"),
    [
        (LINEAR, "a.rtl", "linear", "X"),
        (ANGULAR, "a.rta", "angular", "Y"),
        (STRAIGHTNESS, "a.rts", "straightness", None),
        (STRAIGHTNESS, "a.STY", "straightness", "Y"),
        (STRAIGHTNESS, "a.stz", "straightness", "Z"),
        (LINEAR, "a.dat", "linear", "X"),  # from HEADER File type
        (ANGULAR, "a.txt", "angular", "Y"),
    ],
)
def test_kind_and_axis_by_extension_then_header(tmp_path, source, name, kind, axis):
    path = tmp_path / name
    shutil.copy(source, path)
    p = load_profile(path)
    assert p.kind == kind
    assert p.axis == axis


def test_explicit_kind_wins_over_extension_and_header():
    p = load_profile(LINEAR, kind="straightness", error_direction="Z")
    assert p.kind == "straightness"
    assert p.error_direction == "Z"


def test_extension_wins_over_header(tmp_path):
    path = tmp_path / "a.rta"
    shutil.copy(LINEAR, path)
    assert load_profile(path).kind == "angular"


def test_kind_from_owner_only():
    text = replace_once(linear_text(), "File type  : rtl\n", "")
    text = replace_once(text, "Owner      : Linear", "Owner : Straightness measurement")
    assert parse_laser10(text).kind == "straightness"


def test_kind_unknown_is_a_parse_error():
    text = replace_once(linear_text(), "File type  : rtl\n", "")
    text = replace_once(text, "Owner      : Linear", "Owner : Someone")
    with pytest.raises(ParseError, match="expected the error kind") as info:
        parse_laser10(text, path="m.dat")
    assert str(info.value).startswith("m.dat: ")


def test_header_that_contradicts_itself():
    text = replace_once(linear_text(), "Owner      : Linear", "Owner      : Angular")
    with pytest.raises(ParseError, match="agrees with File type") as info:
        parse_laser10(text, path="m.dat")
    assert info.value.line == 3


def test_unknown_kind_argument():
    with pytest.raises(DataError, match="unknown error kind"):
        read_laser10(LINEAR, kind="squareness")


# -- units ----------------------------------------------------------------------------------


def test_linear_in_mm_is_converted_to_um():
    p = read_laser10(LINEAR, unit="mm")
    assert p.input_unit == "mm"
    np.testing.assert_allclose(p.runs["forward"][0, 1], 1.25 * 1000.0)


def test_unknown_unit_names_the_file():
    with pytest.raises(ParseError, match="unknown unit 'furlong'") as info:
        read_laser10(LINEAR, unit="furlong")
    assert info.value.path == str(LINEAR)
    assert info.value.line is None


def test_unit_that_does_not_fit_the_kind():
    with pytest.raises(ParseError, match="does not fit a linear error"):
        read_laser10(LINEAR, unit="arcsec")
    with pytest.raises(ParseError, match="does not fit a angular error"):
        read_laser10(ANGULAR, unit="um")


# -- strictness -----------------------------------------------------------------------------


def parse_error(text: str) -> ParseError:
    with pytest.raises(ParseError) as info:
        parse_laser10(text, path="m.rtl", kind="linear")
    return info.value


def test_message_format_names_file_line_expected_found():
    text = replace_once(linear_text(), "1   2   1.25", "1   2   1.2x5")
    err = parse_error(text)
    n = line_of(text, "1   2   1.2x5")
    assert err.line == n
    assert str(err) == f"m.rtl:{n}: expected a deviation, found '1.2x5'"


def test_target_count_mismatch():
    text = replace_once(linear_text(), "Target-count: 5", "Target-count: 6")
    err = parse_error(text)
    assert err.line == line_of(text, "Targets :")
    assert "expected 6 targets" in err.message and "found 5" in err.message


def test_missing_run_target():
    text = replace_once(linear_text(), "3   4   3.15\n", "")
    err = parse_error(text)
    assert err.line == line_of(text, "DEVIATIONS::")
    assert "run 3 at target 4" in err.message
    assert "found none" in err.message


def test_duplicated_run_target():
    text = replace_once(linear_text(), "3   4   3.15\n", "3   4   3.15\n3 4 3.20\n")
    err = parse_error(text)
    assert err.line == line_of(text, "3 4 3.20")
    assert f"first at line {line_of(text, '3   4   3.15')}" in err.message


def test_duplicate_replacing_a_missing_one():
    # as many lines as expected, but one pair twice and one never
    text = replace_once(linear_text(), "3   4   3.15", "3   3   3.15")
    err = parse_error(text)
    assert err.line == line_of(text, "3   3   3.15")
    assert "again" in err.message


@pytest.mark.parametrize("junk", ["abc", "1,25", "1.2.3", "--1", "0x10", "1_000", ""])
def test_non_numeric_deviation(junk):
    text = replace_once(linear_text(), "2   3   2.90", f"2   3   {junk}")
    err = parse_error(text)
    assert err.line == line_of(text, f"2   3   {junk}")


@pytest.mark.parametrize("value", ["nan", "NaN", "inf", "-Infinity", "1e999"])
def test_nan_and_inf_rejected(value):
    text = replace_once(linear_text(), "2   3   2.90", f"2   3   {value}")
    err = parse_error(text)
    assert err.line == line_of(text, f"2   3   {value}")
    if value == "1e999":
        assert "finite" in err.message


def test_non_numeric_target():
    text = replace_once(linear_text(), "500.000000  750.000000", "500.000000  seven")
    err = parse_error(text)
    assert err.line == line_of(text, "seven")
    assert "expected a target position in mm, found 'seven'" in err.message


def test_nan_target():
    text = replace_once(linear_text(), "500.000000  750", "nan  750")
    assert parse_error(text).line == line_of(text, "nan  750")


def test_non_monotonic_targets():
    text = replace_once(linear_text(), "750.000000  1000", "400.000000  1000")
    err = parse_error(text)
    assert err.line == line_of(text, "400.000000")
    assert "strictly increasing" in err.message and "400" in err.message


def test_repeated_target():
    text = replace_once(linear_text(), "0.000000  250.000000", "0.000000  0.000000")
    err = parse_error(text)
    assert "twice" in err.message


def test_target_index_out_of_range():
    text = replace_once(linear_text(), "3   4   3.15", "3   6   3.15")
    err = parse_error(text)
    assert err.line == line_of(text, "3   6   3.15")
    assert "target index from 1 to 5" in err.message and "found 6" in err.message


def test_run_out_of_range():
    text = replace_once(linear_text(), "3   4   3.15", "5   4   3.15")
    err = parse_error(text)
    assert "run number from 1 to 4" in err.message and "found 5" in err.message


def test_run_zero_and_negative_index():
    text = replace_once(linear_text(), "3   4   3.15", "0   4   3.15")
    assert "run number" in parse_error(text).message
    text = replace_once(linear_text(), "3   4   3.15", "3   -4   3.15")
    assert "target index" in parse_error(text).message


def test_wrong_field_count():
    text = replace_once(linear_text(), "3   4   3.15", "3   4   3.15   9")
    err = parse_error(text)
    assert "3 fields" in err.message and "found 4" in err.message


@pytest.mark.parametrize("section", ["TARGET DATA", "RUNS", "DEVIATIONS"])
def test_missing_required_section(section):
    text = replace_once(linear_text(), f"{section}::", f"NOT {section}::")
    err = parse_error(text)
    assert err.line is None
    assert f"expected a {section}:: section" in err.message


def test_missing_run_count():
    text = replace_once(linear_text(), "Run-count:4", "Runs done: 4")
    err = parse_error(text)
    assert err.line == line_of(text, "RUNS::")
    assert "Run-count" in err.message


def test_non_numeric_run_count():
    text = replace_once(linear_text(), "Run-count:4", "Run-count: four")
    assert "Run-count" in parse_error(text).message


def test_missing_target_count():
    text = replace_once(linear_text(), "Target-count: 5\n", "")
    assert "Target-count" in parse_error(text).message


def test_text_before_first_section():
    err = parse_error("target_mm,run,direction,deviation\n" + linear_text())
    assert err.line == 1
    assert "section header" in err.message


def test_duplicate_section():
    text = linear_text().replace("EOF::", "RUNS::\nRun-count: 2\nEOF::")
    err = parse_error(text)
    assert "second one" in err.message


def test_stray_line_in_target_data():
    text = replace_once(linear_text(), "Flags: 0 0 2 0", "Flags: 0 0 2 0\nsomething odd")
    assert "Key : value" in parse_error(text).message


def test_text_after_eof_is_ignored():
    p = parse_laser10(linear_text() + "\ntrailing junk\n", kind="linear")
    assert p.run_count("backward") == 2


def test_empty_text():
    err = parse_error("")
    assert "TARGET DATA" in err.message


@pytest.mark.parametrize("bad", ["dir", "missing", "empty", "binary"])
def test_file_level_errors(tmp_path, bad):
    path = tmp_path / "f.rtl"
    if bad == "dir":
        path.mkdir()
    elif bad == "empty":
        path.write_bytes(b"")
    elif bad == "binary":
        path.write_bytes(b"PK\x03\x04\x14\x00\x00\x00" * 20)
    with pytest.raises(ParseError) as info:
        load_profile(path)
    assert info.value.path == str(path)


# -- writing --------------------------------------------------------------------------------


@pytest.mark.parametrize("fixture", [LINEAR, ANGULAR, STRAIGHTNESS, WRAPPED])
def test_round_trip_fixtures(tmp_path, fixture):
    p = read_laser10(fixture)
    out = tmp_path / f"copy{fixture.suffix}"
    write_laser10(out, p)
    q = read_laser10(out)
    assert_same_profile(p, q, atol=5e-7)
    assert q.axis == p.axis


def test_written_text_layout():
    p = read_laser10(LINEAR)
    text = format_laser10(p)
    assert "File type  : rtl" in text
    assert "Target-count: 5" in text
    assert "Run-count: 4" in text
    assert "Flags: 0 0 2 0" in text
    # backward runs listed from the last target down, as instruments write them
    assert text.index("2 5 4.600000") < text.index("2 1 0.400000")
    assert 'Date Time : "10:46 Dec 12 2016" "11:01 Dec 12 2016"' in text
    assert text.endswith("EOF::\n")


def test_round_trip_of_a_constructed_profile(tmp_path):
    p = ErrorProfile(
        kind="angular",
        targets_mm=[-50.0, 0.0, 50.0],
        runs={"forward": [[1.0, -2.0, 3.0], [1.5, -2.5, 3.5]], "backward": [[0.5, 0.25, 0.0]]},
        axis="Z",
        metadata={"Machine": "CMM 3", "Note": "a: b : c", "Empty": ""},
        environment={"Air temp": ("20.1", "20.3", "0"), "Comment": ("two words", "")},
    )
    path = tmp_path / "c.rta"
    write_laser10(path, p)
    q = read_laser10(path)
    assert_same_profile(p, q)
    assert q.run_count("forward") == 2 and q.run_count("backward") == 1


def test_forward_only_profile_written_unidirectional(tmp_path):
    p = ErrorProfile.from_values("straightness", [0, 10, 20], [0.0, 1.0, -1.0])
    text = format_laser10(p)
    assert "Flags: 0 1 2 0" in text
    q = parse_laser10(text)
    assert_same_profile(p, q)


def test_unwritable_profiles(tmp_path):
    backward_only = ErrorProfile("linear", [0, 1], {"backward": [[0.0, 1.0]]})
    with pytest.raises(DataError, match="0 forward and 1 backward"):
        format_laser10(backward_only)
    too_many_forward = ErrorProfile(
        "linear", [0, 1], {"forward": [[0, 1], [0, 1], [0, 1]], "backward": [[0, 1]]}
    )
    with pytest.raises(DataError, match="3 forward and 1 backward"):
        format_laser10(too_many_forward)
    bad_key = ErrorProfile.from_values("linear", [0, 1], [0, 1], metadata={"a:b": "x"})
    path = tmp_path / "bad.rtl"
    with pytest.raises(DataError, match="without ':'"):
        write_laser10(path, bad_key)
    assert list(tmp_path.iterdir()) == []  # nothing half-written


def test_extension_of_another_kind_is_refused(tmp_path):
    with pytest.raises(DataError, match="for linear data"):
        write_laser10(tmp_path / "a.rtl", read_laser10(ANGULAR))
    assert list(tmp_path.iterdir()) == []


# -- round trip as a property ---------------------------------------------------------------

# within the plausibility limit of every kind (10 mm = 1e4 µm; angles 1e5 µm/m)
_values = st.floats(min_value=-1e4, max_value=1e4, allow_nan=False).map(lambda v: round(v, 6))


@st.composite
def profiles(draw):
    n = draw(st.integers(2, 8))
    gaps = draw(st.lists(st.integers(1, 10**6), min_size=n, max_size=n))
    start = draw(st.integers(-(10**6), 10**6))
    targets = (start + np.cumsum(gaps) - gaps[0]) / 1000.0  # mm with 3 decimals
    n_back = draw(st.integers(0, 3))
    n_fwd = draw(st.sampled_from([n_back, n_back + 1] if n_back else [1, 2]))
    rows = st.lists(_values, min_size=n, max_size=n)
    runs = {"forward": draw(st.lists(rows, min_size=n_fwd, max_size=n_fwd))}
    if n_back:
        runs["backward"] = draw(st.lists(rows, min_size=n_back, max_size=n_back))
    kind = draw(st.sampled_from(["linear", "straightness", "angular"]))
    text = st.text(
        st.characters(codec="latin-1", exclude_categories=("Cc", "Zl", "Zp")), max_size=12
    )
    keys = text.map(str.strip).filter(lambda k: k and ":" not in k)
    metadata = draw(st.dictionaries(keys, text.map(str.strip), max_size=3))
    fields = st.lists(
        text.filter(lambda f: '"' not in f and f == f.strip() or f == ""), max_size=3
    ).map(tuple)
    environment = draw(st.dictionaries(keys, fields, max_size=3))
    return ErrorProfile(kind, targets, runs, metadata=metadata, environment=environment)


@pytest.mark.slow
@settings(max_examples=100, derandomize=True, deadline=None)
@given(profiles())
def test_round_trip_property(p):
    q = parse_laser10(format_laser10(p))
    assert_same_profile(p, q, atol=1e-9)


def test_example_in_the_format_documentation_parses():
    docs = Path(__file__).parent.parent / "docs" / "formats.md"
    blocks = docs.read_text(encoding="utf-8").split("```")[1::2]
    example = next(b for b in blocks if b.lstrip().startswith("HEADER::"))
    p = parse_laser10(example)
    assert (p.kind, p.axis) == ("linear", "Y")
    np.testing.assert_array_equal(p.targets_mm, [0.0, 100.0, 200.0, 300.0])
    np.testing.assert_array_equal(p.runs["backward"], [[0.20, 1.05, 1.95, 2.45]])
    assert p.environment["Date Time"] == ("09:12 May 03 2019", "09:31 May 03 2019")


def test_write_a_set_of_files(tmp_path):
    from esp.core.profile import ErrorProfile
    from esp.io.laser10 import read_laser10, write_laser10_set

    profiles = {
        "a.rtl": ErrorProfile("linear", [0.0, 100.0], {"forward": [[0.0, 1.5]]}, axis="X"),
        "b.rta": ErrorProfile("angular", [0.0, 100.0], {"forward": [[2.0, -2.0]]}, axis="X"),
    }
    paths = write_laser10_set(tmp_path / "set", profiles)
    assert [p.name for p in paths] == ["a.rtl", "b.rta"]
    assert read_laser10(paths[1]).mean("forward").tolist() == [2.0, -2.0]
