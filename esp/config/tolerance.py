"""Tolerances of a machine and the decision rule they are decided by: the ``[tolerance]``
table of ``machine.toml``, the ``--tolerance`` / ``--rule`` / ``--guard`` options of
``esp analyse`` and the thresholds of ``esp batch`` (docs/configuration.md, "[tolerance]").

Every tolerance is an upper limit in µm (ISO 14253-1:2017, 3.1: a one-sided specification
limit) on a figure of the analysis::

    [tolerance]
    volumetric_um = 30            # the volumetric accuracy
    planar_um = 25                # every planar accuracy, or per plane: { XY = 20, XZ = 25 }
    range_um = { X = 10, Z = 12 } # the range (max - min) of a direction's error
    uncertainty_um = 5            # the expanded volumetric uncertainty itself
    rule = "guarded"              # "simple" (default) or "guarded"
    guard = 1.0                   # guarded: the guard band w as a fraction of U

The figures are decided by :mod:`esp.volumetric.conformance` with the rules of
:mod:`esp.core.conformity`. The command line overrides the file, limit by limit.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field, replace
from types import MappingProxyType
from typing import Any

from esp.config.reader import Reader
from esp.core.conformity import RULES, DecisionRule
from esp.core.errors import ConfigError
from esp.core.names import AXIS_NAMES
from esp.core.values import Quantity, ValueRefused, check, parse

__all__ = [
    "GUARD_FRACTION",
    "PLANES",
    "TOLERANCE_KEYS",
    "Tolerances",
    "parse_tolerance_options",
    "read_tolerance",
    "rule_from_options",
]

#: the planes of the planar accuracy
PLANES = ("XY", "XZ", "YZ")
#: the keys of ``[tolerance]``
TOLERANCE_KEYS = ("volumetric_um", "planar_um", "range_um", "uncertainty_um", "rule", "guard")
#: the guard band as a fraction of U (``guard``, ``--guard``): above 0, at most 3
GUARD_FRACTION = Quantity("a guard band fraction of U", "", 0.0, 3.0, above_low=True)
#: the quantities ``--tolerance`` names, as in ``--tolerance planar.XY=20``
OPTION_QUANTITIES = ("volumetric", "planar", "range", "uncertainty")


def _frozen(mapping: Mapping[str, float]) -> Mapping[str, float]:
    return MappingProxyType(dict(mapping))


@dataclass(frozen=True)
class Tolerances:
    """Upper limits in µm (None or absent: not checked) and the decision rule.

    ``planar_all_um`` applies to every plane without a limit of its own in ``planar_um``;
    ``range_um`` maps a direction to the limit of the range of its error; ``rule`` is
    None when neither the file nor the command line names one (simple acceptance then);
    ``source`` the file the limits were read from, for messages."""

    volumetric_um: float | None = None
    planar_all_um: float | None = None
    planar_um: Mapping[str, float] = field(default_factory=lambda: _frozen({}))
    range_um: Mapping[str, float] = field(default_factory=lambda: _frozen({}))
    uncertainty_um: float | None = None
    rule: DecisionRule | None = None
    source: str | None = None

    @property
    def empty(self) -> bool:
        """True when no limit is set (a rule alone decides nothing)."""
        return (
            self.volumetric_um is None
            and self.planar_all_um is None
            and not self.planar_um
            and not self.range_um
            and self.uncertainty_um is None
        )

    @property
    def decision_rule(self) -> DecisionRule:
        """The rule the figures are decided by: simple acceptance unless one is named."""
        return self.rule if self.rule is not None else DecisionRule("simple")

    def planar_limit(self, plane: str) -> float | None:
        """The limit of the planar accuracy of ``plane``, or None."""
        return self.planar_um.get(plane, self.planar_all_um)

    def overridden_by(self, other: Tolerances) -> Tolerances:
        """These tolerances with every limit (and the rule) ``other`` sets taking over:
        the command line over the file. A planar limit for every plane replaces the
        file's per-plane limits too."""
        planar = {} if other.planar_all_um is not None else dict(self.planar_um)
        planar.update(other.planar_um)
        ranges = dict(self.range_um)
        ranges.update(other.range_um)
        return Tolerances(
            volumetric_um=_first(other.volumetric_um, self.volumetric_um),
            planar_all_um=_first(other.planar_all_um, self.planar_all_um),
            planar_um=_frozen(planar),
            range_um=_frozen(ranges),
            uncertainty_um=_first(other.uncertainty_um, self.uncertainty_um),
            rule=other.rule if other.rule is not None else self.rule,
            source=self.source,
        )

    def limits_text(self) -> str:
        """The limits in words: ``"volumetric accuracy ≤ 30 µm; planar XY ≤ 20 µm"``."""
        parts = []
        if self.volumetric_um is not None:
            parts.append(f"volumetric accuracy ≤ {self.volumetric_um:g} µm")
        if self.planar_all_um is not None:
            parts.append(f"every planar accuracy ≤ {self.planar_all_um:g} µm")
        parts += [f"planar {p} ≤ {v:g} µm" for p, v in sorted(self.planar_um.items())]
        parts += [f"range of the {d} error ≤ {v:g} µm" for d, v in sorted(self.range_um.items())]
        if self.uncertainty_um is not None:
            parts.append(f"volumetric uncertainty ≤ {self.uncertainty_um:g} µm")
        return "; ".join(parts) if parts else "none"


