"""Coulomb friction in the pairs (issue 23, docs/methods.md#friction-in-the-pairs) against oracles
written in this file, for every dyad kind (RRR, RRP, RPR, RPP, PRP), a class-III group, a slide
input and a hydraulic cylinder.

1. Virtual power with friction: ``sum(Reactions.powers()) = 0``, and the same balance recomputed
   here from the library's balancing load and reaction magnitudes with velocities and
   accelerations of our own (5-point central differences of ``motion.poses`` over the input):
   gravity ``m g . v_S``, inertia ``-(m a_S . v_S + J_S alpha omega)``, the useful loads, and the
   friction of every pair ``-f r |R| |omega_a - omega_b|`` (revolute) or ``-f P |v_rel|``
   (prismatic, ``P = |N|`` or ``|N/2 + M/L| + |N/2 - M/L|`` with a block of length L).
2. ``f -> 0`` gives the frictionless reactions.
3. The fixed point holds: every friction load is ``f r |R|`` / ``f P`` of the reactions returned,
   and opposes the relative motion found by finite differences.
4. Over a steady turn: driving work = useful work + friction work; gravity and inertia do no
   work; friction work > 0 and grows with f; none without friction (efficiency 1); the useful
   work of a constant resistance against the stroke in closed form.
5. Self-locking of an offset slider-crank whose rod reaches beyond the friction cone: locked
   exactly where the pressure angle ``beta > 90 deg - atan f`` (the load resisting), the balancing
   moment in closed form elsewhere up to ``f tan beta = 0.95``; whichever positions share the batch.
6. The instantaneous efficiency of a slider-crank press with friction in its guide only against
   the closed form ``eta = 1 - f |tan beta|``.

Closed forms (slider-crank, crank r about O, rod l, guide along x at y = e, slider B right of A):
the rod's angle with the guide ``sin beta = (r sin phi - e) / l``; the unit vector from B to A
``(-cos beta, sin beta)``. With the rod's force ``F`` on the slider along it (tension > 0), the
guide's normal force ``N`` (along y), the friction ``T = -f |N| sgn(v_B)`` and the load ``Q``
along x: ``N = -F sin beta`` and ``-F cos beta + T + Q = 0``. For a resisting load
(``Q v_B < 0``), ``F (cos beta - f |sin beta|) = Q``: a solution of the right sign exists only
while ``f |tan beta| < 1`` (self-locking beyond); for a driving load ``F (cos beta + f |sin beta|)
= Q``. The massless rod pulls the crank pin A towards B with F, so ``M_b = F r sin(phi + beta)``
(CCW), and with ``dx_B/dphi = -r sin(phi + beta) / cos beta`` the efficiency of a resisting load
is ``eta = -Q dx_B/dphi / M_b = (cos beta - f |sin beta|) / cos beta = 1 - f |tan beta|``.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import linkage
from linkage.kinetostatics.efficiency import cycle_works
from linkage.kinetostatics.reactions import solve_reactions

from _texts import slider_crank_toml

G = np.array([0.0, -9.81])
OMEGA, EPS = 10.0, 3.0              # rad/s, rad/s^2 (a crank)
SLIDE_SPEED, SLIDE_ACC = 0.5, 0.2   # m/s, m/s^2 (a slide input)
N_POS = 30

# friction of every scheme: journals of 20 mm at f = 0.1; blocks 40 mm long at f = 0.12
FRICTION = {"revolute": {"f": 0.1, "radius": 0.02}, "prismatic": {"f": 0.12, "length": 0.04}}

# the loads each scheme gets, as (kind, ...) specs this file turns into [loads] entries and into
# their power: ("resist_x", point, link, P): a constant P (N) along x against the point's x motion;
# ("resist_turn", link, M): a constant M (N m) against the link's rotation; ("force", point, link,
# (Fx, Fy)); ("moment", link, M)
USEFUL = {
    "four_bar": [("resist_turn", "3", 5.0), ("force", "E", "2", (0.0, -20.0))],
    "slider_crank": [("resist_x", "B", "3", 2000.0)],
    "slotted_link": [("resist_turn", "3", 20.0)],
    "scotch_yoke": [("resist_x", "D", "3", 100.0)],
    "slotted_link_two_dyad": [("resist_x", "B", "5", 500.0)],
    "six_bar_class3": [("resist_turn", "4", 2.0)],
    "piston_driven_crank": [("moment", "1", -50.0)],
    "cylinder_boom": [("force", "T", "1", (0.0, -2000.0))],
}
CRANKS = ["four_bar", "slider_crank", "slotted_link", "scotch_yoke", "slotted_link_two_dyad", "six_bar_class3"]
SCHEMES = CRANKS + ["piston_driven_crank", "cylinder_boom"]


# ----------------------------------------------------------------------------------------------
# the mechanisms
# ----------------------------------------------------------------------------------------------


def loads_table(specs) -> dict:
    """The [loads] table of the specs (gravity included)."""
    forces, moments = [], []
    both = {"fractions": [0.0, 1.0], "idle_fractions": [0.0, 1.0]}
    for kind, *rest in specs:
        if kind == "resist_x":
            point, link, p = rest
            forces.append({"point": point, "link": link, "diagram": {
                "along": "x", "working": "+", "values": [p, p], "idle_values": [p, p], **both}})
        elif kind == "resist_turn":
            link, m = rest
            moments.append({"link": link, "diagram": {"working": "+", "values": [m, m], "idle_values": [m, m],
                                                      **both}})
        elif kind == "force":
            point, link, f = rest
            forces.append({"point": point, "link": link, "force": list(f)})
        else:
            link, m = rest
            moments.append({"link": link, "moment": m})
    return {"gravity": list(G), "forces": forces, "moments": moments}


def with_friction(name: str, friction=None):
    """The shipped scheme with this file's loads and friction."""
    mech = linkage.load(name)
    return mech.with_extra(loads=loads_table(USEFUL[name]), friction=FRICTION if friction is None else friction)


