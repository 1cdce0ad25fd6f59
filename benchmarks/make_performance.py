"""Write docs/performance.md from the benchmarks in this folder, run here and now.

Every other ``*.py`` script of ``benchmarks/`` is run ``--repeat`` times, each run a fresh
process (``python benchmarks/NAME.py`` with the arguments of :data:`ARGS`, none for a
script not listed there, and the environment variables of :data:`ENV`, shown in its
command), one script after the other. What a script prints is taken as it
is: the lines of its runs are matched up by their text with the numbers left out, and each
number is written as the range of the values its runs printed (``0.84–0.91``; one value
when every run printed the same). The document is then, per script, the first paragraph
of its docstring as the section's title and text, the command, the load average before
and after each run, and the merged lines. Nothing else is quoted: a figure in the document
is one the scripts printed.

A new script (a benchmark added to this folder) is picked up as it is; a script that fails
is reported in its section with the end of its error output, and the others still run.

``--lowest-python PATH`` (the interpreter of a virtual environment installed with
``pip install -c .ci/lowest.txt -e .``) adds a section that runs ``report.py`` with that
interpreter: the report on the lowest versions esp supports, beside the newest.

Run from the repository root:  python benchmarks/make_performance.py [--repeat 2]
    [--only report,startup] [--out docs/performance.md] [--lowest-python PATH]
"""

from __future__ import annotations

import argparse
import ast
import os
import platform
import re
import subprocess
import sys
import time
from collections.abc import Sequence
from pathlib import Path

from _host import cpu_model

ROOT = Path(__file__).resolve().parent.parent
HERE = Path(__file__).resolve().parent
OUT = ROOT / "docs" / "performance.md"

#: the arguments each script is run with (a script not listed: none, its own defaults);
#: chosen so that one generation takes minutes, not hours, on a shared machine
ARGS: dict[str, list[str]] = {
    "synthesis.py": ["--repeat", "1"],
    "chain.py": ["--repeat", "2"],
    "uncertainty.py": ["--repeat", "1"],
    "report.py": ["--runs", "3"],
    "batch_memory.py": ["--counts", "1", "12"],
    "head.py": ["--repeat", "3"],
    "startup.py": ["--repeat", "5"],
}

#: the environment each script is run with beyond this process's (and shown in its
#: command): identify.py's figures are quoted with one BLAS thread, as its docstring says
ENV: dict[str, dict[str, str]] = {
    "identify.py": {"OPENBLAS_NUM_THREADS": "1"},
    "identify_rotary.py": {"OPENBLAS_NUM_THREADS": "1"},
}

#: the order the scripts run in and of their sections, the quickest first (the document
#: is written after each); scripts not listed follow in name order
ORDER = (
    "startup.py",
    "head.py",
    "chain.py",
    "report.py",
    "batch_memory.py",
    "synthesis.py",
    "uncertainty.py",
)

#: a number as the scripts print them: 12, -3.5, 0.042, 7.5e+07, 1.2e-05, 930,311 (digits
#: grouped by thousands: one number)
_NUMBER = re.compile(
    r"(?<![A-Za-z_\d.,])[-+]?(?:\d{1,3}(?:,\d{3})+(?!\d)|\d+)(?:\.\d+)?(?:[eE][-+]?\d+)?"
)


def scripts(only: Sequence[str] = ()) -> list[Path]:
    """The benchmark scripts, in section order."""
    found = sorted(
        p
        for p in HERE.glob("*.py")
        if p.name not in (Path(__file__).name, "same_outputs.py", "mutation.py")
        and not p.name.startswith("_")
    )
    if only:
        wanted = {n if n.endswith(".py") else n + ".py" for n in only}
        found = [p for p in found if p.name in wanted]
    rank = {name: k for k, name in enumerate(ORDER)}
    return sorted(found, key=lambda p: (rank.get(p.name, len(ORDER)), p.name))


def docstring(path: Path) -> tuple[str, str]:
    """The title (first line) and the text (the rest, without its ``Run:`` line) of a
    script's docstring."""
    doc = ast.get_docstring(ast.parse(path.read_text(encoding="utf-8"))) or path.stem
    lines = doc.strip().splitlines()
    title = lines[0].strip().rstrip(".")
    body = []
    for line in lines[1:]:
        if re.match(r"\s*Run( from [^:]*)?:", line):
            break
        body.append(line)
    return title, "\n".join(body).strip()


#: every 1-minute load average read during this generation
LOADS: list[float] = []


def load() -> str:
    try:
        values = os.getloadavg()
    except OSError:
        return "not available"
    LOADS.append(values[0])
    return ", ".join(f"{v:.2f}" for v in values)


def _cores() -> int:
    return len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count() or 1


