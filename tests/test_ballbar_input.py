"""esp ballbar refuses readings that cannot be right: each refusal is one line naming the
file and line, what was expected and what was found, exit 2, no traceback, no warning
(docs/formats.md, "Measurements for identification"; docs/reliability.md)."""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from click.testing import CliRunner

from esp.cli import main

HEADER = "circle,direction,X,Y,Z,cx,cy,cz,length_mm,deviation_um"


def _rows(
    *,
    radius_mm: float = 100.0,
    length: str = "100",
    centre: tuple[str, str, str] = ("300", "200", "50"),
    deviation: str = "0.25",
    directions: tuple[str, ...] = ("ccw", "cw"),
    same_position: bool = False,
) -> list[str]:
    """Rows of one good bidirectional circle (36 readings a run), with one thing changed."""
    rows = []
    for d in directions:
        for t in np.radians(np.arange(0.0, 360.0, 10.0)):
            x, y = (
                (400.0, 200.0)
                if same_position
                else (300 + radius_mm * np.cos(t), 200 + radius_mm * np.sin(t))
            )
            rows.append(f"c1,{d},{x:.6f},{y:.6f},50,{','.join(centre)},{length},{deviation}")
    return rows


def _replace(rows: list[str], row: int, column: str, value: str) -> list[str]:
    cells = rows[row].split(",")
    cells[HEADER.split(",").index(column)] = value
    return rows[:row] + [",".join(cells)] + rows[row + 1 :]


GOOD = _rows()

BAD = {
    "length 0": ([HEADER, *_rows(length="0")], ":2: column length_mm: expected a", "found 0"),
    "negative length": ([HEADER, *_rows(length="-100")], ":2: column length_mm", "found -100"),
    "length 1e300": ([HEADER, *_rows(length="1e300")], ":2: column length_mm", "found 1e300"),
    "deviation 1e308": (
        [HEADER, *_replace(GOOD, 3, "deviation_um", "1e308")],
        ":5: column deviation_um: expected a deviation within ±10000 um",
        "found 1e308",
    ),
    "deviation -1e308": (
        [HEADER, *_rows(deviation="-1e308")],
        ":2: column deviation_um",
        "found -1e308",
    ),
    "centre 1e300": ([HEADER, *_rows(centre=("1e300", "200", "50"))], ":2: column cx", "1e300"),
    "positions 150 mm from the centre, length 10": (
        [HEADER, *_rows(radius_mm=150.0, length="10")],
        ":2: circle 'c1': expected the position at length_mm 10 mm from the centre",
        "found 150 mm",
    ),
    "identical positions": (
        [HEADER, *_rows(same_position=True)],
        ":3: circle 'c1': expected each position once in a run",
        "(also on line 2)",
    ),
    "all positions at the centre": (
        [HEADER, *_rows(radius_mm=0.0)],
        ":2: circle 'c1': expected the position at length_mm 100 mm",
        "found 0 mm",
    ),
    "a position given twice": (
        [HEADER, *GOOD, GOOD[5]],
        f":{len(GOOD) + 2}: circle 'c1': expected each position once in a run",
        "(also on line 7)",
    ),
    "a third direction": (
        [HEADER, *_rows(directions=("ccw", "cw", "ccw2"))],
        f":{len(GOOD) + 2}: column direction: expected ccw or cw",
        "found 'ccw2'",
    ),
    "an unknown direction": (
        [HEADER, *_replace(GOOD, 0, "direction", "left")],
        ":2: column direction: expected ccw or cw",
        "found 'left'",
    ),
    "a duplicated header column": (
        [HEADER + ",deviation_um", *[r + ",9" for r in GOOD]],
        ":1: expected one column 'deviation_um'",
        "found 2",
    ),
    "a second centre in one circle": (
        [HEADER, *_replace(GOOD, 4, "cx", "301")],
        ":6: circle 'c1': expected one centre (300, 200, 50) mm as on line 2",
        "found (301, 200, 50)",
    ),
    "a second length in one circle": (
        [HEADER, *_replace(GOOD, 4, "length_mm", "101")],
        ":6: circle 'c1': expected one length_mm 100 as on line 2",
        "found 101",
    ),
    "a position off the plane": (
        [HEADER, *_replace(GOOD, 2, "Z", "51")],
        ":4: circle 'c1': expected the position in the plane XY of the centre",
        "found Z = 51 mm",
    ),
    "a deviation nan": (
        [HEADER, *_replace(GOOD, 1, "deviation_um", "nan")],
        ":3: column deviation_um",
        "'nan'",
    ),
}


@pytest.mark.parametrize("out", [False, True], ids=["text", "out"])
@pytest.mark.parametrize("case", BAD)
def test_bad_ballbar_input_is_one_line_and_exit_2(tmp_path, case, out):
    rows, where, found = BAD[case]
    path = tmp_path / "circle.csv"
    path.write_text("\n".join(rows) + "\n", encoding="utf-8")
    args = ["ballbar", str(path)] + (["--out", str(tmp_path / "report")] if out else [])
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no numpy warning either
        result = CliRunner().invoke(main, args)
    lines = result.output.strip().splitlines()
    assert result.exit_code == 2, result.output
    assert "Traceback" not in result.output and len(lines) == 1, result.output
    assert lines[0].startswith(f"esp: error: {path}{where}"), lines[0]
    assert found in lines[0]
    assert not (tmp_path / "report").exists()


def test_the_good_circle_of_these_cases_is_accepted(tmp_path):
    """The cases above differ from this circle by the one thing each names."""
    path = tmp_path / "circle.csv"
    path.write_text("\n".join([HEADER, *GOOD]) + "\n", encoding="utf-8")
    result = CliRunner().invoke(main, ["ballbar", str(path)])
    assert result.exit_code == 0, result.output
    assert "backlash X+ (step at 0°)" in result.output
    assert "  reported" not in result.output  # a constant deviation: no error of the machine
