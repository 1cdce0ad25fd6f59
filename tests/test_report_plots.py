"""The data behind the figures and what the figures say (esp.report.plots)."""

from __future__ import annotations

import io

import numpy as np
import pytest

from esp.analysis import analyse
from esp.report import plots


def figure_text(fig) -> str:
    """Every text placed on the figure itself (the figure title among them)."""
    return "\n".join(t.get_text() for t in fig.texts)


@pytest.fixture
def line_machine(make_machine):
    """Only X.linear, 0 µm at X=0 rising to 8 µm at X=400: the X error is 0.02 µm/mm · X
    everywhere, the other directions are zero (eq. 3.1, term +M_lin)."""
    return make_machine(
        {"X.linear": [(0.0, 0.0), (400.0, 8.0)]},
        travel={"X": (0.0, 400.0), "Y": (0.0, 300.0), "Z": (0.0, 200.0)},
        step=100.0,
    )


def test_direction_planes_pass_through_the_largest_error(line_machine):
    result = analyse(line_machine)
    which, ext, planes = plots.direction_planes(result, "X")
    assert which == "max" and ext.value_um == pytest.approx(8.0)
    assert ext.at["X"] == 400.0
    xy, xz, yz = planes
    assert xy.axes == ("X", "Y") and xy.fixed == ("Z", ext.at["Z"])
    assert xz.axes == ("X", "Z") and xz.fixed == ("Y", ext.at["Y"])
    assert yz.axes == ("Y", "Z") and yz.fixed == ("X", 400.0)
    # on XY: 0.02 µm/mm · X at every Y, i.e. 0, 2, 4, 6, 8 µm along X
    x = xy.grids_mm[0]
    np.testing.assert_allclose(xy.values_um, np.outer(0.02 * x, np.ones(4)), atol=1e-12)
    # on YZ at X = 400: 8 µm everywhere; the star's value is the extreme
    np.testing.assert_allclose(yz.values_um, 8.0, atol=1e-12)
    assert yz.value_at(ext.at) == pytest.approx(ext.value_um)


def test_worst_extreme_takes_the_larger_magnitude(make_machine):
    # X error from -6 µm at X=0 to +2 µm at X=400: the minimum is the larger magnitude
    machine = make_machine({"X.linear": [(0.0, -6.0), (1000.0, 2.0)]})
    case = analyse(machine).cases[0]
    which, ext = plots.worst_extreme(case, "X")
    assert which == "min" and ext.value_um == pytest.approx(-6.0) and ext.at["X"] == 0.0


def test_volumetric_plane_is_normal_to_the_shortest_axis(line_machine):
    result = analyse(line_machine)
    plane = plots.volumetric_plane(result)
    # Z has the shortest range (200 mm), so the plane is XY at the worst point's Z
    assert plane.axes == ("X", "Y") and plane.fixed[0] == "Z"
    # volumetric error = sqrt(ex² + ey² + ez²) = 0.02 · X here (eq. 3.4)
    np.testing.assert_allclose(plane.values_um[:, 0], 0.02 * plane.grids_mm[0], atol=1e-12)
    assert float(plane.values_um.max()) == pytest.approx(result.cases[0].volumetric.value_um)


def test_map_surface_is_bilinear_between_the_nodes():
    # f(u, v) = 1 + 2u - v + 0.5uv is bilinear: resampling must reproduce it exactly,
    # on an uneven grid too (the last interval shorter, as axis grids may be)
    u = np.array([0.0, 100.0, 200.0, 250.0])
    v = np.array([0.0, 50.0, 80.0])

    def f(a, b):
        return 1 + 2 * a - b + 0.5 * a * b

    uf, vf, fine = plots.map_surface(u, v, f(u[:, None], v[None, :]), samples=31)
    assert uf[0] == 0.0 and uf[-1] == 250.0 and vf[-1] == 80.0 and fine.shape == (31, 31)
    np.testing.assert_allclose(fine, f(uf[:, None], vf[None, :]), rtol=1e-12)


def test_zero_terms_are_left_out_of_the_terms_chart(make_machine):
    # squareness.XY levered by X is zero at X = 0; X.linear alone makes the worst point
    machine = make_machine({"X.linear": [(0.0, 0.0), (1000.0, 5.0)], "squareness.XY": 0.0})
    result = analyse(machine)
    fig = plots.terms_figure(result)
    labels = [t.get_text() for t in fig.axes[0].get_yticklabels()]
    assert any(label.startswith("X: X.linear") for label in labels)
    assert not any("squareness" in label for label in labels)
    assert {"X total", "Y total", "Z total"} <= set(labels)
    assert "terms of zero value not shown" in figure_text(fig)


def test_figures_name_their_axes_with_units_and_letters(line_machine):
    result = analyse(line_machine)
    fig = plots.direction_maps_figure(result, "X")
    first = fig.axes[0]
    assert first.get_xlabel() == "X position, bottom axis (mm)"
    assert first.get_ylabel() == "Y position, middle axis (mm)"
    colourbar = fig.axes[-1]
    assert colourbar.get_ylabel() == "total displacement error in X (µm)"
    assert "8.000 µm at X=400" in figure_text(fig)
    component = plots.component_figure(result, "X.linear")
    assert component.axes[0].get_ylabel() == "deviation (µm)"
    assert component.axes[0].get_title().startswith("X.linear (EXX)")


def test_zero_direction_is_said_in_words(line_machine):
    result = analyse(line_machine)
    fig = plots.direction_maps_figure(result, "Y")
    assert "zero over the whole volume" in figure_text(fig)


def test_png_bytes_are_deterministic(line_machine, tmp_path):
    result = analyse(line_machine)
    images = []
    for name in ("a.png", "b.png"):
        plots.save_png(plots.volumetric_map_figure(result), tmp_path / name)
        images.append((tmp_path / name).read_bytes())
    assert images[0] == images[1] and b"Software" not in images[0]
    # the pixel size is the figure size times the resolution: 8 x 6 in at 80 dpi
    buffer = io.BytesIO()
    plots.volumetric_map_figure(result).savefig(buffer, format="png", dpi=80)
    assert buffer.getvalue()[16:24] == (640).to_bytes(4, "big") + (480).to_bytes(4, "big")
