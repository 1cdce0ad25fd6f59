"""Is the drift real? ``esp compare`` states every change with its expanded uncertainty U(Δ)
from both calibrations' uncertainties and its normalised error En = |Δ| / U(Δ) (GUM 5.2.2;
ISO 13528:2015, 9.7), worked by hand on two tiny calibrations written here."""

from __future__ import annotations

import json
import math
import shutil
from pathlib import Path

import pytest
from click.testing import CliRunner

import esp
from esp.cli import main
from esp.compare.model import change_significance, compare
from esp.compare.text import compare_dict, compare_text
from esp.core.errors import DataError

EXAMPLES = Path(__file__).resolve().parent.parent / "data" / "examples"

MACHINE = """
[machine]
name = "Test mill"
serial = "T-1"
measured_by = "{operator}"
date = {date}
configuration = "wBMTt"
axes = {{ bottom = "X", middle = "Y", top = "Z" }}

[axes.X]
travel = [0, 1000]
step = 250

[axes.X.errors]
linear = {{ points = [[0, 0.0], [500, {half}], [1000, {lead}]] }}

[axes.Y]
travel = [0, 1000]
step = 250

[axes.Z]
travel = [0, 1000]
step = 250

[squareness]
XY = {square}
"""


def write(folder: Path, lead: float, square: float, uncertainty: str = "", **info: str) -> Path:
    """A calibration: X.linear 0 -> ``lead`` µm over 1000 mm (straight, measured at 0, 500
    and 1000 mm) and squareness XY ``square``
    µm/m, with ``uncertainty`` appended."""
    folder.mkdir(parents=True, exist_ok=True)
    text = MACHINE.format(
        lead=lead,
        half=lead / 2.0,
        square=square,
        operator=info.get("operator", "A. Operator"),
        date=info.get("date", "2024-01-15"),
    )
    path = folder / "machine.toml"
    path.write_text(text + uncertainty, encoding="utf-8")
    return path


def table(linear: float | str, square: float, k: float = 2.0) -> str:
    return (
        f"\n[uncertainty]\nk = {k}\n"
        f'[uncertainty.components."X.linear"]\nU = {linear}\n'
        f'[uncertainty.components."squareness.XY"]\nU = {square}\n'
    )


def run(*args: object):
    return CliRunner().invoke(main, [str(a) for a in args])


# -- the formula, by hand ---------------------------------------------------------------


def test_independent_calibrations_add_their_standard_uncertainties():
    """Δ = 3, U = 2 (k = 2) on each side: u = 1 and 1, u(Δ) = √2, U(Δ) = 2√2 = 2.828,
    En = 3 / 2.828 = 1.061 > 1: significant."""
    s = change_significance(3.0, 2.0, 2.0)
    assert pytest.approx(2.0 * math.sqrt(2.0)) == s.U
    assert s.En == pytest.approx(3.0 / (2.0 * math.sqrt(2.0)))
    assert s.significant is True and s.reason is None


def test_a_declared_correlation_removes_the_shared_part():
    """r = 0.5: u(Δ)² = 1 + 1 - 2·0.5·1·1 = 1, U(Δ) = 2, En = 1.5 (GUM 5.2.2, eq. 16)."""
    s = change_significance(3.0, 2.0, 2.0, correlation=0.5)
    assert pytest.approx(2.0) == s.U and s.En == pytest.approx(1.5)
    assert s.correlation == 0.5


def test_each_side_is_reduced_with_its_own_k_and_expanded_once():
    """U = 3 at k = 3 (u = 1) and U = 4 at k = 2 (u = 2): u(Δ) = √5, U(Δ) = 2√5 = 4.472;
    Δ = 4 gives En = 0.894, not significant (adding the expanded U's, √(9 + 16) = 5,
    would give 0.8)."""
    s = change_significance(4.0, 3.0, 4.0, k_before=3.0, k_after=2.0)
    assert pytest.approx(2.0 * math.sqrt(5.0)) == s.U
    assert s.En == pytest.approx(4.0 / (2.0 * math.sqrt(5.0)))
    assert s.significant is False


def test_en_of_one_is_not_significant():
    s = change_significance(2.0, 2.0 / math.sqrt(2.0), 2.0 / math.sqrt(2.0))
    assert s.En == pytest.approx(1.0)
    assert s.significant is (s.En > 1.0)


