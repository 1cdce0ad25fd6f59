"""esp identify with the errors of a rotary table as unknowns, from a probed sphere
(esp.identify.rotary; docs/identify.md, "Rotary tables"): readings made through the exact
4x4 chain of the table, recovery, identifiability worked by hand, the written table, the
round trip through esp analyse, and bad input."""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from esp.cli import main
from esp.config.devices import load_table
from esp.identify.config import load_problem
from esp.identify.run import identify, plan
from esp.identify.simulate import probed_centres

ROOT = Path(__file__).resolve().parent.parent
ROTARY = ROOT / "data/examples/rotary"
EXAMPLE = ROOT / "data/examples/identify/trunnion-spheres"

TRUNNION_PARAMS = """
[table.parameters]
x_C = 300
y_C = 0
z_C = 0
x_A = 300
y_A = 0
z_A = 100
"""

MACHINE = """
[machine]
name = "trunnion machine"
configuration = "BwMTt"
axes = {{ bottom = "X", middle = "Y", top = "Z" }}

[table]
file = "table.toml"
angles = {{ A = [-90, 0, 90], C = [0, 90, 180, 270] }}

[axes.X]
travel = [-200, 800]
step = 100

[axes.Y]
travel = [-400, 400]
step = 100

[axes.Z]
travel = [-400, 500]
step = 100

[identify]
k = 2
{identify}

[identify.measurements.sphere]
kind = "sphere"
file = "spheres.csv"
u_um = {u}
{extra}
"""


def _table_toml(errors: str) -> str:
    chain = (ROTARY / "trunnion-ac.toml").as_posix()
    return f'[table]\nchain = "{chain}"\n{TRUNNION_PARAMS}\n[table.errors]\n{errors}\n'


def _settings(kind: str) -> tuple[np.ndarray, np.ndarray]:
    if kind == "C only":
        c = np.arange(0.0, 360.0, 30.0)
        return np.zeros_like(c), c
    a, c = [], []
    for A in (-90.0, -60.0, -30.0, 0.0, 30.0, 60.0, 90.0):
        for C in np.arange(0.0, 360.0, 30.0):
            a.append(A)
            c.append(C)
    return np.array(a), np.array(c)


def _write(
    folder: Path,
    errors: str,
    truth: dict,
    *,
    settings: str = "full",
    spheres=((450.0, 0.0, 40.0),),
    u_um: float = 0.5,
    noise: float = 0.0,
    identify_extra: str = "",
    set_extra: str = "",
    seed: int = 1,
) -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "table.toml").write_text(_table_toml(errors), encoding="utf-8")
    (folder / "machine.toml").write_text(
        MACHINE.format(identify=identify_extra, u=u_um, extra=set_extra), encoding="utf-8"
    )
    table = load_table(folder / "table.toml")
    A, C = _settings(settings)
    rng = np.random.default_rng(seed)
    rows = ["sphere,A,C,X,Y,Z"]
    for k, s in enumerate(spheres):
        m = probed_centres(table, truth, {"A": A, "C": C}, s)
        m = m + rng.normal(0.0, noise / 1000.0, m.shape)
        rows += [
            f"S{k + 1},{a:g},{c:g},{p[0]:.7f},{p[1]:.7f},{p[2]:.7f}"
            for a, c, p in zip(A, C, m, strict=True)
        ]
    (folder / "spheres.csv").write_text("\n".join(rows) + "\n", encoding="utf-8")
    return folder / "machine.toml"


LOCATION = {
    "X0C": 6.0,
    "Y0C": -9.0,
    "A0C": 12.0,
    "B0C": -8.0,
    "Y0A": 14.0,
    "Z0A": -11.0,
    "B0A": 10.0,
    "C0A": -15.0,
}
ALL_LOCATION = "\n".join(f"{k} = {{ identify = true }}" for k in LOCATION)


def _values(result) -> dict[str, tuple[float, float]]:
    return {c.name.split(".", 1)[1]: (c.values[0], c.U[0]) for c in result.curves}


