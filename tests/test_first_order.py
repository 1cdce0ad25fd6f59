"""The validity of the first-order model (esp.core.first_order): the bound of its second-order
remainder holds against the exact chain, and a result the remainder could change by more
than 10 % is refused, by more than 1 % warned (docs/reliability.md, "Where the first-order
model holds")."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from esp.config import load_machine, machine_from_dict
from esp.config.chain import load_chain
from esp.core.analysis import analyse
from esp.core.errors import DataError
from esp.core.first_order import (
    REFUSE_FRACTION,
    WARN_FRACTION,
    first_order_bound,
    first_order_warnings,
    remainder_bound_um,
)
from esp.core.kinematics import position, sensitivities
from esp.core.models.tool import tool_cases

EXAMPLES = Path(__file__).resolve().parents[1] / "data" / "examples"

GANTRY_CHAIN = EXAMPLES / "chains" / "gantry-wBMTt.toml"


def test_remainder_bound_worked_values():
    # one rotation of 1 mrad on a 1 m lever: θ²/2 · L = 0.5e-6 · 1e6 µm = 0.5 µm, plus
    # θ³/6 · L = 1.7e-4 µm (e^θ − 1 − θ is the whole series)
    assert remainder_bound_um([1e-3], 1000.0) == pytest.approx(0.5 + 1e-9 / 6 * 1e6, rel=1e-6)
    # two angles add before squaring: (θ1 + θ2)²/2 · L holds the product θ1 θ2 L
    assert remainder_bound_um([1e-3, 1e-3], 1000.0) == pytest.approx(2.0, rel=1e-3)
    # an angle times a displacement error: (e^θ − 1) Δ ≈ 1e-3 · 1000 µm = 1 µm
    assert remainder_bound_um([1e-3], 0.0, [1000.0]) == pytest.approx(1.0005, rel=1e-6)
    assert remainder_bound_um([], 1e5, [1e4]) == 0.0  # no rotation: the model is exact


@pytest.mark.parametrize("theta", [1e-5, 1e-3, 0.02, 0.09])
def test_bound_holds_against_the_exact_chain(theta):
    """The exact chain (esp.core.kinematics.exact, homogeneous transforms) minus the nominal
    and the first-order terms is the remainder; it never exceeds the bound, for random
    points, signs and tool offsets, and the bound is within two orders of it."""
    chain = load_chain(GANTRY_CHAIN)
    rng = np.random.default_rng(11)
    n = 200
    coords = {a: rng.uniform(-800.0, 800.0, n) for a in ("X", "Y", "Z")}
    params = {"tool_x": 50.0, "tool_y": -120.0, "tool_z": -250.0}
    errors = {}
    for e in chain.errors:
        unit = chain.symbols[e].unit
        if e.startswith("S_"):
            errors[e] = 0.0  # the chain writes squareness as a lever term: linear, exact
        elif unit == "urad":
            errors[e] = float(rng.choice([-1.0, 1.0]) * theta * 1e6)
        else:
            errors[e] = float(rng.choice([-1.0, 1.0]) * 800.0)
    exact = position(chain, coords, params, errors)
    nominal = position(chain, coords, params, {})
    sens = sensitivities(chain, coords, params)
    first = sum(sens[e] * errors[e] for e in chain.errors)
    remainder_um = np.linalg.norm(exact - nominal - first, axis=1).max() * 1000.0
    lever = math.sqrt(3 * 800.0**2) + math.sqrt(50.0**2 + 120.0**2 + 250.0**2)
    angles = [abs(v) * 1e-6 for e, v in errors.items() if chain.symbols[e].unit == "urad"]
    shifts = [abs(v) for e, v in errors.items() if chain.symbols[e].unit == "um"]
    bound = remainder_bound_um(angles, lever, shifts)
    assert remainder_um <= bound
    assert bound <= 100 * remainder_um


def _machine(angle: float, travel: float = 1000.0, tool: float | None = None, offset=0.0):
    angular = {a: {"constant": angle} for a in "XYZ"}
    axes = {
        n: {
            "travel": [-travel, travel],
            "step": travel / 2,
            "offset": offset if n == "X" else 0.0,
            "errors": {"angular": angular},
        }
        for n in "XYZ"
    }
    data = {
        "machine": {
            "name": "m",
            "configuration": "wBMTt",
            "axes": {"bottom": "Y", "middle": "X", "top": "Z"},
        },
        "axes": axes,
    }
    if tool is not None:
        data["analysis"] = {"point": "TCP"}
        data["tool"] = {"lengths": [tool], "orientation": {"tilt": 0, "spin": 0}}
    return machine_from_dict(data, ".")


def test_the_issue_machine_is_refused_naming_the_bound_and_the_keys():
    # angles of ±99 999 µm/m, ±100 m travels, a 100 m tool and a -100 000 mm offset: each
    # within its limit, the result ("51962930.039 µm") meaningless
    machine = _machine(99_999.0, travel=100_000.0, tool=100_000.0, offset=-100_000.0)
    with pytest.raises(DataError) as info:
        analyse(machine)
    message = str(info.value)
    assert "second-order remainder of the first-order model may reach" in message
    assert "axes.X.errors.angular.X 99999 um/m" in message
    for key in ("axes.X.travel", "axes.X.offset", "tool"):
        assert key in message
    assert "above 10% of the result" in message


def test_a_remainder_between_1_and_10_percent_is_a_warning():
    # nine angles of 1000 µm/m: Θ = 0.009 rad on a lever of √3 m (three ±1 m travels), a
    # bound of Θ²/2 · 1.732e6 µm = 70.1 µm (70.36 with the cubic term) against a result of
    # 3742 µm: 1.9 %
    machine = _machine(1000.0)
    result = analyse(machine)
    v = result.cases[result.worst].volumetric.value_um
    b = first_order_bound(machine, [t.offset_mm for t in tool_cases(machine)])
    assert b.bound_um == pytest.approx(0.009**2 / 2 * math.sqrt(3) * 1e6, rel=0.01)
    assert WARN_FRACTION < b.bound_um / v < REFUSE_FRACTION, (b.bound_um, v)
    [warning] = [w for w in result.warnings if "second-order remainder" in w]
    assert "the result may be wrong by more than 1%" in warning


def test_small_angles_give_no_warning():
    result = analyse(_machine(10.0))
    assert not [w for w in result.warnings if "second-order" in w]


def test_the_examples_are_far_inside_the_validity_range():
    machine = load_machine(EXAMPLES / "gantry" / "machine.toml")
    b = first_order_bound(machine)
    # about 10 µm/m angles on 2 m levers: a few hundredths of a µm against 34 µm
    assert 0 < b.bound_um < 0.1
    assert b.relative  # datum = "negative": twice the bound of one point
    assert first_order_warnings(machine, 33.9) == ()


def test_a_zero_result_with_a_negligible_bound_is_not_refused():
    # nine angles of 1 µm/m: a bound of Θ²/2 · L = (9e-6)²/2 · 1.73e6 µm = 7e-5 µm, below
    # the printed resolution of 0.001 µm, whatever the result
    machine = _machine(1.0)
    assert first_order_warnings(machine, 0.0) == ()
    with pytest.raises(DataError):
        first_order_warnings(_machine(4000.0), 0.0)
