"""Coulomb friction in the pairs (docs/methods.md#friction-in-the-pairs) against the test's own mechanics.

The oracle (tests/_friction_oracle.py) never calls the library: closed-form kinematics of an
offset slider-crank (a plain one on a horizontal guide, and one on a tilted guide with a slider
block of length L) and of a four-bar, and its own Newton-Euler equations with the friction moments
``f r |R|`` and the slider's ``f |N|`` (``f (|N1| + |N2|)`` with the block), solved by its own
fixed point. The mechanisms are declared by scheme texts with a ``[friction]`` section (its own f
and radius per pair). Checked here:

1. the library's kinematics equals the closed forms (1e-12);
2. every reaction component, the prismatic normal force and moment, the friction loads and the
   balancing moment of ``solve_reactions(motion, friction=True)`` equal the oracle's (1e-9 of the
   largest reaction) at a real omega and a nonzero eps, 24 positions away from dead centres and
   reversals;
3. f = 1e-15 gives the frictionless results (1e-12);
4. the virtual power with friction, ``M_b w + P_applied + P_inertia + P_friction = 0``, from the
   oracle's kinematics and loads and the library's reactions, the friction powers
   ``-f r |R| |w_rel|`` and ``-f P |v_slide|``;
5. statics: the sense of motion (+1, -1) flips every friction load, and the balancing moment
   with friction exceeds the frictionless one in the driving direction; both equal the oracle's.

Library conventions used in the comparison: ``Reactions.force(K)`` is ``R[a, b]`` (the force link b
exerts on link a for ``links = [a, b]``), so pair O gives ``-F10`` and pair C of the four-bar
(``links = ["3", "0"]``) gives ``F30``; the slide's multipliers are (N, M) of the guide on the
slider, ``force("slide") = -N n`` and ``moment("slide") = -M``; ``friction_load(K)`` is the moment
on the pair's first link (the frame for O) or the force on the slider along u.
"""

from __future__ import annotations

import numpy as np
import pytest

import linkage
from linkage.kinetostatics.reactions import solve_reactions

from _friction_oracle import (FOUR_BAR, GRAVITY, SLIDER_CRANK, dot, four_bar_kinematics, four_bar_oracle,
                              four_bar_text, slider_crank_kinematics, slider_crank_oracle, slider_crank_text)

#: the three mechanisms: name -> (keyword arguments of the slider-crank's text / oracle, input speed, eps)
CASES = {
    "slider_crank": ({}, -12.0, 30.0),
    "slider_crank_block": ({"through": (0.01, 0.02), "angle_deg": 12.0, "length": 0.06}, -12.0, 30.0),
    "four_bar": (None, 15.0, -40.0),
}
#: the oracle's value for each library quantity: (library pair, oracle unknown, sign)
FORCES = {"slider_crank": [("O", "F10", -1.0), ("A", "F12", 1.0), ("B", "F23", 1.0)],
          "four_bar": [("O", "F10", -1.0), ("A", "F12", 1.0), ("B", "F23", 1.0), ("C", "F30", 1.0)]}
#: friction_load(K) is on the pair's first link: the frame for O, whose opposite the oracle gives
FRICTION_SIGN = {"O": -1.0}


def family(case: str) -> str:
    return "four_bar" if case == "four_bar" else "slider_crank"


def text(case: str, scale: float = 1.0) -> str:
    kw = CASES[case][0]
    return four_bar_text(scale) if kw is None else slider_crank_text(scale=scale, **kw)


def kinematics(case: str, phi):
    kw = CASES[case][0]
    if kw is None:
        return four_bar_kinematics(phi)
    return slider_crank_kinematics(phi, kw["through"], kw["angle_deg"]) if kw else slider_crank_kinematics(phi)


def oracle(case: str, phi, omega=None, eps=0.0, sense=1.0, scale=1.0):
    kw = CASES[case][0]
    if kw is None:
        return four_bar_oracle(phi, omega, eps, sense, scale)
    return slider_crank_oracle(phi, omega, eps, sense, scale=scale, **kw)