def test_eight_location_errors_are_recovered_to_the_second_order_remainder(tmp_path):
    """No noise, the truth in the model: the first-order fit recovers the exact chain's
    location errors to the products of errors the first order leaves out (errors of about
    10 µm and 10 µrad over levers of some 100 mm: below 0.01 µm and 0.1 µrad)."""
    path = _write(tmp_path, ALL_LOCATION, LOCATION, spheres=((450, 0, 40), (200, 80, 120)))
    result = identify(load_problem(path))
    got = _values(result)
    for name, truth in LOCATION.items():
        assert got[name][0] == pytest.approx(truth, abs=0.02), name
    assert result.identifiability.rank == result.identifiability.parameters


def test_error_motions_in_a_fourier_basis_are_recovered(tmp_path):
    """ECC, EAC (periodic, in the basis) and EAA (a cubic in A, in a Legendre basis) with
    the location errors; zero noise: each curve at every target to the remainder."""

    def ecc(c):
        return 8.0 * np.cos(np.radians(c)) - 5.0 * np.sin(np.radians(2 * c))

    def eac(c):
        return 6.0 * np.sin(np.radians(c)) + 3.0 * np.cos(np.radians(3 * c))

    def eaa(a):
        u = np.asarray(a) / 90.0
        # P1 and P3 of u, zero at A = 0 as the basis is
        return 7.0 * u + 4.0 * 0.5 * (5 * u**3 - 3 * u)

    truth = dict(LOCATION, ECC=ecc, EAC=eac, EAA=eaa)
    errors = (
        ALL_LOCATION
        + '\nECC = { identify = { basis = "fourier", order = 2 } }'
        + '\nEAC = { identify = { basis = "fourier", order = 3 } }'
        + '\nEAA = { identify = { basis = "legendre", degree = 3 } }'
    )
    path = _write(tmp_path, errors, truth, spheres=((450, 0, 40), (200, 80, 120), (300, -120, 10)))
    result = identify(load_problem(path))
    by_name = {c.name: c for c in result.curves}
    for symbol, f in (("ECC", ecc), ("EAC", eac), ("EAA", eaa)):
        c = by_name[f"table.{symbol}"]
        assert c.target_unit == "deg" and c.angle_axis == symbol[-1]
        np.testing.assert_allclose(c.values, f(np.asarray(c.targets_mm)), atol=0.05)
    got = _values(result)
    for name, value in LOCATION.items():
        assert got[name][0] == pytest.approx(value, abs=0.05), name


def test_noisy_location_errors_lie_within_their_U_at_about_the_stated_coverage(tmp_path):
    """40 data sets of normal noise (u = 0.5 µm): 8 errors each, within ± U (k = 2) at
    about 95 %."""
    inside = total = 0
    for seed in range(40):
        path = _write(tmp_path / str(seed), ALL_LOCATION, LOCATION, noise=0.5, seed=seed)
        got = _values(identify(load_problem(path), volumetric=False))
        for name, truth in LOCATION.items():
            value, U = got[name]
            inside += abs(value - truth) <= U
            total += 1
    assert 0.9 <= inside / total <= 0.99, inside / total


def test_c_alone_at_a_zero_cannot_tell_the_a_axis_line_from_the_c_axis_line(tmp_path):
    """Worked by hand: with A held at 0 both Y0A and Y0C move the tool along Y by a
    constant (-Y0A and -Y0C, docs/rotary.md), so no reading tells them apart: the plan
    is refused naming the two, and passes with Y0A fixed."""
    errors = "Y0C = { identify = true }\nY0A = { identify = true }\nX0C = { identify = true }"
    path = _write(tmp_path, errors, {}, settings="C only")
    result = plan(load_problem(path))
    assert not result.identifiability.identifiable
    said = " ".join(result.identifiability.sentences())
    assert "`table.Y0C`" in said and "`table.Y0A`" in said and "`table.X0C`" not in said
    path = _write(
        tmp_path / "fixed", errors, {}, settings="C only", identify_extra='fix = ["table.Y0A"]'
    )
    result = plan(load_problem(path))
    assert result.identifiability.identifiable


