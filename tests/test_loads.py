"""Loads (docs/methods.md#kinetostatics, #loads): force diagrams over the working stroke, their two values at a
stroke end, the declaration errors of ``[loads]``, notes on missing masses, and gravity off.

Every expected value is computed here: the press's stroke ends from the collinear positions of
crank and rod (x_B = sqrt((l2 +- l1)^2 - e^2)), stroke fractions from the closed-form x_B(phi), the
direction of motion from the textbook analog x_B' times the sign of omega (docs/conventions.md, docs/methods.md#checks).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.optimize import brentq

import linkage
from linkage import SchemeError
from linkage.kinetostatics.loads import LinkMoment, Loads, PointForce, StrokeDiagram, evaluate_loads, loads_of
from linkage.kinetostatics.reactions import solve_reactions
from linkage.model.scheme import from_dict, to_dict

L1, L2, E = 0.0742, 0.2225, 0.01335  # the course press: crank, rod, guide offset (y = +E)
X_MAX = math.sqrt((L1 + L2) ** 2 - E**2)  # crank and rod extended
X_MIN = math.sqrt((L2 - L1) ** 2 - E**2)  # crank and rod folded
STROKE = X_MAX - X_MIN
PHI_MAX = math.atan2(E, X_MAX)  # A on the ray O -> B
PHI_MIN = math.atan2(E, X_MIN) + math.pi  # A opposite to B
W = 10.472

GRID = np.linspace(0.0, 2 * np.pi, 720, endpoint=False) + 0.0071


def x_b(phi):
    phi = np.asarray(phi, float)
    return L1 * np.cos(phi) + np.sqrt(L2**2 - (L1 * np.sin(phi) - E) ** 2)


def x_b_analog(phi):
    """docs/methods.md#checks: x_B' = -l1 sin(phi) - l2 sin(theta2) i21, i21 = -l1 cos(phi)/(l2 cos(theta2))."""
    phi = np.asarray(phi, float)
    th2 = np.arcsin((E - L1 * np.sin(phi)) / L2)
    i21 = -L1 * np.cos(phi) / (L2 * np.cos(th2))
    return -L1 * np.sin(phi) - L2 * np.sin(th2) * i21


def test_independent_stroke_ends():
    """Guards the oracle: the collinear positions are the extremes of the closed-form x_B."""
    assert x_b(PHI_MAX) == pytest.approx(X_MAX, abs=1e-15)
    assert x_b(PHI_MIN) == pytest.approx(X_MIN, abs=1e-15)
    assert abs(x_b_analog(PHI_MAX)) < 1e-15 and abs(x_b_analog(PHI_MIN)) < 1e-15
    assert x_b(GRID).max() < X_MAX and x_b(GRID).min() > X_MIN
    h = 1e-6
    assert np.max(np.abs((x_b(GRID + h) - x_b(GRID - h)) / (2 * h) - x_b_analog(GRID))) < 1e-9
    motion = linkage.analyze(linkage.load("slider_crank"), GRID, order=0)
    assert np.max(np.abs(motion.point("B")[:, 0] - x_b(GRID))) < 1e-15


def press(force=None, moments=None, gravity=(0.0, 0.0)):
    data = to_dict(linkage.load("slider_crank"))
    data["loads"] = {"gravity": list(gravity)}
    if force is not None:
        data["loads"]["forces"] = [force]
    if moments is not None:
        data["loads"]["moments"] = moments
    return from_dict(data)


def diagram_force(diagram):
    return {"point": "B", "link": "3", "diagram": {"along": "x", **diagram}}


def slider_load(mech, phi, omega, ends=None):
    """The x component of the (only) external force, evaluated by the library."""
    motion = linkage.analyze(mech, phi, omega=omega)
    (term,) = [t for t in evaluate_loads(motion, loads_of(mech), ends)
               if t.kind not in ("gravity", "inertia")]
    assert term.link == "3" and np.all(term.force[:, 1] == 0.0)
    return term.force[:, 0]


