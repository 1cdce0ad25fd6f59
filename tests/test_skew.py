"""esp skew: squareness and scale from a square's lengths or from points, their U, and the
firmware lines -- checked against the exact geometry of a skewed machine and against each
firmware's transform as its source writes it."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from click.testing import CliRunner

from esp.cli import main
from esp.core.errors import ConfigError, DataError
from esp.skew.firmware import blocks, firmware_values
from esp.skew.model import (
    Caliper,
    Length,
    PointSet,
    Square,
    from_points,
    from_squares,
    machine_matrix,
)


def _marlin_factor(ac: float, bd: float, ad: float) -> float:
    """Marlin's Configuration.h, written out: AB = √(2AC² + 2BD² − 4AD²)/2 and
    XY_SKEW_FACTOR = tan(π/2 − acos((AC² − AB² − AD²)/(2·AB·AD)))."""
    ab = math.sqrt(2 * ac * ac + 2 * bd * bd - 4 * ad * ad) / 2
    return math.tan(math.pi / 2 - math.acos((ac * ac - ab * ab - ad * ad) / (2 * ab * ad)))


def _made_square(
    theta_deg: float, side_e: float, side_l: float
) -> tuple[float, float, float, float]:
    """AC, BD, AD, AB of the parallelogram a machine whose axes meet at θ makes when
    commanded a square: corners A = 0, D = a·e, B = b·u, C = D + B."""
    t = math.radians(theta_deg)
    a = np.array([0.0, 0.0])
    d = np.array([side_e, 0.0])
    b = side_l * np.array([math.cos(t), math.sin(t)])
    c = d + b
    return (
        float(np.linalg.norm(c - a)),
        float(np.linalg.norm(d - b)),
        float(np.linalg.norm(d - a)),
        float(np.linalg.norm(b - a)),
    )


def _one(name: str, v: float) -> Length:
    return Length(name, (v,))


@pytest.mark.parametrize("theta", [89.2, 89.9, 90.0, 90.35, 91.1])
def test_square_recovers_the_angle_and_scales_of_the_exact_parallelogram(theta):
    ac, bd, ad, ab = _made_square(theta, 100.03, 99.98)
    sq = Square("XY", _one("AC", ac), _one("BD", bd), _one("AD", ad), None, 100.0)
    r = from_squares([sq], Caliper())
    s = r.get("squareness", "XY")
    assert s is not None
    assert s.value == pytest.approx(1 / math.tan(math.radians(theta)), abs=1e-12)
    assert r.planes[0].angle_deg == pytest.approx(theta, abs=1e-9)
    assert r.get("scale", "X").value == pytest.approx(0.03 / 100, abs=1e-12)
    assert r.get("scale", "Y").value == pytest.approx(-0.02 / 100, abs=1e-12)
    # esp's squareness is Marlin's factor: the published formula, independently
    assert s.value == pytest.approx(_marlin_factor(ac, bd, ad), abs=1e-12)


def test_square_with_ab_measured_uses_it_and_checks_the_parallelogram():
    ac, bd, ad, ab = _made_square(89.7, 100.0, 100.0)
    sq = Square("XY", _one("AC", ac), _one("BD", bd), _one("AD", ad), _one("AB", ab))
    r = from_squares([sq], Caliper())
    assert r.planes[0].parallelogram_misfit_mm == pytest.approx(0.0, abs=1e-9)
    assert not r.warnings
    bent = Square("XY", _one("AC", ac), _one("BD", bd), _one("AD", ad), _one("AB", ab + 0.3))
    assert any("parallelogram" in w for w in from_squares([bent], Caliper()).warnings)


def test_square_uncertainty_by_hand():
    """A perfect 100 mm square (cos θ = 0): ∂S/∂AC = AC/(2·AB·AD) = √2/200 per mm,
    ∂S/∂BD = −√2/200, ∂S/∂AD = 0 (AB from the parallelogram law), so
    u(S) = √2 · (√2/200) · u_L = u_L/100 with u_L² = (0.01/√12)² + (0.02/√3)²."""
    d = 100.0 * math.sqrt(2.0)
    sq = Square("XY", _one("AC", d), _one("BD", d), _one("AD", 100.0))
    e = from_squares([sq], Caliper(0.01, 0.02)).get("squareness", "XY")
    u_l = math.sqrt((0.01 / math.sqrt(12)) ** 2 + (0.02 / math.sqrt(3)) ** 2)
    assert e.value == pytest.approx(0.0, abs=1e-15)
    assert e.u == pytest.approx(u_l / 100.0, rel=1e-6)
    assert e.k == pytest.approx(2.0, abs=0.01)  # type B only: normal, about 95 %
    assert not e.significant


def test_repeated_readings_add_type_a_with_its_degrees_of_freedom():
    sq = Square(
        "XY",
        Length("AC", (141.84, 141.80, 141.88)),
        Length("BD", (141.04, 141.04, 141.04)),
        Length("AD", (100.02, 100.02, 100.02)),
    )
    one = from_squares([sq], Caliper(0.01, 0.0)).get("squareness", "XY")
    # AC's scatter: s = 0.04 mm, u of the mean 0.04/√3, 2 degrees of freedom, dominant
    assert math.isfinite(one.dof) and 2.0 <= one.dof < 3.0
    assert one.k > 2.5


def test_zero_skew_gives_zero_and_nothing_to_correct():
    d = 100.0 * math.sqrt(2.0)
    r = from_squares([Square("XY", _one("AC", d), _one("BD", d), _one("AD", 100.0))], Caliper())
    v = firmware_values(r)
    assert v["marlin"]["XY"] == 0.0
    assert np.allclose(np.array(v["linuxcnc"]["C"]).reshape(3, 3), np.eye(3), atol=1e-15)


def test_machine_matrix_has_the_stated_angles_and_lengths():
    sq = {"XY": 0.004, "XZ": -0.002, "YZ": 0.0015}
    sc = {"X": 1e-4, "Y": -2e-4, "Z": 3e-4}
    m = machine_matrix(sq, sc)
    for (i, j), p in (((0, 1), "XY"), ((0, 2), "XZ"), ((1, 2), "YZ")):
        u, v = m[:, i], m[:, j]
        cos = u @ v / np.linalg.norm(u) / np.linalg.norm(v)
        assert cos / math.sqrt(1 - cos * cos) == pytest.approx(sq[p], abs=1e-14)
    for i, ax in enumerate("XYZ"):
        assert np.linalg.norm(m[:, i]) == pytest.approx(1 + sc[ax], abs=1e-14)
    assert np.allclose(np.tril(m, -1), 0.0)


def _random_machine(rng):
    sq = {p: float(rng.uniform(-0.01, 0.01)) for p in ("XY", "XZ", "YZ")}
    sc = {ax: float(rng.uniform(-1e-3, 1e-3)) for ax in "XYZ"}
    return sq, sc, machine_matrix(sq, sc)


def _rotation(rng):
    q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    return q * np.sign(np.linalg.det(q))


def _result_of(sq, sc):
    from esp.skew.model import Estimate, Quantity, SkewResult

    est = [Estimate(Quantity("squareness", p), v, 0.0, math.inf) for p, v in sq.items()]
    est += [Estimate(Quantity("scale", ax), v, 0.0, math.inf) for ax, v in sc.items()]
    return SkewResult("points", "made", tuple(est))


@pytest.mark.parametrize("seed", range(5))
def test_each_firmware_transform_undoes_the_machine_exactly(seed):
    """Commanded c -> the firmware's transform (as its source writes it) -> steps scaled
    -> the machine's motion M: the tool lands on c."""
    rng = np.random.default_rng(seed)
    sq, sc, m = _random_machine(rng)
    v = firmware_values(_result_of(sq, sc))
    c = rng.uniform(-500, 500, size=(3, 20))
    g = np.array([v["marlin"]["steps"][ax] for ax in "XYZ"])[:, None]
    # Marlin planner.h skew(): sx = cx - cy*xy - cz*(xz - xy*yz); sy = cy - cz*yz
    xy, xz, yz = v["marlin"]["XY"], v["marlin"]["XZ"], v["marlin"]["YZ"]
    marlin = np.vstack([c[0] - c[1] * xy - c[2] * (xz - xy * yz), c[1] - c[2] * yz, c[2]])
    assert np.allclose(m @ (g * marlin), c, atol=1e-9)
    # RepRapFirmware Move::AxisTransform: x += tanXY*y + tanXZ*z; y += tanYZ*z
    t = v["reprapfirmware"]
    rrf = np.vstack([c[0] + t["XY"] * c[1] + t["XZ"] * c[2], c[1] + t["YZ"] * c[2], c[2]])
    assert np.allclose(m @ (g * rrf), c, atol=1e-9)
    # LinuxCNC matrixkins: joint = C * axis
    cm = np.array(v["linuxcnc"]["C"]).reshape(3, 3)
    assert np.allclose(m @ (cm @ c), c, atol=1e-9)


