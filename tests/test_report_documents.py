"""The one document style of every PDF (esp.report.document), checked mechanically on the
PDF files themselves with pypdf: every page carries "page n of N" with the right n and N,
no text lies outside the page, no table row stands on a page without its header, no page
holds only a few lines; the same input gives the same bytes.

Most tests build small documents directly through the builder; the ones that run a whole
command are marked slow.
"""

from __future__ import annotations

import copy
import re
import tomllib
from dataclasses import dataclass
from pathlib import Path

import pytest
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from esp.config import machine_from_dict
from esp.core.errors import ConfigError
from esp.report import document as d
from esp.report.tables import Column, Table

pypdf = pytest.importorskip("pypdf")

from pdf_helpers import page_texts  # noqa: E402  # after the check that pypdf is there

ROOT = Path(__file__).parent.parent
EXAMPLES = ROOT / "data" / "examples"
DATE = "2026-01-02"
FOOTER = re.compile(r"page (\d+) of (\d+)")


# -- a Provenance-shaped object (the interface of esp.report.provenance) ----------------------


@dataclass(frozen=True)
class Record:
    path: str
    sha256: str
    size_bytes: int
    kind: str
    user_text: tuple[tuple[str, str], ...] = ()
    environment: tuple[tuple[str, str], ...] = ()


@dataclass(frozen=True)
class Prov:
    esp_version: str
    command: tuple[str, ...]
    inputs: tuple[Record, ...]
    configuration: tuple[tuple[str, str], ...]


def provenance(files: int = 3, config_lines: int = 20) -> Prov:
    records = tuple(
        Record(
            f"data/a-rather-long-folder-name/with/sub/folders/X-straightness-Y-{k}.rtl",
            "ab" * 32,
            12345 + k,
            "laser10",
            user_text=(("Machine", "GX-1500"), ("Serial No", "GX15-0472"), ("By", "M. Weber")),
            environment=(("air temperature", "20.1 °C"), ("material temperature", "absent")),
        )
        for k in range(files)
    )
    text = "\n".join(f"key_{k} = {k}   # a comment" for k in range(config_lines))
    return Prov("0.0.0", ("analyse", "machine.toml", "--out", "r"), records, (("m.toml", text),))


# -- reading a PDF ----------------------------------------------------------------------------


def page_boxes(path: Path) -> list[tuple[float, float]]:
    reader = pypdf.PdfReader(str(path))
    return [(float(p.mediabox.width), float(p.mediabox.height)) for p in reader.pages]


def check_document(path: Path, min_lines: int = 4, tables: dict[str, str] | None = None) -> None:
    """The mechanical checks of issue 20 on one PDF: the footer of every page, every string
    inside its page, no page with fewer than ``min_lines`` lines of text (figure pages have
    their caption and footer), and every row of the tables named in ``tables`` (a cell
    that starts a row -> the header that must stand on its page) under its header."""
    texts = page_texts(path)
    boxes = page_boxes(path)
    total = len(texts)
    for n, (found, (width, height)) in enumerate(zip(texts, boxes, strict=True), start=1):
        footers = [FOOTER.search(t) for _, _, t in found]
        numbers = [(int(m.group(1)), int(m.group(2))) for m in footers if m]
        assert numbers == [(n, total)], (path.name, n, numbers)
        for x, y, t in found:
            assert -1 <= x <= width and -1 <= y <= height, (path.name, n, t, x, y)
            # the right edge: a generous estimate of the advance at 10 pt
            assert x + 0.3 * len(t) <= width + 1, (path.name, n, t, x)
        lines = {round(y) for _, y, _ in found}
        assert len(lines) >= min_lines, (path.name, n, sorted(t for *_, t in found))
        for first, header in (tables or {}).items():
            if any(t.startswith(first) for *_, t in found):
                assert any(t == header for *_, t in found), (path.name, n, first)


# -- the builder ------------------------------------------------------------------------------


def long_table(rows: int, long_names: bool = False) -> Table:
    name = "data/a-very-long-folder-name/with-sub-folders/X-straightness-Y-final-run.rtl"
    return Table(
        (Column("row", "left", 0.6), Column("source", "left", 1.6), Column("value", "right", 1)),
        tuple(
            (f"r{k}", name if long_names else f"file {k}", f"{k * 1.5:.3f}") for k in range(rows)
        ),
    )


