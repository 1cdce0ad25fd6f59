"""``esp analyse`` as a user runs it."""

from __future__ import annotations

import json

import pytest
from click.testing import CliRunner

from esp.cli import main

BASE = """
[machine]
name = "CLI test"
configuration = "wBMTt"
axes = { bottom = "X", middle = "Y", top = "Z" }

[axes.X]
travel = [0, 1000]
step = 250

[axes.X.errors]
linear = { points = [[0, 0.0], [1000, 8.0]] }
angular = { Y = { constant = 5.0 } }

[axes.Y]
travel = [0, 1000]
step = 250

[axes.Z]
travel = [0, 1000]
step = 250

[squareness]
XY = 10.0
"""


def run(tmp_path, text: str, *args: str):
    path = tmp_path / "machine.toml"
    path.write_text(text, encoding="utf-8")
    return CliRunner().invoke(main, ["analyse", str(path), *args])


def test_report_on_the_terminal(tmp_path):
    res = run(tmp_path, BASE)
    assert res.exit_code == 0, res.output
    # X at (1000, 1000, 1000): 8 (X.linear) + 5 (Φ_M(B)·T) + 10 (BM_sqr·M) = 23 µm
    assert "Volumetric accuracy: 23.000 µm at X=1000, Y=1000, Z=1000" in res.output
    assert "case 3.10.1" in res.output and "(rigid-body chain wBMTt)" in res.output
    assert "All axes associated with movement of the tool" in res.output


def test_json_contract_and_determinism(tmp_path):
    a = run(tmp_path, BASE, "--json", "-")
    b = run(tmp_path, BASE, "--json", "-")
    assert a.exit_code == 0 and a.output == b.output
    doc = json.loads(a.output)
    assert doc["schema"] == "esp.result/1"
    assert set(doc) >= {"machine", "analysis", "cases", "worst"}
    case = doc["cases"][0]
    assert set(case) >= {"tool", "volumetric", "planar", "axes", "breakdown"}
    assert case["volumetric"] == {
        "accuracy_um": 23.0,
        "at": {"X": 1000.0, "Y": 1000.0, "Z": 1000.0},
    }
    assert set(case["planar"]) == {"XY", "XZ", "YZ"}
    assert set(case["axes"]["X"]) == {"min_um", "min_at", "max_um", "max_at", "range_um"}
    term = case["breakdown"][0]["terms"][0]
    assert set(term) >= {"direction", "component", "iso", "source", "value_um", "share_pct"}
    assert doc["worst"] == {"case": 0, "accuracy_um": 23.0}


def test_json_to_a_file(tmp_path):
    out = tmp_path / "out" / "result.json"
    res = run(tmp_path, BASE, "--json", str(out), "--quiet")
    assert res.exit_code == 0 and res.output == ""
    assert json.loads(out.read_text(encoding="utf-8"))["schema"] == "esp.result/1"


def test_single_point(tmp_path):
    res = run(tmp_path, BASE, "--at", "X=500,Y=250,Z=100", "--json", "-")
    assert res.exit_code == 0, res.output
    doc = json.loads(res.output)
    assert doc["schema"] == "esp.point/1"
    (case,) = doc["cases"]
    # X: 4 (linear at 500) + 5·100/1000 + 10·250/1000 = 4 + 0.5 + 2.5 = 7
    assert case["errors_um"] == {"X": 7.0, "Y": 0.0, "Z": 0.0}
    assert case["volumetric_um"] == 7.0
    assert {t["component"] for t in case["terms"]} == {"X.linear", "X.angular.Y", "squareness.XY"}


@pytest.mark.parametrize("text", ["X=1", "X=1,Y=2,Z=abc", "X=1,Y=2,W=3", "X=1,X=2,Y=1,Z=1"])
def test_bad_point(tmp_path, text):
    res = run(tmp_path, BASE, "--at", text)
    assert res.exit_code == 2
    assert "Traceback" not in res.output


@pytest.mark.parametrize(
    "old, new, key",
    [
        ('name = "CLI test"', 'name = "CLI test"\ncolour = "red"', "machine.colour"),
        ('configuration = "wBMTt"', 'configuration = "wXYZ"', "machine.configuration"),
        ('bottom = "X"', 'bottom = "W"', "machine.axes.bottom"),
        ("step = 250\n\n[axes.X.errors]", "step = 0\n\n[axes.X.errors]", "axes.X.step"),
        (
            "[axes.Y]\ntravel = [0, 1000]",
            "[axes.Y]\ntravel = [0, 1000]\nsimulate = [0, 1200]",
            "axes.Y.simulate",
        ),
        ("linear = { points", 'linear = "missing.rtl"\n#', "axes.X.errors.linear"),
    ],
)
def test_configuration_errors_exit_2_naming_the_key(tmp_path, old, new, key):
    assert old in BASE
    res = run(tmp_path, BASE.replace(old, new, 1))
    assert res.exit_code == 2
    assert key in res.output
    assert "Traceback" not in res.output
    assert len(res.output.strip().splitlines()) == 1


def test_simulation_outside_the_measured_range(tmp_path):
    text = BASE.replace("[[0, 0.0], [1000, 8.0]]", "[[0, 0.0], [900, 8.0]]")
    res = run(tmp_path, text)
    assert res.exit_code == 2
    assert "X.linear" in res.output and "analysis.extrapolate" in res.output
    out = tmp_path / "result.json"
    res = run(tmp_path, text, "--json", str(out))
    assert res.exit_code == 2 and not out.exists()
    res = run(tmp_path, text + "\n[analysis]\nextrapolate = true\n")
    assert res.exit_code == 0 and "warning:" in res.output


def test_help_has_an_example():
    res = CliRunner().invoke(main, ["analyse", "--help"])
    assert res.exit_code == 0 and "esp analyse data/examples/" in res.output


@pytest.mark.slow
def test_help_examples_run(monkeypatch):
    """The examples in the help texts work on the shipped data."""
    import re
    import shlex
    from pathlib import Path

    root = Path(__file__).resolve().parent.parent
    for command in ("analyse", "inspect", "iso230-2", "angular"):
        text = CliRunner().invoke(main, [command, "--help"]).output
        folder = re.search(r"Examples \(in ([^)]+)\):", text)
        monkeypatch.chdir(root / folder.group(1) if folder else root)
        examples = re.findall(r"^\s+(esp [^\n]+)$", text, flags=re.M)
        assert examples, command
        for line in examples:
            args = shlex.split(line)[1:]
            if ">" in args:
                args = args[: args.index(">")]  # a shell redirection: run the command alone
            writes = {"--out", "-o", "--json", "--plot", "--show"}
            if any(a in writes and args[i + 1] != "-" for i, a in enumerate(args[:-1])):
                continue  # examples that write files are covered by their own tests
            res = CliRunner().invoke(main, args)
            assert res.exit_code == 0, (line, res.output)
