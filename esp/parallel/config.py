"""Read the description of a serial-parallel machine (``machine.toml``) for ``esp parallel``.

Every key is documented in ``docs/parallel.md``. The reader is strict: an unknown key is
refused with a "did you mean", a value that is not a finite number where a number is
expected is refused, and every problem raises :class:`~esp.core.errors.ConfigError` naming the
dotted key, what was expected and what was found. The top-level table that names the
machine is ``[parallel_machine]`` (not ``[machine]``), so that the file is never mistaken
for the Cartesian machines of ``esp analyse`` and ``esp batch``.
"""

from __future__ import annotations

import math
import os
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal, NoReturn, overload

import numpy as np

from esp.core.errors import ConfigError
from esp.core.text import NAME_MAX_CHARS, TEXT_MAX_CHARS, closest, too_long
from esp.core.values import ValueRefused, check, quantity_of_key, shown
from esp.io.tomlfile import read_toml_file
from esp.parallel.geometry import LEGS, Geometry, Leg, symmetric_geometry
from esp.parallel.sources import SOURCE_NAMES, vector_from_mapping
from esp.parallel.sweep import LEG_SOURCES, ErrorSweepSpec, WorkspaceSpec
from esp.parallel.transmission import MAX_CONDITION, MODELS
from esp.parallel.uncertainty import DISTRIBUTIONS, METHODS, MONTECARLO_MODELS, UncertaintySpec

__all__ = ["ParallelMachine", "PoseSpec", "load_parallel", "parallel_from_dict"]

_TOP = ("parallel_machine", "geometry", "analysis", "pose", "errors", "uncertainty", "sweep")
_MACHINE_KEYS = ("name", "serial", "location", "notes")
_SYMMETRIC_KEYS = ("R_mm", "r_mm", "h_mm", "strut_mm")
_GEOMETRY_KEYS = (*_SYMMETRIC_KEYS, "table_origin_mm", "slider_travel_mm", "leg1", "leg2", "leg3")
_LEG_GEOMETRY_KEYS = ("joint_xy_mm", "axis", "ball_mm", "strut_mm")
_ANALYSIS_KEYS = ("model", "max_condition")
_POSE_KEYS = ("z_mm", "alpha_deg", "beta_deg", "table_mm")
_ERROR_TABLES = ("leg1", "leg2", "leg3", "table")
#: per leg: key -> (source suffixes, unit)
_LEG_ERROR_KEYS: dict[str, tuple[tuple[str, ...], str]] = {
    "strut_um": (("strut",), "um"),
    "joint_um": (("joint.X", "joint.Y", "joint.Z"), "um"),
    "slider_um": (("slider.X", "slider.Y", "slider.Z"), "um"),
    "ball_um": (("ball.x", "ball.y", "ball.z"), "um"),
    "axis_urad": (("axis.tilt", "axis.yaw"), "urad"),
}
_TABLE_ERROR_KEYS: dict[str, tuple[tuple[str, ...], str]] = {
    "position_um": (("X", "Y", "Z"), "um"),
    "rotation_urad": (("A", "B", "C"), "urad"),
}
_UNCERTAINTY_KEYS = (
    "k",
    "method",
    "samples",
    "seed",
    "distribution",
    "montecarlo_model",
    *_ERROR_TABLES,
)
_SWEEP_KEYS = ("error", "workspace")
_ERROR_SWEEP_KEYS = ("source", "range", "steps", "cases")
_WORKSPACE_KEYS = ("z_mm", "alpha_deg", "beta_deg", "outside")
_OUTSIDE = ("refuse", "skip")
#: the largest plausible error value (µm or µrad): anything larger is a unit mistake
MAX_ERROR = 1e5


@dataclass(frozen=True)
class PoseSpec:
    """A commanded pose: z_T (mm), α, β (degrees) and the table's X, Y (mm)."""

    z_mm: float
    alpha_deg: float
    beta_deg: float
    table_mm: tuple[float, float] = (0.0, 0.0)


