"""The kinetostatics sheet (linkage/course/project/kinetostatics_sheet.py): its polygons to scale,
the split of the outer reactions, the balancing moment check and its layout."""

from __future__ import annotations

import math

import numpy as np
import pytest

import linkage
from linkage.course.project.frame import layout_problems
from linkage.course.project.kinetostatics_sheet import compose_kinetostatics, kinetostatics_sheet
from linkage.course.project.model import Arrow, Line, Text
from linkage.errors import LinkageError
from linkage.kinetostatics.plans import build_plans
from linkage.kinetostatics.reactions import solve_reactions

#: (scheme, position, omega rad/s or None for the scheme's own speed, the outer reactions split into Rⁿ and Rτ:
#: one per outer revolute pair of a dyad whose links meet in a revolute pair)
CASES = [("course_slider_crank", 12, None, 1), ("four_bar", 4, 10.0, 2), ("six_bar", 3, 10.0, 3),
         ("six_bar_class3", 5, -8.0, 0), ("slotted_link", 7, 5.0, 0)]


@pytest.fixture(scope="module", params=CASES, ids=[c[0] for c in CASES])
def sheet(request):
    name, position, omega, splits = request.param
    sheet = compose_kinetostatics(linkage.load(name), position, omega=omega)
    sheet.expected_splits = splits
    return sheet


def _at_position(sheet):
    """The scheme analysed afresh at the sheet's one position: (motion, reactions, plans)."""
    motion = sheet.plans.motion
    i = sheet.index
    again = linkage.analyze(motion.mechanism, motion.phi[i:i + 1], order=2, omega=float(motion.omega[i]),
                            eps=float(motion.eps[i]))
    reactions = solve_reactions(again)
    return again, reactions, build_plans(again, reactions)


def test_polygon_vectors_to_scale(sheet):
    """Every drawn polygon vector is in the drawing, and its length times μ_F is the value of
    build_plans (run again here at the one position) to 0.5 %."""
    _check_vectors_to_scale(sheet)


def _check_vectors_to_scale(sheet):
    mu_f = sheet.drawing.scales["μ_F"].value
    assert mu_f == sheet.mu_f
    _, _, plans = _at_position(sheet)
    values = {}
    for p in plans.polygons:
        for f in (*p.forces, *p.internal):
            values[(p.step, f.label)] = float(np.hypot(*f.vector[0]))
    checked = 0
    ids = {id(item) for item in sheet.drawing.items}
    for v in sheet.vectors:
        assert v.items and all(id(item) in ids for item in v.items)
        shaft = v.items[0]
        ends = (shaft.start, shaft.end) if isinstance(shaft, Arrow) else (shaft.points[0], shaft.points[-1])
        assert np.allclose(ends, (v.start, v.end), atol=1e-9)
        if v.kind in ("force", "internal", "resultant"):
            expected = values[(v.step, v.label)]
            if expected > 1e-9:
                assert v.length * mu_f == pytest.approx(expected, rel=5e-3)
                checked += 1
    assert checked >= sum(len(p.forces) for p in plans.polygons) - 6
    # one μ_F: the largest polygon's longest vector is 100..200 mm unless a polygon had to fit its place
    longest = max(values.values()) / mu_f
    assert longest <= 200.0 + 1e-9
    assert longest >= 100.0 or any("fit" in n for n in sheet.notes)