def positions(mech) -> np.ndarray:
    """N_POS generic input positions: a turn for a crank, inside the declared stroke for a slide."""
    if mech.coordinate.is_angle and mech.input_range is None:
        return np.linspace(0.0, 2 * np.pi, N_POS, endpoint=False) + 0.0371
    a, b = mech.input_range
    return a + (b - a) * (np.arange(N_POS) + 0.5) / N_POS


def speeds(mech) -> tuple[float, float]:
    return (OMEGA, EPS) if mech.coordinate.is_angle else (SLIDE_SPEED, SLIDE_ACC)


# ----------------------------------------------------------------------------------------------
# our own velocities: 5-point central differences of the poses over the input
# ----------------------------------------------------------------------------------------------


def wrap(a):
    return (a + np.pi) % (2 * np.pi) - np.pi


def rot(theta, p):
    """Rot(theta) p for angles (N,) and a local vector (2,) -> (N, 2)."""
    c, s = np.cos(theta), np.sin(theta)
    return np.stack([c * p[0] - s * p[1], s * p[0] + c * p[1]], axis=-1)


class Stencil:
    """Poses at q - 2h .. q + 2h and the derivatives with respect to q of anything computed from
    them (4th-order central differences)."""

    def __init__(self, mech, q, h):
        self.h = h
        self.poses = [linkage.analyze(mech, q + k * h, order=0).poses for k in (-2, -1, 0, 1, 2)]

    def derivatives(self, value, angle=False):
        """(first, second) derivatives of ``value(poses)`` over the input."""
        v = [value(p) for p in self.poses]
        if angle:
            v = [wrap(x - v[2]) for x in v]
        h = self.h
        first = (v[0] - 8 * v[1] + 8 * v[3] - v[4]) / (12 * h)
        second = (-v[0] + 16 * v[1] - 30 * v[2] + 16 * v[3] - v[4]) / (12 * h * h)
        return first, second

    def turn(self, link):
        return self.derivatives(lambda p: p[link][:, 2], angle=True)

    def point(self, link, local):
        return self.derivatives(lambda p: p[link][:, :2] + rot(p[link][:, 2], local))


