"""What each error of a rotary table does to the tool tip, per table setting: an affine
function of the tool tip's machine position (numpy only).

Why affine
----------
At a fixed setting of its axes the table, with its errors, is a rigid body: the transform
T(θ) from the machine frame (the table's mount) to the workpiece frame is a rotation and a
translation, exact or perturbed. A tool tip at machine position p sits at T(θ)·p in the
workpiece frame, so its error relative to the workpiece, (T_actual − T_nominal)·p, is a
matrix times p plus a vector: affine in p, for the first-order terms and the exact error
alike. To first order the matrix is a small rotation, [ω]×, so each term is
``constant_um + per_mm @ p`` with ``per_mm`` skew-symmetric: a displacement plus a small
rotation levered by the tool tip's position.

Frames
------
The errors are the motions of the **tool relative to the workpiece** (esp's one
convention, ``docs/conventions.md``), expressed in **machine axes**, like the errors of the
linear axes: the two add up (to first order) without rotating either. ``rotation[i]`` is
the nominal rotation of the workpiece frame relative to the machine frame at setting i (a
vector with workpiece components v_W has machine components ``rotation[i] @ v_W``), so an
error in the workpiece frame is ``rotation[i].T @ error``.

References
----------
ISO 230-7:2015 (error motions of an axis of rotation), ISO 230-1:2012 (location errors of
an axis average line), ISO 841:2001 (the sense of rotary axes). The chain machinery is
Freeman & Ford (2003, section 4) and Loh et al. (2004, eq. 1-9), :mod:`esp.core.kinematics`.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from functools import lru_cache
from typing import Any

import numpy as np

from esp.core.devices.device import extended_chain
from esp.core.devices.table import TIP_PARAMETERS, Table
from esp.core.kinematics import Chain, sensitivities, transforms
from esp.core.kinematics.chain import Translate
from esp.core.kinematics.expr import Name

__all__ = [
    "TableTerm",
    "TableTerms",
    "UnitForm",
    "UnitTerms",
    "table_angles",
    "table_terms",
    "tip_chain",
    "unit_terms",
]

_UM = 1000.0  # µm per mm


@dataclass(frozen=True)
class TableTerm:
    """One table error's first-order effect at N settings.

    The error of the tool relative to the workpiece, in machine axes, at a tool tip at
    machine position p (mm) and setting i is ``constant_um[i] + per_mm[i] @ p`` (µm).

    Attributes
    ----------
    name : the error's symbol (``X0C``, ``EXC``)
    value : (N,) its value at each setting, in ``unit`` (a constant repeated, or a curve
        interpolated at the angle of its axis)
    unit : the symbol's unit
    constant_um : (N, 3) µm
    per_mm : (N, 3, 3) µm per mm of tool-tip position; ``per_mm[i, d, j]`` is the error
        along machine axis d per mm along machine axis j
    """

    name: str
    value: np.ndarray
    unit: str
    constant_um: np.ndarray
    per_mm: np.ndarray

    def error_um(self, p_mm: Any) -> np.ndarray:
        """The term at tool tips ``p_mm`` ((3,) for one point at every setting, or (N, 3)
        one point per setting): (N, 3) µm."""
        return _affine(self.constant_um, self.per_mm, p_mm)


@dataclass(frozen=True)
class TableTerms:
    """The table's errors at N settings (see :func:`table_terms`).

    Attributes
    ----------
    angles : coordinate -> (N,) the settings, degrees
    rotation : (N, 3, 3) the nominal rotation of the workpiece frame relative to the machine
        frame: machine components = ``rotation[i] @`` workpiece components
    terms : every error with a non-zero value (at a setting, or at the set-up setting), in
        the chain's order; they add up
    setup_deg : the set-up setting used (coordinate -> degrees), or None
    """

    angles: Mapping[str, np.ndarray]
    rotation: np.ndarray
    terms: tuple[TableTerm, ...]
    setup_deg: Mapping[str, float] | None = None

    @property
    def size(self) -> int:
        return self.rotation.shape[0]

    @property
    def constant_um(self) -> np.ndarray:
        """(N, 3) the sum of the terms' constants."""
        out = np.zeros((self.size, 3))
        for t in self.terms:
            out += t.constant_um
        return out

    @property
    def per_mm(self) -> np.ndarray:
        """(N, 3, 3) the sum of the terms' matrices."""
        out = np.zeros((self.size, 3, 3))
        for t in self.terms:
            out += t.per_mm
        return out

    def error_um(self, p_mm: Any) -> np.ndarray:
        """The table's first-order error at tool tips ``p_mm`` ((3,) or (N, 3) mm), (N, 3)
        µm, machine axes."""
        return _affine(self.constant_um, self.per_mm, p_mm)

    def in_workpiece_frame(self, error_um: Any) -> np.ndarray:
        """(N, 3) errors in machine axes expressed in the workpiece frame at each setting."""
        e = np.asarray(error_um, dtype=float)
        return np.einsum("nji,nj->ni", self.rotation, np.broadcast_to(e, (self.size, 3)))