def test_without_u_on_one_side_nothing_is_evaluated_never_zero():
    s = change_significance(3.0, None, 2.0)
    assert s.U is None and s.En is None and s.significant is None
    assert s.reason == "no U before"


@pytest.mark.parametrize("r", [-0.1, 1.5, math.nan])
def test_a_correlation_outside_0_to_1_is_refused(r):
    with pytest.raises(DataError, match="correlation: expected a correlation coefficient"):
        change_significance(1.0, 1.0, 1.0, correlation=r)


# -- two calibrations -------------------------------------------------------------------


def test_components_by_hand(tmp_path):
    """X.linear 0..10 -> 0..13 µm, squareness 2 -> 5 µm/m, U = 2 everywhere: both changes
    are 3 with U(Δ) = 2.828, En = 1.061, significant; with U = 3, U(Δ) = 4.243, En = 0.707,
    not significant."""
    b = esp.load_machine(write(tmp_path / "b", 10.0, 2.0, table(2.0, 2.0)))
    a = esp.load_machine(write(tmp_path / "a", 13.0, 5.0, table(2.0, 2.0)))
    c = compare(b, a)
    by = {x.name: x for x in c.components}
    for name in ("X.linear", "squareness.XY"):
        s = by[name].significance
        assert s.change == pytest.approx(3.0)
        assert pytest.approx(2.0 * math.sqrt(2.0)) == s.U
        assert s.En == pytest.approx(3.0 / (2.0 * math.sqrt(2.0)))
        assert s.significant is True
    assert by["X.linear"].significance_at_mm == 1000.0
    assert by["X.linear"].U_at_max == pytest.approx(2.0 * math.sqrt(2.0))
    loose = compare(
        esp.load_machine(write(tmp_path / "b3", 10.0, 2.0, table(3.0, 3.0))),
        esp.load_machine(write(tmp_path / "a3", 13.0, 5.0, table(3.0, 3.0))),
    )
    for x in loose.components:
        assert x.significance.En == pytest.approx(3.0 / (3.0 * math.sqrt(2.0)))
        assert x.significance.significant is False


def test_a_u_curve_is_read_where_the_change_is(tmp_path):
    """U of X.linear 0.5 µm up to 500 mm, then growing to 6 µm at 1000 mm: at 1000 mm the
    change 3 has U(Δ) = 2·√(3² + 3²) = 8.485, En = 0.354; at 500 mm the change 1.5 has
    U(Δ) = 2·√(0.25² · 2) = 0.707, En = 2.12: the change is significant, at 500 mm, although
    not where it is largest."""
    curve = "{ points = [[0, 0.5], [500, 0.5], [1000, 6.0]] }"
    c = compare(
        esp.load_machine(write(tmp_path / "b", 10.0, 2.0, table(curve, 2.0))),
        esp.load_machine(write(tmp_path / "a", 13.0, 5.0, table(curve, 2.0))),
    )
    x = next(x for x in c.components if x.name == "X.linear")
    assert x.positions_mm == (0.0, 500.0, 1000.0)
    expected = [math.sqrt(2.0) * u for u in (0.5, 0.5, 6.0)]
    assert x.U_change == pytest.approx(expected)
    assert (x.at_mm, x.max_abs_change) == (1000.0, pytest.approx(3.0))
    assert x.U_at_max == pytest.approx(expected[2])
    assert x.significance_at_mm == 500.0
    assert x.significance.change == pytest.approx(1.5)
    assert x.significance.En == pytest.approx(1.5 / expected[1])
    assert x.significance.significant is True
    assert 3.0 / expected[2] < 1.0  # not significant where the change is largest


def test_the_accuracy_changes_use_each_analysis_uncertainty(tmp_path):
    """The volumetric change's U(Δ) combines the two analyses' volumetric U (k = 2 each),
    a direction's U(Δ) their largest U of that direction."""
    b = esp.load_machine(write(tmp_path / "b", 10.0, 2.0, table(2.0, 2.0)))
    a = esp.load_machine(write(tmp_path / "a", 13.0, 5.0, table(1.0, 1.0)))
    c = compare(b, a, correlation=0.25)
    ub, ua = esp.analyse(b).uncertainty, esp.analyse(a).uncertainty
    vol = c.figure("volumetric")
    assert vol.change == pytest.approx(c.volumetric_change_um)
    u1, u2 = ub.volumetric.value_um / 2.0, ua.volumetric.value_um / 2.0
    expected = 2.0 * math.sqrt(u1 * u1 + u2 * u2 - 2.0 * 0.25 * u1 * u2)
    assert pytest.approx(expected) == vol.significance.U
    assert vol.significance.En == pytest.approx(abs(c.volumetric_change_um) / expected)
    fx = c.figure("field.X").significance
    u1, u2 = ub.axes["X"].value_um / 2.0, ua.axes["X"].value_um / 2.0
    assert pytest.approx(2.0 * math.sqrt(u1 * u1 + u2 * u2 - 0.5 * u1 * u2)) == fx.U
    for plane in c.planar_before:
        assert pytest.approx(expected) == c.figure(f"planar.{plane}").significance.U


