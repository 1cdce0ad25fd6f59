"""The text report and the JSON document (schema ``esp.parallel/1``) of ``esp parallel``.

Both take the results of :mod:`esp.parallel.analysis`; nothing is computed here. The JSON
fields are described in ``docs/parallel.md``.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from esp._version import __version__
from esp.core.rounding import rounded, stated
from esp.parallel.analysis import PoseResult, SweepResult
from esp.parallel.sources import M_COLUMNS, N_COLUMNS, OUTPUTS, SOURCE_NAMES, SOURCES

__all__ = ["SCHEMA", "document", "render_text"]

SCHEMA = "esp.parallel/1"
_UNIT_TEXT = {"um": "µm", "urad": "µrad", "": ""}
_OUT_LABELS = ("e_x", "e_y", "e_z", "ε_x", "ε_y", "ε_z")
_ROW_LABELS = ("strut 1", "strut 2", "strut 3", "plane 1", "plane 2", "plane 3")
_SOURCE = {s.name: s for s in SOURCES}
#: error-sweep rows printed at most (evenly chosen, ends kept)
MAX_SWEEP_ROWS = 11


# -- JSON ------------------------------------------------------------------------------------


def _geometry_dict(result: PoseResult) -> dict:
    g = result.machine.geometry
    out: dict = {"layout": g.layout}
    if g.layout == "symmetric":
        out.update({"R_mm": g.R_mm, "r_mm": g.r_mm, "h_mm": g.h_mm})
    out["legs"] = [
        {
            "leg": i + 1,
            "joint_xy_mm": list(leg.joint_xy_mm),
            "axis": list(leg.axis),
            "ball_mm": list(leg.ball_mm),
            "strut_mm": leg.strut_mm,
        }
        for i, leg in enumerate(g.legs)
    ]
    out["table_origin_mm"] = list(g.table_origin_mm)
    out["slider_travel_mm"] = None if g.slider_travel_mm is None else list(g.slider_travel_mm)
    return out


def _pose_dict(result: PoseResult) -> dict:
    p = result.pose
    t = result.transmission
    return {
        "z_mm": float(p.z_mm[0]),
        "alpha_deg": float(p.alpha_deg[0]),
        "beta_deg": float(p.beta_deg[0]),
        "x_mm": float(p.x_mm[0]),
        "y_mm": float(p.y_mm[0]),
        "gamma_deg": float(p.gamma_deg[0]),
        "table_mm": list(result.pose_spec.table_mm),
        "sliders_mm": p.sliders_mm[0],
        "strut_elevation_deg": p.elevation_deg[0],
        "condition_number": float(t.condition[0]),
        "smallest_singular_value": float(t.smallest_singular_value[0]),
        "max_condition": result.machine.max_condition,
    }


def _outputs(values: np.ndarray) -> dict:
    return {name: float(v) for name, v in zip(OUTPUTS, values, strict=True)}


def _uncertainty_dict(result: PoseResult) -> dict | None:
    u = result.uncertainty
    if u is None:
        return None
    doc = {
        "method": u.method,
        "k": u.k,
        "summation": _outputs(u.summation),
        "statistical": _outputs(u.statistical),
        "position_um": u.position_um,
        "rotation_urad": u.rotation_urad,
        "budget": [
            {
                "source": b.source,
                "unit": _SOURCE[b.source].unit,
                "U": b.U,
                "contribution": _outputs(b.contribution),
                "share_position_pct": b.share_position_pct,
                "share_rotation_pct": b.share_rotation_pct,
            }
            for b in u.budget
        ],
        "montecarlo": None,
    }
    mc = u.montecarlo
    if mc is not None:
        doc["montecarlo"] = {
            "samples": mc.samples,
            "seed": mc.seed,
            "model": mc.model,
            "mean": _outputs(mc.mean),
            "std": _outputs(mc.std),
            "interval_95": {
                name: [float(lo), float(hi)]
                for name, lo, hi in zip(OUTPUTS, mc.low, mc.high, strict=True)
            },
            "position_um": {
                "mean": mc.position_mean_um,
                "std": mc.position_std_um,
                "interval_95": [mc.position_low_um, mc.position_high_um],
            },
        }
    return doc


def _sweep_dict(sweep: SweepResult) -> dict:
    es, ws = sweep.error, sweep.workspace
    return {
        "error": {
            "source": es.source,
            "unit": es.unit,
            "cases": [
                {
                    "case": c.case,
                    "sources": list(c.sources),
                    "values": c.values,
                    "errors": [_outputs(row) for row in c.errors],
                }
                for c in es.cases
            ],
        },
        "workspace": {
            "z_mm": ws.z_mm,
            "alpha_deg": ws.alpha_deg,
            "beta_deg": ws.beta_deg,
            "poses": int(ws.evaluated.size),
            "evaluated": int(ws.evaluated.sum()),
            "points": [
                {
                    "z_mm": float(p[0]),
                    "alpha_deg": float(p[1]),
                    "beta_deg": float(p[2]),
                    "errors": _outputs(e),
                    "condition_number": float(c),
                    **({} if ws.uncertainty is None else {"U": _outputs(ws.uncertainty[i])}),
                }
                for i, (p, e, c) in enumerate(zip(ws.points, ws.errors, ws.condition, strict=True))
            ],
            "excluded": [
                {"z_mm": z, "alpha_deg": a, "beta_deg": b, "reason": why}
                for z, a, b, why in ws.excluded
            ],
            "worst": [
                {
                    "quantity": w.quantity,
                    "unit": w.unit,
                    "value": w.value,
                    "z_mm": w.z_mm,
                    "alpha_deg": w.alpha_deg,
                    "beta_deg": w.beta_deg,
                }
                for w in ws.worst
            ],
        },
    }


def document(result: PoseResult, sweep: SweepResult | None = None) -> dict:
    """The ``esp.parallel/1`` document (plain types; :func:`esp.report.jsonout.dumps`
    rounds and writes it)."""
    t = result.transmission
    machine = result.machine
    return {
        "schema": SCHEMA,
        "esp_version": __version__,
        "machine": {"name": machine.name, "source": machine.source, **dict(machine.info)},
        "model": result.model,
        "units": {
            "position": "mm",
            "angle": "deg",
            "error": "um",
            "rotation_error": "urad",
            "matrices": "mm and rad (the paper's): [J] moment columns in mm, [N] axis and "
            "table-rotation columns per rad",
        },
        "geometry": _geometry_dict(result),
        "pose": _pose_dict(result),
        "methods": {
            "linkage_vs_differential": float(t.methods_difference[0]),
            "first_order_vs_exact": float(np.max(np.abs(result.errors - result.exact))),
        },
        "matrices": {
            "rows": list(_ROW_LABELS),
            "outputs": list(OUTPUTS),
            "J": t.J[0],
            "J_inv": t.J_inv[0],
            "M": t.M[0],
            "M_columns": list(M_COLUMNS),
            "N": t.N[0],
            "N_columns": list(N_COLUMNS),
        },
        "sources": [
            {
                "source": s.name,
                "symbol": s.symbol,
                "unit": s.unit,
                "description": s.description,
                "value": float(result.values[j]),
                "sensitivity": _outputs(t.sensitivity[0][:, j]),
            }
            for j, s in enumerate(SOURCES)
        ],
        "errors": {
            **_outputs(result.errors),
            "position_um": float(np.linalg.norm(result.errors[:3])),
            "rotation_urad": float(np.linalg.norm(result.errors[3:])),
            "exact": _outputs(result.exact),
        },
        "contributions": [
            {
                "source": name,
                **_outputs(result.contributions[j]),
                "share_position_pct": float(result.share_position_pct[j]),
                "share_rotation_pct": float(result.share_rotation_pct[j]),
            }
            for j, name in enumerate(SOURCE_NAMES)
            if result.values[j] != 0
        ],
        "uncertainty": _uncertainty_dict(result),
        "sweep": None if sweep is None else _sweep_dict(sweep),
    }


# -- text ------------------------------------------------------------------------------------


def _f(value: float | np.floating, digits: int = 3) -> str:
    text = f"{value:.{digits}f}"
    return "0." + "0" * digits if text.lstrip("-") == "0." + "0" * digits else text


def _table(header: Sequence[str], rows: Sequence[Sequence[str]], indent: str = "  ") -> list[str]:
    widths = [max(len(h), *(len(r[i]) for r in rows)) for i, h in enumerate(header)]
    lines = [
        indent
        + "  ".join(
            h.rjust(w) if i else h.ljust(w)
            for i, (h, w) in enumerate(zip(header, widths, strict=True))
        )
    ]
    for r in rows:
        lines.append(
            indent
            + "  ".join(
                c.rjust(w) if i else c.ljust(w)
                for i, (c, w) in enumerate(zip(r, widths, strict=True))
            )
        )
    return lines


def _matrix(label: str, rows: Sequence[str], cols: Sequence[str], m: np.ndarray) -> list[str]:
    body = [
        [r, *(f"{v:.5g}" if abs(v) >= 1e-12 else "0" for v in line)]
        for r, line in zip(rows, m, strict=True)
    ]
    return [label, *_table(["", *cols], body)]


def render_text(result: PoseResult, sweep: SweepResult | None = None) -> str:
    """The report printed by ``esp parallel``."""
    m = result.machine
    g = m.geometry
    t = result.transmission
    p = result.pose
    lines = [f"esp parallel: {m.name}"]
    if m.source:
        lines.append(f"File: {m.source}")
    if result.model == "exact":
        lines.append(
            "Model: exact (linkage kinematic analysis; the differential vector method agrees "
            f"to {t.methods_difference[0]:.1e})"
        )
    else:
        lines.append("Model: as-printed (eq. 10-18 of Zhao, Fan et al. 2002 as printed)")
    if g.layout == "symmetric":
        struts = ", ".join(f"{v:g}" for v in g.struts_mm)
        lines.append(
            f"Geometry: R = {g.R_mm:g} mm, r = {g.r_mm:g} mm, h = {g.h_mm:g} mm, struts {struts} mm"
        )
    else:
        lines.append("Geometry: explicit layout (legs given one by one)")
    lines += [
        "",
        f"Pose: z_T = {p.z_mm[0]:g} mm, α = {p.alpha_deg[0]:g}°, β = {p.beta_deg[0]:g}°; "
        f"x_T = {_f(p.x_mm[0])} mm, y_T = {_f(p.y_mm[0])} mm, γ = {p.gamma_deg[0]:.4f}° "
        "(eq. 4)",
        f"X-Y table at X = {result.pose_spec.table_mm[0]:g} mm, "
        f"Y = {result.pose_spec.table_mm[1]:g} mm",
        "Sliders (eq. 5): "
        + ", ".join(f"H_{i + 1} = {_f(h)} mm" for i, h in enumerate(p.sliders_mm[0]))
        + "; strut elevation "
        + ", ".join(f"{e:.2f}°" for e in p.elevation_deg[0]),
        f"Condition number of [J]: {t.condition[0]:.3g} (limit {m.max_condition:g})",
        "",
    ]
    cols_j = ["e_x", "e_y", "e_z", "ε_x", "ε_y", "ε_z"]
    lines += _matrix("[J] (eq. 12; ε columns in mm)", _ROW_LABELS, cols_j, t.J[0])
    lines.append("")
    lines += _matrix(
        "[J]^-1 (rows e: per mm of constraint; rows ε: rad per mm)",
        _OUT_LABELS,
        list(_ROW_LABELS),
        t.J_inv[0],
    )
    lines.append("")
    lines += _matrix("[M]ᵀ (eq. 12; one row per column of [M])", M_COLUMNS, _ROW_LABELS, t.M[0].T)
    lines.append("")
    lines += _matrix(
        "[N]ᵀ (eq. 18; one row per column of [N]; axis and table rotations per rad)",
        N_COLUMNS,
        _ROW_LABELS,
        t.N[0].T,
    )
    lines += ["", "Tool-tip errors for the error values of the file (relative to the table):"]
    e = result.errors
    lines.append(
        "  e = ("
        + ", ".join(_f(v) for v in e[:3])
        + f") µm, |e| = {_f(np.linalg.norm(e[:3]))} µm;  ε = ("
        + ", ".join(_f(v) for v in e[3:])
        + f") µrad, |ε| = {_f(np.linalg.norm(e[3:]))} µrad"
    )
    lines.append(
        "  exact kinematics: largest difference from the first-order model "
        f"{np.max(np.abs(result.errors - result.exact)):.2g} µm or µrad"
    )
    active = [j for j in range(len(SOURCE_NAMES)) if result.values[j] != 0]
    if active:
        cancels = [
            _cancels(result.contributions[active][:, part]) for part in (slice(0, 3), slice(3, 6))
        ]
        rows = []
        for j in sorted(active, key=lambda j: -abs(result.share_position_pct[j])):
            s = SOURCES[j]
            shares = (result.share_position_pct[j], result.share_rotation_pct[j])
            rows.append(
                [
                    s.name,
                    f"{result.values[j]:g} {_UNIT_TEXT[s.unit]}",
                    *(_f(v) for v in result.contributions[j]),
                    *("-" if c else f"{v:.1f}" for c, v in zip(cancels, shares, strict=True)),
                ]
            )
        lines += [
            "",
            "Each source's contribution (µm and µrad) and share (projected on the total):",
        ]
        lines += _table(["source", "value", *_OUT_LABELS, "% of |e|", "% of |ε|"], rows)
        for c, what in zip(cancels, ("|e|", "|ε|"), strict=True):
            if c:
                lines.append(
                    f"  - the contributions to {what} largely cancel (the total is less than a "
                    "tenth of the largest): shares are not shown"
                )
    else:
        lines.append("  (the file gives no error values: every source is 0)")
    if result.uncertainty is not None:
        lines += ["", *_uncertainty_lines(result)]
    if sweep is not None:
        lines += ["", *_sweep_lines(sweep)]
    return "\n".join(lines) + "\n"


def _cancels(contrib: np.ndarray) -> bool:
    """True when contributions (n, 3) cancel so that shares of their total mislead."""
    largest = float(np.max(np.linalg.norm(contrib, axis=1))) if len(contrib) else 0.0
    return largest > 0 and float(np.linalg.norm(contrib.sum(axis=0))) < 0.1 * largest


def _tip_stated(value_um: float, expanded_um: float, k: float, method: str) -> str:
    """``61 µm, U = 23 µm (k = 2, about 95 %)``; a summation bound is no coverage interval:
    ``U ≤ 23 µm (k = 2, summation bound)``."""
    if method != "summation":
        return stated(value_um, expanded_um, "µm", k)
    v_text, u_text = rounded(value_um, expanded_um)
    return f"{v_text} µm, U ≤ {u_text} µm (k = {k:g}, summation bound)"


def _uncertainty_lines(result: PoseResult) -> list[str]:
    u = result.uncertainty
    assert u is not None  # called only for a result with an uncertainty
    method = {
        "statistical": "statistical (root-sum-square, GUM 5.1.2)",
        "summation": "summation, an upper bound (sum of |sensitivity| x U per output)",
        "montecarlo": "Monte Carlo (GUM Supplement 1) with the statistical figures",
    }[u.method]
    values = u.by_method
    tip_um = float(np.linalg.norm(result.errors[:3]))
    lines = [
        f"Uncertainty ({method}, k = {u.k:g}):",
        *(  # the tool tip's error rounded to what its U supports (GUM 7.2.6)
            [f"  tool tip |e| = {_tip_stated(tip_um, u.position_um, u.k, u.method)}"]
            if u.position_um > 0.0
            else []
        ),
        "  U(e) = ("
        + ", ".join(_f(v) for v in values[:3])
        + f") µm, tool tip {_f(u.position_um)} µm",
        "  U(ε) = (" + ", ".join(_f(v) for v in values[3:]) + f") µrad, {_f(u.rotation_urad)} µrad",
    ]
    mc = u.montecarlo
    if mc is not None:
        lines.append(
            f"  Monte Carlo ({mc.samples} draws, seed {mc.seed}, {mc.model} kinematics): "
            f"|e| mean {_f(mc.position_mean_um)} µm, 95 % interval "
            f"[{_f(mc.position_low_um)}, {_f(mc.position_high_um)}] µm"
        )
        rows = [
            [
                lab,
                _f(mc.mean[i]),
                _f(mc.std[i]),
                _f(mc.low[i]),
                _f(mc.high[i]),
                _f(u.statistical[i] / u.k),
            ]
            for i, lab in enumerate(_OUT_LABELS)
        ]
        lines += _table(
            ["output", "mean", "std", "2.5 %", "97.5 %", "u (statistical)"], rows, "    "
        )
    rows = [
        [
            b.source,
            f"{b.U:g} {_UNIT_TEXT[_SOURCE[b.source].unit]}",
            f"{b.share_position_pct:.1f}",
            f"{b.share_rotation_pct:.1f}",
        ]
        for b in u.budget
    ]
    if rows:
        lines += ["  Budget (share of the tool tip's position and orientation uncertainty):"]
        lines += _table(["source", "U", "% of U(e)", "% of U(ε)"], rows, "    ")
    return lines


def _sweep_lines(sweep: SweepResult) -> list[str]:
    es, ws = sweep.error, sweep.workspace
    unit = _UNIT_TEXT[es.unit]
    case0 = es.cases[0]
    lines = [
        f"Error sweep: {es.source} from {case0.values[0]:g} to {case0.values[-1]:g} {unit} "
        f"({case0.values.size} steps), every other source at its value",
    ]
    for c in es.cases:
        what = {"all": "every leg the same (Fig. 5)", "table": "the table"}.get(
            c.case, f"leg {c.case} only (Fig. {6 if c.case == '1' else '6 for leg ' + c.case})"
        )
        lines.append(f"  case {c.case}: {what}")
        idx = np.unique(
            np.linspace(0, c.values.size - 1, min(MAX_SWEEP_ROWS, c.values.size))
            .round()
            .astype(int)
        )
        rows = [[f"{c.values[i]:g}", *(_f(v) for v in c.errors[i])] for i in idx]
        lines += _table([f"value ({unit})", *_OUT_LABELS], rows, "    ")
    z, a, b = ws.z_mm, ws.alpha_deg, ws.beta_deg
    lines += [
        "",
        f"Workspace: z_T {z[0]:g} to {z[-1]:g} mm ({z.size}), α {a[0]:g} to {a[-1]:g}° "
        f"({a.size}), β {b[0]:g} to {b[-1]:g}° ({b.size}): {ws.evaluated.size} poses, "
        f"{int(ws.evaluated.sum())} evaluated",
    ]
    if ws.excluded:
        lines.append(f"  {len(ws.excluded)} poses left out (unreachable or near-singular)")
    rows = [
        [
            w.quantity,
            f"{_f(w.value)} {_UNIT_TEXT[w.unit]}".strip() if w.unit else f"{w.value:.3g}",
            f"{w.z_mm:g}",
            f"{w.alpha_deg:g}",
            f"{w.beta_deg:g}",
        ]
        for w in ws.worst
    ]
    lines.append("  Worst case and where:")
    lines += _table(["quantity", "value", "z_T (mm)", "α (°)", "β (°)"], rows, "    ")
    return lines
