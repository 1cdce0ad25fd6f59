"""``identify`` and ``plan``: from a problem to its result (computation only; rendering is
in :mod:`esp.identify.render`, files in :mod:`esp.identify.write`)."""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from types import MappingProxyType

import numpy as np

from esp.core.devices.table import Table
from esp.core.devices.table_curves import Curve as TableCurve
from esp.core.errors import ConfigError, DataError
from esp.core.machine import Component, Machine
from esp.core.models.tool import ToolCase
from esp.core.names import AXIS_NAMES
from esp.core.results import Extreme
from esp.identify.axislines import AxisLine, axis_lines, linuxcnc_parameters
from esp.identify.config import Problem, Unknown
from esp.identify.model import Block, Engine, build_blocks
from esp.identify.rotary import AngleBasis, DeviceErrorName
from esp.identify.solve import (
    Fit,
    Identifiability,
    IdentifyError,
    Parameters,
    evaluate,
    fit,
    layout,
    plan_covariance,
)

__all__ = [
    "Curve",
    "IdentifyResult",
    "MonteCarlo",
    "SetSummary",
    "Volumetric",
    "identified_machine",
    "identify",
    "least_explained",
    "plan",
    "valuations",
]


@dataclass(frozen=True)
class Curve:
    """One identified component: its values at the targets (engine units, µm or µrad; a
    squareness: one value in µm/m at no target) with the expanded uncertainty U = k·u of
    each value, and its coefficients with their standard uncertainties."""

    name: str
    key: str
    unit: str
    targets_mm: tuple[float, ...]
    values: tuple[float, ...]
    U: tuple[float, ...]
    coefficients: tuple[tuple[str, float, float], ...]
    #: the unit of the targets: ``"mm"`` along a linear axis, ``"deg"`` over the angle of
    #: a table's axis (an error motion; ``targets_mm`` then holds degrees)
    target_unit: str = "mm"
    #: ``"table"`` or ``"head"`` for an error of the rotary table (a location error, or an
    #: error motion over the angle of ``angle_axis``) or of the servo head (a constant), in
    #: its chain symbol's unit; None for the linear axes' components
    device: str | None = None
    angle_axis: str | None = None
    #: how well the readings determine it alone, 0 to 1 (:func:`valuations`; the least of
    #: its coefficients'), None when fixed or unseen
    valuation: float | None = None
    #: the table axis a table error belongs to (a location error's line, an error
    #: motion's joint), None for the linear axes' components
    table_axis: str | None = None

    @property
    def on_table(self) -> bool:
        return self.device == "table"

    @property
    def on_head(self) -> bool:
        return self.device == "head"


@dataclass(frozen=True)
class SetSummary:
    """The residuals of one measurement set: how many, their RMS and largest size in units
    of the stated standard uncertainty, and where the largest is."""

    name: str
    kind: str
    use: str
    files: tuple[str, ...]
    readings: int
    residuals: int
    rms_normalised: float
    max_normalised: float
    max_residual_um: float
    worst_at: tuple[str, int]
    #: the set's ``tool_mm`` as given (one offset, or label -> offset; None: the machine's)
    tool_mm: tuple[float, ...] | Mapping[str, tuple[float, ...]] | None = None


@dataclass(frozen=True)
class Volumetric:
    """The volumetric accuracy of the identified machine (the engine's analysis) and its
    expanded uncertainty from the full covariance of the coefficients (GUM law of
    propagation, JCGM 100:2008 eq. 13, linearised at the worst point), with the value the
    same U would have if the coefficients were independent (their correlations dropped)."""

    value_um: float
    at: Mapping[str, float]
    U_um: float
    U_uncorrelated_um: float
    k: float
    #: on a machine with a head or table: each setting (axis -> deg) with its own
    #: volumetric accuracy and U, referred to the datum with the first setting
    settings: tuple[tuple[Mapping[str, float], Volumetric], ...] = ()


@dataclass(frozen=True)
class MonteCarlo:
    """Re-fits of simulated data sets (JCGM 101:2008, 7): readings = the fitted model plus
    normal noise of the stated uncertainties; the spread of each coefficient against its
    stated standard uncertainty."""

    samples: int
    seed: int
    u_ratio_min: float
    u_ratio_max: float
    volumetric_U_um: float


