"""SIGTERM during a command that writes a report folder removes its staging folder, as
``esp batch`` does, and exits with 143 (docs/reliability.md, "Interrupted runs")."""

from __future__ import annotations

import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from esp.report.workers import SIGTERM_EXIT

ROOT = Path(__file__).parent.parent

pytestmark = pytest.mark.skipif(sys.platform == "win32", reason="POSIX signals")

# esp analyse --out in a subprocess: writing the staged report says so and then hangs, as
# a long report does
ANALYSE = """
import sys, time
from pathlib import Path
import esp.volumetric.report

READY = Path(sys.argv[1])

def write_report_files(analysis, folder, **kwargs):
    (Path(folder) / "half-written.txt").write_text("", encoding="utf-8")
    READY.write_text(str(folder), encoding="utf-8")
    time.sleep(120)

esp.volumetric.report.write_report_files = write_report_files
from esp.cli import main
sys.argv = ["esp", *sys.argv[2:]]
main()
"""


def run_until_staged(tmp_path: Path, *args: str) -> tuple[subprocess.Popen[bytes], Path]:
    ready = tmp_path / "ready"
    proc = subprocess.Popen(
        [sys.executable, "-c", ANALYSE, str(ready), *args],
        cwd=ROOT,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
    )
    deadline = time.monotonic() + 60
    while not ready.exists() or not ready.read_text(encoding="utf-8"):
        assert proc.poll() is None, proc.stderr.read() if proc.stderr else ""
        assert time.monotonic() < deadline, "the report was never staged"
        time.sleep(0.02)
    return proc, Path(ready.read_text(encoding="utf-8"))


@pytest.mark.slow
def test_sigterm_during_analyse_out_removes_the_staging_folder(tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    proc, staged = run_until_staged(
        tmp_path, "analyse", "data/examples/gantry/machine.toml", "--out", str(out / "report")
    )
    assert staged.is_dir() and staged.parent == out
    proc.send_signal(signal.SIGTERM)
    code = proc.wait(30)
    assert proc.stderr is not None
    err = proc.stderr.read().decode()
    proc.stderr.close()
    assert code == SIGTERM_EXIT, err
    assert "Traceback" not in err
    assert list(out.iterdir()) == []  # neither the staging folder nor a report
