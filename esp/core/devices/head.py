"""A servo head: a kinematic chain with the values of its parameters and small errors.

A head is described by a chain (:class:`esp.core.kinematics.Chain`) and the values of its
symbols; :mod:`esp.config.devices` reads it from a head file (``HEAD.toml``, a ``[head]``
table naming a chain file) or from a ``[head]`` table in another file. Each value comes, by
increasing precedence, from the chain's default (``symbols.NAME.value``), the error files,
the table, and :meth:`Head.with_values` (``--set`` on the command line); an error without
a value is zero. Every problem is a :class:`esp.core.errors.ConfigError` naming the dotted
key.

See ``docs/heads.md``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

from esp.core.devices.device import Device, chain_values
from esp.core.errors import ConfigError
from esp.core.kinematics import Chain

__all__ = ["Head", "check_head_chain", "head_from_chain"]


@dataclass(frozen=True)
class Head(Device):
    """A head chain with every parameter and error value (a :class:`Device`).

    Attributes
    ----------
    chain : the kinematic chain, base (the ram, the MCP frame) to the tool tip
    name : for reports
    parameters : every parameter of the chain -> its value, in the symbol's unit
    errors : every small error of the chain -> its value, in the symbol's unit (zero
        when nothing gives one)
    origins : name -> where its value came from (``"chain"``, ``"head"``, a file name,
        ``"--set"``); absent for an error that is zero because nothing gave it
    mcp_mm : the machine control point (where the head is mounted on the ram and the
        Cartesian errors refer to) in the chain's base frame, mm
    source : the file the head was read from, for messages
    inputs : every file read (the head file, the chain, the error files)
    """

    owner: ClassVar[str] = "head"
    coordinate_hint: ClassVar[str] = "give it with --at or a map grid"

    mcp_mm: tuple[float, float, float] = (0.0, 0.0, 0.0)


def check_head_chain(chain: Chain, key: str, source: str | None) -> None:
    """Refuse a chain that cannot be a head's: one without a coordinate (key ``key``)."""
    if not chain.coordinates:
        raise ConfigError(key, "the chain has no coordinate (no joint)", source)


def head_from_chain(chain: Chain, name: str | None = None) -> Head:
    """A head holding the chain's own default values (parameters must have one)."""
    return Head(**chain_values(chain, name))
