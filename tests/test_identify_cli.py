"""esp identify on the command line: outputs, the round trip through esp analyse, the
refusals as one line and exit code 2."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from identify_helpers import (
    identify_config,
    in_basis_truth,
    known_machine,
    plate_positions,
    write_plate,
)

ROOT = Path(__file__).resolve().parent.parent
EXAMPLES = ROOT / "data/examples/identify"


def _esp(*args, cwd=None):
    return subprocess.run(
        [sys.executable, "-m", "esp", *map(str, args)],
        capture_output=True,
        text=True,
        cwd=cwd,
        env={"PYTHONPATH": str(ROOT), "PATH": "/usr/bin:/bin"},
    )


def _write_config(folder: Path, data: dict) -> Path:
    from esp.identify.write import to_toml

    path = folder / "machine.toml"
    path.write_text(to_toml(data), encoding="utf-8")
    return path


@pytest.fixture(scope="module")
def noisy(tmp_path_factory):
    folder = tmp_path_factory.mktemp("noisy")
    truth = in_basis_truth(np.random.default_rng(11))
    positions = plate_positions(known_machine(folder), truth)
    write_plate(folder / "plate.csv", positions, np.random.default_rng(4), u_um=0.4)
    spec = {"kind": "points", "file": "plate.csv", "u_um": 0.4}
    return folder, truth, _write_config(folder, identify_config(2, {"plate": spec}))


@pytest.mark.slow
def test_identify_writes_a_machine_that_analyse_reads_and_the_truth_is_within_u(noisy, tmp_path):
    import esp
    from esp.identify.config import load_problem
    from esp.identify.run import Curve, identified_machine

    folder, truth, config = noisy
    out = tmp_path / "out"
    run = _esp("identify", config, "--out", out, "--json", tmp_path / "r.json")
    assert run.returncode == 0, run.stderr
    doc = json.loads((tmp_path / "r.json").read_text())
    assert doc["schema"] == "esp.identify/1"
    assert doc["identifiability"]["rank"] == doc["identifiability"]["parameters"]
    written = ("machine.toml", "X-linear.csv", "X-linear-U.csv", "identify.png", "identify.pdf")
    for name in (*written, "residuals.png"):
        assert (out / name).is_file(), name
    analysed = esp.analyse(esp.load_machine(out / "machine.toml"))
    value = analysed.cases[analysed.worst].volumetric.value_um
    assert value == pytest.approx(doc["volumetric"]["value_um"], abs=1e-6)
    # the truth through the same engine
    problem = load_problem(config)
    curves = []
    for u in problem.unknowns:
        f = truth[str(u.name)]
        if u.basis is None:
            curves.append(Curve(str(u.name), u.key, "um/m", (), (f,), (0.0,), ()))
            continue
        t = np.asarray(u.basis.targets_mm)
        curves.append(Curve(str(u.name), u.key, "", tuple(t), tuple(f(t)), (), ()))
    true = esp.analyse(identified_machine(problem, curves))
    true_value = true.cases[true.worst].volumetric.value_um
    assert abs(value - true_value) <= doc["volumetric"]["U_um"]


@pytest.mark.slow
def test_identify_json_to_stdout_and_plan(noisy):
    _, _, config = noisy
    run = _esp("identify", config, "--json", "-")
    assert run.returncode == 0, run.stderr
    assert json.loads(run.stdout)["fit"]["consistent"] in (True, False)
    plan = _esp("identify", config, "--plan")
    assert plan.returncode == 0, plan.stderr
    assert "esp identify (plan)" in plan.stdout and "U up to" in plan.stdout


@pytest.mark.slow
def test_an_unidentifiable_plate_is_refused_in_one_line(tmp_path):
    truth = in_basis_truth(np.random.default_rng(1))
    write_plate(tmp_path / "plate.csv", plate_positions(known_machine(tmp_path), truth)[:1])
    spec = {"kind": "points", "file": "plate.csv", "u_um": 0.4}
    config = _write_config(tmp_path, identify_config(2, {"plate": spec}))
    run = _esp("identify", config)
    assert run.returncode == 2
    lines = run.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("esp: error: not identifiable:")
    assert "Traceback" not in run.stderr


@pytest.mark.slow
def test_analyse_refuses_a_file_to_identify_naming_the_command():
    run = _esp("analyse", EXAMPLES / "cmm-ballplate/machine.toml")
    assert run.returncode == 2 and "run 'esp identify'" in run.stderr


@pytest.mark.slow
@pytest.mark.parametrize(
    "example", ["cmm-ballplate", "cmm-starprobe", "tool-ballbar", "tool-tracker"]
)
def test_the_examples_identify_every_component_within_reason(example):
    from esp.identify.config import load_problem
    from esp.identify.run import identify

    r = identify(load_problem(EXAMPLES / example / "machine.toml"), volumetric=False)
    assert r.identifiability.identifiable
    assert 0.8 < r.birge < 1.2
    truth: dict = {}
    for line in (EXAMPLES / example / "truth.csv").read_text().splitlines()[2:]:
        name, x, v = line.split(",")
        truth.setdefault(name, []).append((float(x) if x else None, float(v)))
    for c in r.curves:
        pts = truth[c.name]
        if not c.targets_mm:
            assert abs(c.values[0] - pts[0][1]) < 3 * c.U[0] + 1.0, c.name
            continue
        x = np.array([p[0] for p in pts])
        est = np.interp(x, c.targets_mm, c.values)
        true = np.array([p[1] for p in pts])
        if ".straightness." in c.name:
            G = np.c_[np.ones_like(x), x]
            est = est - G @ np.linalg.lstsq(G, est, rcond=None)[0]
        # the truth is outside the cubic basis: a bias of a fraction of a micrometre
        assert np.max(np.abs(est - true)) < 2 * max(c.U) + 1.0, c.name


@pytest.mark.slow
def test_esp_diagonals_of_the_written_machine_predicts_diagonals_left_out_of_the_fit(
    noisy, tmp_path
):
    """identify --out DIR, then ``esp diagonals DIR/machine.toml --measured ...`` against
    ISO 230-6 diagonals measured on the true machine (exact chain, noise 0.3 µm) that
    the fit never saw. What esp diagonals predicts from the written files is the
    identification's own prediction, and the measured diagonals differ from it by no more
    than their uncertainty: that of the prediction from the full covariance of the
    identified coefficients (the written machine.toml carries each component's U alone,
    which esp diagonals combines as independent: docs/identify.md, "Uncertainty") and
    that of the readings (each relative to the diagonal's start: sqrt(2) · 0.3 µm)."""
    from identify_helpers import base, write_diagonals

    from esp.diagonals.model import body_diagonals
    from esp.identify.config import load_problem
    from esp.identify.model import Engine, build_blocks
    from esp.identify.solve import fit, layout
    from esp.identify.write import to_toml

    folder, truth, config = noisy
    out = tmp_path / "identified"
    run = _esp("identify", config, "--out", out, "--quiet")
    assert run.returncode == 0, run.stderr
    names = ("PPP", "NPP", "PNP", "PPN")
    machine = known_machine(folder)
    files = write_diagonals(tmp_path, machine, truth, names, 0.3, np.random.default_rng(8))
    measured = [a for n, f in files.items() for a in ("--measured", f"{n}={tmp_path / f}")]

    def diagonals(toml):
        check = _esp("diagonals", toml, *measured, "--measurement-u", 0.85, "--json", "-")
        assert check.returncode == 0, check.stderr
        return json.loads(check.stdout)["checks"]

    checks = diagonals(out / "machine.toml")
    assert [c["name"] for c in checks] == list(names)
    # the identification of the same data, in this process: its prediction and covariance
    problem = load_problem(config)
    engine = Engine(problem)
    blocks = build_blocks(problem, engine)
    fitted = fit(blocks, layout(engine, blocks, (), None), "refuse", problem.rank_tolerance)
    n = engine.size
    C = fitted.covariance[:n, :n]
    by_name = {d.name: d for d in body_diagonals(machine)}
    for c in checks:
        d = by_name[c["name"]]
        P = d.points(np.asarray(c["s_mm"]))
        g = np.einsum("nij,i->nj", engine.design(P), d.direction)
        g = g - g[0]  # relative to the diagonal's start
        np.testing.assert_allclose(c["predicted_um"], g @ fitted.x[:n], atol=0.01)
        u = np.sqrt(np.einsum("nj,jk,nk->n", g, C, g) + 2 * 0.3**2)[1:]
        z = np.abs(np.asarray(c["difference_um"])[1:]) / u
        # the diagonals move by several micrometres; the prediction meets them to within
        # three standard uncertainties at every target (k = 3: about 99.7 % each)
        assert max(abs(v) for v in c["measured_um"]) > 3.0
        assert z.max() <= 3.0, (c["name"], z.max())
    # a machine without the identified errors misses them: the check can fail
    flat = tmp_path / "flat.toml"
    flat.write_text(to_toml(base()), encoding="utf-8")
    assert not all(c["explained"] for c in diagonals(flat))