def _affine(constant: np.ndarray, per_mm: np.ndarray, p_mm: Any) -> np.ndarray:
    p = np.asarray(p_mm, dtype=float)
    if p.shape not in ((3,), (constant.shape[0], 3)):
        raise ValueError(f"expected p of shape (3,) or ({constant.shape[0]}, 3), found {p.shape}")
    if not np.all(np.isfinite(p)):
        raise ValueError("expected finite tool-tip positions (mm), found NaN or infinity")
    if p.ndim == 1:
        return constant + np.einsum("nij,j->ni", per_mm, p)
    return constant + np.einsum("nij,nj->ni", per_mm, p)


@lru_cache(maxsize=16)
def tip_chain(chain: Chain) -> Chain:
    """The table chain followed by T(esp_tip_x, esp_tip_y, esp_tip_z): its tip is a tool tip
    at that machine position, seen from the workpiece frame (parameters in mm)."""
    symbols = {n: {"kind": "parameter", "unit": "mm", "value": 0.0} for n in TIP_PARAMETERS}
    x, y, z = (Name(n) for n in TIP_PARAMETERS)
    step = Translate(x, y, z, note="the tool tip, machine frame")
    return extended_chain(chain, step, symbols)


def table_angles(table: Table, angles: Mapping[str, Any]) -> tuple[dict[str, np.ndarray], int]:
    """Check the table's settings: every axis, numbers or 1-D arrays of one length N,
    finite, in degrees. Returns (coordinate -> float64 array (N,), N).

    Raises
    ------
    ConfigError
        A missing or unknown axis, values that are not finite numbers of a sensible size,
        arrays of different lengths (key ``angles.C``).
    """
    return table.settings(angles)


def _in_degrees(table: Table, angles: Mapping[str, np.ndarray]) -> dict[str, np.ndarray]:
    """The settings (each in its coordinate's unit) in degrees, for the curves."""
    out = {}
    for c, a in angles.items():
        out[c] = a * table.chain.symbols[c].scale * (180.0 / np.pi)
    return out