def test_a_missing_u_leaves_the_change_not_evaluated(tmp_path):
    """No [uncertainty] before: every En is not evaluated (None in JSON, '-' in the text),
    never 0; U for X.linear only: X.linear is evaluated, squareness and the accuracies
    (which depend on it) are not, naming it."""
    b = esp.load_machine(write(tmp_path / "b", 10.0, 2.0))
    a = esp.load_machine(write(tmp_path / "a", 13.0, 5.0, table(2.0, 2.0)))
    c = compare(b, a)
    assert all(x.significance.En is None for x in c.components)
    assert all(f.significance.En is None and f.significance.U is None for f in c.figures)
    doc = compare_dict(b, a, c)
    assert doc["volumetric"]["En"] is None and doc["volumetric"]["significant"] is None
    assert doc["volumetric"]["significance"]["not_evaluated"] == "before: no [uncertainty] table"
    assert doc["uncertainty"]["before"]["not_evaluated"] == "no [uncertainty] table"
    assert doc["uncertainty"]["after"]["U_um"] > 0.0
    text = compare_text(b, a, c)
    assert "uncertainty of the changes: not evaluated (before: no [uncertainty] table)" in text
    assert "0.00   not significant" not in text
    only = '\n[uncertainty]\n[uncertainty.components."X.linear"]\nU = 2.0\n'
    c = compare(
        esp.load_machine(write(tmp_path / "b2", 10.0, 2.0, only)),
        esp.load_machine(write(tmp_path / "a2", 13.0, 5.0, only)),
    )
    by = {x.name: x for x in c.components}
    assert by["X.linear"].significance.significant is True
    assert by["squareness.XY"].significance.En is None
    assert by["squareness.XY"].significance.reason == (
        "before: no U for squareness.XY; after: no U for squareness.XY"
    )
    assert c.figure("volumetric").significance.reason == (
        "before: no U for squareness.XY; after: no U for squareness.XY"
    )


# -- through the command line ------------------------------------------------------------


def test_command_marks_the_changes_and_states_both_calibrations(tmp_path):
    b = write(tmp_path / "b", 10.0, 2.0, table(2.0, 2.0), operator="M. Weber", date="2023-03-14")
    a = write(tmp_path / "a", 13.0, 5.0, table(3.0, 3.0), operator="K. Osei", date="2024-03-12")
    r = run("compare", b, a, "--json", tmp_path / "c.json")
    assert r.exit_code == 0, r.output
    lines = r.output.splitlines()
    assert lines[1].endswith("2023-03-14, M. Weber") and lines[2].endswith("2024-03-12, K. Osei")
    doc = json.loads((tmp_path / "c.json").read_text())
    assert doc["before"]["operator"] == "M. Weber" and doc["after"]["date"] == "2024-03-12"
    # U(Δ) = 2·√(1² + 1.5²) = 3.606; Δ = 3: En = 0.832
    by = {x["component"]: x for x in doc["components"]}
    expected = 2.0 * math.sqrt(1.0 + 1.5**2)
    for name in ("X.linear", "squareness.XY"):
        assert by[name]["significance"]["U"] == pytest.approx(expected)
        assert by[name]["En"] == pytest.approx(3.0 / expected)
        assert by[name]["significant"] is False
        assert by[name]["significance"]["verdict"] == "not significant"
    row = next(line for line in lines if line.lstrip().startswith("X.linear"))
    # rounded to what U(Δ) supports: 3.0 µm with U(Δ) = 3.6 µm (GUM 7.2.6)
    assert row.split()[1:7] == ["3.0", "µm", "1000", "3.6", "0.83", "1000"]  # En at 1000 mm
    assert "not significant" in row
    assert doc["uncertainty"]["correlation"] == 0.0
    r = run("compare", b, a, "--json", "-", "--correlation", "0.9")
    doc = json.loads(r.output)
    x = next(x for x in doc["components"] if x["component"] == "X.linear")
    # u(Δ)² = 1 + 2.25 - 2·0.9·1·1.5 = 0.55: U(Δ) = 1.483, En = 2.02
    assert x["significance"]["U"] == pytest.approx(2.0 * math.sqrt(0.55))
    assert x["significant"] is True and doc["uncertainty"]["correlation"] == 0.9


