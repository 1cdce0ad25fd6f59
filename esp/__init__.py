"""esp -- volumetric accuracy of Cartesian machines by synthesis of measured geometric errors.

A reimplementation and extension of ESP, the Error Simulation Program of the University of
Huddersfield (Longstaff 2002, chapters 3-4).
"""

from esp._version import __version__
from esp.errors import ConfigError, DataError, EspError, ParseError


def __getattr__(name):
    # numpy-backed names load on first use, so ``esp --version`` imports nothing heavy
    if name == "ErrorProfile":
        from esp.profile import ErrorProfile

        return ErrorProfile
    raise AttributeError(f"module 'esp' has no attribute {name!r}")


def load_machine(path):
    """Read a ``machine.toml`` into a :class:`esp.machine.Machine` (see :mod:`esp.config`)."""
    from esp.config import load_machine as _load

    return _load(path)


def analyse(machine, progress=None):
    """Evaluate a machine over its volume (see :func:`esp.analysis.analyse`)."""
    from esp.analysis import analyse as _analyse

    return _analyse(machine, progress)


def errors_at(machine, points_mm, tool=None):
    """The X, Y, Z errors (µm) at many positions, shape (N, 3) (see
    :func:`esp.synthesis.errors_at`)."""
    from esp.synthesis import errors_at as _errors_at

    return _errors_at(machine, points_mm, tool)


def evaluate_point(machine, at):
    """Errors and terms at one position (see :func:`esp.analysis.evaluate_point`)."""
    from esp.analysis import evaluate_point as _evaluate

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
    "evaluate_point",
    "load_machine",
]