def expected_slider_load(phi, omega, working, fractions, values, opposes=True, idle=None):
    """Physical meaning of docs/methods.md#loads, computed independently of the library."""
    x, v = x_b(phi), x_b_analog(phi) * omega  # real velocity of B along x
    assert np.all(np.abs(v) > 1e-6), "test positions must avoid the stroke ends"
    t = (x - X_MIN) / STROKE if working > 0 else (X_MAX - x) / STROKE
    on_working = np.sign(v) == working
    mag = np.where(on_working, np.interp(t, fractions, values),
                   0.0 if idle is None else np.interp(1.0 - t, *idle))
    direction = np.sign(v)  # the direction the slider actually moves
    return -direction * mag if opposes else direction * mag


def phi_at_fraction(t, omega, working=1):
    """The input angle on the working stroke where the stroke fraction is t (brentq on x_B)."""
    target = X_MIN + t * STROKE if working > 0 else X_MAX - t * STROKE
    # x increases in time on phi in (PHI_MIN, PHI_MAX + 2 pi) for omega > 0, and on
    # (PHI_MAX, PHI_MIN) for omega < 0 (phi then decreases from PHI_MIN to PHI_MAX)
    rising = (PHI_MIN, PHI_MAX + 2 * np.pi) if omega > 0 else (PHI_MAX, PHI_MIN)
    falling = (PHI_MAX, PHI_MIN) if omega > 0 else (PHI_MIN, PHI_MAX + 2 * np.pi)
    a, b = rising if working > 0 else falling
    return brentq(lambda p: x_b(p) - target, a, b, xtol=1e-15, rtol=1e-15)


# ----------------------------------------------------------------------------------------------
# force diagrams over the working stroke
# ----------------------------------------------------------------------------------------------

OMEGAS = pytest.mark.parametrize("omega", [W, -W], ids=["ccw", "cw"])
STEP = dict(working="+", fractions=[0.0, 0.5, 0.5 + 1e-7, 1.0], values=[0.0, 0.0, 1000.0, 1000.0])


@OMEGAS
def test_step_diagram_switches_at_half_stroke(omega):
    """Zero before t = 0.5, 1000 N after, at positions whose fraction is computed here."""
    mech = press(diagram_force(STEP))
    ts = np.array([0.01, 0.25, 0.49, 0.5 - 1e-5, 0.5 + 1e-5, 0.51, 0.75, 0.99])
    phi = np.array([phi_at_fraction(t, omega) for t in ts])
    np.testing.assert_allclose((x_b(phi) - X_MIN) / STROKE, ts, rtol=0, atol=1e-12)
    got = slider_load(mech, phi, omega)
    expected = np.where(ts < 0.5, 0.0, -1000.0)  # opposes the motion towards +x
    np.testing.assert_array_equal(got, expected)
    # the same slider positions on the idle stroke carry no load
    idle = np.array([phi_at_fraction(t, omega, working=-1) for t in 1.0 - ts])
    np.testing.assert_allclose(x_b(idle), x_b(phi), rtol=0, atol=1e-12)
    np.testing.assert_array_equal(slider_load(mech, idle, omega), 0.0)


@OMEGAS
@pytest.mark.parametrize("working", ["+", "-"])
@pytest.mark.parametrize("opposes", [True, False])
def test_ramp_diagram_over_the_working_stroke(omega, working, opposes):
    """A linear diagram reads the stroke fraction itself: exact stroke ends give 1e-9 agreement."""
    diagram = dict(working=working, fractions=[0.0, 0.3, 1.0], values=[0.0, 300.0, 1000.0])
    if not opposes:
        diagram["opposes"] = False
    got = slider_load(press(diagram_force(diagram)), GRID, omega)
    sgn = 1 if working == "+" else -1
    expected = expected_slider_load(GRID, omega, sgn, diagram["fractions"], diagram["values"], opposes)
    np.testing.assert_allclose(got, expected, rtol=0, atol=1e-9 * 1000.0)
    # the load opposes (or drives) the real motion, and is nonzero on most of the working stroke
    power = got * x_b_analog(GRID) * omega
    assert np.all(power <= 0.0) if opposes else np.all(power >= 0.0)
    assert np.count_nonzero(got) > len(GRID) // 3


