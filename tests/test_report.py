"""The report folder of ``esp analyse --out``: files, pages, pictures, atomicity, the same
bytes whatever the number of processes, and the date of ``SOURCE_DATE_EPOCH``."""

from __future__ import annotations

import csv
import json
import os
import re
import struct
import sys
from pathlib import Path

import pytest
from click.testing import CliRunner

import esp.volumetric.plots as plots
import esp.volumetric.report as bundle
from esp.cli import main
from esp.config import machine_from_dict
from esp.core.analysis import analyse
from esp.core.errors import DataError
from esp.core.rounding import rounded
from esp.volumetric import pdf
from esp.volumetric.export import EXTREMES_COLUMNS, GRID_COLUMNS, TERMS_COLUMNS
from esp.volumetric.text import render_result

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
            # the rest by kind: every component the model uses has a U
            "default": {"linear": 1.0, "straightness": 1.5, "angular": 2.0},
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


def expected_pages(result, titles=()) -> int:
    """The pages of the report of ``result``: its text pages, one per figure, and the
    provenance of the files it was read from (none for a machine built in code)."""
    from esp.report.document import provenance_pages

    prov = pdf.report_provenance(result) if result.machine.inputs else None
    tail = provenance_pages(prov) if prov is not None else []
    return len(pdf.text_pages(result, DATE, titles, provenance=prov)) + len(titles) + len(tail)


def folder_bytes(folder: Path) -> dict[str, bytes]:
    return {p.name: p.read_bytes() for p in sorted(folder.iterdir())}


@pytest.fixture(scope="module")
def full_report(tmp_path_factory):
    """One report with every kind of figure (a sweep and a Monte Carlo uncertainty), made
    in one process; the tests of this module share it."""
    out = tmp_path_factory.mktemp("rep") / "report"
    result = result_of(small(sweep=True, uncertainty="montecarlo"))
    bundle.write_report(result, out, grid_csv=True, date=DATE, jobs=1)
    return result, out


@pytest.mark.slow
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
    # one input figure per axis with a component that has data (not squareness)
    assert {n for n in names if n.startswith("input-")} == {
        "input-X.png",
        "input-Y.png",
        "input-Z.png",
    }
    assert [n for n in names if n.startswith(".")] == [".esp-folder.json"]  # no temporary


@pytest.mark.slow
def test_pdf_has_the_text_pages_and_one_page_per_figure(full_report):
    result, out = full_report
    specs = bundle.figure_specs(result)
    text = pdf.text_pages(result, DATE, [s.title for s in specs])
    assert pdf_pages(out / "report.pdf") == expected_pages(result, [s.title for s in specs])
    # 4 maps, terms, sweep, budget, Monte Carlo histogram, and the inputs of 3 axes
    assert len(specs) == 8 + 3
    first = " ".join(text[0].texts())
    assert "Report test" in first and "Volumetric accuracy" in first and DATE in first
    # the uncertainty statement beside the headline figure of the summary
    assert "uncertainty" in first and ("U = " in first or "U ≤ " in first)


@pytest.mark.slow
def test_every_png_has_the_size_of_the_pdf_page(full_report):
    """One figure at one size: A4 landscape, 11.69 x 8.27 in at 100 dpi."""
    _, out = full_report
    for path in out.glob("*.png"):
        assert png_size(path) == (1169, 827), path.name


@pytest.mark.slow
def test_result_json_is_the_documented_contract(full_report):
    result, out = full_report
    doc = json.loads((out / "result.json").read_text(encoding="utf-8"))
    assert doc["schema"] == "esp.result/1"
    assert set(doc) == {"schema", "machine", "analysis", "cases", "worst", "uncertainty", "sweep"}
    assert set(doc["uncertainty"]) >= {"method", "k", "volumetric_um", "at", "axes", "budget"}
    # added: where the budget is evaluated (the point of the volumetric uncertainty)
    assert doc["uncertainty"]["budget_at"] == doc["uncertainty"]["at"]
    assert set(doc["uncertainty"]["montecarlo"]) >= {
        "mean_um",
        "std_um",
        "interval_um",
        "samples",
        "seed",
    }
    assert len(doc["cases"]) == 2 and len(doc["sweep"]) == 2 * 4


@pytest.mark.slow
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


def one_component() -> dict:
    """The smallest report: one component (X.linear), six figures."""
    data = small()
    data["axes"]["X"]["errors"] = {"linear": {"points": [[0, 0.0], [400, 4.0]]}}
    del data["axes"]["Y"]["errors"], data["axes"]["Z"]["errors"], data["squareness"]
    return data


