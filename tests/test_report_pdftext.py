"""The strings of a PDF text page (:class:`esp.report.document.TextBlock`, measured by
:mod:`esp.report.pdftext`): a reader extracts them as given, placed where they were laid
out (a right-aligned string ends at its x), measured as they are drawn, in their colour
and at full opacity, and the same bytes each time.

The widths are the Adobe metrics of the core fonts (the AFM files matplotlib ships,
``Helvetica.afm``: A and V 667, quotesingle 191, mu 556, Euro 556, emdash 1000,
twosuperior 333; ``Helvetica-Bold.afm``: A 722; Courier 600 for every glyph)."""

from __future__ import annotations

import re
import shutil
import subprocess
import sys
from pathlib import Path

import matplotlib as mpl
import pytest
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.backends.backend_pdf import PdfPages
from matplotlib.figure import Figure
from matplotlib.patches import Rectangle

from esp.report import document as d
from esp.report import pdftext

pypdf = pytest.importorskip("pypdf")

from pdf_helpers import page_texts  # noqa: E402  # after the check that pypdf is there

ROOT = Path(__file__).resolve().parent.parent
#: matplotlib writes a character beyond the first 256 of an embedded Type 3 font as a
#: drawing, not as text, before 3.11 ("Improved font embedding in PDF", its release
#: notes): the page shows it, a reader does not extract it
MULTIBYTE_TEXT = mpl.__version_info__ >= (3, 11)

# -- the pieces -------------------------------------------------------------------------------


def test_advance_is_the_sum_of_the_glyph_widths_without_kerning():
    # Helvetica kerns A V by -70, but a string shown by Tj (as matplotlib shows a core
    # font's string) is not kerned: it advances by the widths alone
    assert pdftext.advance("AV", "Helvetica") == 667 + 667
    # the WinAnsi glyph of each byte: ' is quotesingle (191), not StandardEncoding's
    # quoteright (222); µ € — ² by their names, though matplotlib's table lacks some
    assert pdftext.advance("'", "Helvetica") == 191
    assert pdftext.advance("µ€—²", "Helvetica") == 556 + 556 + 1000 + 333
    assert pdftext.advance("A", "Helvetica-Bold") == 722
    assert pdftext.advance("key = 'v' # (é)", "Courier") == 15 * 600
    assert pdftext.advance("", "Helvetica") == 0
    assert pdftext.advance("★", "Helvetica") is None
    assert pdftext.advance("ab Φ", "Helvetica") is None


def test_string_width_in_is_the_advance_of_the_string_as_drawn():
    text = "Range (X) — 16.686 µm, it's 3 °C"
    units = pdftext.advance(text, "Helvetica")
    assert units is not None
    assert d.string_width_in(text, 9.5) == pytest.approx(units * 9.5 / 1000 / 72, rel=1e-12)
    bold = pdftext.advance(text, "Helvetica-Bold")
    assert bold is not None
    assert d.string_width_in(text, 13.0, "bold") == pytest.approx(bold * 13 / 1000 / 72)
    assert d.string_width_in("abc", 10.0, mono=True) == pytest.approx(3 * 0.6 * 10 / 72)
    # beyond the core fonts: the generous estimate for the embedded font
    assert d.string_width_in("ΦΦ", 10.0) == pytest.approx(2 * 0.62 * 10 / 72)


def test_core_font():
    assert pdftext.core_font() == "Helvetica"
    assert pdftext.core_font("bold") == "Helvetica-Bold"
    assert pdftext.core_font("bold", mono=True) == "Courier"


def test_the_widths_are_read_from_the_font_matplotlib_draws_with():
    """The metrics are those of the AFM file matplotlib's font finder gives for the
    properties the string is drawn with (a regular face is "medium" in them)."""
    from matplotlib.font_manager import findfont

    for font in ("Helvetica", "Helvetica-Bold", "Courier"):
        path = findfont(pdftext.font_properties(font, 9.5), fontext="afm")
        assert path.endswith(".afm")
        assert Path(path).read_text(encoding="latin-1").count("C ") > 200
    assert pdftext.font_properties("Helvetica-Bold", 9.5).get_weight() == "bold"
    assert pdftext.font_properties("Helvetica", 9.5).get_size_in_points() == 9.5