def test_a_table_is_split_with_its_header_and_leaves_no_orphan_rows():
    for filler in range(0, 60, 3):  # wherever on the page the table begins
        lay = d.Layout()
        for k in range(filler):
            lay.line(f"line {k}")
        lay.heading("The table", level=2)
        lay.table(long_table(70))
        for page in lay.pages:
            texts = page.texts()
            rows = [t for t in texts if re.fullmatch(r"r\d+", t)]
            if rows:
                assert "row" in texts and "source" in texts  # the header on every page
                assert len(rows) >= d.MIN_TABLE_ROWS, (filler, rows)
        every = [t for p in lay.pages for t in p.texts() if re.fullmatch(r"r\d+", t)]
        assert every == [f"r{k}" for k in range(70)]  # each row once, in order


def test_a_table_kept_whole_moves_to_the_next_page_with_its_heading():
    for filler in range(20, 62, 4):
        lay = d.Layout()
        for k in range(filler):
            lay.line(f"line {k}")
        lay.heading("Budget", level=2)
        lay.table(long_table(30), keep_whole=True)
        pages = [p.texts() for p in lay.pages]
        with_rows = [k for k, texts in enumerate(pages) if "r0" in texts or "r29" in texts]
        assert len(set(with_rows)) == 1, filler  # every row on one page
        (k,) = set(with_rows)
        assert "Budget" in pages[k]  # its heading with it
        assert len(lay.pages) <= 2
    # a table longer than a page is split as any other
    lay = d.Layout()
    lay.line("a line above")
    lay.table(long_table(120), keep_whole=True)
    assert len(lay.pages) >= 2
    assert "r0" in lay.pages[0].texts()  # it starts under the line, not on a new page
    every = [t for p in lay.pages for t in p.texts() if re.fullmatch(r"r\d+", t)]
    assert every == [f"r{k}" for k in range(120)]


def test_text_report_sets_tables_and_two_column_lists_in_columns():
    text = (
        "format x: a format\n"
        "  tables (corrections in µm):\n"
        "    X.linear           21 points, error -7.294 .. +1.295 µm\n"
        "    X.straightness.Y   21 points, error -1.605 .. +1.149 µm\n"
        "  a sentence that stays a paragraph\n"
        "  direction  before  after\n"
        "  forward     34.26  13.16\n"
        "  backward    33.63  13.17\n"
    )
    lay = d.Layout()
    d.text_report(lay, text)
    items = [i for i in lay.pages[0].items if isinstance(i, d._Text)]
    at = {i.text: i for i in items}
    assert at["format x: a format"].weight == "bold"  # a heading
    # the two-cell lines: the values start at one x, right of the widest name
    first, second = (
        at["21 points, error -7.294 .. +1.295 µm"],
        at["21 points, error -1.605 .. +1.149 µm"],
    )
    assert first.x_in == second.x_in
    assert first.x_in > at["X.straightness.Y"].x_in + d.string_width_in("X.straightness.Y", d.SMALL)
    assert at["X.linear"].x_in == at["X.straightness.Y"].x_in
    assert at["a sentence that stays a paragraph"].x_in < first.x_in
    # the aligned run with a header: a table, its numbers right-aligned in a column
    assert at["before"].weight == "bold"
    assert at["34.26"].ha == at["33.63"].ha == "right" and at["34.26"].x_in == at["33.63"].x_in


def test_a_figure_laid_out_by_its_engine_keeps_a_margin_on_its_page():
    fig = Figure(figsize=(8.0, 4.8), layout="constrained")
    FigureCanvasAgg(fig)
    ax = fig.add_subplot(1, 1, 1)
    ax.plot([0, 1], [0, 1])
    title = fig.suptitle("a title", fontsize=15, color="0.3")
    fig.canvas.draw()  # as its PNG: laid out tight to the figure's edges
    d.fit_page(fig)
    width, height = fig.get_size_inches()
    box = ax.get_position()
    assert box.x0 * width > 0.25 and (1 - box.x1) * width >= 0.25 - 1e-9
    assert box.y0 * height > d.CAPTION_BAND_IN  # above the caption and the footer
    assert title.get_position()[1] * height <= height - 0.25 + 1e-9
    # the same title, its font and colour kept, and one title only
    assert fig.get_suptitle() == "a title" and title.get_fontsize() == 15
    assert title.get_color() == "0.3" and [t.get_text() for t in fig.texts] == ["a title"]
    # laid out once: the page draws these positions, not a layout made again
    fig.canvas.draw()
    assert ax.get_position().bounds == box.bounds
    assert title.get_position()[1] * height <= height - 0.25 + 1e-9  # left where it was put


def test_a_heading_moves_with_the_lines_it_heads():
    for filler in range(50, 62):
        lay = d.Layout()
        for k in range(filler):
            lay.line(f"line {k}")
        lay.heading("Section", level=1)
        lay.heading("Subsection", level=2)
        lay.table(long_table(10))
        for page in lay.pages:
            texts = page.texts()
            if "Section" in texts:
                # the heading is followed by the table's header and rows on its page
                assert "Subsection" in texts and "row" in texts and "r0" in texts, filler