def slide_of(mech, pair):
    """s(poses) of a prismatic pair: u . (slider's point - guide's point), from the scheme."""
    decl = mech.pairs[pair]
    guide_link, slider_link = decl.links
    guide = mech.links[guide_link].guides[decl.guide]
    u_local = (math.cos(guide.angle), math.sin(guide.angle))
    p_local = mech.links[slider_link].points[decl.point]

    def s(poses):
        u = rot(poses[guide_link][:, 2], u_local)
        d = (poses[slider_link][:, :2] + rot(poses[slider_link][:, 2], p_local)
             - poses[guide_link][:, :2] - rot(poses[guide_link][:, 2], guide.point))
        return np.einsum("ni,ni->n", u, d)
    return s, u_local, guide_link


def pressing(reactions, mech, pair, spec):
    """P of a prismatic pair from the returned reactions: |N| or |N/2 + M/L| + |N/2 - M/L|, with N
    along the CCW normal of the guide and M the pair's moment."""
    _, u_local, guide_link = slide_of(mech, pair)
    u = rot(reactions.motion.poses[guide_link][:, 2], u_local)
    n = np.stack([-u[:, 1], u[:, 0]], axis=-1)
    normal = np.einsum("ni,ni->n", reactions.force(pair), n)
    length = spec.get("length")
    if not length:
        return np.abs(normal)
    couple = reactions.moment(pair)
    return np.abs(normal / 2 + couple / length) + np.abs(normal / 2 - couple / length)


def relative_rates(mech, stencil, rate):
    """Per pair with friction: the relative motion in time, rad/s (omega_a - omega_b) or m/s
    (the slider's along the guide)."""
    out = {}
    for name, pair in mech.pairs.items():
        if pair.kind == "R":
            a, b = pair.links
            out[name] = (stencil.turn(a)[0] - stencil.turn(b)[0]) * rate
        else:
            out[name] = stencil.derivatives(slide_of(mech, name)[0])[0] * rate
    return out


def own_powers(mech, reactions, stencil, rate, acc):
    """The powers recomputed here (N,), W: driving, gravity, inertia, useful, friction per pair."""
    out = {"driving": reactions.balancing_moment * rate, "gravity": 0.0, "inertia": 0.0, "useful": 0.0}
    for name, link in mech.links.items():
        if name == mech.frame or link.mass == 0.0:
            continue
        s1, s2 = stencil.point(name, link.center_of_mass)
        t1, t2 = stencil.turn(name)
        v, a = s1 * rate, s2 * rate**2 + s1 * acc
        w, alpha = t1 * rate, t2 * rate**2 + t1 * acc
        out["gravity"] = out["gravity"] + link.mass * (v @ G)
        out["inertia"] = out["inertia"] - link.mass * np.einsum("ni,ni->n", a, v) - link.inertia * alpha * w
    for kind, *rest in USEFUL[mech.name]:
        if kind in ("resist_x", "force"):
            point, link, value = rest
            v = stencil.point(link, mech.links[link].points[point])[0] * rate
            out["useful"] = out["useful"] + (-value * np.abs(v[:, 0]) if kind == "resist_x" else v @ np.array(value))
        else:
            link, value = rest
            w = stencil.turn(link)[0] * rate
            out["useful"] = out["useful"] + (-value * np.abs(w) if kind == "resist_turn" else value * w)
    rel = relative_rates(mech, stencil, rate)
    friction = {}
    for name, pair in mech.pairs.items():
        spec = FRICTION["revolute" if pair.kind == "R" else "prismatic"]
        if pair.kind == "R":
            friction[name] = -spec["f"] * spec["radius"] * reactions.magnitude(name) * np.abs(rel[name])
        else:
            friction[name] = -spec["f"] * pressing(reactions, mech, name, spec) * np.abs(rel[name])
    return out, friction, rel


_CACHE: dict = {}


def solved(name):
    """(mech, reactions with friction, frictionless reactions, stencil, rate, acc), once per scheme."""
    if name not in _CACHE:
        mech = with_friction(name)
        q = positions(mech)
        rate, acc = speeds(mech)
        motion = linkage.analyze(mech, q, omega=rate, eps=acc)
        h = 1e-3 if mech.coordinate.is_angle else 3e-4 * mech.size
        _CACHE[name] = (mech, solve_reactions(motion, friction=True), solve_reactions(motion), Stencil(mech, q, h),
                        rate, acc)
    return _CACHE[name]


