"""``esp derive``: the nominal tool tip and its error formulae from a kinematic chain.

sympy is imported only when formulae are derived; ``--at`` evaluates with the numeric
core alone.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any

import click
import numpy as np

from esp.config.chain import load_chain
from esp.core.errors import ConfigError
from esp.core.kinematics import position, sensitivities, taylor
from esp.core.kinematics.chain import Chain
from esp.core.values import ValueRefused, check_symbol, parse

if TYPE_CHECKING:
    from esp.core.kinematics.symbolic import Derivation

__all__ = ["derive_command", "evaluate", "parse_values"]

SCHEMA = "esp.derive/1"
_AXES = ("X", "Y", "Z")


def parse_values(text: str, option: str) -> dict[str, float]:
    """``"A=30,C=40"`` -> ``{"A": 30.0, "C": 40.0}``; click.BadParameter when malformed."""
    values: dict[str, float] = {}
    for part in text.replace(";", ",").split(","):
        if not part.strip():
            continue
        name, sep, value = part.partition("=")
        name = name.strip()
        if not sep or not name:
            raise click.BadParameter(
                f"expected NAME=value pairs such as A=30,C=40, found {part.strip()!r}",
                param_hint=option,
            )
        if name in values:
            raise click.BadParameter(f"{name} is given twice", param_hint=option)
        try:
            values[name] = parse(value)
        except ValueRefused as exc:
            raise click.BadParameter(f"{name}: {exc.message}", param_hint=option) from None
    return values


def _check_names(
    chain: Chain, given: Mapping[str, float], kinds: tuple[str, ...], option: str
) -> None:
    import difflib

    allowed = [n for n, s in chain.symbols.items() if s.kind in kinds]
    for name in given:
        if name in allowed:
            known = chain.symbols[name]
            try:  # the range of the symbol's kind, in its unit (esp.core.values.SYMBOL_LIMITS)
                check_symbol(known.kind, known.unit, given[name])
            except ValueRefused as exc:
                raise click.BadParameter(f"{name}: {exc.message}", param_hint=option) from None
            continue
        sym = chain.symbols.get(name)
        if sym is not None:
            where = "--at" if sym.kind == "coordinate" else "--set"
            message = f"{name} is a {sym.kind}; give it with {where}"
            raise click.BadParameter(message, param_hint=option)
        close = difflib.get_close_matches(name, allowed, n=1, cutoff=0.6)
        hint = f"; did you mean {close[0]!r}?" if close else ""
        what = " or ".join(f"{k}s" for k in kinds)
        raise click.BadParameter(
            f"{name} is not one of the chain's {what}{hint} ({', '.join(allowed) or 'none'})",
            param_hint=option,
        )


def evaluate(
    chain: Chain, at: Mapping[str, float], values: Mapping[str, float], order: int
) -> dict[str, Any]:
    """The ``esp.derive/1`` document with numbers: the nominal tool tip (mm) and its
    first-order (and second-order, and exact) error (µm) at one point, with each error's
    term. ``at`` holds the coordinates, ``values`` parameters and errors, each in its
    symbol's unit; errors not given take the chain's default values, or zero."""
    params = {n: v for n, v in values.items() if chain.symbols[n].kind == "parameter"}
    errors = {
        n: s.value for n, s in chain.symbols.items() if s.kind == "error" and s.value is not None
    }
    errors.update({n: v for n, v in values.items() if chain.symbols[n].kind == "error"})
    nominal = position(chain, at, params)[0]
    sens = sensitivities(chain, at, params)
    terms = []
    first = np.zeros(3)
    for name in chain.errors:
        value = errors.get(name, 0.0)
        contribution = sens[name][0] * value * 1000.0
        first += contribution
        if value != 0.0:
            terms.append(
                {
                    "error": name,
                    "value": value,
                    "unit": chain.symbols[name].unit,
                    **{a: contribution[k] for k, a in enumerate(_AXES)},
                }
            )
    exact = (position(chain, at, params, errors)[0] - nominal) * 1000.0
    used = {n: chain.symbols[n].value for n in chain.parameters}
    used.update(params)
    doc: dict[str, Any] = {
        "schema": SCHEMA,
        "chain": chain.name,
        "order": order,
        "at": dict(at),
        "values": {**used, **errors},
        "units": {
            "nominal": "mm",
            "first_order": "um",
            **({"second_order": "um"} if order == 2 else {}),
            "exact": "um",
            "terms": "um",
        },
        "nominal": {a: nominal[k] for k, a in enumerate(_AXES)},
        "first_order": {a: first[k] for k, a in enumerate(_AXES)},
    }
    if order == 2:
        expansion = taylor(chain, at, params, errors, order=2)
        assert expansion.second is not None
        second = expansion.second[0] * 1000.0
        doc["second_order"] = {a: second[k] for k, a in enumerate(_AXES)}
    doc["exact"] = {a: exact[k] for k, a in enumerate(_AXES)}
    doc["terms"] = terms
    doc["symbols"] = {n: {"kind": s.kind, "unit": s.unit} for n, s in chain.symbols.items()}
    return doc


# -- text -----------------------------------------------------------------------------------


def _fmt(x: float, digits: int = 6) -> str:
    s = f"{x:.{digits}f}"
    return "0." + "0" * digits if s.strip("-0.") == "" else s


def _header(chain: Chain) -> list[str]:
    lines = [f"{chain.name}: {len(chain.steps)} steps"]
    for kind in ("coordinate", "parameter", "error"):
        names = [n for n, s in chain.symbols.items() if s.kind == kind]
        if names:
            shown = ", ".join(names) if len(names) <= 12 else ", ".join(names[:12]) + ", ..."
            lines.append(f"{kind}s ({len(names)}): {shown}")
    return lines


def _sum_lines(label: str, terms: list[Any]) -> list[str]:
    """``DX = + a*(...)`` with one term per line, the signs aligned."""
    if not terms:
        return [f"{label} = 0"]
    out = []
    pad = " " * (len(label) + 3)
    for i, term in enumerate(terms):
        text = str(term)
        sign, body = ("-", text[1:]) if text.startswith("-") else ("+", text)
        out.append(f"{label + ' = ' if i == 0 else pad}{sign} {body}")
    return out


def render_formulae(derivation: Derivation) -> str:
    import sympy as sp  # type: ignore[import-untyped]

    from esp.core.kinematics.symbolic import signed_term

    chain = derivation.chain
    syms = {n: sp.Symbol(n) for n in chain.symbols}
    lines = _header(chain)
    lines.append("lengths in mm, angles in rad in every formula")
    lines.append("")
    lines.append("Nominal tool tip")
    for a in _AXES:
        lines.append(f"  {a} = {derivation.nominal[a]}")
    lines.append("")
    lines.append("First order (each term linear in one small error)")
    for a in _AXES:
        terms = [signed_term(syms[n], c) for n, c in derivation.first_terms[a].items()]
        lines.extend("  " + s for s in _sum_lines(f"D{a}", terms))
    if derivation.second_terms is not None:
        lines.append("")
        lines.append("Second order (each term a product of two small errors)")
        for a in _AXES:
            terms = [
                signed_term(syms[e1] * syms[e2], c)
                for (e1, e2), c in derivation.second_terms[a].items()
            ]
            lines.extend("  " + s for s in _sum_lines(f"D{a}", terms))
    return "\n".join(lines) + "\n"


def render_values(chain: Chain, doc: Mapping[str, Any]) -> str:
    def unit(n: str) -> str:
        return chain.symbols[n].unit

    lines = _header(chain)
    at = ", ".join(f"{n} = {v:g} {unit(n)}" for n, v in doc["at"].items())
    lines.append(f"at: {at or '(no coordinates)'}")
    kinds = {n: chain.symbols[n].kind for n in doc["values"]}
    params = [f"{n} = {v:g} {unit(n)}" for n, v in doc["values"].items() if kinds[n] == "parameter"]
    if params:
        lines.append("parameters: " + ", ".join(params))
    errs = [
        f"{n} = {v:g} {unit(n)}" for n, v in doc["values"].items() if kinds[n] == "error" and v != 0
    ]
    shown = ", ".join(errs) if errs else ("all zero" if chain.errors else "none in the chain")
    if errs and len(errs) < len(chain.errors):
        shown += " (the others zero)"
    lines.append("errors: " + shown)
    lines.append("")
    rows = [("nominal (mm)", doc["nominal"]), ("first order (um)", doc["first_order"])]
    if "second_order" in doc:
        rows.append(("second order (um)", doc["second_order"]))
    rows.append(("exact (um)", doc["exact"]))
    lines.append(f"{'':<18}{'X':>14}{'Y':>14}{'Z':>14}")
    for label, v in rows:
        lines.append(f"{label:<18}" + "".join(f"{_fmt(v[a]):>14}" for a in _AXES))
    if doc["terms"]:
        lines.append("")
        lines.append("first-order terms (um)")
        width = max(len(t["error"]) for t in doc["terms"])
        for t in doc["terms"]:
            value = f"{t['value']:g} {t['unit']}"
            lines.append(
                f"  {t['error']:<{width}}  {value:>16}"
                + "".join(f"{_fmt(t[a]):>14}" for a in _AXES)
            )
    return "\n".join(lines) + "\n"


# -- the command ----------------------------------------------------------------------------


@click.command("derive")
@click.argument("chain_toml", type=click.Path(dir_okay=False, path_type=Path))
@click.option(
    "--order",
    type=click.IntRange(1, 2),
    default=1,
    show_default=True,
    help="1: nominal and first order; 2: also the terms in products of two small errors.",
)
@click.option(
    "--at",
    "at_text",
    metavar="NAME=V,...",
    help="Evaluate numerically at these coordinates (each in its unit, e.g. degrees).",
)
@click.option(
    "--set",
    "set_text",
    metavar="NAME=V,...",
    help="Parameter and error values for --at (each in its unit), over the file's values.",
)
@click.option(
    "--json",
    "json_target",
    metavar="PATH|-",
    help="Write the esp.derive/1 document to PATH, or to standard output with '-'.",
)
def derive_command(
    chain_toml: Path,
    order: int,
    at_text: str | None,
    set_text: str | None,
    json_target: str | None,
) -> None:
    """Nominal tool tip and error formulae of the kinematic chain in CHAIN_TOML.

    Prints the nominal X, Y, Z of the tool tip and its first-order errors DX, DY, DZ as
    simplified formulae, one error's term per line (Freeman & Ford 2003: products of more
    than ORDER small errors dropped, exact trigonometry of the large angles). In every
    formula lengths are in mm and angles in radians. With --at, evaluates instead: the
    nominal position (mm) and the first-order, second-order (--order 2) and exact errors
    (µm) at those coordinates, with the error values of the file and --set.

    \b
    Examples:
      esp derive data/examples/chains/loh-2004-scmm.toml
      esp derive data/examples/heads/angle-head.toml --order 2 --json formulae.json
      esp derive data/examples/heads/angle-head.toml --at "A=30,C=40" --set "G=20,e=10,Yp=50"
    """
    from esp.cli.output import CommandOutputs

    at = parse_values(at_text, "--at") if at_text is not None else None
    values = parse_values(set_text, "--set") if set_text is not None else {}
    outputs = CommandOutputs([chain_toml], json_target)
    chain = load_chain(chain_toml)
    for name, sym in chain.symbols.items():  # the chain's own values within their range
        if sym.value is not None and sym.kind != "coordinate":
            try:
                check_symbol(sym.kind, sym.unit, sym.value)
            except ValueRefused as exc:
                raise ConfigError(f"symbols.{name}.value", exc.message, chain.source) from None
    _check_names(chain, values, ("parameter", "error"), "--set")
    numeric = at is not None or (set_text is not None and not chain.coordinates)
    if set_text is not None and not numeric:
        raise click.UsageError(
            "--set gives values for a numeric evaluation; give the coordinates with --at "
            f"({', '.join(chain.coordinates)})"
        )
    if numeric:
        at = at or {}
        _check_names(chain, at, ("coordinate",), "--at")
        missing = [c for c in chain.coordinates if c not in at]
        if missing:
            raise click.BadParameter(
                f"missing {', '.join(missing)}; give every coordinate "
                f"({', '.join(chain.coordinates)})",
                param_hint="--at",
            )
        doc = evaluate(chain, at, values, order)
        text = render_values(chain, doc)
    else:
        from esp.core.kinematics.symbolic import derive

        derivation = derive(chain, order)
        doc = derivation.to_dict()
        text = render_formulae(derivation)
    with outputs:
        outputs.finish(text=text, doc=doc)
