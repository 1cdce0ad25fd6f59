"""Make the identification examples from known machines through the exact 4x4 chain.

    python data/examples/identify/make_data.py

Each example folder holds the measurement files, the ``machine.toml`` that identifies the
machine from them, and ``truth.csv``: the error curves the data were made from (the
straightness without its least-squares line, as esp reads a straightness), so that the
recovery can be seen. The readings carry normal noise of the stated standard uncertainty,
and each artefact an error of its calibration, common to all its readings, drawn from the
calibration uncertainty its set states (``calibration = { ... }``).
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
#: the standard uncertainties of the artefacts' calibration, common to all their readings
#: (docs/identify.md, "Calibration of the artefact"):
#: a ball plate's scale, µm/m: its certificate's U = 1.0 µm/m (k = 2), and its temperature
#: known within ±0.15 K (steel, 11.5 µm/(m·K); rectangular, 1.0 µm/m), root-sum-square
PLATE_U_PPM = 1.1
#: a ballbar's length, µm: the bar set on its calibrator, whose certificate states
#: U = 1.0 µm (k = 2)
BALLBAR_U_UM = 0.5
#: a tracking interferometer's scale, µm/m: the air's refractive index from the
#: compensation's sensors, ±0.5 K and ±1 hPa (Edlén 1966: 0.93 µm/m per K and 0.27 µm/m
#: per hPa; rectangular: 0.27 and 0.16 µm/m) and the laser's vacuum wavelength
TRACKER_U_PPM = 0.4
sys.path.insert(0, str(HERE.parents[2]))

from esp.config import machine_from_dict  # noqa: E402
from esp.core.models.bind import bind_model  # noqa: E402
from esp.identify.model import rotation  # noqa: E402
from esp.identify.simulate import actual_positions, commanded_for  # noqa: E402


def legendre_curve(coeffs, lo, hi, zero_start=True):
    """A smooth curve: Σ c_j P_j(u), j from 1 (zero at the low end when zero_start)."""
    from esp.identify.basis import legendre_values

    c = np.asarray(coeffs, dtype=float)

    def f(x):
        u = (2 * np.asarray(x, dtype=float) - lo - hi) / (hi - lo)
        v = legendre_values(u, len(c))[:, 1:] @ c
        if zero_start:
            v = v - legendre_values(np.array([-1.0]), len(c))[:, 1:] @ c
        return v

    return f


def wavy(amplitude, lo, hi, rng, straight=False):
    """A smooth curve outside a low-degree basis: a cubic plus a long sine."""
    a = rng.normal(0, amplitude, 3)
    phase = rng.uniform(0, 2 * np.pi)

    def f(x):
        u = (2 * np.asarray(x, dtype=float) - lo - hi) / (hi - lo)
        v = a[0] * u + a[1] * (1.5 * u**2 - 0.5) + a[2] * (2.5 * u**3 - 1.5 * u)
        v = v + 0.15 * amplitude * np.sin(2.2 * u + phase)
        if straight:
            return v
        u0 = -1.0
        v0 = a[0] * u0 + a[1] * (1.5 * u0**2 - 0.5) + a[2] * (2.5 * u0**3 - 1.5 * u0)
        return v - v0 - 0.15 * amplitude * np.sin(2.2 * u0 + phase)

    return f


def base_config(name, configuration, roles, travel, step):
    return {
        "machine": {"name": name, "configuration": configuration, "axes": roles},
        "axes": {a: {"travel": list(travel[a]), "step": step} for a in "XYZ"},
    }


def truth_for(machine, travel, rng, kinds=("linear", "straightness", "angular")):
    used = {str(t.component) for t in bind_model(machine).terms}
    truth = {}
    for name in sorted(used):
        parts = name.split(".")
        if parts[0] == "squareness":
            truth[name] = float(rng.normal(0, 4))
            continue
        if parts[1] not in kinds:
            continue
        lo, hi = travel[parts[0]]
        amp = {"linear": 4.0, "straightness": 2.0, "angular": 3.0}[parts[1]]
        f = wavy(amp, lo, hi, rng, straight=parts[1] == "straightness")
        if parts[1] == "straightness":
            f = detrended(f, lo, hi)
        truth[name] = f
    return truth


def detrended(f, lo, hi):
    """A straightness without its least-squares line over the travel: the line's slope is
    a squareness (ISO 230-1, 3.4.8), which the truth holds on its own."""
    xs = np.linspace(lo, hi, 401)
    coef = np.linalg.lstsq(np.c_[np.ones_like(xs), xs], f(xs), rcond=None)[0]
    return lambda x: f(x) - coef[0] - coef[1] * np.asarray(x, dtype=float)


def write_truth(folder, truth, travel):
    lines = [
        "# the error curves the data were made from (engine units: um, urad, um/m)",
        "component,position_mm,value",
    ]
    for name, f in truth.items():
        if not callable(f):
            lines.append(f"{name},,{f:.6f}")
            continue
        lo, hi = travel[name.split(".")[0]]
        x = np.linspace(lo, hi, 21)
        v = f(x)
        if ".straightness." in name:
            G = np.c_[np.ones_like(x), x]
            xs = np.linspace(lo, hi, 401)
            coef = np.linalg.lstsq(np.c_[np.ones_like(xs), xs], f(xs), rcond=None)[0]
            v = v - G @ coef
        lines += [f"{name},{a:g},{b:.6f}" for a, b in zip(x, v, strict=True)]
    (folder / "truth.csv").write_text("\n".join(lines) + "\n", encoding="utf-8")


def errors_toml(truth, degree):
    """The [axes.*.errors] and [squareness] lines that identify every truth component."""
    out = {}
    for name in truth:
        parts = name.split(".")
        if parts[0] == "squareness":
            out.setdefault("squareness", []).append(f"{parts[1]} = {{ identify = true }}")
            continue
        d = degree
        spec = f'{{ identify = {{ basis = "legendre", degree = {d} }} }}'
        if parts[1] == "linear":
            out.setdefault(parts[0], []).append(f"linear = {spec}")
        else:
            out.setdefault(parts[0], []).append(f"{parts[1]}.{parts[2]} = {spec}")
    return out


def header_toml(name, configuration, roles, travel, step, truth, degree, extra=""):
    lines = [
        f"# {name}: identified from indirect measurements (made by make_data.py)",
        "",
        "[machine]",
        f'name = "{name}"',
        f'configuration = "{configuration}"',
        "axes = { " + ", ".join(f'{k} = "{v}"' for k, v in roles.items()) + " }",
        "",
        "[analysis]",
        'datum = "negative"',
    ]
    errs = errors_toml(truth, degree)
    for a in "XYZ":
        lines += ["", f"[axes.{a}]", f"travel = [{travel[a][0]}, {travel[a][1]}]", f"step = {step}"]
        if a in errs:
            lines += ["", f"[axes.{a}.errors]", *errs[a]]
    if "squareness" in errs:
        lines += ["", "[squareness]", *errs["squareness"]]
    return "\n".join(lines) + "\n" + extra


def calibration_errors() -> dict[str, float]:
    """The artefacts' actual calibration errors, drawn from their stated uncertainties
    with a seed of their own (so that the noise of the readings is as it was)."""
    rng = np.random.default_rng(20023)
    return {
        "ballplate": float(rng.normal(0.0, PLATE_U_PPM)),
        "starprobe": float(rng.normal(0.0, PLATE_U_PPM)),
        "ballbar": float(rng.normal(0.0, BALLBAR_U_UM)),
        "tracker": float(rng.normal(0.0, TRACKER_U_PPM)),
    }


CALIBRATION = calibration_errors()


def cmm_ballplate(rng):
    folder = HERE / "cmm-ballplate"
    folder.mkdir(exist_ok=True)
    travel = {"X": (0, 800), "Y": (0, 600), "Z": (0, 500)}
    roles = {"bottom": "Y", "middle": "X", "top": "Z"}
    cfg = base_config("Bridge CMM (ball plate)", "wBMTt", roles, travel, 100)
    machine = machine_from_dict(cfg, HERE)
    truth = truth_for(machine, travel, rng)
    g = np.arange(5) * 100.0
    B = np.array([[x, y, 0.0] for x in g for y in g])  # 25 balls, 100 mm pitch
    poses = [
        (np.eye(3), [100, 20, 40]),
        (rotation(np.array([0, 0, 0.3])), [300, 50, 460]),
        (rotation(np.array([np.pi / 2, 0, 0])), [150, 300, 40]),
        (rotation(np.array([0, -np.pi / 2, 0])), [420, 100, 40]),
    ]
    u = 0.4
    rows = [
        "# ball plate in 4 poses: machine readings X Y Z (mm) of each ball, and its",
        "# calibrated position x y z (mm) in the plate's own frame",
        "pose,ball,X,Y,Z,x,y,z",
    ]
    # the plate's balls are (1 + κ) B: its certificate's B is off by its scale error κ
    scale = 1.0 + CALIBRATION["ballplate"] * 1e-6
    for k, (R, t) in enumerate(poses, start=1):
        W = scale * B @ np.asarray(R).T + np.asarray(t, dtype=float)
        P = commanded_for(machine, truth, W) + rng.normal(0, u / 1000.0, W.shape)
        for j, (p, b) in enumerate(zip(P, B, strict=True), start=1):
            rows.append(f"pose{k},{j},{p[0]:.5f},{p[1]:.5f},{p[2]:.5f},{b[0]:g},{b[1]:g},{b[2]:g}")
    (folder / "plate.csv").write_text("\n".join(rows) + "\n", encoding="utf-8")
    extra = (
        '\n[identify]\nk = 2\n\n[identify.measurements.plate]\nkind = "points"\n'
        f'file = "plate.csv"\nu_um = {u}\n'
        "# the plate's scale (µm/m): its certificate's U = 1.0 µm/m (k = 2) and its temperature\n"
        "# within ±0.15 K (steel, 11.5 µm/(m·K)), root-sum-square\n"
        f"calibration = {{ u_ppm = {PLATE_U_PPM} }}\n"
    )
    (folder / "machine.toml").write_text(
        header_toml("Bridge CMM (ball plate)", "wBMTt", roles, travel, 100, truth, 3, extra),
        encoding="utf-8",
    )
    write_truth(folder, truth, travel)


def cmm_starprobe(rng):
    """The bridge CMM again, all 21 components: each ball of the plate probed with the
    three styli of a star probe, whose offsets from the MCP (not on one line) give the
    angles of every axis a lever (docs/identify.md, "Tool offsets")."""
    folder = HERE / "cmm-starprobe"
    folder.mkdir(exist_ok=True)
    travel = {"X": (0, 800), "Y": (0, 600), "Z": (0, 500)}
    roles = {"bottom": "Y", "middle": "X", "top": "Z"}
    name = "Bridge CMM (ball plate, star probe)"
    cfg = base_config(name, "wBMTt", roles, travel, 100)
    # the engine's terms with a tool's lever: all 21 act
    cfg["analysis"] = {"point": "TCP"}
    cfg["tool"] = {"lengths": [100], "orientation": {"tilt": 0, "spin": 0}}
    truth = truth_for(machine_from_dict(cfg, HERE), travel, rng)
    machine = machine_from_dict(base_config(name, "wBMTt", roles, travel, 100), HERE)
    styli = {"down": (0.0, 0.0, -100.0), "east": (100.0, 0.0, -60.0), "north": (0.0, 100.0, -60.0)}
    g = np.arange(5) * 90.0
    B = np.array([[x, y, 0.0] for x in g for y in g])  # 25 balls, 90 mm pitch
    poses = [
        (np.eye(3), [120, 120, -40]),
        (rotation(np.array([0, 0, 0.3])), [350, 130, 380]),
        (rotation(np.array([np.pi / 2, 0, 0])), [120, 350, -40]),
        (rotation(np.array([0, -np.pi / 2, 0])), [450, 120, -40]),
    ]
    u = 0.4
    rows = [
        "# ball plate in 4 poses, each ball probed with each stylus of a star probe: the",
        "# machine readings X Y Z (mm) of the MCP, the stylus, and the ball's calibrated",
        "# position x y z (mm) in the plate's own frame",
        "pose,ball,tool,X,Y,Z,x,y,z",
    ]
    scale = 1.0 + CALIBRATION["starprobe"] * 1e-6
    for k, (R, t) in enumerate(poses, start=1):
        W = scale * B @ np.asarray(R).T + np.asarray(t, dtype=float)
        for label, offset in styli.items():
            T = dict(zip("XYZ", offset, strict=True))
            P = commanded_for(machine, truth, W, T) + rng.normal(0, u / 1000.0, W.shape)
            for j, (p, b) in enumerate(zip(P, B, strict=True), start=1):
                rows.append(
                    f"pose{k},{j},{label},{p[0]:.5f},{p[1]:.5f},{p[2]:.5f},"
                    f"{b[0]:g},{b[1]:g},{b[2]:g}"
                )
    (folder / "plate.csv").write_text("\n".join(rows) + "\n", encoding="utf-8")
    tools = "\n".join(f"{s} = [{o[0]:g}, {o[1]:g}, {o[2]:g}]" for s, o in styli.items())
    extra = (
        '\n[identify]\nk = 2\n\n[identify.measurements.plate]\nkind = "points"\n'
        f'file = "plate.csv"\nu_um = {u}\n'
        "# the plate's scale (µm/m): its certificate's U = 1.0 µm/m (k = 2) and its temperature\n"
        "# within ±0.15 K (steel, 11.5 µm/(m·K)), root-sum-square\n"
        f"calibration = {{ u_ppm = {PLATE_U_PPM} }}\n\n"
        "# the offset of each stylus' ball centre from the MCP (mm): the column tool\n"
        "[identify.measurements.plate.tool_mm]\n" + tools + "\n"
    )
    (folder / "machine.toml").write_text(
        header_toml(name, "wBMTt", roles, travel, 100, truth, 3, extra), encoding="utf-8"
    )
    write_truth(folder, truth, travel)


def tool_machine(rng):
    travel = {"X": (0, 800), "Y": (0, 500), "Z": (0, 400)}
    roles = {"bottom": "X", "middle": "Y", "top": "Z"}
    cfg = base_config("Vertical machining centre", "BwMTt", roles, travel, 50)
    machine = machine_from_dict(cfg, HERE)
    return travel, roles, machine


def tool_ballbar(rng, travel, roles, machine, truth):
    folder = HERE / "tool-ballbar"
    folder.mkdir(exist_ok=True)
    R = 150.0
    u = 0.3
    rows = [
        "# ballbar circles (ISO 230-4) in the three planes; centre and length nominal",
        "circle,direction,X,Y,Z,cx,cy,cz,length_mm,deviation_um",
    ]
    circles = []
    for plane, fixed in (("XY", (100.0, 300.0)), ("XZ", (100.0, 400.0)), ("YZ", (200.0, 600.0))):
        a, b = plane
        c_axis = next(x for x in "XYZ" if x not in plane)
        for level in fixed:
            for ca in np.linspace(travel[a][0] + R + 10, travel[a][1] - R - 10, 3):
                cb = (travel[b][0] + travel[b][1]) / 2.0
                if travel[b][1] - travel[b][0] < 2 * R + 20:
                    continue
                circles.append((plane, a, b, c_axis, level, ca, cb))
    theta = np.radians(np.arange(0, 360, 7.5))
    for n, (_plane, a, b, c_axis, level, ca, cb) in enumerate(circles, start=1):
        centre = {a: ca, b: cb, c_axis: level}
        C = np.array([centre["X"], centre["Y"], centre["Z"]])
        # the table ball sits where the machine was commanded to put the centre
        Ct = actual_positions(machine, truth, C[None, :])[0]
        for direction, sign in (("ccw", 1.0), ("cw", -1.0)):
            P = np.tile(C, (theta.size, 1))
            P[:, "XYZ".index(a)] += R * np.cos(sign * theta)
            P[:, "XYZ".index(b)] += R * np.sin(sign * theta)
            Q = actual_positions(machine, truth, P)
            L = np.linalg.norm(Q - Ct, axis=1)
            # a bar longer than its calibrator says reads every deviation shorter
            dev = 1000.0 * (L - R) - CALIBRATION["ballbar"] + rng.normal(0, u, L.size)
            for p, d in zip(P, dev, strict=True):
                rows.append(
                    f"c{n},{direction},{p[0]:.4f},{p[1]:.4f},{p[2]:.4f},{C[0]:g},{C[1]:g},"
                    f"{C[2]:g},{R:g},{d:.4f}"
                )
    (folder / "ballbar.csv").write_text("\n".join(rows) + "\n", encoding="utf-8")
    # the first circle alone, for esp ballbar
    first = [r for r in rows[2:] if r.startswith("c1,")]
    (folder / "circle-XY.csv").write_text("\n".join(rows[:2] + first) + "\n", encoding="utf-8")
    return folder, u


def tool_tracker(rng, travel, roles, machine, truth):
    folder = HERE / "tool-tracker"
    folder.mkdir(exist_ok=True)
    stations = {
        "S1": np.array([-300.0, -300.0, 200.0]),
        "S2": np.array([1100.0, -250.0, 350.0]),
        "S3": np.array([1050.0, 800.0, 150.0]),
        "S4": np.array([-250.0, 750.0, 450.0]),
    }
    dead = {"S1": 120.0, "S2": 95.0, "S3": 140.0, "S4": 80.0}
    n = 120
    P = np.column_stack([rng.uniform(*travel[a], n) for a in "XYZ"])
    Q = actual_positions(machine, truth, P)
    u = 0.2
    rows = [
        "# tracking interferometer: change of distance (um) from each station to the tool,",
        "# zero at an unknown dead path; station positions approximate in machine.toml",
        "station,X,Y,Z,reading_um",
    ]
    for s, S in stations.items():
        d = np.linalg.norm(Q - S, axis=1)
        # the laser's scale error κ: every distance read (1 + κ) times its length
        true = 1000.0 * (d - d.min() + dead[s] / 1000.0)
        reading = true * (1.0 + CALIBRATION["tracker"] * 1e-6) + rng.normal(0, u, n)
        for p, r in zip(P, reading, strict=True):
            rows.append(f"{s},{p[0]:.4f},{p[1]:.4f},{p[2]:.4f},{r:.4f}")
    (folder / "tracker.csv").write_text("\n".join(rows) + "\n", encoding="utf-8")
    approx = {s: S + rng.normal(0, 20.0, 3) for s, S in stations.items()}
    return folder, u, approx


def main():
    rng = np.random.default_rng(20021)
    cmm_ballplate(rng)
    travel, roles, machine = tool_machine(rng)
    truth = truth_for(machine, travel, rng, kinds=("linear", "straightness"))
    folder, u = tool_ballbar(rng, travel, roles, machine, truth)
    extra = (
        '\n[identify]\nk = 2\n\n[identify.measurements.circles]\nkind = "lengths"\n'
        'form = "ballbar"\nfile = "ballbar.csv"\n'
        f'u_um = {u}\ncentre = "unknown"\nradius = "known"\n'
        "# the bar's length (µm), set on its calibrator: the certificate's U = 1.0 µm (k = 2)\n"
        f"calibration = {{ u_um = {BALLBAR_U_UM} }}\n"
    )
    name = "Vertical machining centre"
    (folder / "machine.toml").write_text(
        header_toml(name + " (ballbar)", "BwMTt", roles, travel, 50, truth, 3, extra),
        encoding="utf-8",
    )
    write_truth(folder, truth, travel)
    folder, u, approx = tool_tracker(rng, travel, roles, machine, truth)
    st = "\n".join(f"{s} = [{a[0]:.1f}, {a[1]:.1f}, {a[2]:.1f}]" for s, a in approx.items())
    extra = (
        '\n[identify]\nk = 2\n\n[identify.measurements.tracker]\nkind = "stations"\n'
        f'file = "tracker.csv"\nu_um = {u}\n'
        "# the laser's scale (µm/m): the air's refractive index from the compensation's sensors\n"
        "# (±0.5 K, ±1 hPa; Edlén 1966) and the vacuum wavelength\n"
        f"calibration = {{ u_ppm = {TRACKER_U_PPM} }}\n\n"
        "[identify.measurements.tracker.stations]\n" + st + "\n"
    )
    (folder / "machine.toml").write_text(
        header_toml(
            name + " (tracking interferometer)", "BwMTt", roles, travel, 50, truth, 3, extra
        ),
        encoding="utf-8",
    )
    write_truth(folder, truth, travel)
    # its own seed, so that the examples above stay as they were
    cmm_starprobe(np.random.default_rng(20022))


if __name__ == "__main__":
    main()
