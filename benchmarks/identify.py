"""Speed of ``esp identify``.

1. A ball plate of 25 balls in 4 poses on a wBMTt machine, every component that acts at
   the MCP (17 of the 21: the top axis' angles and the middle axis' rotation about the
   top axis have no lever there) identified with Legendre degree 5 (squareness: one
   number): identification with its covariance, and ``--plan`` (the design alone).
   With one tool offset all 21 act, but a plate (or a tracker) at one tool offset cannot
   tell the top axis' angles from the straightness of that axis: ``--tool`` runs that
   case with ``null = "minimum-norm"`` and prints how many directions are unseen.
2. A tracking interferometer at 4 stations x 500 positions, the same components.

Each is timed as ``esp.identify.run.identify(problem, volumetric=False)`` (the fit, the
identifiability and the covariance; the volumetric accuracy is one ``esp analyse`` of the
identified machine, timed in benchmarks/synthesis.py) and ``plan(problem)``, next to the
reference: one ``numpy.linalg.lstsq`` of a random matrix of the same size as the final
Jacobian. Data are made through the exact chain. Where a plan cannot see a combination,
``null = "minimum-norm"`` lets it run and the count of unseen directions is printed.

esp sets no thread count; OpenBLAS' default threading on a loaded machine of few cores
is slow, so the figures in docs/ are taken with ``OPENBLAS_NUM_THREADS=1`` (printed).
Times are wall-clock seconds (``time.perf_counter``), medians of ``--repeat`` runs; the
load average is printed first: on a shared machine quote the figures with the load.

Run:  OPENBLAS_NUM_THREADS=1 python benchmarks/identify.py [--repeat N]
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from esp.config import machine_from_dict  # noqa: E402
from esp.identify.config import problem_from_dict  # noqa: E402
from esp.identify.model import rotation  # noqa: E402
from esp.identify.run import identify, plan  # noqa: E402
from esp.identify.simulate import actual_positions, commanded_for  # noqa: E402

TRAVEL = {"X": (0.0, 1000.0), "Y": (0.0, 800.0), "Z": (0.0, 600.0)}
TOOL = {"X": 40.0, "Y": 30.0, "Z": -120.0}


WITH_TOOL = "--tool" in sys.argv


def base() -> dict:
    d = {
        "machine": {
            "name": "benchmark",
            "configuration": "wBMTt",
            "axes": {"bottom": "Y", "middle": "X", "top": "Z"},
        },
        "axes": {a: {"travel": list(TRAVEL[a]), "step": 100} for a in "XYZ"},
    }
    if WITH_TOOL:
        d["analysis"] = {"point": "TCP"}
        d["tool"] = {"orientation": {"offset": dict(TOOL)}}
    return d


def config(measurements: dict) -> dict:
    d = base()
    spec = {"identify": {"basis": "legendre", "degree": 5}}
    acting = {"X": "XY", "Y": "XYZ", "Z": ""} if not WITH_TOOL else {a: "XYZ" for a in "XYZ"}
    for a in "XYZ":
        errors: dict = {"linear": dict(spec), "straightness": {}, "angular": {}}
        for b in "XYZ":
            if b in acting[a]:
                errors["angular"][b] = dict(spec)
            if b != a:
                errors["straightness"][b] = dict(spec)
        if not errors["angular"]:
            del errors["angular"]
        d["axes"][a]["errors"] = errors
    d["squareness"] = {p: {"identify": True} for p in ("XY", "XZ", "YZ")}
    # these plans do not see every combination of 17 (21) curves of degree 5: the
    # benchmark takes the minimum-norm choice, with directions below 1e-4 of the largest
    # singular value counted as unseen, so that it times a fit of the full size
    d["identify"] = {
        "measurements": measurements,
        "null": "minimum-norm",
        "rank_tolerance": 1e-4,
    }
    return d


def truth(rng) -> dict:
    out: dict = {}
    for a in "XYZ":
        lo, hi = TRAVEL[a]
        for name in (
            [f"{a}.linear"]
            + [f"{a}.angular.{b}" for b in "XYZ"]
            + [f"{a}.straightness.{b}" for b in "XYZ" if b != a]
        ):
            c = rng.normal(0, 2.0, 3)

            def f(x, c=c, lo=lo, hi=hi):
                u = (2 * np.asarray(x, dtype=float) - lo - hi) / (hi - lo)
                return c[0] * (u + 1) + c[1] * (u * u - 1) + c[2] * np.sin(u + 1)

            out[name] = f
    out.update({"squareness.XY": 3.0, "squareness.XZ": -2.0, "squareness.YZ": 1.5})
    return out


def plate_problem(folder: Path, rng):
    machine = machine_from_dict(base(), folder)
    t = truth(rng)
    g = np.arange(5) * 130.0
    B = np.array([[x, y, 0.0] for x in g for y in g])
    poses = [
        (np.eye(3), (100, 50, -60)),
        (rotation(np.array([0, 0, 0.3])), (350, 80, 360)),
        (rotation(np.array([np.pi / 2, 0, 0])), (150, 400, -60)),
        (rotation(np.array([0, -np.pi / 2, 0])), (650, 100, -60)),
    ]
    rows = ["pose,X,Y,Z,x,y,z"]
    for k, (R, tr) in enumerate(poses, start=1):
        W = B @ np.asarray(R).T + np.asarray(tr, dtype=float)
        if not WITH_TOOL:  # the same balls, 120 mm higher: where the tool tip would be
            W[:, 2] += 120.0
        P = commanded_for(machine, t, W, TOOL if WITH_TOOL else None)
        P = P + rng.normal(0, 0.0004, W.shape)
        for p, b in zip(P, B, strict=True):
            rows.append(f"p{k},{p[0]:.6f},{p[1]:.6f},{p[2]:.6f},{b[0]:g},{b[1]:g},{b[2]:g}")
    (folder / "plate.csv").write_text("\n".join(rows) + "\n")
    spec = {"kind": "points", "file": "plate.csv", "u_um": 0.4}
    return problem_from_dict(config({"plate": spec}), folder, "bench.toml")


def station_problem(folder: Path, rng, n: int = 500):
    machine = machine_from_dict(base(), folder)
    t = truth(rng)
    P = np.column_stack([rng.uniform(TRAVEL[a][0] + 1, TRAVEL[a][1] - 1, n) for a in "XYZ"])
    Q = actual_positions(machine, t, P, TOOL if WITH_TOOL else None)
    stations = {
        "S1": (-400.0, -300.0, 200.0),
        "S2": (1400.0, -250.0, 400.0),
        "S3": (1300.0, 1100.0, 150.0),
        "S4": (-300.0, 1000.0, 700.0),
    }
    rows = ["station,X,Y,Z,reading_um"]
    for s, S in stations.items():
        d = np.linalg.norm(Q - np.asarray(S), axis=1)
        reading = 1000.0 * (d - d.min() + 0.1) + rng.normal(0, 0.2, n)
        for p, r in zip(P, reading, strict=True):
            rows.append(f"{s},{p[0]:.5f},{p[1]:.5f},{p[2]:.5f},{r:.5f}")
    (folder / "tracker.csv").write_text("\n".join(rows) + "\n")
    spec = {
        "kind": "stations",
        "file": "tracker.csv",
        "u_um": 0.2,
        "stations": {s: [v + 10.0 for v in S] for s, S in stations.items()},
    }
    return problem_from_dict(config({"tracker": spec}), folder, "bench.toml")


def _median(f, repeat: int) -> float:
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        f()
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--tool", action="store_true", help="all 21 at one tool offset")
    args = parser.parse_args()
    threads = os.environ.get("OPENBLAS_NUM_THREADS", "unset (the OpenBLAS default)")
    print(
        f"cores {os.cpu_count()}, load average {os.getloadavg()[0]:.2f}, "
        f"OPENBLAS_NUM_THREADS {threads}"
    )
    rng = np.random.default_rng(7)
    with tempfile.TemporaryDirectory() as tmp:
        for label, make in (
            ("ball plate 25 balls x 4 poses", plate_problem),
            ("tracker 4 stations x 500 positions", station_problem),
        ):
            folder = Path(tmp) / label.split()[0]
            folder.mkdir()
            problem = make(folder, rng)
            result = identify(problem, volumetric=False)  # warm up (imports)
            ident = result.identifiability
            m, n = ident.readings, ident.parameters
            t_fit = _median(lambda p=problem: identify(p, volumetric=False), args.repeat)
            t_plan = _median(lambda p=problem: plan(p), args.repeat)
            A = np.random.default_rng(1).standard_normal((m, n))
            b = np.random.default_rng(2).standard_normal(m)
            t_ref = _median(lambda A=A, b=b: np.linalg.lstsq(A, b, rcond=None), args.repeat)
            unseen = len(ident.combinations) + len(ident.invisible)
            print(
                f"{label}: {m} residuals x {n} parameters (rank {ident.rank}, {unseen} "
                f"unseen directions, Birge ratio {result.birge:.3g})"
            )
            print(f"  identify with covariance  {t_fit:8.3f} s")
            print(f"  --plan                    {t_plan:8.3f} s")
            print(f"  one numpy lstsq {m} x {n}  {t_ref:8.4f} s (reference)")
            print(
                f"  ratio to the reference: identify {t_fit / t_ref:.0f}, "
                f"--plan {t_plan / t_ref:.0f}"
            )


if __name__ == "__main__":
    main()
