"""docs/performance.md is written from what the benchmarks print: the merging of several
runs' lines into ranges (benchmarks/make_performance.py)."""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def _generator():
    folder = str(ROOT / "benchmarks")
    spec = importlib.util.spec_from_file_location(
        "make_performance", Path(folder) / "make_performance.py"
    )
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.path.insert(0, folder)  # the scripts' helper module, as `python benchmarks/X.py` finds it
    try:
        spec.loader.exec_module(module)
    finally:
        sys.path.remove(folder)
    return module


def test_runs_merge_into_ranges_line_by_line():
    gen = _generator()
    runs = [
        ["load 1.20, 0.90", "reference 0.86 s", "MCP    4.95 s  5.8x", "MCP    5.10 s  5.9x"],
        ["load 2.50, 1.10", "reference 0.91 s", "MCP    4.80 s  5.3x", "MCP    5.00 s  6.1x"],
        ["load 1.80, 1.00", "reference 0.88 s", "MCP    5.02 s  5.7x", "MCP    5.05 s  6.0x"],
    ]
    assert gen.merge(runs) == [
        "load 1.20–2.50, 0.90–1.10",
        "reference 0.86–0.91 s",
        "MCP    4.80–5.02 s  5.3–5.8x",  # the first line of its shape with the first
        "MCP    5.00–5.10 s  5.9–6.1x",
    ]


def test_columns_printed_to_a_width_are_matched():
    gen = _generator()
    runs = [["TCP   15.24   11.3  6x"], ["TCP   12.48    7.3  6x"]]
    assert gen.merge(runs) == ["TCP   12.48–15.24   7.3–11.3  6x"]


def test_equal_values_stay_one_and_missing_lines_are_marked():
    gen = _generator()
    runs = [
        ["Python 3.11.7, 2 cores", "-3.5 um", "only here 7"],
        ["Python 3.11.7, 2 cores", "-1 um"],
    ]
    assert gen.merge(runs) == [
        "Python 3.11.7, 2 cores",
        "-3.5–-1 um",
        "only here 7   [printed by 1 of 2 runs]",
    ]


def test_numbers_grouped_by_thousands_are_one_number():
    gen = _generator()
    runs = [
        ["position  0.170 s  2,068,308 points/s", "load 1.11, 1.16", "step 50 mm: 8,463 points"],
        ["position  0.185 s  3,808,934 points/s", "load 1.20, 1.02", "step 50 mm: 12,463 points"],
        ["position  0.181 s    998,001 points/s", "load 1.15, 1.10", "step 50 mm: 8,463 points"],
    ]
    assert gen.merge(runs) == [
        "position  0.170–0.185 s  998,001–3,808,934 points/s",
        "load 1.11–1.20, 1.02–1.16",  # a list of numbers is not one grouped number
        "step 50 mm: 8,463–12,463 points",
    ]


def test_every_script_of_the_folder_is_found_in_section_order():
    gen = _generator()
    names = [p.name for p in gen.scripts()]
    assert "make_performance.py" not in names
    assert {"report.py", "batch_memory.py", "startup.py"} <= set(names)
    assert names.index("startup.py") < names.index("report.py") < names.index("uncertainty.py")
    title, body = gen.docstring(ROOT / "benchmarks" / "batch_memory.py")
    assert title.startswith("Peak memory of a batch") and "Run from" not in body
    _, body = gen.docstring(ROOT / "benchmarks" / "startup.py")
    assert body.startswith("Runs, each in a fresh Python process")  # "Runs," is no Run: line


def test_a_section_of_the_lowest_versions_runs_with_that_interpreter_and_hides_its_path(
    tmp_path, monkeypatch
):
    """--lowest-python: the script is run with ``--python PATH``; the section is headed as
    the lowest versions' and its command shows LOWEST, not the machine's path."""
    gen = _generator()
    script = tmp_path / "report.py"
    script.write_text('"""Cost.\n\nText."""\nimport sys\nprint(" ".join(sys.argv[1:]))\n')
    monkeypatch.setitem(gen.ARGS, "report.py", ["--runs", "1"])
    lowest = tmp_path / "venv" / "bin" / "python"
    lines = gen.section(script, 1, lowest=lowest)
    text = "\n".join(lines)
    assert lines[0] == "## Report (lowest versions)"
    assert "`python benchmarks/report.py --runs 1 --python LOWEST/bin/python`" in text
    assert f"--runs 1 --python {lowest}" in text  # what the script was given
    assert str(tmp_path) not in text.replace(f"--runs 1 --python {lowest}", "")
