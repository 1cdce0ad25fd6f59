"""A kinematic chain: elementary transforms from the workpiece (base) to the tool tip.

Freeman & Ford (2003, section 4) write a serial machine as a product of elementary
transforms, X = Ψ_1 Ψ_2 … Ψ_N X⁰, each a rotation or a translation, with every quantity
marked as large (an axis angle, an offset G) or small (an error); Loh et al. (2004,
eq. 5-9) write a CMM as a product of 4×4 homogeneous transforms, one per carriage, each
holding its six error motions. A :class:`Chain` is that product, listed from the base (the
workpiece side) to the tool tip, and the tool tip in the base frame is

    p = Ψ_1 Ψ_2 … Ψ_N · [0, 0, 0, 1]ᵀ.

The steps (each lowered to one or two elementary transforms Ψ):

* :class:`Translate` -- T(x, y, z);
* :class:`Rotate` -- a rotation about ``x``, ``y`` or ``z`` (or ``-x``, ``-y``, ``-z``: about
  the negative axis) by an angle, right-handed: a positive angle turns a point
  anticlockwise seen from the positive end of the axis;
* :class:`Prismatic` -- a translation along an axis by a machine coordinate;
* :class:`Revolute` -- a rotation about an axis by a machine coordinate;
* :class:`ErrorMotion` -- six small errors, three translations ``tx, ty, tz`` along x, y, z
  and three right-handed rotations ``rx, ry, rz`` about +x, +y, +z, applied about a
  ``pivot`` point. A joint may carry one: it then acts in the joint's moving frame, right
  after the joint's motion, so that the pivot moves with the carriage (an axis' angles act
  about its measurement line, and their lever runs from the pivot to the tool tip).

Every quantity is a number, a symbol or a small expression (:mod:`esp.core.kinematics.expr`).
Every symbol has a kind: ``coordinate`` (drives a joint; one value per point), ``parameter``
(a large constant: G, e, Y_p, a tool offset) or ``error`` (a small quantity; the first- and
second-order terms are the terms linear and quadratic in the errors), and a unit in which
its values are given. Inside the chain, lengths are in mm and angles in radians.

References
----------
Freeman, J. M. & Ford, D. G. (2003), Automated error analysis of serial manipulators and
servo heads, section 3-4 (the chain of Ψ_i, large and small quantities).
Loh, J. et al. (2004), Analysis of linear and angular errors of a small coordinate measuring
machine, eq. 1-9 (4×4 homogeneous transforms of the carriages).
"""

from __future__ import annotations

from collections.abc import Iterable, Iterator, Mapping
from contextlib import contextmanager
from dataclasses import dataclass, field
from functools import cached_property
from types import MappingProxyType
from typing import Any

import numpy as np

from esp.core.errors import ConfigError, DataError
from esp.core.kinematics import units as _units
from esp.core.kinematics.expr import (
    ZERO,
    Call,
    Expr,
    Name,
    Neg,
    Num,
    Pi,
    as_expr,
    check_name,
    check_size,
    size_estimate,
)
from esp.core.text import article, did_you_mean
from esp.core.values import config_number, shown

__all__ = [
    "AXES",
    "KINDS",
    "SLOTS",
    "Chain",
    "ErrorMotion",
    "Op",
    "Prismatic",
    "Revolute",
    "Rotate",
    "Step",
    "Symbol",
    "Translate",
    "check_finite",
    "error_motion",
    "prismatic",
    "revolute",
    "rotate",
    "translate",
]

#: axis name -> (index, sign)
AXES: dict[str, tuple[int, int]] = {
    "x": (0, 1),
    "y": (1, 1),
    "z": (2, 1),
    "-x": (0, -1),
    "-y": (1, -1),
    "-z": (2, -1),
}
KINDS = ("coordinate", "parameter", "error")
#: the six slots of an error motion: translations along and rotations about x, y, z
SLOTS = ("tx", "ty", "tz", "rx", "ry", "rz")
#: largest magnitude accepted for a value in mm or rad (every chain, also in code)
ABSURD = 1e9


def _axis(value: Any, key: str) -> str:
    if isinstance(value, str) and value in AXES:
        return value
    hint = did_you_mean(value, AXES) if isinstance(value, str) else ""
    raise ConfigError(
        key, f"expected an axis 'x', 'y', 'z', '-x', '-y' or '-z', found {value!r}{hint}"
    )


# -- symbols --------------------------------------------------------------------------------


@dataclass(frozen=True)
class Symbol:
    """A named quantity of a chain.

    Parameters
    ----------
    name : the symbol's name (ASCII: a letter, then letters, digits and ``_``)
    kind : ``"coordinate"``, ``"parameter"`` or ``"error"``
    unit : the unit its values are given in (``mm``, ``um``, ``deg``, ``rad``, ``urad``,
        ``arcsec`` ...); inside the chain the value is in mm or rad
    value : a default value in ``unit`` (parameters and errors only), or None
    description : what it is, in words
    """

    name: str
    kind: str
    unit: str
    value: float | None = None
    description: str = ""

    @property
    def dimension(self) -> str:
        """``"length"`` or ``"angle"``."""
        return _units.dimension_of(self.unit)

    @property
    def scale(self) -> float:
        """The factor that turns a value in :attr:`unit` into mm or rad."""
        return _units.factor(self.unit)


