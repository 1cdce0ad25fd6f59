"""``esp inspect``: the command against the library, its files and its failures."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest
from click.testing import CliRunner

from esp.cli import main
from esp.core.profile import ErrorProfile
from esp.io.laser10 import write_laser10
from esp.io.load import load_profile
from esp.report.jsonout import dumps
from esp.report.profile_plots import profile_runs_figure
from esp.report.profile_text import inspect_text, profile_summary

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"
METADATA = {
    "Machine": "Example mill",
    "Serial No": "12345",
    "Date": "12/12/2016",
    "By": "A. User",
    "Axis": "X",
    "Location": "Workshop",
}
ENVIRONMENT = {
    "Air temp": ("20.337280", "20.384956", "0"),
    "Air press": ("99.039005", "99.049346", "1"),
    "Date Time": ("10:46 Dec 12 2016", "11:01 Dec 12 2016"),
}


def run(*args: str):
    return CliRunner().invoke(main, list(args))


@pytest.fixture
def xpos(tmp_path) -> Path:
    path = tmp_path / "Xpos.rtl"
    profile = ErrorProfile(
        "linear",
        [0.0, 100.0, 200.0],
        {
            "forward": [[0, 2, 4], [1, 3, 4], [2, 4, 7]],
            "backward": [[-2, 1, 2], [-2, 1, 2], [-2, 4, 2]],
        },
        metadata=METADATA,
        environment=ENVIRONMENT,
    )
    write_laser10(path, profile)
    return path


def test_text_is_the_library_rendering(xpos):
    result = run("inspect", str(xpos))
    assert result.exit_code == 0, result.output
    assert result.stdout == inspect_text(load_profile(xpos))
    out = result.stdout
    assert "component        X.linear" in out
    assert "targets          3, from 0 to 200 mm" in out
    assert "runs             forward 3, backward 3" in out
    assert "Serial No  12345" in out
    assert "Air temp   20.337280          20.384956" in out
    # means: forward (0+1+2)/3 = 1, backward -2, bidirectional (1 - 2)/2 = -0.5
    assert "0.000    1.000    -2.000  -0.500" in out


def test_json_object(xpos):
    result = run("inspect", str(xpos), "--json", "-")
    assert result.exit_code == 0, result.output
    data = json.loads(result.stdout)
    # the document, then the run's provenance (esp.report.provenance), last
    assert data.pop("provenance")["inputs"][0]["path"] == str(xpos)
    assert dumps(data) == dumps(profile_summary(load_profile(xpos)))
    assert list(data) == [
        "file",
        "component",
        "kind",
        "axis",
        "error_direction",
        "unit",
        "targets",
        "runs",
        "metadata",
        "environment",
        "mean",
    ]
    assert data["kind"] == "linear" and data["axis"] == "X"
    assert data["error_direction"] is None
    assert data["unit"] == {"engine": "um", "file": "um"}
    assert data["targets"] == {
        "count": 3,
        "first_mm": 0.0,
        "last_mm": 200.0,
        "positions_mm": [0.0, 100.0, 200.0],
    }
    assert data["runs"] == {"forward": 3, "backward": 3}
    assert data["metadata"] == METADATA
    assert data["environment"]["Air press"] == {"start": "99.039005", "end": "99.049346"}
    assert data["environment"]["Date Time"]["end"] == "11:01 Dec 12 2016"
    # forward means (0+1+2)/3, (2+3+4)/3, (4+4+7)/3; backward -2, (1+1+4)/3, 2
    assert data["mean"] == {
        "position_mm": [0.0, 100.0, 200.0],
        "forward": [1.0, 3.0, 5.0],
        "backward": [-2.0, 2.0, 2.0],
        "mean": [-0.5, 2.5, 3.5],
    }


def test_json_to_file_still_prints_text(xpos, tmp_path):
    out = tmp_path / "summary.json"
    result = run("inspect", str(xpos), "--json", str(out))
    assert result.exit_code == 0, result.output
    assert result.stdout.startswith("file             Xpos.rtl")
    assert json.loads(out.read_text(encoding="utf-8"))["runs"]["forward"] == 3


def test_unit_option_converts_angles(tmp_path):
    path = tmp_path / "Xpitch.rta"
    write_laser10(path, ErrorProfile("angular", [0.0, 500.0], {"forward": [[0.0, 1.0]]}))
    result = run("inspect", str(path), "--unit", "arcsec", "--json", "-")
    assert result.exit_code == 0, result.output
    data = json.loads(result.stdout)
    assert data["unit"] == {"engine": "um/m", "file": "arcsec"}
    # 1 arcsec = pi / (180 * 3600) rad = 4.848137 µrad = 4.848137 µm/m
    assert data["mean"]["forward"][1] == pytest.approx(math.pi / 648000 * 1e6, abs=1e-6)
    assert "backward" not in data["mean"]
    assert data["runs"] == {"forward": 1, "backward": 0}


def test_kind_option_for_csv(tmp_path):
    path = tmp_path / "ystraight.csv"
    path.write_text(
        "target_mm,run,direction,deviation\n0,1,forward,0\n100,1,forward,3\n",
        encoding="utf-8",
    )
    result = run("inspect", str(path), "--kind", "straightness", "--json", "-")
    assert result.exit_code == 0, result.output
    assert json.loads(result.stdout)["kind"] == "straightness"


@pytest.mark.slow
def test_plot_written_deterministically(xpos, tmp_path):
    first, second = tmp_path / "plots" / "a.png", tmp_path / "plots" / "b.png"
    assert run("inspect", str(xpos), "--plot", str(first)).exit_code == 0
    assert run("inspect", str(xpos), "--plot", str(second)).exit_code == 0
    assert first.read_bytes().startswith(PNG_SIGNATURE)
    assert first.read_bytes() == second.read_bytes()
    # and the registry of the files esp wrote there (esp.io.outputs)
    assert sorted(p.name for p in first.parent.iterdir()) == [".esp-files.json", "a.png", "b.png"]


def test_malformed_file_fails_cleanly_without_output(tmp_path):
    path = tmp_path / "broken.rtl"
    path.write_text("HEADER::\nFile type : rtl\nEOF::\n", encoding="utf-8")
    out_png = tmp_path / "broken.png"
    result = run("inspect", str(path), "--plot", str(out_png))
    assert result.exit_code == 2, result.output
    assert result.stderr.startswith("esp: error: ")
    assert "broken.rtl" in result.stderr
    assert "Traceback" not in result.output
    assert sorted(p.name for p in tmp_path.iterdir()) == ["broken.rtl"]


def test_help_has_an_example():
    result = run("inspect", "--help")
    assert result.exit_code == 0
    assert "Examples:\n    esp inspect data/examples/gantry/X-linear.rtl\n" in result.output
    for option in ("--unit", "--json", "--plot", "--kind"):
        assert option in result.output


def test_runs_figure_draws_every_run_and_the_means():
    profile = ErrorProfile(
        "angular",
        [0.0, 100.0],
        {"forward": [[0, 2], [2, 4]], "backward": [[1, 1], [1, 3], [1, 5]]},
        axis="X",
        error_direction="Z",
        source="Xyaw.rta",
    )
    ax = profile_runs_figure(profile).axes[0]
    assert ax.get_xlabel() == "position (mm)"
    assert ax.get_ylabel() == "deviation (µm/m)"
    assert "Xyaw.rta" in ax.get_title() and "X.angular.Z" in ax.get_title()
    # the runs: thin and translucent (the zero line is thin but opaque)
    thin = [line for line in ax.lines if line.get_linewidth() < 1.0 and line.get_alpha()]
    assert len(thin) == 2 + 3  # every run
    assert {line.get_linestyle() for line in thin[:2]} == {"-"}  # forward solid
    assert {line.get_linestyle() for line in thin[2:]} == {"--"}  # backward dashed
    curves = {tuple(line.get_ydata()) for line in ax.lines}
    # forward mean (0+2)/2, (2+4)/2 = 1, 3; backward 1, (1+3+5)/3 = 3; bidirectional 1, 3
    assert (1.0, 3.0) in curves
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    assert labels == [
        "forward runs (2)",
        "forward mean",
        "backward runs (3)",
        "backward mean",
        "bidirectional mean",
    ]


@pytest.mark.slow
def test_inspect_without_plot_does_not_load_matplotlib(xpos):
    import subprocess
    import sys

    code = (
        "import sys\nfrom esp.cli import main\n"
        f"try:\n    main(['inspect', {str(xpos)!r}])\nexcept SystemExit:\n    pass\n"
        "print('matplotlib' in sys.modules, 'pandas' in sys.modules, file=sys.stderr)\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.startswith("file             Xpos.rtl")
    assert out.stderr.strip() == "False False"


@pytest.mark.slow
def test_a_file_name_with_dollars_and_a_newline(tmp_path):
    """A file name is shown literally in the plot's title and on one line in the text."""
    path = tmp_path / "$x^$\nrun.rtl"
    write_laser10(path, ErrorProfile("linear", [0.0, 100.0], {"forward": [[0.0, 1.0]]}))
    png = tmp_path / "plot.png"
    result = run("inspect", str(path), "--plot", str(png))
    assert result.exit_code == 0, result.output
    assert result.stdout.startswith("file             $x^$\\nrun.rtl\n")
    assert png.read_bytes().startswith(PNG_SIGNATURE)
    title = profile_runs_figure(load_profile(path)).axes[0].title
    assert title.get_text().startswith("$x^$\\nrun.rtl: ")
    assert title._preprocess_math(title.get_text())[1] is False


