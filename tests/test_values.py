"""One value check for every number entering esp (esp.core.values): finite, representable as a
float (TOML allows integers of any length), within the range of its quantity, refused with
the value as given; used by the configuration, the chains (head, rotary table, derive), the
files of error values, the serial-parallel machine and the command-line options
(docs/reliability.md, "Values beyond their plausibility limit")."""

from __future__ import annotations

import copy
import json
import math
import pickle
import tomllib
from pathlib import Path

import pytest

from esp.config import machine_from_dict
from esp.config.chain import load_chain
from esp.core.errors import ConfigError, DataError, ParseError
from esp.core.kinematics import position
from esp.core.values import (
    QUANTITIES,
    SYMBOL_LIMITS,
    Given,
    ValueRefused,
    check,
    check_symbol,
    parse,
    quantity_of_key,
    shown,
)
from esp.heads import head_from_dict
from esp.io.jsonfile import JSON_MAX_DEPTH, loads
from esp.parallel.config import parallel_from_dict

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "data" / "examples"
GANTRY = EXAMPLES / "gantry"
HEADS = EXAMPLES / "heads"
#: "1" followed by 400 zeros: a valid TOML integer that no float can hold
HUGE = int("1" + "0" * 400)


# -- the check itself -------------------------------------------------------------------------


def test_values_are_shown_as_given():
    # the shortest decimal that reads back as the float; integers in full up to 20 digits
    assert shown(10000.0001) == "10000.0001"  # ":g" showed 10000
    assert shown(1e-300) == "1e-300"  # flushed to 0 before, shown as 0
    assert shown(1e12) == "1e12" and shown(400.0) == "400.0" and shown(-7) == "-7"
    assert shown(HUGE) == "a whole number of 401 digits (100000...)"
    assert shown(" 1_000 ") == "'1_000'" and shown(True) == "True"
    assert shown(Given(1e8, "1e8")) == "1e8"


@pytest.mark.parametrize(
    ("value", "quantity", "fragment"),
    [
        (HUGE, "number", "found a whole number of 401 digits"),
        (-HUGE, "position", "within ±100000 mm, found a whole number of 401 digits (-100000...)"),
        (math.inf, "number", "expected a finite number, found inf"),
        (math.nan, "uncertainty", "expected a finite number, found nan"),
        (True, "number", "expected a number, found True"),
        ("3", "number", "expected a number, found '3'"),
        (100000.0001, "position", "within ±100000 mm, found 100000.0001"),
        (1001.0, "uncertainty", "an expanded uncertainty from 0 to 1000 um, found 1001.0"),
        (-1e-9, "uncertainty", "found -1e-9"),
        (0.0, "coverage factor", "above 0 and at most 100, found 0.0"),
        (0.0005, "step", "of at least 0.001 mm and at most 100000 mm, found 0.0005"),
        (400.0, "degrees", "an angle within ±360 degrees, found 400.0"),
    ],
)
def test_check_refuses_with_the_range_and_the_value_as_given(value, quantity, fragment):
    with pytest.raises(ValueRefused) as info:
        check(value, quantity)
    assert fragment in info.value.message, info.value.message


def test_check_accepts_the_range_limits():
    assert check(100000, "position") == 100000.0 and check(-100000.0, "position") == -1e5
    assert check(0, "uncertainty") == 0.0 and check(100, "coverage factor") == 100.0
    assert check(10**300) == 1e300  # a long integer within float range is a number


@pytest.mark.parametrize(
    ("text", "fragment"),
    [
        ("1_000", "expected a number, found '1_000' (write decimal digits: 1000, 2.5, 1e3)"),
        ("0x10", "found '0x10'"),
        ("inf", "expected a finite number, found 'inf'"),
        ("-Infinity", "expected a finite number, found '-Infinity'"),
        ("nan", "expected a finite number, found 'nan'"),
        ("", "found nothing"),
        ("1e400", "found '1e400'"),  # inf once converted: shown as typed
    ],
)
def test_parse_reads_decimal_text_only(text, fragment):
    with pytest.raises(ValueRefused) as info:
        parse(text)
    assert fragment in info.value.message, info.value.message


def test_parse_remembers_the_text():
    x = parse(" 1e8 ")
    assert x == 1e8 and isinstance(x, float) and shown(x) == "1e8"
    assert pickle.loads(pickle.dumps(x)) == 1e8  # batch workers get pickled values
    assert parse("-2.5E-3", "position") == -0.0025


