"""Volumetric uncertainty: the components' expanded uncertainties carried through the
synthesis model (Longstaff 2002, 3.14.7 and 4.01.3-4.01.4), and a Monte Carlo check
(JCGM 101:2008, GUM Supplement 1).

* ``summation`` -- the error model run with each component's U in place of its error,
  signs, levers and datum as in the model; per direction the terms add with their signs,
  then the vector sum of the three directions (thesis 4.01.3, "pure addition").
* ``statistical`` -- per direction the root-sum-square of the terms' contributions (each
  term is U times its lever, so its square is separable like the term itself), then the
  vector sum (thesis 3.14.7, 4.01.4). The datum is not applied: a datum-relative RSS would
  need the covariance of a term with itself at two points, which the thesis does not use.
* ``montecarlo`` -- every component's error is drawn from its distribution about its
  measured profile (normal, or rectangular of the same standard deviation), the whole
  engine is run per draw and the volumetric accuracy collected: its mean, standard
  deviation and 95 % coverage interval. A component's draw is one shape along its axis:
  ``e(x) = measured(x) + z · u(x)`` with one scalar ``z`` per component and draw, i.e. the
  deviation is fully correlated along the axis (a calibration or set-up error shifts the
  whole curve), and components are independent of each other.

The volumetric figures are the maximum over the volume (and over the tool cases).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import replace

import numpy as np

from esp.grid import fold, scan
from esp.machine import AXIS_NAMES, Machine, iso_name
from esp.results import BudgetLine, Extreme, MonteCarloSummary, ToolCase, UncertaintyResult
from esp.synthesis import Synthesis, datum_point, tool_cases
from esp.uncertainty.spec import UncertaintySpec

__all__ = [
    "MONTECARLO_MAX_POINTS",
    "montecarlo_errors",
    "montecarlo_volumetric",
    "uncertainty_machine",
    "volumetric_uncertainty",
]

#: the Monte Carlo method evaluates at most this many grid points per draw; a finer grid is
#: thinned evenly along each axis (both ends kept)
MONTECARLO_MAX_POINTS = 20_000
_BATCH_ELEMENTS = 4_000_000

Progress = Callable[[int, int], None]


def uncertainty_machine(machine: Machine, spec: UncertaintySpec, names=None) -> Machine:
    """The machine with every component's data replaced by its U (and absent components,
    and those not in ``names`` when given, left out)."""
    comps = {
        n: cu.as_component() for n, cu in spec.components.items() if names is None or n in names
    }
    return replace(machine, components=comps, uncertainty=None)


def _budget(
    syn: Synthesis, spec: UncertaintySpec, point, tool: ToolCase, datum, statistical: bool
) -> tuple[BudgetLine, ...]:
    """Each component's share of the volumetric uncertainty at ``point``.

    Statistical: its terms' squares over the sum of all squares. Summation: its signed
    contribution projected on the direction totals, Σ_d t_c,d·E_d / V² (shares add to 100).
    """
    per: dict[str, dict[str, float]] = {}
    for bt in syn.terms():
        v = syn.term_value_um(bt, point, tool)
        if datum is not None and not statistical:
            v -= syn.term_value_um(bt, datum, tool)
        slot = per.setdefault(bt.component, {a: 0.0 for a in AXIS_NAMES})
        slot[bt.direction] += v * v if statistical else v
    if statistical:
        total = sum(sum(d.values()) for d in per.values())
        share = {c: sum(d.values()) for c, d in per.items()}
    else:
        e = {a: sum(d[a] for d in per.values()) for a in AXIS_NAMES}
        total = sum(x * x for x in e.values())
        share = {c: sum(d[a] * e[a] for a in AXIS_NAMES) for c, d in per.items()}
    lines = [
        BudgetLine(
            component=name,
            iso=iso_name(name),
            model=cu.model,
            U=cu.U_max,
            unit=cu.unit,
            share_pct=(100.0 * share.get(name, 0.0) / total) if total > 0 else 0.0,
        )
        for name, cu in spec.components.items()
    ]
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
    """
    um = uncertainty_machine(machine, spec)
    syn = Synthesis.prepare(um)
    statistical = spec.method != "summation"
    datum = None if statistical else datum_point(machine)
    g = syn.grids
    best = None
    for tool in tool_cases(machine):
        if statistical:
            stats = scan(
                fold(syn.squared_products(tool), tuple(g[a].size for a in AXIS_NAMES)),
                squared=True,
            )
            axes = [(v, i) for v, i in stats.maximum]
        else:
            stats = scan(fold(syn.products(tool, datum), tuple(g[a].size for a in AXIS_NAMES)))
            axes = [
                max((abs(lo[0]), lo[1]), (abs(hi[0]), hi[1]), key=lambda t: t[0])
                for lo, hi in zip(stats.minimum, stats.maximum, strict=True)
            ]
        if best is None or stats.volumetric[0] > best[0][0]:
            best = (stats.volumetric, axes, tool)
    (vol_value, vol_index), axes, tool = best

    def at(index) -> dict[str, float]:
        return {a: float(g[a][i]) for a, i in zip(AXIS_NAMES, index, strict=True)}

    volumetric = Extreme(float(vol_value), at(vol_index))
    budget = _budget(syn, spec, volumetric.at, tool, datum, statistical)
    mc = None
    if spec.method == "montecarlo":
        mc = montecarlo_volumetric(machine, spec, montecarlo_tool, progress=progress)
    return UncertaintyResult(
        method=spec.method,
        k=spec.k,
        volumetric=volumetric,
        axes={a: Extreme(float(v), at(i)) for a, (v, i) in zip(AXIS_NAMES, axes, strict=True)},
        budget=budget,
        montecarlo=mc,
    )