def test_a_unit_contradicting_the_file_is_refused(tmp_path):
    """The file says µm; --unit mm would read every deviation 1000 times too large."""
    path = tmp_path / "x.csv"
    path.write_text(
        "# kind: linear\n# unit: um\ntarget_mm,run,direction,deviation\n0,1,+,0\n100,1,+,2\n",
        encoding="utf-8",
    )
    result = run("inspect", str(path), "--unit", "mm")
    assert result.exit_code == 2
    lines = result.output.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in result.output
    assert f"{path}:2: the file states its deviations in um" in lines[0]
    assert "read in mm" in lines[0]
    # the same unit spelled otherwise is the file's unit
    result = run("inspect", str(path), "--unit", "µm", "--json", "-")
    assert result.exit_code == 0, result.output
    assert json.loads(result.stdout)["mean"]["forward"] == [0.0, 2.0]
    # every command with --unit reads through the same reader
    result = run("iso230-2", str(path), "--unit", "mm")
    assert result.exit_code == 2 and "states its deviations in um" in result.output


def test_the_help_examples_do_not_misread_their_files():
    """No example of --help gives a unit to a file of the examples (whose unit is the
    format's): the example once read a µm/m file as arc seconds."""
    text = run("inspect", "--help").output
    for line in text.splitlines():
        if "--unit" in line and "data/examples" in line:
            raise AssertionError(line)
