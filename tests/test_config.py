"""Tests of esp.config: machine.toml -> Machine."""

from __future__ import annotations

import copy
import math
import re
import tomllib
from pathlib import Path

import numpy as np
import pytest

from esp.config import load_machine, machine_from_dict
from esp.core.errors import ConfigError, ParseError
from esp.core.machine import Analysis

DATA = Path(__file__).parent / "data" / "config"
DOCS = Path(__file__).parent.parent / "docs" / "configuration.md"

ARCSEC_UM_PER_M = math.pi / (180 * 3600) * 1e6  # 1 arcsec = 4.8481... µrad = µm/m


def minimal() -> dict:
    """A fresh copy of the minimal configuration, to be changed by a test."""
    with open(DATA / "minimal.toml", "rb") as f:
        return tomllib.load(f)


def build(data: dict, base_dir: Path = DATA):
    return machine_from_dict(data, base_dir, source="machine.toml")


def config_error(data: dict, key: str, base_dir: Path = DATA) -> ConfigError:
    """Build ``data``, expect a ConfigError at ``key``, and check the message names it."""
    with pytest.raises(ConfigError) as info:
        build(data, base_dir)
    err = info.value
    assert err.key == key, str(err)
    assert key in str(err)
    assert str(err).startswith("machine.toml: ")
    return err


def with_errors(errors: dict, axis: str = "X") -> dict:
    data = minimal()
    data["axes"][axis]["errors"] = errors
    return data


# -- valid configurations ------------------------------------------------------------


def test_complete_inline_configuration():
    m = load_machine(DATA / "inline.toml")
    assert m.source == str(DATA / "inline.toml")
    assert m.name == "Gantry CMM"
    assert dict(m.info) == {
        "serial": "472596",
        "location": "Workshop",
        "measured_by": "Metrology lab",
        "date": "2000-11-01",  # a TOML date, kept as ISO text
    }
    assert m.configuration == "wBMTt"
    assert dict(m.roles) == {"bottom": "Y", "middle": "X", "top": "Z"}
    assert m.notation == "wYXZt"  # thesis 3.11: bottom Y, middle X, top Z

    assert m.analysis == Analysis(
        point="TCP",
        compensation="MCP",
        direction="backward",  # "reverse" is stored as backward runs
        datum=m.analysis.datum,
        straightness_fit="endpoint",
        extrapolate=True,
    )
    assert dict(m.analysis.datum) == {"X": 0.0, "Y": 0.0, "Z": 0.0}

    x, y, z = m.axes["X"], m.axes["Y"], m.axes["Z"]
    assert (x.role, x.travel_mm, x.simulate_mm, x.step_mm, x.offset_mm) == (
        "middle",
        (0.0, 1000.0),
        (0.0, 900.0),
        400.0,
        500.0,
    )
    # steps of 400 from 0, then the high simulation limit: 0, 400, 800, 900
    np.testing.assert_array_equal(x.grid_mm(), [0.0, 400.0, 800.0, 900.0])
    assert y.role == "bottom" and y.simulate_mm == (-250.0, 250.0) and y.offset_mm == 0.0
    np.testing.assert_array_equal(y.grid_mm(), [-250.0, -150.0, -50.0, 50.0, 150.0, 250.0])
    np.testing.assert_array_equal(z.grid_mm(), [0.0, 300.0])

    assert list(m.components) == [
        "X.linear",
        "X.straightness.Y",
        "X.straightness.Z",
        "X.angular.Z",
        "X.mechanical.Y",
        "Y.angular.X",
        "squareness.XY",
        "squareness.XZ",
    ]
    c = m.components
    # linear points given out of order, sorted: (0, 0), (500, 4), (1000, 8) µm
    lin = c["X.linear"]
    assert (lin.kind, lin.axis, lin.about, lin.source) == ("linear", "X", None, "points")
    np.testing.assert_array_equal(lin.profile.targets_mm, [0.0, 500.0, 1000.0])
    assert lin.profile.at(250.0, "backward") == pytest.approx((0.0 + 4.0) / 2)
    # straightness in mm: 0.004 mm = 4 µm at 1000 mm, 2 µm half way
    sz = c["X.straightness.Z"]
    assert (sz.kind, sz.axis, sz.about) == ("straightness", "X", "Z")
    assert sz.profile.at(500.0) == pytest.approx(0.004 * 1000 / 2)
    # a constant holds at every position
    sy = c["X.straightness.Y"]
    assert sy.source == "constant 2 um"
    np.testing.assert_allclose(sy.profile.at([-1e6, 0.0, 1e6]), [2.0, 2.0, 2.0])
    yaw = c["X.angular.Z"]
    assert (yaw.kind, yaw.axis, yaw.about, yaw.unit) == ("angular", "X", "Z", "um/m")
    assert yaw.source == "constant 2 arcsec"
    assert yaw.profile.at(0.0) == pytest.approx(2 * ARCSEC_UM_PER_M)
    mech = c["X.mechanical.Y"]
    assert (mech.kind, mech.axis, mech.about) == ("mechanical", "X", "Y")
    assert mech.profile.kind == "angular"  # mechanical angles are angular data
    assert mech.profile.at(0.0) == pytest.approx(0.003 * 1000)  # 0.003 mrad = 3 µm/m
    assert mech.iso == "EBX"
    assert c["Y.angular.X"].profile.at(0.0) == pytest.approx(4.0)  # default unit µm/m

    sq = c["squareness.XY"]  # given as YX
    assert (sq.kind, sq.value, sq.profile, sq.unit) == ("squareness", -2.0, None, "um/m")
    assert c["squareness.XZ"].value == pytest.approx(1 * ARCSEC_UM_PER_M)
    assert c["squareness.XZ"].source == "constant 1 arcsec"

    assert m.tool.lengths_mm == (0.0, 100.0, 300.0)
    # tilt outer, spin inner
    assert m.tool.orientations_deg == ((0.0, 0.0), (0.0, 180.0), (90.0, 0.0), (90.0, 180.0))
    assert m.tool.sweep is True
    assert m.tool.offsets_mm == ()


