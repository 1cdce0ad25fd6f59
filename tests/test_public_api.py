"""esp uses its dependencies through their public API only.

An AST check over every module of ``esp/``: no private module of a dependency imported, no
private attribute of an object esp does not define read or set (``obj._name``, or through
``getattr``/``setattr``/``hasattr``/``delattr`` with the name written out), no method of an
esp class that overrides a private method of a base esp does not define, no attribute of a
dependency's module replaced (a monkey-patch), and nothing put into ``sys.modules``. What
such code relies on can change in any release of the dependency.

A name with one leading underscore is esp's own when esp defines it somewhere (a function,
a class, a method, an assignment, an attribute set, an entry of ``__slots__``): then
``obj._name`` is taken to read esp's attribute. The few documented standard-library names
that begin with an underscore are listed in :data:`DOCUMENTED` with the reason.
"""

from __future__ import annotations

import ast
import builtins
import importlib
from collections.abc import Iterator, Mapping
from dataclasses import dataclass
from pathlib import Path

import pytest

ESP = Path(__file__).resolve().parents[1] / "esp"

#: names that begin with an underscore and are public, documented API
DOCUMENTED = {
    # collections.namedtuple (and typing.NamedTuple): the documented methods and fields of
    # every named tuple begin with an underscore so as not to clash with its field names
    "_asdict": "namedtuple._asdict, documented in collections",
    "_replace": "namedtuple._replace, documented in collections",
    "_fields": "namedtuple._fields, documented in collections",
    "_make": "namedtuple._make, documented in collections",
    "_field_defaults": "namedtuple._field_defaults, documented in collections",
    # os._exit: the documented way to end a (forked) process without cleanup
    "_exit": "os._exit, documented in os",
    # enum's documented "_sunder_" names
    "_missing_": "Enum._missing_, documented in enum",
    "_value_": "Enum._value_, documented in enum",
    "_name_": "Enum._name_, documented in enum",
    "_generate_next_value_": "Enum._generate_next_value_, documented in enum",
}


#: attributes of a standard-library module that its documentation says may be replaced
REPLACEABLE = {
    "sys.stdout": "sys: stdout may be replaced by another file-like object",
    "sys.stderr": "sys: stderr may be replaced by another file-like object",
    "warnings.showwarning": "warnings: 'You may replace this function'",
}


@dataclass(frozen=True)
class Finding:
    path: str
    line: int
    what: str

    def __str__(self) -> str:
        return f"{self.path}:{self.line}: {self.what}"


def _private(name: str) -> bool:
    """One leading underscore, not a dunder (``__x__``): private by Python's convention.
    (``__x`` names are mangled, so that they are private too.)"""
    return name.startswith("_") and not (name.startswith("__") and name.endswith("__"))


def _is_esp(module: str) -> bool:
    return module == "esp" or module.startswith("esp.")


def _defined_names(nodes: list[ast.AST]) -> set[str]:
    """Every private name among ``nodes`` (a module's) that the module defines: functions,
    classes, assignment targets (names and attributes), imports bound under another name
    and the entries of ``__slots__``."""
    names: set[str] = set()
    for node in nodes:
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
            names.add(node.name)
        elif isinstance(node, ast.Name) and isinstance(node.ctx, ast.Store):
            names.add(node.id)
        elif isinstance(node, ast.Attribute) and isinstance(node.ctx, ast.Store):
            names.add(node.attr)
        elif isinstance(node, ast.alias) and node.asname:
            names.add(node.asname)
        elif isinstance(node, ast.Assign) and any(
            isinstance(t, ast.Name) and t.id == "__slots__" for t in node.targets
        ):
            for item in ast.walk(node.value):
                if isinstance(item, ast.Constant) and isinstance(item.value, str):
                    names.add(item.value)
    return {n for n in names if _private(n)}


def _imported_modules(nodes: list[ast.AST]) -> dict[str, str]:
    """The names a module binds to imported modules or objects: name -> dotted origin."""
    bound: dict[str, str] = {}
    for node in nodes:
        if isinstance(node, ast.Import):
            for alias in node.names:
                if alias.asname:
                    bound[alias.asname] = alias.name
                else:
                    top = alias.name.split(".")[0]
                    bound[top] = top
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            for alias in node.names:
                bound[alias.asname or alias.name] = f"{node.module}.{alias.name}"
    return bound


