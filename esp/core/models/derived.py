"""The rigid-body model: term tables derived from the machine's kinematic chain.

A three-axis machine is a chain of three prismatic joints from the workpiece to the tool
tip (:mod:`esp.core.kinematics`), each carrying the six error motions of its axis, followed by
the tool offset. The order of the joints along the chain follows the configuration
(Longstaff 2002, 3.02-3.03): from the workpiece, first the axes that carry it (innermost
first), then the axes that carry the tool::

    wBMTt  workpiece -> B -> M -> T -> tool        BMwTt  workpiece -> M -> B -> T -> tool
    BwMTt  workpiece -> B -> M -> T -> tool        BMTwt  workpiece -> T -> M -> B -> tool

The conventions are those of ``docs/conventions.md``: coordinates are commanded positions
of the tool relative to the workpiece (ISO 841), each axis' six errors are motions of the
tool relative to the workpiece along and about the machine's +X, +Y, +Z (right-handed), an
axis' angles act about its measurement line (the joint's pivot holds the measurement
offsets of the axes after it), and a squareness S_EL of an earlier axis E and a later axis
L (bottom -> middle -> top) displaces the tool along +E by S_EL · (l - offset_L).

The first order of the chain is linear in the errors and, for a Cartesian stack, affine
in the coordinates and the tool offset. :func:`derive_terms` evaluates the chain's exact
first-order sensitivities (:func:`esp.core.kinematics.sensitivities`) at a few points, reads off
the affine coefficients -- each is 0 or ±1 of a lever -- and writes them as the same
:class:`~esp.core.models.terms.Term` records the printed equations use, so that the separable
engine evaluates either model, and every term of a breakdown names its error motion and
lever. A chain that is not affine (a rotary axis, a rotated frame) is refused.

Machines compensated at the MCP (thesis 3.09, eq. 3.14-3.16) are the same chain with the
mechanical angles γ in the joints and the controller's correction of their effect at the
MCP, -(γ - Φ) × r, in the joints' translations (r: the lever of the coordinates only), so
that the residual angles Φ act through the coordinates and γ through the tool offset.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from typing import TYPE_CHECKING

import numpy as np

from esp.core.errors import DataError
from esp.core.models.terms import Term
from esp.core.names import AXIS_NAMES

if TYPE_CHECKING:  # esp.core.kinematics is imported where a chain is built
    from esp.core.kinematics import Chain, Prismatic, Translate

__all__ = [
    "CHAIN_ORDER",
    "DerivedTable",
    "cartesian_chain",
    "derive_terms",
    "error_symbol",
]

#: roles from the workpiece to the tool, per configuration
CHAIN_ORDER = {
    "wBMTt": ("B", "M", "T"),
    "BwMTt": ("B", "M", "T"),
    "BMwTt": ("M", "B", "T"),
    "BMTwt": ("T", "M", "B"),
}
_ROTATION = {"X": "A", "Y": "B", "Z": "C"}
_AXIS_OF_ROTATION = {v: k for k, v in _ROTATION.items()}
#: the unit lever used to read the affine coefficients off the sensitivities (mm)
_PROBE_MM = 1000.0
_TOLERANCE = 1e-9


def error_symbol(kind: str, axis: str, about: str | None = None) -> str:
    """The chain symbol of an error: ``EXX``, ``EYX`` (translations), ``EBX`` (rotation of X
    about Y, the residual angle Φ in a compensated machine), ``GBX`` (its mechanical angle
    γ), ``S_XY`` (squareness of the pair)."""
    if kind == "linear":
        return f"E{axis}{axis}"
    if kind == "straightness":
        return f"E{about}{axis}"
    if kind == "angular":
        assert about is not None, "an angle is about an axis"
        return f"E{_ROTATION[about]}{axis}"
    if kind == "mechanical":
        assert about is not None, "an angle is about an axis"
        return f"G{_ROTATION[about]}{axis}"
    if kind == "squareness":
        return f"S_{about}"
    raise ValueError(f"unknown kind {kind!r}")


def _levi_civita(i: int, j: int, k: int) -> int:
    return (i - j) * (j - k) * (k - i) // 2


@lru_cache(maxsize=64)
def cartesian_chain(configuration: str, letters: tuple[str, str, str], compensated: bool) -> Chain:
    """The kinematic chain of a three-axis machine.

    Parameters
    ----------
    configuration : ``wBMTt``, ``BwMTt``, ``BMwTt`` or ``BMTwt``
    letters : the machine axis letters of the roles (bottom, middle, top)
    compensated : a machine compensated at the MCP (mechanical angles γ in the joints and
        the compensation of their effect at the MCP)

    Returns
    -------
    esp.core.kinematics.Chain
        Coordinates ``X``, ``Y``, ``Z`` (mm); parameters ``X_off``, ``Y_off``, ``Z_off``
        (measurement offsets, mm) and ``P_X``, ``P_Y``, ``P_Z`` (tool offset, mm); errors
        named by :func:`error_symbol` (µm, µrad, µm/m).
    """
    from esp.core.kinematics import Chain, prismatic, translate

    role_letter = dict(zip(("B", "M", "T"), letters, strict=True))
    order = [role_letter[r] for r in CHAIN_ORDER[configuration]]
    later_in_roles = {  # squareness: (earlier, later) pairs in bottom -> middle -> top order
        letters[j]: [letters[i] for i in range(j)] for j in range(3)
    }
    symbols: dict[str, dict] = {}
    for a in AXIS_NAMES:
        symbols[f"{a}_off"] = {"kind": "parameter", "unit": "mm", "value": 0.0}
        symbols[f"P_{a}"] = {"kind": "parameter", "unit": "mm", "value": 0.0}
    steps: list[Prismatic | Translate] = []
    for n, axis in enumerate(order):
        after = order[n + 1 :]
        slots: dict[str, str] = {}
        for d in AXIS_NAMES:
            kind = "linear" if d == axis else "straightness"
            name = error_symbol(kind, axis, d)
            symbols[name] = {"kind": "error", "unit": "um"}
            terms = [name]
            earlier = later_in_roles[axis]
            if d in earlier:
                sq = error_symbol("squareness", axis, "".join(sorted((d, axis))))
                symbols[sq] = {"kind": "error", "unit": "um/m"}
                terms.append(f"{sq}*({axis} - {axis}_off)")
            if compensated:
                # the controller removes the effect at the MCP of the angles it was given
                # (γ - Φ) acting through the coordinates of the later axes: -(γ - Φ) × r
                i = AXIS_NAMES.index(d)
                for r_axis in AXIS_NAMES:
                    for lever in after:
                        eps = _levi_civita(AXIS_NAMES.index(r_axis), AXIS_NAMES.index(lever), i)
                        if eps == 0:
                            continue
                        g = error_symbol("mechanical", axis, r_axis)
                        p = error_symbol("angular", axis, r_axis)
                        sign = "-" if eps > 0 else "+"
                        terms.append(f"{sign}({g} - {p})*({lever} - {lever}_off)")
            slots["t" + d.lower()] = " + ".join(terms).replace("+ -", "- ").replace("+ +", "+ ")
        for r_axis in AXIS_NAMES:
            kind = "mechanical" if compensated else "angular"
            name = error_symbol(kind, axis, r_axis)
            symbols[name] = {"kind": "error", "unit": "urad"}
            if compensated:
                symbols[error_symbol("angular", axis, r_axis)] = {"kind": "error", "unit": "urad"}
            slots["r" + r_axis.lower()] = name
        pivot = [f"{a}_off" if a in after else 0 for a in AXIS_NAMES]
        steps.append(prismatic(axis.lower(), axis, errors=slots, pivot=pivot, note=f"axis {axis}"))
    steps.append(translate("P_X", "P_Y", "P_Z", note="tool offset"))
    return Chain(steps, symbols, name=f"{configuration} ({''.join(letters)})")


@dataclass(frozen=True)
class DerivedTable:
    """The terms of a derived model and the chain they came from."""

    configuration: str
    family: str
    terms: tuple[Term, ...]
    source: str


def _affine(
    configuration: str,
    letters: tuple[str, str, str],
    compensated: bool,
    offsets: tuple[float, float, float],
) -> dict[str, np.ndarray]:
    """Per error symbol, the affine coefficients of its first-order sensitivity, shape
    (7, 3): row 0 the constant, rows 1-3 per mm of X, Y, Z, rows 4-6 per mm of the tool
    offset P_X, P_Y, P_Z; columns the X, Y, Z displacement; in µm per unit of the error
    (µm, or µm/m = µrad, times mm / 1000)."""
    from esp.core.kinematics import sensitivities

    chain = cartesian_chain(configuration, letters, compensated)
    n = 1 + 3 + 3 + 1
    coords = np.zeros((n, 3))
    tool = np.zeros((n, 3))
    for j in range(3):
        coords[1 + j, j] = _PROBE_MM
        tool[4 + j, j] = _PROBE_MM
    rng = np.random.default_rng(12345)  # a fixed check point: the chain must be affine
    coords[-1] = rng.uniform(-700.0, 700.0, 3)
    tool[-1] = rng.uniform(-300.0, 300.0, 3)
    params: dict[str, float | np.ndarray] = {
        f"{a}_off": offsets[i] for i, a in enumerate(AXIS_NAMES)
    }
    params.update({f"P_{a}": tool[:, i] for i, a in enumerate(AXIS_NAMES)})
    sens = sensitivities(chain, {a: coords[:, i] for i, a in enumerate(AXIS_NAMES)}, params)
    out = {}
    for name, s in sens.items():
        s_um = s * 1000.0  # mm per unit -> µm per unit
        if chain.symbols[name].unit in ("urad", "um/m"):
            s_um = s_um * 1000.0  # per µrad: µm per (µm/m · mm / 1000)
        rows = np.zeros((7, 3))
        rows[0] = s_um[0]
        rows[1:4] = (s_um[1:4] - s_um[0]) / _PROBE_MM
        rows[4:7] = (s_um[4:7] - s_um[0]) / _PROBE_MM
        predicted = rows[0] + coords[-1] @ rows[1:4] + tool[-1] @ rows[4:7]
        if not np.allclose(predicted, s_um[-1], rtol=1e-9, atol=1e-9 * _PROBE_MM):
            raise DataError(
                f"the chain {chain.name} is not affine in {name}: the rigid-body model of a "
                "Cartesian machine must be (is a joint rotary?)"
            )
        out[name] = rows
    return out


def _unit(value: float, what: str) -> int:
    """A coefficient that must be 0 or ±1, as an int."""
    if abs(value) < _TOLERANCE:
        return 0
    if abs(abs(value) - 1.0) > 1e-9:
        raise DataError(f"{what}: expected a lever coefficient of ±1, found {value:.12g}")
    return 1 if value > 0 else -1


def derive_terms(
    configuration: str,
    letters: tuple[str, str, str],
    family: str,
    offsets_mm: tuple[float, float, float] = (0.0, 0.0, 0.0),
) -> DerivedTable:
    """The rigid-body term table of a machine, derived from its chain.

    Parameters
    ----------
    configuration : ``wBMTt``, ``BwMTt``, ``BMwTt`` or ``BMTwt``
    letters : the machine letters of the bottom, middle and top axes
    family : ``"mcp"`` (no tool), ``"tcp"`` or ``"tcp-compensated-mcp"`` (the evaluation
        cases of thesis 3.10; see :data:`esp.core.models.esp.CASES`)
    offsets_mm : the measurement offsets of X, Y, Z; the chain's pivots hold them, and the
        derivation checks that every angle's lever is (coordinate - offset)

    Returns
    -------
    DerivedTable
        Terms in role notation (B, M, T), as :func:`esp.core.models.bind.bind_model` expects,
        in the order: direction B, M, T; within a direction linear, straightness, angles,
        squareness.
    """
    if configuration not in CHAIN_ORDER:
        raise DataError(f"unknown configuration {configuration!r}")
    compensated = family == "tcp-compensated-mcp"
    with_tool = family != "mcp"
    coefficients = _affine(configuration, letters, compensated, offsets_mm)
    role_of = dict(zip(letters, ("B", "M", "T"), strict=True))
    source = f"rigid-body chain {configuration}"
    rows: list[tuple[tuple, Term]] = []
    for name, c in coefficients.items():
        kind, axis, about = _parse_symbol(name)
        for d_index, d in enumerate(AXIS_NAMES):
            col = c[:, d_index]
            what = f"{name} in {d} ({configuration}, {''.join(letters)})"
            if kind in ("linear", "straightness"):
                assert axis is not None  # None only for a squareness
                sign = _unit(col[0], what)
                if sign == 0:
                    continue
                if np.any(np.abs(col[1:]) > _TOLERANCE):
                    raise DataError(f"{what}: a translation error must not be levered")
                about_role = None if kind == "linear" else role_of[about]
                term = Term(role_of[d], kind, role_of[axis], about_role, sign, source=source)
                rows.append(((d_index, 0, name), term))
                continue
            levers = [(j, _unit(col[1 + j], what)) for j in range(3)]
            tools = [(k, _unit(col[4 + k], what)) if with_tool else (k, 0) for k in range(3)]
            constant = col[0] + sum(s * offsets_mm[j] for j, s in levers)
            if abs(constant) > 1e-6 * max(1.0, *map(abs, offsets_mm)):
                raise DataError(f"{what}: the lever does not run from the measurement line")
            coordinate = {j: s for j, s in levers if s}
            tool = {k: s for k, s in tools if s}
            for j in sorted(set(coordinate) | set(tool)):
                lever_axis = role_of[AXIS_NAMES[j]] if j in coordinate else None
                tool_axis = role_of[AXIS_NAMES[j]] if j in tool else None
                # one term per lever axis; its sign is the coordinate part's (or the tool's)
                sign = coordinate.get(j, tool.get(j, 1))
                term = Term(
                    role_of[d],
                    kind,
                    role_of[axis] if axis else role_of[about[0]],
                    role_of[about] if kind != "squareness" else role_of[about[1]],
                    sign,
                    lever_axis=lever_axis,
                    lever_sign=1,
                    tool_axis=tool_axis,
                    tool_sign=tool.get(j, 1) * sign if tool_axis else 1,
                    source=source,
                )
                order = {"angular": 1, "mechanical": 2, "squareness": 3}[kind]
                rows.append(((d_index, order, name, j), term))
    rows.sort(key=lambda r: r[0])
    return DerivedTable(configuration, family, tuple(t for _, t in rows), source)


def _parse_symbol(name: str) -> tuple[str, str | None, str]:
    """(kind, axis letter, about) of a chain error symbol; squareness: about is the pair."""
    if name.startswith("S_"):
        return "squareness", None, name[2:]
    prefix, what, axis = name[0], name[1], name[2]
    if prefix == "G":
        return "mechanical", axis, _AXIS_OF_ROTATION[what]
    if what in _AXIS_OF_ROTATION:
        return "angular", axis, _AXIS_OF_ROTATION[what]
    return ("linear" if what == axis else "straightness"), axis, what
