"""Volumetric uncertainty: the components' uncertainties carried through the synthesis model
(Longstaff 2002, 3.14.7 and 4.01.3-4.01.4; JCGM 100:2008, 5.1.2, 6.2 and G.4), and a Monte
Carlo check (JCGM 101:2008, :mod:`esp.core.uncertainty.montecarlo`).

Each component's U is first turned into its standard uncertainty u = U / k with its own
coverage factor (a U given directly with the k stated for it, an instrument model's k), and
the model is run with u in place of the error; the volumetric result is expanded once, with
the analysis' k (GUM 6.2), or with k = t_p(ν_eff) for a stated coverage probability p.
U curves are used exactly as given: no straightness slope is removed from them and no run
direction is chosen (:meth:`esp.core.synthesis.Synthesis.prepare` with ``measured=False``).

Let t_i,d(p) be the value at p of the terms of component i acting in direction d, with u_i
in place of its error (u_i times the term's sign and lever, tool offsets included), less
its value at the datum when one is set: the sensitivity c_i,d(p) of the reported error to
the component, times u_i (GUM 5.1.3).

* ``summation`` -- a bound: per direction B_d(p) = Σ_i |t_i,d(p)| = Σ_i |c_i,d(p)|·u_i(p),
  the largest error any choice of sign of the components (each error +u_i or -u_i along
  its whole axis) can give in that direction (the triangle inequality; attained by the
  signs of the c_i,d); then the vector sum of the three bounds, times k, maximised over the
  volume. It does not depend on the signs of the model or of its inputs (the model,
  ``angle_convention``). |s·f(a)·g(c)| = |s|·|f(a)|·|g(c)| keeps each term separable; with a
  datum a term less its datum value still depends on two coordinates only, so the bound is
  scanned exactly like the errors (:mod:`esp.core.grid`).
* ``pure-addition`` -- the thesis' "pure addition" (4.01.3, table 4.3): the printed model
  (``model = "as-printed"`` only) run with every u_i in place of its error, the terms of a
  direction added with their signs, the vector sum, times k. It is one sign choice among
  many, not a bound; it is kept to reproduce table 4.3.
* ``statistical`` -- per direction the root-sum-square of the terms' contributions (each
  term is u times its lever, so its square is separable like the term itself), then the
  vector sum (thesis 3.14.7, 4.01.4), times k. The datum is not applied: a datum-relative
  RSS would need the covariance of a term with itself at two points, which the thesis does
  not use. The effective degrees of freedom follow by Welch-Satterthwaite from the
  components' variance contributions at the point of the largest value (GUM G.4.1).
* ``montecarlo`` -- the statistical figures, and the distribution of the volumetric
  accuracy over draws of every component's error (:mod:`esp.core.uncertainty.montecarlo`).

The volumetric figures are the maximum over the volume (and over the tool cases); the
budget is evaluated at the point (and tool case) of the volumetric maximum.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import replace

import numpy as np

from esp.core.errors import ConfigError
from esp.core.evaluation import MachineEvaluation
from esp.core.grid import PAIRS, fold, scan
from esp.core.machine import AXIS_NAMES, Machine, iso_name
from esp.core.models.bind import BoundTerm
from esp.core.results import BudgetLine, Extreme, ToolCase, UncertaintyResult
from esp.core.synthesis import Synthesis, datum_point, tool_cases
from esp.core.uncertainty.budget import Contribution
from esp.core.uncertainty.gum import coverage_factor, welch_satterthwaite
from esp.core.uncertainty.montecarlo import (
    MONTECARLO_MAX_BYTES,
    MONTECARLO_MAX_WORK,
    montecarlo_errors,
    montecarlo_memory_bytes,
    montecarlo_volumetric,
)
from esp.core.uncertainty.spec import (
    PURE_ADDITION_MODEL,
    ComponentU,
    UncertaintySpec,
    uncertainty_machine,
)

__all__ = [
    "SUMS",
    "bound_pairs",
    "check_uncertainty",
    "montecarlo_errors",
    "montecarlo_volumetric",
    "uncertainty_machine",
    "volumetric_uncertainty",
]

Progress = Callable[[int, int], None]


def check_uncertainty(machine: Machine, spec: UncertaintySpec | None = None) -> None:
    """Refuse, before any work, what the uncertainty evaluation cannot do.

    * ``method = "pure-addition"`` with a model other than the printed one;
    * a U curve that does not cover the simulated range of its axis (unless
      ``analysis.extrapolate`` holds its end values), naming the component's key;
    * a Monte Carlo evaluation whose work (samples × grid points) exceeds
      :data:`~esp.core.uncertainty.montecarlo.MONTECARLO_MAX_WORK` or whose memory exceeds
      :data:`~esp.core.uncertainty.montecarlo.MONTECARLO_MAX_BYTES`, naming
      ``uncertainty.samples``.

    Raises
    ------
    ConfigError
        with the key to change and the machine's configuration file.
    """
    spec = spec or machine.uncertainty
    if spec is None:
        return
    if spec.method == "pure-addition" and machine.analysis.model != "as-printed":
        raise ConfigError(
            "uncertainty.method",
            PURE_ADDITION_MODEL.format(model=machine.analysis.model),
            machine.source,
        )
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
    if spec.devices:
        first = next(iter(spec.devices))
        raise ConfigError(
            f"uncertainty.{first.split('.')[0]}",
            "the Monte Carlo evaluation does not draw the errors of a servo head or a rotary "
            "table; use method = 'statistical' (the same propagation, GUM 5.1.2) or leave "
            f"out [uncertainty.{first.split('.')[0]}]",
            machine.source,
        )
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


def device_tools(
    machine: Machine, spec: UncertaintySpec, tools: Sequence[ToolCase]
) -> list[ToolCase]:
    """``tools`` with each head or table error's first-order term taken at its standard
    uncertainty u = U / k instead of its value (0 for an error without U): the terms of
    the propagation, linear in each error (GUM 5.1.3)."""
    if not tools or tools[0].setting_deg is None:
        return list(tools)
    stand_in = machine
    for owner in ("head", "table"):
        setup = getattr(machine, owner)
        if setup is None:
            continue
        device = getattr(setup, owner)
        # every error of the chain at its u, a constant: an error given as a curve over
        # the angle (a table's error motion) has its curve dropped, or its values would
        # stand in for its u
        errors = {
            name: (spec.devices[f"{owner}.{name}"].u if f"{owner}.{name}" in spec.devices else 0.0)
            for name in device.chain.errors
        }
        at_u = replace(device, errors=errors)
        if hasattr(device, "curves"):
            at_u = replace(at_u, curves={}, curve_axes={})
        stand_in = replace(stand_in, **{owner: replace(setup, **{owner: at_u})})
    u_cases = tool_cases(stand_in)
    if len(u_cases) != len(tools) or any(
        a.setting_deg != b.setting_deg for a, b in zip(u_cases, tools, strict=True)
    ):  # pragma: no cover - the same machine gives the same settings
        raise ValueError("the settings of the uncertainty's tool cases differ")
    return [replace(t, setting_terms=u.setting_terms) for t, u in zip(tools, u_cases, strict=True)]


def _offset_key(tool: ToolCase) -> tuple[float, ...]:
    return tuple(round(tool.offset_mm[a], 6) + 0.0 for a in AXIS_NAMES)


#: the methods that add the terms of a direction (no variance, no degrees of freedom)
SUMS = ("summation", "pure-addition")


def _components_at(
    syn: Synthesis,
    point: Mapping[str, float],
    tool: ToolCase,
    datum: Mapping[str, float] | None,
    reference: ToolCase | None = None,
) -> dict[str, dict[str, list[float]]]:
    """Per component and direction, the values (µm) of its terms at ``point``, less their
    values at ``datum`` when one is given; a head's or table's errors (at u) as components
    of their own (``head.ThetaAs``), less the ``reference`` setting's value at the datum."""
    per: dict[str, dict[str, list[float]]] = {}
    for bt in syn.terms():
        v = syn.term_value_um(bt, point, tool)
        if datum is not None:
            v -= syn.term_value_um(bt, datum, tool)
        per.setdefault(str(bt.component), {a: [] for a in AXIS_NAMES})[bt.direction].append(v)
    refs = {t.component: t for t in (reference.setting_terms if reference else ())}
    for t in tool.setting_terms:
        for a in AXIS_NAMES:
            v = t.value_um(a, point)
            if datum is not None and t.component in refs:
                v -= refs[t.component].value_um(a, datum)
            per.setdefault(t.component, {d: [] for d in AXIS_NAMES})[a].append(v)
    return per


