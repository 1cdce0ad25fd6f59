"""The list of commands of the ``esp`` group; each lives in a module of its own."""

from __future__ import annotations

from esp.cli.analyse import analyse_command
from esp.cli.angular import angular_command
from esp.cli.batch import batch_command
from esp.cli.inspect import inspect_command
from esp.cli.iso230 import iso230_command

ALL: list = [analyse_command]
ALL.append(inspect_command)
ALL.append(iso230_command)
ALL.append(angular_command)
ALL.append(batch_command)
