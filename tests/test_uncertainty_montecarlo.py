"""The Monte Carlo distribution of the volumetric accuracy (JCGM 101:2008): on the analysis
grid, exact per draw with the tile bounds (against an evaluation of every point), float32 to
the printed digit, the same values whatever the number of samples, the passes and the shape
of the matrix products, per-component coverage factors and distributions, and the limits
refused before any work."""

from __future__ import annotations

import math
import os
import subprocess
import sys
import time
from dataclasses import replace

import numpy as np
import pytest

from esp.config import machine_from_dict
from esp.core.analysis import analyse
from esp.core.errors import ConfigError
from esp.core.grid import fold
from esp.core.machine import AXIS_NAMES
from esp.core.synthesis import Synthesis, datum_point, tool_cases
from esp.core.uncertainty import montecarlo
from esp.core.uncertainty.montecarlo import (
    MONTECARLO_MAX_WORK,
    montecarlo_errors,
    montecarlo_memory_bytes,
    montecarlo_volumetric,
)
from esp.core.uncertainty.spec import uncertainty_machine

AXES3 = ("X", "Y", "Z")


def gantry(step=100.0, travel=1000.0, samples=300, seed=4, **analysis) -> dict:
    """A 1 m wBMTt gantry with a few measured errors and the study's uncertainties."""
    comps = {}
    for a in AXES3:
        comps[f"{a}.linear"] = {"U": {"points": [[0, 0.0], [travel, 8.0 * travel / 1000]]}}
        for b in AXES3:
            if b != a:
                comps[f"{a}.straightness.{b}"] = {"U": 4.0}
            comps[f"{a}.angular.{b}"] = {"U": 4.0, "distribution": "rectangular"}
    for p in ("XY", "XZ", "YZ"):
        comps[f"squareness.{p}"] = {"U": 10.0}
    axes = {a: {"travel": [0, travel], "step": step, "offset": travel / 2} for a in AXES3}
    axes["X"]["errors"] = {
        "linear": {"points": [[0, 0.0], [travel / 3, 6.0], [travel, -9.0]]},
        "angular": {"Z": {"points": [[0, 5.0], [travel, -3.0]]}},
    }
    axes["Y"]["errors"] = {"straightness": {"X": {"points": [[0, 2.0], [travel, -4.0]]}}}
    return {
        "machine": {
            "name": "mc",
            "configuration": "wBMTt",
            "axes": {"bottom": "X", "middle": "Y", "top": "Z"},
        },
        "analysis": {"datum": "negative", **analysis},
        "axes": axes,
        "uncertainty": {
            "method": "montecarlo",
            "samples": samples,
            "seed": seed,
            "components": comps,
        },
    }


def machine(data: dict):
    return machine_from_dict(data, ".")


def values(m, **kw) -> np.ndarray:
    return np.asarray(montecarlo_volumetric(m, m.uncertainty, **kw).values_um)


# -- exact per draw ---------------------------------------------------------------------


@pytest.mark.slow
@pytest.mark.parametrize("dtype, rel", [("float64", 1e-12), ("float32", 2e-6)])
def test_bounds_give_every_draw_the_maximum_over_every_point(dtype, rel):
    # the pruned search and the evaluation of every point of every tile, draw by draw
    m = machine(gantry(step=50.0, samples=500))
    pruned = montecarlo_volumetric(m, m.uncertainty, dtype=dtype)
    full = montecarlo_volumetric(m, m.uncertainty, dtype=dtype, method="full")
    assert pruned.grid_points == full.grid_points == 21**3
    assert np.allclose(pruned.values_um, full.values_um, rtol=rel, atol=0.0)
    assert full.evaluated_points == 500 * 21**3
    assert pruned.evaluated_points < 0.2 * full.evaluated_points


def random_machine(seed: int) -> dict:
    """Random error and U curves on a small odd grid (tiles of unequal sides)."""
    rng = np.random.default_rng(seed)
    data = gantry(step=1.0, travel=10.0, samples=200, seed=seed)
    for a, n in zip(AXES3, (11, 7, 5), strict=True):
        data["axes"][a]["step"] = 10.0 / (n - 1)
        pts = np.linspace(0, 10.0, 4).tolist()
        errors = rng.normal(0, 5, 4).tolist()
        u = rng.uniform(0, 6, 4).tolist()
        data["axes"][a]["errors"] = {
            "linear": {"points": [list(p) for p in zip(pts, errors, strict=True)]}
        }
        data["uncertainty"]["components"][f"{a}.linear"] = {
            "U": {"points": [list(p) for p in zip(pts, u, strict=True)]}
        }
    return data


