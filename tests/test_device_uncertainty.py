"""The U of a servo head's and a rotary table's errors ([uncertainty.head], [uncertainty.table])
carried into the volumetric uncertainty: checked against the head's exact chain, by hand
for the summation bound, linear in the U, and refused where esp cannot carry it."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from esp.core.errors import ConfigError
from esp.core.models.tool import tool_cases
from esp.core.uncertainty.propagate import check_uncertainty, volumetric_uncertainty
from esp.core.uncertainty.spec import DeviceU, UncertaintySpec
from esp.heads import evaluate_head
from tests.test_five_axis import _machine, _table_machine

ARCSEC = "arcsec"


def _head_only(method="statistical", scale=1.0):
    """The five-axis machine with U for its head's errors only: the linear components
    carry none, so the field is the head's alone, a constant per setting."""
    machine = _machine()
    head = machine.head.head
    devices = {
        f"head.{name}": DeviceU(
            scale * (10.0 if head.unit(name) == ARCSEC else 0.002), 2.0, head.unit(name)
        )
        for name in head.errors
    }
    return machine, UncertaintySpec(k=2.0, method=method, devices=devices)


def _exact_terms(machine, spec):
    """Per setting, per head error, the exact chain's tool-tip displacement (µm) with that
    error alone at its standard uncertainty u = U / k."""
    head = machine.head.head
    cases = tool_cases(machine)
    angles = {c: np.array([case.setting_deg[c] for case in cases]) for c in cases[0].setting_deg}
    out = []
    for key, du in spec.devices.items():
        symbol = key.split(".", 1)[1]
        errors = dict.fromkeys(head.errors, 0.0) | {symbol: du.u}
        ev = evaluate_head(replace(head, errors=errors), angles, exact=True)
        out.append(ev.exact_um)
    return np.stack(out)  # (errors, settings, 3)


def test_statistical_head_u_equals_the_exact_chain():
    machine, spec = _head_only()
    result = volumetric_uncertainty(machine, spec)
    terms = _exact_terms(machine, spec)
    per_setting = np.sqrt(np.sum(terms**2, axis=(0, 2)))  # √Σ_d Σ_s t²
    assert result.u_um == pytest.approx(float(per_setting.max()), rel=1e-6)
    assert result.volumetric.value_um == pytest.approx(2.0 * float(per_setting.max()), rel=1e-6)
    assert result.uniform  # a head's terms are constants over the linear axes
    names = {b.component for b in result.budget}
    assert names == set(spec.devices)
    assert math.isclose(sum(b.share_pct for b in result.budget), 100.0)


def test_summation_bound_by_hand():
    """B_d = Σ_s |t_s,d| at each setting, the volumetric bound k·max √Σ_d B_d²."""
    machine, spec = _head_only("summation")
    machine = replace(machine, analysis=replace(machine.analysis, datum="none"))
    result = volumetric_uncertainty(machine, spec)
    terms = _exact_terms(machine, spec)
    bounds = np.sum(np.abs(terms), axis=0)  # (settings, 3)
    expected = 2.0 * float(np.sqrt(np.sum(bounds**2, axis=1)).max())
    assert result.volumetric.value_um == pytest.approx(expected, rel=1e-6)


def test_linear_in_the_stated_u():
    machine, spec = _head_only()
    machine3, spec3 = _head_only(scale=3.0)
    one = volumetric_uncertainty(machine, spec).u_um
    three = volumetric_uncertainty(machine3, spec3).u_um
    assert three == pytest.approx(3.0 * one, rel=1e-6)


def test_table_terms_squared_exactly_over_the_grid():
    """A table's error is affine in the tool tip's position: the propagated field must be
    the brute-force Σ_s (c + a·x)² at every grid point, maximised."""
    machine = _table_machine()
    table = machine.table.table
    devices = {
        f"table.{name}": DeviceU(5.0 if table.unit(name) != "mm" else 0.003, 2.0, table.unit(name))
        for name in table.errors
    }
    spec = UncertaintySpec(k=2.0, devices=devices)
    result = volumetric_uncertainty(machine, spec)
    from esp.core.uncertainty.propagate import device_tools

    tools = device_tools(machine, spec, tool_cases(machine))
    g = {a: machine.axes[a].grid_mm() for a in "XYZ"}
    pts = np.stack(np.meshgrid(g["X"], g["Y"], g["Z"], indexing="ij"), axis=-1).reshape(-1, 3)
    best = 0.0
    for tool in tools:
        total = np.zeros(len(pts))
        for t in tool.setting_terms:
            for a in "XYZ":
                v = t.constant_um.get(a, 0.0) + sum(
                    c * pts[:, "XYZ".index(j)] for j, c in t.per_mm.get(a, {}).items()
                )
                total += v**2
        best = max(best, float(np.sqrt(total.max())))
    assert best > 0.1
    assert result.u_um == pytest.approx(best, rel=1e-9)


