"""Building and reading chains: kinds, units, strict files, one-line errors with dotted keys,
values at the boundary."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

import esp.core.kinematics as K
from esp.config.chain import load_chain
from esp.core.errors import ConfigError, DataError

ROOT = Path(__file__).resolve().parent.parent
# the chain files (the heads folder also holds head files, which name a chain)
SHIPPED = sorted((ROOT / "data/examples/chains").glob("*.toml")) + sorted(
    p
    for p in (ROOT / "data/examples/heads").glob("*.toml")
    if "[[steps]]" in p.read_text(encoding="utf-8")
)


def cartesian():
    """A gantry built in code: X carries Y carries Z, with error motions and pivots."""
    steps = []
    for axis, pivot in (("X", (0, "Y_off", 0)), ("Y", (0, 0, 0)), ("Z", (0, 0, 0))):
        errors = {s: f"{s}_{axis}" for s in ("tx", "ty", "tz", "rx", "ry", "rz")}
        steps.append(K.prismatic(axis.lower(), axis, errors, pivot))
    steps.append(K.translate("Px", "Py", "Pz"))
    params = {n: {"kind": "parameter", "value": 0.0} for n in ("Px", "Py", "Pz", "Y_off")}
    return K.Chain(steps, params, name="gantry")


def test_kinds_and_units_inferred_from_use():
    chain = cartesian()
    assert chain.coordinates == ("X", "Y", "Z")
    assert set(chain.parameters) == {"Px", "Py", "Pz", "Y_off"}
    assert len(chain.errors) == 18
    assert chain.symbols["X"].unit == "mm"
    assert chain.symbols["tx_X"].unit == "um"
    assert chain.symbols["rz_Z"].unit == "urad"
    assert chain.joint_errors()["Y"] == tuple(
        f"{s}_Y" for s in ("tx", "ty", "tz", "rx", "ry", "rz")
    )
    gantry = load_chain(ROOT / "data/examples/chains/gantry-wBMTt.toml")
    # squareness S_XY sits in Y's error motion with Y and Y_off, which are not errors
    assert gantry.joint_errors()["Y"] == ("EXY", "S_XY", "EYY", "EZY", "EAY", "EBY", "ECY")
    head = K.Chain(
        [K.revolute("z", "C"), K.translate(0, "-e", "-e/tan(Yp)"), K.rotate("-x", "Yp")],
        {"e": "parameter", "Yp": "parameter"},
    )
    assert head.symbols["C"].unit == "deg"
    assert head.symbols["Yp"].unit == "deg"  # inside tan() and as a rotation angle
    assert head.symbols["e"].unit == "mm"


@pytest.mark.parametrize(
    "build, key, words",
    [
        (lambda: K.Chain([]), "steps", "empty chain"),
        (lambda: K.Chain([K.translate(0, 0, "G")]), "steps[1].translate.z", "unknown symbol 'G'"),
        (
            lambda: K.Chain([K.translate(0, 0, "Gg")], {"G": "parameter"}),
            "steps[1].translate.z",
            "did you mean 'G'",
        ),
        (lambda: K.Chain([K.prismatic("x", "")]), "steps[1].coordinate", "needs the coordinate"),
        (
            lambda: K.Chain([K.prismatic("x", "G")], {"G": "parameter"}),
            "steps[1].coordinate",
            "declared a parameter",
        ),
        (
            lambda: K.Chain([K.prismatic("x", "q"), K.revolute("z", "q")]),
            "steps[2].coordinate",
            "as an angle here but as a length",
        ),
        (
            lambda: K.Chain([K.error_motion(tx="G")], {"G": {"kind": "parameter", "value": 1}}),
            "steps[1].errors.tx",
            "used as an error",
        ),
        (
            lambda: K.Chain([K.error_motion(tx="d + G")], {"G": "parameter", "d": "error"}),
            "steps[1].errors.tx",
            "must vanish",
        ),
        (
            lambda: K.Chain([K.error_motion(tx="G*H")], {"G": "parameter", "H": "parameter"}),
            "steps[1].errors.tx",
            "holds no small error",
        ),
        (
            lambda: K.Chain([K.error_motion(tx="d", pivot=(0, "d", 0))], {"d": "error"}),
            "steps[1].pivot.y",
            "small error",
        ),
        (
            lambda: K.Chain([K.rotate("x", "Yp")], {"Yp": {"kind": "parameter", "unit": "mm"}}),
            "symbols.Yp.unit",
            "unit of length",
        ),
        (
            lambda: K.Chain([K.translate(0, 0, "G*H")], {"G": "parameter", "H": "parameter"}),
            "symbols.G.unit",
            "cannot tell",
        ),
        (lambda: K.Chain([K.rotate("x", 90)]), "steps[1].angle", "deg(90)"),
        (lambda: K.rotate("w", "Yp"), "rotate", "expected an axis"),
        (lambda: K.Chain([K.translate(0, 0, "G")], {"G": "paramter"}), "symbols.G", "did you mean"),
        (
            lambda: K.Chain([K.translate(0, 0, "G")], {"G": {"kind": "parameter", "unt": "mm"}}),
            "symbols.G.unt",
            "did you mean 'unit'",
        ),
        (
            lambda: K.Chain([K.translate(0, 0, "G")], {"G": {"kind": "parameter", "value": "x"}}),
            "symbols.G.value",
            "expected a number",
        ),
        (
            lambda: K.Chain([K.prismatic("x", "X")], {"X": {"kind": "coordinate", "value": 3}}),
            "symbols.X.value",
            "no default value",
        ),
        (
            lambda: K.Chain(
                [K.translate(0, 0, "a")], {"G": "parameter"}, definitions={"a": "b", "b": "a + G"}
            ),
            "definitions.a",
            "cyclic definition: a -> b -> a",
        ),
        (lambda: K.Chain("translate"), "steps", "expected a sequence of steps"),
        (lambda: K.Chain(["translate"]), "steps[1]", "expected a chain step"),
        (lambda: K.Chain([{"translate": [0, 0, 0]}]), "steps[1]", "expected a chain step"),
    ],
)
def test_bad_chains(build, key, words):
    with pytest.raises(ConfigError) as info:
        build()
    assert info.value.key == key
    assert words in str(info.value)
    assert "\n" not in str(info.value)


def test_definitions_are_substituted():
    chain = K.Chain(
        [K.translate(0, 0, "h")],
        {"e": {"kind": "parameter", "value": 10}, "Yp": {"kind": "parameter", "value": 50}},
        definitions={"h": "-e/t", "t": "tan(Yp)"},
    )
    z = K.position(chain)[0, 2]
    assert z == pytest.approx(-10 / math.tan(math.radians(50)), rel=1e-15)
    assert chain.definitions["h"] == "-e/tan(Yp)"


def test_environment_converts_units_and_checks_values():
    chain = K.Chain(
        [K.revolute("z", "C"), K.translate("L", 0, 0), K.error_motion(rz="th")],
        {"L": {"kind": "parameter", "value": 100}, "th": {"kind": "error", "unit": "arcsec"}},
    )
    env, n = chain.environment({"C": [0, 90, 180]}, {"L": 50}, {"th": 1.0})
    assert n == 3
    np.testing.assert_allclose(env["C"], [0, math.pi / 2, math.pi])
    assert env["L"] == 50.0
    assert env["th"] == pytest.approx(math.pi / 648000)
    p = K.position(chain, {"C": [0, 90, 180]})
    np.testing.assert_allclose(p, [[100, 0, 0], [0, 100, 0], [-100, 0, 0]], atol=1e-12)
    bad = [
        (({}, None), "coordinates.C", "missing"),
        (({"C": "x"}, None), "coordinates.C", "expected a number"),
        (({"C": [1.0, np.nan]}, None), "coordinates.C", "finite"),
        (({"C": 1, "L": 3}, None), "coordinates.L", "'L' is a parameter"),
        (({"C": 1}, {"Lx": 3}), "parameters.Lx", "did you mean 'L'"),
        (({"C": 1}, {"L": "abc"}), "parameters.L", "expected a number"),
        (
            ({"C": 1}, {"L": 1e12}),
            "parameters.L",
            "expected a value within ±1e+09 mm, found 1e12",
        ),
        (({"C": [1, 2]}, {"L": [1, 2, 3]}), "parameters.L", "3 values, but coordinates.C has 2"),
        (({"C": [[1, 2]]}, None), "coordinates.C", "1-D"),
    ]
    for (coords, params), key, words in bad:
        with pytest.raises(ConfigError) as info:
            K.position(chain, coords, params)
        assert info.value.key == key and words in str(info.value), (key, str(info.value))


def test_parameter_without_value_at_evaluation():
    chain = K.Chain([K.translate(0, 0, "G")], {"G": "parameter"})
    with pytest.raises(ConfigError, match=r"parameters\.G: no value"):
        K.position(chain)
    assert K.position(chain, parameters={"G": 3})[0, 2] == 3.0


def test_non_finite_quantity_is_a_data_error():
    chain = K.Chain([K.translate(0, 0, "1/tan(Yp)")], {"Yp": {"kind": "parameter", "unit": "deg"}})
    with pytest.raises(DataError, match=r"steps\[1\]\.translate\.z: '1/tan\(Yp\)' is not finite"):
        K.position(chain, parameters={"Yp": 0})
    with pytest.raises(DataError):
        K.sensitivities(chain, parameters={"Yp": 0})


# -- chain files ----------------------------------------------------------------------------


@pytest.mark.parametrize("path", SHIPPED, ids=lambda p: p.name)
def test_shipped_chain_files_load(path):
    chain = load_chain(path)
    assert chain.steps and chain.name
    assert chain.errors  # every example carries error motions
    for sym in chain.symbols.values():
        assert sym.description, sym.name  # every symbol says what it is


def write(tmp_path, text, name="c.toml"):
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


@pytest.mark.parametrize(
    "text, key, words",
    [
        ("[chain]\nname = 'x'\n", "steps", "empty chain"),
        ("steps = []\n", "steps", "empty chain"),
        ("[chian]\n", "chian", "did you mean 'chain'"),
        ("[chain]\nnmae = 'a'\n[[steps]]\ntranslate = [0,0,0]\n", "chain.nmae", "'name'"),
        ("[[steps]]\ntranslat = [0, 0, 1]\n", "steps[1]", "did you mean 'translate'"),
        ("[[steps]]\nrotate = 'x'\nangel = 'a'\n", "steps[1].angel", "did you mean 'angle'"),
        ("[[steps]]\nrotate = 'w'\nangle = 'deg(3)'\n", "steps[1].rotate", "expected an axis"),
        ("[[steps]]\nrotate = 'x'\n", "steps[1].angle", "needs its angle"),
        ("[[steps]]\nprismatic = 'x'\n", "steps[1].coordinate", "needs the coordinate"),
        ("[[steps]]\nprismatic = 'x'\ncoordinate = 'X'\n", "steps[1].coordinate", "declare it"),
        (
            "[symbols]\nG = 'parameter'\n[[steps]]\ntranslate = [0, 0, 'G']\n[[steps]]\n"
            "translate = [0, 0, 'H']\n",
            "steps[2].translate.z",
            "unknown symbol 'H'",
        ),
        (
            "[symbols]\nd = 'error'\n[[steps]]\nerrors = { tx = 'd' }\npivot = [0, 0]\n",
            "steps[1].pivot",
            "expected [x, y, z]",
        ),
        (
            "[symbols]\nd = 'error'\n[[steps]]\nerrors = { rzz = 'd' }\n",
            "steps[1].errors.rzz",
            "did you mean 'rz'",
        ),
        ("[[steps]]\ntranslate = [0, 0]\n", "steps[1].translate", "expected [x, y, z]"),
        ("[[steps]]\ntranslate = [0, 0, 1]\nrotate = 'x'\n", "steps[1]", "one transform"),
        ("[[steps]]\ntranslate = [0, 0, 1]\npivot = [0, 0, 0]\n", "steps[1].pivot", "unknown key"),
        ("[[steps]]\nprismatic = 'x'\ncoordinate = 3\n", "steps[1].coordinate", "symbol name"),
        ("[symbols\n", "<toml>", "invalid TOML at line 1"),
    ],
)
def test_bad_chain_files(tmp_path, text, key, words):
    path = write(tmp_path, text)
    with pytest.raises(ConfigError) as info:
        load_chain(path)
    assert info.value.key == key, str(info.value)
    assert words in str(info.value)
    assert str(info.value).startswith(str(path))
    assert "\n" not in str(info.value)


def test_missing_and_binary_files(tmp_path):
    with pytest.raises(ConfigError, match="no such chain file"):
        load_chain(tmp_path / "absent.toml")
    with pytest.raises(ConfigError, match="is a folder"):
        load_chain(tmp_path)
    path = tmp_path / "bin.toml"
    path.write_bytes(b"\xff\xfe\x00")
    with pytest.raises(ConfigError, match="UTF-8"):
        load_chain(path)


def test_file_and_code_give_the_same_chain(tmp_path):
    path = write(
        tmp_path,
        """
