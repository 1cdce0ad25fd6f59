"""Write ``calibration.txt``, the synthetic Etalon Exchange file of the example.

A vertical machining centre (BMwTt: the table carries the work on X over Y, the ram moves Z) was
measured with a LaserTRACER; its software exported the volumetric calibration as an
Etalon Exchange file (docs/formats.md): for each axis its linear error, two straightness
errors and three angular errors as ``Gridpoints`` tables (positions and errors in mm,
angles in rad), and the three squareness errors as ``VALUE`` blocks (rad).

The data are invented: smooth curves typical of such a machine (a lead error of some
µm/m with a gentle bow, bows of a few µm, angles of a few µm/m) plus a little noise from a
:class:`numpy.random.Generator` seeded with :data:`SEED`; each curve is zero at the
first position, as a tracker's software reports it. Values are rounded to the file's
resolution (1 nm, 1 nrad), so running the script again writes the same bytes.

Usage: ``python make_data.py [FOLDER]`` (default: the folder holding this script).
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

SEED = 33
TRAVEL_MM = {"X": 800.0, "Y": 600.0, "Z": 500.0}
STEP_MM = 50.0
ROTATION = {"X": "A", "Y": "B", "Z": "C"}
#: squareness as the file gives it: block -> rad
SQUARENESS_RAD = {"C0Y": -6.0e-6, "B0Z": 4.0e-6, "A0Z": -2.5e-6}


def curves(rng: np.random.Generator, axis: str) -> list[tuple[str, np.ndarray, np.ndarray]]:
    """The six error curves of one axis: (block, positions in mm, values in mm or rad)."""
    length = TRAVEL_MM[axis]
    x = np.arange(0.0, length + STEP_MM / 2, STEP_MM)
    u = x / length
    out = []
    for other in "XYZ":  # linear (other == axis) and straightness errors, mm
        if other == axis:
            um = 12.0 * u + 3.0 * np.sin(np.pi * u)
        else:
            um = rng.uniform(-4.0, 4.0) * np.sin(np.pi * u) + rng.uniform(-1.0, 1.0) * u**2
        um = um + rng.normal(0.0, 0.15, x.size)
        out.append((f"E{other}{axis}", x, (um - um[0]) * 1e-3))
    for about in "XYZ":  # angular errors, rad
        urad = rng.uniform(-6.0, 6.0) * u + rng.uniform(-2.0, 2.0) * np.sin(2 * np.pi * u)
        urad = urad + rng.normal(0.0, 0.1, x.size)
        out.append((f"E{ROTATION[about]}{axis}", x, (urad - urad[0]) * 1e-6))
    return out


def text() -> str:
    """The file's text."""
    rng = np.random.default_rng(SEED)
    lines = [
        "// Etalon Exchange file (Vendor variant): synthetic LaserTRACER calibration",
        "// units: arguments and offsets in mm, angles in rad; values are errors",
    ]
    for block, value in SQUARENESS_RAD.items():
        lines += [f"[{block}]", f"VALUE = {value:.9f}"]
    for axis in "XYZ":
        for block, x, values in curves(rng, axis):
            decimals = 6 if block[1] in "XYZ" else 9
            lines += [f"[{block}]", "Gridpoints = {"]
            lines += [
                f"    {p:.6f} {round(v, decimals) + 0.0:.{decimals}f}"
                for p, v in zip(x, values, strict=True)
            ]
            lines.append(f"}}  // end of {block}")
    return "\n".join(lines) + "\n"


def main(folder: Path) -> None:
    (folder / "calibration.txt").write_text(text(), encoding="utf-8")


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else Path(__file__).resolve().parent)
