"""The analysis of one machine: the orchestration of the engine, the uncertainty and the
prior, in that order.

1. Synthesis (:mod:`esp.core.evaluation` on :mod:`esp.core.synthesis`): the machine prepared
   once, and every tool case an immutable evaluation of it over the simulation grid -- the
   extremes of each direction, the volumetric and planar accuracy and where they occur,
   and the breakdown of every term there (Longstaff 2002, 3.05, eq. 3.4-3.5). A head sweep
   evaluates each distinct tool offset once and reports the worst orientation of each
   tool length in full (thesis 3.12).
2. Uncertainty (:mod:`esp.core.uncertainty.propagate`), when the machine has an
   ``[uncertainty]`` table: the volumetric uncertainty over the same grid and tool cases,
   with its budget, and the Monte Carlo distribution of the accuracy when asked.
3. Prior (:mod:`esp.core.uncertainty.bayes`, thesis eq. 3.22-3.24), when one is configured: the
   accuracy and its uncertainty revised with the prior information.

Nothing below this module calls back up: the engine does not know the uncertainty, the
uncertainty uses only the engine's public interface.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import replace

from esp.core.evaluation import Evaluation, evaluate
from esp.core.first_order import first_order_warnings
from esp.core.machine import AXIS_NAMES, Machine
from esp.core.names import ComponentName
from esp.core.numerics import arithmetic
from esp.core.results import (
    AnalysisResult,
    CaseResult,
    Extreme,
    PointCase,
    PointResult,
    SweepEntry,
    ToolCase,
    UncertaintyResult,
)
from esp.core.synthesis import plane_of_motion

__all__ = ["analyse", "evaluate_point", "without_u"]

Progress = Callable[[int, int], None]


def _offset_key(tool: ToolCase) -> tuple[float, ...]:
    """Tool cases with the same offset vector and the same head or table terms give the
    same field (rounded to 1 nm)."""
    key = tuple(round(tool.offset_mm[a], 6) + 0.0 for a in AXIS_NAMES)
    for t in tool.setting_terms:
        key += tuple(round(t.constant_um.get(a, 0.0), 6) + 0.0 for a in AXIS_NAMES)
        key += tuple(
            round(t.per_mm.get(a, {}).get(j, 0.0), 12) + 0.0 for a in AXIS_NAMES for j in AXIS_NAMES
        )
    return key


def _sweep(evaluations: tuple[Evaluation, ...], progress: Progress | None) -> list[SweepEntry]:
    """The volumetric accuracy of every orientation and length of a head sweep; each
    distinct tool offset is evaluated once (tilt 0° repeats one offset for every spin), and
    only its volumetric maximum is searched for."""
    done: dict[tuple[float, ...], Extreme] = {}
    entries = []
    for n, ev in enumerate(evaluations, start=1):
        key = _offset_key(ev.tool)
        if key not in done:
            done[key] = ev.volumetric_extreme()
        entries.append(SweepEntry(ev.tool, done[key]))
        if progress:
            progress(n, len(evaluations))
    return entries


def _prior(unc: UncertaintyResult, accuracy_um: float, machine: Machine) -> UncertaintyResult:
    """The uncertainty result with the Bayesian revision of thesis eq. 3.22-3.24."""
    from esp.core.uncertainty.bayes import bayes_update, expanded_change

    y_pe, u_pe = machine.uncertainty.prior
    u_cm = unc.volumetric.value_um / unc.k
    y, u_c = bayes_update(accuracy_um, u_cm, y_pe, u_pe)
    gamma = u_pe / u_cm if u_cm > 0 else math.inf
    prior = {
        "prior_um": y_pe,
        "prior_u_um": u_pe,
        "accuracy_um": y,
        "U_um": unc.k * u_c,
        "delta_U_um": expanded_change(unc.volumetric.value_um, gamma),
    }
    return replace(unc, prior=prior)


def analyse(machine: Machine, progress: Progress | None = None) -> AnalysisResult:
    """Evaluate the machine over its simulation grid.

    Returns the per-direction extremes, volumetric and planar accuracy with their points,
    and a breakdown of every active term at each of those points, for every reported tool
    case; with an ``[uncertainty]`` table also the volumetric uncertainty.
    ``progress(done, total)`` is called after each tool case (and each Monte Carlo batch).
    """
    with arithmetic():
        return _analyse(machine, progress)


def _analyse(machine: Machine, progress: Progress | None) -> AnalysisResult:
    if machine.uncertainty is not None:
        from esp.core.uncertainty.propagate import check_uncertainty

        check_uncertainty(machine)  # refuse what the uncertainty cannot do before any work
    prepared = evaluate(machine)
    syn = prepared.synthesis
    evaluations = prepared.cases()
    by_tool = {id(ev.tool): ev for ev in evaluations}
    sweeping = bool(machine.tool and machine.tool.sweep and machine.analysis.point == "TCP")
    results: list[CaseResult] = []
    sweep: list[SweepEntry] = []
    if prepared.refers_to_first_setting:
        # a servo head or a rotary table: every setting of their angles swept, the worst
        # reported in full
        sweep = _sweep(evaluations, progress)
        worst_entry = max(sweep, key=lambda e: e.volumetric.value_um)
        results.append(by_tool[id(worst_entry.tool)].case_result())
    elif sweeping:
        sweep = _sweep(evaluations, progress)
        # the worst orientation of each tool length, reported in full (thesis 3.12); ties
        # go to the first orientation of the sweep
        for length in dict.fromkeys(e.tool.length_mm for e in sweep):
            entries = [e for e in sweep if e.tool.length_mm == length]
            worst_entry = max(entries, key=lambda e: e.volumetric.value_um)
            results.append(by_tool[id(worst_entry.tool)].case_result())
    else:
        for n, ev in enumerate(evaluations, start=1):
            results.append(ev.case_result())
            if progress:
                progress(n, len(evaluations))
    worst = max(range(len(results)), key=lambda i: results[i].volumetric.value_um)
    valid = first_order_warnings(
        machine, results[worst].volumetric.value_um, (t.offset_mm for t in prepared.tools)
    )
    uncertainty = None
    missing = without_u(machine, syn.model.active)
    if machine.uncertainty is not None and not missing:
        from esp.core.uncertainty.propagate import volumetric_uncertainty

        uncertainty = volumetric_uncertainty(
            machine,
            machine.uncertainty,
            progress,
            montecarlo_tool=results[worst].tool,
            prepared=prepared,
        )
        if machine.uncertainty.prior is not None:
            uncertainty = _prior(uncertainty, results[worst].volumetric.value_um, machine)
    return AnalysisResult(
        machine=machine,
        case=syn.model.case,
        case_description=syn.model.case_description,
        equations=syn.model.equations.source,
        datum=prepared.datum,
        active=syn.model.active,
        inactive=syn.model.inactive,
        ignored=syn.model.ignored,
        warnings=tuple(machine.warnings)
        + tuple(syn.warnings)
        + valid
        + _instrument_notes(machine)
        + _missing_note(missing),
        cases=tuple(results),
        sweep=tuple(sweep),
        worst=worst,
        grid_sizes={a: int(syn.grids[a].size) for a in AXIS_NAMES},
        plane_of_motion=plane_of_motion(syn.grids),
        uncertainty=uncertainty,
        uncertainty_missing=missing,
    )


def without_u(machine: Machine, active: Sequence[ComponentName]) -> tuple[str, ...]:
    """What the model uses and ``[uncertainty]`` gives no U for: the components of
    ``active`` with neither their own U nor a default, then every non-zero error of a servo
    head or a rotary table (``head.ThetaAs``) without a U in ``[uncertainty.head]`` or
    ``[uncertainty.table]``. With any of them
    the uncertainty is not evaluated, because a U that leaves out an error the figure
    depends on is no U of the figure. Empty without an ``[uncertainty]`` table."""
    spec = machine.uncertainty
    if spec is None:
        return ()
    missing = sorted((n for n in active if str(n) not in spec.components), key=lambda n: n.sort_key)
    out = [str(n) for n in missing]
    for owner, setup in (("head", machine.head), ("table", machine.table)):
        device = getattr(setup, owner, None)
        errors = dict(getattr(device, "errors", None) or {})
        # a table's error motion given as a curve over the angle counts where not all zero
        curves = getattr(device, "curves", None) or {}
        errors.update({name: float(abs(c.values).max()) for name, c in curves.items()})
        out += [
            f"{owner}.{name}"
            for name, value in errors.items()
            if value != 0.0 and f"{owner}.{name}" not in spec.devices
        ]
    return tuple(out)


def _missing_note(missing: Sequence[str]) -> tuple[str, ...]:
    if not missing:
        return ()
    devices = [n for n in missing if n.startswith(("head.", "table."))]
    remedy = []
    if len(devices) < len(missing):
        remedy.append(
            "give their U in [uncertainty.components], or a U per kind in [uncertainty] default"
        )
    if devices:
        remedy.append(
            "give the U of a head's or table's errors in [uncertainty.head] or [uncertainty.table]"
        )
    return (
        f"the uncertainty is not evaluated: no U for {', '.join(missing)}; " + "; ".join(remedy),
    )


def _instrument_notes(machine: Machine) -> tuple[str, ...]:
    """The warnings of the instrument models of ``[uncertainty]`` (a cross-talk term that
    makes most of a U: :func:`esp.core.uncertainty.instruments.instrument_warnings`)."""
    if machine.uncertainty is None:
        return ()
    from esp.core.uncertainty.instruments import instrument_warnings

    return instrument_warnings(machine.uncertainty)


def evaluate_point(machine: Machine, at: Mapping[str, float]) -> PointResult:
    """The three errors, the volumetric error and every term at one machine position, for
    every tool case (relative to the datum when one is set)."""
    with arithmetic():
        return _evaluate_point(machine, at)


def _evaluate_point(machine: Machine, at: Mapping[str, float]) -> PointResult:
    prepared = evaluate(machine)
    point = prepared.check_point(at)
    cases = tuple(PointCase(ev.tool, ev.breakdown("point", point), ev) for ev in prepared.cases())
    syn = prepared.synthesis
    return PointResult(
        machine,
        syn.model.case,
        syn.model.equations.source,
        prepared.datum,
        point,
        cases,
        tuple(machine.warnings) + tuple(syn.warnings),
    )
