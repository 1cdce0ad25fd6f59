"""The lines a controller takes for a measured skew: what each firmware's documentation
(or source, where that is its only documentation) says it applies, written so that the
firmware's own transform undoes the machine's motion matrix exactly (docs/skew.md, "The
firmware").

Every firmware here corrects a commanded position ``c`` before its steps are counted:

* Marlin ``M852 I J K`` (``planner.h``, ``skew()``): x' = x − I·y − (J − I·K)·z,
  y' = y − K·z -- the inverse of the unit upper-triangular matrix [[1, I, J], [0, 1, K],
  [0, 0, 1]]. Klipper's ``[skew_correction]`` is a port of it (``klippy/extras/
  skew_correction.py``); ``SET_SKEW XY=AC,BD,AD`` takes the lengths of a square and
  computes I from them as Marlin does.
* RepRapFirmware ``M556 S X Y Z`` (``Move::AxisTransform``): x' = x + tanXY·y + tanXZ·z,
  y' = y + tanYZ·z with tanXY = X/S, tanYZ = Y/S, tanXZ = Z/S; positive when the angle
  is obtuse (the M556 documentation).
* µCNC (grbl settings ``$37`` XY, ``$38`` XZ, ``$39`` YZ; ``kinematics_apply_transform``):
  x' = x − $37·y, y' = y − $39·z as Marlin; its XZ term, as its source reads, is
  −($37 − $38·$39)·z, which no value of $38 turns into Marlin's, so esp does not write $38.
* LinuxCNC ``matrixkins`` (``src/hal/components/matrixkins.comp``): joints = C·axes, C any
  3×3 matrix: esp writes C = M⁻¹.

With the motion matrix M upper triangular (X along x, Y in the xy plane), M = T·D with T unit
upper triangular and D diagonal: the shear factors are T's off-diagonal entries and the
steps-per-mm factors are 1/D, so that M·D⁻¹·T⁻¹ = I -- the exact correction, not a first-order
one (tests/test_skew.py applies each firmware's transform as its source writes it).

NumPy only.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from esp.skew.model import AXES, PLANES, SkewResult

__all__ = [
    "FIRMWARE",
    "Block",
    "FirmwareLines",
    "blocks",
    "firmware_lines",
    "firmware_values",
    "shear_and_steps",
]

#: the firmware esp writes for, in the order shown
FIRMWARE = ("marlin", "klipper", "reprapfirmware", "ucnc", "linuxcnc", "esp")
#: the side of the square whose lengths carry a factor to Klipper's SET_SKEW (mm)
KLIPPER_SIDE_MM = 100.0
#: a steps-per-mm factor of an axis whose scale was not measured is shown beyond this
#: (the 1/sin θ a skewed axis needs is second order: 16 ppm at 5.7 mm/m)
STEPS_SHOWN = 1e-6
#: the length M556 states its deviations over (mm)
RRF_LENGTH_MM = 100.0


@dataclass(frozen=True)
class Block:
    """The lines for one firmware: its name, the lines, and notes on how to use them."""

    firmware: str
    title: str
    lines: tuple[str, ...]
    notes: tuple[str, ...] = ()


def shear_and_steps(m: np.ndarray) -> tuple[dict[str, float], dict[str, float]]:
    """(Marlin's factors ``{"XY": I, "XZ": J, "YZ": K}``, steps-per-mm factors per axis) of
    an upper-triangular motion matrix ``m``: ``m = T·D``."""
    d = np.diag(m)
    t = m / d[np.newaxis, :]
    shear = {"XY": float(t[0, 1]), "XZ": float(t[0, 2]), "YZ": float(t[1, 2])}
    steps = {ax: float(1.0 / d[i]) for i, ax in enumerate(AXES)}
    return shear, steps


def firmware_values(result: SkewResult) -> dict[str, dict]:
    """The numbers each firmware takes for ``result`` (its motion matrix): Marlin's,
    Klipper's and µCNC's shear factors, RepRapFirmware's tangents, LinuxCNC's matrix C
    (row by row), and the steps-per-mm factors."""
    m = result.matrix()
    shear, steps = shear_and_steps(m)
    rrf = {
        "XY": -shear["XY"],
        "YZ": -shear["YZ"],
        "XZ": shear["XY"] * shear["YZ"] - shear["XZ"],
    }
    return {
        "marlin": {**shear, "steps": steps},
        "klipper": {**shear, "steps": steps},
        "reprapfirmware": {**rrf, "steps": steps},
        "ucnc": {**shear, "steps": steps},
        "linuxcnc": {"C": np.linalg.inv(m).ravel().tolist()},
    }


def _klipper_lengths(factor: float) -> tuple[float, float, float]:
    """AC, BD, AD of a square of side :data:`KLIPPER_SIDE_MM` whose Marlin factor is
    ``factor`` (cot θ)."""
    c = factor / math.sqrt(1.0 + factor * factor)
    a = KLIPPER_SIDE_MM
    return a * math.sqrt(2.0 + 2.0 * c), a * math.sqrt(2.0 - 2.0 * c), a


@dataclass(frozen=True)
class FirmwareLines:
    """The firmware numbers of one result (:func:`firmware_values`) and the lines made of
    them (:func:`blocks`), computed once for the text and the JSON."""

    values: dict[str, dict]
    blocks: tuple[Block, ...]


def firmware_lines(result: SkewResult, wanted: tuple[str, ...] = FIRMWARE) -> FirmwareLines:
    """The numbers and the lines of ``wanted`` firmware for ``result``."""
    values = firmware_values(result)
    return FirmwareLines(values, tuple(blocks(result, wanted, values)))


def blocks(
    result: SkewResult, wanted: tuple[str, ...] = FIRMWARE, values: dict | None = None
) -> list[Block]:
    """The lines to paste, per firmware, for the planes and axes ``result`` measured, from
    its firmware numbers ``values`` (default: :func:`firmware_values` of it)."""
    values = firmware_values(result) if values is None else values
    planes = [p for p in PLANES if result.get("squareness", p) is not None]
    scaled = [ax for ax in AXES if result.get("scale", ax) is not None]
    shear = values["marlin"]
    steps = shear["steps"]
    stepped = [ax for ax in AXES if ax in scaled or abs(steps[ax] - 1.0) > STEPS_SHOWN]
    steps_note = (
        "steps per mm: " + ", ".join(f"{ax} × {steps[ax]:.6f}" for ax in stepped) if stepped else ""
    )
    out: list[Block] = []
    letters = {"XY": "I", "XZ": "J", "YZ": "K"}
    if "marlin" in wanted:
        args = " ".join(f"{letters[p]}{shear[p]:.6f}" for p in planes)
        notes = ["needs SKEW_CORRECTION_GCODE, and SKEW_CORRECTION_FOR_Z for J and K; M500 saves"]
        lines = [f"M852 {args}"] if planes else []
        if steps_note:
            notes.append(steps_note + ": M92 with the new values")
        out.append(Block("marlin", "Marlin", tuple(lines), tuple(notes)))
    if "klipper" in wanted and planes:
        parts = []
        for p in planes:
            ac, bd, ad = _klipper_lengths(shear[p])
            parts.append(f"{p}={ac:.4f},{bd:.4f},{ad:.4f}")
        notes = [
            f"the lengths of a {KLIPPER_SIDE_MM:g} mm square with the measured angles; "
            "needs [skew_correction]; then SKEW_PROFILE SAVE=esp and SAVE_CONFIG",
        ]
        if steps_note:
            notes.append(
                "rotation_distance: " + ", ".join(f"{ax} ÷ {steps[ax]:.6f}" for ax in stepped)
            )
        out.append(Block("klipper", "Klipper", ("SET_SKEW " + " ".join(parts),), tuple(notes)))
    if "reprapfirmware" in wanted:
        rrf = values["reprapfirmware"]
        lines = []
        if planes:
            dev = {p: rrf[p] * RRF_LENGTH_MM + 0.0 for p in PLANES}
            lines.append(
                f"M556 S{RRF_LENGTH_MM:g} X{dev['XY']:.5f} Y{dev['YZ']:.5f} Z{dev['XZ']:.5f}"
            )
        notes = ["kept in config.g, or by M500 with M501 in config.g"]
        if steps_note:
            notes.append(steps_note + ": M92 with the new values")
        out.append(Block("reprapfirmware", "RepRapFirmware", tuple(lines), tuple(notes)))
    if "ucnc" in wanted:
        lines = []
        notes = []
        if "XY" in planes:
            lines.append(f"$37={shear['XY']:.6f}")
        if "YZ" in planes:
            lines.append(f"$39={shear['YZ']:.6f}")
        if "XZ" in planes:
            notes.append("XZ not written: µCNC applies its XZ term as −($37 − $38·$39)·z")
        if steps_note:
            notes.append(steps_note + ": $100, $101, $102 with the new values")
        notes.insert(0, "grbl-style settings of µCNC with ENABLE_SKEW_COMPENSATION")
        out.append(Block("ucnc", "µCNC (grbl settings)", tuple(lines), tuple(notes)))
    if "linuxcnc" in wanted:
        c = np.array(values["linuxcnc"]["C"]).reshape(3, 3)
        lines = ["[KINS] KINEMATICS=matrixkins   (INI file)"]
        for i, r in enumerate("xyz"):
            for j, col in enumerate("xyz"):
                lines.append(f"setp matrixkins.C_{r}{col} {c[i, j]:.9f}")
        out.append(
            Block(
                "linuxcnc",
                "LinuxCNC",
                tuple(lines),
                ("matrixkins carries scale and skew: leave [JOINT_n] SCALE as it is",),
            )
        )
    if "esp" in wanted and planes:
        lines = ["[squareness]"]
        for p in planes:
            e = result.get("squareness", p)
            assert e is not None
            lines.append(f"{p} = {e.value_um_per_m:.1f}  # µm/m, U = {e.expanded_um_per_m:.1f}")
        out.append(Block("esp", "esp machine.toml", tuple(lines)))
    return out
