"""Symbolic derivation of a chain's nominal position and error terms (sympy).

The only module of esp that imports sympy; it is imported when a derivation is asked
for (``esp derive`` without ``--at``, :func:`esp.core.kinematics.derive`), never by the
numeric core or by ``esp analyse``.

The method is Freeman & Ford's (2003, section 4): every small error e is scaled by λ, the
chain's elementary transforms are multiplied out with exact trigonometry of the large
angles and series of the small ones, and products of more than ``order`` small quantities
are dropped -- here by carrying truncated Taylor series in λ (:class:`esp.core.kinematics.expr.Jet`)
through the chain. The coefficient of λ⁰ is the nominal position, that of λ¹ the
first-order error (every term linear in exactly one small error), that of λ² the
second-order error (every term a product of two). Each error's coefficient is then
simplified on its own, so that the first order reads as a sum of error × lever.

In every formula a length is in mm and an angle in radians, whatever unit the symbol's
values are given in.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import sympy as sp  # type: ignore[import-untyped]

from esp.core.errors import ConfigError
from esp.core.kinematics.chain import Chain, Op
from esp.core.kinematics.expr import Jet

__all__ = [
    "SCHEMA",
    "Derivation",
    "canonical",
    "derive",
    "signed_term",
    "simplify",
    "sympy_symbols",
    "tidy",
]

SCHEMA = "esp.derive/1"
AXES_OUT = ("X", "Y", "Z")


def sympy_symbols(chain: Chain) -> dict[str, sp.Symbol]:
    """name -> plain sympy Symbol for every symbol of the chain.

    Raises ConfigError when a name would not read back as a symbol from the formula text
    (``E``, ``I``, ``S``, ``N``, ``gamma``, ``test`` ... are names of sympy objects).
    """
    out = {}
    for name in chain.symbols:
        sym = sp.Symbol(name)
        try:
            back = sp.sympify(name)
        except (sp.SympifyError, SyntaxError, TypeError, ValueError):
            back = None
        if back != sym:
            raise ConfigError(
                f"symbols.{name}",
                f"the name {name!r} means something else to sympy ({back!r}), so the "
                "formulae could not be read back; choose another name",
                chain.source,
            )
        out[name] = sym
    return out


@dataclass(frozen=True)
class Derivation:
    """The formulae of a chain's tool tip.

    Attributes
    ----------
    chain : the chain derived
    order : 1 or 2
    nominal : ``{"X", "Y", "Z"}`` -> sympy expression, the error-free tool tip (mm)
    first_order : ``{"X", "Y", "Z"}`` -> the first-order error DX, DY, DZ (mm): every term
        linear in exactly one small error, collected by error
    second_order : the same for the terms in products of two small errors, or None
    symbols : name -> kind (``coordinate``, ``parameter``, ``error``)
    first_terms : ``{"X", ...}`` -> {error name -> its coefficient}, the lever of each error
    second_terms : ``{"X", ...}`` -> {(e1, e2) -> coefficient of e1·e2}, or None
    """

    chain: Chain
    order: int
    nominal: Mapping[str, Any]
    first_order: Mapping[str, Any]
    second_order: Mapping[str, Any] | None
    symbols: Mapping[str, str]
    first_terms: Mapping[str, Mapping[str, Any]]
    second_terms: Mapping[str, Mapping[tuple[str, str], Any]] | None

    def to_dict(self) -> dict[str, Any]:
        """The ``esp.derive/1`` document: every formula as text that ``sympy.sympify``
        reads back to the same expression."""
        doc: dict[str, Any] = {
            "schema": SCHEMA,
            "chain": self.chain.name,
            "order": self.order,
            "units": {"length": "mm", "angle": "rad"},
            "nominal": {a: str(self.nominal[a]) for a in AXES_OUT},
            "first_order": {a: str(self.first_order[a]) for a in AXES_OUT},
        }
        if self.second_order is not None:
            doc["second_order"] = {a: str(self.second_order[a]) for a in AXES_OUT}
        doc["symbols"] = {
            n: {"kind": s.kind, "unit": s.unit} for n, s in self.chain.symbols.items()
        }
        return doc


def _sym_jet_apply(
    op: Op, env: Mapping[str, Jet], syms: Mapping[str, Any], p: list[Jet], order: int
) -> list[Jet]:
    q = [e.jet(env, sp) for e in op.q]
    if op.kind == "T":
        return [p[k] + q[k] for k in range(3)]
    if op.kind == "R":
        theta = q[0] if op.sign > 0 else -q[0]
        c, s = theta.cos(sp), theta.sin(sp)
        i, j = (op.axis + 1) % 3, (op.axis + 2) % 3
        out = list(p)
        out[i] = c * p[i] - s * p[j]
        out[j] = s * p[i] + c * p[j]
        return out
    piv = [Jet.constant(e.to_sympy(sp, syms), order) for e in op.pivot]
    w = [p[k] - piv[k] for k in range(3)]
    r = q[3:]
    u = [r[1] * w[2] - r[2] * w[1], r[2] * w[0] - r[0] * w[2], r[0] * w[1] - r[1] * w[0]]
    v = [r[1] * u[2] - r[2] * u[1], r[2] * u[0] - r[0] * u[2], r[0] * u[1] - r[1] * u[0]]
    half = sp.Rational(1, 2)
    return [piv[k] + q[k] + w[k] + u[k] + v[k].scale(half) for k in range(3)]


def expand_chain(chain: Chain, order: int) -> tuple[list[Any], dict[str, sp.Symbol]]:
    """The tool tip as [x, y, z], each a list of sympy coefficients of λ⁰ … λ^order."""
    syms = sympy_symbols(chain)
    errors = set(chain.errors)
    env = {
        n: (Jet((0, s) + (0,) * (order - 1)) if n in errors else Jet.constant(s, order))
        for n, s in syms.items()
    }
    p = [Jet.constant(0, order) for _ in range(3)]
    for op in reversed(chain.ops):
        p = _sym_jet_apply(op, env, syms, p, order)
    coeffs = []
    for k in range(3):
        c = p[k]._pad(order)
        coeffs.append([sp.S(x) if isinstance(x, int) else x for x in c])
    return coeffs, syms


def simplify(expr: Any) -> Any:
    """A readable, exact and quick simplification.

    The expression is expanded; then, for each angle θ whose sine and cosine both appear,
    cos²θ is replaced by 1 − sin²θ or sin²θ by 1 − cos²θ where that makes it shorter, and
    common factors are taken out. Products of sines and cosines are not merged into
    functions of angle sums (sympy's trigsimp would, slowly, and into forms such as
    √2·cos(a + π/4) that read worse than the products).
    """
    expr = sp.sympify(expr)
    if expr.is_number:
        return tidy(expr)
    best = sp.expand(expr)
    if best.has(sp.sin, sp.cos):
        angles = {f.args[0] for f in best.atoms(sp.sin, sp.cos)}
        for theta in sorted(angles, key=sp.default_sort_key):
            s, c = sp.sin(theta), sp.cos(theta)
            if not (best.has(s**2) or best.has(c**2)):
                continue
            for old, new in ((c**2, 1 - s**2), (s**2, 1 - c**2)):
                candidate = sp.expand(best.subs(old, new))
                if sp.count_ops(candidate) < sp.count_ops(best):
                    best = candidate
    return canonical(sp.factor_terms(best, sign=False))


def tidy(expr: Any) -> Any:
    """The shortest of a few exact forms of ``expr``: as given, expanded, and its
    cancelled quotient n/d (:func:`sympy.cancel`) written with the number of d taken into
    n (``(-Ocx + dX_5/2)/cos(Yp)`` rather than ``(-2*Ocx + dX_5)/(2*cos(Yp))``); the
    shortest by :func:`sympy.count_ops`, the first of equals.

    For the formulae esp forms (sums of products of lengths, errors and the sines and
    cosines of angles, and the solutions of linear equations in them) these are the forms
    :func:`sympy.simplify` chooses among, without its general search: simplify imports
    ``sympy.physics.units`` (about a second) and tries rewritings (trigonometric sums,
    special functions) that such formulae do not need. sin² + cos² is merged by
    :func:`simplify`, not here."""
    expr = sp.sympify(expr)
    if not expr.args:
        return expr
    expanded = sp.expand(expr)
    numerator, denominator = sp.fraction(sp.cancel(expr))
    number, rest = denominator.as_coeff_Mul()
    quotient = sp.expand(numerator / number) / rest
    return min((expanded, quotient, expr), key=sp.count_ops)


def canonical(expr: Any) -> Any:
    """The form sympy builds from ``str(expr)``: the text of every formula then reads back
    to the very same expression (a factored form such as ``(x + y)/2`` would read back as
    ``x/2 + y/2``)."""
    return sp.sympify(str(expr))


def signed_term(factor: Any, coefficient: Any) -> Any:
    """factor × coefficient, with a minus sign taken out of a sum whose terms are mostly
    negative (``-ECX*(Y - Y_off)`` rather than ``ECX*(-Y + Y_off)``)."""
    if coefficient.is_Add:
        negative = sum(1 for t in coefficient.args if t.could_extract_minus_sign())
        if 2 * negative > len(coefficient.args):
            return sp.Mul(-1, factor, -coefficient)
    return factor * coefficient


def derive(chain: Chain, order: int = 1) -> Derivation:
    """Derive the nominal tool tip and its first- (and second-) order errors.

    Parameters
    ----------
    chain : the chain
    order : 1, or 2 for the second-order terms too

    Returns
    -------
    Derivation

    References
    ----------
    Freeman & Ford (2003), section 4 and Table 2 (the same derivation for the angle head).
    """
    if order not in (1, 2):
        raise ValueError(f"order must be 1 or 2, found {order!r}")
    coeffs, syms = expand_chain(chain, order)
    errors = [syms[e] for e in chain.errors]
    nominal, first, second = {}, {}, {}
    first_terms: dict[str, dict[str, Any]] = {}
    second_terms: dict[str, dict[tuple[str, str], Any]] = {}
    for k, axis in enumerate(AXES_OUT):
        nominal[axis] = simplify(coeffs[k][0])
        lin = sp.expand(coeffs[k][1])
        terms = {}
        for e in errors:
            c = lin.coeff(e)
            if c != 0:
                terms[e.name] = simplify(c)
        first_terms[axis] = terms
        first[axis] = canonical(sp.Add(*(signed_term(syms[n], c) for n, c in terms.items())))
        if order == 2:
            quad = sp.expand(coeffs[k][2])
            pairs: dict[tuple[str, str], Any] = {}
            for i, a in enumerate(errors):
                if quad == 0:
                    break
                with_a = quad.coeff(a)  # the terms holding a once
                for b in errors[i + 1 :]:
                    c = with_a.coeff(b)
                    if c != 0:
                        pairs[(a.name, b.name)] = simplify(c)
                c = quad.coeff(a, 2)
                if c != 0:
                    pairs[(a.name, a.name)] = simplify(c)
            second_terms[axis] = pairs
            second[axis] = canonical(
                sp.Add(*(signed_term(syms[a] * syms[b], c) for (a, b), c in pairs.items()))
            )
    kinds = {n: s.kind for n, s in chain.symbols.items()}
    return Derivation(
        chain,
        order,
        nominal,
        first,
        second if order == 2 else None,
        kinds,
        first_terms,
        second_terms if order == 2 else None,
    )
