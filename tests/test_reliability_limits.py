"""Work bounded up front (docs/reliability.md, "The other commands"): a diagonal, a
compensation table, a table file or a head map beyond its limit is refused with the number,
the limit and the option or key, before any memory is taken."""

from __future__ import annotations

import re
import time
import tracemalloc
from pathlib import Path

import pytest
from click.testing import CliRunner
from conftest import build_machine

from esp.cli import main
from esp.compensation.build import BuildOptions, build, table_positions
from esp.core import limits
from esp.core.errors import ConfigError, DataError
from esp.core.limits import refuse_if
from esp.diagonals.model import Diagonal, diagonal_targets

ROOT = Path(__file__).parent.parent
HEAD = str(ROOT / "data" / "examples" / "heads" / "angle-head-fig3.toml")


def refused(call, error=DataError):
    """The error of ``call()``, checked to come fast and without a large allocation."""
    tracemalloc.start()
    start = time.perf_counter()
    try:
        with pytest.raises(error) as info:
            call()
    finally:
        _, peak = tracemalloc.get_traced_memory()
        tracemalloc.stop()
    assert time.perf_counter() - start < 2.0
    assert peak < 50e6, f"{peak / 1e6:.0f} MB taken before refusing"
    return info.value


def test_refuse_if_names_the_key_the_number_and_the_limit():
    refuse_if(10, 10, "--step", "targets", "use a larger --step")  # at the limit: accepted
    with pytest.raises(DataError, match=r"^--step: targets = 11, above the limit of 10: use"):
        refuse_if(11, 10, "--step", "targets", "use a larger --step")
    with pytest.raises(ConfigError) as info:
        refuse_if(2.5e12, 1e5, "map", "settings", "use larger steps", config=True)
    assert info.value.key == "map" and "settings = 2.5e+12, above the limit of 100000" in str(
        info.value
    )
    with pytest.raises(DataError, match="more than 1e"):
        refuse_if(float("inf"), 1e5, "--step", "targets", "use a larger --step")


# -- esp diagonals ---------------------------------------------------------------------------

PPP = Diagonal("PPP", (0.0, 0.0, 0.0), (1000.0, 1500.0, 600.0))  # 1900 mm long


def test_a_diagonal_in_steps_of_a_nanometre():
    # by hand: 1900 / 1e-9 = 1.9e12 targets; it used to take 13.8 TiB
    err = refused(lambda: diagonal_targets(PPP, 1e-9))
    assert str(err) == (
        "--step: the PPP diagonal of 1900 mm in steps of 1e-09 mm: targets = 1.9e+12, "
        "above the limit of 100000: use a larger --step"
    )
    refused(lambda: diagonal_targets(PPP, 1e-320))  # the ratio overflows


def test_a_diagonal_at_the_limit():
    # 1900 / 0.019 = 100 000 steps = 100 001 targets: one too many; 0.0190001 is accepted
    with pytest.raises(DataError, match="targets = 100001"):
        diagonal_targets(PPP, 0.019)
    # 1900 / 0.0190002 = 99 998.9: 0 to 99 998 steps and the end, 100 000 targets
    assert diagonal_targets(PPP, 0.0190002).size == limits.DIAGONAL_MAX_TARGETS
    with pytest.raises(DataError, match="targets = 100001"):  # 99 999 steps and the end
        diagonal_targets(PPP, 0.01900001)


@pytest.mark.slow
def test_diagonals_command_refuses_in_one_line():
    machine = str(ROOT / "data" / "examples" / "gantry" / "machine.toml")
    # a step below the smallest esp takes (1 µm) is refused by the value check first
    res = CliRunner().invoke(main, ["diagonals", machine, "--step", "1e-9"])
    assert res.exit_code == 2 and res.stderr.count("\n") == 1
    assert "--step" in res.stderr and "'1e-9'" in res.stderr
    # by hand: 1900 mm / 0.001 mm = 1.9e6 targets, above the limit of 1e5
    res = CliRunner().invoke(main, ["diagonals", machine, "--step", "0.001"])
    assert res.exit_code == 2 and res.stderr.count("\n") == 1
    assert res.stderr.startswith("esp: error: --step: the PPP diagonal of 1900 mm")


# -- esp compensate --------------------------------------------------------------------------


def machine():
    return build_machine(
        {"X.linear": [(0.0, 0.0), (500.0, 2.0), (1000.0, 5.0)], "squareness.XY": 3.5},
        travel=(0.0, 1000.0),
        step=250.0,
    )


def test_a_table_every_nanometre():
    # by hand: 1000 / 1e-9 + 1 = 1e12 + 1 points (13.8 TiB of positions)
    err = refused(lambda: table_positions(machine(), "X", 1e-9))
    assert "--spacing: a table along X over its travel of 1000 mm every 1e-09 mm" in str(err)
    assert "points = 1e+12, above the limit of 100000" in str(err)
    err = refused(lambda: build(machine(), "iso-csv", BuildOptions(spacing_mm={"X": 0.001})))
    assert "points = 1000001" in str(err)


