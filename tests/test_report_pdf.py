"""The PDF report: its contents list, its date, its fixed metadata (esp.volumetric.pdf)."""

from __future__ import annotations

import re
import shutil
import subprocess
from pathlib import Path

import pytest

from esp.config import load_machine
from esp.core.analysis import analyse
from esp.report import document
from esp.volumetric import pdf
from esp.volumetric import report as bundle

DATA = Path(__file__).parent / "data" / "reports"
DATE = "2026-01-02"


@pytest.fixture(scope="module")
def sweep_result():
    """Two tool lengths (two tool cases), so the contents list two breakdown sections."""
    return analyse(load_machine(DATA / "sweep" / "machine.toml"))


def contents_of(pages) -> list[tuple[int, str]]:
    """The (page, entry) rows of the contents: the right-aligned page numbers after the
    heading "Contents", each with the entry beside it, up to the heading "Inputs"."""
    items = []
    started = False
    for page in pages:
        for item in page.items:
            if not isinstance(item, pdf._Text):
                continue
            if item.text == "Contents":
                started = True
            elif started and item.text == "Inputs" and item.weight == "bold":
                started = False
                break
            elif started:
                items.append(item)
        if items and not started:
            break
    rows = []
    for k, item in enumerate(items[:-1]):
        if item.ha == "right" and item.text.isdigit():
            rows.append((int(item.text), items[k + 1].text.strip(), item.x_in))
    # two columns: the left column's rows first
    return [(p, e) for p, e, _ in sorted(rows, key=lambda r: (r[2], 0))] if rows else []


def test_contents_give_the_page_of_every_section_and_figure(sweep_result):
    titles = [s.title for s in bundle.figure_specs(sweep_result)]
    pages = pdf.text_pages(sweep_result, DATE, titles)
    rows = contents_of(pages)
    assert len(rows) == 1 + len(sweep_result.cases) + len(titles)
    # each section begins its page with its heading
    inputs_page, inputs = rows[0]
    assert inputs == "Inputs" and "Inputs" in pages[inputs_page - 1].texts()
    for n, (page, entry) in enumerate(rows[1 : 1 + len(sweep_result.cases)]):
        assert entry.startswith(f"Extremes and their terms, tool case {n + 1}: tool ")
        heading = f"Extremes and their terms: tool case {n + 1} of {len(sweep_result.cases)}"
        assert heading in pages[page - 1].texts()
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
    # no [uncertainty] table: said in the summary, beside no figure
    assert "Uncertainty: not evaluated (no [uncertainty] table)." in first


@pytest.mark.slow
def test_pdf_has_fixed_metadata_and_no_creation_date(sweep_result, tmp_path):
    meta = pdf.pdf_metadata(sweep_result)
    assert meta["CreationDate"] is None and meta["Creator"].startswith("esp ")
    path = tmp_path / "r.pdf"
    count = pdf.write_pdf(path, sweep_result, [], [], DATE)
    data = path.read_bytes()
    assert b"/CreationDate" not in data and b"(esp " in data  # Creator and Producer
    prov = pdf.report_provenance(sweep_result)  # the last pages: what the report is made from
    assert (
        len(re.findall(rb"/Type\s*/Page\b", data))
        == count
        == len(pdf.text_pages(sweep_result, DATE, provenance=prov))
        + len(document.provenance_pages(prov))
    )


@pytest.mark.slow
def test_figures_and_titles_must_match(sweep_result, tmp_path):
    path = tmp_path / "r.pdf"
    with pytest.raises(ValueError, match="figure titles"):
        pdf.write_pdf(path, sweep_result, [], ["a missing figure"], DATE)
    assert not path.exists() and list(tmp_path.iterdir()) == []


