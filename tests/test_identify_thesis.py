"""The thesis' MCG calibration (Longstaff 2002, chapter 9) as printed.

Table 9.3 of the thesis gives, for each pod parameter, the difference between the value
estimated by hand (equations 9.1-9.21) and the value the optimisation reached; Table 9.2
gives both. The printed digits are in ``data/identify/longstaff-2002-tables-9.2-9.3.csv``
with their source. The thesis prints no calibration readings (the encoder readings of the
84 points on the four spheres of Table 9.1), so its identification cannot be repeated
from the thesis alone (docs/identify.md, "The thesis' MCG calibration").
"""

from __future__ import annotations

import csv
from decimal import Decimal
from pathlib import Path

TABLES = Path(__file__).parent / "data" / "identify" / "longstaff-2002-tables-9.2-9.3.csv"


def _rows() -> list[dict[str, str]]:
    lines = [ln for ln in TABLES.read_text(encoding="utf-8").splitlines() if not ln.startswith("#")]
    return list(csv.DictReader(lines))


def _places(text: str) -> int:
    return len(text.split(".")[1]) if "." in text else 0


def test_the_data_file_names_its_source_and_holds_both_pods():
    head = TABLES.read_text(encoding="utf-8").splitlines()[0]
    assert head.startswith("# source: Longstaff") and "Table 9.2" in TABLES.read_text()
    rows = _rows()
    assert [(r["parameter"], r["pod"]) for r in rows[:7]] == [
        (p, "1") for p in ("X", "Y", "Z", "m", "rotz", "rotx", "roty")
    ]
    assert len(rows) == 14 and {r["pod"] for r in rows} == {"1", "2"}


def test_table_9_3_is_table_9_2_original_minus_final_to_the_printed_digits():
    for r in _rows():
        original = Decimal(r["table_9_2_original"])
        final = Decimal(r["table_9_2_final"])
        printed = Decimal(r["table_9_3_difference"])
        q = Decimal(1).scaleb(-_places(r["table_9_3_difference"]))
        assert (original - final).quantize(q) == printed, r


def test_the_sign_is_original_minus_final_not_the_reverse():
    # every non-zero difference would fail with final - original: the test above sees the
    # convention, not only the sizes
    rows = [r for r in _rows() if Decimal(r["table_9_3_difference"]) != 0]
    assert len(rows) == 12
    for r in rows:
        reverse = Decimal(r["table_9_2_final"]) - Decimal(r["table_9_2_original"])
        assert reverse != Decimal(r["table_9_3_difference"])


def test_the_largest_change_is_the_x_of_the_second_pod():
    # the thesis' own reading of Table 9.3 (section 9.01.3)
    rows = _rows()
    worst = max(rows, key=lambda r: abs(Decimal(r["table_9_3_difference"])))
    assert (worst["parameter"], worst["pod"]) == ("X", "2")
