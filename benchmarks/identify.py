"""Speed of ``esp identify``.

All 21 components of a wBMTt machine (the linear, two straightness and three angular
errors of each axis and the three squareness values) identified with Legendre degree 5
(squareness: one number), from data made through the exact 4x4 chain:

1. a ball plate of 25 balls in 4 poses, each ball probed with the four styli of a star
   probe (offsets from the MCP not in one plane: with them the angles of the axis nearest
   the tool and the styli's own orientation are seen about every direction; three styli,
   which always lie in one plane, leave one combination of the styli's orientation with
   the angles and the linear error of Z at degree 5 all but unseen, its singular value
   2.5e-7 of the largest; docs/identify.md);
2. a tracking interferometer at 4 stations x 500 positions, the reflector at three
   offsets (a third of the positions each).

At the MCP alone (one stylus) only 17 of the 21 act (the angles of the top axis and the
middle axis' rotation about it have no lever there), and this plate of 25 balls in 4
poses does not see every combination of those 17 curves of degree 5 either: esp refuses
it and names the combinations (docs/identify.md, "Tool offsets").

Each is timed as ``esp.identify.run.identify(problem, volumetric=False)`` (the fit, the
identifiability and the covariance; the volumetric accuracy is one ``esp analyse`` of the
identified machine, timed in benchmarks/synthesis.py) and ``plan(problem)``, next to the
reference: one ``numpy.linalg.lstsq`` of a random matrix of the same size as the final
Jacobian. The benchmark refuses to time a plan that does not identify every component:
the rank is printed and must equal the number of parameters.

esp sets no thread count; OpenBLAS' default threading on a loaded machine of few cores
is slow, so the figures in docs/ are taken with ``OPENBLAS_NUM_THREADS=1`` (printed).
Times are wall-clock seconds (``time.perf_counter``) and the process' CPU seconds
(``time.process_time``), medians of ``--repeat`` runs; the load average is printed first:
on a shared machine quote the figures with the load.

Run:  OPENBLAS_NUM_THREADS=1 python benchmarks/identify.py [--repeat N]
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from _host import cores_load_threads, median_times  # noqa: E402  (beside this script)

from esp.config import machine_from_dict  # noqa: E402
from esp.identify.config import problem_from_dict  # noqa: E402
from esp.identify.model import rotation  # noqa: E402
from esp.identify.run import identify, plan  # noqa: E402
from esp.identify.simulate import actual_positions, commanded_for  # noqa: E402

TRAVEL = {"X": (0.0, 1000.0), "Y": (0.0, 800.0), "Z": (0.0, 600.0)}
#: the styli of the star probe (the reflector offsets), mm from the MCP: the first three
#: are the tracker's reflector offsets; the plate is probed with all four
TOOLS = ((0.0, 0.0, -60.0), (120.0, 0.0, -100.0), (0.0, 120.0, -100.0), (-120.0, 0.0, -100.0))
#: how many of TOOLS the tracker's reflector takes
REFLECTORS = 3
DEGREE = 5


def base() -> dict:
    return {
        "machine": {
            "name": "benchmark",
            "configuration": "wBMTt",
            "axes": {"bottom": "Y", "middle": "X", "top": "Z"},
        },
        "axes": {a: {"travel": list(TRAVEL[a]), "step": 100} for a in "XYZ"},
    }


def tools() -> tuple[tuple[float, float, float], ...]:
    return TOOLS


def config(measurements: dict) -> dict:
    d = base()
    spec = {"identify": {"basis": "legendre", "degree": DEGREE}}
    for a in "XYZ":
        errors: dict = {"linear": dict(spec), "straightness": {}, "angular": {}}
        for b in "XYZ":
            errors["angular"][b] = dict(spec)
            if b != a:
                errors["straightness"][b] = dict(spec)
        d["axes"][a]["errors"] = errors
    d["squareness"] = {p: {"identify": True} for p in ("XY", "XZ", "YZ")}
    d["identify"] = {"measurements": measurements}
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
    g = np.arange(5) * 110.0
    B = np.array([[x, y, 0.0] for x in g for y in g])
    poses = [
        (np.eye(3), (150, 150, 10)),
        (rotation(np.array([0, 0, 0.3])), (400, 180, 400)),
        (rotation(np.array([np.pi / 2, 0, 0])), (150, 400, 10)),
        (rotation(np.array([0, -np.pi / 2, 0])), (700, 150, 10)),
    ]
    styli = {f"T{j}": tool for j, tool in enumerate(tools())}
    rows = ["pose,tool,X,Y,Z,x,y,z"]
    for k, (R, tr) in enumerate(poses, start=1):
        W = B @ np.asarray(R).T + np.asarray(tr, dtype=float)
        for label, tool in styli.items():  # every ball probed with every stylus
            P = commanded_for(machine, t, W, dict(zip("XYZ", tool, strict=True)))
            P = P + rng.normal(0, 0.0004, W.shape)
            for p, b in zip(P, B, strict=True):
                rows.append(
                    f"p{k},{label},{p[0]:.6f},{p[1]:.6f},{p[2]:.6f},{b[0]:g},{b[1]:g},{b[2]:g}"
                )
    (folder / "plate.csv").write_text("\n".join(rows) + "\n")
    spec = {
        "kind": "points",
        "file": "plate.csv",
        "u_um": 0.4,
        "tool_mm": {label: list(tool) for label, tool in styli.items()},
    }
    sets = {"plate": spec}
    return problem_from_dict(config(sets), folder, "bench.toml")


def station_problem(folder: Path, rng, n: int = 500):
    machine = machine_from_dict(base(), folder)
    t = truth(rng)
    stations = {
        "S1": (-400.0, -300.0, 200.0),
        "S2": (1400.0, -250.0, 400.0),
        "S3": (1300.0, 1100.0, 150.0),
        "S4": (-300.0, 1000.0, 700.0),
    }
    sets = {}
    offsets = tools()[:REFLECTORS]
    for j, tool in enumerate(offsets):
        m = n // len(offsets) + (1 if j < n % len(offsets) else 0)
        lo = {a: TRAVEL[a][0] + 1 for a in "XYZ"}
        hi = {a: TRAVEL[a][1] - 1 for a in "XYZ"}
        P = np.column_stack([rng.uniform(lo[a], hi[a], m) for a in "XYZ"])
        Q = actual_positions(machine, t, P, dict(zip("XYZ", tool, strict=True)))
        rows = ["station,X,Y,Z,reading_um"]
        for s, S in stations.items():
            d = np.linalg.norm(Q - np.asarray(S), axis=1)
            reading = 1000.0 * (d - d.min() + 0.1) + rng.normal(0, 0.2, m)
            for p, r in zip(P, reading, strict=True):
                rows.append(f"{s},{p[0]:.5f},{p[1]:.5f},{p[2]:.5f},{r:.5f}")
        (folder / f"tracker{j}.csv").write_text("\n".join(rows) + "\n")
        sets[f"tracker{j}"] = {
            "kind": "stations",
            "file": f"tracker{j}.csv",
            "u_um": 0.2,
            "tool_mm": list(tool),
            "stations": {s: [v + 10.0 for v in S] for s, S in stations.items()},
        }
    return problem_from_dict(config(sets), folder, "bench.toml")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    print(cores_load_threads())
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
            t_fit, c_fit = median_times(
                lambda p=problem: identify(p, volumetric=False), args.repeat
            )
            t_plan, c_plan = median_times(lambda p=problem: plan(p), args.repeat)
            A = np.random.default_rng(1).standard_normal((m, n))
            b = np.random.default_rng(2).standard_normal(m)
            t_ref, _ = median_times(lambda A=A, b=b: np.linalg.lstsq(A, b, rcond=None), args.repeat)
            if not ident.identifiable:
                raise SystemExit(f"{label}: not identifiable: {ident.sentences()}")
            print(
                f"{label}: {len(result.curves)} components of degree {DEGREE}, {m} residuals x "
                f"{n} parameters (rank {ident.rank}, condition number {ident.condition:.3g}, "
                f"Birge ratio {result.birge:.3g}, {sum(1 for _ in result.sets)} sets)"
            )
            print(f"  identify with covariance  {t_fit:8.3f} s (CPU {c_fit:.3f} s)")
            print(f"  --plan                    {t_plan:8.3f} s (CPU {c_plan:.3f} s)")
            print(f"  one numpy lstsq {m} x {n}  {t_ref:8.4f} s (reference)")
            print(
                f"  ratio to the reference: identify {t_fit / t_ref:.0f}, "
                f"--plan {t_plan / t_ref:.0f}"
            )


if __name__ == "__main__":
    main()