def _term_on_grid(
    syn: Synthesis, bt: BoundTerm, tool: ToolCase
) -> tuple[tuple[int, ...], np.ndarray]:
    """One term's value (µm) over the grid of the axes it depends on: ``(axes, values)``,
    ``axes`` the sorted axis indices (none, one or two) and ``values`` of shape
    ``(n_axis for axis in axes)`` (a 0-d array for a constant term)."""
    index = {a: i for i, a in enumerate(AXIS_NAMES)}
    g = syn.grids
    factors: list[tuple[int, np.ndarray]] = []
    scale = float(bt.sign)
    if bt.axis:
        f = np.asarray(syn.component_at(bt, g[bt.axis]), dtype=float)
        factors.append((index[bt.axis], np.broadcast_to(f, g[bt.axis].shape)))
    else:
        scale *= float(syn.component_at(bt, 0.0))
    if bt.is_angle:
        scale *= 1e-3  # µm/m times mm
        p = bt.tool_sign * tool.offset_mm[bt.tool_axis] if bt.tool_axis else 0.0
        if bt.lever_axis:
            lever = bt.lever_sign * (g[bt.lever_axis] - bt.lever_offset_mm) + p
            factors.append((index[bt.lever_axis], lever))
        else:
            scale *= p
    axes = tuple(sorted({a for a, _ in factors}))
    out = np.full(tuple(g[AXIS_NAMES[a]].size for a in axes), scale)
    for a, values in factors:
        shape = [1] * len(axes)
        shape[axes.index(a)] = values.size
        out = out * values.reshape(shape)
    return axes, out