# -- steps ----------------------------------------------------------------------------------


@dataclass(frozen=True)
class Translate:
    """T(x, y, z): a translation by three quantities (mm)."""

    x: Expr = ZERO
    y: Expr = ZERO
    z: Expr = ZERO
    note: str = ""


@dataclass(frozen=True)
class Rotate:
    """A rotation by ``angle`` (radians inside expressions) about ``axis``, right-handed."""

    axis: str
    angle: Expr
    note: str = ""


@dataclass(frozen=True)
class ErrorMotion:
    """Six small errors about a pivot: translations ``tx, ty, tz`` (along x, y, z) and
    right-handed rotations ``rx, ry, rz`` (about +x, +y, +z), any of them None.

    As a transform: T(pivot) · T(t) · R(r) · T(−pivot), where R(r) is the exact rotation
    by the rotation vector r = (rx, ry, rz) (to first order I + [r]×, Loh et al. 2004
    eq. 2; the rotation vector favours no order of the three rotations at second order).
    Each slot must vanish when every small error is zero.
    """

    tx: Expr | None = None
    ty: Expr | None = None
    tz: Expr | None = None
    rx: Expr | None = None
    ry: Expr | None = None
    rz: Expr | None = None
    pivot: tuple[Expr, Expr, Expr] = (ZERO, ZERO, ZERO)
    note: str = ""

    def slots(self) -> dict[str, Expr]:
        """The slots that are set: name -> expression."""
        return {s: getattr(self, s) for s in SLOTS if getattr(self, s) is not None}


@dataclass(frozen=True)
class Prismatic:
    """A linear axis: translation along ``axis`` by ``coordinate`` (mm), then its error
    motion (if any) in the moving frame."""

    axis: str
    coordinate: str
    errors: ErrorMotion | None = None
    note: str = ""


@dataclass(frozen=True)
class Revolute:
    """A rotary axis: rotation about ``axis`` by ``coordinate`` (given in degrees unless
    its unit says otherwise), then its error motion (if any) in the moving frame."""

    axis: str
    coordinate: str
    errors: ErrorMotion | None = None
    note: str = ""


Step = Translate | Rotate | ErrorMotion | Prismatic | Revolute
_STEP_TYPES = (Translate, Rotate, ErrorMotion, Prismatic, Revolute)


# -- builders (accept numbers and text) -----------------------------------------------------


def translate(x: Any = 0, y: Any = 0, z: Any = 0, note: str = "") -> Translate:
    """T(x, y, z); each a number (mm, within ±100 m), a symbol name or an expression."""
    q = [_length_expr(v, f"translate.{c}") for v, c in zip((x, y, z), "xyz", strict=True)]
    return Translate(q[0], q[1], q[2], note)


def rotate(axis: str, angle: Any, note: str = "") -> Rotate:
    """A rotation about ``axis`` by ``angle`` (an expression in radians, or a symbol; write
    ``"deg(90)"`` for a fixed 90°)."""
    return Rotate(_axis(axis, "rotate"), as_expr(angle, "rotate.angle"), note)


def error_motion(
    tx: Any = None,
    ty: Any = None,
    tz: Any = None,
    rx: Any = None,
    ry: Any = None,
    rz: Any = None,
    pivot: Iterable[Any] = (0, 0, 0),
    note: str = "",
) -> ErrorMotion:
    """Six small errors about ``pivot`` (mm); each slot None, a name or an expression."""
    given = dict(tx=tx, ty=ty, tz=tz, rx=rx, ry=ry, rz=rz)
    slots = {k: (None if v is None else as_expr(v, f"errors.{k}")) for k, v in given.items()}
    return ErrorMotion(**slots, pivot=_pivot(pivot, "pivot"), note=note)


def _length_expr(v: Any, key: str) -> Expr:
    """A length of the chain (mm) as an :class:`Expr`; a number within ±100 m."""
    if isinstance(v, int | float) and not isinstance(v, bool):
        config_number(v, key, "position")
    return as_expr(v, key)


def _pivot(value: Any, key: str) -> tuple[Expr, Expr, Expr]:
    if isinstance(value, Mapping):
        extra = set(value) - {"x", "y", "z"}
        if extra:
            name = sorted(extra)[0]
            raise ConfigError(f"{key}.{name}", f"unknown key {name!r}; expected x, y, z")
        return tuple(_length_expr(value.get(c, 0), f"{key}.{c}") for c in "xyz")  # type: ignore[return-value]
    if isinstance(value, str) or not isinstance(value, Iterable):
        raise ConfigError(key, f"expected [x, y, z] (mm), found {value!r}")
    items = list(value)
    if len(items) != 3:
        raise ConfigError(key, f"expected [x, y, z] (mm), found {len(items)} values")
    return tuple(_length_expr(v, f"{key}.{c}") for v, c in zip(items, "xyz", strict=True))  # type: ignore[return-value]


