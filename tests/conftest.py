"""Shared test helpers: machines built in code, without files."""

from __future__ import annotations

import pytest

from esp.core.machine import Analysis, Axis, Component, Machine, Tool
from esp.core.profile import ErrorProfile

#: a 100 mm machine whose X positioning error is read from ``X.csv`` beside it
SMALL_MACHINE = """
[machine]
name = "small"
configuration = "wBMTt"
axes = { bottom = "X", middle = "Y", top = "Z" }
[axes.X]
travel = [0, 100]
step = 50
[axes.X.errors]
linear = "X.csv"
[axes.Y]
travel = [0, 100]
step = 50
[axes.Z]
travel = [0, 100]
step = 50
"""


def component(name: str, data) -> Component:
    """A component from a name and data: a number (constant, or the squareness value), a
    list of (position_mm, value) points, or an ErrorProfile."""
    parts = name.split(".")
    if parts[0] == "squareness":
        return Component(name, "squareness", None, parts[1], value=float(data), source="test")
    axis, kind = parts[0], parts[1]
    about = parts[2] if len(parts) > 2 else None
    pkind = "angular" if kind == "mechanical" else kind
    if isinstance(data, ErrorProfile):
        profile = data
    elif isinstance(data, (int, float)):
        profile = ErrorProfile.from_values(pkind, [0.0], [float(data)], axis=axis)
    else:
        t, v = zip(*data, strict=True)
        profile = ErrorProfile.from_values(pkind, t, v, axis=axis)
    return Component(name, kind, axis, about, profile=profile, source="test")


def build_machine(
    components: dict | None = None,
    configuration: str = "wBMTt",
    roles: tuple[str, str, str] = ("X", "Y", "Z"),
    travel=(0.0, 1000.0),
    step: float = 250.0,
    offsets: dict | None = None,
    tool: Tool | None = None,
    **analysis,
) -> Machine:
    """A machine with equal travel on every axis and the given components."""
    offsets = offsets or {}
    role_of = dict(zip(roles, ("bottom", "middle", "top"), strict=True))
    travels = travel if isinstance(travel, dict) else {a: travel for a in "XYZ"}
    axes = {
        a: Axis(a, role_of[a], tuple(travels[a]), tuple(travels[a]), step, offsets.get(a, 0.0))
        for a in "XYZ"
    }
    comps = {n: component(n, d) for n, d in (components or {}).items()}
    return Machine(
        "test",
        configuration,
        dict(zip(("bottom", "middle", "top"), roles, strict=True)),
        axes,
        comps,
        Analysis(**analysis),
        tool,
    )


@pytest.fixture
def make_machine():
    return build_machine