def _first(a: float | None, b: float | None) -> float | None:
    return a if a is not None else b


def read_tolerance(reader: Reader, value: Any) -> Tolerances:
    """Read the ``[tolerance]`` table (module docstring); every problem is a
    :class:`~esp.core.errors.ConfigError` naming its key."""
    t = reader.table(value, "tolerance", TOLERANCE_KEYS)
    planar_all: float | None = None
    planar: dict[str, float] = {}
    if "planar_um" in t:
        given = t["planar_um"]
        if isinstance(given, Mapping):
            sub = reader.table(given, "tolerance.planar_um", PLANES)
            planar = {
                p: reader.number(v, f"tolerance.planar_um.{p}", "threshold") for p, v in sub.items()
            }
        else:
            planar_all = reader.number(given, "tolerance.planar_um", "threshold")
    ranges: dict[str, float] = {}
    if "range_um" in t:
        sub = reader.table(t["range_um"], "tolerance.range_um", AXIS_NAMES)
        ranges = {
            d: reader.number(v, f"tolerance.range_um.{d}", "threshold") for d, v in sub.items()
        }
    rule = None
    if "rule" in t or "guard" in t:
        kind = reader.choice(t.get("rule", "simple"), "tolerance.rule", RULES)
        guard = 1.0
        if "guard" in t:
            if kind != "guarded":
                reader.fail("tolerance.guard", 'a guard band needs rule = "guarded"')
            guard = reader.number(t["guard"], "tolerance.guard", GUARD_FRACTION)
        rule = replace(_rule(kind, guard, "tolerance.guard"), key="tolerance.rule")
    try:
        return Tolerances(
            volumetric_um=_number(reader, t, "volumetric_um"),
            planar_all_um=planar_all,
            planar_um=_frozen(planar),
            range_um=_frozen(ranges),
            uncertainty_um=_number(reader, t, "uncertainty_um"),
            rule=rule,
            source=reader.source,
        )
    except ConfigError as exc:  # pragma: no cover - every value is checked above
        raise ConfigError(exc.key, exc.message, reader.source) from None


def _number(reader: Reader, t: Mapping[str, Any], key: str) -> float | None:
    return reader.number(t[key], f"tolerance.{key}", "threshold") if key in t else None


def _rule(kind: str, guard: float, key: str) -> DecisionRule:
    """A :class:`DecisionRule`, its range errors naming ``key``."""
    return DecisionRule(kind, guard, key)  # type: ignore[arg-type]


def parse_tolerance_options(texts: Iterable[str], option: str = "--tolerance") -> Tolerances:
    """The limits of repeated ``--tolerance QUANTITY=UM`` options: ``volumetric=30``,
    ``planar=25`` (every plane), ``planar.XY=20``, ``range.X=10``, ``uncertainty=5``.
    A malformed one raises :class:`ConfigError` naming the option and the text."""
    limits: dict[str, Any] = {"planar_um": {}, "range_um": {}}
    seen: set[str] = set()
    for text in texts:
        name, sep, value = text.partition("=")
        name = name.strip()
        quantity, dot, part = name.partition(".")
        quantity = quantity.lower()
        expected = (
            "expected QUANTITY=UM with QUANTITY one of volumetric, planar, planar.XY (XZ, YZ), "
            f"range.X (Y, Z), uncertainty, found {text!r}"
        )
        if not sep or quantity not in OPTION_QUANTITIES:
            raise ConfigError(option, expected)
        part = part.strip().upper()
        if (
            (quantity in ("volumetric", "uncertainty") and dot)
            or (quantity == "planar" and dot and part not in PLANES)
            or (quantity == "range" and part not in AXIS_NAMES)
        ):
            raise ConfigError(option, expected)
        key = f"{quantity}.{part}" if dot else quantity
        if key in seen:
            raise ConfigError(option, f"{key} is given twice")
        seen.add(key)
        try:
            limit = check(parse(value, "threshold"), "threshold")
        except ValueRefused as exc:
            raise ConfigError(option, f"{key}: {exc.message}") from None
        if quantity == "planar" and dot:
            limits["planar_um"][part] = limit
        elif quantity == "planar":
            limits["planar_all_um"] = limit
        elif quantity == "range":
            limits["range_um"][part] = limit
        else:
            limits[f"{quantity}_um"] = limit
    limits["planar_um"] = _frozen(limits["planar_um"])
    limits["range_um"] = _frozen(limits["range_um"])
    return Tolerances(**limits)


def rule_from_options(rule: str | None, guard: float | None) -> DecisionRule | None:
    """The rule of ``--rule`` / ``--guard`` (None when neither is given). ``--guard``
    needs ``--rule guarded``; errors name the option."""
    if guard is not None and rule != "guarded":
        raise ConfigError("--guard", "a guard band needs --rule guarded")
    if rule is None:
        return None
    if rule not in RULES:
        raise ConfigError("--rule", f"expected one of {', '.join(RULES)}, found {rule!r}")
    checked = _rule(rule, 1.0 if guard is None else guard, "--guard")
    return replace(checked, key="--rule")
