"""One absurd reading of a measurement table for ``esp identify`` is refused at its file
and line, before the fit: no numpy overflow warning, no "implausible curves" message that
names no reading (docs/reliability.md, "What is refused")."""

from __future__ import annotations

import shutil
import warnings
from pathlib import Path

import pytest
from click.testing import CliRunner

from esp.cli import main
from esp.core.errors import ParseError
from esp.identify.tables import read_table

EXAMPLE = Path(__file__).resolve().parent.parent / "data" / "examples" / "identify" / "tool-ballbar"


@pytest.mark.parametrize(
    "value, found",
    [("1e308", "1e308"), ("1e30", "1e30"), ("1e6", "1000000"), ("-10000.5", "-10000.5")],
)
def test_an_absurd_ballbar_reading_is_refused_at_its_line(tmp_path, value, found):
    folder = tmp_path / "tool-ballbar"
    shutil.copytree(EXAMPLE, folder)
    path = folder / "ballbar.csv"
    lines = path.read_text(encoding="utf-8").splitlines()
    head, _, _ = lines[3].rpartition(",")
    lines[3] = f"{head},{value}"  # line 4: the second reading of the first circle
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no numpy warning either
        result = CliRunner().invoke(main, ["identify", str(folder / "machine.toml")])
    assert result.exit_code == 2, result.output
    out = result.output.strip().splitlines()
    assert len(out) == 1 and "implausible" not in out[0]
    assert (
        f"{path}:4: column deviation_um: expected a deviation within ±10000 um, found {found}"
        in out[0]
    )


@pytest.mark.parametrize(
    "column, value, found",
    [("X", "2e5", "200000"), ("length_mm", "1e300", "1e300"), ("u_um", "-2e4", "-20000")],
)
def test_every_column_with_a_unit_has_its_limit(tmp_path, column, value, found):
    header = ["circle", "X", "Y", "Z", "length_mm", "deviation_um", "u_um"]
    row = {"circle": "c1", "X": "1", "Y": "2", "Z": "3", "length_mm": "150"}
    row |= {"deviation_um": "0.5", "u_um": "1"}
    bad = dict(row, **{column: value})
    path = tmp_path / "t.csv"
    path.write_text(
        ",".join(header)
        + "\n"
        + ",".join(row[h] for h in header)
        + "\n"
        + ",".join(bad[h] for h in header)
        + "\n",
        encoding="utf-8",
    )
    cols = ("X", "Y", "Z", "length_mm", "deviation_um")
    with pytest.raises(ParseError) as info:
        read_table(path, cols, ("circle",), ("u_um",))
    assert info.value.line == 3
    assert (
        f"column {column}: expected a " in info.value.message and " within ±" in info.value.message
    )
    assert info.value.message.endswith(f"found {found}")