def test_minimal_configuration_takes_the_defaults():
    m = load_machine(DATA / "minimal.toml")
    assert m.analysis == Analysis()
    assert (m.analysis.point, m.analysis.compensation, m.analysis.direction) == (
        "MCP",
        "none",
        "mean",
    )
    assert (m.analysis.datum, m.analysis.straightness_fit, m.analysis.extrapolate) == (
        "none",
        "least-squares",
        False,
    )
    assert m.tool is None
    assert dict(m.components) == {}
    assert dict(m.info) == {}
    assert m.description.startswith("Bottom axis carries the workpiece")
    x = m.axes["X"]
    assert x.simulate_mm == x.travel_mm == (0.0, 500.0)
    assert x.offset_mm == 0.0
    # an axis that does not move needs no step and has a one-point grid
    z = m.axes["Z"]
    assert z.travel_mm == (0.0, 0.0) and z.step_mm == 0.0
    np.testing.assert_array_equal(z.grid_mm(), [0.0])


def test_machine_from_dict_equals_load_machine():
    with open(DATA / "inline.toml", "rb") as f:
        data = tomllib.load(f)
    a = machine_from_dict(data, DATA)
    b = load_machine(DATA / "inline.toml")
    assert a.source is None
    assert list(a.components) == list(b.components)
    assert a.axes == b.axes and a.tool == b.tool and a.analysis == b.analysis


def test_inline_sources_apply_to_both_directions():
    data = with_errors({"linear": {"points": [[0, 1.0], [500, 3.0]]}})
    profile = build(data).components["X.linear"].profile
    for direction in ("forward", "backward", "mean"):
        np.testing.assert_allclose(profile.mean(direction), [1.0, 3.0])


@pytest.mark.parametrize(
    ("given", "stored"),
    [("forward", "forward"), ("reverse", "backward"), ("backward", "backward"), ("mean", "mean")],
)
def test_direction(given, stored):
    data = minimal()
    data["analysis"] = {"direction": given}
    assert build(data).analysis.direction == stored


def test_squareness_pairs_are_unordered():
    for key in ("XZ", "ZX"):
        data = minimal()
        data["squareness"] = {key: 3.5}
        m = build(data)
        assert list(m.components) == ["squareness.XZ"]
        assert m.components["squareness.XZ"].value == 3.5
        assert m.components["squareness.XZ"].iso == "EB0Z"


def test_datum_names():
    for datum in ("none", "negative", "centre"):
        data = minimal()
        data["analysis"] = {"datum": datum}
        assert build(data).analysis.datum == datum


def test_tool_with_one_orientation():
    data = minimal()
    data["analysis"] = {"point": "TCP"}
    data["tool"] = {"lengths": [150], "orientation": {"tilt": 90, "spin": 45}}
    tool = build(data).tool
    assert tool.lengths_mm == (150.0,)
    assert tool.orientations_deg == ((90.0, 45.0),)
    assert tool.sweep is False


def test_tool_sweep_defaults_follow_thesis_3_12():
    # 45° steps from the spindle direction over the hemisphere a head can hold (tilt 0, 45,
    # 90), 90° steps about it (4 spins); the spindle points against the top axis by default
    data = minimal()
    data["tool"] = {"lengths": [100]}  # orientation defaults to the sweep
    tool = build(data).tool
    assert tool.sweep is True and tool.spindle is None
    assert len(tool.orientations_deg) == 3 * 4
    assert tool.orientations_deg[:5] == (
        (0.0, 0.0),
        (0.0, 90.0),
        (0.0, 180.0),
        (0.0, 270.0),
        (45.0, 0.0),
    )
    assert tool.orientations_deg[-1] == (90.0, 270.0)
    data["tool"]["spindle"] = "z"
    assert build(data).tool.spindle == "+Z"
    data["tool"]["spindle"] = "down"
    assert "'+X', '-X'" in config_error(data, "tool.spindle").message