def _joint_errors(errors: Any, pivot: Any) -> ErrorMotion | None:
    if errors is None:
        if pivot is not None and tuple(pivot) != (0, 0, 0):
            raise ConfigError("pivot", "a pivot without errors does nothing")
        return None
    if isinstance(errors, ErrorMotion):
        if pivot is not None:
            raise ConfigError("pivot", "give the pivot in the ErrorMotion, not twice")
        return errors
    if not isinstance(errors, Mapping):
        raise ConfigError("errors", f"expected a mapping of slots {SLOTS}, found {errors!r}")
    for k in errors:
        if k not in SLOTS:
            raise ConfigError(f"errors.{k}", f"unknown slot {k!r}{did_you_mean(k, SLOTS)}")
    return error_motion(**errors, pivot=(0, 0, 0) if pivot is None else pivot)


def prismatic(
    axis: str, coordinate: str, errors: Any = None, pivot: Any = None, note: str = ""
) -> Prismatic:
    """A linear axis along ``axis`` driven by ``coordinate``, with an optional error
    motion: a mapping ``{"tx": "EXX", ...}`` (or an :class:`ErrorMotion`) about ``pivot``."""
    return Prismatic(_axis(axis, "prismatic"), coordinate, _joint_errors(errors, pivot), note)


def revolute(
    axis: str, coordinate: str, errors: Any = None, pivot: Any = None, note: str = ""
) -> Revolute:
    """A rotary axis about ``axis`` driven by ``coordinate``, with an optional error motion
    (see :func:`prismatic`)."""
    return Revolute(_axis(axis, "revolute"), coordinate, _joint_errors(errors, pivot), note)


# -- elementary transforms ------------------------------------------------------------------


@dataclass(frozen=True)
class Op:
    """One elementary transform Ψ, lowered from a step.

    ``kind`` is ``"T"`` (``q`` = x, y, z), ``"R"`` (``q`` = (angle,), about ``axis`` with
    ``sign``) or ``"E"`` (``q`` = tx, ty, tz, rx, ry, rz, ZERO where unset; ``pivot``).
    ``keys`` name each quantity for messages (``steps[3].angle``); ``step`` is the 1-based
    index of the step it came from.
    """

    kind: str
    q: tuple[Expr, ...]
    keys: tuple[str, ...]
    step: int
    axis: int = 0
    sign: int = 1
    pivot: tuple[Expr, ...] = ()
    pivot_keys: tuple[str, ...] = ()


def _fold_zero(e: Expr, errors: Iterable[str]) -> Expr:
    """``e`` with every error set to zero, constants folded."""
    return e.substitute({n: ZERO for n in errors}).folded()


# -- the chain ------------------------------------------------------------------------------