@OMEGAS
def test_idle_diagram(omega):
    diagram = dict(working="+", fractions=[0.0, 1.0], values=[500.0, 500.0],
                   idle_fractions=[0.0, 1.0], idle_values=[0.0, 200.0])
    got = slider_load(press(diagram_force(diagram)), GRID, omega)
    expected = expected_slider_load(GRID, omega, 1, [0.0, 1.0], [500.0, 500.0],
                                    idle=([0.0, 1.0], [0.0, 200.0]))
    np.testing.assert_allclose(got, expected, rtol=0, atol=1e-9 * 500.0)


@OMEGAS
def test_two_values_at_the_stroke_ends(omega):
    """At x_max the working stroke (towards +x) ends and the idle stroke starts; at x_min the
    idle stroke ends and the working stroke starts. ``ends`` True picks the stroke that ends."""
    diagram = dict(working="+", fractions=[0.0, 1.0], values=[400.0, 1000.0])
    mech = press(diagram_force(diagram))
    phi = np.array([PHI_MAX, PHI_MAX, PHI_MIN, PHI_MIN])
    got = slider_load(mech, phi, omega, ends=[False, True, False, True])
    # x_max: start of idle (0) / end of working (1000 N against +x);
    # x_min: start of working (400 N against +x) / end of idle (0)
    np.testing.assert_allclose(got, [0.0, -1000.0, -400.0, 0.0], rtol=0, atol=1e-9)
    # without ``ends`` an extreme position opens the stroke it enters
    np.testing.assert_allclose(slider_load(mech, phi[[0, 2]], omega), [0.0, -400.0], rtol=0, atol=1e-9)


@OMEGAS
def test_diagram_in_the_balancing_moment(omega):
    """No gravity, no inertia: M_b omega + F v = 0, i.e. M_b = -F x_B' (virtual work)."""
    diagram = dict(working="+", fractions=[0.0, 0.5, 1.0], values=[100.0, 2500.0, 800.0])
    mech = press(diagram_force(diagram))
    r = solve_reactions(linkage.analyze(mech, GRID, omega=omega), inertia=False)
    force = expected_slider_load(GRID, omega, 1, diagram["fractions"], diagram["values"])
    np.testing.assert_allclose(r.balancing_moment, -force * x_b_analog(GRID), rtol=0,
                               atol=1e-9 * 2500.0 * L1)


# a moment diagram on the four-bar's rocker (quantity 3.theta)
FB_L1, FB_L2, FB_L3, FB_C = 0.1, 0.3, 0.25, np.array([0.3, 0.0])


def rocker(phi):
    """Rocker angle theta3 and its analog (B left of A -> C), from the loop closure."""
    phi = np.asarray(phi, float)
    A = FB_L1 * np.stack([np.cos(phi), np.sin(phi)], axis=1)
    d = FB_C - A
    D = np.hypot(*d.T)
    a = (FB_L2**2 - FB_L3**2 + D**2) / (2 * D)
    h = np.sqrt(FB_L2**2 - a**2)
    e = d / D[:, None]
    B = A + a[:, None] * e + h[:, None] * np.stack([-e[:, 1], e[:, 0]], axis=1)
    th2 = np.arctan2((B - A)[:, 1], (B - A)[:, 0])
    th3 = np.arctan2((B - FB_C)[:, 1], (B - FB_C)[:, 0])
    # l1 e1' + l2 th2' e2' - l3 th3' e3' = 0 with e' = (-sin, cos); dotted with e2:
    th3_1 = FB_L1 * np.sin(phi - th2) / (FB_L3 * np.sin(th3 - th2))
    return th3, th3_1


