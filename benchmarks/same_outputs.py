"""Every output of every shipped example, as SHA-256 digests: proof that a change of the
code's layout changes no byte a user sees.

Runs each command of the shipped examples' READMEs (each one a fresh ``python -m esp``
process, with ``SOURCE_DATE_EPOCH`` fixed), writes every output into a fresh folder and
records the digest of every file written and of what was printed. Record before a change,
compare after it::

    python benchmarks/same_outputs.py --record before.json
    python benchmarks/same_outputs.py --compare before.json

``--compare`` lists each output that differs and exits 1 if any does. This is a check, not a
benchmark: ``make_performance.py`` does not run it.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
EX = "data/examples"

# Each run: a name and the arguments of ``esp``; "{out}" is the run's own output folder.
RUNS: list[tuple[str, list[str]]] = [
    ("batch", ["batch", EX, "--out", "{out}/batch", "--max-volumetric", "50", "--jobs", "1"]),
    ("gantry-tcp", ["analyse", f"{EX}/gantry/machine-tcp.toml", "--out", "{out}/r"]),
    (
        "gantry-json",
        ["analyse", f"{EX}/gantry/machine.toml", "--json", "-", "--at", "X=500,Y=750,Z=300"],
    ),
    ("gantry-grid", ["analyse", f"{EX}/gantry/machine.toml", "--out", "{out}/r", "--grid-csv"]),
    ("head", ["head", f"{EX}/heads/angle-head-fig3.toml", "--out", "{out}/r"]),
    ("head-at", ["head", f"{EX}/heads/angle-head-fig3.toml", "--at", "A=30,C=40", "--order", "2"]),
    ("head-protocol", ["head", f"{EX}/heads/angle-head-fig3.toml", "--protocol"]),
    (
        "head-measured",
        [
            "head",
            f"{EX}/heads/fork-head-example.toml",
            "--measured",
            f"{EX}/heads/fork-head-measured.csv",
        ],
    ),
    ("parallel", ["parallel", f"{EX}/parallel/machine.toml", "--sweep", "--out", "{out}/r"]),
    ("parallel-printed", ["parallel", f"{EX}/parallel/machine.toml", "--model", "as-printed"]),
    (
        "compensate",
        [
            "compensate",
            f"{EX}/gantry/machine.toml",
            *("--format", "linuxcnc", "--format", "twincat-plane", "--format", "iso-csv"),
            *("--leave-uncorrected", "--out", "{out}/r", "--predict", "--plot", "{out}/p.png"),
        ],
    ),
    ("diagonals", ["diagonals", f"{EX}/gantry/machine.toml", "--faces", "--json", "-"]),
    (
        "compare",
        [
            "compare",
            f"{EX}/gantry/machine.toml",
            f"{EX}/gantry-2024/machine.toml",
            "--out",
            "{out}/r",
        ],
    ),
    (
        "iso230-2",
        [
            "iso230-2",
            f"{EX}/gantry/X-linear.rtl",
            *("--json", "{out}/iso.json", "--plot", "{out}/iso.png"),
        ],
    ),
    ("vdi3441", ["iso230-2", f"{EX}/gantry/X-linear.rtl", "--vdi3441"]),
    (
        "angular",
        [
            "angular",
            f"{EX}/turning-centre/Xpos_z0.rtl",
            f"{EX}/turning-centre/Xpos_z800.rtl",
            *("--displacement", "-800", "--datum", "-560", "-o", "{out}/pitch.rta"),
        ],
    ),
    ("inspect", ["inspect", f"{EX}/gantry/Y-straightness-Z.sty", "--plot", "{out}/i.png"]),
    ("derive", ["derive", f"{EX}/chains/loh-2004-scmm.toml", "--order", "2"]),
    ("derive-head", ["derive", f"{EX}/heads/angle-head.toml", "--at", "A=30,C=40"]),
    ("identify", ["identify", f"{EX}/identify/cmm-ballplate/machine.toml", "--out", "{out}/r"]),
    ("identify-plan", ["identify", f"{EX}/identify/tool-tracker/machine.toml", "--plan"]),
    (
        "ballbar",
        ["ballbar", f"{EX}/identify/tool-ballbar/circle-XY.csv", "--out", "{out}/r"],
    ),
]


def _digest(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()


def run_all(only: set[str] | None = None) -> dict[str, dict[str, str]]:
    """The digests of every run: ``{run: {"stdout": ..., "rc": ..., "<file>": ...}}``."""
    env = dict(os.environ, SOURCE_DATE_EPOCH="1700000000", PYTHONPATH=str(ROOT))
    env.pop("COLUMNS", None)
    results: dict[str, dict[str, str]] = {}
    for name, args in RUNS:
        if only and name not in only:
            continue
        # each run in a fresh folder holding the examples (a link named "data") and its
        # outputs under "out": the paths a command is given, which its outputs record
        # (the command line of a report), are then the same in every run
        with tempfile.TemporaryDirectory() as tmp:
            os.symlink(ROOT / "data", Path(tmp, "data"))
            out = Path(tmp, "out")
            out.mkdir()
            argv = [a.replace("{out}", "out") for a in args]
            proc = subprocess.run(
                [sys.executable, "-m", "esp", *argv],
                cwd=tmp,
                env=env,
                capture_output=True,
            )
            record = {
                "rc": str(proc.returncode),
                "stdout": _digest(proc.stdout),
                "stderr": _digest(proc.stderr),
            }
            for path in sorted(p for p in out.rglob("*") if p.is_file()):
                record[str(path.relative_to(out))] = _digest(path.read_bytes())
            results[name] = record
            print(f"{name}: rc {proc.returncode}, {len(record) - 3} files", flush=True)
    return results


def compare(before: dict[str, dict[str, str]], after: dict[str, dict[str, str]]) -> list[str]:
    """One line per output that differs or is missing on one side."""
    lines = []
    for run in sorted(set(before) | set(after)):
        b, a = before.get(run, {}), after.get(run, {})
        for key in sorted(set(b) | set(a)):
            if b.get(key) != a.get(key):
                lines.append(f"{run}: {key}: {b.get(key, 'absent')} -> {a.get(key, 'absent')}")
    return lines


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    group = parser.add_mutually_exclusive_group(required=True)
    group.add_argument("--record", metavar="JSON")
    group.add_argument("--compare", metavar="JSON")
    parser.add_argument("--only", nargs="*", help="run only these names")
    args = parser.parse_args()
    results = run_all(set(args.only) if args.only else None)
    if args.record:
        Path(args.record).write_text(json.dumps(results, indent=1, sort_keys=True) + "\n")
        return 0
    before = json.loads(Path(args.compare).read_text())
    if args.only:
        before = {k: v for k, v in before.items() if k in args.only}
    differ = compare(before, results)
    for line in differ:
        print(line)
    print(f"{len(differ)} outputs differ" if differ else "every output is the same")
    return 1 if differ else 0


if __name__ == "__main__":
    sys.exit(main())
