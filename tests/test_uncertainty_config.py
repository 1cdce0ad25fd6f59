"""The ``[uncertainty]`` table: what is refused (issue 9) -- non-finite, absurd and negative
U in every form, curves that do not cover the travel, Monte Carlo sample counts beyond the
limit -- each with one line naming the key; and the keys of the combination (``k`` and
``dof`` per component, ``coverage``)."""

from __future__ import annotations

import math

import pytest
from click.testing import CliRunner

from esp.cli import main
from esp.config import machine_from_dict
from esp.core.analysis import analyse
from esp.core.errors import ConfigError
from esp.core.uncertainty.spec import U_LIMITS

KEY = 'uncertainty.components."X.linear"'


def config(components: dict, **table) -> dict:
    return {
        "machine": {
            "name": "u",
            "configuration": "wBMTt",
            "axes": {"bottom": "X", "middle": "Y", "top": "Z"},
        },
        "axes": {a: {"travel": [0, 1000], "step": 250} for a in "XYZ"},
        "uncertainty": {"components": components, **table},
    }


def refused(components: dict, **table) -> ConfigError:
    with pytest.raises(ConfigError) as err:
        machine_from_dict(config(components, **table), ".")
    return err.value


# -- U values ---------------------------------------------------------------------------


@pytest.mark.parametrize(
    "entry, key, words",
    [
        ({"U": 1e308}, f"{KEY}.U", "at most 1000 um (1 mm, the plausibility limit)"),
        ({"U": 1000.5}, f"{KEY}.U", "found 1000.5"),
        ({"U": -2.0}, f"{KEY}.U", ">= 0"),
        ({"U": {"constant": -3}}, f"{KEY}.U.constant", "found -3 um"),
        ({"U": {"constant": 2e3}}, f"{KEY}.U.constant", "at most 1000 um"),
        (
            {"U": {"points": [[0, 1.0], [500, -2.0], [1000, 1.0]]}},
            f"{KEY}.U.points",
            "-2 um at 500 mm",
        ),
        ({"U": {"points": [[0, 1.0], [1000, 2e3]]}}, f"{KEY}.U.points", "at most 1000 um"),
        ({"U": {"points": [[0, 1.0], [1000, 1e308]]}}, f"{KEY}.U.points[1][1]", "within"),
        ({"U": {"points": [[0, 1.0], [1000, 2.0]], "scale": -1}}, f"{KEY}.U.points", ">= 0"),
        ({"U": {"points": [[500, 3.0]]}}, f"{KEY}.U.points", "two [position_mm, value] pairs"),
        ({"U": math.inf}, f"{KEY}.U", "finite"),
        ({"U": math.nan}, f"{KEY}.U", "finite"),
    ],
)
def test_absurd_or_negative_u_is_refused_naming_the_key(entry, key, words):
    err = refused({"X.linear": entry})
    assert err.key.startswith(key)  # points: the pair, where the value is checked there
    assert words in err.message
    assert "\n" not in str(err)


LIMIT_WORDS = "at most 100000 um/m (0.1 rad, the plausibility limit)"


@pytest.mark.parametrize(
    "name, entry, key, words",
    [
        ("X.angular.Y", {"U": 1.5e5}, 'uncertainty.components."X.angular.Y".U', LIMIT_WORDS),
        ("squareness.XY", {"U": 1e308}, 'uncertainty.components."squareness.XY".U', LIMIT_WORDS),
        (
            "squareness.XY",
            {"U": {"constant": -3}},
            'uncertainty.components."squareness.XY".U.constant',
            ">= 0, found -3",
        ),
    ],
)
def test_angles_have_a_limit_of_0_1_rad(name, entry, key, words):
    err = refused({name: entry})
    # both the key and the words, each checked on its own
    assert err.key == key
    assert words in err.message


def test_the_limits_are_accepted_exactly():
    assert U_LIMITS == {"um": 1000.0, "um/m": 100000.0}
    m = machine_from_dict(config({"X.linear": {"U": 1000.0}, "X.angular.Y": {"U": 100000.0}}), ".")
    assert m.uncertainty.components["X.linear"].U == 1000.0


def test_negative_u_in_a_file_is_refused(tmp_path):
    (tmp_path / "u.csv").write_text(
        "target_mm,run,direction,deviation\n0,1,forward,1\n1000,1,forward,2\n"
        "0,2,backward,1\n1000,2,backward,-2\n",
        encoding="utf-8",
    )
    with pytest.raises(ConfigError) as err:
        machine_from_dict(config({"X.linear": {"U": {"file": "u.csv"}}}), tmp_path)
    assert err.value.key == f"{KEY}.U.file"
    assert "-2 um at 1000 mm (backward run 1)" in err.value.message


