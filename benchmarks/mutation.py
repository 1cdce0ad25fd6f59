"""Mutation testing of the numeric core: do the tests notice a wrong number?

Each mutant is one small change to one module -- an arithmetic operator swapped (``+`` and
``-``, ``*`` and ``/``, ``**`` to ``*``), a comparison turned (``<`` and ``<=``, ``>`` and
``>=``, ``==`` and ``!=``, ``is``/``in`` and their negations), ``and``/``or`` swapped, a
unary minus dropped, ``max``/``min`` (and ``argmax``/``argmin``, ``maximum``/``minimum``)
swapped, a numeric constant moved by one (which turns ``position += 1`` into ``+= 2``).
The mutants are made on the syntax tree (:mod:`ast`) and written back with
:func:`ast.unparse`; docstrings, f-strings and annotations are left alone. For every
mutant the tests mapped to the module (:data:`MODULES`) run with ``pytest -x`` in a copy of
the repository (``esp/``, ``tests/``, ``data/`` and ``pyproject.toml`` copied to a
temporary folder, one per job): the working tree is never changed. A mutant is *killed*
when the tests fail, *survives* when they pass, and *times out* when they run longer than
``--timeout-factor`` times the unmutated run (plus 10 s).

The score of a module is (killed + timed out) / mutants run. Every survivor is printed as
``file:line:column  change`` with the line as it reads: either a test is missing, or the change
does not alter what the module computes (an equivalent mutant; docs/testing.md lists
those found so far and why).

Mutation runs are heavy (one pytest run per mutant): cap them with ``--max-mutants``
(a random sample, ``--seed``), and on a shared machine run them with ``nice``.

Run from the repository root:
    nice -n 19 python benchmarks/mutation.py [--modules grid,positioning] [--max-mutants 40]
        [--seed 1] [--jobs 1] [--slow] [--list] [--lines 412,413] [--tests a.py,b.py]
"""

from __future__ import annotations

import argparse
import ast
import os
import random
import shutil
import subprocess
import sys
import tempfile
import time
from collections.abc import Iterator
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from pathlib import Path
from queue import Queue
from typing import Any

ROOT = Path(__file__).resolve().parent.parent

#: the modules of the numeric core and the test files that cover each
MODULES: dict[str, tuple[str, ...]] = {
    "esp/core/grid.py": ("tests/test_grid.py", "tests/test_grid_bounds.py"),
    "esp/core/synthesis.py": (
        "tests/test_synthesis.py",
        "tests/test_synthesis_mutants.py",
        "tests/test_models.py",
        "tests/test_models_derived.py",
        "tests/test_five_axis.py",
        "tests/test_rotary_model.py",
        "tests/test_compensated.py",
        "tests/test_compensation_predict.py",
        "tests/test_uncertainty_propagate.py",
    ),
    "esp/iso230/positioning.py": ("tests/test_iso230.py", "tests/test_cli_iso230.py"),
    "esp/core/uncertainty/gum.py": ("tests/test_uncertainty_gum.py",),
    "esp/core/uncertainty/propagate.py": (
        "tests/test_uncertainty_propagate.py",
        "tests/test_uncertainty_config.py",
        "tests/test_uncertainty_montecarlo.py",
        "tests/test_uncertainty_instruments.py",
    ),
    "esp/identify/solve.py": ("tests/test_identify_solve.py", "tests/test_identify.py"),
}

#: what the copy of the repository holds
COPIED = ("esp", "tests", "data", "pyproject.toml")

_BINARY: dict[type[ast.operator], type[ast.operator]] = {
    ast.Add: ast.Sub,
    ast.Sub: ast.Add,
    ast.Mult: ast.Div,
    ast.Div: ast.Mult,
    ast.FloorDiv: ast.Div,
    ast.Pow: ast.Mult,
    ast.Mod: ast.FloorDiv,
}
_COMPARE: dict[type[ast.cmpop], type[ast.cmpop]] = {
    ast.Lt: ast.LtE,
    ast.LtE: ast.Lt,
    ast.Gt: ast.GtE,
    ast.GtE: ast.Gt,
    ast.Eq: ast.NotEq,
    ast.NotEq: ast.Eq,
    ast.Is: ast.IsNot,
    ast.IsNot: ast.Is,
    ast.In: ast.NotIn,
    ast.NotIn: ast.In,
}
_NAMES = {
    "max": "min",
    "min": "max",
    "argmax": "argmin",
    "argmin": "argmax",
    "maximum": "minimum",
    "minimum": "maximum",
    "nanmax": "nanmin",
    "nanmin": "nanmax",
}
_SYMBOL = {
    ast.Add: "+",
    ast.Sub: "-",
    ast.Mult: "*",
    ast.Div: "/",
    ast.FloorDiv: "//",
    ast.Pow: "**",
    ast.Mod: "%",
    ast.Lt: "<",
    ast.LtE: "<=",
    ast.Gt: ">",
    ast.GtE: ">=",
    ast.Eq: "==",
    ast.NotEq: "!=",
    ast.Is: "is",
    ast.IsNot: "is not",
    ast.In: "in",
    ast.NotIn: "not in",
    ast.And: "and",
    ast.Or: "or",
}


