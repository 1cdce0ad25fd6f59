"""``machine.toml`` for identification: the components to identify, the measurement sets
and the user's choices about what the data cannot see.

An error source may be ``{ identify = { basis = "legendre", degree = 4 } }`` (or
``basis = "bspline", knots = N``), a squareness ``{ identify = true }``; the ``[identify]``
table names the measurement sets and the choices (docs/identify.md). Everything else is
read by the ordinary reader (:func:`esp.config.machine_from_dict`) into the machine of the
known components, so that the identified machine is evaluated by the same engine.
"""

from __future__ import annotations

import copy
import os
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from esp.config.machine import machine_from_dict
from esp.config.reader import Reader
from esp.core.machine import Machine
from esp.core.names import AXIS_NAMES, ComponentName
from esp.identify.basis import BASES, Basis
from esp.identify.rotary import AngleBasis, DeviceErrorName, head_unknowns, table_unknowns
from esp.io.tomlfile import read_toml_file

__all__ = [
    "FORMS",
    "KINDS",
    "MeasurementSpec",
    "Problem",
    "Unknown",
    "load_problem",
    "problem_from_dict",
]

KINDS = ("points", "lengths", "stations", "sphere", "rtest", "rotary-ballbar")
#: the forms of a lengths set
FORMS = ("ballbar", "mcg", "diagonal", "stepgauge")
NULL_CHOICES = ("refuse", "minimum-norm")
#: what to do with a fit whose residuals its stated uncertainties cannot explain
#: (esp.identify.run.INCONSISTENT_BIRGE): refuse it, or report it with a warning
INCONSISTENT_CHOICES = ("refuse", "accept")
#: the default cap on the steps of the fit (``[identify] max_iterations``;
#: esp.identify.solve.fit), and the largest cap accepted
MAX_ITERATIONS = 50
MAX_ITERATIONS_LIMIT = 10000
_IDENTIFY_KEYS = (
    "k",
    "fix",
    "null",
    "rank_tolerance",
    "measurements",
    "targets",
    "inconsistent",
    "max_iterations",
)
_COMMON = ("kind", "file", "u_um", "use", "tool_mm", "calibration")
#: the keys of a set's ``calibration`` table: the standard uncertainty of the artefact's
#: length (µm) and of its scale (µm/m), each common to every reading of the set
CALIBRATION_KEYS = ("u_um", "u_ppm")
_SET_KEYS = {
    "points": (*_COMMON, "scale"),
    "lengths": (*_COMMON, "form", "files", "centre", "radius", "pivot", "length", "placement"),
    "stations": (*_COMMON, "stations"),
    "sphere": ("kind", "file", "u_um", "use", "tool_mm", "probe", "calibration"),
    "rtest": ("kind", "file", "u_um", "use", "tool_mm", "sensors", "calibration"),
    "rotary-ballbar": (
        "kind",
        "file",
        "u_um",
        "use",
        "tool_mm",
        "pivot_mm",
        "length_mm",
        "pivot",
        "length",
        "calibration",
    ),
}
MAX_DEGREE = 12
MAX_KNOTS = 40
#: the positions an identified curve is written at, over the travel
DEFAULT_TARGETS = 101


@dataclass(frozen=True)
class Unknown:
    """One component to identify: its name, the key it was given at, its basis (None for
    a squareness or a table's location error, one constant coefficient; an
    :class:`~esp.identify.rotary.AngleBasis` for a table's error motion)."""

    name: ComponentName | DeviceErrorName
    key: str
    basis: Basis | AngleBasis | None

    @property
    def on_device(self) -> bool:
        """An error of the rotary table or the servo head (not of the linear axes)."""
        return isinstance(self.name, DeviceErrorName)

    @property
    def on_table(self) -> bool:
        """An error of the rotary table."""
        return isinstance(self.name, DeviceErrorName) and self.name.owner == "table"

    @property
    def on_head(self) -> bool:
        """An error of the servo head."""
        return isinstance(self.name, DeviceErrorName) and self.name.owner == "head"

    @property
    def labels(self) -> tuple[str, ...]:
        return ("",) if self.basis is None else self.basis.labels

    @property
    def coefficient_names(self) -> tuple[str, ...]:
        if self.basis is None:
            return (str(self.name),)
        return tuple(f"{self.name}[{lab}]" for lab in self.labels)