@dataclass(frozen=True)
class IdentifyResult:
    """What ``esp identify`` found (or, for ``--plan``, expects)."""

    machine_name: str
    plan: bool
    k: float
    identifiability: Identifiability
    names: tuple[str, ...]
    values: tuple[float, ...]
    u: tuple[float, ...]
    fixed: tuple[str, ...]
    curves: tuple[Curve, ...]
    sets: tuple[SetSummary, ...]
    chi2: float
    dof: int
    birge: float
    chi2_limit: float
    consistent: bool
    volumetric: Volumetric | None
    residuals: tuple[tuple[str, str, int, float, float], ...]
    null: str
    warnings: tuple[str, ...]
    machine: Machine | None = None
    correlation_max: float = 0.0
    montecarlo: MonteCarlo | None = None
    expected_u_um: float | None = None
    checks: tuple[SetSummary, ...] = field(default_factory=tuple)
    #: a table's axis lines from its identified location errors (esp.identify.axislines)
    axis_lines: tuple[AxisLine, ...] = field(default_factory=tuple)
    #: LinuxCNC's trunnion kinematics for them: (module, parameter -> value in mm)
    linuxcnc: tuple[str, Mapping[str, float]] | None = None
    #: per fitted set: (name, RMS and largest residual (µm) with the table's identified
    #: errors at zero -- the kinematics the controller had -- and with them identified)
    before_after: tuple[tuple[str, float, float, float, float], ...] = field(default_factory=tuple)


def valuations(blocks: list[Block], params: Parameters, x: np.ndarray, C: np.ndarray) -> np.ndarray:
    """How well the readings determine each coefficient alone, 0 to 1: its standard
    uncertainty were every other parameter known, 1 / |J_i| (J the weighted Jacobian),
    over its standard uncertainty in the fit, √C_ii. 1: nothing else it could be
    confused with; near 0: another parameter (or a combination) takes its place. It is
    1/√VIF, the variance inflation factor of regression (Belsley, Kuh & Welsch 1980);
    NaN for a fixed or unseen coefficient."""
    n = params.n_coefficients
    _, J = evaluate(blocks, params, x, plan=True)
    norms = np.linalg.norm(J[:, :n], axis=0)
    u_fit = np.sqrt(np.maximum(np.diag(C)[:n], 0.0))
    out = np.full(n, np.nan)
    ok = params.free[:n] & (norms > 0) & (u_fit > 0)
    out[ok] = np.minimum(1.0 / (norms[ok] * u_fit[ok]), 1.0)
    return out


def _curves(
    engine: Engine, x: np.ndarray, C: np.ndarray, k: float, valuation: np.ndarray | None = None
) -> list[Curve]:
    out = []
    for u in engine.unknowns:
        name = str(u.name)
        sl = engine.slices[name]
        seen = None
        if valuation is not None and np.any(np.isfinite(valuation[sl])):
            seen = float(np.nanmin(valuation[sl]))
        coeffs = tuple(
            (label, float(x[i]), float(np.sqrt(max(C[i, i], 0.0))))
            for label, i in zip(u.labels, range(sl.start, sl.stop), strict=True)
        )
        axis = None
        if isinstance(u.name, DeviceErrorName):
            device = engine.table if u.on_table else engine.head
            assert device is not None
            unit = device.unit(u.name.symbol)
            axis = engine.table_axes.get(u.name.symbol) if u.on_table else None
        else:
            unit = "um" if u.name.kind in ("linear", "straightness") else "um/m"
        if u.basis is None:
            value = float(x[sl.start])
            U = k * float(np.sqrt(max(C[sl.start, sl.start], 0.0)))
            out.append(
                Curve(
                    name,
                    u.key,
                    unit if u.on_device else "um/m",
                    (),
                    (value,),
                    (U,),
                    coeffs,
                    device=u.name.owner if isinstance(u.name, DeviceErrorName) else None,
                    valuation=seen,
                    table_axis=axis,
                )
            )
            continue
        if isinstance(u.basis, AngleBasis):
            t = np.asarray(u.basis.targets_deg)
        else:
            t = np.asarray(u.basis.targets_mm)
        Phi = engine.curve(name, t)
        values = Phi @ x[: engine.size]
        Cc = C[: engine.size, : engine.size]
        var = ((Phi @ Cc) * Phi).sum(axis=1)
        out.append(
            Curve(
                name,
                u.key,
                unit,
                tuple(float(v) for v in t),
                tuple(float(v) for v in values),
                tuple(float(v) for v in k * np.sqrt(np.maximum(var, 0.0))),
                coeffs,
                "deg" if u.on_table else "mm",
                device=u.name.owner if isinstance(u.name, DeviceErrorName) else None,
                angle_axis=u.basis.axis if isinstance(u.basis, AngleBasis) else None,
                valuation=seen,
                table_axis=axis,
            )
        )
    return out


