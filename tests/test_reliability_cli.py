"""One-line errors everywhere: every command refuses a bad option value, a bad path or a
bad target with ``esp: error: ...`` naming the option, what was expected and what was
found, exit code 2, before any file is written (docs/reliability.md, "Exit codes")."""

from __future__ import annotations

import os
from pathlib import Path

import pytest
from click.testing import CliRunner

from esp.cli import main
from esp.core.profile import ErrorProfile
from esp.io.laser10 import write_laser10
from esp.io.outputs import REGISTRY

MINIMAL = Path(__file__).parent / "data" / "config" / "minimal.toml"


@pytest.fixture
def place(tmp_path, monkeypatch) -> Path:
    """A working folder with two linear files, a CSV, a machine, a file and a folder."""
    monkeypatch.chdir(tmp_path)
    runs = {"forward": [[0, 1, 2], [0, 1.5, 2]], "backward": [[0, 1, 3], [0.5, 1, 2]]}
    write_laser10(tmp_path / "a.rtl", ErrorProfile("linear", [0, 100, 200], runs))
    write_laser10(tmp_path / "b.rtl", ErrorProfile("linear", [0, 100, 200], runs).scaled(2))
    (tmp_path / "p.csv").write_text(
        "# unit: um\ntarget_mm,run,direction,deviation\n0,1,+,0\n100,1,+,1\n", encoding="utf-8"
    )
    (tmp_path / "machine.toml").write_text(MINIMAL.read_text(encoding="utf-8"), "utf-8")
    (tmp_path / "afile").write_text("keep", encoding="utf-8")
    (tmp_path / "adir").mkdir()
    return tmp_path


def run(*args) -> object:
    return CliRunner().invoke(main, [str(a) for a in args])


def assert_one_line(res, *fragments: str) -> None:
    assert res.exit_code == 2, res.output
    assert res.stderr.startswith("esp: error: ") and res.stderr.count("\n") == 1, res.stderr
    assert "Traceback" not in res.output and "Usage:" not in res.output
    for fragment in fragments:
        assert fragment in res.stderr, res.stderr


def snapshot(folder: Path) -> dict[str, bytes]:
    return {
        str(p.relative_to(folder)): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()
    }


ANGULAR = ("angular", "a.rtl", "b.rtl", "--displacement", "100", "--datum", "0")

BAD_OPTIONS = [
    # --json into a path that runs through a file ("afile: File exists" before)
    (("inspect", "a.rtl", "--json", "afile/r.json"), "--json afile/r.json", "is a file"),
    (("iso230-2", "a.rtl", "--json", "afile/r.json"), "--json afile/r.json", "is a file"),
    ((*ANGULAR, "--json", "afile/r.json"), "--json afile/r.json", "is a file, not a folder"),
    (("analyse", "machine.toml", "--json", "afile/r.json"), "--json afile/r.json", "is a file"),
    # targets that are inputs
    (("inspect", "a.rtl", "--plot", "a.rtl"), "--plot a.rtl: is one of this command's inputs"),
    (("iso230-2", "a.rtl", "--json", "a.rtl"), "--json a.rtl: is one of this command's inputs"),
    ((*ANGULAR, "-o", "b.rtl"), "--output b.rtl: is one of this command's inputs"),
    (("analyse", "machine.toml", "--json", "machine.toml"), "--json machine.toml: is one of"),
    # targets that are folders, folders given as files
    (("inspect", "a.rtl", "--json", "adir"), "--json adir: is a folder; expected a file name"),
    (("analyse", "machine.toml", "--out", "afile"), "'--out'", "'afile' is a file"),
    (("batch", "machine.toml", "--out", "afile"), "'--out'", "'afile' is a file"),
    (("inspect", "adir"), "'FILE'", "'adir' is a directory"),
    (("iso230-2", "adir"), "'FILE'", "'adir' is a directory"),
    (("angular", "adir", "b.rtl", "--displacement", "1", "--datum", "0"), "'adir' is a dir"),
    (("analyse", "adir"), "'MACHINE_TOML'", "'adir' is a directory"),
    # malformed values
    (("analyse", "machine.toml", "--at", "X=1,Y=2"), "'--at'", "missing Z"),
    (("analyse", "machine.toml", "--at", "X=nan,Y=2,Z=0"), "'--at'", "finite number"),
    (("analyse", "machine.toml", "--at", "X=1e308,Y=2,Z=0"), "'--at'", "found '1e308'"),
    (("analyse", "machine.toml", "--at", "Q=1"), "'--at'", "AXIS=mm pairs"),
    (("inspect", "a.rtl", "--unit", "furlong"), "'--unit'", "unknown unit 'furlong'"),
    (("iso230-2", "a.rtl", "--unit", "arcsec"), "'--unit'", "a unit of length"),
    ((*ANGULAR, "--unit", "urad"), "'--unit'", "a unit of length"),
    (("angular", "a.rtl", "b.rtl", "--displacement", "nan", "--datum", "0"), "'--displacement'"),
    (("angular", "a.rtl", "b.rtl", "--displacement", "1e-300", "--datum", "0"), "0.001 mm"),
    (("angular", "a.rtl", "b.rtl", "--displacement", "1", "--datum", "inf"), "'--datum'"),
    (("batch", "machine.toml", "--out", "r", "--max-volumetric", "0"), "'--max-volumetric'"),
    (("batch", "machine.toml", "--out", "r", "--max-planar", "nan"), "finite number"),
    (("batch", "machine.toml", "--out", "r", "--max-planar", "inf"), "found 'inf'"),
    (("batch", "machine.toml", "--out", "r", "--max-planar", "-1"), "above 0", "found '-1'"),
    (("batch", "machine.toml", "--out", "r", "--jobs", "0"), "'--jobs'", "0 is not in the range"),
    (("batch", "machine.toml", "--out", "r", "--jobs", "100000"), "1<=x<=256"),
    (("batch", "nothere", "--out", "r"), "'PATH...'", "'nothere' does not exist"),
    # a CSV unit comment names its line
    (("inspect", "p.csv", "--kind", "angular"), "p.csv:1: unit 'um' does not fit"),
]


