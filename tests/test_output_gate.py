"""The one output gate (esp.io.outputs, esp.cli.output): every path esp writes is checked
before any work, never an input, never a file esp did not write or one changed since, the
outputs of a run written all or none, the staging folders of a live run kept, and
diagnostics on standard error (docs/reliability.md, "Outputs")."""

from __future__ import annotations

import errno
import hashlib
import json
import os
import re
import shlex
import shutil
import subprocess
import sys
import time
from pathlib import Path

import click
import pytest
from click.testing import CliRunner
from conftest import SMALL_MACHINE

from esp.cli import main
from esp.core.profile import ErrorProfile
from esp.io.laser10 import write_laser10
from esp.io.outputs import MARKER, REGISTRY

ROOT = Path(__file__).resolve().parent.parent
GANTRY = ROOT / "data" / "examples" / "gantry"

TOOL_AT_MCP = "[tool]\nlengths = [100]\n"  # given, but the analysis is at the MCP: a warning
WARNING = "[tool] is given but analysis.point = 'MCP'"


@pytest.fixture
def light_reports(monkeypatch):
    """The report's content is stubbed: these tests are about which files are written."""

    def stand_in(result, staged, **kwargs):
        Path(staged, "report.pdf").write_bytes(b"%PDF-1.4 stand-in")
        Path(staged, "result.json").write_text('{"schema": "esp.result/1"}', encoding="utf-8")

    monkeypatch.setattr("esp.volumetric.report.write_report_files", stand_in)


@pytest.fixture
def place(tmp_path, monkeypatch, light_reports) -> Path:
    monkeypatch.chdir(tmp_path)
    (tmp_path / "machine.toml").write_text(SMALL_MACHINE, encoding="utf-8")
    (tmp_path / "tool.toml").write_text(SMALL_MACHINE + TOOL_AT_MCP, encoding="utf-8")
    (tmp_path / "X.csv").write_text(
        "# unit: um\ntarget_mm,run,direction,deviation\n0,1,forward,0\n100,1,forward,3\n",
        encoding="utf-8",
    )
    runs = {"forward": [[0, 1, 2], [0, 1.5, 2]], "backward": [[0, 1, 3], [0.5, 1, 2]]}
    write_laser10(tmp_path / "a.rtl", ErrorProfile("linear", [0, 100, 200], runs))
    write_laser10(tmp_path / "b.rtl", ErrorProfile("linear", [0, 100, 200], runs).scaled(2))
    for name in ("notes.txt", "cert.pdf", "important.toml", "mine.rta"):
        (tmp_path / name).write_bytes(b"the user's own " + name.encode())
    return tmp_path


def run(*args):
    return CliRunner().invoke(main, [str(a) for a in args])


def snapshot(folder: Path) -> dict[str, bytes]:
    return {
        str(p.relative_to(folder)): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()
    }


def refused(res, *fragments: str) -> None:
    assert res.exit_code == 2, res.output
    assert res.stderr.startswith("esp: error: ") and res.stderr.count("\n") == 1, res.stderr
    for fragment in fragments:
        assert fragment in res.stderr, res.stderr


ANGULAR = ("angular", "a.rtl", "b.rtl", "--displacement", "100", "--datum", "0")

# -- 1. single files: never one esp did not write -----------------------------------------

USERS_FILES = [
    (("inspect", "a.rtl", "--plot", "notes.txt"), "--plot notes.txt"),
    (("iso230-2", "a.rtl", "--plot", "cert.pdf"), "--plot cert.pdf"),
    (("analyse", "-q", "machine.toml", "--json", "important.toml"), "--json important.toml"),
    ((*ANGULAR, "-o", "mine.rta"), "--output mine.rta"),
    ((*ANGULAR, "--json", "notes.txt"), "--json notes.txt"),
    (("derive", "machine.toml", "--json", "notes.txt"), "--json notes.txt"),
]


@pytest.mark.parametrize("case", USERS_FILES, ids=lambda c: " ".join(c[0])[:50])
def test_a_users_file_is_never_replaced(place, case):
    args, option = case
    before = snapshot(place)
    refused(run(*args), option, "esp did not write it", "remove it or choose another name")
    assert snapshot(place) == before


@pytest.mark.slow
def test_a_file_esp_wrote_is_replaced_until_it_is_edited(place):
    assert run("inspect", "a.rtl", "--plot", "x.png").exit_code == 0
    registry = json.loads((place / REGISTRY).read_text(encoding="utf-8"))
    png = (place / "x.png").read_bytes()
    assert registry["files"]["x.png"] == {
        "size": len(png),
        "sha256": hashlib.sha256(png).hexdigest(),
    }
    assert run("inspect", "a.rtl", "--plot", "x.png").exit_code == 0  # esp's, unchanged
    assert (place / "x.png").read_bytes() == png
    (place / "x.png").write_bytes(png + b"annotated")
    refused(run("inspect", "a.rtl", "--plot", "x.png"), "changed since esp wrote it")
    assert (place / "x.png").read_bytes() == png + b"annotated"