@pytest.mark.slow
@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="workers fork on Linux")
def test_same_bytes_with_worker_processes(full_report, tmp_path):
    """The same result gives the same bytes in every file, written by one process (the
    fixture) and by three (the PNG and CSV files made by forked workers)."""
    result, first = full_report
    parallel = tmp_path / "parallel"
    timings: dict[str, float] = {}
    bundle.write_report(result, parallel, grid_csv=True, date=DATE, jobs=3, timings=timings)
    assert folder_bytes(parallel) == folder_bytes(first)
    assert {f"png {s.filename}" for s in bundle.figure_specs(result)} <= set(timings)


@pytest.mark.slow
def test_failure_while_writing_leaves_no_partial_report(full_report, tmp_path, monkeypatch):
    """A failure in the first figure stops the report before anything is moved into
    place; an earlier report survives it untouched."""
    _, old = full_report
    result = result_of(one_component())
    calls = []

    def broken(*args, **kwargs):
        calls.append(1)
        raise RuntimeError("plot failed")

    before = folder_bytes(old)
    monkeypatch.setattr(plots, "direction_maps_figure", broken)
    new = tmp_path / "new"
    with pytest.raises(RuntimeError, match="plot failed"):
        bundle.write_report(result, new, date=DATE, jobs=1)
    assert calls == [1]  # the first figure, so nothing else was drawn
    assert list(tmp_path.iterdir()) == []  # no report, no staging folder
    with pytest.raises(RuntimeError, match="plot failed"):
        bundle.write_report(result, old, date=DATE, jobs=1)
    assert folder_bytes(old) == before
    assert sorted(p.name for p in old.parent.iterdir()) == ["report"]


@pytest.mark.slow
@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="workers fork on Linux")
def test_failure_in_a_worker_process_leaves_no_partial_report(tmp_path, monkeypatch):
    """The error of a figure drawn by a worker is raised here, as it would be in one
    process, and nothing is written."""
    result = result_of(one_component())
    here = os.getpid()
    save_png = plots.save_png

    def broken_in_worker(fig, path, *args, **kwargs):
        if os.getpid() != here:
            raise RuntimeError("worker plot failed")
        save_png(fig, path, *args, **kwargs)

    monkeypatch.setattr(plots, "save_png", broken_in_worker)
    built = []
    direction_maps_figure = plots.direction_maps_figure

    def counted(*args, **kwargs):
        built.append(1)
        return direction_maps_figure(*args, **kwargs)

    monkeypatch.setattr(plots, "direction_maps_figure", counted)
    out = tmp_path / "new"
    with pytest.raises(RuntimeError, match="worker plot failed"):
        bundle.write_report(result, out, date=DATE, jobs=2)
    assert list(tmp_path.iterdir()) == []
    assert len(built) < len(bundle.figure_specs(result))  # raised before the PDF was done


@pytest.mark.slow
@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="workers fork on Linux")
def test_a_killed_worker_is_replaced_by_this_process(tmp_path, monkeypatch):
    """A worker that dies (as the out-of-memory killer would kill it) leaves its figures
    to this process: the report is complete."""
    result = result_of(one_component())
    here = os.getpid()
    save_png = plots.save_png

    def dies_in_worker(fig, path, *args, **kwargs):
        if os.getpid() != here:
            os._exit(9)
        save_png(fig, path, *args, **kwargs)

    monkeypatch.setattr(plots, "save_png", dies_in_worker)
    out = tmp_path / "out"
    bundle.write_report(result, out, date=DATE, jobs=2)
    specs = bundle.figure_specs(result)
    assert {s.filename for s in specs} | {"report.pdf", "extremes.csv", "terms.csv"} <= {
        p.name for p in out.iterdir()
    }
    for spec in specs:
        assert png_size(out / spec.filename) == (1169, 827)
    assert pdf_pages(out / "report.pdf") == expected_pages(result, [s.title for s in specs])


@pytest.mark.slow
def test_progress_names_every_file_and_figure_once(tmp_path):
    """The builder tells its caller of each file as it is done: the JSON, the CSV files,
    every figure (by its PNG's name, in the order of the PDF) and the PDF."""
    result = result_of(one_component())
    labels: list[str] = []
    bundle.write_report(result, tmp_path / "out", date=DATE, progress=labels.append)
    figures = [s.filename for s in bundle.figure_specs(result)]
    assert labels == ["result.json", "extremes.csv", *figures, "report.pdf"]