@pytest.mark.slow
def test_text_pages_are_helvetica_and_formulae_embedded(sweep_result, tmp_path):
    """The text pages use the PDF core font Helvetica (not embedded); the term symbols,
    and any text Helvetica's encoding cannot hold, the embedded DejaVu Sans."""
    path = tmp_path / "r.pdf"
    pdf.write_pdf(path, sweep_result, [], [], DATE)
    data = path.read_bytes()
    assert b"/BaseFont /Helvetica" in data and b"/BaseFont /Helvetica-Bold" in data
    assert b"DejaVuSans" in data  # the formula column of the breakdown tables


def test_core_encodable():
    assert pdf._core_encodable("X.linear (EXX) µm/m · 3 °C …")
    assert not pdf._core_encodable("+Φ_M(B)·T") and not pdf._core_encodable("★")


@pytest.mark.slow
@pytest.mark.skipif(shutil.which("pdftotext") is None, reason="needs pdftotext (poppler)")
def test_no_character_is_lost_to_the_core_font(sweep_result, tmp_path):
    """Text the core font cannot show (★, Greek letters, a name in another script) is
    drawn in the embedded font, never replaced by "?"."""
    specs = bundle.figure_specs(sweep_result)
    path = tmp_path / "r.pdf"
    pdf.write_pdf(path, sweep_result, (s.build() for s in specs), [s.title for s in specs], DATE)
    text = subprocess.run(
        ["pdftotext", str(path), "-"], capture_output=True, text=True, check=True
    ).stdout
    assert "?" not in text
    assert "µm" in text and "°" in text
    import matplotlib as mpl

    if mpl.__version_info__ >= (3, 11):  # before, a Type 3 glyph beyond 255 is a drawing
        assert "★" in text


def test_a_text_is_measured_in_the_font_it_is_drawn_in(tmp_path, monkeypatch):
    """A legend sizes its box by measuring its texts when it is drawn: one label beyond
    the core fonts' encoding ("↑") makes the page draw its figure in the embedded font,
    and every text must then be measured in that font too, or it runs out of its box. A
    figure whose words the core fonts hold is drawn, and measured, in Helvetica."""
    import matplotlib as mpl
    from matplotlib.backends import backend_pdf
    from matplotlib.backends.backend_pdf import PdfPages
    from matplotlib.figure import Figure

    pypdf = pytest.importorskip("pypdf")
    measured: dict[str, set[bool]] = {}
    drawn: dict[str, set[bool]] = {}
    base = backend_pdf.RendererPdf
    measure, draw = base.get_text_width_height_descent, base.draw_text

    def record_measure(self, s, prop, ismath):
        measured.setdefault(s, set()).add(bool(mpl.rcParams["pdf.use14corefonts"]))
        return measure(self, s, prop, ismath)

    def record_draw(self, gc, x, y, s, prop, angle, ismath=False, mtext=None):
        drawn.setdefault(s, set()).add(bool(mpl.rcParams["pdf.use14corefonts"]))
        return draw(self, gc, x, y, s, prop, angle, ismath, mtext)

    monkeypatch.setattr(base, "get_text_width_height_descent", record_measure)
    monkeypatch.setattr(base, "draw_text", record_draw)
    fig = Figure(figsize=(6, 4))
    ax = fig.add_subplot()
    ax.plot([0, 1], [0, 1], label="mean up ↑ (forward)")
    ax.plot([0, 1], [1, 0], label="bidirectional mean")
    ax.legend()
    ax.set_title("plain title")
    with PdfPages(tmp_path / "page.pdf") as out:
        document.save_page(out, fig)
    labels = ["mean up ↑ (forward)", "bidirectional mean", "plain title"]
    for label in labels:
        assert label in drawn, label
        assert measured[label] == drawn[label], label
    # the figure as a whole is drawn in the embedded font
    assert drawn["mean up ↑ (forward)"] == {False}
    assert drawn["bidirectional mean"] == {False}
    assert drawn["plain title"] == {False}
    reader = pypdf.PdfReader(str(tmp_path / "page.pdf"))
    fonts = reader.pages[0]["/Resources"]["/Font"]
    assert {fonts[f].get_object()["/Subtype"] for f in fonts} == {"/Type3"}
    drawn.clear()
    measured.clear()
    ax.get_legend().get_texts()[0].set_text("mean up (forward)")
    with PdfPages(tmp_path / "core.pdf") as out:
        document.save_page(out, fig)
    assert drawn["plain title"] == drawn["mean up (forward)"] == {True}
    assert measured["mean up (forward)"] == {True}
    fonts = pypdf.PdfReader(str(tmp_path / "core.pdf")).pages[0]["/Resources"]["/Font"]
    assert "/Helvetica" in {fonts[f].get_object()["/BaseFont"] for f in fonts}


