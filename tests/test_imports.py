"""The numeric core imports only numpy and the standard library: pandas, matplotlib,
sympy and click belong to the report, derivation and command-line layers. The package has
no import cycles."""

from __future__ import annotations

import ast
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent / "esp"

CORE = [
    "esp",
    "esp.core.profile",
    "esp.core.machine",
    "esp.core.units",
    "esp.core.grid",
    "esp.core.synthesis",
    "esp.core.analysis",
    "esp.core.names",
    "esp.core.results",
    "esp.config",
    "esp.io.outputs",
    "esp.core.kinematics",
    "esp.core.kinematics.exact",
    "esp.core.kinematics.linear",
    "esp.config.chain",
    "esp.config.devices",
    "esp.config.curves",
    "esp.core.kinematics.values",
    "esp.io.tomlfile",
    "esp.core.text",
    "esp.core.models.derived",
    "esp.core.models.signs",
    "esp.heads",
    "esp.core.devices",
    "esp.parallel",
    "esp.compensation",
    "esp.diagonals.model",
    "esp.compare.model",
    "esp.iso230.vdi3441",
    "esp.core.uncertainty.montecarlo",
    "esp.core.uncertainty.gum",
    "esp.core.uncertainty.budget",
    "esp.core.environment",
    "esp.iso230.positioning",
    "esp.core.models.esp",
    "esp.core.models.bind",
    "esp.io.load",
    "esp.core.uncertainty",
    "esp.core.uncertainty.spec",
    "esp.core.uncertainty.propagate",
]


