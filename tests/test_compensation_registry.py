"""The registry of compensation formats and the one workflow function: every format
declares what it holds and its limits, writes, reads back its own files and predicts; the
command offers exactly the registry's formats and gives what the library gives."""

from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path

import pytest
from click.testing import CliRunner
from test_compensation_apply import small

import esp
from esp.cli import main
from esp.compensation.build import BuildOptions, build
from esp.compensation.formats import FormatSettings, get, limit_names, names, registry
from esp.compensation.formats.base import TABLE_KINDS, Format
from esp.compensation.model import max_difference_um
from esp.compensation.workflow import compensate
from esp.core.errors import DataError

GANTRY = Path(__file__).resolve().parent.parent / "data" / "examples" / "gantry" / "machine.toml"
SPACING = {"X": 20.0, "Y": 50.0, "Z": 50.0}


def test_every_format_declares_what_it_holds():
    legacy = ["linuxcnc", "twincat-lead", "twincat-cross", "twincat-plane", "isg-volumetric"]
    assert list(names())[:5] == legacy and "iso-csv" in names()
    for name, fmt in registry().items():
        assert isinstance(fmt, Format) and fmt.name == name
        assert fmt.description and fmt.load_words
        assert fmt.capabilities.tables and fmt.capabilities.tables <= set(TABLE_KINDS)
        assert set(fmt.limit_defaults) <= set(limit_names())
        assert fmt.resolution_um(FormatSettings()) > 0


def test_unknown_format_names_the_choices():
    with pytest.raises(DataError, match="linuxcnc"):
        get("nope")


def test_command_choices_are_the_registry():
    r = CliRunner().invoke(main, ["compensate", "--help"])
    assert r.exit_code == 0
    for name in names():
        assert name in r.output
    r = CliRunner().invoke(main, ["compensate", str(GANTRY), "--format", "nope"])
    assert r.exit_code == 2


@pytest.mark.parametrize("name", list(names()))
def test_each_format_reads_back_what_it_writes(name):
    """Through the workflow: the tables read back from the files equal those built, to
    the format's resolution (positions to a thousandth of it in mm)."""
    machine = small()
    options = BuildOptions(spacing_mm=SPACING, leave_uncorrected=True)
    done = compensate(machine, [name], options, FormatSettings(limits={"cec_tables": 20}))
    result = done[name].result
    assert result.files == tuple(done[name].files)
    built = build(machine, name, options)
    back = replace(result.tables, format=built.format)
    tolerance = result.resolution_um / 2
    if get(name).zero_at_reference:  # incremental data: zero at the first point, whose
        # rounding adds to each value's
        shifted = [
            replace(
                t,
                forward_um=t.forward_um - t.forward_um[0],
                backward_um=t.backward_um - t.forward_um[0],
            )
            for t in built.axis_tables
        ]
        built = replace(built, axis_tables=tuple(shifted))
        tolerance = result.resolution_um
    assert max_difference_um(built, back) <= tolerance + 1e-9
    assert result.prediction is None


def test_workflow_refuses_a_large_file_before_writing():
    machine = small()
    options = BuildOptions(spacing_mm={"X": 1.0}, leave_uncorrected=True)
    with pytest.raises(DataError, match="--max-file-mb"):
        compensate(machine, ["iso-csv"], options, max_file_mb=0.001)


def test_the_command_gives_what_the_library_gives(tmp_path):
    machine = esp.load_machine(GANTRY)
    fmts = ["linuxcnc", "siemens-lec"]
    done = compensate(
        machine, fmts, BuildOptions(leave_uncorrected=True), FormatSettings(), predict=True
    )
    out = tmp_path / "c.json"
    args = ["compensate", str(GANTRY), "--leave-uncorrected", "--predict", "--json", str(out)]
    for f in fmts:
        args += ["--format", f]
    r = CliRunner().invoke(main, [*args, "-q"])
    assert r.exit_code == 0, r.output
    doc = json.loads(out.read_text())
    for entry in doc["formats"]:
        p = done[entry["format"]].result.prediction
        assert p is not None
        assert entry["prediction"]["after_um"] == pytest.approx(p.after_um)
        assert entry["files"] == list(done[entry["format"]].files)


def test_the_open_choices_are_reported():
    """A format whose documentation leaves choices open names them, as given or by
    default, in its notes (terminal, JSON and report)."""
    machine = small()
    options = BuildOptions(spacing_mm=SPACING, leave_uncorrected=True)
    settings = FormatSettings(options={"fanuc-sign": "error"})
    done = compensate(machine, ["fanuc", "linuxcnc"], options, settings)
    notes = " ".join(done["fanuc"].result.tables.notes)
    assert "fanuc-sign=error" in notes and "fanuc-between=step" in notes
    assert "fanuc-detection-um=1" in notes
    assert not any("open" in n for n in done["linuxcnc"].result.tables.notes)