def test_tool_cases_follow_the_spindle_direction():
    from esp.core.models.tool import tool_cases

    data = minimal()
    data["analysis"] = {"point": "TCP"}
    data["tool"] = {"lengths": [100], "orientation": {"tilt": 0, "spin": 0}}
    (case,) = tool_cases(build(data))  # default: against the top axis Z
    assert dict(case.offset_mm) == {"X": 0.0, "Y": 0.0, "Z": -100.0}
    data["tool"]["spindle"] = "+Z"  # the thesis' eq. 3.6: tilt from +T
    data["tool"]["orientation"] = {"tilt": 90, "spin": 90}
    (case,) = tool_cases(build(data))
    # spin 0 points along the middle axis, spin 90 along the bottom axis (eq. 3.8-3.9)
    assert dict(case.offset_mm) == {"X": 100.0, "Y": 0.0, "Z": 0.0}
    data["tool"]["spindle"] = "-X"  # a horizontal spindle along the bottom axis
    data["tool"]["orientation"] = {"tilt": 90, "spin": 90}
    (case,) = tool_cases(build(data))
    assert dict(case.offset_mm) == {"X": 0.0, "Y": 0.0, "Z": 100.0}


def test_config_warnings_for_quiet_traps():
    data = minimal()
    data["tool"] = {"lengths": [100]}  # given, but the analysis is at the MCP
    data["axes"]["X"]["offset"] = 5000.0
    warnings = build(data).warnings
    assert any("analysis.point = 'MCP'" in w for w in warnings)
    assert any("axes.X.offset = 5000 mm lies outside the travel" in w for w in warnings)


def test_tool_offset_vector_needs_no_lengths():
    data = minimal()
    data["analysis"] = {"point": "TCP"}
    data["tool"] = {"orientation": {"offset": {"Z": -150}}}
    tool = build(data).tool
    assert [dict(o) for o in tool.offsets_mm] == [{"X": 0.0, "Y": 0.0, "Z": -150.0}]
    assert tool.lengths_mm == () and tool.orientations_deg == ()
    assert tool.sweep is False


def test_mcp_analysis_keeps_a_tool():
    data = minimal()
    data["tool"] = {"lengths": [0, 50], "orientation": {"tilt": 0, "spin": 0}}
    m = build(data)
    assert m.analysis.point == "MCP"
    assert m.tool.lengths_mm == (0.0, 50.0)


def test_the_unit_spelling_is_free():
    data = with_errors({"angular": {"Y": {"constant": 1.0, "unit": "µrad"}}})
    assert build(data).components["X.angular.Y"].profile.at(0.0) == pytest.approx(1.0)


# -- data files -----------------------------------------------------------------------


def test_configuration_with_data_files(tmp_path, monkeypatch):
    # paths are relative to the configuration's folder, not to the working directory
    monkeypatch.chdir(tmp_path)
    folder = DATA / "files"
    m = load_machine(folder / "machine.toml")
    assert list(m.components) == [
        "X.linear",
        "X.straightness.Z",
        "X.angular.Y",
        "X.mechanical.Y",
    ]
    lin = m.components["X.linear"]
    assert lin.source == "Xpos.rtl"
    assert Path(lin.profile.source) == folder / "Xpos.rtl"
    assert (lin.profile.kind, lin.profile.axis) == ("linear", "X")
    # runs 1 and 3 forward: (0, 4, 8) and (1, 5, 9) µm -> mean (0.5, 4.5, 8.5)
    np.testing.assert_allclose(lin.profile.mean("forward"), [0.5, 4.5, 8.5])
    # runs 2 and 4 backward: (-1, 3, 7) and (0, 4, 8) µm -> mean (-0.5, 3.5, 7.5)
    np.testing.assert_allclose(lin.profile.mean("backward"), [-0.5, 3.5, 7.5])
    # bidirectional mean (0, 4, 8), half way between 0 and 500 mm: 2 µm
    assert lin.profile.at(250.0) == pytest.approx(2.0)

    strt = m.components["X.straightness.Z"]
    assert strt.source == "straightness/Xvert.stx"
    assert (strt.profile.kind, strt.profile.axis, strt.profile.error_direction) == (
        "straightness",
        "X",
        "Z",
    )
    np.testing.assert_allclose(strt.profile.mean(), [0.0, 1.5, 3.0, 1.5, 0.0])

    # the same file read as arcsec (angular) and with the default µm/m (mechanical)
    pitch = m.components["X.angular.Y"]
    assert (pitch.profile.kind, pitch.profile.error_direction, pitch.profile.input_unit) == (
        "angular",
        "Y",
        "arcsec",
    )
    np.testing.assert_allclose(pitch.profile.mean(), np.array([1.0, 2.0, 3.0]) * ARCSEC_UM_PER_M)
    mech = m.components["X.mechanical.Y"]
    assert (mech.kind, mech.profile.kind) == ("mechanical", "angular")
    np.testing.assert_allclose(mech.profile.mean(), [1.0, 2.0, 3.0])


def test_absolute_data_path_written_by_the_laser10_writer(tmp_path):
    from esp.core.profile import ErrorProfile
    from esp.io.laser10 import write_laser10

    written = ErrorProfile.from_values("straightness", [0, 250, 500], [0.0, 2.0, 0.5])
    write_laser10(tmp_path / "Yhoriz.rts", written)
    data = with_errors({"straightness": {"X": str(tmp_path / "Yhoriz.rts")}}, axis="Y")
    m = build(data, base_dir=DATA)  # an absolute path ignores the base folder
    profile = m.components["Y.straightness.X"].profile
    assert (profile.axis, profile.error_direction) == ("Y", "X")
    np.testing.assert_allclose(profile.mean(), [0.0, 2.0, 0.5])


