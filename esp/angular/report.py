"""The ``--out`` folder of ``esp angular``: ``report.pdf`` in the document style of every
esp report, ``angular.png`` and ``result.json``."""

from __future__ import annotations

from pathlib import Path

from esp.angular.text import DIRECTION_WORDS, file_name, number_text
from esp.core.angular import IndirectAngle
from esp.report.provenance import Provenance

__all__ = ["write_angular_report"]


def write_angular_report(
    folder: Path, result: IndirectAngle, text: str, provenance: Provenance
) -> None:
    """``report.pdf``, ``angular.png`` and ``result.json`` of ``--out``: the document in
    the style of every esp report (:mod:`esp.report.document`)."""
    from esp.report.document import (
        Document,
        Headline,
        summary,
        text_report,
        title_fields,
        user_text_value,
    )
    from esp.report.epoch import report_date
    from esp.report.jsonout import dumps
    from esp.report.profile_plots import profile_runs_figure, save_png

    (folder / "result.json").write_text(
        dumps({**result.to_dict(), "provenance": provenance.to_dict()}), encoding="utf-8"
    )
    fig = profile_runs_figure(result.profile)
    save_png(fig, folder / "angular.png")
    chosen = result.curve(result.direction)
    assert chosen is not None
    machine = user_text_value(provenance, ("machine", "machine name"))
    files = f"{file_name(result.reference)} and {file_name(result.shifted)}"
    doc = Document(
        "Angular error from two linear measurements",
        f"{machine}: {files}" if machine else files,
        report_date(),
        title_fields(provenance=provenance),
    )
    word = DIRECTION_WORDS[result.direction]
    summary(
        doc.lay,
        [
            Headline(
                f"Range of the {word} angle",
                f"{number_text(float(chosen.max() - chosen.min()))} µm/m",
            ),
            Headline("Smallest", f"{number_text(float(chosen.min()))} µm/m"),
            Headline("Largest", f"{number_text(float(chosen.max()))} µm/m"),
        ],
    )
    doc.lay.paragraph(
        "Uncertainty: not evaluated (the angle is derived from the two measurements as given).",
        size=8.3,
        colour="0.3",
    )
    head, _, rest = text.partition("\n\n")
    doc.section("Set-up")
    pairs = []
    for line in head.splitlines():
        key, _, value = line.partition(" ")
        pairs.append((key.capitalize(), value.strip()))
    doc.lay.pairs(pairs)
    doc.section("Angle at every target")
    text_report(doc.lay, rest.split("\n\nwritten ")[0], skip=1)
    doc.figure(fig, "the angle of every run against position")
    doc.write(folder / "report.pdf", provenance)
