"""Worker processes never outlive esp: after ``kill -9`` or ``kill -TERM`` of ``esp batch
--jobs N`` (or of a report drawing its figures in workers), no worker is left running
(docs/reliability.md, "Batch"). Each test runs esp in a subprocess whose work is made to
hang, kills it, and checks within a few seconds that none of its workers remains."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pytest
from test_batch import machine_text, write

from esp.report.workers import SIGTERM_EXIT

ROOT = Path(__file__).parent.parent

pytestmark = pytest.mark.skipif(sys.platform == "win32", reason="POSIX signals")

# esp batch in a subprocess: each machine's analysis writes its process id into PIDS and
# then hangs, as a long analysis does
BATCH = """
import os, sys, time
from pathlib import Path
import esp.core.analysis

PIDS = Path(sys.argv[1])

def analyse(machine, progress=None):
    (PIDS / str(os.getpid())).write_text("", encoding="utf-8")
    time.sleep(120)

esp.core.analysis.analyse = analyse
from esp.cli import main
sys.argv = ["esp", "batch", sys.argv[2], "--out", sys.argv[3], "--jobs", "2"]
main()
"""

# a report in a subprocess: every figure's PNG made in a worker writes its process id and
# hangs
REPORT = """
import os, sys, time
from pathlib import Path
import esp
from esp.core.analysis import analyse
from esp.volumetric import report as bundle

def make(k):
    if os.getpid() != PARENT:
        (Path(sys.argv[1]) / str(os.getpid())).write_text("", encoding="utf-8")
        time.sleep(120)

PARENT = os.getpid()
result = analyse(esp.load_machine(sys.argv[2]))
bundle._png_in_worker = make
bundle.write_report(result, sys.argv[3], jobs=3)
"""


def alive(pid: int) -> bool:
    """Whether process ``pid`` exists and is not a zombie (a dead process not yet reaped,
    as happens to orphans where the init process does not reap them)."""
    try:
        with open(f"/proc/{pid}/stat", encoding="ascii") as f:
            return f.read().rsplit(")", 1)[1].split()[0] != "Z"
    except FileNotFoundError:
        return False
    except OSError:  # no /proc: ask the kernel
        try:
            os.kill(pid, 0)
        except ProcessLookupError:
            return False
        return True


def start(
    tmp_path: Path, script: str, *args: str, workers: int
) -> tuple[subprocess.Popen, list[int]]:
    pids = tmp_path / "pids"
    pids.mkdir()
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    proc = subprocess.Popen(
        [sys.executable, "-c", textwrap.dedent(script), str(pids), *args],
        cwd=tmp_path,
        env=env,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
    )
    deadline = time.monotonic() + 60
    while len(list(pids.iterdir())) < workers:
        if proc.poll() is not None:
            pytest.fail(f"esp ended before its workers started: {proc.stderr.read()!r}")
        if time.monotonic() > deadline:
            proc.kill()
            pytest.fail("the workers did not start")
        time.sleep(0.05)
    found = [int(p.name) for p in pids.iterdir()]
    assert os.getpid() not in found and proc.pid not in found
    return proc, found


def gone_within(pids: list[int], seconds: float) -> list[int]:
    deadline = time.monotonic() + seconds
    while time.monotonic() < deadline:
        left = [p for p in pids if alive(p)]
        if not left:
            return []
        time.sleep(0.05)
    left = [p for p in pids if alive(p)]
    for p in left:  # do not leave them behind for the rest of the suite
        os.kill(p, signal.SIGKILL)
    return left


def fleet(tmp_path: Path) -> Path:
    root = tmp_path / "fleet"
    for name in ("alpha", "beta", "gamma"):
        write(root / name / "machine.toml", machine_text(name, 3.0))
    return root


@pytest.mark.slow
@pytest.mark.parametrize("sig", [signal.SIGKILL, signal.SIGTERM])
def test_batch_workers_end_with_their_parent(tmp_path, sig):
    proc, workers = start(tmp_path, BATCH, str(fleet(tmp_path)), "reports", workers=2)
    proc.send_signal(sig)
    code = proc.wait(30)
    assert gone_within(workers, 5.0) == [], "workers left running after the parent died"
    if sig == signal.SIGTERM:
        assert code == SIGTERM_EXIT, proc.stderr.read()
        # the batch's staging folder went with it, and no report was written
        assert sorted(p.name for p in tmp_path.iterdir()) == ["fleet", "pids"]
    proc.stderr.close()


@pytest.mark.slow
def test_report_workers_end_with_their_parent(tmp_path):
    machine = str(ROOT / "tests" / "data" / "config" / "inline.toml")  # has figures
    proc, workers = start(tmp_path, REPORT, machine, "R", workers=1)
    proc.send_signal(signal.SIGKILL)
    proc.wait(30)
    assert gone_within(workers, 5.0) == []
    proc.stderr.close()


def test_a_worker_whose_parent_is_gone_ends_at_once(tmp_path):
    """die_with_parent, given a parent id that is not its parent's, ends the process."""
    code = subprocess.run(
        [sys.executable, "-c", "from esp.report.workers import die_with_parent; die_with_parent(1)"
         "\nimport time; time.sleep(30)"],
        env={**os.environ, "PYTHONPATH": str(ROOT)},
        timeout=20,
    ).returncode  # fmt: skip
    assert code == 1


