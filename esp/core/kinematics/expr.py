"""Quantities of a kinematic chain: numbers, names and small expressions.

A quantity in a chain file or in code is a number, a symbol name, or a short formula such
as ``"-e/tan(Yp)"`` (Freeman & Ford 2003, the translation T(0, −e, −e/tan Y_p) of the angle
head). One parser reads them all: Python's :mod:`ast` with a whitelist of node types, so
nothing is ever evaluated as Python. Allowed are

* numbers (``20``, ``0.5``, ``1e-3``), the constant ``pi``;
* names of symbols (letters, digits and ``_``, starting with a letter);
* ``+ - * /``, unary ``-`` and ``+``, parentheses;
* ``sin``, ``cos``, ``tan`` of one argument, and ``deg(number)``, which turns a number of
  degrees into radians (``deg(90)`` is ``pi/2``).

An :class:`Expr` evaluates with numpy (vectorised over points), differentiates itself
exactly (a small tree derivative, no finite differences), propagates truncated Taylor
series in a scale factor λ (:class:`Jet`, used for the first- and second-order terms), and
converts to a sympy expression (sympy is imported by the caller, never here).

Inside expressions every length is in mm and every angle in radians, whatever unit a
symbol's values are given in; the chain converts values once, at its boundary.
"""

from __future__ import annotations

import ast
import keyword
import math
import re
from collections.abc import Callable, Iterable, Mapping
from fractions import Fraction
from typing import Any

import numpy as np

from esp.core.errors import ConfigError
from esp.core.values import config_number

__all__ = [
    "FUNCTIONS",
    "MAX_EXPANDED_TERMS",
    "MAX_NODES",
    "RESERVED",
    "Expr",
    "Jet",
    "as_expr",
    "check_name",
    "check_size",
    "parse_expr",
    "size_estimate",
]

#: functions an expression may call
FUNCTIONS = ("sin", "cos", "tan", "deg")
#: names that cannot be symbols
RESERVED = frozenset(FUNCTIONS) | {"pi"}
#: longest accepted expression text
MAX_LENGTH = 400
_NAME = re.compile(r"^[A-Za-z][A-Za-z0-9_]*$")
#: most nodes of one expression once the definitions it names are substituted into it
MAX_NODES = 20_000
#: most terms of one expression multiplied out (an upper bound: the terms of a sum add, of
#: a product multiply), the work of deriving its formulae with sympy. Nested definitions
#: such as ``d1 = "d0*d0 + d0"`` square it at each level: six levels of a three-term
#: ``d0`` are about 1e39 terms, beyond any computer
MAX_EXPANDED_TERMS = 1_000_000
_SATURATED = 10**30  # sizes are counted up to here, so that the counting stays cheap


def check_name(name: Any, key: str) -> str:
    """``name`` if it can name a symbol, else ConfigError at ``key``."""
    if not isinstance(name, str) or not _NAME.match(name):
        raise ConfigError(
            key,
            f"expected a symbol name (a letter, then letters, digits or '_'), found {name!r}",
        )
    if name in RESERVED or keyword.iskeyword(name):
        raise ConfigError(key, f"{name!r} is a reserved word and cannot name a symbol")
    return name


# -- the nodes ------------------------------------------------------------------------------