@dataclass(frozen=True)
class Mutant:
    """One change: the ``index``-th mutation site of ``module`` (in the order of
    :func:`_sites`), at ``line``, described by ``change``."""

    module: str
    index: int
    line: int
    col: int
    change: str


def _skipped(tree: ast.Module) -> set[int]:
    """Nodes never mutated: docstrings, f-strings, annotations, ``__all__``."""
    out: set[int] = set()

    def drop(node: ast.AST | None) -> None:
        if node is not None:
            out.update(id(n) for n in ast.walk(node))

    for node in ast.walk(tree):
        body = getattr(node, "body", None)
        first = body[0] if isinstance(body, list) and body else None
        if isinstance(first, ast.Expr) and isinstance(first.value, ast.Constant | ast.JoinedStr):
            drop(first)  # a docstring (a lone constant statement is one too)
        if isinstance(node, ast.JoinedStr):
            drop(node)
        elif isinstance(node, ast.AnnAssign | ast.arg):
            drop(node.annotation)
        elif isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef):
            drop(node.returns)
        elif isinstance(node, ast.Assign) and any(
            isinstance(t, ast.Name) and t.id == "__all__" for t in node.targets
        ):
            drop(node)
    return out


@dataclass
class _Site:
    """A place to change: ``kind`` one of op, cmp, const, name, attr, neg; ``value`` the
    new operator class, constant or name; ``k`` the comparison's operator index."""

    node: ast.AST
    line: int
    col: int
    change: str
    kind: str
    value: Any = None
    k: int = 0


def _sites(tree: ast.Module) -> Iterator[_Site]:
    """Every mutation site of the tree, in the order of :func:`ast.walk`."""
    skip = _skipped(tree)
    for node in ast.walk(tree):
        if id(node) in skip:
            continue
        at = getattr(node, "lineno", 0), getattr(node, "col_offset", -1) + 1
        if isinstance(node, ast.BinOp | ast.AugAssign) and type(node.op) in _BINARY:
            new: Any = _BINARY[type(node.op)]
            yield _Site(node, *at, f"`{_SYMBOL[type(node.op)]}` -> `{_SYMBOL[new]}`", "op", new)
        elif isinstance(node, ast.Compare):
            for k, op in enumerate(node.ops):
                if type(op) in _COMPARE:
                    new = _COMPARE[type(op)]
                    change = f"`{_SYMBOL[type(op)]}` -> `{_SYMBOL[new]}`"
                    yield _Site(node, *at, change, "cmp", new, k)
        elif isinstance(node, ast.BoolOp):
            new = ast.Or if isinstance(node.op, ast.And) else ast.And
            yield _Site(node, *at, f"`{_SYMBOL[type(node.op)]}` -> `{_SYMBOL[new]}`", "op", new)
        elif isinstance(node, ast.UnaryOp) and isinstance(node.op, ast.USub):
            yield _Site(node, *at, "unary `-` dropped", "neg")
        elif isinstance(node, ast.Constant) and type(node.value) in (int, float):
            value: Any = node.value
            yield _Site(node, *at, f"`{value!r}` -> `{value + 1!r}`", "const", value + 1)
        elif isinstance(node, ast.Name) and node.id in _NAMES:
            new = _NAMES[node.id]
            yield _Site(node, *at, f"`{node.id}` -> `{new}`", "name", new)
        elif isinstance(node, ast.Attribute) and node.attr in _NAMES:
            new = _NAMES[node.attr]
            yield _Site(node, *at, f"`.{node.attr}` -> `.{new}`", "attr", new)