def positions(case: str, count: int = 24) -> np.ndarray:
    """``count`` crank angles (rad) where every relative motion is well away from a stop: relative
    angular analogs over 0.02, the slide's analog over 2 % of the crank."""
    phi = np.linspace(0.0, 2 * np.pi, 36, endpoint=False) + 0.0731
    kin = kinematics(case, phi)
    w = {k: kin["theta"][k][1] for k in "123"}
    margin = np.minimum.reduce([np.abs(w["1"] - w["2"]), np.abs(w["2"] - w["3"]),
                                np.abs(w["3"]) if case == "four_bar" else np.full(len(phi), 1.0)])
    if case != "four_bar":
        margin = np.minimum(margin, np.abs(kin["slide"][1]) / SLIDER_CRANK["crank"])
    keep = phi[margin > 0.02]
    assert len(keep) >= count, f"{case}: only {len(keep)} positions away from stops"
    return keep[np.linspace(0, len(keep) - 1, count).round().astype(int)]


def differences(reactions, expected: dict, case: str) -> dict[str, float]:
    """The largest difference of every compared quantity, relative to the largest reaction at its
    position (moments: to it times the mechanism's size)."""
    pairs = FORCES[family(case)]
    scale = np.max([np.hypot(*(expected[u]).T) for _, u, _ in pairs], axis=0)
    if "N" in expected:
        scale = np.maximum(scale, np.abs(expected["N"]))
    size = reactions.motion.mechanism.size
    out = {}
    for pair, unknown, sign in pairs:
        out[f"{pair}.R"] = np.max(np.abs(reactions.force(pair) - sign * expected[unknown]) / scale[:, None])
    out["Mb"] = np.max(np.abs(reactions.balancing_moment - expected["Mb"]) / (scale * size))
    for pair, value in expected["friction"].items():
        mine = FRICTION_SIGN.get(pair, 1.0) * value
        unit = scale if pair == "slide" else scale * size
        out[f"{pair}.friction"] = np.max(np.abs(reactions.friction_load(pair) - mine) / unit)
    if "N" in expected:
        u, n = expected["kin"]["u"], expected["kin"]["n"]
        lam = reactions.multipliers["slide"]
        out["slide.N"] = np.max(np.abs(lam[:, 0] - expected["N"]) / scale)
        out["slide.M"] = np.max(np.abs(lam[:, 1] - expected["M"]) / (scale * size))
        out["slide.R"] = np.max(np.abs(reactions.force("slide") + expected["N"][:, None] * n) / scale[:, None])
        out["slide.moment"] = np.max(np.abs(reactions.moment("slide") + expected["M"]) / (scale * size))
        assert abs(u @ n) < 1e-15
    return out


@pytest.mark.parametrize("case", list(CASES))
def test_kinematics_equals_closed_forms(case):
    """Positions, first and second analogs of every link (its origin and angle) and of the
    centres of mass equal the closed forms."""
    phi = positions(case)
    motion = linkage.analyze(linkage.loads(text(case)), phi)
    kin = kinematics(case, phi)
    origins = {"1": "O", "2": "A", "3": "C" if case == "four_bar" else "B"}
    for link, point in origins.items():
        theta = kin["theta"][link]
        turn = motion.poses[link][:, 2] - theta[0]
        assert np.max(np.abs((turn + np.pi) % (2 * np.pi) - np.pi)) < 1e-12
        for order, got in enumerate((motion.poses, motion.first, motion.second)):
            assert np.max(np.abs(got[link][:, :2] - kin["points"][point][order])) < 1e-12, (link, order)
            if order:
                assert np.max(np.abs(got[link][:, 2] - theta[order])) < 1e-12, (link, order)
    for point in ("A", "B", "S1", "S2", "S3"):
        assert np.max(np.abs(motion.point(point) - kin["points"][point][0])) < 1e-12, point