def test_errors_inside_a_data_file_pass_through(tmp_path):
    (tmp_path / "bad.rtl").write_text("HEADER::\nFile type : rtl\nEOF::\n", encoding="utf-8")
    data = with_errors({"linear": "bad.rtl"})
    with pytest.raises(ParseError) as info:
        build(data, base_dir=tmp_path)
    assert not isinstance(info.value, ConfigError)
    assert "bad.rtl" in str(info.value)


# -- errors: file and TOML ----------------------------------------------------------------


def test_missing_configuration_file(tmp_path):
    with pytest.raises(ConfigError) as info:
        load_machine(tmp_path / "nowhere.toml")
    assert info.value.key == "<file>"
    assert "nowhere.toml" in str(info.value)
    assert "no such configuration file" in str(info.value)


def test_toml_syntax_error_names_line_and_column(tmp_path):
    path = tmp_path / "machine.toml"
    path.write_text('[machine]\nname = "A"\nconfiguration = \n', encoding="utf-8")
    with pytest.raises(ConfigError) as info:
        load_machine(path)
    assert info.value.key == "<toml>"
    assert "line 3, column 17" in str(info.value)
    assert str(path) in str(info.value)


def test_toml_key_given_twice(tmp_path):
    path = tmp_path / "machine.toml"
    path.write_text('[machine]\nname = "A"\nname = "B"\n', encoding="utf-8")
    with pytest.raises(ConfigError, match=r"<toml>: invalid TOML at line 3"):
        load_machine(path)


def test_not_utf8(tmp_path):
    path = tmp_path / "machine.toml"
    path.write_bytes(b'[machine]\nname = "\xe9"\n')
    with pytest.raises(ConfigError, match=r"<toml>: expected UTF-8 text, found byte 0xe9"):
        load_machine(path)


def test_byte_order_mark_is_accepted(tmp_path):
    path = tmp_path / "machine.toml"
    path.write_bytes(b"\xef\xbb\xbf" + (DATA / "minimal.toml").read_bytes())
    assert load_machine(path).name == "Minimal"


def test_errors_name_the_configuration_file(tmp_path):
    path = tmp_path / "machine.toml"
    text = (DATA / "minimal.toml").read_text(encoding="utf-8")
    path.write_text(text.replace("step = 100", "step = -1", 1), encoding="utf-8")
    with pytest.raises(ConfigError) as info:
        load_machine(path)
    expected = "expected a step of at least 0.001 mm and at most 100000 mm, found -1"
    assert str(info.value) == f"{path}: axes.X.step: {expected}"


# -- errors: unknown keys -----------------------------------------------------------------


def test_unknown_key_with_suggestion():
    data = minimal()
    data["axes"]["X"]["stpe"] = 10
    err = config_error(data, "axes.X.stpe")
    assert "unknown key 'stpe'; did you mean 'step'?" in err.message


@pytest.mark.parametrize(
    ("change", "key", "suggestion"),
    [
        (lambda d: d.update(analysys={}), "analysys", "analysis"),
        (lambda d: d["machine"].update(serial_no="1"), "machine.serial_no", "serial"),
        (
            lambda d: d.update(analysis={"extrapolation": True}),
            "analysis.extrapolation",
            "extrapolate",
        ),
        (
            lambda d: d["axes"]["X"].update(errors={"angualr": {}}),
            "axes.X.errors.angualr",
            "angular",
        ),
        (
            lambda d: d["axes"]["X"].update(errors={"linear": {"constant": 1, "units": "um"}}),
            "axes.X.errors.linear.units",
            "unit",
        ),
        (lambda d: d.update(tool={"length": [0]}), "tool.length", "lengths"),
        (lambda d: d.update(squareness={"xy": 1.0}), "squareness.xy", "XY"),
        (lambda d: d["axes"].update(x={"travel": [0, 1]}), "axes.x", "X"),
    ],
)
def test_unknown_keys_everywhere(change, key, suggestion):
    data = minimal()
    change(data)
    err = config_error(data, key)
    assert f"did you mean {suggestion!r}?" in err.message


def test_unknown_key_without_close_match_lists_the_keys():
    data = minimal()
    data["axes"]["Y"]["colour"] = "red"
    err = config_error(data, "axes.Y.colour")
    assert "did you mean" not in err.message
    assert "'travel', 'simulate', 'step', 'offset', 'errors'" in err.message


# -- from_linear: an angle derived from two linear files (thesis 3.08.1) ---------------------


def _linear_pair(folder: Path) -> None:
    """Two linear files of X, targets 0, 250, 500 mm, one run each way (µm):
    ref.rtl forward 0, 2, 4 / backward 1, 3, 5; shift.rtl forward 0, 6, 12 / backward 1, 5, 9.
    Shifted minus reference: forward 0, 4, 8 and backward 0, 2, 4 µm."""
    from esp.core.profile import ErrorProfile
    from esp.io.laser10 import write_laser10

    t = [0.0, 250.0, 500.0]
    for name, fwd, bwd in (
        ("ref.rtl", [0.0, 2.0, 4.0], [1.0, 3.0, 5.0]),
        ("shift.rtl", [0.0, 6.0, 12.0], [1.0, 5.0, 9.0]),
    ):
        write_laser10(folder / name, ErrorProfile("linear", t, {"forward": fwd, "backward": bwd}))
    write_laser10(folder / "short.rtl", ErrorProfile("linear", [0.0, 250.0], {"forward": [0, 1]}))
    write_laser10(folder / "pitch.rta", ErrorProfile("angular", t, {"forward": [0, 1, 2]}))