[chain]
name = "two axes"
[symbols]
X = "coordinate"
C = "coordinate"
L = { kind = "parameter", unit = "mm", value = 120 }
exx = { kind = "error", unit = "um" }
ecx = { kind = "error", unit = "urad" }
ebc = { kind = "error", unit = "arcsec" }
[[steps]]
prismatic = "x"
coordinate = "X"
errors = { tx = "exx", rz = "ecx" }
pivot = [0, "L", 0]
[[steps]]
revolute = "z"
coordinate = "C"
errors = { ry = "ebc" }
[[steps]]
translate = { y = "L" }
""",
    )
    from_file = load_chain(path)
    in_code = K.Chain(
        [
            K.prismatic("x", "X", {"tx": "exx", "rz": "ecx"}, (0, "L", 0)),
            K.revolute("z", "C", {"ry": "ebc"}),
            K.translate(0, "L", 0),
        ],
        {"L": {"kind": "parameter", "value": 120}, "ebc": {"kind": "error", "unit": "arcsec"}},
    )
    at = {"X": np.array([0.0, 250.0]), "C": np.array([30.0, -75.0])}
    errors = {"exx": 3.0, "ecx": 40.0, "ebc": 12.0}
    np.testing.assert_array_equal(
        K.position(from_file, at, errors=errors), K.position(in_code, at, errors=errors)
    )
    assert from_file.symbols["ebc"].unit == in_code.symbols["ebc"].unit == "arcsec"
    assert from_file.name == "two axes"


def test_the_format_example_of_the_docs_is_a_valid_chain(tmp_path):
    text = (ROOT / "docs/kinematics.md").read_text(encoding="utf-8")
    block = text.split("```toml\n", 1)[1].split("```", 1)[0]
    chain = load_chain(write(tmp_path, block))
    assert chain.coordinates == ("A",)
    assert chain.symbols["e"].unit == "mm" and chain.symbols["Yp"].unit == "deg"
    assert chain.symbols["Oas"].unit == "um"
    p = K.position(chain, {"A": 0.0})[0]
    y, z = -10 - 20 * math.sin(math.radians(50)), -10 / math.tan(math.radians(50))
    np.testing.assert_allclose(p, [0, y, z - 20 * math.cos(math.radians(50))], atol=1e-12)
