"""Hodographs of the pair reactions: the plotted vectors are the reactions (solved again here, and for a
massless slider-crank under a constant slider force by hand from statics), drawn from one origin at
equal scales, numbered along the curve; the main pairs are those a course work draws."""

import re
import sys

import numpy as np
import pytest

matplotlib = pytest.importorskip(
    "matplotlib", reason="pictures need the plot extra, which the test extra installs: pip install \".[test]\"")

matplotlib.use("Agg")

import matplotlib.pyplot as plt

import linkage
from linkage.errors import InputError, LinkageError
from linkage.kinetostatics.reactions import solve_reactions
from linkage.report.hodographs import main_pairs, pair_words, plot_hodographs
from linkage.report.plots import PlotExtraMissing
from tests._texts import four_bar_toml, slider_crank_toml


@pytest.fixture(autouse=True)
def _close_figures():
    yield
    plt.close("all")


def _line(ax, gid):
    return next(line for line in ax.lines if line.get_gid() == gid)


def _panels(fig):
    return [ax for ax in fig.axes if ax.get_title(loc="left")]


def _labels(ax):
    return [t for t in ax.texts if (t.get_gid() or "").startswith("label:")]


def _table_reactions(name, omega, n=12):
    mech = linkage.load(name)
    phi = linkage.table_angles(mech, n, "extreme", 1 if omega > 0 else -1)
    return mech, phi, solve_reactions(linkage.analyze(mech, phi, omega=omega))


# -- the main pairs -------------------------------------------------------------------------------


@pytest.mark.parametrize("name, expected", [
    ("four_bar", ["O", "A", "C"]),                 # crank bearing, crank pin, rocker bearing
    ("flying_shears", ["O", "A", "C"]),
    ("slider_crank", ["O", "A", "slide"]),         # crank bearing, crank pin, slider's guide
    ("course_slider_crank", ["O", "A", "slide"]),
    ("slider_crank_vertical", ["O", "A", "slide"]),
    ("six_bar", ["O", "A", "C", "slide"]),
    ("scotch_yoke", ["O", "A", "rail"]),
    ("slotted_link", ["O1", "A", "O3"]),
    ("slotted_link_two_dyad", ["O1", "A", "O3", "ram"]),
])
def test_main_pairs_are_the_input_links_and_the_frames(name, expected):
    mech = linkage.load(name)
    assert main_pairs(mech) == expected
    (crank,) = mech.inputs
    for pair in expected:                         # each joins the frame or the input link
        assert set(mech.pairs[pair].links) & {mech.frame, crank}


def test_every_shipped_schemes_main_pairs_hold_its_frame_and_input_pairs():
    for name in linkage.shipped_schemes():
        mech = linkage.load(name)
        pairs = main_pairs(mech)
        # an input named by a pair (a cylinder) stands for the links it joins
        inputs = set().union(*(set(mech.pairs[n].links) - {mech.frame} if n in mech.pairs else {n}
                               for n in mech.inputs))
        want = {k for k, p in mech.pairs.items() if mech.frame in p.links or set(p.links) & inputs}
        assert set(pairs) == want and len(pairs) == len(want), name
        assert mech.frame in mech.pairs[pairs[0]].links and set(mech.pairs[pairs[0]].links) & inputs


# -- the plotted points are the reactions ---------------------------------------------------------


@pytest.mark.parametrize("name, omega", [("four_bar", 10.0), ("slotted_link_two_dyad", -5.0), ("six_bar", 8.0)])
def test_plotted_vectors_are_the_reactions_solved_again(name, omega):
    mech, phi, reactions = _table_reactions(name, omega)
    fig = plot_hodographs(reactions)
    again = solve_reactions(linkage.analyze(mech, phi, omega=omega))          # a second, separate solution
    panels = _panels(fig)
    assert [ax.get_title(loc="left").replace("\n", " ") for ax in panels] == [pair_words(mech, p) for p in
                                                                               main_pairs(mech)]
    for ax, pair in zip(panels, main_pairs(mech)):
        a, b = mech.pairs[pair].links
        plotted = _line(ax, f"positions:{pair}").get_xydata()
        assert plotted == pytest.approx(again.on(a, b), rel=1e-12, abs=1e-9)
        columns = again.columns(full=True)                                    # the forces table's numbers
        assert plotted[:, 0] == pytest.approx(columns[f"{pair}.Rx"], rel=1e-12, abs=1e-9)
        assert plotted[:, 1] == pytest.approx(columns[f"{pair}.Ry"], rel=1e-12, abs=1e-9)
        title = ax.get_title(loc="left").replace("\n", " ")
        assert title == f"pair {pair}: force of {linkage.report.plots.link_role(mech, b)} {b} on " \
                        f"{linkage.report.plots.link_role(mech, a)} {a}"
        vectors = next(c for c in ax.collections if c.get_gid() == f"vectors:{pair}")
        for seg, tip in zip(vectors.get_segments(), plotted):                # each vector from the origin
            assert seg[0] == pytest.approx([0.0, 0.0]) and seg[1] == pytest.approx(tip)


