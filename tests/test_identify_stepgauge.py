"""Step-gauge lengths (``kind = "lengths"``, ``form = "stepgauge"``) on a simulated CMM:
the faces of gauges along the axes and the face diagonals, read through the exact 4x4
chain; the linear errors and squareness identified from the lengths alone."""

from __future__ import annotations

import numpy as np
import pytest
from identify_helpers import TRAVEL, base, known_machine

from esp.core.errors import ConfigError, ParseError
from esp.identify.config import problem_from_dict
from esp.identify.run import identify
from esp.identify.simulate import commanded_for
from esp.identify.solve import IdentifyError

TRUTH = {
    # linear errors in the fitted basis (Legendre degree 2, zero at the low end), µm
    "X.linear": lambda x: 4.0 * (x / 800.0) - 3.0 * (x / 800.0) ** 2,
    "Y.linear": lambda y: -2.5 * (y / 600.0) + 1.5 * (y / 600.0) ** 2,
    "Z.linear": lambda z: 3.0 * (z / 500.0) ** 2,
    "squareness.XY": 6.0,
    "squareness.XZ": -4.0,
    "squareness.YZ": 5.0,
}
#: gauge name -> (start of its reference face, direction): along X, Y, Z and one face
#: diagonal of each plane (the diagonals see the squareness)
GAUGES = {
    "gx": ((50.0, 300.0, 250.0), (1.0, 0.0, 0.0)),
    "gy": ((400.0, 50.0, 250.0), (0.0, 1.0, 0.0)),
    "gz": ((400.0, 300.0, 30.0), (0.0, 0.0, 1.0)),
    "gxy": ((50.0, 50.0, 250.0), (0.8, 0.6, 0.0)),
    "gxz": ((50.0, 300.0, 30.0), (0.8, 0.0, 0.6)),
    "gyz": ((400.0, 50.0, 30.0), (0.0, 0.6, 0.8)),
}
PITCH = 40.0
FACES = 11


def _write(folder, gauges=GAUGES, rng=None, u_um=0.3, name="steps.csv"):
    machine = known_machine(folder)
    rows = ["gauge,X1,Y1,Z1,X2,Y2,Z2,length_mm,deviation_um"]
    for g, (start, direction) in gauges.items():
        W = np.asarray(start) + np.outer(np.arange(FACES) * PITCH, direction)
        P = commanded_for(machine, TRUTH, W)  # what the machine reads at each face
        for i in range(1, FACES):
            L = float(np.linalg.norm(W[i] - W[0]))
            dev = 1000.0 * (np.linalg.norm(P[i] - P[0]) - L)
            if rng is not None:
                dev += rng.normal(0.0, u_um)
            a, b = W[0], W[i]  # nominal positions: the deviation carries the reading
            rows.append(
                f"{g},{a[0]:g},{a[1]:g},{a[2]:g},{b[0]:g},{b[1]:g},{b[2]:g},{L:.6f},{dev:.6f}"
            )
    (folder / name).write_text("\n".join(rows) + "\n", encoding="utf-8")


def _config(u_um=0.3, **extra) -> dict:
    d = base()
    spec = {"identify": {"basis": "legendre", "degree": 2}}
    for a in "XYZ":
        d["axes"][a]["errors"] = {"linear": dict(spec)}
    d["squareness"] = {p: {"identify": True} for p in ("XY", "XZ", "YZ")}
    steps = {"kind": "lengths", "form": "stepgauge", "file": "steps.csv", "u_um": u_um, **extra}
    d["identify"] = {"measurements": {"steps": steps}}
    return d


def _curve_errors(result):
    out = {}
    for c in result.curves:
        if not c.targets_mm:
            out[c.name] = (abs(c.values[0] - TRUTH[c.name]), c.U[0])
            continue
        t = np.asarray(c.targets_mm)
        err = np.abs(np.asarray(c.values) - TRUTH[c.name](t))
        out[c.name] = (float(err.max()), float(np.max(c.U)))
    return out


def test_zero_noise_step_gauges_recover_the_linear_errors_and_squareness(tmp_path):
    assert TRAVEL["X"] == (0.0, 800.0)
    _write(tmp_path)
    r = identify(problem_from_dict(_config(), tmp_path, "m.toml"), volumetric=False)
    assert r.identifiability.identifiable
    assert r.sets[0].kind == "lengths (stepgauge)" and r.sets[0].readings == 60
    # no nuisance parameter: 3 x 2 coefficients and 3 squareness values
    assert r.identifiability.parameters == 9
    assert r.chi2 < 1e-3  # the exact chain against the first-order model: nm
    for name, (err, U) in _curve_errors(r).items():
        assert err < 2e-3 and err < 0.05 * U, (name, err, U)


def test_noisy_step_gauges_agree_with_the_truth_within_U(tmp_path):
    _write(tmp_path, rng=np.random.default_rng(4))
    r = identify(problem_from_dict(_config(), tmp_path, "m.toml"), volumetric=False)
    assert 0.6 < r.birge < 1.4
    errors = _curve_errors(r)
    assert all(err <= U for err, U in errors.values()), errors
    # a wrong sign in the model would put the squareness off by twice its size
    assert errors["squareness.XY"][0] < 1.0


def test_gauges_along_x_alone_cannot_see_y_or_z(tmp_path):
    _write(tmp_path, {"gx": GAUGES["gx"]})
    # the whole component, named with the key it was asked at
    match = r"`Y\.linear` \(axes\.Y\.errors\.linear\) is not seen by any reading"
    with pytest.raises(IdentifyError, match=match):
        identify(problem_from_dict(_config(), tmp_path, "m.toml"), volumetric=False)


def test_a_length_off_the_gauge_line_names_its_line(tmp_path):
    rows = [
        "gauge,X1,Y1,Z1,X2,Y2,Z2,length_mm,deviation_um",
        "g,10,10,10,50,10,10,40,0.1",
        "g,10,10,10,90,12,10,80,0.1",
    ]
    (tmp_path / "steps.csv").write_text("\n".join(rows) + "\n")
    with pytest.raises(ParseError, match=r"steps\.csv:3: gauge 'g': this length is not along"):
        identify(problem_from_dict(_config(), tmp_path, "m.toml"), volumetric=False)


def test_a_ballbar_option_on_a_step_gauge_is_refused_by_its_key(tmp_path):
    _write(tmp_path, {"gx": GAUGES["gx"]})
    with pytest.raises(ConfigError, match=r"identify\.measurements\.steps\.centre"):
        problem_from_dict(_config(centre="known"), tmp_path, "m.toml")
