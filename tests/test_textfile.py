"""Tests of esp.io.textfile: decoding, line ends and refusal of what is not text."""

from __future__ import annotations

import random
from pathlib import Path

import pytest

from esp.core.errors import ParseError
from esp.io.textfile import decode_bytes, normalise_newlines, read_text, read_utf8, split_lines

DATA = Path(__file__).parent / "data"


def test_reads_fixture_unchanged():
    text = read_text(DATA / "linear_bidir.rtl")
    assert text.startswith("HEADER::\n")
    assert "\r" not in text


def test_crlf_and_cr_become_lf(tmp_path):
    path = tmp_path / "a.txt"
    path.write_bytes(b"one\r\ntwo\rthree\nfour")
    assert read_text(path) == "one\ntwo\nthree\nfour"


def test_utf8_bom_is_removed(tmp_path):
    path = tmp_path / "a.txt"
    path.write_bytes(b"\xef\xbb\xbfHEADER::\r\nM\xc3\xbcller\r\n")
    assert read_text(path) == "HEADER::\nM\u00fcller\n"


def test_latin1_fallback(tmp_path):
    # 0xFC is u-umlaut in Latin-1 and Windows-1252, and invalid as UTF-8
    path = tmp_path / "a.txt"
    path.write_bytes(b"By: M\xfcller\r\n")
    assert read_text(path) == "By: M\u00fcller\n"


def test_cp1252_characters(tmp_path):
    # 0x80 is the euro sign in Windows-1252 (a control character in Latin-1)
    path = tmp_path / "a.txt"
    path.write_bytes(b"Cost: 5 \x80\n")
    assert read_text(path) == "Cost: 5 \u20ac\n"


def test_utf16_with_bom(tmp_path):
    path = tmp_path / "a.txt"
    path.write_bytes("Axis: X\r\n".encode("utf-16"))
    assert read_text(path) == "Axis: X\n"


def test_broken_utf16_is_undecodable(tmp_path):
    path = tmp_path / "a.txt"
    path.write_bytes(b"\xff\xfeA\x00x")  # odd number of bytes after the mark
    with pytest.raises(ParseError, match="UTF-16"):
        read_text(path)


def test_directory(tmp_path):
    with pytest.raises(ParseError, match="is a directory, expected a data file") as info:
        read_text(tmp_path)
    assert info.value.path == str(tmp_path)
    assert info.value.line is None


def test_missing_file(tmp_path):
    with pytest.raises(ParseError, match="no such file") as info:
        read_text(tmp_path / "absent.rtl")
    assert str(tmp_path / "absent.rtl") in str(info.value)


@pytest.mark.parametrize("content", [b"", b"   \r\n\n\t", b"\xef\xbb\xbf", b"\xef\xbb\xbf\r\n"])
def test_empty_file(tmp_path, content):
    path = tmp_path / "empty.rtl"
    path.write_bytes(content)
    with pytest.raises(ParseError, match="empty file"):
        read_text(path)


def test_nul_bytes_are_binary_and_named_by_line(tmp_path):
    path = tmp_path / "junk.rtl"
    path.write_bytes(b"HEADER::\nline two\nbad\x00byte\n")
    with pytest.raises(ParseError, match="binary data") as info:
        read_text(path)
    assert info.value.line == 3  # the NUL is on the third line


def test_non_printable_junk_is_binary(tmp_path):
    # no NUL, but most bytes are control characters in every fallback code page
    path = tmp_path / "junk.rtl"
    path.write_bytes(bytes(range(1, 9)) * 50 + b"\x0e\x0f\x10\x11" * 50)
    with pytest.raises(ParseError, match="not printable"):
        read_text(path)


def test_random_bytes_are_refused(tmp_path):
    path = tmp_path / "junk.bin"
    path.write_bytes(random.Random(0).randbytes(4096))
    with pytest.raises(ParseError, match="binary data"):
        read_text(path)


def test_a_few_control_characters_are_tolerated():
    text = "Machine: mill\x07\n" + "x" * 100
    assert decode_bytes(text.encode()) == text


def test_split_lines_keeps_form_feeds_inside_lines():
    assert split_lines("a\fb\r\nc\rd") == ["a\fb", "c", "d"]
    assert normalise_newlines("\ufeffx\r\n") == "x\n"


def test_read_utf8_reads_with_or_without_bom(tmp_path):
    p = tmp_path / "values.csv"
    p.write_bytes("\ufefferror,value\nEXC,1.5 µm\n".encode())
    assert read_utf8(p, 1024, "file of error values") == "error,value\nEXC,1.5 µm\n"


def test_read_utf8_names_the_line_of_a_bad_byte(tmp_path):
    p = tmp_path / "values.csv"
    p.write_bytes(b"error,value\nEXC,1\nEYC,\xe42\n")
    with pytest.raises(ParseError, match=r"values.csv:3: expected UTF-8 text, found byte 0xe4"):
        read_utf8(p, 1024, "file of error values")


@pytest.mark.parametrize(
    ("make", "message"),
    [
        (lambda p: None, "expected a curve file, found no such file"),
        (lambda p: p.mkdir(), "is a directory, expected a curve file"),
        (
            lambda p: p.write_bytes(b"x" * 2048),
            "expected a curve file of at most 1024 bytes, found 2048 bytes",
        ),
    ],
)
def test_read_utf8_refuses_what_is_not_a_small_file(tmp_path, make, message):
    p = tmp_path / "curve.csv"
    make(p)
    with pytest.raises(ParseError, match=message):
        read_utf8(p, 1024, "curve file")