def test_klipper_lengths_carry_the_factor_through_klippers_formula():
    r = _result_of({"XY": 0.0031, "XZ": -0.0012, "YZ": 0.0}, {})
    block = next(b for b in blocks(r, ("klipper",)) if b.firmware == "klipper")
    line = block.lines[0]
    assert line.startswith("SET_SKEW ")
    parts = dict(p.split("=") for p in line.split()[1:])
    v = firmware_values(r)["klipper"]
    for plane in ("XY", "XZ"):
        ac, bd, ad = (float(x) for x in parts[plane].split(","))
        assert _marlin_factor(ac, bd, ad) == pytest.approx(v[plane], abs=2e-6)


@pytest.mark.parametrize("kind", ["made", "probed"])
def test_points_recover_the_machine_exactly_without_noise(kind):
    rng = np.random.default_rng(7)
    sq, sc, m = _random_machine(rng)
    rot = _rotation(rng)
    t = rng.uniform(-50, 50, size=3)
    nominal = rng.uniform(-200, 200, size=(12, 3))
    if kind == "made":
        measured = (rot @ m @ nominal.T).T + t
    else:
        measured = np.linalg.solve(m, (rot @ nominal.T).T.T + t[:, None]).T
    pts = PointSet(("X", "Y", "Z"), nominal, measured, kind, point_u_um=1.0)
    r = from_points(pts)
    for p, v in sq.items():
        assert r.get("squareness", p).value == pytest.approx(v, abs=1e-10)
    for ax, v in sc.items():
        assert r.get("scale", ax).value == pytest.approx(v, abs=1e-10)
    assert r.residual_um == pytest.approx(0.0, abs=1e-6)