@pytest.mark.slow
def test_core_does_not_import_presentation_libraries():
    code = (
        "import importlib, sys\n"
        f"for m in {CORE!r}: importlib.import_module(m)\n"
        "bad = sorted(m for m in ('matplotlib', 'pandas', 'click', 'sympy') if m in sys.modules)\n"
        "print(','.join(bad))\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == ""


def test_library_api_without_the_cli(tmp_path):
    import esp

    toml = tmp_path / "m.toml"
    toml.write_text(
        '[machine]\nname = "m"\nconfiguration = "wBMTt"\n'
        'axes = { bottom = "X", middle = "Y", top = "Z" }\n'
        "[axes.X]\ntravel = [0, 100]\nstep = 50\n"
        "[axes.X.errors]\nlinear = { points = [[0, 0], [100, 3]] }\n"
        "[axes.Y]\ntravel = [0, 100]\nstep = 50\n[axes.Z]\ntravel = [0, 100]\nstep = 50\n",
        encoding="utf-8",
    )
    result = esp.analyse(esp.load_machine(toml))
    assert result.cases[0].volumetric.value_um == 3.0
    point = esp.evaluate_point(esp.load_machine(toml), {"X": 50, "Y": 0, "Z": 0})
    assert point.cases[0].breakdown.errors_um["X"] == 1.5


def _module_name(path: Path) -> str:
    parts = list(path.relative_to(ROOT.parent).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


def _type_checking_only(tree: ast.AST) -> set[int]:
    """The ids of the import statements under ``if TYPE_CHECKING:`` (never run)."""
    out = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.If) and ast.unparse(node.test) in (
            "TYPE_CHECKING",
            "typing.TYPE_CHECKING",
        ):
            out.update(id(n) for stmt in node.body for n in ast.walk(stmt))
    return out


def _runtime_names(node: ast.AST) -> list[str]:
    """The module named by a call that imports at run time from a string:
    ``importlib.import_module("esp.x")``, ``import_module("esp.x")``,
    ``__import__("esp.x")``."""
    if not isinstance(node, ast.Call) or not node.args:
        return []
    func = ast.unparse(node.func)
    arg = node.args[0]
    if func.rpartition(".")[2] in ("import_module", "__import__") and isinstance(arg, ast.Constant):
        return [str(arg.value)]
    return []


def _imports(path: Path, modules: set[str]) -> set[str]:
    """Every esp module ``path`` imports when it runs: at the top, inside a function, or
    from a string (``importlib.import_module``); not the imports for type checkers only."""
    out = set()
    tree = ast.parse(path.read_text(encoding="utf-8"))
    skip = _type_checking_only(tree)
    for node in ast.walk(tree):
        if id(node) in skip:
            continue
        if isinstance(node, ast.Import):
            names = [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            names = [f"{node.module}.{a.name}" for a in node.names] + [node.module]
        elif _runtime_names(node):
            names = _runtime_names(node)
        else:
            continue
        for name in names:
            # the deepest esp module the statement names (a package, or a name in one)
            while name and name not in modules:
                name = name.rpartition(".")[0]
            if name:
                out.add(name)
    return out


def test_runtime_imports_are_seen():
    """The import graph sees an import made from a string, and not one made for type
    checkers only: a cycle through ``importlib.import_module`` cannot hide."""
    src = (
        "import importlib\nfrom typing import TYPE_CHECKING\n"
        "if TYPE_CHECKING:\n    from esp.report import plots\n"
        "def f():\n    return importlib.import_module('esp.volumetric.frames')\n"
    )
    tree = ast.parse(src)
    skip = _type_checking_only(tree)
    found = [n for node in ast.walk(tree) if id(node) not in skip for n in _runtime_names(node)]
    assert found == ["esp.volumetric.frames"]
    assert len(skip) > 0


@pytest.mark.slow
def test_no_import_cycles():
    files = {_module_name(p): p for p in ROOT.rglob("*.py")}
    modules = set(files)
    graph = {m: _imports(p, modules) - {m} for m, p in files.items()}
    # a package's __init__ that re-exports its submodules is not a cycle with them
    for m in graph:
        graph[m] = {
            d for d in graph[m] if not (d.startswith(m + ".") and files[m].name == "__init__.py")
        }
    cycles = []
    state: dict[str, int] = {}

    def visit(m: str, stack: list[str]) -> None:
        state[m] = 1
        for d in sorted(graph[m]):
            if state.get(d) == 1:
                cycles.append(" -> ".join(stack[stack.index(d) :] + [d]))
            elif d not in state:
                visit(d, stack + [d])
        state[m] = 2

    for m in sorted(graph):
        if m not in state:
            visit(m, [m])
    assert cycles == []


def test_version_and_help_load_only_the_command_line():
    """``esp --version`` and ``esp --help`` load the command line and the modules it needs
    for its messages, nothing of the numeric core (numpy) or of the message hints
    (difflib)."""
    code = (
        "import runpy, sys\n"
        "sys.argv = ['esp'] + sys.argv[1:]\n"
        "try:\n"
        "    runpy.run_module('esp', run_name='__main__')\n"
        "except SystemExit:\n"
        "    pass\n"
        "esp = sorted(m for m in sys.modules if m == 'esp' or m.startswith('esp.'))\n"
        "other = sorted(m for m in ('numpy', 'difflib') if m in sys.modules)\n"
        "print(' '.join(esp), '|', ' '.join(other))\n"
    )
    for args in (["--version"], ["--help"]):
        out = subprocess.run(
            [sys.executable, "-c", code, *args], capture_output=True, text=True, check=True
        )
        esp_modules, other = out.stdout.strip().splitlines()[-1].split("|")
        assert set(esp_modules.split()) <= {
            "esp",
            "esp.__main__",
            "esp._version",
            "esp.cli",
            "esp.core",
            "esp.core.errors",
            "esp.core.text",
        }, (args, esp_modules)
        assert other.strip() == "", (args, other)


#: the engine: what computes an error field; renderers read the result's evaluation instead
ENGINE = {"esp.core.synthesis", "esp.core.grid", "esp.core.evaluation", "esp.core.analysis"}


@pytest.mark.slow
def test_no_renderer_imports_the_engine():
    """Maps, grid CSV, frames and PDF draw the evaluation the result carries
    (:class:`esp.core.evaluation.Evaluation`); no module of ``esp.report`` imports the engine to
    compute a field of its own (imports for type checkers only are allowed)."""
    files = {_module_name(p): p for p in ROOT.rglob("*.py")}
    modules = set(files)
    offenders = {
        m: sorted(_imports(p, modules) & ENGINE)
        for m, p in files.items()
        if m.startswith("esp.report") and _imports(p, modules) & ENGINE
    }
    assert offenders == {}
