"""Write ``fork-head-measured.csv``: the measured differences of the fork head's protocol.

The "measurements" are made up: the exact chain of ``fork-head.toml`` (every rotation
exact, nothing dropped) with the error values :data:`ACTUAL` plays the real head, and each
test of the protocol that ``esp head fork-head-example.toml --protocol`` prints reads the
difference of the tool tip's position between its two settings, less the nominal
difference, rounded to 0.1 µm as an instrument would report it. Solving the protocol from
the file (``--measured``) then gives back these values to within what the rounding and the
first-order model leave -- except that the spindle offset EY0S, which the protocol assumes
zero, is not zero here: the identified EA0A holds EA0A + EY0S/G (1.5 µm / 200 mm =
7.5 µrad), as the protocol's assumption says it must.

Running the script again writes the same bytes.

Usage: ``python make_data.py [FOLDER]`` (default: the folder holding this script).
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from esp.heads import build_protocol
from esp.heads.config import read_head_file
from esp.core.kinematics import position

HERE = Path(__file__).resolve().parent
#: the real head's errors (µm, µrad), unknown to the protocol
ACTUAL = {
    "EA0C": 17.3,
    "EB0C": -8.6,
    "EC0C": 23.1,
    "EY0A": 6.4,
    "EB0A": 13.7,
    "EA0A": -21.9,
    "EY0S": 1.5,
    "EB0S": 9.2,
}


def main(folder: Path) -> None:
    spec = read_head_file(HERE / "fork-head-example.toml")
    head = spec.head
    protocol = build_protocol(
        head,
        angles=spec.protocol.angles,
        assume_zero=spec.protocol.assume_zero,
        known=spec.protocol.known,
    )
    coords = protocol.coordinates
    params = head.values_in("parameter")
    errors = {e: ACTUAL[e] for e in head.chain.errors}
    lines = [
        "# Measured differences for: esp head fork-head-example.toml --protocol",
        "# (made up by make_data.py: an exact chain plays the head; 0.1 um steps)",
        "test,axis,"
        + ",".join(f"{c}1" for c in coords)
        + ","
        + ",".join(f"{c}2" for c in coords)
        + ",difference_um",
    ]
    for t in protocol.tests:
        k = "XYZ".index(t.axis)
        at = {c: np.array([t.first[c], t.second[c]]) for c in coords}
        actual = position(head.chain, at, params, errors)
        nominal = position(head.chain, at, params)
        error_um = (actual - nominal)[:, k] * 1000.0
        difference = round(float(error_um[0] - error_um[1]), 1) + 0.0
        settings = [f"{t.first[c]:g}" for c in coords] + [f"{t.second[c]:g}" for c in coords]
        lines.append(f"{t.number},{t.axis},{','.join(settings)},{difference:.1f}")
    (folder / "fork-head-measured.csv").write_text("\n".join(lines) + "\n", encoding="utf-8")


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else HERE)