# -- on a page --------------------------------------------------------------------------------

A4 = d.PAGE_PORTRAIT_IN
FORMULA = "+EBX·(Z+P_Z)"
RIGHT = 7.52  # the right edge of the right-aligned strings (inches)

#: (text, size, weight, colour, mono, formula): one string of each kind
LEFT = [
    ("a (b) c\\d", 9.5, "normal", "black", False, False),
    ("€ µ — it's ²", 9.5, "normal", "black", False, False),
    ("Heading (bold)", 13.0, "bold", "black", False, False),
    ("grey note", 8.3, "normal", "0.4", False, False),
    ("key = 'value' # (c)", 7.2, "normal", "black", True, False),
    ("ab Φ ★", 9.5, "normal", "black", False, False),  # beyond cp1252: embedded
    (FORMULA, 9.5, "normal", "black", False, True),
]


def _page(n: int) -> d.TextPage:
    items: list = []
    for k, (text, size, weight, colour, mono, formula) in enumerate(LEFT):
        y = 1.0 + 0.3 * k
        items.append(d._Text(0.75, y, text, size, weight, colour, "left", formula, mono))
        right = f"{text} {n}" if not formula else text
        items.append(d._Text(RIGHT, y, right, size, weight, colour, "right", formula, mono))
    items.append(d._Rule(0.75, RIGHT, 4.0))
    return d.TextPage(items, A4)


def _write(path: Path, pages: int = 2) -> int:
    return d.write_document(
        path,
        [_page(n) for n in range(pages)],
        footer="a test document · 2026-01-01",
        meta=d.metadata("test"),
    )


@pytest.fixture(scope="module")
def written(tmp_path_factory) -> Path:
    path = tmp_path_factory.mktemp("pdftext") / "page.pdf"
    assert _write(path) == 2
    return path


def test_every_string_is_extracted_as_given_where_it_was_laid_out(written):
    height = A4[1] * 72
    for n, found in enumerate(page_texts(written)):
        for k, (text, size, weight, _, mono, formula) in enumerate(LEFT):
            y = height - (1.0 + 0.3 * k) * 72
            row = sorted((x, t) for x, yy, t in found if abs(yy - y) < 1e-6)
            right = text if formula else f"{text} {n}"
            if not MULTIBYTE_TEXT and any(ord(c) > 255 for c in text):
                continue
            # what a reader extracts: the two strings, as given (a string in the
            # embedded font may come in pieces, one per run of glyphs)
            assert "".join(t for _, t in row).replace(" ", "") == (text + right).replace(" ", "")
            assert row[0][0] == pytest.approx(0.75 * 72, abs=1e-6)
            units = pdftext.advance(right, pdftext.core_font(weight, mono))
            if units is not None and not formula:  # a right-aligned core string ends at x
                assert row[1] == (pytest.approx(RIGHT * 72 - units * size / 1000, abs=1e-6), right)
        footer = [t for *_, t in found if t.startswith("page ")]
        assert footer == [f"page {n + 1} of 2"]


@pytest.mark.skipif(shutil.which("pdftotext") is None, reason="needs pdftotext (poppler)")
@pytest.mark.skipif(not MULTIBYTE_TEXT, reason="a Type 3 glyph beyond 255 is no text before 3.11")
def test_a_right_aligned_string_ends_at_its_x_by_another_readers_metrics(written):
    """poppler measures the words with its own copy of the core fonts' metrics (and
    DejaVu Sans's from the embedded font): the last word of every right-aligned string
    ends at the right edge, to well under a point."""
    html = subprocess.run(
        ["pdftotext", "-bbox", "-f", "1", "-l", "1", str(written), "-"],
        capture_output=True,
        text=True,
        check=True,
    ).stdout
    word = r'<word xMin="[\d.]+" yMin="([\d.]+)" xMax="([\d.]+)"[^>]*>(.*?)</word>'
    words = re.findall(word, html)
    rows: dict[int, float] = {}
    for y, x_max, _ in words:
        rows[round(float(y))] = max(rows.get(round(float(y)), 0.0), float(x_max))
    ends = sorted(rows.values())[-len(LEFT) :]  # the right ends of the seven rows
    assert ends == pytest.approx([RIGHT * 72] * len(LEFT), abs=0.05)
    text = subprocess.run(
        ["pdftotext", str(written), "-"], capture_output=True, text=True, check=True
    ).stdout
    for line, *_ in LEFT:
        assert line in text


