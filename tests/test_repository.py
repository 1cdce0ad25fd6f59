"""The repository itself: no large or binary build artefact is tracked, and nothing a run
wrote sits at its top level."""

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


#: the files the repository's top level may hold (the design card's layout and the usual
#: project files); a report or figure written there by a run is not one of them
TOP_LEVEL_FILES = {".gitignore", "CHANGELOG.md", "LICENSE", "README.md", "pyproject.toml"}
TOP_LEVEL_FOLDERS = {".ci", "benchmarks", "data", "docs", "esp", "tests"}


def test_the_top_level_holds_only_the_project_layout():
    top = {p.relative_to(ROOT).parts[0] for p in _tracked()}
    files = {name for name in top if (ROOT / name).is_file()}
    assert files <= TOP_LEVEL_FILES, files - TOP_LEVEL_FILES
    assert top - files <= TOP_LEVEL_FOLDERS, (top - files) - TOP_LEVEL_FOLDERS
