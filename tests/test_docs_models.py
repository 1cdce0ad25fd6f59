"""docs/models.md holds the tables the code generates (docs/make_model_tables.py): the
printed terms that differ from the rigid-body model and the implied angle signs."""

from __future__ import annotations

import importlib.util
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def _generator():
    spec = importlib.util.spec_from_file_location("tables", ROOT / "docs" / "make_model_tables.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_models_page_holds_the_generated_tables():
    page = (ROOT / "docs" / "models.md").read_text(encoding="utf-8")
    tables = _generator()
    assert tables.differences_table() in page
    assert tables.signs_table() in page
    # the table names the two physical errors of the print
    assert "BwMTt | eq. 3.11 | M | `(none)` | `-Φ_T(B)·B_o`" in page
    assert "BMwTt | eq. 3.12" in page
