"""Check that .ci/lowest.txt pins every dependency of pyproject.toml (the run-time ones and
those of the test extra) at exactly its declared floor, so that the lowest-versions run of
.ci/run tests the floors that users are promised.

Usage: python .ci/check_lowest.py  (exit 1 and one line per mismatch when they differ)
"""

from __future__ import annotations

import re
import sys
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
REQUIREMENT = re.compile(r"^\s*([A-Za-z0-9_.-]+)\s*>=\s*([0-9][0-9.]*)\s*$")
PIN = re.compile(r"^\s*([A-Za-z0-9_.-]+)\s*==\s*([0-9][0-9.]*)\s*(#.*)?$")


def _name(name: str) -> str:
    """A distribution name as the package index compares it (PEP 503)."""
    return re.sub(r"[-_.]+", "-", name).lower()


def _release(version: str) -> tuple[int, ...]:
    """1.25 and 1.25.0 are one release."""
    parts = [int(p) for p in version.split(".")]
    while parts and parts[-1] == 0:
        parts.pop()
    return tuple(parts)


def main() -> int:
    project = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["project"]
    declared = list(project["dependencies"]) + list(project["optional-dependencies"]["test"])
    pins: dict[str, str] = {}
    lowest = ROOT / ".ci" / "lowest.txt"
    for number, line in enumerate(lowest.read_text(encoding="utf-8").splitlines(), 1):
        if not line.strip() or line.lstrip().startswith("#"):
            continue
        match = PIN.match(line)
        if match is None:
            print(f"{lowest.name}:{number}: expected 'name==version', found {line!r}")
            return 1
        pins[_name(match[1])] = match[2]
    problems = []
    for requirement in declared:
        match = REQUIREMENT.match(requirement)
        if match is None:
            problems.append(f"pyproject.toml: {requirement!r} has no plain '>=' floor")
            continue
        name, floor = _name(match[1]), match[2]
        if name not in pins:
            problems.append(f"{lowest.name}: no pin for {name} (pyproject.toml: >={floor})")
        elif _release(pins[name]) != _release(floor):
            problems.append(
                f"{lowest.name}: {name}=={pins[name]}, but pyproject.toml declares >={floor}"
            )
    for problem in problems:
        print(problem)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
