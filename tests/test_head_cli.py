"""``esp head`` end to end: a setting, a map, the report folder, the protocol and its
solution, one-line errors, and what it imports."""

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

from esp.cli import main
from esp.heads import error_map, evaluate_head
from esp.heads.config import read_head_file
from esp.heads.maps import GridSpec

ROOT = Path(__file__).resolve().parent.parent
HEADS = ROOT / "data/examples/heads"
FIG3 = HEADS / "angle-head-fig3.toml"
ANGLE = HEADS / "angle-head.toml"
FORK = HEADS / "fork-head-example.toml"
MEASURED = HEADS / "fork-head-measured.csv"
SMALL = ("--grid", "A=-60:60:30,C=-60:60:30")


def run(*args):
    return CliRunner().invoke(main, ["head", *map(str, args)])


def _one_line_error(res, *fragments: str) -> None:
    assert res.exit_code == 2, res.output
    lines = res.output.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("esp: error: "), res.output
    assert "Traceback" not in res.output
    for fragment in fragments:
        assert fragment in lines[0], lines[0]


def test_setting_json_matches_the_library():
    res = run(FIG3, "--at", "A=30,C=40", "--json", "-")
    assert res.exit_code == 0, res.output
    doc = json.loads(res.output)
    for key in ("schema", "at", "nominal_mm", "errors_mm", "terms"):
        assert key in doc
    assert doc["schema"] == "esp.head/1" and doc["mode"] == "point"
    assert doc["at"] == {"A": 30.0, "C": 40.0}
    ev = evaluate_head(read_head_file(FIG3).head, {"A": 30.0, "C": 40.0})
    for k, axis in enumerate("XYZ"):
        assert doc["nominal_mm"][axis] == pytest.approx(ev.nominal_mm[0, k], abs=1e-6)
        assert doc["errors_mm"][axis] == pytest.approx(ev.first_um[0, k] / 1000, abs=1e-6)
        assert doc["errors_um"][axis] == pytest.approx(ev.first_um[0, k], abs=1e-6)
    assert [t["error"] for t in doc["terms"]] == ["ThetaAs", "Ocx", "Ocy", "ThetaCh", "ThetaCv"]
    total = sum(t["X"] for t in doc["terms"])
    assert total == pytest.approx(doc["errors_um"]["X"], abs=1e-5)
    assert sum(t["share_pct"]["X"] for t in doc["terms"]) == pytest.approx(100.0, abs=1e-3)
    assert doc["values"]["errors"]["Ocx"] == {
        "value": 0.005,
        "unit": "mm",
        "from": "angle-head-fig3.toml",
    }


def test_set_and_order_two():
    res = run(FIG3, "--at", "A=30,C=40", "--set", "G=25,Ocx=0.01", "--order", "2", "--json", "-")
    assert res.exit_code == 0, res.output
    doc = json.loads(res.output)
    assert doc["order"] == 2
    assert doc["values"]["parameters"]["G"]["value"] == 25.0
    assert doc["values"]["errors"]["Ocx"]["from"] == "--set"
    for axis in "XYZ":
        total = doc["first_order_um"][axis] + doc["second_order_um"][axis]
        assert doc["errors_um"][axis] == pytest.approx(total, abs=2e-6)
        # the second order makes the error closer to the exact chain
        assert abs(doc["exact_um"][axis] - doc["errors_um"][axis]) < 1e-3


def test_setting_text():
    res = run(FIG3, "--at", "A=30,C=40")
    assert res.exit_code == 0, res.output
    assert "at: A=30°, C=40°" in res.output
    assert re.search(r"^nominal tip \(mm\)\s+13\.1442\s+-3\.7471\s+-26\.8186$", res.output, re.M)
    assert "breakdown of the first-order error" in res.output