def _derived(source: dict, kind: str = "angular", **analysis) -> dict:
    data = with_errors({kind: {"Y": source}})
    if analysis:
        data["analysis"] = analysis
    return data


def test_from_linear_builds_the_angle(tmp_path):
    _linear_pair(tmp_path)
    src = {"from_linear": ["ref.rtl", "shift.rtl"], "displacement": 400, "datum": 250}
    comp = build(_derived(src), tmp_path).components["X.angular.Y"]
    assert (comp.kind, comp.axis, comp.about, comp.unit) == ("angular", "X", "Y", "um/m")
    assert comp.source == "from_linear ref.rtl, shift.rtl (D = 400 mm, datum 250 mm)"
    # per run: 1000 x (b - a) / 400: forward 0, 10, 20 and backward 0, 5, 10 µm/m; the
    # bidirectional mean at the datum 250 mm is (10 + 5) / 2 = 7.5, removed from every run
    p = comp.profile
    np.testing.assert_allclose(p.mean("forward"), [-7.5, 2.5, 12.5], atol=1e-12)
    np.testing.assert_allclose(p.mean("backward"), [-7.5, -2.5, 2.5], atol=1e-12)
    np.testing.assert_allclose(p.mean("mean"), [-7.5, 0.0, 7.5], atol=1e-12)


def test_from_linear_datum_follows_the_analysed_direction(tmp_path):
    _linear_pair(tmp_path)
    src = {"from_linear": ["ref.rtl", "shift.rtl"], "displacement": 400, "datum": 250}
    # forward runs analysed: the forward angle (10 µm/m at 250 mm) is zero at the datum
    p = build(_derived(src, direction="forward"), tmp_path).components["X.angular.Y"].profile
    np.testing.assert_allclose(p.mean("forward"), [-10.0, 0.0, 10.0], atol=1e-12)
    np.testing.assert_allclose(p.mean("backward"), [-10.0, -5.0, 0.0], atol=1e-12)


def test_from_linear_for_a_mechanical_angle_with_a_unit(tmp_path):
    _linear_pair(tmp_path)
    # the files read in nm: differences 0, 4, 8 nm forward over D = -400 mm
    # -> 1000 x 0.008 / -400 = -0.02 µm/m at 500 mm; datum 0 mm holds no difference
    src = {
        "from_linear": ["ref.rtl", "shift.rtl"],
        "displacement": -400,
        "datum": 0,
        "unit": "nm",
    }
    comp = build(_derived(src, kind="mechanical"), tmp_path).components["X.mechanical.Y"]
    assert comp.kind == "mechanical"
    np.testing.assert_allclose(comp.profile.mean("forward"), [0.0, -0.01, -0.02], atol=1e-12)


@pytest.mark.parametrize(
    ("source", "key", "expected"),
    [
        ({"from_linear": "ref.rtl"}, "from_linear", "two linear file paths"),
        ({"from_linear": ["ref.rtl"]}, "from_linear", "two linear file paths"),
        ({"from_linear": ["ref.rtl", "shift.rtl"], "datum": 0}, "displacement", "missing"),
        ({"from_linear": ["ref.rtl", "shift.rtl"], "displacement": 5}, "datum", "missing"),
        (
            {"from_linear": ["ref.rtl", "shift.rtl"], "displacement": 0, "datum": 0},
            "displacement",
            "of at least 0.001 mm in size, found 0",
        ),
        (
            {"from_linear": ["ref.rtl", "shift.rtl"], "displacement": 5, "datum": 100},
            "datum",
            "not a target",
        ),
        (
            {"from_linear": ["ref.rtl", "nothere.rtl"], "displacement": 5, "datum": 0},
            "from_linear[1]",
            "no such file 'nothere.rtl'",
        ),
        (
            {"from_linear": ["ref.rtl", "short.rtl"], "displacement": 5, "datum": 0},
            "from_linear",
            "same targets",
        ),
        (
            {
                "from_linear": ["ref.rtl", "shift.rtl"],
                "displacement": 5,
                "datum": 0,
                "unit": "um/m",
            },
            "unit",
            "unit of the two linear files",
        ),
        ({"constant": 1.0, "displacement": 5}, "displacement", "only used with 'from_linear'"),
        (
            {"from_linear": ["ref.rtl", "pitch.rta"], "displacement": 5, "datum": 0},
            "from_linear[1]",
            "expected a linear positioning file, found 'pitch.rta' (angular data)",
        ),
    ],
)
@pytest.mark.slow
def test_from_linear_errors_name_the_key(tmp_path, source, key, expected):
    _linear_pair(tmp_path)
    err = config_error(_derived(source), f"axes.X.errors.angular.Y.{key}", tmp_path)
    assert expected in err.message


