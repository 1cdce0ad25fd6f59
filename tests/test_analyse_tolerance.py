"""``esp analyse`` deciding its figures against tolerances (ISO 14253-1:2017, ILAC-G8), with
the figures rounded to their U (GUM 7.2.6), through the command line.

The machine has one error, X.linear rising from 0 to 10 µm over X, with U = 2 µm (k = 2):
the volumetric accuracy is y = 10 µm (at X = 1000), its U = 2 µm, u = 1 µm. Against T:

* T = 13: inside (y ≤ T - w = 11): conforms by both rules;
* T = 11.5: inside for simple, within the guard band for guarded (9.5 < y ≤ 13.5):
  not decided, p_c = Φ(1.5) = 0.933;
* T = 9: outside for simple; within the band for guarded (7 < y ≤ 11): not decided;
* T = 7: outside the band (y > 9): does not conform by both.
"""

from __future__ import annotations

import json
import math

import pytest
from click.testing import CliRunner

from esp.cli import main

MACHINE = """
[machine]
name = "Decision test"
configuration = "wBMTt"
axes = { bottom = "X", middle = "Y", top = "Z" }

[axes.X]
travel = [0, 1000]
step = 500

[axes.X.errors]
linear = { points = [[0, 0.0], [1000, 10.0]] }

[axes.Y]
travel = [0, 1000]
step = 500

[axes.Z]
travel = [0, 1000]
step = 500
"""

UNCERTAINTY = """
[uncertainty]
k = 2.0

[uncertainty.components."X.linear"]
U = 2.0
"""


def run(tmp_path, text: str, *args: str):
    path = tmp_path / "machine.toml"
    path.write_text(text, encoding="utf-8")
    return CliRunner().invoke(main, ["analyse", str(path), *args])


def phi(z: float) -> float:
    return 0.5 * math.erfc(-z / math.sqrt(2.0))


@pytest.mark.parametrize(
    ("limit", "rule", "verdict", "code"),
    [
        ("13", "simple", "conforms", 0),
        ("13", "guarded", "conforms", 0),
        ("11.5", "simple", "conforms", 0),
        ("11.5", "guarded", "not decided", 3),
        ("9", "simple", "does not conform", 1),
        ("9", "guarded", "not decided", 3),
        ("7", "simple", "does not conform", 1),
        ("7", "guarded", "does not conform", 1),
    ],
)
def test_worked_cases(tmp_path, limit, rule, verdict, code):
    res = run(
        tmp_path,
        MACHINE + UNCERTAINTY,
        "--tolerance",
        f"volumetric={limit}",
        "--rule",
        rule,
        "--json",
        "-",
    )
    assert res.exit_code == code, res.output
    (decision,) = json.loads(res.output)["decisions"]
    assert decision["verdict"] == verdict
    assert decision["value"] == pytest.approx(10.0) and decision["tolerance"] == float(limit)
    assert decision["guard_band"] == (2.0 if rule == "guarded" else 0.0)
    assert decision["decision_rule"]["rule"] == rule
    p_c = phi((float(limit) - 10.0) / 1.0)
    assert decision["probability_conforming"] == pytest.approx(p_c, abs=2e-6)


def test_text_names_rule_and_risk_and_rounds_to_u(tmp_path):
    res = run(
        tmp_path, MACHINE + UNCERTAINTY, "--tolerance", "volumetric=11.5", "--rule", "guarded"
    )
    assert res.exit_code == 3, res.output
    assert "Volumetric accuracy of Decision test: 10.0 µm, U = 2.0 µm (k = 2, about 95 %)" in (
        res.output
    )
    assert (
        "volumetric accuracy 10.0 µm (U = 2.0 µm) against 11.5 µm: not decided (guarded "
        "acceptance, w = U" in res.output
    )
    assert "probability of conformity 93.3 %" in res.output


def test_guard_fraction(tmp_path):
    # w = 0.5 U = 1 µm: 10 ≤ 11.5 - 1 conforms, with false acceptance 1 - Φ(1.5) = 6.7 %
    res = run(
        tmp_path, MACHINE + UNCERTAINTY, "--tolerance", "volumetric=11.5", "--rule", "guarded",
        "--guard", "0.5",
    )  # fmt: skip
    assert res.exit_code == 0, res.output
    assert "conforms (guarded acceptance, w = 0.5·U" in res.output
    assert "probability of false acceptance 6.7 %" in res.output


