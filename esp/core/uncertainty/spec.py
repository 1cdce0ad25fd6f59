"""The ``[uncertainty]`` table of ``machine.toml`` as records: what uncertainty each
component has and how to combine them (read by :mod:`esp.config.uncertainty`).

Each component carries an expanded uncertainty U with its own coverage factor k, its
distribution and its degrees of freedom: either given directly (a number, or a curve along
the axis like any error source) or computed by an instrument model of Longstaff (2002)
3.14.1-3.14.6 from its data file and the parameters given
(:mod:`esp.core.uncertainty.instruments`). The volumetric combination works with the standard
uncertainties u = U / k and expands once (GUM 5.1.2, 6.2). A component may have an
uncertainty and no error data: a planning study, its error is zero and its U still counts.
"""

from __future__ import annotations

import math
from collections.abc import Collection, Mapping
from dataclasses import dataclass, field, replace
from types import MappingProxyType

import numpy as np

from esp.core.machine import Component, Machine
from esp.core.names import ComponentName
from esp.core.profile import ErrorProfile
from esp.core.uncertainty.budget import ComponentUncertainty
from esp.core.uncertainty.instruments import MODELS

__all__ = [
    "DISTRIBUTIONS",
    "INSTRUMENTS",
    "METHODS",
    "PURE_ADDITION_MODEL",
    "U_LIMITS",
    "ComponentU",
    "UncertaintySpec",
    "uncertainty_machine",
]

METHODS = ("statistical", "summation", "pure-addition", "montecarlo")
#: why pure addition needs the printed model (``.format(model=...)``: the model found)
PURE_ADDITION_MODEL = (
    "method = 'pure-addition' adds the terms with the signs of the printed equations "
    "(Longstaff 2002, 4.01.3, table 4.3) and needs analysis.model = 'as-printed', found "
    "{model!r}; for a bound that no choice of signs exceeds use method = 'summation'"
)
DISTRIBUTIONS = ("normal", "rectangular")
#: instrument names in the configuration -> model names of :data:`MODELS`
INSTRUMENTS = {name.replace("_", "-"): name for name in MODELS}
#: the largest expanded uncertainty accepted, per unit of U: 1 mm for a displacement
#: (linear, straightness), 0.1 rad for an angle (angular, squareness)
U_LIMITS = {"um": 1000.0, "um/m": 100_000.0}


@dataclass(frozen=True)
class ComponentU:
    """The expanded uncertainty of one component.

    ``U`` is a constant (µm for linear and straightness, µm/m for angles and squareness),
    or ``profile`` a curve of U along the axis (same unit; the mean of its runs is used,
    exactly as given). ``model`` is ``"direct"`` or the instrument's name; ``budget`` the
    instrument model's contributions when there is one; ``distribution`` the shape drawn
    by the Monte Carlo method; ``k`` the coverage factor of this U (None: the table's
    ``k``); ``dof`` the degrees of freedom of u = U / k (``math.inf``: known exactly, Type
    B; for an instrument model, its budget's effective degrees of freedom); ``key`` the
    configuration key the U came from, for messages.
    """

    component: ComponentName
    kind: str
    axis: str | None
    about: str | None
    model: str
    unit: str
    distribution: str
    U: float | None = None
    profile: ErrorProfile | None = None
    budget: ComponentUncertainty | None = None
    k: float | None = None
    dof: float = math.inf
    key: str = ""

    @property
    def U_max(self) -> float:
        """The largest U along the axis (the constant U when there is no curve)."""
        if self.profile is None:
            return float(self.U or 0.0)
        return float(max(np.abs(self.profile.mean("mean")).max(), 0.0))

    def U_at(self, position_mm: float | None = None) -> float:
        """U at a position of the component's axis, mm (the constant U when there is no
        curve; a curve holds its end values beyond its range)."""
        if self.profile is None or position_mm is None:
            return float(self.U or 0.0) if self.profile is None else self.U_max
        return float(self.profile.at(float(position_mm), direction="mean", extrapolate=True))

    @property
    def coverage_k(self) -> float:
        """The coverage factor of this U (2 when neither it nor the table gave one)."""
        return 2.0 if self.k is None else float(self.k)

    def as_component(self, scale: float = 1.0) -> Component:
        """A component whose 'error' is this U times ``scale``: the model run with U in
        place of the error (``scale = 1 / k`` gives the standard uncertainty u)."""
        source = self.key or "U"
        if self.kind == "squareness":
            return Component(
                self.component,
                self.kind,
                None,
                self.about,
                value=float(self.U or 0.0) * scale,
                source=source,
            )
        profile = self.profile
        if profile is None:
            kind = "angular" if self.kind == "mechanical" else self.kind
            run = np.array([[float(self.U or 0.0)]])
            profile = ErrorProfile(
                kind,
                np.zeros(1),
                {"forward": run, "backward": run},
                axis=self.axis,
                source=source,
            )
        else:
            profile = replace(profile, source=source)
        if scale != 1.0:
            profile = profile.scaled(scale)
        return Component(
            self.component, self.kind, self.axis, self.about, profile=profile, source=source
        )

    def standard_component(self) -> Component:
        """A component whose 'error' is the standard uncertainty u = U / k."""
        return self.as_component(1.0 / self.coverage_k)


@dataclass(frozen=True)
class DeviceU:
    """The expanded uncertainty U of one error of a servo head or a rotary table
    (``[uncertainty.head]``, ``[uncertainty.table]``), in the error's own unit (arcsec, µrad,
    mm, ... as the device file gives it), with its coverage factor."""

    U: float
    k: float
    unit: str

    @property
    def u(self) -> float:
        """The standard uncertainty U / k."""
        return self.U / self.k


@dataclass(frozen=True)
class UncertaintySpec:
    """The ``[uncertainty]`` table.

    ``k``: the coverage factor of the expanded results, and of every component U that does
    not state its own; ``coverage``: a coverage probability p instead (the results are
    then expanded with k = t_p(ν_eff), GUM G.4), or None; ``method``; the Monte Carlo
    settings ``samples`` and ``seed``; the components' uncertainties; an optional prior
    (thesis eq. 3.22-3.24) as (volumetric_um, u_um).
    """

    k: float = 2.0
    method: str = "statistical"
    samples: int = 20000
    seed: int = 1
    components: Mapping[str, ComponentU] = field(default_factory=dict)
    prior: tuple[float, float] | None = None
    coverage: float | None = None
    #: "head.ThetaAs" -> its U: the errors of a servo head or rotary table with a stated U
    devices: Mapping[str, DeviceU] = field(default_factory=dict)

    def __post_init__(self) -> None:
        comps = {
            n: cu if cu.k is not None else replace(cu, k=float(self.k))
            for n, cu in dict(self.components).items()
        }
        object.__setattr__(self, "components", MappingProxyType(comps))
        object.__setattr__(self, "devices", MappingProxyType(dict(self.devices)))


def uncertainty_machine(
    machine: Machine,
    spec: UncertaintySpec,
    names: Collection[str | ComponentName] | None = None,
    *,
    standard: bool = False,
) -> Machine:
    """The machine with every component's data replaced by its U (by its standard
    uncertainty u = U / k with ``standard``), absent components, and those not in
    ``names`` when given, left out. Evaluate it with ``Synthesis.prepare(...,
    measured=False)``: a U is not a measurement."""
    comps: dict[str | ComponentName, Component] = {
        n: cu.standard_component() if standard else cu.as_component()
        for n, cu in spec.components.items()
        if names is None or n in names
    }
    return replace(machine, components=comps, uncertainty=None)
