"""Body and face diagonals of the working volume (ISO 230-6:2002): the displacement error
along each diagonal predicted from the 21 components, and checked against measured
diagonal files.

Conventions (esp's reading of ISO 230-6; docs/diagonals.md says what is and is not
confirmed):

* the volume is the machine's simulation range (``axes.*.simulate``, by default the
  travel); a body diagonal joins opposite corners, a face diagonal opposite corners of a
  face (the plane of two axes with the third axis held, by default at the low end);
* a diagonal is named by the direction each axis moves along it from its start: ``P``
  increasing, ``N`` decreasing, in X, Y, Z order -- ``PPP`` (from the low corner to the
  high corner), ``NPP``, ``PNP``, ``PPN`` -- so that every body diagonal is named once; a
  face diagonal by its plane and the two letters (``XY-PP``, ``XY-NP``);
* targets lie every ``step`` mm along the diagonal from its start, the end always
  included (the last interval may be shorter);
* the value is the **displacement error along the diagonal**, the component of the
  volumetric error vector on the diagonal's unit direction ``u``, relative to the start of
  the diagonal (a laser is zeroed there): ``d(s) = u · (e(p(s)) - e(p(0)))``, with
  ``e = esp.errors_at`` of the machine's model;
* checked: ``Δ(s) = measured(s) - d(s)`` with the measurement zeroed at its start; the
  normalised error ``E_n(s) = |Δ(s)| / U(s)``, ``U(s) = k·sqrt(u_pred(s)² + u_meas(s)²)``
  (k = 2), where ``u_pred`` is the standard uncertainty of the prediction from the
  ``[uncertainty]`` table (each component's U, with the table's k, run through the model
  on its own, projected on ``u``, root-sum-square over components) and ``u_meas`` the
  measurement's (``U_meas = A + B·s``, k = 2). The model explains a diagonal when
  ``E_n ≤ 1`` at every target.

This module imports only numpy and the standard library.

References
----------
ISO 230-6:2002, *Test code for machine tools -- Part 6: Determination of positioning
accuracy on body and face diagonals (Diagonal displacement tests)*.
ISO/IEC 17043:2010, annex B (the normalised error E_n).
Longstaff (2002), 2.03.3 (body and face diagonal tests as quick volumetric checks, after
Morris and ASME B5.54).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

import numpy as np
import numpy.typing as npt

from esp.core.errors import DataError
from esp.core.limits import DIAGONAL_MAX_TARGETS, refuse_if
from esp.core.values import ValueRefused, check

if TYPE_CHECKING:
    from esp.core.evaluation import Evaluation
    from esp.core.machine import Machine
    from esp.core.profile import ErrorProfile

__all__ = [
    "BODY",
    "Diagonal",
    "DiagonalCheck",
    "body_diagonals",
    "check_diagonal",
    "default_step",
    "diagonal_targets",
    "face_diagonals",
    "predict_diagonal",
    "prediction_uncertainty",
]

AXES = ("X", "Y", "Z")
BODY = ("PPP", "NPP", "PNP", "PPN")
FACES = ("XY", "XZ", "YZ")
#: how far a measured target may lie from where the volume puts it (mm)
TARGET_TOLERANCE_MM = 0.05


@dataclass(frozen=True)
class Diagonal:
    """One diagonal: its name and its start and end points (mm, X Y Z)."""

    name: str
    start_mm: tuple[float, float, float]
    end_mm: tuple[float, float, float]

    @property
    def length_mm(self) -> float:
        return float(math.dist(self.start_mm, self.end_mm))

    @property
    def direction(self) -> np.ndarray:
        """The unit vector from start to end."""
        v = np.subtract(self.end_mm, self.start_mm, dtype=float)
        return v / np.linalg.norm(v)

    def points(self, s_mm: npt.ArrayLike) -> np.ndarray:
        """Points at distances ``s_mm`` along the diagonal, shape (N, 3)."""
        s = np.asarray(s_mm, dtype=float).reshape(-1, 1)
        return np.asarray(self.start_mm, dtype=float)[None, :] + s * self.direction[None, :]


def _ranges(machine: Machine) -> dict[str, tuple[float, float]]:
    out = {}
    for a in AXES:
        lo, hi = machine.axes[a].simulate_mm
        out[a] = (float(lo), float(hi))
    return out


def _xyz(values: Sequence[float]) -> tuple[float, float, float]:
    """A point of three coordinates as a tuple (X, Y, Z)."""
    x, y, z = values
    return (x, y, z)


def _corner(
    ranges: Mapping[str, tuple[float, float]], signs: str, at_start: bool
) -> tuple[float, float, float]:
    out = []
    for a, s in zip(AXES, signs, strict=True):
        lo, hi = ranges[a]
        out.append(lo if (s == "P") == at_start else hi)
    return _xyz(out)


def body_diagonals(machine: Machine) -> list[Diagonal]:
    """The four body diagonals of the simulation volume, named as in the module
    docstring. Refuses a volume in which an axis does not move."""
    ranges = _ranges(machine)
    flat = [a for a in AXES if ranges[a][1] <= ranges[a][0]]
    if flat:
        raise DataError(
            f"axis {', '.join(flat)} does not move (axes.{flat[0]}.simulate); a volume with "
            f"body diagonals needs three moving axes"
        )
    return [Diagonal(n, _corner(ranges, n, True), _corner(ranges, n, False)) for n in BODY]


def face_diagonals(machine: Machine, face_at: Mapping[str, float] | None = None) -> list[Diagonal]:
    """The two diagonals of each face plane XY, XZ, YZ; the third axis is held at
    ``face_at[axis]`` (default: the low end of its simulation range)."""
    ranges = _ranges(machine)
    out = []
    for plane in FACES:
        third = next(a for a in AXES if a not in plane)
        lo, hi = ranges[third]
        at = float((face_at or {}).get(third, lo))
        if not lo - 1e-9 <= at <= hi + 1e-9:
            raise DataError(
                f"--face-at {third}={at:g} is outside axes.{third}.simulate [{lo:g}, {hi:g}]"
            )
        for signs in ("PP", "NP"):
            if any(ranges[a][1] <= ranges[a][0] for a in plane):
                continue
            start, end = [], []
            letters = dict(zip(plane, signs, strict=True))
            for a in AXES:
                if a == third:
                    start.append(at)
                    end.append(at)
                    continue
                a_lo, a_hi = ranges[a]
                inc = letters[a] == "P"
                start.append(a_lo if inc else a_hi)
                end.append(a_hi if inc else a_lo)
            out.append(Diagonal(f"{plane}-{signs}", _xyz(start), _xyz(end)))
    return out


def default_step(diagonals: Sequence[Diagonal]) -> float:
    """esp's default target spacing: the longest diagonal in 20 intervals, rounded up to
    a whole millimetre."""
    longest = max(d.length_mm for d in diagonals)
    return float(max(1.0, math.ceil(longest / 20.0)))


def diagonal_targets(diagonal: Diagonal, step_mm: float) -> np.ndarray:
    """Distances along the diagonal: 0, step, 2 step, ... and the end (mm); refused
    beyond :data:`esp.core.limits.DIAGONAL_MAX_TARGETS` targets, before they are made."""
    if not np.isfinite(step_mm) or step_mm <= 0:
        raise DataError(f"--step: expected a positive length in mm, found {step_mm!r}")
    length = diagonal.length_mm
    ratio = length / step_mm
    count: float = ratio
    if ratio < 1e18:  # the targets below: 0 to n steps, and the end when it is not one
        n = math.floor(ratio + 1e-9)
        count = n + 1 + (length - step_mm * n > 1e-6)
    refuse_if(
        count,
        DIAGONAL_MAX_TARGETS,
        "--step",
        f"the {diagonal.name} diagonal of {length:g} mm in steps of {step_mm!r} mm: targets",
        "use a larger --step",
    )
    n = int(np.floor(ratio + 1e-9))
    s = step_mm * np.arange(n + 1, dtype=float)
    if length - s[-1] > 1e-6:
        s = np.append(s, length)
    else:
        s[-1] = length
    return s


def _evaluation(machine: Machine, evaluation: Evaluation | None) -> Evaluation:
    """The evaluation the prediction reads: the one given (the machine's, prepared once
    for every diagonal), else the machine's first tool case."""
    if evaluation is not None:
        return evaluation
    from esp.core.evaluation import evaluate

    return evaluate(machine).case()


