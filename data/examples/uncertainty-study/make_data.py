"""Write the error files of the uncertainty study of Longstaff (2002), section 4.01.2.

Each file holds the magnitude of the measurement uncertainty of one error component as if it
were the measured error (thesis 4.01.2.1, the uncertainties of table 4.2), for a gantry
(wBMTt) with three axes of 1 m:

- linear: targets 0, 500, 1000 mm; forward run 0, 4, 8 µm (8 µm/m over the axis), reverse
  run 0, -4, -8 µm (4.01.2.1 a);
- angular: targets 0, 500, 1000 mm; forward 4 µm/m everywhere, reverse -4 µm/m (4.01.2.1 b);
- straightness: targets -0.001, 0, 500, 1000, 1000.001 mm; forward 0, 4, 4, 4, 0 µm, a
  trapezoid that an end-point fit leaves at 4 µm over the whole travel; reverse the same
  with the opposite sign (4.01.2.1 c).

The squareness (10 µm/m per pair, 4.01.2.1 d) is a single value and lives in the
configuration files beside this script.

Run ``python make_data.py`` to (re)write the files next to this script. Nothing here is
random: the files are the same every time.

References
----------
Longstaff, A. P. (2002). The Role of Measurement and Modelling of Machine Tools in
Improving Product Quality. PhD thesis, University of Huddersfield; section 4.01.2.1 and
table 4.2.
"""

from __future__ import annotations

import sys
from pathlib import Path

from esp.io.laser10 import write_laser10_set
from esp.core.profile import ErrorProfile

AXES = ("X", "Y", "Z")
TARGETS_MM = (0.0, 500.0, 1000.0)
STRAIGHTNESS_TARGETS_MM = (-0.001, 0.0, 500.0, 1000.0, 1000.001)
#: forward run of each kind; the reverse run is its negative (thesis 4.01.2.1 a-c)
LINEAR_UM = (0.0, 4.0, 8.0)
ANGULAR_UM_PER_M = (4.0, 4.0, 4.0)
STRAIGHTNESS_UM = (0.0, 4.0, 4.0, 4.0, 0.0)


def _metadata(axis: str, what: str) -> dict[str, str]:
    return {
        "Machine": "1 m gantry, uncertainty study",
        "Axis": axis,
        "Comment": f"uncertainty study (Longstaff 2002, 4.01.2): {what}",
    }


def _profile(kind: str, axis: str, targets, forward, what: str) -> ErrorProfile:
    return ErrorProfile(
        kind=kind,
        targets_mm=targets,
        runs={"forward": [list(forward)], "backward": [[-v for v in forward]]},
        axis=axis,
        metadata=_metadata(axis, what),
    )


def profiles() -> dict[str, ErrorProfile]:
    """File name -> profile for every file of the study, in a fixed order."""
    out: dict[str, ErrorProfile] = {}
    for axis in AXES:
        out[f"{axis}-linear.rtl"] = _profile(
            "linear", axis, TARGETS_MM, LINEAR_UM, "positioning, 8 um/m"
        )
        for about in AXES:
            out[f"{axis}-angular-{about}.rta"] = _profile(
                "angular", axis, TARGETS_MM, ANGULAR_UM_PER_M, f"rotation about {about}, 4 um/m"
            )
        for towards in AXES:
            if towards != axis:
                name = f"{axis}-straightness-{towards}.st{axis.lower()}"
                out[name] = _profile(
                    "straightness",
                    axis,
                    STRAIGHTNESS_TARGETS_MM,
                    STRAIGHTNESS_UM,
                    f"straightness along {towards}, 4 um after an end-point fit",
                )
    return out


def write_files(folder: str | Path) -> list[Path]:
    """Write every file of the study into ``folder`` (created if needed); return the paths."""
    return write_laser10_set(folder, profiles())


def main(argv: list[str] | None = None) -> int:
    args = sys.argv[1:] if argv is None else argv
    folder = Path(args[0]) if args else Path(__file__).resolve().parent
    for path in write_files(folder):
        print(path.name)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
