"""Laser10 files as third-party writers make them (docs/formats.md, "Files of other
writers"): a unidirectional test written with twice its runs, the reverse runs all zeros;
a material temperature of -10, the marker of a sensor not connected; and files whose size
would make reading them take gigabytes (docs/reliability.md, "Files that are not data")."""

from __future__ import annotations

import time
import tracemalloc
import warnings

import numpy as np
import pytest
from click.testing import CliRunner

from esp.cli import main
from esp.core.environment import environment_quantities
from esp.core.errors import EspWarning, ParseError
from esp.io.laser10 import MAX_LINES, MAX_SECTION_LINES, parse_laser10, read_laser10
from esp.iso230.positioning import iso230_2

TARGETS = (0.0, 100.0, 200.0)
#: three forward runs of a unidirectional test, µm
FORWARD = ((0.0, 1.2, 2.5), (0.1, 1.4, 2.7), (0.2, 1.3, 2.6))


def laser10(runs, flags="0 1 2 0", environment="", extra="") -> str:
    lines = ["HEADER::", "File type : rtl", "", "TARGET DATA::", f"Target-count: {len(TARGETS)}"]
    lines += ["Targets :", " ".join(f"{t:.6f}" for t in TARGETS), f"Flags: {flags}", ""]
    lines += ["RUNS::", f"Run-count: {len(runs)}", "", "DEVIATIONS::", "Run Target Data:"]
    for r, row in enumerate(runs, start=1):
        lines += [f"{r} {j} {v:.6f}" for j, v in enumerate(row, start=1)]
    lines += ["", "ENVIRONMENT::", environment, extra, "EOF::", ""]
    return "\n".join(lines)


def line_of(text: str, start: str) -> int:
    """The number of the first line of ``text`` that starts with ``start``."""
    return next(n for n, line in enumerate(text.split("\n"), 1) if line.startswith(start))


def with_zero_runs(even: bool = True):
    zero = (0.0, 0.0, 0.0)
    if even:  # as a bidirectional file places its reverse runs: 1 fwd, 2 zeros, ...
        return [row for run in FORWARD for row in (run, zero)]
    return [*FORWARD, zero, zero, zero]


@pytest.mark.parametrize("even", [True, False])
def test_zero_reverse_runs_of_a_unidirectional_test(even):
    text = laser10(with_zero_runs(even))
    with pytest.warns(EspWarning) as caught:
        p = parse_laser10(text, path="X-uni.rtl")
    message = str(caught[0].message)
    assert message.startswith("X-uni.rtl:")
    assert "unidirectional" in message and "Run-count 6" in message and "3 runs" in message
    assert p.directions == ("forward",) and p.run_count("forward") == 3
    np.testing.assert_array_equal(p.runs["forward"], np.array(FORWARD))
    # by hand: the mean at 200 mm is (2.5 + 2.7 + 2.6) / 3 = 2.6, not 2.6 / 2 with the zeros
    assert p.mean("forward")[2] == pytest.approx(2.6, abs=1e-12)


def test_the_error_is_not_halved_by_iso_230_2():
    with pytest.warns(EspWarning):
        padded = parse_laser10(laser10(with_zero_runs()), path="padded.rtl")
    plain = parse_laser10(laser10(FORWARD), path="plain.rtl")
    assert iso230_2(padded).to_dict() == iso230_2(plain).to_dict()


def test_real_runs_and_zero_files_are_left_as_they_are():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        # one real run and one of zeros: too little to tell
        p = parse_laser10(laser10([FORWARD[0], (0.0, 0.0, 0.0)]), path="two.rtl")
        assert p.run_count("forward") == 2
        # a unidirectional test of four real runs (even count, none all zero)
        p = parse_laser10(laser10([*FORWARD, (0.3, 1.1, 2.4)]), path="four.rtl")
        assert p.run_count("forward") == 4
        # every run zero: nothing tells which runs are real
        p = parse_laser10(laser10([(0.0, 0.0, 0.0)] * 4), path="zero.rtl")
        assert p.run_count("forward") == 4
        # a bidirectional file: zeros where the forward runs are kept as read
        p = parse_laser10(laser10(with_zero_runs(), flags="0 0 2 0"), path="bi.rtl")
        assert p.run_count("forward") == 3 and p.run_count("backward") == 3


ENVIRONMENT = "\n".join(
    [
        "Air temp : 20.41 20.47 0",
        "Mat temp 1 : 20.100000 20.400000 1",
        "Mat temp 2 : -10.000000 -10.000000 1",
        "Mat temp 3 : -10.000000 -10.000000 1",
    ]
)


