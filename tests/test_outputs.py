"""Output safety (esp.io.outputs): never lose a user's file, all outputs or none."""

from __future__ import annotations

import json
import os
import shutil
from pathlib import Path

import pytest
from click.testing import CliRunner
from conftest import SMALL_MACHINE

from esp.cli import main
from esp.core.errors import DataError
from esp.io.outputs import MARKER, Outputs, is_esp_folder

EXAMPLE = Path(__file__).resolve().parent.parent / "data" / "examples" / "gantry"


@pytest.fixture(autouse=True)
def light_reports(monkeypatch):
    """The report's content is stubbed (the figures are tested elsewhere): these tests are
    about which folders are written, replaced or refused."""

    def stand_in(result, staged, **kwargs):
        Path(staged, "report.pdf").write_bytes(b"%PDF-1.4 stand-in")
        Path(staged, "result.json").write_text('{"schema": "esp.result/1"}', encoding="utf-8")

    monkeypatch.setattr("esp.volumetric.report.write_report_files", stand_in)


@pytest.fixture
def workdir(tmp_path, monkeypatch):
    """A user's working folder with a machine.toml, its data file and a .git folder."""
    (tmp_path / "machine.toml").write_text(SMALL_MACHINE, encoding="utf-8")
    (tmp_path / "X.csv").write_text(
        "# unit: um\ntarget_mm,run,direction,deviation\n0,1,forward,0\n100,1,forward,3\n",
        encoding="utf-8",
    )
    (tmp_path / ".git").mkdir()
    (tmp_path / ".git" / "HEAD").write_text("ref: refs/heads/main\n", encoding="utf-8")
    monkeypatch.chdir(tmp_path)
    return tmp_path


def run(*args: str):
    return CliRunner().invoke(main, list(args))


def snapshot(folder: Path) -> dict[str, bytes]:
    return {
        str(p.relative_to(folder)): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()
    }


def test_out_dot_after_json_in_the_same_folder_deletes_nothing(workdir):
    assert run("analyse", "machine.toml", "--json", "result.json", "-q").exit_code == 0
    before = snapshot(workdir)
    res = run("analyse", "machine.toml", "--out", ".")
    assert res.exit_code == 2
    assert "current folder" in res.output and res.output.count("\n") == 1
    assert snapshot(workdir) == before


def test_a_folder_holding_an_input_or_above_the_current_folder_is_refused(workdir):
    sub = workdir / "sub"
    sub.mkdir()
    os.chdir(sub)
    res = run("analyse", "../machine.toml", "--out", "..")
    assert res.exit_code == 2 and "ancestor of the current folder" in res.output
    os.chdir(workdir)
    outputs = Outputs([workdir / "sub" / "data.csv"])
    with pytest.raises(DataError, match=r"holds an input of this command \(data.csv\)"):
        outputs.folder(workdir / "sub", "--out")


def test_user_files_in_an_earlier_report_are_never_deleted(workdir):
    assert run("analyse", "machine.toml", "--out", "R", "-q").exit_code == 0
    assert is_esp_folder(workdir / "R")
    (workdir / "R" / "certificate.pdf").write_bytes(b"%PDF signed")
    res = run("analyse", "machine.toml", "--out", "R", "-q")
    assert res.exit_code == 2 and "certificate.pdf" in res.output
    assert (workdir / "R" / "certificate.pdf").read_bytes() == b"%PDF signed"


def test_a_rerun_replaces_only_a_folder_esp_wrote(workdir):
    assert run("analyse", "machine.toml", "--out", "R", "-q").exit_code == 0
    listed = json.loads((workdir / "R" / MARKER).read_text(encoding="utf-8"))["files"]
    assert "report.pdf" in listed and "result.json" in listed
    assert listed["report.pdf"]["size"] == len(b"%PDF-1.4 stand-in")
    assert run("analyse", "machine.toml", "--out", "R", "-q").exit_code == 0  # unchanged
    # a folder that merely looks like a report (a result.json of esp, no marker) is refused
    fake = workdir / "looks-like"
    fake.mkdir()
    shutil.copy(workdir / "R" / "result.json", fake / "result.json")
    res = run("analyse", "machine.toml", "--out", "looks-like", "-q")
    assert res.exit_code == 2 and "esp did not write it" in res.output


