"""Write synthetic ISO 230-6 body-diagonal measurements of the example gantry.

The gantry of ``../gantry`` was "measured" along its four body diagonals with a laser
interferometer. The files here are synthetic: the displacement error along each diagonal
is synthesised by esp from a *slightly different* error set than the one in
``../gantry`` -- the machine as it really is, as opposed to what the 21 measured
components say -- plus reading noise:

- the squareness of X to Y is 5.3 µm/m instead of the 4.5 µm/m of the gantry's
  ``machine.toml``, Y to Z 6.6 instead of 6.0 (the squares were set up a little off);
- the positioning error of X has 1.2 µm/m more cumulative lead error (the laser's
  material temperature compensation of the X test was a little off);
- every run carries 0.25 µm of reading noise, and the backward runs a reversal of
  0.4 µm.

The volume is that of the gantry's simulation range (X 0-1000, Y 0-1500, Z 0-600 mm); the
four body diagonals are 1900 mm long; targets every 95 mm (21 targets), 3 bidirectional
runs, zeroed at the first target of the first run, one Laser10 linear file per diagonal
(``PPP.rtl``, ``NPP.rtl``, ``PNP.rtl``, ``PPN.rtl``, named as in ``esp diagonals``).

Every file draws from its own seeded generator and values are rounded to 0.001 µm, so
running the script again writes the same bytes (as long as esp's model of the gantry
gives the same errors).

Usage: ``python make_data.py [FOLDER]`` (default: the folder holding this script).
"""

from __future__ import annotations

import sys
from dataclasses import replace
from pathlib import Path

import numpy as np

import esp
from esp.diagonals.model import BODY, body_diagonals, diagonal_targets, predict_diagonal
from esp.io.laser10 import write_laser10_set
from esp.core.machine import Component
from esp.core.profile import ErrorProfile

HERE = Path(__file__).resolve().parent
SEED = 20230320
STEP_MM = 95.0
RUNS = 3
NOISE_UM = 0.25
REVERSAL_UM = 0.4
#: the "true" machine: squareness (µm/m) and extra lead error of X (µm/m)
TRUE_SQUARENESS = {"squareness.XY": 5.3, "squareness.YZ": 6.6}
EXTRA_X_LEAD_UM_PER_M = 1.2


def true_machine():
    """The gantry with the slightly different error set of the module docstring."""
    m = esp.load_machine(HERE.parent / "gantry" / "machine.toml")
    comps = dict(m.components)
    for name, value in TRUE_SQUARENESS.items():
        comps[name] = Component(name, "squareness", None, name.split(".")[1], value=value)
    x = comps["X.linear"]
    extra = EXTRA_X_LEAD_UM_PER_M * x.profile.targets_mm / 1000.0
    runs = {d: r + extra[None, :] for d, r in x.profile.runs.items()}
    comps["X.linear"] = replace(x, profile=replace(x.profile, runs=runs))
    return replace(m, components=comps)


def profiles() -> dict[str, ErrorProfile]:
    """File name -> profile of each diagonal, in :data:`BODY` order."""
    truth = true_machine()
    out = {}
    for index, diagonal in enumerate(body_diagonals(truth)):
        assert diagonal.name == BODY[index]
        rng = np.random.default_rng([SEED, index])
        s = diagonal_targets(diagonal, STEP_MM)
        d = predict_diagonal(truth, diagonal, s)
        forward = [d + rng.normal(0.0, NOISE_UM, s.size) for _ in range(RUNS)]
        backward = [d + REVERSAL_UM + rng.normal(0.0, NOISE_UM, s.size) for _ in range(RUNS)]
        zero = forward[0][0]
        start = ", ".join(f"{v:g}" for v in diagonal.start_mm)
        end = ", ".join(f"{v:g}" for v in diagonal.end_mm)
        out[f"{diagonal.name}.rtl"] = ErrorProfile(
            "linear",
            s,
            {
                "forward": np.round(np.array(forward) - zero, 3),
                "backward": np.round(np.array(backward) - zero, 3),
            },
            metadata={
                "Machine": "GX-1500 gantry milling machine",
                "Serial No": "GX15-0472",
                "Date": "20/03/2023",
                "By": "M. Weber",
                "Location": "Hall 3, bay 2",
                "Comment": f"body diagonal {diagonal.name} from ({start}) to ({end}) mm",
            },
        )
    return out


def write_files(folder: str | Path) -> list[Path]:
    """Write every file into ``folder``; return the paths in :data:`BODY` order."""
    return write_laser10_set(folder, profiles())


def main(argv: list[str] | None = None) -> int:
    args = sys.argv[1:] if argv is None else argv
    folder = Path(args[0]) if args else HERE
    for path in write_files(folder):
        print(path.name)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
