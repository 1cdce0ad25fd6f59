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

from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from types import MappingProxyType

from esp.core.errors import ConfigError
from esp.core.kinematics import Chain
from esp.core.kinematics.values import chain_defaults, symbol_value
from esp.core.text import did_you_mean

__all__ = ["Head", "head_from_chain"]


def _join(prefix: str, name: str) -> str:
    return f"{prefix}.{name}" if prefix else name


@dataclass(frozen=True)
class Head:
    """A head chain with every parameter and error value.

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

    chain: Chain
    name: str
    parameters: Mapping[str, float]
    errors: Mapping[str, float]
    origins: Mapping[str, str] = field(default_factory=dict)
    mcp_mm: tuple[float, float, float] = (0.0, 0.0, 0.0)
    description: str = ""
    source: str | None = None
    inputs: tuple[str, ...] = ()

    @property
    def coordinates(self) -> tuple[str, ...]:
        """The head's axes (the chain's coordinates), base first."""
        return self.chain.coordinates

    def unit(self, name: str) -> str:
        """The unit of a symbol's values."""
        return self.chain.symbols[name].unit

    def with_values(self, values: Mapping[str, float], origin: str = "--set") -> Head:
        """A copy with some parameter and error values replaced (each in its symbol's unit).

        Raises
        ------
        ConfigError
            A name that is not a parameter or an error of the chain (key ``origin.NAME``).
        """
        params = dict(self.parameters)
        errors = dict(self.errors)
        origins = dict(self.origins)
        for n, v in values.items():
            sym = self.chain.symbols.get(n)
            key = f"{origin}.{n}" if origin != "--set" else n
            if sym is None or sym.kind == "coordinate":
                raise ConfigError(
                    key if origin != "--set" else f"--set {n}",
                    _not_a_value(self.chain, n),
                )
            x = symbol_value(v, key if origin != "--set" else f"--set {n}", sym)
            if sym.kind == "parameter":
                params[n] = x
            else:
                errors[n] = x
            origins[n] = origin
        return replace(
            self,
            parameters=MappingProxyType(params),
            errors=MappingProxyType(errors),
            origins=MappingProxyType(origins),
        )

    def values_in(self, kind: str) -> dict[str, float]:
        """parameters or errors as a plain dict (``kind`` ``"parameter"`` or ``"error"``)."""
        return dict(self.parameters if kind == "parameter" else self.errors)


def _not_a_value(chain: Chain, name: str) -> str:
    sym = chain.symbols.get(name)
    if sym is not None and sym.kind == "coordinate":
        return f"{name} is a coordinate of the head; give it with --at or a map grid"
    names = [n for n, s in chain.symbols.items() if s.kind != "coordinate"]
    return (
        f"not a parameter or error of the chain{did_you_mean(name, names)} "
        f"({', '.join(names) or 'none'})"
    )


def head_from_chain(chain: Chain, name: str | None = None) -> Head:
    """A head holding the chain's own default values (parameters must have one)."""
    params, errors, origins = chain_defaults(chain)
    inputs = (chain.source,) if chain.source else ()
    return Head(
        chain,
        name or chain.name,
        MappingProxyType(params),
        MappingProxyType(errors),
        MappingProxyType(origins),
        description=chain.description,
        source=chain.source,
        inputs=inputs,
    )
