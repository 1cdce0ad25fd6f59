"""Ballbar circles made from the exact geometry of a machine with stated errors: the tests'
and the shipped example's data, with their truth (docs/ballbar.md, "The worked example").

The commanded tool point runs on a circle of radius R about the pivot, in the plane a-b,
at angle θ; the machine puts it at the commanded point plus the error vector e(θ, run) of
the effects given (each as :mod:`esp.ballbar.diagnosis` defines it, with a = R cos θ,
b = R sin θ and the axis velocities of the run); the pivot sits at the centre plus the
set-up offset. The bar reads the exact distance of the two minus R (no linearisation),
plus its length error and the noise.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

__all__ = ["Effects", "synthetic_readings", "write_angles", "write_lengths"]


@dataclass(frozen=True)
class Effects:
    """The errors of the machine (zero: none). Per axis values are (a, b) pairs."""

    #: scale error of each axis (µm/m)
    scale_um_per_m: tuple[float, float] = (0.0, 0.0)
    #: out-of-squareness: the tool along +a by S·b (µm/m)
    squareness_um_per_m: float = 0.0
    #: axis b lags its command by this much more than axis a (ms)
    servo_mismatch_ms: float = 0.0
    #: backlash of each axis at its positive and negative end ((a+, a-), (b+, b-)), µm
    backlash_um: tuple[tuple[float, float], tuple[float, float]] = ((0.0, 0.0), (0.0, 0.0))
    #: lateral play of each axis (the carriage across its travel at its reversal), µm
    lateral_um: tuple[float, float] = (0.0, 0.0)
    #: bow of each axis over the diameter (a along b, b along a), µm
    bow_um: tuple[float, float] = (0.0, 0.0)
    #: cyclic error of each axis: (amplitude µm, period mm, phase rad)
    cyclic: tuple[tuple[float, float, float], tuple[float, float, float]] = (
        (0.0, 1.0, 0.0),
        (0.0, 1.0, 0.0),
    )
    #: reversal spike of each axis: (height µm outward, decay angle deg)
    spike: tuple[tuple[float, float], tuple[float, float]] = ((0.0, 1.0), (0.0, 1.0))
    #: stick-slip of each axis: (ripple amplitude µm, its period deg, half-width deg)
    stick_slip: tuple[tuple[float, float, float], tuple[float, float, float]] = (
        (0.0, 1.0, 10.0),
        (0.0, 1.0, 10.0),
    )
    #: the pivot's offset from the commanded centre (a, b), µm
    centre_offset_um: tuple[float, float] = (0.0, 0.0)
    #: the bar longer than its stated length by this (µm)
    length_error_um: float = 0.0
    #: standard deviation of the reading noise (µm)
    noise_um: float = 0.0


def _travel(theta_deg: np.ndarray, sense: float, at: float) -> np.ndarray:
    return sense * ((theta_deg - at + 180.0) % 360.0 - 180.0)


def _error_um(theta_deg: np.ndarray, sense: float, R: float, feed: float, e: Effects) -> np.ndarray:
    """The error vector (µm), shape (n, 2), of the tool at the commanded angles of a run."""
    th = np.radians(theta_deg)
    pos = R * np.column_stack([np.cos(th), np.sin(th)])  # mm from the centre
    u = pos / R
    sgn_v = np.column_stack([np.sign(-sense * np.sin(th)), np.sign(sense * np.cos(th))])
    err = np.zeros_like(pos)
    for i in (0, 1):
        j = 1 - i
        err[:, i] += e.scale_um_per_m[i] * pos[:, i] * 1e-3
        bp, bm = e.backlash_um[i]
        err[:, i] += -0.5 * sgn_v[:, i] * (bp * (1 + u[:, i]) + bm * (1 - u[:, i])) / 2.0
        err[:, j] += -0.5 * sgn_v[:, i] * e.lateral_um[i]
        err[:, j] += e.bow_um[i] * (1.0 - u[:, i] ** 2)
        amp, period, phase = e.cyclic[i]
        err[:, i] += amp * np.sin(2 * np.pi * pos[:, i] / period + phase)
        height, decay = e.spike[i]
        ripple, ripple_period, half = e.stick_slip[i]
        for at in (0.0, 180.0) if i == 0 else (90.0, 270.0):
            x = _travel(theta_deg, sense, at)
            after = (x > 0) & (x < 90.0)
            err[after, i] += height * np.exp(-x[after] / decay) * np.sign(pos[after, i])
            near = np.abs(x) <= half
            err[near, i] += ripple * np.sin(2 * np.pi * x[near] / ripple_period)
    err[:, 0] += e.squareness_um_per_m * pos[:, 1] * 1e-3
    # the lag of b behind a: e_b = -v_b Δτ, v_b = s v cos θ (v = feed in mm/s)
    v = feed / 60.0
    err[:, 1] += -sense * v * np.cos(th) * e.servo_mismatch_ms * 1e-3 * 1e3
    return err


def synthetic_readings(
    R: float,
    effects: Effects,
    *,
    step_deg: float = 0.5,
    start_deg: float = 0.0,
    span_deg: float = 360.0,
    directions: Iterable[str] = ("ccw", "cw"),
    feed_mm_per_min: float = 1000.0,
    seed: int = 1,
) -> list[tuple[str, np.ndarray, np.ndarray]]:
    """Per run (direction, commanded angles in deg, deviations in µm) of a circle of
    radius ``R`` (mm) over the arc from ``start_deg`` over ``span_deg``, with ``effects``,
    computed from the exact geometry (module docstring). The noise is drawn from a
    :class:`numpy.random.Generator` seeded with ``seed``."""
    rng = np.random.default_rng(seed)
    n = int(round(span_deg / step_deg)) + (0 if span_deg >= 360.0 else 1)
    theta = (start_deg + step_deg * np.arange(n)) % 360.0
    out = []
    for d in directions:
        sense = 1.0 if d == "ccw" else -1.0
        th = theta if sense > 0 else theta[::-1]
        err = _error_um(th, sense, R, feed_mm_per_min, effects)
        rad = np.radians(th)
        actual = R * np.column_stack([np.cos(rad), np.sin(rad)]) + err * 1e-3
        pivot = np.array(effects.centre_offset_um) * 1e-3
        length = np.sqrt(np.sum((actual - pivot) ** 2, axis=1))
        dev = (length - R) * 1e3 + effects.length_error_um
        dev = dev + effects.noise_um * rng.standard_normal(dev.size)
        out.append((d, th, dev))
    return out


def write_angles(
    path: str | Path,
    R: float,
    runs: list[tuple[str, np.ndarray, np.ndarray]],
    header: Iterable[str] = (),
) -> None:
    """An angle table (:mod:`esp.ballbar.angles`) of ``runs``, with ``# radius:`` and the
    ``header`` lines (without their ``#``) first."""
    lines = [f"# {h}" for h in header] + [f"# radius: {R:g} mm", "angle,deviation_um,direction"]
    for d, th, dev in runs:
        lines += [f"{t:.4f},{v:.6f},{d}" for t, v in zip(th, dev, strict=True)]
    Path(path).write_text("\n".join(lines) + "\n", encoding="utf-8")


def write_lengths(
    path: str | Path,
    R: float,
    runs: list[tuple[str, np.ndarray, np.ndarray]],
    centre: tuple[float, float, float] = (300.0, 200.0, 50.0),
    plane: str = "XY",
    header: Iterable[str] = (),
    name: str = "c1",
) -> None:
    """The lengths table of ``esp identify`` (docs/formats.md) of ``runs``."""
    i, j = "XYZ".index(plane[0]), "XYZ".index(plane[1])
    lines = [f"# {h}" for h in header] + ["circle,direction,X,Y,Z,cx,cy,cz,length_mm,deviation_um"]
    c = ",".join(f"{v:g}" for v in centre)
    for d, th, dev in runs:
        rad = np.radians(th)
        for t_c, t_s, v in zip(np.cos(rad), np.sin(rad), dev, strict=True):
            p = list(centre)
            p[i] += R * t_c
            p[j] += R * t_s
            lines.append(f"{name},{d},{p[0]:.6f},{p[1]:.6f},{p[2]:.6f},{c},{R:g},{v:.6f}")
    Path(path).write_text("\n".join(lines) + "\n", encoding="utf-8")