def _running(pid: int) -> bool:
    """Whether process ``pid`` exists and is not a zombie (Linux's /proc)."""
    try:
        with open(f"/proc/{pid}/stat") as f:
            state = f.read().rsplit(")", 1)[1].split()[0]
    except (OSError, IndexError):
        return False
    return state not in ("Z", "X")


def test_stop_pool_ends_the_workers_it_started_and_no_other_child():
    """stop_pool ends the workers of a pool of start_pool, found by the ids they report,
    and leaves alone a child process the caller started itself."""
    import multiprocessing

    from esp.report.workers import start_pool, stop_pool

    context = multiprocessing.get_context("fork")
    other = context.Process(target=time.sleep, args=(30,))
    other.start()
    try:
        pool = start_pool(2, mp_context=context)
        ran = {pool.submit(os.getpid).result(timeout=30) for _ in range(4)}
        assert os.getpid() not in ran and other.pid not in ran
        workers = [p for p in multiprocessing.active_children() if p.pid in ran]
        assert workers
        for _ in range(2):  # busy workers: only ending them lets the pool shut down soon
            pool.submit(time.sleep, 60)
        started = time.monotonic()
        stop_pool(pool)
        assert time.monotonic() - started < 30
        # ended: the process is gone or a zombie. Not Process.is_alive(): the executor's
        # own thread reaps its workers too, and a Process whose child another thread
        # reaped reports itself alive (its return code is never set)
        deadline = time.monotonic() + 10  # a loaded machine may take a moment
        while any(map(_running, ran)) and time.monotonic() < deadline:
            time.sleep(0.05)
        assert not any(map(_running, ran))
        assert other.is_alive()
    finally:
        other.kill()
        other.join()


def _never_reports(ids, initializer, initargs):
    """A worker stuck before it reports its id, deaf to SIGTERM (as one whose fork
    inherited a lock another thread held: its Python handler never runs)."""
    import signal

    signal.signal(signal.SIGTERM, signal.SIG_IGN)
    time.sleep(600)


def test_stop_pool_ends_a_worker_that_never_reported(monkeypatch):
    """Such a worker kept the executor's own shutdown waiting for ever (a batch whose pool
    a killed worker broke hung on pool.shutdown); stop_pool finds it among the children
    started since the pool was made and kills it."""
    import multiprocessing
    import threading

    import esp.report.workers as workers

    monkeypatch.setattr(workers, "_report_id", _never_reports)
    context = multiprocessing.get_context("fork")
    pool = workers.start_pool(1, mp_context=context)
    pool.submit(os.getpid)
    deadline = time.monotonic() + 10
    while not multiprocessing.active_children() and time.monotonic() < deadline:
        time.sleep(0.05)
    stuck = [p.pid for p in multiprocessing.active_children()]
    assert stuck
    stopper = threading.Thread(target=workers.stop_pool, args=(pool,), daemon=True)
    stopper.start()
    stopper.join(60)  # a hang guard, not a speed claim: SIGKILL comes after 5 s
    assert not stopper.is_alive()
    assert not any(map(_running, stuck))
