"""Synthetic identification problems for the tests: a small bridge CMM whose errors lie in
the fitted basis, measured by a ball plate through the exact 4x4 chain."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from esp.config import machine_from_dict
from esp.identify.basis import legendre_values
from esp.identify.model import rotation
from esp.identify.simulate import actual_positions, commanded_for

TRAVEL = {"X": (0.0, 800.0), "Y": (0.0, 600.0), "Z": (0.0, 500.0)}
ROLES = {"bottom": "Y", "middle": "X", "top": "Z"}
#: the components a ball plate identifies on this machine at the MCP
COMPONENTS = (
    "X.linear",
    "X.straightness.Y",
    "X.straightness.Z",
    "X.angular.X",
    "X.angular.Y",
    "Y.linear",
    "Y.straightness.X",
    "Y.straightness.Z",
    "Y.angular.X",
    "Y.angular.Y",
    "Y.angular.Z",
    "Z.linear",
    "Z.straightness.X",
    "Z.straightness.Y",
)


def base(name: str = "test CMM") -> dict:
    return {
        "machine": {"name": name, "configuration": "wBMTt", "axes": dict(ROLES)},
        "analysis": {"datum": "negative"},
        "axes": {a: {"travel": list(TRAVEL[a]), "step": 100} for a in "XYZ"},
    }


def in_basis_truth(rng, degree: int = 2) -> dict:
    """Curves inside the Legendre basis of ``degree`` (zero at the low end; straightness
    without constant and slope), squareness values."""
    truth: dict = {}
    for name in COMPONENTS:
        a, kind = name.split(".")[0], name.split(".")[1]
        lo, hi = TRAVEL[a]
        first = 2 if kind == "straightness" else 1
        c = rng.normal(0, 2.0, degree + 1 - first)

        def f(x, c=c, lo=lo, hi=hi, first=first):
            u = (2 * np.asarray(x, dtype=float) - lo - hi) / (hi - lo)
            v = legendre_values(u, degree)[:, first:] @ c
            if first == 1:
                v = v - legendre_values(np.array([-1.0]), degree)[:, first:] @ c
            return v

        truth[name] = f
    truth.update({"squareness.XY": 4.0, "squareness.XZ": -3.0, "squareness.YZ": 2.5})
    return truth


POSES = [
    (np.eye(3), (100, 20, 40)),
    (rotation(np.array([0, 0, 0.3])), (300, 50, 460)),
    (rotation(np.array([np.pi / 2, 0, 0])), (150, 300, 40)),
    (rotation(np.array([0, -np.pi / 2, 0])), (420, 100, 40)),
]


def plate_positions(machine, truth, poses=POSES, n: int = 5, pitch: float = 100.0):
    """(pose label, commanded P, plate B) of every ball."""
    g = np.arange(n) * pitch
    B = np.array([[x, y, 0.0] for x in g for y in g])
    out = []
    for k, (R, t) in enumerate(poses, start=1):
        W = B @ np.asarray(R).T + np.asarray(t, dtype=float)
        out.append((f"p{k}", commanded_for(machine, truth, W), B))
    return out


def write_plate(path: Path, positions, rng=None, u_um: float = 0.4) -> None:
    rows = ["pose,X,Y,Z,x,y,z"]
    for label, P, B in positions:
        if rng is not None:
            P = P + rng.normal(0, u_um / 1000.0, P.shape)
        for p, b in zip(P, B, strict=True):
            rows.append(f"{label},{p[0]:.9f},{p[1]:.9f},{p[2]:.9f},{b[0]:g},{b[1]:g},{b[2]:g}")
    path.write_text("\n".join(rows) + "\n", encoding="utf-8")


def identify_config(degree: int = 2, measurements: dict | None = None) -> dict:
    d = base()
    spec = {"identify": {"basis": "legendre", "degree": degree}}
    for name in COMPONENTS:
        a, kind, *rest = name.split(".")
        errors = d["axes"][a].setdefault("errors", {})
        if kind == "linear":
            errors["linear"] = dict(spec)
        else:
            errors.setdefault(kind, {})[rest[0]] = dict(spec)
    d["squareness"] = {p: {"identify": True} for p in ("XY", "XZ", "YZ")}
    d["identify"] = {"measurements": measurements or {}}
    return d


def known_machine(tmp: Path | None = None):
    return machine_from_dict(base(), tmp or Path("."))


def actual(machine, truth, P):
    return actual_positions(machine, truth, P)


# --- random machines of the four stackings, all 21 components, with tool offsets ---------

STACKINGS = ("wBMTt", "BwMTt", "BMwTt", "BMTwt")
SQUARENESS_PAIRS = ("XY", "XZ", "YZ")


def all_components() -> tuple[str, ...]:
    """The 21 component names of three linear axes (ISO 230-1): per axis one linear, two
    straightness and three angular errors, and the three squareness values."""
    out = []
    for a in "XYZ":
        out.append(f"{a}.linear")
        out += [f"{a}.straightness.{b}" for b in "XYZ" if b != a]
        out += [f"{a}.angular.{b}" for b in "XYZ"]
    return (*out, *(f"squareness.{p}" for p in SQUARENESS_PAIRS))


def random_base(rng, configuration: str) -> dict:
    """A machine of ``configuration`` with a random order of the axes in the chain and
    random travels (300 .. 1000 mm)."""
    order = [str(a) for a in rng.permutation(list("XYZ"))]
    travel = {a: (0.0, float(rng.choice([300, 400, 500, 600, 800, 1000]))) for a in "XYZ"}
    return {
        "machine": {
            "name": f"random {configuration}",
            "configuration": configuration,
            "axes": {"bottom": order[0], "middle": order[1], "top": order[2]},
        },
        "analysis": {"datum": "negative"},
        "axes": {a: {"travel": list(travel[a]), "step": 100} for a in "XYZ"},
    }


def travel_of(base_dict: dict) -> dict:
    return {a: tuple(base_dict["axes"][a]["travel"]) for a in "XYZ"}


def legendre_truth(rng, travel: dict, names, degree: int = 2, size: float = 2.0) -> dict:
    """Curves inside the fitted Legendre basis of ``degree`` (zero at the low end; a
    straightness without constant and slope on the targets), squareness values."""
    truth: dict = {}
    for name in names:
        if name.startswith("squareness."):
            truth[name] = float(rng.normal(0.0, 3.0))
            continue
        a, kind = name.split(".")[:2]
        lo, hi = travel[a]
        first = 2 if kind == "straightness" else 1
        c = rng.normal(0, size, degree + 1 - first)

        def f(x, c=c, lo=lo, hi=hi, first=first):
            u = (2 * np.asarray(x, dtype=float) - lo - hi) / (hi - lo)
            v = legendre_values(u, degree)[:, first:] @ c
            if first == 1:
                v = v - legendre_values(np.array([-1.0]), degree)[:, first:] @ c
            return v

        truth[name] = f
    return truth


def sine_truth(rng, travel: dict, names, size: float = 2.0) -> dict:
    """Smooth curves outside every polynomial basis: two sines each, wavelengths longer
    than the travel, zero at the low end (a straightness: no slope at the start either)."""
    truth: dict = {}
    for name in names:
        if name.startswith("squareness."):
            truth[name] = float(rng.normal(0.0, 3.0))
            continue
        a = name.split(".")[0]
        lo, hi = travel[a]
        amp = rng.normal(0.0, size, 2)
        w = rng.uniform(0.6, 1.3, 2)
        phase = rng.uniform(0.0, np.pi)

        def f(x, amp=amp, w=w, phase=phase, lo=lo, hi=hi):
            u = (2 * np.asarray(x, dtype=float) - lo - hi) / (hi - lo) + 1.0  # 0 .. 2
            return amp[0] * np.sin(w[0] * u) + amp[1] * (np.sin(w[1] * u + phase) - np.sin(phase))

        truth[name] = f
    return truth


def without_line(f, targets):
    """f less its least-squares line on the targets: esp's straightness (its slope is a
    squareness, ISO 230-1 3.4.8)."""
    t = np.asarray(targets)
    G = np.c_[np.ones_like(t), t]
    coef = np.linalg.lstsq(G, f(t), rcond=None)[0]
    return lambda x: f(x) - (coef[0] + coef[1] * np.asarray(x, dtype=float))


def full_config(base_dict: dict, names, degree: int, measurements: dict) -> dict:
    """``base_dict`` with every component of ``names`` to identify (Legendre ``degree``)."""
    import copy

    d = copy.deepcopy(base_dict)
    spec = {"identify": {"basis": "legendre", "degree": degree}}
    for name in names:
        parts = name.split(".")
        if parts[0] == "squareness":
            d.setdefault("squareness", {})[parts[1]] = {"identify": True}
            continue
        errors = d["axes"][parts[0]].setdefault("errors", {})
        if parts[1] == "linear":
            errors["linear"] = dict(spec)
        else:
            errors.setdefault(parts[1], {})[parts[2]] = dict(spec)
    d["identify"] = {"measurements": measurements}
    return d


#: tracking-interferometer stations around a volume of 1000 mm at most
STATIONS = {
    "S1": (-400.0, -350.0, 200.0),
    "S2": (1400.0, -300.0, 450.0),
    "S3": (1350.0, 1300.0, 150.0),
    "S4": (-350.0, 1250.0, 700.0),
}
#: three reflector offsets from the MCP, not on one line: with them the rotation of the
#: axis nearest the tool is seen about every direction (docs/identify.md)
TOOLS = ((0.0, 0.0, 0.0), (150.0, 0.0, -100.0), (0.0, 150.0, -100.0))


def write_tracker(
    folder: Path,
    machine,
    truth: dict,
    rng,
    n: int,
    tools=TOOLS,
    stations=STATIONS,
    u_um: float = 0.2,
    noise: bool = False,
) -> dict:
    """A tracking interferometer's readings through the exact chain: ``n`` random
    positions per reflector offset, seen from every station (a file per offset); the
    measurement sets of ``[identify.measurements]``."""
    travel = {a: machine.axes[a].travel_mm for a in "XYZ"}
    sets = {}
    for k, tool in enumerate(tools):
        P = np.column_stack([rng.uniform(travel[a][0], travel[a][1], n) for a in "XYZ"])
        offset = dict(zip("XYZ", tool, strict=True))
        Q = actual_positions(machine, truth, P, offset)
        rows = ["station,X,Y,Z,reading_um"]
        for s, S in stations.items():
            dist = np.linalg.norm(Q - np.asarray(S), axis=1)
            reading = 1000.0 * (dist - dist.min())
            if noise:
                reading = reading + rng.normal(0.0, u_um, n)
            rows += [
                f"{s},{p[0]:.9f},{p[1]:.9f},{p[2]:.9f},{r:.7f}"
                for p, r in zip(P, reading, strict=True)
            ]
        name = f"tracker{k}"
        (folder / f"{name}.csv").write_text("\n".join(rows) + "\n", encoding="utf-8")
        sets[name] = {
            "kind": "stations",
            "file": f"{name}.csv",
            "u_um": u_um,
            "tool_mm": list(tool),
            "stations": {s: [v + 5.0 for v in S] for s, S in stations.items()},
        }
    return sets


def truth_at(name: str, truth: dict, targets) -> np.ndarray:
    """The true curve as esp writes it: a straightness without its least-squares line."""
    t = np.asarray(targets)
    v = truth[name](t)
    if ".straightness." in name:
        G = np.c_[np.ones_like(t), t]
        v = v - G @ np.linalg.lstsq(G, v, rcond=None)[0]
    return v


def plate_poses(travel: dict, tools=((0.0, 0.0, 0.0),), n: int = 5) -> tuple[np.ndarray, list]:
    """A plate of n x n balls and four poses where every stylus of ``tools`` reaches
    every ball inside the travel: flat low, flat high turned 0.3 rad about Z, upright
    along X, upright along Y (the plate's frame: balls in its xy plane)."""
    T = np.asarray(tools, dtype=float).reshape(-1, 3)
    lo = {a: travel[a][0] + max(0.0, T[:, i].max()) for i, a in enumerate("XYZ")}
    hi = {a: travel[a][1] + min(0.0, T[:, i].min()) for i, a in enumerate("XYZ")}
    span = {a: hi[a] - lo[a] for a in "XYZ"}
    pitch = 0.9 * min(span.values()) / (n + 1)
    g = np.arange(n) * pitch
    B = np.array([[x, y, 0.0] for x in g for y in g])
    m = {a: lo[a] + 0.05 * span[a] for a in "XYZ"}
    top = hi["Z"] - 0.05 * span["Z"]
    poses = [
        (np.eye(3), (m["X"], m["Y"], m["Z"])),
        (rotation(np.array([0, 0, 0.3])), (m["X"] + 0.3 * n * pitch, m["Y"], top)),
        (rotation(np.array([np.pi / 2, 0, 0])), (m["X"], m["Y"] + 0.5 * span["Y"], m["Z"])),
        (rotation(np.array([0, -np.pi / 2, 0])), (m["X"] + 0.5 * span["X"], m["Y"], m["Z"])),
    ]
    return B, poses


def write_plates(
    folder: Path, machine, truth: dict, tools=TOOLS, u_um: float = 0.4, n: int = 5
) -> dict:
    """A ball plate in four poses probed with each stylus of ``tools`` (offsets from the
    MCP), the balls' measured positions through the exact chain: one set per stylus."""
    travel = {a: machine.axes[a].travel_mm for a in "XYZ"}
    B, poses = plate_poses(travel, tools, n)
    sets = {}
    for k, tool in enumerate(tools):
        offset = dict(zip("XYZ", tool, strict=True))
        rows = ["pose,X,Y,Z,x,y,z"]
        for j, (R, t) in enumerate(poses, start=1):
            W = B @ np.asarray(R).T + np.asarray(t, dtype=float)
            P = commanded_for(machine, truth, W, offset)
            for p, b in zip(P, B, strict=True):
                rows.append(f"p{j},{p[0]:.9f},{p[1]:.9f},{p[2]:.9f},{b[0]:g},{b[1]:g},{b[2]:g}")
        name = f"plate{k}"
        (folder / f"{name}.csv").write_text("\n".join(rows) + "\n", encoding="utf-8")
        sets[name] = {"kind": "points", "file": f"{name}.csv", "u_um": u_um, "tool_mm": list(tool)}
    return sets


def truth_machine(problem, truth: dict):
    """The machine of ``problem`` with the true curves at its targets, through the same
    engine (esp.identify.run.identified_machine)."""
    from esp.identify.run import Curve, identified_machine

    curves = []
    for u in problem.unknowns:
        name = str(u.name)
        if u.basis is None:
            curves.append(Curve(name, u.key, "um/m", (), (float(truth[name]),), (0.0,), ()))
            continue
        t = np.asarray(u.basis.targets_mm)
        v = truth_at(name, truth, t)
        curves.append(Curve(name, u.key, "", tuple(t), tuple(v), (), ()))
    return identified_machine(problem, curves)


def write_diagonals(folder, machine, truth, names=("PPP", "NPP"), noise_um=0.0, rng=None):
    """ISO 230-6 diagonal readings through the exact chain: the displacement along each
    body diagonal of the simulation volume, zero at its start (µm)."""
    from esp.diagonals.model import body_diagonals

    out = {}
    for d in body_diagonals(machine):
        if d.name not in names:
            continue
        s = np.linspace(0.0, d.length_mm, 11)
        P = d.points(s)
        e = (actual_positions(machine, truth, P) - P) * 1000.0 @ d.direction
        if noise_um:
            e = e + rng.normal(0.0, noise_um, e.size)
        rows = ["# kind: linear", "# unit: um", "target_mm,run,direction,deviation"]
        rows += [f"{a:.6f},1,forward,{v - e[0]:.6f}" for a, v in zip(s, e, strict=True)]
        (folder / f"{d.name}.csv").write_text("\n".join(rows) + "\n")
        out[d.name] = f"{d.name}.csv"
    return out


#: a star probe: the offsets of three styli from the MCP (mm), not on one line
STYLI = {"down": (0.0, 0.0, -100.0), "east": (100.0, 0.0, -60.0), "north": (0.0, 100.0, -60.0)}


def write_star_plate(
    folder: Path,
    machine,
    truth: dict,
    styli: dict = STYLI,
    u_um: float = 0.4,
    n: int = 5,
    rng=None,
) -> dict:
    """A ball plate in four poses, each ball probed with each stylus of a star probe (one
    set, a column ``tool``, a table ``tool_mm``: the placements are shared by the styli),
    through the exact chain; with ``rng`` normal noise of ``u_um`` on each coordinate."""
    travel = {a: machine.axes[a].travel_mm for a in "XYZ"}
    B, poses = plate_poses(travel, tuple(styli.values()), n)
    rows = ["pose,tool,X,Y,Z,x,y,z"]
    for j, (R, t) in enumerate(poses, start=1):
        W = B @ np.asarray(R).T + np.asarray(t, dtype=float)
        for label, tool in styli.items():
            P = commanded_for(machine, truth, W, dict(zip("XYZ", tool, strict=True)))
            if rng is not None:
                P = P + rng.normal(0.0, u_um / 1000.0, P.shape)
            for p, b in zip(P, B, strict=True):
                rows.append(
                    f"p{j},{label},{p[0]:.9f},{p[1]:.9f},{p[2]:.9f},{b[0]:g},{b[1]:g},{b[2]:g}"
                )
    (folder / "star.csv").write_text("\n".join(rows) + "\n", encoding="utf-8")
    return {
        "star": {
            "kind": "points",
            "file": "star.csv",
            "u_um": u_um,
            "tool_mm": {k: list(v) for k, v in styli.items()},
        }
    }


def free_truth(rng, travel: dict, names, degree: int = 2, size: float = 2.0) -> dict:
    """Curves NOT in esp's gauge form: Legendre P_0 .. P_degree with every coefficient
    drawn, so that angles and linear errors are not zero at the low end of their travel
    and straightness values have a constant and a slope; squareness values."""
    truth: dict = {}
    for name in names:
        if name.startswith("squareness."):
            truth[name] = float(rng.normal(0.0, 3.0))
            continue
        a = name.split(".")[0]
        lo, hi = travel[a]
        c = rng.normal(0, size, degree + 1)

        def f(x, c=c, lo=lo, hi=hi):
            u = (2 * np.asarray(x, dtype=float) - lo - hi) / (hi - lo)
            return legendre_values(u, degree) @ c

        truth[name] = f
    return truth


def fit_with_noise(blocks, params, noise, tolerance: float):
    """The fit of the blocks' readings plus ``noise`` (standard normal, one value per
    residual, scaled by each reading's stated u: the model sees r = model - reading), the
    readings put back afterwards. A set's calibration (``calibration = { ... }``) has one
    residual more, its prior: its noise is the set's common calibration error, drawn once
    per set and call (moving the prior's centre by u_c n is, for the fit, the same as
    moving every reading by -s u_c n: substitute δ' = δ - u_c n)."""
    from esp.identify.solve import fit

    at = 0
    for b in blocks:
        b.data["shift"] = noise[at : at + b.size]
        at += b.size
    try:
        return fit(blocks, params, "refuse", tolerance)
    finally:
        for b in blocks:
            b.data.pop("shift", None)
