"""The ``[uncertainty]`` table of ``machine.toml``: what uncertainty each component has and
how to combine them.

Each component gets an expanded uncertainty U with the coverage factor ``k`` of the table,
either given directly (a number, or a curve along the axis like any error source) or
computed by an instrument model of Longstaff (2002) 3.14.1-3.14.6 from its data file and
the parameters given (:mod:`esp.uncertainty.instruments`). A component may have an
uncertainty and no error data: a planning study, its error is zero and its U still counts.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from types import MappingProxyType

from esp.machine import Component
from esp.names import ComponentName
from esp.profile import ErrorProfile
from esp.uncertainty.instruments import MODELS, ComponentUncertainty

__all__ = [
    "DISTRIBUTIONS",
    "INSTRUMENTS",
    "METHODS",
    "ComponentU",
    "UncertaintySpec",
]

METHODS = ("statistical", "summation", "montecarlo")
DISTRIBUTIONS = ("normal", "rectangular")
#: instrument names in the configuration -> model names of :data:`MODELS`
INSTRUMENTS = {name.replace("_", "-"): name for name in MODELS}


@dataclass(frozen=True)
class ComponentU:
    """The expanded uncertainty of one component.

    ``U`` is a constant (µm for linear and straightness, µm/m for angles and squareness),
    or ``profile`` a curve of U along the axis (same unit). ``model`` is ``"direct"`` or the
    instrument's name; ``budget`` the instrument model's contributions when there is one;
    ``distribution`` the shape drawn by the Monte Carlo method.
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

    @property
    def U_max(self) -> float:
        """The largest U along the axis (the constant U when there is no curve)."""
        if self.profile is None:
            return float(self.U or 0.0)
        return float(max(abs(self.profile.mean("mean")).max(), 0.0))

    def as_component(self) -> Component:
        """A component whose 'error' is this U: the model run with U in place of the error."""
        if self.kind == "squareness":
            return Component(self.component, self.kind, None, self.about, value=self.U, source="U")
        profile = self.profile
        if profile is None:
            kind = "angular" if self.kind == "mechanical" else self.kind
            run = [[float(self.U)]]
            profile = ErrorProfile(
                kind, [0.0], {"forward": run, "backward": run}, axis=self.axis, source="U"
            )
        return Component(self.component, self.kind, self.axis, self.about, profile=profile)


@dataclass(frozen=True)
class UncertaintySpec:
    """The ``[uncertainty]`` table: coverage factor, method, Monte Carlo settings, the
    components' uncertainties and an optional prior (thesis eq. 3.22-3.24)."""

    k: float = 2.0
    method: str = "statistical"
    samples: int = 20000
    seed: int = 1
    components: Mapping[str, ComponentU] = field(default_factory=dict)
    prior: tuple[float, float] | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "components", MappingProxyType(dict(self.components)))
