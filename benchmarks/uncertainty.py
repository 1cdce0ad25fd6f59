"""Speed of the Monte Carlo volumetric uncertainty (GUM Supplement 1), on the analysis grid.

The machine is the example gantry (``data/examples/gantry``: 21 measured components,
datum at the home corner) with an ``[uncertainty]`` table of the thesis' study values for
every component (linear 8 µm/m, straightness 4 µm, angular 4 µm/m, squareness 10 µm/m),
drawn on the analysis grid at three steps. In one process, on one core, it times:

1. ``straightforward`` -- the best-estimate field ``e0`` and one field per component
   materialised over the whole grid (float64), a batch of draws evaluated as
   ``e0 + z @ T``, the volumetric error formed with ``einsum`` and its maximum taken;
2. ``folded`` -- the same with the best estimate folded into the matrix product, a column
   of ones beside the draws, and the volumetric error formed in place (float64);
3. ``folded float32`` -- the same in float32;
4. ``bounds`` -- esp's method: per-tile bounds, each draw evaluates only the tiles that can
   hold its maximum (float32, the default), and the same in float64.

For each it prints the CPU seconds (median of ``--repeat`` runs), the effective
point-draws per second (grid points × draws / time), the ratio to the straightforward
implementation, the largest difference of any draw's value from it, and the summary the
report prints (mean, standard deviation, 95 % interval, to 0.001 µm) -- the same digits
for every method. The straightforward implementation is skipped where its fields would
not fit in ``--memory`` MiB; ratios are then to the evaluation of every point of every
tile, timed on one block of draws.

Then the bounds method against its own cost model, measured in the same run, interleaved
with it ``--repeat`` times: building the linear model, forming every tile once per pass,
the two matrix products of the bounds for every block of draws, and the point-draws the
search evaluated at the rate of one whole tile against one whole block (matrix product,
squares, maximum). The ratio says what the search costs beyond these (the elementwise
work of the bounds, the sweep, small matrix products).

The machine (cores, CPU model), the load average and the BLAS threads are printed first:
quote the figures with them. BLAS is held to one thread (``OPENBLAS_NUM_THREADS`` and the
like are set before numpy is imported).

Run:  python benchmarks/uncertainty.py [--samples N] [--repeat N] [--steps 50,20,10]
"""

from __future__ import annotations

import os

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import argparse  # noqa: E402
import platform  # noqa: E402
import statistics  # noqa: E402
import time  # noqa: E402
from dataclasses import replace  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402
from _host import cpu_model  # noqa: E402

from esp.config import machine_from_dict  # noqa: E402
from esp.core.grid import fold  # noqa: E402
from esp.core.machine import AXIS_NAMES, Machine  # noqa: E402
from esp.core.synthesis import Synthesis, datum_point, tool_cases  # noqa: E402
from esp.core.uncertainty.montecarlo import (  # noqa: E402
    _BLOCK,
    _draw_blocks,
    _pass_blocks,
    _Search,
    montecarlo_model,
    montecarlo_volumetric,
)
from esp.core.uncertainty.propagate import uncertainty_machine  # noqa: E402
from esp.io.tomlfile import read_toml_file  # noqa: E402

GANTRY = Path(__file__).resolve().parent.parent / "data" / "examples" / "gantry"


def gantry(step: float, samples: int) -> Machine:
    """The example gantry with the study's uncertainty on every component."""
    data = read_toml_file(GANTRY / "machine.toml")
    comps = {}
    for a in AXIS_NAMES:
        length = data["axes"][a]["travel"][1]
        comps[f"{a}.linear"] = {"U": {"points": [[0, 0.0], [length, 8.0 * length / 1000]]}}
        for b in AXIS_NAMES:
            if b != a:
                comps[f"{a}.straightness.{b}"] = {"U": 4.0}
            comps[f"{a}.angular.{b}"] = {"U": 4.0}
        data["axes"][a]["step"] = step
    for p in ("XY", "XZ", "YZ"):
        comps[f"squareness.{p}"] = {"U": 10.0}
    data["uncertainty"] = {"method": "montecarlo", "samples": samples, "components": comps}
    return machine_from_dict(data, GANTRY)


def _field(syn: Synthesis, tool, datum, sizes) -> np.ndarray:
    pairs = fold(syn.products(tool, datum), sizes)
    return np.stack(
        [(p[0][:, :, None] + p[1][:, None, :] + p[2][None, :, :]).ravel() for p in pairs]
    ).ravel()


