"""Exit codes and messages of the command line (docs/reliability.md, "Exit codes"): every
number an option gives is read by the one value check and refused with the option and the
text as given; Ctrl-C exits 130; a reader that goes away does not stop a command; a full
disk names the file; a malformed environment (SOURCE_DATE_EPOCH, MPLBACKEND) is refused in
one line or ignored, never a traceback."""

from __future__ import annotations

import errno
import io
import os
import subprocess
import sys
from pathlib import Path

import pytest
from click.testing import CliRunner

import esp.core.analysis
from esp.cli import INTERRUPTED, _file_of, _Stdout, main
from esp.core.errors import DataError
from esp.io.atomic import write_bytes

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "data" / "examples"
GANTRY = EXAMPLES / "gantry"
MINIMAL = ROOT / "tests" / "data" / "config" / "minimal.toml"
LINEAR = ROOT / "tests" / "data" / "linear_bidir.rtl"
HEAD = EXAMPLES / "heads" / "angle-head-fig3.toml"


def run(*args, env=None):
    return CliRunner().invoke(main, [str(a) for a in args], env=env)


def assert_one_line(res, *fragments: str, code: int = 2) -> None:
    assert res.exit_code == code, res.output
    assert res.stderr.startswith("esp: error: ") and res.stderr.count("\n") == 1, res.stderr
    assert "Traceback" not in res.output
    for fragment in fragments:
        assert fragment in res.stderr, res.stderr


# -- numbers given by options ---------------------------------------------------------------

DIAGONALS = ("diagonals", GANTRY / "machine.toml", "--measured", f"PPP={GANTRY}-diagonals/PPP.rtl")


@pytest.mark.parametrize(
    ("option", "value", "fragment"),
    [
        # "explained yes" with exit 0 before
        ("--measurement-u", "inf", "'--measurement-u': expected a finite number, found 'inf'"),
        # a numpy overflow warning and "explained yes" before
        ("--measurement-u", "1e300", "from 0 to 1000 um, found '1e300'"),
        # "U = nan µm" before
        ("--measurement-u", "nan", "expected a finite number, found 'nan'"),
        ("--measurement-u", "-1", "found '-1'"),
        # accepted before
        ("--measurement-u-per-m", "inf", "'--measurement-u-per-m': expected a finite number"),
        ("--measurement-u-per-m", "2e3", "per metre of length from 0 to 1000 um/m"),
        ("--step", "1_0", "'--step': expected a number, found '1_0'"),
    ],
)
def test_diagonals_refuse_an_absurd_measurement_uncertainty(option, value, fragment):
    assert_one_line(run(*DIAGONALS, option, value), fragment)


@pytest.mark.parametrize(
    ("args", "fragment"),
    [
        # --at X=1_000 was accepted, as files refuse 3_0
        (("analyse", MINIMAL, "--at", "X=1_000,Y=0,Z=0"), "X: expected a number, found '1_000'"),
        (("analyse", MINIMAL, "--at", "X=100000.0001,Y=0,Z=0"), "found '100000.0001'"),
        # "found 0" before: the value was flushed to 0 before it was shown
        (
            ("angular", LINEAR, LINEAR, "--displacement", "1e-300", "--datum", "0"),
            "at least 0.001 mm in size, found '1e-300'",
        ),
        (("batch", MINIMAL, "--out", "R", "--max-volumetric", "1_0"), "'--max-volumetric'"),
        (("batch", MINIMAL, "--out", "R", "--max-planar", "0"), "a threshold above 0"),
        # "value out of range" before
        (
            ("head", HEAD, "--at", "A=30,C=40", "--set", "G=1e10"),
            "--set G: expected a length within ±100000 mm, found 1e10",
        ),
        (("head", HEAD, "--at", "A=30,C=40", "--set", "G=1_0"), "--set: G: expected a number"),
        # a 97 m error with exit 0 before
        (
            ("head", HEAD, "--at", "A=30,C=40", "--set", "ThetaAs=1e9"),
            "within ±20626.5 arcsec (0.1 rad), found 1e9",
        ),
        # printed 1e8 µm before
        (
            (
                "derive",
                EXAMPLES / "chains" / "loh-2004-scmm.toml",
                "--at",
                "x=0,y=0,z=0",
                "--set",
                "ex_Y=1e8,dx_Y=1e8",
            ),
            "ex_Y: expected an angle error within ±100000 urad (0.1 rad), found 1e8",
        ),
        (("parallel", EXAMPLES / "parallel" / "machine.toml", "--pose", "z=3_00"), "'--pose'"),
    ],
)
def test_option_numbers_are_refused_as_given(tmp_path, monkeypatch, args, fragment):
    monkeypatch.chdir(tmp_path)
    assert_one_line(run(*args), fragment)
    assert list(tmp_path.iterdir()) == []


# -- Ctrl-C -------------------------------------------------------------------------------------


def test_ctrl_c_exits_130_not_1(monkeypatch):
    # exit 1 before, which for esp batch means "a threshold was exceeded"
    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(esp.core.analysis, "analyse", interrupted)
    res = run("analyse", MINIMAL)
    assert INTERRUPTED == 130
    assert res.exit_code == 130, res.output
    # click ends the line the terminal echoed "^C" on; then the one line
    assert res.stderr.lstrip("\n") == "esp: error: interrupted\n", res.stderr


# -- a reader that goes away ----------------------------------------------------------------------


class _Closed(io.StringIO):
    def write(self, text):
        raise BrokenPipeError(errno.EPIPE, "Broken pipe")

    def flush(self):
        raise BrokenPipeError(errno.EPIPE, "Broken pipe")

    def fileno(self):
        raise io.UnsupportedOperation("no descriptor")


