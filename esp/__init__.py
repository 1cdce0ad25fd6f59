"""esp -- volumetric accuracy of Cartesian machines by synthesis of measured geometric errors.

A reimplementation and extension of ESP, the Error Simulation Program of the University of
Huddersfield (Longstaff 2002, chapters 3-4).
"""

from esp._version import __version__
from esp.errors import ConfigError, DataError, EspError, ParseError
from esp.profile import ErrorProfile

__all__ = [
    "ConfigError",
    "DataError",
    "ErrorProfile",
    "EspError",
    "ParseError",
    "__version__",
]
