"""The identified machine as files esp reads: one tidy CSV profile per identified curve
(docs/formats.md, "CSV profiles"), one CSV of its expanded uncertainty, and a
``machine.toml`` that names them, so that ``esp analyse DIR/machine.toml`` runs unchanged.

The ``machine.toml`` is the input with each ``{ identify = ... }`` replaced by its profile
(a squareness by its value), the ``[identify]`` table left out, the paths of the known
components' files made relative to the output folder, and every identified component's U
in ``[uncertainty.components]`` (the correlations between identified components are in
the identification report, not in these independent U values). A machine with a rotary
table or a servo head gets its identified ``table.toml`` / ``head.toml`` beside it (an
error motion as a curve file ``table-ECC.csv`` with its ``-U`` file), their errors' U in
``[uncertainty.table]`` / ``[uncertainty.head]``, and, for a trunnion LinuxCNC describes,
``kinematics-linuxcnc.hal``.
"""

from __future__ import annotations

import copy
import datetime as _dt
import math
import os
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from esp.identify.config import Problem
from esp.identify.run import Curve, IdentifyResult

__all__ = ["file_name", "machine_toml", "profile_csv", "to_toml", "write_identified"]


def file_name(name: str, suffix: str = "") -> str:
    """``X.straightness.Y`` -> ``X-straightness-Y.csv`` (``-U`` for its uncertainty)."""
    return name.replace(".", "-") + suffix + ".csv"


def profile_csv(curve: Curve, machine_name: str, uncertainty: bool = False) -> str:
    """The curve (or its U) as a tidy CSV profile: the same values as a forward and a
    backward run, so that any ``analysis.direction`` reads them."""
    values = curve.U if uncertainty else curve.values
    kind = curve.name.split(".")[1]
    kind = "angular" if kind == "mechanical" else kind
    unit = "um" if curve.unit == "um" else "urad"
    what = "expanded uncertainty (k as in [uncertainty])" if uncertainty else "identified"
    lines = [
        f"# {curve.name} of {machine_name}, {what} by esp identify",
        f"# kind: {kind}",
        f"# axis: {curve.name.split('.')[0]}",
    ]
    if kind != "linear":
        lines.append(f"# error_direction: {curve.name.split('.')[2]}")
    lines += [f"# unit: {unit}", "target_mm,run,direction,deviation"]
    for run, direction in ((1, "forward"), (2, "backward")):
        for t, v in zip(curve.targets_mm, values, strict=True):
            lines.append(f"{t:.6f},{run},{direction},{v:.6f}")
    return "\n".join(lines) + "\n"


def _relative(value: str, base: Path, out: Path) -> str:
    path = Path(value)
    if path.is_absolute():
        return value
    return os.path.relpath(os.path.abspath(base / path), os.path.abspath(out)).replace(os.sep, "/")


def _repoint(source: Any, base: Path, out: Path) -> Any:
    """A known component's source with its file paths relative to the output folder."""
    if isinstance(source, str):
        return _relative(source, base, out)
    if isinstance(source, Mapping):
        s = dict(source)
        if isinstance(s.get("file"), str):
            s["file"] = _relative(s["file"], base, out)
        if isinstance(s.get("from_linear"), list):
            s["from_linear"] = [_relative(f, base, out) for f in s["from_linear"]]
        return s
    return source


