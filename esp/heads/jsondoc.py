"""The JSON documents of ``esp head``: ``esp.head/1`` (a setting, or a map with its worst
setting) and ``esp.protocol/1`` (a measurement protocol, and the identified errors).

Plain dictionaries, rendered with :func:`esp.report.jsonout.dumps` (floats rounded to 1e-6
of their unit). Documented in ``docs/heads.md``.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from esp.core.devices.head import Head
from esp.core.devices.head_evaluate import HeadEvaluation
from esp.heads.maps import ErrorMap, Extreme
from esp.heads.protocol import Protocol

__all__ = ["HEAD_SCHEMA", "PROTOCOL_SCHEMA", "map_document", "point_document", "protocol_document"]

HEAD_SCHEMA = "esp.head/1"
PROTOCOL_SCHEMA = "esp.protocol/1"
AXES = ("X", "Y", "Z")


def _xyz(v: np.ndarray) -> dict[str, float]:
    return {a: float(v[k]) for k, a in enumerate(AXES)}


def share_pct(value: float, total: float) -> float | None:
    """A term's share of its direction's total, %, or None when the total is zero (as the
    breakdowns of ``esp analyse``)."""
    if abs(total) < 1e-9:  # µm: a total at the level of rounding has no shares
        return None
    return 100.0 * value / total


def _values(head: Head) -> dict[str, Any]:
    def entry(n: str, v: float) -> dict[str, Any]:
        out: dict[str, Any] = {"value": v, "unit": head.unit(n)}
        if n in head.origins:
            out["from"] = head.origins[n]
        return out

    return {
        "parameters": {n: entry(n, v) for n, v in head.parameters.items()},
        "errors": {n: entry(n, v) for n, v in head.errors.items()},
    }


def _header(head: Head, mode: str, order: int) -> dict[str, Any]:
    return {
        "schema": HEAD_SCHEMA,
        "head": head.name,
        "chain": head.chain.name,
        "mode": mode,
        "order": order,
        "units": {
            "angles": "deg",
            "nominal_mm": "mm",
            "errors_mm": "mm",
            "errors_um": "um",
            "terms": "um",
            "tilt_urad": "urad",
            "share_pct": "%",
        },
        "mcp_mm": [float(v) for v in head.mcp_mm],
        "values": _values(head),
    }


def _point(ev: HeadEvaluation, i: int, order: int) -> dict[str, Any]:
    err = ev.error_um[i]
    doc: dict[str, Any] = {
        "at": {c: float(v[i]) for c, v in ev.angles.items()},
        "nominal_mm": _xyz(ev.nominal_mm[i]),
        "tool_axis": _xyz(ev.tool_axis[i]),
        "errors_mm": _xyz(err / 1000.0),
        "errors_um": _xyz(err),
        "magnitude_um": float(np.linalg.norm(err)),
        "first_order_um": _xyz(ev.first_um[i]),
    }
    if ev.second_um is not None:
        doc["second_order_um"] = _xyz(ev.second_um[i])
    if np.all(np.isfinite(ev.exact_um[i])):
        doc["exact_um"] = _xyz(ev.exact_um[i])
    doc["tilt_urad"] = _xyz(ev.tilt_urad[i])
    first = ev.first_um[i]
    doc["terms"] = [
        {
            "error": t.name,
            "value": t.value,
            "unit": t.unit,
            **_xyz(t.error_um[i]),
            "share_pct": {a: share_pct(t.error_um[i, k], first[k]) for k, a in enumerate(AXES)},
        }
        for t in ev.terms
    ]
    return doc


def point_document(ev: HeadEvaluation, order: int, index: int = 0) -> dict[str, Any]:
    """``esp.head/1`` for one setting: nominal tool tip and axis, the error (``errors_mm``,
    ``errors_um``: first order, or first plus second with ``order`` 2), the first-order,
    second-order and exact errors, the tool axis' tilt, and each error's term with its
    share of each direction's first-order total."""
    return {**_header(ev.head, "point", order), **_point(ev, index, order)}


def _extreme(e: Extreme) -> dict[str, Any]:
    return {"value_um": e.value_um, "at": dict(e.at)}