def test_split_reactions(sheet):
    """Rⁿ + Rτ is solve_reactions' reaction (1e-9 relative); Rτ is across and Rⁿ along the link;
    the link's moments about its inner pair, computed here from the loads and the pairs' reactions,
    vanish with Rτ (Rⁿ passes through the inner pair)."""
    mech = sheet.plans.motion.mechanism
    motion, reactions, _ = _at_position(sheet)
    splits = sheet.splits
    assert len(splits) == sheet.expected_splits
    for s in splits:
        pair = mech.pairs[s.pair]
        force = reactions.force(s.pair)[0]
        on_link = force if pair.links[0] == s.link else -force
        scale = max(float(np.hypot(*on_link)), 1e-300)
        assert np.allclose(s.normal + s.tangential, on_link, rtol=0, atol=1e-9 * scale)
        bc = s.inner_point - s.point
        assert abs(float(bc[0] * s.normal[1] - bc[1] * s.normal[0])) <= 1e-9 * scale * np.hypot(*bc)
        assert abs(float(s.tangential @ bc)) <= 1e-9 * scale * np.hypot(*bc)

        def at(link, local):
            return motion.poses[link][0, :2] + motion.arm(link, np.asarray(local, float))[0]

        c = s.inner_point
        moment = 0.0
        for t in reactions.terms:                          # the loads on the link
            if t.link == s.link:
                r = at(t.link, t.local) - c
                moment += r[0] * t.force[0, 1] - r[1] * t.force[0, 0] + t.moment[0]
        for name, p in mech.pairs.items():                 # the other pairs' reactions on the link
            if s.link not in p.links or name in (s.pair, s.inner_pair):
                continue
            f = reactions.force(name)[0]
            f = f if p.links[0] == s.link else -f
            owner = s.link if p.point in mech.links[s.link].points else p.links[1]
            r = at(owner, mech.links[owner].points[p.point]) - c
            moment += r[0] * f[1] - r[1] * f[0]
            if isinstance(p, linkage.model.mechanism.Prismatic):
                moment += float(reactions.moment(name)[0]) * (1.0 if p.links[0] == s.link else -1.0)
        r = s.point - c
        total = moment + r[0] * s.tangential[1] - r[1] * s.tangential[0]
        assert abs(total) <= 1e-9 * max(scale * np.hypot(*r), abs(moment), 1e-300)


def test_balancing_moment_table(sheet):
    """M_b by the polygons and by the lever agree (0.5 %) and equal solve_reactions' M_b; the
    table on the sheet shows both."""
    _, reactions, _ = _at_position(sheet)
    expected = float(reactions.balancing_moment[0])
    assert sheet.mb_polygons == pytest.approx(expected, rel=5e-3, abs=1e-9)
    assert sheet.mb_lever == pytest.approx(sheet.mb_polygons, rel=5e-3, abs=1e-9)
    texts = [t.text for t in sheet.drawing.items if hasattr(t, "text")]
    assert "by the force polygons" in texts and "by Zhukovsky's lever" in texts
    shown = f"{sheet.mb_polygons:.4g}".replace("-", "−")
    assert texts.count(shown) >= 2


def test_layout(sheet):
    assert layout_problems(sheet.drawing) == []
    assert set(sheet.drawing.scales) == {"μ_l", "μ_F", "μ_v"}
    assert any(isinstance(item, Line) and item.layer == "forces" and not item.closed
               and len(item.points) > 10 for item in sheet.drawing.items), "a moment drawn as a curved arrow"


def test_sheet_filled(sheet):
    """The drawing fills the sheet: the union of its primitives' bounds (the frame and the title
    block aside) covers at least 70 % of the frame's inner width and height, and every force
    polygon is at least 40 mm across (its two farthest vertices)."""
    drawing = sheet.drawing
    x0, y0, x1, y1 = next(r.box for r in drawing.regions if r.name == "frame")
    b0, b1, b2, b3 = next(r.box for r in drawing.regions if r.name == "title block")
    boxes = np.array([box for box in (drawing.bounds(item) for item in drawing.items if item.layer != "frame")
                      if not (box[0] >= b0 - 1e-6 and box[1] >= b1 - 1e-6 and box[2] <= b2 + 1e-6
                              and box[3] <= b3 + 1e-6)])
    covered = (boxes[:, 2].max() - boxes[:, 0].min(), boxes[:, 3].max() - boxes[:, 1].min())
    assert covered[0] >= 0.7 * (x1 - x0) and covered[1] >= 0.7 * (y1 - y0)
    for step in {v.step for v in sheet.vectors}:
        ends = np.array([p for v in sheet.vectors if v.step == step for p in (v.start, v.end)])
        assert np.hypot(*(ends[:, None, :] - ends[None, :, :]).transpose(2, 0, 1)).max() >= 40.0, step


