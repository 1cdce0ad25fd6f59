"""A fit that explains nothing is not reported as a machine: every coefficient fixed is
refused by its key, a fit far beyond its stated uncertainties (Birge ratio and χ², both
named) is refused unless ``identify.inconsistent = "accept"``, and its warning then reaches
standard error and the JSON ``warnings`` (docs/identify.md, "Uncertainty")."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest
from click.testing import CliRunner

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


def _one_line_refusal(result) -> str:
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
    ratio about 17, χ² about 4.7e5 on 1691 degrees of freedom): refused, the Birge ratio and
    χ² with its 99.9 % quantile named."""
    path = _config(tmp_path, ALL_BUT_ONE)
    line = _one_line_refusal(CliRunner().invoke(main, ["identify", str(path)]))
    assert "Birge ratio 16.7 (above 3)" in line
    assert "χ² = 4.69e+05 for 1691 degrees of freedom (99.9 % quantile 1876)" in line
    assert "identify.inconsistent" in line


@pytest.mark.slow
def test_an_accepted_inconsistent_fit_warns_on_stderr_and_in_the_json(tmp_path: Path) -> None:
    path = _config(tmp_path, ALL_BUT_ONE, 'inconsistent = "accept"\n')
    out = tmp_path / "r.json"
    result = CliRunner().invoke(main, ["identify", str(path), "--json", str(out)])
    assert result.exit_code == 0, result.stderr
    assert "esp: warning: the residuals are larger than" in result.stderr
    assert "Birge ratio 16.7" in result.stderr
    warnings = json.loads(out.read_text(encoding="utf-8"))["warnings"]
    assert any("Birge ratio 16.7" in w for w in warnings)


def test_the_inconsistent_choice_is_checked_by_its_key(tmp_path: Path) -> None:
    path = _config(tmp_path, ("X.linear",), 'inconsistent = "ignore"\n')
    line = _one_line_refusal(CliRunner().invoke(main, ["identify", str(path), "--plan"]))
    assert "identify.inconsistent" in line and "ignore" in line