def test_a_direction_zero_throughout_has_no_map_and_says_why():
    """A machine with errors only in X and Y (the linear errors of X and Y): the Z
    direction is zero over the whole volume, so map-Z is left out, and the skipped figure
    says so in one line; X and Y keep their maps."""
    data = small()
    data["axes"]["X"]["errors"] = {"linear": {"points": [[0, 0.0], [400, 4.0]]}}
    data["axes"]["Y"]["errors"] = {"linear": {"points": [[0, 0.0], [400, 2.0]]}}
    del data["axes"]["Z"]["errors"], data["squareness"]
    result = result_of(data)
    case = result.cases[result.worst]
    assert case.axes["Z"].minimum.value_um == case.axes["Z"].maximum.value_um == 0
    names = [s.filename for s in bundle.figure_specs(result)]
    assert "map-Z.png" not in names and {"map-X.png", "map-Y.png"} <= set(names)
    skipped = bundle.skipped_figures(result)
    assert [(s.filename, s.reason) for s in skipped] == [
        ("map-Z.png", "Z direction: zero over the whole volume; no figure")
    ]
    data = small()
    data["axes"]["Z"]["errors"]["linear"] = {"constant": 1.0}
    full = result_of(data)  # every direction has an error: nothing is skipped
    assert bundle.skipped_figures(full) == []
    names = [s.filename for s in bundle.figure_specs(full)]
    assert {"map-X.png", "map-Y.png", "map-Z.png"} <= set(names)


# -- SOURCE_DATE_EPOCH ------------------------------------------------------------------


@pytest.mark.parametrize("value", ["abc", "-5", "1e99", "99999999999999", "12.5", " 7 x"])
def test_malformed_source_date_epoch_is_one_line_naming_the_variable(value):
    with pytest.raises(DataError) as err:
        pdf.report_date({"SOURCE_DATE_EPOCH": value})
    message = str(err.value)
    assert message.startswith("SOURCE_DATE_EPOCH: expected a whole number of seconds")
    assert repr(value) in message and "\n" not in message


def test_source_date_epoch_in_range():
    # 365 days of 86 400 s after 1970-01-01 (not a leap year) is 1971-01-01
    assert pdf.report_date({"SOURCE_DATE_EPOCH": str(365 * 86400)}) == "1971-01-01"
    assert pdf.report_date({"SOURCE_DATE_EPOCH": " 0 "}) == "1970-01-01"
    assert pdf.report_date({"SOURCE_DATE_EPOCH": str(pdf.SOURCE_DATE_EPOCH_MAX)}) == "9999-12-31"
    with pytest.raises(DataError):
        pdf.report_date({"SOURCE_DATE_EPOCH": str(pdf.SOURCE_DATE_EPOCH_MAX + 1)})
    assert pdf.source_date_epoch({"SOURCE_DATE_EPOCH": ""}) is None  # empty: not set


@pytest.mark.parametrize("value", ["abc", "-5", "1e99", "99999999999999"])
def test_cli_refuses_a_malformed_source_date_epoch(tmp_path, monkeypatch, value):
    machine = write_machine(tmp_path, TOML)
    out = tmp_path / "report"
    monkeypatch.setenv("SOURCE_DATE_EPOCH", value)
    res = CliRunner().invoke(main, ["analyse", str(machine), "--out", str(out)])
    assert res.exit_code == 2
    assert res.stderr.startswith("esp: error: SOURCE_DATE_EPOCH: expected a whole number")
    assert len(res.stderr.splitlines()) == 1 and "Traceback" not in res.output
    assert not out.exists() and sorted(p.name for p in tmp_path.iterdir()) == ["machine.toml"]


# -- the command --------------------------------------------------------------------------


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


@pytest.mark.slow
def test_cli_out_and_grid_csv(tmp_path, monkeypatch):
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


# -- the terminal report --------------------------------------------------------------------


@pytest.mark.slow
def test_terminal_report_ends_with_the_headline(full_report):
    result, _ = full_report
    lines = render_result(result).splitlines()
    worst = result.cases[result.worst]
    unc = result.uncertainty
    # the figure and U rounded as GUM 7.2.6 says (esp.core.rounding, tested on its own)
    value, expanded = rounded(worst.volumetric.value_um, unc.volumetric.value_um)
    assert len(expanded.replace(".", "").lstrip("0")) == 2  # U to two significant digits
    assert lines[-3] == (
        f"Volumetric accuracy of Report test: {value} µm, U = {expanded} µm "
        "(k = 2, about 95 %) at " + ", ".join(f"{a}={worst.volumetric.at[a]:g}" for a in "XYZ")
    )
    assert lines[-2].startswith(f"  tool {worst.tool.length_mm:g} mm, tilt ")
    assert lines[-2].endswith("(the worst of 2 tool cases)")
    assert lines[-1].startswith(f"  uncertainty: U = {expanded} µm (k = 2, about 95 %")


