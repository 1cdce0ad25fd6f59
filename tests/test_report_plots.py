"""The data behind the figures and what the figures say (esp.volumetric.plots): planes, maps,
the inputs per axis (runs, fitted line, inline values), the sweep, and that no text of any
figure is cut by the edge of the page or drawn over another."""

from __future__ import annotations

import io
from pathlib import Path

import numpy as np
import pytest
from matplotlib.text import Text

from esp.config import load_machine, machine_from_dict
from esp.core.analysis import analyse
from esp.report.drawing import figure_texts
from esp.volumetric import plots
from esp.volumetric import report as bundle

EXAMPLES = Path(__file__).resolve().parent.parent / "data" / "examples"


def figure_text(fig) -> str:
    """Every text placed on the figure itself (the figure title among them)."""
    return "\n".join(t.get_text() for t in fig.texts)


def drawn_texts(fig) -> list[Text]:
    """Every text a draw of ``fig`` shows: titles, notes, legends, axis labels, and the
    labels of the ticks in view (an axis keeps other ticks, not drawn)."""
    texts = figure_texts(fig)
    for ax in fig.axes:
        for axis in (ax.xaxis, ax.yaxis):
            for tick in axis._update_ticks():  # the ticks in view, as the draw takes them
                texts += [tick.label1, tick.label2]
            texts.append(axis.offsetText)
    return texts


def text_problems(fig) -> list[str]:
    """What is wrong with the texts of a drawn figure: a text cut by the edge of the page,
    a label in a plot (a contour label, the value of a bar) not wholly inside its axes,
    and texts drawn over each other (labels in a plot excepted)."""
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    page = fig.bbox
    problems = []
    boxes = []
    for t in drawn_texts(fig):
        if not t.get_visible() or not t.get_text().strip():
            continue
        e = t.get_window_extent(renderer)
        if e.x0 < page.x0 - 0.5 or e.x1 > page.x1 + 0.5 or e.y0 < page.y0 - 0.5 or e.y1 > page.y1:
            problems.append(f"cut by the page: {t.get_text()!r}")
        ax = t.axes
        if ax is not None and t in ax.texts and t.get_transform() == ax.transData:
            box = ax.get_window_extent(renderer)
            if e.x0 < box.x0 or e.x1 > box.x1 or e.y0 < box.y0 or e.y1 > box.y1:
                problems.append(f"outside its axes: {t.get_text()!r}")
            continue
        boxes.append((t.get_text(), e))
    for i, (a, ea) in enumerate(boxes):
        for b, eb in boxes[i + 1 :]:
            w = min(ea.x1, eb.x1) - max(ea.x0, eb.x0)
            h = min(ea.y1, eb.y1) - max(ea.y0, eb.y0)
            if w > 1.5 and h > 1.5:
                problems.append(f"{a!r} over {b!r}")
    return problems


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
    colourbar = fig.axes[-1]  # under the maps
    assert colourbar.get_xlabel() == "total displacement error in X (µm)"
    assert "8.000 µm at X=400" in figure_text(fig)
    component = plots.component_figure(result, "X.linear")
    assert component.axes[0].get_ylabel() == "deviation (µm)"
    assert component.axes[0].texts[0].get_text() == "X.linear (EXX)"


def test_zero_direction_is_said_in_words(line_machine):
    result = analyse(line_machine)
    fig = plots.direction_maps_figure(result, "Y")
    assert "zero over the whole volume" in figure_text(fig)


@pytest.mark.slow
def test_png_bytes_are_deterministic_and_sized(line_machine, tmp_path):
    result = analyse(line_machine)
    images = []
    for name in ("a.png", "b.png"):
        plots.save_png(plots.volumetric_map_figure(result), tmp_path / name)
        images.append((tmp_path / name).read_bytes())
    assert images[0] == images[1] and b"Software" not in images[0]
    # the pixel size is the figure size (A4 landscape) times the resolution: at 80 dpi
    buffer = io.BytesIO()
    plots.volumetric_map_figure(result).savefig(buffer, format="png", dpi=80)
    assert buffer.getvalue()[16:24] == (935).to_bytes(4, "big") + (661).to_bytes(4, "big")


# -- inputs ------------------------------------------------------------------------------


def lines_of(ax) -> list:
    return [line for line in ax.lines if len(line.get_xdata()) > 1]


