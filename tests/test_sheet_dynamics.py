"""The dynamics sheet (linkage/course/project/dynamics_sheet.py) and the flywheel's construction
(flywheel.py): numbers read back from the drawing model against the test's own formulas."""

from __future__ import annotations

import math

import numpy as np
import pytest

import linkage
from linkage.course.project.dynamics_sheet import dynamics_sheet
from linkage.course.project.flywheel import rim_for_inertia, wittenbauer_tangents
from linkage.course.project.frame import TitleInfo, layout_problems
from linkage.course.project.model import Circle, Line, Text
from linkage.course.template import draws, load_template
from linkage.dynamics import course_method
from linkage.dynamics.spec import dynamics_of
from linkage.errors import InputError, LinkageError
from linkage.kinematics.extremes import extreme_positions
from linkage.kinetostatics.loads import loads_of
from linkage.model.scheme import shipped_schemes

SHIPPED_WITH_DYNAMICS = ["course_slider_crank", "flying_shears"]
TEMPLATES = ["press_slider_crank", "press_crank_rocker", "shaper_two_dyad"]


def template_mechanism(name: str):
    template = load_template(name)
    return template.mechanism(next(draws(template, seed=1)), name=name)


def mechanism(name: str):
    return template_mechanism(name) if name in TEMPLATES else linkage.load(name)


@pytest.fixture(scope="module")
def sheets():
    return {name: dynamics_sheet(mechanism(name), title=TitleInfo(scheme=name)) for name in
            SHIPPED_WITH_DYNAMICS + TEMPLATES}


def points_k_l(drawing):
    """The paper points k and l: the dots their labels name (label right-anchored 2 mm left)."""
    found = {}
    for label in (t for t in drawing.items if isinstance(t, Text) and t.text in ("k", "l")):
        dots = [c for c in drawing.items if isinstance(c, Circle) and c.layer == "dimensions"
                and abs(c.centre[1] - label.at[1]) < 1e-9 and abs(c.centre[0] - label.at[0] - 2.0) < 1e-9]
        assert len(dots) == 1, label
        found[label.text] = dots[0].centre
    return found["k"], found["l"]


def own_tangent_inertia(energy, inertia2, wm, delta):
    """(c_max - c_min) / (w_m^2 delta): the support lines of the polygon at slopes w_m^2 (1 +- delta) / 2."""
    c_max = max(e - wm**2 * (1 + delta) / 2 * i for e, i in zip(energy, inertia2))
    c_min = min(e - wm**2 * (1 - delta) / 2 * i for e, i in zip(energy, inertia2))
    return (c_max - c_min) / (wm**2 * delta)


@pytest.mark.parametrize("name", SHIPPED_WITH_DYNAMICS + TEMPLATES)
def test_the_tangents_flywheel_from_the_drawn_kl(sheets, name):
    """kl read off the paper x μ_T / (ω_m² δ) is the test's own tangent construction to the drawing's
    accuracy (0.05 mm of kl), and Mertsalov's I' within the bound max I'' (the tangents take T'' at
    ω_max and ω_min, Mertsalov at ω_m); within 1 % where max I'' is below 1 % of I'."""
    mech = mechanism(name)
    drawing = sheets[name]
    law = course_method(mech)
    spec = dynamics_of(mech)
    wm, delta = abs(spec.mean_speed), spec.delta
    (kx, ky), (lx, ly) = points_k_l(drawing)
    assert kx == pytest.approx(lx, abs=1e-9) and ky > ly
    mu_t = drawing.scales["μ_T"].value
    graphic = mu_t * (ky - ly) / (wm**2 * delta)
    energy = law.details["energy_change"]
    inertia2 = law.reduced.inertia_variable
    own = own_tangent_inertia(energy, inertia2, wm, delta)
    assert graphic == pytest.approx(own, abs=mu_t * 0.05 / (wm**2 * delta))
    mertsalov = law.required_constant_inertia
    assert abs(graphic - mertsalov) <= float(np.max(inertia2)) * (1 + 1e-9)
    if float(np.max(inertia2)) < 0.01 * mertsalov:
        assert graphic == pytest.approx(mertsalov, rel=0.01)


def test_the_tangents_meet_mertsalov_to_one_percent_where_the_variable_inertia_is_small(sheets):
    """press_crank_rocker and shaper_two_dyad (max I'' below 1 % of I'): the drawn construction gives
    Mertsalov's I' to 1 %."""
    for name in ("press_crank_rocker", "shaper_two_dyad"):
        mech = mechanism(name)
        spec = dynamics_of(mech)
        (_, ky), (_, ly) = points_k_l(sheets[name])
        graphic = sheets[name].scales["μ_T"].value * (ky - ly) / (spec.mean_speed**2 * spec.delta)
        assert graphic == pytest.approx(course_method(mech).required_constant_inertia, rel=0.01)


