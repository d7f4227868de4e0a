"""The graphical method as data and drawings (linkage/plans.py, linkage/report/plan_drawings.py,
``linkage plans``): every image of a plan against velocities and accelerations by finite
differences of positions and against the slider-crank's closed form, every vector against the
formula of its kind, every force polygon closing, the lever's balancing moment against the
kinetostatics at every position of every shipped scheme, the drawings of every shipped scheme, and
the command line's JSON, numbering and errors."""

from __future__ import annotations

import json
import math
import re
import warnings
from pathlib import Path

import numpy as np
import pytest

import linkage
from linkage.errors import InputError
from linkage.kinetostatics.plans import POLE, build_plans

from _cli_io import run

ROOT = Path(__file__).resolve().parent.parent
#: the plans are built for a crank input; a scheme driven by a slide is refused (see
#: test_plans_refuse_a_slide_input_naming_the_scheme_and_why)
SHIPPED = [n for n in linkage.shipped_schemes() if linkage.load(n).coordinate.is_angle]
SLIDE_DRIVEN = [n for n in linkage.shipped_schemes() if not linkage.load(n).coordinate.is_angle]
OMEGA, EPS = -7.3, 2.9            # rad/s, rad/s^2: a crank that speeds up while it turns clockwise

# slider_crank.toml: crank OA, rod AB with S2 0.0741 m from A, slider B on the guide y = E
L1, L2, E, AS2 = 0.0742, 0.2225, 0.01335, 0.0741
M2, J2, M3, G = 400.0, 8.35, 500.0, 9.81


def table_motion(name, n=12, omega=OMEGA, eps=EPS):
    """The motion at the n + 1 table positions. Every crank-driven shipped scheme assembles and is
    regular at all 13 and passes no change point between them, so nothing is masked or silenced:
    a status other than 0 raises (AssemblyError), and any warning (a BranchWarning, a numerical
    RuntimeWarning) is an error."""
    mech = linkage.load(name)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        motion = linkage.analyze(mech, linkage.table_angles(mech, n), omega=omega, eps=eps)
    assert motion.status.tolist() == [0] * (n + 1), (name, motion.status)
    return motion


@pytest.fixture(scope="module")
def every_scheme():
    """The plans of every shipped scheme at its 13 table positions."""
    return {name: build_plans(table_motion(name)) for name in SHIPPED}


def perp(v):
    return np.stack([-v[..., 1], v[..., 0]], axis=-1)


def assert_close(actual, expected, rel, scale=None):
    expected = np.asarray(expected, float)
    scale = np.nanmax(np.abs(expected)) if scale is None else scale
    np.testing.assert_allclose(actual, expected, rtol=0, atol=rel * max(scale, 1e-300))


# ----------------------------------------------------------------------------------------------
# the oracle: velocities and accelerations by finite differences of positions
# ----------------------------------------------------------------------------------------------

H = 1e-4     # rad: central differences, truncation ~H^2 of the second analog, round-off ~1e-16/H^2


def finite_differences(motion):
    """Per link, functions of a global point fixed in the link at the analysed positions: its
    velocity and acceleration (m/s, m/s^2) from positions at phi - H, phi, phi + H only (order-0
    analyses), and the links' omega_k, eps_k (rad/s, rad/s^2)."""
    mech = motion.mechanism
    with warnings.catch_warnings():
        warnings.simplefilter("error")            # no warning expected next to a table position
        poses = [linkage.analyze(mech, motion.phi + k * H, order=0).poses for k in (-1, 0, 1)]
    w, e = motion.omega[:, None], motion.eps[:, None]

    def turn(link):
        th = [p[link][:, 2] for p in poses]
        d1 = (np.unwrap(np.stack(th), axis=0)[2] - np.unwrap(np.stack(th), axis=0)[0]) / (2 * H)
        d2 = (th[2] - 2 * th[1] + th[0] + 2 * np.pi * np.round((2 * th[1] - th[2] - th[0]) / (2 * np.pi))) / H**2
        return d1, d2

    def point(link, x):
        """Velocity and acceleration of the point of ``link`` at the global positions ``x`` (N, 2)."""
        p0 = poses[1][link]
        c, s = np.cos(p0[:, 2]), np.sin(p0[:, 2])
        rho = x - p0[:, :2]
        local = np.stack([c * rho[:, 0] + s * rho[:, 1], -s * rho[:, 0] + c * rho[:, 1]], -1)
        at = []
        for p in poses:
            c, s = np.cos(p[link][:, 2]), np.sin(p[link][:, 2])
            at.append(p[link][:, :2] + np.stack([c * local[:, 0] - s * local[:, 1],
                                                 s * local[:, 0] + c * local[:, 1]], -1))
        d1 = (at[2] - at[0]) / (2 * H)
        d2 = (at[2] - 2 * at[1] + at[0]) / H**2
        return d1 * w, d2 * w**2 + d1 * e

    rates = {k: turn(k) for k in mech.moving_links}
    omega_k = {k: d1 * motion.omega for k, (d1, _) in rates.items()}
    eps_k = {k: d2 * motion.omega**2 + d1 * motion.eps for k, (d1, d2) in rates.items()}
    return point, omega_k, eps_k


