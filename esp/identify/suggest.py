"""Which extra probing would help a plan most: ``esp identify --plan --suggest N``.

For a plan with a probed-sphere set (esp.identify.rotary), every setting of the machine's
``[table].angles`` not yet in the plan is tried as one more probing of the set's first
sphere, at its nominal place (T(θ)⁻¹ s, s the sphere's place from the plan's own
readings), and the plan is evaluated again (``plan``: the design alone, nothing fitted).
The candidates are ranked by the rank they give, then by the D-criterion of the table's
coefficients -- the sum of the logarithms of their expected standard uncertainties, each
relative to its unit, smaller is better (the volume of their confidence ellipsoid;
Atkinson, Donev & Tobias 2007, ch. 10) -- so that the first one named is the probing that
sees what the plan cannot, or that tightens the table's errors most.
"""

from __future__ import annotations

import itertools
import math
import tempfile
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from esp.core.errors import ConfigError
from esp.identify.config import Problem
from esp.identify.rotary import nominal_transform, setting_rows
from esp.identify.tables import read_table

__all__ = ["Suggestion", "suggest", "suggestion_lines"]


@dataclass(frozen=True)
class Suggestion:
    """One extra probing: the set and sphere, the setting, the rank it gives (of the
    plan's parameters), the D-criterion (lower is better) and the expected expanded U of
    each table error (name, U, unit), and what would still be unseen."""

    set_name: str
    sphere: str
    setting_deg: dict[str, float]
    rank: int
    parameters: int
    criterion: float
    U: tuple[tuple[str, float, str], ...]
    unseen: tuple[str, ...]


def _criterion(names: tuple[str, ...], u: tuple[float, ...], table_names: set[str]) -> float:
    return float(
        sum(math.log(max(v, 1e-300)) for n, v in zip(names, u, strict=True) if n in table_names)
    )


def suggest(problem: Problem, count: int) -> tuple[Suggestion | None, list[Suggestion]]:
    """The plan as it is (as a :class:`Suggestion` of no setting) and the ``count`` best
    extra probings (see the module docstring).

    Raises
    ------
    ConfigError
        No probed-sphere set to add a probing to, or no table angles to choose from.
    """
    from esp.identify.run import plan

    spec = next((s for s in problem.measurements if s.kind == "sphere" and s.use == "fit"), None)
    if spec is None or problem.machine.table is None:
        raise ConfigError(
            "--suggest",
            "suggests extra probings of a probed sphere: the plan has no set of kind 'sphere'",
            problem.source,
        )
    table = problem.machine.table.table
    coords = table.coordinates
    data = read_table(spec.files[0], ("X", "Y", "Z", *coords), ("sphere",), ("u_um",))
    rows = setting_rows(data, coords, "sphere")
    sphere = rows.labels[0]
    idx = np.array([i for i, g in enumerate(rows.labels) if g == sphere])
    R, t = nominal_transform(table, {c: a[idx] for c, a in rows.angles.items()})
    s = (np.einsum("nij,nj->ni", R, rows.positions[idx]) + t).mean(axis=0)
    taken = {tuple(round(float(rows.angles[c][i]), 9) for c in coords) for i in idx}
    grid = problem.machine.table.angles_deg
    candidates = [
        dict(zip(coords, combo, strict=True))
        for combo in itertools.product(*(grid[c] for c in coords))
        if tuple(round(float(v), 9) for v in combo) not in taken
    ]
    if not candidates:
        raise ConfigError(
            "table.angles",
            "every setting of [table].angles is in the plan already: give more angles to "
            "choose an extra probing from",
            problem.source,
        )
    table_names = {n for u in problem.unknowns if u.on_table for n in u.coefficient_names}
    text = Path(spec.files[0]).read_text(encoding="utf-8").rstrip("\n")
    header = next(
        line for line in text.splitlines() if line.strip() and not line.lstrip().startswith("#")
    )
    # the file's own delimiter, as esp.identify.tables reads it
    delimiter = (
        "," if "," in header else (";" if ";" in header else ("\t" if "\t" in header else ","))
    )
    columns = [c.strip() for c in header.split(delimiter)]

    def evaluate(extra: dict[str, float] | None, folder: Path) -> Suggestion:
        body = text
        if extra is not None:
            Rc, tc = nominal_transform(table, {c: np.array([extra[c]]) for c in coords})
            m = Rc[0].T @ (s - tc[0])
            values = {"sphere": sphere, "X": m[0], "Y": m[1], "Z": m[2], **extra}
            cells = []
            for col in columns:
                v = values.get(col, "")
                cells.append(v if isinstance(v, str) else f"{float(v):.6f}")
            if "u_um" in columns:
                cells[columns.index("u_um")] = f"{float(data.columns['u_um'][idx[0]]):g}"
            body = text + "\n" + delimiter.join(cells)
        path = folder / Path(spec.files[0]).name
        path.write_text(body + "\n", encoding="utf-8")
        trial = replace(
            problem,
            measurements=tuple(
                replace(m, files=(str(path),)) if m is spec else m for m in problem.measurements
            ),
        )
        result = plan(trial)
        ident = result.identifiability
        U = tuple((c.name, float(max(c.U)), c.unit) for c in result.curves if c.on_table)
        return Suggestion(
            spec.name,
            sphere,
            dict(extra or {}),
            ident.rank,
            ident.parameters,
            _criterion(result.names, result.u, table_names),
            U,
            tuple(ident.sentences()) if not ident.identifiable else (),
        )

    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        now = evaluate(None, folder)
        found = [evaluate(c, folder) for c in candidates]
    found.sort(key=lambda g: (-g.rank, g.criterion))
    return now, found[:count]


def suggestion_lines(now: Suggestion | None, found: list[Suggestion]) -> list[str]:
    """The suggestions as text: the plan as it is, then each extra probing with its rank
    and the expected U of the table's errors it would give."""
    if now is None:
        return []
    out = [
        "",
        f"One more probing of sphere {now.sphere!r} ({now.set_name}), best first (by rank, "
        "then by the D-criterion of the table's errors)",
    ]

    def us(g: Suggestion) -> str:
        return ", ".join(f"{n.split('.', 1)[1]} {u:.2g} {unit}" for n, u, unit in g.U)

    part = " (of the seen part only)" if now.rank < now.parameters else ""
    out.append(f"  as planned: rank {now.rank} of {now.parameters}; U{part} {us(now)}")
    for g in found:
        at = ", ".join(f"{c} = {v:g}" for c, v in g.setting_deg.items())
        out.append(f"  + {at}: rank {g.rank} of {g.parameters}; U {us(g)}")
        out.extend(f"      still unseen: {line}" for line in g.unseen)
    return out