def test_symbol_limits_are_in_the_symbols_own_unit():
    # 0.1 rad in arcsec is 20626.5; in urad 1e5; 10 mm in um 1e4
    assert check_symbol("error", "arcsec", 20626.0) == 20626.0
    with pytest.raises(ValueRefused) as info:
        check_symbol("error", "arcsec", 1e9)
    assert info.value.message == (
        "expected an angle error within ±20626.5 arcsec (0.1 rad), found 1000000000.0"
    )
    with pytest.raises(ValueRefused) as info:
        check_symbol("error", "um", 1e8)
    assert "a length error within ±10000 um (10 mm), found 100000000.0" in info.value.message
    with pytest.raises(ValueRefused) as info:
        check_symbol("parameter", "m", 101.0)
    assert "a length within ±100 m (100000 mm), found 101.0" in info.value.message
    assert check_symbol("parameter", "deg", 360.0) == 360.0
    with pytest.raises(ValueRefused):
        check_symbol("parameter", "deg", 361.0)
    assert set(SYMBOL_LIMITS) == {
        (k, d) for k in ("error", "parameter", "coordinate") for d in ("length", "angle")
    }


def test_quantity_of_a_key_comes_from_its_unit_suffix():
    assert quantity_of_key("geometry.strut_mm") == "mm"
    assert quantity_of_key("geometry.leg1.ball_mm[2]") == "mm"
    assert quantity_of_key("errors.leg1.strut_um") == "displacement"
    assert quantity_of_key("uncertainty.leg1.axis_urad[0]") == "angle"
    assert quantity_of_key("pose.alpha_deg") == "degrees"
    assert quantity_of_key("analysis.max_condition") == "number"
    assert set(QUANTITIES) >= {"mm", "displacement", "angle", "degrees", "number"}


# -- the configuration: integers beyond float range (OverflowError tracebacks before) ---------


def _gantry() -> dict:
    return tomllib.loads((GANTRY / "machine.toml").read_text(encoding="utf-8"))


def _set(data: dict, path: list[str], value) -> dict:
    t = data
    for k in path[:-1]:
        t = t.setdefault(k, {})
    t[path[-1]] = value
    return data


HUGE_CASES = [
    (["axes", "X", "step"], HUGE, "axes.X.step"),
    (["axes", "X", "errors", "linear"], {"constant": HUGE}, "axes.X.errors.linear.constant"),
    (
        ["axes", "X", "errors", "linear"],
        {"points": [[0, 0], [HUGE, 1]]},
        "axes.X.errors.linear.points[1][0]",
    ),
    (
        ["axes", "X", "errors", "linear"],
        {"points": [[0, 0], [1000, HUGE]]},
        "axes.X.errors.linear.points[1][1]",
    ),
    (["analysis", "datum"], {"X": HUGE, "Y": 0, "Z": 0}, "analysis.datum.X"),
    (
        ["axes", "X", "errors", "linear"],
        {"file": "X-linear.rtl", "scale": HUGE},
        "axes.X.errors.linear.scale",
    ),
    (["squareness", "XY"], HUGE, "squareness.XY"),
    (["squareness", "XY"], {"constant": HUGE}, "squareness.XY.constant"),
    (["axes", "X", "travel"], [0, HUGE], "axes.X.travel[1]"),
    (["axes", "X", "offset"], HUGE, "axes.X.offset"),
]


@pytest.mark.parametrize(("path", "value", "key"), HUGE_CASES, ids=[c[2] for c in HUGE_CASES])
def test_integers_beyond_float_range_are_refused_with_the_key(path, value, key):
    data = _set(_gantry(), path, value)
    with pytest.raises(ConfigError) as info:
        machine_from_dict(data, GANTRY, "machine.toml")
    assert info.value.key == key, str(info.value)
    assert "a whole number of 401 digits" in info.value.message


@pytest.mark.parametrize(
    ("tool", "key"),
    [
        ({"lengths": [HUGE]}, "tool.lengths[0]"),
        ({"lengths": [100], "sweep": {"tilt": [HUGE]}}, "tool.sweep.tilt[0]"),
        ({"lengths": [100], "orientation": {"tilt": 0, "spin": HUGE}}, "tool.orientation.spin"),
    ],
)
def test_integers_beyond_float_range_in_the_tool(tool, key):
    data = _gantry()
    data["analysis"]["point"] = "TCP"
    data["tool"] = tool
    with pytest.raises(ConfigError) as info:
        machine_from_dict(data, GANTRY, "machine.toml")
    assert info.value.key == key and "401 digits" in info.value.message, str(info.value)