@pytest.mark.parametrize("case", list(CASES))
def test_reactions_with_friction_equal_newton_euler(case):
    """Every reaction, the slide's N and M, each pair's friction load and M_b equal the oracle's
    (1e-9 of the largest reaction), at a real omega and eps; and the friction matters (it moves
    M_b by far more than that)."""
    _, omega, eps = CASES[case]
    phi = positions(case)
    motion = linkage.analyze(linkage.loads(text(case)), phi, omega=omega, eps=eps)
    reactions = solve_reactions(motion, friction=True)
    assert not reactions.locked.any()
    expected = oracle(case, phi, omega, eps)
    worst = differences(reactions, expected, case)
    assert max(worst.values()) < 1e-9, worst
    frictionless = oracle(case, phi, omega, eps, scale=0.0)
    moved = np.abs(expected["Mb"] - frictionless["Mb"]) / np.max(np.abs(frictionless["Mb"]))
    assert np.min(moved) > 1e-4 and np.max(moved) > 1e-2
    assert all(np.all(np.abs(v) > 0) for v in expected["friction"].values())


@pytest.mark.parametrize("case", list(CASES))
def test_vanishing_friction_is_frictionless(case):
    """f = 1e-15 in every pair: every multiplier and M_b equal the frictionless solution (1e-12)."""
    _, omega, eps = CASES[case]
    phi = positions(case)
    motion = linkage.analyze(linkage.loads(text(case, scale=1e-15)), phi, omega=omega, eps=eps)
    tiny = solve_reactions(motion, friction=True)
    none = solve_reactions(motion)
    assert tiny.friction and not tiny.locked.any()
    scale = np.max([np.max(np.abs(v), axis=1) for v in none.multipliers.values()], axis=0)
    size = motion.mechanism.size
    for pair, lam in none.multipliers.items():
        assert np.max(np.abs(tiny.multipliers[pair] - lam) / scale[:, None]) < 1e-12, pair
        assert np.max(np.abs(tiny.friction_load(pair))) < 1e-12 * np.max(scale) * size
    assert np.max(np.abs(tiny.balancing_moment - none.balancing_moment) / (scale * size)) < 1e-12
    # and the oracle at f = 0 is the library's frictionless solution
    worst = differences(none, {**oracle(case, phi, omega, eps, scale=0.0)}, case)
    assert max(v for k, v in worst.items() if not k.endswith("friction")) < 1e-9, worst


def applied_and_inertia_power(case: str, kin: dict, omega: float, eps: float) -> tuple[np.ndarray, np.ndarray]:
    """The powers (W, (N,)) of gravity and the external loads, and of the inertia loads, from the
    oracle's kinematics (velocities ``P' w``, accelerations ``P'' w^2 + P' eps``)."""
    data = FOUR_BAR if case == "four_bar" else SLIDER_CRANK
    applied = np.zeros(len(kin["points"]["A"][0]))
    inertia = np.zeros_like(applied)
    for k in "123":
        _, v1, v2 = kin["points"][f"S{k}"]
        velocity, acceleration = v1 * omega, v2 * omega**2 + v1 * eps
        _, t1, t2 = kin["theta"][k]
        applied += data[f"m{k}"] * velocity @ GRAVITY
        inertia += -data[f"m{k}"] * dot(acceleration, velocity) - data[f"j{k}"] * (t2 * omega**2 + t1 * eps) * t1 * omega
    if case == "four_bar":
        applied += data["moment3"] * kin["theta"]["3"][1] * omega
    else:
        applied += np.array(data["force_k"]) @ (kin["points"]["K"][1] * omega).T
        applied += data["moment2"] * kin["theta"]["2"][1] * omega
    return applied, inertia


