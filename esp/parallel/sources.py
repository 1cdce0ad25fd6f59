"""The error sources of the serial-parallel machine, their names, symbols and units.

Every result names a source the same way. Per leg i (1, 2, 3):

=====================  ========  ======  =====================================================
name                   symbol    unit    meaning
=====================  ========  ======  =====================================================
``legi.joint.X|Y|Z``   δR_i      µm      revolute joint R_i's position error on its slider
                                         (the paper's δR_i, eq. 8-19)
``legi.strut``         δl_i      µm      strut length error (longer is positive)
``legi.slider.X|Y|Z``  δC_i      µm      slider (carriage) position error: Z is the actuation
                                         (feed) error along the column, X and Y the column's
                                         straightness or location (the paper's δC_i, eq. 16-19)
``legi.ball.x|y|z``    δr_i      µm      ball joint b_i's position error, in the tool frame
                                         xyz (the paper's ᵒᵀδr_i, eq. 16-19)
``legi.axis.tilt``     δτ_i      µrad    revolute axis turned about ρ_i (out of horizontal)
``legi.axis.yaw``      δψ_i      µrad    revolute axis turned about Z
=====================  ========  ======  =====================================================

and for the X-Y table, in series: ``table.X|Y|Z`` (δO_P, µm) and ``table.A|B|C`` (its
rotation about X, Y, Z, µrad), stated at the table's reference point.

The order of :data:`SOURCES` is the paper's: first the twelve columns of [M] (δA of eq. 12,
``[δR_1 δl_1 δR_2 δl_2 δR_3 δl_3]``), then the columns of [N] (δB of eq. 18, with each
table error once rather than once per leg, and the axis errors the paper does not model).
δC_i and δR_i enter every result identically (their sum is the joint's position error);
they are kept apart so that a budget can tell an actuation error from a manufacturing one.

The outputs (rows of every matrix) are :data:`OUTPUTS`: the tool tip's position error
e = (e_x, e_y, e_z) in µm and its orientation error ε = (ε_x, ε_y, ε_z) in µrad, both
relative to the table (the workpiece) and in XYZ (eq. 6).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

__all__ = [
    "IN_SCALE",
    "M_COLUMNS",
    "N_COLUMNS",
    "OUTPUTS",
    "OUTPUT_UNITS",
    "OUT_SCALE",
    "SOURCES",
    "SOURCE_NAMES",
    "Source",
    "engine_from_paper",
    "source_index",
    "vector_from_mapping",
]


@dataclass(frozen=True)
class Source:
    """One error source: its name, the paper's symbol, its unit and what it is."""

    name: str
    symbol: str
    unit: str  # "um" | "urad"
    group: str  # joint | strut | slider | ball | axis | table
    leg: int | None
    component: str | None
    description: str


def _leg_sources_m(i: int) -> list[Source]:
    out = [
        Source(
            f"leg{i}.joint.{c}",
            f"δR{i}{c.lower()}",
            "um",
            "joint",
            i,
            c,
            f"revolute joint {i} position error along {c}",
        )
        for c in "XYZ"
    ]
    out.append(Source(f"leg{i}.strut", f"δl{i}", "um", "strut", i, None, f"strut {i} length error"))
    return out


def _leg_sources_n(i: int) -> list[Source]:
    out = [
        Source(
            f"leg{i}.slider.{c}",
            f"δC{i}{c.lower()}",
            "um",
            "slider",
            i,
            c,
            f"slider {i} position error along {c}"
            + (" (actuation, along the column)" if c == "Z" else ""),
        )
        for c in "XYZ"
    ]
    out += [
        Source(
            f"leg{i}.ball.{c}",
            f"δr{i}{c}",
            "um",
            "ball",
            i,
            c,
            f"ball joint {i} position error along the tool frame's {c}",
        )
        for c in "xyz"
    ]
    return out


def _table_sources() -> list[Source]:
    out = [
        Source(
            f"table.{c}",
            f"δOP{c.lower()}",
            "um",
            "table",
            None,
            c,
            f"table position error along {c}",
        )
        for c in "XYZ"
    ]
    out += [
        Source(
            f"table.{c}",
            f"εP{a}",
            "urad",
            "table",
            None,
            c,
            f"table rotation error about {a.upper()}",
        )
        for c, a in zip("ABC", "xyz", strict=True)
    ]
    return out


def _axis_sources(i: int) -> list[Source]:
    return [
        Source(
            f"leg{i}.axis.tilt",
            f"δτ{i}",
            "urad",
            "axis",
            i,
            "tilt",
            f"revolute axis {i} tilt (about the horizontal in the strut's plane)",
        ),
        Source(
            f"leg{i}.axis.yaw",
            f"δψ{i}",
            "urad",
            "axis",
            i,
            "yaw",
            f"revolute axis {i} yaw (about Z)",
        ),
    ]


_M = [s for i in (1, 2, 3) for s in _leg_sources_m(i)]
_N = [s for i in (1, 2, 3) for s in _leg_sources_n(i)] + _table_sources()
_N += [s for i in (1, 2, 3) for s in _axis_sources(i)]

#: every source, in the order of the columns of [M | N]
SOURCES: tuple[Source, ...] = tuple(_M + _N)
SOURCE_NAMES: tuple[str, ...] = tuple(s.name for s in SOURCES)
#: the columns of [M] (12) and of [N] (30), by source name
M_COLUMNS: tuple[str, ...] = tuple(s.name for s in _M)
N_COLUMNS: tuple[str, ...] = tuple(s.name for s in _N)
#: the rows: tool tip position error (µm) and orientation error (µrad)
OUTPUTS: tuple[str, ...] = ("e_x", "e_y", "e_z", "eps_x", "eps_y", "eps_z")
OUTPUT_UNITS: tuple[str, ...] = ("um", "um", "um", "urad", "urad", "urad")

_INDEX = {name: i for i, name in enumerate(SOURCE_NAMES)}

#: engine unit -> paper unit: µm -> mm, µrad -> rad
IN_SCALE = np.array([1e3 if s.unit == "um" else 1e6 for s in SOURCES])
OUT_SCALE = np.array([1e3, 1e3, 1e3, 1e6, 1e6, 1e6])


def source_index(name: str) -> int:
    """The column of a source; KeyError for an unknown name."""
    return _INDEX[name]


def vector_from_mapping(values: Mapping[str, float]) -> np.ndarray:
    """The (42,) vector of source values (engine units) from ``{name: value}``; sources not
    named are 0. Unknown names raise KeyError."""
    out = np.zeros(len(SOURCES))
    for name, value in values.items():
        out[_INDEX[name]] = float(value)
    return out


def engine_from_paper(s_paper: np.ndarray) -> np.ndarray:
    """Sensitivities (..., 6, 42) from the paper's units (Δ in mm and rad per mm or rad of
    source) to esp's (µm and µrad per µm or µrad)."""
    return s_paper * OUT_SCALE[:, None] / IN_SCALE[None, :]