def test_from_linear_is_only_for_angles(tmp_path):
    _linear_pair(tmp_path)
    src = {"from_linear": ["ref.rtl", "shift.rtl"], "displacement": 5, "datum": 0}
    err = config_error(with_errors({"linear": src}), "axes.X.errors.linear.from_linear", tmp_path)
    assert "only for angular and mechanical components" in err.message
    # and the forms offered to a linear component do not list it
    err = config_error(with_errors({"linear": {"unit": "um"}}), "axes.X.errors.linear")
    assert "'from_linear'" not in err.message


# -- errors: machine ----------------------------------------------------------------------


def test_missing_required_tables_and_keys():
    data = minimal()
    del data["axes"]
    config_error(data, "axes")
    data = minimal()
    del data["machine"]["name"]
    config_error(data, "machine.name")
    data = minimal()
    del data["axes"]["Y"]
    config_error(data, "axes.Y")
    data = minimal()
    del data["machine"]["axes"]["top"]
    config_error(data, "machine.axes.top")


def test_bad_configuration_name():
    data = minimal()
    data["machine"]["configuration"] = "wbmtt"
    err = config_error(data, "machine.configuration")
    assert "expected one of 'wBMTt', 'BwMTt', 'BMwTt', 'BMTwt', found 'wbmtt'" in err.message
    assert "did you mean 'wBMTt'?" in err.message


def test_configuration_with_all_axes_carrying_the_workpiece_needs_the_rigid_body_model():
    data = minimal()
    data["machine"]["configuration"] = "BMTwt"
    assert build(data).configuration == "BMTwt"
    data["analysis"] = {"model": "as-printed"}
    err = config_error(data, "analysis.model")
    assert "prints no equations for BMTwt" in err.message


def test_axis_not_x_y_z():
    data = minimal()
    data["machine"]["axes"]["top"] = "W"
    err = config_error(data, "machine.axes.top")
    assert "expected one of 'X', 'Y', 'Z', found 'W'" in err.message


def test_axis_assigned_twice():
    data = minimal()
    data["machine"]["axes"] = {"bottom": "X", "middle": "X", "top": "Z"}
    err = config_error(data, "machine.axes")
    assert "'X' assigned to bottom and middle" in err.message
    assert "Y to none" in err.message


def test_wrong_types():
    data = minimal()
    data["machine"]["name"] = 7
    assert "expected a string, found 7" in config_error(data, "machine.name").message
    data = minimal()
    data["machine"]["serial"] = 472596
    config_error(data, "machine.serial")
    data = minimal()
    data["axes"]["X"]["step"] = True
    assert "expected a number, found True" in config_error(data, "axes.X.step").message
    data = minimal()
    data["axes"]["X"]["offset"] = float("nan")
    assert "finite" in config_error(data, "axes.X.offset").message
    data = minimal()
    data["analysis"] = {"extrapolate": "yes"}
    config_error(data, "analysis.extrapolate")
    data = minimal()
    data["analysis"] = "MCP"
    assert "expected a table" in config_error(data, "analysis").message


# -- errors: axes -------------------------------------------------------------------------


@pytest.mark.parametrize("step", [0, -45, 0.0])
def test_step_must_be_positive(step):
    data = minimal()
    data["axes"]["X"]["step"] = step
    err = config_error(data, "axes.X.step")
    assert (
        f"expected a step of at least 0.001 mm and at most 100000 mm, found {step!r}" in err.message
    )


def test_step_required_when_the_axis_moves():
    data = minimal()
    del data["axes"]["Y"]["step"]
    config_error(data, "axes.Y.step")


def test_step_of_a_still_axis_is_checked_when_given():
    data = minimal()
    data["axes"]["Z"]["step"] = -1
    config_error(data, "axes.Z.step")


@pytest.mark.parametrize("simulate", [[-10, 500], [0, 501], [100, 600]])
def test_simulate_outside_travel(simulate):
    data = minimal()
    data["axes"]["X"]["simulate"] = simulate
    err = config_error(data, "axes.X.simulate")
    assert "within the travel [0, 500] mm" in err.message


def test_simulate_may_be_one_plane():
    data = minimal()
    data["axes"]["Y"]["simulate"] = [200, 200]
    np.testing.assert_array_equal(build(data).axes["Y"].grid_mm(), [200.0])


def test_travel_low_above_high():
    data = minimal()
    data["axes"]["X"]["travel"] = [500, 0]
    err = config_error(data, "axes.X.travel")
    assert "expected low <= high, found [500, 0]" in err.message
    data["axes"]["X"]["travel"] = [0, 1, 2]
    config_error(data, "axes.X.travel")
    data["axes"]["X"]["travel"] = [0, "1"]
    config_error(data, "axes.X.travel[1]")


# -- errors: error sources ----------------------------------------------------------------


def test_missing_data_file_names_the_key_and_the_path(tmp_path):
    data = with_errors({"linear": "Xpos.rtl"})
    err = config_error(data, "axes.X.errors.linear", base_dir=tmp_path)
    assert "'Xpos.rtl'" in err.message
    assert str(tmp_path / "Xpos.rtl") in err.message


