"""Rotary tables: the table file (strict reading, one-line errors naming the key), curve
files (periodic interpolation, one-line errors naming file and line), the shipped
examples, and the numeric core's imports."""

from __future__ import annotations

import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from esp.config.curves import read_curve
from esp.config.devices import load_table, table_from_dict
from esp.core.devices import Curve, table_terms
from esp.core.errors import ConfigError, DataError, ParseError

ROTARY = Path(__file__).resolve().parent.parent / "data" / "examples" / "rotary"


@pytest.fixture
def folder(tmp_path):
    """A copy of the shipped chains and curve files, for table files made in the tests."""
    for f in ROTARY.iterdir():
        if f.suffix in (".toml", ".csv"):
            shutil.copy(f, tmp_path / f.name)
    return tmp_path


def _write(folder, text, name="table.toml"):
    path = folder / name
    path.write_text(text, encoding="utf-8")
    return path


def _error(exc_info):
    text = str(exc_info.value)
    assert "\n" not in text and "Traceback" not in text
    return text


# -- curves -------------------------------------------------------------------------------


def _curve(folder, text, **kw):
    path = _write(folder, text, "curve.csv")
    kw.setdefault("unit", "um")
    kw.setdefault("to_unit", "um")
    return read_curve(path, **kw)


def test_a_periodic_curve_wraps_over_the_seam(folder):
    c = _curve(folder, "# a comment\nangle_deg,EXC\n0,1\n90,3\n180,-1\n270,0\n")
    np.testing.assert_allclose(c.at([0, 45, 90, 180, 270]), [1, 2, 3, -1, 0])
    # between 270 and 360 (= 0): from 0 to 1
    np.testing.assert_allclose(c.at([315, -45, 675, 360, 720, -360]), [0.5, 0.5, 0.5, 1, 1, 1])
    assert c.source == "curve.csv:EXC"


def test_a_periodic_curve_may_start_anywhere_and_close_on_itself(folder):
    c = _curve(folder, "angle_deg,v\n-180,2\n-90,4\n0,6\n90,4\n180,2\n")
    assert c.range_deg == (-180.0, 90.0)  # 180 is -180, and holds the same value
    np.testing.assert_allclose(c.at([135, -135, 180, 540]), [3, 3, 2, 2])


def test_a_curve_that_does_not_close_is_refused(folder):
    with pytest.raises(ParseError, match=r"curve.csv:6: 360 deg is the setting 0 deg") as e:
        _curve(folder, "angle_deg,v\n0,2\n90,4\n180,6\n270,4\n360,2.5\n")
    _error(e)
    with pytest.raises(ParseError, match=r"curve.csv:4: a periodic curve spans at most one turn"):
        _curve(folder, "angle_deg,v\n0,2\n200,4\n400,6\n")


def test_a_curve_of_limited_travel(folder):
    c = _curve(folder, "angle_deg,v\n-120,0\n0,6\n120,12\n", periodic=False)
    np.testing.assert_allclose(c.at([-120, -60, 60, 120]), [0, 3, 9, 12])
    with pytest.raises(DataError, match=r"curve.csv:v: 121 deg is outside the curve's range"):
        c.at([0.0, 121.0])
    long = _curve(folder, "angle_deg,v\n0,0\n720,7.2\n", periodic=False)
    assert long.at(360.0) == pytest.approx(3.6)


def test_curve_units_scale_and_columns(folder):
    text = "angle_deg,EXC,ECC\n0,1,3600\n180,-1,-3600\n"
    c = _curve(folder, text, column="ECC", unit="arcsec", to_unit="urad", scale=-1)
    np.testing.assert_allclose(c.values, [-1e6 * np.pi / 180, 1e6 * np.pi / 180])
    assert _curve(folder, text, prefer="EXC").values.tolist() == [1.0, -1.0]
    assert _curve(folder, "angle_deg,only\n0,1\n10,2\n", prefer="EXC").values.tolist() == [1, 2]


