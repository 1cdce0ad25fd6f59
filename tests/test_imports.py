"""The numeric core imports only numpy and the standard library: pandas, matplotlib and
click belong to the report and command-line layers."""

from __future__ import annotations

import subprocess
import sys

CORE = [
    "esp",
    "esp.profile",
    "esp.machine",
    "esp.units",
    "esp.grid",
    "esp.synthesis",
    "esp.results",
    "esp.config",
    "esp.iso230",
    "esp.models.esp",
    "esp.models.bind",
    "esp.io.load",
    "esp.uncertainty",
    "esp.uncertainty.spec",
    "esp.uncertainty.propagate",
]


def test_core_does_not_import_presentation_libraries():
    code = (
        "import importlib, sys\n"
        f"for m in {CORE!r}: importlib.import_module(m)\n"
        "bad = sorted(m for m in ('matplotlib', 'pandas', 'click') if m in sys.modules)\n"
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
        '[axes.X]\ntravel = [0, 100]\nstep = 50\n'
        '[axes.X.errors]\nlinear = { points = [[0, 0], [100, 3]] }\n'
        '[axes.Y]\ntravel = [0, 100]\nstep = 50\n[axes.Z]\ntravel = [0, 100]\nstep = 50\n',
        encoding="utf-8",
    )
    result = esp.analyse(esp.load_machine(toml))
    assert result.cases[0].volumetric.value_um == 3.0
    point = esp.evaluate_point(esp.load_machine(toml), {"X": 50, "Y": 0, "Z": 0})
    assert point.cases[0].breakdown.errors_um["X"] == 1.5