def test_missing_data_file_in_a_table(tmp_path):
    data = with_errors({"angular": {"Y": {"file": "sub/Xpitch.rta", "unit": "arcsec"}}})
    err = config_error(data, "axes.X.errors.angular.Y.file", base_dir=tmp_path)
    assert str(tmp_path / "sub" / "Xpitch.rta") in err.message


def test_data_file_that_is_a_folder(tmp_path):
    (tmp_path / "data").mkdir()
    data = with_errors({"linear": "data"})
    assert "is a folder" in config_error(data, "axes.X.errors.linear", tmp_path).message


@pytest.mark.parametrize(
    ("errors", "key", "expected"),
    [
        (
            {"linear": {"constant": 1, "unit": "arcsec"}},
            "axes.X.errors.linear.unit",
            "a unit of length (um, mm, nm, in) for the linear error X.linear",
        ),
        (
            {"straightness": {"Y": {"points": [[0, 1], [100, 2]], "unit": "urad"}}},
            "axes.X.errors.straightness.Y.unit",
            "length",
        ),
        (
            {"angular": {"Z": {"constant": 1, "unit": "um"}}},
            "axes.X.errors.angular.Z.unit",
            "unit of angle (um/m, urad, mrad, arcsec, deg) for the angular error X.angular.Z",
        ),
        (
            {"mechanical": {"Y": {"constant": 1, "unit": "mm"}}},
            "axes.X.errors.mechanical.Y.unit",
            "angle",
        ),
        (
            {"linear": {"constant": 1, "unit": "furlong"}},
            "axes.X.errors.linear.unit",
            "found 'furlong'",
        ),
    ],
)
def test_unit_that_does_not_fit_the_kind(errors, key, expected):
    err = config_error(with_errors(errors), key)
    assert expected in err.message


def test_squareness_unit_must_be_an_angle():
    data = minimal()
    data["squareness"] = {"XY": {"constant": 1, "unit": "um"}}
    config_error(data, "squareness.XY.unit")


def test_squareness_given_twice():
    data = minimal()
    data["squareness"] = {"XY": -2.0, "YX": -2.0}
    err = config_error(data, "squareness.YX")
    assert "found it as both XY and YX" in err.message


def test_squareness_must_be_a_number():
    data = minimal()
    data["squareness"] = {"YZ": "5"}
    assert "expected a number in um/m" in config_error(data, "squareness.YZ").message
    data["squareness"] = {"YZ": {"file": "sq.txt"}}
    config_error(data, "squareness.YZ.file")


def test_straightness_along_its_own_axis():
    data = with_errors({"straightness": {"X": {"constant": 1}}})
    err = config_error(data, "axes.X.errors.straightness.X")
    assert "linear error" in err.message and "expected Y or Z" in err.message


def test_straightness_of_another_axis_accepts_the_two_others():
    data = with_errors({"straightness": {"X": {"constant": 1}, "Z": {"constant": 2}}}, axis="Y")
    assert list(build(data).components) == ["Y.straightness.X", "Y.straightness.Z"]


def test_component_tables_need_axis_letters():
    data = with_errors({"angular": {"W": {"constant": 1}}})
    config_error(data, "axes.X.errors.angular.W")
    data = with_errors({"angular": "Xpitch.rta"})
    err = config_error(data, "axes.X.errors.angular")
    assert "table of rotation axis -> source" in err.message


@pytest.mark.parametrize(
    ("source", "key", "expected"),
    [
        (
            {"constant": 1, "points": [[0, 1]]},
            "axes.X.errors.linear",
            "exactly one of 'file', 'constant', 'points', 'etalon', found 'constant' and 'points'",
        ),
        ({"unit": "um"}, "axes.X.errors.linear", "found none"),
        (4.0, "axes.X.errors.linear", "expected a file path or a table"),
        ({"constant": "4"}, "axes.X.errors.linear.constant", "expected a number, found '4'"),
        ({"points": []}, "axes.X.errors.linear.points", "list of [position_mm, value] pairs"),
        ({"points": [[0, 1, 2]]}, "axes.X.errors.linear.points[0]", "pair"),
        ({"points": [[0, 1], [0, 2]]}, "axes.X.errors.linear.points", "0 mm more than once"),
        ({"file": 3}, "axes.X.errors.linear.file", "expected a string"),
        ("", "axes.X.errors.linear", "expected a file path"),
    ],
)
def test_bad_sources(source, key, expected):
    err = config_error(with_errors({"linear": source}), key)
    assert expected in err.message


# -- errors: analysis and tool ------------------------------------------------------------


def test_tcp_without_tool():
    data = minimal()
    data["analysis"] = {"point": "TCP"}
    err = config_error(data, "tool")
    assert "[tool]" in err.message


def test_every_point_and_compensation_pair_is_accepted():
    # the five cases of thesis 3.10.1-3.10.5, and a TCP-compensated machine seen at the MCP
    for point in ("MCP", "TCP"):
        for compensation in ("none", "MCP", "TCP"):
            data = minimal()
            data["analysis"] = {"point": point, "compensation": compensation}
            data["tool"] = {"lengths": [100]}
            a = build(data).analysis
            assert (a.point, a.compensation) == (point, compensation)