class Chain:
    """A kinematic chain: steps from the base (workpiece side) to the tool tip.

    Parameters
    ----------
    steps : the steps in order, base first (:func:`translate`, :func:`rotate`,
        :func:`prismatic`, :func:`revolute`, :func:`error_motion`)
    symbols : declarations, name -> :class:`Symbol`, a kind (``"parameter"``), or a
        mapping with ``kind`` and optionally ``unit``, ``value``, ``description``. A joint's
        coordinate and the names in an error motion's slots are declared by that use;
        every other name must be declared here.
    name, description : for reports
    definitions : named sub-expressions, name -> expression; they are substituted into
        the steps (a definition may use others; a cycle is refused)
    strict : when True (chain files), every symbol must be declared in ``symbols``
    source : the file the chain came from, for messages

    Raises
    ------
    ConfigError
        An empty chain, an unknown symbol, a joint without a coordinate, a symbol used as two
        kinds or as both a length and an angle, a unit that does not fit, an error-motion
        slot that holds no small error or does not vanish when the errors are zero, a
        cyclic definition. The key names the step (``steps[3].coordinate``, 1-based) or the
        symbol (``symbols.G.unit``).
    """

    def __init__(
        self,
        steps: Iterable[Step],
        symbols: Mapping[str, Any] | None = None,
        *,
        name: str = "",
        description: str = "",
        definitions: Mapping[str, Any] | None = None,
        strict: bool = False,
        source: str | None = None,
    ):
        self.name = str(name)
        self.description = str(description)
        self.source = source
        try:
            self._build(steps, symbols or {}, definitions or {}, strict)
        except ConfigError as exc:
            if source and exc.path is None:
                raise ConfigError(exc.key, exc.message, source) from None
            raise

    # -- construction ------------------------------------------------------------------

    def _build(self, steps: Any, symbols: Any, definitions: Any, strict: bool) -> None:
        if isinstance(steps, str | bytes) or not isinstance(steps, Iterable):
            raise ConfigError("steps", f"expected a sequence of steps, found {steps!r}")
        steps = tuple(steps)
        if not steps:
            raise ConfigError("steps", "empty chain: expected at least one step")
        for i, s in enumerate(steps, 1):
            if not isinstance(s, _STEP_TYPES):
                raise ConfigError(f"steps[{i}]", f"expected a chain step, found {s!r}")
        declared = {n: self._declaration(n, d) for n, d in dict(symbols).items()}
        defs = _definitions(definitions, declared)
        if defs:
            _check_step_sizes(steps, defs)
            steps = tuple(_substitute_step(s, defs) for s in steps)
        self.steps: tuple[Step, ...] = steps
        self.definitions = MappingProxyType({n: str(e) for n, e in defs.items()})

        uses = _Uses()
        for i, step in enumerate(steps, 1):
            uses.step(step, f"steps[{i}]")

        # kinds: declared, or declared by use (joint coordinates, error slots)
        kinds: dict[str, str] = {n: d["kind"] for n, d in declared.items()}
        for n, (kind, key) in uses.kind_by_use.items():
            if n in kinds and kinds[n] != kind:
                raise ConfigError(
                    key,
                    f"{n!r} is declared {article(kinds[n])} (symbols.{n}.kind) but is used as "
                    f"{article(kind)} here; a symbol has one kind",
                )
            if n not in kinds:
                if strict and kind == "coordinate":
                    raise ConfigError(key, f'unknown symbol {n!r}: declare it, {n} = "coordinate"')
                kinds.setdefault(n, kind)
        for n, key in uses.first_key.items():
            if n not in kinds or (strict and n not in declared):
                raise ConfigError(key, f"unknown symbol {n!r}{did_you_mean(n, list(kinds))}")
        # an error slot must hold an error, and vanish with the errors
        errors = {n for n, k in kinds.items() if k == "error"}
        for slot_expr, key in uses.error_slots:
            if not (slot_expr.names() & errors):
                raise ConfigError(
                    key,
                    f"{str(slot_expr)!r} holds no small error; a large offset or angle "
                    "belongs in a translate or rotate step",
                )
            rest = _fold_zero(slot_expr, errors)
            if not rest.is_zero():
                raise ConfigError(
                    key,
                    f"{str(slot_expr)!r} must vanish when every small error is zero, "
                    f"but leaves {str(rest)!r}",
                )
        for pivot_expr, key in uses.pivots:
            bad = sorted(pivot_expr.names() & errors)
            if bad:
                raise ConfigError(key, f"a pivot is nominal geometry; {bad[0]!r} is a small error")

        # dimensions and units
        dims: dict[str, tuple[str, str]] = {}
        for n, dim, key in uses.dimensions:
            if n in dims and dims[n][0] != dim:
                other_dim, other_key = dims[n]
                raise ConfigError(
                    key,
                    f"{n!r} is used as {article(dim)} here but as {article(other_dim)} "
                    f"at {other_key}",
                )
            dims.setdefault(n, (dim, key))
        table: dict[str, Symbol] = {}
        order = list(dict.fromkeys(list(declared) + list(uses.first_key)))
        for n in order:
            kind = kinds[n]
            d = declared.get(n, {})
            unit = d.get("unit")
            inferred = dims.get(n, (None, ""))[0]
            if unit is not None and inferred is not None and _units.dimension_of(unit) != inferred:
                raise ConfigError(
                    f"symbols.{n}.unit",
                    f"{unit!r} is a unit of {_units.dimension_of(unit)}, but {n!r} is used as "
                    f"{article(inferred)} at {dims[n][1]}",
                )
            if unit is None:
                if inferred is None:
                    how = "its use" if n in uses.first_key else "its use (it is not used)"
                    raise ConfigError(
                        f"symbols.{n}.unit",
                        f"cannot tell whether {n!r} is a length or an angle from {how}; "
                        'give its unit (e.g. unit = "mm" or unit = "deg")',
                    )
                unit = _units.DEFAULT_UNITS[(kind, inferred)]
            value = d.get("value")
            if value is not None and kind == "coordinate":
                raise ConfigError(
                    f"symbols.{n}.value",
                    "a coordinate has no default value; give it where the chain is evaluated",
                )
            table[n] = Symbol(n, kind, unit, value, d.get("description", ""))
        self.symbols: Mapping[str, Symbol] = MappingProxyType(table)
        self._joint_errors = {
            c: [n for n in names if kinds.get(n) == "error"]
            for c, names in uses.joint_errors.items()
        }

    @staticmethod
    def _declaration(name: str, d: Any) -> dict[str, Any]:
        key = f"symbols.{name}"
        check_name(name, key)
        if isinstance(d, Symbol):
            if d.name != name:
                raise ConfigError(key, f"the Symbol is named {d.name!r}")
            d = {"kind": d.kind, "unit": d.unit, "value": d.value, "description": d.description}
        elif isinstance(d, str):
            if d not in KINDS:
                raise ConfigError(
                    key,
                    "expected a kind 'coordinate', 'parameter' or 'error', "
                    f"found {d!r}{did_you_mean(d, KINDS)}",
                )
            d = {"kind": d}
        elif not isinstance(d, Mapping):
            raise ConfigError(key, f"expected a kind or a table with 'kind', found {d!r}")
        allowed = ("kind", "unit", "value", "description")
        for k in d:
            if k not in allowed:
                raise ConfigError(
                    f"{key}.{k}",
                    f"unknown key {k!r}{did_you_mean(k, allowed)} (expected one of "
                    + ", ".join(repr(a) for a in allowed)
                    + ")",
                )
        kind = d.get("kind")
        if kind not in KINDS:
            hint = did_you_mean(kind, KINDS) if isinstance(kind, str) else ""
            raise ConfigError(
                f"{key}.kind",
                f"expected a kind 'coordinate', 'parameter' or 'error', found {kind!r}{hint}",
            )
        out: dict[str, Any] = {"kind": kind}
        if d.get("unit") is not None:
            unit = _units.canonical(d["unit"])
            if unit is None:
                raise ConfigError(
                    f"{key}.unit",
                    f"unknown unit {d['unit']!r}; expected one of " + ", ".join(_units.UNITS),
                )
            out["unit"] = unit
        if d.get("value") is not None:
            out["value"] = config_number(d["value"], f"{key}.value")
        desc = d.get("description", "")
        if not isinstance(desc, str):
            raise ConfigError(f"{key}.description", f"expected text, found {desc!r}")
        out["description"] = desc
        return out

    # -- what the chain holds --------------------------------------------------------------

    def _names(self, kind: str) -> tuple[str, ...]:
        return tuple(n for n, s in self.symbols.items() if s.kind == kind)

    @property
    def coordinates(self) -> tuple[str, ...]:
        """The coordinate names, in order of first use."""
        return self._names("coordinate")

    @property
    def parameters(self) -> tuple[str, ...]:
        return self._names("parameter")

    @property
    def errors(self) -> tuple[str, ...]:
        """The small errors, in order of first use."""
        return self._names("error")

    def joint_errors(self) -> dict[str, tuple[str, ...]]:
        """coordinate -> the errors in the error motion of the joint it drives (the errors
        that are functions of that coordinate, in a machine's error model)."""
        return {c: tuple(e) for c, e in self._joint_errors.items()}

    @cached_property
    def ops(self) -> tuple[Op, ...]:
        """The elementary transforms Ψ_1 … Ψ_N, base first."""
        out: list[Op] = []
        for i, step in enumerate(self.steps, 1):
            out.extend(_lower(step, i))
        return tuple(out)

    def __repr__(self) -> str:
        return f"Chain({self.name!r}, {len(self.steps)} steps)"

    # -- values at the boundary ------------------------------------------------------------

    @contextmanager
    def named(self) -> Iterator[None]:
        """Within it, a ConfigError or DataError gets the chain's file name in front."""
        try:
            yield
        except ConfigError as exc:
            if self.source and exc.path is None:
                raise ConfigError(exc.key, exc.message, self.source) from None
            raise
        except DataError as exc:
            if self.source and not str(exc).startswith(f"{self.source}: "):
                raise DataError(f"{self.source}: {exc}") from None
            raise

    def environment(
        self,
        coordinates: Mapping[str, Any] | None,
        parameters: Mapping[str, Any] | None,
        errors: Mapping[str, Any] | None = None,
        *,
        error_defaults: bool = False,
    ) -> tuple[dict[str, Any], int]:
        """Check and convert values given in each symbol's unit into mm and rad.

        Coordinates are required; a parameter not given takes its default value; an error
        not given is zero (or its default value with ``error_defaults``). Each value is a
        number or a 1-D array; arrays must share one length N.

        Returns
        -------
        env : name -> float or float64 array (N,), in mm and rad
        n : the number of points N (1 when every value is a number)
        """
        with self.named():
            return self._environment(coordinates, parameters, errors, error_defaults)

    def _environment(
        self,
        coordinates: Mapping[str, Any] | None,
        parameters: Mapping[str, Any] | None,
        errors: Mapping[str, Any] | None,
        error_defaults: bool,
    ) -> tuple[dict[str, Any], int]:
        env: dict[str, Any] = {}
        lengths: dict[int, str] = {}
        groups = (
            ("coordinates", "coordinate", coordinates),
            ("parameters", "parameter", parameters),
            ("errors", "error", errors),
        )
        for group, kind, given in groups:
            if given is None:
                given = {}
            if not isinstance(given, Mapping):
                raise ConfigError(group, f"expected a mapping of name -> value, found {given!r}")
            for n, v in given.items():
                sym = self.symbols.get(n)
                key = f"{group}.{n}"
                if sym is None:
                    names = self._names(kind)
                    raise ConfigError(
                        key,
                        f"not {article(kind)} of this chain{did_you_mean(n, names)} "
                        f"({kind}s: {', '.join(names) or 'none'})",
                    )
                if sym.kind != kind:
                    raise ConfigError(key, f"{n!r} is {article(sym.kind)}, not {article(kind)}")
                arr = _values(v, key)
                _in_range(sym, arr, key, v)
                if arr.ndim == 1:
                    lengths.setdefault(arr.shape[0], key)
                env[n] = arr * sym.scale
        long = {k: v for k, v in lengths.items() if k != 1}
        if len(long) > 1:
            (n1, k1), (n2, k2) = sorted(long.items())[:2]
            raise ConfigError(k2, f"{n2} values, but {k1} has {n1}; give arrays of one length")
        size = next(iter(long), 1)
        for name, sym in self.symbols.items():
            if name in env:
                continue
            if sym.kind == "coordinate":
                raise ConfigError(f"coordinates.{name}", "missing: every coordinate needs a value")
            if sym.kind == "parameter":
                if sym.value is None:
                    raise ConfigError(
                        f"parameters.{name}",
                        f"no value: give one, or a default (symbols.{name}.value)",
                    )
                _in_range(sym, np.float64(sym.value), f"symbols.{name}.value", sym.value)
                env[name] = np.float64(sym.value * sym.scale)
            else:
                v = sym.value if (error_defaults and sym.value is not None) else 0.0
                _in_range(sym, np.float64(v), f"symbols.{name}.value", v)
                env[name] = np.float64(v * sym.scale)
        for name, v in env.items():
            if np.ndim(v) == 0:
                env[name] = np.float64(v)
            elif v.shape[0] == 1 and size != 1:
                env[name] = np.float64(v[0])
        return env, size


