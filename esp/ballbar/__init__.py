"""Ballbar circular tests (``esp ballbar``): the ISO 230-4 figures F, G, G(b) and H, the
diagnosis of the machine's errors from the circle's shape, the test report and its
verdicts (docs/ballbar.md).

Modules: :mod:`~esp.ballbar.circles` (the lengths table of ``esp identify``),
:mod:`~esp.ballbar.angles` (the angle table of a home-made ballbar),
:mod:`~esp.ballbar.conditions` (the test conditions of a file's header),
:mod:`~esp.ballbar.analysis` (ISO 230-4), :mod:`~esp.ballbar.diagnosis`,
:mod:`~esp.ballbar.verdicts` (U and decisions), :mod:`~esp.ballbar.text`,
:mod:`~esp.ballbar.plots` and :mod:`~esp.ballbar.report` (matplotlib, loaded on use),
:mod:`~esp.ballbar.synthetic` (circles from the exact geometry).
"""

from esp.ballbar.analysis import CircleTest, DirectionResult, circle_tests, evaluate
from esp.ballbar.circles import Circle, Run, read_circles
from esp.ballbar.conditions import Conditions
from esp.ballbar.diagnosis import Diagnosis, Term, diagnose
from esp.ballbar.text import ballbar_dict, ballbar_text

__all__ = [
    "Circle",
    "CircleTest",
    "Conditions",
    "Diagnosis",
    "DirectionResult",
    "Run",
    "Term",
    "ballbar_dict",
    "ballbar_text",
    "circle_tests",
    "diagnose",
    "evaluate",
    "read_circles",
]