def test_a_direction_no_term_acts_in_takes_one_line():
    """The turning centre has no Y axis and no term acts in Y: one line says so instead of
    a heading, two empty breakdowns and their notes."""
    config = Path(__file__).parent.parent / "data/examples/turning-centre/machine-mcp.toml"
    pages = pdf.text_pages(analyse(load_machine(config)), DATE)
    texts = [t for p in pages for t in p.texts()]
    assert "Y direction: no active term acts in it; zero over the whole volume" in texts
    assert not any(t.strip() in ("Y minimum", "Y maximum") for t in texts)
    assert "No active term acts in this direction." not in texts
    assert any(t.startswith("X direction: minimum") for t in texts)  # X and Z as before
    assert any(t.strip() == "Z maximum" for t in texts)


def test_a_caption_keeps_the_core_font_it_was_wrapped_by_on_an_embedded_figure(tmp_path):
    """A figure with a word beyond the core fonts (★) is drawn in the embedded font as a
    whole, but its caption and footer, wrapped by Helvetica's widths, are drawn in
    Helvetica: drawn wider, a caption filling its line would run off the page."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.backends.backend_pdf import PdfPages
    from matplotlib.figure import Figure

    pypdf = pytest.importorskip("pypdf")
    fig = Figure(figsize=(8.0, 5.0))
    FigureCanvasAgg(fig)
    fig.add_subplot().set_title("worst point (★)")
    caption = "Figure 1: " + "a long caption of the figure " * 6
    document.add_footer(fig, "a machine · a report", 1, 1, caption=caption)
    with PdfPages(tmp_path / "page.pdf") as out:
        document.save_page(out, fig)
    fonts: dict[str, set[str]] = {}

    def visit(text, cm, tm, font, size):
        if text.strip() and font is not None:
            fonts.setdefault(text.strip(), set()).add(str(font.get("/BaseFont", "/Type3")))

    pypdf.PdfReader(str(tmp_path / "page.pdf")).pages[0].extract_text(visitor_text=visit)
    assert fonts["page 1 of 1"] == {"/Helvetica"}
    assert fonts["a machine · a report"] == {"/Helvetica"}
    lines = [t for t in fonts if t.startswith("Figure 1:") or t.startswith("caption")]
    assert lines and all(fonts[t] == {"/Helvetica"} for t in lines)
    assert all("/Helvetica" not in f for t, f in fonts.items() if "★" in t or "worst" in t)


def test_the_budget_page_says_what_makes_each_components_u():
    """The gantry example's budget: each component's contributors beside the budget, in
    the order of the budget, and a U's contributor u = U / k."""
    result = analyse(
        load_machine(Path(__file__).parent.parent / "data/examples/gantry/machine.toml")
    )
    pages = pdf.text_pages(result, DATE)
    page = next(p.texts() for p in pages if "Uncertainty budget" in p.texts())
    assert "What makes each component's uncertainty" in page
    first = result.uncertainty.budget[0]  # Y.linear, U = 2.3 µm at Y = 1500, k = 2
    (only,) = first.contributors
    assert only.name == "given directly (U / k)" and only.u == pytest.approx(1.15)
    assert "given directly (U / k)" in page and "1.150" in page
