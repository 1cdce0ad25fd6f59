"""Servo heads: a head's tool tip and errors over its angles, error maps, measurement
protocols (Freeman & Ford 2003).

The numeric core imports only numpy (and the numeric :mod:`esp.core.kinematics`):

* :mod:`~esp.core.devices.head` -- a head: its chain and the values of its parameters and small
  errors (:func:`head_from_chain`; :func:`load_head` and :func:`head_from_dict`, for a ``[head]``
  table in any file, are in :mod:`esp.config.devices`);
* :mod:`~esp.core.devices.head_evaluate` -- nominal tool tip and tool axis, first- and
  second-order and exact errors with each error's term, at many settings
  (:func:`evaluate_head`), and what a five-axis analysis needs of a head
  (:func:`head_offsets`);
* :mod:`~esp.heads.maps` -- error maps over a grid of the two angles (:func:`error_map`);
* :mod:`~esp.heads.protocol` -- measurement protocols (:func:`build_protocol`, which
  imports sympy) and their numeric solution (:func:`solve_protocol`);
* :mod:`~esp.heads.measured` -- the file of measured differences;
* :mod:`~esp.heads.config` -- the ``[map]`` and ``[protocol]`` tables of a head file.

See ``docs/heads.md``.
"""

from esp.config.devices import HEAD_KEYS, head_from_dict, load_head
from esp.core.devices.head import Head, head_from_chain
from esp.core.devices.head_evaluate import (
    HeadEvaluation,
    HeadOffsets,
    HeadTerm,
    evaluate_head,
    head_offsets,
)
from esp.heads.maps import DEFAULT_RANGE, ErrorMap, Extreme, GridSpec, error_map
from esp.heads.protocol import (
    DEFAULT_ANGLES,
    Protocol,
    ProtocolStep,
    ProtocolTest,
    build_protocol,
    predict_differences,
    solve_protocol,
)

__all__ = [
    "DEFAULT_ANGLES",
    "DEFAULT_RANGE",
    "HEAD_KEYS",
    "ErrorMap",
    "Extreme",
    "GridSpec",
    "Head",
    "HeadEvaluation",
    "HeadOffsets",
    "HeadTerm",
    "Protocol",
    "ProtocolStep",
    "ProtocolTest",
    "build_protocol",
    "error_map",
    "evaluate_head",
    "head_from_chain",
    "head_from_dict",
    "head_offsets",
    "load_head",
    "predict_differences",
    "solve_protocol",
]
