"""Speed of ``esp identify`` on a rotary table.

The A/C trunnion of data/examples/rotary (its chain and geometry), readings made through
its exact 4x4 chain with normal noise:

1. KinematicsOpt size: one sphere probed at 37 settings, three axes' worth of positions
   (C every 30 deg at A = 0, A every 15 deg over -90..90 at C = 0, C every 30 deg at A =
   60), the 8 location errors;
2. an R-test of 500 settings along four paths (C turning at A = 0 and 45, A tilting at
   C = 0 and 90), three sensors zeroed per path; the 5 location errors it sees and the
   angular positioning errors of C (Fourier order 6) and of A (Legendre degree 6).

Each is timed as ``esp.identify.run.identify(problem, volumetric=False)`` (the fit, the
identifiability, the covariance, the valuations, the axis lines and the residuals before
and after) and ``plan(problem)``, next to two references: one ``numpy.linalg.lstsq`` of a random
matrix of the size of the final Jacobian, and one ``table_terms`` of the table at the
readings' settings (the first-order evaluation of the table ``esp analyse`` makes, of
which the design matrix is made). The rank is printed and must equal the number of
parameters.

Times are wall-clock seconds (``time.perf_counter``) and the process' CPU seconds
(``time.process_time``), medians of ``--repeat`` runs; the load average is printed first.

Run:  OPENBLAS_NUM_THREADS=1 python benchmarks/identify_rotary.py [--repeat N]
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from _host import cores_load_threads, median_times  # noqa: E402  (beside this script)

from esp.config.devices import load_table  # noqa: E402
from esp.identify.config import load_problem  # noqa: E402
from esp.identify.run import identify, plan  # noqa: E402
from esp.identify.simulate import probed_centres  # noqa: E402

CHAIN = Path(__file__).resolve().parent.parent / "data/examples/rotary/trunnion-ac.toml"
LOCATION = {
    "X0C": 6.0,
    "Y0C": -9.0,
    "A0C": 12.1,
    "B0C": -8.0,
    "Y0A": 14.0,
    "Z0A": -11.0,
    "B0A": 10.0,
    "C0A": -15.0,
}
MACHINE = """
[machine]
name = "benchmark"
configuration = "BwMTt"
axes = {{ bottom = "X", middle = "Y", top = "Z" }}

[table]
file = "table.toml"
angles = {{ A = [-90, 0, 90], C = [0, 90, 180, 270] }}

[axes.X]
travel = [-200, 800]
step = 100

[axes.Y]
travel = [-400, 400]
step = 100

[axes.Z]
travel = [-400, 500]
step = 100

[identify]
{identify}