class Expr:
    """An immutable expression tree. Build one with :func:`parse_expr` or :func:`as_expr`."""

    __slots__ = ()

    # structure
    def names(self) -> frozenset[str]:
        raise NotImplementedError

    def substitute(self, mapping: Mapping[str, Expr]) -> Expr:
        """This expression with each name in ``mapping`` replaced by its expression."""
        raise NotImplementedError

    # numbers
    def evaluate(self, env: Mapping[str, Any]) -> Any:
        """The value, with each name looked up in ``env`` (floats or numpy arrays)."""
        raise NotImplementedError

    def diff(self, name: str) -> Expr:
        """The exact derivative with respect to ``name``, as an expression."""
        raise NotImplementedError

    def jet(self, env: Mapping[str, Jet], math_: Any) -> Jet:
        """The truncated Taylor series of the value, with each name a :class:`Jet` in
        ``env``; ``math_`` provides ``sin``, ``cos``, ``tan`` (numpy or sympy)."""
        raise NotImplementedError

    def to_sympy(self, sp: Any, symbols: Mapping[str, Any]) -> Any:
        """The sympy expression (``sp`` is the sympy module, ``symbols`` name -> Symbol)."""
        raise NotImplementedError

    # constant folding
    def folded(self) -> Expr:
        """The expression with constant sub-expressions computed and ``0*x``, ``x+0``,
        ``x*1`` removed."""
        return self

    def is_zero(self) -> bool:
        return isinstance(self, Num) and self.value == 0

    # display
    precedence = 100

    def __str__(self) -> str:
        raise NotImplementedError

    def __repr__(self) -> str:
        return f"Expr({str(self)!r})"

    def __eq__(self, other: object) -> bool:
        return isinstance(other, Expr) and type(self) is type(other) and self._key() == other._key()

    def __hash__(self) -> int:
        return hash((type(self).__name__, self._key()))

    def _key(self) -> tuple[Any, ...]:
        raise NotImplementedError


class Num(Expr):
    """A number; ``text`` is how it was written (kept for an exact sympy rational)."""

    __slots__ = ("text", "value")

    def __init__(self, value: float, text: str | None = None):
        self.value = float(value)
        self.text = text if text is not None else repr(self.value)

    def names(self) -> frozenset[str]:
        return frozenset()

    def substitute(self, mapping: Mapping[str, Expr]) -> Expr:
        return self

    def evaluate(self, env: Mapping[str, Any]) -> Any:
        return self.value

    def diff(self, name: str) -> Expr:
        return ZERO

    def jet(self, env: Mapping[str, Jet], math_: Any) -> Jet:
        if math_ is not np:  # sympy: an exact number
            return Jet((self.to_sympy(math_, {}),))
        return Jet((self.value,))

    def to_sympy(self, sp: Any, symbols: Mapping[str, Any]) -> Any:
        if float(self.value).is_integer() and abs(self.value) < 1e15:
            return sp.Integer(int(self.value))
        try:
            return sp.Rational(Fraction(self.text))
        except (ValueError, ZeroDivisionError):
            return sp.Rational(Fraction(self.value))

    def __str__(self) -> str:
        v = self.value
        if v.is_integer() and abs(v) < 1e15:
            return str(int(v))
        return self.text if _is_plain_number(self.text) else repr(v)

    def _key(self) -> tuple[Any, ...]:
        return (self.value,)


class Pi(Expr):
    """The constant π."""

    __slots__ = ()

    def names(self) -> frozenset[str]:
        return frozenset()

    def substitute(self, mapping: Mapping[str, Expr]) -> Expr:
        return self

    def evaluate(self, env: Mapping[str, Any]) -> Any:
        return math.pi

    def diff(self, name: str) -> Expr:
        return ZERO

    def jet(self, env: Mapping[str, Jet], math_: Any) -> Jet:
        return Jet((math_.pi,))

    def to_sympy(self, sp: Any, symbols: Mapping[str, Any]) -> Any:
        return sp.pi

    def __str__(self) -> str:
        return "pi"

    def _key(self) -> tuple[Any, ...]:
        return ()


class Name(Expr):
    """A symbol."""

    __slots__ = ("name",)

    def __init__(self, name: str):
        self.name = name

    def names(self) -> frozenset[str]:
        return frozenset((self.name,))

    def substitute(self, mapping: Mapping[str, Expr]) -> Expr:
        return mapping.get(self.name, self)

    def evaluate(self, env: Mapping[str, Any]) -> Any:
        return env[self.name]

    def diff(self, name: str) -> Expr:
        return ONE if name == self.name else ZERO

    def jet(self, env: Mapping[str, Jet], math_: Any) -> Jet:
        return env[self.name]

    def to_sympy(self, sp: Any, symbols: Mapping[str, Any]) -> Any:
        return symbols[self.name]

    def __str__(self) -> str:
        return self.name

    def _key(self) -> tuple[Any, ...]:
        return (self.name,)


