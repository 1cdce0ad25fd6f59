"""The angle table of a home-made ballbar (esp.ballbar.angles) and the test conditions of
a file's header (esp.ballbar.conditions): tolerant of how such tables are written, and
refusing a row that cannot be read at its file and line."""

from __future__ import annotations

import numpy as np
import pytest
from click.testing import CliRunner

from esp.ballbar import circle_tests, read_circles
from esp.cli import main
from esp.core.errors import ParseError

ANGLES = np.arange(0.0, 360.0, 10.0)


def _dev(t: np.ndarray) -> np.ndarray:
    """A 2 µm ellipse along the axes (a scale mismatch of 2·2/0.1 = 40 µm/m on R 100)."""
    return 2.0 * np.cos(2 * np.radians(t))


def _write(tmp_path, lines, name="bar.csv"):
    path = tmp_path / name
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return path


def test_a_plain_table_with_radius_line(tmp_path):
    rows = [f"{t:g},{d:.6f}" for t, d in zip(ANGLES, _dev(ANGLES), strict=True)]
    path = _write(tmp_path, ["# radius: 100 mm", "angle,deviation", *rows])
    (c,) = read_circles(path)
    assert c.radius_mm == 100.0 and c.plane == "XY"
    assert [r.direction for r in c.runs] == ["ccw"]
    np.testing.assert_allclose(c.runs[0].deviation_um, _dev(ANGLES), atol=1e-6)
    (t,) = circle_tests(path)
    assert t.diagnosis.term("scale_mismatch").value == pytest.approx(40.0, abs=1e-3)


def test_semicolons_decimal_commas_units_in_brackets_and_nm(tmp_path):
    """A spreadsheet's export: semicolons, decimal commas, the unit in the header."""
    rows = [
        f"{t:g};{d * 1000:.3f}".replace(".", ",") for t, d in zip(ANGLES, _dev(ANGLES), strict=True)
    ]
    path = _write(
        tmp_path, ["# Radius = 100", "Angle (deg);Deviation [nm];note", *[r + ";x" for r in rows]]
    )
    (c,) = read_circles(path)
    np.testing.assert_allclose(c.runs[0].deviation_um, _dev(ANGLES), atol=1e-6)


def test_a_unit_line_and_whitespace_columns(tmp_path):
    rows = [f"{t:g}\t{d / 1000:.9f}" for t, d in zip(ANGLES, _dev(ANGLES), strict=True)]
    path = _write(tmp_path, ["# unit: mm", "angle\tdeviation", *rows])
    (c,) = read_circles(path, radius_mm=100.0)
    np.testing.assert_allclose(c.runs[0].deviation_um, _dev(ANGLES), atol=1e-6)


def test_two_runs_without_a_direction_column_split_where_the_angles_turn(tmp_path):
    ccw = [f"{t:g},{d:.6f}" for t, d in zip(ANGLES, _dev(ANGLES), strict=True)]
    back = ANGLES[::-1]
    cw = [f"{t:g},{d + 0.5:.6f}" for t, d in zip(back, _dev(back), strict=True)]
    path = _write(tmp_path, ["# radius: 100", "angle,deviation", *ccw, *cw])
    (c,) = circle_tests(path)
    assert [r.direction for r in c.circle.runs] == ["ccw", "cw"]
    assert c.H_um == pytest.approx(0.5, abs=1e-6)


def test_the_direction_column_and_its_words(tmp_path):
    rows = [f"{t:g},{d:.4f},anticlockwise" for t, d in zip(ANGLES, _dev(ANGLES), strict=True)]
    rows += [f"{t:g},{d:.4f},Clockwise" for t, d in zip(ANGLES, _dev(ANGLES), strict=True)]
    path = _write(tmp_path, ["# radius: 100", "angle,deviation_um,direction", *rows])
    (c,) = read_circles(path)
    assert [r.direction for r in c.runs] == ["ccw", "cw"]