def _in_range(sym: Symbol, arr: np.ndarray | np.float64, key: str, given: Any) -> None:
    """Refuse a value beyond :data:`ABSURD` in mm or rad, shown as given: no value of any
    chain can be that large. The physical range of each kind of symbol (an error at most
    10 mm or 0.1 rad, a parameter at most 100 m or one turn: :func:`esp.core.values.check_symbol`)
    is checked where values enter esp -- head and table files, files of error values,
    ``--set`` -- so that a chain evaluated in code may still take a large error motion
    (the exact chain is the referee of the first-order models at any angle)."""
    flat = arr.reshape(-1)
    if flat.size == 0:
        return
    i = int(np.argmax(np.abs(flat)))
    if not abs(float(flat[i]) * sym.scale) > ABSURD:
        return
    shown_value = given if np.ndim(given) == 0 else float(flat[i])
    si = "mm" if _units.dimension_of(sym.unit) == _units.LENGTH else "rad"
    both = "" if sym.unit == si else f" ({ABSURD:g} {si})"
    raise ConfigError(
        key,
        f"expected a value within ±{ABSURD / sym.scale:g} {sym.unit}{both}, "
        f"found {shown(shown_value)}",
    )


def _values(v: Any, key: str) -> np.ndarray:
    """A number or a 1-D array of finite numbers as float64."""
    if isinstance(v, bool | str | bytes) or v is None:
        raise ConfigError(key, f"expected a number, found {v!r}")
    try:
        arr = np.asarray(v, dtype=float)
    except (TypeError, ValueError):
        raise ConfigError(key, f"expected a number or an array of numbers, found {v!r}") from None
    if arr.ndim > 1:
        raise ConfigError(key, f"expected a number or a 1-D array, found shape {arr.shape}")
    if arr.ndim == 1 and arr.shape[0] == 0:
        raise ConfigError(key, "expected at least one value, found an empty array")
    if not np.all(np.isfinite(arr)):
        raise ConfigError(key, "expected finite numbers, found NaN or infinity")
    return arr


