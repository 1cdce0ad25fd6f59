"""Wrong numbers never leave esp with exit code 0: non-finite, absurd and one-target inputs
are refused where they enter (the parsers, the configuration reader, ErrorProfile), naming
the file and line or the key (docs/reliability.md, "What is refused")."""

from __future__ import annotations

import copy
import math
import tomllib
from pathlib import Path

import pytest
from click.testing import CliRunner

from esp.cli import main
from esp.config import machine_from_dict
from esp.core.analysis import analyse
from esp.core.angular import angular_from_linear
from esp.core.errors import ConfigError, DataError, ParseError
from esp.core.profile import ErrorProfile
from esp.core.units import (
    ANGLE_LIMIT_UM_PER_M,
    DISPLACEMENT_LIMIT_UM,
    POSITION_LIMIT_MM,
    TINY,
    beyond_limit,
    flush_tiny,
    limit_text,
)
from esp.io.csvfile import parse_csv_profile
from esp.io.laser10 import MAX_READINGS, format_laser10, parse_laser10

DATA = Path(__file__).parent / "data" / "config"


def laser10(targets, runs, unidirectional: bool = False) -> str:
    """A Laser10 text; deviation j of run r is on line 9 + (r - 1) * n + j."""
    n = len(targets)
    lines = [
        "HEADER::",  # 1
        "File type : rtl",  # 2
        "TARGET DATA::",  # 3
        f"Target-count: {n}",  # 4
        "Targets : " + " ".join(str(t) for t in targets),  # 5
        f"Flags: 0 {1 if unidirectional else 0} 2 0",  # 6
        "RUNS::",  # 7
        f"Run-count: {len(runs)}",  # 8
        "DEVIATIONS::",  # 9
    ]
    for r, row in enumerate(runs, start=1):
        lines += [f"{r} {j} {v}" for j, v in enumerate(row, start=1)]
    return "\n".join(lines + ["EOF::", ""])


def laser10_error(text: str, **kwargs) -> ParseError:
    with pytest.raises(ParseError) as info:
        parse_laser10(text, path="m.rtl", **kwargs)
    return info.value


# -- data files -------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("targets", "runs", "unit", "line", "fragment"),
    [
        # the mean of two runs of 1e308 overflowed to inf
        ([0, 100], [[1e308, 1e308], [1e308, 1e308]], None, 10, "found 1e308 um"),
        ([0, 100], [[0, 1e200], [0, 0]], None, 11, "within ±10000 um, found 1e200 um"),
        # in mm the same limit is 10 mm: 11 mm is refused, with both units shown
        ([0, 100], [[0, 0], [11, 0]], "mm", 12, "within ±10 mm (10000 um), found 11 mm"),
        ([0, 100], [[0, 0], [0, -10001]], None, 13, "found -10001 um"),
    ],
)
def test_laser10_deviation_beyond_the_limit(targets, runs, unit, line, fragment):
    err = laser10_error(laser10(targets, runs), unit=unit)
    assert err.line == line and fragment in err.message, str(err)
    assert str(err).startswith(f"m.rtl:{line}: ")


def test_laser10_angle_limit_is_0_1_rad():
    text = laser10([0, 100], [[0, 0.1], [0, 0]])
    assert parse_laser10(text, kind="angular", unit="deg").runs["forward"][0, 1] > 1000
    err = laser10_error(laser10([0, 100], [[0, 6.0], [0, 0]]), kind="angular", unit="deg")
    # 6° = 104 720 µm/m > 100 000 µm/m
    assert err.line == 11 and "found 6 deg" in err.message and "(100000 um/m)" in err.message


@pytest.mark.parametrize(
    ("targets", "line", "fragment"),
    [
        ([0, 1e308], 5, "within ±100000 mm, found '1e+308'"),
        ([-100001, 0], 5, "found '-100001'"),
        ([0, 0.0005, 100], 5, "at least 0.001 mm apart, found 0 and 0.0005 mm"),
        ([500], 4, "Target-count of 2 or more"),
    ],
)
def test_laser10_targets(targets, line, fragment):
    runs = [[0.0] * len(targets)] * 2
    err = laser10_error(laser10(targets, runs))
    assert err.line == line and fragment in err.message, str(err)


def test_one_target_says_what_to_write_instead():
    err = laser10_error(laser10([500], [[3.0], [3.0]]))
    assert "constant = ..." in err.message and "found 1" in err.message