def test_an_unknown_probe_offset_is_one_direction_with_the_location_of_c(tmp_path):
    """Worked by hand: on the C table alone an error d of the probe's offset moves every
    reading by -d, a constant, and X0C moves the tool by -X0C along X, a constant too:
    with the probe's offset unknown the two are one direction."""
    path = _write(
        tmp_path, "X0C = { identify = true }", {}, settings="C only", set_extra='probe = "unknown"'
    )
    result = plan(load_problem(path))
    said = " ".join(result.identifiability.sentences())
    assert "`table.X0C`" in said and "`sphere.probe.dx`" in said, said
    r = CliRunner().invoke(main, ["identify", str(path)])
    assert r.exit_code == 2 and "not identifiable" in r.output


def test_a_known_probe_offset_calibration_lowers_the_valuation_of_what_it_shadows(tmp_path):
    """The probe's calibrated offset (u = 0.5 µm per axis) is a common error of every
    reading: X0C, which it shadows, has a larger U and a lower valuation than without
    it, while A0C (seen through the tilt of the sphere's path) keeps its valuation."""
    bare = identify(load_problem(_write(tmp_path / "a", ALL_LOCATION, LOCATION, noise=0.5)))
    cal = identify(
        load_problem(
            _write(
                tmp_path / "b",
                ALL_LOCATION,
                LOCATION,
                noise=0.5,
                set_extra="calibration = { u_um = 0.5 }",
            )
        )
    )
    b = {c.name: c for c in bare.curves}
    c = {c.name: c for c in cal.curves}
    assert c["table.X0C"].U[0] > 1.5 * b["table.X0C"].U[0]
    assert c["table.X0C"].valuation < b["table.X0C"].valuation
    assert c["table.A0C"].valuation == pytest.approx(b["table.A0C"].valuation, rel=0.05)
    for curve in bare.curves:
        assert 0.0 < curve.valuation <= 1.0


def test_the_example_round_trip_esp_analyse_of_the_identified_machine(tmp_path):
    """esp identify --out writes table.toml and machine.toml; esp analyse of it gives the
    volumetric accuracy of the identification, and the truth's within its U."""
    folder = tmp_path / "ex"
    shutil.copytree(EXAMPLE, folder)
    text = (folder / "table.toml").read_text(encoding="utf-8")
    (folder / "table.toml").write_text(
        text.replace("../../rotary/", (ROTARY.as_posix() + "/")), encoding="utf-8"
    )
    runner = CliRunner()
    out = tmp_path / "out"
    r = runner.invoke(main, ["identify", str(folder / "machine.toml"), "--out", str(out)])
    assert r.exit_code == 0, r.output
    assert (out / "table.toml").is_file()
    table = load_table(out / "table.toml")
    assert not table.to_identify and table.errors["X0C"] != 0.0
    import json

    from esp.config import load_machine
    from esp.core.analysis import analyse

    doc = json.loads((out / "identify.json").read_text(encoding="utf-8"))

    def volumetric(path: Path) -> float:
        result = analyse(load_machine(path))
        return result.cases[result.worst].volumetric.value_um

    assert volumetric(out / "machine.toml") == pytest.approx(
        doc["volumetric"]["value_um"], rel=1e-6
    )
    # the truth's machine, analysed the same way
    truth = dict(
        line.split(",")
        for line in (folder / "truth.csv").read_text(encoding="utf-8").splitlines()[2:]
        if not line.startswith("probe")
    )
    t = (out / "table.toml").read_text(encoding="utf-8")
    for name, value in truth.items():
        t = "\n".join(
            f"{name} = {value}" if line.startswith(f"{name} = ") else line
            for line in t.splitlines()
        )
    (out / "table.toml").write_text(t + "\n", encoding="utf-8")
    true_vol = volumetric(out / "machine.toml")
    v = doc["volumetric"]
    assert abs(true_vol - v["value_um"]) <= v["U_um"], (true_vol, v)


