"""Cost of ``esp head --protocol`` against the import of sympy it cannot avoid.

Each command runs in a fresh Python process, ``--repeat`` times, interleaved: the
reference ``python -c "import sympy"``, then ``esp head FILE --protocol`` for each shipped
head file (``data/examples/heads``: the angle head of Freeman & Ford 2003, Fig. 3, and the
fork head example). Printed: the median CPU time (user + system) of each, its ratio to the
reference, and whether the process loaded ``sympy.physics`` (which ``sympy.simplify``
would load to look for units).

esp's modules are compiled to bytecode first, as an installation does.

Run from the repository root:  python benchmarks/head.py [--repeat 5]
"""

from __future__ import annotations

import argparse
import compileall
import os
import resource
import statistics
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
HEADS = ROOT / "data" / "examples" / "heads"
FILES = ("angle-head-fig3.toml", "fork-head-example.toml")

_PROBE = (
    "import sys, runpy\n"
    "sys.argv = {argv!r}\n"
    "try:\n"
    "    runpy.run_module('esp', run_name='__main__')\n"
    "except SystemExit:\n"
    "    pass\n"
    "sys.stdout.flush()\n"
    "print('PHYSICS', 'sympy.physics' in sys.modules, file=sys.stderr)\n"
)


def cpu_of(code: str) -> tuple[float, str]:
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    done = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=True, cwd=ROOT
    )
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    physics = "no"
    for line in done.stderr.splitlines():
        if line.startswith("PHYSICS"):
            physics = "yes" if line.split()[1] == "True" else "no"
    return (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime), physics


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=5)
    args = ap.parse_args(argv)
    compileall.compile_dir(ROOT / "esp", quiet=1)
    print(
        f"{os.cpu_count()} cores, Python {sys.version.split()[0]}, load average "
        f"{os.getloadavg()[0]:.2f} (before); CPU seconds, medians of {args.repeat} fresh "
        "processes, interleaved"
    )
    cases = [("python -c 'import sympy'", "import sympy")] + [
        (
            f"esp head {name} --protocol",
            _PROBE.format(argv=["esp", "head", str(HEADS / name), "--protocol"]),
        )
        for name in FILES
    ]
    times: dict[str, list[float]] = {label: [] for label, _ in cases}
    loaded: dict[str, str] = {}
    for _ in range(args.repeat):
        for label, code in cases:
            cpu, physics = cpu_of(code)
            times[label].append(cpu)
            loaded[label] = physics
    print(f"load average {os.getloadavg()[0]:.2f} (after)")
    reference = statistics.median(times[cases[0][0]])
    for label, _ in cases:
        cpu = statistics.median(times[label])
        note = "(reference)" if label == cases[0][0] else f"loads sympy.physics: {loaded[label]}"
        print(f"  {label:<44} {cpu:6.2f} s  {cpu / reference:5.2f} x reference  {note}")


if __name__ == "__main__":
    main()
