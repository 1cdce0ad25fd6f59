"""The ``[uncertainty]`` table of ``machine.toml``, read into an
:class:`esp.uncertainty.spec.UncertaintySpec`.

Each component gets an expanded uncertainty U with the coverage factor ``k`` of the table,
either given directly (a number, or a curve along the axis like any error source) or
computed by an instrument model of Longstaff (2002) 3.14.1-3.14.6 from its data file and
the parameters given (:mod:`esp.uncertainty.instruments`).
"""

from __future__ import annotations

import difflib
import inspect
from collections.abc import Mapping
from typing import Any

from esp.config.reader import Reader
from esp.config.sources import Slot, read_source
from esp.errors import DataError
from esp.machine import Component
from esp.names import ComponentName, all_component_names
from esp.uncertainty.instruments import MODELS, from_profile
from esp.uncertainty.spec import DISTRIBUTIONS, INSTRUMENTS, METHODS, ComponentU, UncertaintySpec

__all__ = ["read_uncertainty"]

_TOP_KEYS = ("k", "method", "samples", "seed", "components", "prior")
_COMPONENT_KEYS = ("U", "instrument", "distribution")


def _valid_names() -> list[str]:
    """Every component name, squareness pairs in both orders."""
    names = [str(n) for n in all_component_names()]
    return names + [f"squareness.{p[::-1]}" for p in ("XY", "XZ", "YZ")]


def read_uncertainty(reader: Reader, value: Any, components: Mapping[str, Component]):
    """Read the ``[uncertainty]`` table; ``components`` are the machine's error data,
    which the instrument models read. Returns an :class:`UncertaintySpec`."""
    t = reader.table(value, "uncertainty", _TOP_KEYS)
    k = reader.number(t.get("k", 2.0), "uncertainty.k")
    if k <= 0:
        reader.fail("uncertainty.k", f"expected a coverage factor > 0, found {t['k']!r}")
    method = reader.choice(t.get("method", "statistical"), "uncertainty.method", METHODS)
    samples = t.get("samples", 20000)
    if isinstance(samples, bool) or not isinstance(samples, int) or samples < 2:
        reader.fail("uncertainty.samples", f"expected a whole number >= 2, found {samples!r}")
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
        kind, axis, about = canonical.kind, canonical.axis, canonical.about
        if not isinstance(entry, Mapping):
            reader.fail(key, f"expected a table with U or instrument, found {entry!r}")
        if "U" in entry and "instrument" in entry:
            reader.fail(key, "expected either U or instrument, found both")
        distribution = reader.choice(
            entry.get("distribution", "normal" if "U" in entry else "rectangular"),
            f"{key}.distribution",
            DISTRIBUTIONS,
        )
        unit = "um" if kind in ("linear", "straightness") else "um/m"
        if "U" in entry:
            reader.table(entry, key, _COMPONENT_KEYS)
            out[canonical] = _direct(
                reader, entry["U"], key, kind, axis, about, canonical, unit, distribution
            )
        elif "instrument" in entry:
            out[canonical] = _instrument(
                reader, entry, key, kind, axis, about, canonical, unit, distribution, k, components
            )
        else:
            reader.fail(f"{key}.U", "required key is missing (give U or instrument)")
    return UncertaintySpec(
        k=k, method=method, samples=samples, seed=seed, components=out, prior=prior
    )


def _direct(reader, value, key, kind, axis, about, name, unit, distribution) -> ComponentU:
    if isinstance(value, (int, float)) and not isinstance(value, bool):
        U = reader.number(value, f"{key}.U")
        if U < 0:
            reader.fail(f"{key}.U", f"expected an expanded uncertainty >= 0, found {value!r}")
        return ComponentU(name, kind, axis, about, "direct", unit, distribution, U=U)
    if kind == "squareness":
        reader.fail(f"{key}.U", f"expected a number in um/m, found {value!r}")
    slot = Slot(f"{key}.U", kind, axis, about)
    profile = read_source(reader, value, slot).profile
    return ComponentU(name, kind, axis, about, "direct", unit, distribution, profile=profile)


def _instrument(reader, entry, key, kind, axis, about, name, unit, distribution, k, components):
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
        param = getattr(exc, "name", None) if hasattr(exc, "what") else None
        reader.fail(f"{key}.{param}" if param else key, str(exc))
    if budget.unit != unit:
        reader.fail(
            f"{key}.instrument",
            f"instrument {instrument!r} gives U in {budget.unit}, but {name} needs {unit}",
        )
    return ComponentU(
        name, kind, axis, about, instrument, unit, distribution, U=budget.U, budget=budget
    )
