"""The chain device that the head and the rotary table share (esp.core.devices.device):
their values, the checks of a value and of a setting worded for each, and the chain with
one more step that both evaluators use."""

from __future__ import annotations

from dataclasses import replace
from types import MappingProxyType

import numpy as np
import pytest

from esp.core.devices import Curve, Device, Table, table_from_chain
from esp.core.devices.device import extended_chain
from esp.core.devices.head import Head, head_from_chain
from esp.core.errors import ConfigError
from esp.core.kinematics import Chain, position, revolute, translate


def _chain() -> Chain:
    return Chain(
        [revolute("z", "C", {"tx": "X0C", "rz": "ECC"}), translate(0, 0, "-G")],
        {
            "G": {"kind": "parameter", "value": 100.0},
            "X0C": {"kind": "error"},
            "ECC": {"kind": "error", "value": 2.0},
        },
        name="c",
    )


def _table_chain() -> Chain:
    """The chain without its tool step (a table chain: the workpiece to the mount)."""
    c = _chain()
    return Chain(c.steps[:1], {n: s for n, s in c.symbols.items() if n != "G"}, name="c")


def test_the_head_and_the_table_are_devices_with_the_chain_values():
    head, table = head_from_chain(_chain()), table_from_chain(_table_chain())
    assert isinstance(head, Device) and isinstance(table, Device)
    assert isinstance(head, Head) and isinstance(table, Table)
    assert dict(head.parameters) == {"G": 100.0}
    assert dict(head.errors) == {"X0C": 0.0, "ECC": 2.0}
    # an error nothing gives is zero and has no origin
    assert dict(head.origins) == {"G": "chain", "ECC": "chain"}
    assert head.coordinates == ("C",) and head.unit("X0C") == "um"
    assert head.mcp_mm == (0.0, 0.0, 0.0) and table.setup_deg is None


def test_with_values_replaces_values_and_records_where_they_came_from():
    head = head_from_chain(_chain()).with_values({"X0C": 5.0, "G": 50.0}, origin="test")
    assert head.errors["X0C"] == 5.0 and head.parameters["G"] == 50.0
    assert head.origins["X0C"] == "test" and isinstance(head, Head)
    with pytest.raises(ConfigError) as info:
        head.with_values({"X0D": 1.0})
    assert info.value.key == "--set X0D"
    assert "did you mean 'X0C'" in info.value.message
    with pytest.raises(ConfigError) as info:
        head.with_values({"X0D": 1.0}, origin="file")
    assert info.value.key == "file.X0D"


def test_a_coordinate_is_refused_in_the_words_of_each_device():
    head, table = head_from_chain(_chain()), table_from_chain(_table_chain())
    with pytest.raises(ConfigError, match="C is a coordinate of the head; give it with --at"):
        head.with_values({"C": 1.0})
    with pytest.raises(ConfigError, match="C is an axis of the table; give its angles where"):
        table.with_values({"C": 1.0})
    with pytest.raises(ConfigError, match="not a coordinate of the head"):
        head.settings({"C": 0.0, "A": 1.0})
    with pytest.raises(ConfigError, match=r"expected finite angles \(deg\) within ±1e\+06"):
        table.settings({"C": 2e6})


def test_settings_repeat_a_number_to_the_length_of_the_arrays():
    chain = Chain(
        [revolute("x", "A"), revolute("z", "C")], {}, name="ac"
    )  # two axes: one number, one array
    at, n = head_from_chain(chain).settings({"A": 30.0, "C": [0.0, 90.0, 180.0]})
    assert n == 3 and at["A"].tolist() == [30.0, 30.0, 30.0]


def test_a_constant_given_to_an_error_with_a_curve_drops_only_that_curve():
    table = table_from_chain(_table_chain())
    curve = Curve(np.array([0.0, 180.0]), np.array([1.0, 3.0]), "urad", source="c.csv:ECC")
    table = replace(
        table,
        curves=MappingProxyType({"ECC": curve}),
        curve_axes=MappingProxyType({"ECC": "C"}),
    )
    # at 90° the curve interpolates to 2 µrad; X0C is a constant
    v = table.values_at({"C": np.array([90.0])}, 1)
    assert v["ECC"].tolist() == [2.0] and v["X0C"].tolist() == [0.0]
    kept = table.with_values({"X0C": 4.0})
    assert "ECC" in kept.curves
    dropped = table.with_values({"ECC": 7.0})
    assert dict(dropped.curves) == {} and dict(dropped.curve_axes) == {}
    assert dropped.values_at({"C": np.array([90.0])}, 1)["ECC"].tolist() == [7.0]


def test_the_extended_chain_carries_a_point_of_the_last_frame():
    chain = _chain()
    up = extended_chain(chain, translate(0, 0, "h"), {"h": {"kind": "parameter", "value": 1.0}})
    assert len(up.steps) == len(chain.steps) + 1 and "h" not in chain.symbols
    # C = 90°: the tool tip 100 mm down; one more mm along the last frame's z
    p = position(up, {"C": 90.0}, {"G": 100.0, "h": 1.0})
    assert np.allclose(p, [[0.0, 0.0, -99.0]])


def test_the_core_reads_no_files():
    """esp.core imports nothing of esp.io or esp.config (at any level, inside functions
    too): the readers of chain, head, table and curve files are in esp.config."""
    import ast
    from pathlib import Path

    core = Path(__file__).resolve().parent.parent / "esp" / "core"
    found = []
    for path in sorted(core.rglob("*.py")):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            names = []
            if isinstance(node, ast.Import):
                names = [a.name for a in node.names]
            elif isinstance(node, ast.ImportFrom) and node.module:
                names = [node.module]
            found += [f"{path.name}: {n}" for n in names if n.startswith(("esp.io", "esp.config"))]
    assert found == []