[identify.measurements.m]
{measurement}
"""


def _table(folder: Path, extra: str = "") -> None:
    errors = "\n".join(f"{k} = {{ identify = true }}" for k in LOCATION) + "\n" + extra
    (folder / "table.toml").write_text(
        f'[table]\nchain = "{CHAIN.as_posix()}"\n[table.parameters]\nx_C = 300\nx_A = 300\n'
        f"z_A = 100\n[table.errors]\n{errors}\n",
        encoding="utf-8",
    )


def spheres(folder: Path, rng: np.random.Generator):
    _table(folder)
    (folder / "machine.toml").write_text(
        MACHINE.format(
            identify="k = 2",
            measurement='kind = "sphere"\nfile = "s.csv"\nu_um = 0.5',
        ),
        encoding="utf-8",
    )
    table = load_table(folder / "table.toml")
    C = np.arange(0.0, 360.0, 30.0)
    A = np.arange(-90.0, 91.0, 15.0)
    a = np.concatenate([np.zeros_like(C), A, np.full_like(C, 60.0)])
    c = np.concatenate([C, np.zeros_like(A), C])
    m = probed_centres(table, LOCATION, {"A": a, "C": c}, (450.0, 0.0, 40.0))
    m = m + rng.normal(0.0, 0.0005, m.shape)
    rows = ["sphere,A,C,X,Y,Z"] + [
        f"S1,{x:g},{y:g},{p[0]:.6f},{p[1]:.6f},{p[2]:.6f}" for x, y, p in zip(a, c, m, strict=True)
    ]
    (folder / "s.csv").write_text("\n".join(rows) + "\n", encoding="utf-8")
    return load_problem(folder / "machine.toml")


def rtest(folder: Path, rng: np.random.Generator):
    _table(
        folder,
        'ECC = { identify = { basis = "fourier", order = 6 } }\n'
        'EAA = { identify = { basis = "legendre", degree = 6 } }\n',
    )
    (folder / "machine.toml").write_text(
        MACHINE.format(
            identify='k = 2\nfix = ["table.X0C", "table.Y0A", "table.Z0A"]',
            measurement='kind = "rtest"\nfile = "r.csv"\nu_um = 0.3\n'
            "sensors = { d1 = [1, 0, 0], d2 = [0, 1, 0], d3 = [0, 0, 1] }",
        ),
        encoding="utf-8",
    )
    table = load_table(folder / "table.toml")
    r = np.radians

    truth = dict(
        LOCATION,
        ECC=lambda x: 8 * np.cos(r(x)) - 5 * np.sin(r(2 * x)) + np.cos(r(5 * x)),
        EAA=lambda x: 6 * np.asarray(x) / 90 + 2 * (np.asarray(x) / 90) ** 2,
    )
    C = np.linspace(0.0, 360.0, 125, endpoint=False)
    A = np.linspace(-90.0, 90.0, 125)
    paths = {
        "K1": (np.zeros_like(C), C),
        "K2": (A, np.zeros_like(A)),
        "K3": (A, np.full_like(A, 90.0)),
        "K4": (np.full_like(C, 45.0), C),
    }
    rows = ["path,A,C,X,Y,Z,d1_um,d2_um,d3_um"]
    s = (450.0, 0.0, 40.0)
    for name, (a, c) in paths.items():
        p = probed_centres(table, {}, {"A": a, "C": c}, s)
        q = probed_centres(table, truth, {"A": a, "C": c}, s)
        d = 1000.0 * (q - p)
        d = d - d[0] + rng.normal(0.0, 0.3, d.shape)
        rows += [
            f"{name},{x:g},{y:g},{pp[0]:.6f},{pp[1]:.6f},{pp[2]:.6f},{v[0]:.4f},{v[1]:.4f},{v[2]:.4f}"
            for x, y, pp, v in zip(a, c, p, d, strict=True)
        ]
    (folder / "r.csv").write_text("\n".join(rows) + "\n", encoding="utf-8")
    return load_problem(folder / "machine.toml")


def _angles(problem) -> dict[str, np.ndarray]:
    """The settings of the problem's one measurement set, from its file."""
    from esp.identify.tables import read_table

    spec = problem.measurements[0]
    coords = problem.machine.table.table.coordinates
    data = read_table(spec.files[0], coords)
    return {c: np.asarray(data.columns[c], dtype=float) for c in coords}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    print(cores_load_threads())
    rng = np.random.default_rng(11)
    with tempfile.TemporaryDirectory() as tmp:
        for label, make in (
            ("probed sphere, 37 settings, 8 location errors", spheres),
            ("R-test, 500 settings, errors of order 6", rtest),
        ):
            folder = Path(tmp) / make.__name__
            folder.mkdir()
            problem = make(folder, rng)
            result = identify(problem, volumetric=False)  # warm up (imports)
            ident = result.identifiability
            if not ident.identifiable:
                raise SystemExit(f"{label}: not identifiable: {ident.sentences()}")
            m, n = ident.readings, ident.parameters
            t_fit, c_fit = median_times(
                lambda p=problem: identify(p, volumetric=False), args.repeat
            )
            t_plan, c_plan = median_times(lambda p=problem: plan(p), args.repeat)
            A = np.random.default_rng(1).standard_normal((m, n))
            b = np.random.default_rng(2).standard_normal(m)
            t_ref, _ = median_times(lambda A=A, b=b: np.linalg.lstsq(A, b, rcond=None), args.repeat)
            from esp.core.devices import table_terms

            table = problem.machine.table.table
            block_angles = _angles(problem)
            t_terms, _ = median_times(
                lambda t=table, a=block_angles: table_terms(t, a), args.repeat
            )
            print(
                f"{label}: {m} residuals x {n} parameters (rank {ident.rank}, condition "
                f"number {ident.condition:.3g}, Birge ratio {result.birge:.3g})"
            )
            print(f"  identify with covariance  {t_fit:8.3f} s (CPU {c_fit:.3f} s)")
            print(f"  --plan                    {t_plan:8.3f} s (CPU {c_plan:.3f} s)")
            print(f"  one numpy lstsq {m} x {n}  {t_ref:8.4f} s (reference)")
            size = len(next(iter(block_angles.values())))
            print(f"  one table_terms at {size} settings  {t_terms:8.4f} s (reference)")
            print(
                f"  ratio to lstsq: identify {t_fit / t_ref:.0f}, --plan {t_plan / t_ref:.0f}; "
                f"to table_terms: identify {t_fit / t_terms:.1f}, --plan {t_plan / t_terms:.1f}"
            )


if __name__ == "__main__":
    main()