def test_crank_bearing_of_a_massless_slider_crank_by_statics():
    """Crank r = 0.1, rod l = 0.35, slider on the x axis through O, no masses, F = (-1000, 0) N on
    the slider. The rod is a two-force member along e = (B - A)/l; the slider's balance along x gives
    the rod's force S = 1000 / e_x on it, so the crank presses on its bearing with -S e, the rod on the
    crank with -S e, and the slider on its guide with (0, S e_y)."""
    tail = """
[loads]
gravity = [0.0, 0.0]
[[loads.forces]]
point = "B"
link = "3"
force = [-1000.0, 0.0]
"""
    mech = linkage.loads(slider_crank_toml(0.1, 0.35, tail=tail))
    phi = np.radians(np.arange(10.0, 360.0, 25.0))                          # no dead centre
    reactions = solve_reactions(linkage.analyze(mech, phi, omega=-12.0))
    r, l = 0.1, 0.35
    a = r * np.column_stack([np.cos(phi), np.sin(phi)])
    b = np.column_stack([a[:, 0] + np.sqrt(l**2 - a[:, 1] ** 2), np.zeros_like(phi)])
    e = (b - a) / l
    s = 1000.0 / e[:, 0]
    fig = plot_hodographs(reactions)
    panels = dict(zip(main_pairs(mech), _panels(fig)))
    assert list(panels) == ["O", "A", "slide"]
    assert _line(panels["O"], "positions:O").get_xydata() == pytest.approx(-s[:, None] * e, rel=1e-10)
    assert _line(panels["A"], "positions:A").get_xydata() == pytest.approx(-s[:, None] * e, rel=1e-10)
    slide = _line(panels["slide"], "positions:slide").get_xydata()
    assert slide[:, 0] == pytest.approx(0.0, abs=1e-9)
    assert slide[:, 1] == pytest.approx(s * e[:, 1], rel=1e-10)
    assert panels["O"].get_title(loc="left").replace("\n", " ") == "pair O: force of crank 1 on frame 0"


def test_fine_reactions_draw_the_curve_through_the_table_positions():
    mech, phi, reactions = _table_reactions("four_bar", 10.0)
    fine_phi = np.linspace(phi[0], phi[-1], 241)
    fine = solve_reactions(linkage.analyze(mech, fine_phi, omega=10.0))
    fig = plot_hodographs(reactions, ["C"], fine=fine)
    (ax,) = _panels(fig)
    curve = _line(ax, "hodograph:C").get_xydata()
    assert curve == pytest.approx(fine.on("3", "0"), rel=1e-12, abs=1e-9)
    assert curve[::20] == pytest.approx(_line(ax, "positions:C").get_xydata(), rel=1e-9, abs=1e-9)


# -- the picture ----------------------------------------------------------------------------------


def _overlap(a, b, slack=0.5):
    return (min(a.x1, b.x1) - max(a.x0, b.x0) > slack) and (min(a.y1, b.y1) - max(a.y0, b.y0) > slack)


@pytest.mark.parametrize("name, omega", [("four_bar", 10.0), ("slider_crank", -10.472),
                                         ("slotted_link_two_dyad", 5.0)])