def test_a_material_temperature_of_minus_10_is_an_absent_sensor():
    text = laser10(FORWARD, environment=ENVIRONMENT)
    with pytest.warns(EspWarning) as caught:
        p = parse_laser10(text, path="X.rtl")
    messages = [str(w.message) for w in caught]
    assert len(messages) == 2
    line = line_of(text, "Mat temp 2")
    assert messages[0].startswith(f"X.rtl:{line}: Mat temp 2 reads -10.000000 -10.000000 1")
    assert "recorded as absent" in messages[0]
    assert messages[1].startswith(f"X.rtl:{line + 1}: Mat temp 3")
    assert p.environment["Mat temp 2"] == ("-10.000000", "-10.000000", "1")  # kept as read
    values, _ = environment_quantities(p.environment)
    # by hand from sensor 1 alone: change 20.4 - 20.1 = 0.3; largest |T - 20| = 0.4
    # (with the -10 readings: 30 °C)
    assert values["temperature_change_degc"] == pytest.approx(0.3)
    assert values["max_difference_to_20_degc"] == pytest.approx(0.4)


def test_every_sensor_absent_says_so():
    env = {"Mat temp 1": ("-10.000000", "-10.000000", "1")}
    values, why = environment_quantities(env)
    assert "temperature_change_degc" not in values
    assert "absent" in why["temperature_change_degc"]


def test_inspect_warns_and_reports_the_sensor_absent(tmp_path):
    path = tmp_path / "X.rtl"
    text = laser10(FORWARD, environment=ENVIRONMENT)
    path.write_text(text, encoding="utf-8")
    res = CliRunner().invoke(main, ["inspect", str(path), "--json", "-"])
    assert res.exit_code == 0, res.stderr
    line = line_of(text, "Mat temp 2")
    assert res.stderr.count("esp: warning: ") == 2 and f"{path}:{line}: Mat temp 2" in res.stderr
    import json

    env = json.loads(res.stdout)["environment"]
    assert env["Mat temp 2"] == {"start": None, "end": None, "absent": True}
    assert env["Mat temp 1"] == {"start": "20.100000", "end": "20.400000"}
    text = CliRunner().invoke(main, ["inspect", str(path)]).stdout
    assert "Mat temp 2  absent" in text and "-10" not in text.split("environment")[1]


def test_inspect_warns_of_zero_reverse_runs(tmp_path):
    path = tmp_path / "X.rtl"
    text = laser10(with_zero_runs())
    path.write_text(text, encoding="utf-8")
    res = CliRunner().invoke(main, ["inspect", str(path), "--json", "-"])
    assert res.exit_code == 0
    line = line_of(text, "Run-count")
    assert res.stderr.startswith(f"esp: warning: {path}:{line}: Flags 0 1 2 0 marks")
    assert res.stderr.count("\n") == 1


# -- size ------------------------------------------------------------------------------------


def test_environment_section_is_limited():
    lines = "\n".join(f"Mat temp {i} : 20.1 20.2 1" for i in range(MAX_SECTION_LINES + 1))
    text = laser10(FORWARD, environment=lines)
    with pytest.raises(ParseError) as info:
        parse_laser10(text, path="big.rtl")
    assert info.value.line == line_of(text, "ENVIRONMENT::") + MAX_SECTION_LINES + 1
    assert f"expected at most {MAX_SECTION_LINES} lines in the ENVIRONMENT:: section" in str(
        info.value
    )


def test_too_many_lines_are_refused_before_parsing():
    start = time.perf_counter()
    with pytest.raises(ParseError, match=f"expected at most {MAX_LINES} lines in a Laser10 file"):
        parse_laser10(laser10(FORWARD, extra="\n" * MAX_LINES), path="blank.rtl")
    assert time.perf_counter() - start < 1.0


def test_a_section_esp_does_not_read_is_not_kept(tmp_path):
    """20 000 lines of an EQUIPMENT section: read line by line and dropped, so the memory
    taken is a small multiple of the text (keeping them took some 30 times the text)."""
    body = "EQUIPMENT::\n" + "Laser : XL-80 1\n" * 20_000
    text = laser10(FORWARD, extra=body)
    tracemalloc.start()
    try:
        p = parse_laser10(text, path="equipment.rtl")
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    assert p.run_count("forward") == 3
    assert peak < 3 * len(text), f"{peak / len(text):.1f} times the text"


def test_esp_does_not_write_what_it_would_read_differently():
    from esp.core.errors import DataError
    from esp.core.profile import ErrorProfile
    from esp.io.laser10 import format_laser10

    runs = np.array(with_zero_runs())
    profile = ErrorProfile("linear", np.array(TARGETS), {"forward": runs}, source="p")
    with pytest.raises(DataError, match="would be read back as the empty reverse runs"):
        format_laser10(profile)


def test_read_from_a_file(tmp_path):
    path = tmp_path / "Y.rtl"
    path.write_text(laser10(with_zero_runs()), encoding="utf-8")
    with pytest.warns(EspWarning, match=str(path)):
        assert read_laser10(path).run_count("forward") == 3