def test_a_file_edited_in_a_report_folder_is_never_replaced(workdir):
    """A signed report.pdf saved over esp's: the marker lists the name, but its size and
    hash are not what esp wrote, so the next --out R refuses, naming the file."""
    assert run("analyse", "machine.toml", "--out", "R", "-q").exit_code == 0
    (workdir / "R" / "report.pdf").write_bytes(b"%PDF-1.4 signed by the customer")
    res = run("analyse", "machine.toml", "--out", "R", "-q")
    assert res.exit_code == 2 and res.stderr.count("\n") == 1, res.output
    assert "changed since esp wrote them (report.pdf)" in res.stderr
    assert (workdir / "R" / "report.pdf").read_bytes() == b"%PDF-1.4 signed by the customer"
    # the same size, other bytes: the hash tells them apart
    (workdir / "R" / "report.pdf").write_bytes(b"%PDF-1.4 stand-IN")
    res = run("analyse", "machine.toml", "--out", "R", "-q")
    assert res.exit_code == 2 and "report.pdf" in res.stderr
    # in a subfolder, at any depth: the marker records every file esp wrote
    (workdir / "R" / "report.pdf").write_bytes(b"%PDF-1.4 stand-in")
    assert is_esp_folder(workdir / "R")


def test_no_command_writes_over_its_inputs(workdir):
    before = snapshot(workdir)
    res = run("analyse", "machine.toml", "--json", "machine.toml")
    assert res.exit_code == 2 and "inputs" in res.output
    res = run("analyse", "machine.toml", "--json", "X.csv")
    assert res.exit_code == 2
    os.link(workdir / "X.csv", workdir / "same.csv")  # the same file under another name
    res = run("analyse", "machine.toml", "--json", "same.csv")
    assert res.exit_code == 2
    (workdir / "same.csv").unlink()
    assert snapshot(workdir) == before


def test_outputs_are_all_or_nothing(workdir):
    (workdir / "afile").write_text("x", encoding="utf-8")
    res = run("analyse", "machine.toml", "--out", "R", "--json", "afile/r.json")
    assert res.exit_code == 2
    assert "afile is a file, not a folder" in res.output
    assert not (workdir / "R").exists()
    # a failure while the outputs are staged leaves every target as it was
    outputs = Outputs()
    target = outputs.file(workdir / "r.json", "--json")
    folder = outputs.folder(workdir / "F", "--out")
    with pytest.raises(RuntimeError), outputs:
        outputs.write_file(target, "{}")
        (outputs.stage_folder(folder) / "a.txt").write_text("a", encoding="utf-8")
        raise RuntimeError("drawing failed")
    assert not (workdir / "r.json").exists() and not (workdir / "F").exists()
    assert not [p for p in workdir.iterdir() if p.name.startswith(".") and p.name != ".git"]


def test_targets_are_checked_against_each_other(workdir):
    outputs = Outputs()
    outputs.folder(workdir / "R", "--out")
    with pytest.raises(DataError, match="inside the folder of --out"):
        outputs.file(workdir / "R" / "r.json", "--json")
    outputs.file(workdir / "r.json", "--json")
    with pytest.raises(DataError, match="also the target of --json"):
        outputs.file(workdir / "r.json", "--csv")
    with pytest.raises(DataError, match="is a folder"):
        Outputs().file(workdir / ".git", "--json")


