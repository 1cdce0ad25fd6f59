"""LinuxCNC compensation files: hand-computed tables, round trip through the reader,
limits."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner
from conftest import build_machine

import esp
from esp.cli import main
from esp.compensation.build import BuildOptions, build
from esp.compensation.formats import linuxcnc
from esp.compensation.model import max_difference_um
from esp.core.errors import DataError, ParseError
from esp.core.profile import ErrorProfile

GANTRY = Path(__file__).resolve().parent.parent / "data" / "examples" / "gantry" / "machine.toml"


def small_machine():
    """X.linear measured at 0, 100, 200 mm: forward 0, 2, 5 µm; backward 1, 3, 6 µm."""
    profile = ErrorProfile(
        "linear", [0.0, 100.0, 200.0], {"forward": [[0, 2, 5]], "backward": [[1, 3, 6]]}, axis="X"
    )
    return build_machine({"X.linear": profile}, travel=(0.0, 200.0), step=100.0)


def test_type_1_holds_the_trims_by_hand():
    files = linuxcnc.write(build(small_machine(), "linuxcnc"), comp_type=1, units="mm")
    # trim = nominal - actual = -error, in mm
    assert files["X.comp"] == (
        "0.000000 0.000000 -0.001000\n"
        "100.000000 -0.002000 -0.003000\n"
        "200.000000 -0.005000 -0.006000\n"
    )
    assert set(files) == {"X.comp", "README.txt"}


def test_type_0_holds_the_actual_positions_by_hand():
    files = linuxcnc.write(build(small_machine(), "linuxcnc"), comp_type=0, units="mm")
    assert files["X.comp"].splitlines()[1] == "100.000000 100.002000 100.003000"


def test_inch_units_by_hand():
    files = linuxcnc.write(build(small_machine(), "linuxcnc"), comp_type=1, units="inch")
    # 100 mm = 3.9370079 in; -2 µm = -0.0000787 in
    assert files["X.comp"].splitlines()[1] == "3.9370079 -0.0000787 -0.0001181"


@pytest.fixture(scope="module")
def gantry_tables():
    return build(esp.load_machine(GANTRY), "linuxcnc", BuildOptions(leave_uncorrected=True))


@pytest.mark.parametrize("comp_type", [0, 1])
@pytest.mark.parametrize("units", ["mm", "inch"])
def test_round_trip_of_the_gantry(gantry_tables, comp_type, units):
    files = linuxcnc.write(gantry_tables, comp_type, units)
    back = linuxcnc.read(files, comp_type, units)
    resolution = linuxcnc.UNITS[units][0] * 10.0 ** -linuxcnc.UNITS[units][1]
    assert max_difference_um(gantry_tables, back) <= 0.5 * resolution + 1e-9
    # sign: the trim at the far end of Y is minus the Y positioning error there
    y = next(t for t in back.axis_tables if t.slave == "Y")
    assert y.forward_um[-1] < -15.0


def test_the_gantry_linear_errors_are_the_only_components_held(gantry_tables):
    assert gantry_tables.corrected == ("X.linear", "Y.linear", "Z.linear")
    assert "squareness.XY" in gantry_tables.uncorrected


def test_more_than_256_points_is_refused(gantry_tables):
    many = build(
        esp.load_machine(GANTRY),
        "linuxcnc",
        BuildOptions(spacing_mm={"Y": 5.0}, leave_uncorrected=True),
    )
    with pytest.raises(DataError, match="at most 256"):
        linuxcnc.write(many)


def test_reader_refuses_a_line_that_is_not_three_numbers():
    with pytest.raises(ParseError, match="X.comp:2"):
        linuxcnc.read({"X.comp": "0 0 0\n100 0.001\n200 0 0\n"})
    with pytest.raises(ParseError, match="increase"):
        linuxcnc.read({"X.comp": "0 0 0\n0 0 0\n"})


def run(*args):
    return CliRunner().invoke(main, [str(a) for a in args])


def assert_one_line_failure(result, *fragments):
    assert result.exit_code == 2, result.output
    assert result.stderr.startswith("esp: error: ")
    assert result.stderr.count("\n") == 1
    assert "Traceback" not in result.output
    for f in fragments:
        assert f in result.stderr


def test_cli_refuses_a_component_the_format_cannot_hold():
    assert_one_line_failure(
        run("compensate", GANTRY, "--format", "linuxcnc"), "cannot hold", "--leave-uncorrected"
    )


def test_cli_refuses_a_table_beyond_the_limit(tmp_path):
    assert_one_line_failure(
        run(
            "compensate",
            GANTRY,
            "--format",
            "linuxcnc",
            "--leave-uncorrected",
            "--spacing",
            "Y=5",
            "--out",
            tmp_path / "c",
        ),
        "256",
    )
    assert not (tmp_path / "c").exists()


def test_cli_writes_the_files_of_the_reader(tmp_path):
    out = tmp_path / "comp"
    result = run(
        "compensate",
        GANTRY,
        "--format",
        "linuxcnc",
        "--leave-uncorrected",
        "--linuxcnc-type",
        "0",
        "--out",
        out,
        "-q",
    )
    assert result.exit_code == 0, result.output
    files = {p.name: p.read_text() for p in (out / "linuxcnc").iterdir()}
    back = linuxcnc.read(files, 0, "mm")
    tables = build(esp.load_machine(GANTRY), "linuxcnc", BuildOptions(leave_uncorrected=True))
    assert max_difference_um(tables, replace(back)) <= 0.0005 + 1e-9
    assert np.all([t.bilateral for t in back.axis_tables])