# ----------------------------------------------------------------------------------------------
# 1. the plans
# ----------------------------------------------------------------------------------------------


@pytest.mark.parametrize("name", SHIPPED)
def test_every_image_is_the_velocity_and_acceleration_of_its_point(every_scheme, name):
    """Images of named points, centres, the guides' points under sliders: finite differences."""
    plans = every_scheme[name]
    motion = plans.motion
    ok = motion.status == 0
    point, omega_k, eps_k = finite_differences(motion)
    vel, acc = plans.velocity, plans.acceleration
    v_scale = max(np.nanmax(np.abs(v[ok])) for v in vel.images.values())
    a_scale = max(np.nanmax(np.abs(a[ok])) for a in acc.images.values())
    positions = {}
    for link in motion.mechanism.links:
        for p, local in motion.mechanism.links[link].points.items():
            positions.setdefault(p, (link, motion.poses[link][:, :2] + motion.arm(link, local)))
    for label in vel.images:
        if label in positions:
            link, x = positions[label]
        else:     # a guide's point under a slider, "A(3)", or an unnamed centre of mass "S3"
            m = re.fullmatch(r"(.+)\((.+)\)", label) or re.fullmatch(r"S(.+)", label)
            link = m.group(2) if m.lastindex == 2 else m.group(1)
            x = positions[m.group(1)][1] if m.lastindex == 2 else \
                motion.poses[link][:, :2] + motion.arm(link, motion.mechanism.links[link].center_of_mass)
        v, a = point(link, x)
        assert_close(vel.images[label][ok], v[ok], 1e-7, v_scale)
        assert_close(acc.images[label][ok], a[ok], 2e-5, a_scale)
    for k in motion.mechanism.moving_links:
        assert_close(plans.angular_velocity[k][ok], omega_k[k][ok], 1e-7, abs(OMEGA) * 10)
        assert_close(plans.angular_acceleration[k][ok], eps_k[k][ok], 2e-5, OMEGA**2 * 10)


@pytest.mark.parametrize("name", SHIPPED)
def test_every_vector_joins_its_images_and_is_what_its_kind_says(every_scheme, name):
    """Each vector equals image(end) - image(start), and the formula of its kind with omega_k,
    eps_k from finite differences: omega_k x r, -omega_k^2 r, eps_k x r, along the guide,
    2 omega_g x v_rel."""
    plans = every_scheme[name]
    motion = plans.motion
    ok = motion.status == 0
    _, omega_k, eps_k = finite_differences(motion)
    position = {}
    for link in motion.mechanism.links:
        for p, local in motion.mechanism.links[link].points.items():
            position.setdefault(p, motion.poses[link][:, :2] + motion.arm(link, local))

    def where(label):
        return position[re.sub(r"\(.+\)$", "", label)] if re.sub(r"\(.+\)$", "", label) in position else None

    kinds = set()
    for plan, allowed in ((plans.velocity, {"absolute", "relative", "relative-slide"}),
                          (plans.acceleration, {"absolute", "relative", "normal", "tangential", "coriolis",
                                                "relative-slide"})):
        scale = max(np.nanmax(np.abs(v[ok])) for v in plan.images.values())
        for v in plan.vectors:
            assert v.kind in allowed, v
            kinds.add(v.kind)
            assert_close(v.vector[ok], (plan.image(v.end) - plan.image(v.start))[ok], 1e-12, scale)
            if v.kind == "absolute":
                assert v.start == POLE
                continue
            q, b = where(v.point), where(v.about)
            if v.kind in ("relative", "normal", "tangential") and q is not None and b is not None:
                r = q - b
                w, e = omega_k[v.link][:, None], eps_k[v.link][:, None]
                expected = {"normal": -w**2 * r, "tangential": e * perp(r)}.get(
                    v.kind, w * perp(r) if plan.quantity == "velocity" else -w**2 * r + e * perp(r))
                assert_close(v.vector[ok], expected[ok], 3e-5, scale)
            if v.kind in ("relative-slide", "coriolis"):    # along the guide u; Coriolis across it
                u = motion.joints[v.pair].frame(motion.poses)[0]
                off = np.abs(np.einsum("ni,ni->n", v.vector, perp(u) if v.kind == "relative-slide" else u))
                assert np.all(off[ok] <= 1e-9 * scale)
            if v.kind == "coriolis":
                expected = 2 * omega_k[v.link][:, None] * perp(slides_of(plans, v.pair))
                assert_close(v.vector[ok], expected[ok], 3e-5, scale)
    assert {"absolute"} <= kinds


