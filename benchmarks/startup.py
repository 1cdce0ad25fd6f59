"""Start-up cost of the command line, measured against the imports it cannot avoid.

Runs, each in a fresh Python process, several times, and reports the median CPU time
(user + system of the child) and what each process imported:

* ``python -c "import numpy, click"`` -- the reference: what a numpy command line costs;
* ``esp --version`` and ``esp --help`` -- should stay within 2x the reference and import
  neither matplotlib, pandas nor sympy;
* ``esp analyse data/examples/gantry/machine.toml --json -`` -- the main job without a
  report: no matplotlib, no pandas.

esp's modules are compiled to bytecode first, as an installation does (the reference's
packages are), so that no run pays for compiling them (a first run after an editable
install does, once, unless PYTHONDONTWRITEBYTECODE is set).

Run:  python benchmarks/startup.py [--repeat N]
"""

from __future__ import annotations

import argparse
import compileall
import os
import platform
import resource
import statistics
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
GANTRY = ROOT / "data" / "examples" / "gantry" / "machine.toml"
HEAVY = ("matplotlib", "pandas", "sympy")

_PROBE = (
    "import sys, runpy\n"
    "sys.argv = {argv!r}\n"
    "try:\n"
    "    runpy.run_module('esp', run_name='__main__')\n"
    "except SystemExit:\n"
    "    pass\n"
    "print('\\nLOADED ' + ' '.join(m for m in {heavy!r} if m in sys.modules), file=sys.stderr)\n"
)


def cpu_of(code: str) -> tuple[float, str]:
    """CPU seconds (user + system) of one fresh interpreter running ``code``, and what it
    says it loaded."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    done = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=True, cwd=ROOT
    )
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    loaded = ""
    for line in done.stderr.splitlines():
        if line.startswith("LOADED"):
            loaded = line[len("LOADED") :].strip()
    return cpu, loaded


def median_cpu(code: str, repeat: int) -> tuple[float, str]:
    runs = [cpu_of(code) for _ in range(repeat)]
    return statistics.median(c for c, _ in runs), runs[-1][1]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=7)
    args = ap.parse_args()
    compileall.compile_dir(ROOT / "esp", quiet=1)  # as installed: bytecode cached
    print(
        f"{platform.processor() or platform.machine()}, {os.cpu_count()} cores, Python "
        f"{platform.python_version()}, load average {os.getloadavg()[0]:.2f}; "
        f"CPU seconds, medians of {args.repeat} fresh processes"
    )
    reference, _ = median_cpu("import numpy, click", args.repeat)
    label = 'python -c "import numpy, click"'
    print(f"  {label:<52} {reference:6.3f} s   (reference)")
    cases = [
        ("esp --version", ["esp", "--version"]),
        ("esp --help", ["esp", "--help"]),
        (
            "esp analyse gantry/machine.toml --json -",
            ["esp", "analyse", str(GANTRY), "--json", "-"],
        ),
    ]
    for label, argv in cases:
        cpu, loaded = median_cpu(_PROBE.format(argv=argv, heavy=HEAVY), args.repeat)
        print(
            f"  {label:<52} {cpu:6.3f} s   {cpu / reference:4.2f} x reference; "
            f"loaded: {loaded or 'none of ' + ', '.join(HEAVY)}"
        )


if __name__ == "__main__":
    main()
