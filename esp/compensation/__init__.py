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
* :mod:`esp.compensation.build` -- the tables of a format built from that evaluation, so
  they follow the machine's model;
* :mod:`esp.compensation.linuxcnc`, :mod:`esp.compensation.twincat`,
  :mod:`esp.compensation.isg_volumetric`, :mod:`esp.compensation.iso_csv` -- one module per
  controller format, each with a writer and an independent reader written from the
  vendor's documentation (cited in ``docs/compensation.md``);
* :mod:`esp.compensation.predict` -- the residual after compensation: the machine's error
  field with each table, as read back from its files, applied as its controller applies
  it.

The numeric modules import only numpy and the standard library.
"""

from __future__ import annotations

__all__ = ["FORMATS"]

#: format name -> one-line description (the command's --format choices)
FORMATS = {
    "linuxcnc": "LinuxCNC joint compensation files (COMP_FILE, nominal/forward/reverse)",
    "twincat-lead": "TwinCAT CNC / ISG leadscrew error compensation lists (kw.ssfk.*)",
    "twincat-cross": "TwinCAT CNC / ISG leadscrew and cross compensation (kw.ssfk, kw.crosscomp)",
    "twincat-plane": "TwinCAT CNC / ISG leadscrew and plane compensation (kw.ssfk, kw.crosscomp2)",
    "isg-volumetric": "TwinCAT CNC / ISG volumetric compensation, ISG CSV with ISO 230-1 names",
    "iso-csv": "plain CSV of the ISO 230-1 component errors of each axis and the squareness",
}