def slides_of(plans, pair):
    return next(v.vector for v in plans.velocity.vectors if v.pair == pair and v.kind == "relative-slide")


def test_slider_crank_plans_against_the_closed_form():
    """v_B, a_B, omega_2, eps_2 and v_BA of the offset slider-crank written out here."""
    plans = build_plans(table_motion("slider_crank"))
    phi = plans.motion.phi
    s, c = np.sin(phi), np.cos(phi)
    root = np.sqrt(L2**2 - (L1 * s - E) ** 2)
    x1 = -L1 * s - (L1 * s - E) * L1 * c / root                                   # dx_B/dphi
    # d2x_B/dphi2, differentiating x1 once more
    x2 = (-L1 * c - (L1**2 * c**2 - (L1 * s - E) * L1 * s) / root
          - (L1 * s - E) ** 2 * L1**2 * c**2 / root**3)
    theta1 = -L1 * c / root                                                       # d theta_2 / dphi
    theta2 = (L1 * s / root) - L1 * c * (L1 * s - E) * L1 * c / root**3           # d2 theta_2 / dphi2
    w, e = OMEGA, EPS
    assert_close(plans.velocity.images["B"][:, 0], x1 * w, 1e-12)
    assert_close(plans.velocity.images["B"][:, 1], 0.0, 1e-12, abs(x1 * w).max())
    assert_close(plans.acceleration.images["B"][:, 0], x2 * w**2 + x1 * e, 1e-10)
    assert_close(plans.angular_velocity["2"], theta1 * w, 1e-12)
    assert_close(plans.angular_acceleration["2"], theta2 * w**2 + theta1 * e, 1e-10)
    v_ba = next(v for v in plans.velocity.vectors if (v.start, v.end) == ("A", "B"))
    assert v_ba.kind == "relative" and v_ba.link == "2"
    assert_close(np.hypot(*v_ba.vector.T), np.abs(theta1 * w) * L2, 1e-12)   # |omega_2| AB
    # the student's order: the crank, then the dyad's equation, then the similar points
    steps = [(v.step, v.start, v.end) for v in plans.velocity.vectors][:3]
    assert steps == [("I(0,1)", POLE, "A"), ("II-RRP(2,3)", "A", "B"), ("II-RRP(2,3)", POLE, "B")]


def test_a_turning_guide_has_its_coriolis_part():
    """Slotted link: the block's point A, the rocker's point A(3) under it, the slide along the
    slot and the Coriolis acceleration, whose size is 2 |omega_3| |v_rel| (the course formula)."""
    plans = build_plans(table_motion("slotted_link"))
    kinds = [(v.start, v.end, v.kind) for v in plans.acceleration.vectors if v.pair is not None]
    assert kinds == [("A(3)", "k(A,3)", "coriolis"), ("k(A,3)", "A", "relative-slide")]
    coriolis = np.hypot(*next(v for v in plans.acceleration.vectors if v.kind == "coriolis").vector.T)
    v_rel = np.hypot(*next(v for v in plans.velocity.vectors if v.kind == "relative-slide").vector.T)
    assert_close(coriolis, 2 * np.abs(plans.angular_velocity["3"]) * v_rel, 1e-12)


