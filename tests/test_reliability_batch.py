"""``esp batch`` under attack: a worker killed by the system, a folder that cannot be
searched, control characters in names, and the output folder's safety rules
(docs/reliability.md, "Batch")."""

from __future__ import annotations

import csv
import json
import os
import signal
from pathlib import Path

import pytest
from click.testing import CliRunner
from test_batch import machine_text, write

from esp.cli import main
from esp.io.outputs import _write_marker

MARKER = ".esp-folder.json"


@pytest.fixture
def fleet(tmp_path) -> Path:
    """Four good machines: Alpha 3 µm, Beta 8 µm, Gamma 5 µm, Delta 2 µm."""
    root = tmp_path / "fleet"
    for name, um in (("Alpha", 3.0), ("Beta", 8.0), ("Gamma", 5.0), ("Delta", 2.0)):
        write(root / name.lower() / "machine.toml", machine_text(name, um))
    return root


@pytest.fixture
def fake_reports(monkeypatch):
    """A result.json stub instead of the (slow) report; the folder logic stays real."""

    def stand_in(result, staged, **kwargs):
        doc = {"schema": "esp.result/1", "name": result.machine.name}
        (Path(staged) / "result.json").write_text(json.dumps(doc), encoding="utf-8")

    monkeypatch.setattr("esp.volumetric.report.write_report_files", stand_in)


def batch(*args):
    return CliRunner().invoke(main, ["batch", *map(str, args)])


def rows(out: Path) -> dict[str, dict[str, str]]:
    with open(out / "summary.csv", newline="", encoding="utf-8") as f:
        return {r["file"]: r for r in csv.DictReader(f)}


def kill_when(monkeypatch, should_kill) -> None:
    """Make the analysis kill its own process (SIGKILL, as the out-of-memory killer does)
    for the machines ``should_kill(machine)`` picks; worker processes are forked after
    this, so they see it."""
    import esp.core.analysis

    real = esp.core.analysis.analyse

    def analyse(machine, progress=None):
        if should_kill(machine):
            os.kill(os.getpid(), signal.SIGKILL)
        return real(machine, progress)

    monkeypatch.setattr("esp.core.analysis.analyse", analyse)


# -- a worker killed ----------------------------------------------------------------------------


def test_a_machine_that_kills_its_worker_is_the_only_error(
    fleet, tmp_path, fake_reports, monkeypatch
):
    kill_when(monkeypatch, lambda m: m.name == "Beta")
    out = tmp_path / "out"
    res = batch(fleet, "--out", out, "--jobs", "2")
    assert res.exit_code == 2, res.output
    found = rows(out)
    assert {f: r["verdict"] for f, r in found.items()} == {
        "alpha/machine.toml": "pass",
        "beta/machine.toml": "error",
        "delta/machine.toml": "pass",
        "gamma/machine.toml": "pass",
    }
    assert "killed twice" in found["beta/machine.toml"]["error"]
    assert "BrokenProcessPool" not in res.output
    assert found["gamma/machine.toml"]["volumetric_um"] == "5.000"
    # no staging folder of a killed worker is left behind
    assert sorted(p.name for p in out.iterdir()) == [
        MARKER,
        "alpha__machine",
        "delta__machine",
        "gamma__machine",
        "summary.csv",
        "summary.md",
        "summary.pdf",
    ]