def test_inputs_are_grouped_per_axis_and_inline_values_have_no_runs():
    """points and constant sources are one curve each: no forward or reverse runs are
    drawn or named for them."""
    data = {
        "machine": {
            "name": "m",
            "configuration": "wBMTt",
            "axes": {"bottom": "X", "middle": "Y", "top": "Z"},
        },
        "axes": {
            "X": {
                "travel": [0, 400],
                "step": 100,
                "errors": {
                    "linear": {"points": [[0, 0.0], [200, 3.0], [400, 2.0]]},
                    "angular": {"Y": {"constant": 5.0}, "Z": {"constant": -2.0}},
                },
            },
            "Y": {"travel": [0, 400], "step": 100},
            "Z": {"travel": [0, 200], "step": 100},
        },
    }
    result = analyse(machine_from_dict(data, "."))
    assert plots.input_axes(result) == ("X",)
    fig = plots.axis_inputs_figure(result, "X")
    assert len(fig.axes) == 3  # X.linear, X.angular.Y, X.angular.Z
    linear = fig.axes[0]
    runs = [line for line in linear.lines if line.get_linewidth() < 1 and line.get_alpha()]
    assert runs == []  # thin translucent lines are runs; the zero line is opaque
    given = [line for line in linear.lines if line.get_marker() == "o"]
    assert len(given) == 1 and list(given[0].get_ydata()) == [0.0, 3.0, 2.0]
    # a constant: a level line over the simulated range of X
    level = [line for line in fig.axes[1].lines if list(line.get_ydata()) == [5.0, 5.0]]
    assert len(level) == 1 and list(level[0].get_xdata()) == [0.0, 400.0]
    legend = [t.get_text() for t in fig.legends[0].get_texts()]
    assert not {"forward runs", "forward mean", "reverse runs", "reverse mean"} & set(legend)
    assert "given in the configuration" in legend and "constant (configuration)" in legend


def test_straightness_shows_the_runs_the_fitted_line_and_the_result(make_machine):
    """A straightness with a set-up slope: the raw runs, the least-squares line fitted to
    their mean (dotted) and the result with that line removed (Longstaff 2002,
    4.01.2.1 c), each as drawn data."""
    from esp.core.profile import ErrorProfile

    x = np.array([0.0, 100.0, 200.0, 300.0])
    bow = np.array([0.0, 1.0, 1.0, 0.0])
    slope = 0.02 * x  # 0.02 µm/mm of misalignment
    profile = ErrorProfile(
        "straightness",
        x,
        {"forward": [bow + slope, bow + slope + 0.2], "backward": [bow + slope - 0.2]},
        axis="X",
        error_direction="Y",
        source="X-straightness-Y.stx",
    )
    machine = make_machine({"X.straightness.Y": profile}, travel=(0.0, 300.0), step=100.0)
    result = analyse(machine)
    ax = plots.axis_inputs_figure(result, "X").axes[0]
    # the raw runs, slope and all: one collection of thin lines per direction
    runs = [path.vertices for c in ax.collections for path in c.get_paths()]
    assert len(runs) == 3
    np.testing.assert_allclose(runs[0][:, 0], x)
    np.testing.assert_allclose(runs[0][:, 1], bow + slope)
    np.testing.assert_allclose(runs[2][:, 1], bow + slope - 0.2)
    mean = profile.mean("mean")
    fitted = [line for line in ax.lines if line.get_linestyle() == ":"]
    assert len(fitted) == 1
    # least squares through the mean: the line of the mean's best fit
    coef = np.polyfit(x, mean, 1)
    np.testing.assert_allclose(fitted[0].get_ydata(), np.polyval(coef, x), atol=1e-12)
    used = [line for line in ax.lines if line.get_linewidth() >= 5]
    np.testing.assert_allclose(used[0].get_ydata(), mean - np.polyval(coef, x), atol=1e-12)
    # the result is the bow (whose own best line is removed too): straight runs give zero
    np.testing.assert_allclose(
        used[0].get_ydata(), bow - np.polyval(np.polyfit(x, bow, 1), x), atol=1e-12
    )


# -- the sweep ------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def sweep_result():
    return analyse(
        load_machine(Path(__file__).parent / "data" / "reports" / "sweep" / "machine.toml")
    )