@dataclass(frozen=True)
class MeasurementSpec:
    """One measurement set of ``[identify.measurements]``: its name and kind, the file(s),
    the stated standard uncertainty per file (µm; None: per reading, column ``u_um``), the
    options of its kind (``tool_mm``: the offset of the probed point from the MCP it was
    measured with, for every kind; for points and stations also a table label -> offset,
    the file's column ``tool`` naming each reading's), and whether it is fitted
    (``use = "fit"``) or a check."""

    name: str
    kind: str
    key: str
    files: tuple[str, ...]
    u_um: float | None
    options: Mapping[str, Any] = field(default_factory=dict)
    use: str = "fit"
    #: the standard uncertainties of the artefact's calibration, common to all its
    #: readings: ``{"u_um": ...}`` (a length) and/or ``{"u_ppm": ...}`` (a scale, µm/m)
    calibration: Mapping[str, float] = field(default_factory=dict)


@dataclass(frozen=True)
class Problem:
    """What ``esp identify`` was asked: the machine of the known components, the unknowns,
    the measurement sets and the choices."""

    machine: Machine
    unknowns: tuple[Unknown, ...]
    measurements: tuple[MeasurementSpec, ...]
    fix: tuple[str, ...]
    null: str
    k: float
    rank_tolerance: float
    raw: Mapping[str, Any]
    base_dir: Path
    source: str | None
    inputs: tuple[str, ...]
    #: "refuse" a fit far beyond its stated uncertainties, or "accept" it with a warning
    inconsistent: str = "refuse"
    #: the cap on the steps of the fit (esp.identify.solve.fit)
    max_iterations: int = MAX_ITERATIONS


def load_problem(path: str | os.PathLike[str]) -> Problem:
    """Read a ``machine.toml`` with components to identify and ``[identify]``."""
    p = Path(path)
    return problem_from_dict(read_toml_file(p), p.parent, source=str(p))


def _pop_identify_sources(data: dict, reader: Reader) -> list[tuple[str, ComponentName, Any]]:
    """Take every ``{ identify = ... }`` source out of ``data`` (in place)."""
    found: list[tuple[str, ComponentName, Any]] = []
    axes = data.get("axes")
    if isinstance(axes, Mapping):
        for n in AXIS_NAMES:
            errors = axes.get(n, {}).get("errors") if isinstance(axes.get(n), Mapping) else None
            if not isinstance(errors, dict):
                continue
            linear = errors.get("linear")
            if isinstance(linear, Mapping) and "identify" in linear:
                found.append((f"axes.{n}.errors.linear", ComponentName("linear", n), linear))
                del errors["linear"]
            for kind in ("straightness", "angular", "mechanical"):
                sub = errors.get(kind)
                if not isinstance(sub, dict):
                    continue
                for about in list(sub):
                    v = sub[about]
                    if isinstance(v, Mapping) and "identify" in v:
                        key = f"axes.{n}.errors.{kind}.{about}"
                        try:
                            name = ComponentName(kind, n, about)
                        except ValueError as exc:
                            reader.fail(key, str(exc))
                        found.append((key, name, v))
                        del sub[about]
                if not sub:
                    del errors[kind]
    sq = data.get("squareness")
    if isinstance(sq, dict):
        for pair in list(sq):
            v = sq[pair]
            if isinstance(v, Mapping) and "identify" in v:
                key = f"squareness.{pair}"
                if len(pair) != 2 or any(c not in AXIS_NAMES for c in pair) or pair[0] == pair[1]:
                    reader.fail(key, f"expected a pair of two axes such as XY, found {pair!r}")
                found.append((key, ComponentName.squareness(pair[0], pair[1]), v))
                del sq[pair]
        if not sq:
            del data["squareness"]
    return found


def _targets(machine: Machine, axis: str, count: int) -> tuple[float, ...]:
    """Where a curve of ``axis`` is written: ``count`` even steps over the travel and every
    grid position of the simulation, so that the engine reads it at its targets."""
    lo, hi = machine.axes[axis].travel_mm
    t = np.concatenate([np.linspace(lo, hi, count), machine.axes[axis].grid_mm()])
    t = np.unique(np.round(t, 6))
    keep = [t[0]]
    for x in t[1:]:
        if x - keep[-1] >= 1e-3:
            keep.append(x)
        else:
            keep[-1] = x if x in (lo, hi) else keep[-1]
    return tuple(float(x) for x in keep)


