"""Every number option of every command goes through the one value check: walked from the
command group itself, so that an option added later is held to it without a new test.

A number option is refused in one line naming it, exit code 2, when it is not finite
(``nan``, ``inf``), beyond any float (``1e400``) or beyond its quantity's range
(``1e308``), and when it is negative where its range starts at 0 or above."""

from __future__ import annotations

import click
import pytest
from click.testing import CliRunner

from esp.cli import main
from esp.cli.options import Number
from esp.core.values import QUANTITIES


def _commands():
    ctx = click.Context(main)
    for name in main.list_commands(ctx):
        yield name, main.get_command(ctx, name)


def _numeric(param):
    return isinstance(param.type, Number | click.types.FloatParamType | click.types.IntParamType)


NUMERIC = [
    pytest.param(name, p, id=f"{name} {p.opts[0]}")
    for name, cmd in _commands()
    for p in cmd.params
    if isinstance(p, click.Option) and _numeric(p)
]


def _lowest(param):
    """The lowest value the option's type allows (None: no lower bound)."""
    t = param.type
    if isinstance(t, Number):
        q = QUANTITIES[t.quantity] if isinstance(t.quantity, str) else t.quantity
        return q.low
    return getattr(t, "min", None)


def refused(command, option, value):
    result = CliRunner().invoke(main, [command, option, value])
    assert result.exit_code == 2, (command, option, value, result.output)
    assert "Traceback" not in result.output
    err = result.stderr
    assert err.startswith("esp: error: ") and err.count("\n") == 1, err
    assert option in err, err
    return err


def test_the_walk_finds_the_number_options():
    names = {(n, p.opts[0]) for n, p in (x.values for x in NUMERIC)}
    assert ("compensate", "--max-file-mb") in names
    assert ("batch", "--max-uncertainty") in names
    assert len(names) >= 10


@pytest.mark.parametrize("command, param", NUMERIC)
def test_a_float_option_is_read_by_the_value_check(command, param):
    """A float option has the type Number (esp.core.values), never click's float or
    FloatRange, which take nan, inf and 1e308; a whole number option has a range."""
    t = param.type
    if isinstance(t, click.types.IntParamType):
        assert isinstance(t, click.IntRange) and t.min is not None, (command, param.opts)
    else:
        assert isinstance(t, Number), (command, param.opts, t)


@pytest.mark.parametrize("value", ["nan", "inf", "-inf", "1e400", "1e308"])
@pytest.mark.parametrize("command, param", NUMERIC)
def test_a_number_option_refuses_what_is_not_a_finite_number_in_range(command, param, value):
    refused(command, param.opts[0], value)


@pytest.mark.parametrize("command, param", NUMERIC)
def test_a_number_option_refuses_a_negative_value_where_none_is_possible(command, param):
    low = _lowest(param)
    if low is None or low < 0:
        pytest.skip("a negative value is possible")
    refused(command, param.opts[0], "-1")
