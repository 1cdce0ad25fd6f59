"""SINUMERIK LEC ($AA_ENC_COMP) and CEC ($AN_CEC) part programs: written, read back by a
few lines of their own here (from docs/compensation.md), applied as the control applies
them (linear between equidistant points, ends held, LEC and CEC values errors in mm, CEC
tables per direction of the base axis) and checked against --predict; limits and the
sign option through the command."""

from __future__ import annotations

import re
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner
from test_compensation_apply import AXES, one_datum_errors, small, written

import esp
from esp.cli import main
from esp.compensation.build import BuildOptions, build
from esp.compensation.formats import FormatSettings, read_files, resolution_um, siemens, write_files
from esp.compensation.model import max_difference_um
from esp.compensation.predict import grid_points, predict
from esp.core.errors import DataError, ParseError

GANTRY = Path(__file__).resolve().parent.parent / "data" / "examples" / "gantry" / "machine.toml"
SPACING = {"X": 20.0, "Y": 50.0, "Z": 50.0}


def assignments(text):
    """(variable, indices) -> value of every '$VAR[i,j]=value' line."""
    out = {}
    for line in text.splitlines():
        m = re.match(r"\$(\w+)\[([^\]]*)\]=(\S+)", line)
        if m:
            out[(m.group(1), m.group(2))] = m.group(3)
    return out


def siemens_correction(files, pts, direction, sign=-1.0):
    """The correction (µm) the control adds at the points: LEC and CEC values are errors
    in mm (``sign`` -1), linear between MIN + i STEP, ends held; a CEC table of direction
    1 acts moving forward, -1 backward, 0 always (the mean: half of each)."""
    corr = np.zeros_like(pts)
    lec = assignments(files.get("AX_EEC.INI", ""))
    for key, step in lec.items():
        if key[0] != "AA_ENC_COMP_STEP":
            continue
        ax = key[1].split(",")[1]
        k = int(ax[2:]) - 1
        lo, hi = float(lec[("AA_ENC_COMP_MIN", f"0,{ax}")]), float(lec[("AA_ENC_COMP_MAX", key[1])])
        n = round((hi - lo) / float(step)) + 1
        x = lo + float(step) * np.arange(n)
        v = np.array([float(lec[("AA_ENC_COMP", f"0,{i},{ax}")]) for i in range(n)]) * 1000.0
        corr[:, k] -= np.interp(pts[:, k], x, v)
    cec = assignments(files.get("NC_CEC.INI", ""))
    for key, step in cec.items():
        if key[0] != "AN_CEC_STEP":
            continue
        t = key[1]
        master = int(cec[("AN_CEC_INPUT_AXIS", t)].strip("()")[2:]) - 1
        slave = int(cec[("AN_CEC_OUTPUT_AXIS", t)].strip("()")[2:]) - 1
        lo, hi = float(cec[("AN_CEC_MIN", t)]), float(cec[("AN_CEC_MAX", t)])
        n = round((hi - lo) / float(step)) + 1
        x = lo + float(step) * np.arange(n)
        v = np.array([float(cec[("AN_CEC", f"{t},{i}")]) for i in range(n)]) * 1000.0
        d = int(cec[("AN_CEC_DIRECTION", t)])
        weight = {
            0: 1.0,
            1: {"forward": 1.0, "backward": 0.0, "mean": 0.5}[direction],
            -1: {"forward": 0.0, "backward": 1.0, "mean": 0.5}[direction],
        }[d]
        corr[:, slave] += sign * weight * np.interp(pts[:, master], x, v)
    return corr


def check(machine, fmt, settings=None, **options):
    files, back = written(machine, fmt, settings, **options)
    p = predict(machine, back, resolution_um(fmt, settings), None)
    pts = grid_points(machine, back)
    datum = np.zeros((1, 3))
    reference = machine.analysis.direction
    for d in p.directions:
        c = siemens_correction(files, pts, d.direction)
        c = c - siemens_correction(files, datum, reference)
        r = one_datum_errors(machine, d.direction, pts) + c
        norm = np.linalg.norm(r, axis=1)
        assert d.after_um == pytest.approx(float(norm.max()), abs=1e-9)
        for k, a in enumerate(AXES):
            assert d.axes_after_um[a] == pytest.approx(float(np.abs(r[:, k]).max()), abs=1e-9)
    return files, p


@pytest.mark.parametrize("fmt", ["siemens-lec", "siemens-cec"])
def test_the_residual_is_that_of_the_files_applied_independently(fmt):
    files, p = check(small(), fmt, spacing_mm=SPACING)
    assert p.after_um < p.before_um
    assert ("NC_CEC.INI" in files) == (fmt == "siemens-cec")


def test_lec_holds_the_error_of_the_mean_in_mm_worked_by_hand():
    """X.linear of small(): forward 0, 2.1 at X = 0, 60 and backward 1.2 above; the mean
    is 0.6 at the datum X = 0 and 2.7 at X = 60, so the LEC value at 60 mm is the error
    2.7 - 0.6 = 2.1 µm = 0.0021 mm (a positive value moves the axis back)."""
    tables = build(small(), "siemens-lec", BuildOptions(spacing_mm=SPACING, leave_uncorrected=True))
    e = assignments(write_files(tables)["AX_EEC.INI"])
    assert e[("AA_ENC_COMP_STEP", "0,AX1")] == "20.000000"
    assert e[("AA_ENC_COMP_MIN", "0,AX1")] == "0.000000"
    assert e[("AA_ENC_COMP_MAX", "0,AX1")] == "200.000000"
    assert e[("AA_ENC_COMP_IS_MODULO", "0,AX1")] == "0"
    assert float(e[("AA_ENC_COMP", "0,3,AX1")]) == pytest.approx(0.0021, abs=1e-9)
    assert float(e[("AA_ENC_COMP", "0,0,AX1")]) == pytest.approx(0.0, abs=1e-9)