def test_the_same_pages_give_the_same_bytes(written, tmp_path, monkeypatch):
    again = tmp_path / "again.pdf"
    _write(again)
    assert again.read_bytes() == written.read_bytes()
    monkeypatch.setenv("SOURCE_DATE_EPOCH", "1767312000")
    dated = [tmp_path / "a.pdf", tmp_path / "b.pdf"]
    for path in dated:
        _write(path)
    assert dated[0].read_bytes() == dated[1].read_bytes()


def _drawn_state(path: Path, page: int = 0) -> list[tuple[str, float, tuple[float, ...]]]:
    """Every string shown on a page (and every fill) with the fill opacity and colour it
    is drawn in, following the content stream's graphics state (q, Q, gs, rg, g)."""
    reader = pypdf.PdfReader(str(path))
    pg = reader.pages[page]
    states = pg["/Resources"].get("/ExtGState", {})
    content = pypdf.generic.ContentStream(pg.get_contents(), reader)
    alpha, colour = 1.0, (0.0, 0.0, 0.0)
    stack: list[tuple[float, tuple[float, ...]]] = []
    shown = []
    for operands, op in content.operations:
        if op == b"q":
            stack.append((alpha, colour))
        elif op == b"Q":
            alpha, colour = stack.pop()
        elif op == b"gs":
            alpha = float(states[operands[0]].get_object().get("/ca", alpha))
        elif op == b"rg":
            colour = tuple(float(v) for v in operands)
        elif op == b"g":
            colour = (float(operands[0]),) * 3
        elif op == b"Tj":
            shown.append((str(operands[0]), alpha, colour))
        elif op == b"TJ":  # the embedded font's glyphs: their codes, not text
            shown.append(("(glyphs)", alpha, colour))
        elif op in (b"f", b"f*", b"F", b"B", b"B*", b"b", b"b*"):
            shown.append(("(fill)", alpha, colour))
    return shown


def test_each_string_is_in_its_colour_and_opaque_whatever_was_drawn_before(tmp_path):
    """The footer of a figure page is drawn after the figure: a translucent red patch drawn
    just before (on the figure, unclipped: its state is not restored after it) must not
    leave its opacity or colour to the footer, nor to a string in the embedded font."""
    path = tmp_path / "figure.pdf"
    with PdfPages(path) as pdf:
        for page, translucent in ((1, False), (2, True)):
            fig = Figure(figsize=(8.0, 5.0))
            FigureCanvasAgg(fig)
            if translucent:
                box = Rectangle((0.1, 0.1), 0.5, 0.5, transform=fig.transFigure, zorder=-1)
                box.set(color="red", alpha=0.3)
                fig.add_artist(box)
            # a block of a string in the embedded font alone, drawn next
            note = d.TextBlock([d._Text(0.75, 4.0, "a note ★", 8.0)], 5.0)
            note.set_zorder(-0.5)
            fig.add_artist(note)
            d.add_footer(fig, "a test document", page, 2, caption="Figure 1: a caption ★")
            d.save_page(pdf, fig)
    drawn = _drawn_state(path, page=1)
    assert ("(fill)", 0.3, (1.0, 0.0, 0.0)) in drawn  # the patch, drawn before the footer
    shown = {text: (alpha, colour) for text, alpha, colour in drawn}
    assert shown["page 2 of 2"] == (1.0, (0.4, 0.4, 0.4))
    assert shown["a test document"] == (1.0, (0.4, 0.4, 0.4))
    # the note and the caption, beyond the core fonts: in the embedded font
    glyphs = [(alpha, colour) for text, alpha, colour in drawn if text == "(glyphs)"]
    assert glyphs and set(glyphs) == {(1.0, (0.0, 0.0, 0.0))}


