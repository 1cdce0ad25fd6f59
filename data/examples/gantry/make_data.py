"""Write the synthetic measurement files of the example gantry machine.

The machine is a gantry (wBMTt: every axis moves the tool) written wYXZt:

- bottom Y, the gantry travelling on the bed, 0 to 1500 mm;
- middle X, the carriage travelling on the bridge, 0 to 1000 mm;
- top Z, the vertical ram, 0 to 600 mm.

Every one of the 18 per-axis error components is written as a Renishaw Laser10 text file
(see ``docs/formats.md``) named after the component: ``X-linear.rtl``,
``X-straightness-Y.stx`` (X moving, deviation along Y), ``X-angular-Z.rta`` (X moving,
rotation about Z), and so on. The squareness values are not measured files; they are in
``machine.toml``.

The data are invented, from smooth curves typical of such machines plus noise drawn from a
seeded :class:`numpy.random.Generator`:

- positioning (``.rtl``): a cumulative lead error (a slope of some µm/m) with a gentle
  bow, a small periodic error with the ballscrew's lead, a reversal (backlash) of a few µm
  between forward and backward approach, a slow thermal drift from run to run, and about
  0.3 µm of reading noise; 5 bidirectional runs at targets spaced irregularly so that the
  periodic error is not always sampled at the same phase; the laser is zeroed at the first
  target of the first run;
- straightness (``.stx/.sty/.stz``): a bow of a few µm and a waviness, plus the slope of the
  optics' alignment (tens of µm over the stroke, the same in every run) and an arbitrary
  zero, which the analysis removes; 3 bidirectional runs;
- angular (``.rta``, µm/m): a smooth curve of a few µm/m with some waviness; 2 bidirectional
  runs, zeroed at the first target.

Each file carries the user text and environment sections an instrument would write, with
start and end times that follow one another, one axis a day, over three days.

Running the script again writes the same bytes: every file draws from its own generator,
seeded with :data:`SEED` and the file's position in :data:`PLAN`, and every value is rounded
to 0.001 µm before it is written.

Usage: ``python make_data.py [FOLDER]`` (default: the folder holding this script).
"""

from __future__ import annotations

import sys
from dataclasses import dataclass
from datetime import datetime, timedelta
from pathlib import Path

import numpy as np

from esp.io.laser10 import write_laser10_set
from esp.core.profile import ErrorProfile

SEED = 20230314

#: axis -> end of travel (every axis starts at 0), mm
TRAVEL_MM = {"Y": 1500.0, "X": 1000.0, "Z": 600.0}
#: axis -> nominal target spacing of the positioning test, mm
LINEAR_SPACING_MM = {"Y": 100.0, "X": 50.0, "Z": 50.0}
#: axis -> target spacing of the straightness and angular tests, mm
PROFILE_SPACING_MM = {"Y": 100.0, "X": 50.0, "Z": 50.0}

MACHINE = "GX-1500 gantry milling machine"
SERIAL = "GX15-0472"
LOCATION = "Hall 3, bay 2"
BY = "M. Weber"
FIRST_DAY = datetime(2023, 3, 14, 8, 30)
DAY_START = (8, 30)
DAY_END = (16, 45)
#: expansion coefficient of the scales/ballscrews entered in the laser software, ppm/°C
EXP_COEFF_PPM = 11.5


@dataclass(frozen=True)
class Linear:
    """Positioning error of one axis (µm), see the module docstring."""

    slope_um_per_m: float  # cumulative lead error
    bow_um: float  # mid-travel departure from the straight line
    lead_mm: float  # ballscrew lead, the period of the periodic error
    periodic_um: float  # amplitude of the periodic error
    reversal_um: float  # backward minus forward, at the start of travel
    reversal_growth_um: float  # extra reversal at the end of travel
    drift_um_per_m_per_run: float  # thermal growth between successive runs
    noise_um: float = 0.3
    runs: int = 5  # bidirectional runs