class Neg(Expr):
    __slots__ = ("arg",)
    precedence = 3

    def __init__(self, arg: Expr):
        self.arg = arg

    def names(self) -> frozenset[str]:
        return self.arg.names()

    def substitute(self, mapping: Mapping[str, Expr]) -> Expr:
        return Neg(self.arg.substitute(mapping))

    def evaluate(self, env: Mapping[str, Any]) -> Any:
        return -self.arg.evaluate(env)

    def diff(self, name: str) -> Expr:
        return _neg(self.arg.diff(name))

    def jet(self, env: Mapping[str, Jet], math_: Any) -> Jet:
        return -self.arg.jet(env, math_)

    def to_sympy(self, sp: Any, symbols: Mapping[str, Any]) -> Any:
        return -self.arg.to_sympy(sp, symbols)

    def folded(self) -> Expr:
        return _neg(self.arg.folded())

    def __str__(self) -> str:
        return "-" + _wrap(self.arg, self.precedence + (1 if isinstance(self.arg, Neg) else 0))

    def _key(self) -> tuple[Any, ...]:
        return (self.arg,)


class BinOp(Expr):
    __slots__ = ("left", "op", "right")

    def __init__(self, op: str, left: Expr, right: Expr):
        self.op = op
        self.left = left
        self.right = right

    @property
    def precedence(self) -> int:  # type: ignore[override]
        return 1 if self.op in "+-" else 2

    def names(self) -> frozenset[str]:
        return self.left.names() | self.right.names()

    def substitute(self, mapping: Mapping[str, Expr]) -> Expr:
        return BinOp(self.op, self.left.substitute(mapping), self.right.substitute(mapping))

    def evaluate(self, env: Mapping[str, Any]) -> Any:
        a = self.left.evaluate(env)
        b = self.right.evaluate(env)
        if self.op == "+":
            return a + b
        if self.op == "-":
            return a - b
        if self.op == "*":
            return a * b
        return _divide(a, b)

    def diff(self, name: str) -> Expr:
        a, b = self.left, self.right
        da, db = a.diff(name), b.diff(name)
        if self.op == "+":
            return _add(da, db)
        if self.op == "-":
            return _sub(da, db)
        if self.op == "*":
            return _add(_mul(da, b), _mul(a, db))
        # (a/b)' = a'/b - a b' / b^2
        return _sub(_div(da, b), _div(_mul(a, db), _mul(b, b)))

    def jet(self, env: Mapping[str, Jet], math_: Any) -> Jet:
        a = self.left.jet(env, math_)
        b = self.right.jet(env, math_)
        if self.op == "+":
            return a + b
        if self.op == "-":
            return a - b
        if self.op == "*":
            return a * b
        return a / b

    def to_sympy(self, sp: Any, symbols: Mapping[str, Any]) -> Any:
        a = self.left.to_sympy(sp, symbols)
        b = self.right.to_sympy(sp, symbols)
        if self.op == "+":
            return a + b
        if self.op == "-":
            return a - b
        if self.op == "*":
            return a * b
        return a / b

    def folded(self) -> Expr:
        a, b = self.left.folded(), self.right.folded()
        return {"+": _add, "-": _sub, "*": _mul, "/": _div}[self.op](a, b)

    def __str__(self) -> str:
        p = self.precedence
        left = _wrap(self.left, p)
        # the right operand of - and / needs brackets at equal precedence
        right = _wrap(self.right, p + (1 if self.op in "-/" else 0))
        if self.op in "*/":
            return f"{left}{self.op}{right}"
        return f"{left} {self.op} {right}"

    def _key(self) -> tuple[Any, ...]:
        return (self.op, self.left, self.right)


