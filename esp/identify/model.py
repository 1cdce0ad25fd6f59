"""The first-order model of the measurements, linear in the unknown coefficients.

:class:`Engine` evaluates the machine's total displacement error at any positions as the
engine does (:meth:`esp.core.synthesis.Synthesis.totals_at_um`, the same bound terms), split
into the part of the known components and a design matrix for the unknown ones: each bound
term ``sign · component(axis) [· lever]`` of an unknown component contributes
``sign · φ_j(axis) [· lever / 1000]`` per coefficient (esp.core.models.bind). There is no
second model.

Each measurement set is a :class:`Block` that gives its weighted residuals (model minus
reading, divided by the stated standard uncertainty) and their Jacobian with respect to the
coefficients and to its own nuisance parameters (placements, centres, stations):

* points: ``1000 (p - t) + e(p) - 1000 (1 + s) R b`` per pose (b the artefact's point in
  its own frame, R = exp([ω]) R_0, R_0 from the Kabsch fit; Kabsch 1976);
* lengths: a ballbar or MCG reading ``1000 (|q - c| - L) - δL``, q = p + e(p)/1000,
  with the centre (pivot) c and the length L known or fitted (ISO 230-4:2005 5.1;
  Longstaff 2002, eq. 8.8-8.9, with the positions optionally in an instrument frame of
  unknown placement); an ISO 230-6 diagonal reading ``u · e(p(s)) + o``; a step-gauge
  length ``1000 |q_2 - q_1| - L`` between two faces read at p_1 and p_2 (p_2 placed at
  L + δL from p_1 along their line; ISO 10360-2:2009, 6.3);
* stations: a tracking interferometer's relative distance ``1000 (|q - S| - D)`` from a
  station at S with dead path D, both fitted (multilateration; Schwenke et al. 2005).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

from esp.core.errors import DataError, ParseError
from esp.core.kinematics.exact import rodrigues
from esp.core.models.tool import ToolCase, tool_cases
from esp.core.names import AXIS_NAMES
from esp.identify.ballbar import check_length
from esp.identify.config import MeasurementSpec, Problem
from esp.identify.rotary import (
    AngleBasis,
    DeviceErrorName,
    SettingRows,
    axis_of_errors,
    check_travel,
    nominal_transform,
    setting_rows,
    table_design,
    table_known_um,
)
from esp.identify.tables import Table, read_table

__all__ = ["Block", "Engine", "build_blocks", "rotation"]


def rotation(w: np.ndarray) -> np.ndarray:
    """The rotation matrix of the rotation vector ``w`` (Rodrigues' formula)."""
    a, b = rodrigues(np.float64(w[0]), np.float64(w[1]), np.float64(w[2]))
    K = np.array([[0, -w[2], w[1]], [w[2], 0, -w[0]], [-w[1], w[0], 0]], dtype=float)
    return np.eye(3) + float(a) * K + float(b) * (K @ K)


def _cross_matrix(v: np.ndarray) -> np.ndarray:
    """[v]× for each row of v (N, 3) -> (N, 3, 3): [v]× w = v × w."""
    z = np.zeros(len(v))
    return np.stack(
        [
            np.stack([z, -v[:, 2], v[:, 1]], -1),
            np.stack([v[:, 2], z, -v[:, 0]], -1),
            np.stack([-v[:, 1], v[:, 0], z], -1),
        ],
        1,
    )


class Engine:
    """The machine's error at positions: the known part and the design matrix of the
    unknown coefficients, from the bound terms of the engine."""

    def __init__(self, problem: Problem):
        from esp.core.evaluation import evaluate

        machine = problem.machine
        self.problem = problem
        # the machine's one evaluation; the known part is taken without the datum, which
        # the placements, centres and stations absorb. A set measured with its own tool
        # offset (``tool_mm``) needs the terms of the tool's lever: then the engine is
        # that of the machine at the tool tip (at zero offset the same as at the MCP)
        # the tool of the linear axes alone: a table's errors enter through its own
        # unknowns and known terms (table_columns, table_known_um), at each reading's
        # setting; a measurement of the linear axes at one setting sees them as a rigid
        # motion, which its placement absorbs (docs/identify.md)
        self.tool = self.linear_tool(tool_cases(machine)[0])
        self.table = machine.table.table if machine.table is not None else None
        self.head = machine.head.head if machine.head is not None else None
        #: each table error -> the axis it belongs to (its joint's, or its line's)
        self.table_axes = axis_of_errors(self.table) if self.table is not None else {}
        if machine.analysis.point == "MCP" and any(
            "tool_mm" in s.options for s in problem.measurements
        ):
            machine = replace(machine, analysis=replace(machine.analysis, point="TCP"))
        self.synthesis = evaluate(machine).case().synthesis
        self.unknowns = problem.unknowns
        names: list[str] = []
        self.slices: dict[str, slice] = {}
        for u in self.unknowns:
            start = len(names)
            names.extend(u.coefficient_names)
            self.slices[str(u.name)] = slice(start, len(names))
        self.coefficient_names = tuple(names)
        wanted = {str(u.name) for u in self.unknowns if not u.on_device}
        self.terms = [t for t in self.synthesis.model.terms if str(t.component) in wanted]
        used = {str(t.component) for t in self.terms}
        #: the table's unknowns: (name, basis, their columns)
        self.table_unknowns: list[tuple[DeviceErrorName, AngleBasis | None, slice]] = []
        for u in self.unknowns:
            if isinstance(u.name, DeviceErrorName) and u.on_table:
                assert u.basis is None or isinstance(u.basis, AngleBasis)
                self.table_unknowns.append((u.name, u.basis, self.slices[str(u.name)]))
        #: the head's unknowns (constants): (name, their one column)
        self.head_unknowns: list[tuple[DeviceErrorName, slice]] = [
            (u.name, self.slices[str(u.name)])
            for u in self.unknowns
            if isinstance(u.name, DeviceErrorName) and u.on_head
        ]
        for u in self.unknowns:
            if not u.on_device and str(u.name) not in used:
                raise DataError(
                    f"{u.key}: {u.name} does not act in this machine's model "
                    f"({self.synthesis.model.case}): nothing can identify it"
                )

    @property
    def size(self) -> int:
        return len(self.coefficient_names)

    def tools_of(self, spec: MeasurementSpec) -> dict[str, ToolCase]:
        """The tool cases a set was measured with, by label (``""`` for one): its
        ``tool_mm``, else the machine's first tool case."""
        t = spec.options.get("tool_mm")
        if t is None:
            return {"": self.tool}
        given = t if isinstance(t, Mapping) else {"": t}
        out = {}
        for label, xyz in given.items():
            offset = {a: float(v) for a, v in zip(AXIS_NAMES, xyz, strict=True)}
            out[label] = ToolCase(float(np.linalg.norm(xyz)), None, None, offset)
        return out

    def known_um(self, points_mm: np.ndarray, tool: ToolCase | None = None) -> np.ndarray:
        """The errors (N, 3) of the known components, µm (no datum), at the tool tip of
        ``tool`` (default: the machine's first tool case)."""
        return self.synthesis.totals_at_um(points_mm, tool or self.tool)

    def design(self, points_mm: np.ndarray, tool: ToolCase | None = None) -> np.ndarray:
        """∂e/∂c at the points: shape (N, 3, n), µm per unit coefficient, at the tool tip
        of ``tool`` (default: the machine's first tool case)."""
        tool = tool or self.tool
        pts = np.asarray(points_mm, dtype=float).reshape(-1, 3)
        index = {a: i for i, a in enumerate(AXIS_NAMES)}
        out = np.zeros((len(pts), 3, self.size))
        by_name = {str(u.name): u for u in self.unknowns}
        cache: dict[tuple[str, str | None], np.ndarray] = {}
        for bt in self.terms:
            u = by_name[str(bt.component)]
            sl = self.slices[str(u.name)]
            key = (str(u.name), bt.axis)
            if key not in cache:
                if u.basis is None:
                    cache[key] = np.ones((len(pts), 1))
                else:
                    assert bt.axis is not None
                    cache[key] = u.basis.values(pts[:, index[bt.axis]])
            value = cache[key]
            if bt.is_angle:
                lever = np.zeros(len(pts))
                if bt.lever_axis:
                    lever += bt.lever_sign * (pts[:, index[bt.lever_axis]] - bt.lever_offset_mm)
                if bt.tool_axis:
                    lever += bt.tool_sign * tool.offset_mm[bt.tool_axis]
                value = value * (lever / 1000.0)[:, None]
            out[:, index[bt.direction], sl] += bt.sign * value
        return out

    def table_columns(
        self, angles_deg: Mapping[str, np.ndarray], tips_mm: np.ndarray
    ) -> np.ndarray:
        """∂e/∂c of the table's unknowns at N settings and tool tips (N, 3) mm: shape (N,
        3, n), µm per unit coefficient (zero in the columns of the linear axes)."""
        if self.table is None:
            return np.zeros((len(tips_mm), 3, self.size))
        at = {c: angles_deg[c] for c in self.table.coordinates}
        return table_design(self.table, self.table_unknowns, self.size, at, tips_mm)

    def table_known_um(
        self, angles_deg: Mapping[str, np.ndarray], tips_mm: np.ndarray
    ) -> np.ndarray:
        """The error (N, 3) µm of the table's known errors at N settings and tool tips."""
        if self.table is None:
            return np.zeros((len(tips_mm), 3))
        at = {c: angles_deg[c] for c in self.table.coordinates}
        return table_known_um(self.table, at, tips_mm)

    def by_offset(
        self, points_mm: np.ndarray, offsets_mm: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        """The design (N, 3, n) and known errors (N, 3) of the linear axes at MCP positions,
        each with its own tool offset (a head's at the reading's setting), one evaluation
        per distinct offset."""
        keys, inverse = np.unique(np.round(offsets_mm, 9), axis=0, return_inverse=True)
        inverse = inverse.reshape(-1)
        A = np.zeros((len(points_mm), 3, self.size))
        known = np.zeros((len(points_mm), 3))
        for k, offset in enumerate(keys):
            at = inverse == k
            tool = ToolCase(
                float(np.linalg.norm(offset)),
                None,
                None,
                {a: float(v) for a, v in zip(AXIS_NAMES, offset, strict=True)},
            )
            A[at] = self.design(points_mm[at], tool)
            known[at] = self.known_um(points_mm[at], tool)
        return A, known

    def _head_evaluation(self, angles_deg: Mapping[str, np.ndarray]) -> Any:
        from esp.core.devices.head_evaluate import evaluate_head

        assert self.head is not None
        at = {c: np.asarray(angles_deg[c], dtype=float) for c in self.head.coordinates}
        return evaluate_head(self.head, at, exact=False)

    def head_columns(self, angles_deg: Mapping[str, np.ndarray]) -> np.ndarray:
        """∂e/∂c of the head's unknowns at N settings (N, 3, n): the head's first-order
        error at the tool tip per unit of each (esp.core.devices.head_evaluate)."""
        n = len(next(iter(angles_deg.values())))
        out = np.zeros((n, 3, self.size))
        if self.head is None or not self.head_unknowns:
            return out
        sens = self._head_evaluation(angles_deg).sensitivity
        for name, sl in self.head_unknowns:
            out[:, :, sl.start] = sens[name.symbol]
        return out

    def head_known_um(self, angles_deg: Mapping[str, np.ndarray]) -> np.ndarray:
        """The head's known errors (its unknowns are zero in it) at N settings, (N, 3) µm."""
        n = len(next(iter(angles_deg.values())))
        if self.head is None:
            return np.zeros((n, 3))
        return self._head_evaluation(angles_deg).first_um

    def device_columns(
        self, angles_deg: Mapping[str, np.ndarray], tips_mm: np.ndarray
    ) -> np.ndarray:
        """∂e/∂c of the table's and the head's unknowns at N settings (every axis of both)
        and tool tips (N, 3) mm: (N, 3, n)."""
        return self.table_columns(angles_deg, tips_mm) + self.head_columns(angles_deg)

    def device_known_um(
        self, angles_deg: Mapping[str, np.ndarray], tips_mm: np.ndarray
    ) -> np.ndarray:
        """The table's and the head's known errors at N settings and tool tips, (N, 3) µm."""
        return self.table_known_um(angles_deg, tips_mm) + self.head_known_um(angles_deg)

    @staticmethod
    def linear_tool(tool: ToolCase) -> ToolCase:
        """A tool case of a head or table setting as the linear axes see it: its offset,
        without the setting's own errors (those are the device's terms)."""
        return replace(tool, setting_deg=None, setting_terms=())

    def curve(self, name: str, x_mm: np.ndarray) -> np.ndarray:
        """The basis matrix of one unknown at positions x, (N, n) over all coefficients."""
        u = next(u for u in self.unknowns if str(u.name) == name)
        out = np.zeros((np.size(x_mm), self.size))
        sl = self.slices[name]
        out[:, sl] = 1.0 if u.basis is None else u.basis.values(x_mm)
        return out


@dataclass
class Block:
    """One measurement set as residuals: see the module docstring. ``theta0`` the starting
    nuisance parameters, ``names`` theirs, ``lines`` the file and line of each residual."""

    spec: MeasurementSpec
    kind: str
    names: list[str]
    theta0: np.ndarray
    u_um: np.ndarray  # per residual
    where: list[tuple[str, int]]  # file, line per residual
    readings: int
    data: dict = field(default_factory=dict)

    @property
    def size(self) -> int:
        """The residuals of the set: one per reading (three per point), and one per common
        calibration error (its prior, see :func:`_calibration`)."""
        return int(self.u_um.size) + self.calibrations

    @property
    def calibrations(self) -> int:
        """The common calibration errors of the set (0, 1 or 2), the last nuisance
        parameters and the last residuals."""
        return int(self.data.get("calibration_n", 0))

    # the model, implemented per kind
    def evaluate(
        self, c: np.ndarray, theta: np.ndarray, plan: bool
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(r, Jc, Jt): weighted residuals and their Jacobians at (c, theta)."""
        n_cal = self.calibrations
        if n_cal:
            delta = theta[-n_cal:]
            r, Jc, Jt = self._evaluate(c, theta[:-n_cal], plan)
            S = self.data["calibration_S"]  # weighted sensitivities, rows × n_cal
            w = self.data["calibration_w"]  # 1 / u of each common error
            r = np.concatenate([r + S @ delta, delta * w])
            Jc = np.vstack([Jc, np.zeros((n_cal, Jc.shape[1]))])
            Jt = np.block([[Jt, S], [np.zeros((n_cal, Jt.shape[1])), np.diag(w)]])
        else:
            r, Jc, Jt = self._evaluate(c, theta, plan)
        if "shift" in self.data:  # a simulated data set: readings = model at x̂ + noise
            r = r - self.data["shift"]
        return r, Jc, Jt

    def _evaluate(
        self, c: np.ndarray, theta: np.ndarray, plan: bool
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        k = self.data.get("cluster", 0)
        if k:
            # the rotation of the tool cluster (the last k nuisance parameters) acts as k
            # more columns of the design matrix (see _cluster_rotation)
            n = c.size
            r, Jx, Jt = _EVALUATE[self.kind](
                self, np.concatenate([c, theta[-k:]]), theta[:-k], plan
            )
            Jc, Jt = Jx[:, :n], np.hstack([Jt, Jx[:, n:]])
        else:
            r, Jc, Jt = _EVALUATE[self.kind](self, c, theta, plan)
        return r, Jc, Jt


def _check_travel(table: Table, P: np.ndarray, problem: Problem) -> None:
    for j, a in enumerate(AXIS_NAMES):
        lo, hi = problem.machine.axes[a].travel_mm
        bad = np.flatnonzero((P[:, j] < lo - 1e-6) | (P[:, j] > hi + 1e-6))
        if bad.size:
            i = int(bad[0])
            raise table.fail(
                i, f"{a} = {P[i, j]:g} mm lies outside the travel of {a} [{lo:g}, {hi:g}] mm"
            )


def _check_duplicates(
    table: Table,
    groups: Sequence[str],
    P: np.ndarray,
    what: str,
    tools: npt.ArrayLike | None = None,
) -> None:
    """Refuse a position read twice in one group (and with one tool; to 1 nm), naming the
    second line."""
    codes = {g: i for i, g in enumerate(dict.fromkeys(groups))}
    tool = np.zeros(len(P)) if tools is None else np.asarray(tools, dtype=float)
    key = np.column_stack([[codes[g] for g in groups], tool, np.round(P, 6)])
    _, first, inverse = np.unique(key, axis=0, return_index=True, return_inverse=True)
    earlier = first[inverse.reshape(-1)]  # the first row with the same key
    again = np.flatnonzero(earlier != np.arange(len(P)))
    if again.size:
        i = int(again[0])
        raise table.fail(
            i,
            f"duplicate position ({P[i, 0]:g}, {P[i, 1]:g}, {P[i, 2]:g}) mm in {what} "
            f"{groups[i]!r} (also on line {int(table.lines[earlier[i]])})",
        )


def _u_column(table: Table, spec: MeasurementSpec) -> np.ndarray:
    if table.has("u_um"):
        u = np.asarray(table.columns["u_um"], dtype=float)
        bad = np.flatnonzero(~(u > 0))
        if bad.size:
            raise table.fail(int(bad[0]), f"column u_um: expected > 0, found {u[bad[0]]:g}")
        return u
    if spec.u_um is None:
        raise ParseError(
            table.path,
            None,
            f"no column u_um and no {spec.key}.u_um: give the standard uncertainty of the "
            f"readings per reading or per file",
        )
    return np.full(len(table), spec.u_um)


def _tool_rows(
    table: Table, spec: MeasurementSpec, tools: Mapping[str, ToolCase]
) -> tuple[np.ndarray, np.ndarray]:
    """The index of each row's tool in ``tools`` and its offset T (N, 3), mm: one tool for
    the whole set, or the column ``tool`` naming one of ``tools`` per row."""
    labels = list(tools)
    if labels == [""]:
        offset = np.array([tools[""].offset_mm[a] for a in AXIS_NAMES])
        return np.zeros(len(table), dtype=int), np.tile(offset, (len(table), 1))
    if not table.has("tool"):
        raise ParseError(
            table.path,
            None,
            f"no column tool: {spec.key}.tool_mm names {len(labels)} tools "
            f"({', '.join(labels)}); give each reading's in a column tool",
        )
    index = {g: i for i, g in enumerate(labels)}
    rows = np.empty(len(table), dtype=int)
    for i, g in enumerate(table.columns["tool"]):
        if g not in index:
            raise table.fail(
                i, f"column tool: {g!r} is not in {spec.key}.tool_mm ({', '.join(labels)})"
            )
        rows[i] = index[g]
    offsets = np.array([[tools[g].offset_mm[a] for a in AXIS_NAMES] for g in labels])
    return rows, offsets[rows]


def _xyz(table: Table, cols: tuple[str, str, str]) -> np.ndarray:
    return np.column_stack([np.asarray(table.columns[c], dtype=float) for c in cols])


def _kabsch(B: np.ndarray, P: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """R, t minimising |P - (R B + t)| (Kabsch 1976)."""
    cb, cp = B.mean(axis=0), P.mean(axis=0)
    H = (B - cb).T @ (P - cp)
    U, _, Vt = np.linalg.svd(H)
    d = np.sign(np.linalg.det(Vt.T @ U.T)) or 1.0
    R = Vt.T @ np.diag([1.0, 1.0, d]) @ U.T
    return R, cp - R @ cb


def _build_points(
    spec: MeasurementSpec, problem: Problem, plan: bool, tools: Mapping[str, ToolCase]
) -> Block:
    cols = ("X", "Y", "Z") if plan else ("X", "Y", "Z", "x", "y", "z")
    table = read_table(spec.files[0], cols, ("pose",), ("u_um",), ("tool",))
    P = _xyz(table, ("X", "Y", "Z"))
    _check_travel(table, P, problem)
    poses = table.columns["pose"]
    tool_rows, T = _tool_rows(table, spec, tools)
    _check_duplicates(table, poses, P, "pose", tool_rows)
    B = P.copy() if plan else _xyz(table, ("x", "y", "z"))
    u = _u_column(table, spec)
    labels = list(dict.fromkeys(poses))
    names: list[str] = []
    theta: list[float] = []
    R0 = {}
    for g in labels:
        idx = np.array([i for i, p in enumerate(poses) if p == g])
        if idx.size < 3:
            raise table.fail(
                int(idx[0]), f"pose {g!r} has {idx.size} point(s); a placement needs 3 or more"
            )
        R, t = _kabsch(B[idx], P[idx] + T[idx])
        R0[g] = R
        for n in ("rx", "ry", "rz"):
            names.append(f"{spec.name}.{g}.{n}")
            theta.append(0.0)
        for j, n in enumerate(("tx", "ty", "tz")):
            names.append(f"{spec.name}.{g}.{n}")
            theta.append(float(t[j]))
    if spec.options.get("scale"):
        names.append(f"{spec.name}.scale")
        theta.append(0.0)
    where = [(table.path, int(line)) for line in table.lines for _ in range(3)]
    return Block(
        spec,
        "points",
        names,
        np.array(theta),
        np.repeat(u, 3),
        where,
        len(table),
        {
            "P": P,
            "B": B,
            "poses": poses,
            "labels": labels,
            "R0": R0,
            "T": T,
            "tool_rows": tool_rows,
        },
    )


def _eval_points(
    block: Block, c: np.ndarray, theta: np.ndarray, plan: bool
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    d = block.data
    P, B = d["P"], d["B"]
    A, known = d["A"], d["known"]
    e = known + A @ c
    n = len(P)
    scale = block.spec.options.get("scale")
    s = theta[-1] * 1e-6 if scale else 0.0
    r = np.zeros((n, 3))
    Jt = np.zeros((n, 3, theta.size))
    for k, g in enumerate(d["labels"]):
        idx = d["index"][k]
        w = theta[6 * k : 6 * k + 3]
        t = theta[6 * k + 3 : 6 * k + 6]
        R = rotation(w) @ d["R0"][g]
        v = B[idx] @ R.T
        r[idx] = 1000.0 * (P[idx] + d["T"][idx] - t) + e[idx] - 1000.0 * (1 + s) * v
        Jt[idx, :, 6 * k : 6 * k + 3] = 1000.0 * (1 + s) * _cross_matrix(v)
        Jt[idx, :, 6 * k + 3 : 6 * k + 6] = -1000.0 * np.eye(3)
        if scale:
            Jt[idx, :, -1] = -1e-3 * v
    w_ = 1.0 / block.u_um
    return (
        r.reshape(-1) * w_,
        A.reshape(-1, A.shape[2]) * w_[:, None],
        Jt.reshape(-1, theta.size) * w_[:, None],
    )


def _constant_in_group(
    table: Table, groups: Sequence[str], values: np.ndarray, what: str
) -> dict[str, np.ndarray]:
    out: dict[str, np.ndarray] = {}
    first: dict[str, int] = {}
    for i, g in enumerate(groups):
        if g not in out:
            out[g] = values[i]
            first[g] = i
        elif not np.allclose(values[i], out[g], atol=1e-9, rtol=0):
            raise table.fail(
                i, f"{what} of {g!r} differs from its value on line {int(table.lines[first[g]])}"
            )
    return out


def _build_lengths(
    spec: MeasurementSpec, problem: Problem, plan: bool, tools: Mapping[str, ToolCase]
) -> Block:
    form = spec.options["form"]
    if form == "diagonal":
        return _build_diagonals(spec, problem, plan, tools)
    if form == "stepgauge":
        return _build_stepgauge(spec, problem, plan, tools)
    group = "circle" if form == "ballbar" else "sphere"
    cols: tuple[str, ...] = ("X", "Y", "Z", "cx", "cy", "cz", "length_mm")
    if not plan:
        cols += ("deviation_um",)
    table = read_table(spec.files[0], cols, (group,), ("u_um",), ("direction",))
    P = _xyz(table, ("X", "Y", "Z"))
    tool_rows, T = _tool_rows(table, spec, tools)
    placement = bool(spec.options.get("placement"))
    if not placement:
        _check_travel(table, P, problem)
    groups = table.columns[group]
    runs = groups
    if table.has("direction"):  # both directions of one circle: one run each
        runs = tuple(f"{g} {d}" for g, d in zip(groups, table.columns["direction"], strict=True))
    _check_duplicates(table, runs, P, group)
    C = _xyz(table, ("cx", "cy", "cz"))
    L = np.asarray(table.columns["length_mm"], dtype=float)
    centres = _constant_in_group(table, groups, C, "the centre")
    lengths = _constant_in_group(table, groups, L, "length_mm")  # one length per circle
    dev = np.zeros(len(table)) if plan else np.asarray(table.columns["deviation_um"])
    u = _u_column(table, spec)
    centre_known = spec.options.get("centre", spec.options.get("pivot")) == "known"
    length_known = spec.options.get("radius", spec.options.get("length")) == "known"
    labels = list(dict.fromkeys(groups))
    names: list[str] = []
    theta: list[float] = []
    layout = []
    index = []
    what = "centre" if form == "ballbar" else "pivot"
    for g in labels:
        idx = np.array([i for i, x in enumerate(groups) if x == g])
        index.append(idx)
        if idx.size < 3:
            raise table.fail(
                int(idx[0]), f"{group} {g!r} has {idx.size} reading(s); expected 3 or more"
            )
        if form == "ballbar" and not placement:
            # the rule of ``esp ballbar``: every ball position (the position plus the
            # tool offset) at length_mm from the centre
            check_length(table, str(g), idx, P + T, centres[g], float(lengths[g]))
        entry: dict = {"start": len(theta)}
        if not centre_known:
            # the directions the readings see the centre along: the spread of the points
            D = P[idx] - centres[g]
            _, sv, Vt = np.linalg.svd(D, full_matrices=False)
            dirs = Vt[sv > 1e-6 * max(sv[0], 1e-12)]
            entry["dirs"] = dirs
            for j in range(len(dirs)):
                axis = "xyz"[j] if len(dirs) == 3 else f"{j + 1}"
                names.append(f"{spec.name}.{g}.{what}.{axis}")
                theta.append(0.0)
        if not length_known:
            entry["dL"] = len(theta)
            names.append(f"{spec.name}.{g}.length")
            theta.append(0.0)
        layout.append(entry)
    if placement:
        entry_p = len(theta)
        for n in ("rx", "ry", "rz", "tx", "ty", "tz"):
            names.append(f"{spec.name}.placement.{n}")
            theta.append(0.0)
    else:
        entry_p = -1
    return Block(
        spec,
        "lengths",
        names,
        np.array(theta),
        u,
        [(table.path, int(line)) for line in table.lines],
        len(table),
        {
            "P": P,
            "C": np.array([centres[g] for g in groups]),
            "L": L,
            "dev": dev,
            "labels": labels,
            "index": index,
            "layout": layout,
            "placement": entry_p,
            "T": T,
            "tool_rows": tool_rows,
        },
    )


def _eval_lengths(
    block: Block, c: np.ndarray, theta: np.ndarray, plan: bool
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    d = block.data
    if "diagonal" in d:
        return _eval_diagonals(block, c, theta, plan)
    if "stepgauge" in d:
        return _eval_stepgauge(block, c, theta, plan)
    P, A, known = d["P"], d["A"], d["known"]
    e = known + A @ c
    q = P + d["T"] + e / 1000.0
    R = np.eye(3)
    if d["placement"] >= 0:
        k = d["placement"]
        R = rotation(theta[k : k + 3])
        q = q @ R.T + theta[k + 3 : k + 6]
    centre = d["C"].copy()
    dL = np.zeros(len(P))
    for idx, entry in zip(d["index"], d["layout"], strict=True):
        if "dirs" in entry:
            s = entry["start"]
            n = len(entry["dirs"])
            centre[idx] += theta[s : s + n] @ entry["dirs"]
        if "dL" in entry:
            dL[idx] = theta[entry["dL"]]
    diff = q - centre
    length = np.linalg.norm(diff, axis=1)
    nvec = diff / length[:, None]
    pred = 1000.0 * (length - d["L"]) - dL
    r = pred - d["dev"]
    Jc = np.matmul((nvec @ R)[:, None, :], A)[:, 0]
    Jt = np.zeros((len(P), theta.size))
    for idx, entry in zip(d["index"], d["layout"], strict=True):
        if "dirs" in entry:
            s = entry["start"]
            n = len(entry["dirs"])
            Jt[idx, s : s + n] = -1000.0 * nvec[idx] @ entry["dirs"].T
        if "dL" in entry:
            Jt[idx, entry["dL"]] = -1.0
    if d["placement"] >= 0:
        k = d["placement"]
        v = (P + d["T"] + e / 1000.0) @ R.T
        Jt[:, k : k + 3] = 1000.0 * np.cross(v, nvec)
        Jt[:, k + 3 : k + 6] = 1000.0 * nvec
    w = 1.0 / block.u_um
    return r * w, Jc * w[:, None], Jt * w[:, None]


#: the largest angle (rad) between two lengths of one step gauge: they lie along one line
STEPGAUGE_ANGLE = 1e-3


def _build_stepgauge(
    spec: MeasurementSpec, problem: Problem, plan: bool, tools: Mapping[str, ToolCase]
) -> Block:
    """Step-gauge lengths: each row the distance between two faces of one gauge, as the
    machine reads them, against the gauge's calibrated length (ISO 10360-2:2009, 6.3, the
    length measurement error of a CMM; a step gauge as its material standard)."""
    cols: tuple[str, ...] = ("X1", "Y1", "Z1", "X2", "Y2", "Z2", "length_mm")
    if not plan:
        cols += ("deviation_um",)
    table = read_table(spec.files[0], cols, ("gauge",), ("u_um",))
    P1 = _xyz(table, ("X1", "Y1", "Z1"))
    P2 = _xyz(table, ("X2", "Y2", "Z2"))
    L = np.asarray(table.columns["length_mm"], dtype=float)
    dev = np.zeros(len(table)) if plan else np.asarray(table.columns["deviation_um"])
    bad = np.flatnonzero(~(L > 0))
    if bad.size:
        raise table.fail(int(bad[0]), f"length_mm: expected a length > 0, found {L[bad[0]]:g}")
    span = np.linalg.norm(P2 - P1, axis=1)
    bad = np.flatnonzero(span <= 1e-6)
    if bad.size:
        raise table.fail(int(bad[0]), "the two positions of the length are the same point")
    n = (P2 - P1) / span[:, None]
    # the second face where the machine read it: length_mm + deviation_um from the first,
    # along the line of the two positions (nominal positions or those as read, alike)
    P2 = P1 + n * (L + dev / 1000.0)[:, None]
    _check_travel(table, P1, problem)
    _check_travel(table, P2, problem)
    gauges = table.columns["gauge"]
    first: dict[str, int] = {}
    seen: dict[tuple, int] = {}
    for i, (g, a, b) in enumerate(
        zip(gauges, np.round(P1, 6).tolist(), np.round(P2, 6).tolist(), strict=True)
    ):
        key = (g, *a, *b)
        if key in seen:
            raise table.fail(
                i, f"duplicate length in gauge {g!r} (also on line {int(table.lines[seen[key]])})"
            )
        seen[key] = i
        j = first.setdefault(g, i)
        angle = float(np.linalg.norm(np.cross(n[i], n[j])))
        if angle > STEPGAUGE_ANGLE or float(n[i] @ n[j]) < 0:
            raise table.fail(
                i,
                f"gauge {g!r}: this length is not along the line of line "
                f"{int(table.lines[j])} (angle {np.degrees(np.arcsin(min(angle, 1.0))):.3g}°; "
                "a step gauge's lengths run along one line, from one side)",
            )
    u = _u_column(table, spec)
    m = len(table)
    return Block(
        spec,
        "lengths",
        [],
        np.zeros(0),
        u,
        [(table.path, int(line)) for line in table.lines],
        m,
        {"stepgauge": True, "P": np.vstack([P1, P2]), "L": L, "labels": list(first)},
    )


def _eval_stepgauge(
    block: Block, c: np.ndarray, theta: np.ndarray, plan: bool
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    d = block.data
    P, A, known = d["P"], d["A"], d["known"]
    m = len(d["L"])
    q = P + (known + A @ c) / 1000.0
    diff = q[m:] - q[:m]
    length = np.linalg.norm(diff, axis=1)
    nvec = diff / length[:, None]
    r = 1000.0 * (length - d["L"])
    Jc = np.matmul(nvec[:, None, :], A[m:] - A[:m])[:, 0]
    w = 1.0 / block.u_um
    return r * w, Jc * w[:, None], np.zeros((m, 0))


def _build_diagonals(
    spec: MeasurementSpec, problem: Problem, plan: bool, tools: Mapping[str, ToolCase]
) -> Block:
    from esp.diagonals.model import body_diagonals, face_diagonals
    from esp.io.load import load_profile

    machine = problem.machine
    known = {d.name: d for d in body_diagonals(machine) + face_diagonals(machine)}
    P: list[np.ndarray] = []
    dev: list[np.ndarray] = []
    u: list[np.ndarray] = []
    where: list[tuple[str, int]] = []
    labels: list[tuple[str, np.ndarray]] = []
    index: list[np.ndarray] = []
    start = 0
    for name, path in zip(spec.options["diagonals"], spec.files, strict=True):
        if name not in known:
            raise DataError(
                f"{spec.key}.files.{name}: unknown diagonal; expected one of {', '.join(known)}"
            )
        diag = known[name]
        profile = load_profile(Path(path), kind="linear")
        s = profile.targets_mm
        if s.size < 3:
            raise ParseError(path, None, f"a diagonal needs 3 targets or more, found {s.size}")
        if s[-1] > diag.length_mm + 0.05 or s[0] < -0.05:
            raise ParseError(
                path,
                None,
                f"targets run from {s[0]:g} to {s[-1]:g} mm but diagonal {name} of the "
                f"simulation volume is {diag.length_mm:.6g} mm long",
            )
        P.append(diag.points(s))
        dev.append(np.zeros(s.size) if plan else profile.mean(machine.analysis.direction))
        u.append(np.full(s.size, float(spec.u_um or 0.0)))
        where.extend((str(path), 0) for _ in s)
        labels.append((name, diag.direction))
        index.append(np.arange(start, start + s.size))
        start += s.size
    names = [f"{spec.name}.{n}.offset" for n, _ in labels]
    return Block(
        spec,
        "lengths",
        names,
        np.zeros(len(names)),
        np.concatenate(u),
        where,
        start,
        {
            "diagonal": True,
            "P": np.vstack(P),
            "dev": np.concatenate(dev),
            "labels": labels,
            "index": index,
        },
    )


def _eval_diagonals(
    block: Block, c: np.ndarray, theta: np.ndarray, plan: bool
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    d = block.data
    A, known = d["A"], d["known"]
    e = known + A @ c
    n = len(e)
    r = np.zeros(n)
    Jc = np.zeros((n, c.size))
    Jt = np.zeros((n, theta.size))
    for k, ((_, direction), idx) in enumerate(zip(d["labels"], d["index"], strict=True)):
        r[idx] = e[idx] @ direction + theta[k] - d["dev"][idx]
        Jc[idx] = np.tensordot(A[idx], direction, axes=([1], [0]))
        Jt[idx, k] = 1.0
    w = 1.0 / block.u_um
    return r * w, Jc * w[:, None], Jt * w[:, None]


def _build_stations(
    spec: MeasurementSpec, problem: Problem, plan: bool, tools: Mapping[str, ToolCase]
) -> Block:
    cols = ("X", "Y", "Z") if plan else ("X", "Y", "Z", "reading_um")
    table = read_table(spec.files[0], cols, ("station",), ("u_um",), ("tool",))
    P = _xyz(table, ("X", "Y", "Z"))
    _check_travel(table, P, problem)
    stations = table.columns["station"]
    tool_rows, T = _tool_rows(table, spec, tools)
    _check_duplicates(table, stations, P, "station", tool_rows)
    reading = np.zeros(len(table)) if plan else np.asarray(table.columns["reading_um"])
    u = _u_column(table, spec)
    approx = spec.options["stations"]
    labels = list(dict.fromkeys(stations))
    for g in labels:
        if g not in approx:
            i = stations.index(g)
            raise table.fail(i, f"station {g!r} has no approximate position in {spec.key}.stations")
    for g in approx:
        if g not in labels:
            raise DataError(
                f"{spec.key}.stations.{g}: station {g!r} has no readings in {table.path}"
            )
    if len(labels) < 4:
        raise ParseError(
            table.path,
            None,
            f"readings from {len(labels)} station(s) ({', '.join(labels)}); self-calibration "
            f"by multilateration needs 4 or more",
        )
    names: list[str] = []
    theta: list[float] = []
    index = []
    for g in labels:
        idx = np.array([i for i, x in enumerate(stations) if x == g])
        if idx.size < 4:
            raise table.fail(
                int(idx[0]),
                f"station {g!r} is seen from {idx.size} position(s); expected 4 or more",
            )
        index.append(idx)
        S = np.asarray(approx[g], dtype=float)
        D = float(np.median(np.linalg.norm(P[idx] + T[idx] - S, axis=1) - reading[idx] / 1000.0))
        for j, n in enumerate(("x", "y", "z")):
            names.append(f"{spec.name}.{g}.{n}")
            theta.append(float(S[j]))
        names.append(f"{spec.name}.{g}.dead_path")
        theta.append(D)
    return Block(
        spec,
        "stations",
        names,
        np.array(theta),
        u,
        [(table.path, int(line)) for line in table.lines],
        len(table),
        {
            "P": P,
            "dev": reading,
            "labels": labels,
            "index": index,
            "station_of": np.array([labels.index(g) for g in stations]),
            "T": T,
            "tool_rows": tool_rows,
        },
    )


def _eval_stations(
    block: Block, c: np.ndarray, theta: np.ndarray, plan: bool
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    d = block.data
    P, A, known = d["P"], d["A"], d["known"]
    e = known + A @ c
    q = P + d["T"] + e / 1000.0
    n = len(P)
    st = d["station_of"]  # the station of each reading
    S = theta.reshape(-1, 4)  # x, y, z, dead path per station
    diff = q - S[st, :3]
    dist = np.linalg.norm(diff, axis=1)
    nvec = diff / dist[:, None]
    r = 1000.0 * (dist - S[st, 3]) - d["dev"]
    Jc = np.matmul(nvec[:, None, :], A)[:, 0]
    Jt = np.zeros((n, theta.size))
    rows = np.arange(n)
    for j in range(3):
        Jt[rows, 4 * st + j] = -1000.0 * nvec[:, j]
    Jt[rows, 4 * st + 3] = -1000.0
    w = 1.0 / block.u_um
    return r * w, Jc * w[:, None], Jt * w[:, None]


def _build_sphere(
    spec: MeasurementSpec, problem: Problem, plan: bool, tools: Mapping[str, ToolCase]
) -> Block:
    """A probed sphere (esp.identify.rotary): the sphere's centre read at table settings."""
    read = _rotary_rows(spec, problem, tools, (), "sphere")
    data, rows, m, P, R, t = read.data, read.rows, read.tips, read.mcp, read.R, read.t
    u = _u_column(data, spec)
    seen = np.einsum("nij,nj->ni", R, m) + t  # each reading's centre in the workpiece frame
    labels = list(dict.fromkeys(rows.labels))
    index = [np.array([i for i, g in enumerate(rows.labels) if g == k]) for k in labels]
    names: list[str] = []
    theta: list[float] = []
    for g, idx in zip(labels, index, strict=True):
        start = seen[idx].mean(axis=0)
        for j, n in enumerate(("x", "y", "z")):
            names.append(f"{spec.name}.{g}.{n}")
            theta.append(float(start[j]))
    if spec.options.get("probe") == "unknown":
        names += [f"{spec.name}.probe.{n}" for n in ("dx", "dy", "dz")]
        theta += [0.0, 0.0, 0.0]
    where = [(data.path, int(line)) for line in data.lines for _ in range(3)]
    return Block(
        spec,
        "sphere",
        names,
        np.array(theta),
        np.repeat(u, 3),
        where,
        len(data),
        {
            "P": P,
            "m": m,
            "angles": rows.angles,
            "head_offset": read.head_offset,
            "R": R,
            "t": t,
            "labels": labels,
            "index": index,
        },
    )


def _eval_sphere(
    block: Block, c: np.ndarray, theta: np.ndarray, plan: bool
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``1000 (m - R^T (s - t)) + e(m, θ) + d`` per reading (esp.identify.rotary)."""
    d = block.data
    m, R, t, A = d["m"], d["R"], d["t"], d["A"]
    e = d["known"] + A @ c
    r = 1000.0 * m + e
    Jt = np.zeros((len(m), 3, theta.size))
    for k, idx in enumerate(d["index"]):
        s = theta[3 * k : 3 * k + 3]
        Rt = np.transpose(R[idx], (0, 2, 1))
        r[idx] -= 1000.0 * np.einsum("nij,nj->ni", Rt, s[None, :] - t[idx])
        Jt[idx, :, 3 * k : 3 * k + 3] = -1000.0 * Rt
    if block.spec.options.get("probe") == "unknown":
        r += theta[-3:]
        Jt[:, :, -3:] = np.eye(3)
    w = 1.0 / block.u_um
    return (
        r.reshape(-1) * w,
        A.reshape(-1, A.shape[2]) * w[:, None],
        Jt.reshape(-1, theta.size) * w[:, None],
    )


@dataclass(frozen=True)
class RotaryRows:
    """A set read at settings of the rotary axes (esp.identify.rotary): its file, the
    rows, the tool tips p (N, 3) commanded, mm, the MCP positions (p less the tool's or
    the head's offset), the head's nominal offset per reading (None without a head), and
    the nominal table transform (R, t; the identity without a table)."""

    data: Table
    rows: SettingRows
    tips: np.ndarray
    mcp: np.ndarray
    head_offset: np.ndarray | None
    R: np.ndarray
    t: np.ndarray


def _rotary_rows(
    spec: MeasurementSpec,
    problem: Problem,
    tools: Mapping[str, ToolCase],
    numbers: tuple[str, ...],
    group: str,
) -> RotaryRows:
    """Read a set taken at settings of the table's and the head's axes, with the travels
    checked (the rotary axes' for a Legendre basis, the linear axes' for the MCP)."""
    machine = problem.machine
    table = machine.table.table if machine.table is not None else None
    head = machine.head.head if machine.head is not None else None
    coords = (table.coordinates if table else ()) + (head.coordinates if head else ())
    data = read_table(spec.files[0], ("X", "Y", "Z", *coords, *numbers), (group,), ("u_um",))
    rows = setting_rows(data, coords, group)
    bases = [u.basis for u in problem.unknowns if isinstance(u.basis, AngleBasis)]
    check_travel(data, rows.angles, bases)
    p = rows.positions
    head_offset = None
    if head is not None:
        from esp.core.devices.head_evaluate import head_offsets

        head_offset = head_offsets(head, {c: rows.angles[c] for c in head.coordinates}).offset_mm
        P = p - head_offset
    else:
        P = p - np.array([tools[""].offset_mm[a] for a in AXIS_NAMES])
    _check_travel(data, P, problem)
    if table is not None:
        R, t = nominal_transform(table, {c: rows.angles[c] for c in table.coordinates})
    else:
        R, t = np.tile(np.eye(3), (len(p), 1, 1)), np.zeros((len(p), 3))
    return RotaryRows(data, rows, p, P, head_offset, R, t)


def _build_rtest(
    spec: MeasurementSpec, problem: Problem, plan: bool, tools: Mapping[str, ToolCase]
) -> Block:
    """An R-test (ISO 10791-6): K displacement sensors of a nest at the tool tip read a
    precision sphere on the table along a path of table (and head) settings; per reading
    the tool tip p commanded and the K readings ``{label}_um``. On a machine with a head
    the nest turns with the tool: the directions given (machine axes at the head's zero
    setting) turn by the head's nominal rotation."""
    sensors = spec.options["sensors"]
    labels = list(sensors)
    columns = () if plan else tuple(f"{k}_um" for k in labels)
    read = _rotary_rows(spec, problem, tools, columns, "path")
    data, rows, p, P, R, t = read.data, read.rows, read.tips, read.mcp, read.R, read.t
    n0 = np.array([sensors[k] for k in labels])  # (K, 3), machine axes at the zero setting
    N = np.broadcast_to(n0, (len(p), *n0.shape)).copy()  # (N, K, 3) per reading
    head = problem.machine.head
    if head is not None:
        # the nest turns with the tool: its directions at a setting are those at the zero
        # setting turned by the head's nominal rotation from the zero setting
        from esp.core.kinematics import transforms

        chain = head.head.chain
        params = dict(head.head.parameters)
        coords = {
            c: rows.angles[c] * np.pi / 180.0 / chain.symbols[c].scale for c in chain.coordinates
        }
        turn = transforms(chain, coords, params)[:, :3, :3]
        zero = transforms(chain, {c: np.zeros(1) for c in chain.coordinates}, params)[0, :3, :3]
        N = np.einsum("nij,jk,lk->nli", turn, zero.T, n0)
    u = _u_column(data, spec)
    seen = np.einsum("nij,nj->ni", R, p) + t  # the tool tip in the workpiece frame
    paths = list(dict.fromkeys(rows.labels))
    path_of = np.array([paths.index(g) for g in rows.labels])
    d = np.zeros((len(p), len(labels))) if plan else _xyz_of(data, columns)
    names = [f"{spec.name}.sphere.{n}" for n in ("x", "y", "z")]
    theta = list(seen.mean(axis=0))
    for g in paths:
        names += [f"{spec.name}.{g}.{k}" for k in labels]
        theta += [0.0] * len(labels)
    K = len(labels)
    where = [(data.path, int(line)) for line in data.lines for _ in range(K)]
    return Block(
        spec,
        "rtest",
        names,
        np.array(theta),
        np.repeat(u, K),
        where,
        len(data),
        {"P": P, "m": p, "angles": rows.angles, "R": R, "t": t, "N": N, "d": d, "path_of": path_of},
    )


def _xyz_of(data: Table, columns: tuple[str, ...]) -> np.ndarray:
    return np.column_stack([np.asarray(data.columns[c], dtype=float) for c in columns])


def _eval_rtest(
    block: Block, c: np.ndarray, theta: np.ndarray, plan: bool
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Sensor k reads ``n_k · (1000 (T(θ)⁻¹ s - p) - e(p, θ)) + o_k`` (the sphere relative
    to the nest, µm; o_k the sensor's zero on its path)."""
    d = block.data
    p, R, t, A, N = d["m"], d["R"], d["t"], d["A"], d["N"]  # N (n, K, 3)
    K = N.shape[1]
    e = d["known"] + A @ c
    s = theta[:3]
    Rt = np.transpose(R, (0, 2, 1))
    rel = 1000.0 * (np.einsum("nij,nj->ni", Rt, s[None, :] - t) - p) - e
    offsets = theta[3:].reshape(-1, K)
    model = np.einsum("nkd,nd->nk", N, rel) + offsets[d["path_of"]]
    r = model - d["d"]
    n = len(p)
    Jt = np.zeros((n, K, theta.size))
    Jt[:, :, :3] = 1000.0 * np.einsum("nkd,nde->nke", N, Rt)
    for k in range(K):
        Jt[np.arange(n), k, 3 + d["path_of"] * K + k] = 1.0
    Jc = -np.einsum("nkd,ndj->nkj", N, A)
    w = 1.0 / block.u_um
    return (
        r.reshape(-1) * w,
        Jc.reshape(-1, A.shape[2]) * w[:, None],
        Jt.reshape(-1, theta.size) * w[:, None],
    )


def _build_rotary_ballbar(
    spec: MeasurementSpec, problem: Problem, plan: bool, tools: Mapping[str, ToolCase]
) -> Block:
    """A ballbar between a ball on the table (its centre s, workpiece frame) and the tool
    ball at the tool tip p, read as the table turns (``deviation_um``: the bar's length
    less its nominal length)."""
    read = _rotary_rows(spec, problem, tools, () if plan else ("deviation_um",), "run")
    data, rows, p, P, R, t = read.data, read.rows, read.tips, read.mcp, read.R, read.t
    u = _u_column(data, spec)
    pivot = np.asarray(spec.options["pivot_mm"], dtype=float)
    L = float(spec.options["length_mm"])
    centres = np.einsum("nji,nj->ni", R, pivot[None, :] - t)  # T(θ)⁻¹ s, nominal
    dist = np.linalg.norm(p - centres, axis=1)
    limit = max(1e-3 * L, 1e-3)
    bad = np.flatnonzero(np.abs(dist - L) > limit)
    if bad.size:
        i = int(bad[0])
        raise data.fail(
            i,
            f"expected the tool ball at length_mm {L:g} mm from the table ball (within "
            f"{limit:g} mm; pivot_mm {list(pivot)} turned to this setting), found {dist[i]:.6g} mm",
        )
    names: list[str] = []
    theta: list[float] = []
    if spec.options["pivot"] == "unknown":
        names += [f"{spec.name}.pivot.{n}" for n in ("x", "y", "z")]
        theta += list(pivot)
    if spec.options["length"] == "unknown":
        names.append(f"{spec.name}.length")
        theta.append(0.0)
    dev = np.zeros(len(p)) if plan else np.asarray(data.columns["deviation_um"], dtype=float)
    where = [(data.path, int(line)) for line in data.lines]
    return Block(
        spec,
        "rotary-ballbar",
        names,
        np.array(theta),
        u,
        where,
        len(data),
        {
            "P": P,
            "m": p,
            "angles": rows.angles,
            "head_offset": read.head_offset,
            "R": R,
            "t": t,
            "dev": dev,
            "pivot": pivot,
            "L": L,
        },
    )


def _eval_rotary_ballbar(
    block: Block, c: np.ndarray, theta: np.ndarray, plan: bool
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``1000 (|p - T(θ)⁻¹ s| - L) - δL + û · e(p, θ)``, û the unit vector from the table
    ball to the tool ball (ISO 230-4 5.1 with the table's ball carried by the table)."""
    d = block.data
    p, R, t, A = d["m"], d["R"], d["t"], d["A"]
    opts = block.spec.options
    k = 0
    s = d["pivot"]
    if opts["pivot"] == "unknown":
        s = theta[:3]
        k = 3
    dL = theta[k] if opts["length"] == "unknown" else 0.0
    Rt = np.transpose(R, (0, 2, 1))
    centre = np.einsum("nij,nj->ni", Rt, s[None, :] - t)
    v = p - centre
    dist = np.linalg.norm(v, axis=1)
    uhat = v / dist[:, None]
    e = d["known"] + A @ c
    r = 1000.0 * (dist - d["L"]) - dL + np.einsum("ni,ni->n", uhat, e) - d["dev"]
    Jt = np.zeros((len(p), theta.size))
    if opts["pivot"] == "unknown":
        Jt[:, :3] = -1000.0 * np.einsum("ni,nij->nj", uhat, Rt)
    if opts["length"] == "unknown":
        Jt[:, k] = -1.0
    Jc = np.einsum("ni,nij->nj", uhat, A)
    w = 1.0 / block.u_um
    return r * w, Jc * w[:, None], Jt * w[:, None]


_BUILD = {
    "points": _build_points,
    "lengths": _build_lengths,
    "stations": _build_stations,
    "sphere": _build_sphere,
    "rtest": _build_rtest,
    "rotary-ballbar": _build_rotary_ballbar,
}
_EVALUATE = {
    "points": _eval_points,
    "lengths": _eval_lengths,
    "stations": _eval_stations,
    "sphere": _eval_sphere,
    "rtest": _eval_rtest,
    "rotary-ballbar": _eval_rotary_ballbar,
}


def build_blocks(
    problem: Problem, engine: Engine, plan: bool = False, use: str = "fit"
) -> list[Block]:
    """The blocks of the measurement sets with ``use`` (``"fit"`` or ``"check"``), each
    with the engine's known errors and design matrix at its positions."""
    blocks = []
    for spec in problem.measurements:
        if spec.use != use:
            continue
        tools = engine.tools_of(spec)
        block = _BUILD[spec.kind](spec, problem, plan, tools)
        P = block.data["P"]
        # each reading's tool: the probed point is at P + T (T the nominal offset, mm)
        rows = block.data.get("tool_rows", np.zeros(len(P), dtype=int))
        A = np.zeros((len(P), 3, engine.size))
        known = np.zeros((len(P), 3))
        if block.data.get("head_offset") is not None:
            # the linear axes' angles levered by the head's offset at each reading's setting
            A, known = engine.by_offset(P, block.data["head_offset"])
        else:
            for k, tool in enumerate(tools.values()):
                at = rows == k
                if at.all():
                    A, known = engine.design(P, tool), engine.known_um(P, tool)
                elif at.any():
                    A[at], known[at] = engine.design(P[at], tool), engine.known_um(P[at], tool)
        if "angles" in block.data:
            # the table's and the head's errors at each reading's setting, at the tool tip
            at, m = block.data["angles"], block.data["m"]
            A = A + engine.device_columns(at, m)
            known = known + engine.device_known_um(at, m)
        block.data["A"] = A
        block.data["known"] = known
        if block.kind == "points":
            block.data["index"] = [
                np.array([i for i, p in enumerate(block.data["poses"]) if p == g])
                for g in block.data["labels"]
            ]
        if len(tools) > 1 and "T" in block.data:
            _cluster_rotation(block, engine.size, plan)
        if spec.calibration:
            _calibration(block)
        blocks.append(block)
    return blocks


def _calibration_sensitivity(block: Block, which: str) -> np.ndarray:
    """The change of each residual (µm) with the set's common calibration error: per µm
    of the artefact's length (``u_um``) or per µm/m of its scale (``u_ppm``), at the
    nominal geometry.

    * a ballbar or MCG reading ``1000 (|q - c| - L) - δL``: a bar longer by δ reads δ
      shorter, -1 per µm; a scale κ of its length L, -10⁻³ L per µm/m;
    * a step-gauge length L: the same;
    * a plate's ball b at R b in the machine: a scale κ moves it by 10⁻³ κ R b, as the
      fitted scale of ``scale = true`` does;
    * a diagonal's laser reading at distance s from its first target: 10⁻³ κ s (a constant
      part is the fitted offset);
    * a tracker's distance d from its station: 10⁻³ κ d (a constant part is the fitted
      dead path);
    * an R-test's reading d: 10⁻⁶ κ d, the sensors' common gain."""
    d = block.data
    length = which == "u_um"
    if block.kind == "rtest":
        # the sensors' gain (1 + κ): a sensor reads (1 + κ) times the displacement, the
        # reading itself per unit κ (10⁻⁶ per µm/m); the same for every sensor of the set
        return 1e-6 * np.asarray(d["d"], dtype=float).reshape(-1)
    if block.kind == "rotary-ballbar":
        return np.full(len(d["m"]), -1.0) if length else np.full(len(d["m"]), -1e-3 * d["L"])
    if block.kind == "points":
        v = np.zeros((len(d["P"]), 3))
        for g, idx in zip(d["labels"], d["index"], strict=True):
            v[idx] = d["B"][idx] @ d["R0"][g].T
        return -1e-3 * v.reshape(-1)
    if block.kind == "stations":
        S = np.array([block.spec.options["stations"][g] for g in d["labels"]])
        dist = np.linalg.norm(d["P"] + d["T"] - S[d["station_of"]], axis=1)
        return -1e-3 * dist
    if "diagonal" in d:
        s = np.zeros(len(d["P"]))
        for idx in d["index"]:
            s[idx] = np.linalg.norm(d["P"][idx] - d["P"][idx[0]], axis=1)
        return -1e-3 * s
    return np.full(len(d["L"]), -1.0) if length else -1e-3 * np.asarray(d["L"])


def _calibration(block: Block) -> None:
    """Add the set's common calibration errors (``calibration = { u_um, u_ppm }``) as
    nuisance parameters with a prior: each error δ, of standard uncertainty u_c, moves
    every reading by s_i δ (its sensitivity s) and adds the residual δ / u_c. Eliminating
    δ gives the generalised least squares of the readings with the covariance
    diag(u²) + u_c² s sᵀ, the rank-one term of one error common to all readings (JCGM
    100:2008, 5.2.2 and F.1.2.3; the fitted δ is its conditional estimate), so that the
    weights and the covariance of the coefficients both carry it: a ballbar's length
    error is a scale of the plane's axes at the radius of its circles, and the linear
    errors' U grows by it."""
    spec = block.spec
    rows = []
    w = []
    if block.kind == "sphere":
        # the probe's calibrated offset, wrong by d (µm) along each machine axis: every
        # reading's residual moves by d (esp.identify.rotary)
        for j, axis in enumerate(AXIS_NAMES):
            s = np.zeros((block.readings, 3))
            s[:, j] = 1.0
            rows.append(s.reshape(-1))
            w.append(1.0 / spec.calibration["u_um"])
            block.names.append(f"{spec.name}.calibration.probe_{axis.lower()}")
    for which, label in (("u_um", "length"), ("u_ppm", "scale")):
        if which not in spec.calibration or block.kind == "sphere":
            continue
        rows.append(_calibration_sensitivity(block, which))
        w.append(1.0 / spec.calibration[which])
        block.names.append(f"{spec.name}.calibration.{label}")
    S = np.column_stack(rows) / block.u_um[:, None]
    block.data["calibration_S"] = S
    block.data["calibration_w"] = np.array(w)
    block.data["calibration_n"] = len(w)
    block.theta0 = np.concatenate([block.theta0, np.zeros(len(w))])


#: rotations of the tool cluster whose effect, beyond what the set's own nuisance
#: parameters absorb, is below this share of the largest are not fitted (not seen)
CLUSTER_TOLERANCE = 1e-6


def _cluster_rotation(block: Block, n: int, plan: bool) -> None:
    """Add the orientation of the set's tool cluster (its offsets ``tool_mm``, a table of
    several) as nuisance parameters: a small rotation ω (µrad) of every offset T about the
    MCP, which moves the probed point by ω × T (µm: 10⁻³ ω × T with T in mm).

    Why: ``tool_mm`` is stated in the machine's axes, but the styli (reflectors) are fixed
    to the ram, whose orientation relative to the axes is what the angular errors and the
    squareness describe, and esp's gauge (angles zero at the low end of their travel, no
    straightness slope: docs/identify.md, "Gauge") fixes that orientation at the low end.
    A machine whose axes are square in another form (a straightness slope of the other
    axis, a constant angle) differs from esp's form by a constant rotation of the ram
    against the axes, ω × T: invisible with one offset (a translation, which placements,
    centres and stations absorb), seen through the differences ω × (T_i - T_j) of several.
    Without ω the fit would force that rotation into the angles and the squareness.

    Only the directions of ω the readings see beyond the set's own nuisance parameters
    are fitted: the rotation about T₂ - T₁ of two offsets (or of offsets on one line) is
    not seen and not fitted. They are found from the Jacobian at the start (the columns of
    ω projected off those of the nuisance parameters, their SVD)."""
    T = block.data["T"]
    # ∂(10⁻³ ω × T)/∂ω = -10⁻³ [T]×, per reading (N, 3, 3)
    W = -1e-3 * _cross_matrix(T)
    d = block.data
    A = d["A"]
    d["A"] = np.concatenate([A, W], axis=2)
    c0 = np.zeros(n + 3)
    r, Jx, Jt = _EVALUATE[block.kind](block, c0, block.theta0, plan)
    Jw = Jx[:, n:]
    if Jt.size:
        Q, _ = np.linalg.qr(Jt)
        Jw = Jw - Q @ (Q.T @ Jw)
    _, sv, Vt = np.linalg.svd(Jw, full_matrices=False)
    keep = Vt[sv > CLUSTER_TOLERANCE * max(float(np.max(sv, initial=0.0)), 1e-300)]
    if not keep.size:
        d["A"] = A
        return
    k = len(keep)
    if k == 3:  # every direction: the rotations about X, Y and Z themselves
        keep = np.eye(3)
    d["A"] = np.concatenate([A, W @ keep.T], axis=2)
    d["cluster"] = k
    d["cluster_axes"] = keep
    labels = ("rx", "ry", "rz") if k == 3 else tuple(f"r{j + 1}" for j in range(k))
    block.names.extend(f"{block.spec.name}.tool.{label}" for label in labels)
    block.theta0 = np.concatenate([block.theta0, np.zeros(k)])
