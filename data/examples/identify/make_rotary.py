"""Make the rotary-table identification examples from a known trunnion through its exact
4x4 chain.

    python data/examples/identify/make_rotary.py

``trunnion-spheres/``: an A/C trunnion on a three-axis machine (linear axes taken as
perfect here), a calibration sphere on the table probed at the settings of a
KinematicsOpt-style cycle (C turned at A = 0, A tilted at C = 0, and C turned at A = 60).
The readings are where the exact chain puts the sphere's centre (T(θ)⁻¹ s) plus normal
noise of the stated u. ``truth.csv`` holds the location errors the data were made from
and the error of the probe's calibrated offset (µm), common to all readings.

``trunnion-rtest/``: the same trunnion, with error motions (an angular positioning error
of C over its turn, one of A over its travel), measured by an R-test: a sensor nest of
three displacement sensors at the tool tip reads a precision sphere on the table along
four paths (ISO 10791-6 style: C turning at A = 0 and at A = 45, A tilting at C = 0 and
at C = 90), the linear axes following the sphere; each path's sensors zeroed at its
start.

``head-spheres/``: the angle head of Freeman & Ford (2003) on a gantry (its chain in
../heads; linear axes taken as perfect), the five errors of their Fig. 3 identified from a
sphere on the bed probed at 48 head settings (A every 45 deg, C every 60 deg); the
readings where the head's exact chain puts the tool tip.

``trunnion-ballbar/``: the same trunnion's location errors from a ballbar between a ball
on the table and the tool ball, the bar radial, tangential and axial to C as C turns,
and to A as A tilts; the bar's length calibrated, the table ball's place unknown.

Running it again writes the same bytes.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parents[2]))

from esp.config.devices import load_table  # noqa: E402
from esp.identify.simulate import probed_centres  # noqa: E402

#: the location errors of the trunnion (ISO 230-1 / 230-7; µm and µrad)
LOCATION = {
    "X0C": 6.0,
    "Y0C": -9.0,
    "A0C": 12.1,
    "B0C": -8.0,
    "Y0A": 14.0,
    "Z0A": -11.0,
    "B0A": 10.0,
    "C0A": -15.0,
}
#: the standard uncertainty of one probed centre, µm (the probe's repeatability)
U_UM = 0.5
#: the standard uncertainty of the probe's calibrated offset along each axis, µm: the
#: calibration on a ring gauge of certified diameter, U = 1 µm (k = 2); the data carry an
#: offset error drawn from it, common to all readings
PROBE_U_UM = 0.5
#: the sphere, workpiece frame (mm): 150 mm from the C axis, 40 mm above the table face
SPHERE = (450.0, 0.0, 40.0)

TABLE_TOML = """\
# The A/C trunnion of ../../rotary (its chain and geometry), with its eight location
# errors to identify: where the C axis sits in the cradle (X0C, Y0C) and how it leans
# (A0C, B0C), where the A axis sits on the machine (Y0A, Z0A) and how it leans (B0A, C0A).

[table]
name = "A/C trunnion table"
chain = "../../rotary/trunnion-ac.toml"

[table.parameters]
x_C = 300     # mm: the C axis line at A = 0
y_C = 0
z_C = 0       # the table face
x_A = 300     # the middle of the cradle
y_A = 0       # the A axis line
z_A = 100

[table.errors]
X0C = { identify = true }   # um
Y0C = { identify = true }   # um
A0C = { identify = true }   # urad
B0C = { identify = true }   # urad
Y0A = { identify = true }   # um
Z0A = { identify = true }   # um
B0A = { identify = true }   # urad
C0A = { identify = true }   # urad
"""

MACHINE_TOML = """\
# A five-axis machining centre: three linear axes carrying the tool and an A/C trunnion
# carrying the workpiece. The trunnion's location errors are identified from a sphere
# on the table probed at 15 settings (made by make_rotary.py).
#
#   esp identify data/examples/identify/trunnion-spheres/machine.toml
#   esp identify data/examples/identify/trunnion-spheres/machine.toml --plan

[machine]
name = "Five-axis trunnion machine"
configuration = "BwMTt"
axes = {{ bottom = "X", middle = "Y", top = "Z" }}

[analysis]
datum = "negative"