class Call(Expr):
    __slots__ = ("arg", "func")

    def __init__(self, func: str, arg: Expr):
        self.func = func
        self.arg = arg

    def names(self) -> frozenset[str]:
        return self.arg.names()

    def substitute(self, mapping: Mapping[str, Expr]) -> Expr:
        return Call(self.func, self.arg.substitute(mapping))

    def evaluate(self, env: Mapping[str, Any]) -> Any:
        x = self.arg.evaluate(env)
        if self.func == "deg":
            return x * (math.pi / 180.0)
        return _NUMPY_FUNCS[self.func](x)

    def diff(self, name: str) -> Expr:
        d = self.arg.diff(name)
        if d.is_zero():
            return ZERO
        if self.func == "sin":
            return _mul(d, Call("cos", self.arg))
        if self.func == "cos":
            return _neg(_mul(d, Call("sin", self.arg)))
        if self.func == "tan":  # (tan u)' = u' (1 + tan^2 u)
            t = Call("tan", self.arg)
            return _mul(d, _add(ONE, _mul(t, t)))
        return _mul(d, _div(Pi(), Num(180.0)))

    def jet(self, env: Mapping[str, Jet], math_: Any) -> Jet:
        a = self.arg.jet(env, math_)
        if self.func == "deg":
            return a * Jet((math_.pi / 180,))
        return getattr(a, self.func)(math_)

    def to_sympy(self, sp: Any, symbols: Mapping[str, Any]) -> Any:
        a = self.arg.to_sympy(sp, symbols)
        if self.func == "deg":
            return a * sp.pi / 180
        return getattr(sp, self.func)(a)

    def folded(self) -> Expr:
        a = self.arg.folded()
        if isinstance(a, Num):
            if self.func == "deg":
                return Call("deg", a) if a.value else ZERO
            value = _NUMPY_FUNCS[self.func](a.value)
            if value in (0.0, 1.0):  # sin(0), tan(0), cos(0): exact
                return Num(value)
        return Call(self.func, a)

    def __str__(self) -> str:
        return f"{self.func}({self.arg})"

    def _key(self) -> tuple[Any, ...]:
        return (self.func, self.arg)


ZERO = Num(0.0, "0")
ONE = Num(1.0, "1")

_NUMPY_FUNCS: dict[str, Callable[[Any], Any]] = {"sin": np.sin, "cos": np.cos, "tan": np.tan}


def _is_plain_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def _wrap(e: Expr, precedence: int) -> str:
    s = str(e)
    return f"({s})" if e.precedence < precedence else s


def _divide(a: Any, b: Any) -> Any:
    """a / b without an exception or a numpy warning: a zero divisor gives inf or nan, which
    the caller refuses with a message naming the quantity."""
    if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
        with np.errstate(all="ignore"):
            return np.divide(a, b)
    if b == 0:
        return math.inf if a != 0 else math.nan
    with np.errstate(all="ignore"):
        return np.float64(a) / b


# -- builders that fold as they go (used by diff) ---------------------------------------------


def _num(e: Expr) -> float | None:
    return e.value if isinstance(e, Num) else None


def _add(a: Expr, b: Expr) -> Expr:
    if a.is_zero():
        return b
    if b.is_zero():
        return a
    if isinstance(a, Num) and isinstance(b, Num):
        return Num(a.value + b.value)
    if isinstance(b, Neg):
        return _sub(a, b.arg)
    return BinOp("+", a, b)


def _sub(a: Expr, b: Expr) -> Expr:
    if b.is_zero():
        return a
    if a.is_zero():
        return _neg(b)
    if isinstance(a, Num) and isinstance(b, Num):
        return Num(a.value - b.value)
    if a == b:
        return ZERO
    return BinOp("-", a, b)


def _neg(a: Expr) -> Expr:
    if isinstance(a, Num):
        return Num(-a.value) if a.value else ZERO
    if isinstance(a, Neg):
        return a.arg
    return Neg(a)


def _mul(a: Expr, b: Expr) -> Expr:
    if a.is_zero() or b.is_zero():
        return ZERO
    if _num(a) == 1.0:
        return b
    if _num(b) == 1.0:
        return a
    if _num(a) == -1.0:
        return _neg(b)
    if _num(b) == -1.0:
        return _neg(a)
    if isinstance(a, Num) and isinstance(b, Num):
        return Num(a.value * b.value)
    return BinOp("*", a, b)


