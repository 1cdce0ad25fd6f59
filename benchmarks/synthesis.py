"""Speed of the synthesis engine.

1. Extremes of one error field: a 1000 x 1000 x 500 mm volume at a 1 mm step (about
   5.0e8 points, every one of the 21 components of a wBMTt machine active): the full walk
   of every point (``esp.core.grid.scan_all``, the reference) and the bounded search
   (``esp.core.grid.scan``) on the same folded field, in the same process, with their ratio,
   the effective points per second and a check that both give identical results; then
   the volumetric maximum alone (what a swept tool orientation needs), and two fields on
   which the tile bounds cannot prune (a constant field and one of pure noise).
2. The whole engine (``esp.core.analysis.analyse``) at a 2 mm step, at the MCP (eq. 3.1) and
   at the TCP (eq. 3.10, one tool orientation).
3. On a 10 mm grid, a straightforward implementation -- every term materialised as a full
   3-D array, summed, then the extremes taken -- next to the engine.

Times are CPU seconds of this process (``time.process_time``), medians of ``--repeat``
runs. The machine (cores, CPU model) and the load average are printed first: on a shared
machine quote the figures together with the load.

Run:  python benchmarks/synthesis.py [--step MM] [--repeat N] [--quick]
"""

from __future__ import annotations

import argparse
import os
import platform
import statistics
import time

import numpy as np
from _host import cpu_model

from esp.core.analysis import analyse
from esp.core.grid import PAIRS, fold, scan, scan_all, volumetric_peak
from esp.core.machine import Analysis, Axis, Component, Machine, Tool
from esp.core.profile import ErrorProfile
from esp.core.synthesis import Synthesis, datum_point, tool_cases


def machine(step: float, point: str = "MCP") -> Machine:
    """A wBMTt machine, 1000 x 1000 x 500 mm, every one of the 21 components from data
    with 21 targets per axis."""
    rng = np.random.default_rng(0)
    travel = {"X": 1000.0, "Y": 1000.0, "Z": 500.0}
    axes = {
        a: Axis(a, r, (0.0, travel[a]), (0.0, travel[a]), step, travel[a] / 2)
        for a, r in zip("XYZ", ("bottom", "middle", "top"), strict=True)
    }
    comps = {}

    def prof(kind, axis, scale):
        t = np.linspace(0.0, travel[axis], 21)
        runs = {"forward": rng.normal(size=(5, t.size)) * scale}
        runs["backward"] = runs["forward"] + rng.normal(size=(5, t.size))
        return ErrorProfile(kind, t, runs, axis=axis)

    for a in "XYZ":
        comps[f"{a}.linear"] = Component(f"{a}.linear", "linear", a, None, prof("linear", a, 10))
        for b in "XYZ":
            if b != a:
                n = f"{a}.straightness.{b}"
                comps[n] = Component(n, "straightness", a, b, prof("straightness", a, 2))
            n = f"{a}.angular.{b}"
            comps[n] = Component(n, "angular", a, b, prof("angular", a, 3))
    for p in ("XY", "XZ", "YZ"):
        comps[f"squareness.{p}"] = Component(f"squareness.{p}", "squareness", None, p, value=5.0)
    tool = Tool(lengths_mm=(150.0,), orientations_deg=((45.0, 90.0),))
    return Machine(
        "bench",
        "wBMTt",
        {"bottom": "X", "middle": "Y", "top": "Z"},
        axes,
        comps,
        Analysis(point=point),
        tool,
    )


def straightforward(m: Machine) -> tuple[float, float]:
    """Every term as a full 3-D array; returns (volumetric accuracy, X range)."""
    syn = Synthesis.prepare(m)
    tool = tool_cases(m)[0]
    g = syn.grids
    X, Y, Z = np.meshgrid(g["X"], g["Y"], g["Z"], indexing="ij")
    coords = {"X": X, "Y": Y, "Z": Z}
    total = {a: np.zeros(X.shape) for a in "XYZ"}
    for bt in syn.terms():
        fn = syn.functions[bt.component]
        value = fn(coords[bt.axis]) if bt.axis else fn
        if bt.is_angle:
            lever = np.zeros(X.shape)
            if bt.lever_axis:
                lever = lever + bt.lever_sign * (coords[bt.lever_axis] - bt.lever_offset_mm)
            if bt.tool_axis:
                lever = lever + bt.tool_sign * tool.offset_mm[bt.tool_axis]
            total[bt.direction] += bt.sign * value * lever / 1000.0
        else:
            total[bt.direction] += bt.sign * value
    vol = np.sqrt(total["X"] ** 2 + total["Y"] ** 2 + total["Z"] ** 2)
    for p, q in PAIRS:
        _ = np.sqrt(total["XYZ"[p]] ** 2 + total["XYZ"[q]] ** 2).argmax()
    return float(vol.max()), float(np.ptp(total["X"]))