GOOD = [f"{t:g},{d:.4f}" for t, d in zip(ANGLES, _dev(ANGLES), strict=True)]
BAD = {
    "a word for a number": (
        ["# radius: 100", "angle,deviation", *GOOD[:3], "40,abc", *GOOD[4:]],
        ":6: column deviation: expected a number, found 'abc'",
    ),
    "a missing cell": (
        ["# radius: 100", "angle,deviation", *GOOD[:5], "50", *GOOD[6:]],
        ":8: expected at least 2 values as in the header, found 1",
    ),
    "an angle given twice": (
        ["# radius: 100", "angle,deviation", *GOOD, "370,0"],
        ":39: expected each angle once in the ccw run, found 10 deg again (also on line 4)",
    ),
    "a deviation of 2 m": (
        ["# radius: 100", "# unit: mm", "angle,deviation", *GOOD[:2], "20,2000", *GOOD[3:]],
        ":6: column deviation: expected a deviation within ±10000 um, found 2000 mm",
    ),
    "no radius": (
        ["angle,deviation", *GOOD],
        ": expected the radius of the circle: a '# radius: R mm' line or --radius",
    ),
    "a bad radius line": (
        ["# radius: ten", "angle,deviation", *GOOD],
        ":1: '# radius:' expected a number in mm, found 'ten'",
    ),
    "a bad feed unit": (
        ["# radius: 100", "# feed: 1000 in/min", "angle,deviation", *GOOD],
        ":2: '# feed:' expected a number in mm/min",
    ),
    "an unknown unit": (
        ["# radius: 100", "# unit: furlong", "angle,deviation", *GOOD],
        ":2: '# unit:': expected a unit of um, nm or mm, found 'furlong'",
    ),
    "an unknown direction": (
        ["# radius: 100", "angle,deviation,direction", *[g + ",ccw" for g in GOOD[:4]], "40,0,up"],
        ":7: column direction: expected ccw or cw, found 'up'",
    ),
    "a third turn": (
        ["# radius: 100", "angle,deviation", "0,0", "10,0", "20,0", "10,0", "0,0", "10,0"],
        ":8: expected the angles to run one way in each run",
    ),
    "too few readings": (
        ["# radius: 100", "angle,deviation", *GOOD[:5]],
        ":3: the ccw run has 5 readings; expected 8 or more",
    ),
}


@pytest.mark.parametrize("case", BAD)
def test_a_bad_row_is_refused_at_its_file_and_line(tmp_path, case):
    lines, where = BAD[case]
    path = _write(tmp_path, lines)
    with pytest.raises(ParseError) as info:
        read_circles(path)
    assert str(info.value).startswith(f"{path}{where}"), str(info.value)


def test_through_the_cli_a_bad_row_is_one_line_and_exit_2(tmp_path):
    path = _write(tmp_path, BAD["a word for a number"][0])
    result = CliRunner().invoke(main, ["ballbar", str(path)])
    assert result.exit_code == 2
    assert result.output.strip() == (
        f"esp: error: {path}:6: column deviation: expected a number, found 'abc'"
    )


def test_header_conditions_and_options_that_override_them(tmp_path):
    path = _write(
        tmp_path,
        [
            "# machine: VMC 3",
            "# date: 2026-11-30",
            "# feed: 2000 mm/min",
            "# calibration U: 0.5 um",
            "# spindle: off",
            "# radius: 100",
            "angle,deviation",
            *GOOD,
        ],
    )
    (c,) = circle_tests(path, conditions={"feed_mm_per_min": 500.0, "machine": None})
    k = c.conditions
    assert (k.machine, k.date, k.feed_mm_per_min, k.calibration_U_um) == (
        "VMC 3",
        "2026-11-30",
        500.0,
        0.5,
    )
    assert k.other == (("spindle", "off"),)


@pytest.mark.parametrize(
    "option, value, found",
    [("--radius", "100", "applies to an angle file"), ("--plane", "XZ", "applies to an angle")],
)
def test_angle_file_options_on_a_lengths_table_are_refused(tmp_path, option, value, found):
    from esp.ballbar.synthetic import Effects, synthetic_readings, write_lengths

    path = tmp_path / "lengths.csv"
    write_lengths(path, 100.0, synthetic_readings(100.0, Effects(), step_deg=10.0))
    result = CliRunner().invoke(main, ["ballbar", str(path), option, value])
    assert result.exit_code == 2 and result.output.startswith(f"esp: error: {option}: {found}")


def test_a_bad_plane_is_refused_naming_the_option_or_the_line(tmp_path):
    path = _write(tmp_path, ["# radius: 100", "# plane: AB", "angle,deviation", *GOOD])
    result = CliRunner().invoke(main, ["ballbar", str(path)])
    assert result.exit_code == 2
    assert result.output.startswith(f"esp: error: {path}:2: '# plane:' expected one of XY")
    result = CliRunner().invoke(main, ["ballbar", str(path), "--plane", "yz"])
    assert result.exit_code == 0, result.output
    assert "Circle bar in YZ" in result.output