def test_a_link_figure_on_the_velocity_plan_is_similar_to_the_link(every_scheme):
    """The theorem of similarity: the images of a link's points are the link turned by 90 degrees
    and scaled by omega_k (checked on the four-bar's coupler plate ABE)."""
    plans = every_scheme["four_bar"]
    m = plans.motion
    pts = {p: m.point(p) for p in ("A", "B", "E")}
    w = plans.angular_velocity["2"][:, None]
    for p, q in (("A", "B"), ("A", "E"), ("B", "E")):
        assert_close(plans.velocity.images[q] - plans.velocity.images[p], w * perp(pts[q] - pts[p]), 1e-12)


# ----------------------------------------------------------------------------------------------
# 2. force polygons and the lever
# ----------------------------------------------------------------------------------------------


@pytest.mark.parametrize("name", SHIPPED)
def test_every_force_polygon_closes_and_so_does_every_link(every_scheme, name):
    plans = every_scheme[name]
    ok = plans.motion.status == 0
    structure = plans.motion.structure
    assert [p.step for p in plans.polygons] == [f"I(0,{k})" for k in structure.inputs] + \
        [repr(g) for g in structure.groups]
    for polygon in plans.polygons:
        vectors = [f.vector for f in polygon.forces]
        total = np.sum(vectors, axis=0)
        size = np.sum([np.hypot(*v.T) for v in vectors], axis=0)
        assert np.all(np.hypot(*total[ok].T) <= 1e-9 * size[ok]), polygon.step
        for link in polygon.links:
            own = polygon.on_link(link)
            total = np.sum([f.vector for f in own], axis=0)
            size = np.sum([np.hypot(*f.vector.T) for f in own], axis=0)
            assert np.all(np.hypot(*total[ok].T) <= 1e-9 * size[ok]), (polygon.step, link)
        # the unknown reactions open and close a group's chain
        if len(polygon.links) > 1:
            assert polygon.forces[0].kind == "reaction" and polygon.forces[-1].kind == "reaction"


def test_slider_crank_polygon_against_the_course_force_analysis():
    """The RRP dyad's polygon: the reaction of the guide is normal to it (along y), the rod's
    loads are its weight and inertia, and R[2,1] closes with the slider's forces (x and y of the
    course analysis, written out here from the closed-form kinematics)."""
    plans = build_plans(table_motion("slider_crank"))
    polygon = plans.polygons[1]
    forces = {f.label: f.vector for f in polygon.forces}
    assert list(forces) == ["R[2,1]", "G2", "Fi2", "G3", "Fi3", "R[3,0]"]
    m = plans.motion
    a_s2 = plans.acceleration.images["S2"]
    assert_close(forces["Fi2"], -M2 * a_s2, 1e-12)
    assert_close(forces["G3"], np.tile([0.0, -M3 * G], (len(m.phi), 1)), 1e-15)
    np.testing.assert_allclose(forces["R[3,0]"][:, 0], 0.0, atol=1e-9 * np.abs(forces["R[3,0]"]).max())
    # moments of the rod about A: (B - A) x R[2,3] + (S2 - A) x (G2 + Fi2) + Mi2 = 0, R[2,3] = -R[3,2]
    a, b, s2 = m.point("A"), m.point("B"), m.point("S2")
    slider = forces["G3"] + forces["Fi3"] + forces["R[3,0]"]          # forces on the slider but R[3,2]
    r23 = slider                                                        # R[2,3] = -R[3,2] = slider's loads
    mi2 = next(x.value for x in polygon.moments if x.label == "Mi2")

    def cross(u, v):
        return u[:, 0] * v[:, 1] - u[:, 1] * v[:, 0]
    residual = cross(b - a, r23) + cross(s2 - a, forces["G2"] + forces["Fi2"]) + mi2
    assert_close(residual, 0.0, 1e-9, np.abs(cross(s2 - a, forces["G2"] + forces["Fi2"])).max())
    internal = polygon.internal[0]
    assert internal.label == "R[2,3]"
    assert_close(internal.vector, r23, 1e-9)


