"""The identification report as people read it: one count of readings, the Birge ratio in
words, k on every band, labelled axes, figures rounded to what their U supports (GUM
7.2.6) while the JSON keeps full precision."""

from __future__ import annotations

import json
import re
from dataclasses import replace

import numpy as np
import pytest
from identify_helpers import identify_config, in_basis_truth, known_machine, plate_positions
from identify_helpers import write_plate as _write_plate

from esp.core.rounding import rounded
from esp.identify.config import problem_from_dict
from esp.identify.render import (
    birge_verdict,
    curves_figure,
    identify_dict,
    identify_text,
    residuals_figure,
)
from esp.identify.run import identify

SPEC = {"kind": "points", "file": "plate.csv", "u_um": 0.4, "calibration": {"u_ppm": 1.0}}


@pytest.fixture(scope="module")
def result(tmp_path_factory):
    folder = tmp_path_factory.mktemp("report")
    truth = in_basis_truth(np.random.default_rng(3))
    positions = plate_positions(known_machine(folder), truth)
    _write_plate(folder / "plate.csv", positions, np.random.default_rng(8), u_um=0.4)
    problem = problem_from_dict(identify_config(2, {"plate": SPEC}), folder, "machine.toml")
    return identify(problem)


def test_one_count_of_readings(result):
    """100 balls (4 poses of 25): 100 readings everywhere, the residuals said apart (three
    per point, one for the plate's scale)."""
    text = identify_text(result)
    assert "100 readings (301 residuals: 3 per point, 1 per artefact calibration)" in text
    counts = {int(n) for n in re.findall(r"(\d+) readings", text)}
    assert counts == {100}, counts
    doc = identify_dict(result)
    assert doc["identifiability"]["readings"] == 100
    assert doc["identifiability"]["residuals"] == 301
    assert doc["sets"][0]["readings"] == 100


def test_the_birge_ratio_is_said_in_words(result):
    assert result.consistent
    assert birge_verdict(result) == (
        f"the readings agree with the model within their stated u (Birge ratio {result.birge:.2f})"
    )
    assert birge_verdict(result) in identify_text(result)
    worse = replace(result, consistent=False, birge=1.8)
    assert birge_verdict(worse).startswith(
        "the readings scatter more than their stated u explain (Birge ratio 1.80"
    )
    assert birge_verdict(replace(result, dof=0)).startswith("no degrees of freedom")


def test_stated_figures_are_rounded_to_their_U_and_the_json_keeps_every_digit(result):
    text = identify_text(result)
    v = result.volumetric
    value, U = rounded(v.value_um, v.U_um)
    assert f"Volumetric accuracy {value} um at" in text
    assert f"U = {U} um (k = 2, about 95 %; correlations kept" in text
    assert len(U.replace(".", "").lstrip("0")) == 2  # two significant digits
    x = next(c for c in result.curves if c.name == "X.linear")
    span, U_x = rounded(max(x.values) - min(x.values), max(x.U))
    assert f"range {span} um" in text and f"U up to {U_x} um" in text
    doc = identify_dict(result)
    assert doc["volumetric"]["value_um"] == v.value_um
    assert doc["volumetric"]["U_um"] == v.U_um


def test_the_calibration_of_the_artefact_is_reported(result):
    text = identify_text(result)
    assert "calibration of the artefact's scale, common to its readings: estimate" in text
    names = [p["name"] for p in identify_dict(result)["parameters"]]
    assert "plate.calibration.scale" in names


@pytest.mark.slow
def test_k_on_every_band_and_labelled_residual_axes(result):
    fig = curves_figure(result)
    shown = [ax for ax in fig.axes if ax.get_visible()]
    assert shown and all("k = 2" in ax.get_title() for ax in shown)
    fig = residuals_figure(result)
    for ax in fig.axes:
        assert ax.get_xlabel().startswith("residual number")
        assert ax.get_ylabel() == "residual / u (1)"
        labels = ax.get_legend_handles_labels()[1]
        assert "± 2 u (k = 2, about 95 %)" in labels


@pytest.mark.slow
def test_page_one_of_the_pdf_states_the_verdict_and_the_rounded_figure(tmp_path, result):
    from click.testing import CliRunner
    from pdf_helpers import page_texts

    from esp.cli import main
    from esp.identify.write import to_toml

    folder = tmp_path / "in"
    folder.mkdir()
    truth = in_basis_truth(np.random.default_rng(3))
    positions = plate_positions(known_machine(folder), truth)
    _write_plate(folder / "plate.csv", positions, np.random.default_rng(8), u_um=0.4)
    (folder / "machine.toml").write_text(to_toml(identify_config(2, {"plate": SPEC})))
    out = tmp_path / "out"
    run = CliRunner().invoke(main, ["identify", str(folder / "machine.toml"), "--out", str(out)])
    assert run.exit_code == 0, run.stderr
    doc = json.loads((out / "identify.json").read_text())
    first = " ".join(t for _, _, t in page_texts(out / "identify.pdf")[0])
    assert "the readings agree with the model within their stated u" in first.replace("\n", " ")
    value, U = rounded(doc["volumetric"]["value_um"], doc["volumetric"]["U_um"])
    assert f"{value} µm" in first and f"U = {U} µm (k = 2, about 95 %" in first
