"""Positioning figures of one axis after VDI/DGQ 3441 (1977), beside those of ISO 230-2.

Many older machine acceptance documents quote the figures of the German guideline
VDI/DGQ 3441, *Statistische Prüfung der Arbeits- und Positionsgenauigkeit von
Werkzeugmaschinen -- Grundlagen* (1977), withdrawn in favour of ISO 230-2. From the same
runs as ISO 230-2 (n approaches in each direction at each of m positions j) it defines,
in µm (↑ forward, ↓ backward runs):

- ``x̄j↑``, ``x̄j↓``: mean deviation at position j in each direction; ``sj↑``, ``sj↓``
  their sample standard deviations (n - 1);
- **reversal span** ``Uj = |x̄j↑ - x̄j↓|`` (Umkehrspanne); ``U = max Uj``, ``Ū = mean Uj``;
- **positional scatter** ``Psj = 6·s̄j`` with ``s̄j = (sj↑ + sj↓)/2`` (Positionsstreubreite);
  ``Ps_max = max Psj``, ``Ps_mean = mean Psj``;
- **positional deviation** ``Pa = max x̄j - min x̄j`` with ``x̄j = (x̄j↑ + x̄j↓)/2``, the range
  of the mean positions (Positionsabweichung);
- **position uncertainty** ``P = max(x̄j + Uj/2 + Psj/2) - min(x̄j - Uj/2 - Psj/2)``
  (Positionsunsicherheit), the width of the band holding every position's scatter band
  of both directions.

These are the definitions the guideline's users commonly quote; the test suite checks them
against a hand computation, not against a worked example of the guideline itself. With one
direction only, ``U`` is not defined and ``Psj = 6·sj`` of that direction.

This module imports only numpy and the standard library.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from esp.core.errors import DataError

if TYPE_CHECKING:
    from esp.core.profile import ErrorProfile

__all__ = ["Vdi3441Result", "vdi3441"]


@dataclass(frozen=True, eq=False)
class Vdi3441Result:
    """VDI/DGQ 3441 figures of one axis (µm). Per-position arrays have shape (m,)."""

    targets_mm: np.ndarray
    mean_position: np.ndarray
    U_j: np.ndarray | None
    Ps_j: np.ndarray
    P: float
    Pa: float
    U: float | None
    U_mean: float | None
    Ps_max: float
    Ps_mean: float

    def to_dict(self) -> dict:
        """``{"unit": "um", "P", "Pa", "U", "U_mean", "Ps_max", "Ps_mean",
        "positions": [{position_mm, mean, U, Ps}]}`` (U absent with one direction)."""
        rows = []
        for j, t in enumerate(self.targets_mm):
            row = {"position_mm": float(t), "mean": float(self.mean_position[j])}
            if self.U_j is not None:
                row["U"] = float(self.U_j[j])
            row["Ps"] = float(self.Ps_j[j])
            rows.append(row)
        out = {"unit": "um", "P": self.P, "Pa": self.Pa}
        if self.U is not None:
            out["U"] = self.U
            out["U_mean"] = self.U_mean
        out.update(Ps_max=self.Ps_max, Ps_mean=self.Ps_mean, positions=rows)
        return out


def vdi3441(profile: ErrorProfile) -> Vdi3441Result:
    """VDI/DGQ 3441 figures of a linear :class:`esp.core.profile.ErrorProfile` with at least 2
    runs in each direction it holds.

    Examples
    --------
    >>> from esp.core.profile import ErrorProfile
    >>> runs = {"forward": [[0.0, 2.0], [2.0, 4.0]], "backward": [[0.0, 0.0], [0.0, 0.0]]}
    >>> p = ErrorProfile("linear", [0.0, 100.0], runs)
    >>> r = vdi3441(p)
    >>> r.U, r.Pa
    (3.0, 1.0)
    """
    where = f"{profile.source}: " if profile.source else ""
    if profile.kind != "linear":
        raise DataError(f"{where}VDI/DGQ 3441 figures are defined for positioning (linear) data")
    stats = {}
    for d in profile.directions:
        runs = np.asarray(profile.runs[d], dtype=float)
        if runs.shape[0] < 2:
            raise DataError(
                f"{where}VDI/DGQ 3441 needs at least 2 runs in each direction to estimate a "
                f"scatter; the {d} direction has {runs.shape[0]}"
            )
        stats[d] = (runs.mean(axis=0), runs.std(axis=0, ddof=1))
    if len(stats) == 2:
        (mf, sf), (mb, sb) = stats["forward"], stats["backward"]
        mean = 0.5 * (mf + mb)
        u_j = np.abs(mf - mb)
        ps_j = 6.0 * 0.5 * (sf + sb)
    else:
        ((mean, s),) = stats.values()
        u_j = None
        ps_j = 6.0 * s
    half = 0.5 * ps_j + (0.5 * u_j if u_j is not None else 0.0)
    return Vdi3441Result(
        targets_mm=np.asarray(profile.targets_mm, dtype=float),
        mean_position=mean,
        U_j=u_j,
        Ps_j=ps_j,
        P=float(np.max(mean + half) - np.min(mean - half)),
        Pa=float(np.max(mean) - np.min(mean)),
        U=None if u_j is None else float(np.max(u_j)),
        U_mean=None if u_j is None else float(np.mean(u_j)),
        Ps_max=float(np.max(ps_j)),
        Ps_mean=float(np.mean(ps_j)),
    )
