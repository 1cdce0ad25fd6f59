"""The reversal at the datum reaches the tables: both directions of approach are referred to
one datum (the analysis direction's error there), so the difference of the forward and the
backward table is the reversal everywhere, the datum included, whatever
``[analysis] direction`` and ``datum`` say; and ``--predict`` shows it."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner
from conftest import build_machine

from esp.cli import main
from esp.compensation.build import build
from esp.compensation.formats import read_files, resolution_um, write_files
from esp.compensation.predict import predict
from esp.core.profile import ErrorProfile
from esp.io.load import load_profile
from esp.iso230.positioning import iso230_2

GANTRY = Path(__file__).resolve().parent.parent / "data" / "examples" / "gantry" / "machine.toml"
#: the constant reversal of the hand-made profile, µm (backward minus forward)
REVERSAL_UM = 2.0
#: its slope, µm/mm: the forward error is SLOPE * x
SLOPE = 0.01


def machine(direction="mean", datum="negative"):
    """X positioning error measured 0 to 200 mm: forward e(x) = 0.01 x µm, backward
    e(x) = 0.01 x + 2 µm, a constant reversal of 2 µm."""
    targets = [0.0, 50.0, 100.0, 150.0, 200.0]
    forward = [SLOPE * x for x in targets]
    runs = {"forward": [forward], "backward": [[v + REVERSAL_UM for v in forward]]}
    profile = ErrorProfile("linear", targets, runs, axis="X")
    return build_machine(
        {"X.linear": profile}, travel=(0.0, 200.0), step=50.0, direction=direction, datum=datum
    )


#: the analysis direction's error at the datum (x = 0 for "negative", 100 for "centre")
def reference_um(direction, datum):
    x = {"negative": 0.0, "centre": 100.0}[datum]
    shift = {"forward": 0.0, "backward": REVERSAL_UM, "mean": REVERSAL_UM / 2}[direction]
    return SLOPE * x + shift


@pytest.mark.parametrize("datum", ["negative", "centre"])
@pytest.mark.parametrize("direction", ["forward", "backward", "mean"])
@pytest.mark.parametrize("fmt", ["linuxcnc", "twincat-lead"])
def test_the_tables_hold_the_reversal_at_the_datum(fmt, direction, datum):
    m = machine(direction, datum)
    tables = build(m, fmt)
    back = read_files(fmt, write_files(tables))  # as written, in the file's unit
    (lead,) = back.axis_tables
    x = lead.positions_mm
    ref = reference_um(direction, datum)
    tol = resolution_um(fmt) / 2 + 1e-9
    # the correction of each direction is minus its error relative to the one reference
    assert lead.forward_um == pytest.approx(-(SLOPE * x - ref), abs=tol)
    assert lead.backward_um == pytest.approx(-(SLOPE * x + REVERSAL_UM - ref), abs=tol)
    # at the datum (the first point for "negative") the two columns differ by the reversal
    assert lead.forward_um[0] - lead.backward_um[0] == pytest.approx(REVERSAL_UM, abs=2 * tol)


@pytest.mark.parametrize("direction", ["forward", "backward", "mean"])
def test_predict_shows_the_reversal(direction):
    """Before: each direction's error relative to the one datum holds the reversal; a
    bidirectional table removes it; a component table (one direction's curves) leaves the
    part of the reversal its direction does not hold."""
    m = machine(direction)
    ref = reference_um(direction, "negative")
    x = np.array([0.0, 200.0])
    before = {
        "forward": np.abs(SLOPE * x - ref).max(),
        "backward": np.abs(SLOPE * x + REVERSAL_UM - ref).max(),
    }
    kept = {"forward": 0.0, "backward": REVERSAL_UM, "mean": REVERSAL_UM / 2}[direction]
    left = {"forward": kept, "backward": abs(REVERSAL_UM - kept)}
    for fmt in ("linuxcnc", "iso-csv"):
        tables = build(m, fmt)
        p = predict(m, read_files(fmt, write_files(tables)), resolution_um(fmt))
        assert [d.direction for d in p.directions] == ["forward", "backward"]
        for d in p.directions:
            assert d.before_um == pytest.approx(before[d.direction], abs=1e-9)
            expected = 0.0 if fmt == "linuxcnc" else left[d.direction]
            assert d.after_um == pytest.approx(expected, abs=resolution_um(fmt) + 1e-9)


def test_without_a_datum_the_tables_are_the_raw_errors():
    (lead,) = build(machine("mean", "none"), "linuxcnc").axis_tables
    assert lead.forward_um == pytest.approx(-SLOPE * lead.positions_mm, abs=1e-12)
    assert lead.backward_um == pytest.approx(-SLOPE * lead.positions_mm - REVERSAL_UM, abs=1e-12)


@pytest.mark.slow
def test_the_gantry_linuxcnc_file_holds_the_reversal_at_x0(tmp_path):
    """The issue's command: the first line of X.comp differs between the two directions by
    the file's reversal at X = 0 (ISO 230-2 B_i = x̄↑ - x̄↓; trim = minus the error, so
    forward trim - backward trim = x̄↓ - x̄↑ = -B_i)."""
    out = tmp_path / "c"
    result = CliRunner().invoke(
        main,
        ["compensate", str(GANTRY), "--format", "linuxcnc", "--leave-uncorrected"]
        + ["--out", str(out), "-q"],
    )
    assert result.exit_code == 0, result.output
    first = (out / "linuxcnc" / "X.comp").read_text().splitlines()[0].split()
    nominal, forward_mm, backward_mm = (float(v) for v in first)
    iso = iso230_2(load_profile(GANTRY.parent / "X-linear.rtl"))
    assert nominal == 0.0
    b0_um = float(iso.B_i[0])
    assert abs(b0_um) > 2.0  # the file's reversal at X = 0 (about 2.3 µm)
    assert (forward_mm - backward_mm) * 1000.0 == pytest.approx(-b0_um, abs=0.002)