@pytest.mark.parametrize(
    ("text", "kw", "match"),
    [
        ("", {}, r"curve.csv: expected a header 'angle_deg,...' and rows, found none"),
        ("angle,v\n0,1\n", {}, r"curve.csv:1: expected the first column 'angle_deg'"),
        ("angle_deg\n0\n", {}, r"curve.csv:1: expected at least one value column"),
        ("angle_deg,a,b\n0,1,2\n", {}, r"curve.csv:1: the file has 2 value columns \(a, b\)"),
        ("angle_deg,EXC\n0,1\n", {"column": "EXD"}, r"no column 'EXD'; did you mean 'EXC'\?"),
        ("angle_deg,v\n0,1\n10\n", {}, r"curve.csv:3: expected 2 columns, found 1"),
        ("angle_deg,v\n0,1\n10,x\n", {}, r"curve.csv:3: v: expected a number, found 'x'"),
        ("angle_deg,v\n0,1\n10,nan\n", {}, r"curve.csv:3: v: expected a finite number"),
        (
            "angle_deg,v\n0,1\n0,2\n",
            {},
            r"curve.csv:3: expected increasing angles, found 0 after 0",
        ),
        ("angle_deg,v\n0,1\n", {}, r"curve.csv: expected at least two rows of v, found 1"),
        ("angle_deg,v,v\n0,1,1\n", {}, r"curve.csv:1: column 'v' appears twice"),
    ],
)
def test_bad_curve_files(folder, text, kw, match):
    with pytest.raises(ParseError, match=match) as e:
        _curve(folder, text, **kw)
    _error(e)


def test_a_curve_in_memory_checks_itself():
    with pytest.raises(DataError, match="strictly increasing"):
        Curve(np.array([0.0, 0.0]), np.array([1.0, 2.0]), "um")
    with pytest.raises(DataError, match="less than one turn"):
        Curve(np.array([0.0, 360.0]), np.array([1.0, 1.0]), "um")


# -- the table file -----------------------------------------------------------------------

#: a table file up to its [table.errors]
HEAD = '[table]\nchain = "c-table.toml"\n[table.errors]\n'
CURVE = 'file = "trunnion-C-motions.csv"'

GOOD = """
[table]
name = "C table"
chain = "c-table.toml"
setup = { C = 0 }
[table.parameters]
x_C = 100
y_C = { value = 0.05, unit = "m" }
[table.errors]
X0C = 10
A0C = { value = 2, unit = "arcsec", scale = -1 }
ECC = { file = "trunnion-C-motions.csv", unit = "arcsec" }
EXC = { file = "trunnion-C-motions.csv", column = "EYC", scale = -1 }
"""


def test_a_table_file(folder):
    table = load_table(_write(folder, GOOD))
    assert table.name == "C table"
    assert table.coordinates == ("C",)
    assert table.parameters["y_C"] == pytest.approx(50.0)
    assert table.errors["X0C"] == 10.0
    assert table.errors["A0C"] == pytest.approx(-2 * np.pi / 180 / 3600 * 1e6)
    assert set(table.curves) == {"ECC", "EXC"} and table.curve_axes["ECC"] == "C"
    src = np.loadtxt(folder / "trunnion-C-motions.csv", delimiter=",", skiprows=3)
    np.testing.assert_allclose(table.curves["EXC"].values, -src[:, 2])
    np.testing.assert_allclose(table.curves["ECC"].values, src[:, 6] * np.pi / 0.648)
    assert dict(table.setup_deg) == {"C": 0.0}
    assert table.origins["ECC"] == "trunnion-C-motions.csv:ECC"
    assert table.origins["X0C"] == "table.toml"
    assert any(i.endswith("trunnion-C-motions.csv") for i in table.inputs)
    out = table_terms(table, {"C": [0.0]})
    np.testing.assert_allclose(out.error_um([1.0, 2.0, 3.0]), [[0.0, 0.0, 0.0]], atol=1e-12)