def machine_toml(problem: Problem, result: IdentifyResult, out_dir: Path) -> dict[str, Any]:
    """The configuration of the identified machine, as a dict (see the module docstring)."""
    data = copy.deepcopy(dict(problem.raw))
    data.pop("identify", None)
    base = problem.base_dir
    for axis in data.get("axes", {}).values():
        errors = axis.get("errors", {})
        for kind, value in list(errors.items()):
            if kind == "linear":
                errors[kind] = _repoint(value, base, out_dir)
            elif isinstance(value, Mapping):
                errors[kind] = {b: _repoint(v, base, out_dir) for b, v in value.items()}
    unc = data.setdefault("uncertainty", {})
    if "k" not in unc:
        unc["k"] = result.k
    comps = unc.setdefault("components", {})
    for name, entry in list(comps.items()):
        if isinstance(entry, Mapping) and "U" in entry:
            comps[name] = dict(entry, U=_repoint(entry["U"], base, out_dir))
    for c in result.curves:
        u = next(u for u in problem.unknowns if str(u.name) == c.name)
        if u.on_device:
            continue
        parts = u.key.split(".")
        if u.name.kind == "squareness":
            data.setdefault("squareness", {})[parts[1]] = round(c.values[0], 6)
            comps[c.name] = {"U": round(c.U[0], 6), "k": result.k}
            continue
        errors = data["axes"][parts[1]].setdefault("errors", {})
        if u.name.kind == "linear":
            errors["linear"] = file_name(c.name)
        else:
            errors.setdefault(parts[3], {})[parts[4]] = file_name(c.name)
        comps[c.name] = {"U": file_name(c.name, "-U"), "k": result.k}
    for owner, file in (("table", TABLE_FILE), ("head", HEAD_FILE)):
        if getattr(problem.machine, owner) is None or owner not in data:
            continue
        angles = data[owner].get("angles")
        data[owner] = {"file": file}
        if angles is not None:
            data[owner]["angles"] = angles
        device_u = {}
        for c in result.curves:
            # one U for the error: a constant's, an error motion's largest over the angle
            # (its U at each angle is in its -U file); none for an error held at zero by
            # identify.fix (it is not identified, and zero needs no U)
            if c.device == owner and max(c.U) > 0.0:
                device_u[c.name.split(".", 1)[1]] = round(max(c.U), 6)
        if device_u:
            unc[owner] = {**unc.get(owner, {}), **device_u}
    return data


#: the identified table and head files in the output folder
TABLE_FILE = "table.toml"
HEAD_FILE = "head.toml"
#: LinuxCNC's trunnion kinematics parameters of the identified axis lines (HAL setp lines)
LINUXCNC_FILE = "kinematics-linuxcnc.hal"


def _device_source(problem: Problem, owner: str) -> tuple[dict[str, Any], Path]:
    """The ``[table]`` or ``[head]`` table of the input as given (from its file or
    inline) and the folder its relative paths start from."""
    from esp.io.tomlfile import read_toml_file

    given = problem.raw[owner]
    if "file" in given:
        path = problem.base_dir / given["file"]
        return copy.deepcopy(dict(read_toml_file(path)[owner])), path.parent
    inline = {k: v for k, v in copy.deepcopy(dict(given)).items() if k != "angles"}
    return inline, problem.base_dir


def device_toml(
    problem: Problem, result: IdentifyResult, out_dir: Path, owner: str
) -> dict[str, Any]:
    """The identified table (``owner = "table"``) or head file: the input's with each
    identified constant its value, each identified error motion a curve file
    (``table-EXC.csv``), and the paths of the chain and of the known curve and value
    files made relative to the output folder."""
    table, base = _device_source(problem, owner)
    table["chain"] = _relative(table["chain"], base, out_dir)
    given = table.get("errors_from")
    if isinstance(given, str):
        table["errors_from"] = _relative(given, base, out_dir)
    elif isinstance(given, list):
        table["errors_from"] = [_relative(f, base, out_dir) for f in given]
    errors = table.setdefault("errors", {})
    for name, entry in list(errors.items()):
        if isinstance(entry, Mapping) and isinstance(entry.get("file"), str):
            errors[name] = dict(entry, file=_relative(entry["file"], base, out_dir))
    for c in result.curves:
        if c.device != owner:
            continue
        symbol = c.name.split(".", 1)[1]
        if c.angle_axis is None:
            errors[symbol] = round(c.values[0], 6)
        else:
            u = next(u for u in problem.unknowns if str(u.name) == c.name)
            errors[symbol] = {"file": file_name(c.name)}
            if not getattr(u.basis, "periodic", True):
                errors[symbol]["periodic"] = False
    return {owner: table}


def table_curve_csv(curve: Curve, machine_name: str, uncertainty: bool = False) -> str:
    """An identified error motion (or its U) as a curve file: ``angle_deg`` and one
    column named after the error (docs/rotary.md)."""
    values = curve.U if uncertainty else curve.values
    symbol = curve.name.split(".", 1)[1]
    what = "expanded uncertainty (k as in [uncertainty])" if uncertainty else "identified"
    lines = [
        f"# {curve.name} of {machine_name} over {curve.angle_axis}, {what} by esp identify",
        f"# unit: {curve.unit}",
        f"angle_deg,{symbol}",
    ]
    lines += [f"{t:.6f},{v:.6f}" for t, v in zip(curve.targets_mm, values, strict=True)]
    return "\n".join(lines) + "\n"


# -- a small TOML writer (the configuration holds tables, strings, numbers, booleans,
# dates and lists of those)


