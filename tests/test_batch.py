"""``esp batch``: discovery, folder names, summary rows, thresholds, exit codes, output."""

from __future__ import annotations

import csv
import json
from pathlib import Path

import pytest
from click.testing import CliRunner

from esp.batch.run import SUMMARY_COLUMNS, find_machines, plan
from esp.cli import main

# Every test machine: three axes 0..100 mm in steps of 50 mm (27 points), no datum, and
# only the errors written into it, so every figure below can be worked out by hand.
AXES = """
[axes.X]
travel = [0, 100]
step = 50
{x_errors}
[axes.Y]
travel = [0, 100]
step = 50

[axes.Z]
travel = {z_travel}
step = 50
"""


def machine_text(name: str, x_linear_um: float, z_travel: str = "[0, 100]", extra: str = "") -> str:
    """A machine whose only error is X.linear, 0 at X=0 rising linearly to
    ``x_linear_um`` at X=100."""
    x_errors = f"[axes.X.errors]\nlinear = {{ points = [[0, 0], [100, {x_linear_um}]] }}\n"
    return (
        f'[machine]\nname = "{name}"\nconfiguration = "wBMTt"\n'
        'axes = { bottom = "X", middle = "Y", top = "Z" }\n'
        + AXES.format(x_errors=x_errors, z_travel=z_travel)
        + extra
    )


BROKEN = machine_text("broken", 1.0).replace("step = 50\n", "stpe = 50\n", 1)


def write(path: Path, text: str) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text, encoding="utf-8")
    return path


@pytest.fixture
def fleet(tmp_path) -> Path:
    """Two good machines (3 µm and 8 µm) and a broken one (a misspelt key)."""
    root = tmp_path / "fleet"
    write(root / "alpha" / "machine.toml", machine_text("Alpha", 3.0))
    write(root / "beta" / "machine.toml", machine_text("Beta", 8.0))
    write(root / "gamma" / "machine.toml", BROKEN)
    return root


@pytest.fixture
def fake_reports(monkeypatch):
    """Replace the (slow) report content by a result.json stub; the
    worker processes of --jobs are forked after this, so they see it too."""
    calls = []

    def stand_in(result, staged, **kwargs):
        doc = {"schema": "esp.result/1", "name": result.machine.name}
        (Path(staged) / "result.json").write_text(json.dumps(doc), encoding="utf-8")
        calls.append(Path(staged).name.split(".esp-stage-")[0].lstrip("."))

    # the folder logic (staging, marker, replacing) stays real; only the content is faked
    monkeypatch.setattr("esp.volumetric.report.write_report_files", stand_in)
    return calls


def batch(*args: str):
    return CliRunner().invoke(main, ["batch", *map(str, args)])


def read_rows(out: Path) -> list[dict[str, str]]:
    with open(out / "summary.csv", newline="", encoding="utf-8") as f:
        return list(csv.DictReader(f))


def test_good_and_broken_machines(fleet, tmp_path, fake_reports):
    out = tmp_path / "out"
    res = batch(fleet, "--out", out)
    assert res.exit_code == 2, res.output
    rows = read_rows(out)
    assert [r["file"] for r in rows] == [
        "alpha/machine.toml",
        "beta/machine.toml",
        "gamma/machine.toml",
    ]
    alpha, beta, gamma = rows
    # only X.linear: at X=100 the X error is 3 µm, Y and Z are 0 -> volumetric 3 µm
    assert alpha["name"] == "Alpha" and alpha["configuration"] == "wBMTt"
    assert alpha["volumetric_um"] == "3.000" and beta["volumetric_um"] == "8.000"
    assert alpha["volumetric_X_mm"] == "100"
    assert alpha["verdict"] == "pass" and alpha["error"] == ""
    assert gamma["verdict"] == "error" and gamma["volumetric_um"] == "" and gamma["report"] == ""
    assert "axes.X.stpe" in gamma["error"] and "unknown key 'stpe'" in gamma["error"]
    assert gamma["error"].startswith(str(fleet / "gamma" / "machine.toml"))
    # the good ones still have their report folders, the broken one has none
    assert sorted(p.name for p in out.iterdir()) == [
        ".esp-folder.json",  # the marker: esp wrote this folder (esp.io.outputs)
        "alpha__machine",
        "beta__machine",
        "summary.csv",
        "summary.md",
        "summary.pdf",
    ]
    assert (out / "alpha__machine" / "result.json").is_file()
    md = (out / "summary.md").read_text(encoding="utf-8")
    assert "3 machines: 2 pass, 0 fail, 1 error." in md
    assert "[alpha__machine](alpha__machine/report.pdf)" in md
    assert "error: " + gamma["error"].replace("|", "\\|") in md


