"""The Etalon Exchange layout reader of the io layer (esp.io.etalon)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from esp.core.errors import ParseError
from esp.io.etalon import parse_exchange, read_exchange

TEXT = """// written by hand
[C0Y]
VALUE = 0.000012   // squareness, rad
[EXX]
Gridpoints = {
    0.0 0.0
    100.0 0.0025
    200.0 -0.001
}  // end of EXX
"""


def test_blocks_values_tables_and_lines(tmp_path: Path) -> None:
    path = tmp_path / "cal.txt"
    path.write_text(TEXT, encoding="utf-8")
    blocks = read_exchange(path)
    assert list(blocks) == ["C0Y", "EXX"]
    assert blocks["C0Y"].value == pytest.approx(1.2e-5)
    assert blocks["C0Y"].line == 2
    table = blocks["EXX"].table
    assert table is not None and table.shape == (3, 2)
    np.testing.assert_array_equal(table[:, 0], [0.0, 100.0, 200.0])
    np.testing.assert_allclose(table[:, 1], [0.0, 0.0025, -0.001])
    assert blocks["EXX"].line == 4


@pytest.mark.parametrize(
    ("text", "line", "words"),
    [
        ("[EXX]\nGridpoints = {\n 0 0\n 1 x\n}\n", 4, "expected a number, found 'x'"),
        ("[EXX]\nGridpoints = {\n 0 0 0\n}\n", 3, "expected two numbers"),
        ("VALUE = 1\n", 1, "expected [PARAMETER]"),
        ("[C0Y]\nVALUE = 1\n[C0Y]\nVALUE = 2\n", 3, "given twice (line 1)"),
        ("[C0Y]\nVALUE = nan\n", 2, "finite number"),
        ("[EXX]\nGridpoints = {\n 0 0\n}\n", 4, "at least 2 records"),
        ("[EXX]\nfoo\n", 2, "expected VALUE = or Gridpoints"),
    ],
)
def test_bad_files_name_the_file_and_line(text: str, line: int, words: str) -> None:
    with pytest.raises(ParseError) as info:
        parse_exchange(text, "cal.txt")
    assert info.value.line == line
    assert words in str(info.value)
    assert "cal.txt" in str(info.value)


def test_unclosed_table_and_binary_file(tmp_path: Path) -> None:
    with pytest.raises(ParseError, match="not closed"):
        parse_exchange("[EXX]\nGridpoints = {\n 0 0\n 1 1\n", "cal.txt")
    path = tmp_path / "cal.txt"
    path.write_bytes(b"\xff\xfe\x00[\x00")
    with pytest.raises(ParseError, match="expected a text file"):
        read_exchange(path)


def test_the_compensation_writer_reads_with_the_io_parser() -> None:
    from esp.compensation.formats import etalon

    assert etalon.parse_exchange is parse_exchange