def _add_to_pairs(pairs: list[np.ndarray], axes: tuple[int, ...], values: np.ndarray) -> None:
    """Add a function of at most two axes to one direction's pair arrays of
    :func:`esp.core.grid.fold` (``[P_xy, P_xz, P_yz]``)."""
    if not axes:
        pairs[0] += float(values)
    elif len(axes) == 1:
        a = axes[0]
        if a == 2:
            pairs[1] += values[None, :]
        elif a == 1:
            pairs[0] += values[None, :]
        else:
            pairs[0] += values[:, None]
    else:
        pairs[PAIRS.index((axes[0], axes[1]))] += values


def bound_pairs(
    syn: Synthesis,
    tool: ToolCase,
    datum: Mapping[str, float] | None,
    reference: ToolCase | None = None,
) -> list[list[np.ndarray]]:
    """The pair arrays (:func:`esp.core.grid.fold`) of the summation bound: per direction d,
    B_d = Σ_i |t_i,d|, t_i,d the terms of component i acting in d (less their values at
    ``datum``), so that :func:`esp.core.grid.scan` finds its maxima exactly.

    A component's terms in one direction are added before the absolute value is taken
    (one component, one sign); their sum, less its datum value, depends on at most two
    coordinates (the component's axis and a lever's), which the pair arrays hold exactly.
    A component whose terms in one direction would span all three coordinates (no model
    of esp has one) is bounded term by term, Σ |t|, still a bound. The datum values are
    those of the tool case ``reference`` (default ``tool``): with a head or a table, the
    first setting, to which the analysis refers every setting. The errors of a head or
    table setting (:attr:`Synthesis.setting_errors`) are each one component:
    |c − c_datum| + Σ |a_j|·|x_j| ≥ |c + Σ a_j·x_j − c_datum|.
    """
    index = {a: i for i, a in enumerate(AXIS_NAMES)}
    sizes = tuple(syn.grids[a].size for a in AXIS_NAMES)
    out = fold([], sizes)
    groups: dict[tuple[str, str], list] = {}
    for bt in syn.terms():
        groups.setdefault((str(bt.component), bt.direction), []).append(bt)
    for (_, direction), terms in groups.items():
        pairs = out[index[direction]]
        ref = 0.0
        if datum is not None:
            ref = math.fsum(syn.term_value_um(bt, datum, reference or tool) for bt in terms)
        parts = [_term_on_grid(syn, bt, tool) for bt in terms]
        axes = tuple(sorted({a for ax, _ in parts for a in ax}))
        if len(axes) > 2:  # pragma: no cover - no model has such a component
            for ax, values in parts:
                _add_to_pairs(pairs, ax, np.abs(values))
            _add_to_pairs(pairs, (), np.asarray(abs(ref)))
            continue
        total = np.zeros(tuple(sizes[a] for a in axes))
        for ax, values in parts:
            shape = [sizes[a] if a in ax else 1 for a in axes]
            total = total + values.reshape(shape)
        _add_to_pairs(pairs, axes, np.abs(total - ref))
    refs = {t.component: t for t in syn.setting_terms_of(reference or tool)}
    for t in syn.setting_terms_of(tool):
        for a in AXIS_NAMES:
            pairs = out[index[a]]
            ref = 0.0
            if datum is not None and t.component in refs:
                ref = refs[t.component].value_um(a, datum)
            _add_to_pairs(pairs, (), np.asarray(abs(t.constant_um.get(a, 0.0) - ref)))
            for j, aj in t.per_mm.get(a, {}).items():
                if aj:
                    _add_to_pairs(pairs, (index[j],), abs(aj) * np.abs(syn.grids[j]))
    return out