def test_limits_are_inclusive_and_tiny_values_are_zero():
    p = parse_laser10(laser10([-1e5, 1e5], [[1e4, -1e4], [1e-300, 0]]), kind="linear")
    assert p.runs["forward"][0].tolist() == [1e4, -1e4]
    assert p.runs["backward"][0, 0] == 0.0  # below 1e-30: exactly 0 (no underflow later)
    # targets 1 µm apart are fine, however they are rounded
    assert parse_laser10(laser10([0.999, 1.0, 1.001], [[0, 0, 0]], True)).targets_mm.size == 3


CSV_HEADER = "target_mm,run,direction,deviation\n"


@pytest.mark.parametrize(
    ("body", "line", "fragment"),
    [
        ("0,1,forward,0\n100,1,forward,1e200\n", 3, "found 1e200 um"),
        ("0,1,forward,0\n1e308,1,forward,0\n", 3, "within ±100000 mm"),
        ("500,1,forward,3\n", 2, "expected at least 2 targets"),
        ("500,1,forward,3\n500,2,backward,3\n", 2, "found 1 (500 mm)"),
        ("0,1,+,0\n0.0002,1,+,0\n", 3, "at least 0.001 mm apart"),
    ],
)
def test_csv_values(body, line, fragment):
    with pytest.raises(ParseError) as info:
        parse_csv_profile(CSV_HEADER + body, path="p.csv", kind="linear")
    assert info.value.line == line and fragment in info.value.message, str(info.value)


@pytest.mark.parametrize(
    ("comment", "fragment"),
    [("# unit: furlong\n", "unknown unit 'furlong'"), ("# unit: arcsec\n", "does not fit")],
)
def test_csv_unit_comment_names_its_line(comment, fragment):
    text = "# made by hand\n" + comment + CSV_HEADER + "0,1,+,0\n100,1,+,1\n"
    with pytest.raises(ParseError) as info:
        parse_csv_profile(text, path="p.csv", kind="linear")
    assert info.value.line == 2 and fragment in info.value.message


def test_writer_refuses_what_the_reader_would():
    with pytest.raises(DataError, match="expected 2 targets or more"):
        format_laser10(ErrorProfile("linear", [0.0], {"forward": [[1.0]]}))


# -- ErrorProfile: the same limits for profiles made in code ---------------------------------


@pytest.mark.parametrize(
    ("kind", "targets", "values", "fragment"),
    [
        ("linear", [0, 100], [0, 1e308], "within ±10000 um"),
        ("straightness", [0, 100], [0, -2e4], "found -20000 um"),
        ("angular", [0, 100], [0, 2e5], "within ±100000 um/m"),
        ("linear", [0, 2e5], [0, 1], "targets within ±100000 mm"),
        ("linear", [0, 1e-20], [0, 1], "spanning at least"),
    ],
)
def test_profile_refuses_absurd_values(kind, targets, values, fragment):
    with pytest.raises(DataError, match=fragment.replace("+", r"\+")):
        ErrorProfile(kind, targets, {"forward": [values]}, source="code")


def test_unit_helpers():
    assert DISPLACEMENT_LIMIT_UM == 1e4 and ANGLE_LIMIT_UM_PER_M == 1e5
    assert POSITION_LIMIT_MM == 1e5 and TINY == 1e-30
    assert beyond_limit([0, 1e4, -1e4], "linear") is None
    assert beyond_limit([[0, 1], [math.nan, 0]], "linear") == 2  # NaN is caught too
    assert beyond_limit([1e5, 1e4 + 1], "squareness") is None
    assert limit_text("linear", "in") == "±0.393701 in (10000 um)"
    assert limit_text("angular", "um/m") == "±100000 um/m"
    assert flush_tiny(1e-31) == 0.0 and flush_tiny(-2e-30) == -2e-30
    assert flush_tiny([1e-300, 1.0]).tolist() == [0.0, 1.0]


# -- the configuration ----------------------------------------------------------------------


def minimal() -> dict:
    with open(DATA / "minimal.toml", "rb") as f:
        return tomllib.load(f)


def config_error(data: dict, base_dir: Path = DATA) -> ConfigError:
    with pytest.raises(ConfigError) as info:
        machine_from_dict(data, base_dir, source="machine.toml")
    return info.value


