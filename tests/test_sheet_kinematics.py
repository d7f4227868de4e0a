"""The kinematics sheet (linkage.course.project.kinematics_sheet), checked on its drawing model:
the positions drawn at μ_l are the analysed ones, the plans' vectors times their scales are those
of `linkage plans`, and the layout has nothing a teacher would reject."""

from __future__ import annotations

import json

import numpy as np
import pytest

import linkage
from linkage.course.project.frame import extent, layout_problems
from linkage.course.project.kinematics_sheet import kinematics_sheet
from linkage.course.project.model import Arrow, Circle, Line, Text
from linkage.errors import InputError
from linkage.model.mechanism import Revolute

SCHEMES = ("course_slider_crank", "four_bar", "six_bar", "six_bar_class3", "slotted_link_two_dyad", "cylinder_boom")
CRANKS = ("course_slider_crank", "six_bar_class3", "slotted_link_two_dyad")
POSITION = 3


@pytest.fixture(scope="module")
def sheets():
    return {name: kinematics_sheet(linkage.load(name), POSITION) for name in SCHEMES}


def _inside(xy, box, pad=0.0):
    return box[0] - pad <= xy[0] <= box[2] + pad and box[1] - pad <= xy[1] <= box[3] + pad


def _region(drawing, name):
    return next(r.box for r in drawing.regions if r.name == name)


@pytest.mark.parametrize("name", SCHEMES)
def test_layout_has_no_problems(sheets, name):
    drawing = sheets[name]
    assert layout_problems(drawing) == []
    assert str(drawing.scales["μ_l"]).endswith(" m/mm")
    # every scale stated on the sheet is in its scales table
    texts = {t.text for t in drawing.items if isinstance(t, Text)}
    assert all(str(s) in texts for s in drawing.scales.values())


@pytest.mark.parametrize("name", ("course_slider_crank", "six_bar_class3", "cylinder_boom"))
def test_drawn_positions_are_the_analysed_ones(sheets, name):
    """Every revolute pair of every table position is a circle of the mechanism's part, at the
    analysed point / μ_l (one translation for all), to 0.01 mm."""
    drawing, mech = sheets[name], linkage.load(name)
    mu = drawing.scales["μ_l"].value
    # the table positions as `linkage analyze` prints them (its JSON)
    doc = json.loads(linkage.report.results.kinematics_results(mech).json())
    rows = doc["rows"]
    full_turn = mech.coordinate.is_angle and mech.input_range is None
    rows = rows[:-1] if full_turn else rows
    assert len(rows) == (12 if full_turn else 13)      # a stroke's 12 steps have 13 positions
    box = _region(drawing, "mechanism")
    centres = np.array([c.centre for c in drawing.items if isinstance(c, Circle) and _inside(c.centre, box)])
    pins = [p.point for p in mech.pairs.values() if isinstance(p, Revolute)]
    expected = np.array([[row[f"{q}.x"], row[f"{q}.y"]] for row in rows for q in pins]) / mu
    found = None
    for c in centres:                   # the translation that puts the first expected point on a circle
        t = c - expected[0]
        gaps = np.min(np.hypot(*(expected[:, None, :] + t - centres[None, :, :]).transpose(2, 0, 1)), axis=1)
        if np.all(gaps < 0.01):
            found = gaps
            break
    assert found is not None, "no translation puts every analysed joint on a drawn circle to 0.01 mm"


def _vectors(drawing, region):
    box = _region(drawing, region)
    arrows = [np.subtract(a.end, a.start) for a in drawing.items if isinstance(a, Arrow) and _inside(a.start, box)]
    dashed = [np.subtract(ln.points[1], ln.points[0]) for ln in drawing.items
              if isinstance(ln, Line) and ln.dashed and len(ln.points) == 2 and ln.layer == "plans"
              and _inside(ln.points[0], box)]
    return np.array(arrows), np.array(dashed) if dashed else np.zeros((0, 2))


