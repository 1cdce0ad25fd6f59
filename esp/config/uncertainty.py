"""The ``[uncertainty]`` table of ``machine.toml``, read into an
:class:`esp.core.uncertainty.spec.UncertaintySpec`.

Each component gets an expanded uncertainty U with its own coverage factor (``k`` of its
table, else the ``k`` of ``[uncertainty]``), a distribution and degrees of freedom; U is
either given directly (a number, or a curve along the axis: ``points``, ``constant`` or a
data file, used exactly as given) or computed by an instrument model of Longstaff (2002)
3.14.1-3.14.6 from its data file and the parameters given
(:mod:`esp.core.uncertainty.instruments`).

Refused, naming the key: a U that is negative anywhere, not finite, or beyond the
plausibility limit of its unit (:data:`esp.core.uncertainty.spec.U_LIMITS`: 1 mm for a
displacement, 0.1 rad for an angle); a U curve of a single point; a coverage factor outside
(0, 100]; degrees of freedom below 1; a coverage probability outside [0.5, 0.9999]; more
Monte Carlo samples than :data:`MONTECARLO_MAX_SAMPLES`.
"""

from __future__ import annotations

import difflib
import inspect
import math
from collections.abc import Mapping
from typing import Any

import numpy as np

from esp.config.reader import Reader
from esp.config.sources import Slot, read_source
from esp.core.errors import DataError
from esp.core.machine import Component
from esp.core.names import ComponentName, all_component_names
from esp.core.profile import ErrorProfile
from esp.core.uncertainty.instruments import MODELS, from_profile
from esp.core.uncertainty.spec import (
    DISTRIBUTIONS,
    INSTRUMENTS,
    METHODS,
    U_LIMITS,
    ComponentU,
    DeviceU,
    UncertaintySpec,
)
from esp.core.values import written

__all__ = ["K_MAX", "MONTECARLO_MAX_SAMPLES", "read_uncertainty"]

_TOP_KEYS = (
    "k",
    "coverage",
    "method",
    "samples",
    "seed",
    "components",
    "prior",
    "default",
    "head",
    "table",
)
#: the keys of ``[uncertainty] default``: a U per kind of component (µm for linear and
#: straightness, µm/m for angular -- mechanical angles with them -- and squareness), its k
#: and distribution
_DEFAULT_KINDS = ("linear", "straightness", "angular", "squareness")
_DEFAULT_KEYS = (*_DEFAULT_KINDS, "k", "distribution")
_COMPONENT_KEYS = ("U", "instrument", "distribution", "k", "dof")
#: the most Monte Carlo draws accepted (JCGM 101:2008, 7.2.2, suggests 10^6 for a 95 %
#: coverage interval); each draw keeps one value, 8 bytes
MONTECARLO_MAX_SAMPLES = 1_000_000
#: the largest coverage factor accepted (t_99 % for one degree of freedom is 63.7)
K_MAX = 100.0
_COVERAGE = (0.5, 0.9999)
_U_SOURCES = ("file", "constant", "points")


def _valid_names() -> list[str]:
    """Every component name, squareness pairs in both orders."""
    names = [str(n) for n in all_component_names()]
    return names + [f"squareness.{p[::-1]}" for p in ("XY", "XZ", "YZ")]


def _k(reader: Reader, value: Any, key: str) -> float:
    return reader.number(value, key, "coverage factor")