def test_panels_have_equal_scales_numbered_positions_and_no_text_on_text(name, omega):
    mech, phi, reactions = _table_reactions(name, omega)
    fig = plot_hodographs(reactions)
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    texts = []
    for ax, pair in zip(_panels(fig), main_pairs(mech)):
        to_px = ax.transData.transform
        (x0, y0), (x1, y1) = to_px([[0.0, 0.0], [1.0, 1.0]])
        assert (x1 - x0) == pytest.approx(y1 - y0, rel=1e-9)              # one newton is as long on both axes
        assert ax.get_xlabel() == "x component $R_x$, N" and ax.get_ylabel() == "y component $R_y$, N"
        lo_x, hi_x = ax.get_xlim()
        lo_y, hi_y = ax.get_ylim()
        assert lo_x < 0 < hi_x and lo_y < 0 < hi_y                          # the common origin is shown
        plotted = _line(ax, f"positions:{pair}").get_xydata()
        assert np.all((plotted[:, 0] > lo_x) & (plotted[:, 0] < hi_x) & (plotted[:, 1] > lo_y) & (plotted[:, 1] < hi_y))
        labels = _labels(ax)
        numbers = sorted(int(n) for t in labels for n in t.get_text().split(", "))
        assert numbers == list(range(1, len(phi)))                          # every position numbered once:
        assert "1" in [t.get_text() for t in labels]                        # a turn closes, row 13 is 1 again
        frame = ax.get_window_extent(renderer)
        for t in labels:
            box = t.get_window_extent(renderer)
            assert frame.x0 <= box.x0 and box.x1 <= frame.x1 and frame.y0 <= box.y0 and box.y1 <= frame.y1
            number = int(t.get_text().split(", ")[0])                     # next to its own circle
            tip = to_px(plotted[number - 1])
            centre = np.array([(box.x0 + box.x1) / 2, (box.y0 + box.y1) / 2])
            assert np.hypot(*(centre - tip)) < 40 * fig.dpi / 72
        texts += [(t.get_text(), t.get_window_extent(renderer)) for t in labels]
        ticks = [t for axis in (ax.xaxis, ax.yaxis) for v, t in zip(axis.get_ticklocs(), axis.get_ticklabels())
                 if min(axis.get_view_interval()) <= v <= max(axis.get_view_interval())]
        for t in [ax._left_title, ax.xaxis.label, ax.yaxis.label] + ticks:
            if t.get_text() and t.get_visible():
                texts.append((t.get_text(), t.get_window_extent(renderer)))
    texts.append((fig._suptitle.get_text(), fig._suptitle.get_window_extent(renderer)))
    for k, (ta, a) in enumerate(texts):
        assert fig.bbox.x0 <= a.x0 and a.x1 <= fig.bbox.x1 and fig.bbox.y0 <= a.y0 and a.y1 <= fig.bbox.y1, ta
        for tb, b in texts[:k]:
            assert not _overlap(a, b), (ta, tb)
    assert f"at ω = {omega:.5g} rad/s".replace("-", "−") in fig._suptitle.get_text()


def test_a_pair_without_reaction_gets_a_note():
    mech = linkage.loads(four_bar_toml(0.1, 0.3, 0.25, 0.3))               # no masses, no loads
    reactions = solve_reactions(linkage.analyze(mech, linkage.table_angles(mech, 12, 0.0), omega=10.0))
    assert np.all(reactions.force("O") == 0.0)
    fig = plot_hodographs(reactions)
    for ax, pair in zip(_panels(fig), ["O", "A", "C"]):
        note = next(t for t in ax.texts if t.get_gid() == f"missing:{pair}")
        assert f"no reaction in pair {pair}" in note.get_text() and "R = 0 at every position" in note.get_text()
        assert not ax.lines and not ax.get_xticks().size


def test_odd_number_of_panels_leaves_a_key_in_the_empty_cell():
    _, _, reactions = _table_reactions("four_bar", 10.0)
    fig = plot_hodographs(reactions)
    keys = [t for ax in fig.axes for t in ax.texts if t.get_gid() == "key"]
    assert len(keys) == 1 and "the force of link b on link a" in keys[0].get_text().replace("\n     ", " ")
    fig = plot_hodographs(reactions, ["O", "C"])
    assert not [t for ax in fig.axes for t in ax.texts if t.get_gid() == "key"]


def test_refuses_unknown_pairs():
    _, _, reactions = _table_reactions("four_bar", 10.0)
    with pytest.raises(InputError, match=re.escape("no reaction of pair 'Z'")):
        plot_hodographs(reactions, ["O", "Z"])
    with pytest.raises(InputError, match="at least one pair"):
        plot_hodographs(reactions, [])
    with pytest.raises(InputError, match="list of pair names"):
        plot_hodographs(reactions, "O")


def test_without_matplotlib_hodographs_say_what_to_install(monkeypatch):
    _, _, reactions = _table_reactions("four_bar", 10.0)
    for module in [m for m in list(sys.modules) if m == "matplotlib" or m.startswith("matplotlib.")]:
        monkeypatch.setitem(sys.modules, module, None)
    with pytest.raises(PlotExtraMissing, match=re.escape('pip install "linkage[plot]"')) as info:
        plot_hodographs(reactions)
    assert isinstance(info.value, LinkageError)
    assert main_pairs(reactions.motion.mechanism) == ["O", "A", "C"]      # naming needs no matplotlib
