"""The Etalon Exchange format (Vendor variant) for the ISG volumetric compensation:
written, read back by a few lines of their own here, applied through the machine's model
as the controller does (the component tables linear, ends held, nothing refitted) and
checked against --predict; the reusable block parser and its errors."""

from __future__ import annotations

import numpy as np
import pytest
from test_compensation_apply import (
    _SQUARENESS,
    AXES,
    _name,
    model_of,
    one_datum_errors,
    small,
    written,
)

import esp
from esp.compensation.build import BuildOptions, build
from esp.compensation.formats import FormatSettings, read_files, write_files
from esp.compensation.formats.etalon import parse_exchange
from esp.compensation.model import max_difference_um
from esp.compensation.predict import grid_points, predict
from esp.core.errors import ParseError

SPACING = {"X": 25.0, "Y": 50.0, "Z": 50.0}


def etalon_components(text):
    """component -> (positions mm, values µm or µm/m); squareness -> µm/m."""
    curves, squareness, name, rows = {}, {}, None, None
    for raw in text.splitlines():
        line = raw.split("//")[0].strip()
        if not line:
            continue
        if line.startswith("["):
            name = line[1:-1]
        elif line.startswith("VALUE"):
            sq, sign = _SQUARENESS[name]
            squareness[sq] = sign * float(line.split("=")[1]) * 1e6
        elif line.startswith("Gridpoints"):
            rows = []
        elif line == "}":
            data = np.array(rows)
            unit = 1e3 if name[1] in AXES else 1e6  # mm -> µm, rad -> µm/m
            curves[_name(name[1], name[2])] = (data[:, 0], data[:, 1] * unit)
        else:
            rows.append([float(v) for v in line.split()])
    return curves, squareness


def test_the_residual_is_that_of_the_file_applied_independently():
    machine = small()
    files, back = written(machine, "etalon", spacing_mm=SPACING)
    p = predict(machine, back, 0.001)
    pts = grid_points(machine, back)
    curves, squareness = etalon_components(files["etalon_exchange.txt"])
    model = model_of(machine, curves, squareness)
    c = -np.asarray(esp.errors_at(model, pts))
    c0 = -np.asarray(esp.errors_at(model, np.zeros((1, 3))))
    for d in p.directions:
        r = one_datum_errors(machine, d.direction, pts) + c - c0
        assert d.after_um == pytest.approx(float(np.linalg.norm(r, axis=1).max()), abs=1e-9)
    assert p.after_um < p.before_um


def test_same_content_as_the_isg_csv_and_round_trip():
    """The Etalon file carries exactly what volcomp.csv carries (the same parameters and
    units), and reads back to the tables built."""
    options = BuildOptions(spacing_mm=SPACING, leave_uncorrected=True)
    tables = build(small(), "etalon", options)
    back = read_files("etalon", write_files(tables))
    assert max_difference_um(tables, back) <= 0.0005 + 1e-9
    isg = build(small(), "isg-volumetric", options)
    assert max_difference_um(back, read_files("isg-volumetric", write_files(isg))) <= 0.001


def test_column_order_option():
    tables = build(small(), "etalon", BuildOptions(spacing_mm=SPACING, leave_uncorrected=True))
    s = FormatSettings(options={"etalon-columns": "value-argument"})
    text = write_files(tables, s)["etalon_exchange.txt"]
    first = parse_exchange(text, "f")["EXX"].table
    assert first is not None and first[-1, 1] == pytest.approx(200.0)  # the argument second
    assert max_difference_um(tables, read_files("etalon", {"etalon_exchange.txt": text}, s)) < 1e-3


@pytest.mark.parametrize(
    ("text", "where"),
    [
        ("[EXX]\nGridpoints = {\n0 0.1\n10 abc\n}\n", "f:4"),
        ("[EXX]\nGridpoints = {\n0 0.1\n10 0.2\n", "Gridpoints not closed"),
        ("VALUE = 1\n", "f:1"),
        ("[C0Y]\nVALUE = 1\n[C0Y]\nVALUE = 2\n", "f:3"),
        ("[EXX]\nWHAT = 1\n", "f:2"),
    ],
)
def test_parser_names_file_and_line(text, where):
    with pytest.raises(ParseError, match=where):
        parse_exchange(text, "f")


def test_parser_reads_values_tables_and_comments():
    text = "// c\n[C0Y]\nVALUE = 0.5 // x\n[EYX]\nGridpoints = {\n  -10.0 1e-3\n  10.0 -2e-3\n}\n"
    blocks = parse_exchange(text, "f")
    assert blocks["C0Y"].value == 0.5 and blocks["C0Y"].line == 2
    assert blocks["EYX"].table.tolist() == [[-10.0, 1e-3], [10.0, -2e-3]]