def rocker_extremes():
    """theta3 where crank and coupler are collinear: |OB| = l2 + l1 (min) and l2 - l1 (max)."""
    out = []
    for R in (FB_L2 + FB_L1, FB_L2 - FB_L1):
        x = (R**2 - FB_L3**2 + FB_C[0] ** 2) / (2 * FB_C[0])
        y = math.sqrt(R**2 - x**2)
        out.append(math.atan2(y, x - FB_C[0]))
    return min(out), max(out)


def test_rocker_oracle():
    th_min, th_max = rocker_extremes()
    th3, d1 = rocker(GRID)
    assert th_min < th3.min() and th3.max() < th_max
    assert th3.max() - th_max > -1e-3 and th3.min() - th_min < 1e-3
    h = 1e-6
    assert np.max(np.abs((rocker(GRID + h)[0] - rocker(GRID - h)[0]) / (2 * h) - d1)) < 1e-8
    motion = linkage.analyze(linkage.load("four_bar"), GRID, order=0)
    assert np.max(np.abs(motion.poses["3"][:, 2] - th3)) < 1e-13


@OMEGAS
def test_moment_diagram_on_the_rocker(omega):
    data = to_dict(linkage.load("four_bar"))
    data["loads"] = {"gravity": [0.0, 0.0], "moments": [
        {"link": "3", "diagram": {"working": "+", "fractions": [0.0, 1.0], "values": [0.0, 50.0]}}]}
    mech = from_dict(data)
    motion = linkage.analyze(mech, GRID, omega=omega)
    (term,) = evaluate_loads(motion, loads_of(mech))
    assert term.link == "3" and np.all(term.force == 0.0)
    th_min, th_max = rocker_extremes()
    th3, d1 = rocker(GRID)
    spin = np.sign(d1 * omega)
    expected = np.where(spin > 0, -50.0 * (th3 - th_min) / (th_max - th_min), 0.0)
    np.testing.assert_allclose(term.moment, expected, rtol=0, atol=1e-9 * 50.0)


# ----------------------------------------------------------------------------------------------
# declaration errors: one SchemeError naming the entry
# ----------------------------------------------------------------------------------------------

