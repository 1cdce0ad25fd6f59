"""A five-axis machine, a Cartesian stack carrying a servo head: the engine's tool-tip error
over the linear axes and the head angles equals the first order of the whole machine's
kinematic chain (the Cartesian joints followed by the head's chain), evaluated
independently by esp.core.kinematics."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from esp.core.analysis import analyse
from esp.core.kinematics import Chain, sensitivities
from esp.core.machine import Analysis, Axis, Component, HeadSetup, Machine, Tool
from esp.core.models.derived import cartesian_chain, error_symbol
from esp.core.models.tool import tool_cases
from esp.core.names import AXIS_NAMES, all_component_names
from esp.core.profile import ErrorProfile
from esp.core.synthesis import Synthesis
from esp.heads import load_head

HEADS = Path(__file__).resolve().parent.parent / "data" / "examples" / "heads"


def _machine(configuration="wBMTt", letters=("Y", "X", "Z"), seed=4, datum="none"):
    rng = np.random.default_rng(seed)
    travel = {"X": (0.0, 1000.0), "Y": (0.0, 1500.0), "Z": (0.0, 600.0)}
    roles = dict(zip(("bottom", "middle", "top"), letters, strict=True))
    role_of = {v: k for k, v in roles.items()}
    axes = {
        a: Axis(a, role_of[a], travel[a], travel[a], 250.0, 100.0 * i)
        for i, a in enumerate(AXIS_NAMES)
    }
    comps = {}
    for name in all_component_names(mechanical=False):
        if name.kind == "squareness":
            comps[name] = Component(name, "squareness", None, name.about, value=rng.normal() * 5)
            continue
        t = np.linspace(*travel[name.axis], 11)
        v = rng.normal(size=t.size).cumsum() * (
            1.0 if name.kind in ("linear", "straightness") else 2.0
        )
        prof = ErrorProfile.from_values(
            "angular" if name.kind == "angular" else name.kind, t, v, axis=name.axis
        )
        comps[name] = Component(name, name.kind, name.axis, name.about, profile=prof)
    head, _ = load_head(HEADS / "angle-head-fig3.toml")
    setup = HeadSetup(head, {"A": (-60.0, 0.0, 45.0), "C": (-30.0, 90.0)}, "angle-head-fig3.toml")
    return Machine(
        "five-axis",
        configuration,
        roles,
        axes,
        comps,
        Analysis(point="TCP", straightness_fit="none", datum=datum),
        None,
        head=setup,
    )


def _whole_chain(machine):
    """The Cartesian joints of the machine, then the head's chain instead of a tool offset."""
    letters = tuple(machine.roles[r] for r in ("bottom", "middle", "top"))
    stack = cartesian_chain(machine.configuration, letters, False)
    head = machine.head.head
    steps = tuple(stack.steps[:-1]) + tuple(head.chain.steps)
    symbols = {n: s for n, s in stack.symbols.items() if not n.startswith("P_")}
    symbols.update(head.chain.symbols)
    return Chain(steps, symbols)


@pytest.mark.parametrize(
    ("configuration", "letters"), [("wBMTt", ("Y", "X", "Z")), ("BMwTt", ("X", "Y", "Z"))]
)
@pytest.mark.slow
def test_engine_equals_the_whole_chain_to_first_order(configuration, letters):
    machine = _machine(configuration, letters)
    chain = _whole_chain(machine)
    head = machine.head.head
    rng = np.random.default_rng(7)
    points = np.column_stack([rng.uniform(*machine.axes[a].travel_mm, 20) for a in AXIS_NAMES])
    syn = Synthesis.prepare(machine)
    cases = tool_cases(machine)
    assert len(cases) == 3 * 2
    for case in cases:
        coords = {a: points[:, i] for i, a in enumerate(AXIS_NAMES)}
        coords.update({n: np.full(len(points), v) for n, v in case.setting_deg.items()})
        params = {f"{a}_off": machine.axes[a].offset_mm for a in AXIS_NAMES}
        params.update(head.values_in("parameter"))
        sens = sensitivities(chain, coords, params)
        reference = np.zeros_like(points)
        for name, comp in machine.components.items():
            symbol = error_symbol(name.kind, name.axis, name.about)
            if comp.kind == "squareness":
                value = comp.value
            else:
                value = comp.profile.at(points[:, AXIS_NAMES.index(comp.axis)])
            reference += sens[symbol] * np.reshape(value, (-1, 1)) * 1000.0
        for name, value in head.values_in("error").items():
            reference += sens[name] * value * 1000.0
        engine = syn.totals_at_um(points, case)
        assert np.max(np.abs(engine - reference)) < 1e-6
        assert np.max(np.abs(reference)) > 1.0