def test_the_settings_are_restored_after_a_page(tmp_path):
    before = (mpl.rcParams["pdf.use14corefonts"], mpl.rcParams["axes.unicode_minus"])
    fig = d.render_text(_page(0))
    with PdfPages(tmp_path / "p.pdf") as pdf:
        d.save_page(pdf, fig)
    assert (mpl.rcParams["pdf.use14corefonts"], mpl.rcParams["axes.unicode_minus"]) == before


# -- the embedded font's types ----------------------------------------------------------------

_FONTTYPES = """
import sys
import matplotlib as mpl
from esp.report import document as d

page = d.TextPage([d._Text(0.75, 1.0, "plain (core)", 9.5), d._Text(0.75, 1.5, "Φ beyond", 9.5)])
d.write_document(sys.argv[1], [page], footer="f", meta=d.metadata("t"))
mpl.rcParams["pdf.fonttype"] = 42  # TrueType embedded as Type 42: subset by fontTools
d.write_document(sys.argv[2], [page], footer="f", meta=d.metadata("t"))
print("ok")
"""


@pytest.mark.slow
def test_a_document_is_written_with_the_embedded_font_as_type_3_or_type_42(tmp_path):
    """matplotlib's default embeds DejaVu Sans as Type 3; with ``pdf.fonttype`` 42 it is a
    subset TrueType font: either way the page says what was laid out."""
    type3, type42 = tmp_path / "type3.pdf", tmp_path / "type42.pdf"
    run = subprocess.run(
        [sys.executable, "-c", _FONTTYPES, str(type3), str(type42)],
        capture_output=True,
        text=True,
        cwd=ROOT,
    )
    assert run.returncode == 0 and run.stdout.strip() == "ok", run.stderr
    for path in (type3, type42):
        text = pypdf.PdfReader(str(path)).pages[0].extract_text()
        assert "plain (core)" in text and "beyond" in text
        assert "Φ beyond" in text or not MULTIBYTE_TEXT
    assert b"/FontFile2" in type42.read_bytes()  # the subset TrueType font, embedded
    assert b"/Type3" in type3.read_bytes()


def test_a_document_leaves_older_objects_out_of_the_collector_and_hands_them_back(
    tmp_path, monkeypatch
):
    """While a document is written the objects older than it are frozen out of the
    collector's passes; afterwards, after an error too, none is frozen; a freeze made by
    the caller is left as it was; a cycle made while writing is still collected."""
    import gc
    import weakref

    seen: list[int] = []
    save_page = d.save_page

    def record(pdf, fig):
        seen.append(gc.get_freeze_count())
        save_page(pdf, fig)

    monkeypatch.setattr(d, "save_page", record)
    assert gc.get_freeze_count() == 0
    _write(tmp_path / "a.pdf")
    assert seen and min(seen) > 0 and gc.get_freeze_count() == 0

    class Cycle:
        pass

    def figures():
        made = Cycle()
        made.me = made  # a cycle made while the document is written
        gone.append(weakref.ref(made))
        del made
        gc.collect()
        yield from ()

    gone: list = []
    d.write_document(
        tmp_path / "b.pdf", [_page(0)], footer="f", meta=d.metadata("t"), figures=figures()
    )
    assert gone and gone[0]() is None

    def broken():
        raise RuntimeError("a figure failed")
        yield

    with pytest.raises(RuntimeError):
        d.write_document(
            tmp_path / "c.pdf", [_page(0)], footer="f", meta=d.metadata("t"), figures=broken()
        )
    assert gc.get_freeze_count() == 0
    gc.freeze()  # the caller's own freeze
    try:
        frozen = gc.get_freeze_count()
        _write(tmp_path / "d.pdf")
        assert 0 < gc.get_freeze_count() <= frozen  # still frozen (some may be freed)
    finally:
        gc.unfreeze()