# -- helpers of construction ----------------------------------------------------------------


def _definitions(definitions: Mapping[str, Any], declared: Mapping[str, Any]) -> dict[str, Expr]:
    """Parse named sub-expressions and inline them into each other; refuse cycles."""
    raw: dict[str, Expr] = {}
    for n, text in dict(definitions).items():
        key = f"definitions.{n}"
        check_name(n, key)
        if n in declared:
            raise ConfigError(key, f"{n!r} is also declared in symbols; a name has one meaning")
        raw[n] = as_expr(text, key)
    done: dict[str, Expr] = {}
    sizes: dict[str, tuple[int, int]] = {}

    def resolve(n: str, path: tuple[str, ...]) -> Expr:
        if n in done:
            return done[n]
        if n in path:
            cycle = " -> ".join(path[path.index(n) :] + (n,))
            raise ConfigError(f"definitions.{n}", f"cyclic definition: {cycle}")
        e = raw[n]
        subs = {m: resolve(m, path + (n,)) for m in e.names() if m in raw}
        # the size after substitution, from the sizes of the definitions it names: refused
        # before a tree that grows multiplicatively is formed or derived (expr.check_size)
        sizes[n] = size_estimate(e, sizes)
        check_size(sizes[n], f"definitions.{n}")
        done[n] = e.substitute(subs) if subs else e
        return done[n]

    for n in raw:
        resolve(n, ())
    return done


