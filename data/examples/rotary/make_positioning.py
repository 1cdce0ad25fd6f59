"""Write ``C-positioning.csv``, the example of docs/iso230-2.md ("Rotary axes"): the angular
positioning of a rotary table's C axis over a full turn as a rotary calibrator records it,
made from a stated error (no measurement is behind it):

* a once-per-turn error of 4 arcsec amplitude (an encoder's eccentricity) and a twice-per-
  turn error of 1.5 arcsec;
* a reversal of 3 arcsec (the ↓ runs lag the ↑ runs);
* noise of 0.6 arcsec (standard deviation) per reading;

every 30° from 0° to 360°, five runs in each direction. The noise is drawn from numpy's
generator with a fixed seed: running it again writes the same bytes.

Usage: ``python make_positioning.py [FOLDER]`` (default: the folder holding this script).
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent


def systematic_arcsec(angle_deg: np.ndarray) -> np.ndarray:
    a = np.radians(angle_deg)
    return 4.0 * np.sin(a + 0.3) - 4.0 * np.sin(0.3) + 1.5 * np.sin(2.0 * a)


def main(folder: Path) -> None:
    rng = np.random.default_rng(230)
    targets = np.arange(0.0, 361.0, 30.0)
    rows = [
        "# C axis of a rotary table, a rotary calibrator's runs (esp example; made by",
        "# make_positioning.py from a stated error, no measurement)",
        "# kind: rotary",
        "# axis: C",
        "# unit: arcsec",
        "target_deg,run,direction,deviation",
    ]
    run = 0
    for _ in range(5):
        for direction, order, shift in (
            ("forward", targets, 1.5),
            ("backward", targets[::-1], -1.5),
        ):
            run += 1
            values = systematic_arcsec(order) + shift + rng.normal(scale=0.6, size=order.size)
            rows += [f"{t:g},{run},{direction},{v:.2f}" for t, v in zip(order, values, strict=True)]
    (folder / "C-positioning.csv").write_text("\n".join(rows) + "\n", encoding="utf-8")


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else HERE)
