"""Every TOML file esp reads -- machine, chain, head, table, serial-parallel machine -- goes
through the same checks (esp.io.tomlfile) and is refused with a one-line ConfigError naming
the file; and the "did you mean" hint of esp.core.text."""

from __future__ import annotations

import os

import pytest

from esp.config import load_machine
from esp.config.chain import load_chain
from esp.config.devices import load_table
from esp.core.errors import ConfigError
from esp.core.text import closest, did_you_mean
from esp.heads import load_head
from esp.io.tomlfile import TOML_MAX_BYTES, TOML_MAX_DEPTH, read_toml_file, toml_message
from esp.parallel import load_parallel

LOADERS = {
    "configuration": load_machine,
    "chain": load_chain,
    "head": lambda p: load_head(p)[0],
    "table": load_table,
    "parallel configuration": load_parallel,
}


@pytest.fixture(params=sorted(LOADERS))
def loader(request):
    return request.param, LOADERS[request.param]


def refused(load, path, *fragments: str) -> str:
    with pytest.raises(ConfigError) as info:
        load(path)
    text = str(info.value)
    assert "\n" not in text
    assert str(path) in text
    for fragment in fragments:
        assert fragment in text, text
    return text


def test_missing_file(loader, tmp_path):
    what, load = loader
    noun = "configuration" if what == "parallel configuration" else what
    refused(load, tmp_path / "none.toml", "<file>", f"no such {noun} file")


def test_a_folder(loader, tmp_path):
    _, load = loader
    refused(load, tmp_path, "<file>", "is a folder")


def test_a_pipe(loader, tmp_path):
    _, load = loader
    fifo = tmp_path / "pipe.toml"
    os.mkfifo(fifo)
    refused(load, fifo, "<file>", "found a device or pipe")


def test_too_large(loader, tmp_path):
    _, load = loader
    big = tmp_path / "big.toml"
    big.write_bytes(b"#" * (TOML_MAX_BYTES + 1))
    refused(load, big, "<file>", f"expected at most {TOML_MAX_BYTES} bytes, found")


def test_not_utf8(loader, tmp_path):
    _, load = loader
    bad = tmp_path / "bad.toml"
    bad.write_bytes(b'name = "M\xe4chine"\n')
    refused(load, bad, "<toml>", "expected UTF-8 text, found byte 0xe4 at offset 9")


def test_invalid_toml_names_the_line(loader, tmp_path):
    _, load = loader
    bad = tmp_path / "bad.toml"
    bad.write_text('a = 1\n[b\nc = "x"\n', encoding="utf-8")
    refused(load, bad, "<toml>", "invalid TOML at line 2, column")


def test_too_deep(loader, tmp_path):
    _, load = loader
    deep = tmp_path / "deep.toml"
    deep.write_text("a = " + "[" * (TOML_MAX_DEPTH + 2) + "]" * (TOML_MAX_DEPTH + 2) + "\n")
    refused(load, deep, "<toml>", f"nested at most {TOML_MAX_DEPTH} deep")


def test_byte_order_mark_and_content(tmp_path):
    ok = tmp_path / "ok.toml"
    ok.write_bytes('\ufeffname = "Mäschine"\n[a]\nb = [1, 2]\n'.encode())
    assert read_toml_file(ok) == {"name": "Mäschine", "a": {"b": [1, 2]}}


def test_toml_message():
    assert toml_message("Invalid value (at line 2, column 5)") == (
        "invalid TOML at line 2, column 5: invalid value"
    )
    assert toml_message("Unclosed array (at end of document)") == (
        "invalid TOML at the end of the file: unclosed array"
    )
    assert toml_message("odd") == "invalid TOML: odd"


def test_closest_and_did_you_mean():
    options = ["travel", "step", "offset"]
    assert closest("TRAVEL", options) == "travel"  # equal but for case first
    assert closest("stpe", options) == "step"
    assert closest("Offest", options) == "offset"
    assert closest("zzz", options) is None
    assert did_you_mean("trvel", options) == "; did you mean 'travel'?"
    assert did_you_mean("zzz", options) == ""