def load_note() -> str:
    """A sentence on the load during the generation: the 1-minute load average before the
    first script (what else the machine was doing) and its range before each run (which
    also counts the scripts' own work of the minute before)."""
    if not LOADS:
        return ""
    first, lo, hi, cores = LOADS[0], min(LOADS), max(LOADS), _cores()
    text = (
        f"Before the first script the 1-minute load average was {first:.1f} on {cores} "
        f"usable cores; before each run it was {lo:.1f}–{hi:.1f}, counting the previous "
        "runs' own work of the minute before."
    )
    if first > cores / 2:
        text += (
            " The machine had been busy in the minute before the generation started: "
            "where other work went on, the scripts competed with it for the cores, so "
            "times are longer and ranges wider than on an idle machine, and a ratio holds "
            "only as far as both of its parts met the same load (the scripts interleave "
            "them for that reason)."
        )
    return text


def run(
    path: Path, args: Sequence[str], extra: dict[str, str] | None = None
) -> tuple[list[str], str, str, str, float]:
    """Run one script once (``extra``: variables added to its environment): its output
    lines, its error output if it failed ("" when it did not), the load average before and
    after, the wall seconds."""
    before = load()
    start = time.perf_counter()
    env = {**os.environ, **(extra or {}), "PYTHONPATH": str(ROOT)}
    done = subprocess.run(
        [sys.executable, str(path), *args], capture_output=True, text=True, cwd=ROOT, env=env
    )
    seconds = time.perf_counter() - start
    failed = "" if done.returncode == 0 else (done.stderr.strip() or f"exit {done.returncode}")
    return done.stdout.rstrip().splitlines(), failed, before, load(), seconds


def _shape(line: str) -> str:
    """The line without its numbers (each a ``#``) and with every run of spaces as one: the
    key lines of different runs are matched by (a column of numbers printed to a width
    holds more or fewer spaces)."""
    return re.sub(r" +", " ", _NUMBER.sub("#", line))


def _range(values: list[str]) -> str:
    """The printed values of one number over the runs: one when all are the same, else
    the smallest and the largest, as printed."""
    if len(set(values)) == 1:
        return values[0]
    ordered = sorted(values, key=lambda v: float(v.replace(",", "")))
    return f"{ordered[0]}–{ordered[-1]}"


def merge(runs: Sequence[Sequence[str]]) -> list[str]:
    """The lines of several runs of one script as one: lines are matched by their text
    without its numbers (the k-th line of a shape in one run with the k-th of that shape
    in the others) and each number becomes the range of its values. A line only some runs
    printed keeps the ranges of those, marked with how many."""
    if not runs:
        return []
    keyed: list[dict[tuple[str, int], list[str]]] = []
    layout: dict[tuple[str, int], str] = {}  # the spacing of the first run that printed it
    for lines in runs:
        seen: dict[str, int] = {}
        table = {}
        for line in lines:
            shape = _shape(line)
            n = seen.get(shape, 0)
            seen[shape] = n + 1
            table[(shape, n)] = _NUMBER.findall(line)
            layout.setdefault((shape, n), _NUMBER.sub("#", line))
        keyed.append(table)
    order: list[tuple[str, int]] = []
    known: set[tuple[str, int]] = set()
    for lines in runs:
        seen = {}
        for line in lines:
            shape = _shape(line)
            n = seen.get(shape, 0)
            seen[shape] = n + 1
            if (shape, n) not in known:
                known.add((shape, n))
                order.append((shape, n))
    out = []
    for key in order:
        present = [t[key] for t in keyed if key in t]
        parts = layout[key].split("#")
        columns = list(zip(*present, strict=True)) if present else []
        text = parts[0]
        for k, column in enumerate(columns):
            text += _range(list(column)) + parts[k + 1]
        if len(present) < len(runs):
            text += f"   [printed by {len(present)} of {len(runs)} runs]"
        out.append(text)
    return out


def _machine() -> str:
    model = cpu_model()
    return f"{model}, {_cores()} cores usable, Python {platform.python_version()}"


#: how a section of the lowest versions shows the interpreter in its command
LOWEST_SHOWN = "LOWEST/bin/python"