# ----------------------------------------------------------------------------------------------
# 1. virtual power with friction
# ----------------------------------------------------------------------------------------------


@pytest.mark.parametrize("name", SCHEMES)
def test_virtual_power_with_friction(name):
    mech, reactions, _, stencil, rate, acc = solved(name)
    assert not reactions.locked.any()
    powers = reactions.powers()
    total = sum(powers.values())
    scale = sum(np.abs(v) for v in powers.values())
    assert np.max(np.abs(total) / scale) < 1e-9
    assert np.all(powers["friction"] < 0)

    own, friction, _ = own_powers(mech, reactions, stencil, rate, acc)
    own_friction = sum(friction.values())
    own_total = own["driving"] + own["gravity"] + own["inertia"] + own["useful"] + own_friction
    own_scale = (np.abs(own["driving"]) + np.abs(own["gravity"]) + np.abs(own["inertia"]) + np.abs(own["useful"])
                 + np.abs(own_friction))
    assert np.max(np.abs(own_total) / own_scale) < 1e-8
    # each part as the library books it
    for key in ("gravity", "inertia", "useful"):
        assert np.max(np.abs(powers[key] - own[key]) / own_scale) < 1e-8, key
    for pair, value in friction.items():
        assert np.max(np.abs(reactions.friction_power(pair) - value) / own_scale) < 1e-8, pair
    assert np.max(np.abs(powers["friction"] - own_friction) / own_scale) < 1e-8


# ----------------------------------------------------------------------------------------------
# 2. f -> 0
# ----------------------------------------------------------------------------------------------


@pytest.mark.parametrize("name", SCHEMES)
def test_vanishing_friction_is_frictionless(name):
    mech, _, frictionless, _, rate, acc = solved(name)
    tiny = {"revolute": {"f": 1e-15, "radius": 0.02}, "prismatic": {"f": 1e-15, "length": 0.04}}
    motion = linkage.analyze(with_friction(name, tiny), positions(mech), omega=rate, eps=acc)
    reactions = solve_reactions(motion, friction=True)
    assert set(reactions.friction.pairs) == set(mech.pairs)
    scale = np.max(np.abs(frictionless.balancing_moment))
    assert np.max(np.abs(reactions.balancing_moment - frictionless.balancing_moment)) < 1e-12 * scale
    for pair, lam in frictionless.multipliers.items():
        size = np.max(np.abs(lam))
        assert np.max(np.abs(reactions.multipliers[pair] - lam)) < 1e-12 * size, pair
    assert np.max(np.abs(reactions.friction_power())) < 1e-12 * np.max(np.abs(reactions.powers()["driving"]))


# ----------------------------------------------------------------------------------------------
# 3. the fixed point
# ----------------------------------------------------------------------------------------------


@pytest.mark.parametrize("name", SCHEMES)
def test_friction_loads_are_those_of_the_reactions(name):
    mech, reactions, frictionless, stencil, rate, acc = solved(name)
    rel = relative_rates(mech, stencil, rate)
    differs = 0.0
    for pair, decl in mech.pairs.items():
        load = reactions.friction_load(pair)
        if decl.kind == "R":
            spec = FRICTION["revolute"]
            expected = spec["f"] * spec["radius"] * reactions.magnitude(pair)
        else:
            spec = FRICTION["prismatic"]
            expected = spec["f"] * pressing(reactions, mech, pair, spec)
        assert np.max(np.abs(np.abs(load) - expected) / np.max(expected)) < 1e-10, pair
        moving = np.abs(rel[pair]) > 1e-6 * np.max(np.abs(rel[pair]))
        assert moving.sum() >= N_POS - 2
        assert np.all(np.sign(load[moving]) == -np.sign(rel[pair][moving])), pair
        differs = max(differs, np.max(np.abs(reactions.multipliers[pair] - frictionless.multipliers[pair])))
    assert differs > 1e-3      # the friction changed the reactions: the fixed point was not trivial


# ----------------------------------------------------------------------------------------------
# 4. the works of a steady turn
# ----------------------------------------------------------------------------------------------


