"""ISO 230-6 diagonals: the prediction is the projection of esp.errors_at, a single
component gives its term by hand, the check and its verdict, bad files, the example."""

from __future__ import annotations

import importlib.util
import json
import math
import sys
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner
from conftest import build_machine

import esp
from esp.cli import main
from esp.core.errors import DataError
from esp.core.profile import ErrorProfile
from esp.core.uncertainty.spec import ComponentU, UncertaintySpec
from esp.diagonals.model import (
    body_diagonals,
    check_diagonal,
    default_step,
    diagonal_targets,
    face_diagonals,
    predict_diagonal,
    prediction_uncertainty,
)
from esp.io.load import load_profile

EXAMPLES = Path(__file__).resolve().parent.parent / "data" / "examples"
GANTRY = EXAMPLES / "gantry" / "machine.toml"
MEASURED = EXAMPLES / "gantry-diagonals"


@pytest.fixture(scope="module")
def gantry():
    return esp.load_machine(GANTRY)


@pytest.mark.slow
def test_names_and_corners(gantry):
    d = {x.name: x for x in body_diagonals(gantry)}
    assert list(d) == ["PPP", "NPP", "PNP", "PPN"]
    assert d["PPP"].start_mm == (0.0, 0.0, 0.0) and d["PPP"].end_mm == (1000.0, 1500.0, 600.0)
    assert d["NPP"].start_mm == (1000.0, 0.0, 0.0) and d["NPP"].end_mm == (0.0, 1500.0, 600.0)
    assert d["PPN"].start_mm == (0.0, 0.0, 600.0)
    assert d["PPP"].length_mm == pytest.approx(1900.0)  # 1000² + 1500² + 600² = 1900²
    faces = {x.name: x for x in face_diagonals(gantry, {"Z": 300.0})}
    assert sorted(faces) == ["XY-NP", "XY-PP", "XZ-NP", "XZ-PP", "YZ-NP", "YZ-PP"]
    assert faces["XY-NP"].start_mm == (1000.0, 0.0, 300.0)
    assert default_step(body_diagonals(gantry)) == 95.0
    assert diagonal_targets(d["PPP"], 95.0).size == 21
    assert diagonal_targets(d["PPP"], 400.0).tolist() == [0.0, 400.0, 800.0, 1200.0, 1600.0, 1900.0]


@pytest.mark.parametrize("name", ["PPP", "NPP", "PNP", "PPN"])
def test_prediction_is_the_projection_of_errors_at(gantry, name):
    d = next(x for x in body_diagonals(gantry) if x.name == name)
    s = diagonal_targets(d, 190.0)
    e = esp.errors_at(gantry, d.points(s))
    expected = (e - e[0]) @ d.direction
    assert np.allclose(predict_diagonal(gantry, d, s), expected, atol=1e-12)


def test_single_linear_component_by_hand():
    """Only X.linear, 10 µm over 1000 mm of a 1000 mm cube: along PPP x = s/√3 and the
    displacement along the diagonal is EXX·cos θ = EXX/√3; at the end 10/√3 µm."""
    m = build_machine({"X.linear": [(0.0, 0.0), (1000.0, 10.0)]}, travel=(0.0, 1000.0))
    d = body_diagonals(m)[0]
    s = np.array([0.0, 500.0 * math.sqrt(3), 1000.0 * math.sqrt(3)])
    assert predict_diagonal(m, d, s) == pytest.approx(
        [0.0, 5.0 / math.sqrt(3), 10.0 / math.sqrt(3)]
    )
    # NPP runs X down: the same error, now against the direction, from x = 1000
    npp = body_diagonals(m)[1]
    assert predict_diagonal(m, npp, s)[-1] == pytest.approx(10.0 / math.sqrt(3))


