"""Make the pictures of docs/reports.md from the shipped gantry example.

Run from the repository root:  python docs/make_images.py

The gantry is evaluated at the TCP with its head sweep (machine-tcp.toml) and, for the
uncertainty figures, with a Monte Carlo uncertainty of a few components added in code.
The PNGs are the report's figures (A4 landscape), written small (60 dpi, 701 x 496
pixels) into docs/images/; input images of the earlier one-per-component figures are
removed.

Then one page of each kind of document (``python docs/make_images.py documents`` makes only
these): each command with ``--out`` is run on a shipped example with SOURCE_DATE_EPOCH set,
and the page is rendered with poppler's ``pdftoppm`` at 50 dpi into docs/images/doc-*.png
(quantised to 64 colours, some 20-40 kB each).
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import tempfile
import tomllib
from pathlib import Path

from esp.analysis import analyse
from esp.config import machine_from_dict
from esp.report import bundle, plots

ROOT = Path(__file__).resolve().parent.parent
GANTRY = ROOT / "data" / "examples" / "gantry"
IMAGES = Path(__file__).resolve().parent / "images"
WANTED = (
    "map-Y.png",
    "map-volumetric.png",
    "terms.png",
    "sweep.png",
    "uncertainty-budget.png",
    "uncertainty-montecarlo.png",
    "input-Y.png",
)


def main() -> None:
    data = tomllib.loads((GANTRY / "machine-tcp.toml").read_text(encoding="utf-8"))
    data["uncertainty"] = {
        "method": "montecarlo",
        "samples": 4000,
        "seed": 1,
        "components": {
            "Y.linear": {"U": 6.0},
            "X.linear": {"U": 4.0},
            "Z.linear": {"U": 3.0},
            "Y.angular.Z": {"U": 3.0},
            "squareness.XY": {"U": 5.0},
        },
    }
    result = analyse(machine_from_dict(data, GANTRY, source="machine-tcp.toml"))
    IMAGES.mkdir(exist_ok=True)
    for old in IMAGES.glob("input-*.png"):  # the inputs were one figure per component
        if old.name not in WANTED:
            old.unlink()
    for spec in bundle.figure_specs(result):
        if spec.filename in WANTED:
            plots.save_png(spec.build(), IMAGES / spec.filename, dpi=60)
            print(IMAGES.relative_to(ROOT) / spec.filename)


EXAMPLES = ROOT / "data" / "examples"
#: (image, command after esp, the PDF in the --out folder, the page from 1)
DOCUMENTS = (
    ("doc-analyse-title.png", ["analyse", "gantry/machine.toml"], "report.pdf", 1),
    ("doc-iso230-table.png", ["iso230-2", "gantry/X-linear.rtl"], "report.pdf", 2),
    ("doc-iso230-figure.png", ["iso230-2", "gantry/X-linear.rtl"], "report.pdf", 3),
    ("doc-iso230-provenance.png", ["iso230-2", "gantry/X-linear.rtl"], "report.pdf", 4),
    ("doc-head.png", ["head", "heads/angle-head-fig3.toml"], "head.pdf", 1),
    ("doc-parallel.png", ["parallel", "parallel/machine.toml", "--sweep"], "parallel.pdf", 1),
    (
        "doc-compare.png",
        ["compare", "gantry/machine.toml", "gantry-2024/machine.toml"],
        "report.pdf",
        1,
    ),
    (
        "doc-compensate.png",
        ["compensate", "gantry/machine.toml", "--format", "twincat-plane", "--format"]
        + ["isg-volumetric", "--leave-uncorrected", "--predict"],
        "report.pdf",
        1,
    ),
    (
        "doc-diagonals.png",
        ["diagonals", "gantry/machine.toml", "--measurement-u", "2"]
        + [f"--measured={d}=gantry-diagonals/{d}.rtl" for d in ("PPP", "NPP", "PNP", "PPN")],
        "report.pdf",
        1,
    ),
    (
        "doc-angular.png",
        ["angular", "turning-centre/Xpos_z0.rtl", "turning-centre/Xpos_z800.rtl"]
        + ["--displacement", "-800", "--datum", "-560"],
        "report.pdf",
        1,
    ),
    ("doc-identify.png", ["identify", "identify/cmm-ballplate/machine.toml"], "identify.pdf", 1),
)


def documents() -> None:
    """One page of each kind of document, as docs/reports.md shows them."""
    from PIL import Image

    if shutil.which("pdftoppm") is None:
        sys.exit("pdftoppm (poppler) is needed to render the document pages")
    env = {**os.environ, "SOURCE_DATE_EPOCH": "1767312000", "PYTHONPATH": str(ROOT)}
    made: dict[tuple[str, ...], Path] = {}
    with tempfile.TemporaryDirectory() as tmp:
        for image, args, pdf, page in DOCUMENTS:
            key = tuple(args)
            if key not in made:
                out = Path(tmp) / f"out{len(made)}"
                subprocess.run(
                    [sys.executable, "-m", "esp", *args, "--out", str(out)],
                    cwd=EXAMPLES,
                    env=env,
                    check=True,
                    stdout=subprocess.DEVNULL,
                )
                made[key] = out
            base = Path(tmp) / image.removesuffix(".png")
            subprocess.run(
                ["pdftoppm", "-r", "50", "-png", "-singlefile", "-f", str(page), "-l", str(page)]
                + [str(made[key] / pdf), str(base)],
                check=True,
            )
            picture = Image.open(f"{base}.png").convert("RGB").quantize(64)
            picture.save(IMAGES / image, optimize=True)
            print(IMAGES.relative_to(ROOT) / image)


if __name__ == "__main__":
    if sys.argv[1:] != ["documents"]:
        main()
    documents()
