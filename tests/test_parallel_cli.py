"""``esp parallel`` as a user runs it: the shipped example end to end, the JSON contract,
the report folder, and one line with exit code 2 for every kind of bad input."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest
from click.testing import CliRunner

from esp.cli import main

EXAMPLE = Path(__file__).resolve().parent.parent / "data" / "examples" / "parallel" / "machine.toml"
TEXT = EXAMPLE.read_text(encoding="utf-8")

MINIMAL = """
[parallel_machine]
name = "minimal"

[geometry]
R_mm = 400.0
r_mm = 200.0
h_mm = 300.0
strut_mm = 1000.0

[pose]
z_mm = 300.0
alpha_deg = 15.0
beta_deg = 10.0

[errors.leg1]
strut_um = 60.0
"""


def run(*args):
    return CliRunner().invoke(main, ["parallel", *map(str, args)])


def write(tmp_path, text: str) -> Path:
    path = tmp_path / "machine.toml"
    path.write_text(text, encoding="utf-8")
    return path


@pytest.fixture(scope="module")
def example_doc():
    res = run(EXAMPLE, "--sweep", "--json", "-")
    assert res.exit_code == 0, res.output
    return json.loads(res.stdout)


def test_example_text_report():
    res = run(EXAMPLE)
    assert res.exit_code == 0, res.output
    out = res.output
    assert "Pose: z_T = 300 mm, α = 15°, β = 10°; x_T = 149.690 mm, y_T = 71.929 mm" in out
    assert "[J]^-1" in out and "[M]ᵀ" in out and "[N]ᵀ" in out
    assert "e = (0.068, -0.174, -61.373) µm" in out
    assert "Uncertainty (statistical" in out


def test_example_json(example_doc):
    doc = example_doc
    assert doc["schema"] == "esp.parallel/1" and doc["model"] == "exact"
    pose = doc["pose"]
    assert pose["x_mm"] == pytest.approx(149.689720, abs=1e-6)
    assert pose["gamma_deg"] == pytest.approx(-1.319819, abs=1e-6)
    assert pose["condition_number"] < 5
    assert doc["methods"]["linkage_vs_differential"] < 1e-9
    assert doc["methods"]["first_order_vs_exact"] < 1e-3
    m = doc["matrices"]
    assert len(m["J"]) == 6 and len(m["M"][0]) == 12 and len(m["N"][0]) == 30
    assert m["M_columns"][3] == "leg1.strut"
    # the errors are the sum of the contributions, and the sensitivities times the values
    errors = doc["errors"]
    for name in ("e_x", "e_y", "e_z", "eps_x", "eps_y", "eps_z"):
        total = sum(c[name] for c in doc["contributions"])
        assert total == pytest.approx(errors[name], abs=1e-5)
        from_sources = sum(s["value"] * s["sensitivity"][name] for s in doc["sources"])
        assert from_sources == pytest.approx(errors[name], abs=1e-4)
    assert sum(c["share_position_pct"] for c in doc["contributions"]) == pytest.approx(
        100, abs=1e-3
    )
    assert errors["e_z"] == pytest.approx(-61.373, abs=1e-3)
    unc = doc["uncertainty"]
    assert unc["method"] == "statistical" and unc["k"] == 2
    assert unc["position_um"] == pytest.approx(
        math.hypot(*(unc["statistical"][k] for k in ("e_x", "e_y", "e_z")))
    )


def test_example_sweeps(example_doc):
    sweep = example_doc["sweep"]
    cases = {c["case"]: c for c in sweep["error"]["cases"]}
    assert set(cases) == {"all", "1"} and sweep["error"]["unit"] == "um"
    every = cases["all"]
    # Fig. 5: equal sliding errors raise e_z one for one and leave the rest unchanged
    dz = every["errors"][-1]["e_z"] - every["errors"][0]["e_z"]
    assert dz == pytest.approx(every["values"][-1] - every["values"][0], abs=1e-5)
    assert every["errors"][-1]["e_x"] == pytest.approx(every["errors"][0]["e_x"], abs=1e-6)
    # Fig. 6: slider 1 alone tilts the platform (ε_y) and moves the tool along X
    one = cases["1"]["errors"][-1]
    assert abs(one["eps_y"]) > 100 and abs(one["e_x"]) > 50
    ws = sweep["workspace"]
    assert ws["poses"] == ws["evaluated"] == 245 and ws["excluded"] == []
    worst = {w["quantity"]: w for w in ws["worst"]}
    e_max = max(math.hypot(*(p["errors"][k] for k in ("e_x", "e_y", "e_z"))) for p in ws["points"])
    assert worst["|e|"]["value"] == pytest.approx(e_max, abs=1e-6)
    assert {"z_mm", "alpha_deg", "beta_deg"} <= set(worst["|e|"])


def test_json_to_a_file_and_pose_option(tmp_path):
    out = tmp_path / "r.json"
    res = run(EXAMPLE, "--pose", "alpha=0,beta=0", "--json", out, "-q")
    assert res.exit_code == 0 and res.output == ""
    doc = json.loads(out.read_text(encoding="utf-8"))
    assert doc["pose"]["z_mm"] == 300 and doc["pose"]["alpha_deg"] == 0
    assert doc["sweep"] is None


def test_as_printed_model(tmp_path):
    res = run(EXAMPLE, "--model", "as-printed", "--json", "-")
    assert res.exit_code == 0
    doc = json.loads(res.stdout)
    assert doc["model"] == "as-printed"
    # the printed δl sign: the platform rises where it sinks in the exact kinematics
    assert doc["errors"]["e_z"] == pytest.approx(61.373, abs=1e-3)


SMALL_SWEEP = """
[uncertainty.leg1]
strut_um = 4.0

