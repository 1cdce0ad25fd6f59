"""An Etalon Exchange file as esp input: ``{ etalon = "file" }`` error sources."""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest
from click.testing import CliRunner

from esp.cli import main

GANTRY = Path(__file__).resolve().parents[1] / "data" / "examples" / "gantry" / "machine.toml"

SMALL = """
[machine]
name = "Etalon input"
configuration = "wBMTt"
axes = {{ bottom = "X", middle = "Y", top = "Z" }}

[analysis]
straightness_fit = "none"

[axes.X]
travel = [0, 200]
step = 100

[axes.X.errors]
linear = {{ etalon = "cal.txt" }}
straightness = {{ Y = {{ etalon = "cal.txt" }} }}

[axes.Y]
travel = [0, 100]
step = 100

[axes.Z]
travel = [0, 100]
step = 100

[squareness]
XY = {{ etalon = "cal.txt" }}
{extra}
"""

CAL = """// LaserTRACER result
[C0Y]
VALUE = {square}
[EXX]
Gridpoints = {{
    0 0
    100 0.002
    200 0.005
}}
[EYX]
Gridpoints = {{
    0 0
    100 -0.001
    200 0
}}
"""


def _analyse(folder: Path, square: str = "-0.0001", extra: str = "") -> tuple[int, str]:
    (folder / "machine.toml").write_text(SMALL.format(extra=extra), encoding="utf-8")
    (folder / "cal.txt").write_text(CAL.format(square=square), encoding="utf-8")
    res = CliRunner().invoke(main, ["analyse", str(folder / "machine.toml"), "--json", "-"])
    return res.exit_code, res.output


def test_units_and_squareness_sign(tmp_path: Path) -> None:
    code, out = _analyse(tmp_path)
    assert code == 0, out
    result = json.loads(out)
    # C0Y = -100 µrad is squareness.XY = +100 µm/m (the sign esp's writer uses, the
    # ISO 230-1 EC0Y of docs/conventions.md); it adds S_XY·Y to X: the worst point is
    # X = 200, Y = 100 with EXX 5 µm (0.005 mm) + 100 µm/m · 0.1 m = 15 µm, EYX(200) = 0
    # (with the opposite sign: 10 µm at X = 0, Y = 100)
    text = CliRunner().invoke(main, ["analyse", str(tmp_path / "machine.toml")]).output
    assert re.search(r"XY\s+-EC0Y\s+100\s+used", text), text
    assert "cal.txt [EXX]" in text
    assert result["worst"]["accuracy_um"] == pytest.approx(15.0, abs=1e-6)


@pytest.mark.parametrize(
    ("square", "extra", "words"),
    [
        ("x", "", "cal.txt:3: expected a number, found 'x'"),
        ("0", '[axes.Z.errors]\nlinear = { etalon = "cal.txt" }', "expected a [EZZ] block"),
    ],
)
def test_bad_files_one_line_exit_2(tmp_path: Path, square: str, extra: str, words: str) -> None:
    code, out = _analyse(tmp_path, square, extra)
    assert code == 2
    assert words in out
    assert len(out.strip().splitlines()) == 1, out
    assert "Traceback" not in out


@pytest.mark.slow
def test_round_trip_through_the_compensation_writer(tmp_path: Path) -> None:
    """The gantry's errors written as an Etalon file and read back as input give the same
    volumetric accuracy within the file's resolution (1 nm, 1 nrad: a few nm over the
    chain). The file holds the model's curves, not the runs: so the copy uses them as
    they are (straightness_fit = "none"); bidirectional runs are not in the file."""
    res = CliRunner().invoke(
        main, ["compensate", str(GANTRY), "--format", "etalon", "--out", str(tmp_path)]
    )
    assert res.exit_code == 0, res.output
    folder = tmp_path / "etalon"
    text = GANTRY.read_text(encoding="utf-8")
    source = '{ etalon = "etalon_exchange.txt" }'
    text = re.sub(r'"[A-Z]-[a-z]+(-[A-Z])?\.[a-z]+"', source, text)
    text = re.sub(r"^(XY|XZ|YZ) = .*$", rf"\1 = {source}", text, flags=re.M)
    text = text.replace('straightness_fit = "least-squares"', 'straightness_fit = "none"')
    (folder / "machine.toml").write_text(text, encoding="utf-8")
    runs = [
        CliRunner().invoke(main, ["analyse", str(p), "--json", "-"])
        for p in (GANTRY, folder / "machine.toml")
    ]
    assert all(r.exit_code == 0 for r in runs), [r.output for r in runs]
    before, after = (json.loads(r.output)["worst"]["accuracy_um"] for r in runs)
    assert after == pytest.approx(before, abs=0.005)
    assert (
        "etalon_exchange.txt [EXX]"
        in CliRunner().invoke(main, ["analyse", str(folder / "machine.toml")]).output
    )


def test_example_generator_reproduces_the_shipped_file() -> None:
    import importlib.util

    folder = GANTRY.parents[1] / "etalon"
    spec = importlib.util.spec_from_file_location("_make_etalon", folder / "make_data.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    assert module.text() == (folder / "calibration.txt").read_text(encoding="utf-8")