def _unit_forms(
    table: Table, angles: Mapping[str, np.ndarray], n: int
) -> tuple[dict[str, np.ndarray], dict[str, np.ndarray], np.ndarray, np.ndarray]:
    """Per unit of each error, in the workpiece frame: the constant c (N, 3) mm and the
    matrix P (N, 3, 3) of the first-order change of the tool tip T(θ)·p = c + P·p; and the
    nominal rotation R_WM (N, 3, 3) and translation t_WM (N, 3) of T(θ)."""
    chain = tip_chain(table.chain)
    params: dict[str, Any] = dict(table.parameters)
    # one evaluation over 4N points: the tip at 0, e_x, e_y, e_z
    coords = {c: np.tile(a, 4) for c, a in angles.items()}
    tips = np.zeros((4 * n, 3))
    for k in range(3):
        tips[(k + 1) * n : (k + 2) * n, k] = 1.0
    for k, name in enumerate(TIP_PARAMETERS):
        params[name] = tips[:, k]
    sens = sensitivities(chain, coords, params)
    c = {e: s[:n] for e, s in sens.items()}
    P = {}
    for e, s in sens.items():
        m = np.empty((n, 3, 3))
        for k in range(3):
            m[:, :, k] = s[(k + 1) * n : (k + 2) * n] - s[:n]
        P[e] = m
    frames = transforms(table.chain, angles, dict(table.parameters))
    return c, P, frames[:, :3, :3], frames[:, :3, 3]


@dataclass(frozen=True)
class UnitForm:
    """One table error's effect per unit of its value, in machine axes (µm, mm).

    At setting i an error of value v(θ_i) moves the tool tip at machine position p
    (relative to the workpiece) by ``v(θ_i) · (constant_um[i] + per_mm[i] @ p)``; with a
    set-up setting θ_s it is that less ``v(θ_s) · (setup_constant_um[i] + setup_per_mm[i]
    @ p)``, the effect at θ_s of the same workpiece point (zero without a set-up setting).
    """

    constant_um: np.ndarray
    per_mm: np.ndarray
    setup_constant_um: np.ndarray
    setup_per_mm: np.ndarray


@dataclass(frozen=True)
class UnitTerms:
    """:class:`UnitForm` of some errors at N settings, and the nominal ``rotation`` (N, 3,
    3) of the workpiece frame (machine components = ``rotation[i] @`` workpiece ones)."""

    forms: Mapping[str, UnitForm]
    rotation: np.ndarray


def unit_terms(table: Table, angles: Mapping[str, Any], names: Any = None) -> UnitTerms:
    """The effect of each of ``names`` (default: every error of the chain) per unit of its
    value at N settings (:class:`UnitForm`): what :func:`table_terms` multiplies by the
    errors' values, and the columns of a design matrix for errors to identify
    (:mod:`esp.identify.rotary`).

    Raises
    ------
    ConfigError
        As :func:`table_terms`.
    """
    at, n = table_angles(table, angles)
    wanted = list(table.chain.errors if names is None else names)
    return _unit_terms(table, at, n, wanted)


