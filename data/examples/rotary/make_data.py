"""Write the example curve files of the trunnion table (trunnion.toml).

The component error motions of its two axes, as a calibration would report them, made
up from a few harmonics of the angle (the shapes that a worm gear, an encoder's
eccentricity and a bearing's waviness leave; no measurement is behind them):

* trunnion-C-motions.csv -- C every 15 deg over one turn (periodic): radial EXC, EYC and
  axial EZC (um), tilt EAC, EBC (urad) and the angular positioning error ECC (arcsec);
* trunnion-A-motions.csv -- A every 10 deg over its travel, -120..120 deg (not periodic):
  radial EYA, EZA (um), tilt EBA, ECA (urad) and the angular positioning error EAA
  (arcsec).

Running it again writes the same bytes.

Usage: ``python make_data.py [FOLDER]`` (default: the folder holding this script).
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent

#: error -> (offset, [(harmonic, amplitude, phase_deg), ...]), in the file's unit
C_MOTIONS = {
    "EXC": (0.0, [(2, 0.8, 20.0), (3, 0.3, 75.0)]),
    "EYC": (0.0, [(2, 0.8, 110.0), (3, 0.3, 165.0)]),
    "EZC": (0.2, [(1, 0.6, 40.0), (4, 0.25, 0.0)]),
    "EAC": (0.0, [(1, 2.5, 10.0), (2, 0.8, 60.0)]),
    "EBC": (0.0, [(1, 2.5, 100.0), (2, 0.8, 150.0)]),
    "ECC": (0.0, [(1, 4.0, 30.0), (2, 1.5, 200.0), (6, 0.5, 0.0)]),
}
A_MOTIONS = {
    "EYA": (0.0, [(1, 1.2, 30.0), (2, 0.5, 0.0)]),
    "EZA": (0.0, [(1, 1.5, 120.0), (2, 0.4, 45.0)]),
    "EBA": (0.0, [(1, 3.0, 0.0), (3, 0.6, 30.0)]),
    "ECA": (0.0, [(1, 2.0, 90.0), (3, 0.5, 0.0)]),
    "EAA": (1.0, [(1, 5.0, 60.0), (2, 2.0, 0.0)]),
}
UNITS = "um (EX., EY., EZ.), urad (tilts), arcsec (angular positioning)"


def value(model: tuple[float, list[tuple[int, float, float]]], angle_deg: float) -> float:
    offset, harmonics = model
    return offset + sum(
        a * math.sin(math.radians(k * angle_deg + phase)) for k, a, phase in harmonics
    )


def write(path: Path, title: str, angles: list[int], models: dict) -> None:
    lines = [f"# {title}", f"# units: {UNITS}; made by make_data.py"]
    lines.append(",".join(["angle_deg", *models]))
    for a in angles:
        cells = [f"{value(m, a):.3f}" for m in models.values()]
        lines.append(",".join([str(a), *("0.000" if c == "-0.000" else c for c in cells)]))
    path.write_text("\n".join(lines) + "\n", encoding="utf-8", newline="\n")


def main(folder: Path) -> None:
    write(
        folder / "trunnion-C-motions.csv",
        "C axis of the trunnion table: component error motions over one turn",
        list(range(0, 360, 15)),
        C_MOTIONS,
    )
    write(
        folder / "trunnion-A-motions.csv",
        "A axis of the trunnion table: component error motions over its travel",
        list(range(-120, 121, 10)),
        A_MOTIONS,
    )


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else HERE)
