"""The plan benchmarks/identify.py times is one esp can identify: the ball plate of 25
balls in 4 poses probed with a star probe of four styli (not in one plane) sees every
coefficient of all 21 components at degree 5 and the styli's orientation; with three
styli (always in one plane) one combination of that orientation with the angles and the
linear error of Z is all but unseen (docs/identify.md, "Speed")."""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

import numpy as np
import pytest

from esp.identify.run import plan

ROOT = Path(__file__).resolve().parent.parent


@pytest.fixture(scope="module")
def bench():
    spec = importlib.util.spec_from_file_location(
        "esp_benchmark_identify", ROOT / "benchmarks" / "identify.py"
    )
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    folder = str(ROOT / "benchmarks")
    sys.path.insert(0, folder)  # its helper module, as `python benchmarks/identify.py` finds it
    try:
        spec.loader.exec_module(module)
    finally:
        sys.path.remove(folder)
    return module


def _identifiability(bench, tmp_path: Path, styli):
    old = bench.TOOLS
    bench.TOOLS = styli
    try:
        problem = bench.plate_problem(tmp_path, np.random.default_rng(7))
    finally:
        bench.TOOLS = old
    return plan(problem).identifiability


def test_four_styli_see_every_component_and_their_orientation(bench, tmp_path):
    ident = _identifiability(bench, tmp_path, bench.TOOLS)
    assert len(bench.TOOLS) == 4
    assert ident.identifiable
    assert ident.rank == ident.parameters == 114  # 108 coefficients, 3 squareness, 3 of ω
    assert ident.condition < 1e4


def test_three_styli_leave_one_combination_with_the_styli_orientation(bench, tmp_path):
    ident = _identifiability(bench, tmp_path, bench.TOOLS[:3])
    assert ident.rank == ident.parameters - 1
    sv = np.asarray(ident.singular_values)
    assert sv[-1] / sv[0] < 1e-6 < sv[-2] / sv[0]  # one direction, far below the next
    (combo,) = ident.combinations
    heaviest = {name for name, _ in sorted(combo, key=lambda kv: -abs(kv[1]))[:4]}
    assert heaviest == {"plate.tool.rx", "plate.tool.ry", "Z.angular.X[P2]", "Z.angular.Y[P2]"}