def test_prediction_uncertainty_of_one_component_by_hand():
    """U = 4 µm (k = 2) on X.linear alone: u = 2 µm along X, 2/√3 µm along PPP."""
    m = build_machine({"X.linear": 0.0}, travel=(0.0, 1000.0))
    cu = ComponentU("X.linear", "linear", "X", None, "direct", "um", "normal", U=4.0)
    from dataclasses import replace

    m = replace(m, uncertainty=UncertaintySpec(k=2.0, components={"X.linear": cu}))
    d = body_diagonals(m)[0]
    u = prediction_uncertainty(m, d, [0.0, 800.0, 1700.0])
    assert u == pytest.approx([2.0 / math.sqrt(3)] * 3)


def measured_profile(d, s, values, **kw):
    runs = np.tile(np.asarray(values, dtype=float), (2, 1))
    return ErrorProfile(
        "linear", s, {"forward": runs, "backward": runs}, source=f"{d.name}.rtl", **kw
    )


def test_check_by_hand():
    m = build_machine({"X.linear": [(0.0, 0.0), (1000.0, 10.0)]}, travel=(0.0, 1000.0))
    d = body_diagonals(m)[0]
    s = diagonal_targets(d, 1000.0)  # 0, 1000, 1732.05 mm
    predicted = predict_diagonal(m, d, s)
    measured = predicted + np.array([0.0, 1.0, -3.0]) + 5.0  # +5: a laser zero
    c = check_diagonal(m, d, measured_profile(d, s, measured), 1000.0, U_measurement_um=2.0)
    assert c.difference_um == pytest.approx([0.0, 1.0, -3.0])
    # U = 2·sqrt((2/2)²) = 2 µm: E_n = 0, 0.5, 1.5
    assert c.U_um == pytest.approx([2.0, 2.0, 2.0])
    assert c.En == pytest.approx([0.0, 0.5, 1.5])
    assert c.explained is False
    c = check_diagonal(m, d, measured_profile(d, s, measured), 1000.0, 2.0, 1.0)
    # U = 2 + 1·s/1000 µm: at 1732 mm 3.732, E_n = 3/3.732
    assert c.max_En == pytest.approx(3.0 / (2.0 + math.sqrt(3)))
    assert c.explained is True
    c = check_diagonal(m, d, measured_profile(d, s, measured), 1000.0)
    assert c.En is None and c.explained is None


def test_files_that_do_not_fit_the_volume_are_refused():
    m = build_machine({"X.linear": 1.0}, travel=(0.0, 1000.0))
    d = body_diagonals(m)[0]
    short = np.array([0.0, 500.0, 1000.0])
    with pytest.raises(DataError, match="runs from 0 to 1000 mm"):
        check_diagonal(m, d, measured_profile(d, short, [0, 0, 0]), 500.0)
    s = diagonal_targets(d, 500.0)
    with pytest.raises(DataError, match="every 400 mm"):
        check_diagonal(m, d, measured_profile(d, s, np.zeros(s.size)), 400.0)


def run(*args):
    return CliRunner().invoke(main, [str(a) for a in args])


def example_args():
    out = []
    for n in ("PPP", "NPP", "PNP", "PPN"):
        out += ["--measured", f"{n}={MEASURED / (n + '.rtl')}"]
    return out


@pytest.mark.slow
def test_example_measurements_are_explained_with_their_uncertainty(tmp_path):
    result = run(
        "diagonals",
        GANTRY,
        *example_args(),
        "--measurement-u",
        "1.0",
        "--measurement-u-per-m",
        "0.5",
        "--json",
        "-",
    )
    assert result.exit_code == 0, result.output
    doc = json.loads(result.stdout)
    assert doc["schema"] == "esp.diagonals/1"
    assert doc["step_mm"] == 95.0
    assert doc["verdict"] is True
    worst = max(c["max_abs_difference_um"] for c in doc["checks"])
    assert 1.0 < worst < 2.0  # the slightly different error set shows
    # without the components' U (the example's [uncertainty] left out) and with a tight
    # measurement U, the difference shows
    bare = tmp_path / "gantry"
    bare.mkdir()
    for f in GANTRY.parent.iterdir():
        if f.is_file():
            (bare / f.name).write_bytes(f.read_bytes())
    text = GANTRY.read_text(encoding="utf-8").split("\n[uncertainty]")[0]
    (bare / "machine.toml").write_text(text, encoding="utf-8")
    tight = run("diagonals", bare / "machine.toml", *example_args(), "--measurement-u", "0.3")
    assert tight.exit_code == 0
    assert "does NOT explain" in tight.stdout


