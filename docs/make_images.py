"""Make the pictures of docs/reports.md from the shipped gantry example.

Run from the repository root:  python docs/make_images.py

The gantry is evaluated at the TCP with its head sweep (machine-tcp.toml) and, for the
uncertainty figures, with a Monte Carlo uncertainty of a few components added in code.
The PNGs are the report's figures (A4 landscape), written small (60 dpi, 701 x 496
pixels) into docs/images/; input images of the earlier one-per-component figures are
removed.
"""

from __future__ import annotations

import tomllib
from pathlib import Path

from esp.config import machine_from_dict
from esp.core.analysis import analyse
from esp.report import bundle
from esp.volumetric import plots

ROOT = Path(__file__).resolve().parent.parent
GANTRY = ROOT / "data" / "examples" / "gantry"
IMAGES = Path(__file__).resolve().parent / "images"
WANTED = (
    "map-Y.png",
    "map-volumetric.png",
    "terms.png",
    "sweep.png",
    "uncertainty-budget.png",
    "uncertainty-montecarlo.png",
    "input-Y.png",
)


def main() -> None:
    data = tomllib.loads((GANTRY / "machine-tcp.toml").read_text(encoding="utf-8"))
    data["uncertainty"] = {
        "method": "montecarlo",
        "samples": 4000,
        "seed": 1,
        "components": {
            "Y.linear": {"U": 6.0},
            "X.linear": {"U": 4.0},
            "Z.linear": {"U": 3.0},
            "Y.angular.Z": {"U": 3.0},
            "squareness.XY": {"U": 5.0},
        },
    }
    result = analyse(machine_from_dict(data, GANTRY, source="machine-tcp.toml"))
    IMAGES.mkdir(exist_ok=True)
    for old in IMAGES.glob("input-*.png"):  # the inputs were one figure per component
        if old.name not in WANTED:
            old.unlink()
    for spec in bundle.figure_specs(result):
        if spec.filename in WANTED:
            plots.save_png(spec.build(), IMAGES / spec.filename, dpi=60)
            print(IMAGES.relative_to(ROOT) / spec.filename)


if __name__ == "__main__":
    main()
