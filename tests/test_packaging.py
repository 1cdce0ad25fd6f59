"""The package's declarations that CI relies on: the floors of pyproject.toml are the
versions .ci/lowest.txt installs, and the examples in the docstrings run with the suite;
and what the console script sets up before it runs a command."""

from __future__ import annotations

import os
import re
import runpy
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def _pyproject() -> dict:
    return tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))


def test_lowest_txt_pins_the_declared_floors(capsys):
    check = runpy.run_path(str(ROOT / ".ci" / "check_lowest.py"))
    assert check["main"]() == 0, capsys.readouterr().out
    # and it tells a mismatch: 1.25 and 1.25.0 are one release, 1.25 and 1.24 are not
    assert check["_release"]("1.25") == check["_release"]("1.25.0") != check["_release"]("1.24")
    assert check["_name"]("Pytest_XDist") == "pytest-xdist"


def test_the_distribution_has_a_name_of_its_own_and_installs_esp():
    project = _pyproject()["project"]
    # the index's "esp" is another project; the command and the import package stay esp
    assert project["name"] == "esp-volumetric"
    assert project["scripts"] == {"esp": "esp.cli:run"}


def test_the_docstring_examples_run_with_the_suite():
    options = _pyproject()["tool"]["pytest"]["ini_options"]
    assert "esp" in options["testpaths"]
    assert "--doctest-modules" in options["addopts"].split()
    examples = sum(
        len(re.findall(r"^\s*>>> ", p.read_text(encoding="utf-8"), re.MULTILINE))
        for p in (ROOT / "esp").rglob("*.py")
    )
    skipped = sum(
        p.read_text(encoding="utf-8").count("doctest: +SKIP") for p in (ROOT / "esp").rglob("*.py")
    )
    assert examples >= 50 and skipped == 0


def test_the_command_runs_its_linear_algebra_on_one_thread_unless_told(monkeypatch):
    import esp.cli as cli

    seen: list[dict[str, str | None]] = []
    monkeypatch.setattr(
        cli, "main", lambda **kw: seen.append({k: os.environ.get(k) for k in cli.BLAS_THREADS})
    )
    monkeypatch.setattr(cli.gc, "freeze", lambda: None)  # not this test process's objects
    for key in cli.BLAS_THREADS:  # set first, so that the undo removes what run() sets
        monkeypatch.setenv(key, "")
        monkeypatch.delenv(key)
    monkeypatch.setenv("MKL_NUM_THREADS", "4")  # the user's choice is kept
    cli.run()
    assert seen == [
        {
            "OPENBLAS_NUM_THREADS": "1",
            "MKL_NUM_THREADS": "4",
            "OMP_NUM_THREADS": "1",
            "VECLIB_MAXIMUM_THREADS": "1",
        }
    ]