def _key(k: str) -> str:
    if k and all(ch.isalnum() or ch in "_-" for ch in k):
        return k
    return '"' + k.replace("\\", "\\\\").replace('"', '\\"') + '"'


def _value(v: Any) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        if not math.isfinite(v):
            raise ValueError(f"not a finite number: {v!r}")
        return repr(v)
    if isinstance(v, str):
        return '"' + v.replace("\\", "\\\\").replace('"', '\\"').replace("\n", "\\n") + '"'
    if isinstance(v, _dt.date | _dt.datetime | _dt.time):
        return v.isoformat()
    if isinstance(v, list):
        return "[" + ", ".join(_value(x) for x in v) + "]"
    if isinstance(v, Mapping):
        return "{ " + ", ".join(f"{_key(k)} = {_value(x)}" for k, x in v.items()) + " }"
    raise ValueError(f"cannot write {v!r} as TOML")


def to_toml(data: Mapping[str, Any], header: str = "") -> str:
    """``data`` as TOML text: nested tables as ``[a.b]`` sections, tables inside the
    errors of an axis and the squareness values inline."""
    lines: list[str] = [header] if header else []

    def section(path: list[str], table: Mapping[str, Any]) -> None:
        simple = {k: v for k, v in table.items() if not _is_section(path, k, v)}
        nested = {k: v for k, v in table.items() if _is_section(path, k, v)}
        if path and (simple or not nested):
            lines.append("")
            lines.append("[" + ".".join(_key(p) for p in path) + "]")
        for k, v in simple.items():
            lines.append(f"{_key(k)} = {_value(v)}")
        for k, v in nested.items():
            section([*path, k], v)

    section([], data)
    return "\n".join(lines).lstrip("\n") + "\n"


def _is_section(path: list[str], key: str, value: Any) -> bool:
    """Top-level tables, the axes and their errors, a table's parameters and errors, and
    the uncertainty components and table are sections; every other table is written
    inline."""
    if not isinstance(value, Mapping):
        return False
    if not path:
        return True
    if path == ["axes"] or (len(path) == 2 and path[0] == "axes" and key == "errors"):
        return True
    if path in (["table"], ["head"]) and key in ("parameters", "errors"):
        return True
    return path == ["uncertainty"] and key in ("components", "table", "head")


def write_identified(
    folder: Path, problem: Problem, result: IdentifyResult, final: Path
) -> list[str]:
    """Write the profiles, their U and ``machine.toml`` into ``folder`` (the staged output
    folder whose final place is ``final``). Returns the names written."""
    names = []
    for c in result.curves:
        if not c.targets_mm:
            continue
        if c.on_table:
            for suffix, is_u in (("", False), ("-U", True)):
                (folder / file_name(c.name, suffix)).write_text(
                    table_curve_csv(c, result.machine_name, is_u), encoding="utf-8"
                )
                names.append(file_name(c.name, suffix))
            continue
        (folder / file_name(c.name)).write_text(
            profile_csv(c, result.machine_name), encoding="utf-8"
        )
        (folder / file_name(c.name, "-U")).write_text(
            profile_csv(c, result.machine_name, uncertainty=True), encoding="utf-8"
        )
        names += [file_name(c.name), file_name(c.name, "-U")]
    data = machine_toml(problem, result, final)
    header = (
        f"# {result.machine_name}: identified by esp identify from "
        + ", ".join(s.name for s in result.sets)
        + "\n# the identified components' U are from the covariance of the fit; their "
        "correlations are in identify.json"
    )
    (folder / "machine.toml").write_text(to_toml(data, header), encoding="utf-8")
    names.append("machine.toml")
    for owner, file, what in (
        ("table", TABLE_FILE, "rotary table"),
        ("head", HEAD_FILE, "servo head"),
    ):
        if getattr(problem.machine, owner) is None:
            continue
        text = to_toml(
            device_toml(problem, result, final, owner),
            f"# {result.machine_name}: the {what} identified by esp identify",
        )
        (folder / file).write_text(text, encoding="utf-8")
        names.append(file)
    if result.linuxcnc is not None:
        from esp.identify.axislines import linuxcnc_lines

        module, params = result.linuxcnc
        hal = [
            f"# {result.machine_name}: the table's axis lines identified by esp identify, for",
            f"# LinuxCNC's {module} (mm; positions only: the lines' tilts are in identify.txt)",
            *linuxcnc_lines(module, params),
        ]
        (folder / LINUXCNC_FILE).write_text("\n".join(hal) + "\n", encoding="utf-8")
        names.append(LINUXCNC_FILE)
    return names