@dataclass(frozen=True)
class Profile:
    """Straightness (µm) or angular (µm/m) error of one axis, see the module docstring."""

    bow: float  # mid-travel departure of a parabola
    wave: float  # amplitude of the waviness
    wave_cycles: float  # waves over the travel
    cubic: float  # an S-shaped part, value at the ends
    reversal: float  # backward minus forward
    noise: float
    slope: float = 0.0  # set-up slope over the whole stroke (straightness only)
    intercept: float = 0.0  # arbitrary zero (straightness only)
    runs: int = 2  # bidirectional runs


#: (file name, kind, moving axis, direction of the error or axis of the rotation, model,
#: how it was measured). The order fixes the seeds and the measurement schedule.
#: Linear(slope µm/m, bow µm, lead mm, periodic µm, reversal µm, reversal growth µm,
#:        drift µm/m per run)
#: Profile(bow, wave, wave cycles, cubic, reversal, noise[, slope, intercept, runs])
# fmt: off
PLAN: tuple[tuple[str, str, str, str | None, Linear | Profile, str], ...] = (
    # -- Y, the gantry: day 1 -----------------------------------------------------------
    ("Y-linear.rtl", "linear", "Y", None,
     Linear(14.0, -4.5, 25.0, 1.2, 4.0, 1.0, 0.25), "positioning, linear optics"),
    ("Y-straightness-X.sty", "straightness", "Y", "X",
     Profile(3.5, 1.0, 2.5, 1.0, 0.3, 0.35, slope=-38.0, intercept=6.2, runs=3),
     "straightness in X (horizontal), straightness optics"),
    ("Y-straightness-Z.sty", "straightness", "Y", "Z",
     Profile(-4.0, 0.8, 3.0, -0.8, 0.2, 0.4, slope=52.0, intercept=-11.4, runs=3),
     "straightness in Z (vertical), straightness optics"),
    ("Y-angular-X.rta", "angular", "Y", "X",
     Profile(4.5, 1.0, 2.0, 1.5, 0.4, 0.2), "pitch (about X), angular optics"),
    ("Y-angular-Z.rta", "angular", "Y", "Z",
     Profile(-3.0, 0.8, 2.5, 2.0, 0.3, 0.2), "yaw (about Z), angular optics"),
    ("Y-angular-Y.rta", "angular", "Y", "Y",
     Profile(2.5, 0.6, 1.5, -1.0, 0.2, 0.3), "roll (about Y), differential electronic levels"),
    # -- X, the carriage on the bridge: day 2 -------------------------------------------
    ("X-linear.rtl", "linear", "X", None,
     Linear(-9.0, 3.0, 20.0, 0.8, 2.5, 0.5, 0.2), "positioning, linear optics"),
    ("X-straightness-Y.stx", "straightness", "X", "Y",
     Profile(-2.5, 0.7, 2.0, 0.8, 0.2, 0.3, slope=27.0, intercept=-3.1, runs=3),
     "straightness in Y (horizontal), straightness optics"),
    ("X-straightness-Z.stx", "straightness", "X", "Z",
     Profile(-5.0, 0.6, 3.5, 0.5, 0.3, 0.3, slope=-44.0, intercept=8.7, runs=3),
     "straightness in Z (vertical; the sag of the bridge), straightness optics"),
    ("X-angular-Y.rta", "angular", "X", "Y",
     Profile(-3.5, 0.7, 2.0, 1.0, 0.3, 0.2), "pitch (about Y), angular optics"),
    ("X-angular-Z.rta", "angular", "X", "Z",
     Profile(2.0, 0.5, 3.0, -1.5, 0.2, 0.2), "yaw (about Z), angular optics"),
    ("X-angular-X.rta", "angular", "X", "X",
     Profile(-4.0, 0.8, 1.5, 1.0, 0.3, 0.3), "roll (about X), differential electronic levels"),
    # -- Z, the ram: day 3 ---------------------------------------------------------------
    ("Z-linear.rtl", "linear", "Z", None,
     Linear(18.0, -2.0, 16.0, 0.6, 3.0, -0.8, 0.4), "positioning, linear optics"),
    ("Z-straightness-X.stz", "straightness", "Z", "X",
     Profile(2.0, 0.5, 1.5, 0.6, 0.2, 0.25, slope=31.0, intercept=-2.4, runs=3),
     "straightness in X, straightness optics on a granite square"),
    ("Z-straightness-Y.stz", "straightness", "Z", "Y",
     Profile(-1.5, 0.4, 2.0, -0.7, 0.2, 0.25, slope=-18.0, intercept=4.9, runs=3),
     "straightness in Y, straightness optics on a granite square"),
    ("Z-angular-X.rta", "angular", "Z", "X",
     Profile(3.0, 0.6, 1.5, 1.0, 0.3, 0.2), "tilt about X, angular optics via a beam bender"),
    ("Z-angular-Y.rta", "angular", "Z", "Y",
     Profile(-2.5, 0.5, 2.0, -0.8, 0.3, 0.2), "tilt about Y, angular optics via a beam bender"),
    ("Z-angular-Z.rta", "angular", "Z", "Z",
     Profile(2.0, 0.4, 1.0, 0.5, 0.2, 0.3),
     "roll (about Z), two probes 200 mm apart on a granite square"),
)
# fmt: on

