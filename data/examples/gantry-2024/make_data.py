"""Write the synthetic files of a second calibration of the example gantry, a year later.

The machine is the one of ``../gantry`` (read its ``make_data.py`` and ``README.md``). A
year of work has changed it a little; this script writes the 18 Laser10 files of the
re-calibration with the same generator, the same targets spacing and file layout, and
these changes to the error model of ``../gantry/make_data.py`` (everything else equal):

- Y positioning: the cumulative lead error grew from 14 to 17 µm/m and the reversal from
  4 to 5.5 µm (wear of the gantry's ballscrew nut);
- X straightness in Z: the sag of the bridge grew from a bow of -5 to -6.5 µm;
- Y pitch (about X): the bow grew from 4.5 to 6 µm/m (a worn guideway);
- Z positioning: the lead error fell from 18 to 16 µm/m (the ballscrew was re-tensioned).

The squareness of X to Y changed from 4.5 to 6.0 µm/m; it is in ``machine.toml``.

The systematic curves (their shapes and phases) are those of the first calibration: the
generator runs with the first calibration's seed, so what did not change is the same
curve; each run then gets a fresh reading noise of :data:`REMEASURE_NOISE` (µm or µm/m)
from its own generator, seeded with :data:`SEED` and the file's place in the plan, as a
new measurement would. Values are rounded to 0.001 µm, so running the script again writes
the same bytes.

Usage: ``python make_data.py [FOLDER]`` (default: the folder holding this script).
"""

from __future__ import annotations

import importlib.util
import sys
from dataclasses import replace
from datetime import datetime
from pathlib import Path

import numpy as np

from esp.io.laser10 import write_laser10_set

HERE = Path(__file__).resolve().parent
SEED = 20240312
FIRST_DAY = datetime(2024, 3, 12, 8, 30)
#: standard deviation of the fresh reading noise of the re-measurement (µm, or µm/m)
REMEASURE_NOISE = 0.15
BY = "K. Osei"

#: file name -> changed model parameters (the rest as in ../gantry/make_data.py)
CHANGES = {
    "Y-linear.rtl": {"slope_um_per_m": 17.0, "reversal_um": 5.5},
    "X-straightness-Z.stx": {"bow": -6.5},
    "Y-angular-X.rta": {"bow": 6.0},
    "Z-linear.rtl": {"slope_um_per_m": 16.0},
}


def _gantry_generator():
    """The generator of the first calibration, imported from ../gantry/make_data.py."""
    path = HERE.parent / "gantry" / "make_data.py"
    name = "_gantry_make_data_for_2024"
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module  # dataclasses look their module up while the class is made
    try:
        spec.loader.exec_module(module)
    finally:
        del sys.modules[name]
    return module


def profiles() -> dict:
    """File name -> profile of every file of the re-calibration."""
    gen = _gantry_generator()
    plan = []
    for name, kind, axis, about, model, how in gen.PLAN:
        if name in CHANGES:
            model = replace(model, **CHANGES[name])
        plan.append((name, kind, axis, about, model, how))
    gen.PLAN = tuple(plan)
    gen.FIRST_DAY = FIRST_DAY
    gen.BY = BY
    out = {}
    for index, (name, profile) in enumerate(gen.profiles().items()):
        rng = np.random.default_rng([SEED, index])
        runs = {
            d: np.round(r + rng.normal(0.0, REMEASURE_NOISE, r.shape), 3)
            for d, r in profile.runs.items()
        }
        out[name] = replace(profile, runs=runs)
    return out


def write_files(folder: str | Path) -> list[Path]:
    """Write every file into ``folder``; return the paths in plan order."""
    return write_laser10_set(folder, profiles())


def main(argv: list[str] | None = None) -> int:
    args = sys.argv[1:] if argv is None else argv
    folder = Path(args[0]) if args else HERE
    for path in write_files(folder):
        print(path.name)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
