"""Reading the PDF files esp writes, for the tests: the strings of each page with their
positions, as pypdf extracts them."""

from __future__ import annotations

from pathlib import Path

import pypdf


def page_texts(path: Path) -> list[list[tuple[float, float, str]]]:
    """Per page, the (x, y, text) of every string drawn (PDF points from the bottom
    left)."""
    pages = []
    for page in pypdf.PdfReader(str(path)).pages:
        found: list[tuple[float, float, str]] = []

        def visit(text, cm, tm, font, size, found=found):
            if text.strip():
                m = pypdf.mult(tm, cm)
                found.append((m[4], m[5], text.strip()))

        page.extract_text(visitor_text=visit)
        pages.append(found)
    return pages