@pytest.mark.slow
@pytest.mark.parametrize("case", BAD_OPTIONS, ids=lambda c: " ".join(c[0])[:60])
def test_bad_option_values_are_one_line_and_write_nothing(place, case):
    args, *fragments = case
    before = snapshot(place)
    res = run(*args)
    assert_one_line(res, *fragments)
    assert snapshot(place) == before


def test_a_fifo_or_device_is_refused_without_reading(place):
    os.mkfifo(place / "pipe.rtl")
    os.mkfifo(place / "pipe.toml")
    assert_one_line(run("inspect", "pipe.rtl"), "pipe.rtl: expected a regular data file")
    assert_one_line(run("iso230-2", "/dev/zero"), "/dev/zero: expected a regular data file")
    assert_one_line(run("analyse", "pipe.toml"), "pipe.toml: <file>: expected a regular")
    assert_one_line(run("batch", "pipe.toml", "--out", "r"), "found a device, pipe or socket")


def test_plot_over_the_input_leaves_it_intact(place):
    """``esp inspect a.rtl --plot a.rtl`` replaced the data file by a PNG."""
    before = (place / "a.rtl").read_bytes()
    assert_one_line(run("inspect", "a.rtl", "--plot", "a.rtl"), "--plot a.rtl")
    assert (place / "a.rtl").read_bytes() == before


@pytest.mark.slow
@pytest.mark.parametrize("command", ["inspect", "iso230-2"])
def test_outputs_are_all_or_nothing(place, command):
    res = run(command, "a.rtl", "--plot", "out.png", "--json", "afile/x.json")
    assert_one_line(res, "--json afile/x.json")
    assert not (place / "out.png").exists()
    res = run(command, "a.rtl", "--plot", "out.png", "--json", "out.json")
    assert res.exit_code == 0, res.output
    assert (place / "out.png").read_bytes().startswith(b"\x89PNG")
    assert (place / "out.json").read_text(encoding="utf-8").startswith("{")
    # nothing staged is left; the registry records the two files as esp's
    assert sorted(p.name for p in place.iterdir() if p.name.startswith(".")) == [REGISTRY]


def test_angular_outputs_are_all_or_nothing(place):
    assert_one_line(run(*ANGULAR, "-o", "x.rta", "--json", "x.rta"), "also the target of")
    assert not (place / "x.rta").exists()
    res = run(*ANGULAR, "-o", "x.rta", "--json", "x.json")
    assert res.exit_code == 0, res.output
    assert (place / "x.rta").is_file() and (place / "x.json").is_file()


def test_file_names_with_line_breaks_stay_on_one_line(place):
    odd = place / "new\nline.rtl"
    odd.write_bytes((place / "a.rtl").read_bytes())
    res = run("angular", odd, odd, "--displacement", "100", "--datum", "0", "-o", "o\nut.rta")
    assert res.exit_code == 0, res.output
    assert "reference     new\\nline.rtl" in res.stdout.splitlines()
    assert "written o\\nut.rta" in res.stdout.splitlines()
    res = run("inspect", odd, "--unit", "arc\nsec")
    assert_one_line(res, "unknown unit 'arc\\nsec'")
