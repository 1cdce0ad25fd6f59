"""Write the example ballbar files of docs/ballbar.md, made from the exact geometry of a
machine with the errors stated below (esp.ballbar.synthetic; no measurement is behind
them), and ``truth.json``, what each file's diagnosis should find.

* circle-XY.csv -- a full circle in XY, R = 150 mm, both directions, every 0.5°, feed
  1000 mm/min, a calibrated ballbar (length U 0.2 µm, accuracy ±0.5 µm, resolution
  0.1 µm); the lengths table of esp identify with the test conditions in its header;
* arc-XZ.csv -- a 220° arc in XZ from -20°, R = 150 mm, both directions, every 0.5°
  (a vertical plane, where the bar cannot go round);
* homemade.csv -- a home-made ballbar's angle table: R = 100 mm, every 2°, one run ccw
  then one cw without a direction column, deviations in nm with semicolons and decimal
  commas, the bar not calibrated.

The noise is drawn from numpy's generator seeded per file: running it again writes the
same bytes.

Usage: ``python make_data.py [FOLDER]`` (default: the folder holding this script).
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

from esp.ballbar.synthetic import Effects, synthetic_readings, write_lengths

HERE = Path(__file__).resolve().parent

CIRCLE = Effects(
    scale_um_per_m=(10.0, -2.0),
    squareness_um_per_m=12.0,
    servo_mismatch_ms=0.3,
    backlash_um=((3.0, 2.5), (1.5, 2.0)),
    lateral_um=(1.0, 0.0),
    bow_um=(2.0, 0.0),
    cyclic=((0.0, 1.0, 0.0), (0.6, 10.0, 1.0)),
    spike=((3.0, 0.4), (0.0, 1.0)),
    stick_slip=((0.0, 2.0, 10.0), (0.5, 2.0, 10.0)),
    centre_offset_um=(12.0, -8.0),
    length_error_um=0.08,
    noise_um=0.08,
)
ARC = Effects(
    scale_um_per_m=(5.0, 0.0),
    squareness_um_per_m=15.0,
    backlash_um=((2.0, 2.0), (4.0, 4.0)),
    centre_offset_um=(5.0, 5.0),
    noise_um=0.08,
)
HOMEMADE = Effects(
    scale_um_per_m=(30.0, 0.0),
    squareness_um_per_m=-40.0,
    backlash_um=((10.0, 10.0), (6.0, 6.0)),
    centre_offset_um=(40.0, -25.0),
    length_error_um=15.0,
    noise_um=0.5,
)

#: what each file's diagnosis should find (the units of its terms: µm/m, ms, ppm, µm);
#: the spike is the radial deviation at the first reading after the reversal
TRUTH = {
    "circle-XY.csv": {
        "scale_mismatch": 12.0,
        "scaling": 4.0 + 0.08 / 150.0 * 1e3,
        "squareness": 12.0,
        "servo_mismatch": 0.3,
        "backlash_X+": 3.0,
        "backlash_X-": 2.5,
        "backlash_Y+": 1.5,
        "backlash_Y-": 2.0,
        "lateral_X": 1.0,
        "straightness_X": 2.0,
        "cyclic_Y": 0.6,
        "spike_X+": 3.0 * 0.28650479686019015,  # 3 exp(-0.5/0.4) cos 0.5°
        "spike_X-": 3.0 * 0.28650479686019015,
        "stick_slip_Y": 0.5,
    },
    "arc-XZ.csv": {
        "scale_mismatch": 5.0,
        "squareness": 15.0,
        "backlash_X+": 2.0,
        "backlash_X-": 2.0,
        "backlash_Z+": 4.0,
    },
    "homemade.csv": {
        "scale_mismatch": 30.0,
        "squareness": -40.0,
        "backlash_X+": 10.0,
        "backlash_X-": 10.0,
        "backlash_Y+": 6.0,
        "backlash_Y-": 6.0,
    },
}

HEADER = [
    "machine: Example VMC",
    "date: 2026-11-30",
    "operator: A. Fitter",
    "ballbar: example ballbar, serial 0001",
    "calibration_U: 0.2 um",
    "accuracy: 0.5 um",
    "resolution: 0.1 um",
    "feed: 1000 mm/min",
    "temperature: 20.4 °C",
]


def main(folder: Path) -> None:
    folder.mkdir(parents=True, exist_ok=True)
    runs = synthetic_readings(150.0, CIRCLE, step_deg=0.5, feed_mm_per_min=1000.0, seed=1)
    write_lengths(folder / "circle-XY.csv", 150.0, runs, header=HEADER)
    runs = synthetic_readings(150.0, ARC, step_deg=0.5, start_deg=-20.0, span_deg=220.0, seed=2)
    write_lengths(folder / "arc-XZ.csv", 150.0, runs, plane="XZ", header=HEADER[:4] + HEADER[5:])
    runs = synthetic_readings(100.0, HOMEMADE, step_deg=2.0, seed=3)
    lines = [
        "# a home-made ballbar: a dial gauge on a bar between two balls",
        "# radius: 100 mm",
        "# feed: 500 mm/min",
        "Angle (deg);Deviation (nm)",
    ]
    for _direction, theta, dev in runs:
        lines += [
            f"{t:.1f};{v * 1000:.0f}".replace(".", ",") for t, v in zip(theta, dev, strict=True)
        ]
    (folder / "homemade.csv").write_text("\n".join(lines) + "\n", encoding="utf-8")
    (folder / "truth.json").write_text(json.dumps(TRUTH, indent=2) + "\n", encoding="utf-8")


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else HERE)