def test_links_and_other_names_of_an_input_are_refused(place):
    os.link(place / "a.rtl", place / "hard.png")
    refused(run("inspect", "a.rtl", "--plot", "hard.png"), "is one of this command's inputs")
    os.symlink(place / "b.rtl", place / "soft.json")
    refused(run(*ANGULAR, "--json", "soft.json"), "is one of this command's inputs")
    os.symlink(place / "notes.txt", place / "link.json")
    refused(run("inspect", "a.rtl", "--json", "link.json"), "is a symbolic link")
    refused(run("inspect", "a.rtl", "--json", REGISTRY), "esp keeps for its own records")


@pytest.mark.slow
def test_a_figure_is_written_in_the_format_its_name_says(place):
    assert run("inspect", "a.rtl", "--plot", "x.pdf").exit_code == 0
    assert (place / "x.pdf").read_bytes().startswith(b"%PDF")
    first = (place / "x.pdf").read_bytes()
    assert run("iso230-2", "a.rtl", "--plot", "y.pdf").exit_code == 0
    assert (place / "y.pdf").read_bytes().startswith(b"%PDF")
    assert run("inspect", "a.rtl", "--plot", "x.pdf").exit_code == 0
    assert (place / "x.pdf").read_bytes() == first  # no date in it: the same bytes
    assert run("iso230-2", "a.rtl", "--plot", "y.PNG").exit_code == 0
    assert (place / "y.PNG").read_bytes().startswith(b"\x89PNG")
    refused(run("inspect", "a.rtl", "--plot", "x.svg"), "ending in .png or .pdf, found '.svg'")
    refused(run("iso230-2", "a.rtl", "--plot", "plot"), "found 'no suffix'")
    assert not (place / "x.svg").exists() and not (place / "plot").exists()


def test_the_angular_help_example_does_not_replace_the_shipped_file(tmp_path, monkeypatch):
    """The second example of ``esp angular --help``, run where the help says, once wrote
    over the shipped Xpitch.rta; it names a file of its own now, and the shipped one is
    refused as a target."""
    folder = tmp_path / "turning-centre"
    shutil.copytree(ROOT / "data" / "examples" / "turning-centre", folder)
    monkeypatch.chdir(folder)
    shipped = (folder / "Xpitch.rta").read_bytes()
    args = ["angular", "Xpos_z0.rtl", "Xpos_z800.rtl", "--displacement", "-800", "--datum"]
    refused(run(*args, "-560", "-o", "Xpitch.rta"), "--output Xpitch.rta", "esp did not write")
    assert (folder / "Xpitch.rta").read_bytes() == shipped
    assert "-o Xpitch.rta" not in run("angular", "--help").output


# -- 3. all or none across the outputs of a run -------------------------------------------


def _failing_rename(monkeypatch, fails_for: str):
    """os.replace refuses to move a staged output whose name starts with ``fails_for``
    into place (as a rename across file systems does, EXDEV); putting back what was set
    aside still works."""
    import esp.io.outputs as outputs

    real_replace = os.replace

    def replace(src, dst):
        name = Path(src).name
        if name.startswith(fails_for) and ".esp-old-" not in name and Path(dst).name[0] != ".":
            raise OSError(errno.EXDEV, "Invalid cross-device link", str(dst))
        return real_replace(src, dst)

    monkeypatch.setattr(outputs.os, "replace", replace)


@pytest.mark.parametrize("fails_for", [".R.esp-stage-", ".x.json."])
@pytest.mark.parametrize("earlier", [False, True])
def test_a_commit_that_fails_writes_none_of_the_outputs(place, monkeypatch, fails_for, earlier):
    """--out R whose move fails: --json x.json of the same run is not written either (and
    a move that fails for x.json puts R back); nothing staged is left behind."""
    if earlier:
        assert run("analyse", "machine.toml", "--out", "R", "--json", "x.json", "-q").exit_code == 0
    before = snapshot(place)
    _failing_rename(monkeypatch, fails_for)
    res = run("analyse", "machine.toml", "--out", "R", "--json", "x.json", "-q")
    assert res.exit_code == 2 and "Invalid cross-device link" in res.stderr, res.output
    assert snapshot(place) == before
    assert (place / "x.json").exists() == earlier and (place / "R").exists() == earlier
    assert sorted(p.name for p in place.iterdir() if p.name.startswith(".")) == (
        [REGISTRY] if earlier else []
    )


