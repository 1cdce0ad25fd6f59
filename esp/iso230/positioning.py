"""Accuracy and repeatability of positioning of one linear axis, after ISO 230-2:2014.

A linear positioning file holds, for every target position :math:`P_i` (i = 1..m), the
positional deviations :math:`x_{ij}` of n approaches in the positive direction (↑, the
forward runs of a laser file, targets increasing) and n in the negative direction (↓, the
backward runs). From them ISO 230-2 derives per-target statistics (means, standard
deviations, reversal, repeatability) and per-axis figures (reversal B, repeatability R,
systematic deviation E, range of the bidirectional mean M, accuracy A). All of them are
computed here, in µm, from an :class:`~esp.core.profile.ErrorProfile` of kind ``"linear"``.

Symbols (µm; ↑ is ``up``/forward, ↓ is ``down``/backward; the ↓ forms are alike):

- ``mean_up[i]``: x̄i↑ = (1/n) Σj xij↑, mean unidirectional positional deviation at Pi
- ``s_up[i]``: si↑ = sqrt(Σj (xij↑ − x̄i↑)² / (n − 1)), estimator of the unidirectional
  standard uncertainty of positioning at Pi
- ``R_up_i[i]``: Ri↑ = 4 si↑, unidirectional positioning repeatability at Pi
- ``B_i[i]``: Bi = x̄i↑ − x̄i↓, reversal value at Pi (signed)
- ``R_i[i]``: Ri = max(2 si↑ + 2 si↓ + |Bi|, Ri↑, Ri↓), bidirectional repeatability at Pi
- ``mean_bidirectional[i]``: x̄i = (x̄i↑ + x̄i↓) / 2, mean bidirectional positional deviation
- ``B``: max |Bi|, reversal value of the axis; ``B_mean``: (1/m) Σ Bi, mean reversal value
- ``R_up``: max Ri↑; ``R``: max Ri, positioning repeatability of the axis
- ``E_up``: max x̄i↑ − min x̄i↑; ``E``: the largest minus the smallest of all x̄i↑ and x̄i↓,
  systematic positional deviation of the axis
- ``M``: max x̄i − min x̄i, range of the mean bidirectional positional deviation
- ``A_up``: max (x̄i↑ + 2 si↑) − min (x̄i↑ − 2 si↑); ``A``: the largest x̄ + 2s of both
  directions minus the smallest x̄ − 2s of both, accuracy of positioning of the axis

This module imports only numpy and the standard library.

References
----------
ISO 230-2:2014, *Test code for machine tools -- Part 2: Determination of accuracy and
repeatability of positioning of numerically controlled axes*, clause 2 (terms and
definitions: mean unidirectional and bidirectional positional deviation at a position,
reversal value at a position and of an axis, mean reversal value, range of the mean
bidirectional positional deviation, estimator of the unidirectional standard uncertainty
of positioning, uni- and bidirectional positioning repeatability at a position and of an
axis, uni- and bidirectional systematic positional deviation of an axis, uni- and
bidirectional accuracy of positioning of an axis) and its test programme (five approaches
in each direction at each target).
Longstaff (2002), section 3.13.2 (machine repeatability after ISO 230-2: at least five
runs; a band of two standard uncertainties per direction).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from types import MappingProxyType

import numpy as np

from esp.core.errors import DataError
from esp.core.profile import ErrorProfile

__all__ = [
    "AXIS_KEYS",
    "MIN_RUNS",
    "RECOMMENDED_RUNS",
    "SCHEMA",
    "TARGET_KEYS",
    "Iso230Result",
    "iso230_2",
    "statistics",
]

#: the name and version of the JSON document of ``esp iso230-2``
SCHEMA = "esp.iso230-2/1"

#: fewer runs in a direction leave the standard deviation undefined
MIN_RUNS = 2
#: ISO 230-2 test programme: five approaches in each direction at every target
RECOMMENDED_RUNS = 5

#: keys of ``to_dict()["axis"]``, in output order (absent when a direction is missing)
AXIS_KEYS = (
    "A",
    "A_up",
    "A_down",
    "B",
    "B_mean",
    "E",
    "E_up",
    "E_down",
    "M",
    "R",
    "R_up",
    "R_down",
)
#: keys of each ``to_dict()["targets"]`` row, in output order
TARGET_KEYS = ("position_mm", "mean_up", "mean_down", "s_up", "s_down", "B", "R_up", "R_down", "R")

#: ISO 230-2 arrow names of esp's run directions
_ARROW = {"forward": "up", "backward": "down"}


def _readonly(a: np.ndarray | None) -> np.ndarray | None:
    if a is None:
        return None
    a = np.array(a, dtype=float)
    a.setflags(write=False)
    return a


@dataclass(frozen=True, eq=False)
class Iso230Result:
    """ISO 230-2 positioning statistics of one linear axis (all deviations in µm).

    Per-target arrays have shape (m,), one value per entry of ``targets_mm``; those of a
    direction that was not measured are None, as are the bidirectional ones when only one
    direction was measured. Axis figures are floats, or None when they need a direction
    that was not measured.

    Attributes
    ----------
    targets_mm : target positions Pi, mm, increasing
    runs : ``{"up": n↑, "down": n↓}`` for the directions measured
    mean_up, mean_down : x̄i↑, x̄i↓, mean unidirectional positional deviation, µm
    s_up, s_down : si↑, si↓, sample standard deviation (n − 1), µm
    R_up_i, R_down_i : Ri↑ = 4 si↑, Ri↓ = 4 si↓, µm
    B_i : Bi = x̄i↑ − x̄i↓, reversal value at each target, µm
    R_i : Ri = max(2 si↑ + 2 si↓ + |Bi|, Ri↑, Ri↓), µm
    mean_bidirectional : x̄i = (x̄i↑ + x̄i↓) / 2, µm
    A, A_up, A_down, B, B_mean, E, E_up, E_down, M, R, R_up, R_down : axis figures, µm
        (see the module docstring)
    notes : remarks on the data (too few runs for the standard's test programme, ...)
    axis : the axis that moved, when known
    source : where the profile came from
    unit : always ``"um"``

    References
    ----------
    ISO 230-2:2014, clause 2 (terms and definitions).
    """

    targets_mm: np.ndarray
    runs: Mapping[str, int]
    mean_up: np.ndarray | None = None
    mean_down: np.ndarray | None = None
    s_up: np.ndarray | None = None
    s_down: np.ndarray | None = None
    R_up_i: np.ndarray | None = None
    R_down_i: np.ndarray | None = None
    B_i: np.ndarray | None = None
    R_i: np.ndarray | None = None
    mean_bidirectional: np.ndarray | None = None
    A: float | None = None
    A_up: float | None = None
    A_down: float | None = None
    B: float | None = None
    B_mean: float | None = None
    E: float | None = None
    E_up: float | None = None
    E_down: float | None = None
    M: float | None = None
    R: float | None = None
    R_up: float | None = None
    R_down: float | None = None
    notes: tuple[str, ...] = ()
    axis: str | None = None
    source: str | None = None
    unit: str = "um"
    rotary: bool = False

    def __post_init__(self) -> None:
        object.__setattr__(self, "targets_mm", _readonly(self.targets_mm))
        object.__setattr__(self, "runs", MappingProxyType(dict(self.runs)))
        for name in (
            "mean_up",
            "mean_down",
            "s_up",
            "s_down",
            "R_up_i",
            "R_down_i",
            "B_i",
            "R_i",
            "mean_bidirectional",
        ):
            object.__setattr__(self, name, _readonly(getattr(self, name)))
        object.__setattr__(self, "notes", tuple(self.notes))

    @property
    def value_label(self) -> str:
        """The unit of the deviations as printed: ``µm``, or ``arcsec`` for a rotary axis."""
        return "arcsec" if self.rotary else "µm"

    @property
    def position_label(self) -> str:
        """The unit of the target positions as printed: ``mm``, or ``°`` for a rotary axis."""
        return "°" if self.rotary else "mm"

    def position_text(self, value: float) -> str:
        """A position with its unit: ``1000 mm``, ``360°``."""
        return f"{value:g}°" if self.rotary else f"{value:g} mm"

    @property
    def position_key(self) -> str:
        """The key of a target's position in :meth:`target_rows` and the JSON."""
        return "position_deg" if self.rotary else "position_mm"

    @property
    def bidirectional(self) -> bool:
        """True when both directions were measured (and the bidirectional figures exist)."""
        return "up" in self.runs and "down" in self.runs

    @property
    def directions(self) -> tuple[str, ...]:
        """The ISO directions measured, ``"up"`` first: ``("up", "down")``, ``("up",)``..."""
        return tuple(d for d in ("up", "down") if d in self.runs)

    def axis_values(self) -> dict[str, float]:
        """The axis figures that exist, in the order of :data:`AXIS_KEYS` (µm)."""
        out = {}
        for key in AXIS_KEYS:
            value = getattr(self, key)
            if value is not None:
                out[key] = float(value)
        return out

    def target_rows(self) -> list[dict[str, float]]:
        """One dict per target with the keys of :data:`TARGET_KEYS` that exist (µm)."""
        columns = {
            "mean_up": self.mean_up,
            "mean_down": self.mean_down,
            "s_up": self.s_up,
            "s_down": self.s_down,
            "B": self.B_i,
            "R_up": self.R_up_i,
            "R_down": self.R_down_i,
            "R": self.R_i,
        }
        rows = []
        for i, position in enumerate(self.targets_mm):
            row = {self.position_key: float(position)}
            for key in TARGET_KEYS[1:]:
                col = columns[key]
                if col is not None:
                    row[key] = float(col[i])
            rows.append(row)
        return rows

    def to_dict(self) -> dict:
        """The JSON contract of ``esp iso230-2 --json`` (values in µm).

        ``{"schema": "esp.iso230-2/1", "unit": "um", "bidirectional": bool,
        "runs": {"up": n, "down": n},
        "axis": {A, A_up, A_down, B, B_mean, E, E_up, E_down, M, R, R_up, R_down},
        "targets": [{position_mm, mean_up, mean_down, s_up, s_down, B, R_up, R_down, R}],
        "notes": [str, ...]}``; keys that need a direction that was not measured are
        absent. A rotary axis has ``"unit": "arcsec"``, ``"axis_kind": "rotary"`` and
        ``position_deg`` in place of ``position_mm``.
        """
        extra = {"axis_kind": "rotary"} if self.rotary else {}
        return {
            "schema": SCHEMA,
            **extra,
            "unit": self.unit,
            "bidirectional": self.bidirectional,
            "runs": dict(self.runs),
            "axis": self.axis_values(),
            "targets": self.target_rows(),
            "notes": list(self.notes),
        }


def _direction_stats(runs_um: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Mean x̄i and sample standard deviation si (n − 1) at each target of (n, m) runs."""
    return runs_um.mean(axis=0), runs_um.std(axis=0, ddof=1)


def _described(profile: ErrorProfile) -> str:
    """What a profile holds, in words (``an angular profile of the X axis``), naming only
    what the file records."""
    article = "an" if profile.kind[0] in "aeiou" else "a"
    text = f"{article} {profile.kind} profile"
    if profile.axis:
        text += f" of the {profile.axis} axis"
    if profile.error_direction:
        text += f" ({profile.name})"
    return text


def iso230_2(profile: ErrorProfile) -> Iso230Result:
    """ISO 230-2 positioning statistics of a linear error profile.

    Parameters
    ----------
    profile : an :class:`~esp.core.profile.ErrorProfile` of kind ``"linear"``, deviations in µm,
        with at least 2 runs in each direction it holds. Forward runs are the ISO ↑
        (``up``) approaches, backward runs the ↓ (``down``) approaches.

    Returns
    -------
    Iso230Result
        Per-target and per-axis figures in µm. With one direction only, only that
        direction's figures (``A_up``, ``E_up``, ``R_up`` or the ``_down`` ones) are set and
        ``bidirectional`` is False. With fewer than 5 runs in a direction the result
        carries a note, because the standard's test programme asks for five.

    Raises
    ------
    DataError
        If the profile is not linear (the standard's statistics of positioning are
        defined for positioning deviations along the axis, not for straightness or
        angular errors), or if a direction holds fewer than 2 runs (no standard
        deviation can be estimated).

    References
    ----------
    ISO 230-2:2014, clause 2 (terms and definitions of every figure computed here);
    Longstaff (2002), 3.13.2.

    Examples
    --------
    >>> import numpy as np
    >>> from esp.core.profile import ErrorProfile
    >>> runs = {"forward": [[0.0, 2.0], [2.0, 4.0]], "backward": [[0.0, 0.0], [0.0, 0.0]]}
    >>> p = ErrorProfile("linear", [0.0, 100.0], runs)
    >>> r = iso230_2(p)
    >>> r.B_i.tolist(), r.B
    ([1.0, 3.0], 3.0)
    """
    where = f"{profile.source}: " if profile.source else ""
    if profile.kind != "linear":
        raise DataError(
            f"{where}ISO 230-2 positioning statistics are defined for linear positioning "
            f"profiles; found {_described(profile)}"
        )
    return statistics(
        profile.targets_mm,
        {d: profile.runs[d] for d in profile.directions},
        axis=profile.axis,
        source=profile.source,
    )


def statistics(
    targets: np.ndarray,
    runs_by_direction: Mapping[str, np.ndarray],
    *,
    axis: str | None = None,
    source: str | None = None,
    unit: str = "um",
    rotary: bool = False,
) -> Iso230Result:
    """The ISO 230-2 figures of runs ``{"forward": (n, m), "backward": (n, m)}`` at the
    ``targets`` (mm, or degrees for a rotary axis; deviations in µm, or arcsec): the
    computation :func:`iso230_2` and :func:`esp.iso230.rotary.rotary_iso230_2` share.

    Raises
    ------
    DataError
        A direction with fewer than 2 runs.
    """
    where = f"{source}: " if source else ""
    stats: dict[str, tuple[np.ndarray, np.ndarray]] = {}
    runs: dict[str, int] = {}
    for direction, values in runs_by_direction.items():
        arrow = _ARROW[direction]
        data = np.asarray(values, dtype=float)
        n = int(data.shape[0])
        if n < MIN_RUNS:
            raise DataError(
                f"{where}ISO 230-2 statistics need at least {MIN_RUNS} runs in each direction "
                f"to estimate a standard deviation; the {direction} ({arrow}) direction has {n}"
            )
        runs[arrow] = n
        stats[arrow] = _direction_stats(data)

    notes = []
    short = [f"{d} {runs[d]}" for d in runs if runs[d] < RECOMMENDED_RUNS]
    if short:
        notes.append(
            f"ISO 230-2 asks for at least {RECOMMENDED_RUNS} runs in each direction; this file "
            f"has {', '.join(short)}: the statistics are indicative only"
        )
    if len(runs) == 1:
        only = next(iter(runs))
        notes.append(
            f"unidirectional data ({only} only): bidirectional figures (A, B, E, M, R) are "
            f"not defined"
        )

    fields: dict = {}
    # per direction: x̄i, si, Ri = 4 si; axis: R = max Ri, E = range of x̄i,
    # A = max(x̄i + 2 si) - min(x̄i - 2 si)
    for arrow, (mean, s) in stats.items():
        r_i = 4.0 * s
        fields[f"mean_{arrow}"] = mean
        fields[f"s_{arrow}"] = s
        fields[f"R_{arrow}_i"] = r_i
        fields[f"R_{arrow}"] = float(r_i.max())
        fields[f"E_{arrow}"] = float(mean.max() - mean.min())
        fields[f"A_{arrow}"] = float((mean + 2.0 * s).max() - (mean - 2.0 * s).min())

    if len(stats) == 2:
        mean_up, s_up = stats["up"]
        mean_down, s_down = stats["down"]
        b_i = mean_up - mean_down
        r_i = np.maximum.reduce([2.0 * s_up + 2.0 * s_down + np.abs(b_i), 4.0 * s_up, 4.0 * s_down])
        mean_bi = 0.5 * (mean_up + mean_down)
        both = np.concatenate([mean_up, mean_down])
        upper = np.concatenate([mean_up + 2.0 * s_up, mean_down + 2.0 * s_down])
        lower = np.concatenate([mean_up - 2.0 * s_up, mean_down - 2.0 * s_down])
        fields.update(
            B_i=b_i,
            R_i=r_i,
            mean_bidirectional=mean_bi,
            B=float(np.abs(b_i).max()),
            B_mean=float(b_i.mean()),
            R=float(r_i.max()),
            E=float(both.max() - both.min()),
            M=float(mean_bi.max() - mean_bi.min()),
            A=float(upper.max() - lower.min()),
        )

    return Iso230Result(
        targets_mm=np.asarray(targets, dtype=float),
        runs=runs,
        notes=tuple(notes),
        axis=axis,
        source=source,
        unit=unit,
        rotary=rotary,
        **fields,
    )
