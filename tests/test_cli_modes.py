"""Options that belong to modes of a command (:class:`esp.cli.options.ModalCommand`)."""

from __future__ import annotations

import click
from click.testing import CliRunner

from esp.cli.options import ModalCommand


@click.command(
    cls=ModalCommand,
    mode_of=lambda given: "b" if given.get("b") else "a",
    modes={"x": frozenset({"a"}), "b": frozenset({"b"})},
    refusal=lambda flag, mode: f"{flag} is not for mode {mode}",
)
@click.option("--x", type=int, default=1)
@click.option("--b", is_flag=True)
@click.option("--y", type=int)
def cmd(x: int, b: bool, y: int | None) -> None:
    click.echo(f"ran x={x} b={b} y={y}")


def test_an_option_of_another_mode_is_refused_before_the_command_runs():
    result = CliRunner().invoke(cmd, ["--b", "--x", "3"])
    assert result.exit_code == 2
    assert "--x is not for mode b" in result.output
    assert "ran" not in result.output


def test_a_default_is_not_a_given_option():
    """--x has a default; only an --x written on the command line belongs to a mode."""
    assert CliRunner().invoke(cmd, ["--b"]).output == "ran x=1 b=True y=None\n"


def test_options_of_every_mode_and_of_the_mode_given_pass():
    assert CliRunner().invoke(cmd, ["--x", "3", "--y", "4"]).output == "ran x=3 b=False y=4\n"
    assert CliRunner().invoke(cmd, ["--b", "--y", "4"]).exit_code == 0