def test_the_axis_step_is_named_when_it_sets_the_spacing():
    m = build_machine({"X.linear": [(0.0, 0.0), (1000.0, 5.0)]}, step=0.001)
    with pytest.raises(DataError) as info:
        build(m, "iso-csv")
    assert str(info.value).startswith("axes.X.step: a table along X")


def test_a_plane_table_is_counted_before_it_is_made():
    # 1000 / 0.5 + 1 = 2001 points a side, 2001 x 2001 = 4004001 > 10^6
    m = build_machine({"X.straightness.Y": [(0.0, 0.0), (500.0, 2.0), (1000.0, 0.0)]})
    options = BuildOptions(spacing_mm={"X": 0.5, "Y": 0.5, "Z": 0.5}, leave_uncorrected=True)
    err = refused(lambda: build(m, "twincat-plane", options))
    assert "2001 x 2001 points = 4004001, above the limit of 1000000" in str(err)


def test_a_table_file_above_its_size_limit(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    path = tmp_path / "machine.toml"
    path.write_text(
        (ROOT / "tests" / "data" / "config" / "minimal.toml").read_text(encoding="utf-8")
        + "\n[axes.X.errors]\nlinear = { points = [[0, 0], [500, 3.0]] }\n",
        encoding="utf-8",
    )
    args = ["compensate", str(path), "--format", "iso-csv", "--spacing", "0.1", "--out", "c"]
    # X.csv holds 5001 rows of about 25 bytes: some 0.12 MiB
    res = CliRunner().invoke(main, [*args, "--max-file-mb", "0.05"])
    assert res.exit_code == 2 and res.stderr.count("\n") == 1
    m = re.match(
        r"esp: error: --format iso-csv: the file iso-csv/X\.csv of [0-9.]+ MiB: bytes = (\d+), "
        r"above the limit of 52428: use a larger --spacing, or allow larger files with "
        r"--max-file-mb \(now 0\.05\)$",
        res.stderr,
    )
    assert m, res.stderr
    assert not (tmp_path / "c").exists()  # refused before anything was written
    ok = CliRunner().invoke(main, [*args, "--max-file-mb", "1", "-q"])
    assert ok.exit_code == 0, ok.stderr
    assert (tmp_path / "c" / "iso-csv" / "X.csv").stat().st_size == int(m.group(1))


def test_the_default_file_limit_is_documented():
    assert limits.COMPENSATION_MAX_FILE_BYTES == 4 * 2**20
    res = CliRunner().invoke(main, ["compensate", "--help"])
    assert "--max-file-mb" in res.stdout and "[default: 4.0]" in res.stdout


# -- esp head --------------------------------------------------------------------------------


def test_a_head_map_beyond_its_limit():
    # 501 x 501 = 251 001 settings, one 1 001 above the limit (4e6 took 5.2 GB and 110 s)
    start = time.perf_counter()
    res = CliRunner().invoke(main, ["head", HEAD, "--grid", "A=-60:60:0.24,C=-60:60:0.24"])
    assert time.perf_counter() - start < 5.0
    assert res.exit_code == 2 and res.stderr == (
        "esp: error: --grid: a map of 501 (A) x 501 (C) settings = 251001, above the limit "
        "of 250000: use larger steps in --grid\n"
    )


def test_a_head_map_from_the_file_names_its_table():
    from esp.heads.config import read_head_file
    from esp.heads.maps import GridSpec, error_map

    head = read_head_file(HEAD).head
    grid = [GridSpec("A", -60, 60, 0.24), GridSpec("C", -60, 60, 0.24)]
    err = refused(lambda: error_map(head, grid), ConfigError)
    assert err.key == "map" and "settings = 251001" in str(err)


# -- the documentation -----------------------------------------------------------------------


def test_every_limit_is_documented():
    doc = (ROOT / "docs" / "reliability.md").read_text(encoding="utf-8")
    table = doc.split("### The other commands")[1].split("Why these values")[0]
    for text in ("10⁵ (100 000)", "10⁶ (1 000 000)", "4 MiB", "250 000", "1 000", "64 MiB"):
        assert text in table
    assert limits.DIAGONAL_MAX_TARGETS == limits.COMPENSATION_MAX_TABLE_POINTS == 100_000
    assert limits.COMPENSATION_MAX_PLANE_POINTS == 1_000_000
    assert limits.HEAD_MAP_MAX_SETTINGS == 250_000
    from esp.io.laser10 import MAX_LINES, MAX_SECTION_LINES

    assert (MAX_LINES, MAX_SECTION_LINES) == (1_000_000, 1000)
    assert set(limits.LIMITS) == {n for n in limits.__all__ if n.isupper() and n != "LIMITS"}
