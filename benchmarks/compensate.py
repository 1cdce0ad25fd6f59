"""What ``esp compensate --predict`` costs against the same command without it.

Runs ``esp compensate`` on the shipped gantry in fresh processes, with and without
``--predict``, the two alternating so that a change of load falls on both, and prints the
median wall time of each and their ratio, for:

* one format (``isg-volumetric``) with ``--out``;
* all five formats of docs/compensation.md (``--leave-uncorrected``) with ``--out``.

The goal (issue 22): ``--predict`` within 1.5x the command without it. The figure is
written only with ``--plot``, which is not timed (it costs matplotlib's import).

esp's modules are compiled to bytecode first, as an installation does, so that no run
pays for compiling them.

Run:  python benchmarks/compensate.py [--repeat N]
"""

from __future__ import annotations

import argparse
import compileall
import os
import platform
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
GANTRY = ROOT / "data" / "examples" / "gantry" / "machine.toml"
ALL = ("linuxcnc", "twincat-cross", "twincat-plane", "isg-volumetric", "iso-csv")


def wall(args: list[str], out: Path) -> float:
    """Wall seconds of one fresh ``python -m esp`` process writing into ``out``."""
    shutil.rmtree(out, ignore_errors=True)
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    start = time.perf_counter()
    subprocess.run(
        [sys.executable, "-m", "esp", *args, "--out", str(out), "-q"],
        check=True,
        cwd=ROOT,
        env=env,
        capture_output=True,
    )
    return time.perf_counter() - start


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=7)
    args = ap.parse_args()
    if args.repeat < 5:
        ap.error("--repeat: at least 5 runs of each")
    compileall.compile_dir(ROOT / "esp", quiet=1)  # as installed: bytecode cached
    print(
        f"{platform.processor() or platform.machine()}, {os.cpu_count()} cores, Python "
        f"{platform.python_version()}, load average {os.getloadavg()[0]:.2f}; wall seconds, "
        f"medians of {args.repeat} fresh processes, alternating"
    )
    cases = [
        ("isg-volumetric", ["--format", "isg-volumetric"]),
        ("five formats", [x for f in ALL for x in ("--format", f)] + ["--leave-uncorrected"]),
    ]
    with tempfile.TemporaryDirectory() as tmp:
        for label, fmt_args in cases:
            base = ["compensate", str(GANTRY), *fmt_args]
            times: dict[bool, list[float]] = {False: [], True: []}
            wall(base, Path(tmp) / "warm")  # the files in the page cache for both
            for _ in range(args.repeat):
                for predict in (False, True):
                    run = base + (["--predict"] if predict else [])
                    times[predict].append(wall(run, Path(tmp) / "comp"))
            without = statistics.median(times[False])
            with_ = statistics.median(times[True])
            print(
                f"  {label:<16} without --predict {without:6.3f} s   with {with_:6.3f} s   "
                f"ratio {with_ / without:4.2f}x   (goal <= 1.5x)"
            )


if __name__ == "__main__":
    main()
