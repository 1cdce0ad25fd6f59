"""``esp derive``: formulae, numbers, JSON, one-line errors, and no sympy where it is not
needed."""

from __future__ import annotations

import json
import re
import shlex
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

import esp.core.kinematics as K
from esp.cli import main
from esp.config.chain import load_chain

ROOT = Path(__file__).resolve().parent.parent
LOH = ROOT / "data/examples/chains/loh-2004-scmm.toml"
HEAD = ROOT / "data/examples/heads/angle-head.toml"
GANTRY = ROOT / "data/examples/chains/gantry-wBMTt.toml"


def run(*args):
    return CliRunner().invoke(main, ["derive", *map(str, args)])


@pytest.mark.slow
def test_formulae_of_loh_scmm():
    res = run(LOH)
    assert res.exit_code == 0, res.output
    out = res.output
    assert "X = a_P + a_Y + a_Z + x" in out
    # one error's term per line, signs aligned
    assert re.search(r"^  DX = \+ dx_Y$", out, flags=re.M)
    assert re.search(r"^       \+ ey_Y\*\(c_P \+ c_X \+ c_Z \+ z\)$", out, flags=re.M)
    assert re.search(r"^       - ez_Y\*\(b_P \+ b_Z\)$", out, flags=re.M)
    assert "Second order" not in out


SHIPPED = sorted((ROOT / "data/examples/chains").glob("*.toml")) + [HEAD]


@pytest.mark.slow
@pytest.mark.parametrize("path", SHIPPED, ids=lambda p: p.name)
def test_every_shipped_chain_derives(path):
    sp = pytest.importorskip("sympy")
    res = run(path, "--json", "-")
    assert res.exit_code == 0, res.output
    doc = json.loads(res.output)
    for part in ("nominal", "first_order"):
        for axis in "XYZ":
            assert str(sp.sympify(doc[part][axis])) == doc[part][axis]


@pytest.mark.slow
def test_json_formulae_read_back_with_sympify(tmp_path):
    sp = pytest.importorskip("sympy")
    target = tmp_path / "f.json"
    res = run(HEAD, "--order", "2", "--json", target)
    assert res.exit_code == 0, res.output
    doc = json.loads(target.read_text(encoding="utf-8"))
    assert doc["schema"] == "esp.derive/1"
    assert set(doc) >= {"schema", "nominal", "first_order", "second_order", "symbols"}
    assert doc["symbols"]["A"] == {"kind": "coordinate", "unit": "deg"}
    assert doc["symbols"]["G"]["kind"] == "parameter"
    assert doc["symbols"]["ThetaAs"] == {"kind": "error", "unit": "arcsec"}
    derivation = K.derive(load_chain(HEAD), order=2)
    for part in ("nominal", "first_order", "second_order"):
        for axis in "XYZ":
            assert sp.sympify(doc[part][axis]) == getattr(derivation, part)[axis]
    # the text on the terminal holds the same formulae
    assert f"X = {doc['nominal']['X']}" in res.output
    # standard output
    res = run(HEAD, "--json", "-")
    assert res.exit_code == 0
    doc = json.loads(res.output)
    assert "second_order" not in doc and doc["order"] == 1


def test_numeric_evaluation_of_the_angle_head():
    res = run(HEAD, "--at", "A=30,C=40", "--set", "G=20,e=10,Yp=50", "--order", "2", "--json", "-")
    assert res.exit_code == 0, res.output
    doc = json.loads(res.output)
    assert doc["schema"] == "esp.derive/1"
    assert doc["units"]["nominal"] == "mm" and doc["units"]["first_order"] == "um"
    chain = load_chain(HEAD)
    p = K.position(chain, {"A": 30, "C": 40}, {"G": 20, "e": 10, "Yp": 50})[0]
    np.testing.assert_allclose([doc["nominal"][a] for a in "XYZ"], p, atol=1e-6)
    # the file's Fig. 3 error values: the terms add up to the first order, which is close
    # to the exact error; the second order closes most of the gap
    first = np.array([doc["first_order"][a] for a in "XYZ"])
    terms = np.array([[t[a] for a in "XYZ"] for t in doc["terms"]])
    np.testing.assert_allclose(terms.sum(axis=0), first, atol=1e-5)
    exact = np.array([doc["exact"][a] for a in "XYZ"])
    second = np.array([doc["second_order"][a] for a in "XYZ"])
    assert np.abs(exact - first).max() < 0.05  # µm, against errors of tens of µm
    assert np.abs(exact - first - second).max() < 1e-4
    assert {t["error"] for t in doc["terms"]} == {"ThetaAs", "Ocx", "Ocy", "ThetaCh", "ThetaCv"}
    # --set overrides an error value of the file
    res = run(HEAD, "--at", "A=0,C=0", "--set", "ThetaAs=0,Ocx=0,Ocy=0,ThetaCh=0,ThetaCv=0")
    assert res.exit_code == 0
    assert "errors: all zero" in res.output
    assert re.search(r"first order \(um\)\s+0\.000000\s+0\.000000\s+0\.000000", res.output)


