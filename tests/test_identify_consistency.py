"""A fit that explains nothing is not reported as a machine: every coefficient fixed is
refused by its key, a fit far beyond its stated uncertainties (Birge ratio and χ², both
named) is refused unless ``identify.inconsistent = "accept"``, and its warning then reaches
standard error and the JSON ``warnings`` (docs/identify.md, "Uncertainty")."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest
from click.testing import CliRunner, Result

from esp.cli import main

EXAMPLE = Path(__file__).resolve().parent.parent / "data/examples/identify/tool-ballbar"
#: every identified component of the tool-ballbar example but squareness.YZ
ALL_BUT_ONE = (
    "X.linear",
    "Y.linear",
    "Z.linear",
    "X.straightness.Y",
    "X.straightness.Z",
    "Y.straightness.X",
    "Y.straightness.Z",
    "Z.straightness.X",
    "Z.straightness.Y",
    "squareness.XY",
    "squareness.XZ",
)


def _config(folder: Path, fix: tuple[str, ...], extra: str = "") -> Path:
    for f in EXAMPLE.iterdir():
        shutil.copy(f, folder / f.name)
    text = (EXAMPLE / "machine.toml").read_text(encoding="utf-8")
    names = ", ".join(f'"{n}"' for n in fix)
    assert "\n[identify]\n" in text
    text = text.replace("\n[identify]\n", f"\n[identify]\nfix = [{names}]\n{extra}", 1)
    path = folder / "machine.toml"
    path.write_text(text, encoding="utf-8")
    return path


def _one_line_refusal(result: Result) -> str:
    assert result.exit_code == 2, (result.exit_code, result.stdout, result.stderr)
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("esp: error: "), result.stderr
    return lines[0]


@pytest.mark.slow
def test_every_identified_component_fixed_is_refused_by_its_key(tmp_path: Path) -> None:
    """Nothing left to identify: not a volumetric accuracy of 0 with U = 0, exit 0."""
    path = _config(tmp_path, (*ALL_BUT_ONE, "squareness.YZ"))
    line = _one_line_refusal(CliRunner().invoke(main, ["identify", str(path)]))
    assert "identify.fix" in line and "nothing is left to identify" in line


@pytest.mark.slow
def test_a_fit_far_beyond_its_uncertainties_is_refused_with_its_figures(tmp_path: Path) -> None:
    """All but squareness.YZ fixed at zero: the circles' ellipses stay unexplained (Birge
    ratio about 16, χ² about 4.4e5 on 1691 degrees of freedom): refused, the Birge ratio and
    χ² with its 99.9 % quantile named."""
    path = _config(tmp_path, ALL_BUT_ONE)
    line = _one_line_refusal(CliRunner().invoke(main, ["identify", str(path)]))
    assert "Birge ratio 16.2 (above 3)" in line
    assert "χ² = 4.416e+05 for 1691 degrees of freedom (99.9 % quantile 1876)" in line
    assert "identify.inconsistent" in line


@pytest.mark.slow
def test_an_accepted_inconsistent_fit_warns_on_stderr_and_in_the_json(tmp_path: Path) -> None:
    path = _config(tmp_path, ALL_BUT_ONE, 'inconsistent = "accept"\n')
    out = tmp_path / "r.json"
    result = CliRunner().invoke(main, ["identify", str(path), "--json", str(out)])
    assert result.exit_code == 0, result.stderr
    assert "esp: warning: the residuals are larger than" in result.stderr
    assert "Birge ratio 16.2" in result.stderr
    warnings = json.loads(out.read_text(encoding="utf-8"))["warnings"]
    assert any("Birge ratio 16.2" in w for w in warnings)


def test_the_inconsistent_choice_is_checked_by_its_key(tmp_path: Path) -> None:
    path = _config(tmp_path, ("X.linear",), 'inconsistent = "ignore"\n')
    line = _one_line_refusal(CliRunner().invoke(main, ["identify", str(path), "--plan"]))
    assert "identify.inconsistent" in line and "ignore" in line


#: every identified component of the example but squareness.XY: the circles in XY alone
XY_FIXED = (*ALL_BUT_ONE[:9], "squareness.XZ", "squareness.YZ")


def _xy_config(
    folder: Path, extra: str = "", rows: dict[int, dict[int, str]] | None = None
) -> Path:
    """The example's XY circles alone (circle-XY.csv, 96 readings), squareness.XY identified,
    the rest fixed; ``rows`` replaces fields (0-based columns) of the given 1-based lines."""
    lines = (EXAMPLE / "circle-XY.csv").read_text(encoding="utf-8").splitlines()
    for number, fields in (rows or {}).items():
        cells = lines[number - 1].split(",")
        for column, value in fields.items():
            cells[column] = value
        lines[number - 1] = ",".join(cells)
    (folder / "circle-XY.csv").write_text("\n".join(lines) + "\n", encoding="utf-8")
    text = (EXAMPLE / "machine.toml").read_text(encoding="utf-8")
    text = text.replace('file = "ballbar.csv"', 'file = "circle-XY.csv"', 1)
    names = ", ".join(f'"{n}"' for n in XY_FIXED)
    text = text.replace(
        "\n[identify]\n", f'\n[identify]\nfix = [{names}]\ninconsistent = "accept"\n{extra}', 1
    )
    path = folder / "machine.toml"
    path.write_text(text, encoding="utf-8")
    return path


def test_ballbar_positions_must_agree_with_length_mm(tmp_path: Path) -> None:
    """Circle c1 (lines 3 to 98, positions 150 mm from the centre) said to be 10 mm long:
    refused at its first line by the rule of ``esp ballbar`` (0.1 % of the length), not left
    to the fit, whose χ² named no file."""
    length = {3 + i: {8: "10"} for i in range(96)}
    path = _xy_config(tmp_path, rows=length)
    assert (tmp_path / "circle-XY.csv").read_text().splitlines()[97].startswith("c1,")
    line = _one_line_refusal(CliRunner().invoke(main, ["identify", str(path)]))
    assert line == (
        f"esp: error: {tmp_path / 'circle-XY.csv'}:3: circle 'c1': expected the position "
        "at length_mm 10 mm from the centre (within 0.01 mm), found 150 mm"
    )


def test_one_ballbar_position_off_its_circle_is_named_by_its_line(tmp_path: Path) -> None:
    """Line 7 moved 0.5 mm along X, where the circle runs at 31° from X (radius change about
    0.43 mm, beyond 0.15 mm = 0.1 % of 150 mm): its line is named."""
    x_mm = float((EXAMPLE / "circle-XY.csv").read_text().splitlines()[6].split(",")[2])
    path = _xy_config(tmp_path, rows={7: {2: f"{x_mm + 0.5:.4f}"}})
    line = _one_line_refusal(CliRunner().invoke(main, ["identify", str(path), "--plan"]))
    assert "circle-XY.csv:7: circle 'c1': expected the position at length_mm 150 mm" in line
    assert "(within 0.15 mm)" in line


def test_the_unchanged_circles_are_identified(tmp_path: Path) -> None:
    """The companion of the two refusals above: the same copy, unchanged, is accepted."""
    result = CliRunner().invoke(main, ["identify", str(_xy_config(tmp_path))])
    assert result.exit_code == 0, result.stderr


def test_a_fit_stopped_by_its_cap_is_refused_by_the_cli(tmp_path: Path) -> None:
    """One step from the nominal centres leaves a next step of about 5e-3 standard
    uncertainties (the test is 1e-5): refused, one line, exit 2, the key named."""
    path = _xy_config(tmp_path, "max_iterations = 1\n")
    line = _one_line_refusal(CliRunner().invoke(main, ["identify", str(path)]))
    assert "the fit did not converge in 1 iteration: the last step moved" in line
    assert "raise identify.max_iterations" in line


@pytest.mark.parametrize("value", ["0", "2.5", "true", "10001"])
def test_the_iteration_cap_is_checked_by_its_key(tmp_path: Path, value: str) -> None:
    path = _xy_config(tmp_path, f"max_iterations = {value}\n")
    line = _one_line_refusal(CliRunner().invoke(main, ["identify", str(path), "--plan"]))
    assert "identify.max_iterations: expected a whole number of steps from 1 to 10000" in line


PLATE = Path(__file__).resolve().parent.parent / "data/examples/identify/cmm-ballplate"


@pytest.mark.parametrize("line", [4, 20, 33])
def test_one_wrong_reading_is_named_at_its_line(tmp_path, line):
    """One machine reading of the ball plate 100 to 400 mm off (within every plausibility
    limit, so no range check sees it): the fit is refused as inconsistent, and the refusal
    names that reading's file and line by its standardised residual, where the largest plain
    residual may name a neighbour the fit was pulled towards."""
    for f in PLATE.iterdir():
        shutil.copy(f, tmp_path / f.name)
    plate = tmp_path / "plate.csv"
    rows = plate.read_text(encoding="utf-8").splitlines()
    fields = rows[line - 1].split(",")
    fields[2] = "300.1"  # the machine's X reading of that ball
    rows[line - 1] = ",".join(fields)
    plate.write_text("\n".join(rows) + "\n", encoding="utf-8")
    res = CliRunner().invoke(main, ["identify", str(tmp_path / "machine.toml")])
    assert res.exit_code == 2, res.output
    message = res.stderr.strip()
    assert "\n" not in message and "Traceback" not in res.output
    assert "the fit does not explain the readings" in message
    assert f"the reading least explained is {plate}:{line} (standardised residual" in message
