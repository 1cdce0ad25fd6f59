"""What the benchmarks say about the machine they ran on, and how they time (a helper
module of the scripts in this folder, not a benchmark: ``make_performance.py`` skips names
starting with ``_``)."""

from __future__ import annotations

import os
import platform
import statistics
import time
from collections.abc import Callable


def cpu_model() -> str:
    """The processor's model name (``/proc/cpuinfo``), else what :mod:`platform` says."""
    model = platform.processor() or platform.machine() or "unknown CPU"
    try:
        with open("/proc/cpuinfo", encoding="utf-8") as fh:
            for line in fh:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return model


def usable_cores() -> int:
    """The cores this process may run on."""
    if hasattr(os, "sched_getaffinity"):
        return len(os.sched_getaffinity(0))
    return os.cpu_count() or 1


def cores_load_threads() -> str:
    """One line: the cores, the 1-minute load average and the OpenBLAS thread count the
    process was given (the benchmarks of linear algebra print it first)."""
    threads = os.environ.get("OPENBLAS_NUM_THREADS", "unset (the OpenBLAS default)")
    return (
        f"cores {os.cpu_count()}, load average {os.getloadavg()[0]:.2f}, "
        f"OPENBLAS_NUM_THREADS {threads}"
    )


def median_times(f: Callable[[], object], repeat: int) -> tuple[float, float]:
    """Medians of the wall-clock and of this process' CPU time (s) of ``repeat`` calls of
    ``f``: on a shared machine the CPU time is the figure the load does not stretch."""
    wall, cpu = [], []
    for _ in range(repeat):
        t0, c0 = time.perf_counter(), time.process_time()
        f()
        wall.append(time.perf_counter() - t0)
        cpu.append(time.process_time() - c0)
    return statistics.median(wall), statistics.median(cpu)
