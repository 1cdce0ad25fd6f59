"""Helpers shared by the commands: writing JSON to a path or standard output."""

from __future__ import annotations

from pathlib import Path

import click

from esp.io.atomic import write_text
from esp.report.jsonout import dumps

__all__ = ["emit_json"]


def emit_json(obj, target: str) -> None:
    """Write ``obj`` as JSON to ``target``: ``"-"`` for standard output, else a path
    (written atomically)."""
    text = dumps(obj)
    if target == "-":
        click.echo(text, nl=False)
    else:
        write_text(Path(target), text)
