"""The output steps every command shares: one gate for every path it writes, one place
that prints.

A command makes a :class:`CommandOutputs` with its inputs and its ``--json`` target as
soon as its options are read, checks every other target with :meth:`~CommandOutputs.file`,
:meth:`~CommandOutputs.figure` or :meth:`~CommandOutputs.folder` (all before any work),
does its work, stages what it writes, and ends with :meth:`~CommandOutputs.finish`, which
writes the JSON file, commits every output of the run together (all or none,
:class:`esp.io.outputs.Outputs`), prints the warnings on standard error and then the report
or the JSON on standard output. Standard output never holds anything else.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Iterable, Mapping
from pathlib import Path
from typing import Any

import click

from esp.core.errors import DataError
from esp.core.text import one_line
from esp.io.outputs import Outputs

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
    quiet : ``-q``: print neither the text report nor the warnings (the JSON of
        ``--json -`` is still printed: it is what was asked for)
    """

    def __init__(
        self,
        inputs: Iterable[str | os.PathLike[str]] = (),
        json_target: str | os.PathLike[str] | None = None,
        quiet: bool = False,
    ):
        super().__init__(inputs)
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
            from esp.report.pdf import source_date_epoch

            source_date_epoch()  # a malformed SOURCE_DATE_EPOCH is refused before any work
        self._figures[target] = fmt
        return target

    def save_figure(self, fig: Any, path: Path) -> None:
        """Stage ``fig`` for the figure target ``path``, in the format its suffix names."""
        from esp.report.profile_plots import save_figure

        save_figure(fig, self.stage_file(path), self._figures[path])

    def finish(
        self,
        *,
        text: str | Callable[[], str] | None = None,
        doc: Mapping[str, Any] | Callable[[], Mapping[str, Any]] | None = None,
        warnings: Iterable[str] | None = None,
    ) -> None:
        """Write the JSON file (``doc``, with ``"warnings"`` added when the command has
        warnings and the document does not carry them yet), commit every output of the
        run, print the warnings on standard error, then the JSON (``--json -``) or the
        text report on standard output."""
        warned = list(warnings) if warnings is not None else []
        data = None
        if self.wants_json and doc is not None:
            from esp.report.jsonout import dumps

            document = dict(doc() if callable(doc) else doc)
            if warnings is not None and not _carries_warnings(document):
                document["warnings"] = warned
            data = dumps(document)
        try:
            if self.json_path is not None and data is not None:
                self.write_file(self.json_path, data)
        except BaseException:
            self.discard()
            raise
        self.commit()
        warn(warned, self.quiet)
        if self.to_stdout and data is not None:
            click.echo(data, nl=False)
        elif not self.quiet and text is not None:
            click.echo(text() if callable(text) else text, nl=False)


def _carries_warnings(doc: Mapping[str, Any]) -> bool:
    """Whether ``doc`` lists its warnings already (at the top, or in its ``analysis``)."""
    analysis = doc.get("analysis")
    return "warnings" in doc or (isinstance(analysis, Mapping) and "warnings" in analysis)