@pytest.mark.parametrize(
    ("table", "key"),
    [
        ({"k": HUGE}, "uncertainty.k"),
        ({"components": {"X.linear": {"U": HUGE}}}, 'uncertainty.components."X.linear".U'),
    ],
)
def test_integers_beyond_float_range_in_the_uncertainty(table, key):
    data = _gantry()
    data["uncertainty"] = table
    with pytest.raises(ConfigError) as info:
        machine_from_dict(data, GANTRY, "machine.toml")
    assert info.value.key == key and "401 digits" in info.value.message, str(info.value)


def test_a_constant_just_beyond_the_limit_is_shown_as_given():
    data = _set(_gantry(), ["axes", "X", "errors", "linear"], {"constant": 10000.0001})
    with pytest.raises(ConfigError) as info:
        machine_from_dict(data, GANTRY, "machine.toml")
    assert info.value.message.endswith("found 10000.0001 um"), info.value.message  # was 10000


# -- chains: each symbol within the range of its kind, in its unit ------------------------------


def _head(**errors) -> dict:
    return {
        "chain": str(HEADS / "angle-head.toml"),
        "parameters": {"G": 20, "e": 10, "Yp": 50},
        "errors": errors,
    }


def test_a_head_error_of_1e9_arcsec_is_refused():
    # before: accepted (the old limit was 1e9 in the symbol's unit): a 97 m error, exit 0
    with pytest.raises(ConfigError) as info:
        head_from_dict(_head(ThetaAs=1e9), prefix="head")
    assert info.value.key == "head.errors.ThetaAs"
    assert "within ±20626.5 arcsec (0.1 rad), found 1000000000.0" in info.value.message
    head_from_dict(_head(ThetaAs=20000), prefix="head")  # 0.097 rad: accepted


def test_a_head_value_with_a_unit_is_checked_after_conversion():
    with pytest.raises(ConfigError) as info:
        head_from_dict(_head(ThetaAs={"value": 6, "unit": "deg"}), prefix="head")
    assert info.value.key == "head.errors.ThetaAs.value"
    assert "found 6 deg" in info.value.message, info.value.message


def test_a_head_parameter_beyond_float_range_and_set_values():
    with pytest.raises(ConfigError) as info:
        head_from_dict({**_head(), "parameters": {"G": HUGE, "e": 10, "Yp": 50}}, prefix="head")
    assert info.value.key == "head.parameters.G" and "401 digits" in info.value.message
    head = head_from_dict(_head(), prefix="head")
    with pytest.raises(ConfigError) as info:
        head.with_values({"G": 1e10})
    # before: "value out of range: 10000000000.0"
    assert info.value.key == "--set G"
    assert "expected a length within ±100000 mm, found 10000000000.0" in info.value.message


@pytest.mark.parametrize(
    ("text", "fragment"),
    [
        ("error,value\nThetaAs,1e9\n", ":2: ThetaAs: expected an angle error within ±20626.5"),
        ("error,value,unit\nThetaAs,6,deg\n", "found 6 deg"),
        ("error,value\nOcx,1_0\n", ":2: Ocx: expected a number, found '1_0' (write decimal digits"),
        ("error,value\nOcx,20\n", "Ocx: expected a length error within ±10 mm, found 20"),
    ],
)
def test_error_files_are_checked_per_symbol(tmp_path, text, fragment):
    (tmp_path / "e.csv").write_text(text, encoding="utf-8")
    with pytest.raises(ParseError) as info:
        head_from_dict({**_head(), "errors_from": "e.csv"}, base_dir=tmp_path, prefix="head")
    assert fragment in str(info.value), str(info.value)


def test_a_json_file_of_error_values_with_a_huge_integer_or_deep_nesting(tmp_path):
    doc = {"schema": "esp.protocol/1", "identified": {"ThetaAs": {"value": HUGE}}}
    (tmp_path / "e.json").write_text(json.dumps(doc), encoding="utf-8")
    with pytest.raises(ParseError) as info:
        head_from_dict({**_head(), "errors_from": "e.json"}, base_dir=tmp_path, prefix="head")
    assert "e.json: ThetaAs: expected a number" in str(info.value)
    assert "found a whole number of 401 digits" in str(info.value)
    # a RecursionError traceback before
    (tmp_path / "deep.json").write_text("[" * 100_000 + "]" * 100_000, encoding="utf-8")
    with pytest.raises(ParseError) as info:
        head_from_dict({**_head(), "errors_from": "deep.json"}, base_dir=tmp_path, prefix="head")
    assert f"nested at most {JSON_MAX_DEPTH} deep" in str(info.value)