BAD_LOADS = {
    "unknown point": ({"forces": [{"point": "Z", "force": [1.0, 0.0]}]}, ["forces[0]", "'Z'"]),
    "moment on unknown link": ({"moments": [{"link": "9", "moment": 1.0}]}, ["moments[0]", "'9'"]),
    "point on several links": ({"forces": [{"point": "B", "force": [1.0, 0.0]}]},
                               ["forces[0]", "'B'", "link"]),
    "link without the point": ({"forces": [{"point": "S2", "link": "3", "force": [1.0, 0.0]}]},
                               ["forces[0]", "'S2'", "'3'"]),
    "fractions decreasing": (
        {"forces": [diagram_force(dict(working="+", fractions=[0, 0.6, 0.4, 1], values=[0, 1, 1, 0]))]},
        ["forces[0]", "fractions", "[0, 0.6, 0.4, 1]"]),
    # a fraction given twice is a jump (a step diagram, tests/test_scheme_format.py); three times,
    # or twice at a stroke end, cannot be meant
    "fraction given three times": (
        {"forces": [diagram_force(dict(working="+", fractions=[0, 0.5, 0.5, 0.5, 1], values=[0, 1, 2, 3, 0]))]},
        ["forces[0]", "fractions", "three times", "[0, 0.5, 0.5, 0.5, 1]"]),
    "stroke end repeated": (
        {"forces": [diagram_force(dict(working="+", fractions=[0, 0.5, 1, 1], values=[0, 1, 2, 0]))]},
        ["forces[0]", "fractions", "stroke end 1", "[0, 0.5, 1, 1]"]),
    "fractions above 1": (
        {"forces": [diagram_force(dict(working="+", fractions=[0, 0.5, 1.5], values=[0, 1, 0]))]},
        ["forces[0]", "fractions", "1.5"]),
    "fractions below 0": (
        {"forces": [diagram_force(dict(working="+", fractions=[-0.2, 0.5, 1], values=[0, 1, 0]))]},
        ["forces[0]", "fractions", "-0.2"]),
    "negative values": (
        {"forces": [diagram_force(dict(working="+", fractions=[0, 1], values=[0, -5]))]},
        ["forces[0]", "values", "-5"]),
    "direction never taken": (
        {"forces": [{"point": "B", "link": "3",
                     "diagram": {"along": "y", "working": "+", "fractions": [0, 1], "values": [0, 5]}}]},
        ["forces[0]", "B.y"]),
    "crank angle has no stroke": (
        {"moments": [{"link": "1", "diagram": {"working": "+", "fractions": [0, 1], "values": [0, 5]}}]},
        ["moments[0]", "1.theta"]),
    "unknown loads key": ({"gravty": [0.0, -9.81]}, ["gravty"]),
    "unknown force key": ({"forces": [{"point": "B", "link": "3", "force": [1.0, 0.0], "magnitude": 3}]},
                          ["forces[0]", "magnitude"]),
    "unknown diagram key": (
        {"forces": [diagram_force(dict(working="+", fractions=[0, 1], values=[0, 5], smooth=True))]},
        ["forces[0]", "smooth"]),
    "unknown moment key": ({"moments": [{"link": "3", "moment": 1.0, "torque": 2.0}]},
                           ["moments[0]", "torque"]),
    "bad gravity": ({"gravity": [0.0, -9.81, 0.0]}, ["gravity"]),
    "bad working": ({"forces": [diagram_force(dict(working="up", fractions=[0, 1], values=[0, 5]))]},
                    ["forces[0]", "working", "'up'"]),
}


@pytest.mark.parametrize("case", list(BAD_LOADS))
def test_bad_loads_raise_one_scheme_error_naming_the_entry(case):
    raw, needles = BAD_LOADS[case]
    data = to_dict(linkage.load("slider_crank"))
    data["loads"] = raw
    with pytest.raises(SchemeError) as info:
        from_dict(data)
    problems = info.value.problems
    assert len(problems) == 1, problems
    for needle in needles:
        assert needle in problems[0], (needle, problems[0])
    # the same section attached to a built mechanism: loads_of reports it too
    with pytest.raises(SchemeError):
        loads_of(linkage.load("slider_crank").with_extra(loads=raw))


def test_bad_loads_in_a_scheme_file_name_the_file(tmp_path):
    text = linkage.dumps(linkage.load("slider_crank")).replace(
        "[loads]", '[loads]\nforces = [{ point = "Q", force = [1.0, 2.0] }]')
    path = tmp_path / "press_with_bad_load.toml"
    path.write_text(text)
    with pytest.raises(SchemeError, match=r"press_with_bad_load\.toml.*forces\[0\].*'Q'"):
        linkage.load(path)


def test_stroke_diagram_is_parsed_as_declared():
    mech = press(diagram_force(dict(working="-", fractions=[0, 0.25, 1], values=[0, 7, 3], opposes=False)))
    (f,) = loads_of(mech).forces
    assert f.point == "B" and f.link == "3"
    assert f.force == StrokeDiagram("B.x", -1, (0.0, 0.25, 1.0), (0.0, 7.0, 3.0), False)


# ----------------------------------------------------------------------------------------------
# notes on missing masses, gravity off
# ----------------------------------------------------------------------------------------------


def without_masses(name, links=None):
    """A shipped scheme with the masses (and inertias) of some moving links taken out."""
    data = to_dict(linkage.load(name))
    for k in links or [k for k in data["links"] if k != data["frame"]]:
        data["links"][k].pop("mass", None)
        data["links"][k]["inertia"] = 0.0
    return from_dict(data)