@dataclass(frozen=True)
class ParallelMachine:
    """A serial-parallel machine as read from its file.

    ``values`` (42,) are the error values of ``[errors]`` in µm and µrad (order of
    :data:`esp.parallel.sources.SOURCE_NAMES`).
    """

    name: str
    geometry: Geometry
    values: np.ndarray
    model: str = "exact"
    max_condition: float = MAX_CONDITION
    pose: PoseSpec | None = None
    uncertainty: UncertaintySpec | None = None
    error_sweep: ErrorSweepSpec = field(default_factory=ErrorSweepSpec)
    workspace: WorkspaceSpec | None = None
    info: Mapping[str, str] = field(default_factory=dict)
    source: str | None = None

    @property
    def inputs(self) -> tuple[str, ...]:
        return (self.source,) if self.source else ()


def load_parallel(path: str | os.PathLike[str]) -> ParallelMachine:
    """Read a serial-parallel machine file.

    Raises
    ------
    ConfigError
        The file is missing or unreadable (key ``"<file>"``), not valid TOML (``"<toml>"``,
        with line and column), or a key is unknown, missing or holds a value that does
        not fit (the dotted key).
    """
    p = Path(path)
    data = read_toml_file(p)
    return parallel_from_dict(data, source=str(p))


def parallel_from_dict(data: Mapping[str, Any], source: str | None = None) -> ParallelMachine:
    """Build a :class:`ParallelMachine` from the parsed content of its file (what
    :func:`tomllib.loads` returns)."""
    return _Reader(source).machine(data)


