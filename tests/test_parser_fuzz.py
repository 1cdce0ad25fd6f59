"""Property tests of the data-file parsers on random and damaged input.

Whatever the text, a parser either returns an ErrorProfile or raises ParseError /
DataError; any other exception (IndexError, KeyError, ValueError from deep inside, ...)
is a defect. Examples are derandomized so that every run tests the same cases.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from esp.core.errors import DataError, ParseError
from esp.core.profile import ErrorProfile
from esp.io.csvfile import parse_csv_profile
from esp.io.laser10 import parse_laser10
from esp.io.textfile import decode_bytes

DATA = Path(__file__).parent / "data"
FIXTURES = {
    "laser10": [
        (DATA / name).read_text(encoding="utf-8")
        for name in (
            "linear_bidir.rtl",
            "angular.rta",
            "straightness.stx",
            "wrapped_descending.rtl",
        )
    ],
    "csv": [(DATA / "profile.csv").read_text(encoding="utf-8")],
}
FUZZ = settings(
    max_examples=200,
    derandomize=True,
    deadline=None,
    suppress_health_check=[HealthCheck.too_slow],
)
JUNK = ["abc", "nan", "inf", "-", "", "1e999", "1.2.3", "0x1F", "\u0661", "9" * 30, ":", "::"]


def parse(kind: str, text: str):
    if kind == "laser10":
        return parse_laser10(text, path="fuzz.rtl")
    return parse_csv_profile(text, path="fuzz.csv", kind="linear")


def accepts(kind: str, text: str) -> None:
    """Parse ``text``; only a profile, ParseError or DataError is acceptable."""
    try:
        result = parse(kind, text)
    except (ParseError, DataError) as exc:
        assert str(exc)  # a message, not an empty error
        return
    assert isinstance(result, ErrorProfile)


@st.composite
def mutated(draw, kind: str) -> str:
    """A valid file with one to four random edits."""
    text = draw(st.sampled_from(FIXTURES[kind]))
    for _ in range(draw(st.integers(1, 4))):
        lines = text.split("\n")
        op = draw(st.sampled_from(["delete", "duplicate", "junk", "truncate", "insert", "swap"]))
        i = draw(st.integers(0, len(lines) - 1))
        if op == "delete":
            del lines[i]
        elif op == "duplicate":
            lines.insert(i, lines[i])
        elif op == "swap":
            j = draw(st.integers(0, len(lines) - 1))
            lines[i], lines[j] = lines[j], lines[i]
        elif op == "junk":
            tokens = lines[i].replace(",", " , ").split(" ")
            k = draw(st.integers(0, max(0, len(tokens) - 1)))
            tokens[k] = draw(st.sampled_from(JUNK))
            lines[i] = " ".join(tokens).replace(" , ", ",")
        text = "\n".join(lines)
        if op == "truncate":
            text = text[: draw(st.integers(0, len(text)))]
        elif op == "insert":
            at = draw(st.integers(0, len(text)))
            text = text[:at] + draw(st.text(max_size=20)) + text[at:]
    return text


@pytest.mark.parametrize("kind", ["laser10", "csv"])
def test_fixtures_parse(kind):
    for text in FIXTURES[kind]:
        assert isinstance(parse(kind, text), ErrorProfile)


@pytest.mark.slow
@FUZZ
@given(st.text(max_size=400))
def test_random_text_laser10(text):
    accepts("laser10", text)


@pytest.mark.slow
@FUZZ
@given(st.text(max_size=400))
def test_random_text_csv(text):
    accepts("csv", text)


@pytest.mark.slow
@FUZZ
@given(st.data())
def test_mutated_laser10(data):
    accepts("laser10", data.draw(mutated("laser10")))


@pytest.mark.slow
@FUZZ
@given(st.data())
def test_mutated_csv(data):
    accepts("csv", data.draw(mutated("csv")))


@pytest.mark.slow
@FUZZ
@given(st.binary(max_size=400))
def test_random_bytes_decode(data):
    try:
        text = decode_bytes(data, "fuzz.rtl")
    except ParseError:
        return
    assert isinstance(text, str) and "\r" not in text
    accepts("laser10", text)
