"""Rotary tables: a table carrying the workpiece (a C table, an A/C or B/C trunnion) as a
kinematic chain from the workpiece to the table's mount, with the ISO 230-7 errors of its
axes, and what each error does to the tool tip at each table setting (numpy only).

* :mod:`~esp.rotary.table` -- a table: its chain and the values of its parameters and
  errors, constants or curves over an angle (:func:`load_table`, :func:`table_from_dict`
  for a ``[table]`` table in any file);
* :mod:`~esp.rotary.curves` -- a component error motion over its axis' angle, read from a
  small CSV file, interpolated periodically (:class:`Curve`, :func:`read_curve`);
* :mod:`~esp.rotary.terms` -- each error's first-order effect, affine in the tool tip's
  machine position, per setting (:func:`table_terms`).

See ``docs/rotary.md``.
"""

from esp.rotary.curves import Curve, read_curve
from esp.rotary.table import (
    TABLE_KEYS,
    Table,
    load_table,
    table_from_chain,
    table_from_dict,
)
from esp.rotary.terms import TableTerm, TableTerms, table_angles, table_terms, tip_chain

__all__ = [
    "TABLE_KEYS",
    "Curve",
    "Table",
    "TableTerm",
    "TableTerms",
    "load_table",
    "read_curve",
    "table_angles",
    "table_from_chain",
    "table_from_dict",
    "table_terms",
    "tip_chain",
]
