"""The options of ``esp compensate`` that take numbers: each through the one value check,
refused in one line naming the option (exit 2), before any table is made."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from click.testing import CliRunner

from esp.cli import main

GANTRY = Path(__file__).resolve().parent.parent / "data" / "examples" / "gantry" / "machine.toml"


def run(*args):
    return CliRunner().invoke(main, ["compensate", str(GANTRY), *map(str, args)])


def one_line(result, *words):
    assert result.exit_code == 2, result.output
    assert "Traceback" not in result.output
    err = result.stderr
    assert err.startswith("esp: error: ") and err.count("\n") == 1, err
    for w in words:
        assert w in err, err
    return err


@pytest.mark.parametrize("value", ["nan", "inf", "1e308", "0", "-1", "1e-300"])
def test_max_file_mb_that_is_no_file_size_is_refused(value):
    """The issue's command: nan, inf and 1e308 gave a traceback (int() of them)."""
    one_line(
        run("--format", "linuxcnc", "--leave-uncorrected", "--max-file-mb", value),
        "--max-file-mb",
        repr(value),
    )


@pytest.mark.parametrize(
    "spacing, words",
    [
        ("X=5,X=7", ["--spacing", "X is given twice"]),
        ("1e9", ["--spacing", "'1e9'", "100000 mm"]),
        ("X=1e308", ["--spacing", "X:", "'1e308'"]),
        ("X=nan", ["--spacing", "X:", "finite", "'nan'"]),
        ("inf", ["--spacing", "finite"]),
        ("0", ["--spacing", "at least 0.001 mm"]),
        ("X=-50", ["--spacing", "X:", "'-50'"]),
        # beyond the axis' travel: the table would hold the two ends alone
        ("X=1200", ["--spacing for X", "travel of 1000 mm", "1200"]),
        ("5000", ["--spacing for X", "travel of 1000 mm"]),
    ],
)
def test_a_spacing_given_twice_or_absurd_is_refused(spacing, words):
    one_line(run("--format", "linuxcnc", "--leave-uncorrected", "--spacing", spacing), *words)


@pytest.mark.parametrize(
    "option, value, words",
    [
        ("--axis-numbers", "X=1,X=2", ["X is given twice"]),
        ("--axis-numbers", "X=0", ["from 1 to 2147483647", "'0'"]),
        ("--axis-numbers", "Y=1e308", ["Y:", "whole number", "'1e308'"]),
        ("--max-points", "ssfk=99999999999999", ["ssfk:", "from 1 to 2147483647"]),
        ("--max-points", "ssfk=nan", ["ssfk:", "'nan'"]),
        ("--cross", "Y=X,Y=Z", ["Y is given twice"]),
        ("--max-records", "99999999999999999999999", ["2147483647"]),
    ],
)
def test_the_other_pairs_and_whole_numbers_are_refused(option, value, words):
    one_line(run("--format", "twincat-cross", "--leave-uncorrected", option, value), option, *words)


def test_a_spacing_up_to_the_travel_is_taken(tmp_path):
    """The bound is the travel itself: X every 1000 mm is its two ends, as asked."""
    result = run(
        "--format",
        "linuxcnc",
        "--leave-uncorrected",
        "--spacing",
        "X=1000,Y=500",
        "--json",
        tmp_path / "c.json",
        "-q",
    )
    assert result.exit_code == 0, result.output
    doc = json.loads((tmp_path / "c.json").read_text())
    tables = {t["slave"]: t for t in doc["formats"][0]["tables"]}
    assert tables["X"]["points"] == 2 and tables["Y"]["points"] == 4
