"""A rotary table: a kinematic chain from the workpiece to the table's mount, with the
values of its parameters and of its ISO 230-7 errors (constants, or curves over an angle).

A table is described by a chain (:class:`esp.core.kinematics.Chain`) whose coordinates all
drive revolute joints, and the values of its symbols; :mod:`esp.config.devices` reads it
from a table file (``TABLE.toml``, a ``[table]`` table naming a chain file) or from a
``[table]`` table in another file. A value comes, by increasing precedence, from the
chain's default (``symbols.NAME.value``), the files of ``errors_from``, the table, and
:meth:`Table.with_values`; an error nothing gives a value is zero. A curve can feed only an
error in the error motion of a joint (a component error motion, a function of that joint's
angle); the location errors are constants. Every problem is one
:class:`esp.core.errors.ConfigError` naming the dotted key.

See ``docs/rotary.md``.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from types import MappingProxyType
from typing import Any, ClassVar

import numpy as np

from esp.core.devices.device import Device, ToIdentify, chain_values
from esp.core.devices.table_curves import Curve
from esp.core.errors import ConfigError
from esp.core.kinematics import Chain, Prismatic, Revolute
from esp.core.kinematics.values import finite_value
from esp.core.text import did_you_mean

__all__ = [
    "MAX_ANGLE",
    "TIP_PARAMETERS",
    "Table",
    "ToIdentify",
    "check_table_chain",
    "joint_of",
    "positioning_error",
    "setup_setting",
    "table_from_chain",
]

#: the parameters esp appends to a table chain for the tool tip in the machine frame
TIP_PARAMETERS = ("esp_tip_x", "esp_tip_y", "esp_tip_z")
#: largest angle accepted, degrees
MAX_ANGLE = 1e6


@dataclass(frozen=True)
class Table(Device):
    """A table chain with the values of its parameters and errors (a :class:`Device`).

    Attributes
    ----------
    chain : the kinematic chain from the workpiece (its base) to the table's mount on the
        linear axes (its tip: the origin of the machine frame); every coordinate drives a
        revolute joint
    name, description : for reports
    parameters : every parameter of the chain -> its value, in the symbol's unit
    errors : every small error of the chain given as a constant -> its value, in the
        symbol's unit (zero when nothing gives one); an error with a curve is not here
    curves : error -> :class:`~esp.core.devices.table_curves.Curve`, its values over the angle of
        ``curve_axes[error]``, in the symbol's unit
    curve_axes : error with a curve -> the coordinate of the joint whose error motion
        holds it
    setup_deg : the setting at which the workpiece is set up (coordinate -> degrees), or
        None: the workpiece frame is the nominal table's (``docs/rotary.md``)
    origins : name -> where its value came from (``"chain"``, a file name, ``"--set"``)
    source : the file the table was read from, for messages
    inputs : every file read (the table file, the chain, the value and curve files)
    """

    owner: ClassVar[str] = "table"
    member: ClassVar[str] = "axis"
    values_word: ClassVar[str] = "angles (deg)"
    limit: ClassVar[float] = MAX_ANGLE
    coordinate_hint: ClassVar[str] = "give its angles where the table is evaluated"

    curves: Mapping[str, Curve] = field(default_factory=dict)
    curve_axes: Mapping[str, str] = field(default_factory=dict)
    setup_deg: Mapping[str, float] | None = None

    def values_at(self, angles_deg: Mapping[str, np.ndarray], n: int) -> dict[str, np.ndarray]:
        """Every error of the chain -> its values (N,) at N settings (each coordinate ->
        (N,) degrees), in the symbol's unit: a constant repeated, a curve interpolated."""
        out: dict[str, np.ndarray] = {}
        for e in self.chain.errors:
            if e in self.curves:
                out[e] = np.asarray(self.curves[e].at(angles_deg[self.curve_axes[e]]), float)
            else:
                out[e] = np.full(n, float(self.errors.get(e, 0.0)))
        return out

    def _constants(self, names: list[str]) -> Table:
        """An error given a constant loses its curve."""
        if not any(n in self.curves for n in names):
            return self
        curves = {e: c for e, c in self.curves.items() if e not in names}
        axes = {e: a for e, a in self.curve_axes.items() if e not in names}
        return replace(self, curves=MappingProxyType(curves), curve_axes=MappingProxyType(axes))

    def with_setup(self, setup: Mapping[str, Any] | None, key: str = "setup") -> Table:
        """A copy whose workpiece is set up at ``setup`` (every axis -> degrees), or, with
        None, whose workpiece frame is the nominal table's.

        Raises
        ------
        ConfigError
            Not a mapping of every axis of the table to a finite angle (key ``setup.C``).
        """
        if setup is None:
            return replace(self, setup_deg=None)
        setting = setup_setting(setup, key, self.coordinates)
        return replace(self, setup_deg=MappingProxyType(setting))


