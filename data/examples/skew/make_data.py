"""Write the example files of docs/skew.md, made from the exact geometry of machines with the
skew and scale stated below (no measurement is behind them), and ``truth.json``.

* plate-probed.csv -- a 5 × 5 hole plate, 200 mm square, calibrated coordinates, probed in
  XY by a router whose Y axis leans towards +X by 450 µm/m and whose X and Y travel
  +120 and −80 µm/m too far; the plate lies 0.4° turned and off the origin; the probe's
  noise 2 µm (standard deviation per coordinate);
* part-made.csv -- a stepped block a machine milled (corners and steps at three heights,
  nominal coordinates from the CAD model) measured on a CMM: squareness XY −300, XZ 150,
  YZ 220 µm/m, scales +50, −30, +90 µm/m; the CMM's noise 1.5 µm.

The square of the docs (``--xy 141.84,141.04,100.02``) is the one a printer with 5.66 mm/m
of XY skew prints when commanded a 100 mm square, read with a 0.01 mm caliper.

The noise is drawn from numpy's generator with a fixed seed: running it again writes the
same bytes.

Usage: ``python make_data.py [FOLDER]`` (default: the folder holding this script).
"""

from __future__ import annotations

import json
import math
import sys
from pathlib import Path

import numpy as np

from esp.skew.model import machine_matrix

HERE = Path(__file__).resolve().parent

PLATE = {"squareness": {"XY": 450e-6}, "scale": {"X": 120e-6, "Y": -80e-6}}
PART = {
    "squareness": {"XY": -300e-6, "XZ": 150e-6, "YZ": 220e-6},
    "scale": {"X": 50e-6, "Y": -30e-6, "Z": 90e-6},
}


def _plate(rng: np.random.Generator) -> str:
    m = machine_matrix(PLATE["squareness"], PLATE["scale"])[:2, :2]
    turn = math.radians(0.4)
    rot = np.array([[math.cos(turn), -math.sin(turn)], [math.sin(turn), math.cos(turn)]])
    where = np.array([152.0, 87.5])
    rows = [
        "# A 5 x 5 hole plate probed in XY (esp skew example; made by make_data.py)",
        "# kind: probed",
        "point,x_nominal,y_nominal,x_measured,y_measured",
    ]
    k = 1
    for y in np.linspace(0.0, 200.0, 5):
        for x in np.linspace(0.0, 200.0, 5):
            true = rot @ np.array([x, y]) + where  # where the hole is on the machine
            reading = np.linalg.solve(m, true) + rng.normal(scale=0.002, size=2)
            rows.append(f"H{k},{x:.3f},{y:.3f},{reading[0]:.4f},{reading[1]:.4f}")
            k += 1
    return "\n".join(rows) + "\n"


def _part(rng: np.random.Generator) -> str:
    m = machine_matrix(PART["squareness"], PART["scale"])
    pts = []
    for z in (0.0, 40.0, 80.0):
        size = 160.0 - z
        for x, y in ((0.0, 0.0), (size, 0.0), (size, size), (0.0, size)):
            pts.append((x, y, z))
    turn = math.radians(-1.2)
    rot = np.array(
        [[math.cos(turn), -math.sin(turn), 0.0], [math.sin(turn), math.cos(turn), 0.0], [0, 0, 1]]
    )
    rows = [
        "# A stepped block the machine milled, measured on a CMM (esp skew example)",
        "# kind: made",
        "point,x_nominal,y_nominal,z_nominal,x_measured,y_measured,z_measured",
    ]
    for k, p in enumerate(pts, start=1):
        made = rot @ (m @ np.array(p)) + np.array([10.0, -5.0, 2.0])
        got = made + rng.normal(scale=0.0015, size=3)
        rows.append(f"C{k},{p[0]:.3f},{p[1]:.3f},{p[2]:.3f},{got[0]:.4f},{got[1]:.4f},{got[2]:.4f}")
    return "\n".join(rows) + "\n"


def main(folder: Path) -> None:
    rng = np.random.default_rng(2026)
    (folder / "plate-probed.csv").write_text(_plate(rng), encoding="utf-8")
    (folder / "part-made.csv").write_text(_part(rng), encoding="utf-8")
    truth = {
        name: {kind: {k: v * 1e6 for k, v in values.items()} for kind, values in spec.items()}
        for name, spec in (("plate-probed.csv", PLATE), ("part-made.csv", PART))
    }
    (folder / "truth.json").write_text(json.dumps(truth, indent=2) + "\n", encoding="utf-8")


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else HERE)