def test_the_worst_head_setting_is_reported_with_the_head_terms():
    machine = _machine()
    result = analyse(machine)
    assert len(result.sweep) == 6 and len(result.cases) == 1
    worst = max(result.sweep, key=lambda e: e.volumetric.value_um)
    case = result.cases[0]
    assert case.tool.setting_deg == worst.tool.setting_deg
    assert case.volumetric.value_um == pytest.approx(worst.volumetric.value_um)
    terms = [t for t in case.breakdowns[0].terms if str(t.component).startswith("head.")]
    assert {t.symbol for t in terms} <= set(machine.head.head.errors)
    assert terms and all(t.source.startswith("head") for t in terms)
    # the breakdown adds up to the errors, head terms included
    b = case.breakdowns[0]
    for a in AXIS_NAMES:
        assert sum(t.value_um for t in b.terms if t.direction == a) == pytest.approx(b.errors_um[a])


def test_a_datum_refers_every_setting_to_the_first():
    """With a datum, every head setting is referred to the error at the datum with the
    first setting, so the head's own errors stay in: at the first setting they cancel, at
    the others they are the change of the head's error from the first setting."""
    from esp.core.analysis import evaluate_point

    machine = _machine(datum="negative")
    at = {"X": 0.0, "Y": 0.0, "Z": 0.0}  # the datum itself
    cases = evaluate_point(machine, at).cases
    first, others = cases[0], cases[1:]
    assert first.breakdown.errors_um == pytest.approx({"X": 0.0, "Y": 0.0, "Z": 0.0}, abs=1e-9)
    plain = evaluate_point(_machine(), at).cases
    for case, raw in zip(others, plain[1:], strict=True):
        expected = {
            a: raw.breakdown.errors_um[a] - plain[0].breakdown.errors_um[a] for a in AXIS_NAMES
        }
        assert case.breakdown.errors_um == pytest.approx(expected, abs=1e-9)
        heads = [t for t in case.breakdown.terms if str(t.component).startswith("head.")]
        assert heads


ROTARY = HEADS.parent / "rotary"


def _table_machine(seed=6):
    """The gantry-like stack above a workpiece on the example A/C trunnion table."""
    from esp.config.devices import load_table
    from esp.core.machine import TableSetup

    machine = _machine(seed=seed)
    table = load_table(ROTARY / "trunnion.toml")
    setup = TableSetup(table, {"A": (-30.0, 0.0, 45.0), "C": (0.0, 120.0)}, "trunnion.toml")
    tool = Tool(lengths_mm=(), orientations_deg=(), offsets_mm=({"X": 40.0, "Z": -150.0},))
    return replace(machine, head=None, table=setup, tool=tool)


def test_rotary_table_equals_the_whole_chain_to_first_order():
    """The table's chain (workpiece -> table mount), then the Cartesian stack and the tool:
    the engine's error, in machine axes, equals the whole chain's first order rotated from
    the workpiece frame into machine axes by the table's nominal rotation."""
    from esp.core.devices import table_terms

    machine = _table_machine()
    setup = machine.table
    letters = tuple(machine.roles[r] for r in ("bottom", "middle", "top"))
    stack = cartesian_chain(machine.configuration, letters, False)
    chain = Chain(
        tuple(setup.table.chain.steps) + tuple(stack.steps),
        {**setup.table.chain.symbols, **stack.symbols},
    )
    rng = np.random.default_rng(11)
    points = np.column_stack([rng.uniform(*machine.axes[a].travel_mm, 16) for a in AXIS_NAMES])
    syn = Synthesis.prepare(machine)
    cases = tool_cases(machine)
    assert len(cases) == 3 * 2
    n = len(points)
    for case in cases:
        angles = {c: np.full(n, v) for c, v in case.setting_deg.items()}
        coords = {a: points[:, i] for i, a in enumerate(AXIS_NAMES)} | angles
        params = {f"{a}_off": machine.axes[a].offset_mm for a in AXIS_NAMES}
        params.update({f"P_{a}": case.offset_mm[a] for a in AXIS_NAMES})
        params.update(setup.table.parameters)
        sens = sensitivities(chain, coords, params)
        values = setup.table.values_at(angles, n)
        for name, comp in machine.components.items():
            symbol = error_symbol(name.kind, name.axis, name.about)
            if comp.kind == "squareness":
                values[symbol] = np.full(n, comp.value)
            else:
                values[symbol] = comp.profile.at(points[:, AXIS_NAMES.index(comp.axis)])
        workpiece = sum(sens[e] * values[e][:, None] * 1000.0 for e in sens if e in values)
        rotation = table_terms(setup.table, {c: v[:1] for c, v in angles.items()}).rotation[0]
        reference = workpiece @ rotation.T  # machine components = rotation @ workpiece ones
        engine = syn.totals_at_um(points, case)
        assert np.max(np.abs(engine - reference)) < 1e-6
        assert np.max(np.abs(reference)) > 1.0
