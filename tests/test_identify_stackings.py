"""Known truth through the exact 4x4 chain on random machines of the four stackings, at
the MCP and with tool offsets: all 21 components where the measurements can see them.

Each machine has a random order of its axes and random travels (identify_helpers). The
readings are made with :func:`esp.identify.simulate.actual_positions` (the exact chain,
not the first-order engine that identifies). With the truth inside the fitted basis and no
noise, the identified curves recover it to the second-order remainder (products of errors,
nanometres against a stated u of tenths of a micrometre). With the truth outside the basis
(sines) and noise of the stated size, the identified curves lie within U = 2u at about
95 % of their values over many seeds (JCGM 100:2008, 6.2-6.3).

A tool offset changes what the data see (docs/identify.md, "Tool offsets"): at the MCP the
angles of the axis nearest the tool and some of the others have no lever; with one offset
T they act as ε × T, a function of one axis' position as the straightness and linear error
of that axis are, so only the differences between offsets separate them; with two offsets
the rotation about their difference is still unseen; three offsets not on one line see
every direction.
"""

from __future__ import annotations

import json
from dataclasses import replace

import numpy as np
import pytest
from identify_helpers import (
    STACKINGS,
    TOOLS,
    all_components,
    fit_with_noise,
    full_config,
    legendre_truth,
    random_base,
    sine_truth,
    travel_of,
    truth_at,
    truth_machine,
    without_line,
    write_plates,
    write_tracker,
)

import esp
from esp.config import machine_from_dict
from esp.core.models.bind import bind_model
from esp.identify.config import DEFAULT_TARGETS, _targets, problem_from_dict
from esp.identify.run import identify, plan

SEEDS = {"wBMTt": 21, "BwMTt": 22, "BMwTt": 23, "BMTwt": 24}
NAMES = all_components()


def _setting(conf: str, folder, kind: str, truth_kind: str = "legendre"):
    """A random machine of ``conf``, its truth, the measurement sets made from it and the
    components they identify: ``plate`` (three styli) and ``tracker`` (three reflector
    offsets) all 21, ``tracker-mcp`` (the reflector at the MCP) those that act there."""
    rng = np.random.default_rng(SEEDS[conf])
    base = random_base(rng, conf)
    machine = machine_from_dict(base, folder)
    travel = travel_of(base)
    names = NAMES
    if kind == "tracker-mcp":
        names = tuple(sorted({str(t.component) for t in bind_model(machine).terms}))
    if truth_kind == "legendre":
        truth = legendre_truth(rng, travel, names, 2)
    else:
        truth = sine_truth(rng, travel, names)
        # esp's straightness has no least-squares line on the targets it is written at:
        # the true slope is a squareness (ISO 230-1 3.4.8)
        for name in names:
            if ".straightness." in name:
                a = name.split(".")[0]
                truth[name] = without_line(truth[name], _targets(machine, a, DEFAULT_TARGETS))
    if kind == "plate":
        sets = write_plates(folder, machine, truth, TOOLS)
    elif kind == "tracker":
        sets = write_tracker(folder, machine, truth, rng, 40, TOOLS)
    else:
        sets = write_tracker(folder, machine, truth, rng, 60, ((0.0, 0.0, 0.0),))
        for s in sets.values():
            del s["tool_mm"]  # the MCP, as the machine is analysed
    return base, machine, truth, sets, names


def _worst(result, truth) -> float:
    """The largest |identified - true| / U over every value of every curve."""
    worst = 0.0
    for c in result.curves:
        if not c.targets_mm:
            worst = max(worst, abs(c.values[0] - truth[c.name]) / c.U[0])
            continue
        U = np.asarray(c.U)
        keep = U > 1e-9  # zero at the low end of the travel, with no uncertainty
        error = np.abs(np.asarray(c.values) - truth_at(c.name, truth, c.targets_mm))
        assert np.all(error[~keep] < 1e-9), c.name
        worst = max(worst, float(np.max(error[keep] / U[keep])))
    return worst


