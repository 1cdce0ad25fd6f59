"""Bounded resources: a grid, a sweep or a list of tool lengths beyond the documented
limits is refused when the configuration is read, with the numbers and the key to change,
before any memory is taken (docs/reliability.md, "Resource limits")."""

from __future__ import annotations

import copy
import time
import tomllib
import tracemalloc
from pathlib import Path

import pytest
from click.testing import CliRunner

from esp.cli import main
from esp.config import machine_from_dict
from esp.config.machine import (
    MAX_GRID_POINTS,
    MAX_PLANE_POINTS,
    MAX_TOOL_CASES,
    MAX_WORK_POINTS,
    grid_count,
)
from esp.core.errors import ConfigError
from esp.core.machine import Axis

DATA = Path(__file__).parent / "data" / "config"


def machine(travel_mm=(500, 400, 0), steps_mm=(100, 100, None), tool=None) -> dict:
    with open(DATA / "minimal.toml", "rb") as f:
        data = tomllib.load(f)
    for axis, travel, step in zip("XYZ", travel_mm, steps_mm, strict=True):
        data["axes"][axis] = {"travel": [0, travel]}
        if step is not None:
            data["axes"][axis]["step"] = step
    if tool is not None:
        data["analysis"] = {"point": "TCP"}
        data["tool"] = tool
    return data


def refused(data: dict) -> ConfigError:
    """The ConfigError of ``data``, checked to come fast and without a large allocation."""
    tracemalloc.start()
    start = time.perf_counter()
    try:
        with pytest.raises(ConfigError) as info:
            machine_from_dict(copy.deepcopy(data), DATA, source="machine.toml")
    finally:
        _, peak = tracemalloc.get_traced_memory()
        tracemalloc.stop()
    assert time.perf_counter() - start < 5.0
    assert peak < 200e6, f"{peak / 1e6:.0f} MB taken before refusing"
    return info.value


def test_limits_are_as_documented():
    assert MAX_GRID_POINTS == 2_000_000_000 and MAX_PLANE_POINTS == 10_000_000
    assert MAX_TOOL_CASES == 10_000 and MAX_WORK_POINTS == 10_000_000_000
    doc = (Path(__file__).parent.parent / "docs" / "reliability.md").read_text(encoding="utf-8")
    for text in ("2·10⁹", "10⁷", "10 000", "10¹⁰", "axes.X.step", "tool.sweep"):
        assert text in doc


def test_grid_of_10_to_the_12_points():
    err = refused(machine((10_000, 10_000, 10_000), (1, 1, 1)))
    assert err.key == "axes.X.step"
    assert "10001 (X) x 10001 (Y) x 10001 (Z) = 1e+12 points" in err.message
    assert "above the limit of 2e+09 points per tool case" in err.message
    assert "increase axes.X.step or axes.Y.step" in err.message


def test_a_long_thin_grid_is_limited_by_its_planes():
    # 2 001 x 5 001 x 1 = 1e7 points, but the XY plane alone holds 1e7 + 7 002 points
    err = refused(machine((2000, 5000, 0), (1, 1, None)))
    assert err.key == "axes.Y.step" and "three coordinate planes" in err.message
    assert "above the limit of 1e+07" in err.message and "GB of memory" in err.message


def test_a_step_of_one_micrometre_on_100_m():
    err = refused(machine((100_000, 400, 0), (0.001, 100, None)))
    assert err.key == "axes.X.step" and "100000001 (X)" in err.message


def test_largest_cube_is_accepted():
    # 1 261³ = 2.005e9 > 2e9 is refused; 1 260³ = 2.0004e9 too; 1 259³ = 1.996e9 passes
    refused(machine((1260, 1260, 1260), (1, 1, 1)))
    m = machine_from_dict(machine((1258, 1258, 1258), (1, 1, 1)), DATA)
    assert [grid_count(m.axes[a]) for a in "XYZ"] == [1259] * 3


@pytest.mark.slow
def test_sweep_of_2000_x_2000_orientations():
    tilts = [i * 0.01 for i in range(2000)]
    spins = [i * 0.1 for i in range(2000)]
    tool = {"lengths": [0], "orientation": "sweep", "sweep": {"tilt": tilts, "spin": spins}}
    err = refused(machine(tool=tool))
    assert err.key == "tool.sweep.tilt"
    assert "4000000 orientations (2000 tilt x 2000 spin)" in err.message
    assert "above the limit of 10000" in err.message


def test_100000_tool_lengths():
    tool = {"lengths": list(range(100_000)), "orientation": {"tilt": 0, "spin": 0}}
    err = refused(machine(tool=tool))
    assert err.key == "tool.lengths" and "at most 10000 tool lengths, found 100000" in err.message
    # 1 000 lengths in the default sweep of 12 orientations: 12 000 tool cases
    err = refused(machine(tool={"lengths": list(range(1000)), "orientation": "sweep"}))
    assert err.key == "tool.lengths" and "= 12000 tool cases" in err.message


def test_total_work_over_the_tool_cases():
    # 1 001 x 1 001 x 1 001 ≈ 1e9 points per case, x 12 orientations ≈ 1.2e10 > 1e10
    err = refused(machine((1000, 1000, 1000), (1, 1, 1), {"lengths": [0], "orientation": "sweep"}))
    assert err.key == "tool" and "12 tool cases x 1e+09 grid points" in err.message
    assert "use fewer tool lengths or orientations, or increase axes.X.step" in err.message


@pytest.mark.parametrize(
    ("simulate", "step"),
    [((0, 500), 100), ((0, 500), 30), ((-3.5, 7.25), 0.5), ((0, 1), 0.001), ((2, 2), 0.0)],
)
def test_grid_count_is_the_size_of_the_grid(simulate, step):
    axis = Axis("X", "bottom", simulate, simulate, step)
    assert grid_count(axis) == axis.grid_mm().size


def test_command_refuses_in_one_line(tmp_path):
    toml = (DATA / "minimal.toml").read_text(encoding="utf-8")
    path = tmp_path / "machine.toml"
    path.write_text(toml.replace("step = 100", "step = 0.001"), encoding="utf-8")
    res = CliRunner().invoke(main, ["analyse", str(path), "--at", "X=1,Y=1,Z=0"])
    assert res.exit_code == 2 and res.stderr.count("\n") == 1
    assert res.stderr.startswith(f"esp: error: {path}: axes.X.step: a grid of 500001 (X)")