@pytest.mark.slow
@pytest.mark.parametrize("seed", [1, 2, 3])
def test_bounds_are_exact_on_random_fields(seed):
    m = machine(random_machine(seed))
    a = values(m, dtype="float64")
    b = values(m, dtype="float64", method="full")
    assert np.allclose(a, b, rtol=1e-12, atol=0.0)


def test_a_flat_field_is_still_exact():
    # constant errors and constant U (no levers): every tile has the same bound and the
    # same values; the search must still return the value of the full evaluation
    data = gantry(step=100.0, samples=200)
    for a in AXES3:
        data["axes"][a].pop("errors", None)
        data["axes"][a]["offset"] = 0.0
    data["axes"]["X"]["errors"] = {"linear": {"constant": 3.0}}
    data["analysis"] = {}
    data["uncertainty"]["components"] = {
        "X.linear": {"U": 2.0},
        "Y.straightness.Z": {"U": 1.0, "distribution": "rectangular"},
    }
    m = machine(data)
    for dtype, rel in (("float64", 1e-12), ("float32", 2e-6)):
        pruned = montecarlo_volumetric(m, m.uncertainty, dtype=dtype)
        full = montecarlo_volumetric(m, m.uncertainty, dtype=dtype, method="full")
        assert np.allclose(pruned.values_um, full.values_um, rtol=rel, atol=0.0)
        # decided by the first tile of each draw: the others can only tie
        assert pruned.evaluated_points < 0.1 * full.evaluated_points
    # by hand: the field is (3 + z1·1, z2·0.5, 0) µm everywhere (u = U / 2)
    z = np.asarray(full.values_um)
    assert z.min() >= 0 and np.mean(z) == pytest.approx(3.0, abs=0.3)


@pytest.mark.slow
def test_float32_gives_the_printed_digits_of_float64():
    m = machine(gantry(step=50.0, samples=2000))
    a = montecarlo_volumetric(m, m.uncertainty, dtype="float32")
    b = montecarlo_volumetric(m, m.uncertainty, dtype="float64")
    assert a.dtype == "float32" and b.dtype == "float64"
    assert np.abs(np.asarray(a.values_um) - np.asarray(b.values_um)).max() < 1e-4
    printed = [f"{x:.3f}" for x in (a.mean_um, a.std_um, *a.interval_um)]
    assert printed == [f"{x:.3f}" for x in (b.mean_um, b.std_um, *b.interval_um)]


# -- on the analysis grid ----------------------------------------------------------------


def test_montecarlo_finds_a_peak_between_the_points_of_a_thinned_grid():
    # 61 x 61 x 61 points: a 10 µm peak of X.linear at X = 10 mm lies at grid index 1,
    # which a grid thinned to 27³ points (every second or third index) would skip. With a
    # tiny U every draw must find it.
    data = gantry(step=10.0, travel=600.0, samples=200)
    for a in AXES3:
        data["axes"][a].pop("errors", None)
    data["axes"]["X"]["errors"] = {
        "linear": {"points": [[0, 0.0], [10, 10.0], [20, 0.0], [600, 0.0]]}
    }
    data["analysis"] = {}
    data["uncertainty"]["components"] = {"X.linear": {"U": 0.02}}
    res = analyse(machine(data))
    assert res.cases[0].volumetric.value_um == pytest.approx(10.0)
    assert res.cases[0].volumetric.at["X"] == 10.0
    mc = res.uncertainty.montecarlo
    assert mc.grid_points == 61**3
    assert mc.mean_um == pytest.approx(10.0, abs=0.02)


def test_draws_use_each_components_own_coverage_factor_and_distribution():
    # X.linear U = 6 µm with k = 3 (u = 2, normal); Y.linear U = 3 µm, k = 2, rectangular
    # (u = 1.5: a half-width of 1.5·sqrt(3)); one point, no error data
    data = gantry(samples=20000, seed=9)
    for a in AXES3:
        data["axes"][a].pop("errors", None)
    data["analysis"] = {}  # no datum: a constant shift would cancel against it
    data["uncertainty"]["components"] = {
        "X.linear": {"U": 6.0, "k": 3.0},
        "Y.linear": {"U": 3.0, "distribution": "rectangular"},
    }
    m = machine(data)
    draws = montecarlo_errors(m, m.uncertainty, {"X": 500.0, "Y": 500.0, "Z": 500.0})
    rel = 4 / math.sqrt(2 * (20000 - 1))  # four standard errors of a standard deviation
    assert draws[:, 0].std(ddof=1) == pytest.approx(2.0, rel=rel)
    assert draws[:, 1].std(ddof=1) == pytest.approx(1.5, rel=rel)
    assert np.abs(draws[:, 1]).max() <= 1.5 * math.sqrt(3.0)
    assert np.all(draws[:, 2] == 0.0)


