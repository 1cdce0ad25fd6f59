"""An uncertainty is complete or explicit: evaluated for every component the model uses (its
own U, or a stated default per kind), or not stated at all, the components without U named."""

from __future__ import annotations

import json
import math

import pytest
from click.testing import CliRunner

from esp.cli import main
from esp.config import machine_from_dict
from esp.core.analysis import analyse
from esp.core.errors import ConfigError


def machine(uncertainty: dict | None) -> dict:
    """A 1 m machine with constant linear errors of X (5 µm) and Y (2 µm) and a squareness
    XY of 4 µm/m; nothing else."""
    data: dict = {
        "machine": {
            "name": "Complete",
            "configuration": "wBMTt",
            "axes": {"bottom": "X", "middle": "Y", "top": "Z"},
        },
        "axes": {
            "X": {"travel": [0, 1000], "step": 250, "errors": {"linear": {"constant": 5.0}}},
            "Y": {"travel": [0, 1000], "step": 250, "errors": {"linear": {"constant": 2.0}}},
            "Z": {"travel": [0, 500], "step": 250},
        },
        "squareness": {"XY": 4.0},
    }
    if uncertainty is not None:
        data["uncertainty"] = uncertainty
    return data


def write(tmp_path, text: str):
    path = tmp_path / "machine.toml"
    path.write_text(
        '[machine]\nname = "Complete"\nconfiguration = "wBMTt"\n'
        'axes = { bottom = "X", middle = "Y", top = "Z" }\n'
        "[axes.X]\ntravel = [0, 1000]\nstep = 250\n[axes.X.errors]\nlinear = { constant = 5.0 }\n"
        "[axes.Y]\ntravel = [0, 1000]\nstep = 250\n[axes.Y.errors]\nlinear = { constant = 2.0 }\n"
        "[axes.Z]\ntravel = [0, 500]\nstep = 250\n" + text,
        encoding="utf-8",
    )
    return str(path)


def test_a_partial_table_states_no_u_and_names_what_is_missing():
    res = analyse(machine_from_dict(machine({"components": {"X.linear": {"U": 2.0}}}), "."))
    assert res.uncertainty is None
    assert [str(n) for n in res.uncertainty_missing] == ["Y.linear", "squareness.XY"]
    assert any("no U for Y.linear, squareness.XY" in w for w in res.warnings)


def test_every_component_with_its_own_u_is_complete():
    comps = {"X.linear": {"U": 2.0}, "Y.linear": {"U": 4.0}, "squareness.XY": {"U": 0.0}}
    res = analyse(machine_from_dict(machine({"components": comps}), "."))
    assert res.uncertainty_missing == ()
    # statistical, k = 2: u = 1 µm in X and 2 µm in Y (a zero U of the squareness adds
    # nothing), U = 2·√(1² + 2²) = 4.472 µm, the same at every point (no lever arm)
    assert res.uncertainty.volumetric.value_um == pytest.approx(2.0 * math.sqrt(5.0))
    assert res.uncertainty.uniform


def test_a_default_fills_the_rest_by_kind_and_says_so():
    table = {
        "components": {"X.linear": {"U": 2.0}},
        "default": {"linear": 4.0, "squareness": 0.0},
    }
    res = analyse(machine_from_dict(machine(table), "."))
    assert res.uncertainty_missing == ()
    # X.linear keeps its own U = 2 µm; Y.linear takes the default 4 µm: as above, 4.472 µm
    assert res.uncertainty.volumetric.value_um == pytest.approx(2.0 * math.sqrt(5.0))
    models = {b.component: b.model for b in res.uncertainty.budget}
    assert models == {"X.linear": "direct", "Y.linear": "default", "squareness.XY": "default"}
    # a default's own k: U = 6 µm at k = 3 is u = 2 µm, as before
    table["default"] = {"linear": 6.0, "squareness": 0.0, "k": 3.0}
    res = analyse(machine_from_dict(machine(table), "."))
    assert res.uncertainty.volumetric.value_um == pytest.approx(2.0 * math.sqrt(5.0))


def test_a_default_without_the_kind_needed_leaves_it_missing():
    table = {"components": {"X.linear": {"U": 2.0}}, "default": {"linear": 4.0}}
    res = analyse(machine_from_dict(machine(table), "."))
    assert res.uncertainty is None
    assert [str(n) for n in res.uncertainty_missing] == ["squareness.XY"]


@pytest.mark.parametrize(
    ("default", "message"),
    [
        ({}, "uncertainty.default: expected a U for at least one kind"),
        ({"linear": -1.0}, "uncertainty.default.linear: expected an expanded uncertainty >= 0"),
        ({"linear": 1.0, "roll": 2.0}, "uncertainty.default"),
        ({"linear": 1.0, "k": 0.0}, "uncertainty.default.k"),
    ],
)
def test_bad_defaults_are_refused_naming_the_key(default, message):
    with pytest.raises(ConfigError, match=message):
        machine_from_dict(machine({"default": default}), ".")