def _div(a: Expr, b: Expr) -> Expr:
    if a.is_zero() and not b.is_zero():
        return ZERO
    if _num(b) == 1.0:
        return a
    return BinOp("/", a, b)


# -- the parser -----------------------------------------------------------------------------

_BINOPS = {ast.Add: "+", ast.Sub: "-", ast.Mult: "*", ast.Div: "/"}


def parse_expr(text: str, key: str) -> Expr:
    """Parse ``text`` into an :class:`Expr`; ConfigError at ``key`` if it is not one.

    Only the constructs listed in the module docstring are accepted; anything else (a
    power, a comparison, an attribute, a string, an unknown function) is refused with a
    message naming it.
    """
    if not isinstance(text, str):
        raise ConfigError(key, f"expected a number or an expression in quotes, found {text!r}")
    stripped = text.strip()
    if not stripped:
        raise ConfigError(key, "expected a number or an expression, found an empty string")
    if len(stripped) > MAX_LENGTH:
        raise ConfigError(key, f"expression longer than {MAX_LENGTH} characters")
    if any(ord(ch) < 32 for ch in stripped):
        raise ConfigError(key, f"expression holds a control character: {text!r}")
    try:
        tree = ast.parse(stripped, mode="eval")
    except SyntaxError as exc:
        where = f" at column {exc.offset}" if exc.offset else ""
        raise ConfigError(key, f"cannot read expression {text!r}{where}") from None
    except (RecursionError, MemoryError, ValueError):
        raise ConfigError(key, f"cannot read expression {text!r} (too deeply nested)") from None
    try:
        return _convert(tree.body, key, text)
    except RecursionError:
        raise ConfigError(key, f"expression {text!r} is too deeply nested") from None


def _convert(node: ast.AST, key: str, text: str) -> Expr:
    if isinstance(node, ast.Constant):
        v = node.value
        if isinstance(v, bool) or not isinstance(v, int | float):
            raise ConfigError(key, f"{v!r} is not a number (in {text!r})")
        if not math.isfinite(float(v)):
            raise ConfigError(key, f"expected a finite number in {text!r}")
        segment = ast.get_source_segment(text.strip(), node) or repr(v)
        return Num(float(v), segment.replace("_", ""))
    if isinstance(node, ast.Name):
        if node.id == "pi":
            return Pi()
        if node.id in FUNCTIONS:
            raise ConfigError(key, f"{node.id} is a function: write {node.id}(...) (in {text!r})")
        if not _NAME.match(node.id):
            raise ConfigError(key, f"{node.id!r} is not an ASCII symbol name (in {text!r})")
        return Name(node.id)
    if isinstance(node, ast.UnaryOp) and isinstance(node.op, ast.USub | ast.UAdd):
        arg = _convert(node.operand, key, text)
        if isinstance(node.op, ast.UAdd):
            return arg
        if isinstance(arg, Num):
            return Num(-arg.value, arg.text[1:] if arg.text.startswith("-") else "-" + arg.text)
        return Neg(arg)
    if isinstance(node, ast.BinOp) and type(node.op) in _BINOPS:
        return BinOp(
            _BINOPS[type(node.op)], _convert(node.left, key, text), _convert(node.right, key, text)
        )
    if isinstance(node, ast.Call):
        fname = node.func.id if isinstance(node.func, ast.Name) else None
        if fname not in FUNCTIONS:
            shown = fname or ast.get_source_segment(text.strip(), node.func) or "?"
            raise ConfigError(
                key,
                f"unknown function {shown!r} in {text!r}; expected one of "
                + ", ".join(repr(f) for f in FUNCTIONS),
            )
        if len(node.args) != 1 or node.keywords or isinstance(node.args[0], ast.Starred):
            raise ConfigError(key, f"{fname}() takes exactly one argument (in {text!r})")
        arg = _convert(node.args[0], key, text)
        if fname == "deg" and arg.names():
            raise ConfigError(
                key,
                f"deg() converts a number of degrees, found {str(arg)!r} in {text!r}; "
                "a symbol's values are converted by its unit",
            )
        return Call(fname, arg)
    what = {
        ast.Pow: "a power (**)",
        ast.Compare: "a comparison",
        ast.Attribute: "an attribute",
        ast.Subscript: "an index",
        ast.BoolOp: "'and'/'or'",
        ast.IfExp: "'if'",
        ast.Lambda: "a lambda",
        ast.Tuple: "a tuple",
        ast.List: "a list",
    }
    kind = type(node.op) if isinstance(node, ast.BinOp) else type(node)
    name = what.get(kind, f"the construct {type(node).__name__}")
    raise ConfigError(
        key, f"{name} is not allowed in an expression (in {text!r}); use + - * / sin cos tan"
    )


