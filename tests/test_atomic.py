"""Atomic writing: whole files or none, with ordinary permissions."""

from __future__ import annotations

import os
import stat

import pytest

from esp.io.atomic import atomic_path, write_text


def test_written_whole_with_the_mode_of_a_plain_file(tmp_path):
    path = tmp_path / "out" / "a.json"
    write_text(path, "{}\n")
    assert path.read_text(encoding="utf-8") == "{}\n"
    mask = os.umask(0o022)
    os.umask(mask)
    assert stat.S_IMODE(path.stat().st_mode) == 0o666 & ~mask


def test_failure_leaves_the_old_file_and_no_temporary(tmp_path):
    path = tmp_path / "a.txt"
    path.write_text("old", encoding="utf-8")
    with pytest.raises(RuntimeError), atomic_path(path) as tmp:
        tmp.write_text("half", encoding="utf-8")
        raise RuntimeError("interrupted")
    assert path.read_text(encoding="utf-8") == "old"
    assert [p.name for p in tmp_path.iterdir()] == ["a.txt"]
