"""User text is bounded where it is read (a name or short field at most
esp.core.text.NAME_MAX_CHARS characters, free text at most TEXT_MAX_CHARS): a 2 KB machine
name once made ``analyse --out`` take 23 s (docs/reliability.md, "Bounded work")."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from click.testing import CliRunner

from esp.cli import main
from esp.core.errors import ParseError
from esp.core.text import NAME_MAX_CHARS, TEXT_MAX_CHARS
from esp.io.laser10 import parse_laser10

EXAMPLES = Path(__file__).resolve().parent.parent / "data" / "examples"

TOML = """
[machine]
name = {name}
configuration = "wBMTt"
axes = {{ bottom = "X", middle = "Y", top = "Z" }}
{extra}
[axes.X]
travel = [0, 100]
step = 50
[axes.X.errors]
linear = {{ constant = 1.5 }}
[axes.Y]
travel = [0, 100]
step = 50
[axes.Z]
travel = [0, 100]
step = 50
"""


def analyse(tmp_path: Path, name: str, extra: str = ""):
    path = tmp_path / "machine.toml"
    path.write_text(TOML.format(name=json.dumps(name), extra=extra), encoding="utf-8")
    return CliRunner().invoke(main, ["analyse", str(path), "--json", "-"])


def test_a_name_at_the_limit_is_read(tmp_path):
    result = analyse(tmp_path, "n" * NAME_MAX_CHARS)
    assert result.exit_code == 0, result.output


@pytest.mark.parametrize(
    "key, extra, length",
    [
        ("machine.name", "", 2048),
        ("machine.location", 'location = "{text}"', NAME_MAX_CHARS + 1),
        ("report.operator", '[report]\noperator = "{text}"', 8192),
    ],
)
def test_a_longer_name_is_refused_in_one_line(tmp_path, key, extra, length):
    text = "n" * length
    result = analyse(tmp_path, "m", extra.format(text=text)) if extra else analyse(tmp_path, text)
    assert result.exit_code == 2
    lines = result.output.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in result.output
    assert f"{key}: expected at most {NAME_MAX_CHARS} characters, found {length}" in lines[0]


def test_long_user_text_of_a_data_file_is_refused_at_its_line():
    text = (EXAMPLES / "gantry" / "X-linear.rtl").read_text(encoding="utf-8")
    at = text.splitlines().index("USER-TEXT::") + 2  # the line after the section's name
    ok = text.replace("USER-TEXT::\n", "USER-TEXT::\nRemark: " + "c" * TEXT_MAX_CHARS + "\n")
    assert len(parse_laser10(ok, path="X.rtl").metadata["Remark"]) == TEXT_MAX_CHARS
    for added, what in [
        ("Comment: " + "c" * (TEXT_MAX_CHARS + 1), "USER-TEXT value"),
        ("K" * (NAME_MAX_CHARS + 1) + ": v", "USER-TEXT key"),
        ("\n".join(["a loose line " * 10] * 20), "USER-TEXT text without a key"),
    ]:
        with pytest.raises(ParseError) as info:
            parse_laser10(text.replace("USER-TEXT::\n", f"USER-TEXT::\n{added}\n"), path="X.rtl")
        assert what in info.value.message and "expected at most" in info.value.message
        assert info.value.line >= at


def test_a_long_chain_description_is_refused():
    from esp.config.chain import chain_from_dict
    from esp.core.errors import ConfigError

    data = {
        "chain": {"name": "c", "description": "d" * (TEXT_MAX_CHARS + 1)},
        "steps": [{"translate": {"x": 1}}],
    }
    with pytest.raises(ConfigError) as info:
        chain_from_dict(data)
    assert info.value.key == "chain.description"
    assert f"found {TEXT_MAX_CHARS + 1}" in info.value.message