@pytest.mark.slow
def test_real_report_folder(tmp_path):
    machine = write(tmp_path / "m" / "machine.toml", machine_text("Real", 3.0))
    out = tmp_path / "out"
    res = batch(machine, "--out", out)
    assert res.exit_code == 0, res.output
    folder = out / "machine"
    assert (folder / "report.pdf").read_bytes().startswith(b"%PDF")
    doc = json.loads((folder / "result.json").read_text(encoding="utf-8"))
    assert doc["schema"].startswith("esp.result/")
    assert read_rows(out)[0]["report"] == "machine"
    # no temporary folders or files are left behind
    assert sorted(p.name for p in out.iterdir()) == [
        ".esp-folder.json",
        "machine",
        "summary.csv",
        "summary.md",
        "summary.pdf",
    ]


@pytest.mark.parametrize(
    ("options", "code", "verdicts"),
    [
        ((), 0, ["pass", "pass"]),
        (("--max-volumetric", "10"), 0, ["pass", "pass"]),
        (("--max-volumetric", "5"), 1, ["pass", "fail: volumetric 8.000 um > 5 um"]),
        # a value equal to its threshold passes
        (("--max-volumetric", "8"), 0, ["pass", "pass"]),
        # planar XY = sqrt(3² + 0²) = 3 µm and XZ = 3 µm; YZ = 0 µm (no Y or Z error)
        (
            ("--max-planar", "2.5"),
            1,
            [
                "fail: planar XY 3.000 um > 2.5 um; planar XZ 3.000 um > 2.5 um",
                "fail: planar XY 8.000 um > 2.5 um; planar XZ 8.000 um > 2.5 um",
            ],
        ),
        (
            ("--max-volumetric", "5", "--max-planar", "4"),
            1,
            [
                "pass",
                "fail: volumetric 8.000 um > 5 um; planar XY 8.000 um > 4 um; "
                "planar XZ 8.000 um > 4 um",
            ],
        ),
    ],
)
@pytest.mark.slow
def test_thresholds_decide(fleet, tmp_path, fake_reports, options, code, verdicts):
    (fleet / "gamma" / "machine.toml").unlink()
    out = tmp_path / "out"
    res = batch(fleet, "--out", out, *options)
    assert res.exit_code == code, res.output
    rows = read_rows(out)
    assert [r["verdict"] for r in rows] == verdicts
    assert [(r["planar_XY_um"], r["planar_XZ_um"], r["planar_YZ_um"]) for r in rows] == [
        ("3.000", "3.000", "0.000"),
        ("8.000", "8.000", "0.000"),
    ]


def test_error_wins_over_fail(fleet, tmp_path, fake_reports):
    res = batch(fleet, "--out", tmp_path / "out", "--max-volumetric", "5")
    assert res.exit_code == 2
    assert [r["verdict"][:4] for r in read_rows(tmp_path / "out")] == ["pass", "fail", "erro"]


@pytest.mark.parametrize("value", ["0", "-1", "nan"])
def test_threshold_must_be_positive(fleet, tmp_path, value):
    res = batch(fleet, "--out", tmp_path / "out", "--max-volumetric", value)
    assert res.exit_code == 2 and f"found '{value}'" in res.output
    assert not (tmp_path / "out").exists()


@pytest.mark.slow
def test_jobs_give_the_same_summary(fleet, tmp_path, fake_reports):
    write(fleet / "delta" / "sub" / "machine.toml", machine_text("Delta", 5.0))
    one, two = tmp_path / "one", tmp_path / "two"
    res1 = batch(fleet, "--out", one, "--max-volumetric", "6", "--jobs", "1")
    res2 = batch(fleet, "--out", two, "--max-volumetric", "6", "--jobs", "2")
    assert res1.exit_code == res2.exit_code == 2
    for name in ("summary.csv", "summary.md"):
        assert (one / name).read_bytes() == (two / name).read_bytes()
    assert sorted(p.name for p in two.iterdir()) == sorted(p.name for p in one.iterdir())
    assert "delta__sub__machine" in {p.name for p in two.iterdir()}


