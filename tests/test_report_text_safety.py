"""User text in a report -- a machine name, a file name, a serial -- is drawn literally in
every figure (a ``$`` is a dollar sign, never mathtext) and stays on one line in every
one-line output (the terminal report, the PDF's lines, titles and footers)."""

from __future__ import annotations

import json
import warnings
from pathlib import Path

import pytest
from test_report_plots import drawn_texts

from esp.config import load_machine
from esp.core.analysis import analyse
from esp.report.words import one_line
from esp.volumetric import pdf, plots
from esp.volumetric import report as bundle
from esp.volumetric.text import render_result

NAME = "Price $100 or $200\n$x^$ \\alpha_1 中"
DATA_FILE = "$x^$ run.csv"

TOML = f"""
[machine]
name = {json.dumps(NAME)}
serial = "S/N $5$\\u001b[31m"
location = "Hall\\t3"
measured_by = "A. User\\r\\nB. User"
configuration = "wBMTt"
axes = {{ bottom = "X", middle = "Y", top = "Z" }}

[axes.X]
travel = [0, 200]
step = 100
[axes.X.errors]
linear = {json.dumps(DATA_FILE)}
straightness = {{ Y = {{ points = [[0, 0.0], [100, 1.0], [200, 0.0]] }} }}

[axes.Y]
travel = [0, 200]
step = 100
[axes.Y.errors]
linear = {{ constant = 1.5 }}

[axes.Z]
travel = [0, 100]
step = 100
"""


@pytest.fixture(scope="module")
def result(tmp_path_factory):
    folder = tmp_path_factory.mktemp("text")
    (folder / "machine.toml").write_text(TOML, encoding="utf-8")
    (folder / DATA_FILE).write_text(
        "# unit: um\ntarget_mm,run,direction,deviation\n"
        "0,1,forward,0\n100,1,forward,2\n200,1,forward,3\n"
        "200,2,backward,3.5\n100,2,backward,2.5\n0,2,backward,0.5\n",
        encoding="utf-8",
    )
    return analyse(load_machine(folder / "machine.toml"))


def test_the_machine_is_read_with_its_odd_text(result):
    assert result.machine.name == NAME
    assert result.machine.components["X.linear"].source == DATA_FILE


@pytest.mark.slow
def test_every_figure_draws_user_text_literally(result, tmp_path, monkeypatch):
    """The whole report is written without an exception or a warning (a missing glyph is
    drawn as a box without a word), and every text of every figure is drawn as it reads:
    no mathtext anywhere."""
    figures = []
    save_png = plots.save_png

    def kept(fig, path, *args, **kwargs):
        figures.append((Path(path).name, fig))
        save_png(fig, path, *args, **kwargs)

    monkeypatch.setattr(plots, "save_png", kept)
    out = tmp_path / "report"
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        bundle.write_report(result, out, date="2026-01-02", jobs=1)
    assert (out / "report.pdf").read_bytes().startswith(b"%PDF")
    doc = json.loads((out / "result.json").read_text(encoding="utf-8"))
    assert doc["machine"]["name"] == NAME  # JSON keeps the text exactly
    assert len(figures) == len(bundle.figure_specs(result))
    seen = []
    for name, fig in figures:
        for text in drawn_texts(fig):
            content = text.get_text()
            _, mathtext = text._preprocess_math(content)
            assert mathtext is False, (name, content)
            seen.append(content)
    assert any(one_line(NAME) in t for t in seen)  # the name, on one line, as written
    assert any(DATA_FILE in t for t in seen)  # the file name, in its input panel
    assert not any("\n" in t and one_line(NAME)[:10] in t for t in seen)


def test_pdf_lines_are_one_line_each(result):
    pages = pdf.text_pages(result, "2026-01-02")
    texts = [t for page in pages for t in page.texts()]
    assert not any(ch in t for t in texts for ch in "\n\r\t\x1b")
    assert one_line(NAME) in texts  # the name under the title, escaped
    assert any("S/N $5$\\x1b[31m" in t for t in texts)
    assert pdf.pdf_metadata(result)["Title"].endswith(one_line(NAME))
    footer = pdf._footer_items(result, "2026-01-02", 1, 9, pdf.PAGE_LANDSCAPE_IN)
    assert footer[0].text.startswith(one_line(NAME) + " · ")


def test_terminal_report_keeps_every_row_on_one_line(result):
    text = render_result(result)
    assert "\x1b" not in text and "\r" not in text and "\t" not in text
    lines = text.splitlines()
    machine = [line for line in lines if line.startswith("Machine        : ")]
    assert len(machine) == 1 and one_line(NAME) in machine[0]
    assert "Measured by: A. User\\r\\nB. User" in machine[0]
    # the file name in the table of components, in one row with its component
    row = [line for line in lines if "X.linear" in line and DATA_FILE in line]
    assert len(row) == 1
    assert lines[-2].startswith(f"Volumetric accuracy of {one_line(NAME)}: ")


def test_one_line():
    assert one_line("a\nb\rc\td\x1b\x7f\x85\u2028e") == "a\\nb\\rc d\\x1b\\x7f\\x85\\u2028e"
    assert one_line("Fräse µm · ok") == "Fräse µm · ok"
    assert one_line(Path("x")) == "x"


BIDI = "\u202a\u202b\u202c\u202d\u202e\u2066\u2067\u2068\u2069\u200e\u200f\u061c"


def test_one_line_escapes_bidirectional_controls():
    assert one_line("abc\u202edef") == "abc\\u202edef"
    shown = one_line("x" + BIDI + "y")
    assert not any(ch in shown for ch in BIDI)
    assert shown == "x" + "".join(f"\\u{ord(c):04x}" for c in BIDI) + "y"


def test_bidi_controls_in_a_name_stay_out_of_the_terminal(tmp_path):
    from click.testing import CliRunner

    from esp.cli import main

    toml = TOML.replace(json.dumps(NAME), json.dumps("evil\u202etxt.exe\u2066x\u2069"))
    (tmp_path / "machine.toml").write_text(toml, encoding="utf-8")
    (tmp_path / DATA_FILE).write_text(
        "# unit: um\ntarget_mm,run,direction,deviation\n0,1,forward,0\n200,1,forward,3\n",
        encoding="utf-8",
    )
    runner = CliRunner()
    res = runner.invoke(main, ["analyse", str(tmp_path / "machine.toml")])
    assert res.exit_code == 0, res.output
    assert "evil\\u202etxt.exe\\u2066x\\u2069" in res.output
    assert not any(ch in res.output for ch in BIDI)


def test_bidi_controls_in_a_name_stay_out_of_summary_md():
    from esp.batch.run import BatchRow, summary_markdown

    row = BatchRow("m\u202e.toml", "m", name="evil\u202etxt.exe", configuration="wBMTt")
    summary = summary_markdown([row])
    assert "| m\\u202e.toml | evil\\u202etxt.exe | wBMTt |" in summary
    assert not any(ch in summary for ch in BIDI)
