"""Component tables: the ISG volumetric compensation CSV and esp's plain ISO 230-1 CSV,
written and read back (units mm/rad and µm/µrad, names of ISO 230-1)."""

from __future__ import annotations

from pathlib import Path

import pytest
from conftest import build_machine

import esp
from esp.compensation.build import build
from esp.compensation.formats import isg_volumetric, iso_csv
from esp.compensation.model import max_difference_um
from esp.core.errors import DataError, ParseError

GANTRY = Path(__file__).resolve().parent.parent / "data" / "examples" / "gantry" / "machine.toml"
ALL = (
    [f"{a}.linear" for a in "XYZ"]
    + [f"{a}.straightness.{b}" for a in "XYZ" for b in "XYZ" if a != b]
    + [f"{a}.angular.{b}" for a in "XYZ" for b in "XYZ"]
    + ["squareness.XY", "squareness.XZ", "squareness.YZ"]
)


def test_isg_names_of_every_component():
    assert isg_volumetric.iso_symbol("X.linear") == "EXX"
    assert isg_volumetric.iso_symbol("X.straightness.Y") == "EYX"
    assert isg_volumetric.iso_symbol("Y.angular.X") == "EAY"
    assert isg_volumetric.iso_symbol("Z.angular.Z") == "ECZ"
    assert isg_volumetric.iso_symbol("squareness.XY") == "C0Y"
    assert isg_volumetric.iso_symbol("squareness.XZ") == "B0Z"
    assert isg_volumetric.iso_symbol("squareness.YZ") == "A0Z"
    symbols = [isg_volumetric.iso_symbol(n) for n in ALL]
    assert len(set(symbols)) == 21
    assert [isg_volumetric._name_of(s) for s in symbols] == ALL  # noqa: SLF001


def small():
    return build_machine(
        {
            "X.linear": [(0.0, 0.0), (100.0, 2.0), (200.0, 5.0)],
            "X.angular.Y": 4.0,
            "squareness.XY": 3.5,
        },
        travel=(0.0, 200.0),
        step=100.0,
    )


def test_volumetric_csv_by_hand():
    text = isg_volumetric.write(build(small(), "isg-volumetric"))["volcomp.csv"]
    lines = [line for line in text.splitlines() if not line.startswith("//")]
    # position errors in rad, then the X block: position mm, EXX mm, EBX rad
    assert lines[0] == "C0Y"
    assert lines[1] == "-0.000003500"  # C0Y = EC0Y = -S_XY (ISO signs), in rad
    assert lines[2] == "#"
    assert lines[3] == "X EXX EBX"
    assert lines[5] == "100.000000 0.002000 0.000004000"


def test_iso_csv_by_hand():
    files = iso_csv.write(build(small(), "iso-csv"))
    rows = [r for r in files["X.csv"].splitlines() if not r.startswith("#")]
    assert rows[0] == "position_mm,EXX_um,EYX_um,EZX_um,EAX_urad,EBX_urad,ECX_urad"
    assert rows[2] == "100.0000,2.000,,,,4.000,"
    # in ISO 230-1 signs: EC0Y turns Y right-handed about Z, so EC0Y = -S_XY
    # (docs/conventions.md: esp's S_XY = 3.5 µm/m means an included angle below 90°)
    assert files["squareness.csv"].splitlines()[-1] == "squareness.XY,EC0Y,-3.500"


@pytest.fixture(scope="module")
def gantry():
    return esp.load_machine(GANTRY)


@pytest.mark.parametrize("fmt, module", [("isg-volumetric", isg_volumetric), ("iso-csv", iso_csv)])
def test_round_trip_of_the_gantry(gantry, fmt, module):
    tables = build(gantry, fmt)
    assert tables.uncorrected == ()
    assert len(tables.component_table.curves) == 18
    back = module.read(module.write(tables))
    assert max_difference_um(tables, back) <= 0.0005 + 1e-9
    # the sign of an error: Y's positioning error grows to some +24 µm at the far end
    assert back.component_table.curves["Y.linear"][1][-1] > 20.0


def test_record_limit_is_refused(gantry):
    tables = build(gantry, "isg-volumetric")
    assert isg_volumetric.record_count(tables) == 1 + 21 + 31 + 25
    with pytest.raises(DataError, match="max_records"):
        isg_volumetric.write(tables, max_records=50)


def test_a_mechanical_angle_cannot_be_held():
    from esp.core.machine import Tool

    # a machine compensated at the MCP, evaluated at a tilted tool: the mechanical angle acts
    tool = Tool(lengths_mm=(100.0,), orientations_deg=((45.0, 0.0),))
    m = build_machine(
        {"X.linear": 1.0, "X.mechanical.Y": 5.0}, point="TCP", compensation="MCP", tool=tool
    )
    with pytest.raises(DataError, match="cannot hold"):
        build(m, "isg-volumetric")


def test_readers_refuse_malformed_files():
    with pytest.raises(ParseError, match="volcomp.csv:2"):
        isg_volumetric.read({"volcomp.csv": "X EXX\n0 0 0\n"})
    with pytest.raises(ParseError, match="unknown ISG parameter"):
        isg_volumetric.read({"volcomp.csv": "X EQX\n0 0\n"})
    with pytest.raises(ParseError, match="X.csv"):
        iso_csv.read({"X.csv": "position,EXX\n"})