@pytest.mark.parametrize(
    ("errors", "set_extra", "message"),
    [
        (
            "ECC = { identify = true }",
            "",
            "table.errors.ECC.identify: ECC is an error motion of C",
        ),
        (
            'X0C = { identify = { basis = "fourier", order = 2 } }',
            "",
            "table.errors.X0C.identify: X0C is a location error",
        ),
        (
            'ECC = { identify = { basis = "spline", order = 2 } }',
            "",
            "table.errors.ECC.identify.basis: expected one of fourier, legendre",
        ),
        (
            'ECC = { identify = { basis = "fourier", order = 0 } }',
            "",
            "table.errors.ECC.identify.order: expected a whole number from 1 to 24",
        ),
        (
            "X0C = { identify = true }",
            "calibration = { u_ppm = 1 }",
            "calibration.u_ppm: a probed sphere has no scale of its own",
        ),
    ],
)
def test_bad_unknowns_are_refused_in_one_line(tmp_path, errors, set_extra, message):
    path = _write(tmp_path, errors, {}, set_extra=set_extra)
    r = CliRunner().invoke(main, ["identify", str(path)])
    assert r.exit_code == 2
    assert message in r.output
    assert "Traceback" not in r.output and len(r.output.strip().splitlines()) == 1


def test_bad_readings_are_refused_naming_file_and_line(tmp_path):
    path = _write(tmp_path, ALL_LOCATION, LOCATION)
    csv = tmp_path / "spheres.csv"
    lines = csv.read_text(encoding="utf-8").splitlines()
    runner = CliRunner()
    # a sphere seen from one setting
    csv.write_text("\n".join([*lines, "S9,0,0,450,0,40"]) + "\n", encoding="utf-8")
    r = runner.invoke(main, ["identify", str(path)])
    assert r.exit_code == 2
    assert f"spheres.csv:{len(lines) + 1}: sphere 'S9' is seen from one setting" in r.output
    # an angle outside the travel of an error motion identified over A
    errors = ALL_LOCATION + '\nEAA = { identify = { basis = "legendre", degree = 2 } }'
    path = _write(tmp_path / "b", errors, LOCATION)
    csv = tmp_path / "b" / "spheres.csv"
    lines = csv.read_text(encoding="utf-8").splitlines()
    lines[3] = "S1,120" + lines[3][lines[3].index(",", 3) :]
    csv.write_text("\n".join(lines) + "\n", encoding="utf-8")
    r = runner.invoke(main, ["identify", str(path)])
    assert r.exit_code == 2
    assert "spheres.csv:4: A = 120 deg lies outside the travel -90..90 deg" in r.output
    # a reading far off
    path = _write(tmp_path / "c", ALL_LOCATION, LOCATION)
    csv = tmp_path / "c" / "spheres.csv"
    lines = csv.read_text(encoding="utf-8").splitlines()
    parts = lines[5].split(",")
    parts[3] = f"{float(parts[3]) + 0.05:.7f}"
    lines[5] = ",".join(parts)
    csv.write_text("\n".join(lines) + "\n", encoding="utf-8")
    r = runner.invoke(main, ["identify", str(path)])
    assert r.exit_code == 2
    assert "the reading least explained is" in r.output and "spheres.csv:6" in r.output


def test_a_table_with_unknowns_is_refused_by_esp_analyse(tmp_path):
    path = _write(tmp_path, ALL_LOCATION, LOCATION)
    text = path.read_text(encoding="utf-8")
    plain = tmp_path / "plain.toml"
    plain.write_text(text[: text.index("[identify]")], encoding="utf-8")
    r = CliRunner().invoke(main, ["analyse", str(plain)])
    assert r.exit_code == 2
    assert "table.toml: table.errors.X0C: an unknown to identify" in r.output


def test_a_sphere_set_needs_a_table(tmp_path):
    path = _write(tmp_path, ALL_LOCATION, LOCATION)
    text = path.read_text(encoding="utf-8")
    start = text.index("[table]")
    text = text[:start] + text[text.index("[axes.X]") :]
    text = text.replace(
        "[axes.X]",
        '[axes.X.errors]\nlinear = { identify = { basis = "legendre", degree = 2 } }\n\n[axes.X]',
        1,
    )
    path.write_text(text, encoding="utf-8")
    r = CliRunner().invoke(main, ["identify", str(path)])
    assert r.exit_code == 2
    assert "identify.measurements.sphere.kind: a probed sphere measures a rotary table" in r.output