def _unknown(
    reader: Reader, key: str, name: ComponentName, value: Mapping, machine: Machine, count: int
) -> Unknown:
    reader.table(value, key, ("identify",))
    spec = value["identify"]
    if name.kind == "squareness":
        if spec is not True:
            reader.fail(
                f"{key}.identify", f"expected true for a squareness (one number), found {spec!r}"
            )
        return Unknown(name, key, None)
    k = f"{key}.identify"
    if not isinstance(spec, Mapping):
        reader.fail(
            k, f'expected a table such as {{ basis = "legendre", degree = 4 }}, found {spec!r}'
        )
    basis = reader.choice(spec.get("basis"), f"{k}.basis", BASES) if "basis" in spec else None
    if basis is None:
        reader.fail(f"{k}.basis", f"required key is missing (one of {', '.join(BASES)})")
    assert name.axis is not None
    lo, hi = machine.axes[name.axis].travel_mm
    if hi <= lo:
        reader.fail(k, f"axis {name.axis} does not move (axes.{name.axis}.travel): nothing to fit")
    if basis == "legendre":
        reader.table(spec, k, ("basis", "degree"), ("degree",))
        size = spec["degree"]
        low = 2 if name.kind == "straightness" else 1
        if isinstance(size, bool) or not isinstance(size, int) or not low <= size <= MAX_DEGREE:
            reader.fail(
                f"{k}.degree",
                f"expected a whole number from {low} to {MAX_DEGREE}"
                f"{' (a straightness has no constant and no slope)' if low == 2 else ''}, "
                f"found {size!r}",
            )
    else:
        reader.table(spec, k, ("basis", "knots"), ("knots",))
        size = spec["knots"]
        if isinstance(size, bool) or not isinstance(size, int) or not 0 <= size <= MAX_KNOTS:
            reader.fail(
                f"{k}.knots", f"expected a whole number from 0 to {MAX_KNOTS}, found {size!r}"
            )
    targets = _targets(machine, name.axis, count)
    return Unknown(name, key, Basis(basis, size, name.kind, (lo, hi), targets))


def _files(reader: Reader, value: Any, key: str) -> Path:
    given = reader.string(value, key)
    path = reader.base_dir / given
    if not given.strip() or not path.is_file():
        reader.fail(key, f"no such file {given!r} (looked for {str(path)!r})")
    return path


def _offset(reader: Reader, t: Any, key: str, more: str = "") -> tuple[float, float, float]:
    if not isinstance(t, list) or len(t) != 3:
        also = f" ({more} such as {{ A = [0, 0, -50], B = [40, 0, -50] }})" if more else ""
        reader.fail(
            key,
            f"expected the offset [x, y, z] in mm of the probed point from the MCP{also}, "
            f"found {t!r}",
        )
    x, y, z = (reader.position(v, f"{key}[{i}]") for i, v in enumerate(t))
    return (x, y, z)