def read_uncertainty(
    reader: Reader,
    value: Any,
    components: Mapping[str | ComponentName, Component],
    devices: Mapping[str, Any] | None = None,
) -> UncertaintySpec:
    """Read the ``[uncertainty]`` table; ``components`` are the machine's error data,
    which the instrument models read; ``devices`` the machine's servo head and rotary
    table (``{"head": Head or None, "table": Table or None}``), whose errors
    ``[uncertainty.head]`` and ``[uncertainty.table]`` name. Returns an
    :class:`UncertaintySpec`."""
    t = reader.table(value, "uncertainty", _TOP_KEYS)
    k = _k(reader, t.get("k", 2.0), "uncertainty.k")
    method = reader.choice(t.get("method", "statistical"), "uncertainty.method", METHODS)
    coverage = None
    if "coverage" in t:
        coverage = reader.number(t["coverage"], "uncertainty.coverage")
        lo, hi = _COVERAGE
        if not lo <= coverage <= hi:
            reader.fail(
                "uncertainty.coverage",
                f"expected a coverage probability from {lo:g} to {hi:g} (0.95 for 95 %), "
                f"found {t['coverage']!r}",
            )
        if method in ("summation", "pure-addition"):
            reader.fail(
                "uncertainty.coverage",
                "a coverage probability needs the statistical combination (method = "
                f"'statistical' or 'montecarlo'); the {method} method is a sum, not a "
                "variance: give k instead",
            )
    samples = t.get("samples", 20000)
    if isinstance(samples, bool) or not isinstance(samples, int) or samples < 2:
        reader.fail("uncertainty.samples", f"expected a whole number >= 2, found {samples!r}")
    if samples > MONTECARLO_MAX_SAMPLES:
        reader.fail(
            "uncertainty.samples",
            f"expected at most {MONTECARLO_MAX_SAMPLES} Monte Carlo draws (the documented "
            f"limit), found {samples}",
        )
    seed = t.get("seed", 1)
    if isinstance(seed, bool) or not isinstance(seed, int) or seed < 0:
        reader.fail("uncertainty.seed", f"expected a whole number >= 0, found {seed!r}")
    prior = None
    if "prior" in t:
        p = reader.table(
            t["prior"], "uncertainty.prior", ("volumetric_um", "u_um"), ("volumetric_um", "u_um")
        )
        prior = (
            reader.number(p["volumetric_um"], "uncertainty.prior.volumetric_um"),
            reader.number(p["u_um"], "uncertainty.prior.u_um"),
        )
        if prior[1] <= 0:
            reader.fail(
                "uncertainty.prior.u_um",
                f"expected a standard uncertainty > 0, found {p['u_um']!r}",
            )
    comps = reader.table(t.get("components", {}), "uncertainty.components", _valid_names())
    out: dict[str, ComponentU] = {}
    for name, entry in comps.items():
        key = f'uncertainty.components."{name}"'
        canonical = ComponentName.parse(name)
        if not isinstance(entry, Mapping):
            reader.fail(key, f"expected a table with U or instrument, found {entry!r}")
        if "U" in entry and "instrument" in entry:
            reader.fail(key, "expected either U or instrument, found both")
        distribution = reader.choice(
            entry.get("distribution", "normal" if "U" in entry else "rectangular"),
            f"{key}.distribution",
            DISTRIBUTIONS,
        )
        k_own = _k(reader, entry["k"], f"{key}.k") if "k" in entry else k
        if "U" in entry:
            reader.table(entry, key, _COMPONENT_KEYS)
            dof = math.inf
            if "dof" in entry:
                dof = reader.number(entry["dof"], f"{key}.dof")
                if dof < 1:
                    reader.fail(
                        f"{key}.dof",
                        f"expected degrees of freedom >= 1 (leave it out for a U known "
                        f"exactly), found {entry['dof']!r}",
                    )
            out[str(canonical)] = _direct(
                reader, entry["U"], key, canonical, distribution, k_own, dof
            )
        elif "instrument" in entry:
            if "dof" in entry:
                reader.fail(
                    f"{key}.dof",
                    "an instrument model states its own degrees of freedom (Type A terms "
                    "from the runs); remove dof",
                )
            out[str(canonical)] = _instrument(
                reader, entry, key, canonical, distribution, k_own, components
            )
        else:
            reader.fail(f"{key}.U", "required key is missing (give U or instrument)")
    if "default" in t:
        out.update(_defaults(reader, t["default"], k, out, components))
    device_u = {}
    for owner in ("head", "table"):
        if owner in t:
            device_u.update(_device_u(reader, t[owner], owner, (devices or {}).get(owner), k))
    return UncertaintySpec(
        k=k,
        method=method,
        samples=samples,
        seed=seed,
        components=out,
        prior=prior,
        coverage=coverage,
        devices=device_u,
    )


def _device_u(reader: Reader, value: Any, owner: str, device: Any, k: float) -> dict[str, DeviceU]:
    """``[uncertainty.head]`` or ``[uncertainty.table]``: error symbol -> U (a number, in
    the error's unit, with the table's k) or ``{ U = .., k = .. }``."""
    key = f"uncertainty.{owner}"
    if device is None:
        reader.fail(key, f"the machine has no [{owner}]: remove {key}")
    # the constants and, of a table, the error motions given as curves over the angle
    # (one U for the whole curve)
    errors = [*device.errors, *getattr(device, "curves", {})]
    entries = reader.table(value, key, tuple(errors))
    out = {}
    for symbol, entry in entries.items():
        where = f"{key}.{symbol}"
        own_k = k
        if isinstance(entry, Mapping):
            reader.table(entry, where, ("U", "k"), ("U",))
            if "k" in entry:
                own_k = _k(reader, entry["k"], f"{where}.k")
            entry = entry["U"]
        big_u = reader.number(entry, where)
        unit = device.unit(symbol)
        if not (big_u > 0.0 and math.isfinite(big_u)):
            reader.fail(where, f"expected a U > 0 in {unit}, found {entry!r}")
        out[f"{owner}.{symbol}"] = DeviceU(big_u, own_k, unit)
    return out


