"""The calibration of a measurement set's artefact, common to all its readings
(``calibration = { u_um, u_ppm }``, docs/identify.md "Calibration of the artefact"): one
correlated contribution, the rank-one term u_c² s sᵀ of the readings' covariance."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
from identify_helpers import POSES, base, known_machine, plate_positions, write_plate

from esp.core.errors import ConfigError
from esp.identify.config import problem_from_dict
from esp.identify.model import Engine, build_blocks
from esp.identify.simulate import actual_positions, commanded_for
from esp.identify.solve import evaluate, fit, layout

R_MM = 150.0
U_UM = 0.3
#: the circles: (plane, the level of the third axis, the centre along the plane's axes)
CIRCLES = (
    ("XY", 100.0, (250.0, 300.0)),
    ("XY", 400.0, (550.0, 300.0)),
    ("XZ", 200.0, (250.0, 250.0)),
    ("XZ", 400.0, (550.0, 250.0)),
    ("YZ", 200.0, (200.0, 250.0)),
    ("YZ", 600.0, (400.0, 250.0)),
)
LINEAR = ("X.linear", "Y.linear", "Z.linear")


def _truth() -> dict:
    """Linear errors in the basis (degree 2) and squareness values."""
    travel = {"X": 800.0, "Y": 600.0, "Z": 500.0}

    def curve(a: str, c1: float, c2: float):
        return lambda x: c1 * np.asarray(x) / travel[a] + c2 * (np.asarray(x) / travel[a]) ** 2

    return {
        "X.linear": curve("X", -8.0, 3.0),
        "Y.linear": curve("Y", 5.0, -2.0),
        "Z.linear": curve("Z", 4.0, 1.0),
        "squareness.XY": 4.0,
        "squareness.XZ": -3.0,
        "squareness.YZ": 2.5,
    }


def _write_ballbar(folder, machine, truth, bar_error_um: float = 0.0) -> None:
    """Circles of radius 150 mm through the exact chain, read with a bar
    ``bar_error_um`` longer than its stated length (its calibration error)."""
    rows = ["circle,X,Y,Z,cx,cy,cz,length_mm,deviation_um"]
    theta = np.radians(np.arange(0.0, 360.0, 15.0))
    for n, (plane, level, (ca, cb)) in enumerate(CIRCLES, start=1):
        a, b = plane
        c_axis = next(x for x in "XYZ" if x not in plane)
        centre = {a: ca, b: cb, c_axis: level}
        C = np.array([centre[x] for x in "XYZ"])
        Ct = actual_positions(machine, truth, C[None, :])[0]
        P = np.tile(C, (theta.size, 1))
        P[:, "XYZ".index(a)] += R_MM * np.cos(theta)
        P[:, "XYZ".index(b)] += R_MM * np.sin(theta)
        L = np.linalg.norm(actual_positions(machine, truth, P) - Ct, axis=1)
        dev = 1000.0 * (L - R_MM) - bar_error_um
        rows += [
            f"c{n},{p[0]:.6f},{p[1]:.6f},{p[2]:.6f},{C[0]:g},{C[1]:g},{C[2]:g},{R_MM:g},{d:.6f}"
            for p, d in zip(P, dev, strict=True)
        ]
    (folder / "ballbar.csv").write_text("\n".join(rows) + "\n", encoding="utf-8")


def _config(measurements: dict, fix: tuple[str, ...] = ()) -> dict:
    d = base()
    spec = {"identify": {"basis": "legendre", "degree": 2}}
    for name in LINEAR:
        d["axes"][name[0]]["errors"] = {"linear": dict(spec)}
    d["squareness"] = {p: {"identify": True} for p in ("XY", "XZ", "YZ")}
    d["identify"] = {"measurements": measurements, "fix": list(fix)}
    return d


def _ballbar_set(calibration: dict | None) -> dict:
    spec = {
        "kind": "lengths",
        "form": "ballbar",
        "file": "ballbar.csv",
        "u_um": U_UM,
        "centre": "unknown",
        "radius": "known",
    }
    if calibration is not None:
        spec["calibration"] = calibration
    return spec


@pytest.fixture(scope="module")
def ballbar(tmp_path_factory):
    folder = tmp_path_factory.mktemp("calibration")
    truth = _truth()
    _write_ballbar(folder, known_machine(folder), truth)
    return folder, truth


def _setup(folder, calibration, fix=()):
    problem = problem_from_dict(
        _config({"bar": _ballbar_set(calibration)}, fix), folder, "machine.toml"
    )
    engine = Engine(problem)
    blocks = build_blocks(problem, engine)
    return problem, engine, blocks, layout(engine, blocks, problem.fix, None)


def test_the_common_error_is_generalised_least_squares_with_the_rank_one_term(ballbar):
    """The covariance of the coefficients with the calibration as a parameter with a prior
    equals that of generalised least squares with the readings' full covariance
    Σ = diag(u²) + u_c² s sᵀ (s = -1 per µm of bar length; Aitken 1935)."""
    folder, _ = ballbar
    u_c = 0.5
    problem, engine, blocks, params = _setup(folder, {"u_um": u_c})
    f = fit(blocks, params, "refuse", problem.rank_tolerance)
    # the same readings without the calibration, at the same solution
    _, _, blocks0, params0 = _setup(folder, None)
    x0 = f.x[:-1]  # the calibration is the set's last parameter
    _, J = evaluate(blocks0, params0, x0)
    Jr = J * U_UM  # unweighted: µm per parameter
    m = Jr.shape[0]
    Sigma = np.diag(np.full(m, U_UM**2)) + u_c**2 * np.ones((m, m))
    C_gls = np.linalg.inv(Jr.T @ np.linalg.solve(Sigma, Jr))
    n = engine.size
    assert np.allclose(f.covariance[:n, :n], C_gls[:n, :n], rtol=1e-6, atol=1e-12)
    # and it is not the covariance of independent readings
    C_ind = np.linalg.inv(Jr.T @ Jr / U_UM**2)
    assert not np.allclose(f.covariance[:n, :n], C_ind[:n, :n], rtol=0.05)
    # χ² counts the prior as one more residual and the calibration as one more parameter
    assert f.dof == m - f.identifiability.rank + 1


def test_a_bar_length_error_is_a_scale_of_the_axes_at_the_radius(ballbar):
    """A common length error δ of the bar is indistinguishable from the scale δ/R of every
    axis, so the linear errors' U at the end of an axis' travel of length T grows by about
    k u_c T / R (here 2 · 0.5 µm · 800 mm / 150 mm = 5.3 µm for X) from 1 µm or less,
    root-sum-square."""
    from esp.identify.run import _curves

    folder, _ = ballbar
    out = {}
    for u_c in (None, 0.5):
        problem, engine, blocks, params = _setup(folder, None if u_c is None else {"u_um": u_c})
        f = fit(blocks, params, "refuse", problem.rank_tolerance)
        out[u_c] = {c.name: max(c.U) for c in _curves(engine, f.x, f.covariance, 2.0)}
    for axis, travel in (("X", 800.0), ("Y", 600.0), ("Z", 500.0)):
        scale_U = 2 * 0.5 * travel / R_MM
        alone = out[None][f"{axis}.linear"]
        assert alone < 0.35 * scale_U
        # the scale adds to the noise's part (nearly independent of it)
        expected = np.hypot(scale_U, alone)
        assert 0.95 * expected <= out[0.5][f"{axis}.linear"] <= 1.05 * expected, (axis, out)
    # the squareness is not a scale: unchanged
    assert out[0.5]["squareness.XY"] == pytest.approx(out[None]["squareness.XY"], rel=1e-6)


def test_the_fitted_calibration_error_has_the_sign_of_the_bar(tmp_path):
    """A bar 2 µm longer than stated, the linear errors known (fixed at the truth's zero):
    the fitted length error is +2 µm, within its uncertainty."""
    truth = _truth()
    for name in LINEAR:
        truth[name] = lambda x: 0.0 * np.asarray(x)
    _write_ballbar(tmp_path, known_machine(tmp_path), truth, bar_error_um=2.0)
    problem, _, blocks, params = _setup(tmp_path, {"u_um": 10.0}, fix=LINEAR)
    f = fit(blocks, params, "refuse", problem.rank_tolerance)
    i = params.names.index("bar.calibration.length")
    assert abs(f.x[i] - 2.0) < 0.01, f.x[i]
    assert f.birge < 0.05  # no noise: the common error explains the readings


def test_a_plate_scale_error_has_the_sign_of_the_plate(tmp_path):
    """A plate 5 µm/m longer than its certificate states (its balls further apart), the
    linear errors fixed: the fitted scale is +5 µm/m."""
    truth = _truth()
    for name in LINEAR:
        truth[name] = lambda x: 0.0 * np.asarray(x)
    machine = known_machine(tmp_path)
    stretched = []
    # the balls really are at (1 + 5e-6) B: the certificate's B is short by that
    for label, _, B in plate_positions(machine, truth):
        R, t = POSES[int(label[1:]) - 1]
        W = (1 + 5e-6) * B @ np.asarray(R).T + np.asarray(t, dtype=float)
        stretched.append((label, commanded_for(machine, truth, W), B))
    write_plate(tmp_path / "plate.csv", stretched)
    spec = {"kind": "points", "file": "plate.csv", "u_um": 0.4, "calibration": {"u_ppm": 50.0}}
    problem = problem_from_dict(_config({"plate": spec}, LINEAR), tmp_path, "machine.toml")
    engine = Engine(problem)
    blocks = build_blocks(problem, engine)
    params = layout(engine, blocks, problem.fix, None)
    f = fit(blocks, params, "refuse", problem.rank_tolerance)
    i = params.names.index("plate.calibration.scale")
    assert abs(f.x[i] - 5.0) < 0.05, f.x[i]


@pytest.mark.parametrize(
    ("spec", "key", "expected"),
    [
        (
            {"kind": "points", "file": "plate.csv", "u_um": 0.4, "calibration": {"u_um": 1}},
            "identify.measurements.s.calibration.u_um",
            "a placement",
        ),
        (
            {
                "kind": "points",
                "file": "plate.csv",
                "u_um": 0.4,
                "scale": True,
                "calibration": {"u_ppm": 1},
            },
            "identify.measurements.s.calibration.u_ppm",
            "scale = true",
        ),
        (
            {**_ballbar_set({"u_um": 0.5}), "file": "plate.csv", "radius": "unknown"},
            "identify.measurements.s.calibration.u_um",
            "the length is fitted",
        ),
        (
            {"kind": "points", "file": "plate.csv", "u_um": 0.4, "calibration": {"u_ppm": -1}},
            "identify.measurements.s.calibration.u_ppm",
            "found -1",
        ),
        (
            {"kind": "points", "file": "plate.csv", "u_um": 0.4, "calibration": {"u": 1}},
            "identify.measurements.s.calibration",
            "u",
        ),
        (
            {"kind": "points", "file": "plate.csv", "u_um": 0.4, "calibration": 0.5},
            "identify.measurements.s.calibration",
            "{ u_um = 0.5 }",
        ),
    ],
)
def test_a_calibration_that_adds_nothing_or_is_malformed_is_refused_by_its_key(
    tmp_path, spec, key, expected
):
    (tmp_path / "plate.csv").write_text("pose,X,Y,Z,x,y,z\n", encoding="utf-8")
    with pytest.raises(ConfigError) as info:
        problem_from_dict(_config({"s": spec}), tmp_path, "machine.toml")
    assert info.value.key.startswith(key), info.value.key
    assert expected in str(info.value)


def _coverage(blocks, params, problem, engine, truth, draws, common: bool) -> float:
    """The share of the linear errors' values (and squareness) within ± U over ``draws``
    trials of normal noise of u per reading plus, when ``common``, one bar length error
    of u_c per trial drawn into the readings (a bar δ longer reads every deviation δ
    shorter), as the artefact's calibration would be."""
    from esp.identify.run import _curves

    rng = np.random.default_rng(7)
    u_c = 0.5
    start = replace(params, x0=params.x0.copy())
    inside = []
    for _ in range(draws):
        for b in blocks:
            m = b.u_um.size
            reading = rng.standard_normal(m) * b.u_um
            if common:
                reading = reading - rng.normal(0.0, u_c)  # once per set per trial
            shift = np.zeros(b.size)
            shift[:m] = reading / b.u_um  # r = model - reading
            b.data["shift"] = -shift
        try:
            f = fit(blocks, start, "refuse", problem.rank_tolerance)
        finally:
            for b in blocks:
                b.data.pop("shift", None)
        for c in _curves(engine, f.x, f.covariance, 2.0):
            if not c.targets_mm:
                inside.append(abs(c.values[0] - truth[c.name]) <= c.U[0])
                continue
            U = np.asarray(c.U)
            keep = U > 1e-9
            true = truth[c.name](np.asarray(c.targets_mm))
            inside.extend(np.abs(np.asarray(c.values) - true)[keep] <= U[keep])
    return float(np.mean(inside))


@pytest.mark.slow
def test_coverage_with_the_common_error_drawn_once_per_set_and_trial(ballbar):
    """With the bar's calibration error drawn into the readings once per trial, the stated
    U covers the truth at about 95 % when the set declares it; the same readings fitted
    as if their errors were independent cover far less (the test can fail)."""
    folder, truth = ballbar
    problem, engine, blocks, params = _setup(folder, {"u_um": 0.5})
    share = _coverage(blocks, params, problem, engine, truth, 200, common=True)
    assert 0.93 <= share <= 0.975, share
    problem0, engine0, blocks0, params0 = _setup(folder, None)
    ignored = _coverage(blocks0, params0, problem0, engine0, truth, 200, common=True)
    assert ignored < 0.8, ignored


def test_the_examples_state_their_artefacts_calibration():
    """Every shipped example's set declares its artefact's calibration."""
    from pathlib import Path

    from esp.identify.config import load_problem

    root = Path(__file__).resolve().parent.parent / "data/examples/identify"
    for folder in sorted(p for p in root.iterdir() if (p / "machine.toml").is_file()):
        problem = load_problem(folder / "machine.toml")
        for spec in problem.measurements:
            if spec.kind == "sphere" and problem.machine.head is not None:
                # the probe turns with the head: its offset's error is the head's (its
                # tool length), an error of the head chain, not a common calibration
                continue
            assert spec.calibration, (folder.name, spec.name)


def test_the_cli_refuses_a_calibration_of_a_fitted_length_in_one_line(tmp_path):
    """Through the command line: exit code 2, one line naming the file, the key, what was
    expected and what to do."""
    import shutil
    from pathlib import Path

    from click.testing import CliRunner

    from esp.cli import main

    example = Path(__file__).resolve().parent.parent / "data/examples/identify/tool-ballbar"
    for f in example.iterdir():
        shutil.copy(f, tmp_path / f.name)
    path = tmp_path / "machine.toml"
    text = path.read_text(encoding="utf-8")
    assert 'radius = "known"' in text and "calibration = { u_um" in text
    path.write_text(text.replace('radius = "known"', 'radius = "unknown"'), encoding="utf-8")
    result = CliRunner().invoke(main, ["identify", str(path)])
    assert result.exit_code == 2
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1, result.stderr
    assert lines[0].startswith("esp: error: ")
    assert "identify.measurements.circles.calibration.u_um" in lines[0]
    assert "the length is fitted" in lines[0] and "Traceback" not in result.stderr
