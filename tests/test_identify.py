"""esp identify: identification from synthetic measurements made with the exact chain."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
from identify_helpers import (
    COMPONENTS,
    identify_config,
    in_basis_truth,
    known_machine,
    plate_positions,
    write_diagonals,
    write_plate,
)

from esp.core.errors import ConfigError, EspError, ParseError
from esp.identify.basis import Basis, bspline_values, legendre_values
from esp.identify.config import problem_from_dict
from esp.identify.run import identify, plan
from esp.identify.solve import IdentifyError


@pytest.fixture(scope="module")
def truth():
    return in_basis_truth(np.random.default_rng(5))


@pytest.fixture(scope="module")
def exact_plate(truth, tmp_path_factory):
    folder = tmp_path_factory.mktemp("plate")
    positions = plate_positions(known_machine(folder), truth)
    write_plate(folder / "plate.csv", positions)
    return folder, positions


def _problem(folder, **plate):
    spec = {"kind": "points", "file": "plate.csv", "u_um": 0.4, **plate}
    return problem_from_dict(identify_config(2, {"plate": spec}), folder, "machine.toml")


def test_legendre_recursion_against_closed_forms():
    u = np.linspace(-1, 1, 7)
    P = legendre_values(u, 3)
    np.testing.assert_allclose(P[:, 2], 1.5 * u**2 - 0.5, atol=1e-15)
    np.testing.assert_allclose(P[:, 3], 2.5 * u**3 - 1.5 * u, atol=1e-15)


def test_bsplines_are_a_partition_of_unity_and_zero_basis_at_the_start():
    u = np.linspace(-1, 1, 41)
    B = bspline_values(u, 3)
    assert B.shape == (41, 7)
    np.testing.assert_allclose(B.sum(axis=1), 1.0, atol=1e-12)
    basis = Basis("bspline", 3, "linear", (0.0, 100.0), tuple(np.linspace(0, 100, 11)))
    assert np.allclose(basis.values(np.array([0.0])), 0.0)


def test_a_straightness_basis_has_no_least_squares_line_on_its_targets():
    t = np.linspace(0.0, 800.0, 17)
    basis = Basis("legendre", 4, "straightness", (0.0, 800.0), tuple(t))
    V = basis.values(t)
    G = np.c_[np.ones_like(t), t]
    coef = np.linalg.lstsq(G, V, rcond=None)[0]
    assert np.abs(coef).max() < 1e-12
    assert basis.labels == ("P2", "P3", "P4")


@pytest.mark.slow
def test_zero_noise_recovers_the_truth_to_the_second_order_remainder(truth, exact_plate):
    folder, _ = exact_plate
    r = identify(_problem(folder), volumetric=False)
    assert r.identifiability.identifiable
    # the exact chain differs from the first-order model by products of errors (µm·µrad
    # levers): residuals of a few nm against a stated u of 0.4 µm
    assert r.chi2 < 1e-2
    for c in r.curves:
        if not c.targets_mm:
            assert abs(c.values[0] - truth[c.name]) < 0.01 * c.U[0], c.name
            continue
        t = np.asarray(c.targets_mm)
        true = truth[c.name](t)
        if ".straightness." in c.name:  # esp's straightness: without its least-squares line
            G = np.c_[np.ones_like(t), t]
            true = true - G @ np.linalg.lstsq(G, true, rcond=None)[0]
        error = np.abs(np.asarray(c.values) - true)
        # the remainder moves each value by far less than its uncertainty
        assert np.all(error < 0.01 * np.maximum(np.asarray(c.U), 1e-3)), c.name


@pytest.mark.slow
def test_the_design_matrix_is_the_engine(truth, exact_plate, tmp_path):
    """The known part plus design·c equals the engine's totals of the identified machine."""
    from esp.core.synthesis import Synthesis
    from esp.identify.model import Engine

    folder, _ = exact_plate
    problem = _problem(folder)
    r = identify(problem, volumetric=False)
    engine = Engine(problem)
    pts = np.array([[100.0, 200.0, 300.0], [800.0, 0.0, 500.0], [350.0, 600.0, 0.0]])
    c = np.asarray(r.values[: engine.size])
    mine = engine.known_um(pts) + np.einsum("nij,j->ni", engine.design(pts), c)
    syn = Synthesis.prepare(r.machine)
    theirs = syn.totals_at_um(pts, engine.tool)
    # the engine reads the written curve between its targets by linear interpolation
    np.testing.assert_allclose(mine, theirs, atol=2e-3)