@pytest.mark.parametrize("name", ["gantry-wBMTt", "moving-table-BwMTt"])
def test_table_axis_angle_with_a_tool_offset(name):
    """EBX (X about +Y) of 100 µrad with a 100 mm tool offset along X moves the tool by
    −EBX·tool_x = −10 µm in Z, on the gantry and on the moving table alike (a rigid body
    does not care which side of the chain moves)."""
    path = ROOT / f"data/examples/chains/{name}.toml"
    res = run(path, "--at", "X=500,Y=500,Z=0", "--set", "EBX=100,tool_x=100", "--json", "-")
    assert res.exit_code == 0, res.output
    doc = json.loads(res.output)
    assert doc["first_order"]["Z"] == pytest.approx(-10.0)
    assert doc["first_order"]["X"] == pytest.approx(0.0)
    assert doc["exact"]["Z"] == pytest.approx(-10.0, abs=1e-5)


BAD = {
    "unknown-symbol": (
        "[symbols]\nG = 'parameter'\n[[steps]]\ntranslate = [0, 0, 'Gg']\n",
        "steps[1].translate.z: unknown symbol 'Gg'; did you mean 'G'?",
    ),
    "joint-without-coordinate": ("[[steps]]\nprismatic = 'x'\n", "steps[1].coordinate"),
    "two-kinds": (
        "[symbols]\nG = { kind = 'parameter', value = 1 }\n[[steps]]\nprismatic = 'x'\n"
        "coordinate = 'G'\n",
        "declared a parameter",
    ),
    "empty": ("[chain]\nname = 'nothing'\n", "steps: empty chain"),
    "unknown-axis": (
        "[symbols]\nY = 'parameter'\n[[steps]]\nrotate = 'w'\nangle = 'Y'\n",
        "steps[1].rotate: expected an axis",
    ),
    "cyclic": (
        "[symbols]\nG = { kind = 'parameter', value = 1 }\n[definitions]\na = 'b + G'\n"
        "b = '2*a'\n[[steps]]\ntranslate = [0, 0, 'a']\n",
        "definitions.a: cyclic definition",
    ),
    "unknown-key": ("[[steps]]\ntranslat = [0, 0, 1]\n", "did you mean 'translate'"),
    "bad-toml": ("[symbols\n", "invalid TOML at line 1"),
    "forbidden-expression": (
        "[symbols]\nG = { kind = 'parameter', value = 1 }\n[[steps]]\n"
        "translate = [0, 0, \"__import__('os')\"]\n",
        "unknown function '__import__'",
    ),
}


@pytest.mark.parametrize("name", sorted(BAD))
def test_bad_chains_are_one_line_errors(tmp_path, name):
    text, words = BAD[name]
    path = tmp_path / f"{name}.toml"
    path.write_text(text, encoding="utf-8")
    res = run(path)
    assert res.exit_code == 2, res.output
    lines = res.output.strip().splitlines()
    assert len(lines) == 1, res.output
    assert lines[0].startswith(f"esp: error: {path}: ")
    assert words in lines[0]
    assert "Traceback" not in res.output


PARAM_CHAIN = (
    "[symbols]\nX = 'coordinate'\nG = { kind = 'parameter', unit = 'mm' }\n"
    "d = { kind = 'error', unit = 'um' }\n[[steps]]\nprismatic = 'x'\ncoordinate = 'X'\n"
    "errors = { tx = 'd' }\n[[steps]]\ntranslate = [0, 0, 'G']\n"
)


