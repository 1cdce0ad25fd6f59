"""Two calibrations of one machine: a machine against itself, a change by hand, machines
that are not one machine, the shipped second calibration of the gantry."""

from __future__ import annotations

import importlib.util
import json
import re
import sys
from dataclasses import replace
from pathlib import Path

import pytest
from click.testing import CliRunner
from conftest import build_machine

import esp
from esp.cli import main
from esp.compare.model import check_same_machine, compare, component_change
from esp.core.errors import DataError

EXAMPLES = Path(__file__).resolve().parent.parent / "data" / "examples"
GANTRY = EXAMPLES / "gantry" / "machine.toml"
LATER = EXAMPLES / "gantry-2024" / "machine.toml"


def test_a_machine_against_itself_has_no_change():
    m = esp.load_machine(GANTRY)
    c = compare(m, m)
    assert all(x.max_abs_change == 0.0 for x in c.components)
    assert len(c.components) == 21
    assert c.field["max_um"] == 0.0
    assert c.volumetric_change_um == 0.0


def test_a_change_by_hand():
    """X positioning 10 -> 13 µm over 1000 mm; squareness XY 2 -> 5 µm/m; the field at the
    far corner changes by 3 µm in X and by the squareness over its lever."""
    before = build_machine({"X.linear": [(0.0, 0.0), (1000.0, 10.0)], "squareness.XY": 2.0})
    after = build_machine({"X.linear": [(0.0, 1.0), (1000.0, 14.0)], "squareness.XY": 5.0})
    x = component_change(before, after, "X.linear")
    # both referred to their first point: 0..10 and 0..13
    assert x.max_abs_change == pytest.approx(3.0)
    assert x.at_mm == 1000.0
    assert (x.range_before, x.range_after) == (10.0, 13.0)
    sq = component_change(before, after, "squareness.XY")
    assert sq.max_abs_change == pytest.approx(3.0) and sq.at_mm is None
    c = compare(before, after)
    import numpy as np

    g = [before.axes[a].grid_mm() for a in "XYZ"]
    pts = np.stack([m.ravel() for m in np.meshgrid(*g, indexing="ij")], axis=1)
    delta = esp.errors_at(after, pts) - esp.errors_at(before, pts)
    norm = np.linalg.norm(delta, axis=1)
    assert c.field["max_um"] == pytest.approx(norm.max())
    i = int(np.argmax(norm))
    assert c.field["at"] == {a: pts[i, k] for k, a in enumerate("XYZ")}
    # X error: +1 µm offset and +3 µm/1000 mm; the squareness adds 3 µm/m over a lever
    assert c.field["directions"]["X"]["value_um"] == pytest.approx(
        float(delta[np.argmax(np.abs(delta[:, 0])), 0])
    )


def test_a_component_of_one_calibration_only_counts_as_zero_in_the_other():
    before = build_machine({"X.linear": [(0.0, 0.0), (1000.0, 10.0)]})
    after = build_machine({"X.linear": [(0.0, 0.0), (1000.0, 10.0)], "Y.angular.Z": 4.0})
    change = component_change(before, after, "Y.angular.Z")
    assert (change.present_before, change.present_after) == (False, True)
    assert change.max_abs_change == 0.0  # a constant angle, referred to its first point


@pytest.mark.parametrize(
    "other, fragment",
    [
        (dict(configuration="BwMTt"), "configuration wBMTt against BwMTt"),
        (dict(roles=("Y", "X", "Z")), "axes"),
        (dict(travel=(0.0, 900.0)), "axes.X.travel"),
    ],
)
def test_two_machines_are_refused(other, fragment):
    a = build_machine({"X.linear": 1.0})
    b = build_machine({"X.linear": 1.0}, **other)
    with pytest.raises(DataError, match=re.escape(fragment)):
        check_same_machine(a, b)


def test_two_serial_numbers_are_refused():
    a = replace(build_machine({}), info={"serial": "A-1"})
    b = replace(build_machine({}), info={"serial": "B-2"})
    with pytest.raises(DataError, match="serial A-1 against B-2"):
        compare(a, b)


def run(*args):
    return CliRunner().invoke(main, [str(a) for a in args])


@pytest.mark.slow
def test_the_shipped_recalibration(tmp_path):
    out = tmp_path / "drift"
    result = run("compare", GANTRY, LATER, "--out", out, "--json", tmp_path / "c.json")
    assert result.exit_code == 0, result.output
    doc = json.loads((tmp_path / "c.json").read_text())
    assert doc["schema"] == "esp.compare/1"
    by = {c["component"]: c for c in doc["components"]}
    # the changes the generator made stand out above the re-measurement noise (0.15)
    largest = sorted(by.values(), key=lambda c: -c["max_abs_change"])
    um = [c["component"] for c in largest if c["unit"] == "um"][:3]
    assert um == ["Y.linear", "Z.linear", "X.straightness.Z"]
    assert by["squareness.XY"]["max_abs_change"] == pytest.approx(1.5)
    assert by["Y.angular.X"]["max_abs_change"] > 1.0
    assert doc["volumetric"]["after_um"] > doc["volumetric"]["before_um"]
    for name in ("compare.json", "compare.txt", "compare-components.png", "compare-curves.png"):
        assert (out / name).is_file()