def scaled(factor):
    return {"revolute": {"f": 0.1 * factor, "radius": 0.02}, "prismatic": {"f": 0.12 * factor, "length": 0.04}}


@pytest.mark.parametrize("name", CRANKS)
def test_cycle_works(name):
    samples = 240
    mech = with_friction(name)
    works = cycle_works(mech, omega=OMEGA, samples=samples)
    more = cycle_works(with_friction(name, scaled(2.0)), omega=OMEGA, samples=samples)
    none = cycle_works(mech, omega=OMEGA, friction=False, samples=samples)
    for w in (works, more):
        assert w.locked == 0
        assert abs(w.driving - w.useful - w.friction) < 1e-6 * w.driving
        assert abs(w.gravity) < 1e-9 * w.driving and abs(w.inertia) < 1e-9 * w.driving
        assert w.useful > 0 and w.friction > 0
        assert w.efficiency == pytest.approx(w.useful / w.driving, rel=1e-14)
    assert more.friction > 1.5 * works.friction
    assert more.efficiency < works.efficiency < 1.0
    assert none.friction == 0.0
    assert none.efficiency == pytest.approx(1.0, abs=1e-9)
    assert none.driving == pytest.approx(none.useful, rel=1e-9)
    # the useful work does not depend on the friction (same motion, same resistances)
    assert works.useful == pytest.approx(none.useful, rel=1e-12)


def test_cycle_useful_work_closed_form():
    """A constant resistance P against the slider's motion takes P * 2 * stroke per turn; a
    constant moment M against the four-bar's rocker M * 2 * swing."""
    works = cycle_works(with_friction("slider_crank"), omega=OMEGA, samples=720)
    r, l, e = 0.0742, 0.2225, 0.01335
    stroke = math.sqrt((l + r) ** 2 - e**2) - math.sqrt((l - r) ** 2 - e**2)
    assert works.useful == pytest.approx(2 * 2000.0 * stroke, rel=2e-5)
    works = cycle_works(with_friction("four_bar"), omega=OMEGA, samples=720)
    crank, coupler, rocker, ground = 0.1, 0.3, 0.25, 0.3

    def rocker_angle(diagonal):      # the angle OCB at an extreme: crank and coupler in line, |OB| = diagonal
        return math.acos((ground**2 + rocker**2 - diagonal**2) / (2 * ground * rocker))
    swing = rocker_angle(coupler + crank) - rocker_angle(coupler - crank)
    useful = 2 * 5.0 * swing
    # the constant force at E adds nothing over a turn
    assert works.useful == pytest.approx(useful, rel=2e-5)


# ----------------------------------------------------------------------------------------------
# 5. and 6. the offset slider-crank: self-locking and efficiency in closed form
# ----------------------------------------------------------------------------------------------


def closed_form(phi, r, l, e, f, q):
    """Slider-crank with friction in its guide only, a load q (N) along x on the slider, static,
    the crank turning CCW: (beta, dx_B/dphi, M_b). Where q resists (q v_B < 0),
    ``F = q / (cos beta - f |sin beta|)`` (NaN where that has the wrong sign: self-locking);
    where q drives, ``F = q / (cos beta + f |sin beta|)``; ``M_b = F r sin(phi + beta)``."""
    sin_b = (r * np.sin(phi) - e) / l
    beta = np.arcsin(sin_b)
    cos_b = np.cos(beta)
    dx = -r * np.sin(phi + beta) / cos_b
    resisting = q * dx < 0
    rod = q / (cos_b - np.where(resisting, f, -f) * np.abs(sin_b))        # F, tension > 0
    rod = np.where(rod * q > 0, rod, np.nan)
    return beta, dx, rod * r * np.sin(phi + beta)


def slider_crank_with(r, l, e, f, q, name="offset_press"):
    mech = linkage.loads(slider_crank_toml(r, l, 'from = "O"\ntowards_deg = 0', name=name, offset=e))
    return mech.with_extra(loads={"gravity": [0.0, -9.81], "forces": [{"point": "B", "link": "3", "force": [q, 0.0]}]},
                           friction={"prismatic": {"f": f}})


