"""The layers of ``docs/architecture.md``, enforced on every import the package makes when
it runs (at the top of a module, inside a function, or from a string; not the imports for
type checkers only): each layer imports only the layers below it, a feature imports another
feature only where the architecture names that edge, and nothing imports the ``esp``
facade."""

from __future__ import annotations

from pathlib import Path

import pytest
from test_imports import ROOT, _imports, _module_name

#: bottom to top; a module may import its own layer and the layers listed before it
LAYERS = ("core", "io", "config", "report", "feature", "cli")

#: one folder per feature (``esp/<name>/``): its model, its results and its rendering
FEATURES = (
    "volumetric",
    "iso230",
    "angular",
    "heads",
    "parallel",
    "compensation",
    "diagonals",
    "compare",
    "batch",
    "identify",
    "ballbar",
    "skew",
)

#: the features a feature builds on (docs/architecture.md, "Features")
FEATURE_EDGES = {
    ("batch", "volumetric"),  # a batch is many volumetric analyses
    ("compare", "volumetric"),  # a comparison of two of them
    ("identify", "diagonals"),  # diagonal displacements are one kind of length
    ("ballbar", "identify"),  # a ballbar circle is read as identify reads its lengths
}


def layer_of(module: str) -> tuple[str, str]:
    """The layer of a module and its folder (the feature's name for a feature)."""
    parts = module.split(".")
    if module == "esp":
        return "facade", "esp"
    top = parts[1]
    if top in ("core", "_version"):
        return "core", "core"
    if top in ("io", "config", "report"):
        return top, top
    if top in FEATURES:
        return "feature", top
    if top in ("cli", "__main__"):
        return "cli", "cli"
    raise AssertionError(f"{module} is in no layer of docs/architecture.md")


def _graph() -> dict[str, set[str]]:
    files = {_module_name(p): p for p in ROOT.rglob("*.py")}
    return {m: _imports(p, set(files)) - {m} for m, p in files.items()}


def violations(graph: dict[str, set[str]]) -> list[str]:
    """Every import that goes up a layer, across features without a named edge, or into
    the facade."""
    out = []
    for module, deps in sorted(graph.items()):
        layer, folder = layer_of(module)
        for dep in sorted(deps):
            dep_layer, dep_folder = layer_of(dep)
            if dep_layer == "facade":
                out.append(f"{module} imports the esp facade")
            elif layer == "facade":
                continue  # the facade may re-export from any layer below the CLI
            elif LAYERS.index(dep_layer) > LAYERS.index(layer):
                out.append(f"{module} ({layer}) imports {dep} ({dep_layer})")
            elif (
                layer == dep_layer == "feature"
                and folder != dep_folder
                and (folder, dep_folder) not in FEATURE_EDGES
            ):
                out.append(f"{module} (feature {folder}) imports {dep} (feature {dep_folder})")
    return out


@pytest.mark.slow
def test_every_module_is_in_a_layer():
    for module in _graph():
        layer_of(module)


@pytest.mark.slow
def test_layers_import_only_downward():
    assert violations(_graph()) == []


def test_the_rule_sees_an_upward_import():
    """The rule is not vacuous: a core module importing the report, a report module
    importing a feature, a feature importing another without a named edge, and anything
    importing the facade are each caught; the named edges and downward imports are not."""
    graph = {
        "esp.core.grid": {"esp.report.drawing", "esp.core.errors"},
        "esp.report.drawing": {"esp.heads.maps", "esp.core.names"},
        "esp.heads.maps": {"esp.parallel.geometry", "esp.report.drawing"},
        "esp.batch.run": {"esp.volumetric.text", "esp.config"},
        "esp.cli.head": {"esp"},
        "esp": {"esp.cli.output"},
    }
    assert violations(graph) == [
        "esp.cli.head imports the esp facade",
        "esp.core.grid (core) imports esp.report.drawing (report)",
        "esp.heads.maps (feature heads) imports esp.parallel.geometry (feature parallel)",
        "esp.report.drawing (report) imports esp.heads.maps (feature)",
    ]


def test_feature_folders_exist():
    """Each feature of the picture is a folder of the package, and every top-level folder
    is a layer or a feature."""
    here = Path(ROOT)
    folders = {p.name for p in here.iterdir() if p.is_dir() and (p / "__init__.py").exists()}
    assert folders == set(FEATURES) | {"core", "io", "config", "report", "cli"}


def test_the_facade_api_is_the_documented_one():
    """``esp.__all__`` is the list of docs/api.md, and each name exists."""
    import re

    import esp

    doc = (ROOT.parent / "docs" / "api.md").read_text(encoding="utf-8")
    documented = set(re.findall(r"^\| `(\w+)(?:\(|`)", doc, flags=re.M))
    assert documented == set(esp.__all__)
    for name in esp.__all__:
        assert getattr(esp, name) is not None