def predict_diagonal(
    machine: Machine,
    diagonal: Diagonal,
    s_mm: npt.ArrayLike,
    *,
    evaluation: Evaluation | None = None,
) -> np.ndarray:
    """The displacement error along the diagonal (µm) at distances ``s_mm``, relative to
    its start: ``u · (e(p(s)) - e(p(0)))``, with ``e`` the machine's one evaluation
    (:class:`esp.core.evaluation.Evaluation`; ``evaluation`` when given, to prepare the machine
    once for many diagonals)."""
    s = np.asarray(s_mm, dtype=float)
    case = _evaluation(machine, evaluation)
    e = case.errors_at(diagonal.points(np.concatenate([[0.0], s])))
    d = e @ diagonal.direction
    return d[1:] - d[0]


def prediction_uncertainty(
    machine: Machine, diagonal: Diagonal, s_mm: npt.ArrayLike
) -> np.ndarray | None:
    """The standard uncertainty (µm, k = 1) of the predicted displacement along the
    diagonal at ``s_mm``, from the machine's ``[uncertainty]`` table, or None without one.

    Each component's standard uncertainty u = U / k (with the component's own k) is put in
    place of its error, exactly as given (no straightness slope removed, no run chosen),
    and run through the machine's model alone, without datum; its contribution is the
    projection of that error vector on the diagonal at the point; the contributions of the
    components are independent and add in quadrature (GUM 5.1.2). The datum is not applied,
    as in esp's statistical volumetric uncertainty."""
    from esp.core.numerics import arithmetic
    from esp.core.synthesis import Synthesis, tool_cases

    spec = getattr(machine, "uncertainty", None)
    if spec is None or not spec.components:
        return None
    pts = diagonal.points(s_mm)
    analysis = replace(machine.analysis, datum="none", extrapolate=True)
    total = np.zeros(pts.shape[0])
    with arithmetic():
        for name, cu in spec.components.items():
            m = replace(
                machine,
                components={name: cu.standard_component()},
                uncertainty=None,
                analysis=analysis,
            )
            syn = Synthesis.prepare(m, measured=False)
            contribution = syn.totals_at_um(pts, tool_cases(m)[0]) @ diagonal.direction
            total += contribution**2
    return np.sqrt(total)


