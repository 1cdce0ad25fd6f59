"""Cost of the report folder (``esp analyse --out``) against one figure, in one run.

The reference is a fresh Python process that imports matplotlib, draws one 800 x 600
pixel figure (a filled contour map with contour lines, a colour bar, a title and axis
labels) and saves it as PNG. Each report is a fresh process running ``esp analyse
CONFIG --out DIR`` (the command line itself: the report is made in that one process), for
the shipped gantry at the MCP (``machine.toml``) and at the TCP with its head sweep
(``machine-tcp.toml``). Processes of the reference and the reports
alternate, and each figure is the median of ``--runs`` runs, so that a change of load
during the run affects all alike.

esp's modules are compiled to bytecode first, as an installation does (matplotlib's are),
so that no run pays for compiling them.

Printed: the machine and its load, then per case the CPU time (user + system) and the
wall time, each as seconds and as a ratio to the reference, with the goal (4x for the
MCP, 5x for the TCP with sweep, in CPU, through matplotlib's public API alone);
``--repeats N`` measures the whole run N times and prints each ratio's range over them;
with ``--parts``, the CPU seconds of the report path's imports (a fresh process) and the
seconds of each part of one report (in this process).

``--python PATH`` runs the reference and the reports with another interpreter (a virtual
environment's ``bin/python`` with other versions of matplotlib and numpy, which need not
have esp installed: the processes import it from this checkout); the versions printed are
that interpreter's. ``--parts`` measures in this process, so it goes without ``--python``.

The measured processes inherit the environment, ``OPENBLAS_NUM_THREADS`` with it (printed).
The worker threads of OpenBLAS, which numpy's wheels bundle, wait for work by spinning
after each call that used them, and that CPU time (system time, mostly) is counted: with
numpy 1.25 1.5-2.3 s of a report's CPU on two cores, with numpy 2.4 0.3-0.5 s. So
the ``esp`` command (``esp.cli.run``, which the reports run) takes one BLAS thread unless
the environment names a count; the reference, a plain Python process, keeps OpenBLAS'
default. ``--blas-threads N`` sets ``OPENBLAS_NUM_THREADS=N`` for every measured process,
the reference and the reports alike.

Run from the repository root:
python benchmarks/report.py [--runs 3] [--repeats 1] [--parts] [--python PATH]
    [--blas-threads N]
"""

from __future__ import annotations

import argparse
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from _host import cpu_model

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))  # --parts imports esp here: the checkout, installed or not
GANTRY = ROOT / "data" / "examples" / "gantry"

#: one figure, as a user of matplotlib would draw it
REFERENCE = """
import sys
import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

fig = Figure(figsize=(8, 6), dpi=100)
FigureCanvasAgg(fig)
ax = fig.add_subplot()
x = np.linspace(0.0, 1000.0, 101)
y = np.linspace(0.0, 1500.0, 151)
z = np.sin(x[:, None] / 200.0) * np.cos(y[None, :] / 300.0)
filled = ax.contourf(x, y, z.T, levels=10)
ax.contour(x, y, z.T, levels=10, colors="k", linewidths=0.5)
fig.colorbar(filled, ax=ax)
ax.set_title("reference")
ax.set_xlabel("x (mm)")
ax.set_ylabel("y (mm)")
fig.savefig(sys.argv[1], format="png")
"""

#: ``esp analyse CONFIG --out DIR -q``, as the command line (its console script) runs it
REPORT = """
import sys
from esp.cli import run

sys.argv = ["esp", "analyse", sys.argv[1], "--out", sys.argv[2], "-q"]
run()
"""

#: (name, configuration, goal: the CPU ratio to the reference)
CASES = (
    ("gantry, MCP", GANTRY / "machine.toml", 4.0),
    ("gantry, TCP with sweep", GANTRY / "machine-tcp.toml", 5.0),
)


#: the interpreter of the measured processes (``--python``)
PYTHON = sys.executable
#: the environment of the measured processes (``--blas-threads`` sets OPENBLAS_NUM_THREADS)
ENV = {**os.environ, "SOURCE_DATE_EPOCH": "0"}

#: the versions the measured interpreter runs with
VERSIONS = """
import platform
import matplotlib
import numpy

print(
    f"Python {platform.python_version()}, numpy {numpy.__version__}, "
    f"matplotlib {matplotlib.__version__}"
)
"""


def _run(args: list[str]) -> tuple[float, float]:
    """CPU seconds (the process and every process it waited for) and wall seconds."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    subprocess.run(args, check=True, cwd=ROOT, env=ENV)
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return cpu, wall


def _machine() -> str:
    model = cpu_model()
    versions = subprocess.run(
        [PYTHON, "-c", VERSIONS], check=True, cwd=ROOT, capture_output=True, text=True, env=ENV
    ).stdout.strip()
    cores = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count()
    threads = ENV.get("OPENBLAS_NUM_THREADS", "unset (the OpenBLAS default)")
    return f"{model}, {cores} cores usable; {versions}; OPENBLAS_NUM_THREADS {threads}"


def _load() -> str:
    try:
        return "load average (1, 5, 15 min) " + ", ".join(f"{v:.2f}" for v in os.getloadavg())
    except OSError:
        return "load average not available"


#: what the report's command imports before it draws, in a fresh process: its CPU seconds
IMPORTS = """
import time
start = time.process_time()
import esp.cli
import esp.config
import esp.core.analysis
import esp.volumetric.report
from matplotlib.backends.backend_pdf import PdfPages
print(time.process_time() - start)
"""


def _imports(runs: int) -> float:
    """The median CPU seconds of the report path's imports, each in a fresh process."""
    seconds = []
    for _ in range(runs):
        out = subprocess.run(
            [PYTHON, "-c", IMPORTS], check=True, cwd=ROOT, capture_output=True, text=True, env=ENV
        ).stdout
        seconds.append(float(out.strip()))
    return statistics.median(seconds)