def section(path: Path, repeat: int, note: str = "", lowest: Path | None = None) -> list[str]:
    """The document's section of one script: run it ``repeat`` times and merge; with
    ``lowest``, ``report.py`` run with that interpreter (``--python``)."""
    title, body = docstring(path)
    args = ARGS.get(path.name, [])
    shown = list(args)
    if lowest is not None:
        args, shown = [*args, "--python", str(lowest)], [*args, "--python", LOWEST_SHOWN]
        title += ", on the lowest supported versions"
        note = (
            f"`LOWEST` is a virtual environment installed with "
            f"`pip install -c .ci/lowest.txt -e .` (the floors of pyproject.toml). {note}"
        ).strip()
    extra = ENV.get(path.name, {})
    outputs, loads, failures, seconds = [], [], [], []
    for _ in range(repeat):
        lines, failed, before, after, wall = run(path, args, extra)
        loads.append(f"{before} → {after}")
        seconds.append(wall)
        if failed:
            failures.append(failed)
        else:
            outputs.append(lines)
        print(f"  {path.name}: run {len(loads)} of {repeat}, {wall:.0f} s", file=sys.stderr)
    settings = [f"{k}={v}" for k, v in extra.items()]
    command = " ".join([*settings, "python", f"benchmarks/{path.name}", *shown])
    heading = _heading(path) + (" (lowest versions)" if lowest is not None else "")
    text = [heading, "", f"**{title}.**", "", body, "", f"`{command}`, "]
    took = _range([f"{v:.0f}" for v in seconds])
    text[-1] += (
        f"{len(outputs)} of {repeat} runs, one after the other, {took} s each; load average "
        "(1, 5, 15 min) before → after each run:"
    )
    text += [""] + [f"- run {k + 1}: {span}" for k, span in enumerate(loads)]
    if note:
        text += ["", note]
    if outputs:
        text += ["", "```", *merge(outputs), "```"]
    for failed in failures[:1]:
        tail = "\n".join(failed.splitlines()[-6:])
        text += ["", f"{len(failures)} run(s) failed; the end of the first one's errors:"]
        text += ["", "```", tail, "```"]
    return text + [""]


HEADER = """# Performance

How fast esp is, as the scripts in `benchmarks/` measure it. This page is written by
`python benchmarks/make_performance.py`, which runs every script of that folder several
times, one after the other, and writes here what they printed: each number is the range of
the values of those runs (`a–b`; one value when every run printed the same), each figure
stands next to the load average of the machine while it was measured. Run the generator
(or a single script) on your own machine to compare.

Ratios are measured within one run of a script, against a reference timed in the same run
(interleaved where the script says so), never across runs; the ranges show how much they
moved from run to run. On a shared machine, with other work on it, times and ratios both
move: compare them with the load beside them.
"""


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--repeat", type=int, default=2, help="runs of each script")
    ap.add_argument("--only", default="", help="scripts to run, comma-separated")
    ap.add_argument("--out", type=Path, default=OUT, help="the document to write")
    ap.add_argument("--note", default="", help="a sentence written under the header")
    ap.add_argument(
        "--lowest-python",
        type=Path,
        default=None,
        help="also run report.py with this interpreter (a venv of .ci/lowest.txt)",
    )
    ap.add_argument(
        "--update",
        action="store_true",
        help="measure only the scripts of --only and keep the other sections of the document",
    )
    args = ap.parse_args(argv)
    only = [n for n in args.only.split(",") if n]
    found = scripts(only)
    started = time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime())
    text = [HEADER, f"Generated {started} on {_machine()}, {args.repeat} runs per script."]
    if args.note:
        text += ["", args.note]
    text.append("")
    kept: dict[str, list[str]] = {}
    if args.update and args.out.exists():
        old = args.out.read_text(encoding="utf-8").splitlines()
        first = next((k for k, line in enumerate(old) if line.startswith("## ")), len(old))
        text = [line for line in old[:first] if not line.startswith("Not yet measured")]
        text += [f"Updated {started}: {', '.join(p.name for p in found)} measured again.", ""]
        for line in old[first:]:
            if line.startswith("## "):
                kept[line] = []
                current = kept[line]
            current.append(line)
        for lines in kept.values():  # the file's last section lost its closing blank line
            while lines and not lines[-1].strip():
                lines.pop()
            lines.append("")
    done: dict[str, list[str]] = {}
    jobs: list[tuple[Path, Path | None]] = [(p, None) for p in found]
    if args.lowest_python is not None:
        at = next((k + 1 for k, p in enumerate(found) if p.name == "report.py"), None)
        if at is not None:
            jobs.insert(at, (found[at - 1], args.lowest_python))
    for k, (path, lowest) in enumerate(jobs):
        print(f"{path.name}{' (lowest)' if lowest else ''} ...", file=sys.stderr)
        lines = section(path, args.repeat, lowest=lowest)
        done[lines[0]] = lines
        # written after every section: what is measured is kept if a later script hangs
        body: list[str] = []
        for name in (p for p in scripts() if args.update or p in found):
            for heading in (_heading(name), _heading(name) + " (lowest versions)"):
                body += done.get(heading) or kept.get(heading, [])
        left = [p.name for p, _ in jobs[k + 1 :]]
        pending = [f"Not yet measured in this generation: {', '.join(left)}.", ""] if left else []
        note = [] if args.update else [load_note(), ""]
        document = [*text, *note, *pending, *body]
        args.out.write_text("\n".join(document).rstrip() + "\n", encoding="utf-8")
    print(f"wrote {args.out}", file=sys.stderr)


def _heading(path: Path) -> str:
    return "## " + path.stem.replace("_", " ").capitalize()


if __name__ == "__main__":
    main()
