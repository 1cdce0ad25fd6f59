"""Angular positioning tables of a rotary table's axes (esp compensate): a modulo table
of C over one turn and a table of A over its travel, written as SINUMERIK LEC (degrees,
``$AA_ENC_COMP_IS_MODULO``), read back, refused where they cannot be."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from esp.cli import main
from esp.compensation.build import BuildOptions, rotary_tables
from esp.compensation.formats import FormatSettings, get
from esp.compensation.workflow import compensate
from esp.config import machine_from_dict
from esp.core.errors import DataError

ROOT = Path(__file__).resolve().parent.parent
TRUNNION = (ROOT / "data/examples/rotary/trunnion.toml").as_posix()


def _machine(table: str = TRUNNION):
    return machine_from_dict(
        {
            "machine": {
                "name": "trunnion",
                "configuration": "BwMTt",
                "axes": {"bottom": "X", "middle": "Y", "top": "Z"},
            },
            "table": {"file": table, "angles": {"A": [-90, 0, 90], "C": [0, 180]}},
            "axes": {a: {"travel": [0, 500], "step": 100} for a in "XYZ"},
        },
        ROOT,
    )


def test_the_tables_are_minus_the_positioning_errors():
    """C: ECC is a periodic curve (arcsec in the file): a modulo table 0..360° every 5°,
    each value minus ECC at that angle in µrad, the last equal to the first; A: EAA over
    its travel -120..120°, ends held."""
    machine = _machine()
    table = machine.table.table
    found = {t.axis: t for t in rotary_tables(machine, BuildOptions())}
    c, a = found["C"], found["A"]
    assert c.modulo and c.positions_deg[0] == 0.0 and c.positions_deg[-1] == 360.0
    assert c.positions_deg.size == 73 and c.error == "table.ECC"
    expected = -table.curves["ECC"].at(c.positions_deg[:-1]) * (
        table.chain.symbols["ECC"].scale / 1e-6
    )
    np.testing.assert_allclose(c.correction_urad[:-1], expected, rtol=1e-12)
    assert c.correction_urad[-1] == c.correction_urad[0]
    assert not a.modulo and (a.positions_deg[0], a.positions_deg[-1]) == (-120.0, 120.0)
    # between points a modulo table wraps: 362.5° is 2.5°
    assert c.correction_at(362.5) == pytest.approx(c.correction_at(2.5))


def test_sinumerik_modulo_lec_by_hand_and_read_back():
    """A constant ECC of 10 µrad: every LEC value of C is the error in degrees,
    10e-6 · 180/π = 0.000573°, from 0 to 360° every 30°, modulo; the file reads back to
    the same table."""
    machine = _machine()
    table = machine.table.table.with_values({"ECC": 10.0, "EAA": 0.0})
    machine = replace(machine, table=replace(machine.table, table=table))
    done = compensate(machine, ["siemens-lec"], BuildOptions(spacing_mm={"C": 30.0}))
    files = done["siemens-lec"].files
    text = files["AX_EEC.INI"]
    lines = [line for line in text.splitlines() if "AX4" in line]
    assert "$AA_ENC_COMP[0,0,AX4]=0.000573" in lines
    assert "$AA_ENC_COMP[0,12,AX4]=0.000573" in lines
    assert "$AA_ENC_COMP_STEP[0,AX4]=30.000000" in lines
    assert "$AA_ENC_COMP_MIN[0,AX4]=0.000000" in lines
    assert "$AA_ENC_COMP_MAX[0,AX4]=360.000000" in lines
    assert "$AA_ENC_COMP_IS_MODULO[0,AX4]=1" in lines
    assert not any("AX5" in line for line in text.splitlines())  # EAA is zero: no table
    settings = FormatSettings(axis_numbers={"X": 1, "Y": 2, "Z": 3, "C": 4, "A": 5})
    back = get("siemens-lec").read(files, settings)
    (rot,) = back.rotary_tables
    assert rot.axis == "C" and rot.modulo
    np.testing.assert_allclose(rot.correction_urad, -10.0, atol=0.01)  # 1e-6° is 0.017 µrad


def test_spacing_and_formats_are_checked(tmp_path):
    machine = _machine()
    with pytest.raises(DataError, match=r"--spacing C=7: a table of C runs from 0 to 360"):
        compensate(machine, ["siemens-lec"], BuildOptions(spacing_mm={"C": 7.0}))
    with pytest.raises(DataError, match=r"--spacing B: the machine has no axis B"):
        compensate(machine, ["siemens-lec"], BuildOptions(spacing_mm={"B": 5.0}))
    done = compensate(machine, ["linuxcnc"], BuildOptions())
    notes = " ".join(done["linuxcnc"].result.tables.notes)
    assert "angular positioning errors (table.ECC, table.EAA) are not in this format" in notes


def test_the_cli_writes_the_rotary_tables(tmp_path):
    path = tmp_path / "machine.toml"
    path.write_text(
        '[machine]\nname = "t"\nconfiguration = "BwMTt"\n'
        'axes = { bottom = "X", middle = "Y", top = "Z" }\n'
        f'[table]\nfile = "{TRUNNION}"\nangles = {{ A = [-90, 0, 90], C = [0, 180] }}\n'
        + "".join(f"[axes.{a}]\ntravel = [0, 500]\nstep = 100\n" for a in "XYZ"),
        encoding="utf-8",
    )
    r = CliRunner().invoke(
        main,
        [
            "compensate",
            str(path),
            "--format",
            "siemens-lec",
            "--spacing",
            "C=10,A=20",
            "--axis-numbers",
            "C=6",
            "--out",
            str(tmp_path / "out"),
        ],
    )
    assert r.exit_code == 0, r.output
    assert "rotary C: 37 points 0 to 360° (modulo, every turn)" in r.output
    assert "rotary A: 13 points -120 to 120° (ends held)" in r.output
    text = (tmp_path / "out" / "siemens-lec" / "AX_EEC.INI").read_text(encoding="utf-8")
    assert "$AA_ENC_COMP_IS_MODULO[0,AX6]=1" in text  # C numbered by the user
    assert "$AA_ENC_COMP_IS_MODULO[0,AX7]=0" in text  # A: the next free number


def test_fanuc_rotation_axis_by_hand_and_read_back():
    """The 0i-PB parameter manual's rotation axis: 45° intervals, the reference position
    its own farthest - side (3621 = 3620), the farthest + side 3620 + 360/45, the values
    of one rotation adding up to zero and the reference taking the last one's value. A
    correction of 3, 5, 4, 1, -2, -4, -1, 2, 3 thousandths of a degree at 0..360° (IS-B:
    0.001° units) is written as the increments 2, -1, -3, -3, -2, 3, 3, 1 after the
    reference's 1, and reads back less its value at 0° (held by the reference position)."""
    from esp.compensation.model import CompensationSet, RotaryTable

    positions = np.arange(0.0, 361.0, 45.0)
    correction_deg = np.array([3, 5, 4, 1, -2, -4, -1, 2, 3]) / 1000.0
    table = RotaryTable("C", positions, correction_deg * np.pi / 180.0 * 1e6, True)
    settings = FormatSettings(axis_numbers={"X": 1, "Y": 2, "Z": 3, "C": 4})
    files = get("fanuc").write(CompensationSet("fanuc", rotary_tables=(table,)), settings)
    data = [line for line in files["PITCH.TXT"].splitlines() if line.startswith("N")]
    assert [int(line.split("P")[1]) for line in data] == [1, 2, -1, -3, -3, -2, 3, 3, 1]
    params = files["PARAM.TXT"].splitlines()
    for line in ("N3620A4P0", "N3621A4P0", "N3622A4P8", "N3624A4P45000", "N3625A4P360000"):
        assert line in params
    (back,) = get("fanuc").read(files, settings).rotary_tables
    assert back.modulo
    np.testing.assert_allclose(
        back.correction_urad * 1e-6 * 180.0 / np.pi, correction_deg - correction_deg[0], atol=1e-12
    )
