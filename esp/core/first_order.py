"""Where the first-order model of a machine holds: an upper bound of its second-order
remainder, from the machine's largest angles, displacement errors and levers.

Every model of esp takes an angle through its linear effect, angle × lever (Longstaff
2002, 3.04; the rigid-body chain of ``docs/kinematics.md`` to first order). Each value can
lie within its limit (docs/reliability.md) and the result still be meaningless: angles of
0.1 rad on levers of 100 m are not small. This module bounds what the first order leaves
out and refuses a result that the remainder could change by more than
:data:`REFUSE_FRACTION` (a warning above :data:`WARN_FRACTION`).

The bound (derived from the rigid-body chain)
---------------------------------------------
The tool point of a serial chain is p = Σ_k (Π_{i<k} R_i)(t_k + δ_k), each axis i moving
the rest of the chain by a translation error δ_i and a rotation R_i = exp([ε_i]×) of its
angular errors ε_i, about its pivot (Loh et al. 2004, eq. 1 and 9; Freeman & Ford 2003,
section 4). The first-order model keeps δ_i and [ε_i]× × lever_i. What it leaves out:

* the rotations beyond their linear part: Π exp(A_i) − I − Σ A_i holds every product of
  two or more of the A_i = [ε_i]× (the second-order term of one rotation, θ²/2 · lever,
  and the products of two angles times a lever are its first terms). Since
  ‖A_i‖ ≤ θ_i = |ε_i|, its norm is at most e^Θ − 1 − Θ (Θ = Σ θ_i; the series of the
  exponential with every term bounded by its norm), which is Θ²/2 (1 + Θ/3 + ...);
  acting on levers of length at most L, it moves the point by at most (e^Θ − 1 − Θ) L;
* the rotation of the translation errors by the angles of the axes before them, an angle
  times a displacement error: at most (e^Θ − 1) Δ, Δ = Σ |δ_i|.

Hence |remainder| ≤ (e^Θ − 1 − Θ) · L + (e^Θ − 1) · Δ (:func:`remainder_bound_um`),
≈ Θ²/2 · L + Θ · Δ for small angles. For a machine, Θ sums the largest magnitude of
every angular and mechanical error and every squareness (µm/m = µrad), Δ the largest
magnitude of every linear and straightness error, and L is the largest lever: the
distance from the axes' reference positions (``offset``) to the farthest grid point, plus
the longest tool offset. An error relative to a datum is the difference of two points'
errors, so its remainder is bounded by twice that. The test compares the bound with the
exact chain of :mod:`esp.core.kinematics.exact`.

This module imports only the standard library.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING

from esp.core.errors import DataError

if TYPE_CHECKING:
    from esp.core.machine import Component, Machine
    from esp.core.names import ComponentName

__all__ = [
    "REFUSE_FRACTION",
    "RESOLUTION_UM",
    "WARN_FRACTION",
    "FirstOrderBound",
    "first_order_bound",
    "first_order_warnings",
    "remainder_bound_um",
]

#: a result whose second-order remainder may exceed this fraction of it is refused
REFUSE_FRACTION = 0.10
#: above this fraction the result carries a warning
WARN_FRACTION = 0.01
#: a bound below this is never a concern, however small the result: the last digit esp
#: prints of an accuracy (1 nm)
RESOLUTION_UM = 0.001


def remainder_bound_um(
    angles_rad: Iterable[float], lever_mm: float, displacements_um: Iterable[float] = ()
) -> float:
    """An upper bound (µm) of what a first-order model leaves out of the position of a
    point reached through rigid rotations by ``angles_rad`` (the magnitudes of the
    rotation vectors) on levers of at most ``lever_mm``, and translation errors
    ``displacements_um``: (e^Θ − 1 − Θ) L + (e^Θ − 1) Δ, Θ = Σ|θ|, Δ = Σ|δ| (module
    docstring)."""
    theta = sum(abs(float(a)) for a in angles_rad)
    delta = sum(abs(float(d)) for d in displacements_um)
    rotation = math.expm1(theta) - theta  # e^Θ − 1 − Θ without cancellation for small Θ
    return rotation * abs(lever_mm) * 1000.0 + math.expm1(theta) * delta


@dataclass(frozen=True)
class FirstOrderBound:
    """The bound of a machine's second-order remainder and what it comes from: ``angles``
    and ``displacements`` map configuration keys to the largest magnitude (µm/m, µm),
    ``lever_mm`` the largest lever and the keys it comes from."""

    bound_um: float
    theta_rad: float
    delta_um: float
    lever_mm: float
    lever_keys: tuple[str, ...]
    angles: Mapping[str, float]
    displacements: Mapping[str, float]
    relative: bool


def _key(name: ComponentName) -> str:
    """The configuration key of a component (``axes.X.errors.angular.Z``,
    ``squareness.XY``)."""
    if name.kind == "squareness":
        return f"squareness.{name.about}"
    if name.kind == "linear":
        return f"axes.{name.axis}.errors.linear"
    return f"axes.{name.axis}.errors.{name.kind}.{name.about}"


def _largest(component: Component) -> float:
    """The largest magnitude of a component's data, in its engine unit."""
    if component.profile is None:
        return abs(float(component.value or 0.0))
    return max(float(abs(runs).max()) for runs in component.profile.runs.values())