def test_missing_masses_give_notes_naming_the_links():
    mech = without_masses("slider_crank_vertical")
    assert not any(mech.links[k].mass_declared for k in mech.moving_links)
    notes = loads_of(mech).notes
    for k in mech.moving_links:
        assert sum(f"'{k}'" in n for n in notes) == 1, notes
    r = solve_reactions(linkage.analyze(mech, GRID[:5]))
    for k in mech.moving_links:
        assert any(f"'{k}'" in n and "mass" in n for n in r.notes), r.notes
    # massless: no gravity, and no balancing moment for no load
    assert np.all(r.balancing_moment == 0.0)


def test_one_missing_mass_is_named_alone():
    mech = without_masses("slider_crank", ["3"])
    notes = loads_of(mech).notes
    assert len(notes) == 1 and "'3'" in notes[0] and "mass" in notes[0]
    motion = linkage.analyze(mech, GRID[:7], omega=-W)
    r = solve_reactions(motion)
    assert r.notes == notes
    assert {t.link for t in r.terms if t.kind == "gravity"} == {"1", "2"}
    assert {t.link for t in r.terms if t.kind == "inertia"} == {"1", "2"}
    assert not loads_of(linkage.load("slider_crank")).notes


def test_gravity_off():
    mech = press(gravity=(0.0, 0.0))
    assert loads_of(mech).gravity == (0.0, 0.0)
    motion = linkage.analyze(mech, GRID)
    assert evaluate_loads(motion, loads_of(mech)) == []
    r = solve_reactions(motion)
    assert np.all(r.balancing_moment == 0.0)
    # gravity on (the scheme's own [loads]): the press's weights do need a moment
    r_on = solve_reactions(linkage.analyze(linkage.load("slider_crank"), GRID))
    assert np.max(np.abs(r_on.balancing_moment)) > 1.0


def test_gravity_is_the_declared_vector():
    """M_b at rest is linear in g: a sideways gravity gives -sum m g_x x'_S (virtual work)."""
    mech = press(gravity=(2.0, 0.0))
    r = solve_reactions(linkage.analyze(mech, GRID))
    phi = GRID
    th2 = np.arcsin((E - L1 * np.sin(phi)) / L2)
    i21 = -L1 * np.cos(phi) / (L2 * np.cos(th2))
    xs2_1 = -L1 * np.sin(phi) - 0.0741 * np.sin(th2) * i21
    expected = -(400.0 * 2.0 * xs2_1 + 500.0 * 2.0 * x_b_analog(phi))
    np.testing.assert_allclose(r.balancing_moment, expected, rtol=0,
                               atol=1e-9 * np.max(np.abs(expected)))


def test_moment_diagram_on_a_rocker_whose_angle_crosses_the_pi_cut():
    """The four-bar turned by 70 deg about O: its rocker swings through theta = 180 deg, where the
    angle is reported as -180 deg. The swing (stroke) and a constant 10 N m resistance on the
    working stroke (theta increasing) must not notice the cut: the turned mechanism is the same
    machine, so its stroke equals the untouched four-bar's (found by its own closed form below)."""
    d = to_dict(linkage.load("four_bar"))
    a = np.radians(70.0)
    d["links"]["0"]["points"] = {"O": [0.0, 0.0], "C": [0.3 * np.cos(a), 0.3 * np.sin(a)]}
    d["loads"] = {"gravity": [0.0, 0.0], "moments": [{"link": "3", "diagram": {
        "working": "+", "fractions": [0.0, 1.0], "values": [10.0, 10.0]}}]}
    mech = from_dict(d)
    # rocker extremes of the original four-bar: crank and coupler aligned (|CB| = 0.25, OC = 0.3)
    def rocker_angle(reach):  # angle of CB when |OB| = reach, B above OC
        cos_c = (0.3**2 + 0.25**2 - reach**2) / (2 * 0.3 * 0.25)
        return np.pi - np.arccos(cos_c)
    stroke = abs(rocker_angle(0.4) - rocker_angle(0.2))
    ext = linkage.extreme_positions(mech, "3.theta")
    assert ext.stroke == pytest.approx(stroke, abs=1e-10)
    assert ext.value_min < np.pi < ext.value_max  # the swing straddles the cut
    phi = np.linspace(0.0, 2 * np.pi, 37)[:-1]
    motion = linkage.analyze(mech, phi, omega=1.0)
    moment = evaluate_loads(motion, loads_of(mech))[0].moment
    rising = motion.quantity("3.theta")[1] > 0
    np.testing.assert_array_equal(moment, np.where(rising, -10.0, 0.0))