def _set(data: dict, dotted: str, value) -> dict:
    data = copy.deepcopy(data)
    *path, last = dotted.split(".")
    node = data
    for part in path:
        node = node.setdefault(part, {})
    node[last] = value
    return data


TCP = {"analysis": {"point": "TCP"}}


@pytest.mark.parametrize(
    ("setting", "value", "key", "fragment"),
    [
        ("axes.X.errors.linear", {"constant": 1e308}, ".constant", "found 1e308 um"),
        ("axes.X.errors.linear", {"constant": 11, "unit": "mm"}, ".constant", "±10 mm"),
        ("axes.X.errors.angular.Z", {"constant": 1e6}, ".constant", "±100000 um/m"),
        ("squareness.XY", 1e308, "", "squareness error within ±100000 um/m"),
        ("squareness.XY", {"constant": 7, "unit": "deg"}, ".constant", "found 7 deg"),
        ("axes.X.errors.linear", {"points": [[0, 0], [500, 1e308]]}, ".points[1][1]", "1e308"),
        ("axes.X.errors.linear", {"points": [[0, 0], [1e308, 1]]}, ".points[1][0]", "±100000 mm"),
        ("axes.X.errors.linear", {"points": [[500, 3.0]]}, ".points", "'constant = ...'"),
        ("axes.X.errors.linear", {"points": [[0, 0], [1e-4, 1]]}, ".points[1][0]", "0.001 mm"),
        ("axes.X.errors.linear", {"constant": 9000, "scale": 2}, ".scale", "scaled by 2"),
        ("squareness.XY", {"constant": 90000, "scale": 2}, ".scale", "beyond the plaus"),
        ("axes.X.travel", [-1e308, 1e308], "[0]", "within ±100000 mm"),
        ("axes.X.simulate", [0, 1e308], "[1]", "within ±100000 mm"),
        ("axes.X.step", 1e-300, "", "at least 0.001 mm and at most 100000 mm, found 1e-300"),
        ("axes.X.offset", 1e308, "", "within ±100000 mm"),
        ("analysis.datum", {"X": 1e308, "Y": 0, "Z": 0}, ".X", "within ±100000 mm"),
    ],
)
def test_configuration_values(setting, value, key, fragment):
    err = config_error(_set(minimal(), setting, value))
    assert err.key == setting + key, str(err)
    assert fragment in err.message, str(err)


@pytest.mark.parametrize(
    ("tool", "key", "fragment"),
    [
        ({"lengths": [1e308], "orientation": "sweep"}, "tool.lengths[0]", "from 0 to 100000 mm"),
        ({"lengths": [0], "orientation": {"tilt": 1e308, "spin": 0}}, "tool.orientation.tilt", ""),
        ({"lengths": [0], "sweep": {"spin": [0, 400]}}, "tool.sweep.spin[1]", "±360 degrees"),
        ({"orientation": {"offset": {"X": 1e308}}}, "tool.orientation.offset.X", "100000 mm"),
    ],
)
def test_tool_values(tool, key, fragment):
    err = config_error({**minimal(), **TCP, "tool": tool})
    assert err.key == key and fragment in err.message, str(err)


def test_from_linear_needs_a_real_displacement(tmp_path):
    text = laser10([0, 100, 200], [[0, 1, 2], [0, 1, 2]])
    (tmp_path / "a.rtl").write_text(text, encoding="utf-8")
    (tmp_path / "b.rtl").write_text(text.replace("1 2 1", "1 2 9"), encoding="utf-8")
    source = {"from_linear": ["a.rtl", "b.rtl"], "displacement": 1e-300, "datum": 0}
    data = _set(minimal(), "axes.X.errors.angular.Z", source)
    err = config_error(data, tmp_path)
    assert err.key == "axes.X.errors.angular.Z.displacement" and "0.001 mm" in err.message
    # 8 µm over 0.01 mm is 800 000 µm/m: beyond 0.1 rad, named with the files
    data["axes"]["X"]["errors"]["angular"]["Z"]["displacement"] = 0.01
    err = config_error(data, tmp_path)
    assert err.key == "axes.X.errors.angular.Z.from_linear" and "a.rtl and b.rtl" in err.message


