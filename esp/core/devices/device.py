"""A chain device: a kinematic chain with the values of its parameters and small errors,
the part a servo head (:class:`~esp.core.devices.head.Head`) and a rotary table
(:class:`~esp.core.devices.table.Table`) share (numpy only).

A device holds its chain, every parameter's value, every small error's value (zero when
nothing gives one) and where each value came from. Its coordinates are the chain's; their
settings are checked by :meth:`Device.settings`, in the words of the device
(:attr:`Device.member`, :attr:`Device.owner`). A value comes, by increasing precedence,
from the chain's default (``symbols.NAME.value``, :func:`chain_values`), the description
file (:mod:`esp.config.devices`) and :meth:`Device.with_values` (``--set`` on the command
line). Every problem is a :class:`esp.core.errors.ConfigError` naming the dotted key.

The head and the table add their own: the head its MCP, the table the curves of its error
motions over an angle and its set-up setting.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from types import MappingProxyType
from typing import Any, ClassVar, Self

import numpy as np

from esp.core.errors import ConfigError
from esp.core.kinematics import Chain
from esp.core.kinematics.chain import Step
from esp.core.kinematics.values import chain_defaults, coordinate_arrays, symbol_value
from esp.core.text import did_you_mean

__all__ = ["Device", "ToIdentify", "chain_values", "extended_chain", "join_key"]


def join_key(prefix: str, name: str) -> str:
    """The dotted key ``prefix.name`` (``name`` alone without a prefix)."""
    return f"{prefix}.{name}" if prefix else name


@dataclass(frozen=True)
class ToIdentify:
    """An error of a device given as an unknown, ``{ identify = ... }``: the key it was
    given at and what was given (``true``, or for a table's error motion a basis such as
    ``{ basis = "fourier", order = 3 }``), read by :mod:`esp.identify.rotary`."""

    key: str
    spec: Any


@dataclass(frozen=True)
class Device:
    """A chain with every parameter and error value.

    Attributes
    ----------
    chain : the kinematic chain
    name, description : for reports
    parameters : every parameter of the chain -> its value, in the symbol's unit
    errors : every small error of the chain given as a constant -> its value, in the
        symbol's unit (zero when nothing gives one)
    origins : name -> where its value came from (``"chain"``, a file name, ``"--set"``);
        absent for an error that is zero because nothing gave it
    source : the file the device was read from, for messages
    inputs : every file read (the device's file, the chain, the value files)
    to_identify : error -> :class:`ToIdentify`, the errors given as unknowns
        (``{ identify = ... }``) for ``esp identify``; their value here is zero
    """

    #: how the messages name the device, one of its coordinates, their values
    owner: ClassVar[str] = "device"
    member: ClassVar[str] = "coordinate"
    values_word: ClassVar[str] = "values"
    #: the largest magnitude of a coordinate's setting
    limit: ClassVar[float] = 1e6
    #: what to do with a coordinate given as a value (after "NAME is ... ; ")
    coordinate_hint: ClassVar[str] = "give it where the device is evaluated"

    chain: Chain
    name: str
    parameters: Mapping[str, float]
    errors: Mapping[str, float]
    origins: Mapping[str, str] = field(default_factory=dict)
    description: str = ""
    source: str | None = None
    inputs: tuple[str, ...] = ()
    to_identify: Mapping[str, ToIdentify] = field(default_factory=dict)

    @property
    def coordinates(self) -> tuple[str, ...]:
        """The device's axes (the chain's coordinates), base first."""
        return self.chain.coordinates

    def unit(self, name: str) -> str:
        """The unit of a symbol's values."""
        return self.chain.symbols[name].unit

    def values_in(self, kind: str) -> dict[str, float]:
        """parameters or errors as a plain dict (``kind`` ``"parameter"`` or ``"error"``)."""
        return dict(self.parameters if kind == "parameter" else self.errors)

    def settings(self, angles: Any) -> tuple[dict[str, np.ndarray], int]:
        """Check settings of the coordinates: every one given, as a number or a 1-D array,
        the arrays of one length N, finite, of magnitude at most :attr:`limit`. Returns
        (coordinate -> float64 array (N,), N); see
        :func:`esp.core.kinematics.values.coordinate_arrays`.

        Raises
        ------
        ConfigError
            A missing or unknown coordinate, values that are not finite numbers of a
            sensible size, arrays of different lengths (key ``angles.C``).
        """
        return coordinate_arrays(
            angles,
            self.coordinates,
            member=self.member,
            owner=self.owner,
            values=self.values_word,
            limit=self.limit,
        )

    def not_a_value(self, name: str) -> str:
        """Why ``name`` cannot be given a value: a coordinate, or not a symbol."""
        sym = self.chain.symbols.get(name)
        if sym is not None and sym.kind == "coordinate":
            return f"{name} is {_a(self.member)} of the {self.owner}; {self.coordinate_hint}"
        names = [n for n, s in self.chain.symbols.items() if s.kind != "coordinate"]
        return (
            f"not a parameter or error of the chain{did_you_mean(name, names)} "
            f"({', '.join(names) or 'none'})"
        )

    def with_values(self, values: Mapping[str, float], origin: str = "--set") -> Self:
        """A copy with some parameter and error values replaced (each in its symbol's unit).

        Raises
        ------
        ConfigError
            A name that is not a parameter or an error of the chain, a value that is not a
            finite number (key ``--set NAME``, or ``origin.NAME``).
        """
        params = dict(self.parameters)
        errors = dict(self.errors)
        origins = dict(self.origins)
        constants = []
        for n, v in values.items():
            key = f"--set {n}" if origin == "--set" else join_key(origin, n)
            sym = self.chain.symbols.get(n)
            if sym is None or sym.kind == "coordinate":
                raise ConfigError(key, self.not_a_value(n))
            x = symbol_value(v, key, sym)
            if sym.kind == "parameter":
                params[n] = x
            else:
                errors[n] = x
                constants.append(n)
            origins[n] = origin
        out = replace(
            self,
            parameters=MappingProxyType(params),
            errors=MappingProxyType(errors),
            origins=MappingProxyType(origins),
        )
        return out._constants(constants)

    def _constants(self, names: list[str]) -> Self:
        """A copy in which the errors ``names`` hold only their constant value (the table
        drops their curves); the device has nothing else."""
        return self


def _a(word: str) -> str:
    return f"an {word}" if word[:1] in "aeiou" else f"a {word}"


def chain_values(chain: Chain, name: str | None = None) -> dict[str, Any]:
    """The fields of a device holding the chain's own default values (every parameter must
    have one): ``chain``, ``name``, ``parameters``, ``errors``, ``origins``,
    ``description``, ``source``, ``inputs``.

    Raises
    ------
    ConfigError
        A parameter without a default, a default out of its range (key ``symbols.NAME``).
    """
    params, errors, origins = chain_defaults(chain)
    return {
        "chain": chain,
        "name": name or chain.name,
        "parameters": MappingProxyType(params),
        "errors": MappingProxyType(errors),
        "origins": MappingProxyType(origins),
        "description": chain.description,
        "source": chain.source,
        "inputs": (chain.source,) if chain.source else (),
    }


def extended_chain(chain: Chain, step: Step, symbols: Mapping[str, Any] | None = None) -> Chain:
    """The chain followed by one more step, with more symbols (name -> declaration): a point
    carried by the chain's last frame (the head's tool axis, a tool tip on a table)."""
    declared: dict[str, Any] = dict(chain.symbols)
    declared.update(symbols or {})
    return Chain(
        tuple(chain.steps) + (step,),
        declared,
        name=chain.name,
        description=chain.description,
        source=chain.source,
    )