[table]
file = "table.toml"
angles = {{ A = [-90, -45, 0, 45, 90], C = [0, 90, 180, 270] }}

[axes.X]
travel = [0, 600]
step = 50

[axes.Y]
travel = [-400, 400]
step = 50

[axes.Z]
travel = [-300, 500]
step = 50

[identify]
k = 2

[identify.measurements.sphere]
kind = "sphere"
file = "spheres.csv"
u_um = {u}               # each centre: the probe's repeatability
probe = "known"         # the probe's offset calibrated on a ring gauge beforehand
calibration = {{ u_um = {probe} }}   # that calibration's standard uncertainty, each axis
"""


def settings() -> tuple[np.ndarray, np.ndarray]:
    """A, C of each probing: C every 60 deg at A = 0, A every 30 deg at C = 0, C every
    90 deg at A = 60."""
    a, c = [], []
    for C in range(0, 360, 60):
        a.append(0.0)
        c.append(float(C))
    for A in (-90, -60, -30, 30, 60, 90):
        a.append(float(A))
        c.append(0.0)
    for C in (90, 180, 270):
        a.append(60.0)
        c.append(float(C))
    return np.array(a), np.array(c)


def main() -> None:
    rng = np.random.default_rng(20023)
    folder = HERE / "trunnion-spheres"
    folder.mkdir(exist_ok=True)
    (folder / "table.toml").write_text(TABLE_TOML, encoding="utf-8")
    (folder / "machine.toml").write_text(
        MACHINE_TOML.format(u=U_UM, probe=PROBE_U_UM), encoding="utf-8"
    )
    table = load_table(folder / "table.toml")
    A, C = settings()
    m = probed_centres(table, LOCATION, {"A": A, "C": C}, SPHERE)
    # the probe's actual offset is off its calibrated value by d: the tip reaches the
    # sphere's centre when commanded d short of it
    d_um = rng.normal(0.0, PROBE_U_UM, 3)
    m = m - d_um / 1000.0 + rng.normal(0.0, U_UM / 1000.0, m.shape)
    rows = [
        "# a calibration sphere on the table, probed at each setting: its centre as the",
        "# machine reads it (probe ball centre, machine coordinates, mm)",
        "sphere,A,C,X,Y,Z",
    ]
    for a, c, p in zip(A, C, m, strict=True):
        rows.append(f"S1,{a:g},{c:g},{p[0]:.5f},{p[1]:.5f},{p[2]:.5f}")
    (folder / "spheres.csv").write_text("\n".join(rows) + "\n", encoding="utf-8")
    truth = ["# the location errors the data were made from (um, urad)", "error,value"]
    truth += [f"{k},{v:g}" for k, v in LOCATION.items()]
    truth += [f"probe_{a},{v:.4f}" for a, v in zip("xyz", d_um, strict=True)]
    (folder / "truth.csv").write_text("\n".join(truth) + "\n", encoding="utf-8")


#: the error motions of the R-test example: ECC over C (µrad) and EAA over A (µrad)
def ecc(c):
    r = np.radians(np.asarray(c, dtype=float))
    return 8.0 * np.cos(r) - 5.0 * np.sin(2 * r) + 1.5 * np.cos(3 * r)


def eaa(a):
    u = np.asarray(a, dtype=float) / 90.0
    return 6.0 * u + 2.0 * u**2


RTEST_TABLE = TABLE_TOML.replace(
    "C0A = { identify = true }   # urad\n",
    "C0A = { identify = true }   # urad\n"
    'ECC = { identify = { basis = "fourier", order = 3 } }      # urad, over C\n'
    'EAA = { identify = { basis = "legendre", degree = 3 } }    # urad, over A\n',
).replace(
    "# (A0C, B0C), where the A axis sits on the machine (Y0A, Z0A) and how it leans (B0A, C0A).",
    "# (A0C, B0C), where the A axis sits on the machine (Y0A, Z0A) and how it leans (B0A, C0A);\n"
    "# and the angular positioning errors of C over its turn and of A over its travel.",
)

HEADER = """\
[machine]
name = "Five-axis trunnion machine"
configuration = "BwMTt"
axes = {{ bottom = "X", middle = "Y", top = "Z" }}

[analysis]
datum = "negative"