def _defaults(
    reader: Reader,
    value: Any,
    k: float,
    given: Mapping[str, ComponentU],
    components: Mapping[str | ComponentName, Component],
) -> dict[str, ComponentU]:
    """``[uncertainty] default``: the U of every component with error data and no U of its
    own, by its kind (``model = "default"``, so that every report names it as such)."""
    d = reader.table(value, "uncertainty.default", _DEFAULT_KEYS)
    if not any(kind in d for kind in _DEFAULT_KINDS):
        reader.fail(
            "uncertainty.default",
            f"expected a U for at least one kind ({', '.join(_DEFAULT_KINDS)}), found none",
        )
    k_own = _k(reader, d["k"], "uncertainty.default.k") if "k" in d else k
    distribution = reader.choice(
        d.get("distribution", "normal"), "uncertainty.default.distribution", DISTRIBUTIONS
    )
    out: dict[str, ComponentU] = {}
    for name in components:
        canonical = ComponentName.parse(str(name))
        kind = "angular" if canonical.kind == "mechanical" else canonical.kind
        if str(canonical) in given or kind not in d:
            continue
        key = f"uncertainty.default.{kind}"
        unit = _unit(canonical)
        U = reader.number(d[kind], key)
        _check_number(reader, U, key, unit, d[kind])
        out[str(canonical)] = ComponentU(
            canonical,
            canonical.kind,
            canonical.axis,
            canonical.about,
            model="default",
            unit=unit,
            distribution=distribution,
            U=U,
            k=k_own,
            key=key,
        )
    return out


def _unit(name: ComponentName) -> str:
    return "um" if name.kind in ("linear", "straightness") else "um/m"


def _limit_text(unit: str) -> str:
    return "1 mm" if unit == "um" else "0.1 rad"


def _check_number(reader: Reader, value: float, key: str, unit: str, given: Any) -> None:
    limit = U_LIMITS[unit]
    if value < 0:
        reader.fail(key, f"expected an expanded uncertainty >= 0, found {given!r}")
    if value > limit:
        reader.fail(
            key,
            f"expected an expanded uncertainty of at most {U_LIMITS[unit]:g} {unit} "
            f"({_limit_text(unit)}, the plausibility limit), found {given!r}",
        )


def _direct(
    reader: Reader,
    value: Any,
    key: str,
    name: ComponentName,
    distribution: str,
    k: float,
    dof: float,
) -> ComponentU:
    kind, axis, about = name.kind, name.axis, name.about
    unit = _unit(name)
    common: dict[str, Any] = dict(
        model="direct", unit=unit, distribution=distribution, k=k, dof=dof
    )
    if isinstance(value, (int, float)) and not isinstance(value, bool):
        U = reader.number(value, f"{key}.U")
        _check_number(reader, U, f"{key}.U", unit, value)
        return ComponentU(name, kind, axis, about, U=U, key=f"{key}.U", **common)
    if kind == "squareness":
        # one number: U = 10.0, or written as a source, U = { constant = 10.0 } (um/m)
        if not isinstance(value, Mapping) or "constant" not in value:
            reader.fail(f"{key}.U", f"expected a number in um/m, found {value!r}")
        reader.table(value, f"{key}.U", ("constant",))
        U = reader.number(value["constant"], f"{key}.U.constant")
        _check_number(reader, U, f"{key}.U.constant", unit, value["constant"])
        return ComponentU(name, kind, axis, about, U=U, key=f"{key}.U", **common)
    slot = Slot(f"{key}.U", kind, axis, about)
    profile = read_source(reader, value, slot, _U_SOURCES).profile
    assert profile is not None  # every source but a squareness constant makes a curve
    form = next((s for s in _U_SOURCES if isinstance(value, Mapping) and s in value), "file")
    where = f"{key}.U" if isinstance(value, str) else f"{key}.U.{form}"
    _check_curve(reader, profile, where, unit, form)
    if form == "constant":
        U = float(profile.mean("mean")[0])
        return ComponentU(name, kind, axis, about, U=U, key=f"{key}.U", **common)
    return ComponentU(name, kind, axis, about, profile=profile, key=f"{key}.U", **common)


