"""Make the rotary-table identification example from a known trunnion through its exact
4x4 chain.

    python data/examples/identify/make_rotary.py

``trunnion-spheres/``: an A/C trunnion on a three-axis machine (linear axes taken as
perfect here), a calibration sphere on the table probed at the settings of a
KinematicsOpt-style cycle (C turned at A = 0, A tilted at C = 0, and C turned at A = 60).
The readings are where the exact chain puts the sphere's centre (T(θ)⁻¹ s) plus normal
noise of the stated u. ``truth.csv`` holds the location errors the data were made from
and the error of the probe's calibrated offset (µm), common to all readings. Running it
again writes the same bytes.
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


if __name__ == "__main__":
    main()