def test_a_lone_u_curve_gives_a_half_normal_accuracy():
    # no error data, X.straightness.Y U rising 0 -> 8 µm (u = 4 at X = 1000) with the
    # slope-removing fit of the measurements: the U is used as given, so the accuracy of
    # a draw is |z|·4 µm: mean 4·sqrt(2/π) = 3.19, standard deviation 4·sqrt(1 - 2/π)
    data = gantry(samples=20000, seed=2, straightness_fit="least-squares")
    for a in AXES3:
        data["axes"][a].pop("errors", None)
    data["uncertainty"]["components"] = {
        "X.straightness.Y": {"U": {"points": [[0, 0.0], [1000, 8.0]]}}
    }
    mc = analyse(machine(data)).uncertainty.montecarlo
    sd = 4.0 * math.sqrt(1.0 - 2.0 / math.pi)
    assert mc.mean_um == pytest.approx(4.0 * math.sqrt(2.0 / math.pi), abs=4 * sd / 141)
    assert mc.std_um == pytest.approx(sd, rel=0.03)


def brute_force(m) -> np.ndarray:
    """Every draw's volumetric accuracy by forming the whole field of every column over
    the grid (float64) and evaluating every point: the same draws, none of the tiles,
    bounds, passes or recomputation."""
    spec = m.uncertainty
    tool = tool_cases(m)[0]
    datum = datum_point(m)
    base = Synthesis.prepare(m)
    sizes = tuple(base.grids[a].size for a in AXIS_NAMES)

    def field(syn):
        return np.stack(
            [
                (p[0][:, :, None] + p[1][:, None, :]) + p[2][None, :, :]
                for p in fold(syn.products(tool, datum), sizes)
            ]
        ).reshape(3, -1)

    columns = [field(base)]
    for name in spec.components:
        syn = Synthesis.prepare(uncertainty_machine(m, spec, {name}, standard=True), measured=False)
        syn.grids.update(base.grids)
        columns.append(field(syn))
    t = np.stack(columns)  # (columns, 3, points)
    shapes = [cu.distribution for cu in spec.components.values()]
    zeta = np.concatenate(list(montecarlo._draw_blocks(spec, shapes)))[: spec.samples]
    e = np.einsum("sc,cdp->sdp", zeta, t)
    return np.sqrt((e**2).sum(axis=1).max(axis=1))


@pytest.mark.slow
def test_every_draw_is_the_maximum_of_a_brute_force_evaluation():
    # random error and U curves on an 11 x 7 x 5 grid (tiles of unequal sides), and the
    # test gantry on 11³ points: each draw against the maximum over every point of the
    # whole field formed for that draw, to 1e-12 in float64 and 2e-6 in float32
    for data in (random_machine(4), gantry(samples=300)):
        m = machine(data)
        want = brute_force(m)
        assert np.allclose(values(m, dtype="float64"), want, rtol=1e-12, atol=0.0)
        assert np.allclose(values(m), want, rtol=2e-6, atol=0.0)


@pytest.mark.slow
def test_same_seed_same_draws_whatever_the_method_and_batches():
    m = machine(gantry(samples=5000))
    a = montecarlo_volumetric(m, m.uncertainty)
    fewer = replace(m.uncertainty, samples=100)
    b = montecarlo_volumetric(m, fewer)
    assert np.array_equal(np.asarray(a.values_um)[:100], b.values_um)
    calls = []
    montecarlo_volumetric(m, m.uncertainty, progress=lambda d, n: calls.append((d, n)))
    assert calls[-1] == (5000, 5000) and all(n == 5000 for _, n in calls)


@pytest.mark.slow
def test_the_values_do_not_depend_on_the_passes(monkeypatch):
    # 2500 draws: three blocks in one pass, or one block per pass
    m = machine(gantry(samples=2500))
    a = values(m)
    monkeypatch.setattr(montecarlo, "_PASS_ELEMENTS", 1)
    calls = []
    b = montecarlo_volumetric(m, m.uncertainty, progress=lambda d, n: calls.append(d))
    assert calls == [1024, 2048, 2500]
    assert np.array_equal(a, b.values_um)


