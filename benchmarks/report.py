"""Time of the report folder (`esp analyse --out`) of the shipped gantry example.

Prints the seconds of the analysis and of the report, whole and per part (each figure as
PNG and as a PDF page, the PDF's text pages, JSON, CSV), for the MCP configuration and for
the TCP configuration with its head sweep.

Run from the repository root:  python benchmarks/report.py
"""

from __future__ import annotations

import tempfile
import time
from pathlib import Path

from esp.analysis import analyse
from esp.config import load_machine
from esp.report.bundle import write_report

GANTRY = Path(__file__).resolve().parent.parent / "data" / "examples" / "gantry"


def main() -> None:
    for name in ("machine.toml", "machine-tcp.toml"):
        t0 = time.perf_counter()
        result = analyse(load_machine(GANTRY / name))
        t_analysis = time.perf_counter() - t0
        timings: dict[str, float] = {}
        with tempfile.TemporaryDirectory() as tmp:
            t0 = time.perf_counter()
            write_report(result, Path(tmp) / "report", timings=timings, date="2026-01-01")
            t_report = time.perf_counter() - t0
        pngs = sum(v for k, v in timings.items() if k.startswith("png "))
        pages = sum(v for k, v in timings.items() if k.startswith("pdf "))
        print(
            f"gantry/{name}: analysis {t_analysis:.2f} s, report {t_report:.2f} s "
            f"(PNG figures {pngs:.2f} s, PDF figure pages {pages:.2f} s, "
            f"PDF text pages {timings['pdf'] - pages:.2f} s, JSON {timings['json']:.2f} s, "
            f"CSV {timings['csv']:.2f} s)"
        )
        slowest = sorted(
            ((k, v) for k, v in timings.items() if k.startswith(("png ", "pdf "))),
            key=lambda kv: -kv[1],
        )[:3]
        print("  slowest parts: " + ", ".join(f"{k} {v:.2f} s" for k, v in slowest))


if __name__ == "__main__":
    main()
