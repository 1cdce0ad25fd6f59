"""The devices a machine may carry at either end of its chain: a servo head carrying the
tool (Freeman & Ford 2003) and a rotary table carrying the workpiece (a C table, an A/C or
B/C trunnion), each a kinematic chain with the values of its parameters and small errors
(numpy only; their description files are read by :mod:`esp.config.devices`). The
``esp head`` command's maps, protocols and reports are in :mod:`esp.heads`.

* :mod:`~esp.core.devices.device` -- what the two share: a chain with the values of its
  parameters and errors, their checks and settings (:class:`Device`);
* :mod:`~esp.core.devices.head` -- a head: its chain and values (:func:`head_from_chain`);
* :mod:`~esp.core.devices.head_evaluate` -- nominal tool tip and axis, first- and
  second-order and exact errors of a head at many settings (:func:`evaluate_head`), and
  what a five-axis analysis needs of it (:func:`head_offsets`);
* :mod:`~esp.core.devices.table` -- a table: its chain and the values of its parameters and
  errors, constants or curves over an angle (:func:`table_from_chain`);
* :mod:`~esp.core.devices.table_curves` -- a component error motion over its axis' angle,
  interpolated periodically (:class:`Curve`);
* :mod:`~esp.core.devices.table_effects` -- each table error's first-order effect, affine in
  the tool tip's machine position, per setting (:func:`table_terms`).

See ``docs/heads.md`` and ``docs/rotary.md``.
"""

from esp.core.devices.device import Device
from esp.core.devices.table import Table, table_from_chain
from esp.core.devices.table_curves import Curve
from esp.core.devices.table_effects import (
    TableTerm,
    TableTerms,
    table_angles,
    table_terms,
    tip_chain,
)

__all__ = [
    "Curve",
    "Device",
    "Table",
    "TableTerm",
    "TableTerms",
    "table_angles",
    "table_from_chain",
    "table_terms",
    "tip_chain",
]
