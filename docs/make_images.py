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

from esp.config import machine_from_dict
from esp.core.analysis import analyse
from esp.volumetric import plots
from esp.volumetric import report as bundle

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
    ("doc-analyse-title.png", ["analyse", "data/examples/gantry/machine.toml"], "report.pdf", 1),
    ("doc-iso230-table.png", ["iso230-2", "data/examples/gantry/X-linear.rtl"], "report.pdf", 2),
    ("doc-iso230-figure.png", ["iso230-2", "data/examples/gantry/X-linear.rtl"], "report.pdf", 3),
    (
        "doc-iso230-provenance.png",
        ["iso230-2", "data/examples/gantry/X-linear.rtl"],
        "report.pdf",
        4,
    ),
    ("doc-head.png", ["head", "data/examples/heads/angle-head-fig3.toml"], "head.pdf", 1),
    (
        "doc-parallel.png",
        ["parallel", "data/examples/parallel/machine.toml", "--sweep"],
        "parallel.pdf",
        1,
    ),
    (
        "doc-compare.png",
        ["compare", "data/examples/gantry/machine.toml", "data/examples/gantry-2024/machine.toml"],
        "report.pdf",
        1,
    ),
    (
        "doc-compensate.png",
        ["compensate", "data/examples/gantry/machine.toml", "--format", "twincat-plane", "--format"]
        + ["isg-volumetric", "--leave-uncorrected", "--predict"],
        "report.pdf",
        1,
    ),
    (
        "doc-diagonals.png",
        ["diagonals", "data/examples/gantry/machine.toml", "--measurement-u", "2"]
        + [
            f"--measured={d}=data/examples/gantry-diagonals/{d}.rtl"
            for d in ("PPP", "NPP", "PNP", "PPN")
        ],
        "report.pdf",
        1,
    ),
    (
        "doc-angular.png",
        [
            "angular",
            "data/examples/turning-centre/Xpos_z0.rtl",
            "data/examples/turning-centre/Xpos_z800.rtl",
        ]
        + ["--displacement", "-800", "--datum", "-560"],
        "report.pdf",
        1,
    ),
    (
        "doc-identify.png",
        ["identify", "data/examples/identify/cmm-ballplate/machine.toml"],
        "identify.pdf",
        1,
    ),
)


def documents() -> None:
    """One page of each kind of document, as docs/reports.md shows them."""
    from PIL import Image

    if shutil.which("pdftoppm") is None:
        sys.exit("pdftoppm (poppler) is needed to render the document pages")
    env = {**os.environ, "SOURCE_DATE_EPOCH": "1767312000", "PYTHONPATH": str(ROOT)}
    made: dict[tuple[str, ...], Path] = {}
    with tempfile.TemporaryDirectory() as tmp:
        # run in a folder of its own that shows the examples as data/examples, so that
        # the command lines in the provenance are those of the READMEs
        (Path(tmp) / "data").symlink_to(ROOT / "data")
        for image, args, pdf, page in DOCUMENTS:
            key = tuple(args)
            if key not in made:
                name = f"report-{len(made) + 1}"
                out = Path(tmp) / name
                subprocess.run(
                    [sys.executable, "-m", "esp", *args, "--out", name],
                    cwd=tmp,
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