OFFSET_PRESS = dict(r=0.06, l=0.1, e=-0.0395, f=0.15, q=300.0)   # r + |e| = 0.0995 m, just under l


def test_self_locking_offset_slider_crank():
    r, l, e, f, q = (OFFSET_PRESS[k] for k in "rlefq")
    locking = math.pi / 2 - math.atan(f)
    mech = slider_crank_with(r, l, e, f, q)
    phi = np.radians(np.arange(0.5, 360.0, 2.0))
    beta, dx, moment = closed_form(phi, r, l, e, f, q)
    resisting = q * dx < 0                                           # the slider moving towards -x
    motion = linkage.analyze(mech, phi)
    reactions = solve_reactions(motion, friction=True)

    locked = resisting & (np.abs(beta) > locking)
    assert locked.sum() >= 5                                         # the scheme does reach the cone
    assert np.all(np.isnan(moment[locked]))                          # (the closed form: no solution)
    assert np.all(reactions.locked[locked])
    assert all(p == "slide" for p in reactions.locked_pair[locked])
    assert np.all(np.isnan(reactions.balancing_moment[locked]))
    assert all(np.all(np.isnan(v[locked])) for v in reactions.multipliers.values())
    note = next(n for n in reactions.notes if "self-locking" in n)
    assert "pair slide" in note and "f = 0.15" in note

    # outside the cone, up to close to its edge, on both strokes (the load resisting, and driving),
    # away from the dead centres
    clear = (f * np.abs(np.tan(beta)) < 0.95) & (np.abs(dx) > 0.02 * r)
    assert clear.sum() >= 150 and (clear & resisting).sum() >= 40
    assert not reactions.locked[clear].any()
    assert np.max(np.abs(reactions.balancing_moment[clear] - moment[clear]) / np.abs(moment[clear])) < 1e-9
    # where it locks, the frictionless mechanism still runs: the friction, not the geometry, stops it
    assert np.all(np.isfinite(solve_reactions(motion).balancing_moment[locked]))


def test_locking_does_not_depend_on_the_batch():
    """Positions close to the cone's edge converge slowly; one that locks in the same batch must
    not stop them (it did with a batch-wide stop of the fixed point)."""
    r, l, e, f, q = (OFFSET_PRESS[k] for k in "rlefq")
    mech = slider_crank_with(r, l, e, f, q)
    phi = np.radians([70.5, 74.5, 78.5, 80.5])                      # f |tan beta| = 0.52 .. 0.91: they move
    beta, dx, moment = closed_form(phi, r, l, e, f, q)
    alone = solve_reactions(linkage.analyze(mech, phi), friction=True)
    assert not alone.locked.any()
    assert np.max(np.abs(alone.balancing_moment - moment) / np.abs(moment)) < 1e-9
    with_locked = solve_reactions(linkage.analyze(mech, np.append(phi, np.radians(90.5))), friction=True)
    assert with_locked.locked[-1]                                     # beta = 84.3 deg: locked
    assert not with_locked.locked[:-1].any()


@pytest.mark.parametrize("q", [800.0, -800.0])
def test_press_efficiency_closed_form(q):
    r, l, e, f = 0.0742, 0.2225, 0.01335, 0.15
    mech = slider_crank_with(r, l, e, f, q, name="press")
    phi = np.radians(np.arange(1.0, 360.0, 4.0))
    beta, dx, moment = closed_form(phi, r, l, e, f, q)
    away = (q * dx < 0) & (np.abs(dx) > 0.1 * r)                      # resisting, off the dead centres
    assert away.sum() >= 30
    reactions = solve_reactions(linkage.analyze(mech, phi[away]), friction=True)
    assert not reactions.locked.any()
    eta = 1.0 - f * np.abs(np.tan(beta[away]))
    assert np.max(np.abs(reactions.efficiency() - eta)) < 1e-10
    assert np.max(np.abs(reactions.balancing_moment - moment[away]) / np.abs(moment[away])) < 1e-10
    powers = reactions.powers()
    assert np.max(np.abs(powers["useful"] + abs(q) * np.abs(dx[away])) / np.abs(powers["useful"])) < 1e-10
