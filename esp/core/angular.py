"""Angular error from two linear positioning measurements (the indirect method).

An angular error of an axis shows up as a linear positioning error that grows with the
distance from the line it was measured on. Measuring the linear error of the same axis on
two parallel lines a known, signed distance ``D`` apart (the *reference* run and the
*shifted* run) therefore gives the angle at every target as the difference of the two
deviations over ``D``, made zero at a chosen datum target (Longstaff 2002, 3.08.1)::

    angle_i = (b_i - a_i) / D  -  (b_datum - a_datum) / D

with ``a`` the reference and ``b`` the shifted deviations. On a machine with volumetric
compensation this is the only correct source of the angles used at the MCP: what it
measures is the *residual* slope left after compensation, not the mechanical angle that
angular optics see (3.08; cases 3.10.2, 3.10.4 and 3.10.5).

Units: deviations in µm, ``D`` in mm, so ``(b - a) / D`` is in µm/mm = mrad; one µm/mm is
1000 µm/m. A difference of 8 µm over D = 800 mm is 8 / 800 x 1000 = 10 µm/m.

Runs are paired: run j of the shifted file is compared with run j of the reference in each
direction, so the result keeps one angle curve per run and its means per direction are the
differences of the files' means. One datum correction, taken from the mean curve of the
chosen direction, is removed from every run: that curve is exactly zero at the datum and
the difference between forward and backward angles is kept.

References
----------
Longstaff (2002), section 3.08 (measurement of a compensated machine, eq. 3.13),
3.08.1 (angular error calculation pseudo-code), 3.10.2-3.10.5 (which angles each case
needs), 4.02.2 (X-axis pitch from runs at two Z positions on a turning machine).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import PurePath

import numpy as np

from esp.core.errors import DataError
from esp.core.profile import DIRECTIONS, ErrorProfile, normalise_direction
from esp.core.units import MIN_SPACING_MM, POSITION_LIMIT_MM, beyond_limit, limit_text

__all__ = [
    "ANGULAR_SCHEMA",
    "UM_PER_M_PER_UM_PER_MM",
    "IndirectAngle",
    "angular_from_linear",
    "datum_index",
]

#: the name and version of the JSON document of ``esp angular``
ANGULAR_SCHEMA = "esp.angular/1"

#: 1 µm of deviation per mm of displacement is 1000 µm/m (= 1 mrad)
UM_PER_M_PER_UM_PER_MM = 1000.0

#: targets (and the datum) closer than this are the same position, mm
_TARGET_TOLERANCE_MM = 1e-6
_SHOW_TARGETS = 8


def _name(profile: ErrorProfile, fallback: str) -> str:
    """The file name of a profile's source, control characters shown escaped (``\\n``) so
    that it fits on one line of a message or of a Laser10 file."""
    if not profile.source:
        return fallback
    name = PurePath(profile.source).name
    return "".join(c if c.isprintable() else repr(c)[1:-1] for c in name)


def _show(targets: np.ndarray) -> str:
    values = [f"{float(t):g}" for t in targets]
    if len(values) > _SHOW_TARGETS:
        values = values[: _SHOW_TARGETS - 2] + ["...", values[-1]]
    return ", ".join(values)


def _same_target(a: float, b: float) -> bool:
    return abs(a - b) <= _TARGET_TOLERANCE_MM + 1e-12 * max(abs(a), abs(b))


@dataclass(frozen=True)
class IndirectAngle:
    """An angular error derived from two linear measurements.

    Attributes
    ----------
    profile : angular :class:`~esp.core.profile.ErrorProfile`, µm/m; one run per pair of runs
        of the two files, in the same directions
    displacement_mm : the signed distance D from the reference line to the shifted one
    datum_mm : the target where the chosen mean angle is zero
    direction : ``"forward"``, ``"backward"`` or ``"mean"``: the curve made zero at the datum
    reference, shifted : where the two linear measurements came from (None if unknown)
    """

    profile: ErrorProfile
    displacement_mm: float
    datum_mm: float
    direction: str
    reference: str | None = None
    shifted: str | None = None

    @property
    def targets_mm(self) -> np.ndarray:
        return self.profile.targets_mm

    def curve(self, direction: str) -> np.ndarray | None:
        """The mean angle over the runs of a direction, µm/m, shape (n,); None when the
        files hold no runs in that direction. ``"mean"``: the average of the two."""
        d = normalise_direction(direction)
        if d != "mean" and d not in self.profile.runs:
            return None
        return self.profile.mean(d)

    def to_dict(self) -> dict:
        """The JSON object of ``esp angular --json``.

        Keys: ``schema`` (``"esp.angular/1"``), ``unit`` (``"um/m"``), ``displacement_mm``,
        ``datum_mm``, ``targets_mm``,
        ``angle`` (``forward``, ``backward``: mean over the runs of that direction, null when
        there are none; ``mean``: their average), then ``datum_direction``, ``runs``
        (count per direction), ``reference`` and ``shifted`` (the two files).
        """
        return {
            "schema": ANGULAR_SCHEMA,
            "unit": "um/m",
            "displacement_mm": self.displacement_mm,
            "datum_mm": self.datum_mm,
            "targets_mm": self.targets_mm,
            "angle": {d: self.curve(d) for d in (*DIRECTIONS, "mean")},
            "datum_direction": self.direction,
            "runs": {d: self.profile.run_count(d) for d in DIRECTIONS},
            "reference": self.reference,
            "shifted": self.shifted,
        }


def _check_pair(reference: ErrorProfile, shifted: ErrorProfile) -> None:
    """The error traps of thesis 3.08.1 step 2: corresponding targets and runs."""
    ra, rb = _name(reference, "the reference"), _name(shifted, "the shifted run")
    for profile, name in ((reference, ra), (shifted, rb)):
        if profile.kind != "linear":
            raise DataError(
                f"{name}: expected linear positioning data for an indirect angle, found "
                f"{profile.kind} data"
            )
    if reference.axis and shifted.axis and reference.axis != shifted.axis:
        raise DataError(
            f"{ra} is a measurement of the {reference.axis} axis but {rb} of the "
            f"{shifted.axis} axis; expected two measurements of the same axis"
        )
    ta, tb = reference.targets_mm, shifted.targets_mm
    if ta.size != tb.size:
        raise DataError(
            f"expected the same targets in both files, found {ta.size} targets in {ra} "
            f"({_show(ta)}) and {tb.size} in {rb} ({_show(tb)})"
        )
    for i, (a, b) in enumerate(zip(ta, tb, strict=True)):
        if not _same_target(float(a), float(b)):
            raise DataError(
                f"expected the same targets in both files, found target {i + 1} at "
                f"{float(a):g} mm in {ra} but at {float(b):g} mm in {rb}"
            )
    for d in DIRECTIONS:
        na, nb = reference.run_count(d), shifted.run_count(d)
        if na != nb:
            raise DataError(
                f"expected the same runs in both files, found {na} {d} run"
                f"{'s' if na != 1 else ''} in {ra} and {nb} in {rb}"
            )


def datum_index(targets: np.ndarray, datum_mm: float) -> int:
    """The index of the target at ``datum_mm`` (within 1e-6 mm); DataError if none is."""
    hits = [i for i, t in enumerate(targets) if _same_target(float(t), datum_mm)]
    if not hits:
        raise DataError(
            f"the datum {datum_mm:g} mm is not a target of the files; expected one of "
            f"{_show(targets)} mm"
        )
    return hits[0]


def angular_from_linear(
    reference: ErrorProfile,
    shifted: ErrorProfile,
    displacement_mm: float,
    datum_mm: float,
    direction: str = "mean",
    *,
    error_direction: str | None = None,
) -> IndirectAngle:
    """The angular error of an axis from two of its linear positioning measurements.

    Parameters
    ----------
    reference : linear profile measured on the reference line (the one with, nominally, no
        angular effect), deviations ``a`` in µm
    shifted : linear profile measured on a line displaced by ``displacement_mm``,
        deviations ``b`` in µm; same targets and same runs per direction as ``reference``
    displacement_mm : signed distance D from the reference line to the shifted line, mm,
        along the axis that amplifies the angle. The angle is the one whose effect on the
        linear error is ``+angle x D``; the sign of D and the order of the files settle
        the sign convention (3.08.1 step 3)
    datum_mm : a target where the angle is taken as zero, mm
    direction : ``"forward"``, ``"reverse"`` (``"backward"``) or ``"mean"``: the mean
        curve that is made exactly zero at the datum
    error_direction : the axis the rotation is about (X, Y, Z), kept on the profile

    Returns
    -------
    IndirectAngle
        Its ``profile`` holds, for run j of each direction,
        ``1000 * (b_j - a_j) / D - 1000 * (mean b - mean a at the datum) / D`` in µm/m.

    Raises
    ------
    DataError
        A profile is not linear data, the axes differ, the targets or the run counts per
        direction differ, the datum is not a target, D is not finite or is smaller than
        1 µm or larger than 100 m in size, the files hold no runs in ``direction``, or an
        angle lies beyond the plausibility limit of 0.1 rad (:mod:`esp.core.units`).

    References
    ----------
    Longstaff (2002), 3.08.1 (steps 2-5), eq. 3.13.

    Examples
    --------
    >>> a = ErrorProfile.from_values("linear", [0, 100, 200], [0.0, 1.0, 2.0])
    >>> b = ErrorProfile.from_values("linear", [0, 100, 200], [0.0, 9.0, 2.0])
    >>> angular_from_linear(a, b, 800.0, 0.0).curve("forward").tolist()  # 8 µm / 800 mm
    [0.0, 10.0, 0.0]
    """
    d = float(displacement_mm)
    if not (math.isfinite(d) and MIN_SPACING_MM <= abs(d) <= POSITION_LIMIT_MM):
        raise DataError(
            f"expected a non-zero displacement between the two runs, of {MIN_SPACING_MM:g} to "
            f"{POSITION_LIMIT_MM:g} mm in size, found {displacement_mm!r} mm"
        )
    datum = float(datum_mm)
    if not (math.isfinite(datum) and abs(datum) <= POSITION_LIMIT_MM):
        raise DataError(
            f"expected a finite datum position within ±{POSITION_LIMIT_MM:g} mm, found "
            f"{datum_mm!r} mm"
        )
    direction = normalise_direction(direction)
    _check_pair(reference, shifted)
    j = datum_index(reference.targets_mm, datum)
    datum_error = (shifted.mean(direction)[j] - reference.mean(direction)[j]) / d
    runs = {
        k: UM_PER_M_PER_UM_PER_MM * ((shifted.runs[k] - reference.runs[k]) / d - datum_error)
        for k in reference.directions
    }
    ra, rb = _name(reference, "reference"), _name(shifted, "shifted")
    for k, block in runs.items():
        bad = beyond_limit(block, "angular")
        if bad is not None:
            target = float(reference.targets_mm[bad % block.shape[1]])
            raise DataError(
                f"the {k} angle from {ra} and {rb} at {target:g} mm is "
                f"{float(block.flat[bad]):g} µm/m, beyond the plausibility limit "
                f"{limit_text('angular')} (0.1 rad): check the displacement ({d:g} mm) and "
                "the unit of the files"
            )
    metadata = {k: v for k, v in reference.metadata.items() if "\n" not in v and "\r" not in v}
    axis = reference.axis or shifted.axis
    if axis and not any(k.strip().lower() == "axis" for k in metadata):
        metadata["Axis"] = axis
    metadata.update(
        {
            "Method": "indirect, from two linear runs (Longstaff 2002, 3.08.1)",
            "Reference": ra,
            "Shifted": rb,
            "Displacement": f"{d:g} mm",
            "Datum": f"{float(reference.targets_mm[j]):g} mm ({direction} angle zero)",
        }
    )
    profile = ErrorProfile(
        kind="angular",
        targets_mm=reference.targets_mm,
        runs=runs,
        axis=axis,
        error_direction=error_direction,
        input_unit="um/m",
        metadata=metadata,
        source=f"indirect angle from {ra} and {rb}",
    )
    return IndirectAngle(
        profile=profile,
        displacement_mm=d,
        datum_mm=float(reference.targets_mm[j]),
        direction=direction,
        reference=reference.source,
        shifted=shifted.source,
    )
