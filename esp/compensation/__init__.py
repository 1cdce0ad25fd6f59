"""Compensation tables for CNC controllers, written from the measured errors of a machine,
and the residual error predicted after the controller applies them.

Modules:

* :mod:`esp.compensation.model` -- the shared table model (:class:`CompensationSet`):
  one-dimensional axis tables, two-dimensional plane tables and component tables, all in
  esp's units and sign (a correction is added to the commanded position; it is the
  negative of the error);
* :mod:`esp.compensation.field` -- the one evaluation of the machine's error field the
  package uses: the machine prepared once (as :func:`esp.errors_at` prepares it) and
  evaluated at any points, restricted to some components, or with a table's values;
* :mod:`esp.compensation.build` -- the tables a format can hold (its
  :class:`~esp.compensation.formats.base.Capabilities`), built from that evaluation, so
  they follow the machine's model;
* :mod:`esp.compensation.formats` -- the registry of formats: one module per controller
  format, each with a writer, an independent reader written from the vendor's
  documentation (cited in ``docs/compensation.md``) and its limits, behind one interface
  (:class:`~esp.compensation.formats.base.Format`);
* :mod:`esp.compensation.predict` -- the residual after compensation: the machine's error
  field with each table, as read back from its files, applied as its controller applies
  it;
* :mod:`esp.compensation.workflow` -- the whole of ``esp compensate`` as one function:
  build, write, refuse oversized files, read back, predict.

The numeric modules import only numpy and the standard library.
"""

from __future__ import annotations

__all__ = ["FORMATS"]


def __getattr__(name: str) -> object:
    """``FORMATS``: format name -> one-line description, from the registry of formats
    (:func:`esp.compensation.formats.registry`), read when first asked for."""
    if name == "FORMATS":
        from esp.compensation.formats import registry

        return {n: f.description for n, f in registry().items()}
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