def _unit_terms(table: Table, at: Mapping[str, np.ndarray], n: int, names: list[str]) -> UnitTerms:
    c, P, R_wm, t_wm = _unit_forms(table, at, n)
    rotation = np.transpose(R_wm, (0, 2, 1))  # R_MW: workpiece -> machine components
    setup = table.setup_deg
    if setup is not None:
        s_at = {
            k: np.array([v * np.pi / 180.0 / table.chain.symbols[k].scale])
            for k, v in setup.items()
        }
        c0, P0, R_s, t_s = _unit_forms(table, s_at, 1)
        # y = R_y p + t_y: T_nom(θ_s)^-1 T_nom(θ) p, with T_nom(θ) = (R_wm, t_wm)
        R_y = np.einsum("ji,njk->nik", R_s[0], R_wm)
        t_y = np.einsum("ji,nj->ni", R_s[0], t_wm - t_s[0])

    def machine(const_w: np.ndarray, mat_w: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        const_m = np.einsum("nij,nj->ni", rotation, const_w) * _UM
        mat_m = np.einsum("nij,njk->nik", rotation, mat_w) * _UM
        return const_m, mat_m

    forms = {}
    for e in names:
        const_m, mat_m = machine(c[e], P[e])
        if setup is not None:
            s_const, s_mat = machine(
                np.broadcast_to(c0[e][0], (n, 3)) + np.einsum("ij,nj->ni", P0[e][0], t_y),
                np.einsum("ij,njk->nik", P0[e][0], R_y),
            )
        else:
            s_const, s_mat = np.zeros((n, 3)), np.zeros((n, 3, 3))
        forms[e] = UnitForm(const_m, mat_m, s_const, s_mat)
    return UnitTerms(forms, rotation)


def table_terms(table: Table, angles: Mapping[str, Any]) -> TableTerms:
    """Each table error's first-order effect on the tool tip at N settings: the error of
    the tool relative to the workpiece, in machine axes, affine in the tool tip's machine
    position p: ``constant_um[i] + per_mm[i] @ p`` (µm, p in mm).

    The table's chain runs from the workpiece to the table's mount; appending T(p) puts a
    tool tip at machine position p, and the first-order change of that tip in the
    workpiece frame is Σ_e (∂x/∂e)·e (:func:`esp.core.kinematics.sensitivities`, exact
    derivatives). Evaluated with p at the origin and at the three unit vectors it gives the
    constant and the three columns of the matrix, exactly, since the change is affine in p
    (module docstring); ``rotation`` turns both into machine axes.

    With a set-up setting θ_s (``table.setup_deg``), the workpiece frame is the one the
    workpiece takes at θ_s: the table's actual transform there is taken as its nominal one.
    The tool tip's error at θ is then e(θ, p) − e(θ_s, y) in the workpiece frame, where
    y = T_nominal(θ_s)⁻¹·T_nominal(θ)·p is the machine position at which the same
    workpiece point sat at θ_s: every error's effect vanishes at θ_s.

    Parameters
    ----------
    table : the table (chain, parameter and error values, set-up setting)
    angles : every axis of the table (e.g. ``{"A": a, "C": c}``) -> a number or (N,)
        values, in the coordinate's unit (degrees)

    Returns
    -------
    TableTerms
        ``angles`` (N,) each, ``rotation`` (N, 3, 3) and the ``terms``; each term has
        ``value`` (N,), ``constant_um`` (N, 3) and ``per_mm`` (N, 3, 3).

    Raises
    ------
    ConfigError
        A missing or unknown axis, angles that are not finite numbers (``angles.C``).
    DataError
        A curve with ``periodic = false`` asked for an angle outside its range; a quantity
        of the chain is not finite at these values.

    Examples
    --------
    >>> from esp.core.kinematics import Chain, revolute
    >>> from esp.core.devices import table_from_chain, table_terms
    >>> chain = Chain([revolute("z", "C", {"tx": "-X0C"})], {"X0C": {"kind": "error"}})
    >>> table = table_from_chain(chain).with_values({"X0C": 10.0})
    >>> out = table_terms(table, {"C": [0.0, 90.0]})
    >>> (out.error_um([0.0, 0.0, 0.0]).round(9) + 0.0).tolist()
    [[-10.0, 0.0, 0.0], [-10.0, 0.0, 0.0]]
    """
    at, n = table_angles(table, angles)
    deg = _in_degrees(table, at)
    values = table.values_at(deg, n)
    setup = table.setup_deg
    s_values = None
    if setup is not None:
        s_values = table.values_at({k: np.array([v]) for k, v in setup.items()}, 1)
    live = [
        e
        for e in table.chain.errors
        if np.any(values[e]) or (s_values is not None and s_values[e][0] != 0.0)
    ]
    units = _unit_terms(table, at, n, live)
    terms = []
    for e in live:
        v = values[e]
        u = units.forms[e]
        const_m = u.constant_um * v[:, None]
        mat_m = u.per_mm * v[:, None, None]
        if s_values is not None and s_values[e][0] != 0.0:
            v0 = s_values[e][0]
            const_m = const_m - v0 * u.setup_constant_um
            mat_m = mat_m - v0 * u.setup_per_mm
        terms.append(TableTerm(e, v.copy(), table.unit(e), const_m, mat_m))
    rotation = units.rotation
    return TableTerms(
        {k: a.copy() for k, a in at.items()},
        rotation,
        tuple(terms),
        None if setup is None else dict(setup),
    )