def test_points_u_covers_the_truth_about_95_percent():
    rng = np.random.default_rng(11)
    sq = {"XY": 0.0008}
    sc = {"X": 2e-4, "Y": -1e-4}
    m = machine_matrix(sq, sc)[:2, :2]
    gx, gy = np.meshgrid(np.linspace(0, 200, 5), np.linspace(0, 200, 5))
    nominal = np.column_stack([gx.ravel(), gy.ravel()])
    hits = 0
    trials = 300
    for _ in range(trials):
        measured = nominal @ m.T + rng.normal(scale=0.002, size=nominal.shape)
        r = from_points(PointSet(("X", "Y"), nominal, measured, "made"))
        e = r.get("squareness", "XY")
        hits += abs(e.value - sq["XY"]) <= e.expanded
    assert 0.91 <= hits / trials <= 0.99


def test_points_refused_when_too_few_or_on_a_line():
    line = np.column_stack([np.linspace(0, 100, 6), np.zeros(6)])
    with pytest.raises(DataError, match="one line"):
        from_points(PointSet(("X", "Y"), line, line, "made", "p.csv"))
    few = np.array([[0.0, 0.0], [100.0, 0.0], [0.0, 100.0]])
    with pytest.raises(DataError, match="at least 4 points"):
        from_points(PointSet(("X", "Y"), few, few, "made", "p.csv"))


