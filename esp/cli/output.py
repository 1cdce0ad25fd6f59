"""The output steps every command shares: one gate for every path it writes, one place
that prints.

A command makes a :class:`CommandOutputs` with its inputs and its ``--json`` target as
soon as its options are read, checks every other target with :meth:`~CommandOutputs.file`,
:meth:`~CommandOutputs.figure` or :meth:`~CommandOutputs.folder` (all before any work),
does its work, stages what it writes, and ends with :meth:`~CommandOutputs.finish`, which
writes the JSON file (with the run's :attr:`~CommandOutputs.provenance`: every input with
its SHA-256, the esp version, the configuration as given, the command line), commits every
output of the run together (all or none, :class:`esp.io.outputs.Outputs`), prints the
warnings on standard error, ``esp: report written to DIR`` for each ``--out`` folder, and
then the report or the JSON on standard output. Standard output never holds anything else.

While a long output builds, :meth:`~CommandOutputs.progress` shows what is being made on
one line of standard error, only when standard error is a terminal and not with ``-q``.
"""

from __future__ import annotations

import os
import sys
from collections.abc import Callable, Iterable, Mapping, Sequence
from contextlib import AbstractContextManager
from pathlib import Path
from types import TracebackType
from typing import TYPE_CHECKING, Any

import click

from esp.core.errors import DataError
from esp.core.text import one_line
from esp.io.outputs import Outputs
from esp.report.provenance import command_line

if TYPE_CHECKING:
    from esp.report.provenance import Provenance

__all__ = ["CommandOutputs", "warn"]


def warn(warnings: Iterable[str], quiet: bool = False) -> None:
    """Print each warning as one line ``esp: warning: ...`` on standard error (not with
    ``quiet``)."""
    if quiet:
        return
    for w in warnings:
        click.echo(f"esp: warning: {one_line(w)}", err=True)


