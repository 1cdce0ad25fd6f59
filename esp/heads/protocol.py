"""Measurement protocols for a head: which differences of tool-tip errors between head
settings isolate each small error (Freeman & Ford 2003, section 5).

The head is set to every combination of a few angles (by default each axis at 0°, 90°,
180° and 270°: 16 settings for a two-axis head). At each setting the tool tip's error is
the first-order sum D(s) = Σ_e c_e(s)·e. A measurement compares two settings: the tool
tip's X (or Y, or Z) error at the first minus that at the second,

    dX = DX(s₁) − DX(s₂) = Σ_e [c_e(s₁) − c_e(s₂)]·e,

which needs no absolute reference: only the change of the tip's position between the two
settings, less its nominal change. Every pair of settings and every direction gives one
such equation (16 settings: 120 pairs × 3 = 360). They are formed symbolically (the
coefficients are formulae of the head's parameters G, e, Y_p …), simplified, and searched:

1. errors the user assumes zero are dropped; errors already identified are known;
2. an equation isolates an error when that error is its only unknown; among those the
   simplest is taken: fewest known errors carried, then the shortest formula, then the
   largest sensitivity at the head's parameter values, then the first settings;
3. the identified error becomes known and the search goes on (the paper's "the software
   then considers that the variable has been identified");
4. where no single equation isolates an error, two or three equations in as many unknowns
   are solved together;
5. an error that no combination isolates is explained: it moves the tool tip the same at
   every setting, or it acts only together with others (the combination that can be
   measured is named), so that the user can choose what to assume zero.

sympy is imported inside the functions that build a protocol; solving a protocol from
measured differences (:func:`solve_protocol`) is numeric.

References
----------
Freeman, J. M. & Ford, D. G. (2003), Automated error analysis of serial manipulators and
servo heads, section 5 (the 16 settings, the pairwise differences, the search for the
simplest equations, Table 4).
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from esp.core.devices.head import Head
from esp.core.errors import ConfigError, DataError
from esp.core.text import did_you_mean

__all__ = [
    "DEFAULT_ANGLES",
    "SCHEMA",
    "Protocol",
    "ProtocolStep",
    "ProtocolTest",
    "build_protocol",
    "predict_differences",
    "solve_protocol",
]

SCHEMA = "esp.protocol/1"
#: the paper's settings of each axis, degrees
DEFAULT_ANGLES = (0.0, 90.0, 180.0, 270.0)
AXES = ("X", "Y", "Z")
#: relative size below which a numeric coefficient counts as zero
_TINY = 1e-9
#: the most unknowns solved together in one step
MAX_TOGETHER = 3


@dataclass(frozen=True)
class ProtocolTest:
    """One measurement of a protocol: a direction's error difference between two settings.

    Attributes
    ----------
    number : 1, 2, … in the order of the protocol
    step : the step it belongs to (tests of one step are solved together)
    axis : ``"X"``, ``"Y"`` or ``"Z"``: the direction measured
    first, second : the two settings, coordinate -> value (degrees)
    symbol : the name of the measured difference in the formulae, e.g. ``"dX_1"``
    difference : the formula of the difference (lengths in mm, angles in rad)
    coefficients_um : each error in the formula -> µm of difference per unit of the error
        (its own unit), at the head's parameter values
    known : the errors in the formula identified by earlier steps (or given as known)
    alternatives : how many other equations would have served equally (same unknowns,
        same number of known errors)
    """

    number: int
    step: int
    axis: str
    first: Mapping[str, float]
    second: Mapping[str, float]
    symbol: str
    difference: str
    coefficients_um: Mapping[str, float]
    known: tuple[str, ...]
    alternatives: int

    @property
    def equation(self) -> str:
        return f"{self.symbol} = {self.difference}"


@dataclass(frozen=True)
class ProtocolStep:
    """Errors identified together, from the tests of this step.

    ``solution`` maps each error to its formula in the measured differences (the tests'
    symbols) and the errors identified before (lengths in mm, angles in rad).
    """

    number: int
    errors: tuple[str, ...]
    tests: tuple[int, ...]
    solution: Mapping[str, str]


@dataclass(frozen=True)
class Protocol:
    """A measurement protocol for a head.

    Attributes
    ----------
    head : the head (its parameter values give the numeric sensitivities)
    coordinates : the head's axes, in the order of the settings columns
    angles : the settings of every axis (degrees)
    assume_zero : errors assumed zero
    known : errors known beforehand (their values are the head's)
    identify : the errors identified, in the protocol's order
    steps, tests : the protocol
    searched : how many differences were formed (pairs × 3 directions)
    """

    head: Head
    coordinates: tuple[str, ...]
    angles: tuple[float, ...]
    assume_zero: tuple[str, ...]
    known: tuple[str, ...]
    identify: tuple[str, ...]
    steps: tuple[ProtocolStep, ...]
    tests: tuple[ProtocolTest, ...]
    searched: int

    def test(self, number: int) -> ProtocolTest:
        return self.tests[number - 1]


# -- the candidate equations ----------------------------------------------------------------


@dataclass
class _Equation:
    index: int
    axis: str
    first: tuple[float, ...]
    second: tuple[float, ...]
    coefficients: dict[str, Any]  # error -> sympy coefficient (mm per mm or rad), non-zero
    numeric: dict[str, float]  # error -> µm per unit of the error, at the head's values
    ops: int  # sympy operation count of the whole difference


def _check_names(head: Head, names: Iterable[str], option: str) -> tuple[str, ...]:
    errors = head.chain.errors
    out: list[str] = []
    for n in names:
        if n in out:
            continue
        sym = head.chain.symbols.get(n)
        if sym is None:
            raise ConfigError(
                option,
                f"unknown error {n!r}{did_you_mean(n, errors)} "
                f"(the head's errors: {', '.join(errors)})",
            )
        if sym.kind != "error":
            raise ConfigError(
                option, f"{n} is a {sym.kind} of the head, not a small error ({', '.join(errors)})"
            )
        out.append(n)
    return tuple(out)


def _exact(value: float, unit: str, sp: Any) -> Any:
    """A coordinate value as an exact sympy number in rad (or mm)."""
    from esp.core.kinematics import units as kunits

    r = sp.Rational(repr(float(value)))
    if unit == "deg":
        return r * sp.pi / 180
    return r * sp.nsimplify(kunits.factor(unit))


def _settings(coords: Sequence[str], angles: Sequence[float]) -> list[tuple[float, ...]]:
    return list(itertools.product(angles, repeat=len(coords)))


def _equations(
    head: Head, coords: tuple[str, ...], angles: tuple[float, ...]
) -> tuple[list[_Equation], dict[str, Any]]:
    """Every pairwise difference at the settings, with its symbolic and numeric
    coefficients; and the derivation's symbols."""
    import sympy as sp  # type: ignore[import-untyped]

    from esp.core.devices.head_evaluate import evaluate_head
    from esp.core.kinematics.symbolic import derive, simplify

    chain = head.chain
    derivation = derive(chain, 1)
    syms = {n: sp.Symbol(n) for n in chain.symbols}
    settings = _settings(coords, angles)
    # numeric sensitivities at every setting, µm per unit of each error
    arrays = {c: np.array([s[k] for s in settings]) for k, c in enumerate(coords)}
    ev = evaluate_head(head, arrays, order=1, exact=False)
    numeric = ev.sensitivity
    # the symbolic coefficients at every setting
    at: list[dict[str, dict[str, Any]]] = []
    for s in settings:
        subs = {
            syms[c]: _exact(v, chain.symbols[c].unit, sp) for c, v in zip(coords, s, strict=True)
        }
        per_axis = {}
        for a in AXES:
            per_axis[a] = {
                e: sp.expand(coef.subs(subs)) for e, coef in derivation.first_terms[a].items()
            }
        at.append(per_axis)
    # generic values of the parameters, to tell a coefficient that vanishes identically
    # (but did not simplify to zero) from one that vanishes at the head's values only
    rng = np.random.default_rng(2003)
    probes = []
    for _ in range(2):
        probe = {}
        for n in chain.parameters:
            angle = chain.symbols[n].dimension == "angle"
            probe[syms[n]] = rng.uniform(0.2, 1.3) if angle else rng.uniform(5.0, 200.0)
        probes.append(probe)
    out: list[_Equation] = []
    cache: dict[Any, Any] = {}
    ops_cache: dict[Any, int] = {}
    # the coefficients at the settings take few distinct values (sines and cosines of
    # multiples of 90° are 0 and ±1), so most pairs of them recur: each pair's difference
    # is formed and simplified once, and each difference tested for vanishing once
    pairs: dict[tuple[Any, Any], Any] = {}
    vanishing: dict[Any, bool] = {}
    scales = {e: _scale(numeric[e]) for e in chain.errors}
    index = 0
    for i, j in itertools.combinations(range(len(settings)), 2):
        for k, a in enumerate(AXES):
            coefficients = {}
            nums = {}
            for e in chain.errors:
                num = float(numeric[e][i, k] - numeric[e][j, k])
                c1 = at[i][a].get(e, 0)
                c2 = at[j][a].get(e, 0)
                diff = pairs.get((c1, c2))
                if diff is None:
                    diff = sp.expand(c1 - c2)
                    if diff != 0:
                        diff = _simplified(diff, cache, simplify, sp)
                    pairs[(c1, c2)] = diff
                # zero at the head's values: identically zero, or only for these values?
                tiny = abs(num) <= _TINY * scales[e]
                if diff != 0 and tiny:
                    if diff not in vanishing:
                        vanishing[diff] = _vanishes(diff, probes)
                    if vanishing[diff]:
                        diff = sp.S(0)
                if diff != 0:
                    coefficients[e] = diff
                    nums[e] = num
            if coefficients:
                # the operation count of the difference: each coefficient's, one product
                # per error, one sum between terms
                ops = sum(_ops(c, ops_cache, sp) + 1 for c in coefficients.values()) - 1
                out.append(_Equation(index, a, settings[i], settings[j], coefficients, nums, ops))
            index += 1
    return out, syms


def _simplified(expr: Any, cache: dict[Any, Any], simplify: Any, sp: Any) -> Any:
    """``simplify(expr)``, remembered (the same differences recur, often negated)."""
    if expr in cache:
        return cache[expr]
    neg = sp.expand(-expr)
    out = simplify(-cache[neg]) if neg in cache else simplify(expr)
    cache[expr] = out
    return out


def _ops(expr: Any, cache: dict[Any, int], sp: Any) -> int:
    if expr not in cache:
        cache[expr] = int(sp.count_ops(expr))
    return cache[expr]


def _scale(values: np.ndarray) -> float:
    m = float(np.max(np.abs(values))) if values.size else 0.0
    return m if m > 0 else 1.0


def _vanishes(expr: Any, probes: list[dict[Any, float]]) -> bool:
    """True when ``expr`` is zero at every probe (generic parameter values)."""
    for p in probes:
        try:
            value = complex(expr.subs(p).evalf())
        except (TypeError, ValueError):
            return False
        if abs(value) > 1e-9:
            return False
    return True


# -- the search -----------------------------------------------------------------------------


@dataclass(frozen=True)
class _Choice:
    unknowns: tuple[str, ...]
    rows: tuple[_Equation, ...]
    key: tuple
    alternatives: int


def _known_in(eq: _Equation, known: set[str]) -> list[str]:
    return [e for e in eq.coefficients if e in known]


def _single(
    equations: list[_Equation], unknown: set[str], known: set[str], peak: dict[str, float]
) -> dict[str, list[tuple[tuple, _Equation]]]:
    """unknown -> the equations isolating it, each with its score key."""
    out: dict[str, list[tuple[tuple, _Equation]]] = {}
    for eq in equations:
        free = [e for e in eq.coefficients if e in unknown]
        if len(free) != 1:
            continue
        u = free[0]
        if abs(eq.numeric.get(u, 0.0)) <= _TINY * peak[u]:
            continue  # a coefficient that vanishes at the head's values measures nothing
        key = (len(_known_in(eq, known)), eq.ops, -round(abs(eq.numeric[u]) / peak[u], 9), eq.index)
        out.setdefault(u, []).append((key, eq))
    return out


def _together(
    equations: list[_Equation], unknown: set[str], known: set[str], k: int, peak: dict[str, float]
) -> list[_Choice]:
    """Sets of k equations in the same k unknowns that determine them."""
    by_set: dict[frozenset[str], None] = {}
    free_of: dict[int, frozenset[str]] = {}
    for eq in equations:
        free = frozenset(e for e in eq.coefficients if e in unknown)
        free_of[eq.index] = free
        if len(free) == k:
            by_set.setdefault(free, None)
    choices = []
    for S in by_set:
        cols = sorted(S)
        rows = [eq for eq in equations if free_of[eq.index] and free_of[eq.index] <= S]
        rows.sort(key=lambda eq: (len(_known_in(eq, known)), eq.ops, eq.index))
        picked: list[_Equation] = []
        matrix = np.zeros((0, k))
        for eq in rows:
            row = np.array([eq.numeric.get(c, 0.0) / peak[c] for c in cols])
            trial = np.vstack([matrix, row])
            if np.linalg.matrix_rank(trial, tol=1e-8) > matrix.shape[0]:
                picked.append(eq)
                matrix = trial
                if len(picked) == k:
                    break
        if len(picked) == k:
            key = (
                k,
                sum(len(_known_in(eq, known)) for eq in picked),
                sum(eq.ops for eq in picked),
                tuple(eq.index for eq in picked),
            )
            choices.append(_Choice(tuple(cols), tuple(picked), key, max(0, len(rows) - k)))
    return choices


def _rank(matrix: np.ndarray) -> int:
    if matrix.size == 0:
        return 0
    return int(np.linalg.matrix_rank(matrix, tol=1e-8 * max(1.0, float(np.abs(matrix).max()))))


def _explain(
    target: str,
    equations: list[_Equation],
    unknown: set[str],
    peak: dict[str, float],
    head: Head,
) -> str:
    """Why ``target`` cannot be isolated: one line."""
    cols = sorted(unknown)
    M = np.array([[eq.numeric.get(c, 0.0) / peak[c] for c in cols] for eq in equations])
    if not any(target in eq.coefficients for eq in equations):
        return (
            f"{target} cannot be isolated: it moves the tool tip the same at every setting, so "
            "no difference of two settings holds it; assume it zero (--assume-zero "
            f"{target}) or measure it otherwise"
        )
    others = [c for c in cols if c != target]
    identifiable = _rank(M) - _rank(M[:, [cols.index(c) for c in others]]) == 1
    if identifiable:
        return (
            f"{target} is determined by the differences only through more than "
            f"{MAX_TOGETHER} equations at once; assume some of the errors with it zero "
            "(--assume-zero) or identify others first (--known)"
        )
    for size in (2, 3, 4):
        for group in itertools.combinations(others, size - 1):
            S = [target, *group]
            sub = M[:, [cols.index(c) for c in S]]
            if _rank(sub) >= size:
                continue
            _, _, vt = np.linalg.svd(sub)
            null = vt[-1]
            if abs(null[0]) < 1e-6:
                continue
            names = ", ".join(S)
            if size == 2:
                u = group[0]
                combo = _combination(target, u, equations)
                if combo is not None:
                    return (
                        f"{target} cannot be isolated: at every setting {target} and {u} act "
                        f"only together, as {combo} (lengths in mm, angles in rad); assume one "
                        f"of them zero (--assume-zero {u} or {target})"
                    )
            # numeric: a change of the errors along the null vector moves nothing
            null = null / null[0]
            parts = ", ".join(
                f"{c} by {null[k] / peak[c] * peak[target]:.4g} {head.unit(c)}"
                for k, c in enumerate(S)
            )
            return (
                f"{target} cannot be isolated: changing {parts} together changes no "
                f"difference between settings; assume one of {names} zero (--assume-zero)"
            )
    return f"{target} cannot be isolated by any combination of the differences"


def _combination(t: str, u: str, equations: list[_Equation]) -> str | None:
    """``t + r*u`` when every equation holds t and u as c·(t + r·u), r a formula."""
    import sympy as sp

    from esp.core.kinematics.symbolic import simplify, tidy

    ratios = [
        eq.coefficients[u] / eq.coefficients[t]
        for eq in equations
        if t in eq.coefficients and u in eq.coefficients
    ]
    if not ratios:
        return None
    r = tidy(simplify(ratios[0]))
    for other in ratios[1:4]:  # the same formula in every equation, or no formula
        if tidy(simplify(other - r)) != 0:
            return None
    return str(sp.Symbol(t) + r * sp.Symbol(u))


def build_protocol(
    head: Head,
    *,
    angles: Sequence[float] = DEFAULT_ANGLES,
    assume_zero: Iterable[str] = (),
    known: Iterable[str] = (),
    identify: Iterable[str] | None = None,
) -> Protocol:
    """Search the simplest measurement protocol for a head (imports sympy).

    Parameters
    ----------
    head : the head; its parameter values give the numeric sensitivities and decide which
        coefficients vanish
    angles : the values every axis takes (degrees); all combinations are the settings
    assume_zero : errors assumed zero
    known : errors known beforehand (identified otherwise); their values are the head's
    identify : the errors to identify (default: every error neither assumed zero nor known)

    Returns
    -------
    Protocol

    Raises
    ------
    ConfigError
        An unknown error name (key ``--assume-zero``, ``--known``, ``--identify``), an
        error both assumed zero and to be identified, fewer than two distinct angles.
    DataError
        An error that no combination of the differences isolates; the message says why
        (it moves the tip the same at every setting, or acts only together with others).
    """
    z = _check_names(head, assume_zero, "--assume-zero")
    k0 = _check_names(head, known, "--known")
    both = sorted(set(z) & set(k0))
    if both:
        raise ConfigError("--known", f"{both[0]} is also assumed zero (--assume-zero)")
    angles = tuple(float(a) for a in angles)
    if len(set(angles)) < 2:
        found = ", ".join(f"{a:g}" for a in angles)
        raise ConfigError("--angles", f"expected at least two distinct angles, found {found}")
    if len(set(angles)) != len(angles):
        raise ConfigError("--angles", "an angle is given twice")
    if not all(math.isfinite(a) and abs(a) <= 3600 for a in angles):
        raise ConfigError("--angles", "expected finite angles of at most 3600 degrees")
    chain = head.chain
    if identify is None:
        targets = tuple(e for e in chain.errors if e not in z and e not in k0)
    else:
        targets = _check_names(head, identify, "--identify")
        for t in targets:
            if t in z:
                raise ConfigError(
                    "--identify", f"{t} is assumed zero (--assume-zero, or the head file's)"
                )
            if t in k0:
                raise ConfigError("--identify", f"{t} is given as known (--known)")
    if not targets:
        raise ConfigError("--identify", "nothing to identify: every error is assumed zero or known")
    coords = tuple(sorted(head.coordinates))
    settings = _settings(coords, angles)
    if len(settings) > 400:
        raise ConfigError(
            "--angles", f"{len(settings)} settings: expected at most 400 (fewer angles)"
        )
    equations, syms = _equations(head, coords, angles)
    searched = math.comb(len(settings), 2) * 3
    # drop the errors assumed zero
    zero = set(z)
    for eq in equations:
        for e in list(eq.coefficients):
            if e in zero:
                del eq.coefficients[e]
                eq.numeric.pop(e, None)
    equations = [eq for eq in equations if eq.coefficients]
    peak = {
        e: max([abs(eq.numeric.get(e, 0.0)) for eq in equations] + [1e-300]) for e in chain.errors
    }

    known_set = set(k0)
    unknown = set(chain.errors) - zero - known_set
    remaining = list(targets)
    chosen: list[_Choice] = []
    while remaining:
        choice = None
        singles = _single(equations, unknown, known_set, peak)
        options = [(min(c[0] for c in cands), u, cands) for u, cands in singles.items()]
        if options:
            preferred = [o for o in options if o[1] in remaining] or options
            _, u, cands = min(preferred, key=lambda o: (o[0], chain.errors.index(o[1])))
            best = min(cands, key=lambda c: c[0])
            same = sum(1 for c in cands if c[0][0] == best[0][0]) - 1
            choice = _Choice((u,), (best[1],), best[0], same)
        else:
            for k in range(2, MAX_TOGETHER + 1):
                groups = _together(equations, unknown, known_set, k, peak)
                if groups:
                    useful = [g for g in groups if set(g.unknowns) & set(remaining)] or groups
                    choice = min(useful, key=lambda g: g.key)
                    break
        if choice is None:
            target = remaining[0]
            raise DataError(_explain(target, equations, unknown, peak, head))
        chosen.append(choice)
        for u in choice.unknowns:
            unknown.discard(u)
            known_set.add(u)
            if u in remaining:
                remaining.remove(u)
    return _assemble(head, coords, angles, z, k0, chosen, syms, searched)


def _assemble(
    head: Head,
    coords: tuple[str, ...],
    angles: Sequence[float],
    z: Sequence[str],
    k0: Sequence[str],
    chosen: Sequence[_Choice],
    syms: Mapping[str, Any],
    searched: int,
) -> Protocol:
    import sympy as sp

    from esp.core.kinematics.symbolic import signed_term, tidy

    tests: list[ProtocolTest] = []
    steps: list[ProtocolStep] = []
    known_before: set[str] = set(k0)
    order: list[str] = []
    for s, choice in enumerate(chosen, 1):
        eqs = []
        numbers = []
        for eq in choice.rows:
            number = len(tests) + 1
            symbol = f"d{eq.axis}_{number}"
            terms = [signed_term(syms[e], c) for e, c in eq.coefficients.items()]
            difference = sp.Add(*terms)
            eqs.append(sp.Eq(sp.Symbol(symbol), difference))
            numbers.append(number)
            known_here = tuple(e for e in eq.coefficients if e in known_before)
            tests.append(
                ProtocolTest(
                    number,
                    s,
                    eq.axis,
                    dict(zip(coords, eq.first, strict=True)),
                    dict(zip(coords, eq.second, strict=True)),
                    symbol,
                    str(difference),
                    dict(eq.numeric),
                    known_here,
                    choice.alternatives,
                )
            )
        unknowns = [syms[u] for u in choice.unknowns]
        solved = sp.solve(eqs, unknowns, dict=True)
        solution = {}
        if solved:
            for u in choice.unknowns:
                solution[u] = str(sp.factor_terms(tidy(solved[0][syms[u]])))
        steps.append(ProtocolStep(s, tuple(choice.unknowns), tuple(numbers), solution))
        known_before.update(choice.unknowns)
        order.extend(choice.unknowns)
    return Protocol(
        head,
        coords,
        tuple(angles),
        tuple(z),
        tuple(k0),
        tuple(order),
        tuple(steps),
        tuple(tests),
        searched,
    )


# -- numbers --------------------------------------------------------------------------------


def predict_differences(protocol: Protocol, errors: Mapping[str, float]) -> dict[int, float]:
    """The first-order difference (µm) every test of the protocol would measure for the
    given error values (each in its unit; errors not given are zero). Every error counts,
    also those the protocol assumes zero."""
    from esp.core.devices.head_evaluate import evaluate_head

    head = protocol.head
    out: dict[int, float] = {}
    values = {e: float(errors.get(e, 0.0)) for e in head.chain.errors}
    first = [t.first for t in protocol.tests]
    second = [t.second for t in protocol.tests]
    angles = {
        c: np.array([f[c] for f in first] + [s[c] for s in second]) for c in protocol.coordinates
    }
    ev = evaluate_head(head, angles, order=1, exact=False)
    n = len(protocol.tests)
    total = np.zeros((2 * n, 3))
    for e, v in values.items():
        total += ev.sensitivity[e] * v
    for i, t in enumerate(protocol.tests):
        k = AXES.index(t.axis)
        out[t.number] = float(total[i, k] - total[n + i, k])
    return out


def solve_protocol(
    protocol: Protocol,
    measured_um: Mapping[int, float],
    known_values: Mapping[str, float] | None = None,
) -> dict[str, float]:
    """The errors a protocol identifies from measured differences.

    Parameters
    ----------
    protocol : the protocol
    measured_um : test number -> its measured difference, µm (the first setting's error
        minus the second's, in the test's direction)
    known_values : values of the errors given as known (each in its unit); default the
        head's values

    Returns
    -------
    dict error -> value, in the error's unit, in the protocol's order

    Raises
    ------
    DataError
        A test of the protocol without a measured difference, or a number that is not
        finite.
    """
    head = protocol.head
    values: dict[str, float] = {}
    given = dict(head.errors) if known_values is None else dict(known_values)
    for e in protocol.known:
        values[e] = float(given.get(e, 0.0))
    for t in protocol.tests:
        if t.number not in measured_um:
            raise DataError(f"test {t.number} ({t.symbol}) has no measured difference")
        if not math.isfinite(float(measured_um[t.number])):
            raise DataError(f"test {t.number}: expected a finite difference")
    out: dict[str, float] = {}
    for step in protocol.steps:
        rows = []
        rhs = []
        for number in step.tests:
            t = protocol.test(number)
            b = float(measured_um[number])
            for e in t.known:
                b -= t.coefficients_um[e] * values[e]
            rows.append([t.coefficients_um.get(u, 0.0) for u in step.errors])
            rhs.append(b)
        x = np.linalg.solve(np.array(rows), np.array(rhs))
        for u, v in zip(step.errors, x, strict=True):
            values[u] = float(v)
            out[u] = float(v)
    return out
