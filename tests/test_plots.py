"""Pictures for people: drawings inside their frame with labels that do not collide, diagrams with
labelled axes and units, the table positions marked, and the install hint without matplotlib."""

import io
import re
import sys

import numpy as np
import pytest

matplotlib = pytest.importorskip(
    "matplotlib", reason="pictures need the plot extra, which the test extra installs: pip install \".[test]\"")

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.collections import LineCollection  # noqa: E402
from matplotlib.lines import Line2D  # noqa: E402
from matplotlib.patches import Patch  # noqa: E402
from matplotlib.text import Annotation  # noqa: E402

import linkage  # noqa: E402
from linkage.dynamics.pipeline import run_dynamics  # noqa: E402
from linkage.errors import InputError, LinkageError  # noqa: E402
from linkage.report import plots  # noqa: E402
from linkage.report.plots import (PlotExtraMissing, describe_column, draw_mechanism, draw_positions,  # noqa: E402
                                  extreme_marks, plot_columns, plot_diagrams, plot_dynamics, plot_motion)

SCHEMES = list(linkage.shipped_schemes())
UNIT = re.compile(r", (m|deg|rad|m/rad|m/rad²|rad/rad|rad/rad²|N|N·m|kg·m²|kg·m²/rad|rad/s|rad/s²|s)$")


@pytest.fixture(autouse=True)
def _close_figures():
    yield
    plt.close("all")


def _table(name, n=12):
    mech = linkage.load(name)
    return mech, linkage.analyze(mech, linkage.table_angles(mech, n))


def _data_points(artist) -> np.ndarray:
    """Every vertex an artist draws, in data coordinates."""
    if isinstance(artist, Line2D):
        return np.asarray(artist.get_xydata(), dtype=float)
    if isinstance(artist, Patch):
        path = artist.get_path().transformed(artist.get_patch_transform())
        return path.vertices
    if isinstance(artist, LineCollection):
        segs = artist.get_segments()
        return np.vstack(segs) if segs else np.zeros((0, 2))
    return np.zeros((0, 2))


def _assert_inside(ax):
    """Every line, patch and collection lies within the axis limits, as do the data limits."""
    x0, x1 = ax.get_xlim()
    y0, y1 = ax.get_ylim()
    lim = ax.dataLim
    assert x0 <= lim.x0 and lim.x1 <= x1 and y0 <= lim.y0 and lim.y1 <= y1, (lim, ax.get_xlim(), ax.get_ylim())
    artists = list(ax.lines) + list(ax.patches) + list(ax.collections)
    assert artists
    for artist in artists:
        pts = _data_points(artist)
        pts = pts[np.all(np.isfinite(pts), axis=1)]
        if len(pts):
            assert (pts[:, 0] >= x0).all() and (pts[:, 0] <= x1).all(), artist.get_gid()
            assert (pts[:, 1] >= y0).all() and (pts[:, 1] <= y1).all(), artist.get_gid()


def _overlap(a, b, slack=0.5):
    return (min(a.x1, b.x1) - max(a.x0, b.x0) > slack) and (min(a.y1, b.y1) - max(a.y0, b.y0) > slack)


