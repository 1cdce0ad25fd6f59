"""The ``esp`` command line: a thin layer that parses options, calls the library and
renders. It is the only place that knows about exit codes:

* 0 -- success
* 1 -- a threshold was not met (batch)
* 2 -- bad input: a malformed file, a configuration error, a value out of range
"""

from __future__ import annotations

import sys

import click

from esp._version import __version__
from esp.errors import EspError

__all__ = ["main"]


class EspGroup(click.Group):
    """A click group that turns the library's typed errors into one line and exit code 2."""

    def invoke(self, ctx: click.Context):
        try:
            return super().invoke(ctx)
        except EspError as exc:
            click.echo(f"esp: error: {exc}", err=True)
            ctx.exit(2)
        except OSError as exc:
            name = getattr(exc, "filename", None)
            what = exc.strerror or str(exc)
            click.echo(f"esp: error: {name}: {what}" if name else f"esp: error: {what}", err=True)
            ctx.exit(2)


@click.group(cls=EspGroup, context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(__version__, "--version", prog_name="esp")
def main() -> None:
    """esp -- volumetric accuracy of Cartesian machines from their measured errors.

    \b
    Examples:
      esp inspect data/examples/gantry/X-linear.rtl
      esp iso230-2 data/examples/gantry/X-linear.rtl --json -
      esp analyse data/examples/gantry/machine.toml
      esp analyse data/examples/gantry/machine.toml --out gantry-report
      esp batch data/examples --out reports --max-volumetric 50
    """


def _register() -> None:
    from esp.cli import commands

    for command in commands.ALL:
        main.add_command(command)


_register()


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
