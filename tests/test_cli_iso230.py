"""``esp iso230-2``: the command against the library, its files and its failures."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from esp.cli import main
from esp.core.profile import ErrorProfile
from esp.io.laser10 import write_laser10
from esp.io.load import load_profile
from esp.iso230.plots import iso230_figure
from esp.iso230.positioning import AXIS_KEYS, iso230_2
from esp.iso230.text import iso230_text
from esp.report.jsonout import dumps

SQRT3 = math.sqrt(3.0)
PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"

# the worked example of tests/test_iso230.py and docs/iso230-2.md (µm)
FORWARD = [[0, 2, 4], [1, 3, 4], [2, 4, 7]]
BACKWARD = [[-2, 1, 2], [-2, 1, 2], [-2, 4, 2]]


def run(*args: str):
    return CliRunner().invoke(main, list(args))


def assert_clean_failure(result, *fragments: str) -> None:
    """Exit code 2, one line on stderr naming the problem, no traceback."""
    assert result.exit_code == 2, result.output
    assert result.stderr.startswith("esp: error: ")
    assert result.stderr.count("\n") == 1
    assert "Traceback" not in result.output
    for fragment in fragments:
        assert fragment in result.stderr


@pytest.fixture
def xpos(tmp_path) -> Path:
    path = tmp_path / "Xpos.rtl"
    profile = ErrorProfile(
        "linear",
        [0.0, 100.0, 200.0],
        {"forward": FORWARD, "backward": BACKWARD},
        axis="X",
        metadata={"Machine": "Example mill", "Axis": "X"},
    )
    write_laser10(path, profile)
    return path


def test_table_is_the_library_rendering(xpos):
    result = run("iso230-2", str(xpos))
    assert result.exit_code == 0, result.output
    from esp.iso230.statement import LaserSetup, conditions_of, uncertainty

    profile = load_profile(xpos)
    stats = iso230_2(profile)
    said = iso230_text(stats, conditions_of(profile, {}), uncertainty(stats, profile, LaserSetup()))
    assert result.stdout == said
    assert "U: not evaluated (no the laser's accuracy" not in said
    assert "U: not evaluated" in said
    assert "Xpos.rtl, X axis" in result.stdout
    # E = 5 - (-2) = 7 µm, A = (5 + 2√3) - (-2) = 10.464 µm (see docs/iso230-2.md)
    assert "  E        7.000 µm" in result.stdout
    assert f"  A       {7 + 2 * SQRT3:6.3f} µm" in result.stdout
    assert "at least 5 runs" in result.stdout


def test_json_to_stdout(xpos):
    result = run("iso230-2", str(xpos), "--json", "-")
    assert result.exit_code == 0, result.output
    data = json.loads(result.stdout)
    assert data.pop("provenance")["inputs"][0]["path"] == str(xpos)
    assert data.pop("decisions") == []
    assert data.pop("uncertainty")["evaluated"] is False
    assert isinstance(data.pop("conditions"), list)
    assert dumps(data) == dumps(iso230_2(load_profile(xpos)).to_dict())
    assert list(data["axis"]) == list(AXIS_KEYS)
    assert data["unit"] == "um"
    assert data["runs"] == {"up": 3, "down": 3}
    # hand values: B = max(3, 1, 3), E = 5 - (-2), M = 3.5 - (-0.5)
    assert (data["axis"]["B"], data["axis"]["E"], data["axis"]["M"]) == (3.0, 7.0, 4.0)
    assert data["axis"]["R"] == pytest.approx(4 * SQRT3, abs=1e-6)
    assert [row["position_mm"] for row in data["targets"]] == [0.0, 100.0, 200.0]
    assert data["targets"][0]["R"] == 5.0  # max(2·1 + 2·0 + 3, 4, 0)


@pytest.mark.slow
def test_json_to_file_and_plot(xpos, tmp_path):
    out_json = tmp_path / "out" / "x.json"
    out_png = tmp_path / "out" / "x.png"
    result = run("iso230-2", str(xpos), "--json", str(out_json), "--plot", str(out_png))
    assert result.exit_code == 0, result.output
    assert result.stdout.startswith("ISO 230-2 positioning statistics")
    assert json.loads(out_json.read_text(encoding="utf-8"))["axis"]["E"] == 7.0
    assert out_png.read_bytes().startswith(PNG_SIGNATURE)
    names = sorted(p.name for p in out_png.parent.iterdir())
    assert names == [".esp-files.json", "x.json", "x.png"]


@pytest.mark.slow
def test_plot_is_deterministic(xpos, tmp_path):
    first, second = tmp_path / "a.png", tmp_path / "b.png"
    assert run("iso230-2", str(xpos), "--plot", str(first)).exit_code == 0
    assert run("iso230-2", str(xpos), "--plot", str(second)).exit_code == 0
    assert first.read_bytes() == second.read_bytes()
    assert b"Software" not in first.read_bytes()


def test_unidirectional_file_reports_one_direction(tmp_path):
    path = tmp_path / "Yuni.rtl"
    write_laser10(path, ErrorProfile("linear", [0.0, 50.0], {"forward": [[0, 2], [2, 4]]}))
    result = run("iso230-2", str(path), "--json", "-")
    assert result.exit_code == 0, result.output
    data = json.loads(result.stdout)
    assert data["bidirectional"] is False
    assert list(data["axis"]) == ["A_up", "E_up", "R_up"]
    # x̄↑ = 1, 3: E↑ = 2
    assert data["axis"]["E_up"] == 2.0


def test_csv_without_kind_is_read_as_linear(tmp_path):
    path = tmp_path / "x.csv"
    rows = ["target_mm,run,direction,deviation"]
    for r, (direction, values) in enumerate(
        [("forward", [0, 2]), ("backward", [1, 1]), ("forward", [2, 4]), ("backward", [1, 1])],
        start=1,
    ):
        rows += [f"{t},{r},{direction},{v}" for t, v in zip((0, 50), values, strict=True)]
    path.write_text("\n".join(rows) + "\n", encoding="utf-8")
    result = run("iso230-2", str(path), "--json", "-")
    assert result.exit_code == 0, result.output
    data = json.loads(result.stdout)
    # x̄↑ = 1, 3 ; x̄↓ = 1, 1 ; Bi = 0, 2 -> B = 2 ; E = 3 - 1 = 2
    assert (data["axis"]["B"], data["axis"]["E"]) == (2.0, 2.0)


def test_csv_declaring_another_kind_is_refused(tmp_path):
    path = tmp_path / "pitch.csv"
    path.write_text(
        "# kind: angular\ntarget_mm,run,direction,deviation\n"
        "0,1,forward,0\n50,1,forward,1\n0,2,forward,0\n50,2,forward,2\n",
        encoding="utf-8",
    )
    result = run("iso230-2", str(path))
    assert_clean_failure(result, "pitch.csv", "linear", "angular")


def test_angular_file_is_refused_and_nothing_written(tmp_path):
    path = tmp_path / "Xpitch.rta"
    write_laser10(path, ErrorProfile("angular", [0.0, 50.0], {"forward": [[0, 1], [0, 2]]}))
    out_png, out_json = tmp_path / "p.png", tmp_path / "p.json"
    result = run("iso230-2", str(path), "--plot", str(out_png), "--json", str(out_json))
    assert_clean_failure(result, "Xpitch.rta", "defined for linear", "found an angular profile")
    assert "?" not in result.output  # the rotation axis is not recorded: not shown as "?"
    assert not out_png.exists() and not out_json.exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["Xpitch.rta"]


def test_one_run_per_direction_is_refused(tmp_path):
    path = tmp_path / "once.rtl"
    write_laser10(
        path, ErrorProfile("linear", [0.0, 50.0], {"forward": [0, 1], "backward": [0, 1]})
    )
    assert_clean_failure(run("iso230-2", str(path)), "once.rtl", "at least 2 runs")


def test_missing_file(tmp_path):
    result = run("iso230-2", str(tmp_path / "absent.rtl"))
    assert_clean_failure(result, "absent.rtl")


def test_help_has_an_example():
    result = run("iso230-2", "--help")
    assert result.exit_code == 0
    assert "Examples:\n    esp iso230-2 data/examples/gantry/X-linear.rtl\n" in result.output
    for option in ("--unit", "--json", "--plot"):
        assert option in result.output


def test_figure_shows_means_and_two_sigma_bands():
    result = iso230_2(
        ErrorProfile(
            "linear",
            [0.0, 100.0, 200.0],
            {"forward": FORWARD, "backward": BACKWARD},
            axis="X",
            source="data/Xpos.rtl",
        )
    )
    ax = iso230_figure(result).axes[0]
    assert ax.get_xlabel() == "target position (mm)"
    assert ax.get_ylabel() == "positional deviation (µm)"
    assert "X axis" in ax.get_title() and "Xpos.rtl" in ax.get_title()
    assert [t.get_text() for t in ax.get_legend().get_texts()] == [
        "mean up ↑ (forward), ±2s band",
        "mean down ↓ (backward), ±2s band",
        "bidirectional mean",
    ]
    lines = {tuple(np.round(line.get_ydata(), 9)) for line in ax.lines}
    r3 = round(2 * SQRT3, 9)
    # up: x̄ = 1, 3, 5 and s = 1, 1, √3 -> bands -1, 1, 5 - 2√3 and 3, 5, 5 + 2√3
    assert (1.0, 3.0, 5.0) in lines
    assert (-1.0, 1.0, round(5 - r3, 9)) in lines
    assert (3.0, 5.0, round(5 + r3, 9)) in lines
    # down: x̄ = -2, 2, 2 and s = 0, √3, 0 -> bands -2, 2 - 2√3, 2 and -2, 2 + 2√3, 2
    assert (-2.0, round(2 - r3, 9), 2.0) in lines
    assert (-2.0, round(2 + r3, 9), 2.0) in lines
    # bidirectional mean (x̄↑ + x̄↓) / 2
    assert (-0.5, 2.5, 3.5) in lines


def test_quiet_prints_nothing_and_still_writes(xpos, tmp_path):
    """``-q``: no report on standard output and no line on standard error; the JSON file
    is written all the same."""
    target = tmp_path / "r.json"
    result = CliRunner().invoke(main, ["iso230-2", str(xpos), "--json", str(target), "-q"])
    assert result.exit_code == 0, result.output
    assert result.stdout == "" and result.stderr == ""
    assert json.loads(target.read_text(encoding="utf-8"))["schema"] == "esp.iso230-2/1"