def timed(fn, repeat: int) -> tuple[float, object]:
    """Median CPU seconds of ``repeat`` calls, and the last result."""
    times, out = [], None
    for _ in range(repeat):
        t0 = time.process_time()
        out = fn()
        times.append(time.process_time() - t0)
    return statistics.median(times), out


def describe_machine() -> str:
    model = cpu_model()
    try:
        load = " ".join(f"{v:.2f}" for v in os.getloadavg())
    except OSError:
        load = "unknown"
    return (
        f"machine: {os.cpu_count()} cores, {model}; load average {load}; "
        f"Python {platform.python_version()}, numpy {np.__version__}"
    )


def folded(m: Machine, squared: bool = False) -> tuple[list, int, float]:
    """The pair arrays of the machine's first tool case (of its squared terms when
    ``squared``), its point count and the CPU time of forming them (products and fold)."""
    syn = Synthesis.prepare(m)
    tool = tool_cases(m)[0]
    sizes = tuple(syn.grids[a].size for a in "XYZ")
    t0 = time.process_time()
    products = syn.squared_products(tool) if squared else syn.products(tool, datum_point(m))
    pairs = fold(products, sizes)
    return pairs, int(np.prod(sizes)), time.process_time() - t0


def compare(label: str, pairs, n: int, repeat: int, squared: bool = False) -> None:
    """Full walk and bounded search of one field: times, ratio, points/s, agreement."""
    t_full, full = timed(lambda: scan_all(pairs, squared), repeat)
    t_fast, fast = timed(lambda: scan(pairs, squared), repeat)
    t_vol, vol = timed(lambda: volumetric_peak(pairs, squared), repeat)
    assert fast == full, "the bounded search differs from the full walk"
    assert vol == full.volumetric, "the volumetric-only search differs"
    print(
        f"  {label}: full walk {t_full:.3f} s ({n / t_full:.3g} points/s); "
        f"bounded search {t_fast:.3f} s ({n / t_fast:.3g} points/s, "
        f"{100 * fast.evaluated / n:.2f} % of the points evaluated), "
        f"ratio {t_full / t_fast:.1f}x; volumetric only {t_vol:.3f} s "
        f"(ratio {t_full / t_vol:.1f}x); results identical"
    )


def flat_fields(sizes: tuple[int, int, int], seed: int = 0) -> dict[str, list]:
    """Fields on which the tile bounds cannot prune."""
    rng = np.random.default_rng(seed)
    nx, ny, nz = sizes
    shapes = ((nx, ny), (nx, nz), (ny, nz))
    return {
        "constant field": [[np.full(s, 2.5) for s in shapes] for _ in range(3)],
        "noise, no trend": [[rng.normal(size=s) for s in shapes] for _ in range(3)],
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--step", type=float, default=1.0, help="grid step of the extremes, mm")
    ap.add_argument("--repeat", type=int, default=3, help="runs per figure (median)")
    ap.add_argument("--quick", action="store_true", help="2 mm extremes, skip the engine runs")
    args = ap.parse_args()
    step = 2.0 if args.quick else args.step
    print(describe_machine())

    m = machine(step)
    pairs, n, t_fold = folded(m)
    print(
        f"extremes of one field, 1000 x 1000 x 500 mm at {step:g} mm ({n:,} points, "
        f"21 components, MCP); forming the 2-D arrays: {t_fold:.3f} s"
    )
    compare("signed errors", pairs, n, args.repeat)
    squares, _, _ = folded(m, squared=True)
    compare("sums of squares (root-sum-square)", squares, n, args.repeat, squared=True)
    del squares
    sizes = (*pairs[0][0].shape, pairs[0][1].shape[1])
    small = tuple(max(1, (s + 1) // 2) for s in sizes)
    for label, flat in flat_fields(small).items():
        compare(f"{label}, {int(np.prod(small)):,} points", flat, int(np.prod(small)), args.repeat)
    if args.quick:
        return

    for point in ("MCP", "TCP"):
        m = machine(2.0, point)
        seconds, res = timed(lambda m=m: analyse(m), args.repeat)
        n = res.cases[0].points
        accuracy = res.cases[0].volumetric.value_um
        print(
            f"engine, {point}, 21 components, {n:,} points: {seconds:.2f} s, "
            f"{n / seconds:.3g} points/s (volumetric accuracy {accuracy:.3f} um)"
        )

    m = machine(10.0)
    t_engine, res = timed(lambda: analyse(m), args.repeat)
    t_plain, (vol, xrange_um) = timed(lambda: straightforward(m), args.repeat)
    n = res.cases[0].points
    assert abs(vol - res.cases[0].volumetric.value_um) < 1e-9
    assert abs(xrange_um - res.cases[0].axes["X"].range_um) < 1e-9
    print(
        f"same grid ({n:,} points, 10 mm step): straightforward full 3-D arrays {t_plain:.3f} s, "
        f"engine {t_engine:.3f} s, ratio {t_plain / t_engine:.1f}x (results agree)"
    )


if __name__ == "__main__":
    main()