def identified_machine(problem: Problem, curves: list[Curve] | tuple[Curve, ...]) -> Machine:
    """The machine with the identified components as data (in memory)."""
    from esp.core.profile import ErrorProfile

    machine = problem.machine
    comps = dict(machine.components)
    table_curves = []
    head_values: dict[str, float] = {}
    for c in curves:
        u = next(u for u in problem.unknowns if str(u.name) == c.name)
        n = u.name
        if isinstance(n, DeviceErrorName):
            if u.on_head:
                head_values[n.symbol] = c.values[0]
            else:
                table_curves.append((u, c))
            continue
        if n.kind == "squareness":
            comps[n] = Component(
                n, "squareness", None, None, value=c.values[0], source="identified"
            )
            continue
        kind = "angular" if n.kind == "mechanical" else n.kind
        profile = ErrorProfile.from_values(
            kind, c.targets_mm, c.values, axis=n.axis, error_direction=n.about, source="identified"
        )
        run = profile.runs["forward"]
        profile = replace(profile, runs={"forward": run, "backward": run})
        comps[n] = Component(n, n.kind, n.axis, n.about, profile=profile, source="identified")
    if table_curves:
        assert machine.table is not None
        table = identified_table(machine.table.table, table_curves)
        machine = replace(machine, table=replace(machine.table, table=table))
    if machine.head is not None:
        head = machine.head.head
        if head_values:
            head = head.with_values(head_values, origin="identified")
        head = replace(head, to_identify=MappingProxyType({}))
        machine = replace(machine, head=replace(machine.head, head=head))
    return replace(machine, components=comps, uncertainty=None)


def identified_table(table: Table, found: list[tuple[Unknown, Curve]]) -> Table:
    """The table with its identified errors: a location error its value, an error motion
    a curve over the angle at its targets (periodic for a Fourier basis)."""
    errors = dict(table.errors)
    curves = dict(table.curves)
    axes = dict(table.curve_axes)
    origins = dict(table.origins)
    for u, c in found:
        assert isinstance(u.name, DeviceErrorName)
        symbol = u.name.symbol
        origins[symbol] = "identified"
        if not isinstance(u.basis, AngleBasis):
            errors[symbol] = c.values[0]
            continue
        errors.pop(symbol, None)
        curves[symbol] = TableCurve(
            np.asarray(c.targets_mm),
            np.asarray(c.values),
            c.unit,
            periodic=u.basis.periodic,
            source=f"identified {symbol}",
        )
        axes[symbol] = u.basis.axis
    return replace(
        table,
        errors=MappingProxyType(errors),
        curves=MappingProxyType(curves),
        curve_axes=MappingProxyType(axes),
        origins=MappingProxyType(origins),
        to_identify=MappingProxyType({}),
    )


def _summaries(
    blocks: list[Block], r: np.ndarray
) -> tuple[list[SetSummary], list[tuple[str, str, int, float, float]]]:
    out, rows = [], []
    start = 0
    for b in blocks:
        # the readings' residuals; the priors of the common calibration errors follow
        rb = r[start : start + b.u_um.size]
        start += b.size
        raw = rb * b.u_um
        i = int(np.argmax(np.abs(rb))) if rb.size else 0
        out.append(
            SetSummary(
                b.spec.name,
                b.spec.kind if b.kind != "lengths" else f"lengths ({b.spec.options['form']})",
                b.spec.use,
                b.spec.files,
                b.readings,
                int(rb.size),
                float(np.sqrt(np.mean(rb**2))) if rb.size else 0.0,
                float(np.abs(rb).max(initial=0.0)),
                float(raw[i]) if rb.size else 0.0,
                b.where[i] if rb.size else ("", 0),
                b.spec.options.get("tool_mm"),
            )
        )
        for j in range(rb.size):
            rows.append((b.spec.name, b.where[j][0], b.where[j][1], float(raw[j]), float(rb[j])))
    return out, rows