def test_range_uses_root_two_u(tmp_path):
    # range of X = 10 µm, U = √2 · 2 µm = 2.83 µm: T = 12 is within the band (9.17, 14.83]
    res = run(tmp_path, MACHINE + UNCERTAINTY, "--tolerance", "range.X=12", "--rule", "guarded",
              "--json", "-")  # fmt: skip
    assert res.exit_code == 3, res.output
    (decision,) = json.loads(res.output)["decisions"]
    assert decision["quantity"] == "range of the X error"
    assert decision["expanded_uncertainty"] == pytest.approx(2.0 * math.sqrt(2.0), abs=1e-6)


def test_file_table_and_command_line_override(tmp_path):
    table = '\n[tolerance]\nvolumetric_um = 9\nrange_um = { X = 20 }\nrule = "guarded"\n'
    res = run(tmp_path, MACHINE + UNCERTAINTY + table, "--json", "-")
    assert res.exit_code == 3, res.output  # 10 within (7, 11]
    verdicts = [d["verdict"] for d in json.loads(res.output)["decisions"]]
    assert verdicts == ["not decided", "conforms"]
    res = run(tmp_path, MACHINE + UNCERTAINTY + table, "--tolerance", "volumetric=13")
    assert res.exit_code == 0, res.output
    res = run(tmp_path, MACHINE + UNCERTAINTY + table, "--rule", "simple")
    assert res.exit_code == 1, res.output


def test_guarded_without_u_is_refused(tmp_path):
    res = run(tmp_path, MACHINE, "--tolerance", "volumetric=30", "--rule", "guarded")
    assert res.exit_code == 2
    assert res.output.startswith("esp: error: --rule: guarded acceptance needs the expanded")
    assert res.output.rstrip().endswith("(--rule simple)")
    assert len(res.output.strip().splitlines()) == 1
    res = run(tmp_path, MACHINE + '\n[tolerance]\nvolumetric_um = 30\nrule = "guarded"\n')
    assert res.exit_code == 2
    assert "machine.toml: tolerance.rule: guarded acceptance needs" in res.output
    assert res.output.rstrip().endswith('(rule = "simple")')


def test_guarded_planar_is_refused(tmp_path):
    res = run(tmp_path, MACHINE + UNCERTAINTY, "--tolerance", "planar.XY=30", "--rule", "guarded")
    assert res.exit_code == 2
    assert (
        "--rule: guarded acceptance needs the expanded uncertainty of the planar accuracy XY"
        in (res.output)
    )


def test_simple_without_u_and_no_tolerance(tmp_path):
    res = run(tmp_path, MACHINE, "--tolerance", "planar=9.5", "--json", "-")
    assert res.exit_code == 1, res.output  # planar XY and XZ are 10 µm
    decisions = json.loads(res.output)["decisions"]
    assert [d["verdict"] for d in decisions] == ["does not conform", "does not conform", "conforms"]
    assert decisions[0]["risk"]["value"] is None
    res = run(tmp_path, MACHINE, "--json", "-")
    assert res.exit_code == 0 and "decisions" not in json.loads(res.output)
    # no U: fixed decimals, no U in the headline
    assert "Volumetric accuracy of Decision test: 10.000 µm at" in run(tmp_path, MACHINE).output


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (("--tolerance", "volum=3"), "--tolerance: expected QUANTITY=UM"),
        (("--tolerance", "range=3"), "--tolerance: expected QUANTITY=UM"),
        (("--tolerance", "volumetric=-3"), "--tolerance: volumetric:"),
        (("--tolerance", "planar.XY=3", "--tolerance", "planar.xy=4"), "planar.XY is given twice"),
        (("--guard", "0.5"), "--guard: a guard band needs --rule guarded"),
        (("--rule", "guarded", "--guard", "5"), "a guard band fraction of U above 0 and at most 3"),
    ],
)
def test_bad_options(tmp_path, args, message):
    res = run(tmp_path, MACHINE + UNCERTAINTY, *args)
    assert res.exit_code == 2 and message in res.output, res.output
    assert len(res.output.strip().splitlines()) == 1


