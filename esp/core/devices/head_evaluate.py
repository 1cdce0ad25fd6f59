"""The tool tip of a head at many settings: nominal position and orientation, first- and
second-order error, the exact error, and each small error's term (numpy only).

Frames and units
----------------
The head's chain runs from its base frame -- fixed to the ram, its x, y, z parallel to the
machine's X, Y, Z -- to the tool tip. Positions are given relative to the head's MCP (the
machine control point: where the head is mounted on the ram, the point the Cartesian
errors refer to; :attr:`esp.heads.Head.mcp_mm` in the base frame, by default its origin),
in mm, in the machine's axes. Errors are in µm, tool-axis tilts in µrad. The tool axis is
the z axis of the chain's last frame, a unit vector; for the shipped heads it points from
the tool tip into the spindle (the +Z of the tool in the sense of ISO 841).

References
----------
Freeman & Ford (2003), section 3-4: the tool tip X = (Π Ψ_i) X⁰ and its first-order
error DX, DY, DZ; section 4.2: the second order ("ignoring only terms involving products
of more than two small quantities").
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from functools import lru_cache
from typing import Any

import numpy as np

from esp.core.devices.device import extended_chain
from esp.core.devices.head import Head
from esp.core.kinematics import Chain, position, sensitivities, taylor, transforms
from esp.core.kinematics.chain import Translate
from esp.core.kinematics.expr import Num

__all__ = [
    "HeadEvaluation",
    "HeadOffsets",
    "HeadTerm",
    "evaluate_head",
    "head_offsets",
    "settings_arrays",
]

_UM = 1000.0  # µm per mm


@dataclass(frozen=True)
class HeadTerm:
    """One small error's first-order contribution at every setting.

    Attributes
    ----------
    name : the error's symbol
    value : its value, in ``unit``
    unit : the symbol's unit
    error_um : (N, 3) its contribution to the tool tip's X, Y, Z error, µm
    """

    name: str
    value: float
    unit: str
    error_um: np.ndarray


@dataclass(frozen=True)
class HeadEvaluation:
    """A head evaluated at N settings.

    Attributes
    ----------
    head : the head
    angles : coordinate -> (N,) its values, in the coordinate's unit (degrees)
    nominal_mm : (N, 3) the error-free tool tip relative to the MCP, machine axes
    tool_axis : (N, 3) the error-free tool axis (unit vectors)
    first_um : (N, 3) the first-order error DX, DY, DZ
    second_um : (N, 3) the second-order terms (products of two errors), or None
    exact_um : (N, 3) the exact error: the exact chain with the errors minus without
    tilt_urad : (N, 3) the first-order change of the tool axis (a vector ⟂ the axis), µrad
    terms : every error with a non-zero value, in the chain's order
    sensitivity : error -> (N, 3) µm of tool-tip error per unit of the error (its own
        unit), for every error of the chain
    order : the order of :attr:`error_um`: 1, or 2 (first plus second)
    """

    head: Head
    angles: Mapping[str, np.ndarray]
    nominal_mm: np.ndarray
    tool_axis: np.ndarray
    first_um: np.ndarray
    second_um: np.ndarray | None
    exact_um: np.ndarray
    tilt_urad: np.ndarray
    terms: tuple[HeadTerm, ...]
    sensitivity: Mapping[str, np.ndarray]
    order: int = 1

    @property
    def size(self) -> int:
        return self.nominal_mm.shape[0]

    @property
    def error_um(self) -> np.ndarray:
        """The error at :attr:`order`: the first order, or first plus second."""
        if self.order == 2 and self.second_um is not None:
            return self.first_um + self.second_um
        return self.first_um


@dataclass(frozen=True)
class HeadOffsets:
    """What a five-axis analysis needs of a head, per setting (see :func:`head_offsets`).

    Attributes
    ----------
    angles : coordinate -> (N,) values, in the coordinate's unit (degrees)
    offset_mm : (N, 3) nominal tool-tip offset from the MCP, in the machine frame, mm
    tool_axis : (N, 3) nominal tool axis (unit vectors, from the tip into the spindle)
    error_um : (N, 3) the head's own first-order error at the tool tip, µm
    terms : each head error with a non-zero value: name, value, unit and its
        contribution ``error_um`` (N, 3); they sum to ``error_um``
    """

    angles: Mapping[str, np.ndarray]
    offset_mm: np.ndarray
    tool_axis: np.ndarray
    error_um: np.ndarray
    terms: tuple[HeadTerm, ...]


def settings_arrays(head: Head, angles: Mapping[str, Any]) -> tuple[dict[str, np.ndarray], int]:
    """Check the head angles: every coordinate of the head, numbers or 1-D arrays of one
    length N, finite. Returns (coordinate -> float64 array (N,), N)."""
    return head.settings(angles)


@lru_cache(maxsize=16)
def _axis_chain(chain: Chain) -> Chain:
    """The chain with one more step, T(0, 0, 1 mm): its tip minus the tool tip is the tool
    axis, and its sensitivities minus the tip's are the axis' first-order tilt."""
    return extended_chain(chain, Translate(Num(0.0), Num(0.0), Num(1.0)))


def evaluate_head(
    head: Head, angles: Mapping[str, Any], *, order: int = 1, exact: bool = True
) -> HeadEvaluation:
    """The head's tool tip and its errors at N settings.

    Parameters
    ----------
    head : the head (chain, parameter and error values)
    angles : every coordinate of the head -> a number or (N,) values, in its unit (deg)
    order : 1, or 2 to add the second-order terms
    exact : also evaluate the exact chain (the referee of the first order)

    Returns
    -------
    HeadEvaluation

    Raises
    ------
    ConfigError
        A missing or unknown coordinate, values that are not finite numbers.
    DataError
        A quantity of the chain is not finite at these values (``e/tan(Yp)``, Yp = 0).
    """
    if order not in (1, 2):
        raise ValueError(f"order must be 1 or 2, found {order!r}")
    at, n = settings_arrays(head, angles)
    chain = head.chain
    params = head.values_in("parameter")
    errors = head.values_in("error")
    mcp = np.asarray(head.mcp_mm, dtype=float)
    sens_mm = sensitivities(chain, at, params)
    sens = {e: s * _UM for e, s in sens_mm.items()}
    frames = transforms(chain, at, params)
    nominal = frames[:, :3, 3] - mcp
    axis = frames[:, :3, 2]
    first = np.zeros((n, 3))
    terms = []
    for e in chain.errors:
        v = errors.get(e, 0.0)
        if v == 0.0:
            continue
        contribution = sens[e] * v
        first += contribution
        terms.append(HeadTerm(e, v, chain.symbols[e].unit, contribution))
    # the tool axis' first-order tilt: the sensitivities of a point 1 mm up the axis
    # minus the tip's, per unit of each error
    tilt = np.zeros((n, 3))
    active = [t.name for t in terms]
    if active:
        up = sensitivities(_axis_chain(chain), at, params)
        for t in terms:
            tilt += (up[t.name] - sens_mm[t.name]) * t.value * 1e6  # mm/mm -> µrad
    second = None
    if order == 2:
        expansion = taylor(chain, at, params, errors, order=2)
        assert expansion.second is not None
        second = expansion.second * _UM
    if exact:
        # the same evaluation with and without the errors: zero errors give exactly zero
        exact_um = (position(chain, at, params, errors) - position(chain, at, params)) * _UM
    else:
        exact_um = np.full((n, 3), np.nan)
    return HeadEvaluation(
        head,
        at,
        nominal,
        axis,
        first,
        second,
        exact_um,
        tilt,
        tuple(terms),
        sens,
        order,
    )


def head_offsets(head: Head, angles: Mapping[str, Any]) -> HeadOffsets:
    """Per head setting: the nominal tool offset from the MCP and the head's own
    first-order tool-tip error, with each head error's contribution (vectorised).

    This is what a five-axis machine (a Cartesian stack carrying the head) needs: the
    Cartesian stack's error at the MCP, plus its angular errors levered by ``offset_mm``,
    plus ``error_um``.

    Parameters
    ----------
    head : the head (chain, parameter and error values); its chain's base frame is the
        ram's, with x, y, z along the machine's X, Y, Z, and :attr:`Head.mcp_mm` the MCP in
        that frame
    angles : every coordinate of the head (e.g. ``{"A": a, "C": c}``) -> a number or (N,)
        values, in the coordinate's unit (degrees)

    Returns
    -------
    HeadOffsets
        ``offset_mm`` (N, 3) mm, ``tool_axis`` (N, 3), ``error_um`` (N, 3) µm and the
        ``terms`` (each with ``error_um`` (N, 3)), in the machine frame.

    Examples
    --------
    >>> from esp.heads import head_from_chain, head_offsets
    >>> from esp.core.kinematics import Chain, revolute, translate
    >>> chain = Chain([revolute("x", "A"), translate(0, 0, "-G")],
    ...               {"G": {"kind": "parameter", "value": 100.0}})
    >>> out = head_offsets(head_from_chain(chain), {"A": [0.0, 90.0]})
    >>> (out.offset_mm.round(9) + 0.0).tolist()
    [[0.0, 0.0, -100.0], [0.0, 100.0, 0.0]]
    """
    ev = evaluate_head(head, angles, order=1, exact=False)
    return HeadOffsets(ev.angles, ev.nominal_mm, ev.tool_axis, ev.first_um, ev.terms)