def test_group_drawn_at_mu_l(sheet):
    """A pair drawn on a group sits at the analysed position / μ_l from the group's other pairs."""
    # the input link's two pins (frame pivot and crank pin) are |OA| / μ_l apart on paper
    mech = sheet.plans.motion.mechanism
    crank = sheet.plans.motion.structure.inputs[0]
    pins = [p for p in mech.pairs.values() if crank in p.links and isinstance(p, linkage.model.mechanism.Revolute)]
    pts = [np.asarray(mech.links[crank].points[p.point]) for p in pins[:2]]
    length_mm = float(np.hypot(*(pts[1] - pts[0]))) / sheet.mu_l
    circles = [c.centre for c in sheet.drawing.items if type(c).__name__ == "Circle" and c.layer == "links"]
    gaps = [math.dist(a, b) for k, a in enumerate(circles) for b in circles[k + 1:]]
    assert min(abs(g - length_mm) for g in gaps) < 0.01


def test_refusals():
    with pytest.raises(LinkageError, match=r"mean_speed"):
        kinetostatics_sheet(linkage.load("six_bar"), 3)
    with pytest.raises(LinkageError, match=r"slide"):
        kinetostatics_sheet(linkage.load("piston_driven_crank"), 3, omega=0.1)
    bare = linkage.load("four_bar").with_extra(loads=None)
    with pytest.raises(LinkageError, match=r"\[loads\]"):
        kinetostatics_sheet(bare, 3, omega=10.0)
    with pytest.raises(LinkageError, match=r"position 40"):
        kinetostatics_sheet(linkage.load("course_slider_crank"), 40)


#: (scheme, position, omega) drawn on the smaller papers
SMALL = [("course_slider_crank", 12, None), ("six_bar", 3, 10.0)]


@pytest.fixture(scope="module", params=[(c, paper) for c in SMALL for paper in ("A2", "A3")],
                ids=[f"{c[0]}-{paper}" for c in SMALL for paper in ("A2", "A3")])
def small_sheet(request):
    (name, position, omega), paper = request.param
    return compose_kinetostatics(linkage.load(name), position, paper, omega=omega)


def test_small_paper_layout(small_sheet):
    """On A2 and A3 nothing leaves the frame or covers the title block or another text; every
    element of the A1 sheet is there; the texts are 3.5 mm (headings) and 2.5 mm (the rest)."""
    drawing = small_sheet.drawing
    assert layout_problems(drawing) == []
    assert set(drawing.scales) == {"μ_l", "μ_F", "μ_v"}
    regions = {r.name for r in drawing.regions}
    steps = {p.step for p in small_sheet.plans.polygons}
    assert {"lever", "lever table", "balancing moment", "scales"} <= regions
    assert {f"polygon {s}" for s in steps} | {f"group {s}" for s in steps} | {f"table {s}" for s in steps} <= regions
    heights = {t.height for t in drawing.items if isinstance(t, Text) and t.layer != "frame"}
    assert heights <= {3.5, 2.5} and 3.5 in heights
    texts = "\n".join(t.text for t in drawing.items if isinstance(t, Text))
    assert texts.startswith("Kinetostatic analysis of") or "Kinetostatic analysis of" in texts
    assert "Notes:" in texts and "Mb = −ΣM/ω₁" in texts


def test_small_paper_vectors_to_scale(small_sheet):
    """The polygons stay to scale on the smaller papers (A3 above all, where μ_F is coarsest)."""
    _check_vectors_to_scale(small_sheet)