@dataclass(frozen=True, eq=False)
class DiagonalCheck:
    """A measured diagonal against the prediction (µm; distances in mm).

    ``U_um`` is the expanded uncertainty (k = 2) of the difference at each target,
    ``En`` the normalised error ``|difference| / U`` (None without any uncertainty);
    ``explained`` is True when ``En ≤ 1`` at every target, None when it cannot be judged.
    """

    diagonal: Diagonal
    s_mm: np.ndarray
    predicted_um: np.ndarray
    measured_um: np.ndarray
    difference_um: np.ndarray
    u_prediction_um: np.ndarray | None
    u_measurement_um: np.ndarray
    U_um: np.ndarray | None
    En: np.ndarray | None
    source: str = ""

    @property
    def max_abs_difference_um(self) -> float:
        return float(np.max(np.abs(self.difference_um)))

    @property
    def worst_index(self) -> int:
        values = self.En if self.En is not None else np.abs(self.difference_um)
        return int(np.argmax(values))

    @property
    def max_En(self) -> float | None:
        return None if self.En is None else float(np.max(self.En))

    @property
    def explained(self) -> bool | None:
        return None if self.En is None else bool(np.all(self.En <= 1.0))


def check_diagonal(
    machine: Machine,
    diagonal: Diagonal,
    profile: ErrorProfile,
    step_mm: float,
    U_measurement_um: float = 0.0,
    U_measurement_per_m_um: float = 0.0,
    direction: str = "mean",
    *,
    evaluation: Evaluation | None = None,
) -> DiagonalCheck:
    """Compare a measured diagonal (an :class:`esp.core.profile.ErrorProfile` of kind linear,
    targets in mm from the start of the diagonal, deviations in µm) with the prediction
    (:func:`predict_diagonal`, from ``evaluation`` when given).

    Raises
    ------
    DataError
        The file's targets do not start at 0, do not end at the diagonal's length, or do
        not lie every ``step_mm``; a negative uncertainty.
    """
    where = profile.source or diagonal.name
    for name, value, quantity in (
        ("U_measurement_um", U_measurement_um, "uncertainty"),
        ("U_measurement_per_m_um", U_measurement_per_m_um, "uncertainty per metre"),
    ):
        try:
            check(value, quantity)
        except ValueRefused as exc:
            raise DataError(f"{name}: {exc.message}") from None
    if profile.kind != "linear":
        raise DataError(
            f"{where}: a diagonal file holds displacements (linear), not {profile.kind}"
        )
    t = np.asarray(profile.targets_mm, dtype=float)
    expected = diagonal_targets(diagonal, step_mm)
    length = diagonal.length_mm
    if abs(t[0]) > TARGET_TOLERANCE_MM or abs((t[-1] - t[0]) - length) > TARGET_TOLERANCE_MM:
        raise DataError(
            f"{where}: the file runs from {t[0]:g} to {t[-1]:g} mm; the {diagonal.name} "
            f"diagonal of this volume runs from 0 to {length:.3f} mm"
        )
    if t.size != expected.size or np.max(np.abs(t - expected)) > TARGET_TOLERANCE_MM:
        raise DataError(
            f"{where}: {t.size} targets do not lie every {step_mm:g} mm along the "
            f"{diagonal.name} diagonal ({expected.size} targets expected); give the "
            f"file's step with --step"
        )
    measured = np.asarray(profile.mean(direction), dtype=float)
    measured = measured - measured[0]
    predicted = predict_diagonal(machine, diagonal, t, evaluation=evaluation)
    difference = measured - predicted
    u_pred = prediction_uncertainty(machine, diagonal, t)
    u_meas = (U_measurement_um + U_measurement_per_m_um * t / 1000.0) / 2.0
    u2 = u_meas**2 + (u_pred**2 if u_pred is not None else 0.0)
    if np.all(u2 > 0):
        U = 2.0 * np.sqrt(u2)
        En = np.abs(difference) / U
    else:
        U, En = None, None
    return DiagonalCheck(diagonal, t, predicted, measured, difference, u_pred, u_meas, U, En, where)
