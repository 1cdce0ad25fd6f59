"""esp identify on the command line with bad input: each refusal is one line on standard
error, ``esp: error: ...`` naming the file and line or the key, exit code 2, no
traceback -- and ``--plan`` of a plan that cannot see a component says so the same way
after its report."""

from __future__ import annotations

import numpy as np
import pytest
from click.testing import CliRunner
from identify_helpers import STATIONS, base, full_config

from esp.cli import main
from esp.identify.write import to_toml

LINEAR = ("X.linear", "Y.linear", "Z.linear")


def _run(*args):
    return CliRunner().invoke(main, [str(a) for a in args])


def _refused(result, *parts: str) -> str:
    assert result.exit_code == 2, (result.exit_code, result.stdout, result.stderr)
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1, result.stderr
    assert lines[0].startswith("esp: error: ") and "Traceback" not in result.stderr
    for p in parts:
        assert p in lines[0], lines[0]
    return lines[0]


def _tracker_rows(rng, counts: dict, reading: str | None = None) -> str:
    rows = ["station,X,Y,Z,reading_um"]
    for s, n in counts.items():
        for p in rng.uniform(50, 450, (n, 3)):
            rows.append(f"{s},{p[0]:.3f},{p[1]:.3f},{p[2]:.3f},{reading or '12.5'}")
    return "\n".join(rows) + "\n"


def _config(folder, names=LINEAR, **tracker) -> str:
    spec = {
        "kind": "stations",
        "file": "t.csv",
        "u_um": 0.2,
        "stations": {s: list(STATIONS[s]) for s in tracker.pop("stations", STATIONS)},
        **tracker,
    }
    path = folder / "machine.toml"
    path.write_text(to_toml(full_config(base(), names, 2, {"t": spec})), encoding="utf-8")
    return str(path)


def test_too_few_readings_for_the_unknowns(tmp_path):
    rng = np.random.default_rng(1)
    (tmp_path / "t.csv").write_text(_tracker_rows(rng, {s: 4 for s in STATIONS}))
    names = (*LINEAR, "X.straightness.Y", "Y.straightness.X", "Z.straightness.X")
    line = _refused(_run("identify", _config(tmp_path, names)), "t.csv: too few readings")
    assert "16 residuals for 25 free parameters" in line


def test_fewer_than_four_stations(tmp_path):
    rng = np.random.default_rng(1)
    three = {s: 8 for s in ("S1", "S2", "S3")}
    (tmp_path / "t.csv").write_text(_tracker_rows(rng, three))
    _refused(
        _run("identify", _config(tmp_path, stations=tuple(three))),
        "t.csv: readings from 3 station(s)",
        "needs 4 or more",
    )


def test_a_station_seen_from_fewer_than_four_places(tmp_path):
    rng = np.random.default_rng(1)
    (tmp_path / "t.csv").write_text(_tracker_rows(rng, {"S1": 8, "S2": 8, "S3": 8, "S4": 3}))
    _refused(
        _run("identify", _config(tmp_path)),
        "t.csv:26: station 'S4' is seen from 3 position(s); expected 4 or more",
    )


@pytest.mark.parametrize("bad", ["nan", "inf", "-Infinity", "1e999"])
def test_a_reading_that_is_not_a_finite_number(tmp_path, bad):
    rng = np.random.default_rng(1)
    text = _tracker_rows(rng, {s: 6 for s in STATIONS}).splitlines()
    cells = text[7].split(",")
    cells[-1] = bad
    text[7] = ",".join(cells)
    (tmp_path / "t.csv").write_text("\n".join(text) + "\n")
    _refused(_run("identify", _config(tmp_path)), "t.csv:8: column reading_um: expected a")


def test_a_position_read_twice_from_one_station(tmp_path):
    rng = np.random.default_rng(1)
    text = _tracker_rows(rng, {s: 6 for s in STATIONS}).splitlines()
    text[5] = text[2]  # S1 reads its second position again on line 6
    (tmp_path / "t.csv").write_text("\n".join(text) + "\n")
    _refused(
        _run("identify", _config(tmp_path)),
        "t.csv:6: duplicate position",
        "in station 'S1' (also on line 3)",
    )