def test_an_instrument_giving_an_absurd_u_is_refused():
    entry = {
        "instrument": "square",
        "measuring_length_mm": 500.0,
        "edge_a_um": 1e9,
        "edge_b_um": 1.0,
        "squareness_um_per_m": 1.0,
    }
    err = refused({"squareness.XY": entry})
    assert err.key == 'uncertainty.components."squareness.XY".instrument'
    assert "plausibility limit" in err.message


# -- a U curve must cover the travel ----------------------------------------------------


def test_a_u_curve_shorter_than_the_travel_names_its_key():
    data = config({"X.linear": {"U": {"points": [[0, 1.0], [500, 2.0]]}}})
    m = machine_from_dict(data, ".")
    with pytest.raises(ConfigError) as err:
        analyse(m)
    assert err.value.key == f"{KEY}.U"
    assert "runs from 0 to 500 mm but axes.X.simulate runs from 0 to 1000 mm" in str(err.value)
    # allowed with extrapolation: the end value is held
    data["analysis"] = {"extrapolate": True}
    u = analyse(machine_from_dict(data, ".")).uncertainty
    assert u.volumetric.value_um == pytest.approx(2.0)


def test_cli_says_it_in_one_line(tmp_path):
    toml = tmp_path / "m.toml"
    toml.write_text(
        '[machine]\nname = "m"\nconfiguration = "wBMTt"\n'
        'axes = { bottom = "X", middle = "Y", top = "Z" }\n'
        "[axes.X]\ntravel = [0, 1000]\nstep = 250\n"
        "[axes.Y]\ntravel = [0, 1000]\nstep = 250\n[axes.Z]\ntravel = [0, 1000]\nstep = 250\n"
        '[uncertainty.components."X.linear"]\nU = { points = [[0, 1.0], [500, 2.0]] }\n',
        encoding="utf-8",
    )
    result = CliRunner().invoke(main, ["analyse", str(toml)])
    assert result.exit_code == 2
    lines = result.output.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("esp: error: ")
    assert 'uncertainty.components."X.linear".U: the U curve of X.linear' in lines[0]


# -- Monte Carlo samples ------------------------------------------------------------------


def test_a_billion_samples_are_refused_up_front(tmp_path):
    err = refused({"X.linear": {"U": 1.0}}, method="montecarlo", samples=10**9)
    assert err.key == "uncertainty.samples"
    assert "at most 1000000" in err.message and "1000000000" in err.message


# -- the keys of the combination ---------------------------------------------------------


def test_component_k_dof_and_table_coverage_are_read():
    m = machine_from_dict(
        config(
            {
                "X.linear": {"U": 6.0, "k": 3},
                "Y.linear": {"U": 3.0, "dof": 4},
                "Z.linear": {"U": 2.0},
            },
            k=2.5,
            coverage=0.95,
        ),
        ".",
    )
    spec = m.uncertainty
    assert spec.coverage == 0.95 and spec.k == 2.5
    c = spec.components
    assert (c["X.linear"].k, c["Y.linear"].k, c["Z.linear"].k) == (3.0, 2.5, 2.5)
    assert c["Y.linear"].dof == 4.0 and math.isinf(c["X.linear"].dof)


@pytest.mark.parametrize(
    "components, table, key",
    [
        ({"X.linear": {"U": 1.0, "k": 0}}, {}, f"{KEY}.k"),
        ({"X.linear": {"U": 1.0, "k": 1e9}}, {}, f"{KEY}.k"),
        ({"X.linear": {"U": 1.0, "dof": 0.5}}, {}, f"{KEY}.dof"),
        ({"X.linear": {"U": 1.0}}, {"k": 1e308}, "uncertainty.k"),
        ({"X.linear": {"U": 1.0}}, {"coverage": 1.0}, "uncertainty.coverage"),
        (
            {"X.linear": {"U": 1.0}},
            {"coverage": 0.95, "method": "summation"},
            "uncertainty.coverage",
        ),
        (
            {"squareness.XY": {"instrument": "square", "dof": 3}},
            {},
            'uncertainty.components."squareness.XY".dof',
        ),
    ],
)
def test_bad_combination_keys_are_refused(components, table, key):
    assert refused(components, **table).key == key