def test_discovery_skips_what_is_not_a_machine(tmp_path):
    root = tmp_path / "root"
    good = write(root / "a" / "machine.toml", machine_text("A", 1.0))
    other = write(root / "b" / "cell-2.TOML", machine_text("B", 1.0))  # any name, any case
    write(root / "pyproject.toml", '[project]\nname = "x"\n')  # no [machine] table
    write(root / "settings.toml", 'machine = "not a table"\n')
    write(root / "notes.txt", "[machine]\n")  # not *.toml
    write(root / ".hidden" / "machine.toml", machine_text("H", 1.0))  # hidden folder
    write(root / "a" / ".machine.toml.tmp.toml", machine_text("T", 1.0))  # hidden file
    write(root / "out" / "machine.toml", machine_text("O", 1.0))  # the output folder
    broken = write(root / "c" / "machine.toml", "[machine\n")  # not TOML: kept, reported
    found = find_machines([root], skip=[root / "out"])
    assert sorted(found) == sorted([good, other, broken])
    # a file named explicitly is always taken, and a file reached twice is listed once
    explicit = root / "pyproject.toml"
    assert find_machines([explicit, root / "a", good]) == sorted([explicit, good])


def test_discovery_through_the_command(tmp_path, fake_reports):
    root = tmp_path / "root"
    write(root / "a" / "machine.toml", machine_text("A", 1.0))
    write(root / "pyproject.toml", '[project]\nname = "x"\n')
    write(root / "bad" / "machine.toml", "[machine\nname = 1\n")
    out = root / "reports"  # inside the searched folder: not searched itself
    write(out / "old" / "machine.toml", machine_text("old", 1.0))
    # a folder of the user's is refused before any work, and left as it was
    res = batch(root, "--out", out)
    assert res.exit_code == 2 and "esp did not write" in res.output, res.output
    assert fake_reports == [] and sorted(p.name for p in out.iterdir()) == ["old"]
    (out / "old" / "machine.toml").unlink()
    (out / "old").rmdir()
    for _ in range(2):  # the second run finds the same machines, not what the first wrote
        res = batch(root, "--out", out)
        assert res.exit_code == 2, res.output
        rows = read_rows(out)
        assert [r["file"] for r in rows] == ["a/machine.toml", "bad/machine.toml"]
        assert "<toml>" in rows[1]["error"] and "line 1" in rows[1]["error"]


def test_nothing_found_is_an_error(tmp_path):
    write(tmp_path / "pyproject.toml", '[project]\nname = "x"\n')
    res = batch(tmp_path, "--out", tmp_path / "out")
    assert res.exit_code == 2
    assert "no machine configuration found" in res.output
    assert not (tmp_path / "out").exists()


def test_out_must_be_a_folder(fleet, tmp_path):
    target = write(tmp_path / "out", "keep me")
    res = batch(fleet, "--out", target)
    assert res.exit_code == 2
    assert target.read_text(encoding="utf-8") == "keep me"


def test_summary_csv_columns(tmp_path, fake_reports):
    root = tmp_path / "root"
    # a two-axis machine: Z does not move, so only the XY plane is reported
    write(root / "lathe.toml", machine_text("Lathe", 2.0, z_travel="[0, 0]"))
    # statistical uncertainty with U(X.linear) = 4 µm only: X: 4, Y: 0, Z: 0 -> 4 µm
    unc = '\n[uncertainty]\nmethod = "statistical"\n[uncertainty.components."X.linear"]\nU = 4.0\n'
    write(root / "cmm.toml", machine_text("CMM, room 2", 3.0, extra=unc))
    res = batch(root, "--out", tmp_path / "out")
    assert res.exit_code == 0, res.output
    with open(tmp_path / "out" / "summary.csv", newline="", encoding="utf-8") as f:
        reader = csv.reader(f)
        header = next(reader)
        body = list(reader)
    assert tuple(header) == SUMMARY_COLUMNS
    assert header == [
        "file", "name", "configuration", "volumetric_um",
        "volumetric_X_mm", "volumetric_Y_mm", "volumetric_Z_mm",
        "planar_XY_um", "planar_XZ_um", "planar_YZ_um",
        "uncertainty_um", "verdict", "decision_rule", "decisions", "error", "report",
    ]  # fmt: skip
    cmm, lathe = (dict(zip(header, r, strict=True)) for r in body)
    assert cmm["name"] == "CMM, room 2"  # quoted by the writer, read back whole
    assert cmm["uncertainty_um"] == "4.000"
    assert lathe["uncertainty_um"] == ""
    assert (lathe["planar_XY_um"], lathe["planar_XZ_um"], lathe["planar_YZ_um"]) == (
        "2.000",
        "",
        "",
    )
    assert lathe["volumetric_Z_mm"] == "0"