def test_a_worker_killed_before_every_machine_is_queued(fleet, tmp_path, fake_reports, monkeypatch):
    """Alpha kills its worker before the other machines are submitted to the pool (a
    loaded machine can schedule it so): the submissions that find the pool broken are
    rerun like the lost ones, not a crash of the batch."""
    import concurrent.futures

    import esp.batch.run

    kill_when(monkeypatch, lambda m: m.name == "Alpha")
    first = []

    class SlowQueue(concurrent.futures.ProcessPoolExecutor):
        def submit(self, fn, /, *args, **kwargs):
            future = super().submit(fn, *args, **kwargs)
            if not first:  # let the first machine kill its worker before queueing more
                first.append(future)
                concurrent.futures.wait([future])
            return future

    import esp.report.workers

    # the pools of esp batch are made by esp.report.workers.start_pool
    monkeypatch.setattr(esp.report.workers, "ProcessPoolExecutor", SlowQueue)
    out = tmp_path / "out"
    res = batch(fleet, "--out", out, "--jobs", "2")
    assert res.exit_code == 2, res.output
    assert first and isinstance(first[0].exception(), esp.batch.run.BrokenProcessPool)
    assert {f: r["verdict"] for f, r in rows(out).items()} == {
        "alpha/machine.toml": "error",
        "beta/machine.toml": "pass",
        "delta/machine.toml": "pass",
        "gamma/machine.toml": "pass",
    }
    assert "killed twice" in rows(out)["alpha/machine.toml"]["error"]


def test_a_machine_killed_once_is_analysed_again(fleet, tmp_path, fake_reports, monkeypatch):
    """The first attempt at Gamma kills its worker (and the machines sharing the pool are
    lost with it); the fresh worker of the second attempt succeeds: every row passes."""
    flag = tmp_path / "killed-once"

    def first_time(machine) -> bool:
        if machine.name != "Gamma" or flag.exists():
            return False
        flag.write_text("x", encoding="utf-8")
        return True

    kill_when(monkeypatch, first_time)
    res = batch(fleet, "--out", tmp_path / "out", "--jobs", "3")
    assert res.exit_code == 0, res.output
    assert flag.exists()
    assert {r["verdict"] for r in rows(tmp_path / "out").values()} == {"pass"}
    assert len([ln for ln in res.output.splitlines() if ln.startswith("ok ")]) == 4


# -- a folder that cannot be searched --------------------------------------------------------


def test_unreadable_subfolder_is_an_error_row(fleet, tmp_path, fake_reports, monkeypatch):
    locked = fleet / "locked"
    write(locked / "machine.toml", machine_text("Locked", 1.0))
    real = os.scandir

    def scandir(path="."):
        if os.fspath(path) == os.fspath(locked):
            raise PermissionError(13, "Permission denied", os.fspath(path))
        return real(path)

    monkeypatch.setattr(os, "scandir", scandir)
    out = tmp_path / "out"
    res = batch(fleet, "--out", out)
    assert res.exit_code == 2, res.output
    found = rows(out)
    assert list(found) == [
        "alpha/machine.toml",
        "beta/machine.toml",
        "delta/machine.toml",
        "gamma/machine.toml",
        "locked/",
    ]
    error = found["locked/"]["error"]
    assert error == f"{locked}: the folder cannot be searched: Permission denied"
    assert found["locked/"]["report"] == ""
    assert f"err  locked/  {error}" in res.output.splitlines()
    assert "5 machines: 4 pass, 0 fail, 1 error" in (out / "summary.md").read_text("utf-8")


# -- control characters ------------------------------------------------------------------------


def test_control_characters_do_not_split_rows_or_lines(tmp_path, fake_reports):
    root = tmp_path / "root"
    write(root / "we\nird" / "machine.toml", machine_text("Line\\nBreak\\u001b[31m|x", 3.0))
    write(root / "plain" / "machine.toml", machine_text("Plain", 2.0))
    write(root / "bro\rken" / "machine.toml", "[machine\n")
    out = tmp_path / "out"
    res = batch(root, "--out", out)
    assert res.exit_code == 2, res.output
    lines = res.output.splitlines()
    assert len(lines) == 4  # three machines and the count
    assert "ok   we\\nird/machine.toml  3.000 um  pass" in lines
    assert any(ln.startswith("err  bro\\rken/machine.toml  ") for ln in lines)
    md = (out / "summary.md").read_text(encoding="utf-8").splitlines()
    table = [ln for ln in md if ln.startswith("| ") and "---" not in ln]
    assert len(table) == 4  # the header and three rows
    weird = next(ln for ln in table if "we\\nird" in ln)
    assert "| Line\\nBreak\\x1b[31m\\|x |" in weird
    # the CSV keeps the exact text (quoted), as a CSV reader reads it back
    assert rows(out)["we\nird/machine.toml"]["name"] == "Line\nBreak\x1b[31m|x"