@pytest.mark.parametrize(
    ("table", "message"),
    [
        ("volumetric_um = -1", "tolerance.volumetric_um:"),
        ("planar_um = { XW = 3 }", "tolerance.planar_um"),
        ("range_um = 3", "tolerance.range_um: expected a table"),
        ('rule = "strict"', "tolerance.rule:"),
        ("guard = 0.5", 'tolerance.guard: a guard band needs rule = "guarded"'),
        ("maximum = 3", "tolerance"),
        ('rule = "guarded"\nguard = 0', "tolerance.guard: expected a guard band fraction of U"),
    ],
)
def test_bad_table(tmp_path, table, message):
    res = run(tmp_path, MACHINE + UNCERTAINTY + f"\n[tolerance]\n{table}\n")
    assert res.exit_code == 2 and message in res.output, res.output
    assert len(res.output.strip().splitlines()) == 1


def test_summation_bound_states_no_coverage_probability(tmp_path):
    # a summation bound is no coverage interval: "U ≤", k, and no "about 95 %"
    text = MACHINE + UNCERTAINTY.replace("k = 2.0", 'k = 2.0\nmethod = "summation"')
    res = run(tmp_path, text)
    assert res.exit_code == 0, res.output
    assert "Volumetric accuracy of Decision test: 10.0 µm, U ≤ 2.0 µm (k = 2) at" in res.output
    assert "about 95 %" not in res.output


def test_parallel_tool_tip_rounded_to_its_u():
    from pathlib import Path

    import numpy as np

    from esp.core.rounding import rounded

    example = Path(__file__).resolve().parent.parent / "data" / "examples" / "parallel"
    res = CliRunner().invoke(main, ["parallel", str(example / "machine.toml"), "--json", "-"])
    assert res.exit_code == 0, res.output
    doc = json.loads(res.output)
    tip_um = float(np.linalg.norm([doc["errors"][f"e_{a}"] for a in "xyz"]))
    u_tip = doc["uncertainty"]["position_um"]
    v_text, u_text = rounded(tip_um, u_tip)
    text = CliRunner().invoke(main, ["parallel", str(example / "machine.toml")]).output
    assert f"tool tip |e| = {v_text} µm, U = {u_text} µm (k = 2, about 95 %)" in text


@pytest.mark.slow  # draws page 1 (about 0.4 s)
def test_pdf_page_one_headline_and_decisions(tmp_path):
    from dataclasses import replace

    from esp.config import load_machine
    from esp.config.tolerance import Tolerances
    from esp.core.analysis import analyse
    from esp.core.conformity import DecisionRule
    from esp.volumetric import pdf

    path = tmp_path / "machine.toml"
    path.write_text(MACHINE + UNCERTAINTY, encoding="utf-8")
    machine = load_machine(path)
    tolerance = Tolerances(volumetric_um=11.5, rule=DecisionRule("guarded"))
    first = pdf.text_pages(analyse(replace(machine, tolerance=tolerance)), "2026-01-01")[0]
    texts = first.texts()
    assert "Volumetric accuracy  10.0 µm, U = 2.0 µm (k = 2, about 95 %)" in texts
    assert "Decisions against the tolerances" in texts
    joined = " ".join(texts)
    assert "volumetric accuracy 10.0 µm (U = 2.0 µm) against 11.5 µm: not decided" in joined
    assert "probability of conformity 93.3 %" in joined
    # without tolerances there is no block
    plain = pdf.text_pages(analyse(machine), "2026-01-01")[0].texts()
    assert "Decisions against the tolerances" not in plain


def test_a_planar_limit_for_every_plane_replaces_the_files_per_plane_limits(tmp_path):
    table = "\n[tolerance]\nplanar_um = { XY = 5 }\n"
    res = run(tmp_path, MACHINE + table)
    assert res.exit_code == 1, res.output  # planar XY 10 µm > 5 µm
    res = run(tmp_path, MACHINE + table, "--tolerance", "planar=25", "--json", "-")
    assert res.exit_code == 0, res.output
    decisions = json.loads(res.output)["decisions"]
    assert [d["tolerance"] for d in decisions] == [25.0, 25.0, 25.0]