@pytest.mark.parametrize("name", CRANKS)
def test_plan_vectors_times_scale_are_those_of_linkage_plans(sheets, linkage_run, name):
    run = linkage_run("plans", name, "--position", str(POSITION))
    assert run.status == 0, run.err
    doc = json.loads(run.out)
    drawing = sheets[name]
    for quantity, symbol in (("velocity", "μ_v"), ("acceleration", "μ_a")):
        mu = drawing.scales[symbol].value
        arrows, dashed = _vectors(drawing, f"{quantity} plan")
        longest = 0.0
        for v in doc[f"{quantity}_plan"]:
            if v["role"] == "similarity" or v["magnitude"] / mu < 0.3:
                continue
            target = np.array(v["vector"])
            pool = dashed if (v["kind"] == "relative" and quantity == "acceleration") else arrows
            error = np.min(np.hypot(*(pool * mu - target).T)) / v["magnitude"]
            assert error < 0.005, (quantity, v["from"], v["to"], error)
            longest = max(longest, v["magnitude"] / mu)
        assert 30.0 <= longest <= 120.0        # readable: the longest vector between 30 (small box) and 120 mm
        # one scale per quantity, shared by every file that draws it: the separate plan's own
        assert mu == doc["scales"][quantity], (quantity, mu, doc["scales"][quantity])


@pytest.mark.parametrize("name", SCHEMES)
def test_the_drawing_uses_the_sheet(sheets, name):
    """The parts together span at least 70 % of the frame's inner width and height (the frame and
    title block left out), and the positions drawing spans at least half of its box's smaller side."""
    drawing = sheets[name]
    fx0, fy0, fx1, fy1 = _region(drawing, "frame")
    boxes = np.array([extent(drawing, item) for item in drawing.items if item.layer != "frame"])
    assert np.max(boxes[:, 2]) - np.min(boxes[:, 0]) >= 0.7 * (fx1 - fx0)
    assert np.max(boxes[:, 3]) - np.min(boxes[:, 1]) >= 0.7 * (fy1 - fy0)
    mx0, my0, mx1, my1 = _region(drawing, "mechanism")
    drawn = np.array([drawing.bounds(item) for item in drawing.items if item.layer in ("links", "positions")
                      and _inside(drawing.bounds(item)[:2], (mx0, my0, mx1, my1))])
    size = max(np.max(drawn[:, 2]) - np.min(drawn[:, 0]), np.max(drawn[:, 3]) - np.min(drawn[:, 1]))
    assert size >= 0.5 * min(mx1 - mx0, my1 - my0)


def test_a_slide_input_gets_the_sheet_without_plans_and_says_why(sheets):
    drawing = sheets["cylinder_boom"]
    names = {r.name for r in drawing.regions}
    assert "plans" in names and "velocity plan" not in names and "comparison" not in names
    assert "μ_v" not in drawing.scales and "μ_a" not in drawing.scales
    words = " ".join(t.text for t in drawing.items if isinstance(t, Text))
    assert "driven by a slide" in words


def test_diagram_scales_draw_the_output_stroke():
    """The first diagram's curve spans the output's stroke over the turn at μ_s (independent:
    the stroke of the slider of a central slider-crank, 2 r, to the drawing's 0.1 %)."""
    mech = linkage.load("course_slider_crank")
    drawing = kinematics_sheet(mech, 1, paper="A2")
    assert layout_problems(drawing) == []
    box = _region(drawing, "diagram 1")
    curves = [ln for ln in drawing.items if isinstance(ln, Line) and ln.layer == "diagrams" and len(ln.points) > 20
              and _inside(ln.points[0], box)]
    ys = np.array([p[1] for ln in curves for p in ln.points])
    stroke = np.ptp(ys) * drawing.scales["μ_s"].value
    sweep = linkage.analyze(mech, np.linspace(0, 2 * np.pi, 2001))
    x = sweep.point("B")[:, 0]
    assert stroke == pytest.approx(np.ptp(x), rel=2e-3)


def test_a_position_outside_the_table_is_refused():
    with pytest.raises(InputError, match="table positions 1 to 13"):
        kinematics_sheet(linkage.load("four_bar"), 14)


@pytest.mark.parametrize("paper", ("A2", "A3"))
def test_smaller_papers(paper):
    drawing = kinematics_sheet(linkage.load("six_bar"), POSITION, paper=paper)
    assert drawing.paper == paper
    assert layout_problems(drawing) == []
