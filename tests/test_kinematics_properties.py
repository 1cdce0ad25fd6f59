"""Property tests over random chains built from every kind of step.

Three independent routes to the first order must agree: the numeric sensitivities
(prefix rotations × suffix points), the Taylor jets, and the symbolic derivation; and all
must be the derivative of the exact 4×4 chain (central finite differences). The exact chain
minus the first-order prediction shrinks as the square of the errors' scale, minus the
second-order prediction as the cube.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import esp.core.kinematics as K

AXES = ("x", "y", "z", "-x", "-y", "-z")
SLOTS = ("tx", "ty", "tz", "rx", "ry", "rz")


class RandomChain:
    """A random chain, with values for its coordinates, parameters and errors."""

    def __init__(self, seed: int, n_steps: int | None = None):
        rng = np.random.default_rng(seed)
        self.rng = rng
        self.symbols: dict[str, dict] = {
            "L1": {"kind": "parameter", "unit": "mm", "value": float(rng.uniform(20, 300))},
            "L2": {"kind": "parameter", "unit": "mm", "value": float(rng.uniform(-300, -20))},
            "L3": {"kind": "parameter", "unit": "mm", "value": float(rng.uniform(5, 80))},
            "T1": {"kind": "parameter", "unit": "deg", "value": float(rng.uniform(20, 70))},
        }
        self.errors: list[str] = []
        self.coords: dict[str, str] = {}
        kinds = ["translate", "rotate", "prismatic", "revolute", "motion"]
        n = n_steps or int(rng.integers(3, 8))
        picks = list(rng.choice(kinds, size=n))
        # every kind at least once in longer chains
        if n >= len(kinds):
            picks[: len(kinds)] = kinds
            rng.shuffle(picks)
        self.steps = [getattr(self, f"_{k}")() for k in picks]
        self.chain = K.Chain(self.steps, self.symbols, name=f"random {seed}")

    def _error(self, dim: str) -> str:
        name = f"e{len(self.errors) + 1}"
        self.errors.append(name)
        self.symbols[name] = {"kind": "error", "unit": "um" if dim == "length" else "urad"}
        return name

    def _pick(self, options):
        return options[int(self.rng.integers(len(options)))]

    def _length(self, with_error: bool = True) -> str:
        base = self._pick(["0", "L1", "-L2", "L1*cos(T1)", "L3/tan(T1)", "2*L2 - L1", "12.5"])
        if with_error and self.rng.random() < 0.4:
            base = f"{base} + {self._error('length')}"
        return base

    def _translate(self):
        return K.translate(self._length(), self._length(), self._length())

    def _rotate(self):
        options = ["T1", "-T1", "deg(35)", "pi/3 - T1", None, None]
        angle = self._pick(options)
        if angle is None:
            angle = f"-{self._error('angle')}" if self.rng.random() < 0.5 else "T1 + {}"
            if "{}" in angle:
                angle = angle.format(self._error("angle"))
        return K.rotate(self._pick(AXES), angle)

    def _slots(self) -> dict:
        chosen = [s for s in SLOTS if self.rng.random() < 0.6] or ["rz"]
        out = {}
        for s in chosen:
            e = self._error("length" if s[0] == "t" else "angle")
            form = self._pick(["{}", "{}", "-{}", "{}*cos(T1)", "{}*L3/L1"])
            out[s] = form.format(e)
        return out

    def _pivot(self):
        return tuple(self._pick([0, "L1", "L3", "-L3"]) for _ in range(3))

    def _joint(self, kind: str):
        name = f"{'q' if kind == 'prismatic' else 'a'}{len(self.coords) + 1}"
        self.coords[name] = kind
        self.symbols[name] = {"kind": "coordinate", "unit": "mm" if kind == "prismatic" else "deg"}
        errors = self._slots() if self.rng.random() < 0.85 else None
        pivot = self._pivot() if errors else None
        build = K.prismatic if kind == "prismatic" else K.revolute
        return build(self._pick(AXES), name, errors, pivot)

    def _prismatic(self):
        return self._joint("prismatic")

    def _revolute(self):
        return self._joint("revolute")

    def _motion(self):
        return K.error_motion(**self._slots(), pivot=self._pivot())

    def coordinates(self, n: int) -> dict[str, np.ndarray]:
        return {
            c: self.rng.uniform(-400, 400, n)
            if k == "prismatic"
            else self.rng.uniform(-180, 180, n)
            for c, k in self.coords.items()
        }

    def error_values(self, scale: float = 1.0) -> dict[str, float]:
        return {e: float(self.rng.uniform(-200, 200)) * scale for e in self.errors}


SEEDS = st.integers(min_value=0, max_value=2**32 - 1)


@pytest.mark.slow
@settings(max_examples=40, deadline=None, derandomize=True)
@given(SEEDS)
def test_sensitivities_are_the_derivative_of_the_exact_chain(seed):
    rc = RandomChain(seed)
    chain = rc.chain
    at = rc.coordinates(6)
    sens = K.sensitivities(chain, at)
    assert list(sens) == list(chain.errors)
    h = 5.0  # µm or µrad
    for e in chain.errors:
        up = K.position(chain, at, errors={e: h})
        down = K.position(chain, at, errors={e: -h})
        fd = (up - down) / (2 * h)
        scale = np.abs(fd).max() + 1e-9
        np.testing.assert_allclose(sens[e], fd, rtol=0, atol=1e-6 * scale + 1e-12, err_msg=e)


@pytest.mark.slow
@settings(max_examples=40, deadline=None, derandomize=True)
@given(SEEDS)
def test_sensitivities_agree_with_the_taylor_jets(seed):
    rc = RandomChain(seed)
    at = rc.coordinates(5)
    errors = rc.error_values()
    sens = K.sensitivities(rc.chain, at)
    first = sum((sens[e] * v for e, v in errors.items()), np.zeros((1, 3)))
    expansion = K.taylor(rc.chain, at, errors=errors, order=2)
    np.testing.assert_allclose(expansion.first, first, rtol=1e-10, atol=1e-13)
    np.testing.assert_allclose(expansion.nominal, K.position(rc.chain, at), rtol=1e-12, atol=1e-10)
    np.testing.assert_allclose(
        K.transforms(rc.chain, at, errors=errors)[:, :3, 3],
        K.position(rc.chain, at, errors=errors),
        rtol=1e-12,
        atol=1e-10,
    )


@pytest.mark.slow
@settings(max_examples=25, deadline=None, derandomize=True)
@given(SEEDS)
def test_truncation_error_shrinks_with_the_order(seed):
    """exact − first order ∝ t², exact − first − second order ∝ t³ as the errors scale by t."""
    rc = RandomChain(seed, n_steps=6)
    at = rc.coordinates(4)
    errors = rc.error_values(scale=20.0)  # up to 4 mm and 4 mrad
    nominal = K.position(rc.chain, at)
    expansion = K.taylor(rc.chain, at, errors=errors, order=2)
    res1, res2 = [], []
    for t in (1.0, 0.1):
        exact = K.position(rc.chain, at, errors={e: v * t for e, v in errors.items()})
        res1.append(np.abs(exact - nominal - t * expansion.first).max())
        res2.append(np.abs(exact - nominal - t * expansion.first - t * t * expansion.second).max())
    if res1[0] > 1e-9:  # a chain whose second order vanishes has nothing to shrink
        assert 70 < res1[0] / res1[1] < 130, res1
    if res2[0] > 1e-9:
        assert 600 < res2[0] / res2[1] < 1400, res2


# -- numeric against symbolic -----------------------------------------------------------------

sp = pytest.importorskip("sympy")


def _numeric(expr, names, env):
    f = sp.lambdify([sp.Symbol(n) for n in names], expr, "numpy")
    return np.broadcast_to(np.asarray(f(*[env[n] for n in names]), dtype=float), (len(env["_"]),))


@pytest.mark.slow
@pytest.mark.parametrize("seed", [3, 11, 19, 27, 42, 77])
def test_symbolic_first_and_second_order_equal_the_numeric_ones(seed):
    rc = RandomChain(seed, n_steps=5)
    chain = rc.chain
    derivation = K.derive(chain, order=2)
    n = 4
    at = rc.coordinates(n)
    errors = rc.error_values()
    env, _ = chain.environment(at, None, errors)  # mm and rad, as in the formulae
    env = {k: np.broadcast_to(v, (n,)) for k, v in env.items()}
    env["_"] = np.zeros(n)
    names = list(chain.symbols)
    sens = K.sensitivities(chain, at)
    nominal = K.position(chain, at)
    expansion = K.taylor(chain, at, errors=errors, order=2)
    for k, axis in enumerate("XYZ"):
        np.testing.assert_allclose(
            _numeric(derivation.nominal[axis], names, env), nominal[:, k], rtol=1e-11, atol=1e-9
        )
        for e in chain.errors:
            coefficient = derivation.first_terms[axis].get(e, 0)
            symbolic = _numeric(coefficient, names, env) * chain.symbols[e].scale
            np.testing.assert_allclose(symbolic, sens[e][:, k], rtol=1e-10, atol=1e-14)
        second = _numeric(derivation.second_order[axis], names, env)
        np.testing.assert_allclose(second, expansion.second[:, k], rtol=1e-9, atol=1e-15)
        first = _numeric(derivation.first_order[axis], names, env)
        np.testing.assert_allclose(first, expansion.first[:, k], rtol=1e-9, atol=1e-14)


@pytest.mark.parametrize("seed", [5, 8])
def test_second_order_is_half_the_second_derivative_of_the_exact_chain(seed):
    rc = RandomChain(seed, n_steps=6)
    at = rc.coordinates(3)
    errors = rc.error_values()
    expansion = K.taylor(rc.chain, at, errors=errors, order=2)
    h = 2.0

    def p(t):
        return K.position(rc.chain, at, errors={e: v * t for e, v in errors.items()})

    fd = (p(h) - 2 * p(0.0) + p(-h)) / (2 * h * h)
    scale = np.abs(fd).max() + 1e-12
    np.testing.assert_allclose(expansion.second, fd, rtol=0, atol=1e-4 * scale)
