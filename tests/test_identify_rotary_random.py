"""Random five-axis machines identified from probed spheres (docs/identify.md, "Rotary
tables"): the three kinds of rotary axes -- two on a table (an A/C trunnion of random
geometry), two on a head (the angle head, random errors), one on each (the head over a B
table) -- with random errors and an angular positioning error of C partly outside its
fitted basis (a 5th harmonic beside the 3 the basis holds), readings through the exact
chains with normal noise. The identified values lie within ± U (k = 2) at about the
stated coverage. Marked slow (about 8 s): ``python -m pytest -m slow``."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from esp.config.devices import load_head, load_table
from esp.core.devices.head_evaluate import evaluate_head
from esp.identify.config import load_problem
from esp.identify.run import identify
from esp.identify.simulate import probed_centres

ROOT = Path(__file__).resolve().parent.parent
TRUNNION = (ROOT / "data/examples/rotary/trunnion-ac.toml").as_posix()
HEAD = (ROOT / "data/examples/heads/angle-head.toml").as_posix()
LOCATION = ("X0C", "Y0C", "A0C", "B0C", "Y0A", "Z0A", "B0A", "C0A")
HEAD_ERRORS = ("ThetaAs", "Ocx", "Ocy", "ThetaCh", "ThetaCv")
U_UM = 0.5

AXES = """
[axes.X]
travel = [-400, 1000]
step = 100

[axes.Y]
travel = [-600, 1500]
step = 100

[axes.Z]
travel = [-400, 700]
step = 100

[identify]
k = 2