@pytest.mark.slow
def test_sweep_marks_the_worst_and_spans_the_values(sweep_result):
    entries = sweep_result.sweep
    values = [e.volumetric.value_um for e in entries]
    fig = plots.sweep_figure(sweep_result)
    ax = fig.axes[0]
    stars = [line for line in ax.lines if line.get_marker() == "*"]
    assert len(stars) == 1 and stars[0].get_ydata()[0] == pytest.approx(max(values))
    lo, hi = ax.get_ylim()
    assert lo <= min(values) and hi >= max(values)
    if max(values) > min(values):  # the axis shows the differences: not from zero
        assert hi - lo <= 1.5 * (max(values) - min(values))
    # the legend lies outside the plot, right of it
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    legend = ax.get_legend().get_window_extent(renderer)
    assert legend.x0 >= ax.get_window_extent(renderer).x1
    assert text_problems(fig) == []


# -- no text cut or overdrawn -----------------------------------------------------------------


def check_figures(result, skip: tuple[str, ...] = ()) -> list[str]:
    problems = []
    for spec in bundle.figure_specs(result):
        if spec.filename in skip:
            continue
        problems += [f"{spec.filename}: {p}" for p in text_problems(spec.build())]
    return problems


@pytest.mark.slow
def test_no_text_is_cut_or_overdrawn(make_machine):
    machine = make_machine(
        {
            "X.linear": [(0.0, 0.0), (1000.0, 5.0)],
            "X.straightness.Y": [(0.0, 0.0), (500.0, 2.0), (1000.0, 0.0)],
            "Y.angular.Z": [(0.0, 3.0), (1000.0, -4.0)],
            "squareness.XY": 7.0,
        }
    )
    assert check_figures(analyse(machine)) == []


#: shipped examples whose figures differ in kind: a head sweep with three tool lengths, a
#: two-axis machine (plane of motion, a non-moving axis), an uncertainty budget of 21
#: components with no error data; docs/reports.md says how every example was checked
REPRESENTATIVE = (
    "gantry/machine-tcp.toml",
    "turning-centre/machine-mcp.toml",
    "uncertainty-study/machine-statistical.toml",
)


@pytest.mark.slow
@pytest.mark.parametrize("name", REPRESENTATIVE)
def test_no_text_is_cut_in_the_shipped_examples(name):
    # the three direction maps have one layout whatever the data (checked above)
    maps = ("map-X.png", "map-Y.png", "map-Z.png")
    assert check_figures(analyse(load_machine(EXAMPLES / name)), skip=maps) == []


def test_the_text_check_finds_cut_and_overdrawn_texts():
    fig = plots._new_figure()
    fig.text(0.9, 0.5, "a note that runs off the right edge of the page")
    fig.text(0.1, 0.2, "one text")
    fig.text(0.1, 0.2, "another text")
    problems = text_problems(fig)
    assert any(p.startswith("cut by the page") for p in problems)
    assert "'one text' over 'another text'" in problems


# -- the PNG files ------------------------------------------------------------------------


def _small_figure():
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(2.0, 1.5), dpi=50)
    FigureCanvasAgg(fig)
    ax = fig.add_axes((0.2, 0.2, 0.7, 0.7))
    ax.imshow(np.arange(12.0).reshape(3, 4), cmap="viridis", aspect="auto")
    ax.set_title("µm −3", fontsize=8)
    return fig


def test_png_files_hold_the_pixels_matplotlib_draws(tmp_path):
    """drawing.save_png writes what matplotlib draws on its Agg canvas, at the resolution
    asked for (the pixel size and pHYs), with no text chunk (no software version), the
    same bytes each time."""
    from PIL import Image

    from esp.report import drawing

    fig = _small_figure()
    drawing.save_png(fig, tmp_path / "a.png", 80)
    drawing.save_png(_small_figure(), tmp_path / "b.png", 80)
    data = (tmp_path / "a.png").read_bytes()
    assert data == (tmp_path / "b.png").read_bytes()
    assert b"tEXt" not in data and b"iTXt" not in data and b"zTXt" not in data
    fig.set_dpi(80)
    fig.canvas.draw()
    drawn = np.asarray(fig.canvas.buffer_rgba())
    with Image.open(tmp_path / "a.png") as png:
        assert png.size == (160, 120)
        assert png.info["dpi"] == pytest.approx((80.0, 80.0), abs=0.05)  # pixels per metre
        assert np.array_equal(np.asarray(png.convert("RGBA")), drawn)