[table]
file = "table.toml"
angles = {{ A = [-90, -45, 0, 45, 90], C = [0, 90, 180, 270] }}

[axes.X]
travel = [0, 600]
step = 50

[axes.Y]
travel = [-400, 400]
step = 50

[axes.Z]
travel = [-300, 500]
step = 50
"""

RTEST_MACHINE = (
    """\
# A five-axis machining centre with an A/C trunnion: the trunnion's location errors and
# the angular positioning errors of A and C identified from an R-test along four paths
# (made by make_rotary.py).
#
#   esp identify data/examples/identify/trunnion-rtest/machine.toml
#
# The sensors are zeroed at the start of each path, so a constant displacement of the
# tool relative to the workpiece is not seen: X0C (along the A axis, so constant at every
# setting), Y0A and Z0A (the A axis line displaced) move the tool by the same amount at
# every setting and are fixed (docs/identify.md, "Rotary tables").

"""
    + HEADER
    + """
[identify]
k = 2
fix = ["table.X0C", "table.Y0A", "table.Z0A"]

[identify.measurements.rtest]
kind = "rtest"
file = "rtest.csv"
u_um = {u}                  # each sensor reading
sensors = {{ d1 = [1, 0, 0], d2 = [0, 1, 0], d3 = [0, 0, 1] }}   # measuring directions
calibration = {{ u_ppm = {gain} }}   # the sensors' gain, from their calibration (µm/m)
"""
)

BALLBAR_MACHINE = (
    """\
# A five-axis machining centre with an A/C trunnion: the trunnion's location errors
# identified from a ballbar between a ball on the table and the tool ball, as C turns and
# as A tilts (made by make_rotary.py).
#
#   esp identify data/examples/identify/trunnion-ballbar/machine.toml

"""
    + HEADER
    + """
[identify]
k = 2

