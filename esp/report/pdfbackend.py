"""matplotlib's PDF writer, loaded without the font subsetter until a document needs it.

Importing matplotlib's PDF backend imports ``fontTools.subset`` (its module shared with
the PostScript backend does, at the top), about 0.2 s of CPU, nearly all the cost of the
import. The subsetter serves only to embed a TrueType font as Type 42
(``pdf.fonttype = 42``); esp's documents embed DejaVu Sans as Type 3 (matplotlib's
default), built from FreeType's outlines alone, so it is never used. :func:`pdf_pages`
loads the backend with a stand-in for the module that imports the real one at its first
use (any attribute asked of it) and from then on passes every use on to it, so that a
Type 42 document, or any other user of the module in the process, works as before.
"""

from __future__ import annotations

import importlib
import sys
import types
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from matplotlib.backends.backend_pdf import PdfPages

__all__ = ["SUBSET", "pdf_pages"]

#: the module deferred
SUBSET = "fontTools.subset"


class _Deferred(types.ModuleType):
    """Stands for :data:`SUBSET` until it is used: the first attribute asked of it
    imports the real module (which then replaces it in ``sys.modules`` and on its
    package); this and every later one is read from the real module."""

    def __getattr__(self, name: str) -> Any:
        if sys.modules.get(SUBSET) is self:
            del sys.modules[SUBSET]
        return getattr(importlib.import_module(SUBSET), name)


def _defer_subset() -> None:
    """Put the stand-in in place of :data:`SUBSET`, unless the module or the PDF
    backend is loaded already (or fontTools is missing: matplotlib's import then fails
    as it would)."""
    if SUBSET in sys.modules or "matplotlib.backends.backend_pdf" in sys.modules:
        return
    try:
        import fontTools  # the package alone: a few ms
    except ImportError:
        return
    stand_in = _Deferred(SUBSET)
    sys.modules[SUBSET] = stand_in
    fontTools.subset = stand_in  # type: ignore[attr-defined]  # what importing it sets


def pdf_pages() -> type[PdfPages]:
    """matplotlib's :class:`~matplotlib.backends.backend_pdf.PdfPages`, its backend
    loaded with the font subsetter deferred (:func:`_defer_subset`)."""
    _defer_subset()
    from matplotlib.backends.backend_pdf import PdfPages

    return PdfPages