def test_per_position_force_and_moment_arrays():
    """A force at E and a moment on the rocker that differ at every position: statics by virtual
    work, M_b = -(F . E' + M theta3'), with E' and theta3' by central differences of positions."""
    mech = linkage.load("four_bar")
    phi = np.radians(np.arange(5.0, 360.0, 40.0))
    n = len(phi)
    force = np.column_stack([100.0 * np.cos(phi), -50.0 + 10.0 * np.arange(n)])
    moment = 3.0 * np.sin(2 * phi)
    loads = Loads(gravity=(0.0, 0.0), forces=(PointForce("E", "2", force),),
                  moments=(LinkMoment("3", moment),))
    reactions = solve_reactions(linkage.analyze(mech, phi), loads)
    h = 1e-6
    at = lambda p: linkage.analyze(mech, p, order=0)  # noqa: E731
    e_prime = (at(phi + h).point("E") - at(phi - h).point("E")) / (2 * h)
    t_prime = (at(phi + h).quantity("3.theta")[0] - at(phi - h).quantity("3.theta")[0]) / (2 * h)
    expected = -(np.einsum("ni,ni->n", force, e_prime) + moment * t_prime)
    np.testing.assert_allclose(reactions.balancing_moment, expected, rtol=1e-7, atol=1e-7)


def test_per_position_force_of_the_wrong_shape_is_named():
    mech = linkage.load("four_bar")
    loads = Loads(forces=(PointForce("E", "2", np.zeros((3, 2))),))
    with pytest.raises(ValueError, match=r"force at point 'E'.*shape \(5, 2\).*got shape \(3, 2\)"):
        solve_reactions(linkage.analyze(mech, np.linspace(0, 1, 5)), loads)


@pytest.mark.parametrize("force, named", [
    ('point = "C"\nlink = "0"', "link '0' is the frame: a force on it moves nothing and loads no pair; apply it to a "
                                "moving link (the moving links with point 'C': ['3'])"),
])
def test_a_force_on_the_frame_is_refused_by_its_rule(force, named):
    """The frame declares C (a pivot of the rocker 3 too): a force said to act on the frame is
    refused because the frame takes it, not because the frame lacks the point."""
    text = linkage.model.scheme.scheme_path("four_bar").read_text()
    with pytest.raises(SchemeError) as caught:
        linkage.loads(text + f"\n[[loads.forces]]\n{force}\nforce = [10.0, 0.0]\n")
    assert named in str(caught.value) and "has no point" not in str(caught.value)


def test_a_force_at_a_frame_point_only_is_refused_as_on_the_frame():
    """A point only the frame declares: the force would act on the frame."""
    text = linkage.model.scheme.scheme_path("four_bar").read_text().replace(
        "points = { O = [0.0, 0.0], C = [0.3, 0.0] }", "points = { O = [0.0, 0.0], C = [0.3, 0.0], G = [0.1, -0.1] }")
    with pytest.raises(SchemeError, match=r"link '0' is the frame: .*\(no moving link has point 'G'\)"):
        linkage.loads(text + '\n[[loads.forces]]\npoint = "G"\nforce = [10.0, 0.0]\n')