class _DropMinus(ast.NodeTransformer):
    def __init__(self, target: ast.AST) -> None:
        self.target = target

    def visit_UnaryOp(self, node: ast.UnaryOp) -> ast.AST:  # noqa: N802 (ast's name)
        if node is self.target:
            return node.operand
        self.generic_visit(node)
        return node


def mutants(module: str, source: str) -> list[Mutant]:
    """Every mutant of ``module`` (a path relative to the repository root) of text
    ``source``."""
    tree = ast.parse(source)
    return [
        Mutant(module, k, site.line, site.col, site.change) for k, site in enumerate(_sites(tree))
    ]


def mutated_source(source: str, index: int) -> str:
    """The module's source with its ``index``-th site changed (:func:`ast.unparse`)."""
    tree = ast.parse(source)
    for k, site in enumerate(_sites(tree)):
        if k != index:
            continue
        node: Any = site.node
        if site.kind == "op":
            node.op = site.value()
        elif site.kind == "cmp":
            node.ops[site.k] = site.value()
        elif site.kind == "const":
            node.value = site.value
        elif site.kind == "name":
            node.id = site.value
        elif site.kind == "attr":
            node.attr = site.value
        else:  # "neg"
            tree = _DropMinus(node).visit(tree)
        return ast.unparse(ast.fix_missing_locations(tree))
    raise IndexError(f"no mutation site {index}")


def _copy(into: Path) -> None:
    for name in COPIED:
        src = ROOT / name
        if src.is_dir():
            shutil.copytree(
                src,
                into / name,
                ignore=shutil.ignore_patterns("__pycache__", "*.pyc", ".pytest_cache"),
            )
        elif src.exists():
            shutil.copy2(src, into / name)


def _pytest(
    copy: Path, tests: tuple[str, ...], slow: bool, timeout: float
) -> tuple[str, float, str]:
    """Run the tests in the copy: ("passed" | "failed" | "timeout", seconds, the end of
    pytest's output)."""
    env = dict(os.environ, PYTHONPATH=str(copy), PYTHONDONTWRITEBYTECODE="1")
    cmd = [sys.executable, "-m", "pytest", "-x", "-q", "-n", "0", "-p", "no:cacheprovider"]
    cmd += ["-m", "" if slow else "not slow", *tests]
    start = time.monotonic()
    try:
        done = subprocess.run(
            cmd, cwd=copy, env=env, capture_output=True, text=True, timeout=timeout, check=False
        )
    except subprocess.TimeoutExpired:
        return "timeout", time.monotonic() - start, ""
    tail = "\n".join((done.stdout + done.stderr).splitlines()[-15:])
    return ("passed" if done.returncode == 0 else "failed"), time.monotonic() - start, tail