@pytest.mark.slow
@pytest.mark.parametrize("kind", ["plate", "tracker"])
@pytest.mark.parametrize("conf", STACKINGS)
def test_three_tool_offsets_identify_all_21_components_of_every_stacking(conf, kind, tmp_path):
    base, _, truth, sets, _ = _setting(conf, tmp_path, kind)
    problem = problem_from_dict(full_config(base, NAMES, 2, sets), tmp_path, "m.toml")
    r = identify(problem, volumetric=False)
    assert r.identifiability.identifiable
    assert sorted(c.name for c in r.curves) == sorted(NAMES) and len(r.curves) == 21
    # the exact chain differs from the first-order model by products of errors only
    assert r.chi2 < 1e-3 * r.dof
    assert _worst(r, truth) < 0.01


@pytest.mark.slow
@pytest.mark.parametrize("conf", STACKINGS)
def test_at_the_mcp_every_component_with_a_lever_is_identified(conf, tmp_path):
    """At the MCP (no offset) a tracker sees exactly the components that act there: the
    engine's terms of the MCP say which (the rest are refused by their key)."""
    base, _, truth, sets, acting = _setting(conf, tmp_path, "tracker-mcp")
    assert 17 <= len(acting) < 21
    problem = problem_from_dict(full_config(base, acting, 2, sets), tmp_path, "m.toml")
    r = identify(problem)
    assert r.identifiability.identifiable and len(r.curves) == len(acting)
    assert _worst(r, truth) < 0.01
    # the volumetric accuracy of the identified machine is the truth's (zero noise: to
    # far less than its uncertainty)
    true = esp.analyse(truth_machine(problem, truth))
    assert r.volumetric is not None
    assert abs(r.volumetric.value_um - true.cases[true.worst].volumetric.value_um) < (
        0.01 * r.volumetric.U_um
    )


def _wbmtt(tmp_path):
    """wBMTt with Z nearest the tool, a tracker's plan for any reflector offsets."""
    base = random_base(np.random.default_rng(0), "wBMTt")
    base["machine"]["axes"] = {"bottom": "X", "middle": "Y", "top": "Z"}
    base["axes"] = {a: {"travel": [0.0, 500.0], "step": 100} for a in "XYZ"}
    machine = machine_from_dict(base, tmp_path)
    truth = legendre_truth(np.random.default_rng(1), travel_of(base), NAMES, 2)
    rng = np.random.default_rng(2)

    def ident(tools):
        sets = write_tracker(tmp_path, machine, truth, rng, 30, tools=tools)
        problem = problem_from_dict(full_config(base, NAMES, 2, sets), tmp_path, "m.toml")
        return plan(problem).identifiability

    return ident


#: a reflector offset from the MCP, mm
OFFSET = (150.0, 0.0, -100.0)


def test_at_the_mcp_the_angles_without_a_lever_are_unseen_and_three_offsets_see_all(tmp_path):
    """At the MCP the angles of Z and the yaw of Y have no lever: named whole, with the
    key they were asked at; three offsets not on one line see all 21."""
    ident = _wbmtt(tmp_path)
    at_mcp = ident(((0.0, 0.0, 0.0),))
    unseen = {"Y.angular.Z", "Z.angular.X", "Z.angular.Y", "Z.angular.Z"}
    assert {n.split("[")[0] for n in at_mcp.invisible} == unseen
    assert not at_mcp.combinations
    assert "`Z.angular.X` (axes.Z.errors.angular.X) is not seen by any reading" in (
        at_mcp.sentences()
    )
    three = ident(TOOLS)
    assert three.identifiable and three.rank == three.parameters


def test_one_offset_mixes_the_angles_and_two_leave_the_rotation_about_their_line(tmp_path):
    """One offset T: ε × T is a function of one axis' position, as the straightness,
    linear error and squareness are, so every angle of Z is mixed with them; the MCP and
    T: only the rotation about T is unseen, for each coefficient."""
    ident = _wbmtt(tmp_path)
    one = ident((OFFSET,))
    assert not one.invisible
    mixed = {name for c in one.combinations for name, _ in c}
    assert {f"Z.angular.{b}[P{j}]" for b in "XYZ" for j in (1, 2)} <= mixed
    two = ident(((0.0, 0.0, 0.0), OFFSET))
    assert not two.invisible and two.rank == two.parameters - 2
    pairs = sorted(sorted(name for name, _ in c) for c in two.combinations)
    assert pairs == [[f"Z.angular.{b}[P{j}]" for b in "XZ"] for j in (1, 2)]
    for combo in two.combinations:
        # ε ∥ (150, 0, -100): the X and Z parts of opposite sign
        x, z = (w for name, w in sorted(combo))
        assert np.sign(x) == -np.sign(z)


