"""The repository itself: no large or binary build artefact is tracked."""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent

#: the largest file the repository may track (data examples are small text files)
MAX_TRACKED_BYTES = 1_000_000


def _tracked() -> list[Path]:
    if shutil.which("git") is None or not (ROOT / ".git").exists():
        pytest.skip("not a git checkout")
    out = subprocess.run(
        ["git", "ls-files", "-z"], cwd=ROOT, capture_output=True, check=True
    ).stdout.decode("utf-8")
    return [ROOT / p for p in out.split("\0") if p]


def test_no_tracked_file_is_over_one_megabyte():
    big = {
        str(p.relative_to(ROOT)): p.stat().st_size
        for p in _tracked()
        if p.is_file() and p.stat().st_size > MAX_TRACKED_BYTES
    }
    assert big == {}


def test_no_wheel_or_archive_is_tracked():
    found = [
        str(p.relative_to(ROOT))
        for p in _tracked()
        if p.suffix in (".whl", ".egg", ".zip", ".gz", ".tar")
    ]
    assert found == []