def _resolve(expr: ast.expr, bound: Mapping[str, str]) -> str | None:
    """The dotted name an expression of names and attributes stands for, through the
    module's imports (``maxis.XAxis`` -> ``matplotlib.axis.XAxis``), or None."""
    parts: list[str] = []
    while isinstance(expr, ast.Attribute):
        parts.append(expr.attr)
        expr = expr.value
    if not isinstance(expr, ast.Name):
        return None
    head = bound.get(expr.id)
    if head is None:
        return f"builtins.{expr.id}" if not parts and hasattr(builtins, expr.id) else None
    return ".".join([head, *reversed(parts)])


def _load(dotted: str) -> object | None:
    """The object ``dotted`` names, imported; None when it cannot be."""
    parts = dotted.split(".")
    for cut in range(len(parts), 0, -1):
        try:
            obj: object = importlib.import_module(".".join(parts[:cut]))
        except ImportError:
            continue
        try:
            for name in parts[cut:]:
                obj = getattr(obj, name)
        except AttributeError:
            return None
        return obj
    return None


def check(sources: Mapping[str, str]) -> list[Finding]:
    """The findings over ``sources`` (the path of each module of esp -> its text)."""
    nodes = {path: list(ast.walk(ast.parse(text, filename=path))) for path, text in sources.items()}
    own: set[str] = set()
    own_classes: set[str] = set()
    for walked in nodes.values():
        own |= _defined_names(walked)
        own_classes |= {n.name for n in walked if isinstance(n, ast.ClassDef)}
    findings: list[Finding] = []
    for path, walked in nodes.items():
        findings += _check_module(path, walked, own, own_classes)
    return sorted(findings, key=lambda f: (f.path, f.line, f.what))


def _check_module(
    path: str, nodes: list[ast.AST], own: set[str], own_classes: set[str]
) -> Iterator[Finding]:
    bound = _imported_modules(nodes)
    foreign = {  # names bound to a dependency's module or object
        name for name, origin in bound.items() if not _is_esp(origin)
    }
    for node in nodes:
        line = getattr(node, "lineno", 0)
        # (a) a private module of a dependency, or a private name from one
        if isinstance(node, ast.Import):
            for alias in node.names:
                if not _is_esp(alias.name) and any(map(_private, alias.name.split("."))):
                    yield Finding(path, line, f"imports the private module {alias.name}")
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            if _is_esp(node.module) or node.module == "__future__":
                continue
            if any(map(_private, node.module.split("."))):
                yield Finding(path, line, f"imports from the private module {node.module}")
            for alias in node.names:
                if _private(alias.name):
                    yield Finding(path, line, f"imports the private {node.module}.{alias.name}")
        # (b) a private attribute of an object esp does not define
        elif isinstance(node, ast.Attribute):
            if not _private(node.attr) or node.attr in DOCUMENTED:
                continue
            if node.attr not in own:
                yield Finding(path, line, f"uses the private attribute .{node.attr}")
            elif isinstance(node.value, ast.Name) and node.value.id in foreign:
                yield Finding(path, line, f"uses the private {bound[node.value.id]}.{node.attr}")
        elif isinstance(node, ast.Call):
            yield from _check_call(path, node, bound, own)
        # (c) a method overriding a private method of a base esp does not define
        elif isinstance(node, ast.ClassDef):
            yield from _overrides(path, node, bound, own_classes)
        # (d) an entry of sys.modules set, and (e) a dependency's module patched
        elif isinstance(node, (ast.Assign, ast.AugAssign, ast.AnnAssign, ast.Delete)):
            targets = node.targets if isinstance(node, (ast.Assign, ast.Delete)) else [node.target]
            for target in targets:
                if isinstance(target, ast.Subscript):
                    if _resolve(target.value, bound) == "sys.modules":
                        yield Finding(path, line, "sets an entry of sys.modules")
                elif (
                    isinstance(target, ast.Attribute)
                    and isinstance(target.value, ast.Name)
                    and target.value.id in foreign
                ):
                    patched = f"{bound[target.value.id]}.{target.attr}"
                    if patched not in REPLACEABLE:
                        yield Finding(path, line, f"replaces {patched}")