def test_long_names_are_wrapped_never_cut():
    lay = d.Layout()
    lay.table(long_table(3, long_names=True))
    texts = lay.pages[0].texts()
    assert not any("…" in t for t in texts)
    name = "data/a-very-long-folder-name/with-sub-folders/X-straightness-Y-final-run.rtl"
    pieces = [t for t in texts if t not in ("row", "source", "value") and not t[0].isdigit()]
    pieces = [t for t in pieces if not re.fullmatch(r"r\d", t)]
    assert "".join(pieces[: len(pieces) // 3]) == name
    for item in lay.pages[0].items:
        if isinstance(item, d._Text) and item.ha == "left":
            assert item.x_in + d.string_width_in(item.text, item.size) <= lay.right + 1e-6


def test_wrap_keeps_every_character_and_the_width():
    text = "a " * 50 + "averyveryverylongwordwithoutanyspacesinsideitatall" * 3
    lines = d.wrap(text, 2.0, 9.5)
    assert "".join(lines).replace(" ", "") == text.replace(" ", "")
    assert all(d.string_width_in(line, 9.5) <= 2.0 + 1e-9 for line in lines)


def test_a_paragraph_leaves_no_single_line_on_a_page():
    for filler in range(55, 64):
        lay = d.Layout()
        for k in range(filler):
            lay.line(f"line {k}")
        lay.paragraph("word " * 300)
        counts = [p.lines() for p in lay.pages]
        assert all(c >= d.MIN_BLOCK_LINES for c in counts[1:]), (filler, counts)


def test_a_section_continues_on_a_page_that_has_room():
    lay = d.Layout()
    lay.heading("First")
    lay.paragraph("text " * 40)
    lay.section_break()
    lay.heading("Second")
    assert len(lay.pages) == 1
    while lay.used() < 0.75:
        lay.line("more")
    assert len(lay.pages) == 1
    lay.section_break()
    lay.heading("Third")
    assert len(lay.pages) == 2 and lay.pages[-1].texts()[0] == "Third"


def test_title_fields_from_the_report_table_machine_and_user_text():
    from esp.core.machine import ReportInfo

    fields = d.title_fields(
        ReportInfo(owner="ACME", laboratory="Lab 1"),
        {"serial": "S1", "measured_by": "A. B.", "date": "2024-01-02"},
        provenance(),
    )
    assert fields == [
        ("Serial", "S1"),
        ("Owner", "ACME"),
        ("Measured on", "2024-01-02"),
        ("Operator", "A. B."),
        ("Laboratory", "Lab 1"),
    ]
    # from the files' USER-TEXT alone
    assert d.title_fields(provenance=provenance()) == [
        ("Serial", "GX15-0472"),
        ("Operator", "M. Weber"),
    ]
    assert d.title_fields() == []


def test_summary_puts_the_uncertainty_statement_beside_its_figure():
    lay = d.Layout()
    d.summary(
        lay,
        [
            d.Headline("Volumetric accuracy", "12.000 µm", "U = 2.000 µm (k = 2, statistical)"),
            d.Headline("Planar accuracy XY", "8.000 µm"),
        ],
    )
    items = [i for i in lay.pages[0].items if isinstance(i, d._Text)]
    row = {i.text.strip(): i.y_in for i in items}
    assert row["Volumetric accuracy"] == row["U = 2.000 µm (k = 2, statistical)"]
    assert row["Planar accuracy XY"] == row["not evaluated"]


def test_provenance_pages_list_every_file_its_hash_environment_and_the_configuration():
    pages = d.provenance_pages(provenance(files=3, config_lines=10))
    texts = [t for p in pages for t in p.texts()]
    assert texts[0] == "Provenance"
    assert "analyse machine.toml --out r" in texts
    hashes = "".join(t.strip() for t in texts if set(t.strip()) <= set("ab") and t.strip())
    assert hashes.count("ab" * 32) == 3  # the SHA-256 of each file, wrapped, whole
    assert texts.count("20.1 °C") == 3 and texts.count("absent") == 3
    assert "key_9 = 9   # a comment" in texts  # the configuration, as given
    assert any(t == "Configuration as given: m.toml" for t in texts)


def test_environment_and_user_text_take_a_row_per_file():
    from esp.report.provenance import InputRecord, Provenance, readings

    def record(k: int) -> InputRecord:
        lines = readings(
            [
                ("Air temp", f"20.1{k} 20.2{k} 0"),
                ("Mat temp 1", "-10.0 -10.0 0"),
                ("Exp coeff", "11.5 11.5 0"),
                ("Date Time", f'"08:3{k} Mar 15 2023" "09:0{k} Mar 15 2023"'),
            ]
        )
        return InputRecord(
            f"X-{k}.rtl",
            "ab" * 32,
            100,
            "laser10",
            user_text=(("Machine", "GX-1500"), ("Axis", "XYZ"[k]), ("Comment", f"run {k}")),
            readings=lines,
        )

    prov = Provenance("0.0.0", ("analyse", "m.toml"), tuple(record(k) for k in range(3)), ())
    (page,) = d.provenance_pages(prov)
    items = [i for i in page.items if isinstance(i, d._Text)]
    texts = [i.text for i in items]
    start = texts.index("Environment recorded with the data")
    items, texts = items[start:], texts[start:]  # the files' rows after "Files read"
    # the unit once, in the header; the readings of a file on one row
    assert "air temperature" in " ".join(texts) and "(°C)" in " ".join(texts)
    for k in range(3):
        row_y = next(i.y_in for i in items if i.text == f"X-{k}.rtl")
        row = [i.text for i in items if abs(i.y_in - row_y) < 1e-9]
        want = [f"20.1{k} / 20.2{k}", "absent", "11.5", f"Mar 15 2023 08:3{k} / 09:0{k}"]
        assert row[1:] == want
    # what every file says alike once; a row per file for what differs
    assert texts.count("GX-1500") == 1
    row_y = next(i.y_in for i in items if i.text == "run 1")
    assert [i.text for i in items if abs(i.y_in - row_y) < 1e-9] == ["X-1.rtl", "Y", "run 1"]


def test_files_of_one_name_in_two_folders_are_told_apart():
    names = d._short_names(["a/gantry/X.rtl", "a/gantry-2024/X.rtl", "a/gantry/Y.rtl", "m.toml"])
    assert names == {
        "a/gantry/X.rtl": "gantry/X.rtl",
        "a/gantry-2024/X.rtl": "gantry-2024/X.rtl",
        "a/gantry/Y.rtl": "Y.rtl",
        "m.toml": "m.toml",
    }


def test_the_configuration_does_not_spill_a_few_lines_onto_a_page():
    # a few files (the configuration starts high on the page) and many (it starts low,
    # and may have to start on a page of its own)
    for files in (2, 14):
        for lines in range(20, 140, 7):
            pages = d.provenance_pages(provenance(files=files, config_lines=lines))
            assert len(pages) == 1 or pages[-1].lines() >= 15, (files, lines)


def small_figure(width=8.0, height=4.8) -> Figure:
    fig = Figure(figsize=(width, height))
    FigureCanvasAgg(fig)
    ax = fig.add_subplot(1, 1, 1)
    ax.plot([0, 1], [0, 1])
    ax.set_xlabel("x (mm)")
    return fig


@pytest.fixture(scope="module")
def built(tmp_path_factory) -> Path:
    """A document of every kind of element: title block, summary, sections, a long
    table, a figure, the provenance."""
    path = tmp_path_factory.mktemp("doc") / "doc.pdf"
    doc = d.Document(
        "Test report",
        "A machine whose name is long enough to need a second line on page one of the report",
        DATE,
        [("Serial", "1"), ("Laboratory", "Lab")],
    )
    d.summary(doc.lay, [d.Headline("Figure", "1.000 µm", "U = 0.1 µm (k = 2, statistical)")])
    doc.section("Inputs")
    doc.lay.table(long_table(70, long_names=True))
    doc.section("More")
    doc.lay.paragraph("text " * 100)
    doc.figure(small_figure(4.0, 3.0), "a small figure")
    doc.figure(small_figure(4.0, 2.83), "an A4 figure")
    doc.write(path, provenance(files=2, config_lines=30))
    return path


@pytest.mark.slow
def test_every_page_has_its_footer_and_its_text_inside(built):
    check_document(built, tables={"r1": "source"})


@pytest.mark.slow
def test_figure_pages_have_their_caption(built):
    texts = page_texts(built)
    captions = [n for n, page in enumerate(texts) for *_, t in page if t.startswith("Figure ")]
    assert len(captions) == 2
    assert any(t == "Figure 1: a small figure" for *_, t in texts[captions[0]])


@pytest.mark.slow
def test_the_same_document_gives_the_same_bytes(built, tmp_path, monkeypatch):
    monkeypatch.setenv("SOURCE_DATE_EPOCH", "1767312000")
    paths = []
    for k in range(2):
        doc = d.Document("Test report", "M", DATE)
        doc.lay.table(long_table(40))
        doc.figure(small_figure(), "figure")
        paths.append(tmp_path / f"{k}.pdf")
        doc.write(paths[-1], provenance(1, 5))
    assert paths[0].read_bytes() == paths[1].read_bytes()


# -- [report] in machine.toml -----------------------------------------------------------------


def minimal() -> dict:
    with open(ROOT / "tests" / "data" / "config" / "minimal.toml", "rb") as f:
        return tomllib.load(f)


def test_the_report_table_is_read_and_strict():
    data = minimal()
    data["report"] = {"serial": "S-1", "owner": "ACME", "operator": "A", "laboratory": "L"}
    m = machine_from_dict(copy.deepcopy(data), ROOT / "tests" / "data" / "config")
    assert m.report is not None and m.report.owner == "ACME" and m.report.serial == "S-1"
    data["report"]["customer"] = "x"
    with pytest.raises(ConfigError) as info:
        machine_from_dict(data, ROOT / "tests" / "data" / "config", source="machine.toml")
    assert info.value.key == "report.customer"
    data["report"] = {"owner": 3}
    with pytest.raises(ConfigError) as info:
        machine_from_dict(data, ROOT / "tests" / "data" / "config", source="machine.toml")
    assert info.value.key == "report.owner"
    assert machine_from_dict(minimal(), ROOT / "tests" / "data" / "config").report is None


# -- whole documents of the commands ----------------------------------------------------------


def run(args: list[str]) -> None:
    from click.testing import CliRunner

    from esp.cli import main

    result = CliRunner().invoke(main, args, catch_exceptions=False)
    assert result.exit_code == 0, result.output


@pytest.mark.slow
@pytest.mark.parametrize(
    ("args", "pdf", "tables"),
    [
        (["iso230-2", str(EXAMPLES / "gantry" / "X-linear.rtl")], "report.pdf", {}),
        (["head", str(EXAMPLES / "heads" / "angle-head-fig3.toml")], "head.pdf", {}),
        (["parallel", str(EXAMPLES / "parallel" / "machine.toml"), "--sweep"], "parallel.pdf", {}),
        (
            ["identify", str(EXAMPLES / "identify" / "cmm-ballplate" / "machine.toml")],
            "identify.pdf",
            {},
        ),
        (
            [
                "angular",
                str(EXAMPLES / "turning-centre" / "Xpos_z0.rtl"),
                str(EXAMPLES / "turning-centre" / "Xpos_z800.rtl"),
                "--displacement",
                "-800",
                "--datum",
                "-560",
            ],
            "report.pdf",
            {},
        ),
        (
            [
                "compensate",
                str(EXAMPLES / "gantry" / "machine.toml"),
                "--format",
                "isg-volumetric",
                "--predict",
            ],
            "report.pdf",
            {},
        ),
        (
            [
                "diagonals",
                str(EXAMPLES / "gantry" / "machine.toml"),
                "--measured",
                f"PPP={EXAMPLES / 'gantry-diagonals' / 'PPP.rtl'}",
                "--measurement-u",
                "2",
            ],
            "report.pdf",
            {},
        ),
        (
            [
                "compare",
                str(EXAMPLES / "gantry" / "machine.toml"),
                str(EXAMPLES / "gantry-2024" / "machine.toml"),
            ],
            "report.pdf",
            {},
        ),
    ],
)
def test_command_documents(args, pdf, tables, tmp_path, monkeypatch):
    monkeypatch.setenv("SOURCE_DATE_EPOCH", "1767312000")
    run([*args, "--out", str(tmp_path / "a")])
    check_document(tmp_path / "a" / pdf, tables=tables)
    first = (tmp_path / "a" / pdf).read_bytes()
    run([*args, "--out", str(tmp_path / "a")])  # the same command: the same bytes
    assert (tmp_path / "a" / pdf).read_bytes() == first


@pytest.mark.slow
def test_analyse_document(tmp_path, monkeypatch):
    monkeypatch.setenv("SOURCE_DATE_EPOCH", "1767312000")
    run(["analyse", str(EXAMPLES / "gantry" / "machine.toml"), "--out", str(tmp_path / "a"), "-q"])
    path = tmp_path / "a" / "report.pdf"
    check_document(path, tables={"EXX": "component"})
    pages = page_texts(path)
    starts = [n for n, page in enumerate(pages) if page and page[0][2] == "Provenance"]
    figures = [n for n, page in enumerate(pages) if any(t.startswith("Figure ") for *_, t in page)]
    assert len(starts) == 1 and starts[0] > max(figures)  # the last pages