def _check_curve(reader: Reader, profile: ErrorProfile, key: str, unit: str, form: str) -> None:
    """Every value of a U curve (every run of a file) >= 0 and within the plausibility
    limit; a curve has at least two points."""
    targets = profile.targets_mm
    if form != "constant" and targets.size < 2:
        reader.fail(
            key,
            f"expected a U curve of at least two positions, found one ({targets[0]:g} mm); "
            "give a U that holds along the whole axis as a number",
        )
    for direction in profile.directions:
        runs = profile.runs[direction]
        bad = np.argwhere(runs < 0)
        what = "" if form != "file" else f" ({direction} run {{run}})"
        if bad.size:
            r, j = (int(v) for v in bad[0])
            at = "" if form == "constant" else f" at {targets[j]:g} mm"
            reader.fail(
                key,
                f"expected an expanded uncertainty >= 0 everywhere, found "
                f"{runs[r, j]:g} {unit}{at}{what.format(run=r + 1)}",
            )
        big = np.argwhere(runs > U_LIMITS[unit])
        if big.size:
            r, j = (int(v) for v in big[0])
            at = "" if form == "constant" else f" at {targets[j]:g} mm"
            reader.fail(
                key,
                f"expected an expanded uncertainty of at most {U_LIMITS[unit]:g} {unit} "
                f"({_limit_text(unit)}, the plausibility limit), found {written(runs[r, j])} {unit}"
                f"{at}{what.format(run=r + 1)}",
            )


def _instrument(
    reader: Reader,
    entry: Mapping[str, Any],
    key: str,
    name: ComponentName,
    distribution: str,
    k: float,
    components: Mapping[str | ComponentName, Component],
) -> ComponentU:
    kind, axis, about = name.kind, name.axis, name.about
    unit = _unit(name)
    instrument = reader.choice(entry["instrument"], f"{key}.instrument", tuple(INSTRUMENTS))
    model = INSTRUMENTS[instrument]
    params = {p: v for p, v in entry.items() if p not in _COMPONENT_KEYS}
    function = MODELS[model][0]
    allowed = [p for p in inspect.signature(function).parameters if p != "k"]
    if model != "angular_from_linear":
        allowed.append("statistic")  # how from_profile takes the scatter of the runs
    for p, v in params.items():
        if p not in allowed:
            hint = difflib.get_close_matches(p, allowed, n=1)
            dym = f"; did you mean {hint[0]!r}?" if hint else ""
            reader.fail(
                f"{key}.{p}",
                f"unknown parameter of instrument {instrument!r}{dym} "
                f"(expected one of {', '.join(allowed)})",
            )
        if isinstance(v, bool) or not isinstance(v, (int, float, str)):
            reader.fail(f"{key}.{p}", f"expected a number or a string, found {v!r}")
    data = components.get(name)
    try:
        if data is not None and data.profile is not None:
            budget = from_profile(model, data.profile, k=k, **params)
        else:
            params.pop("statistic", None)
            signature = inspect.signature(function).parameters.values()
            for param in signature:
                if param.default is inspect.Parameter.empty and param.name not in params:
                    reader.fail(
                        f"{key}.{param.name}",
                        f"required by instrument {instrument!r} when {name} has no data file "
                        f"to take it from; give it in this table",
                    )
            budget = function(k=k, **params)
    except DataError as exc:
        missing = getattr(exc, "name", None) if hasattr(exc, "what") else None
        reader.fail(f"{key}.{missing}" if missing else key, str(exc))
    if budget.unit != unit:
        reader.fail(
            f"{key}.instrument",
            f"instrument {instrument!r} gives U in {budget.unit}, but {name} needs {unit}",
        )
    expanded = budget.U
    if expanded > U_LIMITS[unit]:
        reader.fail(
            f"{key}.instrument",
            f"instrument {instrument!r} gives U = {budget.U:.6g} {unit}, beyond the "
            f"plausibility limit of {U_LIMITS[unit]:g} {unit} ({_limit_text(unit)}); "
            "check its parameters",
        )
    return ComponentU(
        name,
        kind,
        axis,
        about,
        instrument,
        unit,
        distribution,
        U=budget.U,
        budget=budget,
        k=budget.k,
        dof=budget.dof,
        key=f"{key}.instrument",
    )