def test_mcg_spheres_leave_three_one_and_no_free_directions(tmp_path):
    """Longstaff 2002, 8.04: one sphere of known centre leaves the three rotations about
    it free, two the rotation about the line through their centres, three none."""
    rng = np.random.default_rng(3)
    pivots = [(300.0, 300.0, 200.0), (600.0, 300.0, 250.0), (450.0, 500.0, 300.0)]
    expected = {1: 3, 2: 1, 3: 0}
    for n, free in expected.items():
        rows = ["sphere,X,Y,Z,cx,cy,cz,length_mm"]
        for s, c in enumerate(pivots[:n], start=1):
            d = rng.normal(size=(30, 3))
            d[:, 2] = np.abs(d[:, 2]) * 0.6
            d /= np.linalg.norm(d, axis=1)[:, None]
            for p in np.asarray(c) + 150.0 * d:
                rows.append(f"s{s},{p[0]:.6f},{p[1]:.6f},{p[2]:.6f},{c[0]},{c[1]},{c[2]},150")
        (tmp_path / "mcg.csv").write_text("\n".join(rows) + "\n")
        spec = {
            "kind": "lengths",
            "form": "mcg",
            "file": "mcg.csv",
            "u_um": 0.5,
            "pivot": "known",
            "length": "known",
            "placement": True,
        }
        d = identify_config(2, {"mcg": spec})
        d["identify"]["fix"] = [*COMPONENTS, "squareness.XY", "squareness.XZ", "squareness.YZ"]
        r = plan(problem_from_dict(d, tmp_path, "machine.toml"))
        combos = r.identifiability.combinations
        assert len(combos) == free, (n, r.identifiability.sentences())
        assert all(name.startswith("mcg.placement.") for c in combos for name, _ in c)


@pytest.mark.slow
def test_a_plate_in_one_plane_cannot_see_z_and_says_so(truth, tmp_path):
    positions = plate_positions(known_machine(tmp_path), truth)[:1]
    write_plate(tmp_path / "plate.csv", positions)
    with pytest.raises(IdentifyError) as info:
        identify(_problem(tmp_path))
    text = str(info.value)
    assert "not identifiable" in text and "`Z.linear[P1]`" in text
    assert "identify.fix" in text


def test_minimum_norm_is_an_explicit_choice_and_is_reported(truth, tmp_path):
    positions = plate_positions(known_machine(tmp_path), truth)[:2]
    write_plate(tmp_path / "plate.csv", positions)
    d = identify_config(2, {"plate": {"kind": "points", "file": "plate.csv", "u_um": 0.4}})
    d["identify"]["null"] = "minimum-norm"
    r = identify(problem_from_dict(d, tmp_path, "m.toml"), volumetric=False)
    assert not r.identifiability.identifiable
    assert any("minimum-norm choice" in w for w in r.warnings)


def test_a_fix_that_names_nothing_is_refused_with_a_suggestion(exact_plate):
    folder, _ = exact_plate
    d = identify_config(2, {"plate": {"kind": "points", "file": "plate.csv", "u_um": 0.4}})
    d["identify"]["fix"] = ["plate.p1.tq"]
    with pytest.raises(ConfigError) as info:
        identify(problem_from_dict(d, folder, "m.toml"))
    assert "identify.fix[0]" in str(info.value) and "did you mean" in str(info.value)


def test_birge_ratio_flags_readings_noisier_than_stated(truth, exact_plate, tmp_path):
    _, positions = exact_plate
    write_plate(tmp_path / "plate.csv", positions, np.random.default_rng(2), u_um=1.2)
    # states u = 0.4 µm: a Birge ratio about 3, beyond the refusal's bound (above 3 and χ²
    # above its 99.9 % quantile): refused with both figures unless accepted
    with pytest.raises(IdentifyError, match=r"Birge ratio 3\.\d+ \(above 3\), χ² = "):
        identify(_problem(tmp_path), volumetric=False)
    r = identify(replace(_problem(tmp_path), inconsistent="accept"), volumetric=False)
    assert r.birge > 3.0 and not r.consistent
    assert any("larger than the stated uncertainties" in w for w in r.warnings)