def test_square_refusals_name_the_option():
    with pytest.raises(ConfigError, match="--xy"):
        from_squares([Square("XY", _one("AC", 100), _one("BD", 100), _one("AD", 110))], Caliper())
    with pytest.raises(ConfigError, match="more than 11"):
        from_squares([Square("XY", _one("AC", 150), _one("BD", 120), _one("AD", 100))], Caliper())


def _run(args):
    return CliRunner().invoke(main, args, catch_exceptions=False)


def test_cli_square_text_and_json(tmp_path):
    target = tmp_path / "skew.json"
    res = _run(["skew", "--xy", "141.84,141.04,100.02", "--side", "100", "--json", str(target)])
    assert res.exit_code == 0, res.output
    assert "M852 I0.005656" in res.output
    assert "M556 S100 X-0.56562" in res.output
    assert "$37=0.005656" in res.output
    assert "setp matrixkins.C_xy -0.0056" in res.output
    doc = json.loads(target.read_text())
    assert doc["schema"] == "esp.skew/1"
    xy = next(e for e in doc["estimates"] if e["name"] == "XY")
    assert xy["value_um_per_m"] == pytest.approx(
        _marlin_factor(141.84, 141.04, 100.02) * 1e6, abs=1e-6
    )


@pytest.mark.parametrize(
    ("args", "expect"),
    [
        (["--xy", "141,140"], "--xy: expected AC,BD,AD"),
        (["--xy", "141,nan,100"], "--xy: BD"),
        (["--xy", "100,100,110"], "no parallelogram"),
        (["--xy", "141.8,141.0,100", "--kind", "made"], "--kind"),
        ([], "expected the lengths of a square"),
    ],
)
def test_cli_bad_input_is_one_line_exit_2(args, expect):
    res = CliRunner().invoke(main, ["skew", *args])
    assert res.exit_code == 2
    lines = res.output.strip().splitlines()
    assert len(lines) == 1 and expect in lines[0], res.output


def test_cli_points_file(tmp_path):
    f = tmp_path / "plate.csv"
    rows = ["# kind: probed", "point,x_nominal,y_nominal,x_measured,y_measured"]
    m = machine_matrix({"XY": 0.001}, {})[:2, :2]
    k = 0
    for x in (0.0, 100.0, 200.0):
        for y in (0.0, 100.0, 200.0):
            r = np.linalg.solve(m, [x, y]) + [0.0005 * ((-1) ** k), 0.0]
            rows.append(f"P{k},{x},{y},{r[0]:.5f},{r[1]:.5f}")
            k += 1
    f.write_text("\n".join(rows) + "\n")
    res = _run(["skew", str(f), "--firmware", "marlin"])
    assert res.exit_code == 0, res.output
    assert "M852 I0.00" in res.output
    bad = tmp_path / "bad.csv"
    bad.write_text("# kind: made\nx_nominal,y_nominal,x_measured,y_measured\n0,0,0,zero\n")
    res = CliRunner().invoke(main, ["skew", str(bad)])
    assert res.exit_code == 2
    assert "bad.csv:3: y_measured" in res.output


EXAMPLES = __import__("pathlib").Path(__file__).resolve().parents[1] / "data" / "examples" / "skew"


def test_shipped_examples_find_their_truth_within_u(tmp_path):
    from esp.skew.readings import read_points

    truth = json.loads((EXAMPLES / "truth.json").read_text())
    for name, spec in truth.items():
        r = from_points(read_points(EXAMPLES / name))
        for kind, values in spec.items():
            for what, true_um_per_m in values.items():
                e = r.get(kind, what)
                assert abs(e.value_um_per_m - true_um_per_m) <= e.expanded_um_per_m, (name, what)
    # the generator writes the same bytes
    import runpy

    runpy.run_path(str(EXAMPLES / "make_data.py"), run_name="make")["main"](tmp_path)
    for name in ("plate-probed.csv", "part-made.csv", "truth.json"):
        assert (tmp_path / name).read_bytes() == (EXAMPLES / name).read_bytes()


def test_the_command_offers_every_firmware_esp_writes():
    from esp.cli import skew as skew_cli
    from esp.skew.firmware import FIRMWARE

    assert skew_cli._FIRMWARE == FIRMWARE