def _check_step_sizes(steps: tuple[Step, ...], defs: Mapping[str, Expr]) -> None:
    """Refuse a step whose expressions grow beyond :func:`expr.check_size` once the
    definitions are substituted (estimated from each definition's own size)."""
    sizes = {n: size_estimate(e) for n, e in defs.items()}  # each within the bounds
    for i, step in enumerate(steps, 1):
        found: list[tuple[str, Any]] = []
        if isinstance(step, Translate):
            found = [(f"translate.{c}", getattr(step, c)) for c in "xyz"]
        elif isinstance(step, Rotate):
            found = [("angle", step.angle)]
        else:
            motion = step if isinstance(step, ErrorMotion) else step.errors
            if motion is not None:
                found = [(f"errors.{slot}", getattr(motion, slot)) for slot in SLOTS]
                found += [(f"pivot[{k}]", p) for k, p in enumerate(motion.pivot)]
        for where, e in found:
            if isinstance(e, Expr):
                check_size(size_estimate(e, sizes), f"steps[{i}].{where}")


def _substitute_step(step: Step, defs: Mapping[str, Expr]) -> Step:
    def sub(e: Any) -> Any:
        return None if e is None else e.substitute(defs)

    if isinstance(step, Translate):
        return Translate(sub(step.x), sub(step.y), sub(step.z), step.note)
    if isinstance(step, Rotate):
        return Rotate(step.axis, sub(step.angle), step.note)
    if isinstance(step, ErrorMotion):
        slots = {s: sub(getattr(step, s)) for s in SLOTS}
        return ErrorMotion(
            **slots,
            pivot=tuple(sub(p) for p in step.pivot),  # type: ignore[arg-type]
            note=step.note,
        )
    if step.coordinate in defs:
        raise ConfigError(
            f"definitions.{step.coordinate}", "a joint's coordinate cannot be a definition"
        )
    errors = step.errors and _substitute_step(step.errors, defs)
    return type(step)(step.axis, step.coordinate, errors, step.note)  # type: ignore[arg-type]


@dataclass
class _Uses:
    """What the steps do with each name."""

    first_key: dict[str, str] = field(default_factory=dict)
    kind_by_use: dict[str, tuple[str, str]] = field(default_factory=dict)
    dimensions: list[tuple[str, str, str]] = field(default_factory=list)
    error_slots: list[tuple[Expr, str]] = field(default_factory=list)
    pivots: list[tuple[Expr, str]] = field(default_factory=list)
    joint_errors: dict[str, list[str]] = field(default_factory=dict)

    def name(self, n: str, key: str) -> None:
        check_name(n, key)
        self.first_key.setdefault(n, key)

    def expr(self, e: Expr, dim: str, key: str) -> None:
        if not isinstance(e, Expr):
            raise ConfigError(key, f"expected an expression, found {e!r}")
        for n in sorted(e.names()):
            self.name(n, key)
        _infer(e, dim, key, self.dimensions)

    def step(self, step: Step, where: str) -> None:
        L, A = _units.LENGTH, _units.ANGLE
        if isinstance(step, Translate):
            for c in "xyz":
                self.expr(getattr(step, c), L, f"{where}.translate.{c}")
        elif isinstance(step, Rotate):
            _axis(step.axis, f"{where}.rotate")
            e = step.angle
            key = f"{where}.angle"
            folded = e.folded() if isinstance(e, Expr) else e
            if isinstance(folded, Num) and folded.value != 0 and not _has_call(e, "deg"):
                raise ConfigError(
                    key,
                    f"a bare number is ambiguous as an angle: write deg({str(e)}) for degrees "
                    "or an expression of pi for radians",
                )
            self.expr(e, A, key)
        elif isinstance(step, ErrorMotion):
            self.motion(step, where, joint=None)
        else:
            kind = "prismatic" if isinstance(step, Prismatic) else "revolute"
            _axis(step.axis, f"{where}.{kind}")
            c = step.coordinate
            key = f"{where}.coordinate"
            if c is None or c == "":
                raise ConfigError(
                    key,
                    f'a {kind} joint needs the coordinate that drives it (e.g. coordinate = "X")',
                )
            self.name(c, key)
            prev = self.kind_by_use.get(c)
            if prev is not None and prev[0] != "coordinate":
                raise ConfigError(key, f"{c!r} is used as {article(prev[0])} at {prev[1]}")
            self.kind_by_use.setdefault(c, ("coordinate", key))
            self.dimensions.append((c, L if kind == "prismatic" else A, key))
            if step.errors is not None:
                self.motion(step.errors, where, joint=c)

    def motion(self, m: ErrorMotion, where: str, joint: str | None) -> None:
        slots = m.slots()
        if not slots:
            raise ConfigError(f"{where}.errors", "an error motion needs at least one slot")
        for s, e in slots.items():
            key = f"{where}.errors.{s}"
            self.expr(e, _units.LENGTH if s[0] == "t" else _units.ANGLE, key)
            for n in sorted(e.names()):
                if isinstance(e, Name) or (isinstance(e, Neg) and isinstance(e.arg, Name)):
                    prev = self.kind_by_use.get(n)
                    if prev is not None and prev[0] != "error":
                        raise ConfigError(key, f"{n!r} is used as {article(prev[0])} at {prev[1]}")
                    self.kind_by_use.setdefault(n, ("error", key))
            self.error_slots.append((e, key))
            if joint is not None:
                for n in sorted(e.names()):
                    self.joint_errors.setdefault(joint, [])
                    if n not in self.joint_errors[joint]:
                        self.joint_errors[joint].append(n)
        if len(m.pivot) != 3:
            raise ConfigError(f"{where}.pivot", "expected [x, y, z]")
        for c, p in zip("xyz", m.pivot, strict=True):
            key = f"{where}.pivot.{c}"
            self.expr(p, _units.LENGTH, key)
            self.pivots.append((p, key))