def _assert_labels_clear(fig):
    """Point labels inside their axes, clear of each other and of the revolute pairs; no two texts of
    the figure (titles, axis labels, tick labels, point labels) overlap."""
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    texts = []
    for ax in fig.axes:
        frame = ax.get_window_extent(renderer)
        labels = [t for t in ax.texts if isinstance(t, Annotation) and (t.get_gid() or "").startswith("label:")]
        assert labels, "no point labels"
        boxes = [t.get_window_extent(renderer) for t in labels]
        for t, b in zip(labels, boxes):
            assert frame.x0 <= b.x0 and b.x1 <= frame.x1 and frame.y0 <= b.y0 and b.y1 <= frame.y1, t.get_text()
        for k, a in enumerate(boxes):
            for j in range(k):
                assert not _overlap(a, boxes[j]), (labels[k].get_text(), labels[j].get_text())
        pins = [p for p in ax.patches if (p.get_gid() or "").startswith("pair:")]
        for pin in pins:
            centre = ax.transData.transform(pin.center)
            for t, b in zip(labels, boxes):
                assert not b.contains(*centre), (t.get_text(), pin.get_gid())
        texts += [(t.get_text(), b) for t, b in zip(labels, boxes)]
        ticks = ax.get_xticklabels() + ax.get_yticklabels()
        for t in [ax.title, ax._left_title, ax.xaxis.label, ax.yaxis.label] + ticks:
            if t.get_text() and t.get_visible():
                texts.append((t.get_text(), t.get_window_extent(renderer)))
    if fig._suptitle is not None:
        texts.append((fig._suptitle.get_text(), fig._suptitle.get_window_extent(renderer)))
    page = fig.bbox
    for text, box in texts:   # nothing cut off at the edges of the figure
        assert page.x0 <= box.x0 and box.x1 <= page.x1 and page.y0 <= box.y0 and box.y1 <= page.y1, text
    for k, (ta, a) in enumerate(texts):
        for tb, b in texts[:k]:
            assert not _overlap(a, b), (ta, tb)


def _assert_axis_labels(ax, x=True):
    for label in (ax.get_xlabel(), ax.get_ylabel())[0 if x else 1:]:
        assert label.strip(), "an empty axis label"
        assert UNIT.search(label.replace("\n", " ")), label


# -- the mechanism drawn to scale -----------------------------------------------------------------


@pytest.mark.parametrize("name", SCHEMES)
def test_drawing_of_every_scheme_is_inside_its_frame_with_clear_labels(name):
    _, motion = _table(name)
    for position in (1, 7) if name in ("four_bar", "slotted_link_two_dyad") else (7,):
        ax = draw_mechanism(motion, position)
        _assert_inside(ax)
        _assert_axis_labels(ax)
        assert ax.get_aspect() == 1.0
        _assert_labels_clear(ax.figure)
        title = ax.get_title("left")
        count = 12 if motion.mechanism.input_range is None else 13      # over a turn row 13 is row 1
        assert f"Position {position + 1} of {count}" in title
        mech = motion.mechanism
        if mech.coordinate.is_angle:
            assert "crank turned" in title and "°" in title
        else:   # how far the slide input moved from position 1 and where it is, in m
            moved = abs(motion.phi[position] - motion.phi[0])
            verb = "cylinder extended by" if mech.inputs[0] in mech.pairs else "input slider moved"
            assert f"{verb} {moved:.4g} m" in title.replace("\n", " "), title
            assert f"s = {motion.phi[position]:.4g} m" in title.replace("\n", " ") and "°" not in title, title
        plt.close(ax.figure)


@pytest.mark.parametrize("name", SCHEMES)
def test_several_positions_share_one_scale_and_stay_clear(name):
    _, motion = _table(name)
    fig = draw_positions(motion, [0, 4, 9])
    assert len(fig.axes) == 3
    limits = {(ax.get_xlim(), ax.get_ylim()) for ax in fig.axes}
    assert len(limits) == 1
    for ax in fig.axes:
        _assert_inside(ax)
        _assert_axis_labels(ax)
    _assert_labels_clear(fig)


def test_drawing_shows_every_pair_guide_pivot_and_the_trajectory():
    mech, motion = _table("slotted_link_two_dyad")
    ax = draw_mechanism(motion, 2, trajectories=["C"])
    gids = {a.get_gid() for a in list(ax.lines) + list(ax.patches) + list(ax.collections)}
    for pair in mech.pairs.values():
        if pair.kind == "R":
            assert f"pair:{pair.name}" in gids
        else:
            assert f"block:{pair.links[1]}" in gids
    assert {"guide", "guide-surface", "hatching", "support", "slot:3", "trajectory:C"} <= gids
    path = next(line for line in ax.lines if line.get_gid() == "trajectory:C").get_xydata()
    assert np.min(np.hypot(*(path - motion.point("C")[2]).T)) < 0.01 * mech.size
    labels = {t.get_text() for t in ax.texts if (t.get_gid() or "").startswith("label:")}
    assert labels == set(mech.point_names)
    assert "dashed: trajectory of C over a turn" in ax.get_title("left")