def _measurement(reader: Reader, name: str, value: Any) -> MeasurementSpec:
    key = f"identify.measurements.{name}"
    if not isinstance(value, Mapping):
        reader.fail(key, f"expected a table with kind and file, found {value!r}")
    if "kind" not in value:
        reader.fail(f"{key}.kind", f"required key is missing (one of {', '.join(KINDS)})")
    kind = reader.choice(value["kind"], f"{key}.kind", KINDS)
    reader.table(value, key, _SET_KEYS[kind])
    u = None
    if "u_um" in value:
        u = reader.number(value["u_um"], f"{key}.u_um")
        if not 0 < u <= 1000:
            reader.fail(
                f"{key}.u_um", f"expected a standard uncertainty > 0 and <= 1000 µm, found {u!r}"
            )
    use = reader.choice(value.get("use", "fit"), f"{key}.use", ("fit", "check"))
    options: dict[str, Any] = {}
    files: list[str] = []
    if kind == "lengths":
        form = reader.choice(value.get("form"), f"{key}.form", FORMS) if "form" in value else None
        if form is None:
            reader.fail(f"{key}.form", f"required key is missing (one of {', '.join(FORMS)})")
        options["form"] = form
        if form == "diagonal":
            if "file" in value:
                reader.fail(f"{key}.file", "a diagonal set names its files in 'files'")
            t = value.get("files")
            if not isinstance(t, Mapping) or not t:
                reader.fail(
                    f"{key}.files",
                    f'expected a table of diagonal -> file such as {{ PPP = "PPP.rtl" }}, '
                    f"found {t!r}",
                )
            names = []
            for d, f in t.items():
                files.append(str(_files(reader, f, f"{key}.files.{d}")))
                names.append(d.upper())
            options["diagonals"] = tuple(names)
            if u is None:
                reader.fail(
                    f"{key}.u_um", "required key is missing (a diagonal file has no u_um column)"
                )
        else:
            wanted = {
                "ballbar": ("centre", "radius"),
                "mcg": ("pivot", "length", "placement"),
                "stepgauge": (),
            }
            for opt in ("centre", "radius", "pivot", "length", "placement", "files"):
                if opt in value and opt not in wanted[form]:
                    reader.fail(f"{key}.{opt}", f"not used by form {form!r}; remove it")
            for opt in wanted[form]:
                if opt == "placement":
                    options[opt] = reader.boolean(value.get(opt, False), f"{key}.{opt}")
                else:
                    options[opt] = reader.choice(
                        value.get(opt, "unknown"), f"{key}.{opt}", ("known", "unknown")
                    )
    if kind == "points":
        options["scale"] = reader.boolean(value.get("scale", False), f"{key}.scale")
    if kind == "sphere":
        options["probe"] = reader.choice(
            value.get("probe", "known"), f"{key}.probe", ("known", "unknown")
        )
    if kind == "rtest":
        options["sensors"] = _sensors(reader, value.get("sensors"), f"{key}.sensors")
    if kind == "rotary-ballbar":
        k = f"{key}.pivot_mm"
        if "pivot_mm" not in value:
            reader.fail(
                k, "required: the table ball's nominal centre [x, y, z], workpiece frame, mm"
            )
        options["pivot_mm"] = _offset(reader, value["pivot_mm"], k)
        if "length_mm" not in value:
            reader.fail(f"{key}.length_mm", "required: the bar's nominal length, mm")
        length = reader.number(value["length_mm"], f"{key}.length_mm")
        if not 1.0 <= length <= 10000.0:
            reader.fail(
                f"{key}.length_mm", f"expected a length from 1 to 10000 mm, found {length!r}"
            )
        options["length_mm"] = length
        for opt, default in (("pivot", "unknown"), ("length", "known")):
            options[opt] = reader.choice(
                value.get(opt, default), f"{key}.{opt}", ("known", "unknown")
            )
    if kind == "stations":
        t = value.get("stations")
        if not isinstance(t, Mapping) or not t:
            reader.fail(
                f"{key}.stations",
                "required: the approximate position of each station, mm, such as "
                "{ S1 = [-500, 0, 300], ... }",
            )
        approx = {}
        for s, xyz in t.items():
            if not isinstance(xyz, list) or len(xyz) != 3:
                reader.fail(f"{key}.stations.{s}", f"expected [x, y, z] in mm, found {xyz!r}")
            approx[str(s)] = tuple(
                reader.position(v, f"{key}.stations.{s}[{i}]") for i, v in enumerate(xyz)
            )
        options["stations"] = approx
    if "tool_mm" in value:
        t = value["tool_mm"]
        several = kind in ("points", "stations")
        if isinstance(t, Mapping) and several and t:
            # several styli (reflector offsets), the file's column ``tool`` says which
            options["tool_mm"] = {
                str(label): _offset(reader, xyz, f"{key}.tool_mm.{label}")
                for label, xyz in t.items()
            }
        else:
            options["tool_mm"] = _offset(
                reader, t, f"{key}.tool_mm", "or a table of them" if several else ""
            )
    if not files:
        if "file" not in value:
            reader.fail(f"{key}.file", "required key is missing (the measurement table)")
        files.append(str(_files(reader, value["file"], f"{key}.file")))
    calibration = _calibration(reader, value.get("calibration"), key, kind, options)
    return MeasurementSpec(name, kind, key, tuple(files), u, options, use, calibration)


def _sensors(reader: Reader, value: Any, key: str) -> dict[str, tuple[float, float, float]]:
    """An R-test's ``sensors = { d1 = [1, 0, 0], ... }``: each sensor's measuring direction
    in machine axes (normalised), three or more spanning space."""
    if not isinstance(value, Mapping) or len(value) < 3:
        reader.fail(
            key,
            "required: three or more sensors and their directions in machine axes, such as "
            f"{{ d1 = [1, 0, 0], d2 = [0, 1, 0], d3 = [0, 0, 1] }}, found {value!r}",
        )
    out = {}
    for label, xyz in value.items():
        k = f"{key}.{label}"
        if not isinstance(xyz, list) or len(xyz) != 3:
            reader.fail(k, f"expected a direction [x, y, z], found {xyz!r}")
        v = np.array([reader.number(x, f"{k}[{i}]") for i, x in enumerate(xyz)])
        norm = float(np.linalg.norm(v))
        if not norm > 0:
            reader.fail(k, "expected a direction, found the zero vector")
        out[str(label)] = tuple(float(x) for x in v / norm)
    if np.linalg.matrix_rank(np.array(list(out.values())), tol=1e-3) < 3:
        reader.fail(key, "the sensors' directions span a plane or a line; they must span space")
    return out  # type: ignore[return-value]


