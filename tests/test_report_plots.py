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


# -- the canvas of the PNG files ------------------------------------------------------------


def _ink_box(fig) -> tuple[int, int, int, int]:
    """The pixel box (x0, y0, x1, y1) of everything not white on the drawn figure."""
    fig.canvas.draw()
    grey = np.asarray(fig.canvas.buffer_rgba())[..., :3].min(axis=2)
    rows, cols = np.nonzero(grey < 200)
    return int(cols.min()), int(rows.min()), int(cols.max()), int(rows.max())


def _text_figure(angle: float):
    from matplotlib.figure import Figure

    fig = Figure(figsize=(4, 3), dpi=100)  # room for the whole text, either way
    fig.text(0.1, 0.1, "X position, middle axis (mm) -5", fontsize=10, rotation=angle)
    return fig


@pytest.mark.parametrize("angle", [0.0, 90.0])
def test_agg_canvas_draws_a_text_where_matplotlib_does(angle):
    """A text drawn as one bitmap (drawing.agg_canvas) covers the same pixels as
    matplotlib's own glyph-by-glyph drawing, to a pixel or two at each edge: the same
    font, size and anchor; only the sub-pixel placement of the glyphs may differ."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    from esp.report import drawing

    theirs = _text_figure(angle)
    FigureCanvasAgg(theirs)
    ours = _text_figure(angle)
    drawing.agg_canvas(ours)
    a, b = _ink_box(theirs), _ink_box(ours)
    assert all(abs(p - q) <= 2 for p, q in zip(a, b, strict=True)), (a, b)
    width = a[2] - a[0] if angle == 0 else a[3] - a[1]
    assert width > 150  # the whole string is drawn, not a glyph of it


def test_png_bytes_do_not_depend_on_the_texts_kept_from_earlier_figures(tmp_path):
    """The bitmaps of texts are kept between figures (drawing._rendered_text): the same
    figure saved with nothing kept and with everything kept gives the same bytes."""
    from esp.report import drawing

    def saved(name: str) -> bytes:
        fig = plots._new_figure()
        plots._title(fig, "A headline of a figure", "and its subtitle, µm at X=0 mm")
        ax = plots._axes(fig, 1.0, 1.0, 8.0, 5.0)
        ax.plot([0.0, 400.0], [-3.0, 2.0])
        ax.set_xlabel("X position (mm)")
        drawing.flat_ticks(fig)
        plots.save_png(fig, tmp_path / name)
        return (tmp_path / name).read_bytes()

    drawing._rendered_text.cache_clear()
    first = saved("a.png")
    assert drawing._rendered_text.cache_info().currsize > 0
    assert saved("b.png") == first


def _small_figure():
    from matplotlib.figure import Figure

    from esp.report import drawing

    fig = Figure(figsize=(2.0, 1.5), dpi=50)
    drawing.agg_canvas(fig)
    ax = fig.add_axes((0.2, 0.2, 0.7, 0.7))
    ax.imshow(np.arange(12.0).reshape(3, 4), cmap="viridis", aspect="auto")
    ax.set_title("µm −3", fontsize=8)
    return fig


def test_png_files_hold_the_pixels_matplotlib_draws(tmp_path):
    """esp's encoder (drawing.png_bytes) writes the pixels matplotlib's own PNG holds:
    decoded by Pillow, the same array; opaque, so RGB; the resolution in pHYs."""
    from PIL import Image

    from esp.report import drawing

    theirs = io.BytesIO()
    _small_figure().savefig(theirs, format="png", dpi=50)
    drawing.save_png(_small_figure(), tmp_path / "ours.png", 50)
    a = np.asarray(Image.open(theirs).convert("RGBA"))
    with Image.open(tmp_path / "ours.png") as ours:
        assert ours.mode == "RGB" and ours.size == (100, 75)
        assert ours.info["dpi"] == pytest.approx((50.0, 50.0), abs=0.05)  # whole pixels per metre
        b = np.asarray(ours.convert("RGBA"))
    assert np.array_equal(a, b)


def test_png_rows_are_stored_as_differences_from_the_row_above():
    """A 2 x 2 image worked by hand (ISO/IEC 15948, 9.2, filter type 2 "Up"): the first
    row less zero, the second less the first, modulo 256; a pixel not opaque keeps the
    alpha channel (colour type 6), and Pillow decodes the same pixels."""
    import struct
    import zlib

    from PIL import Image

    from esp.report import drawing

    rgba = np.array(
        [[[10, 20, 30, 255], [200, 0, 5, 255]], [[12, 10, 30, 255], [1, 0, 250, 128]]],
        dtype=np.uint8,
    )
    data = drawing.png_bytes(rgba, 100)
    width, height, depth, colour = struct.unpack(">IIBB", data[16:26])
    assert (width, height, depth, colour) == (2, 2, 8, 6)
    start = data.index(b"IDAT") + 4
    (size,) = struct.unpack(">I", data[start - 8 : start - 4])
    rows = zlib.decompress(data[start : start + size])
    assert list(rows) == [
        *(2, 10, 20, 30, 255, 200, 0, 5, 255),
        # 12-10, 10-20 (= 246), 30-30, 255-255; 1-200 (= 57), 0-0, 250-5, 128-255 (= 129)
        *(2, 2, 246, 0, 0, 57, 0, 245, 129),
    ]
    assert np.array_equal(np.asarray(Image.open(io.BytesIO(data))), rgba)
    opaque = rgba.copy()
    opaque[..., 3] = 255
    assert drawing.png_bytes(opaque, 100)[25] == 2  # RGB: the alpha channel left out


def test_kept_layouts_are_the_ones_matplotlib_makes():
    """A text's kept layout (drawing.cached_layouts) is matplotlib's own for the text as
    it is at each call: a text changed (its string, size or angle) is laid out again."""
    from matplotlib.text import Text

    from esp.report import drawing

    fig = _small_figure()
    drawing.cached_layouts(fig)
    renderer = fig.canvas.get_renderer()
    text = fig.axes[0].title
    assert "_get_layout" in vars(text)

    def same(layout, expected) -> bool:
        (box, lines, corner), (box2, lines2, corner2) = layout, expected
        return (
            np.array_equal(box.get_points(), box2.get_points())
            and lines == lines2
            and corner == corner2
        )

    for change in ({}, {"text": "a longer title"}, {"fontsize": 14}, {"rotation": 90}):
        text.set(**change)
        kept = text._get_layout(renderer)
        assert same(kept, Text._get_layout(text, renderer))
        assert same(text._get_layout(renderer), kept)  # from what was kept
    box = text._get_layout(renderer)[0]
    box.x0 += 50  # a caller moving the box it got does not move the kept one
    assert text._get_layout(renderer)[0].x0 == pytest.approx(box.x0 - 50)


@pytest.mark.parametrize("weight", ["normal", "bold"])
def test_font_files_are_matplotlibs_whatever_the_size(weight):
    from matplotlib.font_manager import FontProperties, fontManager

    from esp.report import drawing

    for size in (6.0, 8.5, 12.5):
        prop = FontProperties(size=size, weight=weight)
        assert drawing._font_files(prop) == fontManager._find_fonts_by_props(prop)


def test_kept_font_lookups_find_the_fonts_matplotlib_finds():
    """A font kept under its properties less its size (drawing.quick_font_lookup) is the
    one matplotlib's own search finds, at any size and weight, for core (AFM) and
    TrueType fonts; a change of the settings the search reads is looked up afresh."""
    import matplotlib as mpl
    from matplotlib import font_manager
    from matplotlib.font_manager import FontProperties

    from esp.report import drawing

    drawing.quick_font_lookup()
    manager = font_manager.fontManager
    assert getattr(manager.findfont, "_esp_kept", False)
    own = type(manager).findfont  # matplotlib's search, not kept
    for family in ("sans-serif", "serif", "monospace", "Helvetica"):
        for weight in ("normal", "bold"):
            for size in (6.0, 9.5, 31.0):
                prop = FontProperties(family=family, weight=weight, size=size)
                for kw in ({}, {"fontext": "afm"}):
                    found = own(manager, prop, **kw)
                    assert manager.findfont(prop, **kw) == found
                    assert font_manager.findfont(prop, **kw) == found
    prop = FontProperties(family="sans-serif", size=9.0)
    before = manager._find_fonts_by_props(prop)
    with mpl.rc_context({"font.sans-serif": ["DejaVu Serif"]}):
        serif = manager._find_fonts_by_props(prop)
        assert serif == [own(manager, prop)]
    assert "Serif" in str(serif[0]) and serif != before
    assert manager._find_fonts_by_props(prop) == before


def test_flat_tick_labels_are_drawn_where_matplotlib_draws_its_own(monkeypatch):
    """The labels of drawing.flat_ticks (one artist per axis) are the strings matplotlib's
    own ticks draw, at the same places, and the axis labels beside them are placed as
    matplotlib places them: every text drawn, its string and position, is the same."""
    from esp.report import drawing

    def drawn(flat: bool) -> list[tuple[str, float, float, float]]:
        fig = plots._new_figure()
        ax = plots._axes(fig, 1.0, 1.0, 6.0, 4.0)
        ax.plot([-350.0, 420.0], [-3.5, 12.0])
        ax.set_xlabel("X position (mm)")
        ax.set_ylabel("deviation (µm)")
        if flat:
            drawing.flat_ticks(fig)
        assert any(isinstance(a, type(drawing._ticks_artist([]))) for a in ax.artists) == flat
        calls: list[tuple[str, float, float, float]] = []
        renderer_class = drawing._RENDERER[0]
        draw_text = renderer_class.draw_text

        def record(self, gc, x, y, s, prop, angle, ismath=False, mtext=None):
            calls.append((s, round(x, 6), round(y, 6), prop.get_size_in_points()))
            return draw_text(self, gc, x, y, s, prop, angle, ismath, mtext)

        monkeypatch.setattr(renderer_class, "draw_text", record)
        fig.canvas.draw()
        monkeypatch.setattr(renderer_class, "draw_text", draw_text)
        return sorted(calls)

    own, flat = drawn(False), drawn(True)
    assert flat == own
    strings = [s for s, *_ in flat]
    assert "\N{MINUS SIGN}200" in strings and "X position (mm)" in strings


def test_esp_axes_make_ticks_only_when_asked_with_matplotlibs_clip_and_settings():
    """drawing.axes_class makes no tick with a new axes; ticks asked for later (a minor
    locator, the major ticks of a draw) have the settings and the clip matplotlib's own
    axes give them."""
    from matplotlib.figure import Figure
    from matplotlib.ticker import AutoMinorLocator

    from esp.report import drawing

    made = []
    for cls in (None, drawing.axes_class()):
        fig = Figure(figsize=(4.0, 3.0), dpi=50)
        ax = fig.add_axes((0.2, 0.2, 0.7, 0.7), axes_class=cls)
        ax.tick_params(which="minor", length=7.0, labelsize=6.0)
        ax.tick_params(which="major", length=5.0, labelsize=8.0, grid_alpha=0.25)
        ax.grid(True)
        made.append(("minorTicks" in vars(ax.xaxis), "majorTicks" in vars(ax.xaxis)))
        ax.plot([0.0, 10.0], [0.0, 1.0])
        ax.xaxis.set_minor_locator(AutoMinorLocator())
        ticks = [*ax.xaxis.get_minor_ticks(3), *ax.xaxis.get_major_ticks(3)]
        made.append(
            [
                (
                    t._size,
                    t.label1.get_fontsize(),
                    t.gridline.get_visible(),
                    t.gridline.get_alpha(),
                    t.gridline.get_clip_path() is None,
                )
                for t in ticks
            ]
        )
    assert made[0] == (True, True) and made[2] == (False, False)
    assert made[1] == made[3]
    assert made[1][2][:2] == (7.0, 6.0) and made[1][3][:4] == (5.0, 8.0, True, 0.25)


def test_kept_tick_properties_are_those_of_a_tick_made_now():
    """The tick properties drawing.flat_ticks reads are kept per kind of axis, tick
    settings and rcParams: whatever was kept before, an axis gets the properties of a tick
    matplotlib makes for it now -- after tick_params, grid and a change of rcParams alike."""
    import matplotlib as mpl
    from matplotlib.figure import Figure

    from esp.report import drawing

    def axes(kind):
        fig = Figure(figsize=(4.0, 3.0), dpi=50)
        return fig.add_axes((0.2, 0.2, 0.7, 0.7), axes_class=kind)

    def settings(ax, k):
        if k >= 1:
            ax.tick_params(labelsize=6.5, length=2.5, colors="0.3")
        if k >= 2:
            ax.grid(True, linewidth=0.4, alpha=0.5)

    seen = []
    for rc in ({}, {"xtick.major.pad": 9.0, "ytick.color": "red", "font.size": 13.0}):
        with mpl.rc_context(rc):
            for k in range(3):
                for axis in ("xaxis", "yaxis"):
                    kept = [axes(drawing.axes_class()) for _ in range(2)]
                    for ax in kept:
                        settings(ax, k)
                    props, again = (drawing._tick_props(getattr(ax, axis)) for ax in kept)
                    assert again is props  # kept: the second axes made no tick
                    assert "majorTicks" not in vars(getattr(kept[1], axis))
                    plain = axes(None)  # matplotlib's own axes: its ticks are made
                    settings(plain, k)
                    tick = getattr(plain, axis).get_major_ticks(1)[0]
                    assert props == drawing._props_of(tick)
                    assert props.pad_pt == tick.get_pad() + tick.get_tick_padding()
                    assert props.label[0].get_size_in_points() == tick.label1.get_fontsize()
                    seen.append(props)
    # seen: per rc (2), per settings (3), x then y; each change gave other properties
    assert seen[0] != seen[2] != seen[4] and seen[1] != seen[3] != seen[5]
    assert seen[0].pad_pt != seen[6].pad_pt and seen[1].mark != seen[7].mark


def test_a_flattened_axis_makes_no_tick_when_drawn(monkeypatch):
    """Once its tick properties are kept, an axis flattened by drawing.flat_ticks makes no
    matplotlib tick at all, neither when flattened nor when the figure is drawn (its
    spines placed first: placing one remakes its axis's tick lists)."""
    from matplotlib import axis as maxis

    from esp.report import drawing

    def figure():
        fig = plots._new_figure()
        ax = plots._axes(fig, 1.0, 1.0, 6.0, 4.0)
        ax.plot([-350.0, 420.0], [-3.5, 12.0])
        ax.grid(True, linewidth=0.4)
        return fig

    drawing.flat_ticks(figure())  # the properties kept
    made = []
    get_tick = maxis.Axis._get_tick
    monkeypatch.setattr(
        maxis.Axis, "_get_tick", lambda self, major: made.append(major) or get_tick(self, major)
    )
    fig = drawing.flat_ticks(figure())
    fig.canvas.draw()
    assert made == []
    assert len(fig.axes[0].artists) == 2  # the flat ticks of both axes


def test_esp_axes_background_keeps_its_transform_while_it_stays_in_place():
    """Every artist clipped to an esp axes is clipped through the one transform of its
    background, which gives the place matplotlib's gives; a background moved or given
    another transform composes a new one."""
    import numpy as np
    from matplotlib.figure import Figure
    from matplotlib.patches import Rectangle

    from esp.report import drawing

    fig = Figure(figsize=(4.0, 3.0), dpi=50)
    ax = fig.add_axes((0.2, 0.2, 0.7, 0.7), axes_class=drawing.axes_class())
    lines = [ax.plot([0.0, 1.0], [0.0, float(k)])[0] for k in range(3)]
    text = ax.text(0.5, 0.5, "note")
    transform = ax.patch.get_transform()
    assert ax.patch.get_transform() is transform
    assert all(a.clipbox._transform is transform for a in [*lines, text])
    plain = Rectangle((0.0, 0.0), 1.0, 1.0, transform=ax.transAxes)
    assert np.allclose(transform.get_matrix(), plain.get_transform().get_matrix())
    ax.set_position((0.1, 0.1, 0.5, 0.5))  # the axes moves: the same transform follows
    assert np.allclose(transform.get_matrix(), plain.get_transform().get_matrix())
    ax.patch.set_width(0.5)
    moved = ax.patch.get_transform()
    assert moved is not transform
    plain.set_width(0.5)
    assert np.allclose(moved.get_matrix(), plain.get_transform().get_matrix())
    ax.patch.set_transform(fig.transFigure)
    assert ax.patch.get_transform() is not moved


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