#: minutes a test takes, before the random part (0 to 5 min) is added
DURATION_MIN = {"linear": 31, "straightness": 22, "angular": 16}
#: minutes to change the set-up between two tests
SETUP_MIN = 20


def linear_targets(axis: str, rng: np.random.Generator) -> np.ndarray:
    """Targets from 0 to the end of travel, each inner one moved by up to ±20 % of the
    spacing so that the ballscrew's periodic error is sampled at changing phases."""
    end, p = TRAVEL_MM[axis], LINEAR_SPACING_MM[axis]
    n = int(round(end / p))
    targets = np.arange(n + 1) * p
    targets[1:-1] += np.round(rng.uniform(-0.2 * p, 0.2 * p, n - 1), 1)
    targets[-1] = end
    return targets


def profile_targets(axis: str) -> np.ndarray:
    end, p = TRAVEL_MM[axis], PROFILE_SPACING_MM[axis]
    return np.arange(int(round(end / p)) + 1) * p


def _shape(u: np.ndarray, m: Profile, phase: float) -> np.ndarray:
    """The systematic curve of a straightness or angular profile at u = x / travel."""
    return (
        m.bow * 4.0 * u * (1.0 - u)
        + m.wave * np.sin(2.0 * np.pi * m.wave_cycles * u + phase)
        + m.cubic * (2.0 * u - 1.0) ** 3
    )


def linear_runs(targets: np.ndarray, m: Linear, rng: np.random.Generator) -> dict:
    """Forward and backward runs (µm) of a positioning test."""
    x = targets
    u = x / x[-1]
    phase = rng.uniform(0.0, 2.0 * np.pi)
    curve = (
        m.slope_um_per_m * x / 1000.0
        + m.bow_um * 4.0 * u * (1.0 - u)
        + m.periodic_um * np.sin(2.0 * np.pi * x / m.lead_mm + phase)
    )
    reversal = m.reversal_um + m.reversal_growth_um * u
    forward, backward = [], []
    for run in range(m.runs):
        # a forward and a backward pass take the same time: both see the same drift
        drift = m.drift_um_per_m_per_run * run * x / 1000.0
        forward.append(curve + drift + rng.normal(0.0, m.noise_um, x.size))
        backward.append(curve + drift + reversal + rng.normal(0.0, m.noise_um, x.size))
    zero = forward[0][0]  # the laser reading is zeroed at the first target of run 1
    return {
        "forward": np.round(np.array(forward) - zero, 3),
        "backward": np.round(np.array(backward) - zero, 3),
    }