def test_a_killed_runs_staging_folder_is_removed_by_the_next_run(workdir):
    stale = workdir / ".R.esp-stage-abc123"
    stale.mkdir()
    (stale / MARKER).write_text(
        json.dumps({"schema": "esp.folder/1", "files": [], "staging": True}), encoding="utf-8"
    )
    (stale / "report.pdf").write_bytes(b"half")
    # killed before its marker was written, or while writing it: nothing else in them
    empty = workdir / ".R.esp-stage-empty1"
    empty.mkdir()
    cut = workdir / ".R.esp-old-cut123"
    cut.mkdir()
    (cut / MARKER).write_text('{"schema": "esp.fol', encoding="utf-8")
    mine = workdir / ".R.esp-stage-not-esp"  # same name pattern, no marker: not touched
    mine.mkdir()
    (mine / "notes.txt").write_text("mine", encoding="utf-8")
    theirs = workdir / ".R.esp-old-theirs"  # an unreadable marker beside a file: kept
    theirs.mkdir()
    (theirs / MARKER).write_text("not json", encoding="utf-8")
    (theirs / "data.csv").write_text("1,2", encoding="utf-8")
    assert run("analyse", "machine.toml", "--out", "R", "-q").exit_code == 0
    assert not stale.exists() and not empty.exists() and not cut.exists()
    assert (mine / "notes.txt").exists() and (theirs / "data.csv").exists()


def test_an_error_while_a_staging_folder_is_made_leaves_nothing(workdir, monkeypatch):
    """The staging folder is known to the outputs from the moment it exists: an error
    while its marker is written (a full disk, an interrupt) discards it."""
    import esp.io.outputs as outputs_module

    def fail(folder, staging=False):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(outputs_module, "_write_marker", fail)
    outputs = Outputs()
    target = outputs.folder(workdir / "R", "--out")
    with pytest.raises(OSError), outputs:
        outputs.stage_folder(target)
    assert sorted(p.name for p in workdir.iterdir() if p.name.startswith(".R")) == []


def test_a_file_put_in_the_report_folder_during_the_run_is_kept(workdir, monkeypatch):
    """The folder was checked before the work; a file the user puts into it while the
    report is being made stops the commit: the file and the earlier report stay, nothing
    staged is left behind."""
    assert run("analyse", "machine.toml", "--out", "R", "-q").exit_code == 0
    before = snapshot(workdir / "R")

    def meanwhile(result, staged, **kwargs):
        Path(staged, "report.pdf").write_bytes(b"%PDF-1.4 new")
        (workdir / "R" / "notes.txt").write_text("signed certificate", encoding="utf-8")

    monkeypatch.setattr("esp.volumetric.report.write_report_files", meanwhile)
    res = run("analyse", "machine.toml", "--out", "R", "-q")
    assert res.exit_code == 2
    assert "appeared in it during the run (notes.txt)" in res.output
    after = snapshot(workdir / "R")
    assert after.pop("notes.txt") == b"signed certificate"
    assert after == before
    assert not [p.name for p in workdir.iterdir() if p.name.startswith(".R")]


def test_a_folder_made_at_the_target_during_the_run_is_kept(workdir, monkeypatch):
    def meanwhile(result, staged, **kwargs):
        Path(staged, "report.pdf").write_bytes(b"%PDF-1.4 new")
        (workdir / "R").mkdir()
        (workdir / "R" / "mine.txt").write_text("mine", encoding="utf-8")

    monkeypatch.setattr("esp.volumetric.report.write_report_files", meanwhile)
    res = run("analyse", "machine.toml", "--out", "R", "-q")
    assert res.exit_code == 2
    assert snapshot(workdir / "R") == {"mine.txt": b"mine"}


def test_a_folder_written_to_as_it_is_set_aside_is_put_back(workdir, monkeypatch):
    """The last guard: a file that arrives between the commit's check and the move is found
    in the set-aside folder, which is then put back as it was."""
    import esp.io.outputs as outputs

    assert run("analyse", "machine.toml", "--out", "R", "-q").exit_code == 0
    out = Outputs()
    target = out.folder("R", "--out")
    staged = out.stage_folder(target)
    (staged / "report.pdf").write_bytes(b"new")
    monkeypatch.setattr(outputs, "_check_replaceable", lambda target: None)  # the race
    (workdir / "R" / "late.txt").write_text("late", encoding="utf-8")
    with pytest.raises(DataError, match="changed while esp replaced it"):
        out.commit()
    assert (workdir / "R" / "late.txt").read_text(encoding="utf-8") == "late"
    assert (workdir / "R" / "report.pdf").read_bytes() == b"%PDF-1.4 stand-in"
    assert not staged.exists()
    assert not [p.name for p in workdir.iterdir() if p.name.startswith(".R")]