def _calibration(
    reader: Reader, value: Any, key: str, kind: str, options: Mapping[str, Any]
) -> dict[str, float]:
    """A set's ``calibration = { u_um = ..., u_ppm = ... }``: the standard uncertainty of
    the artefact's length (µm; a ballbar, an MCG arm, a step gauge) and of its scale (µm/m;
    a plate, a step gauge, a laser or tracker), each one error common to every reading of
    the set. Refused where the set fits that error itself (it would add nothing): a length
    where a length or offset per circle, sphere, diagonal or station is fitted, a scale of
    a plate fitted with ``scale = true``."""
    if value is None:
        return {}
    k = f"{key}.calibration"
    if not isinstance(value, Mapping) or not value:
        reader.fail(
            k,
            "expected a table such as { u_um = 0.5 } (the artefact's length) or "
            f"{{ u_ppm = 1.0 }} (its scale, µm/m), found {value!r}",
        )
    reader.table(value, k, CALIBRATION_KEYS)
    form = options.get("form")
    length_fitted = options.get("radius", options.get("length")) == "unknown"
    out: dict[str, float] = {}
    for name in CALIBRATION_KEYS:
        if name not in value:
            continue
        unit = "µm" if name == "u_um" else "µm/m"
        v = reader.number(value[name], f"{k}.{name}")
        if not 0 < v <= 1000:
            reader.fail(
                f"{k}.{name}",
                f"expected a standard uncertainty > 0 and <= 1000 {unit}, found {v!r}",
            )
        if kind == "rtest":
            if name == "u_um":
                reader.fail(
                    f"{k}.{name}",
                    "an R-test's sensors are zeroed on each path (a zero is fitted per path "
                    "and sensor): give their gain's calibration (u_ppm) instead",
                )
        elif kind == "rotary-ballbar":
            if options.get("length") == "unknown":
                reader.fail(
                    f"{k}.{name}",
                    "the length is fitted (length = 'unknown'): its calibration adds "
                    "nothing; remove it or make the length 'known'",
                )
        elif kind == "sphere":
            if name == "u_ppm":
                reader.fail(
                    f"{k}.{name}",
                    "a probed sphere has no scale of its own: give the probe's offset "
                    "calibration (u_um)",
                )
            if options.get("probe") == "unknown":
                reader.fail(
                    f"{k}.{name}",
                    "the probe's offset is fitted (probe = 'unknown'): its calibration adds "
                    "nothing; remove it or make the probe 'known'",
                )
        elif name == "u_um":
            if kind != "lengths" or form == "diagonal":
                what = {"points": "a placement", "stations": "a dead path"}.get(kind, "an offset")
                reader.fail(
                    f"{k}.{name}",
                    f"a common length error is {what} this set fits already; give its scale "
                    "(u_ppm) instead",
                )
            if length_fitted:
                reader.fail(
                    f"{k}.{name}",
                    "the length is fitted (the set's radius or length = 'unknown'): its "
                    "calibration adds nothing; remove it or make the length 'known'",
                )
        elif kind != "sphere":
            if kind == "points" and options.get("scale"):
                reader.fail(
                    f"{k}.{name}",
                    "the plate's scale is fitted (scale = true): its calibration adds "
                    "nothing; remove it or set scale = false",
                )
            if length_fitted:
                reader.fail(
                    f"{k}.{name}",
                    "the length is fitted (the set's radius or length = 'unknown'): its "
                    "calibration adds nothing; remove it or make the length 'known'",
                )
        out[name] = v
    return out