def test_a_plan_that_cannot_see_a_component_names_it_and_its_key(tmp_path):
    """At the MCP (a reflector offset of zero) the roll of the top axis Z has no lever:
    identify refuses it; --plan prints its report and then refuses the same way."""
    rng = np.random.default_rng(1)
    (tmp_path / "t.csv").write_text(_tracker_rows(rng, {s: 10 for s in STATIONS}))
    config = _config(tmp_path, (*LINEAR, "Z.angular.Z"), tool_mm=[0.0, 0.0, 0.0])
    expected = "`Z.angular.Z` (axes.Z.errors.angular.Z) is not seen by any reading"
    _refused(_run("identify", config), "not identifiable: ", expected)
    planned = _run("identify", config, "--plan")
    _refused(planned, "the plan cannot see: ", expected)
    assert "esp identify (plan)" in planned.stdout  # the report came first
    # the plan is accepted once the user fixes the unseen component explicitly
    text = (tmp_path / "machine.toml").read_text()
    (tmp_path / "machine.toml").write_text(
        text.replace("[identify]\n", '[identify]\nfix = ["Z.angular.Z"]\n')
    )
    assert _run("identify", config, "--plan").exit_code == 0


def test_a_bad_tool_offset_is_refused_by_its_key(tmp_path):
    rng = np.random.default_rng(1)
    (tmp_path / "t.csv").write_text(_tracker_rows(rng, {s: 6 for s in STATIONS}))
    _refused(
        _run("identify", _config(tmp_path, tool_mm=[0.0, 10.0])),
        "identify.measurements.t.tool_mm: expected the offset [x, y, z] in mm",
        "found [0.0, 10.0]",
    )


def test_a_tool_label_not_in_the_table_of_offsets_names_its_line(tmp_path):
    rng = np.random.default_rng(1)
    rows = _tracker_rows(rng, {s: 6 for s in STATIONS}).splitlines()
    rows[0] += ",tool"
    rows[1:] = [r + (",B" if i == 4 else ",A") for i, r in enumerate(rows[1:])]
    (tmp_path / "t.csv").write_text("\n".join(rows) + "\n")
    config = _config(tmp_path, tool_mm={"A": [0.0, 0.0, 0.0], "C": [0.0, 0.0, -50.0]})
    _refused(
        _run("identify", config),
        "t.csv:6: column tool: 'B' is not in identify.measurements.t.tool_mm (A, C)",
    )


@pytest.mark.slow
def test_a_design_too_large_to_solve_is_refused_before_it_is_built(tmp_path):
    """600 stations seen from 4 positions each: 2400 residuals, 4 unknowns per station
    (2400 + 9 coefficients of three linear errors of degree 3): the SVD would take
    2·2409·2400² + 11·2400³ + 4·2409·2400² ≈ 2.4e11 operations, above the limit of 1e11;
    refused in one line by the set's key, before any design is built (--plan and the fit)."""
    from esp.core.limits import IDENTIFY_MAX_SVD_FLOPS, design_work

    rng = np.random.default_rng(1)
    names = tuple(f"S{i}" for i in range(600))
    (tmp_path / "t.csv").write_text(_tracker_rows(rng, {s: 4 for s in names}))
    stations = {s: [float(v) for v in rng.uniform(-300.0, 1100.0, 3)] for s in names}
    spec = {"kind": "stations", "file": "t.csv", "u_um": 0.2, "stations": stations}
    path = tmp_path / "machine.toml"
    path.write_text(to_toml(full_config(base(), LINEAR, 3, {"t": spec})), encoding="utf-8")
    _, flops = design_work(2400, 2409)
    assert flops == pytest.approx(6 * 2409 * 2400**2 + 11 * 2400**3)
    assert flops > IDENTIFY_MAX_SVD_FLOPS
    for extra in ((), ("--plan",)):
        _refused(
            _run("identify", path, *extra),
            "machine.toml: identify.measurements.t: 2400 residuals x 2409 parameters: "
            "SVD operations = 2.35e+11, above the limit of 1e+11",
        )


def test_design_work_counts_memory_and_operations():
    """A tall design (1000 x 100): five copies and V, 8·(5·10⁵ + 10⁴) bytes, and the
    R-SVD's 2mn² + 11n³ operations; a wide one (100 x 1000) adds U and 4mn²."""
    from esp.core.limits import design_work

    assert design_work(1000, 100) == (8.0 * (5e5 + 1e4), 2e7 + 1.1e7)
    assert design_work(100, 1000) == (8.0 * (5e5 + 1e6 + 1e4), 2e7 + 1.1e7 + 4e7)