def profile_runs(targets: np.ndarray, m: Profile, kind: str, rng: np.random.Generator) -> dict:
    """Forward and backward runs of a straightness (µm) or angular (µm/m) test."""
    u = targets / targets[-1]
    curve = _shape(u, m, rng.uniform(0.0, 2.0 * np.pi))
    if kind == "straightness":
        curve = curve + m.intercept + m.slope * u
    forward, backward = [], []
    for _ in range(m.runs):
        forward.append(curve + rng.normal(0.0, m.noise, u.size))
        backward.append(curve + m.reversal + rng.normal(0.0, m.noise, u.size))
    zero = forward[0][0] if kind == "angular" else 0.0
    return {
        "forward": np.round(np.array(forward) - zero, 3),
        "backward": np.round(np.array(backward) - zero, 3),
    }


def _next_slot(start: datetime, minutes: int) -> tuple[datetime, datetime]:
    """A test of ``minutes`` starting at ``start``, moved to the next morning if it would
    end after the working day."""
    end = start + timedelta(minutes=minutes)
    if (end.hour, end.minute) > DAY_END:
        start = (start + timedelta(days=1)).replace(hour=DAY_START[0], minute=DAY_START[1])
        end = start + timedelta(minutes=minutes)
    return start, end


def _stamp(t: datetime) -> str:
    return t.strftime("%H:%M %b %d %Y")


def _hours_into_day(t: datetime) -> float:
    return t.hour + t.minute / 60.0 - (DAY_START[0] + DAY_START[1] / 60.0)


def _environment(start: datetime, end: datetime, rng: np.random.Generator) -> dict:
    """Readings at the start and end of a test: the shop warms through the day."""
    air = [20.2 + 0.12 * _hours_into_day(t) + rng.normal(0.0, 0.03) for t in (start, end)]
    mat = [a - 0.25 + rng.normal(0.0, 0.02) for a in air]
    press = 101.25 - 0.15 * (start.day - FIRST_DAY.day) + rng.normal(0.0, 0.02)
    press = [press, press + rng.normal(0.0, 0.03)]
    humid = rng.uniform(41.0, 48.0)
    humid = [humid, humid + rng.normal(0.0, 0.4)]
    return {
        "Air temp": (f"{air[0]:.2f}", f"{air[1]:.2f}", "0"),
        "Air press": (f"{press[0]:.2f}", f"{press[1]:.2f}", "1"),
        "Air humid": (f"{humid[0]:.1f}", f"{humid[1]:.1f}", "0"),
        "Mat temp 1": (f"{mat[0]:.2f}", f"{mat[1]:.2f}", "1"),
        "Exp coeff": (f"{EXP_COEFF_PPM:.6f}", f"{EXP_COEFF_PPM:.6f}", "0"),
        "Date Time": (_stamp(start), _stamp(end)),
    }


def profiles() -> dict[str, ErrorProfile]:
    """File name -> profile of every file of the data set, in :data:`PLAN` order."""
    out: dict[str, ErrorProfile] = {}
    clock = FIRST_DAY
    for index, (name, kind, axis, about, model, how) in enumerate(PLAN):
        rng = np.random.default_rng([SEED, index])
        if kind == "linear":
            targets = linear_targets(axis, rng)
            runs = linear_runs(targets, model, rng)
        else:
            targets = profile_targets(axis)
            runs = profile_runs(targets, model, kind, rng)
        minutes = DURATION_MIN[kind] + int(rng.integers(0, 6))
        if index and axis != PLAN[index - 1][2]:
            # each axis on a day of its own
            clock = (clock + timedelta(days=1)).replace(hour=DAY_START[0], minute=DAY_START[1])
        start, end = _next_slot(clock, minutes)
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