def test_a_mount_point_is_refused_before_any_work(place, monkeypatch):
    (place / "mnt").mkdir()
    real = os.path.realpath(place / "mnt")
    monkeypatch.setattr("esp.io.outputs.os.path.ismount", lambda p: os.fspath(p) == real)
    refused(run("analyse", "machine.toml", "--out", "mnt", "--json", "x.json"), "a mount point")
    assert not (place / "x.json").exists() and os.listdir(place / "mnt") == []


# -- 4. two runs into one --out -----------------------------------------------------------

DRIVER = """
import sys, time
from pathlib import Path

import esp.volumetric.report as bundle

go = Path(sys.argv[1])


def slow(result, staged, **kwargs):
    Path(staged, "report.pdf").write_bytes(b"%PDF-1.4 stand-in")
    if go.name != "-":
        (go.parent / "started").write_text("1")
        for _ in range(1500):
            if go.exists():
                break
            time.sleep(0.02)


bundle.write_report_files = slow
from esp.cli import main

main(sys.argv[2:], prog_name="esp")
"""


@pytest.mark.slow
def test_a_second_run_keeps_the_staging_folder_of_a_live_first(place):
    """Run A stages its report and waits; run B into the same --out starts, removes stale
    staging folders, and commits; A then commits too. B must not have removed A's live
    staging folder (both exit 0), but removes one whose owner is gone."""
    driver = place / "driver.py"
    driver.write_text(DRIVER, encoding="utf-8")
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    cmd = [sys.executable, str(driver)]
    args = ["analyse", "machine.toml", "--out", "R", "-q"]
    # a staging folder of a run that is gone: a process that has ended
    gone = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"], **_out())
    dead = place / f".R.esp-stage-{int(gone.stdout)}.1.abcdef"
    dead.mkdir()
    (dead / MARKER).write_text(
        json.dumps({"schema": "esp.folder/2", "files": {}, "staging": True}), encoding="utf-8"
    )
    first = subprocess.Popen([*cmd, str(place / "go"), *args], env=env, cwd=place, **_out())
    try:
        for _ in range(1500):
            if (place / "started").exists() or first.poll() is not None:
                break
            time.sleep(0.02)
        live = [p for p in place.iterdir() if p.name.startswith(".R.esp-stage-") and p != dead]
        assert len(live) == 1, first.communicate()
        second = subprocess.run([*cmd, "-", *args], env=env, cwd=place, **_out())
        assert second.returncode == 0, second.stderr
        assert live[0].is_dir()  # the live run's folder is kept ...
        assert not dead.exists()  # ... the dead one's removed
    finally:
        (place / "go").write_text("go", encoding="utf-8")
        out, err = first.communicate(timeout=120)
    assert first.returncode == 0, err
    assert (place / "R" / "report.pdf").is_file()
    assert sorted(p.name for p in place.iterdir() if p.name.startswith(".R")) == []


def test_stale_folders_are_removed_only_when_their_owner_is_gone(tmp_path):
    """The owner is in the name (pid.start-time): a folder of this live process is kept,
    one of an ended process or of an earlier process with the same pid removed, one
    whose marker names another host kept."""
    from esp.io.outputs import _start_time, remove_stale

    ended_process = subprocess.Popen(["true"])
    ended_process.wait()
    child = ended_process.pid
    me, start = os.getpid(), _start_time(os.getpid())
    marker = {"schema": "esp.folder/2", "files": {}, "folders": [], "staging": True}

    def stage(name: str, owner: dict | None = None) -> Path:
        folder = tmp_path / name
        folder.mkdir()
        doc = marker if owner is None else {**marker, "owner": owner}
        (folder / MARKER).write_text(json.dumps(doc), encoding="utf-8")
        return folder

    live = stage(f".R.esp-stage-{me}.{start}.live0001")
    ended = stage(f".R.esp-stage-{child}.{start}.gone0001")
    reused = stage(f".R.esp-old-{me}.{start + 1}.reused01")
    elsewhere = stage(f".R.esp-stage-{child}.1.other001", {"pid": child, "host": "elsewhere"})
    remove_stale(tmp_path / "R")
    assert live.is_dir() and elsewhere.is_dir()
    assert not ended.exists() and not reused.exists()


def _out() -> dict:
    return {"stdout": subprocess.PIPE, "stderr": subprocess.PIPE, "text": True}


# -- 5. diagnostics on standard error -----------------------------------------------------

