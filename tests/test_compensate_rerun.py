"""``esp compensate --out DIR`` run again into the same folder: every per-format subfolder
carries esp's marker, so the whole of DIR is known as esp's and replaced; a file a user put
into a subfolder still stops the run (docs/reliability.md, "Outputs")."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from click.testing import CliRunner

from esp.cli import main
from esp.io.outputs import MARKER

MACHINE = str(Path(__file__).parent.parent / "data" / "examples" / "gantry" / "machine.toml")


def run(*args):
    return CliRunner().invoke(main, ["compensate", MACHINE, *args, "-q"])


@pytest.mark.slow
def test_second_and_third_run_into_the_same_folder(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    first = ["--format", "isg-volumetric", "--out", "comp"]
    assert run(*first).exit_code == 0
    marker = json.loads((tmp_path / "comp" / "isg-volumetric" / MARKER).read_text())
    assert list(marker["files"]) == ["volcomp.csv"]
    again = run(*first)
    assert again.exit_code == 0, again.stderr
    # the third example of `esp compensate --help`, after the first
    third = run(
        "--format", "twincat-plane", "--format", "isg-volumetric", "--leave-uncorrected",
        "--out", "comp",
    )  # fmt: skip
    assert third.exit_code == 0, third.stderr
    assert sorted(p.name for p in (tmp_path / "comp").iterdir()) == [
        MARKER, "isg-volumetric", "report.pdf", "twincat-plane",
    ]  # fmt: skip


def test_a_file_put_into_a_format_folder_is_kept(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert run("--format", "isg-volumetric", "--out", "comp").exit_code == 0
    note = tmp_path / "comp" / "isg-volumetric" / "note.txt"
    note.write_text("mine", encoding="utf-8")
    res = run("--format", "isg-volumetric", "--out", "comp")
    assert res.exit_code == 2
    assert "isg-volumetric/note.txt" in res.stderr
    assert note.read_text(encoding="utf-8") == "mine"