def test_four_bar_coupler_curve_is_inside_and_labels_clear():
    _, motion = _table("four_bar")
    ax = draw_mechanism(motion, 2, trajectories=["E"])
    _assert_inside(ax)
    _assert_labels_clear(ax.figure)


def test_drawing_saves_as_png_and_svg():
    _, motion = _table("flying_shears")
    fig = draw_positions(motion, [0, 3, 6, 9], trajectories=["E"])
    for fmt, magic in (("png", b"\x89PNG"), ("svg", b"<?xml")):
        out = io.BytesIO()
        fig.savefig(out, format=fmt)
        assert out.getvalue().startswith(magic)


def test_drawing_refuses_what_it_cannot_draw():
    _, motion = _table("four_bar")
    with pytest.raises(InputError, match="no point 'Z'"):
        draw_mechanism(motion, 0, trajectories=["Z"])
    with pytest.raises(InputError, match="index of the 13 analysed angles"):
        draw_mechanism(motion, 13)


# -- diagrams of table columns --------------------------------------------------------------------


def test_column_words_name_the_quantity_and_its_unit():
    mech = linkage.load("slider_crank")
    assert describe_column("B.x", mech).axis == "slider position $x_{\\mathrm{B}}$, m"
    # analogs per rad turned, psi: the x axis of every diagram (docs/conventions.md)
    assert describe_column("B.x'").legend == ("velocity analog of B along x $x'_{\\mathrm{B}} = dx_{\\mathrm{B}}/d\\psi$ "
                                              "(m/rad, per rad of crank rotation)")
    assert describe_column("A.y''").axis == "acceleration analog of A along y $d^2y_{\\mathrm{A}}/d\\psi^2$, m/rad²"
    assert describe_column("phi_deg", mech).axis == "crank angle turned from position 1 $\\psi$, deg"
    assert describe_column("T.x'", linkage.load("cylinder_boom")).legend.endswith("/ds$ (m/m, per m of cylinder travel)")
    assert describe_column("2.theta'", mech).words == "angular velocity analog of coupler 2"
    assert describe_column("3.theta", linkage.load("four_bar")).words == "angle of rocker 3"
    assert describe_column("slide.R").axis == "reaction in pair slide $R_{\\mathrm{slide}}$, N"
    assert describe_column("balancing_moment").legend == "balancing moment on the crank $M_b$ (N·m, CCW positive)"
    assert describe_column("reduced_inertia").unit == "kg·m²"
    assert describe_column("slot_A.s").symbol == "$s_{\\mathrm{slot\\_A}}$"
    for name in ("B.x", "B.x'", "3.theta''", "slide.s'", "A.angle_deg", "omega", "eps", "t"):
        assert UNIT.search(describe_column(name).axis), name


def test_motion_diagrams_mark_and_number_every_table_position():
    _, motion = _table("slider_crank")
    fig = plot_motion(motion, ["B.x", "B.x'", "B.x''"])
    panels = [ax for ax in fig.axes if ax.get_ylabel()]
    assert len(panels) == 3
    for ax, name in zip(panels, ["B.x", "B.x'", "B.x''"]):
        _assert_axis_labels(ax, x=ax is panels[-1])
        marked = next(line for line in ax.lines if line.get_gid() == f"positions:{name}")
        np.testing.assert_allclose(marked.get_ydata(), motion.columns()[name])
        assert len(marked.get_xdata()) == 13
        curve = next(line for line in ax.lines if line.get_gid() == f"curve:{name}")
        assert len(curve.get_xdata()) > 300
        extremes = [line.get_xdata()[0] for line in ax.lines if line.get_gid() == "extreme-position"]
        assert sorted(extremes) == pytest.approx([0.0, 182.59, 360.0], abs=0.01)
    top = panels[0].child_axes[0]
    assert top.get_gid() == "position-numbers"
    assert [t.get_text() for t in top.get_xticklabels()] == [str(i) for i in range(1, 14)]
    assert all(not ax.get_title() for ax in panels)          # no "phi = 426.4 deg" titles
    fig.canvas.draw()