def map_document(m: ErrorMap, *, maps: bool = True) -> dict[str, Any]:
    """``esp.head/1`` for a map: the grid, the extremes of DX, DY, DZ and |D| with where,
    the largest second-order term and exact residual, the worst setting (largest |D|) in
    the keys of a point (``at``, ``nominal_mm``, ``errors_mm``, ``terms`` …), and the maps
    themselves (rows the first angle, columns the second; µm)."""
    doc = _header(m.head, "map", m.order)
    doc["grid"] = {m.names[0]: m.rows.tolist(), m.names[1]: m.cols.tolist()}
    ext = m.extremes()
    doc["extremes"] = {k: {kind: _extreme(e) for kind, e in v.items()} for k, v in ext.items()}
    peak = ext["D"]["max"].value_um
    so = m.second_order_peak()
    ex = m.exact_residual_peak()
    doc["second_order"] = {
        "max_um": so.value_um,
        "at": dict(so.at),
        "of_largest_pct": share_pct(so.value_um, peak),
    }
    doc["exact_minus_first"] = {
        "max_um": ex.value_um,
        "at": dict(ex.at),
        "of_largest_pct": share_pct(ex.value_um, peak),
    }
    doc["at_is"] = "the setting of the largest |D|"
    doc.update(_point(m.evaluation, m.worst_index(), m.order))
    if maps:
        err = m.error_um
        doc["maps"] = {
            "rows": m.names[0],
            "cols": m.names[1],
            "X": err[..., 0],
            "Y": err[..., 1],
            "Z": err[..., 2],
            "D": m.magnitude_um,
            "second_order_D": np.linalg.norm(m.second_um, axis=-1),
        }
    return doc


def protocol_document(
    protocol: Protocol,
    measured_um: Mapping[int, float] | None = None,
    identified: Mapping[str, float] | None = None,
) -> dict[str, Any]:
    """``esp.protocol/1``: the settings and assumptions, every test (settings, direction,
    equation, sensitivities), every step's solution, and with measured differences the
    identified errors."""
    head = protocol.head
    step_of = {u: s.number for s in protocol.steps for u in s.errors}
    n = len(protocol.angles) ** len(protocol.coordinates)
    doc: dict[str, Any] = {
        "schema": PROTOCOL_SCHEMA,
        "head": head.name,
        "chain": head.chain.name,
        "settings": {
            "coordinates": list(protocol.coordinates),
            "angles_deg": list(protocol.angles),
            "count": n,
        },
        "searched": protocol.searched,
        "assume_zero": list(protocol.assume_zero),
        "known": list(protocol.known),
        "identify": list(protocol.identify),
        "units": {
            "formulae": {"length": "mm", "angle": "rad"},
            "difference": "um",
            "sensitivity_um": "um of difference per unit of the error",
        },
        "parameters": {n: {"value": v, "unit": head.unit(n)} for n, v in head.parameters.items()},
        "tests": [
            {
                "test": t.number,
                "step": t.step,
                "errors": list(protocol.steps[t.step - 1].errors),
                "axis": t.axis,
                "symbol": t.symbol,
                "first": dict(t.first),
                "second": dict(t.second),
                "difference": t.difference,
                "equation": t.equation,
                "known": list(t.known),
                "sensitivity_um": dict(t.coefficients_um),
                "alternatives": t.alternatives,
            }
            for t in protocol.tests
        ],
        "steps": [
            {
                "step": s.number,
                "errors": list(s.errors),
                "tests": list(s.tests),
                "solution": dict(s.solution),
            }
            for s in protocol.steps
        ],
    }
    if protocol.known:
        doc["known_values"] = {
            e: {"value": head.errors.get(e, 0.0), "unit": head.unit(e)} for e in protocol.known
        }
    if measured_um is not None:
        doc["measured_um"] = {str(k): float(v) for k, v in sorted(measured_um.items())}
    if identified is not None:
        doc["identified"] = {
            e: {"value": v, "unit": head.unit(e), "step": step_of[e]} for e, v in identified.items()
        }
    return doc