[identify.measurements.ballbar]
kind = "rotary-ballbar"
file = "ballbar.csv"
u_um = {u}                  # each length reading
pivot_mm = [400, 0, 30]     # the table ball, nominal, workpiece frame (mm)
length_mm = 100             # the bar's nominal length
pivot = "unknown"           # the table ball's place is fitted
length = "known"
calibration = {{ u_um = {cal} }}   # the bar's length, set on its calibrator (µm)
"""
)

#: the R-test's sensors (µm) and the ballbar's length readings (µm), standard uncertainty
RTEST_U_UM = 0.3
#: the standard uncertainty of the R-test sensors' gain, µm/m (0.05 %: a calibration of
#: the sensors against a gauge block stack); the data carry a gain error drawn from it
RTEST_GAIN_PPM = 500
BALLBAR_U_UM = 0.3
#: the ballbar's length calibration, µm (U = 1 µm at k = 2)
BAR_U_UM = 0.5
#: the R-test's sphere and the ballbar's table ball, workpiece frame, mm
RTEST_SPHERE = (450.0, 0.0, 40.0)
BALLBAR_PIVOT = (400.0, 0.0, 30.0)


def _truth_file(folder: Path, values: dict[str, float], curves: dict) -> None:
    truth = ["# the errors the data were made from (um, urad; a curve at its angles, deg)"]
    truth.append("error,angle_deg,value")
    truth += [f"{k},,{v:g}" for k, v in values.items()]
    for name, (f, angles) in curves.items():
        truth += [f"{name},{a:g},{float(f(a)):.6f}" for a in angles]
    (folder / "truth.csv").write_text("\n".join(truth) + "\n", encoding="utf-8")


def rtest(rng: np.random.Generator) -> None:
    folder = HERE / "trunnion-rtest"
    folder.mkdir(exist_ok=True)
    (folder / "table.toml").write_text(RTEST_TABLE, encoding="utf-8")
    (folder / "machine.toml").write_text(
        RTEST_MACHINE.format(u=RTEST_U_UM, gain=RTEST_GAIN_PPM), encoding="utf-8"
    )
    table = load_table(folder / "table.toml")
    truth = dict(LOCATION, ECC=ecc, EAA=eaa)
    gain = rng.normal(0.0, RTEST_GAIN_PPM * 1e-6)  # the sensors' actual gain error
    C = np.arange(0.0, 360.0, 5.0)
    A = np.arange(-90.0, 91.0, 5.0)
    paths = {
        "K1": (np.zeros_like(C), C),
        "K2": (A, np.zeros_like(A)),
        "K3": (A, np.full_like(A, 90.0)),
        "K4": (np.full_like(C, 45.0), C),
    }
    rows = [
        "# R-test: three sensors of a nest at the tool tip read a sphere on the table; X, Y, Z",
        "# the tool tip commanded (the sphere's nominal place), d1..d3 the readings (um),",
        "# zeroed at the start of each path",
        "path,A,C,X,Y,Z,d1_um,d2_um,d3_um",
    ]
    for name, (a, c) in paths.items():
        at = {"A": a, "C": c}
        p = probed_centres(table, {}, at, RTEST_SPHERE)  # the tool follows the nominal sphere
        q = probed_centres(table, truth, at, RTEST_SPHERE)  # where the sphere is
        d = 1000.0 * (q - p)
        d = (1.0 + gain) * (d - d[0]) + rng.normal(0.0, RTEST_U_UM, d.shape)
        rows += [
            f"{name},{x:g},{y:g},{pp[0]:.5f},{pp[1]:.5f},{pp[2]:.5f},"
            f"{dd[0]:.4f},{dd[1]:.4f},{dd[2]:.4f}"
            for x, y, pp, dd in zip(a, c, p, d, strict=True)
        ]
    (folder / "rtest.csv").write_text("\n".join(rows) + "\n", encoding="utf-8")
    _truth_file(
        folder,
        dict(LOCATION, sensor_gain_ppm=float(round(gain * 1e6, 3))),
        {"ECC": (ecc, np.arange(0.0, 360.0, 30.0)), "EAA": (eaa, np.arange(-90.0, 91.0, 30.0))},
    )


def ballbar(rng: np.random.Generator) -> None:
    folder = HERE / "trunnion-ballbar"
    folder.mkdir(exist_ok=True)
    (folder / "table.toml").write_text(TABLE_TOML, encoding="utf-8")
    (folder / "machine.toml").write_text(
        BALLBAR_MACHINE.format(u=BALLBAR_U_UM, cal=BAR_U_UM), encoding="utf-8"
    )
    table = load_table(folder / "table.toml")
    bar_error_um = rng.normal(0.0, BAR_U_UM)  # the bar's actual length less its stated one
    s = np.array(BALLBAR_PIVOT)
    C = np.arange(0.0, 360.0, 10.0)
    A = np.arange(-90.0, 91.0, 10.0)
    runs = {
        "C-radial": (np.zeros_like(C), C, (-100.0, 0.0, 0.0)),
        "C-tangential": (np.zeros_like(C), C, (0.0, 100.0, 0.0)),
        "C-axial": (np.zeros_like(C), C, (0.0, 0.0, 100.0)),
        "A-radial": (A, np.zeros_like(A), (0.0, 0.0, 100.0)),
        "A-tangential": (A, np.zeros_like(A), (0.0, 100.0, 0.0)),
        "A-axial": (A, np.zeros_like(A), (100.0, 0.0, 0.0)),
    }
    rows = [
        "# ballbar between a ball on the table and the tool ball: the bar's direction fixed",
        "# on the table (radial, tangential, axial); X, Y, Z the tool ball commanded, the",
        "# deviation the bar's length less its nominal 100 mm (um)",
        "run,A,C,X,Y,Z,deviation_um",
    ]
    for name, (a, c, offset) in runs.items():
        at = {"A": a, "C": c}
        p = probed_centres(table, {}, at, s + np.array(offset))  # the tool ball commanded
        q = probed_centres(table, LOCATION, at, s)  # the table ball, where it is
        length = np.linalg.norm(p - q, axis=1)
        # a bar longer by bar_error_um reads shorter by as much
        dev = 1000.0 * (length - 100.0) - bar_error_um + rng.normal(0.0, BALLBAR_U_UM, a.size)
        rows += [
            f"{name},{x:g},{y:g},{pp[0]:.5f},{pp[1]:.5f},{pp[2]:.5f},{v:.4f}"
            for x, y, pp, v in zip(a, c, p, dev, strict=True)
        ]
    (folder / "ballbar.csv").write_text("\n".join(rows) + "\n", encoding="utf-8")
    _truth_file(folder, dict(LOCATION, bar_length_um=float(round(bar_error_um, 4))), {})


#: the errors of the angle head, Freeman & Ford (2003), Fig. 3 (arcsec, mm)
HEAD_ERRORS = {"ThetaAs": 100.0, "Ocx": 0.005, "Ocy": -0.015, "ThetaCh": 150.0, "ThetaCv": -50.0}
HEAD_U_UM = 0.5
HEAD_SPHERE = (500.0, 400.0, 100.0)

HEAD_TOML = """\
# The angle head of Freeman & Ford (2003) (its chain in ../../heads), with the five
# errors of their Fig. 3 to identify; the others of the chain held at zero.