def _volumetric(
    problem: Problem, engine: Engine, machine: Machine, x: np.ndarray, C: np.ndarray, k: float
) -> Volumetric:
    """The volumetric accuracy of the identified machine at its worst point, with U; on a
    machine with a head or table also at every setting (:attr:`Volumetric.settings`)."""
    from esp.core.analysis import analyse
    from esp.core.models.tool import tool_cases
    from esp.core.synthesis import datum_point

    result = analyse(machine)
    case = result.cases[result.worst]
    # every setting is referred to the datum with the first setting (esp.core.evaluation):
    # the rows there are the same for every setting, taken once
    datum = datum_point(problem.machine)
    at_datum = None if datum is None else _error_rows(engine, datum, tool_cases(machine)[0])
    out = _volumetric_at(engine, x, C, k, case.volumetric, case.tool, at_datum)
    settings = tuple(
        (
            dict(entry.tool.setting_deg),
            _volumetric_at(engine, x, C, k, entry.volumetric, entry.tool, at_datum),
        )
        for entry in result.sweep
        if entry.tool.setting_deg is not None
    )
    return replace(out, settings=settings)


def _volumetric_at(
    engine: Engine,
    x: np.ndarray,
    C: np.ndarray,
    k: float,
    worst: Extreme,
    tool: ToolCase,
    at_datum: tuple[np.ndarray, np.ndarray] | None,
) -> Volumetric:
    """U of the volumetric accuracy ``worst`` (the analysis' extreme of one tool case):
    the covariance propagated through the design rows at its point, less ``at_datum``
    (the known error and rows at the datum with the reference setting; GUM law of
    propagation, linearised there)."""
    n = engine.size
    c = x[:n]
    known, G = _error_rows(engine, worst.at, tool)
    e = known + G @ c
    if at_datum is not None:
        known_d, Gd = at_datum
        e = e - known_d - Gd @ c
        G = G - Gd
    g = e / max(float(np.linalg.norm(e)), 1e-300)
    row = g @ G
    Cc = C[:n, :n]
    u = float(np.sqrt(max(row @ Cc @ row, 0.0)))
    u_ind = float(np.sqrt(max(np.sum(row**2 * np.diag(Cc)), 0.0)))
    return Volumetric(float(worst.value_um), dict(worst.at), k * u, k * u_ind, k)


def _error_rows(
    engine: Engine, point: Mapping[str, float], tool: ToolCase
) -> tuple[np.ndarray, np.ndarray]:
    """The known error (3,) µm and the design rows (3, n) at one MCP position with one
    tool case: the linear axes at its tool tip, and the table's at its setting."""
    p = np.array([[point[a] for a in AXIS_NAMES]])
    bare = engine.linear_tool(tool)
    known = engine.known_um(p, bare)[0]
    G = engine.design(p, bare)[0]
    if tool.setting_deg is not None:
        at = {a: np.array([v]) for a, v in tool.setting_deg.items()}
        tip = p + np.array([tool.offset_mm[a] for a in AXIS_NAMES])
        known = known + engine.device_known_um(at, tip)[0]
        G = G + engine.device_columns(at, tip)[0]
    return known, G


def _correlation_max(C: np.ndarray, n: int) -> float:
    d = np.sqrt(np.diag(C)[:n])
    ok = d > 0
    if ok.sum() < 2:
        return 0.0
    R = C[:n, :n][np.ix_(ok, ok)] / np.outer(d[ok], d[ok])
    np.fill_diagonal(R, 0.0)
    return float(np.abs(R).max())


def _table_lines(
    engine: Engine, x: np.ndarray, C: np.ndarray, k: float
) -> tuple[tuple[AxisLine, ...], tuple[str, Mapping[str, float]] | None]:
    """The axis lines of the table from its identified location errors, and of the head
    from its identified errors, with their covariance, and LinuxCNC's parameters for the
    table's (esp.identify.axislines)."""
    lines: tuple[AxisLine, ...] = ()
    linuxcnc = None
    if engine.table is not None:
        index = [
            (name.symbol, sl.start) for name, basis, sl in engine.table_unknowns if basis is None
        ]
        if index:
            location = {symbol: float(x[i]) for symbol, i in index}
            at = [i for _, i in index]
            lines = tuple(axis_lines(engine.table, location, C[np.ix_(at, at)], k))
            linuxcnc = linuxcnc_parameters(lines)
    if engine.head is not None and engine.head_unknowns:
        index = [(name.symbol, sl.start) for name, sl in engine.head_unknowns]
        values = {symbol: float(x[i]) for symbol, i in index}
        at = [i for _, i in index]
        head_lines = axis_lines(engine.head, values, C[np.ix_(at, at)], k)
        lines += tuple(replace(line, owner="head") for line in head_lines)
    return lines, linuxcnc