def test_errors_from_a_file_and_precedence(folder):
    (folder / "identified.csv").write_text("error,value,unit\nX0C,4,um\nY0C,0.002,mm\n")
    text = (
        '[table]\nchain = "c-table.toml"\nerrors_from = "identified.csv"\n[table.errors]\nX0C = 7\n'
    )
    table = load_table(_write(folder, text))
    assert table.errors["X0C"] == 7.0 and table.errors["Y0C"] == pytest.approx(2.0)
    assert table.origins["Y0C"] == "identified.csv"
    again = table.with_values({"X0C": 1.0, "ECC": 2.0})
    assert again.errors["X0C"] == 1.0 and again.origins["X0C"] == "--set"


def test_a_chain_file_is_a_table_with_its_defaults():
    table = load_table(ROTARY / "trunnion-ac.toml")
    assert table.coordinates == ("C", "A")
    assert all(v == 0.0 for v in table.errors.values())
    assert table.setup_deg is None


def test_table_from_dict_with_a_prefix_and_keys_of_the_caller(folder):
    raw = {"chain": "c-table.toml", "angles": {"C": [0, 90]}, "errors": {"X0C": 1}}
    table = table_from_dict(
        raw, base_dir=folder, source="machine.toml", prefix="table", allow=("angles",)
    )
    assert table.errors["X0C"] == 1.0
    with pytest.raises(ConfigError) as e:
        table_from_dict({"chain": "c-table.toml", "angels": {}}, base_dir=folder, allow=("angles",))
    assert str(e.value).startswith("table.angels: unknown key 'angels'; did you mean 'angles'?")


@pytest.mark.parametrize(
    ("text", "message"),
    [
        (
            '[table]\nchian = "c-table.toml"\n',
            "table.chian: unknown key 'chian'; did you mean 'chain'?",
        ),
        ("[table]\nname = 'x'\n", "table.chain: required key is missing: the table's chain file"),
        ('[table]\nchain = "nope.toml"\n', "table.chain: "),
        (
            '[table]\nchain = "c-table.toml"\n[tabel]\n',
            "tabel: unknown table 'tabel'; did you mean 'table'?",
        ),
        ('[head]\nchain = "c-table.toml"\n', "table: required table is missing"),
        ("[table\n", "<toml>: invalid TOML at line 1"),
        (
            HEAD + "X0D = 1\n",
            "table.errors.X0D: not an error of the chain; did you mean 'X0C'?",
        ),
        (
            HEAD + "x_C = 1\n",
            "table.errors.x_C: x_C is a parameter of the chain, not an error; "
            "give it in [table.parameters]",
        ),
        (
            '[table]\nchain = "c-table.toml"\n[table.parameters]\nC = 1\n',
            "table.parameters.C: C is a coordinate of the chain, not a parameter",
        ),
        (
            HEAD + 'X0C = "ten"\n',
            "table.errors.X0C: expected a number, found 'ten'",
        ),
        (
            HEAD + 'X0C = { value = 1, unit = "deg" }\n',
            "table.errors.X0C.unit: 'deg' is a unit of angle, but X0C is a length (its unit is um)",
        ),
        (
            HEAD + 'X0C = { value = 1, unit = "furlong" }\n',
            "table.errors.X0C.unit: unknown unit 'furlong'",
        ),
        (
            HEAD + "X0C = { value = 1, scale = 0 }\n",
            "table.errors.X0C.scale: expected a non-zero factor",
        ),
        (
            HEAD + "X0C = { valu = 1 }\n",
            "table.errors.X0C.valu: unknown key 'valu'; did you mean 'value'?",
        ),
        (
            HEAD + 'X0C = { value = 1, column = "a" }\n',
            "table.errors.X0C.column: 'column' belongs to a curve: give file = ... too",
        ),
        (
            HEAD + "X0C = { " + CURVE + " }\n",
            "table.errors.X0C.file: X0C is not in the error motion of one rotary joint",
        ),
        (
            HEAD + "EXC = { " + CURVE + ", periodic = 1 }\n",
            "table.errors.EXC.periodic: expected true or false, found 1",
        ),
        (
            HEAD + "EXC = { " + CURVE + ', unit = "deg" }\n',
            "table.errors.EXC.unit: 'deg' is a unit of angle, but the error is a length",
        ),
        (
            HEAD + "EXC = { " + CURVE + ", scale = 0 }\n",
            "table.errors.EXC.scale: expected a non-zero factor",
        ),
        (
            HEAD + "EXC = { " + CURVE + ", unit = 5 }\n",
            "table.errors.EXC.unit: unknown unit 5",
        ),
        (
            HEAD + "EXC = { " + CURVE + ', colum = "EYC" }\n',
            "table.errors.EXC.colum: unknown key 'colum'; did you mean 'column'?",
        ),
        (
            '[table]\nchain = "c-table.toml"\n[table.parameters]\nx_C = { file = "a.csv" }\n',
            "table.parameters.x_C.file: a parameter is a number, not a curve from a file",
        ),
        (
            '[table]\nchain = "c-table.toml"\nsetup = { A = 0 }\n',
            "table.setup.A: not an axis of the table (C)",
        ),
        (
            '[table]\nchain = "c-table.toml"\nsetup = 0\n',
            "table.setup: expected the set-up setting",
        ),
        (
            '[table]\nchain = "trunnion-ac.toml"\nsetup = { C = 0 }\n',
            "table.setup.A: missing: give the set-up angle of every axis (C, A)",
        ),
        (
            '[table]\nchain = "c-table.toml"\nerrors_from = [1]\n',
            "table.errors_from: expected a file name or a list of file names",
        ),
        ('[table]\nchain = "table.toml"\n', "table.chain: names this file itself"),
    ],
)
@pytest.mark.slow
def test_bad_table_files(folder, text, message):
    path = _write(folder, text)
    with pytest.raises(ConfigError) as e:
        load_table(path)
    assert _error(e).startswith(f"{path}: {message}")