def as_expr(value: Any, key: str) -> Expr:
    """A quantity as an :class:`Expr`: an Expr, a finite number, or expression text."""
    if isinstance(value, Expr):
        return value
    if isinstance(value, bool):
        raise ConfigError(key, f"expected a number or an expression, found {value!r}")
    if isinstance(value, int | float | np.integer | np.floating):
        return Num(config_number(value, key))  # finite, within float range
    return parse_expr(value, key)


# -- truncated Taylor series ------------------------------------------------------------------


def _zero(x: Any) -> bool:
    """True only for a coefficient known to be exactly zero (the int 0 placeholder)."""
    return isinstance(x, int) and not isinstance(x, bool) and x == 0


class Jet:
    """A truncated Taylor series c0 + c1 λ + c2 λ² (up to second order) in the scale
    factor λ of the small errors.

    Coefficients are floats, numpy arrays or sympy expressions; the integer ``0`` marks a
    coefficient known to be zero, so that products of zeros cost nothing. Arithmetic
    truncates at the jet's order; ``sin``, ``cos`` and ``tan`` use the exact functions of
    the zeroth coefficient and the series of the rest (a large angle stays exact, a small
    one is expanded).
    """

    __slots__ = ("c",)

    def __init__(self, c: Iterable[Any]) -> None:
        self.c = tuple(c)

    @property
    def order(self) -> int:
        return len(self.c) - 1

    @staticmethod
    def constant(value: Any, order: int) -> Jet:
        return Jet((value,) + (0,) * order)

    def _pad(self, order: int) -> tuple:
        return self.c + (0,) * (order + 1 - len(self.c))

    def _pair(self, other: Jet) -> tuple[tuple, tuple, int]:
        n = max(self.order, other.order)
        return self._pad(n), other._pad(n), n

    def __add__(self, other: Jet) -> Jet:
        a, b, _ = self._pair(other)
        return Jet(_plus(x, y) for x, y in zip(a, b, strict=True))

    def __sub__(self, other: Jet) -> Jet:
        a, b, _ = self._pair(other)
        return Jet(_plus(x, _minus(y)) for x, y in zip(a, b, strict=True))

    def __neg__(self) -> Jet:
        return Jet(_minus(x) for x in self.c)

    def __mul__(self, other: Jet) -> Jet:
        a, b, n = self._pair(other)
        out = []
        for k in range(n + 1):
            acc: Any = 0
            for i in range(k + 1):
                acc = _plus(acc, _times(a[i], b[k - i]))
            out.append(acc)
        return Jet(out)

    def __truediv__(self, other: Jet) -> Jet:
        a, b, n = self._pair(other)
        b0 = b[0]
        out: list[Any] = []
        for k in range(n + 1):
            acc = a[k]
            for i in range(k):
                acc = _plus(acc, _minus(_times(out[i], b[k - i])))
            out.append(0 if _zero(acc) else _over(acc, b0))
        return Jet(out)

    def scale(self, factor: Any) -> Jet:
        return Jet(_times(x, factor) for x in self.c)

    def _trig(self, f0: Any, d1: Any, d2: Any) -> Jet:
        """f(a0 + u) with u = a1 λ + a2 λ²: f0 + d1 u + d2/2 u² truncated."""
        c = self._pad(self.order)
        out: list[Any] = [f0]
        if self.order >= 1:
            out.append(_times(d1, c[1]))
        if self.order >= 2:
            half = _times(_times(c[1], c[1]), d2)
            out.append(_plus(_times(d1, c[2]), _over(half, 2) if not _zero(half) else 0))
        if self.order > 2:
            raise ValueError("jets above second order are not supported")
        return Jet(out)

    def sin(self, m: Any) -> Jet:
        a0 = self.c[0]
        s, co = m.sin(a0), m.cos(a0)
        return self._trig(s, co, _minus(s))

    def cos(self, m: Any) -> Jet:
        a0 = self.c[0]
        s, co = m.sin(a0), m.cos(a0)
        return self._trig(co, _minus(s), _minus(co))

    def tan(self, m: Any) -> Jet:
        t = m.tan(self.c[0])
        sec2 = _plus(1, _times(t, t))
        return self._trig(t, sec2, _times(_times(2, sec2), t))