def test_the_drawn_tangents_have_the_course_s_angles(sheets):
    """Each tangent line leaves k (l) at tan ψ = (μ_I / 2μ_T) ω_m² (1 ± δ) on paper."""
    drawing = sheets["course_slider_crank"]
    spec = dynamics_of(linkage.load("course_slider_crank"))
    mu_i, mu_t = drawing.scales["μ_I"].value, drawing.scales["μ_T"].value
    k, l_ = points_k_l(drawing)
    for point, sign in ((k, 1), (l_, -1)):
        lines = [it for it in drawing.items if isinstance(it, Line) and it.layer == "dimensions"
                 and len(it.points) == 2 and it.points[0] == point and it.points[1][0] != point[0]]
        assert len(lines) == 1
        (x0, y0), (x1, y1) = lines[0].points
        expected = mu_i / (2 * mu_t) * spec.mean_speed**2 * (1 + sign * spec.delta)
        assert (y1 - y0) / (x1 - x0) == pytest.approx(expected, rel=1e-9)


def test_the_rim_closed_form():
    """m = ρ π D b h, b = ψ_b D, h = ψ_h D, and m D² / 4 is the inertia it was sized for."""
    for inertia, rho, pb, ph in ((7.0655, 7800.0, 0.2, 0.15), (145.0, 7200.0, 0.1, 0.2), (0.01, 2700.0, 0.3, 0.1)):
        rim = rim_for_inertia(inertia, rho, pb, ph)
        assert rim.width == pytest.approx(pb * rim.diameter, rel=1e-12)
        assert rim.height == pytest.approx(ph * rim.diameter, rel=1e-12)
        assert rim.mass == pytest.approx(rho * math.pi * rim.diameter * rim.width * rim.height, rel=1e-12)
        assert rim.mass * rim.diameter**2 / 4 == pytest.approx(inertia, rel=1e-9)
        assert rim.diameter == pytest.approx((4 * inertia / (math.pi * rho * pb * ph)) ** 0.2, rel=1e-12)
    with pytest.raises(ValueError, match="height_ratio"):
        rim_for_inertia(1.0, height_ratio=1.5)


def test_the_sheet_states_the_rim_of_the_library_s_flywheel(sheets):
    """The rim table's D, b, h, m are those of the flywheel I' - I_0 of `linkage dynamics`."""
    law = course_method(linkage.load("course_slider_crank"))
    texts = [t.text for t in sheets["course_slider_crank"].items if isinstance(t, Text)]
    flywheel = law.required_constant_inertia - law.reduced.inertia_constant
    diameter = (4 * flywheel / (math.pi * 7800 * 0.2 * 0.15)) ** 0.2
    assert f"{diameter:.4f}" in texts and f"{0.2 * diameter:.4f}" in texts and f"{0.15 * diameter:.4f}" in texts


def test_wittenbauer_tangents_by_hand():
    """Three points: the upper tangent touches the top one, the lower one the bottom ones."""
    t = wittenbauer_tangents([0.0, 50.0, 0.0], [1.0, 2.0, 1.0], 10.0, 0.1)
    assert (t.slope_upper, t.slope_lower) == pytest.approx((55.0, 45.0))
    assert t.intercept_upper == pytest.approx(max(-55.0, 50.0 - 110.0))
    assert t.intercept_lower == pytest.approx(min(-45.0, 50.0 - 90.0))
    assert t.constant_inertia == pytest.approx((t.intercept_upper - t.intercept_lower) / 10.0)


def curve_points(drawing, region_name):
    """The filled dots of a region's diagram, paper mm."""
    box = next(r.box for r in drawing.regions if r.name == region_name)
    return np.array([c.centre for c in drawing.items if isinstance(c, Circle) and c.filled and c.layer == "diagrams"
                     and box[0] <= c.centre[0] <= box[2] and box[1] <= c.centre[1] <= box[3]])


def test_the_drawn_curves_are_the_library_s_arrays(sheets):
    """ΔT(ψ), I_red(ψ) and ω(ψ) dots / scales: the course method's arrays, ψ_i = (i-1) 2π/n."""
    drawing = sheets["course_slider_crank"]
    law = course_method(linkage.load("course_slider_crank"))
    n = len(law.phi) - 1
    mu_psi = drawing.scales["μ_ψ"].value
    for region, symbol, values in (("diagram T", "μ_T", law.details["energy_change"]),
                                   ("diagram I", "μ_I", law.reduced.inertia),
                                   ("diagram omega", "μ_ω", np.abs(law.omega))):
        dots = curve_points(drawing, region)
        assert len(dots) == n + 1
        psi = (dots[:, 0] - dots[0, 0]) * mu_psi
        np.testing.assert_allclose(psi, np.arange(n + 1) * 2 * np.pi / n, atol=1e-9)
        rise = (dots[:, 1] - dots[0, 1]) * drawing.scales[symbol].value
        np.testing.assert_allclose(rise, values - values[0], atol=1e-9 * np.max(np.abs(values)))
    witt = curve_points(drawing, "energy-inertia diagram")
    x = (witt[:, 0] - witt[0, 0]) * drawing.scales["μ_I"].value
    np.testing.assert_allclose(x, (law.reduced.inertia_variable - law.reduced.inertia_variable[0])[:-1], atol=1e-9)


