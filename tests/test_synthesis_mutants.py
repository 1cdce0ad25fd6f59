"""Numbers of the synthesis that only arranged cases reach (docs/testing.md, "Mutation
runs"): a head's or table's setting errors in the many-point evaluation, the root-sum-square
products with tool offsets, lever offsets and squareness constants, and the breakdown at
each direction's maximum.

Referees: values worked out by hand, and the sum over every grid point of each term's value
squared, each term evaluated one point at a time (``Synthesis.term_value_um``, the route the
breakdowns take) -- not the separable products under test.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable

import numpy as np
import pytest

from esp.config import machine_from_dict
from esp.core.grid import Product
from esp.core.machine import Machine
from esp.core.models.tool import SettingTerm, ToolCase
from esp.core.names import AXIS_NAMES
from esp.core.synthesis import Synthesis, case_result

#: the tool tip's offset from the MCP (mm): none of ±1, so a product and a quotient differ
TOOL_MM = {"X": 40.0, "Y": -25.0, "Z": -150.0}
#: the offsets of the axes' measurement lines (mm): the levers' zeros
AXIS_OFFSET_MM = {"X": 120.0, "Y": -60.0, "Z": 35.0}
#: squareness constants (µm/m): neither 0, 1 nor 2, so s, s², s³ and 1/s² all differ
SQUARENESS = {"squareness.XY": 7.0, "squareness.XZ": -3.0, "squareness.YZ": 12.5}


def _machine(point: str = "TCP") -> Machine:
    data = {
        "machine": {
            "name": "arranged",
            "configuration": "wBMTt",
            "axes": {"bottom": "X", "middle": "Y", "top": "Z"},
        },
        "analysis": {"point": point},
        "axes": {
            a: {"travel": [0, 200], "step": 50, "offset": AXIS_OFFSET_MM[a]} for a in AXIS_NAMES
        },
    }
    if point == "TCP":
        data["tool"] = {"orientation": {"offset": dict(TOOL_MM)}}
    return machine_from_dict(data, ".")


def _curve(c0: float, c1: float, c2: float) -> Callable[[np.ndarray], np.ndarray]:
    def f(x: np.ndarray) -> np.ndarray:
        t = np.asarray(x, dtype=float) / 100.0
        return c0 + c1 * t + c2 * t * t

    return f


def _synthesis() -> Synthesis:
    """Every component of the wBMTt model with a value: a quadratic curve of its axis
    (coefficients drawn once, seed 7) or a squareness constant."""
    machine = _machine()
    names = sorted({str(t.component) for t in Synthesis.prepare(machine).model.terms})
    rng = np.random.default_rng(7)
    values: dict = {}
    for name in names:
        if name in SQUARENESS:
            values[name] = SQUARENESS[name]
        else:
            values[name] = _curve(*rng.uniform(-5.0, 5.0, 3))
    assert set(SQUARENESS) <= set(values) and len(values) == 21
    return Synthesis.prepare(machine, values=values, measured=False)


def _product_at(p: Product, index: tuple[int, ...]) -> float:
    value = p.scale
    if p.a is not None and p.f is not None:
        value *= float(p.f[index[p.a]])
    if p.c is not None and p.g is not None:
        value *= float(p.g[index[p.c]])
    return value


def test_squared_products_are_the_sum_of_each_term_squared_at_every_point() -> None:
    """Thesis 3.14.7: the statistical combination of a direction is Σ t² over its terms.
    With lever offsets, a tool offset on every axis (angular terms whose lever is a tool
    offset alone, or an axis position plus one) and squareness constants, every point of
    the 5 × 5 × 5 grid: the separable products against each term evaluated there."""
    syn = _synthesis()
    tool = ToolCase(None, None, None, dict(TOOL_MM))
    terms = syn.terms()
    assert any(t.tool_axis and t.lever_axis for t in terms)
    assert any(t.tool_axis and not t.lever_axis for t in terms)
    assert any(t.lever_axis and not t.tool_axis and not t.axis for t in terms)  # squareness
    products = syn.squared_products(tool)
    g = syn.grids
    for index in itertools.product(*(range(g[a].size) for a in AXIS_NAMES)):
        point = {a: float(g[a][i]) for a, i in zip(AXIS_NAMES, index, strict=True)}
        for d, a in enumerate(AXIS_NAMES):
            expected = math.fsum(
                syn.term_value_um(t, point, tool) ** 2 for t in terms if t.direction == a
            )
            got = math.fsum(_product_at(p, index) for p in products if p.direction == d)
            assert got == pytest.approx(expected, rel=1e-12, abs=1e-12), (point, a)


def test_squareness_alone_squares_its_constant_by_hand() -> None:
    """squareness.XY = 7 µm/m alone, in X with lever Y from the line at Y = -60 mm: at
    Y = 200 mm its term is 7 · 260 / 1000 = 1.82 µm, squared 3.3124 µm²."""
    machine = _machine("MCP")
    syn = Synthesis.prepare(machine, values={"squareness.XY": 7.0}, measured=False)
    tool = ToolCase(None, None, None, {a: 0.0 for a in AXIS_NAMES})
    index = (0, 4, 0)  # X = 0, Y = 200, Z = 0
    by_direction = [0.0, 0.0, 0.0]
    for p in syn.squared_products(tool):
        by_direction[p.direction] += _product_at(p, index)
    assert by_direction == pytest.approx([3.3124, 0.0, 0.0], rel=1e-12, abs=1e-15)


def test_setting_terms_add_their_constants_and_slopes_at_many_points() -> None:
    """A head's errors at one setting (esp.core.models.tool.SettingTerm): one term 3 µm in
    X and 0.002 X - 0.001 Z µm in Y, another -1.5 µm in Z; no other error. By hand at
    (100, 50, 200): X 3, Y 0.2 - 0.2 = 0, Z -1.5; at (0, 0, 0): 3, 0, -1.5; at
    (200, 0, 0): 3, 0.4, -1.5. A direction a term does not name gets nothing."""
    syn = Synthesis.prepare(_machine("MCP"))
    assert syn.terms() == []
    terms = (
        SettingTerm(
            "head.one", "test", "e1", 1.0, "um", {"X": 3.0}, {"Y": {"X": 0.002, "Z": -0.001}}
        ),
        SettingTerm("head.two", "test", "e2", 1.0, "um", {"Z": -1.5}),
    )
    tool = ToolCase(None, None, None, {a: 0.0 for a in AXIS_NAMES}, {"A": 0.0}, terms)
    pts = np.array([[100.0, 50.0, 200.0], [0.0, 0.0, 0.0], [200.0, 0.0, 0.0]])
    expected = np.array([[3.0, 0.0, -1.5], [3.0, 0.0, -1.5], [3.0, 0.4, -1.5]])
    np.testing.assert_allclose(syn.totals_at_um(pts, tool), expected, rtol=0, atol=1e-12)


def test_each_breakdown_is_read_at_its_own_extreme() -> None:
    """The breakdowns "X min" ... "Z max" are the terms at the point of that extreme: the
    breakdown's total in that direction is the extreme's value, at the extreme's point."""
    syn = _synthesis()
    tool = ToolCase(None, None, None, dict(TOOL_MM))
    result = case_result(syn, tool, None, True)
    records = {b.label: b for b in result.breakdowns}
    for a in AXIS_NAMES:
        low, high = result.axes[a].minimum, result.axes[a].maximum
        assert low.value_um < high.value_um and low.at != high.at
        for label, extreme in ((f"{a} min", low), (f"{a} max", high)):
            assert records[label].at == extreme.at
            assert records[label].errors_um[a] == pytest.approx(extreme.value_um, rel=1e-12)
