"""The provenance of a command's outputs (esp.report.provenance) and its place in every
command's JSON (esp.cli.output.CommandOutputs)."""

from __future__ import annotations

import hashlib
import json
import os
from pathlib import Path

import pytest
from click.testing import CliRunner

from esp._version import __version__
from esp.cli import main
from esp.io.laser10 import record_sections
from esp.report.provenance import (
    InputRecord,
    Provenance,
    collect,
    environment_lines,
    readings,
)

ROOT = Path(__file__).resolve().parents[1]
GANTRY = ROOT / "data" / "examples" / "gantry"

LINEAR = """HEADER::
File type  : rtl
Owner      : Linear

TARGET DATA::
Target-count: 2
Targets :
0.0 100.0
Flags: 0 0 2 0

USER-TEXT::
Machine: Example mill
Serial No: 12345
Date: 12/12/2016
By: A. User
a line without a colon

RUNS::
Run-count: 2

DEVIATIONS::
Run Target Data:
1 1 0.0
1 2 1.0
2 2 2.0
2 1 0.0

ENVIRONMENT::
Air temp   : 20.337280 20.384956 0
Air press  : 99.039005 99.049346 1
Air humid  : 45.2 45.9 0
Mat temp 1 : 20.1 20.2 1
Mat temp 2 : -10.000000 -10.000000 0
Mat temp 3 : 0 0 0
Env factor : 0.31641096 0.31641067
Exp coeff  : 8.000000 8.000000 0
Date Time  : "10:46 Dec 12 2016" "11:01 Dec 12 2016"
Final Data : 1 0
EOF::
"""