def test_json_nesting_limit():
    assert loads("[" * JSON_MAX_DEPTH + "]" * JSON_MAX_DEPTH) is not None
    with pytest.raises(ParseError):
        loads("[" * (JSON_MAX_DEPTH + 1) + "]" * (JSON_MAX_DEPTH + 1))
    with pytest.raises(ParseError) as info:
        loads('{"a": 1,\n "b": }', "x.json")
    assert info.value.line == 2


def test_chain_evaluation_refuses_only_absurd_values():
    # in code a chain takes large error motions (the exact chain is the referee at any
    # angle); the physical ranges are checked where values enter (files, --set)
    chain = load_chain(EXAMPLES / "chains" / "loh-2004-scmm.toml")
    at = {"x": 0.0, "y": 0.0, "z": 0.0}
    position(chain, at, None, {"ex_Y": 0.3e6})  # 0.3 rad
    with pytest.raises(ConfigError) as info:
        position(chain, at, None, {"dx_Y": 1e13})
    assert info.value.key == "errors.dx_Y"
    assert "within ±1e+12 um (1e+09 mm), found 1e13" in info.value.message, info.value.message


def test_chain_defaults_within_their_range(tmp_path):
    text = (HEADS / "angle-head.toml").read_text(encoding="utf-8")
    assert 'G = { kind = "parameter", unit = "mm", value = 20' in text
    bad = text.replace(
        'G = { kind = "parameter", unit = "mm", value = 20',
        'G = { kind = "parameter", unit = "mm", value = 1e7',
    )
    (tmp_path / "c.toml").write_text(bad, encoding="utf-8")
    with pytest.raises(ConfigError) as info:
        head_from_dict({"chain": str(tmp_path / "c.toml")}, prefix="head")
    assert info.value.key == "symbols.G.value" and "found 10000000.0" in info.value.message


# -- the serial-parallel machine -----------------------------------------------------------------


def _parallel() -> dict:
    return tomllib.loads((EXAMPLES / "parallel" / "machine.toml").read_text(encoding="utf-8"))


@pytest.mark.parametrize(
    ("key", "value", "fragment"),
    [
        ("strut_mm", 1e12, "geometry.strut_mm: expected a length or position within ±100000 mm"),
        ("R_mm", 1e300, "geometry.R_mm: expected a length or position within ±100000 mm"),
        ("R_mm", HUGE, "geometry.R_mm: expected a length or position within"),
    ],
)
def test_parallel_geometry_values_within_their_range(key, value, fragment, recwarn):
    data = _parallel()
    data["geometry"][key] = value
    with pytest.raises(ConfigError) as info:
        parallel_from_dict(copy.deepcopy(data), "machine.toml")
    assert fragment in str(info.value), str(info.value)
    assert not [w for w in recwarn if issubclass(w.category, RuntimeWarning)]


def test_parallel_strut_error_beyond_10_mm_is_a_unit_mistake():
    data = _parallel()
    data["errors"]["leg1"]["strut_um"] = 60_000
    with pytest.raises(ConfigError) as info:
        parallel_from_dict(data, "machine.toml")
    assert "within ±10000 um, found 60000 (a unit mistake?)" in str(info.value)


def test_value_refused_is_a_data_error():
    assert issubclass(ValueRefused, DataError)


def test_chain_lengths_and_head_settings_within_their_range(tmp_path):
    from esp.core.kinematics.chain import translate
    from esp.heads.config import read_head_file

    with pytest.raises(ConfigError) as info:
        translate(0, HUGE, 0)  # an OverflowError traceback before
    assert info.value.key == "translate.y" and "401 digits" in info.value.message
    with pytest.raises(ConfigError) as info:
        translate(1e12, 0, 0)  # a 10⁹ m offset, accepted before
    assert "a position within ±100000 mm, found 1e12" in info.value.message
    text = (HEADS / "angle-head-fig3.toml").read_text(encoding="utf-8")
    text = text.replace('chain = "angle-head.toml"', f'chain = "{HEADS / "angle-head.toml"}"')
    for old, new, key in (
        ("A = { from = -60,", f"A = {{ from = {HUGE},", "map.A.from"),
        ("angles = [0, 90, 180, 270]", "angles = [0, 90, 180, 1e300]", "protocol.angles[3]"),
    ):
        (tmp_path / "h.toml").write_text(text.replace(old, new), encoding="utf-8")
        with pytest.raises(ConfigError) as info:
            read_head_file(tmp_path / "h.toml")
        assert info.value.key == key and "a setting of the axis" in info.value.message