@pytest.mark.parametrize("name", SHIPPED)
def test_the_lever_gives_the_kinetostatic_balancing_moment(every_scheme, name):
    """At every position of every shipped scheme, to 1e-9 of the loads' scale; each force's moment
    about the pole of the turned plan is its power F . v (v by finite differences)."""
    plans = every_scheme[name]
    motion = plans.motion
    ok = motion.status == 0
    lever = plans.lever
    point, _, _ = finite_differences(motion)
    scale = np.zeros(len(motion.phi))
    for f in lever.forces:
        link = f.link
        x = motion.poses[link][:, :2] + motion.arm(link, next(t.local for t in plans.reactions.terms
                                                               if t.label == f.label and t.link == link))
        v, _ = point(link, x)
        power = np.einsum("ni,ni->n", f.force, v)
        assert_close(f.moment[ok], power[ok], 1e-7, np.nanmax(np.abs(f.force)) * np.nanmax(np.abs(v)))
        scale = scale + np.abs(f.moment) / abs(OMEGA) + np.hypot(*f.force.T) * motion.mechanism.size
    for m in lever.moments:
        scale = scale + np.abs(m.contribution) / abs(OMEGA) + np.abs(m.value)
    expected = plans.reactions.balancing_moment
    assert np.all(np.abs(lever.balancing_moment - expected)[ok] <= 1e-9 * (scale + np.abs(expected))[ok])
    assert np.isfinite(lever.balancing_moment[ok]).all()


def test_several_inputs_carry_the_further_balancing_moments_to_the_lever(every_scheme):
    """The five-bar's second crank (input 4) brings its balancing moment Mb4 to the lever. Oracle:
    virtual work under a turn of crank 4 alone, crank 1 held, Mb4 = -sum (F . dS/dtheta4 +
    M dtheta_k/dtheta4) over the loads of the scheme's text (weights, the tool's 20 N at B, the
    inertia forces -m a_S and moments -J eps_k from finite differences of positions), the partials
    by central differences of positions with the second crank's phase moved by +-h (the law
    theta_4 = 150 deg - phi); the lever's contribution of Mb4 is Mb4 omega_4 (omega_4 by finite
    differences)."""
    plans = every_scheme["five_bar_two_input"]
    moments = [m for m in plans.lever.moments if m.kind == "balancing"]
    assert [m.label for m in moments] == ["Mb4"]
    assert [p.step for p in plans.polygons][:2] == ["I(0,1)", "I(0,4)"]
    motion = plans.motion
    text = (ROOT / "schemes" / "five_bar_two_input.toml").read_text(encoding="utf-8")
    assert text.count("phase_deg = 150.0") == 1
    h = 1e-4

    def turned(dh):
        mech = linkage.loads(text.replace("phase_deg = 150.0", f"phase_deg = {150.0 + math.degrees(dh)!r}"))
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            return linkage.analyze(mech, motion.phi, order=0)

    plus, minus = turned(h), turned(-h)

    def along(point):          # d point / d theta4, m/rad
        return (plus.point(point) - minus.point(point)) / (2 * h)

    def turn(link):            # d theta_k / d theta4
        return ((plus.poses[link][:, 2] - minus.poses[link][:, 2] + np.pi) % (2 * np.pi) - np.pi) / (2 * h)

    np.testing.assert_allclose(turn("4"), 1.0, rtol=1e-9)
    np.testing.assert_allclose(turn("1"), 0.0, atol=1e-12)
    point, omega_k, eps_k = finite_differences(motion)
    gravity = np.array([0.0, -9.81])
    terms = []
    for link, mass, com, inertia in (("2", 0.6, "S2", 0.001125), ("3", 0.6, "S3", 0.001125)):
        _, a = point(link, motion.point(com))
        terms.append(np.einsum("ni,ni->n", mass * gravity - mass * a, along(com)))
        terms.append(-inertia * eps_k[link] * turn(link))
    terms.append(along("B") @ np.array([0.0, -20.0]))
    terms.append(-0.0002 * eps_k["4"] * turn("4"))       # crank 4: its centre of mass Q does not move
    expected = -np.sum(terms, axis=0)
    scale = np.sum(np.abs(terms), axis=0)
    for got in (moments[0].value, plans.reactions.balancing_moments["4"]):
        assert np.all(np.abs(got - expected) <= 1e-6 * scale), np.max(np.abs(got - expected) / scale)
    assert_close(moments[0].contribution, moments[0].value * omega_k["4"], 1e-7)