def test_the_title_block_names_both_calibrations(tmp_path):
    from esp.compare.text import calibration_fields

    b = esp.load_machine(write(tmp_path / "b", 10.0, 2.0, operator="M. Weber", date="2023-03-14"))
    a = esp.load_machine(write(tmp_path / "a", 13.0, 5.0, operator="K. Osei", date="2024-03-12"))
    assert calibration_fields(b, a) == [
        ("Serial", "T-1"),
        ("Before", "2023-03-14, M. Weber, Test mill"),
        ("After", "2024-03-12, K. Osei, Test mill"),
    ]


@pytest.mark.parametrize("value", ["1.5", "-0.2", "nan"])
def test_command_refuses_a_correlation_outside_0_to_1(tmp_path, value):
    b = write(tmp_path / "b", 10.0, 2.0)
    r = run("compare", b, b, "--correlation", value)
    assert r.exit_code == 2
    assert len(r.stderr.strip().splitlines()) == 1 and "--correlation" in r.stderr
    assert "Traceback" not in r.output + r.stderr


@pytest.mark.slow
def test_the_shipped_recalibration_with_uncertainty(tmp_path):
    """The gantry and its recalibration with U stated (written here): the generator's
    changes of the Y lead error and of the gantry pitch stand out (En > 1), the
    re-measurement noise of the others does not; the PDF and the three figures are
    written."""
    sides = []
    lines = [
        "\n[uncertainty]",
        'method = "statistical"',
        "k = 2.0",
    ]
    travel = {"X": 1000, "Y": 1500, "Z": 600}
    for a in "XYZ":
        lines += [
            f'[uncertainty.components."{a}.linear"]',
            f"U = {{ points = [[0, 0.2], [{travel[a]}, {0.2 + travel[a] * 0.001:g}]] }}",
        ]
        for b in "XYZ":
            if b != a:
                lines += [f'[uncertainty.components."{a}.straightness.{b}"]', "U = 0.4"]
            lines += [f'[uncertainty.components."{a}.angular.{b}"]', "U = 0.6"]
    for p in ("XY", "XZ", "YZ"):
        lines += [f'[uncertainty.components."squareness.{p}"]', "U = 1.0"]
    for name in ("gantry", "gantry-2024"):
        folder = tmp_path / name
        shutil.copytree(EXAMPLES / name, folder)
        toml = folder / "machine.toml"
        text = toml.read_text(encoding="utf-8").split("\n[uncertainty")[0]
        toml.write_text(text + "\n".join(lines) + "\n", encoding="utf-8")
        sides.append(toml)
    out = tmp_path / "drift"
    r = run("compare", *sides, "--out", out, "--json", tmp_path / "c.json")
    assert r.exit_code == 0, r.output
    doc = json.loads((tmp_path / "c.json").read_text())
    by = {x["component"]: x for x in doc["components"]}
    assert by["Y.linear"]["significant"] is True
    assert by["Y.angular.X"]["significant"] is True
    for name in ("X.angular.X", "Z.straightness.Y", "squareness.YZ"):
        assert by[name]["significant"] is False, name
    assert doc["volumetric"]["U_change_um"] > 0.0
    pypdf = pytest.importorskip("pypdf")
    first = pypdf.PdfReader(str(out / "report.pdf")).pages[0].extract_text()
    assert "2023-03-14, M. Weber" in first and "2024-03-12, K. Osei" in first
    # the headline rounded to its U (GUM 7.2.6): one decimal for U of a few µm
    before = doc["volumetric"]["before_um"]
    assert f"{before:.1f} µm" in first and f"{before:.3f}" not in first
    for name in (
        "report.pdf",
        "compare-components.png",
        "compare-change.png",
        "compare-curves.png",
    ):
        assert (out / name).is_file()