def _before_after(
    problem: Problem, engine: Engine, blocks: list[Block], params: Parameters, fitted: Fit
) -> tuple[tuple[str, float, float, float, float], ...]:
    """Each set's residuals with the table's and the head's identified errors at zero
    (the nuisance parameters fitted again) and as identified: what the corrections gain."""
    if not engine.table_unknowns and not engine.head_unknowns:
        return ()
    n = engine.size
    x0 = fitted.x.copy()
    for _, _, sl in engine.table_unknowns:
        x0[sl] = 0.0
    for _, sl in engine.head_unknowns:
        x0[sl] = 0.0
    free = params.free.copy()
    free[:n] = False
    before = fit(
        blocks,
        replace(params, x0=x0, free=free),
        "minimum-norm",
        problem.rank_tolerance,
        problem.max_iterations,
    )
    out = []
    start = 0
    for b in blocks:
        m = b.u_um.size
        raw0 = before.residuals[start : start + m] * b.u_um
        raw1 = fitted.residuals[start : start + m] * b.u_um
        start += b.size
        out.append(
            (
                b.spec.name,
                float(np.sqrt(np.mean(raw0**2))),
                float(np.abs(raw0).max()),
                float(np.sqrt(np.mean(raw1**2))),
                float(np.abs(raw1).max()),
            )
        )
    return tuple(out)


def _checks(problem: Problem, engine: Engine, fitted: Fit, params: Parameters) -> list[SetSummary]:
    blocks = build_blocks(problem, engine, use="check")
    if not blocks:
        return []
    p = layout(engine, blocks, (), problem.source)
    x0 = p.x0.copy()
    x0[: engine.size] = fitted.x[: engine.size]
    free = p.free.copy()
    free[: engine.size] = False
    p = replace(p, x0=x0, free=free)
    f = fit(blocks, p, "refuse", problem.rank_tolerance, problem.max_iterations)
    return _summaries(blocks, f.residuals)[0]


def _montecarlo(
    blocks: list[Block],
    params: Parameters,
    fitted: Fit,
    problem: Problem,
    engine: Engine,
    samples: int,
    seed: int,
    vol: Volumetric | None,
) -> MonteCarlo:
    """JCGM 101 re-fits: readings = the fitted model plus normal noise of the stated
    uncertainties (a shift of each block's weighted residuals), fitted from the solution."""
    rng = np.random.default_rng(seed)
    base, _ = evaluate(blocks, params, fitted.x)
    n = engine.size
    draws = []
    try:
        for _ in range(samples):
            noise = rng.standard_normal(base.size)
            start = 0
            for b in blocks:
                b.data["shift"] = base[start : start + b.size] + noise[start : start + b.size]
                start += b.size
            f = fit(
                blocks,
                replace(params, x0=fitted.x.copy()),
                problem.null,
                problem.rank_tolerance,
                problem.max_iterations,
            )
            draws.append(f.x[:n])
    finally:
        for b in blocks:
            b.data.pop("shift", None)
    D = np.array(draws)
    sd = D.std(axis=0, ddof=1)
    stated = np.sqrt(np.diag(fitted.covariance)[:n])
    ok = stated > 0
    ratio = sd[ok] / stated[ok]
    U_vol = float("nan")
    if vol is not None:
        C = np.zeros_like(fitted.covariance)
        C[:n, :n] = np.cov(D.T)
        machine = identified_machine(
            problem, _curves(engine, fitted.x, fitted.covariance, problem.k)
        )
        U_vol = _volumetric(problem, engine, machine, fitted.x, C, problem.k).U_um
    return MonteCarlo(samples, seed, float(ratio.min()), float(ratio.max()), U_vol)