@pytest.mark.parametrize("name", SLIDE_DRIVEN)
def test_plans_refuse_a_slide_input_naming_the_scheme_and_why(capsys, name):
    """The graphical method starts from a crank's angular velocity: a slide input (a piston, a
    cylinder) is refused by the library and the command line, naming the scheme, the input and
    what to use instead; nothing is printed on stdout."""
    mech = linkage.load(name)
    motion = linkage.analyze(mech, np.linspace(*mech.input_range, 5), omega=0.5, eps=0.1)
    with pytest.raises(InputError) as caught:
        build_plans(motion)
    message = str(caught.value)
    assert f"mechanism '{name}' is driven by a slide" in message and "crank input only" in message
    assert f"'{mech.inputs[0]}'" in message and "linkage forces" in message
    code, out, err = run(capsys, "plans", name, "--position", 2, "--omega", 0.5)
    assert code == 2 and out == "" and "Traceback" not in err
    assert f"mechanism '{name}' is driven by a slide" in err and "crank input only" in err


def test_plans_need_a_moving_input():
    mech = linkage.load("four_bar")
    with pytest.raises(InputError, match="omega = 0"):
        build_plans(linkage.analyze(mech, np.radians([10.0, 20.0]), omega=0.0))
    with pytest.raises(InputError, match="omega"):
        build_plans(linkage.analyze(mech, np.radians([10.0])))


# ----------------------------------------------------------------------------------------------
# 3. drawings
# ----------------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def pyplot():
    matplotlib = pytest.importorskip("matplotlib", reason="drawings need the plot extra")
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    yield plt
    plt.close("all")


@pytest.mark.parametrize("name", SHIPPED)
def test_every_shipped_scheme_has_its_sheet(every_scheme, pyplot, tmp_path, name):
    from linkage.report.plan_drawings import write_plan_drawings

    written = write_plan_drawings(every_scheme[name], 2, tmp_path, drawings=("sheet",), dpi=40)
    assert [p.name for p in written] == ["plans_sheet.svg", "plans_sheet.png"]
    assert all(p.stat().st_size > 5000 for p in written)
    assert written[1].read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


@pytest.mark.parametrize("name", ["slider_crank", "four_bar", "slotted_link_two_dyad"])
def test_drawings_to_scale_with_their_scales_and_labels_that_do_not_collide(every_scheme, pyplot, name):
    """True size (1 mm of data is 1 mm of the printed figure), the scale written as students write
    it, every label inside the figure and clear of the others."""
    from linkage.report import plan_drawings as pd

    plans = every_scheme[name]
    for fig, unit in ((pd.draw_plan(plans, 1, "velocity"), "(m/s)/mm"),
                      (pd.draw_plan(plans, 1, "acceleration", scale=0.5), "(m/s²)/mm"),
                      (pd.draw_force_polygons(plans, 1), "N/mm"), (pd.draw_lever(plans, 1), "N/mm")):
        texts = [t.get_text() for t in fig.texts]
        assert any(re.search(r"\$\\mu_[vaF]\$ = [0-9.]+ " + re.escape(unit), t) for t in texts), texts
        renderer = fig.canvas.get_renderer()
        page = fig.bbox
        for ax in fig.axes:
            x0, x1 = ax.get_xlim()
            box = ax.get_window_extent(renderer)
            mm = box.width / fig.dpi * 25.4
            assert mm == pytest.approx(x1 - x0, rel=1e-6)           # 1 mm of data = 1 mm of paper
            boxes = [t.get_window_extent(renderer) for t in ax.texts]
            for k, a in enumerate(boxes):
                assert a.x0 >= page.x0 and a.x1 <= page.x1 and a.y0 >= page.y0 and a.y1 <= page.y1
                for b in boxes[k + 1:]:
                    assert not a.overlaps(b), (name, ax.texts[k].get_text())
        pyplot.close(fig)
    fig = pd.draw_plan(plans, 1, "velocity", scale=0.005)
    assert any("$\\mu_v$ = 0.005 (m/s)/mm" in t.get_text() for t in fig.texts)
    pyplot.close(fig)


def test_nice_scales():
    from linkage.report.plan_drawings import nice_scale

    assert [nice_scale(x) for x in (0.0113, 0.02, 0.021, 0.26, 3.0, 4.5, 7.0, 1234.0)] == \
        [0.02, 0.02, 0.025, 0.4, 4.0, 5.0, 10.0, 2000.0]


# ----------------------------------------------------------------------------------------------
# 4. the command line
# ----------------------------------------------------------------------------------------------


