"""VDI/DGQ 3441 figures against a hand computation, and the iso230-2 option."""

from __future__ import annotations

import json
import math

import pytest
from click.testing import CliRunner

from esp.cli import main
from esp.core.errors import DataError
from esp.core.profile import ErrorProfile
from esp.io.laser10 import write_laser10
from esp.iso230.vdi3441 import vdi3441

SQRT3 = math.sqrt(3.0)
# the worked example of tests/test_iso230.py (µm), targets 0, 100, 200 mm
FORWARD = [[0, 2, 4], [1, 3, 4], [2, 4, 7]]
BACKWARD = [[-2, 1, 2], [-2, 1, 2], [-2, 4, 2]]


def profile():
    return ErrorProfile("linear", [0.0, 100.0, 200.0], {"forward": FORWARD, "backward": BACKWARD})


def test_figures_by_hand():
    """By hand:
    forward means 1, 3, 5; s 1, 1, √3 (columns 0 1 2 / 2 3 4 / 4 4 7);
    backward means -2, 2, 2; s 0, √3, 0 (columns -2 -2 -2 / 1 1 4 / 2 2 2);
    U_j = |x̄↑ - x̄↓| = 3, 1, 3: U = 3, Ū = 7/3;
    Ps_j = 6 (s↑ + s↓)/2 = 3, 3 + 3√3, 3√3: Ps_max = 3 + 3√3, Ps_mean = 2 + 2√3;
    x̄_j = -0.5, 2.5, 3.5: Pa = 4;
    upper x̄ + U/2 + Ps/2 = 2.5, 4.5 + 1.5√3, 5 + 1.5√3; lower = -3.5, 0.5 - 1.5√3,
    2 - 1.5√3: P = 5 + 1.5√3 + 3.5 = 8.5 + 1.5√3."""
    r = vdi3441(profile())
    assert pytest.approx(3.0) == r.U
    assert r.U_mean == pytest.approx(7.0 / 3.0)
    assert r.Ps_j.tolist() == pytest.approx([3.0, 3.0 + 3.0 * SQRT3, 3.0 * SQRT3])
    assert r.Ps_max == pytest.approx(3.0 + 3.0 * SQRT3)
    assert r.Ps_mean == pytest.approx(2.0 + 2.0 * SQRT3)
    assert r.Pa == pytest.approx(4.0)
    assert pytest.approx(8.5 + 1.5 * SQRT3) == r.P


def test_one_direction():
    """Forward only: no reversal span; Ps = 6 s; P = max(x̄ + 3s) - min(x̄ - 3s)
    = (5 + 3√3) - (1 - 3) = 7 + 3√3."""
    r = vdi3441(ErrorProfile("linear", [0.0, 100.0, 200.0], {"forward": FORWARD}))
    assert r.U is None and r.U_j is None
    assert pytest.approx(7.0 + 3.0 * SQRT3) == r.P
    assert "U" not in r.to_dict()


def test_too_few_runs_and_wrong_kind_are_refused():
    with pytest.raises(DataError, match="at least 2 runs"):
        vdi3441(ErrorProfile("linear", [0.0, 1.0], {"forward": [[0, 1]], "backward": [[0, 1]]}))
    with pytest.raises(DataError, match="linear"):
        vdi3441(ErrorProfile("angular", [0.0, 1.0], {"forward": [[0, 1], [0, 1]]}))


def test_iso230_option(tmp_path):
    path = tmp_path / "X.rtl"
    write_laser10(
        path,
        ErrorProfile(
            "linear", [0.0, 100.0, 200.0], {"forward": FORWARD, "backward": BACKWARD}, axis="X"
        ),
    )
    result = CliRunner().invoke(main, ["iso230-2", str(path), "--vdi3441"])
    assert result.exit_code == 0, result.output
    assert "VDI/DGQ 3441" in result.stdout
    assert f"{8.5 + 1.5 * SQRT3:9.3f}" in result.stdout
    result = CliRunner().invoke(main, ["iso230-2", str(path), "--vdi3441", "--json", "-"])
    doc = json.loads(result.stdout)
    assert doc["vdi3441"]["P"] == pytest.approx(8.5 + 1.5 * SQRT3, abs=1e-6)
    assert doc["axis"]["B"] == pytest.approx(3.0)  # the ISO figures are still there
    plain = CliRunner().invoke(main, ["iso230-2", str(path), "--json", "-"])
    assert "vdi3441" not in json.loads(plain.stdout)
