"""The ``esp`` command line: a thin layer that parses options, calls the library and
renders. It is the only place that knows about exit codes:

* 0 -- success
* 1 -- a threshold was not met (batch)
* 2 -- bad input: a malformed file, a configuration error, a value out of range, an
  option the parser refuses, work refused (a limit, a target that may not be written)
* 130 -- interrupted (Ctrl-C)

Every error is one line on standard error, ``esp: error: ...``, with no usage block and
no traceback. Subcommands are loaded when they are run (:data:`COMMANDS`), so
``esp --version`` and ``esp --help`` import neither matplotlib nor pandas.
"""

from __future__ import annotations

import gc
import importlib
import importlib.util
import os
import re
import sys
import warnings
from collections.abc import Sequence
from pathlib import PurePath
from typing import Any, NamedTuple, TextIO

import click

from esp._version import __version__
from esp.core.errors import EspError, EspWarning
from esp.core.text import one_line

__all__ = ["BLAS_THREADS", "COMMANDS", "INTERRUPTED", "main", "one_line", "run"]

#: the exit code of a command interrupted by Ctrl-C (128 + SIGINT, as shells report it)
INTERRUPTED = 130


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
    "identify": _Entry(
        "esp.cli.identify",
        "identify_command",
        "Identify error components from ball plates, ballbars, trackers.",
    ),
    "ballbar": _Entry(
        "esp.cli.ballbar", "ballbar_command", "ISO 230-4 circular test of a ballbar file."
    ),
    "skew": _Entry(
        "esp.cli.skew", "skew_command", "Squareness and scale from a square or probed points."
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
            _check_environment()
            return super().invoke(ctx)
        except EspError as exc:
            _fail(str(exc))
        except OSError as exc:
            name = _file_of(exc)
            what = exc.strerror or str(exc)
            _fail(f"{name}: {what}" if name else what)

    def main(
        self,
        args: Sequence[str] | None = None,
        prog_name: str | None = None,
        complete_var: str | None = None,
        standalone_mode: bool = True,
        **extra: Any,
    ) -> Any:
        with warnings.catch_warnings():
            _show_esp_warnings()
            return self._main(args, prog_name, complete_var, standalone_mode, **extra)

    def _main(
        self,
        args: Sequence[str] | None,
        prog_name: str | None,
        complete_var: str | None,
        standalone_mode: bool,
        **extra: Any,
    ) -> Any:
        if standalone_mode:
            _quiet_broken_pipe()
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
        except click.Abort as exc:
            if isinstance(exc.__cause__, KeyboardInterrupt):
                _fail("interrupted", INTERRUPTED)
            _fail("aborted", 1)
        except KeyboardInterrupt:
            _fail("interrupted", INTERRUPTED)
        if not standalone_mode:
            return rv
        sys.exit(rv if isinstance(rv, int) else 0)


#: the temporary names of esp.io.outputs and esp.io.atomic: ".NAME.esp-stage-PID.START.XXXX"
#: (a staged folder, its owner in its name), ".NAME.XXXXXXXX.tmp" or ".NAME.XXXXXXXX.ext" (a
#: staged file)
_STAGED_FOLDER = re.compile(r"^\.(.+?)\.esp-stage-[A-Za-z0-9_.]+$")
_STAGED_FILE = re.compile(r"^\.(.+)\.[a-z0-9_]{8}(\.[A-Za-z0-9]+)$")


def _file_of(exc: OSError) -> str | None:
    """The file an :class:`OSError` is about, as the user named it: its ``filename``, or
    for an error that names none (a full disk, ENOSPC, raised by a write) the path of
    the innermost :class:`pathlib.Path` method that was writing; a staging name is shown
    as the target it stands for."""
    name = getattr(exc, "filename", None)
    if name is None:
        tb = exc.__traceback__
        while tb is not None:
            here = tb.tb_frame.f_locals.get("self")
            if isinstance(here, PurePath):
                name = str(here)
            tb = tb.tb_next
    if name is None:
        return None
    parts = list(PurePath(os.fsdecode(name)).parts)
    for i, part in enumerate(parts):
        m = _STAGED_FOLDER.match(part)
        if m:
            parts[i] = m.group(1)
        elif i == len(parts) - 1:
            m = _STAGED_FILE.match(part)
            if m and (m.group(2) == ".tmp" or m.group(1).endswith(m.group(2))):
                parts[i] = m.group(1)
    return str(PurePath(*parts))


class _Stdout:
    """Standard output, except that a reader that has gone away (a broken pipe:
    ``esp batch ... | head -1``) ends the output quietly instead of the command: the
    command finishes, writes its files and exits with its own code. The descriptor is
    pointed at the null device, so that nothing later (the interpreter's last flush
    included) fails on it."""

    def __init__(self, stream: TextIO) -> None:
        self._stream = stream
        self._gone = False

    def write(self, text: str) -> int:
        if self._gone:
            return len(text)
        try:
            return self._stream.write(text)
        except BrokenPipeError:
            self._away()
            return len(text)

    def flush(self) -> None:
        if self._gone:
            return
        try:
            self._stream.flush()
        except BrokenPipeError:
            self._away()

    def _away(self) -> None:
        self._gone = True
        try:
            null = os.open(os.devnull, os.O_WRONLY)
            try:
                os.dup2(null, self._stream.fileno())
            finally:
                os.close(null)
        except (OSError, ValueError, AttributeError):
            pass  # no descriptor (a test's buffer): nothing is written any more anyway

    def __getattr__(self, name: str) -> Any:
        return getattr(self._stream, name)


def _quiet_broken_pipe() -> None:
    if sys.stdout is not None and not isinstance(sys.stdout, _Stdout):
        sys.stdout = _Stdout(sys.stdout)  # type: ignore[assignment]


def _check_environment() -> None:
    """What every command needs of its environment, before any work: esp draws with Agg
    whatever ``MPLBACKEND`` says (a value matplotlib does not know would fail its import),
    and a malformed ``SOURCE_DATE_EPOCH`` is refused in one line
    (:func:`esp.report.epoch.source_date_epoch`) rather than deep in the PDF writer."""
    from esp.report.epoch import source_date_epoch

    os.environ["MPLBACKEND"] = "agg"
    source_date_epoch()


def _show_esp_warnings() -> None:
    """Inside a :func:`warnings.catch_warnings` block: show every
    :class:`~esp.core.errors.EspWarning` (each message once) as one line on standard error,
    ``esp: warning: ...``; other warnings as Python shows them."""
    shown = warnings.showwarning

    def show(
        message: Warning | str,
        category: type[Warning],
        filename: str,
        lineno: int,
        file: TextIO | None = None,
        line: str | None = None,
    ) -> None:
        if issubclass(category, EspWarning):
            click.echo(f"esp: warning: {one_line(str(message))}", err=True)
        else:
            shown(message, category, filename, lineno, file, line)

    warnings.simplefilter("default", EspWarning)
    warnings.showwarning = show


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


#: the thread counts of the BLAS libraries numpy may be built with (OpenBLAS, MKL, an
#: OpenMP build of either, Apple's Accelerate), which :func:`run` sets to 1 unless the
#: environment names them
BLAS_THREADS = (
    "OPENBLAS_NUM_THREADS",
    "MKL_NUM_THREADS",
    "OMP_NUM_THREADS",
    "VECLIB_MAXIMUM_THREADS",
)


def run() -> None:
    """The ``esp`` program (its console script, and ``python -m esp``): :func:`main` in a
    process that ends when it returns.

    Its linear algebra runs on one thread (:data:`BLAS_THREADS`, set before numpy is
    loaded; a value the environment gives is kept). A BLAS pool's threads spin after each
    call that woke them: on two cores they cost the gantry's report 0.3-0.5 s of CPU with
    numpy 2.4 and 1.5-2.3 s with numpy 1.25, and its wall time was no shorter with them.
    ``esp batch --jobs`` and a report's ``--jobs`` use processes, which threads would
    oversubscribe (docs/commands.md, "Environment").

    The process gives its memory back to the system whole at its end, so the objects it
    holds then (matplotlib's modules, the figures of a report) are frozen out of the
    collector's last pass over them at exit, about 0.2 s of CPU after a report. Every file
    a command writes is closed before it returns; nothing is left for that pass to finish.
    """
    for key in BLAS_THREADS:
        os.environ.setdefault(key, "1")
    try:
        main(prog_name="esp")
    finally:
        gc.freeze()


if __name__ == "__main__":  # pragma: no cover
    run()
