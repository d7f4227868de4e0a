"""Report pictures (issue 22, item 3): the cylinder drawn joined, titles inside their figures,
hodograph numbers that do not overlap, captions true to the case, one plan scale per position."""

import matplotlib

matplotlib.use("Agg")

import numpy as np
import pytest

import linkage
from linkage.kinetostatics.plans import build_plans
from linkage.report.drawing import Geometry, draw_mechanism
from linkage.report.hodographs import plot_hodographs
from linkage.report.plan_drawings import TARGET_MM, drawing_scales, draw_plan
from linkage.report.results import forces_results
from linkage.report.words import plain, position_caption, speed_words


def _table(name):
    mech = linkage.load(name)
    return linkage.analyze(mech, linkage.table_angles(mech, 12))


def test_cylinder_barrel_and_rod_stay_joined_over_the_stroke():
    """At every table position the rod's inner end (its piston) lies inside the barrel rectangle,
    the rod's outer end is the pair's point B, and the barrel's axis passes through the pivot C."""
    motion = _table("cylinder_boom")
    geometry = Geometry(motion, range(len(motion.phi)))
    for i in range(len(motion.phi)):
        sc = geometry.scene(i)
        (barrel, rod, tube, line, _), = sc.cylinders
        assert (barrel, rod) == ("2", "3")
        axis = (tube[1] - tube[0]) / np.hypot(*(tube[1] - tube[0]))
        across = tube[3] - tube[0]
        along = (line[0] - tube[0]) @ axis
        assert 0.0 < along < np.hypot(*(tube[1] - tube[0]))                # piston inside the barrel's length
        assert abs((line[0] - tube[0]) @ across / (across @ across) - 0.5) < 1e-9   # on its axis
        assert np.allclose(line[1], sc.points["B"])
        c = sc.points["C"]
        normal = np.array([-axis[1], axis[0]])
        assert abs((c - (tube[0] + tube[3]) / 2) @ normal) < 1e-9          # the barrel's axis through C
        assert not sc.slots and not sc.blocks


def _inside(fig):
    fig.canvas.draw()
    box = fig.bbox
    renderer = fig.canvas.get_renderer()
    texts = list(fig.texts) + [t for ax in fig.axes for t in (ax.title, ax._left_title, *ax.texts)]
    texts = [t for t in texts if t.get_text() and t.get_visible()]
    for t in texts:
        e = t.get_window_extent(renderer)
        assert box.x0 - 1 <= e.x0 and e.x1 <= box.x1 + 1 and box.y0 - 1 <= e.y0 and e.y1 <= box.y1 + 1, t.get_text()


@pytest.mark.parametrize("name", ["six_bar", "slotted_link", "cylinder_boom", "flying_shears"])
def test_hodographs_titles_inside_and_numbers_apart(name):
    fig = plot_hodographs(forces_results(linkage.load(name)).reactions)
    _inside(fig)
    renderer = fig.canvas.get_renderer()
    for ax in fig.axes:
        boxes = [t.get_window_extent(renderer) for t in ax.texts if (t.get_gid() or "").startswith("label:")]
        for k, a in enumerate(boxes):
            for b in boxes[k + 1:]:
                overlap = min(a.x1, b.x1) - max(a.x0, b.x0), min(a.y1, b.y1) - max(a.y0, b.y0)
                assert overlap[0] <= 0.5 or overlap[1] <= 0.5
    matplotlib.pyplot.close(fig)


def test_captions_true_to_the_case():
    assert plain(-0.04, ".1f") == "0.0" and plain(-0.06, ".1f") == "-0.1"
    crank = _table("four_bar")
    assert position_caption(crank, 0).startswith("Position 1 of 12:")
    assert position_caption(crank, 12).startswith("Position 1 of 12, a turn later")
    assert all("-0.0" not in position_caption(crank, i) for i in range(13))
    slide = _table("cylinder_boom")
    text = position_caption(slide, 4)
    assert text.startswith("Position 5 of 13") and " m" in text and "°" not in text
    fig = plot_hodographs(forces_results(linkage.load("cylinder_boom")).reactions)
    header = fig.texts[0].get_text().replace("\n", " ")
    assert "over 0.7 m of the cylinder's slide" in header and "°" not in header
    assert "static" in header
    matplotlib.pyplot.close(fig)
    assert speed_words(slide).startswith("no speed given")


def test_one_plan_scale_per_position_and_the_longest_vector_60_to_120_mm():
    mech = linkage.load("course_slider_crank")
    results = forces_results(mech)
    plans = build_plans(results.motion, results.reactions)
    scales = drawing_scales(plans, 2)
    for quantity in ("velocity", "acceleration"):
        plan = getattr(plans, quantity)
        longest = max(float(np.hypot(*v.vector[2])) for v in plan.vectors) / scales[quantity]
        largest_image = max(float(np.hypot(*img[2])) for img in plan.images.values()) / scales[quantity]
        assert TARGET_MM / 2 < max(longest, largest_image) <= TARGET_MM
        fig = draw_plan(plans, 2, quantity)
        title = next(t.get_text() for t in fig.texts if "/mm" in t.get_text())
        assert f"= {scales[quantity]:g} " in title
        matplotlib.pyplot.close(fig)


def test_drawing_caption_has_no_minus_zero():
    ax = draw_mechanism(_table("course_slider_crank"), 12)
    assert "-0.0" not in ax.get_title("left") and "of 12" in ax.get_title("left")
    matplotlib.pyplot.close(ax.figure)