def _refuse_large(problem: Problem, blocks: list[Block], params: Parameters) -> None:
    """Refuse a design matrix whose memory or SVD exceeds the limits of
    :mod:`esp.core.limits`, before it is built, naming the set that adds the most to it."""
    from esp.core.limits import (
        IDENTIFY_MAX_DESIGN_BYTES,
        IDENTIFY_MAX_SVD_FLOPS,
        design_work,
        refuse_if,
    )

    rows = sum(b.size for b in blocks)
    columns = params.x0.size
    memory, flops = design_work(rows, columns)
    largest = max(blocks, key=lambda b: b.size + len(b.names))
    key = f"identify.measurements.{largest.spec.name}"
    what = f"{rows} residuals x {columns} parameters"
    advice = "use fewer readings, stations or poses, or a smaller basis"
    refuse_if(
        math.ceil(memory / 1024**2),
        IDENTIFY_MAX_DESIGN_BYTES // 1024**2,
        key,
        f"{what}: MiB of design",
        advice,
        config=True,
        source=problem.source,
    )
    refuse_if(
        flops,
        IDENTIFY_MAX_SVD_FLOPS,
        key,
        f"{what}: SVD operations",
        advice,
        config=True,
        source=problem.source,
    )


#: a fit is refused as inconsistent when its Birge ratio exceeds this (the residuals three
#: times larger than the stated uncertainties explain) and its χ² its 99.9 % quantile
INCONSISTENT_BIRGE = 3.0
#: the quantile of χ²(ν) that an inconsistent fit's χ² exceeds as well
INCONSISTENT_QUANTILE = 0.999


def _inconsistency(fitted: Fit) -> str:
    """The figures of a fit its stated uncertainties cannot explain ("" when they can): the
    Birge ratio R_B = sqrt(χ²/ν) above :data:`INCONSISTENT_BIRGE` and χ² above the 99.9 %
    quantile of χ²(ν), 2 P⁻¹(ν/2, 0.999) (Abramowitz & Stegun 1964, 26.4.19). Both are
    asked: the quantile alone refuses a Birge ratio of 1.1 at ν of some thousands (a small
    basis bias), the ratio alone a χ² of 10 at ν = 1 (chance, at 0.16 %)."""
    from scipy.special import gammaincinv

    if fitted.dof <= 0:
        return ""
    limit = float(2.0 * gammaincinv(fitted.dof / 2.0, INCONSISTENT_QUANTILE))
    if fitted.birge > INCONSISTENT_BIRGE and fitted.chi2 > limit:
        return (
            f"Birge ratio {fitted.birge:.3g} (above {INCONSISTENT_BIRGE:g}), χ² = "
            f"{fitted.chi2:.4g} for {fitted.dof} degrees of freedom (99.9 % quantile "
            f"{limit:.4g})"
        )
    return ""


def least_explained(
    blocks: list[Block], params: Parameters, fitted: Fit, tolerance: float
) -> tuple[tuple[str, int], float] | None:
    """Where the reading the fit explains least is (file, line) and its standardised
    residual t_i = r_i / sqrt(1 - h_ii), r_i the weighted residual and h_ii the leverage of
    the reading (the diagonal of the hat matrix U Uᵀ of the weighted Jacobian of the free
    parameters, U its left singular vectors of the singular values above ``tolerance``
    times the largest; Cook & Weisberg 1982, 2.2). One wrong reading pulls the fit towards
    itself and spreads its error over the readings it shares parameters with; dividing by
    sqrt(1 - h) undoes that pull, so the largest t names the reading itself, where the
    largest plain residual may name a neighbour. Readings the fit follows exactly
    (h = 1) are passed over; None when there is none to name."""
    r, J = evaluate(blocks, params, fitted.x)
    if r.size == 0:
        return None
    Jf = J[:, np.flatnonzero(params.free)]
    norms = np.linalg.norm(Jf, axis=0)
    Jf = Jf[:, norms > 0] / norms[norms > 0]
    U, s, _ = np.linalg.svd(Jf, full_matrices=False)
    rank = int(np.count_nonzero(s > tolerance * s.max(initial=0.0))) if s.size else 0
    h = np.sum(U[:, :rank] ** 2, axis=1)
    spare = 1.0 - h
    t = np.where(spare > 1e-9, np.abs(r) / np.sqrt(np.maximum(spare, 1e-9)), 0.0)
    start = 0
    for b in blocks:  # a calibration's prior is not a reading of a file: not named
        t[start + b.u_um.size : start + b.size] = 0.0
        start += b.size
    i = int(np.argmax(t))
    start = 0
    for b in blocks:
        if i < start + b.u_um.size:
            return b.where[i - start], float(t[i])
        start += b.size
    return None