[identify.measurements.sphere]
kind = "sphere"
file = "spheres.csv"
u_um = 0.5
"""


def _inside(result, truth: dict) -> tuple[int, int]:
    inside = total = 0
    for c in result.curves:
        symbol = c.name.split(".", 1)[1]
        f = truth[symbol]
        if c.angle_axis is None:
            inside += abs(c.values[0] - f) <= c.U[0]
            total += 1
        else:
            t = np.asarray(c.targets_mm)[::20]
            v, U = np.asarray(c.values)[::20], np.asarray(c.U)[::20]
            inside += int(np.sum(np.abs(v - f(t)) <= U))
            total += t.size
    return inside, total


def _trunnion(folder: Path, rng: np.random.Generator) -> tuple[Path, dict]:
    x_c, z_a = rng.uniform(200, 500), rng.uniform(60, 160)
    errors = "\n".join(f"{k} = {{ identify = true }}" for k in LOCATION)
    errors += '\nECC = { identify = { basis = "fourier", order = 3 } }'
    (folder / "table.toml").write_text(
        f'[table]\nchain = "{TRUNNION}"\n[table.parameters]\nx_C = {x_c}\nx_A = {x_c}\n'
        f"z_A = {z_a}\n[table.errors]\n{errors}\n",
        encoding="utf-8",
    )
    (folder / "machine.toml").write_text(
        '[machine]\nname = "t"\nconfiguration = "BwMTt"\n'
        'axes = { bottom = "X", middle = "Y", top = "Z" }\n'
        '[table]\nfile = "table.toml"\nangles = { A = [-90, 0, 90], C = [0, 90, 180, 270] }\n'
        + AXES,
        encoding="utf-8",
    )
    a1, a2, a3, a5 = rng.normal(0, 6, 4)

    def ecc(c):
        r = np.radians(np.asarray(c, dtype=float))
        return a1 * np.cos(r) + a2 * np.sin(2 * r) + a3 * np.cos(3 * r) + 0.02 * a5 * np.sin(5 * r)

    truth = {k: float(rng.normal(0, 10)) for k in LOCATION} | {"ECC": ecc}
    table = load_table(folder / "table.toml")
    C = np.arange(0.0, 360.0, 20.0)
    A = np.arange(-90.0, 91.0, 15.0)
    a = np.concatenate([np.zeros_like(C), A, np.full_like(C, 60.0)])
    c = np.concatenate([C, np.zeros_like(A), C])
    rows = ["sphere,A,C,X,Y,Z"]
    for k in range(2):
        s = (x_c + rng.uniform(80, 200), rng.uniform(-60, 60), rng.uniform(20, 150))
        m = probed_centres(table, truth, {"A": a, "C": c}, s)
        m = m + rng.normal(0, U_UM / 1000.0, m.shape)
        rows += [
            f"S{k},{x:g},{y:g},{p[0]:.7f},{p[1]:.7f},{p[2]:.7f}"
            for x, y, p in zip(a, c, m, strict=True)
        ]
    (folder / "spheres.csv").write_text("\n".join(rows) + "\n", encoding="utf-8")
    return folder / "machine.toml", truth


def _head(folder: Path, rng: np.random.Generator, table: bool) -> tuple[Path, dict]:
    errors = "\n".join(f"{k} = {{ identify = true }}" for k in HEAD_ERRORS)
    g = rng.uniform(100, 250)
    (folder / "head.toml").write_text(
        f'[head]\nchain = "{HEAD}"\n[head.parameters]\nG = {g}\ne = 10\nYp = 50\n'
        f"[head.errors]\n{errors}\nOas = 0\nThetaAv = 0\nDY = 0\n",
        encoding="utf-8",
    )
    section = ""
    truth: dict = {
        "ThetaAs": float(rng.normal(0, 60)),
        "Ocx": float(rng.normal(0, 0.01)),
        "Ocy": float(rng.normal(0, 0.01)),
        "ThetaCh": float(rng.normal(0, 60)),
        "ThetaCv": float(rng.normal(0, 60)),
    }
    if table:
        (folder / "b.toml").write_text(
            '[chain]\nname = "B"\n[symbols]\nB = { kind = "coordinate", unit = "deg" }\n'
            'x_B = { kind = "parameter", unit = "mm", value = 0 }\n'
            'X0B = { kind = "error", unit = "um" }\nZ0B = { kind = "error", unit = "um" }\n'
            'A0B = { kind = "error", unit = "urad" }\nC0B = { kind = "error", unit = "urad" }\n'
            '[[steps]]\ntranslate = ["x_B", 0, 0]\n[[steps]]\nrevolute = "y"\ncoordinate = "B"\n'
            '[[steps]]\nerrors = { tx = "-X0B", tz = "-Z0B", rx = "-A0B", rz = "-C0B" }\n'
            '[[steps]]\ntranslate = ["-x_B", 0, 0]\n',
            encoding="utf-8",
        )
        names = ("X0B", "Z0B", "A0B", "C0B")
        (folder / "table.toml").write_text(
            '[table]\nchain = "b.toml"\n[table.parameters]\nx_B = 400\n[table.errors]\n'
            + "\n".join(f"{k} = {{ identify = true }}" for k in names)
            + "\n",
            encoding="utf-8",
        )
        section = '[table]\nfile = "table.toml"\nangles = { B = [-90, 0, 90] }\n'
        truth |= {k: float(rng.normal(0, 10)) for k in names}
    (folder / "machine.toml").write_text(
        '[machine]\nname = "h"\nconfiguration = "wBMTt"\n'
        'axes = { bottom = "Y", middle = "X", top = "Z" }\n[analysis]\npoint = "TCP"\n'
        '[head]\nfile = "head.toml"\nangles = { A = [0, 90, 180, 270], C = [0, 90, 180, 270] }\n'
        + section
        + AXES,
        encoding="utf-8",
    )
    head, _ = load_head(folder / "head.toml")
    A, C = np.meshgrid(np.arange(0.0, 360.0, 45.0), np.arange(0.0, 360.0, 60.0))
    A, C = A.ravel(), C.ravel()
    exact = evaluate_head(head.with_values({k: truth[k] for k in HEAD_ERRORS}), {"A": A, "C": C})
    rows = ["sphere,B,A,C,X,Y,Z" if table else "sphere,A,C,X,Y,Z"]
    settings = (-60.0, 0.0, 60.0) if table else (None,)
    spheres = ((550.0, 0.0, 80.0), (300.0, 60.0, 150.0)) if table else ((500.0, 400.0, 100.0),)
    for k, s in enumerate(spheres):
        for b in settings:
            if b is None:
                target = np.tile(s, (A.size, 1))
            else:
                tb = load_table(folder / "table.toml")
                target = probed_centres(
                    tb,
                    {n: truth[n] for n in ("X0B", "Z0B", "A0B", "C0B")},
                    {"B": np.full(A.size, b)},
                    s,
                )
            m = target - exact.exact_um / 1000.0 + rng.normal(0, U_UM / 1000.0, target.shape)
            lead = f"S{k}," + ("" if b is None else f"{b:g},")
            rows += [
                f"{lead}{x:g},{y:g},{p[0]:.7f},{p[1]:.7f},{p[2]:.7f}"
                for x, y, p in zip(A, C, m, strict=True)
            ]
    (folder / "spheres.csv").write_text("\n".join(rows) + "\n", encoding="utf-8")
    return folder / "machine.toml", truth


@pytest.mark.slow
@pytest.mark.parametrize("kind", ["table-table", "head-head", "head-table"])
def test_random_five_axis_machines_lie_within_their_U(tmp_path, kind):
    inside = total = 0
    for seed in range(40):
        rng = np.random.default_rng(1000 + seed)
        folder = tmp_path / str(seed)
        folder.mkdir()
        if kind == "table-table":
            path, truth = _trunnion(folder, rng)
        else:
            path, truth = _head(folder, rng, table=kind == "head-table")
        result = identify(load_problem(path), volumetric=False)
        assert result.birge < 1.4, (kind, seed, result.birge)  # no bias of the basis
        i, t = _inside(result, truth)
        inside += i
        total += t
    assert 0.9 <= inside / total <= 0.99, (kind, inside / total)