def _check_call(
    path: str, node: ast.Call, bound: Mapping[str, str], own: set[str]
) -> Iterator[Finding]:
    line = node.lineno
    called = _resolve(node.func, bound)
    first = node.args[0] if node.args else None
    second = node.args[1] if len(node.args) > 1 else None
    if called in ("importlib.import_module", "builtins.__import__"):
        name = first.value if isinstance(first, ast.Constant) else None
        if isinstance(name, str) and not _is_esp(name) and any(map(_private, name.split("."))):
            yield Finding(path, line, f"imports the private module {name}")
    elif called in ("builtins.getattr", "builtins.setattr", "builtins.hasattr", "builtins.delattr"):
        if (
            isinstance(second, ast.Constant)
            and isinstance(second.value, str)
            and _private(second.value)
            and second.value not in own | DOCUMENTED.keys()
        ):
            name = called.split(".")[1]
            yield Finding(path, line, f"{name}() of the private attribute {second.value}")
    elif (
        isinstance(node.func, ast.Attribute)
        and node.func.attr in ("update", "setdefault", "pop", "popitem", "clear", "__setitem__")
        and _resolve(node.func.value, bound) == "sys.modules"
    ):
        yield Finding(path, line, f"changes sys.modules ({node.func.attr})")


def _overrides(
    path: str, cls: ast.ClassDef, bound: Mapping[str, str], own_classes: set[str]
) -> Iterator[Finding]:
    methods = [
        n
        for n in cls.body
        if isinstance(n, (ast.FunctionDef, ast.AsyncFunctionDef)) and _private(n.name)
    ]
    if not methods:
        return
    for base in cls.bases:
        dotted = _resolve(base, bound)
        if dotted is None:
            if isinstance(base, ast.Name) and base.id in own_classes:
                continue  # esp's own class: its private methods are esp's
            yield Finding(
                path, cls.lineno, f"class {cls.name} has private methods and a base esp cannot name"
            )
            continue
        if _is_esp(dotted) or dotted == "builtins.object":
            continue
        loaded = _load(dotted)
        for method in methods:
            if loaded is None or hasattr(loaded, method.name):
                yield Finding(
                    path,
                    method.lineno,
                    f"{cls.name}.{method.name} overrides the private {dotted}.{method.name}",
                )


def esp_sources() -> dict[str, str]:
    root = ESP.parent
    return {
        str(p.relative_to(root)): p.read_text(encoding="utf-8") for p in sorted(ESP.rglob("*.py"))
    }


@pytest.mark.slow  # parses every module of esp: a second or more
def test_esp_uses_only_the_public_api_of_its_dependencies() -> None:
    findings = check(esp_sources())
    assert not findings, "private API of a dependency used:\n" + "\n".join(map(str, findings))


def test_the_check_finds_each_kind_of_private_use() -> None:
    """The check itself: each kind of violation in a sample module is found, at its line;
    esp's own private names and the documented ones are not."""
    sample = "\n".join(
        [
            "import sys",  # 1
            "import matplotlib._afm",  # 2 (a)
            "from matplotlib._mathtext_data import tex2uni",  # 3 (a)
            "from matplotlib import _api, font_manager",  # 4 (a)
            "from argparse import HelpFormatter",  # 5
            "def f(text, nt, os):",  # 6
            "    text._get_layout(None)",  # 7 (b)
            "    nt._replace(a=1)",  # 8 documented
            "    os._exit(0)",  # 9 documented
            "    getattr(text, '_renderer')",  # 10 (b)
            "    sys.modules['fontTools.subset'] = text",  # 11 (d)
            "    font_manager.findfont = f",  # 12 (e)
            "    text._mine = 1",  # 13 esp's own (defined here)
            "    sys.modules.setdefault('x', text)",  # 14 (d)
            "class A(HelpFormatter):",  # 15
            "    def _format_usage(self):",  # 16 (c)
            "        pass",  # 17
            "    def _own(self):",  # 18 not a method of HelpFormatter
            "        pass",  # 19
            "font_manager._mine",  # 20 (b): esp's name, but read on a dependency's module
            "import importlib",  # 21
            "importlib.import_module('matplotlib._afm')",  # 22 (a)
            "del sys.modules['x']",  # 23 (d)
        ]
    )
    found = check({"esp/sample.py": sample})
    lines = [f.line for f in found]
    assert lines == [2, 3, 4, 7, 10, 11, 12, 14, 16, 20, 22, 23], "\n".join(map(str, found))
    assert all(str(f).startswith(f"esp/sample.py:{f.line}: ") for f in found)
    # esp's own module's private names are esp's
    assert check({"esp/a.py": "from esp.b import _x\n", "esp/b.py": "_x = 1\n"}) == []
