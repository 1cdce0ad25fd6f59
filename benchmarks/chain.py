"""Speed of the kinematic chain (esp.core.kinematics).

On a gantry-sized grid (1000 x 1000 x 500 mm at a 10 mm step, about 5.2e5 points) with
the wBMTt chain of data/examples/chains (21 error symbols, a 150 mm tool offset), times

* the exact chain applied to the tool point (position), with every error a different
  value at every point, as measured errors are;
* the full 4x4 homogeneous products (transforms);
* the numeric first-order sensitivities dp/de of all errors (sensitivities), and the
  first-order error they give;
* the Taylor expansion to second order (taylor);

then, for the shipped gantry example (data/examples/gantry/machine.toml, its measured
profiles), the exact chain of its rigid-body model over its whole analysis grid beside the
separable engine's full analysis of the same grid, with the largest difference between
the engine and the chain's first order and the exact-minus-first-order residual;
and, for the angle head of Freeman & Ford (2003), the exact chain and the sensitivities
over an A x C grid. Prints points per second and the ratios, all measured in this run.

Run:  python benchmarks/chain.py [--step MM] [--repeat N]
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

import esp.core.kinematics as K
from esp.config.chain import load_chain

ROOT = Path(__file__).resolve().parent.parent


def timed(fn, repeat: int):
    best, out = float("inf"), None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t0)
    return best, out


def gantry_grid(step: float) -> dict[str, np.ndarray]:
    x = np.arange(0.0, 1000.0 + step / 2, step)
    y = np.arange(0.0, 1000.0 + step / 2, step)
    z = np.arange(0.0, 500.0 + step / 2, step)
    X, Y, Z = np.meshgrid(x, y, z, indexing="ij")
    return {"X": X.ravel(), "Y": Y.ravel(), "Z": Z.ravel()}


def error_values(chain: K.Chain, at: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
    """A smooth, different value of every error at every point: each axis' errors are
    functions of that axis' coordinate, as measured profiles are (µm, µrad)."""
    rng = np.random.default_rng(0)
    out = {}
    for coordinate, errors in chain.joint_errors().items():
        u = at[coordinate] / 1000.0
        for e in errors:
            a, b, c = rng.normal(size=3) * (5.0, 3.0, 1.0)
            out[e] = a * u + b * np.sin(6.0 * u) + c
    for e in chain.errors:
        out.setdefault(e, np.full_like(at["X"], 5.0))
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--step", type=float, default=10.0, help="grid step, mm")
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args()

    chain = load_chain(ROOT / "data/examples/chains/gantry-wBMTt.toml")
    params = {"tool_z": 150.0, "X_off": 500.0, "Y_off": 500.0, "Z_off": 250.0}
    at = gantry_grid(args.step)
    n = at["X"].size
    errors = error_values(chain, at)
    print(
        f"gantry chain {chain.name}: {len(chain.steps)} steps, {len(chain.errors)} errors, "
        f"{n:,} points ({args.step:g} mm step)"
    )

    t_pos, exact = timed(lambda: K.position(chain, at, params, errors), args.repeat)
    t_htm, T = timed(lambda: K.transforms(chain, at, params, errors), args.repeat)
    assert np.abs(T[:, :3, 3] - exact).max() < 1e-9

    def first_order():
        sens = K.sensitivities(chain, at, params)
        total = np.zeros((n, 3))
        for e, s in sens.items():
            total += s * errors[e][:, None]
        return total

    t_sens, first = timed(lambda: K.sensitivities(chain, at, params), args.repeat)
    t_first, first = timed(first_order, args.repeat)
    t_taylor, expansion = timed(lambda: K.taylor(chain, at, params, errors, order=2), 1)
    nominal = K.position(chain, at, params)
    residual = np.abs(exact - nominal - first).max() * 1000.0
    assert np.abs(expansion.first - first).max() < 1e-12

    rows = [
        ("exact chain, tool point (position)", t_pos),
        ("exact chain, 4x4 products (transforms)", t_htm),
        ("sensitivities of all errors", t_sens),
        ("sensitivities + first-order error", t_first),
        ("Taylor expansion to second order", t_taylor),
    ]
    for label, t in rows:
        print(f"  {label:<42} {t:7.3f} s  {n / t:>14,.0f} points/s")
    print(
        f"  ratios: 4x4 products / position {t_htm / t_pos:.2f}; "
        f"sensitivities / position {t_sens / t_pos:.2f}; "
        f"first-order error / position {t_first / t_pos:.2f}"
    )
    print(f"  largest |exact - nominal - first order| over the grid: {residual:.2e} um")

    engine_beside_chain(args.repeat)

    head = load_chain(ROOT / "data/examples/heads/angle-head.toml")
    angles = np.arange(-60.0, 60.0 + 0.05, 0.25)
    A, C = np.meshgrid(angles, angles, indexing="ij")
    hat = {"A": A.ravel(), "C": C.ravel()}
    m = hat["A"].size
    herr = {e: head.symbols[e].value for e in head.errors}
    t_hpos, _ = timed(lambda: K.position(head, hat, errors=herr), args.repeat)
    t_hsens, _ = timed(lambda: K.sensitivities(head, hat), args.repeat)
    print(f"angle head (Freeman & Ford 2003): {m:,} settings of A, C (0.25 deg step)")
    print(f"  {'exact chain (position)':<42} {t_hpos:7.3f} s  {m / t_hpos:>14,.0f} points/s")
    print(f"  {'sensitivities of all errors':<42} {t_hsens:7.3f} s  {m / t_hsens:>14,.0f} points/s")
    print(f"  ratio sensitivities / position {t_hsens / t_hpos:.2f}")