def test_line_output_without_a_terminal(fleet, tmp_path, fake_reports):
    out = tmp_path / "out"
    res = batch(fleet, "--out", out, "--max-volumetric", "5")
    lines = res.output.splitlines()
    assert len(lines) == 4
    assert "ok   alpha/machine.toml  3.000 um  pass" in lines
    assert "ok   beta/machine.toml  8.000 um  fail: volumetric 8.000 um > 5 um" in lines
    error = read_rows(out)[2]["error"]
    assert f"err  gamma/machine.toml  {error}" in lines
    assert lines[-1] == f"3 machines: 1 pass, 1 fail, 1 error; summary in {out}/summary.csv"


def test_quiet_prints_only_the_machines_in_error(fleet, tmp_path, fake_reports, monkeypatch):
    monkeypatch.setattr("esp.cli.batch._stderr_is_terminal", lambda: True)  # no bar either
    out = tmp_path / "out"
    res = batch(fleet, "--out", out, "-q")
    assert res.exit_code == 2
    error = read_rows(out)[2]["error"]
    assert res.output.splitlines() == [f"err  gamma/machine.toml  {error}"]


def test_terminal_shows_a_bar_then_sorted_lines(fleet, tmp_path, fake_reports, monkeypatch):
    monkeypatch.setattr("esp.cli.batch._stderr_is_terminal", lambda: True)
    res = batch(fleet, "--out", tmp_path / "out", "--jobs", "2")
    lines = [ln for ln in res.output.splitlines() if ln.startswith(("ok", "err"))]
    assert [ln.split()[1] for ln in lines] == [
        "alpha/machine.toml",
        "beta/machine.toml",
        "gamma/machine.toml",
    ]


def test_unexpected_exception_is_that_machines_error(fleet, tmp_path, fake_reports, monkeypatch):
    import esp.core.analysis

    real = esp.core.analysis.analyse

    def analyse(machine, progress=None):
        if machine.name == "Beta":
            raise ZeroDivisionError("float division by zero")
        return real(machine, progress)

    monkeypatch.setattr("esp.core.analysis.analyse", analyse)
    (fleet / "gamma" / "machine.toml").unlink()
    res = batch(fleet, "--out", tmp_path / "out")
    assert res.exit_code == 2
    alpha, beta = read_rows(tmp_path / "out")
    assert alpha["verdict"] == "pass"
    assert beta["error"] == (
        f"{fleet / 'beta' / 'machine.toml'}: unexpected ZeroDivisionError: float division by zero"
    )


@pytest.mark.slow
def test_existing_reports_are_replaced_and_foreign_folders_kept(fleet, tmp_path, fake_reports):
    (fleet / "gamma" / "machine.toml").unlink()
    out = tmp_path / "out"
    assert batch(fleet, "--out", out).exit_code == 0
    assert batch(fleet, "--out", out).exit_code == 0  # DIR exists: reports replaced
    assert fake_reports == ["alpha__machine", "beta__machine"] * 2
    # a file of the user's own in a report folder: the output folder is refused before
    # any work, and nothing in it changes
    write(out / "beta__machine" / "notes.txt", "mine")
    before = {p: p.read_bytes() for p in out.rglob("*") if p.is_file()}
    res = batch(fleet, "--out", out)
    assert res.exit_code == 2
    assert "holds files esp did not write (beta__machine/notes.txt)" in res.output
    assert fake_reports == ["alpha__machine", "beta__machine"] * 2
    assert {p: p.read_bytes() for p in out.rglob("*") if p.is_file()} == before


def test_folder_names(tmp_path):
    files = [
        tmp_path / "a" / "b.toml",
        tmp_path / "a__b.toml",
        tmp_path / "A__B.toml",
        tmp_path / "Fräse 1" / "machine.toml",
        tmp_path / "summary.csv.toml",
        tmp_path / "x" / "y" / "gantry.toml",
    ]
    items = plan(files)
    # rows sorted part by part of the path relative to the common folder (tmp_path)
    assert [(i.file, i.folder) for i in items] == [
        ("A__B.toml", "A__B"),
        ("Fräse 1/machine.toml", "Frase_1__machine"),
        ("a/b.toml", "a__b-2"),  # taken by A__B (names are compared without case)
        ("a__b.toml", "a__b-3"),
        ("summary.csv.toml", "summary.csv-2"),  # the summary file's own name
        ("x/y/gantry.toml", "x__y__gantry"),
    ]
    assert plan([tmp_path / "only" / "machine.toml"])[0].folder == "machine"