class _Reader:
    def __init__(self, source: str | None):
        self.source = source

    # -- primitives -----------------------------------------------------------------------

    def fail(self, key: str, message: str) -> NoReturn:
        raise ConfigError(key, message, self.source)

    def table(self, value: Any, key: str) -> Mapping[str, Any]:
        if not isinstance(value, Mapping):
            self.fail(key, f"expected a table, found {value!r}")
        return value

    def keys(self, table: Mapping[str, Any], allowed: Iterable[str], prefix: str) -> None:
        allowed = tuple(allowed)
        for key in table:
            if key not in allowed:
                hint = closest(key, allowed)
                where = f"{prefix}.{key}" if prefix else key
                if hint:
                    self.fail(where, f"unknown key; did you mean {hint!r}?")
                self.fail(where, f"unknown key; expected one of {', '.join(allowed)}")

    def number(self, value: Any, key: str) -> float:
        """A number within the range its key's unit names (``strut_mm``: a length of at
        most 100 m, ``strut_um``: an error of at most 10 mm, ``alpha_deg``: at most one
        turn; :func:`esp.core.values.quantity_of_key`), refused with the value as given."""
        quantity = quantity_of_key(key)
        try:
            return check(value, quantity)
        except ValueRefused as exc:
            hint = " (a unit mistake?)" if quantity in ("displacement", "angle") else ""
            self.fail(key, exc.message + hint)

    def whole(self, value: Any, key: str, low: int) -> int:
        if isinstance(value, bool) or not isinstance(value, int) or value < low:
            self.fail(key, f"expected a whole number ≥ {low}, found {value!r}")
        return int(value)

    @overload
    def numbers(self, value: Any, key: str, count: Literal[2]) -> tuple[float, float]: ...
    @overload
    def numbers(self, value: Any, key: str, count: Literal[3]) -> tuple[float, float, float]: ...
    @overload
    def numbers(self, value: Any, key: str, count: int) -> tuple[float, ...]: ...
    def numbers(self, value: Any, key: str, count: int) -> tuple[float, ...]:
        if not isinstance(value, list) or len(value) != count:
            self.fail(key, f"expected a list of {count} numbers, found {value!r}")
        return tuple(self.number(v, f"{key}[{i}]") for i, v in enumerate(value))

    def choice(self, value: Any, key: str, options: Iterable[str]) -> str:
        options = tuple(options)
        if not isinstance(value, str) or value not in options:
            hint = closest(value, options) if isinstance(value, str) else None
            more = f"; did you mean {hint!r}?" if hint else ""
            self.fail(key, f"expected one of {', '.join(options)}, found {value!r}{more}")
        return value

    def positive(self, value: Any, key: str) -> float:
        f = self.number(value, key)
        if f <= 0:
            self.fail(key, f"expected a value > 0, found {shown(value)}")
        return f

    # -- sections -----------------------------------------------------------------------------

    def machine(self, data: Mapping[str, Any]) -> ParallelMachine:
        if "parallel_machine" not in data:
            if "machine" in data:
                self.fail(
                    "parallel_machine",
                    "missing; this looks like a Cartesian machine for 'esp analyse' "
                    "(it has [machine])",
                )
            self.fail("parallel_machine", "missing: the table that names the machine")
        self.keys(data, _TOP, "")
        head = self.table(data["parallel_machine"], "parallel_machine")
        self.keys(head, _MACHINE_KEYS, "parallel_machine")
        if "name" not in head:
            self.fail("parallel_machine.name", "missing: the machine's name")
        info = {}
        for key in _MACHINE_KEYS:
            if key in head and not isinstance(head[key], str):
                self.fail(f"parallel_machine.{key}", f"expected text, found {head[key]!r}")
            if key in head:
                limit = TEXT_MAX_CHARS if key == "notes" else NAME_MAX_CHARS
                message = too_long(head[key], limit)
                if message is not None:
                    self.fail(f"parallel_machine.{key}", message)
            if key in head and key != "name":
                info[key] = head[key]
        if "geometry" not in data:
            self.fail("geometry", "missing: R_mm, r_mm, h_mm and strut_mm (or leg1-leg3)")
        try:
            geometry = self.geometry(self.table(data["geometry"], "geometry"))
        except ConfigError as exc:
            if exc.path is None:
                raise ConfigError(exc.key, exc.message, self.source) from None
            raise
        model, max_condition = "exact", MAX_CONDITION
        if "analysis" in data:
            analysis = self.table(data["analysis"], "analysis")
            self.keys(analysis, _ANALYSIS_KEYS, "analysis")
            if "model" in analysis:
                model = self.choice(analysis["model"], "analysis.model", MODELS)
            if "max_condition" in analysis:
                max_condition = self.number(analysis["max_condition"], "analysis.max_condition")
                if max_condition < 1:
                    self.fail(
                        "analysis.max_condition",
                        f"expected a value ≥ 1, found {shown(max_condition)}",
                    )
        pose = self.pose(self.table(data["pose"], "pose")) if "pose" in data else None
        values = np.zeros(len(SOURCE_NAMES))
        if "errors" in data:
            values = self.errors(self.table(data["errors"], "errors"), "errors")[0]
        uncertainty = None
        if "uncertainty" in data:
            uncertainty = self.uncertainty(self.table(data["uncertainty"], "uncertainty"))
        error_sweep, workspace = ErrorSweepSpec(), None
        if "sweep" in data:
            sweep = self.table(data["sweep"], "sweep")
            self.keys(sweep, _SWEEP_KEYS, "sweep")
            if "error" in sweep:
                error_sweep = self.error_sweep(self.table(sweep["error"], "sweep.error"))
            if "workspace" in sweep:
                workspace = self.workspace(self.table(sweep["workspace"], "sweep.workspace"))
        return ParallelMachine(
            head["name"],
            geometry,
            values,
            model,
            max_condition,
            pose,
            uncertainty,
            error_sweep,
            workspace,
            info,
            self.source,
        )

    def geometry(self, g: Mapping[str, Any]) -> Geometry:
        self.keys(g, _GEOMETRY_KEYS, "geometry")
        legs = [k for k in ("leg1", "leg2", "leg3") if k in g]
        symmetric = [k for k in _SYMMETRIC_KEYS if k in g]
        origin = None
        if "table_origin_mm" in g:
            origin = self.numbers(g["table_origin_mm"], "geometry.table_origin_mm", 3)
        travel = None
        if "slider_travel_mm" in g:
            travel = self.numbers(g["slider_travel_mm"], "geometry.slider_travel_mm", 2)
        if legs and symmetric:
            self.fail(
                f"geometry.{symmetric[0]}",
                "give either the symmetric layout (R_mm, r_mm, h_mm, strut_mm) or the "
                "legs one by one (leg1, leg2, leg3), not both",
            )
        if legs:
            missing = [k for k in ("leg1", "leg2", "leg3") if k not in g]
            if missing:
                self.fail(
                    f"geometry.{missing[0]}", "missing: an explicit layout needs all three legs"
                )
            built = []
            for i in LEGS:
                key = f"geometry.leg{i}"
                t = self.table(g[f"leg{i}"], key)
                self.keys(t, _LEG_GEOMETRY_KEYS, key)
                for need in _LEG_GEOMETRY_KEYS:
                    if need not in t:
                        self.fail(f"{key}.{need}", "missing")
                axis = self.numbers(t["axis"], f"{key}.axis", 2)
                norm = math.hypot(*axis)
                if norm == 0:
                    self.fail(
                        f"{key}.axis", "expected a horizontal direction [u_X, u_Y], found [0, 0]"
                    )
                built.append(
                    Leg(
                        self.numbers(t["joint_xy_mm"], f"{key}.joint_xy_mm", 2),
                        (axis[0] / norm, axis[1] / norm),
                        self.numbers(t["ball_mm"], f"{key}.ball_mm", 3),
                        self.number(t["strut_mm"], f"{key}.strut_mm"),
                    )
                )
            if origin is None:
                centre = np.mean([leg.joint_xy_mm for leg in built], axis=0)
                origin = (float(centre[0]), float(centre[1]), 0.0)
            return Geometry((built[0], built[1], built[2]), origin, travel, "explicit")
        missing = [k for k in _SYMMETRIC_KEYS if k not in g]
        if missing:
            self.fail(f"geometry.{missing[0]}", "missing (or give leg1, leg2, leg3 instead)")
        strut = g["strut_mm"]
        if isinstance(strut, list):
            struts: float | tuple[float, ...] = self.numbers(strut, "geometry.strut_mm", 3)
        else:
            struts = self.number(strut, "geometry.strut_mm")
        return symmetric_geometry(
            self.number(g["R_mm"], "geometry.R_mm"),
            self.number(g["r_mm"], "geometry.r_mm"),
            self.number(g["h_mm"], "geometry.h_mm"),
            struts,
            table_origin_mm=origin,
            slider_travel_mm=travel,
        )

    def pose(self, t: Mapping[str, Any]) -> PoseSpec:
        self.keys(t, _POSE_KEYS, "pose")
        for need in ("z_mm", "alpha_deg", "beta_deg"):
            if need not in t:
                self.fail(f"pose.{need}", "missing")
        table = self.numbers(t["table_mm"], "pose.table_mm", 2) if "table_mm" in t else (0.0, 0.0)
        return PoseSpec(
            self.number(t["z_mm"], "pose.z_mm"),
            self.number(t["alpha_deg"], "pose.alpha_deg"),
            self.number(t["beta_deg"], "pose.beta_deg"),
            table,
        )

    def errors(
        self, t: Mapping[str, Any], prefix: str, extra: tuple[str, ...] = ()
    ) -> tuple[np.ndarray, dict[str, str]]:
        """The values of an ``[errors]``-shaped table (also ``[uncertainty]``'s legs and
        table), and the distribution named per sub-table."""
        values: dict[str, float] = {}
        distributions: dict[str, str] = {}
        if prefix == "errors":
            self.keys(t, _ERROR_TABLES, prefix)
        for name in _ERROR_TABLES:
            if name not in t:
                continue
            key = f"{prefix}.{name}"
            sub = self.table(t[name], key)
            spec = _TABLE_ERROR_KEYS if name == "table" else _LEG_ERROR_KEYS
            self.keys(sub, (*spec, *extra), key)
            for item, (suffixes, _unit) in spec.items():
                if item not in sub:
                    continue
                raw = sub[item]
                if len(suffixes) == 1:
                    numbers: tuple[float, ...] = (self.number(raw, f"{key}.{item}"),)
                else:
                    numbers = self.numbers(raw, f"{key}.{item}", len(suffixes))
                for suffix, v in zip(suffixes, numbers, strict=True):
                    if abs(v) > MAX_ERROR:
                        self.fail(
                            f"{key}.{item}",
                            f"expected an error below {MAX_ERROR:g} in µm or µrad, "
                            f"found {shown(v)} "
                            "(a unit mistake?)",
                        )
                    values[f"{name}.{suffix}"] = v
            if "distribution" in sub:
                distributions[name] = self.choice(
                    sub["distribution"], f"{key}.distribution", DISTRIBUTIONS
                )
        return vector_from_mapping(values), distributions

    def uncertainty(self, t: Mapping[str, Any]) -> UncertaintySpec:
        self.keys(t, _UNCERTAINTY_KEYS, "uncertainty")
        k = self.positive(t.get("k", 2.0), "uncertainty.k")
        try:  # the coverage factor's range, as [uncertainty] k of a machine.toml
            check(k, "coverage factor")
        except ValueRefused as exc:
            self.fail("uncertainty.k", exc.message)
        method = self.choice(t.get("method", "statistical"), "uncertainty.method", METHODS)
        samples = self.whole(t.get("samples", 20000), "uncertainty.samples", 2)
        if samples > 10_000_000:
            self.fail("uncertainty.samples", f"expected at most 10000000 draws, found {samples}")
        seed = self.whole(t.get("seed", 1), "uncertainty.seed", 0)
        default = self.choice(
            t.get("distribution", "normal"), "uncertainty.distribution", DISTRIBUTIONS
        )
        mc_model = self.choice(
            t.get("montecarlo_model", "exact"), "uncertainty.montecarlo_model", MONTECARLO_MODELS
        )
        U, per_table = self.errors(t, "uncertainty", extra=("distribution",))
        if np.any(U < 0):
            j = int(np.argmax(U < 0))
            self.fail("uncertainty", f"{SOURCE_NAMES[j]}: expected U ≥ 0, found {shown(U[j])}")
        distributions = tuple(per_table.get(name.split(".")[0], default) for name in SOURCE_NAMES)
        return UncertaintySpec(U, k, method, samples, seed, distributions, mc_model)

    def error_sweep(self, t: Mapping[str, Any]) -> ErrorSweepSpec:
        self.keys(t, _ERROR_SWEEP_KEYS, "sweep.error")
        table_sources = tuple(n for n in SOURCE_NAMES if n.startswith("table."))
        source = t.get("source", "slider.Z")
        if not isinstance(source, str) or source not in (*LEG_SOURCES, *table_sources):
            hint = (
                closest(source, (*LEG_SOURCES, *table_sources)) if isinstance(source, str) else None
            )
            more = f"; did you mean {hint!r}?" if hint else ""
            self.fail(
                "sweep.error.source",
                f"expected a leg's source ({', '.join(LEG_SOURCES)}) or a table source, "
                f"found {source!r}{more}",
            )
        start, stop = self.numbers(t.get("range", [0.0, 100.0]), "sweep.error.range", 2)
        if start == stop:
            self.fail(
                "sweep.error.range", f"expected two different values, found [{start:g}, {stop:g}]"
            )
        if max(abs(start), abs(stop)) > MAX_ERROR:
            self.fail("sweep.error.range", f"expected values below {MAX_ERROR:g} µm or µrad")
        steps = self.whole(t.get("steps", 11), "sweep.error.steps", 2)
        if steps > 10_000:
            self.fail("sweep.error.steps", f"expected at most 10000 steps, found {steps}")
        if source in table_sources:
            if "cases" in t:
                self.fail("sweep.error.cases", "a table source has no legs to choose")
            return ErrorSweepSpec(source, start, stop, steps, ("table",))
        cases_raw = t.get("cases", ["all", "1"])
        if not isinstance(cases_raw, list) or not cases_raw:
            self.fail(
                "sweep.error.cases", f'expected a list such as ["all", "1"], found {cases_raw!r}'
            )
        cases = []
        for i, c in enumerate(cases_raw):
            c = str(c) if isinstance(c, int) and not isinstance(c, bool) else c
            cases.append(self.choice(c, f"sweep.error.cases[{i}]", ("all", "1", "2", "3")))
        if len(set(cases)) != len(cases):
            self.fail("sweep.error.cases", f"expected each case once, found {cases_raw!r}")
        return ErrorSweepSpec(source, start, stop, steps, tuple(cases))

    def workspace(self, t: Mapping[str, Any]) -> WorkspaceSpec:
        self.keys(t, _WORKSPACE_KEYS, "sweep.workspace")
        axes = []
        for name in ("z_mm", "alpha_deg", "beta_deg"):
            key = f"sweep.workspace.{name}"
            if name not in t:
                self.fail(key, "missing: [start, stop, count]")
            raw = t[name]
            if not isinstance(raw, list) or len(raw) != 3:
                self.fail(key, f"expected [start, stop, count], found {raw!r}")
            start = self.number(raw[0], f"{key}[0]")
            stop = self.number(raw[1], f"{key}[1]")
            count = self.whole(raw[2], f"{key}[2]", 1)
            if count == 1 and start != stop:
                self.fail(key, "a count of 1 needs start = stop")
            if name != "z_mm" and max(abs(start), abs(stop)) >= 90:
                self.fail(key, f"expected angles within ±90°, found [{start:g}, {stop:g}]")
            axes.append((start, stop, count))
        outside = self.choice(t.get("outside", "refuse"), "sweep.workspace.outside", _OUTSIDE)
        return WorkspaceSpec(axes[0], axes[1], axes[2], outside)
