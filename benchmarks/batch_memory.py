"""Peak memory of a batch in one process, against the batch of one machine.

Each count runs in a fresh Python process: ``esp.batch.run.run_batch`` with ``jobs=1`` (every
machine analysed and reported in this one process) on the shipped gantry at the MCP
(``data/examples/gantry/machine.toml``) repeated ``N`` times, its reports made in that
process (a report is made in one process; no worker is forked, so that the figure is the
memory of that process alone). The
peak resident set size is the process's own ``ru_maxrss`` (:func:`resource.getrusage`)
read at its end; it also prints the resident size after each report and how many objects
the collector tracks then.

Printed: the machine and its load, then per count the peak in MiB and its ratio to the
peak of one machine (goal: 12 machines within 1.2x one).

Run from the repository root:  python benchmarks/batch_memory.py [--counts 1 2 4 12]
"""

from __future__ import annotations

import argparse
import compileall
import os
import platform
import subprocess
import sys
import tempfile
from pathlib import Path

from _host import cpu_model

ROOT = Path(__file__).resolve().parent.parent
GANTRY = ROOT / "data" / "examples" / "gantry" / "machine.toml"

#: one batch of ``N`` gantries in this process; prints the RSS after each and the peak
BATCH = """
import gc, resource, sys
from esp.batch.run import plan, run_batch

n = int(sys.argv[2])

def rss_mb():
    with open("/proc/self/statm") as fh:
        return int(fh.read().split()[1]) * resource.getpagesize() / 2**20

after = []
def done(row):
    after.append(f"{rss_mb():.0f}:{len(gc.get_objects())}")

rows = run_batch(plan([sys.argv[1]] * n), sys.argv[3], jobs=1, on_done=done)
assert all(r.error is None for r in rows), [r.error for r in rows]
peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024  # KiB on Linux: MiB
print(f"PEAK {peak:.1f}")
print("AFTER " + " ".join(after))
"""


def _load() -> str:
    try:
        return "load average (1, 5, 15 min) " + ", ".join(f"{v:.2f}" for v in os.getloadavg())
    except OSError:
        return "load average not available"


def _machine() -> str:
    model = cpu_model()
    return f"{model}; Python {platform.python_version()}"


def peak_of(count: int, tmp: str) -> tuple[float, str]:
    """Peak RSS in MiB of one process reporting ``count`` machines, and its RSS trail."""
    out = f"{tmp}/batch-{count}"
    done = subprocess.run(
        [sys.executable, "-c", BATCH, str(GANTRY), str(count), out],
        capture_output=True,
        text=True,
        check=True,
        cwd=ROOT,
        env={**os.environ, "SOURCE_DATE_EPOCH": "0"},
    )
    peak, trail = 0.0, ""
    for line in done.stdout.splitlines():
        if line.startswith("PEAK "):
            peak = float(line.split()[1])
        elif line.startswith("AFTER "):
            trail = line[len("AFTER ") :]
    return peak, trail


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--counts", type=int, nargs="+", default=[1, 2, 4, 12])
    args = parser.parse_args(argv)
    if sys.platform != "linux":
        raise SystemExit("batch_memory.py reads /proc and ru_maxrss in kB: Linux only")
    compileall.compile_dir(ROOT / "esp", quiet=1)  # as installed: bytecode cached
    print(_machine())
    print(_load() + " (before)")
    peaks: dict[int, float] = {}
    with tempfile.TemporaryDirectory() as tmp:
        for count in args.counts:
            peaks[count], trail = peak_of(count, tmp)
            print(f"  {count} machines: RSS MiB : tracked objects after each report: {trail}")
    print(_load() + " (after)")
    first = peaks[args.counts[0]]
    print(f"\n{'machines in one process':<26}{'peak RSS MiB':>12}{'ratio':>8}  goal")
    for count in args.counts:
        print(f"{count:<26}{peaks[count]:>12.0f}{peaks[count] / first:>8.2f}  1.2x")


if __name__ == "__main__":
    main()
