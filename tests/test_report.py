"""The report folder of ``esp analyse --out``: files, pages, pictures, atomicity."""

from __future__ import annotations

import csv
import json
import re
import struct
from pathlib import Path

import pytest
from click.testing import CliRunner

import esp.report.plots as plots
from esp.analysis import analyse
from esp.cli import main
from esp.config import machine_from_dict
from esp.report import bundle, pdf
from esp.report.export import EXTREMES_COLUMNS, GRID_COLUMNS, TERMS_COLUMNS

DATE = "2026-01-02"


def small(sweep: bool = False, uncertainty: str | None = None) -> dict:
    """A 3-axis machine with a few inline components on a 5 x 5 x 3 grid."""
    data = {
        "machine": {
            "name": "Report test",
            "configuration": "wBMTt",
            "axes": {"bottom": "X", "middle": "Y", "top": "Z"},
        },
        "axes": {
            "X": {
                "travel": [0, 400],
                "step": 100,
                "errors": {
                    "linear": {"points": [[0, 0.0], [200, 3.0], [400, 2.0]]},
                    "angular": {"Y": {"constant": 5.0}},
                },
            },
            "Y": {"travel": [0, 400], "step": 100, "errors": {"linear": {"constant": 1.0}}},
            "Z": {
                "travel": [0, 200],
                "step": 100,
                "errors": {"straightness": {"X": {"points": [[0, 0.0], [100, 1.0], [200, 0.0]]}}},
            },
        },
        "squareness": {"XY": 4.0},
    }
    if sweep:
        data["analysis"] = {"point": "TCP"}
        data["tool"] = {"lengths": [0, 100], "sweep": {"tilt": [0, 90], "spin": [0, 90]}}
    if uncertainty:
        data["uncertainty"] = {
            "method": uncertainty,
            "samples": 200,
            "components": {"X.linear": {"U": 2.0}, "squareness.XY": {"U": 3.0}},
        }
    return data


def result_of(data: dict):
    return analyse(machine_from_dict(data, "."))


def png_size(path: Path) -> tuple[int, int]:
    """Width and height from the PNG header (IHDR follows the 8-byte signature)."""
    head = path.read_bytes()[:24]
    assert head[:8] == b"\x89PNG\r\n\x1a\n" and head[12:16] == b"IHDR"
    return struct.unpack(">II", head[16:24])


def pdf_pages(path: Path) -> int:
    return len(re.findall(rb"/Type\s*/Page\b", path.read_bytes()))


@pytest.fixture(scope="module")
def full_report(tmp_path_factory):
    """One report with every kind of figure: a sweep and a Monte Carlo uncertainty."""
    out = tmp_path_factory.mktemp("rep") / "report"
    result = result_of(small(sweep=True, uncertainty="montecarlo"))
    bundle.write_report(result, out, grid_csv=True, date=DATE)
    return result, out


def test_report_files_exist(full_report):
    result, out = full_report
    names = {p.name for p in out.iterdir()}
    expected = {
        "report.pdf",
        "result.json",
        "extremes.csv",
        "terms.csv",
        "grid.csv",
        "map-X.png",
        "map-Y.png",
        "map-Z.png",
        "map-volumetric.png",
        "terms.png",
        "sweep.png",
        "uncertainty-budget.png",
        "uncertainty-montecarlo.png",
    }
    assert expected <= names
    # one input figure per active component with data (not squareness)
    inputs = {n for n in names if n.startswith("input-")}
    assert inputs == {
        "input-X-linear.png",
        "input-X-angular-Y.png",
        "input-Y-linear.png",
        "input-Z-straightness-X.png",
    }
    assert [n for n in names if n.startswith(".")] == [".esp-folder.json"]  # no temporary


def test_pdf_has_the_text_pages_and_one_page_per_figure(full_report):
    result, out = full_report
    specs = bundle.figure_specs(result)
    text = pdf.text_pages(result, DATE, [s.title for s in specs])
    assert pdf_pages(out / "report.pdf") == len(text) + len(specs)
    # 4 maps, terms, sweep, budget, Monte Carlo histogram, and the 4 input figures
    assert len(specs) == 8 + 4
    first = " ".join(text[0].texts())
    assert "Report test" in first and "Volumetric accuracy" in first and DATE in first
    assert "Uncertainty" in first


def test_pngs_open_with_their_size(full_report):
    _, out = full_report
    for name in ("map-X.png", "terms.png", "input-X-linear.png", "sweep.png"):
        width, height = png_size(out / name)
        assert 300 < width <= 2000 and 200 < height <= 2000, name
    # the terms chart is 11 inches wide at 100 dpi
    assert png_size(out / "terms.png")[0] == 1100