@pytest.mark.parametrize(
    ("analysis", "key"),
    [
        ({"point": "tcp"}, "analysis.point"),
        ({"compensation": "yes"}, "analysis.compensation"),
        ({"direction": "both"}, "analysis.direction"),
        ({"straightness_fit": "least squares"}, "analysis.straightness_fit"),
    ],
)
def test_bad_analysis_choices(analysis, key):
    data = minimal()
    data["analysis"] = analysis
    config_error(data, key)


@pytest.mark.parametrize(
    ("datum", "key", "expected"),
    [
        ("center", "analysis.datum", "did you mean 'centre'?"),
        ("middle", "analysis.datum", "expected one of 'none', 'negative', 'centre'"),
        ({"X": 0, "Y": 0}, "analysis.datum.Z", "required key is missing"),
        ({"X": 0, "Y": 0, "Z": "0"}, "analysis.datum.Z", "expected a number"),
        ({"X": 0, "Y": 0, "Z": 0, "W": 0}, "analysis.datum.W", "unknown key"),
        ({"X": 600, "Y": 0, "Z": 0}, "analysis.datum.X", "within the travel of X [0, 500]"),
        ([0, 0, 0], "analysis.datum", "found [0, 0, 0]"),
    ],
)
def test_bad_datum(datum, key, expected):
    data = minimal()
    data["analysis"] = {"datum": datum}
    assert expected in config_error(data, key).message


@pytest.mark.parametrize(
    ("tool", "key", "expected"),
    [
        ({"orientation": "sweep"}, "tool.lengths", "required key is missing"),
        ({"lengths": []}, "tool.lengths", "non-empty list"),
        (
            {"lengths": [100, -5]},
            "tool.lengths[1]",
            "expected a tool length from 0 to 100000 mm, found -5",
        ),
        ({"lengths": [100, 100]}, "tool.lengths", "each length once"),
        ({"lengths": [100], "orientation": "swep"}, "tool.orientation", "did you mean 'sweep'?"),
        ({"lengths": [100], "orientation": {"tilt": 90}}, "tool.orientation.spin", "missing"),
        (
            {"lengths": [100], "orientation": {"tilt": 90, "spin": 0, "offset": {"X": 1}}},
            "tool.orientation",
            "either tilt and spin, or offset",
        ),
        (
            {"lengths": [100], "orientation": {"offset": {"X": 1}}},
            "tool.lengths",
            "not used when tool.orientation gives an offset",
        ),
        ({"orientation": {"offset": {"B": 1}}}, "tool.orientation.offset.B", "unknown key"),
        ({"orientation": {"offset": 150}}, "tool.orientation.offset", "expected a table"),
        (
            {"lengths": [100], "orientation": {"tilt": 0, "spin": 0}, "sweep": {"tilt": [0]}},
            "tool.sweep",
            "only used with orientation = 'sweep'",
        ),
        ({"lengths": [100], "sweep": {"tilt": []}}, "tool.sweep.tilt", "non-empty list"),
        ({"lengths": [100], "sweep": {"spin": [0, "90"]}}, "tool.sweep.spin[1]", "number"),
        ({"lengths": [100], "orientation": 90}, "tool.orientation", "expected 'sweep'"),
    ],
)
def test_bad_tool(tool, key, expected):
    data = minimal()
    data["tool"] = tool
    assert expected in config_error(data, key).message


# -- the documentation covers the contract ---------------------------------------------


def test_every_key_is_documented():
    import esp.config as cfg

    text = DOCS.read_text(encoding="utf-8")
    keys = (
        set(cfg.MACHINE_KEYS)
        | set(cfg.ANALYSIS_KEYS)
        | set(cfg.AXIS_KEYS)
        | set(cfg.ERROR_KEYS)
        | set(cfg.TOOL_KEYS)
        | set(cfg.SOURCE_BUILDERS)
        | set(cfg.SOURCE_OPTIONS)
        | {k for keys in cfg.SOURCE_KEYS.values() for k in keys}
        | {"tilt", "spin", "offset", "bottom", "middle", "top"}
    )
    missing = sorted(k for k in keys if not re.search(rf"`{re.escape(k)}`", text))
    # the tables are documented under headings such as `[machine]` or `[axes.X]`
    missing += sorted(t for t in cfg.SECTIONS if not re.search(rf"`\[{t}[.\]]", text))
    assert missing == []


def test_documented_example_loads(tmp_path):
    """The complete example of docs/configuration.md is a valid configuration."""
    text = DOCS.read_text(encoding="utf-8")
    blocks = re.findall(r"```toml\n(.*?)```", text, flags=re.S)
    example = next(b for b in blocks if "[machine]" in b and "[tool]" in b)
    data = tomllib.loads(example)
    # the example names data files: give it inline values instead, keeping every other key
    for axis in data["axes"].values():
        for kind, entry in axis.get("errors", {}).items():
            if isinstance(entry, dict) and "file" not in entry:
                for about in entry:
                    entry[about] = {"constant": 1.0}
            else:
                axis["errors"][kind] = {"constant": 1.0}
    m = machine_from_dict(copy.deepcopy(data), tmp_path)
    assert m.name == data["machine"]["name"]