# -- Monte Carlo ------------------------------------------------------------------------


def _thin(grid: np.ndarray, n: int) -> np.ndarray:
    if grid.size <= n:
        return grid
    return grid[np.unique(np.linspace(0, grid.size - 1, n).round().astype(int))]


def _field(syn: Synthesis, tool: ToolCase, datum) -> np.ndarray:
    """The three directions' errors on the synthesis grid, shape (3, P)."""
    sizes = tuple(syn.grids[a].size for a in AXIS_NAMES)
    pairs = fold(syn.products(tool, datum), sizes)
    return np.stack(
        [
            (pairs[d][0][:, :, None] + pairs[d][1][:, None, :] + pairs[d][2][None, :, :]).ravel()
            for d in range(3)
        ]
    )


def _linear_model(machine: Machine, spec: UncertaintySpec, tool: ToolCase, grids):
    """(E0, T, shapes): best-estimate field (3P,), one unit-U field per component (n, 3P)
    and each component's distribution. The field of a draw is E0 + Σ z_c·T_c / k."""
    datum = datum_point(machine)

    def prepared(m: Machine) -> Synthesis:
        syn = Synthesis.prepare(m)
        syn.grids.update(grids)
        return syn

    e0 = _field(prepared(machine), tool, datum).ravel()
    names = list(spec.components)
    t = (
        np.stack(
            [
                _field(prepared(uncertainty_machine(machine, spec, {n})), tool, datum).ravel()
                for n in names
            ]
        )
        if names
        else np.zeros((0, e0.size))
    )
    shapes = [spec.components[n].distribution for n in names]
    return e0, t, shapes


def _draw(rng: np.random.Generator, shapes, count: int) -> np.ndarray:
    """Standardised draws (mean 0, standard deviation 1), shape (count, n)."""
    z = np.empty((count, len(shapes)))
    for j, shape in enumerate(shapes):
        if shape == "rectangular":
            z[:, j] = rng.uniform(-math.sqrt(3.0), math.sqrt(3.0), size=count)
        else:
            z[:, j] = rng.standard_normal(count)
    return z


def montecarlo_volumetric(
    machine: Machine,
    spec: UncertaintySpec,
    tool: ToolCase | None = None,
    progress: Progress | None = None,
    max_points: int = MONTECARLO_MAX_POINTS,
) -> MonteCarloSummary:
    """The distribution of the volumetric accuracy over ``spec.samples`` draws.

    Vectorised: the field is linear in the draws, so a batch of draws is one matrix
    product ``Z @ T`` on the (thinned) grid.
    """
    tool = tool or tool_cases(machine)[0]
    base = Synthesis.prepare(machine).grids
    per_axis = max(2, int(round(max_points ** (1 / 3))))
    grids = {a: _thin(base[a], per_axis) for a in AXIS_NAMES}
    e0, t, shapes = _linear_model(machine, spec, tool, grids)
    rng = np.random.default_rng(spec.seed)
    points = e0.size // 3
    batch = max(1, _BATCH_ELEMENTS // e0.size)
    values = np.empty(spec.samples)
    done = 0
    while done < spec.samples:
        n = min(batch, spec.samples - done)
        z = _draw(rng, shapes, n) / spec.k
        e = (e0 + z @ t).reshape(n, 3, points)
        values[done : done + n] = np.sqrt(np.einsum("sdp,sdp->sp", e, e).max(axis=1))
        done += n
        if progress:
            progress(done, spec.samples)
    lo, hi = np.percentile(values, [2.5, 97.5])
    return MonteCarloSummary(
        mean_um=float(values.mean()),
        std_um=float(values.std(ddof=1)),
        interval_um=(float(lo), float(hi)),
        samples=int(spec.samples),
        seed=int(spec.seed),
        values_um=tuple(float(v) for v in values),
    )


def montecarlo_errors(
    machine: Machine, spec: UncertaintySpec, point, tool: ToolCase | None = None
) -> np.ndarray:
    """Monte Carlo draws of the three errors at one point, shape (samples, 3) in µm."""
    tool = tool or tool_cases(machine)[0]
    grids = {a: np.array([float(point[a])]) for a in AXIS_NAMES}
    e0, t, shapes = _linear_model(machine, spec, tool, grids)
    z = _draw(np.random.default_rng(spec.seed), shapes, spec.samples) / spec.k
    return e0[None, :] + z @ t
