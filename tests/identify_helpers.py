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
