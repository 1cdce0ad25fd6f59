"""The shipped examples in ``data/examples``: every configuration runs end to end, the data
files are what the configurations say they are, the generators reproduce the files byte for
byte, and the uncertainty study gives the figures of Longstaff (2002), table 4.3."""

from __future__ import annotations

import importlib.util
import json
import math
import re
import sys
import tomllib
from datetime import datetime
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from esp.batch.run import is_machine_config
from esp.cli import main
from esp.io.load import load_profile

EXAMPLES = Path(__file__).resolve().parent.parent / "data" / "examples"
GANTRY = EXAMPLES / "gantry"
STUDY = EXAMPLES / "uncertainty-study"
# every machine configuration shipped (other TOML files describe chains, heads, ...)
CONFIGS = sorted(p for p in EXAMPLES.glob("*/machine*.toml") if is_machine_config(p))
AXES = ("X", "Y", "Z")


def _run(*args: str):
    return CliRunner().invoke(main, [str(a) for a in args])


@pytest.fixture(scope="module")
def results() -> dict[Path, dict]:
    """The ``--json -`` document of every example configuration, run once."""
    out = {}
    for config in CONFIGS:
        result = _run("analyse", config, "--json", "-")
        assert result.exit_code == 0, f"{config.name}: {result.output}"
        out[config] = json.loads(result.stdout)
    return out


def _point(config: Path, x: float, y: float, z: float) -> dict:
    result = _run("analyse", config, "--at", f"X={x},Y={y},Z={z}", "--json", "-")
    assert result.exit_code == 0, result.output
    doc = json.loads(result.stdout)
    assert doc["schema"] == "esp.point/1"
    return doc["cases"][0]