@pytest.mark.parametrize(
    ("rows", "expected"),
    [
        ("pose,X,Y,Z,x,y,z\np1,1,2,nan,0,0,0\n", "plate.csv:2: column Z: expected a number"),
        (
            "pose,X,Y,Z,x,y,z\np1,1,2,3,0,0,0\np1,5,5,5,1,0,0\np1,1,2,3,0,1,0\n",
            "plate.csv:4: duplicate position",
        ),
        ("pose,X,Y,Z,x,y,z\np1,1,2,3,0,0,0\np1,2,2,3,1,0,0\n", "plate.csv:2: pose 'p1' has 2"),
        ("pose,X,Y,x,y,z\np1,1,2,0,0,0\n", "missing Z"),
        ("pose,X,Y,Z,x,y,z\np1,1,2,3000,0,0,0\n", "outside the travel of Z"),
    ],
)
def test_bad_plate_files_name_file_and_line(tmp_path, rows, expected):
    (tmp_path / "plate.csv").write_text(rows)
    with pytest.raises(ParseError) as info:
        identify(_problem(tmp_path))
    assert expected in str(info.value)


def test_too_few_readings_are_refused(tmp_path):
    (tmp_path / "plate.csv").write_text(
        "pose,X,Y,Z,x,y,z\np1,10,10,10,0,0,0\np1,200,10,10,190,0,0\np1,10,200,10,0,190,0\n"
    )
    with pytest.raises(IdentifyError, match=r"plate.csv: too few readings: 9 residuals"):
        identify(_problem(tmp_path))


def test_a_component_the_model_does_not_use_is_refused_by_its_key(tmp_path):
    d = identify_config(2, {"plate": {"kind": "points", "file": "plate.csv", "u_um": 0.4}})
    d["axes"]["Z"]["errors"]["angular"] = {"X": {"identify": {"basis": "legendre", "degree": 2}}}
    (tmp_path / "plate.csv").write_text("pose,X,Y,Z,x,y,z\np1,1,2,3,0,0,0\n")
    with pytest.raises(EspError, match=r"axes.Z.errors.angular.X: Z.angular.X does not act"):
        identify(problem_from_dict(d, tmp_path, "m.toml"))


def test_stations_need_four(tmp_path):
    rows = ["station,X,Y,Z,reading_um"]
    rng = np.random.default_rng(1)
    for s in ("S1", "S2", "S3"):
        for p in rng.uniform(50, 450, (6, 3)):
            rows.append(f"{s},{p[0]:.3f},{p[1]:.3f},{p[2]:.3f},0")
    (tmp_path / "t.csv").write_text("\n".join(rows) + "\n")
    spec = {
        "kind": "stations",
        "file": "t.csv",
        "u_um": 0.2,
        "stations": {s: [-500.0, 0.0, 0.0] for s in ("S1", "S2", "S3")},
    }
    with pytest.raises(ParseError, match=r"t.csv: readings from 3 station\(s\).*needs 4"):
        identify(problem_from_dict(identify_config(2, {"t": spec}), tmp_path, "m.toml"))


def test_a_station_seen_from_three_places_is_refused(tmp_path):
    rows = ["station,X,Y,Z,reading_um"]
    rng = np.random.default_rng(1)
    for s, n in (("S1", 6), ("S2", 6), ("S3", 6), ("S4", 3)):
        for p in rng.uniform(50, 450, (n, 3)):
            rows.append(f"{s},{p[0]:.3f},{p[1]:.3f},{p[2]:.3f},0")
    (tmp_path / "t.csv").write_text("\n".join(rows) + "\n")
    spec = {
        "kind": "stations",
        "file": "t.csv",
        "u_um": 0.2,
        "stations": {s: [-500.0, 0.0, 0.0] for s in ("S1", "S2", "S3", "S4")},
    }
    with pytest.raises(ParseError, match=r"t.csv:20: station 'S4' is seen from 3"):
        identify(problem_from_dict(identify_config(2, {"t": spec}), tmp_path, "m.toml"))