@pytest.mark.parametrize(
    "args, words",
    [
        (["--at", "X=1"], "parameters.G: no value"),
        (
            ["--at", "X=1", "--set", "G=abc"],
            "--set: G: expected a number, found 'abc' (write decimal digits: 1000, 2.5, 1e3)",
        ),
        (["--at", "X=1", "--set", "G=nan"], "expected a finite number"),
        (["--at", "X=1", "--set", "Gg=1"], "did you mean 'G'"),
        (["--at", "X=1", "--set", "X=1"], "X is a coordinate; give it with --at"),
        (["--at", "Q=1"], "Q is not one of the chain's coordinates"),
        (["--at", "X"], "expected NAME=value pairs"),
        (["--at", "X=1,X=2"], "X is given twice"),
        (["--at", ""], "missing X"),
        (["--set", "G=1"], "give the coordinates with --at"),
        (["--order", "3"], "'--order'"),
        (["--at", "X=1e12", "--set", "G=1"], "expected a position within ±100000 mm, found 1e12"),
    ],
)
def test_bad_options_are_one_line_errors(tmp_path, args, words):
    path = tmp_path / "c.toml"
    path.write_text(PARAM_CHAIN, encoding="utf-8")
    res = run(path, *args)
    assert res.exit_code == 2, res.output
    assert len(res.output.strip().splitlines()) == 1, res.output
    assert res.output.startswith("esp: error: ")
    assert words in res.output, res.output


def test_non_finite_quantity_at_evaluation(tmp_path):
    path = tmp_path / "c.toml"
    path.write_text(
        "[symbols]\nYp = { kind = 'parameter', unit = 'deg', value = 50 }\n[[steps]]\n"
        "translate = [0, 0, '1/tan(Yp)']\n",
        encoding="utf-8",
    )
    res = run(path, "--set", "Yp=0")
    assert res.exit_code == 2
    assert res.output.strip() == (
        f"esp: error: {path}: steps[1].translate.z: '1/tan(Yp)' is not finite at the given "
        "values (a division by zero, or tan of a right angle)"
    )
    doc = json.loads(run(path, "--set", "Yp=45", "--json", "-").output)
    doc.pop("provenance")  # its name holds "nan"
    assert "nan" not in json.dumps(doc).lower()


def test_json_target_checked_before_work_and_never_the_input(tmp_path):
    chain = tmp_path / "c.toml"
    chain.write_text(LOH.read_text(encoding="utf-8"), encoding="utf-8")
    res = run(chain, "--json", chain)
    assert res.exit_code == 2 and "inputs" in res.output
    assert chain.read_text(encoding="utf-8") == LOH.read_text(encoding="utf-8")
    folder = tmp_path / "d"
    folder.mkdir()
    res = run(chain, "--json", folder)
    assert res.exit_code == 2 and "is a folder" in res.output
    # a bad chain writes nothing
    bad = tmp_path / "bad.toml"
    bad.write_text("[[steps]]\nprismatic = 'x'\n", encoding="utf-8")
    target = tmp_path / "out.json"
    assert run(bad, "--json", target).exit_code == 2 and not target.exists()


@pytest.mark.slow
def test_help_examples_run(monkeypatch):
    monkeypatch.chdir(ROOT)
    text = CliRunner().invoke(main, ["derive", "--help"]).output
    examples = re.findall(r"^\s+(esp derive [^\n]+)$", text, flags=re.M)
    assert len(examples) >= 3
    for line in examples:
        args = shlex.split(line)[1:]
        if "--json" in args and args[args.index("--json") + 1] != "-":
            args[args.index("--json") + 1] = "-"  # do not write into the project
        res = CliRunner().invoke(main, args)
        assert res.exit_code == 0, (line, res.output)