def test_many_positions_are_all_marked_and_the_numbers_thinned():
    _, motion = _table("flying_shears", 72)
    fig = plot_motion(motion, ["E.y"])
    ax = fig.axes[0]
    marked = next(line for line in ax.lines if line.get_gid() == "positions:E.y")
    assert len(marked.get_xdata()) == 73
    numbers = [t.get_text() for t in ax.child_axes[0].get_xticklabels()]
    assert numbers[0] == "1" and numbers[-1] == "73" and len(numbers) <= 26


def test_angle_columns_are_continuous():
    mech, motion = _table("slider_crank", 24)
    cols = motion.columns()
    assert np.max(np.abs(np.diff(cols["1.theta"]))) > np.pi      # the table folds it into (-pi, pi]
    ax = plot_columns(cols, ["1.theta"], mechanism=mech)
    y = ax.lines[0].get_ydata()
    assert np.max(np.abs(np.diff(y))) < 0.3
    _assert_axis_labels(ax)


def test_columns_of_different_units_go_on_panels_of_their_own():
    mech, motion = _table("four_bar")
    cols = motion.columns()
    with pytest.raises(InputError, match="different units"):
        plot_columns(cols, ["E.x", "E.x'"])
    fig = plot_diagrams(cols, ["E.x", "E.y", "3.theta'"], mechanism=mech,
                        marks=extreme_marks(mech, motion.phi))
    panels = [ax for ax in fig.axes if ax.get_ylabel()]
    assert len(panels) == 2
    assert panels[0].get_ylabel().startswith("coordinates $x_{\\mathrm{E}}$, $y_{\\mathrm{E}}$")
    legend = [t.get_text() for t in fig.legends[0].get_texts()]
    assert legend[:2] == ["x coordinate of E $x_{\\mathrm{E}}$ (m)", "y coordinate of E $y_{\\mathrm{E}}$ (m)"]
    for ax in panels:
        _assert_axis_labels(ax, x=ax is panels[-1])


def test_balancing_moment_carries_the_mean_driving_moment():
    report = run_dynamics(linkage.load("course_slider_crank"), compare=False)
    fig = plot_dynamics(report, ["balancing_moment", "omega", "reduced_moment_resistance"])
    panels = [ax for ax in fig.axes if ax.get_ylabel()]
    md = report.summary()["driving_moment"]
    mean = next(line for line in panels[0].lines if line.get_gid() == "mean-moment")
    assert mean.get_ydata()[0] == pytest.approx(-md)          # clockwise: s M_d, the mean of M_b
    assert np.mean(report.balancing_moment[:-1]) == pytest.approx(-md, rel=2e-3)
    assert not any(line.get_gid() == "mean-moment" for line in panels[1].lines)
    reduced = next(line for line in panels[2].lines if line.get_gid() == "mean-moment")
    assert reduced.get_ydata()[0] == pytest.approx(md)
    for ax in panels:
        _assert_axis_labels(ax, x=ax is panels[-1])
        marked = next(line for line in ax.lines if (line.get_gid() or "").startswith("positions:"))
        assert len(marked.get_xdata()) == 13


# -- without matplotlib ---------------------------------------------------------------------------


def test_without_matplotlib_every_picture_says_what_to_install(monkeypatch):
    _, motion = _table("four_bar")
    cols = motion.columns()
    for module in [m for m in list(sys.modules) if m == "matplotlib" or m.startswith("matplotlib.")]:
        monkeypatch.setitem(sys.modules, module, None)
    calls = [lambda: draw_mechanism(motion, 0), lambda: draw_positions(motion),
             lambda: plot_columns(cols, ["E.x"]), lambda: plot_diagrams(cols, ["E.x"]),
             lambda: plot_motion(motion, ["E.x"])]
    for call in calls:
        with pytest.raises(PlotExtraMissing, match=re.escape('pip install "linkage[plot]"')) as info:
            call()
        assert isinstance(info.value, LinkageError) and isinstance(info.value, ImportError)
    assert describe_column("E.x").unit == "m"      # naming needs no matplotlib
    assert plots.INSTALL_HINT.endswith('pip install "linkage[plot]"')