WARNING_COMMANDS = [
    ("analyse", "tool.toml"),
    ("analyse", "tool.toml", "--at", "X=50,Y=50,Z=50"),
    ("compare", "tool.toml", "tool.toml"),
    ("diagonals", "tool.toml"),
    ("compensate", "tool.toml", "--format", "iso-csv", "--leave-uncorrected"),
]


def _warnings_of(doc: dict) -> list[str]:
    return doc.get("warnings", doc.get("analysis", {}).get("warnings"))


@pytest.mark.slow
@pytest.mark.parametrize("args", WARNING_COMMANDS, ids=lambda a: " ".join(a[:3]))
def test_warnings_go_to_standard_error_and_into_the_json(place, args):
    res = run(*args)
    assert res.exit_code == 0, res.output
    assert WARNING not in res.stdout
    assert res.stderr.startswith("esp: warning: ") and WARNING in res.stderr
    res = run(*args, "--json", "-")
    assert res.exit_code == 0, res.output
    assert any(WARNING in w for w in _warnings_of(json.loads(res.stdout)))  # JSON only
    assert WARNING in res.stderr
    res = run(*args, "--json", "r.json", "-q")
    assert res.exit_code == 0 and res.stdout == "" and res.stderr == "", res.output
    doc = json.loads((place / "r.json").read_text(encoding="utf-8"))
    assert any(WARNING in w for w in _warnings_of(doc))


def test_no_warnings_is_an_empty_list(place):
    res = run("diagonals", "machine.toml", "--json", "-")
    assert res.exit_code == 0 and res.stderr == ""
    assert json.loads(res.stdout)["warnings"] == []


# -- every --help example, twice, in a copy of the repository -------------------------------


def _examples() -> list[tuple[str, str, list[str]]]:
    """(command, folder to run in, argv) of every example in every command's --help."""
    ctx = click.Context(main)
    helps = [("esp", main.help or "")]
    helps += [(n, main.get_command(ctx, n).help or "") for n in main.list_commands(ctx)]
    found = []
    for name, text in helps:
        lines = text.replace("\\\n", " ").replace("\b\n", "").splitlines()
        folder, examples = ".", False
        for line in lines:
            if line.strip().startswith("Examples"):
                examples = True
                where = re.search(r"Examples \(in ([^)]+)\)", line)
                folder = where.group(1) if where else "."
            elif examples and line.strip().startswith("esp "):
                found.append((name, folder, shlex.split(line.strip())[1:]))
    return found


def test_every_command_has_examples():
    names = {name for name, _, _ in _examples()}
    assert names == {"esp", *main.list_commands(click.Context(main))}


def _hashes(folder: Path) -> dict[str, str]:
    return {
        str(p.relative_to(folder)): hashlib.sha256(p.read_bytes()).hexdigest()
        for p in sorted(folder.rglob("*"))
        if p.is_file()
    }


@pytest.mark.slow
def test_every_help_example_runs_twice_without_changing_a_shipped_file(
    tmp_path, monkeypatch, light_reports
):
    """Each example as its help gives it, from the root of a copy of the repository (or
    the folder its help names), twice: each ends with 0 (or 1 for a threshold a batch
    example exceeds), and no shipped file changes. The analysis report's pages are
    stubbed (they are tested elsewhere; which paths are written does not depend on
    them)."""
    shutil.copytree(ROOT / "data", tmp_path / "data")
    shipped = _hashes(tmp_path / "data")
    for attempt in (1, 2):
        for _name, folder, argv in _examples():
            monkeypatch.chdir(tmp_path / folder)
            redirect = None
            if ">" in argv:
                argv, redirect = argv[: argv.index(">")], argv[argv.index(">") + 1]
            res = CliRunner().invoke(main, argv)
            assert res.exit_code in ((0, 1) if argv[0] == "batch" else (0,)), (
                attempt,
                argv,
                res.output,
            )
            if redirect is not None:
                Path(redirect).write_text(res.stdout, encoding="utf-8")
    after = _hashes(tmp_path / "data")  # new files (the angular example's) may be added
    assert {name: after.get(name) for name in shipped} == shipped


def test_a_staging_name_is_shown_as_the_target_it_stands_for():
    """A full disk while a report folder is staged names the report's file, not the
    staging folder (whose name carries its owner: pid and start time)."""
    from esp.cli import _file_of

    exc = OSError(errno.ENOSPC, "No space left on device", "/x/.R.esp-stage-12.34.ab_c/r.pdf")
    assert _file_of(exc) == "/x/R/r.pdf"
    exc = OSError(errno.ENOSPC, "No space left on device", "/x/.result.json.a1b2c3d4.tmp")
    assert _file_of(exc) == "/x/result.json"
