"""Volumetric uncertainty: the components' uncertainties carried through the synthesis model
(Longstaff 2002, 3.14.7 and 4.01.3-4.01.4; JCGM 100:2008, 5.1.2, 6.2 and G.4), and a Monte
Carlo check (JCGM 101:2008, :mod:`esp.uncertainty.montecarlo`).

Each component's U is first turned into its standard uncertainty u = U / k with its own
coverage factor (a U given directly with the k stated for it, an instrument model's k), and
the model is run with u in place of the error; the volumetric result is expanded once, with
the analysis' k (GUM 6.2), or with k = t_p(ν_eff) for a stated coverage probability p.
U curves are used exactly as given: no straightness slope is removed from them and no run
direction is chosen (:meth:`esp.synthesis.Synthesis.prepare` with ``measured=False``).

* ``summation`` -- the error model run with each component's u in place of its error,
  signs, levers and datum as in the model; per direction the terms add with their signs,
  then the vector sum of the three directions (thesis 4.01.3, "pure addition"), times k.
* ``statistical`` -- per direction the root-sum-square of the terms' contributions (each
  term is u times its lever, so its square is separable like the term itself), then the
  vector sum (thesis 3.14.7, 4.01.4), times k. The datum is not applied: a datum-relative
  RSS would need the covariance of a term with itself at two points, which the thesis does
  not use. The effective degrees of freedom follow by Welch-Satterthwaite from the
  components' variance contributions at the point of the largest value (GUM G.4.1).
* ``montecarlo`` -- the statistical figures, and the distribution of the volumetric
  accuracy over draws of every component's error (:mod:`esp.uncertainty.montecarlo`).

The volumetric figures are the maximum over the volume (and over the tool cases); the
budget is evaluated at the point (and tool case) of the volumetric maximum.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping

from esp.errors import ConfigError
from esp.grid import fold, scan
from esp.machine import AXIS_NAMES, Machine, iso_name
from esp.results import BudgetLine, Extreme, ToolCase, UncertaintyResult
from esp.synthesis import Synthesis, datum_point, tool_cases
from esp.uncertainty.gum import coverage_factor, welch_satterthwaite
from esp.uncertainty.montecarlo import (
    MONTECARLO_MAX_BYTES,
    MONTECARLO_MAX_WORK,
    montecarlo_errors,
    montecarlo_memory_bytes,
    montecarlo_volumetric,
)
from esp.uncertainty.spec import UncertaintySpec, uncertainty_machine

__all__ = [
    "check_uncertainty",
    "montecarlo_errors",
    "montecarlo_volumetric",
    "uncertainty_machine",
    "volumetric_uncertainty",
]

Progress = Callable[[int, int], None]


def check_uncertainty(machine: Machine, spec: UncertaintySpec | None = None) -> None:
    """Refuse, before any work, what the uncertainty evaluation cannot do.

    * a U curve that does not cover the simulated range of its axis (unless
      ``analysis.extrapolate`` holds its end values), naming the component's key;
    * a Monte Carlo evaluation whose work (samples × grid points) exceeds
      :data:`~esp.uncertainty.montecarlo.MONTECARLO_MAX_WORK` or whose memory exceeds
      :data:`~esp.uncertainty.montecarlo.MONTECARLO_MAX_BYTES`, naming
      ``uncertainty.samples``.

    Raises
    ------
    ConfigError
        with the key to change and the machine's configuration file.
    """
    spec = spec or machine.uncertainty
    if spec is None:
        return
    for name, cu in spec.components.items():
        if cu.profile is None or cu.axis is None:
            continue
        grid = machine.axes[cu.axis].grid_mm()
        lo, hi = float(cu.profile.targets_mm[0]), float(cu.profile.targets_mm[-1])
        if grid[0] < lo - 1e-9 or grid[-1] > hi + 1e-9:
            if machine.analysis.extrapolate:
                continue
            raise ConfigError(
                cu.key or f'uncertainty.components."{name}".U',
                f"the U curve of {name} runs from {lo:g} to {hi:g} mm but "
                f"axes.{cu.axis}.simulate runs from {grid[0]:g} to {grid[-1]:g} mm; extend "
                "the curve to the whole range, or set analysis.extrapolate = true to hold its "
                "end values",
                machine.source,
            )
    if spec.method != "montecarlo":
        return
    points = math.prod(machine.axes[a].grid_mm().size for a in AXIS_NAMES)
    work = spec.samples * points
    if work > MONTECARLO_MAX_WORK:
        most = max(2, MONTECARLO_MAX_WORK // points)
        raise ConfigError(
            "uncertainty.samples",
            f"{spec.samples} Monte Carlo draws over {points} grid points is "
            f"{work:.3g} point-draws, beyond the limit of {MONTECARLO_MAX_WORK:.3g}; use at "
            f"most {most} draws, or a coarser grid (axes.*.step)",
            machine.source,
        )
    memory = montecarlo_memory_bytes(machine, spec)
    if memory > MONTECARLO_MAX_BYTES:
        raise ConfigError(
            "uncertainty.samples",
            f"the Monte Carlo evaluation would need about {memory / 2**20:.0f} MiB, beyond "
            f"the limit of {MONTECARLO_MAX_BYTES / 2**20:.0f} MiB; use fewer draws or a "
            "coarser grid (axes.*.step)",
            machine.source,
        )


def _offset_key(tool: ToolCase) -> tuple[float, ...]:
    return tuple(round(tool.offset_mm[a], 6) + 0.0 for a in AXIS_NAMES)


def _components_at(
    syn: Synthesis, point: Mapping[str, float], tool: ToolCase, datum, statistical: bool
) -> dict[str, dict[str, list[float]]]:
    """Per component and direction, the values (µm) of its terms at ``point`` (relative
    to the datum for the summation method)."""
    per: dict[str, dict[str, list[float]]] = {}
    for bt in syn.terms():
        v = syn.term_value_um(bt, point, tool)
        if datum is not None and not statistical:
            v -= syn.term_value_um(bt, datum, tool)
        per.setdefault(str(bt.component), {a: [] for a in AXIS_NAMES})[bt.direction].append(v)
    return per


def _budget(
    spec: UncertaintySpec,
    per: Mapping[str, Mapping[str, list[float]]],
    point: Mapping[str, float],
    statistical: bool,
) -> tuple[BudgetLine, ...]:
    """Each component at ``point``: its U, k, u and degrees of freedom there, its standard
    contribution and its share of the volumetric uncertainty.

    Statistical: its terms' squares over the sum of all squares. Summation: its signed
    contribution projected on the direction totals, Σ_d t_c,d·E_d / V² (shares add to 100).
    """
    squares = {c: math.fsum(v * v for d in dirs.values() for v in d) for c, dirs in per.items()}
    if statistical:
        total = math.fsum(squares.values())
        share = squares
    else:
        sums = {c: {a: math.fsum(d[a]) for a in AXIS_NAMES} for c, d in per.items()}
        e = {a: math.fsum(s[a] for s in sums.values()) for a in AXIS_NAMES}
        total = math.fsum(x * x for x in e.values())
        share = {c: math.fsum(s[a] * e[a] for a in AXIS_NAMES) for c, s in sums.items()}
    lines = []
    for name, cu in spec.components.items():
        U = cu.U_at(point[cu.axis] if cu.axis else None)
        lines.append(
            BudgetLine(
                component=str(name),
                iso=iso_name(name),
                model=cu.model,
                U=U,
                unit=cu.unit,
                share_pct=(100.0 * share.get(name, 0.0) / total) if total > 0 else 0.0,
                k=cu.coverage_k,
                u=U / cu.coverage_k,
                U_max=cu.U_max,
                distribution=cu.distribution,
                dof=cu.dof,
                contribution_um=math.sqrt(squares.get(name, 0.0)),
            )
        )
    return tuple(sorted(lines, key=lambda b: (-b.share_pct, b.component)))


def volumetric_uncertainty(
    machine: Machine,
    spec: UncertaintySpec,
    progress: Progress | None = None,
    montecarlo_tool: ToolCase | None = None,
) -> UncertaintyResult:
    """The volumetric uncertainty of ``machine`` by the method of ``spec``.

    ``montecarlo_tool`` is the tool case on which the Monte Carlo distribution of the
    volumetric accuracy is drawn (the analysis passes its worst case; default: the first
    tool case). For ``montecarlo`` the volumetric U, its point and the budget are the
    statistical ones, and the Monte Carlo summary is added. The prior of eq. 3.22-3.24 is
    applied by :func:`esp.analysis.analyse`.

    Raises
    ------
    ConfigError
        what :func:`check_uncertainty` refuses.
    """
    check_uncertainty(machine, spec)
    syn = Synthesis.prepare(uncertainty_machine(machine, spec, standard=True), measured=False)
    statistical = spec.method != "summation"
    datum = None if statistical else datum_point(machine)
    g = syn.grids
    sizes = tuple(g[a].size for a in AXIS_NAMES)
    best = None
    seen: set[tuple[float, ...]] = set()
    for tool in tool_cases(machine):
        key = _offset_key(tool)
        if key in seen:
            continue  # the same offset gives the same field: the first case keeps a tie
        seen.add(key)
        if statistical:
            stats = scan(fold(syn.squared_products(tool), sizes), squared=True)
            axes = [(v, i) for v, i in stats.maximum]
        else:
            stats = scan(fold(syn.products(tool, datum), sizes))
            axes = [
                max((abs(lo[0]), lo[1]), (abs(hi[0]), hi[1]), key=lambda t: t[0])
                for lo, hi in zip(stats.minimum, stats.maximum, strict=True)
            ]
        if best is None or stats.volumetric[0] > best[0][0]:
            best = (stats.volumetric, axes, tool)
    if best is None:  # pragma: no cover - a machine has at least one tool case
        raise ValueError("the machine has no tool case")
    (u_vol, vol_index), axes, tool = best

    def at(index) -> dict[str, float]:
        return {a: float(g[a][i]) for a, i in zip(AXIS_NAMES, index, strict=True)}

    point = at(vol_index)
    per = _components_at(syn, point, tool, datum, statistical)
    budget = _budget(spec, per, point, statistical)
    dof_eff = None
    k = spec.k
    if statistical:
        dof_eff = welch_satterthwaite(
            (b.contribution_um, b.dof) for b in budget if b.contribution_um > 0
        )
        if spec.coverage is not None:
            k = coverage_factor(spec.coverage, dof_eff)
    mc = None
    if spec.method == "montecarlo":
        mc = montecarlo_volumetric(machine, spec, montecarlo_tool, progress=progress)
    return UncertaintyResult(
        method=spec.method,
        k=k,
        volumetric=Extreme(k * float(u_vol), point),
        axes={a: Extreme(k * float(v), at(i)) for a, (v, i) in zip(AXIS_NAMES, axes, strict=True)},
        budget=budget,
        montecarlo=mc,
        u_um=float(u_vol),
        dof_eff=dof_eff,
        coverage=spec.coverage,
        budget_tool=tool,
    )