def test_result_json_is_the_documented_contract(full_report):
    result, out = full_report
    doc = json.loads((out / "result.json").read_text(encoding="utf-8"))
    assert doc["schema"] == "esp.result/1"
    assert set(doc) == {"schema", "machine", "analysis", "cases", "worst", "uncertainty", "sweep"}
    assert set(doc["uncertainty"]) >= {"method", "k", "volumetric_um", "at", "axes", "budget"}
    assert set(doc["uncertainty"]["montecarlo"]) == {
        "mean_um",
        "std_um",
        "interval_um",
        "samples",
        "seed",
    }
    assert len(doc["cases"]) == 2 and len(doc["sweep"]) == 2 * 4


def test_csv_files(full_report):
    result, out = full_report
    with open(out / "extremes.csv", encoding="utf-8", newline="") as fh:
        rows = list(csv.reader(fh))
    assert tuple(rows[0]) == EXTREMES_COLUMNS
    with open(out / "terms.csv", encoding="utf-8", newline="") as fh:
        terms = list(csv.DictReader(fh))
    assert tuple(terms[0]) == TERMS_COLUMNS
    n_terms = sum(len(b.terms) for c in result.cases for b in c.breakdowns)
    assert len(terms) == n_terms
    with open(out / "grid.csv", encoding="utf-8", newline="") as fh:
        grid = list(csv.reader(fh))
    assert tuple(grid[0]) == GRID_COLUMNS
    assert len(grid) - 1 == 5 * 5 * 3
    # the grid's largest volumetric error is the worst case's volumetric accuracy
    worst = max(float(r[-1]) for r in grid[1:])
    assert worst == pytest.approx(result.cases[result.worst].volumetric.value_um, abs=1e-6)


def test_same_input_gives_the_same_bytes(tmp_path):
    result = result_of(small())
    a, b = tmp_path / "a", tmp_path / "b"
    bundle.write_report(result, a, date=DATE)
    bundle.write_report(result, b, date=DATE)
    for path in sorted(a.iterdir()):
        assert path.read_bytes() == (b / path.name).read_bytes(), path.name


def test_failure_while_writing_leaves_no_partial_report(tmp_path, monkeypatch):
    result = result_of(small())

    def broken(*args, **kwargs):
        raise RuntimeError("plot failed")

    monkeypatch.setattr(plots, "terms_figure", broken)
    out = tmp_path / "new"
    with pytest.raises(RuntimeError):
        bundle.write_report(result, out, date=DATE)
    assert not out.exists()
    assert [p.name for p in tmp_path.iterdir()] == []  # no staging folder left either
    # an earlier report survives a failed rewrite untouched
    monkeypatch.undo()
    old = tmp_path / "old"
    bundle.write_report(result, old, date=DATE)
    before = {p.name: p.read_bytes() for p in old.iterdir()}
    monkeypatch.setattr(plots, "terms_figure", broken)
    with pytest.raises(RuntimeError):
        bundle.write_report(result, old, date=DATE)
    assert {p.name: p.read_bytes() for p in old.iterdir()} == before


def write_machine(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "machine.toml"
    path.write_text(text, encoding="utf-8")
    return path


TOML = """
[machine]
name = "CLI report"
configuration = "wBMTt"
axes = { bottom = "X", middle = "Y", top = "Z" }
[axes.X]
travel = [0, 200]
step = 100
[axes.X.errors]
linear = { points = [[0, 0.0], [200, 3.0]] }
[axes.Y]
travel = [0, 200]
step = 100
[axes.Z]
travel = [0, 200]
step = 100
"""


def test_cli_out_and_grid_csv(tmp_path):
    machine = write_machine(tmp_path, TOML)
    out = tmp_path / "report"
    res = CliRunner().invoke(main, ["analyse", str(machine), "--out", str(out), "--grid-csv"])
    assert res.exit_code == 0, res.output
    assert (out / "report.pdf").exists() and (out / "grid.csv").exists()
    assert "Volumetric accuracy: 3.000 µm" in res.output


def test_cli_refuses_a_folder_that_is_not_a_report(tmp_path):
    machine = write_machine(tmp_path, TOML)
    mine = tmp_path / "mine"
    mine.mkdir()
    (mine / "notes.txt").write_text("keep me", encoding="utf-8")
    res = CliRunner().invoke(main, ["analyse", str(machine), "--out", str(mine)])
    assert res.exit_code == 2 and "not replaced" in res.output
    assert [p.name for p in mine.iterdir()] == ["notes.txt"]


def test_cli_refuses_a_grid_csv_of_a_large_grid_before_any_work(tmp_path):
    machine = write_machine(tmp_path, TOML.replace("step = 100", "step = 1"))
    out = tmp_path / "report"
    res = CliRunner().invoke(main, ["analyse", str(machine), "--out", str(out), "--grid-csv"])
    assert res.exit_code == 2 and "grid CSV refused" in res.output
    assert not out.exists()


def test_cli_grid_csv_needs_out(tmp_path):
    machine = write_machine(tmp_path, TOML)
    res = CliRunner().invoke(main, ["analyse", str(machine), "--grid-csv"])
    assert res.exit_code == 2
