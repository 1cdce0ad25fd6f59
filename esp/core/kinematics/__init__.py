"""Kinematic chains: a machine as elementary transforms from the workpiece to the tool tip.

* build a chain in code (:func:`translate`, :func:`rotate`, :func:`prismatic`,
  :func:`revolute`, :func:`error_motion`, :class:`Chain`), or read one from a chain file
  (:func:`esp.config.chain.load_chain`);
* evaluate it exactly by homogeneous transforms (:func:`position`, :func:`transforms`,
  :func:`tool_axis`), vectorised over points;
* its first-order error terms numerically (:func:`sensitivities`: ∂p/∂e for every small
  error) and the first- and second-order terms for given errors (:func:`taylor`);
* its formulae symbolically (:func:`derive`, the only part that imports sympy).

See ``docs/kinematics.md``. Units: values are given in each symbol's unit (by default mm
and degrees for coordinates and parameters, µm and µrad for errors); positions come back
in mm; inside the chain and in every formula, lengths are in mm and angles in radians.

References
----------
Freeman & Ford (2003), Automated error analysis of serial manipulators and servo heads.
Loh et al. (2004), Analysis of linear and angular errors of a small coordinate measuring
machine, eq. 1-10.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from esp.core.kinematics.chain import (
    Chain,
    ErrorMotion,
    Prismatic,
    Revolute,
    Rotate,
    Symbol,
    Translate,
    error_motion,
    prismatic,
    revolute,
    rotate,
    translate,
)
from esp.core.kinematics.exact import position, tool_axis, transforms
from esp.core.kinematics.expr import Expr, parse_expr
from esp.core.kinematics.linear import Expansion, sensitivities, taylor

if TYPE_CHECKING:  # pragma: no cover
    from esp.core.kinematics.symbolic import Derivation

__all__ = [
    "Chain",
    "Derivation",
    "ErrorMotion",
    "Expansion",
    "Expr",
    "Prismatic",
    "Revolute",
    "Rotate",
    "Symbol",
    "Translate",
    "derive",
    "error_motion",
    "parse_expr",
    "position",
    "prismatic",
    "revolute",
    "rotate",
    "sensitivities",
    "taylor",
    "tool_axis",
    "transforms",
    "translate",
]


def derive(chain: Chain, order: int = 1) -> Derivation:
    """The nominal tool tip and its first- (``order=2``: and second-) order errors as
    simplified formulae (see :func:`esp.core.kinematics.symbolic.derive`; imports sympy)."""
    from esp.core.kinematics.symbolic import derive as _derive

    return _derive(chain, order)


def __getattr__(name: str) -> Any:
    if name == "Derivation":
        from esp.core.kinematics.symbolic import Derivation

        return Derivation
    raise AttributeError(f"module 'esp.core.kinematics' has no attribute {name!r}")