@pytest.mark.slow
def test_command_report_folder_and_faces(tmp_path):
    out = tmp_path / "d"
    result = run("diagonals", GANTRY, "--out", out, "-q")
    assert result.exit_code == 0, result.output
    assert sorted(p.name for p in out.iterdir() if not p.name.startswith(".")) == [
        "diagonals.json",
        "diagonals.png",
        "diagonals.txt",
        "report.pdf",
    ]
    assert (out / "diagonals.png").read_bytes().startswith(b"\x89PNG")
    faces = run("diagonals", GANTRY, "--faces", "--face-at", "Z=300", "--json", "-")
    assert faces.exit_code == 0, faces.output
    names = [d["name"] for d in json.loads(faces.stdout)["diagonals"]]
    assert names[:4] == ["PPP", "NPP", "PNP", "PPN"] and len(names) == 10


def test_command_reads_a_csv_diagonal(tmp_path, gantry):
    d = body_diagonals(gantry)[0]
    s = diagonal_targets(d, 95.0)
    values = predict_diagonal(gantry, d, s)
    path = tmp_path / "ppp.csv"
    rows = ["target_mm,run,direction,deviation"] + [
        f"{t:.4f},1,forward,{v:.4f}" for t, v in zip(s, values, strict=True)
    ]
    path.write_text("\n".join(rows) + "\n")
    result = run(
        "diagonals", GANTRY, "--measured", f"PPP={path}", "--measurement-u", "0.5", "--json", "-"
    )
    assert result.exit_code == 0, result.output
    check = json.loads(result.stdout)["checks"][0]
    assert check["max_abs_difference_um"] < 1e-3


@pytest.mark.parametrize(
    "args, fragment",
    [
        (["--measured", "QQQ=x.rtl"], "unknown diagonal"),
        (["--measured", "PPP"], "NAME=FILE"),
        (["--measured", "PPP=" + str(MEASURED / "PPP.rtl"), "--step", "100"], "every 100 mm"),
        (["--measurement-u", "-1"], "--measurement-u"),
        (["--measured", "PPP=missing.rtl"], "missing.rtl"),
    ],
)
@pytest.mark.slow
def test_bad_input_is_one_line(args, fragment):
    result = run("diagonals", GANTRY, *args)
    assert result.exit_code == 2, result.output
    assert result.stderr.startswith("esp: error: ") and result.stderr.count("\n") == 1
    assert fragment in result.stderr


def test_a_file_of_another_volume_is_refused(tmp_path):
    other = build_machine({"X.linear": 1.0}, travel=(0.0, 500.0))
    d = body_diagonals(other)[0]
    s = diagonal_targets(d, 95.0)
    from esp.io.laser10 import write_laser10

    write_laser10(tmp_path / "PPP.rtl", measured_profile(d, s, np.zeros(s.size)))
    result = run("diagonals", GANTRY, "--measured", f"PPP={tmp_path / 'PPP.rtl'}")
    assert result.exit_code == 2
    assert "the PPP diagonal of this volume runs from 0 to 1900.000 mm" in result.stderr


def test_generator_reproduces_the_files(tmp_path):
    spec = importlib.util.spec_from_file_location("_diag_make", MEASURED / "make_data.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules["_diag_make"] = module
    try:
        spec.loader.exec_module(module)
    finally:
        del sys.modules["_diag_make"]
    written = module.write_files(tmp_path)
    assert [p.name for p in written] == ["PPP.rtl", "NPP.rtl", "PNP.rtl", "PPN.rtl"]
    for p in written:
        assert p.read_bytes() == (MEASURED / p.name).read_bytes(), p.name
    assert load_profile(MEASURED / "PPP.rtl", kind="linear").run_count("forward") == 3
