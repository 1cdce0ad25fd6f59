"""Draw the gantry example's report and an ``esp inspect --plot`` figure twice each, with
the interpreter that runs this script, and check that the two drawings are the same byte
for byte (with a fixed SOURCE_DATE_EPOCH, the date that a reproducible document carries).

Usage: python .ci/same_twice.py  (exit 0 when every file is identical, else 1 and what
differs; the output goes to a temporary folder)
"""

from __future__ import annotations

import os
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
GANTRY = ROOT / "data" / "examples" / "gantry"
# 2026-01-01T00:00:00Z
EPOCH = "1767225600"


def _esp(*args: str, cwd: Path) -> None:
    env = dict(os.environ, SOURCE_DATE_EPOCH=EPOCH)
    done = subprocess.run(
        [sys.executable, "-m", "esp", *args], cwd=cwd, env=env, capture_output=True, text=True
    )
    if done.returncode != 0:
        raise SystemExit(f"esp {' '.join(args)}: exit {done.returncode}\n{done.stderr}")


def _files(folder: Path) -> dict[str, bytes]:
    return {
        p.relative_to(folder).as_posix(): p.read_bytes()
        for p in sorted(folder.rglob("*"))
        if p.is_file()
    }


def main() -> int:
    with tempfile.TemporaryDirectory() as temp:
        work = Path(temp)
        drawings = []
        for n in (1, 2):
            # both drawings under the same names: the report records its command line
            out = work / "out"
            out.mkdir()
            _esp("analyse", str(GANTRY / "machine.toml"), "--out", "out/report", cwd=work)
            _esp("inspect", str(GANTRY / "X-linear.rtl"), "--plot", "out/inspect.png", cwd=work)
            drawings.append(_files(out))
            out.rename(work / f"drawing{n}")
        first, second = drawings
        problems = []
        if sorted(first) != sorted(second):
            problems.append(f"different files: {sorted(first)} and {sorted(second)}")
        for name in sorted(set(first) & set(second)):
            if first[name] != second[name]:
                problems.append(f"{name}: the two drawings differ")
        pdfs = [name for name in first if name.endswith(".pdf")]
        pngs = [name for name in first if name.endswith(".png")]
        if not pdfs or "inspect.png" not in pngs:
            problems.append(f"expected PDF and PNG files, found {sorted(first)}")
        for problem in problems:
            print(problem)
        if not problems:
            print(f"same twice: {len(first)} files ({len(pdfs)} PDF, {len(pngs)} PNG)")
        return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
