"""The shipped ballbar example (data/examples/ballbar, docs/ballbar.md): its files are what
make_data.py writes, and the diagnosis of each finds the truth it was made with, and
nothing else."""

from __future__ import annotations

import importlib.util
import json
from pathlib import Path

import pytest

from esp.ballbar import circle_tests

EXAMPLE = Path(__file__).resolve().parent.parent / "data" / "examples" / "ballbar"
TRUTH = json.loads((EXAMPLE / "truth.json").read_text(encoding="utf-8"))
#: recovered within this many standard uncertainties plus a share of the value
K_TOL, REL_TOL = 4.0, 0.02


@pytest.mark.parametrize("name", sorted(TRUTH))
def test_the_example_finds_its_truth(name):
    (c,) = circle_tests(EXAMPLE / name)
    truth = TRUTH[name]
    for t in c.diagnosis.terms:
        if t.key in truth:
            assert t.reported, t
            assert abs(t.value - truth[t.key]) <= K_TOL * t.u + REL_TOL * abs(truth[t.key]), t
        else:
            assert not t.reported, t


def test_make_data_writes_the_shipped_files(tmp_path):
    spec = importlib.util.spec_from_file_location("ballbar_make_data", EXAMPLE / "make_data.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    module.main(tmp_path)
    for path in sorted(tmp_path.iterdir()):
        assert path.read_bytes() == (EXAMPLE / path.name).read_bytes(), path.name