def test_terminal_report_without_uncertainty_says_so():
    lines = render_result(result_of(small())).splitlines()
    assert lines[-2].startswith("Volumetric accuracy of Report test: ")
    assert lines[-1] == "  uncertainty: not evaluated (no [uncertainty] table)"


@pytest.mark.slow
def test_micrometre_is_spelled_one_way(full_report):
    """µm with the micro sign everywhere a person reads it: the terminal, the PDF's text
    pages, the figures; never "um" or the Greek letter mu."""
    result, _ = full_report
    texts = [render_result(result)]
    texts += [" ".join(p.texts()) for p in pdf.text_pages(result, DATE)]
    for spec in bundle.figure_specs(result):
        fig = spec.build()
        texts += [t.get_text() for t in pdf._figure_texts(fig)]
        texts += [a.colorbar.ax.get_ylabel() for a in fig.axes if getattr(a, "colorbar", None)]
    for text in texts:
        assert "μ" not in text  # Greek small letter mu
        assert not re.search(r"(?<![A-Za-z_])um(/m)?(?![A-Za-z_])", text), text
    assert any("µm/m" in t for t in texts) and any("µm" in t for t in texts)


# -- issue 17, items 3 and 6: a bound says so; a plan headlines its uncertainty ----------------


def plan_data(method: str = "statistical", sweep: bool = False) -> dict:
    """The machine of :func:`small` without its error data: U only (a plan). X.linear U 2 µm
    acts in X, squareness.XY U 3 µm/m in X with the lever Y (400 mm at most): at Y = 400 the
    X terms are 2 and 1.2 µm; statistical sqrt(2² + 1.2²) = 2.332 µm, summation 3.2 µm."""
    data = small(sweep=sweep, uncertainty=method)
    for a in ("X", "Y", "Z"):
        data["axes"][a].pop("errors", None)
    del data["squareness"]
    return data


@pytest.mark.parametrize("method, value", [("statistical", 2.332), ("summation", 3.2)])
def test_a_plan_headlines_its_uncertainty_in_text_json_and_pdf(method, value):
    from esp.volumetric.jsondoc import result_dict

    result = result_of(plan_data(method, sweep=True))
    u = result.uncertainty.volumetric.value_um
    assert u == pytest.approx(value, abs=5e-4)
    relation = "≤" if method == "summation" else "="
    text = render_result(result)
    last = text.rstrip("\n").split("=" * 78 + "\n")[-1].split("\n")  # the headline
    assert last[0].startswith("Volumetric uncertainty of Report test: U " + relation)
    assert last[1].startswith("  tool ") and "uncertainty plan" in last[2]
    # no accuracy claimed, no page of zeros
    assert "Volumetric accuracy" not in text and "Breakdown at" not in text
    assert "Total displacement error" not in text and "Sweep of" not in text
    doc = result_dict(result)
    assert doc["analysis"]["plan"] is True
    assert doc["worst"]["accuracy_um"] is None and doc["worst"]["uncertainty_um"] == u
    assert all(set(c) == {"tool", "grid_points"} for c in doc["cases"])
    assert "sweep" not in doc and doc["uncertainty"]["bound"] is (method == "summation")
    pages = pdf.text_pages(result, DATE)
    first = pages[0].texts()
    assert first[0] == "Volumetric uncertainty plan"
    assert any(t.startswith("Volumetric uncertainty  U " + relation) for t in first)
    every = [t for page in pages for t in page.texts()]
    assert not any("Volumetric accuracy" in t or "Extremes and their terms" in t for t in every)
    assert pdf.pdf_metadata(result)["Title"].startswith("Volumetric uncertainty plan")
    assert [s.filename for s in bundle.figure_specs(result)] == ["uncertainty-budget.png"]


def test_a_machine_with_errors_is_no_plan_and_its_bound_says_so():
    from esp.volumetric.jsondoc import result_dict

    result = result_of(small(uncertainty="summation"))
    text = render_result(result)
    assert "Volumetric accuracy of Report test:" in text
    assert "Volumetric uncertainty (an upper bound):" in text
    assert "uncertainty: U ≤ " in text and "summation bound" in text
    doc = result_dict(result)
    assert doc["analysis"]["plan"] is False and doc["uncertainty"]["bound"] is True
    assert doc["worst"]["accuracy_um"] == result.cases[result.worst].volumetric.value_um
    first = pdf.text_pages(result, DATE)[0].texts()
    assert first[0] == "Volumetric accuracy report"
    assert any("It is an upper bound" in t for t in first)