def engine_beside_chain(repeat: int, step: float = 10.0) -> None:
    """The gantry example: exact chain of its rigid-body model on a grid vs the engine."""
    from dataclasses import replace

    import esp
    from esp.core.models.derived import cartesian_chain, error_symbol
    from esp.core.synthesis import Synthesis, case_result, datum_point, tool_cases

    machine = esp.load_machine(ROOT / "data/examples/gantry/machine.toml")
    axes = {a: replace(ax, step_mm=step) for a, ax in machine.axes.items()}
    machine = replace(machine, axes=axes)
    syn = Synthesis.prepare(machine)
    g = syn.grids
    X, Y, Z = np.meshgrid(g["X"], g["Y"], g["Z"], indexing="ij")
    points = np.column_stack([X.ravel(), Y.ravel(), Z.ravel()])
    n = len(points)
    letters = tuple(machine.roles[r] for r in ("bottom", "middle", "top"))
    chain = cartesian_chain(machine.configuration, letters, False)
    params = {f"{a}_off": machine.axes[a].offset_mm for a in "XYZ"}
    at = {a: points[:, i] for i, a in enumerate("XYZ")}
    # each chain error takes the machine's curve of that component, as the engine reads it
    errors = {}
    for bt in syn.terms():
        name = bt.component
        symbol = error_symbol(name.kind, name.axis, name.about)
        if symbol in errors:
            continue
        if bt.axis:
            errors[symbol] = np.asarray(syn.component_at(bt, points[:, "XYZ".index(bt.axis)]))
        else:
            errors[symbol] = np.full(n, float(syn.functions[name]))
    (tool,) = tool_cases(machine)
    datum = datum_point(machine)
    t_exact, exact = timed(lambda: K.position(chain, at, params, errors), repeat)
    t_engine, _ = timed(lambda: case_result(syn, tool, datum, breakdowns=False), repeat)
    nominal = K.position(chain, at, params)
    sens = K.sensitivities(chain, at, params)
    first = sum(s * errors[e][:, None] for e, s in sens.items() if e in errors)
    engine = syn.totals_at_um(points, tool)
    print(f"gantry example, rigid-body model: {n:,} grid points ({step:g} mm step)")
    print(f"  {'exact chain over the grid':<42} {t_exact:7.3f} s  {n / t_exact:>14,.0f} points/s")
    print(
        f"  {'separable engine, all extremes':<42} {t_engine:7.3f} s  "
        f"{n / t_engine:>14,.0f} points/s"
    )
    print(f"  ratio exact chain / separable engine {t_exact / t_engine:.1f}")
    linear = np.abs(engine - first * 1000.0).max()
    residual = np.abs((exact - nominal - first) * 1000.0).max()
    print(f"  largest |engine - chain first order| {linear:.2e} um")
    print(f"  largest |exact - nominal - first order| {residual:.2e} um")


if __name__ == "__main__":
    main()