def test_cli_json_keys_units_and_the_table_numbering(capsys):
    """Position I is row I of `linkage forces` with the same options (phi_deg, M_b) and of `linkage
    analyze` (the scheme's declared speed: course_slider_crank turns clockwise)."""
    code, out, err = run(capsys, "plans", "course_slider_crank", "--position", 12)
    assert code == 0, err
    doc = json.loads(out)
    for key in ("phi_deg", "velocity", "acceleration", "lever_balancing_moment", "balancing_moment",
                "velocity_plan", "acceleration_plan", "force_polygons", "lever", "scales", "units"):
        assert key in doc, key
    assert doc["units"]["velocity"] == "m/s" and doc["units"]["acceleration"] == "m/s^2"
    assert doc["units"]["balancing_moment"] == "N m" and doc["units"]["lever_balancing_moment"] == "N m"
    assert doc["phi_deg"] == 330.0 and doc["omega"] == -10.472
    code, out, _ = run(capsys, "forces", "course_slider_crank", "--format", "json")
    row = json.loads(out)["rows"][11]
    assert row["phi_deg"] == doc["phi_deg"]
    assert doc["balancing_moment"] == pytest.approx(row["balancing_moment"], rel=1e-12)
    assert doc["lever_balancing_moment"] == pytest.approx(row["balancing_moment"], rel=1e-9)
    code, out, _ = run(capsys, "analyze", "course_slider_crank", "--format", "json")
    row = json.loads(out)["rows"][11]
    # the table's analogs are per rad turned (d/dpsi): the velocity is B.x' * |omega|
    assert doc["velocity"]["B"][0] == pytest.approx(row["B.x'"] * 10.472, rel=1e-12)
    assert doc["acceleration"]["B"][0] == pytest.approx(row["B.x''"] * 10.472**2, rel=1e-12)


def test_cli_speed_options_and_the_note_without_a_speed(capsys):
    code, out, err = run(capsys, "plans", "slider_crank", "-i", 3)
    assert code == 0 and "omega = 1 rad/s" in err
    assert json.loads(out)["omega"] == 1.0
    code, out, _ = run(capsys, "plans", "slider_crank", "-i", 3, "--rpm", -60, "--eps", 1.5)
    doc = json.loads(out)
    assert doc["omega"] == pytest.approx(-2 * math.pi) and doc["eps"] == 1.5
    assert doc["phi_deg"] == 60.0


@pytest.mark.parametrize("args, message", [
    (("--position", 14), "--position 14: scheme 'slider_crank' has the table positions 1 to 13"),
    (("--position", 0), "--position"),
    (("--position", 2, "--omega", 0), "--omega 0"),
    (("--position", 2, "--mu-v", -1), "--mu-v -1"),
])
def test_cli_errors_name_the_option_and_the_value(capsys, args, message):
    code, out, err = run(capsys, "plans", "slider_crank", *args)
    assert code == 2 and out == "" and message in err and "Traceback" not in err


@pytest.mark.parametrize("fmt", ["svg", "png"])
def test_cli_writes_the_drawings(capsys, pyplot, tmp_path, fmt):
    code, out, err = run(capsys, "plans", "slider_crank", "-i", 2, "--omega", -10, "--format", fmt,
                         "--out", tmp_path, "--mu-v", 0.01)
    assert code == 0, err
    paths = out.split()
    assert [p.rsplit("_", 1)[1] for p in paths] == [f"{d}.{fmt}" for d in ("velocity", "acceleration", "forces",
                                                                             "lever", "sheet")]
    assert all((tmp_path / p.rsplit("/", 1)[1]).stat().st_size > 3000 for p in paths)


def test_cli_refuses_a_position_that_cannot_be_assembled(capsys, tmp_path):
    """A user's scheme (the four-bar with a crank of 0.28 m, too long to pass phi = 180 deg): the
    error names the position and its input angle; the other positions have their plans."""
    source = (ROOT / "schemes" / "four_bar.toml").read_text(encoding="utf-8")
    scheme = tmp_path / "long_crank.toml"
    scheme.write_text(re.sub(r"(?m)^length = 0\.1\b.*$", "length = 0.28", source, count=1), encoding="utf-8")
    code, out, err = run(capsys, "plans", scheme, "--position", 7, "--start", 0, "--omega", 1)
    assert code == 2 and out == "" and "Traceback" not in err
    assert "--position 7" in err and "cannot be assembled at the input angle 180 deg" in err
    code, out, err = run(capsys, "plans", scheme, "--position", 3, "--start", 0, "--omega", 1)
    assert code == 0 and json.loads(out)["input_angle_deg"] == pytest.approx(60.0)