def _parts(config: Path) -> None:
    from esp.config import load_machine
    from esp.core.analysis import analyse
    from esp.volumetric.report import write_report

    t0 = time.perf_counter()
    result = analyse(load_machine(config))
    t_analysis = time.perf_counter() - t0
    timings: dict[str, float] = {}
    with tempfile.TemporaryDirectory() as tmp:
        t0 = time.perf_counter()
        write_report(result, Path(tmp) / "report", timings=timings, date="2026-01-01", jobs=1)
        t_report = time.perf_counter() - t0
    pngs = sum(v for k, v in timings.items() if k.startswith("png "))
    pages = sum(v for k, v in timings.items() if k.startswith("pdf "))
    print(
        f"  {config.name}, one process: analysis {t_analysis:.2f} s, report {t_report:.2f} s "
        f"(PNG figures {pngs:.2f} s, PDF figure pages {pages:.2f} s, PDF text pages "
        f"{timings['pdf'] - pages:.2f} s, JSON {timings['json']:.2f} s, CSV "
        f"{timings['csv']:.2f} s)"
    )
    slowest = sorted(
        ((k, v) for k, v in timings.items() if k.startswith(("png ", "pdf "))),
        key=lambda kv: -kv[1],
    )[:3]
    print("    slowest parts: " + ", ".join(f"{k} {v:.2f} s" for k, v in slowest))


def _measure(runs: int) -> tuple[tuple[float, float], dict[str, tuple[float, float]]]:
    """One interleaved measurement: the medians of ``runs`` runs of the reference and of
    each report, (CPU s, wall s)."""
    ref: list[tuple[float, float]] = []
    times: dict[str, list[tuple[float, float]]] = {}
    with tempfile.TemporaryDirectory() as tmp:
        for k in range(runs):
            ref.append(_run([PYTHON, "-c", REFERENCE, f"{tmp}/ref.png"]))
            for name, config, _ in CASES:
                out = f"{tmp}/report-{k}-{config.stem}"
                cmd = [PYTHON, "-c", REPORT, str(config), out]
                times.setdefault(name, []).append(_run(cmd))

    def medians(values: list[tuple[float, float]]) -> tuple[float, float]:
        return statistics.median(c for c, _ in values), statistics.median(w for _, w in values)

    return medians(ref), {name: medians(v) for name, v in times.items()}


def _span(values: list[float], digits: int) -> str:
    lo, hi = min(values), max(values)
    return (
        f"{lo:.{digits}f}"
        if f"{lo:.{digits}f}" == f"{hi:.{digits}f}"
        else (f"{lo:.{digits}f} to {hi:.{digits}f}")
    )


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--runs", type=int, default=3, help="runs of each process (median)")
    parser.add_argument("--repeats", type=int, default=1, help="measurements (ranges)")
    parser.add_argument("--parts", action="store_true", help="time each part of one report")
    parser.add_argument(
        "--python",
        metavar="PATH",
        help="the interpreter that runs the reference and the reports (default: this one)",
    )
    parser.add_argument(
        "--blas-threads",
        type=int,
        metavar="N",
        help="set OPENBLAS_NUM_THREADS=N for every measured process (default: inherited)",
    )
    args = parser.parse_args(argv)
    global PYTHON
    if args.blas_threads is not None:
        if args.blas_threads < 1:
            parser.error("--blas-threads: expected a whole number of at least 1")
        ENV["OPENBLAS_NUM_THREADS"] = str(args.blas_threads)
    if args.python is not None:
        if args.parts:
            parser.error("--parts measures in this process: leave out --python")
        PYTHON = str(Path(args.python).absolute())
        if not os.access(PYTHON, os.X_OK):
            parser.error(f"--python: {args.python} is not an executable file")
    # as installed: bytecode cached, by the measured interpreter (its cache tag)
    subprocess.run([PYTHON, "-m", "compileall", "-q", str(ROOT / "esp")], check=True, cwd=ROOT)
    print(_machine())
    print(_load() + " (before)")
    measured = [_measure(args.runs) for _ in range(args.repeats)]
    print(_load() + " (after)")
    refs = [ref for ref, _ in measured]
    print(
        f"\nreference, one 800 x 600 contour figure: CPU {_span([c for c, _ in refs], 2)} s, "
        f"wall {_span([w for _, w in refs], 2)} s (medians of {args.runs}, "
        f"{args.repeats} measurement{'s' if args.repeats > 1 else ''})"
    )
    print(f"{'report, one process':<24}{'CPU s':>15}{'ratio':>13}{'wall s':>15}{'ratio':>13}  goal")
    for name, _, goal in CASES:
        cpu = [times[name][0] for _, times in measured]
        wall = [times[name][1] for _, times in measured]
        cpu_ratio = [times[name][0] / ref[0] for ref, times in measured]
        wall_ratio = [times[name][1] / ref[1] for ref, times in measured]
        print(
            f"{name:<24}{_span(cpu, 2):>15}{_span(cpu_ratio, 1):>13}{_span(wall, 2):>15}"
            f"{_span(wall_ratio, 1):>13}  {goal:g}x"
        )
    if args.parts:
        print("\nparts of one report:")
        print(
            f"  imports of the report path (esp.cli, the analysis, the report, matplotlib's "
            f"figure and PDF backend), a fresh process: CPU {_imports(args.runs):.2f} s "
            f"(median of {args.runs})"
        )
        for _, config, _ in CASES:
            _parts(config)


if __name__ == "__main__":
    main()