def test_map_json():
    res = run(FIG3, *SMALL, "--json", "-")
    assert res.exit_code == 0, res.output
    doc = json.loads(res.output)
    assert doc["schema"] == "esp.head/1" and doc["mode"] == "map"
    assert doc["grid"] == {
        "A": [-60.0, -30.0, 0.0, 30.0, 60.0],
        "C": [-60.0, -30.0, 0.0, 30.0, 60.0],
    }
    m = error_map(
        read_head_file(FIG3).head, [GridSpec("A", -60, 60, 30), GridSpec("C", -60, 60, 30)]
    )
    worst = m.extremes()["D"]["max"]
    assert doc["extremes"]["D"]["max"]["value_um"] == pytest.approx(worst.value_um, abs=1e-6)
    assert doc["at"] == worst.at  # the worst setting in the keys of a point
    assert np.array(doc["maps"]["Y"]).shape == (5, 5)
    assert doc["second_order"]["max_um"] < 0.05  # the paper: no significant change
    assert "NaN" not in res.output


def test_map_text_default_grid_from_the_file():
    res = run(FIG3)
    assert res.exit_code == 0, res.output
    assert "A -60° to 60° step 2.5°, C -60° to 60° step 2.5° (2401 settings)" in res.output
    assert "the first order is enough" in res.output


@pytest.mark.slow
def test_report_folder(tmp_path, monkeypatch):
    monkeypatch.setenv("SOURCE_DATE_EPOCH", "1700000000")
    out = tmp_path / "r"
    res = run(FIG3, *SMALL, "--out", out, "-q")
    assert res.exit_code == 0, res.output
    assert res.output == ""
    names = {p.name for p in out.iterdir()}
    for name in (
        "result.json",
        "summary.txt",
        "surfaces.png",
        "contours.png",
        "second-order.png",
        "terms.png",
        "head.pdf",
    ):
        assert name in names
    assert (out / "head.pdf").read_bytes().startswith(b"%PDF")
    first = {p.name: p.read_bytes() for p in out.iterdir() if not p.name.startswith(".")}
    res = run(FIG3, *SMALL, "--out", out, "-q")  # an esp folder is replaced
    assert res.exit_code == 0, res.output
    again = {p.name: p.read_bytes() for p in out.iterdir() if not p.name.startswith(".")}
    assert again == first  # deterministic bytes


@pytest.mark.slow
def test_protocol_json_and_text(tmp_path):
    target = tmp_path / "p.json"
    res = run(FIG3, "--protocol", "--json", target)
    assert res.exit_code == 0, res.output
    doc = json.loads(target.read_text(encoding="utf-8"))
    assert doc["schema"] == "esp.protocol/1"
    assert doc["assume_zero"] == ["DY", "ThetaAv"]
    first = doc["tests"][0]
    assert first["errors"] == ["Ocx"] and first["equation"] == "dX_1 = 2*Ocx"
    assert first["first"] == {"A": 90.0, "C": 0.0} and first["second"] == {"A": 270.0, "C": 180.0}
    assert re.search(
        r"^\s+1\s+Ocx\s+dX_1\s+90\s+0\s+270\s+180\s+dX_1 = 2\*Ocx\s+Ocx = dX_1/2", res.output, re.M
    )
    # docs/heads.md shows this protocol as the command prints it
    docs = (ROOT / "docs/heads.md").read_text(encoding="utf-8")
    block = docs.split("$ esp head data/examples/heads/angle-head-fig3.toml --protocol\n")[1]
    assert block.split("```")[0] == res.output


@pytest.mark.slow
def test_protocol_solved_from_measurements(tmp_path):
    target = tmp_path / "identified.json"
    res = run(FORK, "--measured", MEASURED, "--json", target)
    assert res.exit_code == 0, res.output
    assert "identified errors" in res.output
    doc = json.loads(target.read_text(encoding="utf-8"))
    assert doc["identified"]["EY0A"] == {"value": 6.4, "unit": "um", "step": 1}
    assert doc["measured_um"]["1"] == 12.8
    # the identified values feed a head file back
    head = tmp_path / "h.toml"
    chain = (HEADS / "fork-head.toml").as_posix()
    head.write_text(
        f'[head]\nchain = "{chain}"\nerrors_from = "identified.json"\n', encoding="utf-8"
    )
    res = run(head, "--at", "A=0,C=0", "--json", "-")
    assert res.exit_code == 0, res.output
    values = json.loads(res.output)["values"]["errors"]
    assert values["EY0A"] == {"value": 6.4, "unit": "um", "from": "identified.json"}