@pytest.fixture
def folder(tmp_path, monkeypatch):
    """A configuration naming one Laser10 file, in the current folder."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / "data").mkdir()
    (tmp_path / "data" / "X.rtl").write_text(LINEAR, encoding="utf-8")
    return tmp_path


def test_record_sections_reads_user_text_environment_and_equipment():
    text = LINEAR.replace("EOF::", "EQUIPMENT::\nLaser : ML10 Gold\nEOF::\nAfter : no")
    sections = record_sections(text)
    assert sections["USER-TEXT"][:2] == (("Machine", "Example mill"), ("Serial No", "12345"))
    # a line without a colon is kept, under Text, as parse_laser10 keeps it
    assert sections["USER-TEXT"][-1] == ("Text", "a line without a colon")
    assert sections["ENVIRONMENT"][0] == ("Air temp", "20.337280 20.384956 0")
    assert sections["EQUIPMENT"] == (("Laser", "ML10 Gold"),)
    # nothing after EOF::, and a text that is no Laser10 file gives nothing, never raises
    assert all(key != "After" for key, _ in sections["EQUIPMENT"])
    assert record_sections("not a laser file\n") == {
        "USER-TEXT": (),
        "ENVIRONMENT": (),
        "EQUIPMENT": (),
    }


def test_environment_lines_name_each_quantity_with_its_unit_and_show_sentinels_as_absent():
    lines = dict(environment_lines(record_sections(LINEAR)["ENVIRONMENT"]))
    assert lines == {
        "air temperature": "20.337280 °C (start), 20.384956 °C (end)",
        "air pressure": "99.039005 kPa (start), 99.049346 kPa (end)",
        "air humidity": "45.2 %RH (start), 45.9 %RH (end)",
        "material temperature 1": "20.1 °C (start), 20.2 °C (end)",
        "material temperature 2": "absent",  # -10: a sensor not connected
        "material temperature 3": "absent",  # 0 and 0: a sensor not fitted
        "environment factor": "0.31641096 (start), 0.31641067 (end)",
        "expansion coefficient": "8.000000 µm/(m·°C) (start and end)",
        "date and time": "10:46 Dec 12 2016 (start), 11:01 Dec 12 2016 (end)",
        "Final Data": "1 0",  # a line esp does not know: as written
    }


def test_readings_keep_the_values_as_written_and_say_them_compactly():
    found = {r.quantity: r for r in readings(record_sections(LINEAR)["ENVIRONMENT"])}
    air = found["air temperature"]
    assert (air.unit, air.start, air.end) == ("°C", "20.337280", "20.384956")
    assert air.compact == "20.337280 / 20.384956"  # the unit goes in the table's header
    assert found["expansion coefficient"].compact == "8.000000"  # the same at both
    assert found["material temperature 2"].absent
    assert found["material temperature 2"].compact == "absent"
    assert found["environment factor"].unit == ""
    # a date and time of one day: the day once, then the two clock times
    assert found["date and time"].compact == "Dec 12 2016 10:46 / 11:01"
    other_day = readings([("Date Time", '"23:50 Dec 12 2016" "00:10 Dec 13 2016"')])[0]
    assert other_day.compact == "23:50 Dec 12 2016 / 00:10 Dec 13 2016"
    assert found["Final Data"].compact == found["Final Data"].text == "1 0"
    # the text form is environment_lines'
    assert tuple((r.quantity, r.text) for r in found.values()) == environment_lines(
        record_sections(LINEAR)["ENVIRONMENT"]
    )


def test_a_pressure_that_is_not_kpa_is_shown_without_a_unit():
    assert environment_lines([("Air press", "1011.2 1011.3 1")]) == (
        ("air pressure", "1011.2 (start), 1011.3 (end)"),
    )


def test_collect_hashes_each_input_once_and_names_it_as_the_configuration_does(folder):
    config = folder / "machine.toml"
    config.write_text('# a comment\n[machine]\nname = "m"\n', encoding="utf-8")
    inputs = ["machine.toml", os.path.join(".", "data", "X.rtl"), "data/X.rtl"]
    prov = collect(inputs, ["analyse", "machine.toml"])
    assert isinstance(prov, Provenance)
    assert prov.esp_version == __version__
    assert prov.command == ("analyse", "machine.toml")
    assert [r.path for r in prov.inputs] == ["machine.toml", "data/X.rtl"]  # each file once
    conf, data = prov.inputs
    assert conf == InputRecord(
        "machine.toml",
        hashlib.sha256(config.read_bytes()).hexdigest(),
        config.stat().st_size,
        "configuration",
    )
    assert data.kind == "laser10" and data.error_kind == "linear"
    assert data.sha256 == hashlib.sha256(LINEAR.encode()).hexdigest()
    assert data.size_bytes == len(LINEAR.encode())
    assert ("By", "A. User") in data.user_text
    assert ("material temperature 2", "absent") in data.environment
    # the configuration as given, comment and all
    assert prov.configuration == (("machine.toml", config.read_text(encoding="utf-8")),)


def test_a_file_the_configuration_names_is_shown_relative_to_the_configuration(folder):
    (folder / "cfg").mkdir()
    (folder / "cfg" / "m.toml").write_text("[machine]\n", encoding="utf-8")
    prov = collect(["cfg/m.toml", "cfg/../data/X.rtl"], ["analyse", "cfg/m.toml"])
    assert [r.path for r in prov.inputs] == ["cfg/m.toml", "../data/X.rtl"]
    # a toml the configuration includes (a head, a table) is not named on the command line
    (folder / "cfg" / "head.toml").write_text("[head]\n", encoding="utf-8")
    prov = collect(["cfg/m.toml", "cfg/head.toml"], ["analyse", "cfg/m.toml"])
    assert [r.kind for r in prov.inputs] == ["configuration", "toml"]
    assert [name for name, _ in prov.configuration] == ["cfg/m.toml", "head.toml"]


def test_to_dict_is_the_documented_json(folder):
    (folder / "m.toml").write_text("[machine]\n", encoding="utf-8")
    (folder / "data" / "p.csv").write_text("position_mm,error_um\n0,0\n", encoding="utf-8")
    doc = collect(["m.toml", "data/X.rtl", "data/p.csv"], ["analyse", "m.toml"]).to_dict()
    assert list(doc) == ["esp_version", "command", "inputs", "configuration"]
    assert [list(r) for r in doc["inputs"]] == [
        ["path", "sha256", "size_bytes", "kind"],
        ["path", "sha256", "size_bytes", "kind", "error_kind", "user_text", "environment"],
        ["path", "sha256", "size_bytes", "kind"],
    ]
    assert doc["inputs"][2]["kind"] == "csv"
    assert doc["inputs"][1]["user_text"]["Date"] == "12/12/2016"
    assert doc["configuration"] == [{"file": "m.toml", "text": "[machine]\n"}]
    json.dumps(doc)  # plain JSON types throughout


def test_collect_refuses_an_input_that_is_gone(folder):
    from esp.core.errors import ParseError

    with pytest.raises(ParseError):
        collect(["data/missing.rtl"], ["inspect", "data/missing.rtl"])


@pytest.mark.slow
def test_every_command_json_carries_the_provenance_and_regenerates_byte_identical(
    tmp_path, monkeypatch
):
    monkeypatch.chdir(ROOT)
    runs = []
    for name in ("a.json", "b.json"):
        target = tmp_path / name
        result = CliRunner().invoke(
            main, ["analyse", "data/examples/gantry/machine.toml", "--json", str(target), "-q"]
        )
        assert result.exit_code == 0, result.output
        runs.append(json.loads(target.read_text(encoding="utf-8")))
    first, second = (r["provenance"] for r in runs)
    assert first["inputs"] == second["inputs"]
    assert first["command"] == [
        "analyse",
        "data/examples/gantry/machine.toml",
        "--json",
        str(tmp_path / "a.json"),
        "--quiet",
    ]
    paths = [r["path"] for r in first["inputs"]]
    # the configuration, then every data file it names, as it names them
    assert paths[0] == "data/examples/gantry/machine.toml"
    named = sorted(
        p.name for p in GANTRY.iterdir() if p.suffix in (".rtl", ".rta", ".stx", ".sty", ".stz")
    )
    assert sorted(paths[1:]) == named
    assert all(not os.path.isabs(p) for p in paths)
    assert (
        first["inputs"][0]["sha256"]
        == hashlib.sha256((GANTRY / "machine.toml").read_bytes()).hexdigest()
    )
    assert first["configuration"][0]["text"] == (GANTRY / "machine.toml").read_text(
        encoding="utf-8"
    )
    assert list(runs[0])[-1] == "provenance"


def test_the_same_command_gives_the_same_bytes(tmp_path, monkeypatch):
    monkeypatch.chdir(ROOT)
    outputs = []
    for _ in range(2):
        result = CliRunner().invoke(
            main, ["inspect", "data/examples/gantry/X-linear.rtl", "--json", "-"]
        )
        assert result.exit_code == 0, result.output
        outputs.append(result.stdout)
    assert outputs[0] == outputs[1]
    prov = json.loads(outputs[0])["provenance"]
    assert prov["command"] == ["inspect", "data/examples/gantry/X-linear.rtl", "--json", "-"]
    assert prov["inputs"][0]["environment"]["expansion coefficient"] == (
        "11.500000 µm/(m·°C) (start and end)"
    )


def test_the_folder_written_is_named_on_standard_error_and_not_with_quiet(tmp_path):
    from esp.cli.output import CommandOutputs

    out = tmp_path / "R"
    for quiet, expected in ((False, f"esp: report written to {out}\n"), (True, "")):
        runner = CliRunner()

        def body(quiet=quiet):
            outputs = CommandOutputs([], None, quiet, command=("x",))
            outputs.folder(out, "--out")
            (outputs.stage_folder(out) / "f.txt").write_text("x")
            outputs.finish(text="")

        import click

        result = runner.invoke(click.command()(lambda: body()), [])
        assert result.exit_code == 0, result.output
        assert result.stderr == expected
        assert (out / "f.txt").read_text() == "x"


def test_progress_prints_only_on_a_terminal_and_not_with_quiet(monkeypatch, capsys):
    from esp.cli.output import CommandOutputs

    class Terminal:
        def __init__(self):
            self.text = ""

        def isatty(self):
            return True

        def write(self, s):
            self.text += s

        def flush(self):
            pass

    term = Terminal()
    monkeypatch.setattr("sys.stderr", term)
    outputs = CommandOutputs([], None, False, command=("x",))
    assert outputs.shows_progress
    outputs.progress("volumetric-xy.png")
    outputs.progress("x")
    outputs.finish()
    # one line, rewritten in place, cleared at the end
    assert term.text.startswith("\resp: volumetric-xy.png ...")
    assert "\resp: x ..." + " " * (len("esp: volumetric-xy.png ...") - len("esp: x ...")) in (
        term.text
    )
    assert term.text.endswith("\r")
    assert "\n" not in term.text
    term.text = ""
    quiet = CommandOutputs([], None, True, command=("x",))
    assert not quiet.shows_progress
    quiet.progress("anything")
    assert term.text == ""
    monkeypatch.setattr(Terminal, "isatty", lambda self: False)
    CommandOutputs([], None, False, command=("x",)).progress("anything")
    assert term.text == ""


def test_a_configuration_named_with_a_dot_is_still_the_configuration(folder):
    (folder / "m.toml").write_text("[machine]\n", encoding="utf-8")
    absolute = str(folder / "data" / "X.rtl")
    prov = collect(["m.toml", "data/X.rtl", absolute], ["analyse", "./m.toml"])
    assert [r.kind for r in prov.inputs] == ["configuration", "laser10"]
    # a file a configuration names by an absolute path is shown as read
    prov = collect(["m.toml", absolute], ["analyse", "m.toml"])
    assert prov.inputs[1].path == Path(absolute).as_posix()


def test_a_csv_records_its_comment_lines(folder):
    text = "# kind: linear\n# unit: um\n# X axis, measured 2019-05-03\n#\ntarget_mm,run\n# no\n"
    (folder / "data" / "p.csv").write_text(text, encoding="utf-8")
    (record,) = collect(["data/p.csv"], ["inspect", "data/p.csv"]).inputs
    assert record.kind == "csv"
    # key: value pairs, then the other comments under Text; nothing after the header
    assert record.user_text == (
        ("kind", "linear"),
        ("unit", "um"),
        ("Text", "X axis, measured 2019-05-03"),
    )
    assert record.to_dict()["user_text"] == {
        "kind": "linear",
        "unit": "um",
        "Text": "X axis, measured 2019-05-03",
    }


def test_a_label_written_twice_keeps_both_values():
    record = InputRecord("a.rtl", "0" * 64, 1, "laser10", user_text=(("By", "A"), ("By", "B")))
    assert record.to_dict()["user_text"] == {"By": "A", "By (2)": "B"}


def test_the_progress_line_is_cleared_when_the_work_fails(monkeypatch):
    from esp.cli.output import CommandOutputs

    class Terminal:
        text = ""

        def isatty(self):
            return True

        def write(self, s):
            Terminal.text += s

        def flush(self):
            pass

    monkeypatch.setattr("sys.stderr", Terminal())
    outputs = CommandOutputs([], None, False, command=("x",))
    with pytest.raises(RuntimeError), outputs:
        outputs.progress("drawing terms")
        raise RuntimeError("failed")
    assert Terminal.text == "\resp: drawing terms ..." + "\r" + " " * 22 + "\r"


def test_staging_an_out_folder_shows_the_progress_line(tmp_path, monkeypatch):
    from esp.cli.output import CommandOutputs

    class Terminal:
        text = ""

        def isatty(self):
            return True

        def write(self, s):
            Terminal.text += s

        def flush(self):
            pass

    monkeypatch.setattr("sys.stderr", Terminal())
    out = tmp_path / "R"
    outputs = CommandOutputs([], None, False, command=("x",))
    outputs.folder(out, "--out")
    with outputs:
        outputs.stage_folder(out)
        assert Terminal.text == f"\resp: building the report in {out} ..."
        outputs.finish()
    # the line cleared, then where the report went
    shown = f"esp: building the report in {out} ..."
    assert Terminal.text == f"\r{shown}\r{' ' * len(shown)}\resp: report written to {out}\n"


def test_the_command_line_is_the_arguments_as_given_when_esp_runs_as_a_program(monkeypatch):
    import click

    from esp.report.provenance import command_line

    @click.group()
    def esp():
        pass

    @esp.command("inspect")
    @click.argument("file")
    @click.option("--json", "json_target")
    @click.option("--quiet", "-q", is_flag=True)
    def command(file, json_target, quiet):
        click.echo(repr(command_line()))

    args = ["inspect", "-q", "--json", "-", "a.rtl"]
    # from Python: rebuilt from the parameters, arguments first, options in their order
    monkeypatch.setattr("sys.argv", ["pytest", "whatever"])
    result = CliRunner().invoke(esp, args)
    assert result.stdout.strip() == "('inspect', 'a.rtl', '--json', '-', '--quiet')"
    # as a program: as typed
    monkeypatch.setattr("sys.argv", ["/usr/bin/esp", *args])
    result = CliRunner().invoke(esp, args)
    assert result.stdout.strip() == "('inspect', '-q', '--json', '-', 'a.rtl')"


def test_a_report_folders_documents_carry_the_provenance(tmp_path):
    """``CommandOutputs.write_documents``: STEM.json is the document with the run's
    provenance last, STEM.txt the text, and the document returned is the one written."""
    from esp.cli.output import CommandOutputs

    source = tmp_path / "in.csv"
    source.write_text("position_mm,forward\n0,0\n", encoding="utf-8")
    outputs = CommandOutputs([source], command=("ballbar", "in.csv"))
    folder = tmp_path / "staged"
    folder.mkdir()
    doc = outputs.write_documents(folder, "ballbar", "the text\n", {"schema": "x/1"})
    written = json.loads((folder / "ballbar.json").read_text(encoding="utf-8"))
    assert written == doc and list(written) == ["schema", "provenance"]
    assert written["provenance"]["command"] == ["ballbar", "in.csv"]
    assert (folder / "ballbar.txt").read_text(encoding="utf-8") == "the text\n"