def _budget(
    spec: UncertaintySpec,
    per: Mapping[str, Mapping[str, list[float]]],
    point: Mapping[str, float],
    method: str,
) -> tuple[BudgetLine, ...]:
    """Each component at ``point``: its U, k, u and degrees of freedom there, its standard
    contribution and its share of the volumetric uncertainty.

    Statistical: its terms' squares over the sum of all squares; contribution √(Σ t²).
    Summation: with b_c,d = |Σ t_c,d| its part of the bound of direction d and B_d = Σ_c
    b_c,d, its share Σ_d b_c,d·B_d / Σ_d B_d² (each ≥ 0; they add to 100), contribution
    √(Σ_d b_c,d²). Pure addition: the same with the signed sums t_c,d = Σ t and the
    direction totals E_d (a share may be negative).
    """
    if method in SUMS:
        sums = {c: {a: math.fsum(d[a]) for a in AXIS_NAMES} for c, d in per.items()}
        if method == "summation":
            sums = {c: {a: abs(v) for a, v in s.items()} for c, s in sums.items()}
        e = {a: math.fsum(s[a] for s in sums.values()) for a in AXIS_NAMES}
        total = math.fsum(x * x for x in e.values())
        share = {c: math.fsum(s[a] * e[a] for a in AXIS_NAMES) for c, s in sums.items()}
        squares = {c: math.fsum(v * v for v in s.values()) for c, s in sums.items()}
    else:
        squares = {c: math.fsum(v * v for d in dirs.values() for v in d) for c, dirs in per.items()}
        total = math.fsum(squares.values())
        share = squares
    lines = []
    for name, du in spec.devices.items():
        lines.append(
            BudgetLine(
                component=name,
                iso=name.split(".", 1)[1],
                model="direct",
                U=du.U,
                unit=du.unit,
                share_pct=(100.0 * share.get(name, 0.0) / total) if total > 0 else 0.0,
                k=du.k,
                u=du.u,
                U_max=du.U,
                distribution="normal",
                dof=math.inf,
                contribution_um=math.sqrt(squares.get(name, 0.0)),
                contributors=(Contribution(_GIVEN["direct"], du.u, du.unit),),
            )
        )
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
                contributors=_contributors(cu, U),
            )
        )
    return tuple(sorted(lines, key=lambda b: (-b.share_pct, b.component)))


#: the one contributor of a U not made by an instrument model, by its model
_GIVEN = {"direct": "given directly (U / k)", "default": "[uncertainty] default (U / k)"}


def _contributors(cu: ComponentU, U: float) -> tuple[Contribution, ...]:
    """What makes the standard uncertainty of one component: its instrument model's budget,
    or one line for a U given directly or by default (``U`` where the budget is taken)."""
    if cu.budget is not None and cu.budget.contributions:
        return tuple(cu.budget.contributions)
    name = _GIVEN.get(cu.model, f"{cu.model} (U / k)")
    return (Contribution(name, U / cu.coverage_k, cu.unit, cu.dof),)