class CommandOutputs(Outputs):
    """The targets of one command run (:class:`esp.io.outputs.Outputs`) and what it prints.

    Parameters
    ----------
    inputs : every file the command reads
    json_target : the value of ``--json``: a file, ``"-"`` for standard output, or None
    quiet : ``-q``: print neither the text report nor the warnings nor the progress (the
        JSON of ``--json -`` is still printed: it is what was asked for)
    command : the arguments after ``esp`` for the provenance; None takes them from the
        command being run (:func:`esp.report.provenance.command_line`)
    """

    def __init__(
        self,
        inputs: Iterable[str | os.PathLike[str]] = (),
        json_target: str | os.PathLike[str] | None = None,
        quiet: bool = False,
        command: Sequence[str] | None = None,
    ):
        given = tuple(os.fspath(p) for p in inputs)
        super().__init__(given)
        #: every input as the command names it, in the order read (for the provenance)
        self.given_inputs = given
        self._command = None if command is None else tuple(command)
        self._provenance: Provenance | None = None
        self._progress_width = 0
        self._sigterm: AbstractContextManager[None] | None = None
        self.quiet = quiet
        self.to_stdout = json_target is not None and os.fspath(json_target) == "-"
        self.json_path = (
            self.file(json_target, "--json")
            if json_target is not None and not self.to_stdout
            else None
        )
        self.wants_json = json_target is not None
        self._figures: dict[Path, str] = {}

    def figure(self, path: str | os.PathLike[str], option: str) -> Path:
        """Check a figure target: a file whose suffix names a format esp writes
        (:data:`esp.report.drawing.FIGURE_FORMATS`)."""
        from esp.report.drawing import FIGURE_FORMATS, figure_format

        target = self.file(path, option)
        fmt = figure_format(Path(path))
        if fmt is None:
            raise DataError(
                f"{option} {os.fspath(path)}: expected a figure file name ending in "
                f"{' or '.join(FIGURE_FORMATS)}, found {Path(path).suffix or 'no suffix'!r}"
            )
        if fmt == "pdf":
            from esp.report.epoch import source_date_epoch

            source_date_epoch()  # a malformed SOURCE_DATE_EPOCH is refused before any work
        self._figures[target] = fmt
        return target

    @property
    def command(self) -> tuple[str, ...]:
        """The arguments after ``esp`` of this run
        (:func:`esp.report.provenance.command_line`)."""
        if self._command is None:
            self._command = command_line()
        return self._command

    @property
    def provenance(self) -> Provenance:
        """What this run's outputs are made from: every input (read once, with its
        SHA-256, and for a Laser10 file its USER-TEXT and ENVIRONMENT), the esp version,
        the configuration as given and the command line
        (:func:`esp.report.provenance.collect`). Built once, on first use."""
        if self._provenance is None:
            from esp.report.provenance import collect

            self._provenance = collect(self.given_inputs, self.command)
        return self._provenance

    @property
    def shows_progress(self) -> bool:
        """Whether :meth:`progress` prints: standard error is a terminal and not ``-q``."""
        if self.quiet:
            return False
        try:
            return sys.stderr.isatty()
        except (AttributeError, ValueError):
            return False

    def progress(self, label: str) -> None:
        """Show ``esp: LABEL ...`` on one line of standard error, replacing the one
        shown before (only on a terminal, not with ``-q``; :attr:`shows_progress`). The
        line is cleared by :meth:`finish`, or by ``progress("")``."""
        if not self.shows_progress:
            return
        line = f"esp: {one_line(label)} ..." if label else ""
        pad = " " * max(0, self._progress_width - len(line))
        click.echo(f"\r{line}{pad}" + ("\r" if not line else ""), err=True, nl=False)
        self._progress_width = len(line)

    def _end_progress(self) -> None:
        if self._progress_width:
            self.progress("")
            self._progress_width = 0

    def stage_folder(self, path: str | os.PathLike[str]) -> Path:
        """:meth:`esp.io.outputs.Outputs.stage_folder`, and the progress line
        ``esp: building the report in DIR ...`` for an ``--out`` folder: every command's
        report is written into its staged folder right after."""
        staged = super().stage_folder(path)
        real = Path(os.path.realpath(os.path.abspath(path)))
        given, option = self._folders.get(real, (Path(path), ""))
        if option == "--out":
            self.progress(f"building the report in {os.fspath(given)}")
        return staged

    def write_documents(
        self, folder: Path, stem: str, text: str, doc: Mapping[str, Any]
    ) -> dict[str, Any]:
        """Write a report folder's ``STEM.json`` (``doc`` with the run's
        :attr:`provenance` last, the document ``--json`` writes too) and ``STEM.txt`` (the
        text report) into ``folder``, a folder staged by :meth:`stage_folder`; return the
        document as written."""
        from esp.report.jsonout import dumps

        written = {**doc, "provenance": self.provenance.to_dict()}
        (folder / f"{stem}.json").write_text(dumps(written), encoding="utf-8")
        (folder / f"{stem}.txt").write_text(text, encoding="utf-8")
        return written

    def __enter__(self) -> CommandOutputs:
        """Inside, SIGTERM ends the command through :meth:`__exit__`, which removes every
        staged file and folder (:func:`esp.report.workers.terminate_on_sigterm`, as
        ``esp batch`` does), instead of leaving a staging folder beside the target."""
        from esp.report.workers import terminate_on_sigterm

        super().__enter__()
        self._sigterm = terminate_on_sigterm()
        self._sigterm.__enter__()
        return self

    def __exit__(
        self,
        exc_type: type[BaseException] | None,
        exc: BaseException | None,
        tb: TracebackType | None,
    ) -> None:
        try:
            self._end_progress()  # so that an error's line starts on a clear line
            super().__exit__(exc_type, exc, tb)
        finally:
            sigterm = self._sigterm
            if sigterm is not None:
                self._sigterm = None
                sigterm.__exit__(None, None, None)

    def save_figure(self, fig: Any, path: Path, dpi: float | None = None) -> None:
        """Stage ``fig`` for the figure target ``path``, in the format its suffix names
        (at ``dpi``, by default the resolution of the profile figures)."""
        if dpi is None:
            from esp.report.profile_plots import save_figure

            save_figure(fig, self.stage_file(path), self._figures[path])
        else:
            from esp.report.drawing import save_figure as save_at

            save_at(fig, self.stage_file(path), dpi, self._figures[path])

    def finish(
        self,
        *,
        text: str | Callable[[], str] | None = None,
        doc: Mapping[str, Any] | Callable[[], Mapping[str, Any]] | None = None,
        warnings: Iterable[str] | None = None,
    ) -> None:
        """Write the JSON file (``doc``, with ``"warnings"`` added when the command has
        warnings and the document does not carry them yet, and ``"provenance"``, the
        run's :attr:`provenance`, last), commit every output of the run, print the
        warnings and ``esp: report written to DIR`` for each ``--out`` folder on standard
        error, then the JSON (``--json -``) or the text report on standard output."""
        warned = list(warnings) if warnings is not None else []
        data = None
        try:
            if self.wants_json and doc is not None:
                from esp.report.jsonout import dumps

                document = dict(doc() if callable(doc) else doc)
                if warnings is not None and not _carries_warnings(document):
                    document["warnings"] = warned
                document.setdefault("provenance", self.provenance.to_dict())
                data = dumps(document)
            if self.json_path is not None and data is not None:
                self.write_file(self.json_path, data)
        except BaseException:
            self.discard()
            raise
        written = [
            given
            for _staged, target in self._staged_folders
            for real, (given, option) in self._folders.items()
            if option == "--out" and real == Path(os.path.realpath(target))
        ]
        self.commit()
        self._end_progress()
        warn(warned, self.quiet)
        if not self.quiet:
            for folder in written:
                click.echo(f"esp: report written to {os.fspath(folder)}", err=True)
        if self.to_stdout and data is not None:
            click.echo(data, nl=False)
        elif not self.quiet and text is not None:
            click.echo(text() if callable(text) else text, nl=False)


def _carries_warnings(doc: Mapping[str, Any]) -> bool:
    """Whether ``doc`` lists its warnings already (at the top, or in its ``analysis``)."""
    analysis = doc.get("analysis")
    return "warnings" in doc or (isinstance(analysis, Mapping) and "warnings" in analysis)