@pytest.mark.slow
def test_help_examples_run(monkeypatch):
    monkeypatch.chdir(ROOT)
    text = CliRunner().invoke(main, ["head", "--help"]).output
    examples = re.findall(r"^\s+(esp head [^\n]+?)(?: \\)?$", text, flags=re.M)
    assert len(examples) >= 4
    text = text.replace("\\\n", "")
    examples = [
        " ".join(e.split()) for e in re.findall(r"^\s+(esp head [^\n]+)$", text, flags=re.M)
    ]
    for line in examples:
        args = shlex.split(line)[1:]
        if "--out" in args:
            continue  # writes a folder (tested above)
        res = CliRunner().invoke(main, args)
        assert res.exit_code == 0, (line, res.output)


# -- one-line errors ------------------------------------------------------------------------


def write(tmp_path, text):
    path = tmp_path / "head.toml"
    path.write_text(f'[head]\nchain = "{ANGLE.as_posix()}"\n' + text, encoding="utf-8")
    return path


@pytest.mark.parametrize(
    ("text", "fragments"),
    [
        ("erors = 1\n", ("head.erors: unknown key 'erors'; did you mean 'errors'?",)),
        ("[head.errors]\nOcz = 1\n", ("head.errors.Ocz", "did you mean 'Ocy'?")),
        ("[head.errors]\nOcx = 'a'\n", ("head.errors.Ocx: expected a number",)),
        ("[head.parameters]\nYp = 0\n", ("'-e/tan(Yp)' is not finite",)),
        ("[mapp]\n", ("mapp: unknown table 'mapp'; did you mean 'map'?",)),
        ("[protocol]\nassume_zero = ['DYY']\n", ("protocol.assume_zero", "did you mean 'DY'?")),
        ("x = = 1\n", ("invalid TOML at line 3",)),
    ],
)
def test_bad_head_files(tmp_path, text, fragments):
    _one_line_error(run(write(tmp_path, text)), *fragments)


@pytest.mark.parametrize(
    ("grid", "fragment"),
    [
        ("step = 1e-308", "map.A.step: values from 0 to 90 in steps of 1e-308 = more than 1e+308"),
        ("step = 1e-9", "map.A.step: values from 0 to 90 in steps of 1e-9 = 9e+10, above"),
        ("step = -5", "map.A.step: expected a step above zero, found -5"),
    ],
)
def test_a_map_of_the_head_file_is_bounded_before_its_values_are_made(tmp_path, grid, fragment):
    """The count of a [map] angle is estimated as a float before any value is made: a step
    of 1e-308 was an OverflowError traceback."""
    path = tmp_path / "h.toml"
    path.write_text(
        f'[head]\nchain = "{ANGLE.as_posix()}"\n[map]\nA = {{ from = 0, to = 90, {grid} }}\n'
        "C = { from = 0, to = 90, step = 30 }\n",
        encoding="utf-8",
    )
    _one_line_error(run(path), "h.toml: ", fragment)


def test_missing_files(tmp_path):
    _one_line_error(run(tmp_path / "none.toml"), "no such head file")
    path = tmp_path / "h.toml"
    path.write_text('[head]\nchain = "nope.toml"\n', encoding="utf-8")
    _one_line_error(run(path), "head.chain", "no such chain file")
    path.write_text("[other]\nx = 1\n", encoding="utf-8")
    _one_line_error(run(path), "head: required table is missing")