def test_montecarlo_with_device_u_is_refused():
    machine, spec = _head_only("montecarlo")
    with pytest.raises(ConfigError, match=r"uncertainty\.head"):
        check_uncertainty(machine, spec)


def test_config_reads_and_refuses(tmp_path):
    from esp.config import load_machine
    from esp.core.analysis import without_u

    root = __import__("pathlib").Path(__file__).resolve().parents[1]
    text = (root / "data" / "examples" / "five-axis" / "machine.toml").read_text()
    text = text.replace('"../', f'"{root}/data/examples/')
    path = tmp_path / "m.toml"
    path.write_text(text)
    machine = load_machine(path)
    assert machine.uncertainty.devices["head.ThetaAs"].U == 10.0
    assert machine.uncertainty.devices["head.Ocx"].unit == "mm"
    assert without_u(machine, ()) == ()
    # an error left out: no U for the volume, named
    path.write_text(text.replace("ThetaCv = 10     # arcsec\n", ""))
    assert without_u(load_machine(path), ()) == ("head.ThetaCv",)
    line = "ThetaCv = 10     # arcsec"
    for bad, match in (
        ("Nonsense = 3", "uncertainty.head"),
        ("ThetaCv = -1", "uncertainty.head.ThetaCv"),
    ):
        path.write_text(text.replace(line, bad))
        with pytest.raises(ConfigError, match=match):
            load_machine(path)


def test_summation_bound_refers_every_setting_to_the_first():
    """With a datum the analysis refers every setting to the first one's error there: the
    bound is then, per direction, B_d = Σ_s |t_s,d(setting) − t_s,d(first)| (a head's terms
    are constants), and 0 at the first setting itself."""
    machine, spec = _head_only("summation")
    machine = replace(machine, analysis=replace(machine.analysis, datum="negative"))
    result = volumetric_uncertainty(machine, spec)
    terms = _exact_terms(machine, spec)  # (errors, settings, 3)
    bounds = np.sum(np.abs(terms - terms[:, :1, :]), axis=0)
    expected = 2.0 * float(np.sqrt(np.sum(bounds**2, axis=1)).max())
    assert expected > 0.0
    assert result.volumetric.value_um == pytest.approx(expected, rel=1e-6)


def test_a_table_error_motion_given_as_a_curve_takes_its_U_not_its_curve():
    """ECC of the example trunnion is a curve over C. Its U (here 10 arcsec, k = 2) is a
    constant standard uncertainty at every angle: the propagated field is that of a table
    whose ECC is the constant u and every other error zero (table_terms, by brute force
    over the grid), not the curve's values; without a U the curve is named missing."""
    from esp.core.analysis import without_u
    from esp.core.devices import table_terms

    machine = _table_machine()
    table = machine.table.table
    assert "ECC" in table.curves
    u_urad = 10.0 * math.pi / 180.0 / 3600.0 * 1e6 / 2.0  # 10 arcsec at k = 2, in µrad
    spec = UncertaintySpec(k=2.0, devices={"table.ECC": DeviceU(2.0 * u_urad, 2.0, "urad")})
    result = volumetric_uncertainty(machine, spec)
    alone = replace(table, curves={}, curve_axes={}).with_values(
        dict.fromkeys(table.chain.errors, 0.0) | {"ECC": u_urad}
    )
    g = {a: machine.axes[a].grid_mm() for a in "XYZ"}
    pts = np.stack(np.meshgrid(g["X"], g["Y"], g["Z"], indexing="ij"), axis=-1).reshape(-1, 3)
    best = 0.0
    for tool in tool_cases(machine):
        at = {c: [tool.setting_deg[c]] for c in table.coordinates}
        offset = np.array([tool.offset_mm[a] for a in "XYZ"])
        terms = table_terms(alone, at)
        e = terms.constant_um[0] + (pts + offset) @ terms.per_mm[0].T
        best = max(best, float(np.linalg.norm(e, axis=1).max()))
    assert best > 1.0
    assert result.u_um == pytest.approx(best, rel=1e-9)
    with_u = replace(machine, uncertainty=UncertaintySpec(k=2.0, devices=spec.devices))
    assert "table.EXC" in without_u(with_u, ())
    assert "table.ECC" not in without_u(with_u, ())