def test_cec_direction_tables_hold_the_reversal():
    """The reversal of X.linear (backward 1.2 µm above forward) is in the two direction
    tables of X over itself: +0.6 µm and -0.6 µm of error from the mean."""
    tables = build(small(), "siemens-cec", BuildOptions(spacing_mm=SPACING, leave_uncorrected=True))
    e = assignments(write_files(tables)["NC_CEC.INI"])
    own = [
        t
        for (name, t), v in e.items()
        if name == "AN_CEC_INPUT_AXIS" and v == "(AX1)" and e[("AN_CEC_OUTPUT_AXIS", t)] == "(AX1)"
    ]
    directions = {int(e[("AN_CEC_DIRECTION", t)]): t for t in own}
    assert sorted(directions) == [-1, 1]
    assert float(e[("AN_CEC", f"{directions[1]},3")]) == pytest.approx(-0.0006, abs=1e-9)
    assert float(e[("AN_CEC", f"{directions[-1]},3")]) == pytest.approx(0.0006, abs=1e-9)


def test_round_trip_and_sign_option():
    tables = build(small(), "siemens-cec", BuildOptions(spacing_mm=SPACING, leave_uncorrected=True))
    for sign in ("error", "correction"):
        s = FormatSettings(cross_sign=sign)
        back = read_files("siemens-cec", write_files(tables, s), s)
        assert max_difference_um(tables, replace(back, format=tables.format)) <= 0.0005 + 1e-9
    err = write_files(tables, FormatSettings(cross_sign="error"))
    cor = write_files(tables, FormatSettings(cross_sign="correction"))
    assert err["AX_EEC.INI"] == cor["AX_EEC.INI"]  # the LEC sign is documented
    a, b = assignments(err["NC_CEC.INI"]), assignments(cor["NC_CEC.INI"])
    values = [k for k in a if k[0] == "AN_CEC" and float(a[k]) != 0.0]
    assert values and all(float(a[k]) == -float(b[k]) for k in values)


def test_limits_and_equidistant_points():
    machine = small()
    tables = build(machine, "siemens-cec", BuildOptions(spacing_mm=SPACING, leave_uncorrected=True))
    with pytest.raises(DataError, match="MD38000"):
        write_files(tables, FormatSettings(limits={"lec": 10}))
    with pytest.raises(DataError, match="CEC tables"):
        write_files(tables, FormatSettings(limits={"cec_tables": 2}))
    with pytest.raises(DataError, match="equidistant"):
        build(machine, "siemens-lec", BuildOptions(spacing_mm={"X": 30.0}, leave_uncorrected=True))


def test_reader_names_file_and_line():
    text = "%_N_AX_EEC_INI\nCHANDATA(1)\n$AA_ENC_COMP[0,0,AX1]=abc\nM17\n"
    rest = (
        "$AA_ENC_COMP[0,1,AX1]=0\n$AA_ENC_COMP_STEP[0,AX1]=1\n$AA_ENC_COMP_MIN[0,AX1]=0\n"
        "$AA_ENC_COMP_MAX[0,AX1]=1\n$AA_ENC_COMP_IS_MODULO[0,AX1]=0\n"
    )
    with pytest.raises(ParseError, match=r"AX_EEC.INI:3: \$AA_ENC_COMP: expected a number"):
        siemens.read({"AX_EEC.INI": text.replace("M17\n", rest)})
    with pytest.raises(ParseError, match="AX_EEC.INI:5"):
        siemens.read({"AX_EEC.INI": text + "nonsense\n"})


def test_command_refuses_in_one_line():
    runner = CliRunner()
    args = ["compensate", str(GANTRY), "--format", "siemens-lec", "--leave-uncorrected"]
    r = runner.invoke(main, [*args, "--max-points", "lec=5"])
    assert r.exit_code == 2
    assert r.output.strip().count("\n") == 0 and "MD38000" in r.output
    r = runner.invoke(main, [*args, "--spacing", "X=30"])
    assert r.exit_code == 2 and "equidistant" in r.output
    r = runner.invoke(main, [*args, "--max-points", "nope=5"])
    assert r.exit_code == 2 and "lec" in r.output


def test_cec_holds_every_straightness_and_squareness():
    """Several CEC tables may correct one axis (their values add up), so every
    straightness and squareness of the gantry is held, one table per compensation axis and
    base axis (six); only the angular components stay (no axis table holds them), where
    one cross table per axis (kw.crosscomp) leaves three straightnesses and two
    squarenesses."""
    machine = esp.load_machine(GANTRY)
    options = BuildOptions(leave_uncorrected=True)
    cec = build(machine, "siemens-cec", options)
    assert cec.uncorrected and all(".angular." in name for name in cec.uncorrected)
    pairs = [(t.slave, t.master) for t in cec.axis_tables if t.kind == "cross"]
    assert len(pairs) == len(set(pairs)) == 6
    one = build(machine, "twincat-cross", options)
    left = set(one.uncorrected) - set(cec.uncorrected)
    assert {n.split(".")[0] if n.startswith("squareness") else n.split(".")[1] for n in left} == {
        "straightness",
        "squareness",
    }