[sweep.error]
steps = 3

[sweep.workspace]
z_mm = [300.0, 300.0, 1]
alpha_deg = [-10.0, 10.0, 3]
beta_deg = [-10.0, 10.0, 3]
"""


@pytest.mark.slow
def test_out_folder_is_complete(tmp_path, monkeypatch):
    monkeypatch.setenv("SOURCE_DATE_EPOCH", "0")
    monkeypatch.chdir(tmp_path)
    write(tmp_path, MINIMAL + SMALL_SWEEP)
    res = run("machine.toml", "--sweep", "--out", "a", "-q")
    assert res.exit_code == 0, res.output
    names = sorted(p.name for p in (tmp_path / "a").iterdir())
    assert names == [
        ".esp-folder.json",
        "budget.png",
        "parallel.pdf",
        "result.json",
        "sweep-all.png",
        "sweep-leg1.png",
        "workspace.png",
    ]
    pdf = (tmp_path / "a" / "parallel.pdf").read_bytes()
    assert pdf.startswith(b"%PDF") and b"CreationDate" not in pdf
    assert (tmp_path / "a" / "budget.png").read_bytes().startswith(b"\x89PNG")
    doc = json.loads((tmp_path / "a" / "result.json").read_text(encoding="utf-8"))
    assert doc["schema"] == "esp.parallel/1" and doc["sweep"]["workspace"]["evaluated"] == 9


@pytest.mark.slow
def test_figures_have_deterministic_bytes(tmp_path):
    """The same result gives the same PNG and PDF bytes (no date, no version text)."""
    import io
    import tomllib

    from matplotlib.backends.backend_pdf import PdfPages

    from esp.parallel.analysis import analyse_pose
    from esp.parallel.config import parallel_from_dict
    from esp.parallel.plots import budget_figure, pdf_metadata

    result = analyse_pose(parallel_from_dict(tomllib.loads(MINIMAL)))

    def render() -> tuple[bytes, bytes]:
        fig = budget_figure(result)
        png, pdf = io.BytesIO(), io.BytesIO()
        fig.savefig(png, format="png", metadata={"Software": None})
        with PdfPages(pdf, metadata=pdf_metadata(result)) as pages:
            pages.savefig(fig)
        return png.getvalue(), pdf.getvalue()

    assert render() == render()


def test_out_refuses_a_folder_esp_did_not_write(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    write(tmp_path, MINIMAL)
    (tmp_path / "mine").mkdir()
    (tmp_path / "mine" / "notes.txt").write_text("keep", encoding="utf-8")
    res = run("machine.toml", "--out", "mine", "-q")
    _one_line_error(res, "--out mine", "esp did not write")
    assert (tmp_path / "mine" / "notes.txt").read_text(encoding="utf-8") == "keep"


def _one_line_error(res, *fragments: str) -> None:
    assert res.exit_code == 2, res.output
    lines = res.output.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("esp: error: "), res.output
    assert "Traceback" not in res.output
    for fragment in fragments:
        assert fragment in lines[0], lines[0]


@pytest.mark.parametrize(
    ("change", "fragments"),
    [
        # unknown keys, with a suggestion
        (
            ("strut_mm = 1000.0", "strut_m = 1000.0"),
            ("geometry.strut_m", "did you mean 'strut_mm'"),
        ),
        (("[errors.leg1]", "[errors.leg4]"), ("errors.leg4", "unknown key")),
        (("strut_um = 60.0", "strutt_um = 60.0"), ("errors.leg1.strutt_um", "strut_um")),
        # non-finite and wrong types
        (("h_mm = 300.0", "h_mm = nan"), ("geometry.h_mm", "finite")),
        (("strut_um = 60.0", "strut_um = inf"), ("errors.leg1.strut_um", "finite")),
        (("z_mm = 300.0", 'z_mm = "300"'), ("pose.z_mm", "expected a number")),
        (("strut_um = 60.0", "strut_um = 6e7"), ("errors.leg1.strut_um", "unit mistake")),
        # bad geometry
        (("r_mm = 200.0", "r_mm = 0.0"), ("geometry.r_mm", "radius > 0")),
        (("strut_mm = 1000.0", "strut_mm = -1000.0"), ("strut_mm", "length > 0")),
        (("R_mm = 400.0", "R_mm = 400.0\n[geometry.leg1]"), ("geometry",)),
        # unreachable and singular poses
        (("strut_mm = 1000.0", "strut_mm = 150.0"), ("unreachable", "no strut solution")),
        (("strut_mm = 1000.0", "strut_mm = 200.0001\n[analysis]\nmax_condition = 1000"), ()),
        (("alpha_deg = 15.0", "alpha_deg = 95.0"), ("±90°",)),
        # TOML syntax
        (("z_mm = 300.0", "z_mm = = 300"), ("invalid TOML at line",)),
    ],
)
def test_bad_input_is_one_line_and_exit_2(tmp_path, change, fragments):
    old, new = change
    assert old in MINIMAL
    res = run(write(tmp_path, MINIMAL.replace(old, new, 1)))
    _one_line_error(res, *fragments)


def test_singular_pose_message(tmp_path):
    text = MINIMAL.replace("strut_mm = 1000.0", "strut_mm = 200.0001")
    res = run(write(tmp_path, text), "--pose", "alpha=0,beta=0")
    _one_line_error(res, "near-singular", "condition number of [J]", "> limit 1000")


@pytest.mark.parametrize(
    ("args", "fragment"),
    [
        (("--pose", "z=300,alpah=15,beta=10"), "did you mean 'alpha'"),
        (("--pose", "z=nan,alpha=0,beta=0"), "finite"),
        (("--pose", "z=inf"), "finite"),
        (("--pose", "z=300,z=200"), "twice"),
        (("--pose", "z"), "key=value"),
        (("--model", "printed"), "--model"),
        (("--json",), "--json"),
    ],
)
def test_bad_options_are_one_line_and_exit_2(tmp_path, args, fragment):
    res = run(write(tmp_path, MINIMAL), *args)
    _one_line_error(res, fragment)


def test_no_pose_anywhere(tmp_path):
    text = MINIMAL.replace("[pose]\nz_mm = 300.0\nalpha_deg = 15.0\nbeta_deg = 10.0\n", "")
    _one_line_error(run(write(tmp_path, text)), "no pose")
    _one_line_error(run(write(tmp_path, text), "--pose", "z=300"), "missing alpha, beta")
    assert run(write(tmp_path, text), "--pose", "z=300,alpha=1,beta=2").exit_code == 0


def test_workspace_outside_refused_or_skipped(tmp_path):
    sweep = (
        "\n[analysis]\nmax_condition = 5.0\n"
        "\n[sweep.workspace]\nz_mm = [300.0, 300.0, 1]\nalpha_deg = [-85.0, 85.0, 5]\n"
        "beta_deg = [0.0, 0.0, 1]\n"
    )
    res = run(write(tmp_path, MINIMAL + sweep), "--sweep")
    _one_line_error(res, "sweep.workspace", "cannot be evaluated", 'outside = "skip"')
    res = run(write(tmp_path, MINIMAL + sweep + 'outside = "skip"\n'), "--sweep", "--json", "-")
    assert res.exit_code == 0, res.output
    ws = json.loads(res.stdout)["sweep"]["workspace"]
    assert ws["evaluated"] < ws["poses"] and ws["excluded"]
    assert "NaN" not in res.stdout and "Infinity" not in res.stdout


def test_a_cartesian_machine_file_is_recognised(tmp_path):
    res = run(write(tmp_path, '[machine]\nname = "m"\n'))
    _one_line_error(res, "esp analyse")


def test_output_targets_are_checked_before_work(tmp_path):
    path = write(tmp_path, MINIMAL)
    _one_line_error(run(path, "--json", path), "inputs")
    res = run(path.parent / "missing.toml", "--json", tmp_path / "x.json")
    assert res.exit_code == 2 and not (tmp_path / "x.json").exists()


def test_help_examples_run(monkeypatch):
    import re
    import shlex

    root = Path(__file__).resolve().parent.parent
    monkeypatch.chdir(root)
    text = CliRunner().invoke(main, ["parallel", "--help"]).output
    examples = re.findall(r"^\s+(esp parallel [^\n]+)$", text, flags=re.M)
    assert len(examples) >= 3
    for line in examples:
        args = shlex.split(line)[1:]
        if "--out" in args:
            continue  # writes a folder: covered above
        res = CliRunner().invoke(main, args)
        assert res.exit_code == 0, (line, res.output)