def fields(m: Machine) -> tuple[np.ndarray, np.ndarray]:
    """(e0, T): the best-estimate field (3P,) and one standard-uncertainty field per
    component (n, 3P), over the whole grid, float64."""
    spec = m.uncertainty
    tool = tool_cases(m)[0]
    datum = datum_point(m)
    base = Synthesis.prepare(m)
    sizes = tuple(base.grids[a].size for a in AXIS_NAMES)
    e0 = _field(base, tool, datum, sizes)
    t = np.stack(
        [
            _field(
                Synthesis.prepare(uncertainty_machine(m, spec, {n}, standard=True), measured=False),
                tool,
                datum,
                sizes,
            )
            for n in spec.components
        ]
    )
    return e0, t


def draws(m: Machine, samples: int) -> np.ndarray:
    """The augmented draws (1, z) of the seed, as esp draws them, shape (samples, n + 1)."""
    shapes = tuple(cu.distribution for cu in m.uncertainty.components.values())
    return np.concatenate(list(_draw_blocks(m.uncertainty, shapes)))[:samples]


def straightforward(m: Machine, e0, t, samples: int) -> np.ndarray:
    """``e0 + z @ T`` per batch, ``einsum`` for the squares (float64)."""
    zeta = draws(m, samples)
    points = e0.size // 3
    batch = max(1, 4_000_000 // e0.size)
    out = np.empty(samples)
    for b0 in range(0, samples, batch):
        z = zeta[b0 : b0 + batch, 1:]
        e = (e0 + z @ t).reshape(z.shape[0], 3, points)
        out[b0 : b0 + z.shape[0]] = np.sqrt(np.einsum("sdp,sdp->sp", e, e).max(axis=1))
    return out


def folded(m: Machine, matrix: np.ndarray, samples: int) -> np.ndarray:
    """``(1, z) @ [e0; T]`` per batch, squares summed in place, in ``matrix``'s type."""
    zeta = draws(m, samples).astype(matrix.dtype)
    points = matrix.shape[1] // 3
    batch = max(1, 4_000_000 // matrix.shape[1])
    out = np.empty(samples)
    for b0 in range(0, samples, batch):
        e = (zeta[b0 : b0 + batch] @ matrix).reshape(-1, 3, points)
        np.square(e, out=e)
        s = e[:, 0] + e[:, 1]
        s += e[:, 2]
        out[b0 : b0 + s.shape[0]] = np.sqrt(s.max(axis=1))
    return out


def cost_model(m: Machine, evaluated: int, dtype: str = "float32") -> dict[str, float]:
    """The cost of the bounds method by its own design, each part measured in this run
    (CPU seconds): building the linear model; forming every tile once per pass; the two
    matrix products of the bounds for every block of draws; and the point-draws the
    search evaluated (``evaluated``), at the rate of one whole tile against one whole
    block of draws (matrix product, squares, maximum)."""
    spec = m.uncertainty
    t0 = time.process_time()
    model = montecarlo_model(m, spec, dtype=dtype)
    parts = {"model": time.process_time() - t0}
    search = _Search(model, dtype)
    blocks = -(-spec.samples // _BLOCK)
    passes = -(-blocks // _pass_blocks(search.count))
    t0 = time.process_time()
    for t in range(search.count):
        model.tile_field(t)
    parts["tiles"] = passes * (time.process_time() - t0)
    z = next(_draw_blocks(spec, model.shapes)).astype(dtype)
    t0 = time.process_time()
    for _ in range(3):
        z @ search.mid
        np.abs(z) @ search.rad
    parts["bound products"] = blocks * (time.process_time() - t0) / 3
    tile = model.tile_field(0)  # the first tile is whole
    n = tile.shape[1] // 3
    t0 = time.process_time()
    for _ in range(5):
        e = (z @ tile).reshape(-1, 3, n)
        np.square(e, out=e)
        s = e[:, 0] + e[:, 1]
        s += e[:, 2]
        s.max(axis=1)
    parts["evaluation"] = evaluated * (time.process_time() - t0) / (5 * z.shape[0] * n)
    return parts


def timed(repeat: int, call, *args, **kwargs):
    """(median CPU seconds of ``repeat`` calls, the last value)."""
    times = []
    value = None
    for _ in range(repeat):
        t0 = time.process_time()
        value = call(*args, **kwargs)
        times.append(time.process_time() - t0)
    return statistics.median(times), value


def summary(values: np.ndarray) -> str:
    lo, hi = np.percentile(values, [2.5, 97.5])
    return f"mean {values.mean():.3f}, s {values.std(ddof=1):.3f}, 95 % [{lo:.3f}, {hi:.3f}] um"


def describe_machine() -> str:
    model = cpu_model()
    load = ", ".join(f"{x:.2f}" for x in os.getloadavg()) if hasattr(os, "getloadavg") else "?"
    return (
        f"{os.cpu_count()} cores, {model}; Python {platform.python_version()}, numpy "
        f"{np.__version__}, BLAS threads {os.environ['OPENBLAS_NUM_THREADS']}; load average "
        f"{load}"
    )


def bench_step(step: float, args) -> None:
    """Every method on the grid of ``step`` mm; one printed block."""
    m = gantry(step, args.samples)
    spec = m.uncertainty
    n = args.samples
    points = int(np.prod([m.axes[a].grid_mm().size for a in AXIS_NAMES]))
    columns = len(spec.components) + 1
    print(f"step {step:g} mm: {points:,} grid points, {columns} columns")
    rows = []
    if 8 * columns * 3 * points * 2 <= args.memory * 2**20:
        e0, t = fields(m)
        matrix = np.vstack([e0[None, :], t])
        sec, ref = timed(args.repeat, straightforward, m, e0, t, n)
        rows.append(("straightforward (float64)", sec, n, ref))
        reference = ("straightforward", sec / n)
        sec, val = timed(args.repeat, folded, m, matrix, n)
        rows.append(("folded (float64)", sec, n, val))
        sec, val = timed(args.repeat, folded, m, matrix.astype(np.float32), n)
        rows.append(("folded (float32)", sec, n, val))
        del e0, t, matrix
    else:
        # the whole fields do not fit: every point of every tile for a subset of the draws
        few = min(n, _BLOCK)  # one whole block (esp searches whole blocks)
        sec, mc = timed(1, montecarlo_volumetric, m, replace(spec, samples=few), method="full")
        rows.append(("full, by tiles (float32)", sec, few, np.asarray(mc.values_um)))
        reference = ("full (float32)", sec / few)
    evaluated = 0
    for dtype in ("float32", "float64"):
        sec, mc = timed(args.repeat, montecarlo_volumetric, m, spec, dtype=dtype)
        frac = mc.evaluated_points / (points * n)
        name = f"bounds ({dtype}), evaluated {100 * frac:.2f} %"
        rows.append((name, sec, n, np.asarray(mc.values_um)))
        if dtype == "float32":
            evaluated = mc.evaluated_points
    base = rows[0][3]
    for name, sec, count, values in rows:
        k = min(values.size, base.size)
        diff = np.abs(values[:k] - base[:k]).max()
        print(
            f"  {name:42s} {sec:8.3f} s  {points * count / sec:9.3g} point-draws/s  "
            f"ratio {reference[1] / (sec / count):7.1f}x  max |diff| {diff:.1e} um"
        )
        if count == n:
            print(f"  {'':42s} {summary(values)}")
    print(f"  (ratios to the {reference[0]} evaluation)")
    # the method and its cost model, interleaved so that both see the same load
    ratios, parts = [], {}
    for _ in range(args.repeat):
        sec, _ = timed(1, montecarlo_volumetric, m, spec)
        parts = cost_model(m, evaluated)
        ratios.append(sec / sum(parts.values()))
    detail = " + ".join(f"{k} {v:.3f} s" for k, v in parts.items())
    print(f"  cost model of bounds (float32), last run: {detail} = {sum(parts.values()):.3f} s")
    print(
        f"  bounds (float32) / its cost model: median {statistics.median(ratios):.2f}x, "
        f"lowest {min(ratios):.2f}x, highest {max(ratios):.2f}x over {len(ratios)} runs\n"
    )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--samples", type=int, default=20000)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--steps", default="50,20,10", help="grid steps in mm, comma-separated")
    ap.add_argument("--memory", type=float, default=600.0, help="MiB for the full fields")
    args = ap.parse_args()
    print(describe_machine())
    print(f"{args.samples} draws, CPU seconds, medians of {args.repeat} runs\n")
    for step in (float(s) for s in args.steps.split(",")):
        bench_step(step, args)


if __name__ == "__main__":
    main()