def volumetric_uncertainty(
    machine: Machine,
    spec: UncertaintySpec,
    progress: Progress | None = None,
    montecarlo_tool: ToolCase | None = None,
    prepared: MachineEvaluation | None = None,
) -> UncertaintyResult:
    """The volumetric uncertainty of ``machine`` by the method of ``spec``.

    ``montecarlo_tool`` is the tool case on which the Monte Carlo distribution of the
    volumetric accuracy is drawn (the analysis passes its worst case; default: the first
    tool case). ``prepared`` is the analysis' preparation of the machine: its tool cases are
    the ones scanned and its evaluation the one Monte Carlo draws from. For ``montecarlo``
    the volumetric U, its point and the budget are the
    statistical ones, and the Monte Carlo summary is added. The prior of eq. 3.22-3.24 is
    applied by :func:`esp.core.analysis.analyse`.

    Raises
    ------
    ConfigError
        what :func:`check_uncertainty` refuses.
    """
    check_uncertainty(machine, spec)
    # a U is not a measurement (measured=False); the errors of a head or table setting are
    # taken at their u by device_tools, so the Synthesis counts them
    syn = replace(
        Synthesis.prepare(uncertainty_machine(machine, spec, standard=True), measured=False),
        setting_errors=True,
    )
    statistical = spec.method not in SUMS
    datum = None if statistical else datum_point(machine)
    g = syn.grids
    best = None
    seen: set[tuple[float, ...]] = set()
    tools = device_tools(
        machine, spec, list(prepared.tools if prepared is not None else tool_cases(machine))
    )
    # with a head or a table every setting is referred to the first one's datum
    reference = tools[0] if tools and tools[0].setting_deg is not None else None
    for tool in tools:
        key = _offset_key(tool)
        if spec.devices and tool.setting_deg is not None:
            key += tuple(sorted(tool.setting_deg.values()))
        if key in seen:
            continue  # the same offset gives the same field: the first case keeps a tie
        seen.add(key)
        fields = _fields(syn, tool, datum, spec.method, reference)
        if statistical:
            stats = scan(fields, squared=True)
            axes = [(v, i) for v, i in stats.maximum]
        elif spec.method == "summation":
            stats = scan(fields)
            axes = list(stats.maximum)  # a bound is never negative
        else:
            stats = scan(fields)
            axes = [
                max((abs(lo[0]), lo[1]), (abs(hi[0]), hi[1]), key=lambda t: t[0])
                for lo, hi in zip(stats.minimum, stats.maximum, strict=True)
            ]
        if best is None or stats.volumetric[0] > best[0][0]:
            best = (stats.volumetric, axes, tool)
    if best is None:  # pragma: no cover - a machine has at least one tool case
        raise ValueError("the machine has no tool case")
    (u_vol, vol_index), axes, tool = best
    uniform = _uniform(syn, tool, datum, spec.method, reference)

    def at(index: Sequence[int]) -> dict[str, float]:
        return {a: float(g[a][i]) for a, i in zip(AXIS_NAMES, index, strict=True)}

    point = at(vol_index)
    per = _components_at(syn, point, tool, datum, reference)
    budget = _budget(spec, per, point, spec.method)
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
        mc = montecarlo_volumetric(
            machine, spec, montecarlo_tool, progress=progress, prepared=prepared
        )
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
        uniform=uniform,
    )


def _fields(
    syn: Synthesis,
    tool: ToolCase,
    datum: Mapping[str, float] | None,
    method: str,
    reference: ToolCase | None,
) -> list[list[np.ndarray]]:
    """The pair arrays of one tool case's uncertainty field by ``method``: the squares
    (statistical), the bound (summation) or the signed sums (pure addition), the head's
    or table's terms at u included (the Synthesis takes them: ``setting_errors``)."""
    sizes = tuple(syn.grids[a].size for a in AXIS_NAMES)
    if method not in SUMS:
        return fold(syn.squared_products(tool), sizes)
    if method == "summation":
        return bound_pairs(syn, tool, datum, reference)
    return fold(syn.products(tool, datum, reference=reference), sizes)


def _uniform(
    syn: Synthesis,
    tool: ToolCase,
    datum: Mapping[str, float] | None,
    method: str,
    reference: ToolCase | None = None,
) -> bool:
    """Whether every direction's uncertainty of ``tool`` is the same at every point of the
    grid (to 1 part in 10^9), so that the volumetric U has no point where it is largest:
    constant U of components without lever arms. Its direction fields (the squares for
    the statistical method) are scanned for their minima and maxima, exactly."""
    stats = scan(_fields(syn, tool, datum, method, reference))
    return all(
        hi[0] - lo[0] <= 1e-9 * max(abs(hi[0]), abs(lo[0]))
        for lo, hi in zip(stats.minimum, stats.maximum, strict=True)
    )