def _generator(folder: Path):
    """Import ``folder/make_data.py`` as a module."""
    name = f"_make_data_{folder.name.replace('-', '_')}"
    spec = importlib.util.spec_from_file_location(name, folder / "make_data.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module  # dataclasses look their module up while the class is made
    try:
        spec.loader.exec_module(module)
    finally:
        del sys.modules[name]
    return module


def _sources(config: Path) -> dict[str, Path]:
    """Component name -> data file for every file-backed component of a configuration."""
    data = tomllib.loads(config.read_text(encoding="utf-8"))
    out = {}
    for axis, table in data["axes"].items():
        errors = table.get("errors", {})
        if "linear" in errors:
            out[f"{axis}.linear"] = config.parent / errors["linear"]
        for kind in ("straightness", "angular"):
            for about, source in errors.get(kind, {}).items():
                out[f"{axis}.{kind}.{about}"] = config.parent / source
    return out


# -- every example runs --------------------------------------------------------------------


def test_there_are_examples():
    names = {c.relative_to(EXAMPLES).as_posix() for c in CONFIGS}
    assert {
        "gantry/machine.toml",
        "gantry/machine-tcp.toml",
        "uncertainty-study/machine.toml",
        "uncertainty-study/machine-central.toml",
        "uncertainty-study/machine-statistical.toml",
        "uncertainty-study/machine-statistical-central.toml",
    } <= names


@pytest.mark.slow
@pytest.mark.parametrize("config", CONFIGS, ids=lambda c: c.relative_to(EXAMPLES).as_posix())
def test_example_runs_through_the_cli(config, results):
    doc = results[config]
    assert doc["schema"] == "esp.result/1"
    assert doc["analysis"]["warnings"] == []
    accuracy = doc["worst"]["accuracy_um"]
    if doc["analysis"]["plan"]:
        # an uncertainty plan (no error data) claims no accuracy: it headlines its U
        assert "uncertainty" in doc and not doc["analysis"]["active"]
        assert accuracy is None and all("volumetric" not in c for c in doc["cases"])
        assert doc["worst"]["uncertainty_um"] == doc["uncertainty"]["volumetric_um"] > 0
        return
    assert math.isfinite(accuracy) and accuracy > 0
    # the worst case is the largest of the reported cases
    assert accuracy == max(c["volumetric"]["accuracy_um"] for c in doc["cases"])


def test_text_report_of_the_gantry():
    result = _run("analyse", GANTRY / "machine.toml")
    assert result.exit_code == 0, result.output
    assert "GX-1500 gantry milling machine" in result.output
    assert "wYXZt" in result.output
    assert "Volumetric accuracy" in result.output


# -- the gantry's data files ---------------------------------------------------------------


def test_gantry_names_every_component_with_a_file():
    sources = _sources(GANTRY / "machine.toml")
    # 3 axes x (1 linear + 2 straightness + 3 angular) = 18 components, each from a file
    assert len(sources) == 18
    assert all(path.is_file() for path in sources.values())
    # and every data file of the folder is used
    data_files = {
        p for p in GANTRY.iterdir() if p.suffix in {".rtl", ".rta", ".stx", ".sty", ".stz"}
    }
    assert data_files == set(sources.values())
    # the TCP configuration reads the same files for the same components
    assert _sources(GANTRY / "machine-tcp.toml") == sources


@pytest.mark.slow
@pytest.mark.parametrize("component", sorted(_sources(GANTRY / "machine.toml")))
def test_gantry_file_is_what_the_configuration_says(component):
    path = _sources(GANTRY / "machine.toml")[component]
    axis, kind = component.split(".")[:2]
    travel = tomllib.loads((GANTRY / "machine.toml").read_text(encoding="utf-8"))["axes"][axis][
        "travel"
    ]
    profile = load_profile(path)  # kind from the extension, axis from .st? or USER-TEXT
    assert profile.kind == kind
    assert profile.axis == axis
    assert profile.metadata["Axis"] == axis
    for key in ("Machine", "Serial No", "Date", "By", "Location"):
        assert profile.metadata[key]
    # the measured range covers the travel exactly
    assert profile.targets_mm[0] == travel[0]
    assert profile.targets_mm[-1] == travel[1]
    runs = {"linear": 5, "straightness": 3, "angular": 2}[kind]
    assert profile.run_count("forward") == profile.run_count("backward") == runs
    if kind == "linear":
        assert 11 <= profile.targets_mm.size <= 21
    # a test of 15 to 40 minutes, on the day of the USER-TEXT date
    start, end = (datetime.strptime(t, "%H:%M %b %d %Y") for t in profile.environment["Date Time"])
    assert 15 * 60 <= (end - start).total_seconds() <= 40 * 60
    assert start.strftime("%d/%m/%Y") == profile.metadata["Date"]
    for key in ("Air temp", "Air press", "Air humid", "Mat temp 1", "Exp coeff"):
        start_value, end_value = (float(v) for v in profile.environment[key][:2])
        assert math.isfinite(start_value) and math.isfinite(end_value)


@pytest.mark.slow
@pytest.mark.parametrize("component", sorted(_sources(GANTRY / "machine.toml")))
def test_gantry_magnitudes_are_those_the_readme_states(component):
    """Properties the README promises of the synthetic data."""
    profile = load_profile(_sources(GANTRY / "machine.toml")[component])
    kind = component.split(".")[1]
    forward, backward = profile.mean("forward"), profile.mean("backward")
    spread = max(float(np.ptp(profile.runs[d], axis=0).max()) for d in ("forward", "backward"))
    if kind == "linear":
        assert 5.0 < np.ptp(profile.mean()) < 50.0  # tens of µm
        assert 1.0 < abs(np.mean(backward - forward)) < 6.0  # a reversal of a few µm
        assert spread < 3.0  # runs agree to about a micrometre
        assert profile.runs["forward"][0, 0] == 0.0  # zeroed at the first target of run 1
    elif kind == "straightness":
        raw = np.ptp(profile.mean())
        bow = np.ptp(profile.without_slope("least-squares").mean())
        assert raw > 10.0  # the set-up slope, tens of µm over the stroke
        assert 1.0 < bow < 8.0  # a few µm once the slope is removed
    else:
        assert 1.0 < np.ptp(profile.mean()) < 10.0  # a few µm/m
        assert profile.runs["forward"][0, 0] == 0.0


@pytest.mark.slow
def test_gantry_errors_vanish_at_the_datum():
    """datum = "negative": every total is referred to X = Y = Z = 0 (thesis 3.05)."""
    for config in (GANTRY / "machine.toml", GANTRY / "machine-tcp.toml"):
        case = _point(config, 0, 0, 0)
        assert case["errors_um"] == {"X": 0.0, "Y": 0.0, "Z": 0.0}
        assert case["volumetric_um"] == 0.0


@pytest.mark.slow
def test_gantry_worst_point_by_hand(results):
    """The rigid body of wYXZt (B = Y, M = X, T = Z; chain Y -> X -> Z), written out from
    the files at the point of the volumetric accuracy, each term referred to the datum
    (0, 0, 0); levers are the coordinate less the offset (Y 750, X 500, Z 300 mm), angles
    in µm/m x lever in m. Y's angles turn (x - X0) e_X + (z - Z0) e_Z, X's turn
    (z - Z0) e_Z, right-handed about +X, +Y, +Z: e_X × e_Z = -e_Y, e_Y × e_X = -e_Z,
    e_Y × e_Z = e_X, e_Z × e_X = e_Y. Eq. 3.1 as printed differs only in the signs of the
    two rolls (the thesis' Φ_M(B) and Φ_M(M) here are -EAY and -EAX)."""
    config = GANTRY / "machine.toml"
    doc = results[config]
    at = doc["cases"][0]["volumetric"]["at"]
    sources = _sources(config)
    data = tomllib.loads(config.read_text(encoding="utf-8"))
    sq = data["squareness"]
    offset = {a: data["axes"][a]["offset"] for a in AXES}

    def comp(name: str, position: float) -> float:
        profile = load_profile(sources[name])
        if profile.kind == "straightness":
            profile = profile.without_slope("least-squares")
        return float(profile.at(position, "mean"))

    def totals(p: dict) -> dict:
        x, y, z = p["X"], p["Y"], p["Z"]
        lx, lz = (x - offset["X"]) / 1000, (z - offset["Z"]) / 1000  # levers in m
        e_y = (  # bottom direction
            comp("Y.linear", y)
            + comp("X.straightness.Y", x)
            + comp("Z.straightness.Y", z)
            - comp("Y.angular.X", y) * lz  # EAY e_X × lz e_Z
            - comp("X.angular.X", x) * lz  # EAX e_X × lz e_Z
            + comp("Y.angular.Z", y) * lx  # ECY e_Z × lx e_X
            + sq["YZ"] * lz  # S_YZ: Z moving displaces towards +Y
            + sq["XY"] * lx  # S_XY: X moving displaces towards +Y (Y before X)
        )
        e_x = (  # middle direction
            comp("X.linear", x)
            + comp("Y.straightness.X", y)
            + comp("Z.straightness.X", z)
            + comp("Y.angular.Y", y) * lz  # EBY e_Y × lz e_Z
            + comp("X.angular.Y", x) * lz  # EBX e_Y × lz e_Z
            + sq["XZ"] * lz  # S_XZ
        )
        e_z = (  # top direction
            comp("Z.linear", z)
            + comp("Y.straightness.Z", y)
            + comp("X.straightness.Z", x)
            - comp("Y.angular.Y", y) * lx  # EBY e_Y × lx e_X
        )
        return {"X": e_x, "Y": e_y, "Z": e_z}

    here, datum = totals(at), totals({"X": 0.0, "Y": 0.0, "Z": 0.0})
    expected = {a: here[a] - datum[a] for a in AXES}
    volumetric = math.sqrt(sum(v * v for v in expected.values()))
    assert doc["cases"][0]["volumetric"]["accuracy_um"] == pytest.approx(volumetric, abs=1e-5)
    breakdown = doc["cases"][0]["breakdown"][0]
    assert breakdown["label"] == "volumetric"
    assert breakdown["errors_um"] == pytest.approx(expected, abs=1e-5)


def test_gantry_tcp_sweeps_every_orientation(results):
    doc = results[GANTRY / "machine-tcp.toml"]
    # 3 lengths x (3 tilts x 4 spins) of the default sweep: the hemisphere about the
    # spindle in the steps of thesis 3.12
    assert len(doc["sweep"]) == 3 * 3 * 4
    assert [c["tool"]["length_mm"] for c in doc["cases"]] == [0.0, 150.0, 300.0]
    assert doc["analysis"]["not_active"] == []  # at the TCP every component has a lever
    # a zero-length tool is the MCP evaluation
    mcp = results[GANTRY / "machine.toml"]["cases"][0]["volumetric"]["accuracy_um"]
    assert doc["cases"][0]["volumetric"]["accuracy_um"] == pytest.approx(mcp, abs=1e-9)


def test_gantry_readme_quotes_the_results(results):
    readme = (GANTRY / "README.md").read_text(encoding="utf-8")
    figures = [
        c["volumetric"]["accuracy_um"] for c in results[GANTRY / "machine-tcp.toml"]["cases"]
    ]
    figures.append(results[GANTRY / "machine.toml"]["worst"]["accuracy_um"])
    for value in figures:
        assert f"{value:.1f} µm" in readme


# -- generators are deterministic ----------------------------------------------------------


@pytest.mark.parametrize("folder", [GANTRY, STUDY], ids=lambda f: f.name)
def test_generator_reproduces_the_files(folder, tmp_path):
    written = _generator(folder).write_files(tmp_path)
    names = {p.name for p in written}
    shipped = {p.name for p in folder.iterdir() if re.fullmatch(r".*\.(rtl|rta|st[xyz])", p.name)}
    assert names == shipped
    for name in sorted(names):
        assert (tmp_path / name).read_bytes() == (folder / name).read_bytes(), name


# -- Longstaff (2002), 4.01: uncertainty by pure addition -----------------------------------


def test_study_files_hold_the_thesis_values():
    """4.01.2.1 a-c: forward runs +U, reverse runs -U."""
    linear = load_profile(STUDY / "X-linear.rtl")
    assert linear.targets_mm.tolist() == [0.0, 500.0, 1000.0]
    assert linear.mean("forward").tolist() == [0.0, 4.0, 8.0]
    assert linear.mean("backward").tolist() == [0.0, -4.0, -8.0]
    angular = load_profile(STUDY / "Y-angular-Z.rta")
    assert angular.mean("forward").tolist() == [4.0, 4.0, 4.0]
    assert angular.mean("backward").tolist() == [-4.0, -4.0, -4.0]
    straightness = load_profile(STUDY / "Z-straightness-X.stz")
    assert straightness.targets_mm.tolist() == [-0.001, 0.0, 500.0, 1000.0, 1000.001]
    assert straightness.mean("forward").tolist() == [0.0, 4.0, 4.0, 4.0, 0.0]
    # the end-point line of the bidirectional mean (all zero) is zero: 4 µm stays
    fitted = straightness.without_slope("endpoint")
    assert fitted.mean("forward").tolist() == [0.0, 4.0, 4.0, 4.0, 0.0]


def test_study_at_the_origin_gives_table_4_3(results):
    """Offsets 0, 1 m³: thesis table 4.3 prints 60.0 µm.

    At X = Y = Z = 1000 mm (levers 1 m), eq. 3.1 with B = X, M = Y, T = Z adds
    X: 8 + 4 + 4 + 4 + 4 + 4 + 10 + 10 = 48 µm (linear, 2 straightness, 3 angles, 2 squareness)
    Y: 8 + 4 + 4 + 4 + 4 + 10 = 34 µm
    Z: 8 + 4 + 4 - 4 = 12 µm
    and sqrt(48² + 34² + 12²) = sqrt(3604) = 60.03 µm.
    """
    config = STUDY / "machine.toml"
    volumetric = results[config]["cases"][0]["volumetric"]
    assert round(volumetric["accuracy_um"], 1) == 60.0
    assert volumetric["accuracy_um"] == pytest.approx(math.sqrt(48**2 + 34**2 + 12**2), abs=1e-6)
    assert volumetric["at"] == {"X": 1000.0, "Y": 1000.0, "Z": 1000.0}
    case = _point(config, 1000, 1000, 1000)
    assert case["errors_um"] == pytest.approx({"X": 48.0, "Y": 34.0, "Z": 12.0}, abs=1e-9)


def test_study_measured_centrally_gives_table_4_3(results):
    """Offsets 500 mm, 1 m³: thesis table 4.3 prints 43.0 µm.

    At X = Y = Z = 1000 mm every lever is 1000 - 500 = 500 mm, so each angle gives 2 µm and
    each squareness 5 µm:
    X: 8 + 4 + 4 + 3 x 2 + 2 x 5 = 32 µm
    Y: 8 + 4 + 4 + 2 x 2 + 5 = 25 µm
    Z: 8 + 4 + 4 - 2 = 14 µm
    and sqrt(32² + 25² + 14²) = sqrt(1845) = 42.95 µm.
    """
    config = STUDY / "machine-central.toml"
    volumetric = results[config]["cases"][0]["volumetric"]
    assert round(volumetric["accuracy_um"], 1) == 43.0
    assert volumetric["accuracy_um"] == pytest.approx(math.sqrt(32**2 + 25**2 + 14**2), abs=1e-6)
    case = _point(config, 1000, 1000, 1000)
    assert case["errors_um"] == pytest.approx({"X": 32.0, "Y": 25.0, "Z": 14.0}, abs=1e-9)


@pytest.mark.parametrize(
    "name, printed",
    [
        ("machine-statistical.toml", 26.2),  # table 4.4, measured at the origin, 1 m³
        ("machine-statistical-central.toml", 19.7),  # table 4.4, measured centrally, 1 m³
    ],
)
def test_study_statistical_method_gives_table_4_4(results, name, printed):
    """The same files as expanded uncertainties of a planning study (no error data): the
    root-sum-square per direction, then the vector sum. At (1000, 1000, 1000), offsets 0:
    X² = 8² + 2·4² + 3·4² + 2·10² = 344, Y² = 8² + 2·4² + 2·4² + 10² = 228,
    Z² = 8² + 2·4² + 4² = 112; sqrt(684) = 26.15 µm."""
    doc = results[STUDY / name]
    assert doc["analysis"]["plan"] and doc["worst"]["accuracy_um"] is None  # no error data
    u = doc["uncertainty"]
    assert u["method"] == "statistical" and u["k"] == 2.0
    assert round(u["volumetric_um"], 1) == printed
    assert u["at"] == {"X": 1000.0, "Y": 1000.0, "Z": 1000.0}
    assert len(u["budget"]) == 21
    assert sum(b["share_pct"] for b in u["budget"]) == pytest.approx(100.0)


def test_study_summation_is_the_bound_of_the_plan(results):
    """machine-summation.toml: the values of 4.01.2.1 as U, summed as a bound. At the far
    corner every lever is 1 m and every term is U whatever its sign: X 8 + 4 + 4 + 3·4 +
    2·10 = 48, Y 8 + 4 + 4 + 2·4 + 10 = 34, Z 8 + 4 + 4 + 4 = 20 µm; sqrt(3860) = 62.13 µm.
    The pure addition of the same values (machine.toml: 60.03 µm, table 4.3) is one choice
    of signs, below it."""
    doc = results[STUDY / "machine-summation.toml"]
    u = doc["uncertainty"]
    assert doc["analysis"]["plan"] and u["method"] == "summation" and u["bound"] is True
    assert u["volumetric_um"] == pytest.approx(math.sqrt(3860.0), abs=1e-6)
    assert {a: e["max_um"] for a, e in u["axes"].items()} == pytest.approx(
        {"X": 48.0, "Y": 34.0, "Z": 20.0}, abs=1e-6
    )
    assert all(b["share_pct"] >= 0.0 for b in u["budget"])
    assert sum(b["share_pct"] for b in u["budget"]) == pytest.approx(100.0)
    assert results[STUDY / "machine.toml"]["worst"]["accuracy_um"] < u["volumetric_um"]


def test_study_pure_addition_of_the_0_3_m3_cube(results):
    """machine-300-pure-addition.toml: table 4.3, 0.3 m³, 11.1 µm; at (0, 300, 300) with
    the datum at the origin X = 3·1.2 + 2·3 = 9.6, Y = 2·1.2 + 3 = 5.4, Z = -1.2 µm,
    sqrt(122.76) = 11.08 µm."""
    u = results[STUDY / "machine-300-pure-addition.toml"]["uncertainty"]
    assert u["method"] == "pure-addition" and u["bound"] is False
    assert u["volumetric_um"] == pytest.approx(math.sqrt(122.76), abs=1e-6)