def test_curve_and_value_files_name_their_file_and_line(folder):
    (folder / "bad.csv").write_text("angle_deg,EXC\n0,1\n90,oops\n")
    path = _write(folder, HEAD + 'EXC = { file = "bad.csv" }\n')
    with pytest.raises(ParseError, match=r"bad.csv:3: EXC: expected a number, found 'oops'") as e:
        load_table(path)
    _error(e)
    path = _write(folder, HEAD + 'EXC = { file = "none.csv" }\n')
    with pytest.raises(ParseError, match=r"none.csv: expected a curve file, found no such file"):
        load_table(path)
    (folder / "values.csv").write_text("error,value\nX0Z,1\n")
    path = _write(folder, '[table]\nchain = "c-table.toml"\nerrors_from = ["values.csv"]\n')
    with pytest.raises(ParseError, match=r"values.csv:2: 'X0Z' is not a small error"):
        load_table(path)


def test_chains_that_are_not_tables(folder):
    chain = (folder / "c-table.toml").read_text().replace('revolute = "z"', 'prismatic = "z"')
    (folder / "linear.toml").write_text(chain.replace('unit = "deg"', 'unit = "mm"'))
    path = _write(folder, '[table]\nchain = "linear.toml"\n')
    with pytest.raises(ConfigError, match=r"table.chain: linear.toml: steps\[2\] is a prismatic"):
        load_table(path)
    (folder / "fixed.toml").write_text("[[steps]]\ntranslate = [0, 0, 1]\n")
    path = _write(folder, '[table]\nchain = "fixed.toml"\n')
    with pytest.raises(ConfigError, match=r"the chain has no coordinate \(no revolute joint\)"):
        load_table(path)