# -- the output folder -------------------------------------------------------------------------


def test_output_folder_is_all_or_nothing(fleet, tmp_path, fake_reports, monkeypatch):
    out = tmp_path / "out"
    assert batch(fleet, "--out", out).exit_code == 0
    before = {p: p.read_bytes() for p in out.rglob("*") if p.is_file()}

    def broken(*args, **kwargs):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr("esp.batch.run.write_summary", broken)
    (fleet / "beta" / "machine.toml").unlink()
    write(fleet / "alpha" / "machine.toml", machine_text("Alpha, new data", 4.0))
    res = batch(fleet, "--out", out)
    assert res.exit_code == 2 and "No space left on device" in res.stderr
    # the earlier output is untouched and no staging folder is left beside it
    assert {p: p.read_bytes() for p in out.rglob("*") if p.is_file()} == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["fleet", "out"]


@pytest.mark.parametrize("where", ["top", "report"])
def test_a_users_file_in_the_output_is_never_replaced(fleet, tmp_path, fake_reports, where):
    out = tmp_path / "out"
    assert batch(fleet, "--out", out).exit_code == 0
    note = (out if where == "top" else out / "alpha__machine") / "certificate.pdf"
    note.write_bytes(b"signed")
    res = batch(fleet, "--out", out)
    assert res.exit_code == 2 and res.stderr.count("\n") == 1
    assert "holds files esp did not write" in res.stderr and "certificate.pdf" in res.stderr
    assert note.read_bytes() == b"signed"


def test_a_folder_esp_did_not_write_is_refused(fleet, tmp_path, fake_reports):
    out = tmp_path / "out"
    write(out / "notes.txt", "mine")
    res = batch(fleet, "--out", out)
    assert res.exit_code == 2 and "esp did not write" in res.stderr
    assert sorted(p.name for p in out.iterdir()) == ["notes.txt"]


@pytest.mark.parametrize(
    ("args", "fragment"),
    [
        (("{fleet}", "--out", "{fleet}"), "--out {fleet}: holds an input of this command"),
        (("{fleet}/alpha", "--out", "{fleet}"), "holds an input of this command (alpha)"),
        (("{fleet}/alpha/machine.toml", "--out", "{fleet}"), "(machine.toml)"),
        (("{fleet}", "--out", "."), "is the current folder"),
    ],
)
def test_inputs_inside_the_output_are_refused(fleet, fake_reports, args, fragment, monkeypatch):
    monkeypatch.chdir(fleet.parent)
    res = batch(*(a.format(fleet=fleet) for a in args))
    assert res.exit_code == 2, res.output
    assert fragment.format(fleet=fleet) in res.stderr and res.stderr.count("\n") == 1
    assert not (fleet / MARKER).exists()


def test_a_data_file_inside_the_output_folder(fleet, tmp_path, fake_reports):
    out = tmp_path / "out"
    assert batch(fleet, "--out", out).exit_code == 0
    # a machine whose data file is a file of the output folder: replacing the folder at
    # the end would remove it, so that machine is refused (and only that one)
    text = machine_text("Odd", 1.0).replace(
        "linear = { points = [[0, 0], [100, 1.0]] }", 'linear = "../../out/alpha__machine/x.csv"'
    )
    write(fleet / "odd" / "machine.toml", text)
    write(
        out / "alpha__machine" / "x.csv", "target_mm,run,direction,deviation\n0,1,+,0\n100,1,+,1\n"
    )
    _write_marker(out)  # as if esp had written x.csv: the marker records it
    res = batch(fleet, "--out", out)
    assert res.exit_code == 2, res.output
    odd = rows(out)["odd/machine.toml"]
    assert "lies inside the output folder" in odd["error"]
    assert rows(out)["alpha/machine.toml"]["verdict"] == "pass"