def _least_explained_text(
    blocks: list[Block], params: Parameters, fitted: Fit, tolerance: float
) -> str:
    worst = least_explained(blocks, params, fitted, tolerance)
    if worst is None:
        return ""
    (path, line), t = worst
    return f"; the reading least explained is {path}:{line} (standardised residual {t:.3g})"


def identify(
    problem: Problem, montecarlo: int = 0, seed: int = 1, volumetric: bool = True
) -> IdentifyResult:
    """Identify the unknown components from the measurement sets."""
    engine = Engine(problem)
    blocks = build_blocks(problem, engine)
    if not blocks:
        raise ConfigError(
            "identify.measurements",
            "every set is a check (use = 'check'); nothing to fit",
            problem.source,
        )
    params = layout(engine, blocks, problem.fix, problem.source)
    if not params.free[: engine.size].any():
        # nothing left to identify: a "fit" would report the start (zero) as the machine,
        # with no uncertainty (a plan may still study the nuisance parameters alone)
        raise ConfigError(
            "identify.fix",
            f"every one of the {engine.size} identified coefficients is fixed: nothing is "
            "left to identify (remove a component from identify.fix, or measure it instead "
            "of identifying it)",
            problem.source,
        )
    _refuse_large(problem, blocks, params)
    fitted = fit(blocks, params, problem.null, problem.rank_tolerance, problem.max_iterations)
    inconsistent = _inconsistency(fitted)
    if inconsistent and problem.inconsistent == "refuse":
        worst = _least_explained_text(blocks, params, fitted, problem.rank_tolerance)
        raise IdentifyError(
            f"the fit does not explain the readings: {inconsistent}{worst}; the model (its "
            "basis, identify.fix), a reading or the stated uncertainties are wrong "
            '(identify.inconsistent = "accept" reports it anyway; docs/identify.md)'
        )
    k = problem.k
    curves = _curves(
        engine,
        fitted.x,
        fitted.covariance,
        k,
        valuations(blocks, params, fitted.x, fitted.covariance),
    )
    try:
        machine = identified_machine(problem, curves)
    except DataError as exc:
        worst = _least_explained_text(blocks, params, fitted, problem.rank_tolerance)
        raise IdentifyError(
            f"the fit gives implausible curves ({exc}): a combination is barely seen "
            f"(condition number {fitted.identifiability.condition:.3g}){worst}; fix it "
            "(identify.fix) or count it as unseen with a larger identify.rank_tolerance"
        ) from None
    sets, rows = _summaries(blocks, fitted.residuals)
    vol = (
        _volumetric(problem, engine, machine, fitted.x, fitted.covariance, k)
        if volumetric
        else None
    )
    warnings = list(problem.machine.warnings)
    if not fitted.consistent and fitted.dof > 0:
        warnings.append(
            f"the residuals are larger than the stated uncertainties explain: χ² = "
            f"{fitted.chi2:.4g} for {fitted.dof} degrees of freedom (97.5 % quantile "
            f"{fitted.chi2_limit:.4g}), Birge ratio {fitted.birge:.3g}; the uncertainties "
            "below are from the stated ones and are too small, or the basis too poor"
        )
    if not fitted.identifiability.identifiable:
        warnings.append(
            "minimum-norm choice: "
            + "; ".join(fitted.identifiability.sentences())
            + " -- each such combination is set to its smallest size, not measured"
        )
    mc = None
    if montecarlo:
        mc = _montecarlo(blocks, params, fitted, problem, engine, montecarlo, seed, vol)
    checks = _checks(problem, engine, fitted, params)
    lines, linuxcnc = _table_lines(engine, fitted.x, fitted.covariance, k)
    u = np.sqrt(np.maximum(np.diag(fitted.covariance), 0.0))
    return IdentifyResult(
        machine_name=problem.machine.name,
        plan=False,
        k=k,
        identifiability=fitted.identifiability,
        names=params.names,
        values=tuple(float(v) for v in fitted.x),
        u=tuple(float(v) for v in u),
        fixed=tuple(n for n, f in zip(params.names, params.free, strict=True) if not f),
        curves=tuple(curves),
        sets=tuple(sets),
        chi2=fitted.chi2,
        dof=fitted.dof,
        birge=fitted.birge,
        chi2_limit=fitted.chi2_limit,
        consistent=fitted.consistent,
        volumetric=vol,
        residuals=tuple(rows),
        null=problem.null,
        warnings=tuple(warnings),
        machine=machine,
        correlation_max=_correlation_max(fitted.covariance, engine.size),
        montecarlo=mc,
        checks=tuple(checks),
        axis_lines=lines,
        linuxcnc=linuxcnc,
        before_after=_before_after(problem, engine, blocks, params, fitted),
    )