def test_command_refuses_another_machine(tmp_path):
    other = tmp_path / "m.toml"
    text = GANTRY.read_text().replace('configuration = "wBMTt"', 'configuration = "BwMTt"')
    other.write_text(text)
    for p in GANTRY.parent.glob("*.r*"):
        (tmp_path / p.name).write_bytes(p.read_bytes())
    for p in GANTRY.parent.glob("*.st?"):
        (tmp_path / p.name).write_bytes(p.read_bytes())
    result = run("compare", GANTRY, other)
    assert result.exit_code == 2, result.output
    assert result.stderr == "esp: error: not the same machine: configuration wBMTt against BwMTt\n"


def test_generator_reproduces_the_files(tmp_path):
    folder = LATER.parent
    spec = importlib.util.spec_from_file_location("_later_make", folder / "make_data.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules["_later_make"] = module
    try:
        spec.loader.exec_module(module)
    finally:
        del sys.modules["_later_make"]
    written = module.write_files(tmp_path)
    shipped = {p.name for p in folder.iterdir() if re.fullmatch(r".*\.(rtl|rta|st[xyz])", p.name)}
    assert {p.name for p in written} == shipped
    for p in written:
        assert p.read_bytes() == (folder / p.name).read_bytes(), p.name


# -- like with like ---------------------------------------------------------------------


@pytest.mark.parametrize(
    ("other", "message"),
    [
        ("five-axis/machine.toml", "analysis.point is 'MCP' before and 'TCP' after"),
        ("gantry/machine-tcp.toml", "analysis.point is 'MCP' before and 'TCP' after"),
    ],
)
@pytest.mark.slow
def test_two_different_evaluations_are_refused(other, message):
    """gantry against five-axis showed +161.22 µm volumetric but a field change of 1.83
    µm; machine.toml against machine-tcp.toml +1.54 µm but 0.00 µm: they are not one
    evaluation, so they are refused with what differs, on the command line in one line."""
    with pytest.raises(DataError, match=re.escape(message)):
        compare(esp.load_machine(GANTRY), esp.load_machine(EXAMPLES / other))
    r = CliRunner().invoke(main, ["compare", str(GANTRY), str(EXAMPLES / other)])
    assert r.exit_code == 2
    assert len(r.stderr.strip().splitlines()) == 1 and "not comparable" in r.stderr


def test_a_head_against_a_plain_tool_is_refused():
    tcp = esp.load_machine(EXAMPLES / "gantry" / "machine-tcp.toml")
    with pytest.raises(DataError, match="with a head or rotary table after|without a head"):
        compare(tcp, esp.load_machine(EXAMPLES / "five-axis" / "machine.toml"))


def test_a_different_grid_or_tool_is_refused():
    m = build_machine({"X.linear": [(0.0, 0.0), (1000.0, 10.0)]})
    axes = dict(m.axes)
    axes["X"] = replace(axes["X"], step_mm=axes["X"].step_mm / 2)
    with pytest.raises(DataError, match="simulation grid of X differs"):
        compare(m, replace(m, axes=axes))


@pytest.mark.slow
def test_the_field_change_bounds_the_change_of_the_accuracy():
    """Both accuracies are maxima over one grid of the same case, so |Δ volumetric| <=
    max |Δe| (triangle inequality); the shipped recalibration, and a change by hand."""
    c = compare(esp.load_machine(GANTRY), esp.load_machine(LATER))
    assert abs(c.volumetric_change_um) <= c.field["max_um"] + 1e-9
    for plane, before in c.planar_before.items():
        assert abs(c.planar_after[plane] - before) <= c.field["max_um"] + 1e-9
    before = build_machine({"X.linear": [(0.0, 0.0), (1000.0, 10.0)], "squareness.XY": 2.0})
    after = build_machine({"X.linear": [(0.0, 5.0), (1000.0, -4.0)], "squareness.XY": -7.0})
    c = compare(before, after)
    assert abs(c.volumetric_change_um) <= c.field["max_um"] + 1e-9


def test_compare_a_with_a_says_the_inputs_are_identical():
    r = CliRunner().invoke(main, ["compare", str(GANTRY), str(GANTRY), "--json", "-"])
    assert r.exit_code == 0, r.output
    doc = json.loads(r.output)
    assert doc["identical_inputs"] is True and doc["unchanged"] is True
    r = CliRunner().invoke(main, ["compare", str(GANTRY), str(GANTRY)])
    assert "identical inputs (the same files, byte for byte)" in r.output.splitlines()[3]


def test_identical_inputs_are_byte_for_byte_copies(tmp_path):
    """A copy of the folder is identical; with one reading file a byte longer it is not,
    although nothing changed (said as "no change"); two calibrations are neither."""
    import shutil

    from esp.compare.model import identical_inputs
    from esp.compare.text import compare_dict, compare_text

    copy = tmp_path / "copy"
    shutil.copytree(GANTRY.parent, copy)
    gantry = esp.load_machine(GANTRY)
    assert identical_inputs(gantry, esp.load_machine(copy / "machine.toml"))
    rtl = copy / "X-linear.rtl"
    rtl.write_text(rtl.read_text(encoding="utf-8") + "\n", encoding="utf-8")
    changed = esp.load_machine(copy / "machine.toml")
    assert not identical_inputs(gantry, changed)
    c = compare(gantry, changed)
    assert not c.identical_inputs and c.unchanged
    assert "  no change: every component" in compare_text(gantry, changed, c)
    assert not identical_inputs(gantry, esp.load_machine(LATER))
    assert not identical_inputs(build_machine(), build_machine())  # no inputs named
    later = compare(gantry, esp.load_machine(LATER))
    doc = compare_dict(gantry, esp.load_machine(LATER), later)
    assert doc["identical_inputs"] is False and doc["unchanged"] is False