def first_order_bound(
    machine: Machine, tool_offsets_mm: Iterable[Mapping[str, float]] = ()
) -> FirstOrderBound:
    """The :class:`FirstOrderBound` of ``machine`` for tools of the given offsets (mm;
    the MCP when none is given)."""
    angles: dict[str, float] = {}
    displacements: dict[str, float] = {}
    for component in machine.components.values():
        size = _largest(component)
        if size == 0.0:
            continue
        if component.kind in ("linear", "straightness"):
            displacements[_key(component.name)] = size
        else:
            angles[_key(component.name)] = size
    reach = 0.0
    keys = []
    for n, axis in machine.axes.items():
        lo, hi = axis.simulate_mm
        far = max(abs(lo - axis.offset_mm), abs(hi - axis.offset_mm))
        reach += far * far
        if far > 0:
            keys.append(f"axes.{n}.travel")
            if axis.offset_mm != 0:
                keys.append(f"axes.{n}.offset")
    tool = max(
        (math.sqrt(sum(float(v) ** 2 for v in o.values())) for o in tool_offsets_mm),
        default=0.0,
    )
    if tool > 0:
        keys.append("tool")
    lever = math.sqrt(reach) + tool
    theta = sum(angles.values()) * 1e-6
    delta = sum(displacements.values())
    relative = machine.analysis.datum != "none"
    bound = remainder_bound_um([theta], lever, [delta]) * (2.0 if relative else 1.0)
    return FirstOrderBound(bound, theta, delta, lever, tuple(keys), angles, displacements, relative)


def _describe(b: FirstOrderBound) -> str:
    top = sorted(b.angles.items(), key=lambda kv: -kv[1])[:3]
    listed = ", ".join(f"{k} {v:.6g} um/m" for k, v in top)
    more = f" and {len(b.angles) - 3} more" if len(b.angles) > 3 else ""
    return (
        f"from angles summing to {b.theta_rad:.3g} rad ({listed}{more}) on a lever of "
        f"{b.lever_mm:.6g} mm ({', '.join(b.lever_keys) or 'no travel'})"
        + (f" and displacement errors summing to {b.delta_um:.6g} um" if b.delta_um else "")
    )


def first_order_warnings(
    machine: Machine, volumetric_um: float, tool_offsets_mm: Iterable[Mapping[str, float]] = ()
) -> tuple[str, ...]:
    """Check that the first-order model holds for a result of ``volumetric_um``: a warning
    when its second-order remainder may exceed :data:`WARN_FRACTION` of the result.

    A bound of at most :data:`RESOLUTION_UM` is never a concern (a result of 0 with
    angles of a few µm/m).

    Raises
    ------
    DataError
        The remainder may exceed :data:`REFUSE_FRACTION` of the result: the number is not
        an accuracy of the machine; the message names the bound and the keys it comes from.
    """
    b = first_order_bound(machine, tool_offsets_mm)
    if b.bound_um <= max(WARN_FRACTION * volumetric_um, RESOLUTION_UM):
        return ()
    share = b.bound_um / volumetric_um if volumetric_um > 0 else math.inf
    what = (
        f"the second-order remainder of the first-order model may reach {b.bound_um:.6g} um, "
        f"{100 * share:.3g} % of the volumetric accuracy of {volumetric_um:.6g} um, "
        f"{_describe(b)}"
    )
    if share > REFUSE_FRACTION:
        raise DataError(
            f"{what}: above {REFUSE_FRACTION:.0%} of the result, the model does not hold "
            "(angles x levers are not small); check these values and their units"
        )
    return (f"{what}: the result may be wrong by more than {WARN_FRACTION:.0%}",)