@pytest.mark.parametrize("case", list(CASES))
def test_virtual_power_with_friction(case):
    """``M_b w + P_applied + P_inertia + P_friction = 0`` with the friction powers
    ``-f r |R| |w_rel|`` and ``-f P |v_slide|`` from the oracle's kinematics and the library's
    reaction magnitudes; each pair's ``friction_power`` equals its own, and ``powers()`` agree."""
    kw, omega, eps = CASES[case]
    phi = positions(case)
    motion = linkage.analyze(linkage.loads(text(case)), phi, omega=omega, eps=eps)
    reactions = solve_reactions(motion, friction=True)
    kin = kinematics(case, phi)
    applied, inertia = applied_and_inertia_power(case, kin, omega, eps)
    w = {k: kin["theta"][k][1] * omega for k in "123"}
    data = FOUR_BAR if case == "four_bar" else SLIDER_CRANK
    rates = {"O": w["1"], "A": w["1"] - w["2"], "B": w["2"] - w["3"], "C": w["3"]}
    lost = {}
    for pair, (f, radius) in data["friction"].items():
        lost[pair] = -f * radius * reactions.magnitude(pair) * np.abs(rates[pair])
    if case != "four_bar":
        normal, couple = reactions.multipliers["slide"].T
        length = kw.get("length")
        pressing = (np.abs(normal / 2 + couple / length) + np.abs(normal / 2 - couple / length) if length
                    else np.abs(normal))
        lost["slide"] = -data["f_slide"] * pressing * np.abs(kin["slide"][1] * omega)
    driving = reactions.balancing_moment * omega
    total = driving + applied + inertia + sum(lost.values())
    scale = np.abs(driving) + np.abs(applied) + np.abs(inertia) + sum(np.abs(v) for v in lost.values())
    assert np.max(np.abs(total) / scale) < 1e-9
    assert np.min(-sum(lost.values()) / scale) > 1e-4          # friction takes a visible share
    for pair, mine in lost.items():
        assert np.max(np.abs(reactions.friction_power(pair) - mine) / scale) < 1e-9, pair
    powers = reactions.powers()
    assert np.max(np.abs(powers["friction"] - sum(lost.values())) / scale) < 1e-9
    assert np.max(np.abs(powers["inertia"] - inertia) / scale) < 1e-9
    assert np.max(np.abs(powers["gravity"] + powers["useful"] - applied) / scale) < 1e-9


@pytest.mark.parametrize("case", ["slider_crank_block", "four_bar"])
def test_static_sense_flips_friction(case):
    """Statics (no omega): with sense +1 and -1 every friction load changes sign, the balancing
    moment moves from the frictionless one in the driving direction (``s (M_b,s - M_b,0) > 0``, so
    where the load resists the motion, ``|M_b,s| > |M_b,0|``), and both equal the oracle's."""
    phi = positions(case)
    motion = linkage.analyze(linkage.loads(text(case)), phi)
    assert motion.omega is None
    frictionless = solve_reactions(motion).balancing_moment
    moments = {}
    loads = {}
    for sense in (1, -1):
        reactions = solve_reactions(motion, friction=True, sense=sense)
        assert not reactions.locked.any()
        expected = oracle(case, phi, sense=float(sense))
        worst = differences(reactions, expected, case)
        assert max(worst.values()) < 1e-9, (sense, worst)
        moments[sense] = reactions.balancing_moment
        loads[sense] = {pair: reactions.friction_load(pair) for pair in expected["friction"]}
        assert np.all(reactions.friction_power() < 0)
        assert np.all(sense * (moments[sense] - frictionless) > 0)
        resisting = sense * frictionless > 0
        assert resisting.any() and np.all(np.abs(moments[sense][resisting]) > np.abs(frictionless[resisting]))
    for pair, plus in loads[1].items():
        assert np.all(np.abs(plus) > 0) and np.all(np.sign(plus) == -np.sign(loads[-1][pair])), pair
    assert np.all(moments[1] > moments[-1])
