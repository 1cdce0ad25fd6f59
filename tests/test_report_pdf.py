"""The PDF report: its contents list, its date, its fixed metadata (esp.report.pdf)."""

from __future__ import annotations

import datetime as dt
import re
from pathlib import Path

import pytest

from esp.analysis import analyse
from esp.config import load_machine
from esp.report import bundle, pdf

DATA = Path(__file__).parent / "data" / "reports"
DATE = "2026-01-02"


@pytest.fixture(scope="module")
def sweep_result():
    """Two tool lengths (two tool cases), so the contents list two breakdown sections."""
    return analyse(load_machine(DATA / "sweep" / "machine.toml"))


def contents_of(pages) -> list[tuple[int, str]]:
    """The (page, entry) rows of the contents: after the heading "Contents" and the two
    column headers on the first page, and after the repeated headers on the pages that
    continue it, up to the page of the inputs."""
    texts = pages[0].texts()
    cells = texts[texts.index("Contents") + 3 :]
    for page in pages[1:]:
        if page.texts()[0] == "Inputs":
            break
        cells += page.texts()[2:]
    return [(int(cells[k]), cells[k + 1].strip()) for k in range(0, len(cells) - 1, 2)]


def test_contents_give_the_page_of_every_section_and_figure(sweep_result):
    titles = [s.title for s in bundle.figure_specs(sweep_result)]
    pages = pdf.text_pages(sweep_result, DATE, titles)
    rows = contents_of(pages)
    assert len(rows) == 1 + len(sweep_result.cases) + len(titles)
    # each section begins its page with its heading
    inputs_page, inputs = rows[0]
    assert inputs == "Inputs" and pages[inputs_page - 1].texts()[0] == "Inputs"
    for n, (page, entry) in enumerate(rows[1 : 1 + len(sweep_result.cases)]):
        assert entry.startswith(f"Extremes and their terms, tool case {n + 1}: length")
        assert pages[page - 1].texts()[0].startswith("Extremes and their terms")
    # the figures follow the text pages, one per page, in the order given
    figures = rows[1 + len(sweep_result.cases) :]
    assert [p for p, _ in figures] == list(range(len(pages) + 1, len(pages) + 1 + len(titles)))
    assert [e for _, e in figures] == [f"Figure: {t}" for t in titles]


def test_first_page_holds_the_headline_figures(sweep_result):
    first = pdf.text_pages(sweep_result, DATE)[0].texts()
    worst = sweep_result.cases[sweep_result.worst]
    assert first[0] == "Volumetric accuracy report" and first[1] == "Sweep mill"
    assert f"Volumetric accuracy  {worst.volumetric.value_um:.3f} µm" in first
    assert any(DATE in t for t in first)
    assert "Not evaluated for this report." in first  # no [uncertainty] table


def test_report_date_follows_source_date_epoch():
    # 365 days of 86 400 s after 1970-01-01 (not a leap year) is 1971-01-01
    assert pdf.report_date({"SOURCE_DATE_EPOCH": str(365 * 86400)}) == "1971-01-01"
    assert pdf.report_date({"SOURCE_DATE_EPOCH": "0"}) == "1970-01-01"
    today = dt.date.today().isoformat()
    assert pdf.report_date({}) in (today, (dt.date.today() + dt.timedelta(days=1)).isoformat())
    # a value that is not a whole number of seconds is ignored
    assert pdf.report_date({"SOURCE_DATE_EPOCH": "soon"}) != "1970-01-01"


def test_pdf_has_fixed_metadata_and_no_creation_date(sweep_result, tmp_path):
    meta = pdf.pdf_metadata(sweep_result)
    assert meta["CreationDate"] is None and meta["Creator"].startswith("esp ")
    path = tmp_path / "r.pdf"
    count = pdf.write_pdf(path, sweep_result, [], [], DATE)
    data = path.read_bytes()
    assert b"/CreationDate" not in data and b"(esp " in data  # Creator and Producer
    assert (
        len(re.findall(rb"/Type\s*/Page\b", data))
        == count
        == len(pdf.text_pages(sweep_result, DATE))
    )


def test_figures_and_titles_must_match(sweep_result, tmp_path):
    path = tmp_path / "r.pdf"
    with pytest.raises(ValueError, match="figure titles"):
        pdf.write_pdf(path, sweep_result, [], ["a missing figure"], DATE)
    assert not path.exists() and list(tmp_path.iterdir()) == []