def test_the_useful_resistance_diagram_of_a_stroke_diagram(sheets):
    """shaper_two_dyad declares P over the working stroke: its drawn points are the fractions x H
    and the values (H the ram's stroke), at μ_s and μ_P."""
    mech = template_mechanism("shaper_two_dyad")
    force = loads_of(mech).forces[0].force
    ext = extreme_positions(mech, force.quantity)
    drawing = sheets["shaper_two_dyad"]
    dots = curve_points(drawing, "useful resistance")
    s = (dots[:, 0] - dots[:, 0].min()) * drawing.scales["μ_s"].value
    p = (dots[:, 1] - dots[:, 1].min()) * drawing.scales["μ_P"].value
    expected = sorted(zip(np.asarray(force.fractions) * (ext.value_max - ext.value_min), force.values))
    np.testing.assert_allclose(sorted(zip(s, p)), expected, atol=1e-9 * max(force.values))


def test_the_useful_resistance_of_a_cycle_table_rises_towards_the_end_of_the_working_stroke(sheets):
    """The course press resists its slider's motion towards +x (the scheme's comment), most at the
    end of that stroke: the drawn points are s = B.x - min B.x of the positions moving to +x and the
    table's values, so 125 kN stands at s = H, not at the stroke's start."""
    mech = linkage.load("course_slider_crank")
    law = course_method(mech)
    r, rod, offset = 0.0742, 0.2225, 0.01335                  # the scheme's crank, rod and guide's offset
    x = r * np.cos(law.phi) + np.sqrt(rod**2 - (offset - r * np.sin(law.phi)) ** 2)
    values = np.abs(np.array([0, 0, 0, 0, 0, 0, 0, 0, 0, 0, -12321, -27142, -125000], float))
    drawing = sheets["course_slider_crank"]
    dots = curve_points(drawing, "useful resistance")
    s = (dots[:, 0] - dots[:, 0].min()) * drawing.scales["μ_s"].value
    p = (dots[:, 1] - dots[:, 1].min()) * drawing.scales["μ_P"].value
    stroke = x.max() - x.min()
    towards_plus = np.r_[x[1:] - x[:-1], 1.0] > 0          # the positions 7..13 run to +x, 13 ends it
    expected = sorted(zip(x[towards_plus] - x.min(), values[towards_plus]))
    np.testing.assert_allclose(sorted(zip(s, p)), expected, atol=2e-4 * stroke + 1e-9 * 125000)
    assert s[np.argmax(p)] == pytest.approx(stroke, rel=1e-6)


@pytest.mark.parametrize("name", SHIPPED_WITH_DYNAMICS + TEMPLATES)
def test_nothing_overlaps(sheets, name):
    assert layout_problems(sheets[name]) == []


def test_every_other_shipped_scheme_is_refused_naming_the_key():
    """The shipped schemes without [dynamics] (the two above have it) are refused with a message
    naming the section to add."""
    others = sorted(set(shipped_schemes()) - set(SHIPPED_WITH_DYNAMICS))
    assert others
    for name in others:
        with pytest.raises(LinkageError) as refused:
            dynamics_sheet(linkage.load(name))
        assert "[dynamics]" in str(refused.value), (name, refused.value)


def test_no_dynamics_section_is_refused_naming_it():
    with pytest.raises(InputError, match=r"add \[dynamics\]"):
        dynamics_sheet(linkage.load("four_bar"))


@pytest.mark.parametrize("paper", ["A2", "A3"])
@pytest.mark.parametrize("name", SHIPPED_WITH_DYNAMICS)
def test_nothing_overlaps_on_the_smaller_papers(name, paper):
    """A2 and A3: the sheet is laid out in proportion to the paper, nothing overlaps or leaves the frame,
    and no text is below 2.5 mm."""
    drawing = dynamics_sheet(linkage.load(name), paper, TitleInfo(scheme=name))
    assert drawing.paper == paper
    assert layout_problems(drawing) == []
    assert min(t.height for t in drawing.items if isinstance(t, Text)) >= 2.5 - 1e-9


def test_the_tangents_hold_on_a3():
    """On A3 (coarser scales) kl x μ_T / (ω_m² δ) is still the test's own tangent construction."""
    mech = linkage.load("course_slider_crank")
    drawing = dynamics_sheet(mech, "A3")
    law = course_method(mech)
    spec = dynamics_of(mech)
    wm, delta = abs(spec.mean_speed), spec.delta
    (kx, ky), (lx, ly) = points_k_l(drawing)
    assert kx == pytest.approx(lx, abs=1e-9) and ky > ly
    mu_t = drawing.scales["μ_T"].value
    own = own_tangent_inertia(law.details["energy_change"], law.reduced.inertia_variable, wm, delta)
    assert mu_t * (ky - ly) / (wm**2 * delta) == pytest.approx(own, abs=mu_t * 0.05 / (wm**2 * delta))


def test_an_unknown_paper_is_refused():
    with pytest.raises(InputError, match="A4"):
        dynamics_sheet(linkage.load("course_slider_crank"), "A4")