def test_library_angle_refuses_a_tiny_displacement():
    a = ErrorProfile.from_values("linear", [0, 100], [0.0, 1.0], source="a")
    b = ErrorProfile.from_values("linear", [0, 100], [0.0, 9.0], source="b")
    with pytest.raises(DataError, match="non-zero displacement"):
        angular_from_linear(a, b, 1e-300, 0.0)
    with pytest.raises(DataError, match=r"at 100 mm is 800000 µm/m, beyond"):
        angular_from_linear(a, b, 0.01, 0.0)


def test_tiny_numbers_analyse_as_zero():
    """Numbers below 1e-30 are read as 0: the engine, which treats underflow as an error,
    gives the answer of the zero error instead of refusing the machine."""
    tiny = _set(minimal(), "axes.X.errors.linear", {"points": [[0, 1e-300], [500, 1e-200]]})
    tiny = _set(tiny, "squareness.XY", 1e-300)
    tiny = _set(tiny, "axes.X.travel", [1e-300, 500])
    m = machine_from_dict(tiny, DATA, source="machine.toml")
    assert m.axes["X"].travel_mm == (0.0, 500.0)
    assert analyse(m).cases[0].volumetric.value_um == 0.0


# -- through the command line: one line, exit 2, no warning ---------------------------------


@pytest.mark.parametrize(
    ("text", "fragment"),
    [
        ("linear = { constant = 1e308 }", "axes.X.errors.linear.constant"),
        ("linear = { points = [[0, 1e308], [100, 0]] }", "axes.X.errors.linear.points[0][1]"),
        ("linear = { points = [[500, 3.0]] }", "axes.X.errors.linear.points"),
        ('linear = "big.rtl"', "big.rtl:10: expected a linear deviation"),
        ('linear = "one.rtl"', "one.rtl:4: expected a Target-count of 2 or more"),
    ],
)
def test_command_refuses_in_one_line(tmp_path, text, fragment):
    (tmp_path / "big.rtl").write_text(laser10([0, 100], [[1e308, 1e308]] * 2), encoding="utf-8")
    (tmp_path / "one.rtl").write_text(laser10([500], [[3.0]] * 2), encoding="utf-8")
    toml = (DATA / "minimal.toml").read_text(encoding="utf-8")
    toml = toml.replace("[axes.Y]", f"[axes.X.errors]\n{text}\n\n[axes.Y]")
    (tmp_path / "machine.toml").write_text(toml, encoding="utf-8")
    res = CliRunner().invoke(main, ["analyse", str(tmp_path / "machine.toml")])
    assert res.exit_code == 2, res.output
    assert res.stderr.startswith("esp: error: ") and res.stderr.count("\n") == 1
    assert fragment in res.stderr and res.stdout == ""


def test_inspect_of_an_absurd_file_is_refused(tmp_path):
    path = tmp_path / "huge.rtl"
    path.write_text(laser10([0, 100], [[1e200, 0], [0, 0]]), encoding="utf-8")
    res = CliRunner().invoke(main, ["inspect", str(path)])
    assert res.exit_code == 2 and f"{path}:10: expected a linear deviation" in res.stderr
    assert res.stdout == ""  # the table used to print a 200-digit number


# -- files too large to be measurements ----------------------------------------------------


@pytest.mark.slow
def test_readings_are_limited():
    """A file of millions of readings took gigabytes of memory to read; at most
    MAX_READINGS (runs x targets) are read, refused at the line that exceeds them."""
    assert MAX_READINGS == 200_000
    err = laser10_error(
        laser10([0, 100], [[0, 0]] * 2).replace("Run-count: 2", "Run-count: 100001")
    )
    assert err.line == 8 and "Run-count 100001 x Target-count 2 = 200002" in err.message
    many = laser10([0, 100], [[0, 0]] * 2).replace("Target-count: 2", "Target-count: 200001")
    assert "at most 200000 targets, found 200001" in laser10_error(many).message
    targets = " ".join(str(i / 10) for i in range(MAX_READINGS + 1))
    text = laser10([0, 100], [[0, 0]]).replace("Targets : 0 100", f"Targets : {targets}")
    assert "at most 200000 targets, found more" in laser10_error(text).message
    rows = "".join(f"{i},1,+,0\n" for i in range(MAX_READINGS + 1))
    with pytest.raises(ParseError) as info:
        parse_csv_profile(CSV_HEADER + rows, path="p.csv", kind="linear")
    assert info.value.line == MAX_READINGS + 2 and "at most 200000 readings" in str(info.value)