@pytest.mark.slow
def test_sympy_is_loaded_only_to_derive_formulae():
    """``esp --version``, ``esp --help``, ``esp analyse`` and ``esp derive --at`` never import
    sympy; ``esp derive`` of formulae does."""
    code = (
        "import sys\n"
        "from click.testing import CliRunner\n"
        "from esp.cli import main\n"
        "args = sys.argv[1:]\n"
        "r = CliRunner().invoke(main, args)\n"
        "assert r.exit_code == 0, r.output\n"
        "print('sympy' in sys.modules)\n"
    )
    cases = [
        (["--version"], False),
        (["--help"], False),
        (["derive", "--help"], False),
        (["derive", str(HEAD), "--at", "A=30,C=40", "--set", "G=20,e=10,Yp=50"], False),
        (
            [
                "analyse",
                str(ROOT / "data/examples/gantry/machine.toml"),
                "--at",
                "X=100,Y=100,Z=100",
            ],
            False,
        ),
        (["derive", str(LOH)], True),
    ]
    for args, loaded in cases:
        out = subprocess.run(
            [sys.executable, "-c", code, *args], capture_output=True, text=True, cwd=ROOT
        )
        assert out.returncode == 0, (args, out.stderr)
        assert out.stdout.strip().splitlines()[-1] == str(loaded), args


@pytest.mark.slow
def test_core_imports_neither_sympy_nor_presentation_libraries():
    code = (
        "import sys\n"
        "import esp.core.kinematics, esp.core.kinematics.exact, esp.core.kinematics.linear\n"
        "import esp.config.chain\n"
        "bad = sorted(m for m in ('sympy', 'matplotlib', 'pandas', 'click') if m in sys.modules)\n"
        "print(','.join(bad))\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == ""


def _nested_chain(levels: int, step: str | None = None) -> str:
    """A 1 KB chain whose definitions square at each level: d_k = d_{k-1}^2 + d_{k-1}."""
    lines = [
        "[chain]",
        'name = "nested"',
        "[symbols]",
        'X = { kind = "coordinate", unit = "mm" }',
        'a = { kind = "parameter", unit = "mm", value = 1 }',
        'b = { kind = "parameter", unit = "mm", value = 2 }',
        'e = { kind = "error", unit = "um" }',
        "[definitions]",
        'd0 = "a + b + X"',
    ]
    lines += [f'd{k} = "d{k - 1}*d{k - 1} + d{k - 1}"' for k in range(1, levels + 1)]
    lines += [
        "[[steps]]",
        'prismatic = "x"',
        'coordinate = "X"',
        'errors = { tx = "e" }',
        "[[steps]]",
        f'translate = {{ x = "{step or f"d{levels}"}" }}',
    ]
    return "\n".join(lines) + "\n"


@pytest.mark.parametrize(
    "levels, step, key, found",
    [
        # terms multiplied out: 3, 12, 156, 24492, 599882556 (t_k = t^2 + t): d4 is refused
        (6, None, "definitions.d4", "about 6e+08"),
        (40, None, "definitions.d4", "about 6e+08"),  # refused before d5..d40 are formed
        # within the bounds each, but the step multiplies three of them
        (3, "d3*d3*d3", "steps[2].translate.x", "about 1.5e+13"),
    ],
)
def test_nested_definitions_are_refused_before_they_grow(tmp_path, levels, step, key, found):
    path = tmp_path / "nested.toml"
    path.write_text(_nested_chain(levels, step), encoding="utf-8")
    assert path.stat().st_size < 2048
    result = run(path)
    assert result.exit_code == 2
    lines = result.output.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in result.output
    assert f"{key}: expected at most 1e+06 terms multiplied out, found {found}" in lines[0]


def test_nested_definitions_within_the_bound_are_derived(tmp_path):
    """Two levels: d2 = (d1)^2 + d1 with d1 = d0^2 + d0, d0 = a + b + X; the tool tip's
    nominal x is the joint's X plus d2."""
    path = tmp_path / "nested.toml"
    path.write_text(_nested_chain(2), encoding="utf-8")
    result = run(path, "--at", "X=1", "--set", "e=0")
    assert result.exit_code == 0, result.output
    d0 = 1 + 2 + 1
    d1 = d0 * d0 + d0
    d2 = d1 * d1 + d1
    nominal = [line for line in result.output.splitlines() if line.startswith("nominal (mm)")]
    assert nominal[0].split()[2] == f"{1 + d2:.6f}"  # 421
