"""``esp batch`` deciding every machine against tolerances (ISO 14253-1:2017, ILAC-G8):
the thresholds and each machine's own ``[tolerance]``, decided by the rule in the same place
as ``esp analyse`` (:mod:`esp.volumetric.conformance`), through the command line.

The machine's one error, X.linear, rises from 0 to 10 µm over X with U = 2 µm (k = 2): the
volumetric accuracy is y = 10 µm with U = 2 µm. Against T = 13 it conforms by both rules
(y ≤ T - w = 11); against T = 11.5 it conforms by simple acceptance and lies within the
guard band (9.5, 13.5] of guarded acceptance; against T = 9 it does not conform by simple
acceptance and lies within the band (7, 11]; against T = 7 it does not conform by both.
"""

from __future__ import annotations

import csv
import json
from pathlib import Path

import pytest
from click.testing import CliRunner

from esp.cli import main

MACHINE = """
[machine]
name = "{name}"
configuration = "wBMTt"
axes = {{ bottom = "X", middle = "Y", top = "Z" }}

[axes.X]
travel = [0, 100]
step = 50

[axes.X.errors]
linear = {{ points = [[0, 0.0], [100, 10.0]] }}

[axes.Y]
travel = [0, 100]
step = 50

[axes.Z]
travel = [0, 100]
step = 50
"""

UNCERTAINTY = '\n[uncertainty]\nk = 2.0\n[uncertainty.components."X.linear"]\nU = 2.0\n'


def write(path: Path, text: str) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text, encoding="utf-8")
    return path


@pytest.fixture
def fake_reports(monkeypatch):
    """The report content replaced by a stub (the folder logic stays real), as in
    tests/test_batch.py: the decisions are the summary's, not the PDF's."""

    def stand_in(result, staged, **kwargs):
        doc = {"schema": "esp.result/1", "name": result.machine.name}
        (Path(staged) / "result.json").write_text(json.dumps(doc), encoding="utf-8")

    monkeypatch.setattr("esp.volumetric.report.write_report_files", stand_in)


def batch(*args: object):
    return CliRunner().invoke(main, ["batch", *map(str, args)])


def read_rows(out: Path) -> list[dict[str, str]]:
    with open(out / "summary.csv", newline="", encoding="utf-8") as f:
        return list(csv.DictReader(f))


@pytest.mark.parametrize(
    ("limit", "rule", "verdict", "code"),
    [
        ("13", "simple", "pass", 0),
        ("13", "guarded", "pass", 0),
        ("11.5", "simple", "pass", 0),
        ("11.5", "guarded", "not decided: volumetric 10.0 um within 11.5 um ± 2 um", 3),
        ("9", "simple", "fail: volumetric 10.0 um > 9 um", 1),
        ("9", "guarded", "not decided: volumetric 10.0 um within 9 um ± 2 um", 3),
        ("7", "simple", "fail: volumetric 10.0 um > 7 um", 1),
        ("7", "guarded", "fail: volumetric 10.0 um > 7 um", 1),
    ],
)
def test_worked_cases(tmp_path, fake_reports, limit, rule, verdict, code):
    path = write(tmp_path / "m" / "machine.toml", MACHINE.format(name="M") + UNCERTAINTY)
    out = tmp_path / "out"
    res = batch(path, "--out", out, "--max-volumetric", limit, "--rule", rule)
    assert res.exit_code == code, res.output
    (row,) = read_rows(out)
    assert row["verdict"] == verdict
    assert row["decision_rule"].startswith(f"{rule} acceptance")
    assert row["decisions"].startswith(f"volumetric 10.0 µm against {limit} µm: ")
    assert f"ok   machine.toml  10.0 um, U = 2.0 um  {verdict}" in res.output


@pytest.mark.slow  # four batches (about 0.5 s)
def test_each_machine_own_tolerance_and_exit_codes(tmp_path, fake_reports):
    root = tmp_path / "fleet"
    own = '\n[tolerance]\nvolumetric_um = {}\nrule = "guarded"\n'
    write(root / "a.toml", MACHINE.format(name="A") + UNCERTAINTY + own.format(13))
    write(root / "b.toml", MACHINE.format(name="B") + UNCERTAINTY + own.format(11.5))
    out = tmp_path / "out"
    res = batch(root, "--out", out)
    assert res.exit_code == 3, res.output  # none fails, one is not decided
    rows = read_rows(out)
    assert [r["verdict"].split(":")[0] for r in rows] == ["pass", "not decided"]
    assert "probability of false acceptance 0.1 %" in rows[0]["decisions"]  # 1 - Φ(3)
    assert "probability of conformity 93.3 %" in rows[1]["decisions"]
    md = (out / "summary.md").read_text(encoding="utf-8")
    assert "2 machines: 1 pass, 0 fail, 0 error, 1 not decided." in md
    assert "guarded acceptance, w = U" in md
    # the command line takes over: simple acceptance, both pass
    assert batch(root, "--out", out, "--rule", "simple").exit_code == 0
    # a threshold takes over the machines' limit: 10 µm does not conform to 7 µm
    res = batch(root, "--out", out, "--max-volumetric", "7")
    assert res.exit_code == 1, res.output


def test_guarded_without_u_is_an_error_row(tmp_path, fake_reports):
    root = tmp_path / "fleet"
    write(root / "a.toml", MACHINE.format(name="A") + UNCERTAINTY)
    write(root / "b.toml", MACHINE.format(name="B"))
    out = tmp_path / "out"
    res = batch(root, "--out", out, "--max-volumetric", "30", "--rule", "guarded")
    assert res.exit_code == 2, res.output
    a, b = read_rows(out)
    assert a["verdict"] == "pass"
    assert b["verdict"] == "error"
    assert b["error"].startswith("--rule: guarded acceptance needs the expanded uncertainty")


def test_guard_option_needs_guarded(tmp_path, fake_reports):
    path = write(tmp_path / "m" / "machine.toml", MACHINE.format(name="M") + UNCERTAINTY)
    res = batch(path, "--out", tmp_path / "out", "--guard", "0.5")
    assert res.exit_code == 2
    assert res.output.strip() == "esp: error: --guard: a guard band needs --rule guarded"
    assert not (tmp_path / "out").exists()
    # w = 0.5 U = 1 µm: 10 ≤ 11.5 - 1 passes
    res = batch(path, "--out", tmp_path / "out", "--max-volumetric", "11.5", "--rule", "guarded",
                "--guard", "0.5")  # fmt: skip
    assert res.exit_code == 0, res.output


@pytest.mark.slow  # writes summary.pdf
def test_summary_pdf_names_rule_and_risk(tmp_path, fake_reports):
    pypdf = pytest.importorskip("pypdf")
    path = write(tmp_path / "m" / "machine.toml", MACHINE.format(name="M") + UNCERTAINTY)
    out = tmp_path / "out"
    res = batch(path, "--out", out, "--max-volumetric", "11.5", "--rule", "guarded")
    assert res.exit_code == 3, res.output
    text = " ".join(p.extract_text() for p in pypdf.PdfReader(str(out / "summary.pdf")).pages)
    text = " ".join(text.split())
    assert "Decisions against the tolerances" in text
    assert "guarded acceptance, w = U" in text
    assert "probability of conformity 93.3 %" in text