def test_a_varying_u_says_where_it_is_largest():
    # Y.linear's U grows along Y: 0 µm at Y = 0 to 4 µm at Y = 1000 mm, the rest zero
    comps = {
        "X.linear": {"U": 0.0},
        "Y.linear": {"U": {"points": [[0, 0.0], [1000, 4.0]]}},
        "squareness.XY": {"U": 0.0},
    }
    res = analyse(machine_from_dict(machine({"components": comps}), "."))
    assert not res.uncertainty.uniform
    assert res.uncertainty.volumetric.value_um == pytest.approx(4.0)
    assert res.uncertainty.volumetric.at["Y"] == 1000.0


def test_the_cli_names_the_missing_components(tmp_path):
    path = write(tmp_path, '[uncertainty.components]\n"X.linear" = { U = 2.0 }\n')
    res = CliRunner().invoke(main, ["analyse", path])
    assert res.exit_code == 0, res.output
    assert "uncertainty: not evaluated (no U for Y.linear)" in res.stdout
    assert "esp: warning: the uncertainty is not evaluated: no U for Y.linear" in res.stderr
    assert "0.000" not in res.stdout.split("Volumetric accuracy of")[1]
    doc = json.loads(CliRunner().invoke(main, ["analyse", path, "--json", "-"]).stdout)
    assert doc["analysis"]["uncertainty_missing"] == ["Y.linear"]
    assert "uncertainty" not in doc
    # a guarded decision needs U: refused, naming the way out
    res = CliRunner().invoke(
        main, ["analyse", path, "--tolerance", "volumetric=30", "--rule", "guarded"]
    )
    assert res.exit_code == 2
    assert res.stderr.startswith("esp: error: --rule: guarded acceptance needs")
    assert "not evaluated (no U for Y.linear)" in res.stderr


def test_the_cli_states_a_default_and_a_uniform_u(tmp_path):
    path = write(
        tmp_path,
        "[uncertainty]\ndefault = { linear = 4.0 }\n"
        '[uncertainty.components]\n"X.linear" = { U = 2.0 }\n',
    )
    res = CliRunner().invoke(main, ["analyse", path])
    assert res.exit_code == 0, res.output
    assert "U = 4.5 µm (k = 2, about 95 %)" in res.stdout  # 4.472 to two digits
    assert "the same at every point of the volume" in res.stdout
    assert "default" in res.stdout  # the budget names the default as the U's model


def test_the_range_of_a_direction_has_one_u_in_the_summary_and_the_decision():
    from esp.config.tolerance import Tolerances
    from esp.volumetric.conformance import decide_result
    from esp.volumetric.pdf import headlines

    comps = {
        "X.linear": {"U": 0.0},
        "Y.linear": {"U": {"points": [[0, 0.0], [1000, 4.0]]}},
        "squareness.XY": {"U": 0.0},
    }
    res = analyse(machine_from_dict(machine({"components": comps}), "."))
    # the range is max - min of the Y error, each known to U_Y = 4 µm: U = √2·4 = 5.66 µm
    assert res.uncertainty.range_um("Y") == pytest.approx(4.0 * math.sqrt(2.0))
    row = next(h for h in headlines(res) if h.label == "Range of the Y error")
    assert row.uncertainty.startswith("U = 5.7 µm (k = 2")
    (decision,) = decide_result(res, Tolerances(range_um={"Y": 10.0}))
    assert decision.expanded == pytest.approx(4.0 * math.sqrt(2.0))


def test_every_budget_line_says_what_makes_its_u(tmp_path):
    from esp.core.uncertainty.instruments import laser_linear
    from esp.volumetric.jsondoc import result_dict

    params = {
        "measuring_length_mm": 1000.0,
        "duration_min": 31.0,
        "temperature_change_degc": 0.2,
        "max_difference_to_20_degc": 0.5,
        "expansion_coefficient_um_per_m_per_degc": 11.5,
        "u_calibration_um_per_m": 0.25,
        "alignment_mm": 0.5,
    }
    table = {
        "components": {"X.linear": {"instrument": "laser-linear", **params}},
        "default": {"linear": 4.0, "squareness": 3.0},
    }
    res = analyse(machine_from_dict(machine(table), "."))
    lines = {b.component: b for b in res.uncertainty.budget}
    expected = laser_linear(**params)
    x = lines["X.linear"]
    assert x.contributors == expected.contributions
    # the thermal drift of a 31-minute test, between the rows of table 3.2: 2.1 µm
    drift = next(c for c in x.contributors if "thermal drift" in c.name)
    assert drift.u == pytest.approx(2.1)
    # their root-sum-square is the component's u
    assert math.sqrt(sum(c.u**2 for c in x.contributors)) == pytest.approx(x.u)
    # a default is one contributor, U / k
    (y,) = lines["Y.linear"].contributors
    assert y.name.startswith("[uncertainty] default") and y.u == pytest.approx(2.0)
    doc = result_dict(res)
    entry = next(b for b in doc["uncertainty"]["budget"] if b["component"] == "X.linear")
    assert [c["name"] for c in entry["contributors"]] == [c.name for c in expected.contributions]
    assert all(c["sensitivity"] == 1.0 and c["type"] == "B" for c in entry["contributors"])
