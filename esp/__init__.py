"""esp -- volumetric accuracy of Cartesian machines by synthesis of measured geometric errors.

A reimplementation and extension of ESP, the Error Simulation Program of the University of
Huddersfield (Longstaff 2002, chapters 3-4).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from os import PathLike
from typing import TYPE_CHECKING

from esp._version import __version__
from esp.core.errors import ConfigError, DataError, EspError, ParseError

if TYPE_CHECKING:
    import numpy as np
    import numpy.typing as npt
    import pandas

    from esp.core.evaluation import MachineEvaluation
    from esp.core.machine import Machine
    from esp.core.profile import ErrorProfile
    from esp.core.results import AnalysisResult, PointResult, ToolCase


def __getattr__(name: str) -> type[ErrorProfile]:
    # numpy-backed names load on first use, so ``esp --version`` imports nothing heavy
    if name == "ErrorProfile":
        from esp.core.profile import ErrorProfile

        return ErrorProfile
    raise AttributeError(f"module 'esp' has no attribute {name!r}")


def load_machine(path: str | PathLike[str]) -> Machine:
    """Read a ``machine.toml`` into a :class:`esp.core.machine.Machine` (see :mod:`esp.config`)."""
    from esp.config import load_machine as _load

    return _load(path)


def analyse(machine: Machine, progress: Callable[[int, int], None] | None = None) -> AnalysisResult:
    """Evaluate a machine over its volume (see :func:`esp.core.analysis.analyse`)."""
    from esp.core.analysis import analyse as _analyse

    return _analyse(machine, progress)


def evaluate(machine: Machine) -> MachineEvaluation:
    """The machine prepared for evaluation once; ``.case(tool)`` is the one evaluation of a
    tool case (see :func:`esp.core.evaluation.evaluate`)."""
    from esp.core.evaluation import evaluate as _evaluate

    return _evaluate(machine)


def errors_at(
    machine: Machine | AnalysisResult, points_mm: npt.ArrayLike, tool: ToolCase | None = None
) -> np.ndarray:
    """The X, Y, Z errors (µm) at many positions, shape (N, 3), relative to the datum, for
    one tool case (default: the first): ``evaluate(machine).case(tool).errors_at(points)``
    (see :meth:`esp.core.evaluation.Evaluation.errors_at`). Pass an analysis result for the
    evaluation of its worst case."""
    from esp.core.evaluation import evaluate as _evaluate

    if hasattr(machine, "evaluation") and hasattr(machine, "cases"):  # an AnalysisResult
        if tool is not None:
            found = [c.evaluation for c in machine.cases if c.tool == tool]
            if not found:
                raise DataError("errors_at: the tool case is not one of the result's cases")
            return found[0].errors_at(points_mm)  # type: ignore[union-attr]
        return machine.evaluation.errors_at(points_mm)
    return _evaluate(machine).case(tool).errors_at(points_mm)


def result_frame(result: AnalysisResult) -> pandas.DataFrame:
    """The extremes of an analysis as a pandas DataFrame
    (:func:`esp.volumetric.frames.result_frame`)."""
    from esp.volumetric.frames import result_frame as _frame

    return _frame(result)


def terms_frame(result: AnalysisResult) -> pandas.DataFrame:
    """Every breakdown term in long form (:func:`esp.volumetric.frames.terms_frame`)."""
    from esp.volumetric.frames import terms_frame as _frame

    return _frame(result)


def grid_frame(result: AnalysisResult, limit: int | None = None) -> pandas.DataFrame:
    """The error at every grid point of the worst case, from its one evaluation
    (:func:`esp.volumetric.frames.grid_frame`; refused above the documented limit)."""
    from esp.volumetric.frames import grid_frame as _frame

    return _frame(result, limit)


def evaluate_point(machine: Machine, at: Mapping[str, float]) -> PointResult:
    """Errors and terms at one position (see :func:`esp.core.analysis.evaluate_point`)."""
    from esp.core.analysis import evaluate_point as _evaluate

    return _evaluate(machine, at)


__all__ = [
    "ConfigError",
    "DataError",
    "ErrorProfile",
    "EspError",
    "ParseError",
    "__version__",
    "analyse",
    "errors_at",
    "evaluate",
    "evaluate_point",
    "grid_frame",
    "load_machine",
    "result_frame",
    "terms_frame",
]