@pytest.mark.slow
def test_coverage_of_the_expanded_uncertainty_over_many_seeds(truth, exact_plate, tmp_path):
    """With noise of the stated size, |identified - true| <= 2 u for about 95 % of the
    coefficients (JCGM 100:2008, 6.2-6.3: k = 2 for about 95 % under normality)."""
    from esp.identify.model import Engine, build_blocks
    from esp.identify.solve import evaluate, fit, layout

    folder, positions = exact_plate
    problem = _problem(folder)
    engine = Engine(problem)
    blocks = build_blocks(problem, engine)
    params = layout(engine, blocks, (), None)
    exact = fit(blocks, params, "refuse", 1e-9)
    base, _ = evaluate(blocks, params, exact.x)
    n = engine.size
    sigma = np.sqrt(np.diag(exact.covariance)[:n])
    inside = []
    for seed in range(200):
        noise = np.random.default_rng(seed).standard_normal(base.size)
        start = 0
        for b in blocks:
            b.data["shift"] = base[start : start + b.size] + noise[start : start + b.size]
            start += b.size
        f = fit(blocks, params, "refuse", 1e-9)
        inside.append(np.abs(f.x[:n] - exact.x[:n]) <= 2.0 * sigma)
    share = float(np.mean(inside))
    assert 0.93 <= share <= 0.975, share


def test_diagonals_left_out_of_the_fit_are_checked(truth, exact_plate):
    folder, _ = exact_plate
    files = write_diagonals(folder, known_machine(folder), truth)
    d = identify_config(2, {"plate": {"kind": "points", "file": "plate.csv", "u_um": 0.4}})
    d["identify"]["measurements"]["diagonals"] = {
        "kind": "lengths",
        "form": "diagonal",
        "files": files,
        "u_um": 0.5,
        "use": "check",
    }
    r = identify(problem_from_dict(d, folder, "m.toml"), volumetric=False)
    (check,) = r.checks
    assert check.use == "check" and check.readings == 22
    # the identified machine predicts the diagonals not used in the fit (zero noise: to the
    # second-order remainder)
    assert check.max_normalised < 0.05


def test_diagonals_in_the_fit_agree_with_the_plate(truth, exact_plate):
    folder, _ = exact_plate
    files = write_diagonals(folder, known_machine(folder), truth, ("PPP", "NPP", "PNP", "PPN"))
    d = identify_config(2, {"plate": {"kind": "points", "file": "plate.csv", "u_um": 0.4}})
    d["identify"]["measurements"]["diagonals"] = {
        "kind": "lengths",
        "form": "diagonal",
        "files": files,
        "u_um": 0.5,
    }
    r = identify(problem_from_dict(d, folder, "m.toml"), volumetric=False)
    assert r.chi2 < 1e-2 and r.identifiability.identifiable
    assert {s.name for s in r.sets} == {"plate", "diagonals"}


@pytest.mark.slow
def test_montecarlo_spread_matches_the_stated_uncertainty(truth, exact_plate, tmp_path):
    _, positions = exact_plate
    write_plate(tmp_path / "plate.csv", positions, np.random.default_rng(9), u_um=0.4)
    r = identify(_problem(tmp_path), montecarlo=40, seed=3, volumetric=False)
    m = r.montecarlo
    assert m is not None and m.samples == 40
    # 40 draws: the sample standard deviation is within about ±25 % of σ for every
    # coefficient (the relative standard error of s is 1/sqrt(2·39) ≈ 11 %)
    assert m.u_ratio_min > 0.6 and m.u_ratio_max < 1.45


def test_a_plan_needs_no_readings(truth, exact_plate, tmp_path):
    _, positions = exact_plate
    rows = ["pose,X,Y,Z"]
    for label, P, _ in positions:
        rows += [f"{label},{p[0]:.4f},{p[1]:.4f},{p[2]:.4f}" for p in P]
    (tmp_path / "plate.csv").write_text("\n".join(rows) + "\n")
    r = plan(_problem(tmp_path))
    assert r.plan and r.identifiability.identifiable
    assert r.expected_u_um is not None and r.expected_u_um > 0
    # the plan's expected U equals the U of the fit made from the same positions
    folder, _ = exact_plate
    fitted = identify(_problem(folder), volumetric=False)
    for a, b in zip(r.curves, fitted.curves, strict=True):
        np.testing.assert_allclose(a.U, b.U, rtol=1e-3)