def _coverage_share(conf: str, kind: str, folder, seeds: int) -> tuple[float, float]:
    """(share of identified values within ±U over ``seeds`` noisy data sets, the largest
    |error| / U of the zero-noise fit): the truth is outside the basis (sines fitted with
    Legendre degree 4), the readings through the exact chain; each seed adds normal noise
    of the stated u to the readings."""
    from esp.identify.model import Engine, build_blocks
    from esp.identify.run import _curves
    from esp.identify.solve import fit, layout

    base, _, truth, sets, names = _setting(conf, folder, kind, truth_kind="sines")
    problem = problem_from_dict(full_config(base, names, 4, sets), folder, "m.toml")
    engine = Engine(problem)
    blocks = build_blocks(problem, engine)
    params = layout(engine, blocks, (), None)
    exact = fit(blocks, params, "refuse", problem.rank_tolerance)

    def z(f):
        out = []
        for c in _curves(engine, f.x, f.covariance, 2.0):
            if not c.targets_mm:
                out.append([(c.values[0] - truth[c.name]) / c.U[0]])
                continue
            U = np.asarray(c.U)
            keep = U > 1e-9
            true = truth_at(c.name, truth, c.targets_mm)
            out.append(((np.asarray(c.values) - true)[keep] / U[keep]).tolist())
        return np.concatenate(out)

    bias = float(np.abs(z(exact)).max())
    start = replace(params, x0=exact.x.copy())
    rng = np.random.default_rng(SEEDS[conf] * 100 + len(kind))
    inside = []
    for _ in range(seeds):
        noise = rng.standard_normal(sum(b.size for b in blocks))
        f = fit_with_noise(blocks, start, noise, problem.rank_tolerance)
        inside.append(np.abs(z(f)) <= 1.0)
    return float(np.mean(np.concatenate(inside))), bias


@pytest.mark.slow
def test_coverage_of_all_21_components_on_every_stacking_is_about_95_percent(tmp_path):
    """4 stackings x (ball plate with three styli, tracker with three reflector offsets:
    all 21 components; tracker at the MCP: those that act there) x 25 seeds = 300 noisy
    data sets, Legendre degree 4 fitted to curves outside the basis."""
    shares = []
    for conf in STACKINGS:
        for kind in ("plate", "tracker", "tracker-mcp"):
            folder = tmp_path / f"{conf}-{kind}"
            folder.mkdir()
            share, bias = _coverage_share(conf, kind, folder, 25)
            # the basis' own error is small against the noise (else the coverage falls)
            assert bias < 0.1, (conf, kind, bias)
            assert 0.88 <= share <= 0.99, (conf, kind, share)
            shares.append(share)
    # 300 data sets of strongly correlated curves: 95.4 % within about ±1.5 %
    assert 0.935 <= float(np.mean(shares)) <= 0.97, shares


def test_the_report_names_each_sets_tool_offsets():
    """The star-probe example: --plan's text and JSON give the styli of its one set."""
    from pathlib import Path

    from click.testing import CliRunner

    from esp.cli import main

    config = Path(__file__).parent.parent / "data/examples/identify/cmm-starprobe/machine.toml"
    text = CliRunner().invoke(main, ["identify", str(config), "--plan"])
    assert text.exit_code == 0, text.stderr
    assert "tool offsets: down (0, 0, -100) mm, east (100, 0, -60) mm" in text.stdout
    doc = CliRunner().invoke(main, ["identify", str(config), "--plan", "--json", "-"])
    (plate,) = json.loads(doc.stdout)["sets"]
    assert plate["tool_mm"]["north"] == [0.0, 100.0, -60.0]
