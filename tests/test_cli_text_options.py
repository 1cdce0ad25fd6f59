"""Numbers inside the text options of ``esp head``, ``esp derive``, ``esp parallel`` and
``esp analyse`` (``--at "A=30,C=40"``, ``--grid "A=0:90:5"``, ``--pose``, ``--set``,
``--angles``): each goes through the one value check with its range, and a grid's count of
values is bounded before any is made. Every bad value is refused in one line that names the
option the user typed, with exit code 2 and no traceback."""

from __future__ import annotations

from pathlib import Path

import pytest
from click.testing import CliRunner

from esp.cli import main

ROOT = Path(__file__).resolve().parent.parent
HEAD = ROOT / "data/examples/heads/angle-head-fig3.toml"
CHAIN = ROOT / "data/examples/heads/angle-head.toml"
PARALLEL = ROOT / "data/examples/parallel/machine.toml"
MACHINE = ROOT / "data/examples/gantry/machine.toml"

GRID_OK = "C=0:90:30"

CASES = [
    # esp head --grid: each of from, to, step, their order and the count of values
    (("head", HEAD, "--grid", f"A=0:90:1e-308,{GRID_OK}"), "--grid", "A.step"),
    (("head", HEAD, "--grid", "A=0:90:1e-308"), "--grid", "more than 1e+308"),
    (("head", HEAD, "--grid", f"A=-1e308:1e308:1e300,{GRID_OK}"), "--grid", "A.from"),
    (("head", HEAD, "--grid", f"A=0:90:1e-9,{GRID_OK}"), "--grid", "above the limit of 100000"),
    (("head", HEAD, "--grid", f"A=nan:90:1,{GRID_OK}"), "--grid", "A.from"),
    (("head", HEAD, "--grid", f"A=0:inf:1,{GRID_OK}"), "--grid", "A.to"),
    (("head", HEAD, "--grid", f"A=0:1e308:1,{GRID_OK}"), "--grid", "found '1e308'"),
    (("head", HEAD, "--grid", f"A=0:90:nan,{GRID_OK}"), "--grid", "A.step"),
    (("head", HEAD, "--grid", f"A=0:90:0,{GRID_OK}"), "--grid", "above zero, found 0"),
    (("head", HEAD, "--grid", f"A=0:90:-5,{GRID_OK}"), "--grid", "above zero, found -5"),
    (("head", HEAD, "--grid", f"A=90:0:5,{GRID_OK}"), "--grid", "from 90 > to 0"),
    # esp head --at, --set, --angles
    (("head", HEAD, "--at", "A=1e308,C=0"), "--at", "A: expected an angle within"),
    (("head", HEAD, "--at", "A=1e308"), "--at", "found 1e308"),
    (("head", HEAD, "--at", "A=30,C=-inf"), "--at", "C: expected a finite number"),
    (("head", HEAD, "--set", "G=1e308"), "--set", "expected a length within"),
    (("head", HEAD, "--set", "G=nan"), "--set", "G: expected a finite number"),
    (("head", HEAD, "--protocol", "--angles", "0,1e308"), "--angles", "found '1e308'"),
    (("head", HEAD, "--protocol", "--angles", "0,inf"), "--angles", "finite"),
    # esp derive --at, --set
    (("derive", CHAIN, "--at", "A=1e308,C=0"), "--at", "A: expected an angle within"),
    (("derive", CHAIN, "--at", "A=nan,C=0"), "--at", "A: expected a finite number"),
    (("derive", CHAIN, "--at", "A=30,C=40", "--set", "G=1e308"), "--set", "G: expected"),
    (("derive", CHAIN, "--at", "A=30,C=40", "--set", "G=inf"), "--set", "G: expected"),
    # esp parallel --pose
    (("parallel", PARALLEL, "--pose", "z=1e308,alpha=0,beta=0"), "--pose", "z: expected"),
    (("parallel", PARALLEL, "--pose", "z=300,alpha=nan,beta=0"), "--pose", "alpha: expected"),
    (("parallel", PARALLEL, "--pose", "z=300,alpha=0,beta=90"), "--pose", "beta: expected"),
    (("parallel", PARALLEL, "--pose", "z=300,alpha=0,beta=0,x=-inf"), "--pose", "x: expected"),
    # esp analyse --at
    (("analyse", MACHINE, "--at", "X=1e308,Y=0,Z=0"), "--at", "X: expected a position"),
    (("analyse", MACHINE, "--at", "X=0,Y=nan,Z=0"), "--at", "Y: expected a finite number"),
]


@pytest.mark.parametrize(("args", "option", "fragment"), CASES)
def test_a_bad_number_in_a_text_option_is_one_line_naming_the_option(args, option, fragment):
    res = CliRunner().invoke(main, [str(a) for a in args])
    assert res.exit_code == 2, res.output
    assert res.stdout == ""
    lines = res.stderr.splitlines()
    assert len(lines) == 1 and lines[0].startswith("esp: error: "), res.stderr
    assert "Traceback" not in res.stderr and "Warning" not in res.stderr
    line = lines[0]
    assert option in line, line
    assert fragment in line, line
    for other in ("angles.", "--at", "--set", "--grid", "--pose", "--angles"):
        if other != option and not option.startswith(other):
            assert other not in line, f"names {other}: {line}"


def test_a_grid_of_tiny_steps_is_refused_before_any_value_is_made():
    """The count is estimated as a float first: 90 / 1e-308 is beyond any integer a float
    converts to, and was an OverflowError."""
    from esp.core.errors import ConfigError
    from esp.heads.maps import MAX_AXIS_VALUES, grid_axis

    with pytest.raises(ConfigError) as info:
        grid_axis(0.0, 90.0, 1e-308, "map.A")
    assert info.value.key == "map.A.step"
    assert "more than 1e+308" in info.value.message
    assert "above the limit of 100000" in info.value.message
    # the limit itself holds: MAX_AXIS_VALUES values pass, one more is refused
    assert grid_axis(0.0, MAX_AXIS_VALUES - 1.0, 1.0).size == MAX_AXIS_VALUES
    with pytest.raises(ConfigError, match="100001"):
        grid_axis(0.0, float(MAX_AXIS_VALUES), 1.0)


def test_a_grid_whose_step_exceeds_its_span_is_its_start():
    from esp.heads.maps import grid_axis

    assert grid_axis(10.0, 90.0, 1e308).tolist() == [10.0]
    assert grid_axis(-60.0, 60.0, 30.0).tolist() == [-60.0, -30.0, 0.0, 30.0, 60.0]
