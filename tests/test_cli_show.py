"""``esp analyse --show FIGURE``: one figure of the report, without the rest."""

from __future__ import annotations

import json

import pytest
from click.testing import CliRunner

from esp.cli import main
from esp.cli.analyse import figure_name, show_path

PNG = b"\x89PNG\r\n\x1a\n"

BASE = """
[machine]
name = "show test"
configuration = "wBMTt"
axes = { bottom = "X", middle = "Y", top = "Z" }

[axes.X]
travel = [0, 1000]
step = 500

[axes.X.errors]
linear = { points = [[0, 0.0], [1000, 8.0]] }

[axes.Y]
travel = [0, 1000]
step = 500

[axes.Z]
travel = [0, 1000]
step = 500
"""


@pytest.fixture
def machine(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "machine.toml").write_text(BASE, encoding="utf-8")
    return "machine.toml"


def run(*args: str):
    return CliRunner().invoke(main, ["analyse", *args])


def test_a_show_value_names_a_figure_and_where_it_goes():
    assert (figure_name("terms"), show_path("terms")) == ("terms", "terms.png")
    assert (figure_name("figs/map-X.pdf"), show_path("figs/map-X.pdf")) == (
        "map-X",
        "figs/map-X.pdf",
    )
    assert (figure_name("out/terms.PNG"), show_path("out/terms.PNG")) == (
        "terms",
        "out/terms.PNG",
    )
    assert show_path("figs/terms") == "figs/terms.png"


@pytest.mark.slow
def test_show_writes_the_figure_and_prints_its_path_only(machine, tmp_path):
    result = run(machine, "--show", "map-volumetric")
    assert result.exit_code == 0, result.output
    assert result.stdout == "map-volumetric.png\n"  # the path, not the text report
    assert (tmp_path / "map-volumetric.png").read_bytes().startswith(PNG)
    # nothing else: no report folder, no other figure
    assert sorted(p.name for p in tmp_path.iterdir()) == [
        ".esp-files.json",
        "machine.toml",
        "map-volumetric.png",
    ]
    # a second run replaces the file esp wrote
    assert run(machine, "--show", "map-volumetric", "-q").exit_code == 0


def test_show_list_lists_the_figures_of_this_report(machine):
    result = run(machine, "--show", "list")
    assert result.exit_code == 0, result.output
    names = [line.split()[0] for line in result.stdout.splitlines()]
    assert names[:5] == ["map-X", "map-Y", "map-Z", "map-volumetric", "terms"]
    assert "input-X" in names


def test_an_unknown_figure_is_refused_with_the_names(machine, tmp_path):
    result = run(machine, "--show", "map-vol")
    assert result.exit_code == 2
    assert "did you mean 'map-volumetric'?" in result.stderr
    assert "map-X, map-Y, map-Z, map-volumetric, terms" in result.stderr
    assert not (tmp_path / "map-vol.png").exists()


@pytest.mark.slow
def test_show_with_json_to_stdout_names_the_figure_on_standard_error(machine, tmp_path):
    result = run(machine, "--show", "terms.pdf", "--json", "-")
    assert result.exit_code == 0, result.output
    assert json.loads(result.stdout)["schema"] == "esp.result/1"
    assert result.stderr == "esp: figure written to terms.pdf\n"
    assert (tmp_path / "terms.pdf").read_bytes().startswith(b"%PDF")


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (("--show", "terms", "--out", "R"), "does not go with --out"),
        (("--show", "terms", "--at", "X=0,Y=0,Z=0"), "does not go with --at"),
        (("--show", "list", "--show", "terms"), "give it alone"),
        (("--show", "terms.svg"), "expected a figure file name ending in .png or .pdf"),
    ],
)
def test_show_refuses_what_it_cannot_do_before_any_work(machine, args, message):
    result = run(machine, *args)
    assert result.exit_code == 2
    assert message in result.stderr


def test_show_never_writes_over_a_file_esp_did_not_write(machine, tmp_path):
    (tmp_path / "terms.png").write_bytes(b"mine")
    result = run(machine, "--show", "terms")
    assert result.exit_code == 2
    assert (tmp_path / "terms.png").read_bytes() == b"mine"
