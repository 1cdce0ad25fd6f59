"""Read a machine description (``machine.toml``) into a :class:`esp.core.machine.Machine`.

* :mod:`esp.config.reader` -- the checking primitives and the reading of a TOML file;
* :mod:`esp.config.sources` -- error sources: files, constants, points, derived angles;
* :mod:`esp.config.machine` -- the sections of ``machine.toml``;
* :mod:`esp.config.uncertainty` -- the ``[uncertainty]`` table.

Every key is documented in ``docs/configuration.md``.
"""

from esp.config.machine import (
    ANALYSIS_KEYS,
    AXIS_KEYS,
    ERROR_KEYS,
    MACHINE_KEYS,
    SECTIONS,
    TOOL_KEYS,
    load_machine,
    machine_from_dict,
)
from esp.config.sources import SOURCE_BUILDERS, SOURCE_KEYS, SOURCE_OPTIONS

__all__ = [
    "ANALYSIS_KEYS",
    "AXIS_KEYS",
    "ERROR_KEYS",
    "MACHINE_KEYS",
    "SECTIONS",
    "SOURCE_BUILDERS",
    "SOURCE_KEYS",
    "SOURCE_OPTIONS",
    "TOOL_KEYS",
    "load_machine",
    "machine_from_dict",
]