def test_a_broken_pipe_ends_the_output_quietly():
    out = _Stdout(_Closed())
    assert out.write("first line\n") == len("first line\n")  # no BrokenPipeError
    out.flush()
    assert out.write("more\n") == 5  # and everything after it goes nowhere


@pytest.mark.slow
def test_batch_piped_into_head_finishes(tmp_path):
    """``esp batch ... | head -1``: aborted the whole batch on the broken pipe before."""
    machines = tmp_path / "machines"
    machines.mkdir()
    for i in range(3):
        text = MINIMAL.read_text(encoding="utf-8").replace('"Minimal"', f'"M{i}"')
        (machines / f"m{i}.toml").write_text(text, encoding="utf-8")
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    proc = subprocess.Popen(
        [sys.executable, "-m", "esp", "batch", str(machines), "--out", str(tmp_path / "R")],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        env=env,
    )
    assert proc.stdout is not None and proc.stderr is not None
    first = proc.stdout.readline()
    proc.stdout.close()  # the reader goes away after one line
    err = proc.stderr.read().decode()
    proc.stderr.close()
    assert proc.wait(timeout=120) == 0, err
    assert first.strip(), first  # one row was read
    assert "Traceback" not in err and "Broken pipe" not in err and "BrokenPipe" not in err
    assert (tmp_path / "R" / "summary.csv").is_file()  # the batch finished and wrote it


# -- a full disk names the file ----------------------------------------------------------------


def test_a_full_disk_names_the_file(tmp_path, monkeypatch):
    target = tmp_path / "r.json"

    def full(self, data):
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(Path, "write_bytes", full)
    with pytest.raises(OSError) as info:
        write_bytes(target, b"{}")
    assert info.value.errno == errno.ENOSPC and info.value.filename == str(target)
    assert list(tmp_path.iterdir()) == []


@pytest.mark.skipif(not os.path.exists("/dev/full"), reason="needs /dev/full")
def test_a_write_error_without_a_name_is_named_from_the_writer():
    with pytest.raises(OSError) as info:
        Path("/dev/full").write_text("x" * 10, encoding="utf-8")
    assert info.value.filename is None  # what Python gives: "No space left on device"
    assert _file_of(info.value) == "/dev/full"


def test_staging_names_are_shown_as_their_targets():
    staged = OSError(errno.ENOSPC, "No space", "/w/.R.esp-stage-k2j4_x9/report.pdf")
    assert _file_of(staged) == "/w/R/report.pdf"
    assert _file_of(OSError(errno.ENOSPC, "No space", "/w/.x.png.ab12cd_9.tmp")) == "/w/x.png"
    assert _file_of(OSError(errno.ENOSPC, "No space", "/w/.x.png.ab12cd_9.png")) == "/w/x.png"
    assert _file_of(OSError(errno.ENOSPC, "No space", "/w/notes.txt")) == "/w/notes.txt"


# -- the environment ----------------------------------------------------------------------------


@pytest.mark.parametrize(
    "args",
    [
        ("head", HEAD, "--out", "R"),
        ("parallel", EXAMPLES / "parallel" / "machine.toml", "--out", "R"),
        ("batch", MINIMAL, "--out", "R"),
        ("analyse", MINIMAL, "--out", "R"),
    ],
    ids=["head", "parallel", "batch", "analyse"],
)
def test_a_source_date_epoch_of_spaces_is_refused_before_any_work(tmp_path, monkeypatch, args):
    # a ValueError inside matplotlib's PDF backend before (esp read " " as not set)
    monkeypatch.chdir(tmp_path)
    res = run(*args, env={"SOURCE_DATE_EPOCH": " "})
    assert_one_line(res, "SOURCE_DATE_EPOCH: expected a whole number of seconds", "found ' '")
    assert list(tmp_path.iterdir()) == []


def test_source_date_epoch_spaces_only_is_refused_empty_is_not_set():
    from esp.report.epoch import source_date_epoch

    assert source_date_epoch({"SOURCE_DATE_EPOCH": ""}) is None
    assert source_date_epoch({"SOURCE_DATE_EPOCH": " 7 "}) == 7  # int() reads it so too
    with pytest.raises(DataError):
        source_date_epoch({"SOURCE_DATE_EPOCH": " "})


@pytest.mark.slow
def test_a_bogus_mplbackend_is_ignored(tmp_path):
    # a ValueError traceback from matplotlib's import before: esp draws with Agg
    env = {**os.environ, "PYTHONPATH": str(ROOT), "MPLBACKEND": "bogus"}
    proc = subprocess.run(
        [sys.executable, "-m", "esp", "iso230-2", str(LINEAR), "--plot", "x.png"],
        capture_output=True,
        text=True,
        cwd=tmp_path,
        env=env,
    )
    assert proc.returncode == 0, proc.stderr
    assert (tmp_path / "x.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert "Traceback" not in proc.stderr


@pytest.mark.parametrize("text", ["X=1_000", "X=inf", "X=0x10"])
def test_pairs_of_compensate_and_face_at_read_numbers_as_files_do(text):
    import click

    from esp.cli.compensate import parse_pairs

    with pytest.raises(click.BadParameter):
        parse_pairs(text, "--spacing")
    with pytest.raises(click.BadParameter):
        parse_pairs("X=1_0", "--axis-numbers", int)  # int() takes 1_0
    assert parse_pairs("X=50,Y=2.5", "--spacing") == {"X": 50.0, "Y": 2.5}
