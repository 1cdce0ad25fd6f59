"""The ``esp`` command line: a thin layer that parses options, calls the library and
renders. It is the only place that knows about exit codes:

* 0 -- success
* 1 -- a threshold was not met (batch)
* 2 -- bad input: a malformed file, a configuration error, a value out of range, an
  option the parser refuses

Every error is one line on standard error, ``esp: error: ...``, with no usage block and
no traceback. Subcommands are loaded when they are run (:data:`COMMANDS`), so
``esp --version`` and ``esp --help`` import neither matplotlib nor pandas.
"""

from __future__ import annotations

import atexit
import gc
import importlib
import importlib.util
import sys
import warnings
from typing import Any, NamedTuple

import click

from esp._version import __version__
from esp.errors import EspError, EspWarning
from esp.text import one_line

__all__ = ["COMMANDS", "main", "one_line"]


class _Entry(NamedTuple):
    module: str
    attribute: str
    help: str


#: every subcommand: name -> where it lives and its one-line help (shown by ``esp --help``
#: without importing it). An entry whose module is not installed is not offered.
COMMANDS: dict[str, _Entry] = {
    "analyse": _Entry(
        "esp.cli.analyse", "analyse_command", "Volumetric and planar accuracy of a machine."
    ),
    "batch": _Entry("esp.cli.batch", "batch_command", "Analyse many machines; pass/fail for CI."),
    "inspect": _Entry("esp.cli.inspect", "inspect_command", "Show what a measurement file holds."),
    "iso230-2": _Entry(
        "esp.cli.iso230", "iso230_command", "ISO 230-2 positioning accuracy of one axis."
    ),
    "angular": _Entry(
        "esp.cli.angular", "angular_command", "Angular error from two linear runs (.rta)."
    ),
    "derive": _Entry(
        "esp.cli.derive", "derive_command", "Nominal and error formulae of a kinematic chain."
    ),
    "head": _Entry(
        "esp.cli.head", "head_command", "Errors of a servo head over its angles; protocols."
    ),
    "parallel": _Entry(
        "esp.cli.parallel", "parallel_command", "Error transmission of a serial-parallel machine."
    ),
    "compensate": _Entry(
        "esp.cli.compensate", "compensate_command", "Compensation tables for CNC controllers."
    ),
    "diagonals": _Entry(
        "esp.cli.diagonals", "diagonals_command", "ISO 230-6 diagonals predicted and checked."
    ),
    "compare": _Entry(
        "esp.cli.compare", "compare_command", "Compare two calibrations of one machine."
    ),
}


def _fail(message: str, code: int = 2) -> None:
    click.echo(f"esp: error: {one_line(message)}", err=True)
    sys.exit(code)


class EspGroup(click.Group):
    """A click group whose subcommands load on use, and whose every failure -- the
    library's typed errors, an unreadable file, an option the parser refuses -- is one
    line and exit code 2."""

    def list_commands(self, ctx: click.Context) -> list[str]:
        return [name for name, e in COMMANDS.items() if importlib.util.find_spec(e.module)]

    def get_command(self, ctx: click.Context, cmd_name: str) -> click.Command | None:
        entry = COMMANDS.get(cmd_name)
        if entry is None or not importlib.util.find_spec(entry.module):
            return None
        return getattr(importlib.import_module(entry.module), entry.attribute)

    def format_commands(self, ctx: click.Context, formatter: click.HelpFormatter) -> None:
        rows = [(name, COMMANDS[name].help) for name in self.list_commands(ctx)]
        if rows:
            with formatter.section("Commands"):
                formatter.write_dl(rows)

    def invoke(self, ctx: click.Context) -> Any:
        try:
            return super().invoke(ctx)
        except EspError as exc:
            _fail(str(exc))
        except OSError as exc:
            name = getattr(exc, "filename", None)
            what = exc.strerror or str(exc)
            _fail(f"{name}: {what}" if name else what)

    def main(self, args=None, prog_name=None, complete_var=None, standalone_mode=True, **extra):
        with warnings.catch_warnings():
            _show_esp_warnings()
            return self._main(args, prog_name, complete_var, standalone_mode, **extra)

    def _main(self, args, prog_name, complete_var, standalone_mode, **extra):
        if standalone_mode:
            _end_without_collecting()
        try:
            rv = super().main(
                args, prog_name or "esp", complete_var, standalone_mode=False, **extra
            )
        except click.UsageError as exc:
            hint = ""
            if exc.ctx is not None and exc.ctx.command is not self:
                hint = f" (see '{exc.ctx.command_path} --help')"
            elif exc.ctx is not None:
                hint = " (see 'esp --help')"
            _fail(exc.format_message() + hint)
        except click.ClickException as exc:
            _fail(exc.format_message(), exc.exit_code)
        except click.Abort:
            _fail("aborted", 1)
        if not standalone_mode:
            return rv
        sys.exit(rv if isinstance(rv, int) else 0)


def _show_esp_warnings() -> None:
    """Inside a :func:`warnings.catch_warnings` block: show every
    :class:`~esp.errors.EspWarning` (each message once) as one line on standard error,
    ``esp: warning: ...``; other warnings as Python shows them."""
    shown = warnings.showwarning

    def show(message, category, filename, lineno, file=None, line=None):
        if issubclass(category, EspWarning):
            click.echo(f"esp: warning: {one_line(str(message))}", err=True)
        else:
            shown(message, category, filename, lineno, file, line)

    warnings.simplefilter("default", EspWarning)
    warnings.showwarning = show


_ENDING: list[bool] = []


def _end_without_collecting() -> None:
    """Once per process that runs a command: at exit, after every other exit handler,
    freeze the garbage collector (:func:`gc.freeze`), so that interpreter shutdown does
    not visit every object left (the figures of a report, the analysis) only for the
    operating system to free them anyway -- about a tenth of a report's time
    (docs/performance.md). Every file a command writes is complete and closed before it
    returns; nothing is left for a finaliser to do."""
    if not _ENDING:
        _ENDING.append(True)
        atexit.register(gc.freeze)


@click.group(cls=EspGroup, context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(__version__, "--version", prog_name="esp")
def main() -> None:
    """esp -- volumetric accuracy of machine tools and CMMs from their measured errors.

    \b
    Examples:
      esp inspect data/examples/gantry/X-linear.rtl
      esp iso230-2 data/examples/gantry/X-linear.rtl --json -
      esp analyse data/examples/gantry/machine.toml
      esp analyse data/examples/gantry/machine.toml --out gantry-report
      esp batch data/examples --out reports --max-volumetric 50
    """


if __name__ == "__main__":  # pragma: no cover
    main()