def _has_call(e: Expr, func: str) -> bool:
    if isinstance(e, Call):
        return e.func == func or _has_call(e.arg, func)
    if isinstance(e, Neg):
        return _has_call(e.arg, func)
    if hasattr(e, "left"):
        return _has_call(e.left, func) or _has_call(e.right, func)  # type: ignore[attr-defined]
    return False


def _dimensionless(e: Expr) -> bool:
    """True for a number, pi, a trig function, or products and quotients of those."""
    if isinstance(e, Num | Pi):
        return True
    if isinstance(e, Call):
        return e.func in ("sin", "cos", "tan") or not e.names()
    if isinstance(e, Neg):
        return _dimensionless(e.arg)
    if hasattr(e, "op") and e.op in "*/":  # type: ignore[attr-defined]
        return _dimensionless(e.left) and _dimensionless(e.right)  # type: ignore[attr-defined]
    return False


def _infer(e: Expr, dim: str | None, key: str, out: list[tuple[str, str, str]]) -> None:
    """Record the dimension of each name whose dimension the expression shows: a name in a
    slot of known dimension (alone, negated, summed, or scaled by a dimensionless factor)
    has that dimension; the argument of sin, cos, tan is an angle."""
    if isinstance(e, Name):
        if dim is not None:
            out.append((e.name, dim, key))
    elif isinstance(e, Neg):
        _infer(e.arg, dim, key, out)
    elif isinstance(e, Call):
        if e.func in ("sin", "cos", "tan"):
            _infer(e.arg, _units.ANGLE, key, out)
    elif hasattr(e, "op"):
        a, b, op = e.left, e.right, e.op  # type: ignore[attr-defined]
        if op in "+-":
            _infer(a, dim, key, out)
            _infer(b, dim, key, out)
        elif op == "*":
            _infer(a, dim if _dimensionless(b) else None, key, out)
            _infer(b, dim if _dimensionless(a) else None, key, out)
        else:
            _infer(a, dim if _dimensionless(b) else None, key, out)
            _infer(b, None, key, out)


def _lower(step: Step, i: int) -> list[Op]:
    where = f"steps[{i}]"
    if isinstance(step, Translate):
        keys = tuple(f"{where}.translate.{c}" for c in "xyz")
        return [Op("T", (step.x, step.y, step.z), keys, i)]
    if isinstance(step, Rotate):
        ax, sg = AXES[step.axis]
        return [Op("R", (step.angle,), (f"{where}.angle",), i, ax, sg)]
    if isinstance(step, ErrorMotion):
        return [_motion_op(step, where, i)]
    ax, sg = AXES[step.axis]
    name = Name(step.coordinate)
    key = (f"{where}.coordinate",)
    if isinstance(step, Prismatic):
        q: list[Expr] = [ZERO, ZERO, ZERO]
        q[ax] = name if sg > 0 else Neg(name)
        keys = key * 3
        ops = [Op("T", tuple(q), keys, i)]
    else:
        ops = [Op("R", (name,), key, i, ax, sg)]
    if step.errors is not None:
        ops.append(_motion_op(step.errors, where, i))
    return ops


def _motion_op(m: ErrorMotion, where: str, i: int) -> Op:
    q = tuple(ZERO if getattr(m, s) is None else getattr(m, s) for s in SLOTS)
    keys = tuple(f"{where}.errors.{s}" for s in SLOTS)
    pkeys = tuple(f"{where}.pivot.{c}" for c in "xyz")
    return Op("E", q, keys, i, pivot=tuple(m.pivot), pivot_keys=pkeys)


def check_finite(value: Any, key: str, expr: Expr) -> Any:
    """``value`` if every element is finite, else DataError naming the quantity."""
    if np.all(np.isfinite(value)):
        return value
    raise DataError(
        f"{key}: {str(expr)!r} is not finite at the given values "
        "(a division by zero, or tan of a right angle)"
    )
