"""The machine file of ``esp parallel``: every section read, every refusal naming its key."""

from __future__ import annotations

import math

import numpy as np
import pytest

from esp.core.errors import ConfigError
from esp.parallel.config import load_parallel, parallel_from_dict
from esp.parallel.sources import SOURCE_NAMES

BASE = {
    "parallel_machine": {"name": "m"},
    "geometry": {"R_mm": 400.0, "r_mm": 200.0, "h_mm": 300.0, "strut_mm": 1000.0},
}


def _with(**sections):
    data = {k: dict(v) for k, v in BASE.items()}
    data.update(sections)
    return data


def test_every_error_key_lands_on_its_source():
    errors = {
        "leg2": {
            "strut_um": 1.0,
            "joint_um": [2.0, 3.0, 4.0],
            "slider_um": [5.0, 6.0, 7.0],
            "ball_um": [8.0, 9.0, 10.0],
            "axis_urad": [11.0, 12.0],
        },
        "table": {"position_um": [13.0, 14.0, 15.0], "rotation_urad": [16.0, 17.0, 18.0]},
    }
    m = parallel_from_dict(_with(errors=errors))
    named = {n: v for n, v in zip(SOURCE_NAMES, m.values, strict=True) if v}
    assert named == {
        "leg2.strut": 1.0,
        "leg2.joint.X": 2.0,
        "leg2.joint.Y": 3.0,
        "leg2.joint.Z": 4.0,
        "leg2.slider.X": 5.0,
        "leg2.slider.Y": 6.0,
        "leg2.slider.Z": 7.0,
        "leg2.ball.x": 8.0,
        "leg2.ball.y": 9.0,
        "leg2.ball.z": 10.0,
        "leg2.axis.tilt": 11.0,
        "leg2.axis.yaw": 12.0,
        "table.X": 13.0,
        "table.Y": 14.0,
        "table.Z": 15.0,
        "table.A": 16.0,
        "table.B": 17.0,
        "table.C": 18.0,
    }


def test_uncertainty_section():
    unc = {
        "k": 3.0,
        "method": "montecarlo",
        "samples": 100,
        "seed": 9,
        "distribution": "rectangular",
        "montecarlo_model": "linear",
        "leg1": {"strut_um": 4.0, "distribution": "normal"},
        "table": {"position_um": [1.0, 1.0, 1.0]},
    }
    spec = parallel_from_dict(_with(uncertainty=unc)).uncertainty
    assert (spec.k, spec.method, spec.samples, spec.seed, spec.montecarlo_model) == (
        3.0,
        "montecarlo",
        100,
        9,
        "linear",
    )
    assert spec.U[SOURCE_NAMES.index("leg1.strut")] == 4.0
    assert spec.distributions[SOURCE_NAMES.index("leg1.strut")] == "normal"
    assert spec.distributions[SOURCE_NAMES.index("table.X")] == "rectangular"


def test_explicit_layout_and_defaults():
    s3 = math.sqrt(3.0)
    legs = {
        "leg1": {
            "joint_xy_mm": [600.0, 0.0],
            "axis": [0.0, 2.0],
            "ball_mm": [200.0, 0.0, 300.0],
            "strut_mm": 1000.0,
        },
        "leg2": {
            "joint_xy_mm": [0.0, 200 * s3],
            "axis": [-s3, -1.0],
            "ball_mm": [-100.0, 100 * s3, 300.0],
            "strut_mm": 1000.0,
        },
        "leg3": {
            "joint_xy_mm": [0.0, -200 * s3],
            "axis": [s3, -1.0],
            "ball_mm": [-100.0, -100 * s3, 300.0],
            "strut_mm": 1000.0,
        },
    }
    m = parallel_from_dict({"parallel_machine": {"name": "m"}, "geometry": legs})
    assert m.geometry.layout == "explicit"
    np.testing.assert_allclose(m.geometry.axes[1], [-s3 / 2, -0.5, 0.0])  # normalised
    np.testing.assert_allclose(m.geometry.table_origin_mm, [200.0, 0.0, 0.0], atol=1e-12)
    assert m.model == "exact" and m.pose is None and m.uncertainty is None
    assert m.error_sweep.source == "slider.Z" and m.error_sweep.cases == ("all", "1")


@pytest.mark.parametrize(
    ("data", "key", "fragment"),
    [
        (_with(extra={}), "extra", "unknown key"),
        (_with(analysis={"model": "printed"}), "analysis.model", "did you mean 'as-printed'"),
        (_with(analysis={"max_condition": 0.5}), "analysis.max_condition", "≥ 1"),
        (_with(pose={"z_mm": 1.0, "alpha_deg": 0.0}), "pose.beta_deg", "missing"),
        (_with(pose={"z_mm": True, "alpha_deg": 0.0, "beta_deg": 0.0}), "pose.z_mm", "number"),
        (_with(errors={"leg1": {"joint_um": [1.0, 2.0]}}), "errors.leg1.joint_um", "3 numbers"),
        (_with(uncertainty={"leg1": {"strut_um": -1.0}}), "uncertainty", "U ≥ 0"),
        (_with(uncertainty={"samples": 1}), "uncertainty.samples", "≥ 2"),
        (_with(uncertainty={"k": 0}), "uncertainty.k", "> 0"),
        (_with(sweep={"error": {"source": "slider.W"}}), "sweep.error.source", "did you mean"),
        (_with(sweep={"error": {"range": [5.0, 5.0]}}), "sweep.error.range", "different"),
        (
            _with(sweep={"error": {"source": "table.X", "cases": ["all"]}}),
            "sweep.error.cases",
            "no legs",
        ),
        (
            _with(sweep={"workspace": {"z_mm": [0.0, 1.0, 2]}}),
            "sweep.workspace.alpha_deg",
            "missing",
        ),
        (
            _with(
                sweep={
                    "workspace": {
                        "z_mm": [0.0, 1.0, 2],
                        "alpha_deg": [-95.0, 0.0, 2],
                        "beta_deg": [0.0, 0.0, 1],
                    }
                }
            ),
            "sweep.workspace.alpha_deg",
            "±90°",
        ),
        ({"geometry": BASE["geometry"]}, "parallel_machine", "missing"),
        ({"parallel_machine": {"name": "m"}}, "geometry", "missing"),
        (
            {"parallel_machine": {"name": "m"}, "geometry": {**BASE["geometry"], "leg1": {}}},
            "geometry.R_mm",
            "not both",
        ),
    ],
)
def test_refusals_name_their_key(data, key, fragment):
    with pytest.raises(ConfigError) as info:
        parallel_from_dict(data)
    assert info.value.key == key
    assert fragment in info.value.message


def test_file_errors(tmp_path):
    with pytest.raises(ConfigError, match="no such configuration file"):
        load_parallel(tmp_path / "none.toml")
    bad = tmp_path / "bad.toml"
    bad.write_bytes(b"\xff\xfe")
    with pytest.raises(ConfigError, match="UTF-8"):
        load_parallel(bad)
    bad.write_text("[geometry\n", encoding="utf-8")
    with pytest.raises(ConfigError, match="invalid TOML at line 1"):
        load_parallel(bad)
