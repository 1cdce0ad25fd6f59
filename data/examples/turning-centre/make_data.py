"""Write the synthetic measurement files of the example turning centre.

The machine is a two-axis turning centre of the kind described in Longstaff (2002), 4.02:
the workpiece only turns (the C axis), the tool turret is moved by a cross slide X that
carries a ram Z, and a probe for in-process measurement sits on the turret 170 mm or
270 mm from the measurement centre point (MCP), along X. A volumetric compensation system
corrects the errors seen at the MCP. The missing Y axis is the third axis of the model,
with no travel and no errors.

Files (Renishaw Laser10 text, see ``docs/formats.md``), taken with the compensation on:

- ``Xpos_z0.rtl``, ``Xpos_z800.rtl``: X positioning, with the ram at Z = 0 and at
  Z = -800 mm. What is left of the X error after compensation (a few µm) plus, in the
  second file, the effect of the *residual* pitch of X over the ram's extension. The
  analysis derives that residual pitch from the two files (thesis 3.08.1);
- ``Zpos.rtl``: Z positioning after compensation;
- ``Xpitch.rta``, ``Xyaw.rta``: the *mechanical* rotation of X about Y (tens of µm/m, as in
  the thesis' figures 4.3 and 4.14) and about Z, by angular optics, which the compensation
  cannot change;
- ``Zyaw.rta``, ``Zroll.rta``: the rotation of the ram about Y and about its own axis.

The data are invented, from smooth curves plus noise drawn from a seeded
:class:`numpy.random.Generator`; every file draws from its own generator (seeded with
:data:`SEED` and the file's position in :data:`PLAN`), and every value is rounded to
0.001 before it is written, so running the script again writes the same bytes.

Usage: ``python make_data.py [FOLDER]`` (default: the folder holding this script).
"""

from __future__ import annotations

import sys
from datetime import datetime, timedelta
from pathlib import Path

import numpy as np

from esp.io.laser10 import write_laser10_set
from esp.core.profile import ErrorProfile

SEED = 20020402

MACHINE = "TC-2 turning centre"
SERIAL = "TC2-1187"
LOCATION = "Cell 4"
BY = "R. Okafor"
START = datetime(2024, 5, 21, 8, 0)

X_TRAVEL_MM = (-700.0, 0.0)
Z_TRAVEL_MM = (-800.0, 0.0)
#: the ram extension between the two X positioning runs, signed, mm
DISPLACEMENT_MM = -800.0
#: the X position where the residual pitch is zero by definition (the squareness of X to
#: Z was measured there), mm
DATUM_X_MM = -560.0
#: the residual squareness of X to Z after compensation, µm/m (machine.toml [squareness])
SQUARENESS_XZ_UM_PER_M = 2.0


def x_targets(spacing_mm: float = 35.0) -> np.ndarray:
    lo, hi = X_TRAVEL_MM
    return lo + spacing_mm * np.arange(int(round((hi - lo) / spacing_mm)) + 1)


def z_targets(spacing_mm: float) -> np.ndarray:
    lo, hi = Z_TRAVEL_MM
    return lo + spacing_mm * np.arange(int(round((hi - lo) / spacing_mm)) + 1)


def residual_x_um(x: np.ndarray) -> np.ndarray:
    """What compensation leaves of the X positioning error at Z = 0, µm."""
    u = (x - X_TRAVEL_MM[0]) / (X_TRAVEL_MM[1] - X_TRAVEL_MM[0])
    return 2.0 * np.sin(2.0 * np.pi * 1.5 * u + 0.7) + 1.5 * u


def residual_pitch_um_per_m(x: np.ndarray) -> np.ndarray:
    """The residual X pitch after compensation (the compensation table against the true
    angle), zero at the datum, within ±5 µm/m as in thesis table 4.5."""
    return 5.0 * np.sin(2.0 * np.pi * (x - DATUM_X_MM) / 420.0)


def mechanical_pitch_um_per_m(x: np.ndarray) -> np.ndarray:
    """The physical rotation of X about Y, from about -10 to 72 µm/m (thesis figure 4.3)."""
    u = (x - X_TRAVEL_MM[0]) / (X_TRAVEL_MM[1] - X_TRAVEL_MM[0])
    return -10.0 + 80.0 * u**1.6 + 2.0 * np.sin(2.0 * np.pi * 2.0 * u)


def x_yaw_um_per_m(x: np.ndarray) -> np.ndarray:
    u = (x - X_TRAVEL_MM[0]) / (X_TRAVEL_MM[1] - X_TRAVEL_MM[0])
    return 4.0 * 4.0 * u * (1.0 - u) + 1.0 * np.sin(2.0 * np.pi * 2.5 * u)


def z_yaw_um_per_m(z: np.ndarray) -> np.ndarray:
    """The ram's rotation about Y, some 20 µm/m over the stroke (thesis figure 4.14)."""
    u = (z - Z_TRAVEL_MM[0]) / (Z_TRAVEL_MM[1] - Z_TRAVEL_MM[0])
    return 18.0 * (1.0 - u) ** 2 + 1.5 * np.sin(2.0 * np.pi * 1.5 * u)


def z_roll_um_per_m(z: np.ndarray) -> np.ndarray:
    u = (z - Z_TRAVEL_MM[0]) / (Z_TRAVEL_MM[1] - Z_TRAVEL_MM[0])
    return 3.0 * (2.0 * u - 1.0) ** 3 + 0.5 * np.sin(2.0 * np.pi * 2.0 * u)