def problem_from_dict(
    data: Mapping[str, Any], base_dir: str | os.PathLike[str], source: str | None = None
) -> Problem:
    """A :class:`Problem` from the parsed content of a ``machine.toml``."""
    base = Path(base_dir)
    raw = copy.deepcopy(dict(data))
    work = copy.deepcopy(dict(data))
    reader = Reader(base, source)
    section = work.pop("identify", None)
    if section is None:
        reader.fail("identify", "required table is missing ([identify.measurements])")
    t = reader.table(section, "identify", _IDENTIFY_KEYS, ("measurements",))
    found = _pop_identify_sources(work, reader)
    machine = machine_from_dict(work, base, source, identify=True)
    if machine.analysis.model != "rigid-body" or machine.analysis.angle_convention != "iso230-1":
        reader.fail(
            "analysis.model",
            "identification uses the rigid-body model with ISO 230-1 angles (model = "
            "'rigid-body', angle_convention = 'iso230-1')",
        )
    count = DEFAULT_TARGETS
    if "targets" in t:
        count = t["targets"]
        if isinstance(count, bool) or not isinstance(count, int) or not 11 <= count <= 2001:
            reader.fail(
                "identify.targets", f"expected a whole number from 11 to 2001, found {count!r}"
            )
    unknowns = tuple(_unknown(reader, key, name, v, machine, count) for key, name, v in found)
    if machine.table is not None:
        unknowns += tuple(
            Unknown(name, key, basis)
            for name, key, basis in table_unknowns(
                machine.table.table, machine.table.angles_deg, count
            )
        )
    if machine.head is not None:
        unknowns += tuple(
            Unknown(name, key, None) for name, key in head_unknowns(machine.head.head)
        )
    if not unknowns:
        reader.fail(
            "axes",
            "no component to identify: give at least one source as "
            '{ identify = { basis = "legendre", degree = 4 } } (or a table error as '
            "{ identify = true })",
        )
    k = reader.number(t.get("k", 2.0), "identify.k")
    if not 0 < k <= 100:
        reader.fail("identify.k", f"expected a coverage factor > 0 and <= 100, found {k!r}")
    null = reader.choice(t.get("null", "refuse"), "identify.null", NULL_CHOICES)
    inconsistent = reader.choice(
        t.get("inconsistent", "refuse"), "identify.inconsistent", INCONSISTENT_CHOICES
    )
    tol = reader.number(t.get("rank_tolerance", 1e-6), "identify.rank_tolerance")
    if not 0 < tol < 0.1:
        reader.fail("identify.rank_tolerance", f"expected a number > 0 and < 0.1, found {tol!r}")
    iterations = t.get("max_iterations", MAX_ITERATIONS)
    if (
        isinstance(iterations, bool)
        or not isinstance(iterations, int)
        or not 1 <= iterations <= MAX_ITERATIONS_LIMIT
    ):
        reader.fail(
            "identify.max_iterations",
            f"expected a whole number of steps from 1 to {MAX_ITERATIONS_LIMIT}, "
            f"found {iterations!r}",
        )
    fix = t.get("fix", [])
    if not isinstance(fix, list) or not all(isinstance(f, str) for f in fix):
        reader.fail("identify.fix", f"expected a list of names, found {fix!r}")
    sets = t["measurements"]
    if not isinstance(sets, Mapping) or not sets:
        reader.fail("identify.measurements", "expected a table of measurement sets, found none")
    specs = tuple(_measurement(reader, n, v) for n, v in sets.items())
    for spec in specs:
        if (
            spec.kind in ("sphere", "rotary-ballbar")
            and machine.head is not None
            and "tool_mm" in spec.options
        ):
            reader.fail(
                f"{spec.key}.tool_mm",
                "the servo head gives the tool's offset at each setting; remove tool_mm",
            )
        if (
            spec.kind == "sphere"
            and machine.head is not None
            and (spec.calibration or spec.options.get("probe") == "unknown")
        ):
            reader.fail(
                f"{spec.key}.{'calibration' if spec.calibration else 'probe'}",
                "the probe turns with the servo head: an error of its offset is not a "
                "constant in machine axes but an error of the head's chain (its tool "
                "length); identify that error of the head instead",
            )
        if (
            spec.kind in ("sphere", "rtest", "rotary-ballbar")
            and machine.table is None
            and machine.head is None
        ):
            what = {"sphere": "a probed sphere", "rtest": "an R-test"}.get(
                spec.kind, "a ballbar with a rotary axis moving"
            )
            reader.fail(
                f"{spec.key}.kind",
                f"{what} measures rotary axes: the machine has no [table] or [head]",
            )
    inputs = list(machine.inputs) + [f for s in specs for f in s.files]
    return Problem(
        machine=machine,
        unknowns=unknowns,
        measurements=specs,
        fix=tuple(fix),
        null=null,
        k=k,
        rank_tolerance=tol,
        raw=raw,
        base_dir=base,
        source=source,
        inputs=tuple(dict.fromkeys(inputs)),
        inconsistent=inconsistent,
        max_iterations=iterations,
    )