def plan(problem: Problem) -> IdentifyResult:
    """The identifiability and expected uncertainties of a proposed plan: the plan files
    give positions only; nothing is fitted."""
    engine = Engine(problem)
    blocks = build_blocks(problem, engine, plan=True)
    params = layout(engine, blocks, problem.fix, problem.source)
    _refuse_large(problem, blocks, params)
    ident, C = plan_covariance(blocks, params, problem.rank_tolerance)
    k = problem.k
    zero = np.zeros(params.x0.size)
    curves = _curves(engine, zero, C, k, valuations(blocks, params, params.x0, C))
    # the largest expected standard uncertainty of a total displacement error over the
    # grid corners and centre, from the full covariance
    grids = {a: problem.machine.axes[a].grid_mm() for a in AXIS_NAMES}
    pts = _probe_points(grids)
    A = _plan_design(problem, engine, pts)
    Cc = C[: engine.size, : engine.size]
    var = ((A @ Cc) * A).sum(axis=-1)
    u = np.sqrt(np.maximum(np.diag(C), 0.0))
    return IdentifyResult(
        machine_name=problem.machine.name,
        plan=True,
        k=k,
        identifiability=ident,
        names=params.names,
        values=tuple(0.0 for _ in params.names),
        u=tuple(float(v) for v in u),
        fixed=tuple(n for n, f in zip(params.names, params.free, strict=True) if not f),
        curves=tuple(curves),
        sets=tuple(
            SetSummary(
                b.spec.name,
                b.spec.kind,
                b.spec.use,
                b.spec.files,
                b.readings,
                b.u_um.size,
                0.0,
                0.0,
                0.0,
                ("", 0),
                b.spec.options.get("tool_mm"),
            )
            for b in blocks
        ),
        chi2=float("nan"),
        dof=int(sum(b.size for b in blocks) - ident.rank),
        birge=float("nan"),
        chi2_limit=float("nan"),
        consistent=True,
        volumetric=None,
        residuals=(),
        null=problem.null,
        warnings=tuple(ident.sentences()),
        machine=None,
        correlation_max=_correlation_max(C, engine.size),
        expected_u_um=float(np.sqrt(var.max())) * k if var.size else None,
        axis_lines=_table_lines(engine, zero, C, k)[0],
    )


def _plan_design(problem: Problem, engine: Engine, pts: np.ndarray) -> np.ndarray:
    """The design rows (M, 3, n) at the points: of the linear axes; on a machine with a
    rotary table or a servo head, at every setting of their angles too (their unknowns at
    the tool tip)."""
    if engine.table is None and engine.head is None:
        return engine.design(pts)
    from esp.core.models.tool import tool_cases

    cases = tool_cases(problem.machine)
    rows = [engine.design(pts, engine.linear_tool(t)) for t in cases]
    G = np.concatenate(rows)
    # the table's and the head's columns at every setting and point in one evaluation
    coords = list(cases[0].setting_deg or {})
    at = {
        a: np.repeat([t.setting_deg[a] for t in cases], len(pts))  # type: ignore[index]
        for a in coords
    }
    tips = np.concatenate([pts + [t.offset_mm[a] for a in AXIS_NAMES] for t in cases])
    return G + engine.device_columns(at, tips)


def _probe_points(grids: Mapping[str, np.ndarray]) -> np.ndarray:
    """The corners, edge midpoints and centre of the simulation volume (27 points)."""
    axes = []
    for a in AXIS_NAMES:
        g = grids[a]
        axes.append(np.unique([g[0], (g[0] + g[-1]) / 2.0, g[-1]]))
    mesh = np.meshgrid(*axes, indexing="ij")
    return np.column_stack([m.reshape(-1) for m in mesh])
