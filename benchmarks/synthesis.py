"""Speed of the synthesis engine.

Prints grid points per second for a 1000 x 1000 x 500 mm volume at a 2 mm step (about
6.3e7 points) with every component of a wBMTt machine active, at the MCP (eq. 3.1) and at
the TCP (eq. 3.10, one tool orientation); then, on a smaller grid, the time of a
straightforward implementation -- every term materialised as a full 3-D array, summed,
then the extremes taken -- next to the engine's, in the same process, and their ratio.

Run:  python benchmarks/synthesis.py [--step MM] [--repeat N]
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from esp.analysis import analyse
from esp.grid import PAIRS
from esp.machine import Analysis, Axis, Component, Machine, Tool
from esp.profile import ErrorProfile
from esp.synthesis import Synthesis, tool_cases


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
    best, out = float("inf"), None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t0)
    return best, out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--step", type=float, default=2.0, help="grid step of the large run, mm")
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args()

    for point in ("MCP", "TCP"):
        m = machine(args.step, point)
        seconds, res = timed(lambda m=m: analyse(m), args.repeat)
        n = res.cases[0].points
        accuracy = res.cases[0].volumetric.value_um
        print(
            f"engine, {point}, 21 components, {n:,} points: {seconds:.2f} s, "
            f"{n / seconds:,.0f} points/s (volumetric accuracy {accuracy:.3f} um)"
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