def residual_z_um(z: np.ndarray) -> np.ndarray:
    u = (z - Z_TRAVEL_MM[0]) / (Z_TRAVEL_MM[1] - Z_TRAVEL_MM[0])
    return 2.5 * np.sin(2.0 * np.pi * 1.2 * u) - 1.0 * u


def _runs(curve, n_runs, reversal, noise, rng) -> dict:
    """``n_runs`` bidirectional runs of ``curve`` plus noise, zeroed at the first target of
    the first run as an instrument is."""
    forward = [curve + rng.normal(0.0, noise, curve.size) for _ in range(n_runs)]
    backward = [curve + reversal + rng.normal(0.0, noise, curve.size) for _ in range(n_runs)]
    zero = forward[0][0]
    return {
        "forward": np.round(np.array(forward) - zero, 3),
        "backward": np.round(np.array(backward) - zero, 3),
    }


def _x_linear(z_mm: float):
    def make(rng):
        x = x_targets()
        # the linear effect of the residual pitch and squareness at this ram extension
        # (eq. 3.13 with the residual angle): angle [µm/m] x z [mm] / 1000 = µm
        pitch = (residual_pitch_um_per_m(x) + SQUARENESS_XZ_UM_PER_M) * z_mm / 1000.0
        return x, _runs(residual_x_um(x) + pitch, 5, 1.0, 0.3, rng)

    return make


def _angular(targets, curve, reversal=0.4, noise=0.3):
    def make(rng):
        return targets, _runs(curve(targets), 2, reversal, noise, rng)

    return make


def _z_linear(rng):
    z = z_targets(50.0)
    return z, _runs(residual_z_um(z), 5, 1.5, 0.3, rng)


#: (file name, kind, moving axis, axis of the rotation, maker, what the test was).
#: The order fixes the seeds and the measurement schedule.
PLAN = (
    ("Xpos_z0.rtl", "linear", "X", None, _x_linear(0.0),
     "positioning, compensation on, ram at Z = 0"),
    ("Xpos_z800.rtl", "linear", "X", None, _x_linear(DISPLACEMENT_MM),
     "positioning, compensation on, ram at Z = -800"),
    ("Xpitch.rta", "angular", "X", "Y", _angular(x_targets(), mechanical_pitch_um_per_m),
     "rotation about Y (pitch), angular optics"),
    ("Xyaw.rta", "angular", "X", "Z", _angular(x_targets(), x_yaw_um_per_m),
     "rotation about Z (yaw), angular optics"),
    ("Zpos.rtl", "linear", "Z", None, _z_linear, "positioning, compensation on"),
    ("Zyaw.rta", "angular", "Z", "Y", _angular(z_targets(100.0), z_yaw_um_per_m),
     "rotation about Y, angular optics"),
    ("Zroll.rta", "angular", "Z", "Z", _angular(z_targets(100.0), z_roll_um_per_m, 0.2),
     "roll (about Z), electronic levels"),
)  # fmt: skip

#: minutes a test takes, and to change the set-up
DURATION_MIN = {"linear": 28, "angular": 17}
SETUP_MIN = 25


def _stamp(t: datetime) -> str:
    return t.strftime("%H:%M %b %d %Y")


def _environment(start: datetime, end: datetime, rng: np.random.Generator) -> dict:
    """Readings at the start and end of a test: the shop warms slowly through the day."""
    hours = [(t - START).total_seconds() / 3600.0 for t in (start, end)]
    air = [20.4 + 0.1 * h + rng.normal(0.0, 0.03) for h in hours]
    mat = [a - 0.3 + rng.normal(0.0, 0.02) for a in air]
    press = 100.85 + rng.normal(0.0, 0.02)
    humid = rng.uniform(40.0, 46.0)
    return {
        "Air temp": (f"{air[0]:.2f}", f"{air[1]:.2f}", "0"),
        "Air press": (f"{press:.2f}", f"{press + rng.normal(0.0, 0.03):.2f}", "1"),
        "Air humid": (f"{humid:.1f}", f"{humid + rng.normal(0.0, 0.4):.1f}", "0"),
        "Mat temp 1": (f"{mat[0]:.2f}", f"{mat[1]:.2f}", "1"),
        "Exp coeff": ("11.700000", "11.700000", "0"),
        "Date Time": (_stamp(start), _stamp(end)),
    }


def profiles() -> dict[str, ErrorProfile]:
    """File name -> profile of every file of the data set, in :data:`PLAN` order."""
    out: dict[str, ErrorProfile] = {}
    clock = START
    for index, (name, kind, axis, about, make, how) in enumerate(PLAN):
        rng = np.random.default_rng([SEED, index])
        targets, runs = make(rng)
        start = clock
        end = start + timedelta(minutes=DURATION_MIN[kind] + int(rng.integers(0, 6)))
        clock = end + timedelta(minutes=SETUP_MIN)
        metadata = {
            "Machine": MACHINE,
            "Serial No": SERIAL,
            "Date": start.strftime("%d/%m/%Y"),
            "By": BY,
            "Axis": axis,
            "Location": LOCATION,
            "Comment": f"{axis} axis {how}",
        }
        out[name] = ErrorProfile(
            kind=kind,
            targets_mm=targets,
            runs=runs,
            axis=axis,
            error_direction=about,
            metadata=metadata,
            environment=_environment(start, end, rng),
        )
    return out


def write_files(folder: str | Path) -> list[Path]:
    """Write every file of the data set into ``folder`` (created if needed); return the
    paths in :data:`PLAN` order."""
    return write_laser10_set(folder, profiles())


def main(argv: list[str] | None = None) -> int:
    args = sys.argv[1:] if argv is None else argv
    folder = Path(args[0]) if args else Path(__file__).resolve().parent
    for path in write_files(folder):
        print(path.name)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
