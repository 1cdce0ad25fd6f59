"""Speed of the Monte Carlo volumetric uncertainty (GUM Supplement 1).

Prints Monte Carlo draws per second for the thesis 4.01 study machine (21 components with
an uncertainty, 1 m wBMTt gantry) on a grid of about 2·10^4 points, and, for a few draws,
the time of a straightforward implementation that rebuilds every component's curve and
re-runs the whole synthesis per draw, in the same process, with their ratio.

Run:  python benchmarks/uncertainty.py [--samples N]
"""

from __future__ import annotations

import argparse
import time
from dataclasses import replace

import numpy as np

from esp.analysis import analyse
from esp.config import machine_from_dict
from esp.machine import Component
from esp.profile import ErrorProfile
from esp.uncertainty.propagate import montecarlo_volumetric


def study(samples: int) -> dict:
    axes = ("X", "Y", "Z")
    comps = {}
    for a in axes:
        comps[f"{a}.linear"] = {"U": {"points": [[0, 0.0], [500, 4.0], [1000, 8.0]]}}
        for b in axes:
            if b != a:
                comps[f"{a}.straightness.{b}"] = {"U": 4.0}
            comps[f"{a}.angular.{b}"] = {"U": 4.0}
    for p in ("XY", "XZ", "YZ"):
        comps[f"squareness.{p}"] = {"U": 10.0}
    return {
        "machine": {
            "name": "bench",
            "configuration": "wBMTt",
            "axes": {"bottom": "X", "middle": "Y", "top": "Z"},
        },
        "axes": {a: {"travel": [0, 1000], "step": 40, "offset": 500} for a in axes},
        "uncertainty": {"method": "montecarlo", "samples": samples, "components": comps},
    }


def per_draw(machine, draws: int) -> list[float]:
    """One full synthesis per draw: each component's curve rebuilt as U·z/k."""
    rng = np.random.default_rng(machine.uncertainty.seed)
    spec = machine.uncertainty
    out = []
    for _ in range(draws):
        comps = {}
        for name, cu in spec.components.items():
            z = rng.standard_normal() / spec.k
            c = cu.as_component()
            if c.kind == "squareness":
                comps[name] = replace(c, value=c.value * z)
            else:
                p = c.profile
                runs = {d: r * z for d, r in p.runs.items()}
                comps[name] = Component(
                    name,
                    c.kind,
                    c.axis,
                    c.about,
                    ErrorProfile(p.kind, p.targets_mm, runs, axis=p.axis),
                )
        m = replace(machine, components=comps, uncertainty=None)
        out.append(analyse(m).cases[0].volumetric.value_um)
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--samples", type=int, default=20000)
    args = ap.parse_args()
    machine = machine_from_dict(study(args.samples), ".")
    t0 = time.perf_counter()
    mc = montecarlo_volumetric(machine, machine.uncertainty)
    t_mc = time.perf_counter() - t0
    points = 26**3  # a 40 mm step over 1000 mm: no thinning below the limit
    print(
        f"Monte Carlo, 21 components, {points:,} grid points: {mc.samples:,} draws in "
        f"{t_mc:.2f} s, {mc.samples / t_mc:,.0f} draws/s (mean {mc.mean_um:.2f} um, "
        f"95 % interval {mc.interval_um[0]:.2f}..{mc.interval_um[1]:.2f} um)"
    )
    draws = 50
    t0 = time.perf_counter()
    per_draw(machine, draws)
    t_loop = (time.perf_counter() - t0) / draws
    t_vec = t_mc / mc.samples
    print(
        f"straightforward: one full synthesis per draw {t_loop * 1e3:.2f} ms/draw; "
        f"vectorised {t_vec * 1e3:.4f} ms/draw; ratio {t_loop / t_vec:.0f}x"
    )


if __name__ == "__main__":
    main()