def test_figures_are_matplotlibs_own_axes_on_its_agg_canvas(line_machine):
    """Every figure of a report is drawn by matplotlib's own classes (no subclass of its
    axes or canvas)."""
    from matplotlib.axes import Axes
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    result = analyse(line_machine)
    for fig in (plots.volumetric_map_figure(result), plots.direction_maps_figure(result, "X")):
        assert type(fig.canvas) is FigureCanvasAgg
        assert {type(ax) for ax in fig.axes} == {Axes}


def test_a_source_too_long_for_the_panel_goes_on_a_line_of_its_own():
    """The description, unit and source of a panel on one line when they fit; else the
    source on a line of its own, whole (never cut with "…")."""
    from matplotlib.figure import Figure

    from esp.config import load_machine
    from esp.core.analysis import analyse
    from esp.volumetric import plots

    root = Path(__file__).parent.parent / "data" / "examples"
    result = analyse(load_machine(root / "turning-centre" / "machine-mcp.toml"))
    fig = plots.axis_inputs_figure(result, "X")
    assert isinstance(fig, Figure)
    texts = [t.get_text() for ax in fig.axes for t in ax.texts]
    assert "X-axis linear positioning · µm · Xpos_z0.rtl" in texts  # fits: one line
    assert "X-axis rotation about Y · µm/m" in texts  # too long: two lines
    source = [t for t in texts if t.startswith("from_linear")]
    assert source and not any(t.endswith("…") for t in source)


def test_axes_get_only_the_ticks_they_draw(line_machine):
    """The panels of the input and map figures locate only the ticks inside their view
    (matplotlib builds a tick, two marks, a grid line and two labels, for every location
    it is given), and those are the ticks a plain MaxNLocator of the same bins draws."""
    from matplotlib.ticker import MaxNLocator

    result = analyse(line_machine)
    inputs = plots.axis_inputs_figure(result, "X")
    maps = plots.direction_maps_figure(result, "X")
    panels = [*inputs.axes, *maps.axes[:3]]  # the maps' fourth axes is the colour bar
    for ax in panels:
        for axis, limits in ((ax.xaxis, ax.get_xlim()), (ax.yaxis, ax.get_ylim())):
            lo, hi = sorted(limits)
            locs = axis.get_majorticklocs()
            assert len(locs) >= 2 and lo <= min(locs) and max(locs) <= hi
            # the plain locator's ticks, of which it draws those inside the view
            plain = MaxNLocator.tick_values(axis.get_major_locator(), lo, hi)
            slack = 1e-9 * (hi - lo)
            np.testing.assert_array_equal(
                locs, plain[(plain >= lo - slack) & (plain <= hi + slack)]
            )


def test_texts_placed_by_offset_are_plain_texts_where_an_annotation_would_put_them(line_machine):
    """The lines above an input panel are plain texts (an annotation works out its place
    anew at every drawing), each its given number of points above the top left corner of
    the panel, at the PNG's resolution and at the PDF's."""
    from matplotlib.text import Annotation

    result = analyse(line_machine)
    fig = plots.axis_inputs_figure(result, "X")
    ax = fig.axes[0]
    assert ax.texts and not any(isinstance(t, Annotation) for ax in fig.axes for t in ax.texts)
    head = ax.texts[0]
    assert head.get_text().startswith("X.linear")
    for dpi in (plots.DPI, 72):
        fig.set_dpi(dpi)
        corner = ax.transAxes.transform((0.0, 1.0))
        at = head.get_transform().transform(head.get_position())
        np.testing.assert_allclose(at - corner, (0.0, 17.0 * dpi / 72.0), atol=1e-9)


def test_map_titles_sit_on_their_panels_without_being_measured(line_machine):
    """The title of a map panel is placed at the top of its axes (given, not found by
    measuring the tick labels of both axes at every drawing): no tick label is above a
    panel, and the y axis shows its numbers whole, with no offset text for the title to
    avoid, so that it clears the panel as matplotlib's own placement would."""
    result = analyse(line_machine)
    fig = plots.direction_maps_figure(result, "X")
    panels = fig.axes[:3]  # the fourth axes is the colour bar
    for ax in panels:
        assert ax.get_title().endswith(" mm")
        assert ax.title.get_position()[1] == 1.0
        assert ax.yaxis.get_major_formatter().get_useOffset() is False
    fig.canvas.draw()
    for ax in panels:
        assert ax.yaxis.get_offset_text().get_text() == ""
        top = ax.get_window_extent().y1
        assert ax.title.get_window_extent().y0 > top  # above the panel, not over it