def run_module(
    module: str,
    original: str,
    chosen: list[Mutant],
    copies: Queue[Path],
    slow: bool,
    factor: float,
    jobs: int,
) -> dict[str, list[Mutant]] | None:
    """Run one module's chosen mutants of its text ``original``; None when its tests fail
    unmutated."""
    tests = MODULES[module]
    copy = copies.get()
    try:
        (copy / module).write_text(original, encoding="utf-8")
        status, base, tail = _pytest(copy, tests, slow, timeout=600.0)
    finally:
        copies.put(copy)
    if status != "passed":
        print(f"{module}: the tests fail without a mutation ({' '.join(tests)}); skipped")
        print("    " + tail.replace("\n", "\n    "))
        return None
    timeout = factor * base + 10.0
    outcome: dict[str, list[Mutant]] = {"killed": [], "survived": [], "timeout": []}

    def one(m: Mutant) -> tuple[str, Mutant]:
        source = mutated_source(original, m.index)
        try:
            compile(source, m.module, "exec")
        except SyntaxError:
            return "killed", m
        copy = copies.get()
        target = copy / m.module
        try:
            target.write_text(source, encoding="utf-8")
            status, _, _ = _pytest(copy, tests, slow, timeout)
        finally:
            target.write_text(original, encoding="utf-8")
            copies.put(copy)
        return {"passed": "survived", "failed": "killed", "timeout": "timeout"}[status], m

    with ThreadPoolExecutor(max_workers=jobs) as pool:
        for status, m in pool.map(one, chosen):
            outcome[status].append(m)
    return outcome


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument(
        "--modules",
        default="",
        help="comma-separated module names or paths (default: every module of MODULES)",
    )
    parser.add_argument("--max-mutants", type=int, default=40, help="per module (0: all)")
    parser.add_argument("--seed", type=int, default=1, help="of the random sample of mutants")
    parser.add_argument("--jobs", type=int, default=1, help="pytest runs at a time")
    parser.add_argument("--slow", action="store_true", help="include the tests marked slow")
    parser.add_argument("--timeout-factor", type=float, default=3.0)
    parser.add_argument("--lines", default="", help="only mutants on these lines (one module)")
    parser.add_argument("--list", action="store_true", help="list the mutants, run nothing")
    parser.add_argument(
        "--tests", default="", help="comma-separated test files instead of those of MODULES"
    )
    args = parser.parse_args(argv)

    wanted = [w.strip() for w in args.modules.split(",") if w.strip()]
    modules = [
        m
        for m in MODULES
        if not wanted or any(w in (m, Path(m).name, Path(m).stem) for w in wanted)
    ]
    unknown = [w for w in wanted if not any(w in (m, Path(m).name, Path(m).stem) for m in MODULES)]
    if unknown or not modules:
        parser.error(f"unknown module(s) {', '.join(unknown) or '(none)'}; known: {list(MODULES)}")
    lines = {int(v) for v in args.lines.split(",") if v.strip()}
    if args.tests:
        chosen_tests = tuple(t.strip() for t in args.tests.split(",") if t.strip())
        for module in modules:
            MODULES[module] = chosen_tests
    if args.jobs < 1 or args.max_mutants < 0:
        parser.error("--jobs must be at least 1 and --max-mutants at least 0")

    plan: dict[str, list[Mutant]] = {}
    sources = {m: (ROOT / m).read_text(encoding="utf-8") for m in modules}
    for module in modules:
        every = mutants(module, sources[module])
        chosen = [m for m in every if not lines or m.line in lines]
        if args.max_mutants and len(chosen) > args.max_mutants:
            chosen = random.Random(f"{args.seed}:{module}").sample(chosen, args.max_mutants)
        plan[module] = sorted(chosen, key=lambda m: (m.line, m.index))
        print(f"{module}: {len(every)} mutants, {len(plan[module])} chosen")
    if args.list:
        for module, chosen in plan.items():
            source = sources[module].splitlines()
            for m in chosen:
                print(f"  {module}:{m.line}:{m.col}  {m.change}   | {source[m.line - 1].strip()}")
        return 0

    print(
        f"seed {args.seed}, at most {args.max_mutants or 'all'} mutants per module, "
        f"{args.jobs} job(s), {'all' if args.slow else 'fast'} tests, "
        f"timeout {args.timeout_factor:g} x the unmutated run + 10 s"
    )
    rows = []
    with tempfile.TemporaryDirectory(prefix="esp-mutation-") as tmp:
        copies: Queue[Path] = Queue()
        for j in range(args.jobs):
            copy = Path(tmp) / f"copy{j}"
            copy.mkdir()
            _copy(copy)
            copies.put(copy)
        for module, chosen in plan.items():
            start = time.monotonic()
            outcome = run_module(
                module, sources[module], chosen, copies, args.slow, args.timeout_factor, args.jobs
            )
            if outcome is None:
                continue
            n = len(chosen)
            caught = len(outcome["killed"]) + len(outcome["timeout"])
            score = 100.0 * caught / n if n else 100.0
            rows.append((module, n, outcome, score))
            print(
                f"{module}: {n} run, {len(outcome['killed'])} killed, "
                f"{len(outcome['survived'])} survived, {len(outcome['timeout'])} timed out: "
                f"score {score:.0f} % ({time.monotonic() - start:.0f} s)"
            )
            source = sources[module].splitlines()
            for m in sorted(outcome["survived"], key=lambda m: (m.line, m.index)):
                text = source[m.line - 1].strip()
                print(f"  survived  {module}:{m.line}:{m.col}  {m.change}   | {text}")
            sys.stdout.flush()
    print("\nmodule                               run  killed  survived  timeout  score")
    for module, n, outcome, score in rows:
        print(
            f"{module:<36} {n:>4} {len(outcome['killed']):>7} {len(outcome['survived']):>9}"
            f" {len(outcome['timeout']):>8}  {score:>4.0f} %"
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