def _plus(x: Any, y: Any) -> Any:
    if _zero(x):
        return y
    if _zero(y):
        return x
    return x + y


def _minus(x: Any) -> Any:
    return 0 if _zero(x) else -x


def _times(x: Any, y: Any) -> Any:
    if _zero(x) or _zero(y):
        return 0
    return x * y


def _over(x: Any, y: Any) -> Any:
    if _zero(x):
        return 0
    if isinstance(y, np.ndarray) or isinstance(x, np.ndarray):
        return _divide(x, y)
    if isinstance(y, int | float) and y == 0:
        return _divide(x, y)
    return x / y


def size_estimate(e: Expr, known: Mapping[str, tuple[int, int]] | None = None) -> tuple[int, int]:
    """``(nodes, terms)`` of ``e`` once every name of ``known`` (name -> its own
    ``(nodes, terms)``, e.g. a definition) is substituted into it, computed without
    substituting: the nodes of the tree, and an upper bound on its terms multiplied out
    (leaves 1; a sum or difference adds, a product or quotient multiplies; a function call
    counts as the terms of its argument). Both saturate at 1e30; a subtree shared by
    substitution is walked once, so that a chain of definitions that squares at each level
    costs one walk of each definition."""
    known = known or {}
    seen: dict[int, tuple[int, int]] = {}  # a substituted tree shares its subtrees

    def walk(x: Expr) -> tuple[int, int]:
        if id(x) not in seen:
            seen[id(x)] = size(x)
        return seen[id(x)]

    def size(x: Expr) -> tuple[int, int]:
        if isinstance(x, Name):
            return known.get(x.name, (1, 1))
        if isinstance(x, Neg):
            n, t = walk(x.arg)
            return min(n + 1, _SATURATED), t
        if isinstance(x, BinOp):
            nl, tl = walk(x.left)
            nr, tr = walk(x.right)
            t = tl + tr if x.op in "+-" else tl * tr
            return min(nl + nr + 1, _SATURATED), min(t, _SATURATED)
        if isinstance(x, Call):
            n, t = walk(x.arg)
            return min(n + 1, _SATURATED), t
        return 1, 1

    return walk(e)


def check_size(size: tuple[int, int], key: str) -> None:
    """Refuse (:class:`ConfigError` at ``key``) an expression whose
    :func:`size_estimate` is beyond :data:`MAX_NODES` or :data:`MAX_EXPANDED_TERMS`: its
    formulae would take minutes and gigabytes to derive."""
    nodes, terms = size

    def about(x: int) -> str:
        return f"more than {_SATURATED:.0e}" if x >= _SATURATED else f"about {x:.2g}"

    if terms > MAX_EXPANDED_TERMS:
        raise ConfigError(
            key,
            f"expected at most {MAX_EXPANDED_TERMS:.0e} terms multiplied out, found "
            f"{about(terms)} once the definitions are substituted; write a smaller expression",
        )
    if nodes > MAX_NODES:
        raise ConfigError(
            key,
            f"expected at most {MAX_NODES} operations and names, found {about(nodes)} once "
            "the definitions are substituted; write a smaller expression",
        )
