"""The list of commands of the ``esp`` group; each lives in a module of its own."""

from __future__ import annotations

ALL: list = []
