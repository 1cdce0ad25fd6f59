"""TwinCAT CNC / ISG axis compensation lists: hand-computed tables, round trip through
the reader (unit 0.1 µm and sign included), limits."""

from __future__ import annotations

from pathlib import Path

import pytest
from conftest import build_machine

import esp
from esp.compensation.build import BuildOptions, build
from esp.compensation.formats import twincat
from esp.compensation.model import max_difference_um
from esp.core.errors import DataError, ParseError
from esp.core.profile import ErrorProfile

GANTRY = Path(__file__).resolve().parent.parent / "data" / "examples" / "gantry" / "machine.toml"


def small_machine(**analysis):
    """X.linear forward 0, 2, 5 µm, backward 1, 3, 6 µm at 0, 100, 200 mm; the
    straightness of X in Y 0, 3, 0 µm (no slope to remove)."""
    linear = ErrorProfile(
        "linear", [0.0, 100.0, 200.0], {"forward": [[0, 2, 5]], "backward": [[1, 3, 6]]}, axis="X"
    )
    straight = ErrorProfile(
        "straightness",
        [0.0, 100.0, 200.0],
        {"forward": [[0, 3, 0]]},
        axis="X",
        error_direction="Y",
    )
    return build_machine(
        {"X.linear": linear, "X.straightness.Y": straight},
        travel=(0.0, 200.0),
        step=100.0,
        straightness_fit="endpoint",
        **analysis,
    )


def entries(text: str) -> dict[str, str]:
    return dict(line.split() for line in text.splitlines() if line and not line.startswith("#"))


def test_leadscrew_list_by_hand():
    files = twincat.write(build(small_machine(), "twincat-cross"))
    x = entries(files["X.lis"])
    assert x["kopf.log_achs_name"] == "X"
    assert x["kw.ssfk.unit"] == "1"
    assert x["kw.ssfk.kw_nr_max"] == "3"
    assert x["kw.ssfk.bilateral"] == "1"
    # positions in 0.1 µm; the values are the errors (actual - setpoint) in 0.1 µm
    assert [x[f"kw.ssfk.table[{i}].setpoint"] for i in range(3)] == ["0", "1000000", "2000000"]
    assert [x[f"kw.ssfk.table[{i}].pos"] for i in range(3)] == ["0", "20", "50"]
    assert [x[f"kw.ssfk.table[{i}].neg"] for i in range(3)] == ["10", "30", "60"]


@pytest.mark.parametrize(
    "sign, expected", [("error", ["0", "30", "0"]), ("correction", ["0", "-30", "0"])]
)
def test_cross_list_by_hand(sign, expected):
    files = twincat.write(build(small_machine(), "twincat-cross"), cross_sign=sign)
    y = entries(files["Y.lis"])
    assert y["kw.crosscomp.master_ax_nr"] == "1"  # X
    assert y["kw.crosscomp.last_index"] == "2"
    assert [y[f"kw.crosscomp.table[{i}].correction"] for i in range(3)] == expected
    back = twincat.read(files, cross_sign=sign)
    cross = next(t for t in back.axis_tables if t.kind == "cross")
    assert (cross.slave, cross.master) == ("Y", "X")
    assert cross.forward_um.tolist() == [0.0, -3.0, 0.0]  # a correction is minus the error


@pytest.fixture(scope="module")
def gantry():
    return esp.load_machine(GANTRY)


@pytest.mark.slow
@pytest.mark.parametrize("fmt", ["twincat-lead", "twincat-cross", "twincat-plane"])
@pytest.mark.parametrize("sign", ["error", "correction"])
def test_round_trip_of_the_gantry(gantry, fmt, sign):
    tables = build(gantry, fmt, BuildOptions(leave_uncorrected=True))
    files = twincat.write(tables, {"X": 4, "Y": 5, "Z": 6}, cross_sign=sign)
    back = twincat.read(files, {"X": 4, "Y": 5, "Z": 6}, cross_sign=sign)
    assert back.format == fmt
    assert max_difference_um(tables, back) <= 0.05 + 1e-9  # half of 0.1 µm


def test_plane_table_is_one_grid_per_slave(gantry):
    tables = build(gantry, "twincat-plane", BuildOptions(leave_uncorrected=True))
    assert sorted(p.slave for p in tables.plane_tables) == ["X", "Y", "Z"]
    z = next(p for p in tables.plane_tables if p.slave == "Z")
    assert z.masters == ("X", "Y")
    assert z.values_um.shape == (31, 21)  # j along Y (1500/50), i along X (1000/50)
    assert set(tables.uncorrected) == {
        f"{a}.angular.{b}" for a, b in ("XX", "XY", "YX", "YY", "YZ")
    }


def test_a_plane_spacing_that_does_not_divide_the_travel_is_refused(gantry):
    with pytest.raises(DataError, match="does not divide"):
        build(
            gantry,
            "twincat-plane",
            BuildOptions(spacing_mm={"X": 70.0, "Y": 70.0, "Z": 70.0}, leave_uncorrected=True),
        )


@pytest.mark.slow
@pytest.mark.parametrize("kind, limit", [("ssfk", 20), ("crosscomp", 20), ("crosscomp2", 500)])
def test_tables_beyond_the_limits_are_refused(gantry, kind, limit):
    fmt = {"ssfk": "twincat-lead", "crosscomp": "twincat-cross", "crosscomp2": "twincat-plane"}[
        kind
    ]
    tables = build(gantry, fmt, BuildOptions(leave_uncorrected=True))
    with pytest.raises(DataError, match=kind):
        twincat.write(tables, limits={kind: limit})


def test_a_position_finer_than_0_1_um_is_refused(gantry):
    tables = build(
        gantry, "twincat-lead", BuildOptions(spacing_mm={"X": 33.33333333}, leave_uncorrected=True)
    )
    with pytest.raises(DataError, match="0.1 µm"):
        twincat.write(tables)


def test_reader_refuses_malformed_lists():
    with pytest.raises(ParseError, match="X.lis:2"):
        twincat.read({"X.lis": "kopf.achs_nr 1\nnot a pair here\n"})
    with pytest.raises(ParseError, match="missing kw.ssfk.table"):
        twincat.read(
            {"X.lis": "kopf.achs_nr 1\nkw.ssfk.unit 1\nkw.ssfk.interval 0\nkw.ssfk.kw_nr_max 2\n"}
        )