[head]
name = "Angle head"
chain = "../../heads/angle-head.toml"

[head.parameters]
G = 150     # mm, spindle nose to tool tip
e = 10      # mm
Yp = 50     # deg

[head.errors]
ThetaAs = { identify = true }   # arcsec
Ocx = { identify = true }       # mm
Ocy = { identify = true }       # mm
ThetaCh = { identify = true }   # arcsec
ThetaCv = { identify = true }   # arcsec
Oas = 0
ThetaAv = 0
DY = 0
"""

HEAD_MACHINE = """\
# A five-axis gantry with an angle head: the head's errors identified from a sphere on
# the bed probed at 48 head settings (made by make_rotary.py). The gantry's own errors are
# taken as zero here (measured and compensated beforehand).
#
#   esp identify data/examples/identify/head-spheres/machine.toml --out head
#   esp analyse head/machine.toml

[machine]
name = "GX-1500 with angle head"
configuration = "wBMTt"
axes = {{ bottom = "Y", middle = "X", top = "Z" }}

[analysis]
point = "TCP"
datum = "negative"

[head]
file = "head.toml"
angles = {{ A = [0, 90, 180, 270], C = [0, 90, 180, 270] }}

[axes.Y]
travel = [0, 1500]
step = 50

[axes.X]
travel = [0, 1000]
step = 50

[axes.Z]
travel = [0, 600]
step = 25

[identify]
k = 2

[identify.measurements.sphere]
kind = "sphere"
file = "spheres.csv"
u_um = {u}               # each centre: the probe's repeatability
"""


def head(rng: np.random.Generator) -> None:
    from esp.config.devices import load_head
    from esp.core.devices.head_evaluate import evaluate_head

    folder = HERE / "head-spheres"
    folder.mkdir(exist_ok=True)
    (folder / "head.toml").write_text(HEAD_TOML, encoding="utf-8")
    (folder / "machine.toml").write_text(HEAD_MACHINE.format(u=HEAD_U_UM), encoding="utf-8")
    head_device, _ = load_head(folder / "head.toml")
    A, C = np.meshgrid(np.arange(0.0, 360.0, 45.0), np.arange(0.0, 360.0, 60.0))
    A, C = A.ravel(), C.ravel()
    exact = evaluate_head(head_device.with_values(HEAD_ERRORS), {"A": A, "C": C}).exact_um
    # the tool tip commanded to m is really at m + exact / 1000: it meets the sphere there
    m = np.array(HEAD_SPHERE) - exact / 1000.0 + rng.normal(0.0, HEAD_U_UM / 1000.0, exact.shape)
    rows = [
        "# a sphere on the bed, probed with the head at each setting: its centre as the",
        "# machine reads it (the tool tip commanded, machine coordinates, mm)",
        "sphere,A,C,X,Y,Z",
    ]
    rows += [
        f"S1,{a:g},{c:g},{p[0]:.5f},{p[1]:.5f},{p[2]:.5f}" for a, c, p in zip(A, C, m, strict=True)
    ]
    (folder / "spheres.csv").write_text("\n".join(rows) + "\n", encoding="utf-8")
    truth = ["# the head's errors the data were made from (arcsec, mm)", "error,angle_deg,value"]
    truth += [f"{k},,{v:g}" for k, v in HEAD_ERRORS.items()]
    (folder / "truth.csv").write_text("\n".join(truth) + "\n", encoding="utf-8")


if __name__ == "__main__":
    main()
    rtest(np.random.default_rng(20024))
    ballbar(np.random.default_rng(20025))
    head(np.random.default_rng(20026))