def check_table_chain(chain: Chain, key: str, source: str | None) -> None:
    """Refuse a chain that cannot be a table's: no revolute joint, a prismatic joint, a
    reserved symbol name (key ``key``, file ``source``)."""
    if not chain.coordinates:
        raise ConfigError(key, "the chain has no coordinate (no revolute joint)", source)
    for i, step in enumerate(chain.steps, 1):
        if isinstance(step, Prismatic):
            raise ConfigError(
                key,
                f"steps[{i}] is a prismatic joint ({step.coordinate}); a table chain holds "
                "only rotary axes (the linear axes are the machine's)",
                source,
            )
    for n in TIP_PARAMETERS:
        if n in chain.symbols:
            raise ConfigError(key, f"the symbol name {n!r} is reserved for the tool tip", source)


def positioning_error(chain: Chain, coordinate: str) -> tuple[str, float] | None:
    """The angular positioning error of a joint: the error in the slot of its error motion
    about its own axis (``rz`` of ``revolute = "z"``), and the sign that makes it the
    deviation of the angle reached from the angle commanded in the sense of the joint's
    coordinate (docs/rotary.md: ``rz = "ECC"`` about +z, ``rz = "-ECC"`` about -z, both
    +1); None when the joint has none, or its slot is not one error times ±1."""
    for step in chain.steps:
        if not isinstance(step, Revolute) or step.coordinate != coordinate:
            continue
        if step.errors is None:
            return None
        axis = step.axis.lstrip("+-")
        expr = step.errors.slots().get(f"r{axis}")
        if expr is None:
            return None
        names = [n for n in expr.names() if chain.symbols[n].kind == "error"]
        if len(names) != 1 or len(expr.names()) != 1:
            return None
        gain = float(expr.evaluate({names[0]: 1.0}))
        if abs(abs(gain) - 1.0) > 1e-12:
            return None
        sense = -1.0 if step.axis.startswith("-") else 1.0
        return names[0], sense * gain
    return None


def joint_of(chain: Chain) -> dict[str, str]:
    """error -> the coordinate of the one revolute joint whose error motion holds it."""
    out: dict[str, str] = {}
    seen: dict[str, set[str]] = {}
    for step in chain.steps:
        if isinstance(step, Revolute) and step.errors is not None:
            for expr in step.errors.slots().values():
                for n in expr.names():
                    if chain.symbols[n].kind == "error":
                        seen.setdefault(n, set()).add(step.coordinate)
    for n, coords in seen.items():
        if len(coords) == 1:
            out[n] = next(iter(coords))
    return out


def table_from_chain(chain: Chain, name: str | None = None) -> Table:
    """A table holding the chain's own default values (every parameter must have one).

    Raises
    ------
    ConfigError
        The chain has no revolute joint, holds a prismatic joint, uses a reserved name, or
        a parameter has no default value.
    """
    check_table_chain(chain, "chain", chain.source)
    return Table(
        **chain_values(chain, name),
        curves=MappingProxyType({}),
        curve_axes=MappingProxyType({}),
    )


def setup_setting(raw: Any, key: str, coords: tuple[str, ...]) -> dict[str, float]:
    """A set-up setting: every one of ``coords`` -> a finite angle, degrees (key ``key``)."""
    if not isinstance(raw, Mapping):
        raise ConfigError(
            key, f"expected the set-up setting, e.g. {{ {coords[0]} = 0 }}, found {raw!r}"
        )
    for c in raw:
        if c not in coords:
            raise ConfigError(
                f"{key}.{c}",
                f"not an axis of the table{did_you_mean(c, coords)} ({', '.join(coords)})",
            )
    out = {}
    for c in coords:
        if c not in raw:
            raise ConfigError(
                f"{key}.{c}", f"missing: give the set-up angle of every axis ({', '.join(coords)})"
            )
        out[c] = finite_value(raw[c], f"{key}.{c}", MAX_ANGLE)
    return out