# -- issue 17, item 6: an uncertainty plan has no accuracy ---------------------------------

# no error data; X.straightness.Y U = 4 µm acts in Y with lever 1, X.linear U = 3 µm in X:
# the volumetric uncertainty is sqrt(3² + 4²) = 5 µm (statistical, one term per direction)
PLAN = (
    '[machine]\nname = "Plan"\nconfiguration = "wBMTt"\n'
    'axes = { bottom = "X", middle = "Y", top = "Z" }\n'
    + AXES.format(x_errors="", z_travel="[0, 100]")
    + '\n[uncertainty]\n[uncertainty.components."X.linear"]\nU = 3.0\n'
    + '[uncertainty.components."X.straightness.Y"]\nU = 4.0\n'
)


@pytest.mark.parametrize(
    "options, code, verdict",
    [
        ((), 0, "plan"),
        (("--max-volumetric", "1", "--max-planar", "1"), 0, "plan"),
        (("--max-uncertainty", "5"), 0, "pass"),
        (("--max-uncertainty", "4.5"), 1, "fail: uncertainty 5.000 um > 4.5 um"),
    ],
)
def test_an_uncertainty_plan_is_judged_on_its_uncertainty_only(
    tmp_path, fake_reports, options, code, verdict
):
    path = write(tmp_path / "study" / "plan.toml", PLAN)
    out = tmp_path / "out"
    res = batch(path, "--out", out, *options)
    assert res.exit_code == code, res.output
    (row,) = read_rows(out)
    assert row["uncertainty_um"] == "5.000" and row["verdict"] == verdict
    # no accuracy is claimed: the accuracy columns are empty, not 0.000
    assert row["volumetric_um"] == "" and row["volumetric_X_mm"] == ""
    assert row["planar_XY_um"] == "" and row["report"] == "plan"
    # on the terminal U is stated to two significant digits (GUM 7.2.6)
    assert f"ok   plan.toml  U = 5.0 um (uncertainty plan)  {verdict}" in res.output
    assert "0.000 um" not in res.output
    if verdict == "plan":
        assert "1 machine: 0 pass, 0 fail, 0 error, 1 plan" in res.output


def test_max_uncertainty_checks_every_machine_with_an_uncertainty(tmp_path, fake_reports):
    # an error machine (3 µm) with X.linear U = 2 µm: accuracy and uncertainty both checked
    text = machine_text("Both", 3.0, extra='\n[uncertainty.components."X.linear"]\nU = 2.0\n')
    path = write(tmp_path / "m" / "machine.toml", text)
    res = batch(
        path, "--out", tmp_path / "out", "--max-volumetric", "2.5", "--max-uncertainty", "1"
    )
    assert res.exit_code == 1, res.output
    (row,) = read_rows(tmp_path / "out")
    # the accuracy is rounded to its U = 2.0 µm (GUM 7.2.6); U itself has no U
    assert row["verdict"] == "fail: volumetric 3.0 um > 2.5 um; uncertainty 2.000 um > 1 um"


def test_an_identify_configuration_gets_a_row_saying_why_it_is_skipped(tmp_path, fake_reports):
    """The input of esp identify ([machine] and [identify]) is not analysed, but listed:
    a ``skip`` line, its verdict in summary.csv and summary.md, no report, exit code of
    the others."""
    root = tmp_path / "root"
    write(root / "a" / "machine.toml", machine_text("A", 1.0))
    ident = machine_text("I", 1.0, extra="\n[identify]\nk = 2\n[identify.measurements]\n")
    write(root / "ident" / "machine.toml", ident)
    out = tmp_path / "out"
    res = batch(root, "--out", out)
    assert res.exit_code == 0, res.output
    assert "skip ident/machine.toml  skipped: an identify configuration" in res.output
    assert "2 machines: 1 pass, 0 fail, 0 error, 1 skipped" in res.output
    rows = read_rows(out)
    assert [r["file"] for r in rows] == ["a/machine.toml", "ident/machine.toml"]
    assert rows[1]["verdict"].startswith("skipped: an identify configuration")
    assert "run esp identify" in rows[1]["verdict"]
    assert rows[1]["report"] == "" and rows[1]["error"] == ""
    assert fake_reports == ["a__machine"]
    markdown = (out / "summary.md").read_text(encoding="utf-8")
    assert "| ident/machine.toml |" in markdown and "skipped: an identify" in markdown
    assert not (out / "ident__machine").exists()