def test_bad_angles(folder):
    table = load_table(ROTARY / "trunnion-ac.toml")
    cases = [
        ({"C": [0.0]}, "angles.A: missing: give every axis of the table (C, A)"),
        ({"C": 0, "A": 0, "B": 0}, "angles.B: not an axis of the table (C, A)"),
        ({"C": [0, 1], "A": [0, 1, 2]}, "angles.A: 3 values, but the others have 2"),
        ({"C": np.nan, "A": 0}, "angles.C: expected finite angles"),
        ({"C": "0", "A": 0}, "angles.C: expected numbers, found '0'"),
        ({"C": [[0.0]], "A": 0}, "angles.C: expected a number or a 1-D array"),
    ]
    for angles, message in cases:
        with pytest.raises(ConfigError) as e:
            table_terms(table, angles)
        assert message in _error(e)


# -- the shipped examples -----------------------------------------------------------------


def test_the_example_curve_files_are_what_the_script_writes(tmp_path):
    subprocess.run([sys.executable, str(ROTARY / "make_data.py"), str(tmp_path)], check=True)
    for name in ("trunnion-C-motions.csv", "trunnion-A-motions.csv"):
        assert (tmp_path / name).read_bytes() == (ROTARY / name).read_bytes()


def test_the_trunnion_example_loads_and_stays_within_its_size():
    table = load_table(ROTARY / "trunnion.toml")
    assert table.coordinates == ("C", "A")
    assert set(table.curves) == {
        "EXC",
        "EYC",
        "EZC",
        "EAC",
        "EBC",
        "ECC",
        "EYA",
        "EZA",
        "EBA",
        "ECA",
        "EAA",
    }
    assert not table.curves["EAA"].periodic and table.curves["ECC"].periodic
    A, C = np.meshgrid(np.arange(-120.0, 121.0, 30.0), np.arange(0.0, 360.0, 45.0))
    out = table_terms(table, {"A": A.ravel(), "C": C.ravel()})
    # a tool tip 50 mm above the table centre: tens of µm, not millimetres
    err = np.linalg.norm(out.error_um([300.0, 0.0, 50.0]), axis=1)
    assert 5.0 < err.max() < 100.0


@pytest.mark.slow
def test_the_core_imports_only_numpy():
    code = (
        "import sys, esp.core.devices\n"
        "bad = sorted(m for m in ('matplotlib', 'pandas', 'click', 'sympy', 'scipy') "
        "if m in sys.modules)\n"
        "print(','.join(bad))\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == ""


def test_the_docstring_examples_run():
    import doctest

    import esp.core.devices.table_effects

    result = doctest.testmod(
        esp.core.devices.table_effects, optionflags=doctest.NORMALIZE_WHITESPACE
    )
    assert result.attempted > 0 and result.failed == 0


def test_with_values_and_with_setup_refuse_what_does_not_fit():
    table = load_table(ROTARY / "trunnion-ac.toml")
    with pytest.raises(ConfigError, match=r"^--set X0D: not a parameter or error of the chain; "):
        table.with_values({"X0D": 1.0})
    with pytest.raises(ConfigError, match=r"^--set C: C is an axis of the table"):
        table.with_values({"C": 1.0})
    with pytest.raises(ConfigError, match=r"^--set X0C: expected a finite number"):
        table.with_values({"X0C": float("inf")})
    with pytest.raises(ConfigError, match=r"^setup.A: missing"):
        table.with_setup({"C": 0.0})
    assert dict(table.with_setup({"C": 0, "A": 90}).setup_deg) == {"C": 0.0, "A": 90.0}
    assert table.with_setup({"C": 0, "A": 90}).with_setup(None).setup_deg is None
    out = table_terms(table.with_values({"X0C": 1.0}), {"A": [0.0], "C": [0.0]})
    with pytest.raises(ValueError, match="expected p of shape"):
        out.error_um([1.0, 2.0])
    with pytest.raises(ValueError, match="finite"):
        out.error_um([1.0, np.nan, 2.0])