@pytest.mark.slow
@pytest.mark.parametrize("configuration", ["wBMTt", "BwMTt", "BMwTt", "BMTwt"])
def test_stations_identify_every_stacking_from_the_exact_chain(configuration, tmp_path):
    """A tracking interferometer at 5 stations, positions and dead paths unknown, sees
    every component that acts at the MCP, on all four stackings; zero noise recovers the
    truth to the second-order remainder."""
    from esp.config import machine_from_dict
    from esp.core.models.bind import bind_model
    from esp.identify.simulate import actual_positions

    travel = {"X": (0.0, 800.0), "Y": (0.0, 600.0), "Z": (0.0, 500.0)}
    base = {
        "machine": {
            "name": configuration,
            "configuration": configuration,
            "axes": {"bottom": "X", "middle": "Y", "top": "Z"},
        },
        "axes": {a: {"travel": list(travel[a]), "step": 100} for a in "XYZ"},
    }
    machine = machine_from_dict(base, tmp_path)
    used = sorted({str(t.component) for t in bind_model(machine).terms})
    rng = np.random.default_rng(1)
    truth: dict = {}
    for name in used:
        if name.startswith("squareness"):
            truth[name] = float(rng.normal(0, 3))
            continue
        a, kind = name.split(".")[:2]
        lo, hi = travel[a]
        first = 2 if kind == "straightness" else 1
        c = rng.normal(0, 2, 3 - first)

        def f(x, c=c, lo=lo, hi=hi, first=first):
            u = (2 * np.asarray(x, dtype=float) - lo - hi) / (hi - lo)
            v = legendre_values(u, 2)[:, first:] @ c
            if first == 1:
                v = v - legendre_values(np.array([-1.0]), 2)[:, first:] @ c
            return v

        truth[name] = f
    P = np.column_stack([rng.uniform(*travel[a], 150) for a in "XYZ"])
    Q = actual_positions(machine, truth, P)
    stations = {
        "S1": (-300.0, -300.0, 200.0),
        "S2": (1100.0, -250.0, 350.0),
        "S3": (1050.0, 800.0, 150.0),
        "S4": (-250.0, 750.0, 450.0),
        "S5": (400.0, 300.0, 900.0),
    }
    rows = ["station,X,Y,Z,reading_um"]
    for s, S in stations.items():
        d = np.linalg.norm(Q - np.array(S), axis=1)
        rows += [
            f"{s},{p[0]:.9f},{p[1]:.9f},{p[2]:.9f},{r:.6f}"
            for p, r in zip(P, 1000 * (d - d.min()), strict=True)
        ]
    (tmp_path / "t.csv").write_text("\n".join(rows) + "\n")
    config = {k: v for k, v in base.items()}
    spec = {"identify": {"basis": "legendre", "degree": 2}}
    for name in used:
        parts = name.split(".")
        if parts[0] == "squareness":
            config.setdefault("squareness", {})[parts[1]] = {"identify": True}
            continue
        errors = config["axes"][parts[0]].setdefault("errors", {})
        if parts[1] == "linear":
            errors["linear"] = dict(spec)
        else:
            errors.setdefault(parts[1], {})[parts[2]] = dict(spec)
    approx = {s: [v + 5.0 for v in S] for s, S in stations.items()}
    config["identify"] = {
        "measurements": {
            "t": {"kind": "stations", "file": "t.csv", "u_um": 0.2, "stations": approx}
        }
    }
    r = identify(problem_from_dict(config, tmp_path, "m.toml"), volumetric=False)
    assert r.identifiability.identifiable and r.chi2 < 1e-4
    # the stations themselves are found: S1 within a micrometre of where it is
    i = r.names.index("t.S1.x")
    assert abs(r.values[i] - stations["S1"][0]) < 1e-3
    for c in r.curves:
        if not c.targets_mm:
            assert abs(c.values[0] - truth[c.name]) < 0.01 * c.U[0] + 1e-4, c.name
            continue
        t = np.asarray(c.targets_mm)
        true = truth[c.name](t)
        if ".straightness." in c.name:
            G = np.c_[np.ones_like(t), t]
            true = true - G @ np.linalg.lstsq(G, true, rcond=None)[0]
        assert np.max(np.abs(np.asarray(c.values) - true)) < 0.01 * max(c.U) + 1e-4, c.name