@pytest.mark.slow
def test_the_values_do_not_depend_on_the_shape_of_the_matrix_products(monkeypatch):
    # one row per matrix product (a BLAS computes those as matrix-vector products, whose
    # float32 sums round differently from the matrix-matrix ones): the search may round
    # otherwise, but each value is recomputed in float64 at the point found, in a fixed
    # order. Two points within the float32 rounding of each other could make the values
    # differ by that rounding (the tolerance stated in docs/uncertainty.md); this smooth
    # field has none.
    m = machine(gantry(step=50.0, samples=300))
    a = values(m)
    monkeypatch.setattr(montecarlo, "_EVAL_ELEMENTS", 1)
    monkeypatch.setattr(montecarlo, "_BOUND_ELEMENTS", 1)
    b = values(m)
    assert np.allclose(a, b, rtol=2e-6, atol=0.0)
    assert np.array_equal(a, b)


def test_the_draws_come_from_one_spawned_seed_per_block():
    # X.linear U = 2 µm with k = 2 (u = 1) and no error data: the X error of a draw is its
    # standard normal z; block 1 (draws 1024 to 2047) comes from the second child of
    # SeedSequence(seed).spawn, whatever the number of samples
    data = gantry(samples=1500, seed=7)
    for a in AXES3:
        data["axes"][a].pop("errors", None)
    data["analysis"] = {}
    data["uncertainty"]["components"] = {"X.linear": {"U": 2.0}}
    m = machine(data)
    draws = montecarlo_errors(m, m.uncertainty, {"X": 500.0, "Y": 500.0, "Z": 500.0})
    child = np.random.SeedSequence(7).spawn(2)[1]
    z = np.random.default_rng(child).standard_normal(1024)
    assert np.array_equal(draws[1024:, 0], z[: 1500 - 1024])
    first = montecarlo_errors(m, replace(m.uncertainty, samples=10), {a: 500.0 for a in AXES3})
    assert np.array_equal(first, draws[:10])


@pytest.mark.slow
def test_the_values_do_not_depend_on_the_blas_threads():
    # the same draws in two processes whose BLAS runs on one and on two threads
    code = (
        "import sys; sys.path.insert(0, 'tests');"
        "import numpy as np;"
        "from test_uncertainty_montecarlo import machine, gantry, values;"
        "v = values(machine(gantry(step=50.0, samples=2000)));"
        "sys.stdout.write(v.tobytes().hex())"
    )
    out = []
    for threads in ("1", "2"):
        env = dict(os.environ, OPENBLAS_NUM_THREADS=threads, OMP_NUM_THREADS=threads)
        run = subprocess.run(
            [sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True
        )
        out.append(np.frombuffer(bytes.fromhex(run.stdout), dtype=float))
    assert out[0].size == 2000
    assert np.allclose(out[0], out[1], rtol=2e-6, atol=0.0)


# -- limits -------------------------------------------------------------------------------


def test_too_much_work_is_refused_before_the_synthesis(monkeypatch):
    # 10^6 draws over 201³ = 8.1·10^6 points: 8.1·10^12 point-draws
    data = gantry(step=5.0, samples=1_000_000)
    m = machine(data)

    def never(*args, **kwargs):
        raise AssertionError("the synthesis ran before the limit was checked")

    monkeypatch.setattr("esp.core.synthesis.Synthesis.prepare", never)
    t0 = time.perf_counter()
    with pytest.raises(ConfigError) as err:
        analyse(m)
    assert time.perf_counter() - t0 < 5.0
    assert err.value.key == "uncertainty.samples"
    assert "1000000 Monte Carlo draws over 8120601 grid points" in str(err.value)
    assert f"{MONTECARLO_MAX_WORK:.3g}" in str(err.value)


def test_too_much_memory_is_refused():
    # a 1001³ grid: the stacked pair arrays of 22 columns need 0.8 GB, the tile bounds
    # 0.26 GB
    data = gantry(step=1.0, samples=2)
    m = machine(data)
    assert montecarlo_memory_bytes(m, m.uncertainty) > 2**30
    with pytest.raises(ConfigError, match=r"uncertainty\.samples: the Monte Carlo .* MiB"):
        analyse(m)


@pytest.mark.slow
def test_the_thesis_study_distribution_is_reproducible():
    # the study's U with the X.linear error of 12 µm at X = 1000: seeds fix the figures
    data = gantry(samples=400, seed=11)
    a = analyse(machine(data)).uncertainty.montecarlo
    b = analyse(machine(data)).uncertainty.montecarlo
    assert (a.mean_um, a.std_um, a.interval_um) == (b.mean_um, b.std_um, b.interval_um)
    assert a.samples == 400 and len(a.values_um) == 400 and a.dtype == "float32"
    assert a.tool is not None