@pytest.mark.parametrize(
    ("args", "fragments"),
    [
        (("--at", "A=30"), ("missing C",)),
        (("--at", "A=30,C=40,B=1"), ("B is not one of the head's coordinates",)),
        (("--at", "A=x,C=1"), ("expected a number",)),
        (("--at", "A=nan,C=1"), ("finite",)),
        (("--set", "Gg=3"), ("did you mean 'G'?",)),
        (("--set", "A=3"), ("A is a coordinate",)),
        (("--grid", "A=-60:60"), ("NAME=from:to:step",)),
        (("--grid", "A=-60:60:5"), ("grid of the head's two angles",)),
        (("--grid", "A=60:-60:5,C=0:1:1"), ("from <= to",)),
        (("--grid", "B=0:1:1,C=0:1:1"), ("B is not one of the head's coordinates",)),
        (("--order", "3"), ("--order",)),
        (("--at", "A=1,C=2", "--protocol"), ("--at does not apply to --protocol",)),
        (("--assume-zero", "DY"), ("--assume-zero applies to --protocol only",)),
        (("--at", "A=1,C=2", "--out", "x"), ("--out",)),
        (("--protocol", "--assume-zero", "DYY"), ("unknown error 'DYY'; did you mean 'DY'?",)),
        (("--protocol", "--assume-zero", "G"), ("G is a parameter of the head",)),
        (("--protocol", "--assume-zero", "DY"), ("ThetaAs cannot be isolated", "ThetaAv")),
        (("--protocol", "--identify", "Ocq"), ("--identify: unknown error",)),
        (("--protocol", "--angles", "0,x"), ("--angles",)),
        (("--protocol", "--angles", "0"), ("at least two distinct angles",)),
    ],
)
@pytest.mark.slow
def test_bad_options(args, fragments):
    _one_line_error(run(FIG3, *args), *fragments)


@pytest.mark.slow
def test_bad_measured_files(tmp_path):
    m = tmp_path / "m.csv"
    m.write_text("test,axis,A1,C1,A2,C2,difference_um\n1,Y,90,0,90,90,3\n", encoding="utf-8")
    _one_line_error(run(FORK, "--measured", m), "m.csv:2", "does not match this protocol")
    m.write_text("test,difference_um\n1,3\n", encoding="utf-8")
    _one_line_error(run(FORK, "--measured", m), "test 2 (dZ_2) has no measured difference")
    _one_line_error(run(FORK, "--measured", tmp_path / "none.csv"), "no such file")


def test_outputs_are_checked_before_work(tmp_path):
    _one_line_error(run(FIG3, "--json", FIG3), "is one of this command's inputs")
    _one_line_error(run(FIG3, "--json", ANGLE), "is one of this command's inputs")
    (tmp_path / "mine").mkdir()
    (tmp_path / "mine" / "notes.txt").write_text("keep", encoding="utf-8")
    _one_line_error(run(FIG3, *SMALL, "--out", tmp_path / "mine"), "esp did not write")


@pytest.mark.slow
def test_no_sympy_or_matplotlib_without_protocol_or_plots():
    """``esp head --json -`` (a map, then a setting, in one process) imports neither sympy
    nor matplotlib; ``--protocol`` imports sympy, but not ``sympy.physics`` (which
    ``sympy.simplify`` would load, for a second, to look for units)."""
    code = (
        "import sys\n"
        "from click.testing import CliRunner\n"
        "from esp.cli import main\n"
        "for args in sys.argv[1:]:\n"
        "    r = CliRunner().invoke(main, args.split('|'))\n"
        "    assert r.exit_code == 0, r.output\n"
        "heavy = ('sympy', 'sympy.physics', 'matplotlib', 'pandas')\n"
        "print(','.join(m for m in heavy if m in sys.modules))\n"
    )
    cases = [
        (
            [
                "|".join(["head", str(FIG3), "--json", "-", *SMALL]),
                "|".join(["head", str(FIG3), "--at", "A=30,C=40", "--json", "-"]),
            ],
            "",
        ),
        (["|".join(["head", str(FIG3), "--protocol", "--json", "-"])], "sympy"),
    ]
    for args, loaded in cases:
        out = subprocess.run(
            [sys.executable, "-c", code, *args], capture_output=True, text=True, cwd=ROOT
        )
        assert out.returncode == 0, (args, out.stderr)
        assert out.stdout.strip() == loaded, (args, out.stdout[-200:])


@pytest.mark.slow
def test_heads_core_imports_only_numpy():
    code = (
        "import sys\n"
        "import esp.heads, esp.heads.config, esp.heads.measured\n"
        "bad = sorted(m for m in ('sympy', 'matplotlib', 'pandas', 'click') if m in sys.modules)\n"
        "print(','.join(bad))\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == ""
