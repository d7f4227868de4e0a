"""Kinetostatics (docs/methods.md#kinetostatics) against oracles written independently in this file.

1. The course's step-by-step algorithm for the slider-crank (horizontal guide, and the same press
   turned upright), with closed-form kinematics (docs/methods.md#checks) computed here, never taken from
   the library's analogs or accelerations.
2. Zhukovsky's virtual power balance for every shipped scheme with gravity, inertia, an external
   force and an external moment, evaluated by the library *and* recomputed here from the loads.
3. The equilibrium of every link of the four-bar under the reported reactions, and R[i,j] = -R[j,i].
4. Statics by virtual work: ``M_b = -sum m_k g . r'_Sk`` with finite-difference analogs.

Convention: ``R[i, j]`` is the force that link j exerts on link i; ``Reactions.on(i, j)`` gives it.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import linkage
from linkage import SchemeError
from linkage.kinetostatics.loads import LinkMoment, Loads, PointForce, loads_of
from linkage.kinetostatics.reactions import solve_reactions, virtual_power_residual
from linkage.model.scheme import from_dict, to_dict

G = 9.81
OMEGA = -10.472  # rad/s, the course press (clockwise crank)

# the course press
L1, L2, LS2 = 0.0742, 0.2225, 0.0741
OFFSET = 0.01335
M1, M2, J2, M3 = 30.0, 400.0, 8.35, 500.0

PHI = np.linspace(0.0, 2 * np.pi, 36, endpoint=False) + 0.0123  # 36 positions, none special
N = len(PHI)
SLIDE_SPEED = 0.85  # m/s, the speed of a slide input (its OMEGA)


def positions(mech) -> np.ndarray:
    """PHI (rad) for a crank; for a slide input, 36 slides (m) inside its declared stroke."""
    if mech.coordinate.is_angle:
        return PHI
    a, b = mech.input_range
    return a + (b - a) * (np.arange(N) + 0.5) / N


def speed(mech) -> float:
    """The input's speed: OMEGA (rad/s) for a crank, SLIDE_SPEED (m/s) for a slide."""
    return OMEGA if mech.coordinate.is_angle else SLIDE_SPEED


def cross(a, b):
    """z component of a x b for (..., 2) arrays."""
    return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]


def unit(theta):
    return np.stack([np.cos(theta), np.sin(theta)], axis=-1)


def unit_perp(theta):
    return np.stack([-np.sin(theta), np.cos(theta)], axis=-1)


def rel_err(actual, expected):
    """Largest error over positions relative to the largest magnitude of the expected values."""
    actual, expected = np.asarray(actual, float), np.asarray(expected, float)
    if expected.ndim == 2:
        diff, scale = np.hypot(*(actual - expected).T), np.hypot(*expected.T)
    else:
        diff, scale = np.abs(actual - expected), np.abs(expected)
    return float(np.max(diff) / max(float(np.max(scale)), 1e-300))


# ----------------------------------------------------------------------------------------------
# independent slider-crank kinematics (docs/methods.md#positions-the-five-dyads, #checks)
# ----------------------------------------------------------------------------------------------


def slider_crank_kinematics(phi, guide_point, guide_dir):
    """Closed-form positions and exact first / second analogs of the slider-crank O-A-B.

    The slider B runs on the line ``guide_point + s u`` (u = unit ``guide_dir``), on the branch
    ``s = u.(A - G) + sqrt(l2^2 - h^2)`` (slider ahead of the crank along u), ``h = n.(A - G)``.
    Returns a dict of arrays: A, B, S2 and theta2 with ``'`` / ``''`` analogs.
    """
    phi = np.asarray(phi, float)
    G_ = np.asarray(guide_point, float)
    u = np.asarray(guide_dir, float) / np.hypot(*guide_dir)
    n = np.array([-u[1], u[0]])
    A = L1 * unit(phi)
    A1 = L1 * unit_perp(phi)
    A2 = -A
    h, h1, h2 = (A - G_) @ n, A1 @ n, A2 @ n
    r = np.sqrt(L2**2 - h**2)
    r1 = -h * h1 / r
    r2 = -(h1**2 + h * h2) / r - h**2 * h1**2 / r**3
    s, s1, s2 = (A - G_) @ u + r, A1 @ u + r1, A2 @ u + r2
    B, B1, B2 = G_ + s[:, None] * u, s1[:, None] * u, s2[:, None] * u
    d, d1, d2 = B - A, B1 - A1, B2 - A2
    th2 = np.arctan2(d[:, 1], d[:, 0])
    th21 = cross(d, d1) / L2**2
    th22 = cross(d, d2) / L2**2  # d . d' = 0 (constant length)
    k = LS2 / L2
    return {
        "A": A, "A'": A1, "A''": A2,
        "B": B, "B'": B1, "B''": B2,
        "S2": A + k * d, "S2'": A1 + k * d1, "S2''": A2 + k * d2,
        "th2": th2, "th2'": th21, "th2''": th22,
        "s": s, "s'": s1, "s''": s2,
    }


HORIZONTAL = dict(guide_point=(0.0, OFFSET), guide_dir=(1.0, 0.0))
VERTICAL = dict(guide_point=(OFFSET, 0.0), guide_dir=(0.0, 1.0))


def course_press_oracle(phi, omega, eps, f_ext, guide_point, guide_dir, gravity=(0.0, -G)):
    """The course's step-by-step kinetostatics of the slider-crank (group 2-3, then the crank).

    Loads: gravity of the three links, inertia of the rod (at S2, and -J_S2 eps2) and of the
    slider (at B), and the external force ``f_ext`` on the slider at B. The crank's centre of mass
    is at O (no inertia force, J = 0).
    """
    kin = slider_crank_kinematics(phi, guide_point, guide_dir)
    u = np.asarray(guide_dir, float) / np.hypot(*guide_dir)
    n = np.array([-u[1], u[0]])
    w = np.broadcast_to(np.asarray(omega, float), phi.shape)
    e = np.broadcast_to(np.asarray(eps, float), phi.shape)
    g = np.asarray(gravity, float)
    acc = lambda q: kin[q + "''"] * (w**2)[:, None] + kin[q + "'"] * e[:, None]  # noqa: E731
    aS2, aB = acc("S2"), acc("B")
    eps2 = kin["th2''"] * w**2 + kin["th2'"] * e
    A, B, S2 = kin["A"], kin["B"], kin["S2"]
    # applied + inertia loads on each link
    P1 = np.tile(M1 * g, (len(phi), 1))
    P2 = M2 * g - M2 * aS2
    Mi2 = -J2 * eps2
    P3 = M3 * g - M3 * aB + np.broadcast_to(np.asarray(f_ext, float), (len(phi), 2))
    # group 2-3
    # (1) along the guide, on the whole group: the guide's reaction is normal to it
    F21_u = -((P2 + P3) @ u)
    # (2) moments on link 2 about B: (A-B) x F21 + (S2-B) x P2 + Mi2 = 0
    AB, SB = A - B, S2 - B
    F21_n = -(F21_u * cross(AB, np.tile(u, (len(phi), 1))) + cross(SB, P2) + Mi2) / \
        cross(AB, np.tile(n, (len(phi), 1)))
    F21 = F21_u[:, None] * u + F21_n[:, None] * n
    # (3) normal to the guide, on the whole group
    F30 = (-((F21 + P2 + P3) @ n))[:, None] * n
    # (4) link 2 alone: F21 + P2 + F23 = 0
    F23 = -(F21 + P2)
    # link 3 alone about B: every force acts at B, so the guide's moment on the slider is zero
    M30 = np.zeros(len(phi))
    # crank: moments about O, then its balance
    F12 = -F21
    Mb = -cross(A, F12)  # G1 acts at O
    F10 = -(F12 + P1)
    return {"F21": F21, "F23": F23, "F30": F30, "F10": F10, "M30": M30, "Mb": Mb, "kin": kin}


def press(vertical: bool) -> linkage.Mechanism:
    if not vertical:
        return linkage.load("slider_crank")
    # the shipped upright press, given the course masses (whatever it declares itself)
    data = to_dict(linkage.load("slider_crank_vertical"))
    links = data["links"]
    assert links["2"]["points"]["S2"] == pytest.approx([LS2, 0.0])
    links["1"].update(mass=M1, com=[0.0, 0.0], inertia=0.0)
    links["2"].update(mass=M2, com=links["2"]["points"]["S2"], inertia=J2)
    links["3"].update(mass=M3, com=links["3"]["points"]["B"], inertia=0.0)
    return from_dict(data)


# ----------------------------------------------------------------------------------------------
# 1. the course oracle
# ----------------------------------------------------------------------------------------------


def test_course_press_declares_the_course_masses():
    mech = linkage.load("slider_crank")
    L = mech.links
    assert (L["1"].mass, L["2"].mass, L["2"].inertia, L["3"].mass) == (M1, M2, J2, M3)
    assert L["2"].center_of_mass == pytest.approx((LS2, 0.0))
    assert L["1"].center_of_mass == (0.0, 0.0) and L["3"].center_of_mass == L["3"].points["B"]


@pytest.mark.parametrize("geometry", [HORIZONTAL, VERTICAL], ids=["horizontal", "vertical"])
def test_oracle_kinematics_self_consistent(geometry):
    """The oracle's analogs agree with its own positions by finite differences (guards the test)."""
    h = 1e-3
    kin = slider_crank_kinematics(PHI, **geometry)
    stencil = {o: slider_crank_kinematics(PHI + o * h, **geometry) for o in (-2, -1, 1, 2)}
    for q in ("B", "S2", "th2"):
        v = {o: stencil[o][q] for o in stencil}
        if q == "th2":
            v = {o: np.unwrap(np.stack([kin[q], v[o]]), axis=0)[1] for o in v}
        d1 = (v[-2] - 8 * v[-1] + 8 * v[1] - v[2]) / (12 * h)
        d2 = (-v[-2] + 16 * v[-1] - 30 * kin[q] + 16 * v[1] - v[2]) / (12 * h**2)
        assert np.max(np.abs(d1 - kin[q + "'"])) < 1e-9
        assert np.max(np.abs(d2 - kin[q + "''"])) < 1e-6


def test_oracle_kinematics_match_method_formulas():
    """Horizontal case: the textbook formulas for x_B, i21 and x_B'."""
    kin = slider_crank_kinematics(PHI, **HORIZONTAL)
    xB = L1 * np.cos(PHI) + np.sqrt(L2**2 - (L1 * np.sin(PHI) - OFFSET) ** 2)
    th2 = kin["th2"]
    i21 = -L1 * np.cos(PHI) / (L2 * np.cos(th2))
    xB1 = -L1 * np.sin(PHI) - L2 * np.sin(th2) * i21
    np.testing.assert_allclose(kin["B"][:, 0], xB, rtol=0, atol=1e-15)
    np.testing.assert_allclose(kin["B"][:, 1], OFFSET, rtol=0, atol=1e-15)
    np.testing.assert_allclose(kin["th2'"], i21, rtol=0, atol=1e-13)
    np.testing.assert_allclose(kin["B'"][:, 0], xB1, rtol=0, atol=1e-15)


EPS_CASES = {
    "eps=0": 0.0,
    "eps=const": 37.5,
    "eps=array": 40.0 * np.sin(PHI) - 15.0,
}


@pytest.mark.parametrize("vertical", [False, True], ids=["horizontal", "vertical"])
@pytest.mark.parametrize("eps_name", list(EPS_CASES))
def test_course_press_reactions(vertical, eps_name):
    eps = EPS_CASES[eps_name]
    geometry = VERTICAL if vertical else HORIZONTAL
    mech = press(vertical)
    f_ext = (-12000.0, 1500.0) if not vertical else (800.0, -12000.0)
    loads = Loads(gravity=(0.0, -G), forces=(PointForce("B", "3", f_ext),))
    motion = linkage.analyze(mech, PHI, omega=OMEGA, eps=eps)
    r = solve_reactions(motion, loads)
    ref = course_press_oracle(PHI, OMEGA, eps, f_ext, **geometry)

    # the library's positions are the same mechanism (not a tolerance on forces: a sanity check)
    assert np.max(np.abs(motion.point("B") - ref["kin"]["B"])) < 1e-14

    tol = 1e-9
    assert rel_err(r.on("2", "1"), ref["F21"]) < tol
    assert rel_err(r.on("1", "2"), -ref["F21"]) < tol
    assert rel_err(r.on("2", "3"), ref["F23"]) < tol
    assert rel_err(r.on("3", "2"), -ref["F23"]) < tol
    assert rel_err(r.on("3", "0"), ref["F30"]) < tol
    assert rel_err(r.on("0", "3"), -ref["F30"]) < tol
    assert rel_err(r.on("1", "0"), ref["F10"]) < tol
    assert rel_err(r.balancing_moment, ref["Mb"]) < tol
    # the guide's reaction is normal to the guide
    u = np.array(geometry["guide_dir"], float)
    assert np.max(np.abs(r.on("3", "0") @ u)) <= 1e-9 * np.max(np.hypot(*ref["F30"].T))
    # guide moment: zero (all slider loads act at B)
    assert np.max(np.abs(r.moment("slide"))) <= 1e-9 * np.max(np.hypot(*ref["F30"].T)) * L2

    # per-pair reports: R[a, b] for the pair declared links = [a, b]
    declared = {"O": ("0", "1", -ref["F10"]), "A": ("1", "2", -ref["F21"]),
                "B": ("2", "3", ref["F23"]), "slide": ("0", "3", -ref["F30"])}
    for pair, (a, b, expected) in declared.items():
        assert tuple(mech.pairs[pair].links) == (a, b)
        assert rel_err(r.force(pair), expected) < tol
        mag = np.hypot(*expected.T)
        assert rel_err(r.magnitude(pair), mag) < tol
        ang = np.degrees(np.arctan2(expected[:, 1], expected[:, 0]))
        diff = (r.direction_deg(pair) - ang + 180.0) % 360.0 - 180.0
        big = mag > 1e-6 * mag.max()
        assert np.max(np.abs(diff[big])) < 1e-7


def test_course_press_without_external_force_or_speed_is_statics():
    """Gravity only, no speed: the crank holds the weight; M_b = -sum m g.r'_S (exact analogs)."""
    mech = linkage.load("slider_crank")
    r = solve_reactions(linkage.analyze(mech, PHI), Loads(gravity=(0.0, -G)))
    kin = slider_crank_kinematics(PHI, **HORIZONTAL)
    expected = -(M2 * (-G) * kin["S2'"][:, 1] + M3 * (-G) * kin["B'"][:, 1])
    assert rel_err(r.balancing_moment, expected) < 1e-9
    assert any("static" in note for note in r.notes)


# ----------------------------------------------------------------------------------------------
# 2. virtual power (Zhukovsky) on every shipped scheme
# ----------------------------------------------------------------------------------------------


def _loaded_scheme(name: str):
    """The shipped scheme with masses on every moving link, an external force and a moment.

    Returns the mechanism and a description of the loads for the independent power balance.
    """
    data = to_dict(linkage.load(name))
    moving = sorted(k for k in data["links"] if k != data["frame"])
    for i, k in enumerate(moving):
        spec = data["links"][k]
        if spec.get("mass"):
            continue
        pts = np.array(list(spec["points"].values()), float)
        centre = pts.mean(axis=0) + np.array([0.004 * (i + 1), -0.003 * (i + 1)])
        spec.update(mass=1.5 + 0.7 * i, com=centre.tolist(), inertia=0.002 + 0.001 * i)
    # an external force at a point of the last moving link; moments on the second moving link
    # and on the first non-input link that turns (they do work: the balance sees them)
    last = moving[-1]
    point = sorted(data["links"][last]["points"])[-1]
    force = [-350.0, 120.0]
    shipped = linkage.load(name)
    turning = linkage.analyze(shipped, positions(shipped), order=1).first
    crank = shipped.inputs[0]
    rotating = [k for k in moving if k != crank and np.ptp(turning[k][:, 2]) > 1e-6] or [crank]
    moments = [(moving[1], -17.5), (rotating[0], 6.25)]
    data["loads"] = {
        "gravity": [0.0, -G],
        "forces": [{"point": point, "link": last, "force": force}],
        "moments": [{"link": k, "moment": m} for k, m in moments],
    }
    mech = from_dict(data, name)
    extras = {"force": (last, point, np.array(force)), "moments": moments}
    return mech, extras


def _rigid(motion, link, local):
    """Position, velocity analog and acceleration analog of a point fixed in a link."""
    pose, d1, d2 = motion.poses[link], motion.first[link], motion.second[link]
    th = pose[:, 2]
    p = np.asarray(local, float)
    rp = np.stack([np.cos(th) * p[0] - np.sin(th) * p[1], np.sin(th) * p[0] + np.cos(th) * p[1]], axis=1)
    erp = np.stack([-rp[:, 1], rp[:, 0]], axis=1)
    v = d1[:, :2] + d1[:, 2:3] * erp
    a = d2[:, :2] + d2[:, 2:3] * erp - (d1[:, 2:3] ** 2) * rp
    return pose[:, :2] + rp, v, a


def _power_balance(reactions, mech, extras, omega, eps):
    """Independent Zhukovsky balance: M_b w + sum F.v + M w_k (loads recomputed here)."""
    motion = reactions.motion
    w = np.broadcast_to(omega, PHI.shape)
    e = np.broadcast_to(eps, PHI.shape)
    g = np.array([0.0, -G])
    powers = [reactions.balancing_moment * w]
    for k in mech.inputs[1:]:      # further inputs: their own balancing moments at their own speeds
        powers.append(reactions.balancing_moments[k] * motion.first[k][:, 2] * w)
    for k in mech.moving_links:
        link = mech.links[k]
        _, v1, a2 = _rigid(motion, k, link.center_of_mass)
        vS = v1 * w[:, None]
        aS = a2 * (w**2)[:, None] + v1 * e[:, None]
        wk = motion.first[k][:, 2] * w
        ek = motion.second[k][:, 2] * w**2 + motion.first[k][:, 2] * e
        powers.append(np.einsum("ni,ni->n", link.mass * g - link.mass * aS, vS))
        powers.append(-link.inertia * ek * wk)
    flink, fpoint, fvec = extras["force"]
    _, v1, _ = _rigid(motion, flink, mech.links[flink].points[fpoint])
    powers.append((v1 * w[:, None]) @ fvec)
    for mlink, mval in extras["moments"]:
        powers.append(mval * motion.first[mlink][:, 2] * w)
    powers = np.array(powers)
    return np.abs(powers.sum(axis=0)) / np.abs(powers).sum(axis=0)


SCHEMES = list(linkage.shipped_schemes())


@pytest.mark.parametrize("name", SCHEMES)
def test_virtual_power_every_shipped_scheme(name):
    mech, extras = _loaded_scheme(name)
    assert all(mech.links[k].mass > 0 for k in mech.moving_links)
    assert not loads_of(mech).notes
    # eps: rad/s^2 for a crank, m/s^2 for a slide (its speed, m/s, times 1/s)
    omega, eps = speed(mech), (23.0 * np.cos(PHI) + 4.0) * abs(speed(mech) / OMEGA)
    motion = linkage.analyze(mech, positions(mech), omega=omega, eps=eps)
    r = solve_reactions(motion)
    kinds = {t.kind for t in r.terms}
    assert kinds == {"gravity", "inertia", "external"}
    assert np.all(np.isfinite(r.balancing_moment))
    assert np.max(virtual_power_residual(r)) <= 1e-9
    assert np.max(_power_balance(r, mech, extras, omega, eps)) <= 1e-9


def test_every_dyad_kind_is_exercised():
    kinds = {g.kind for name in SCHEMES for g in linkage.structure_of(linkage.load(name)).groups}
    assert {"RRR", "RRP", "RPR", "PRP", "RPP"} <= kinds


@pytest.mark.parametrize("name", SCHEMES)
def test_action_equals_reaction_every_shipped_scheme(name):
    mech, _ = _loaded_scheme(name)
    r = solve_reactions(linkage.analyze(mech, positions(mech), omega=speed(mech), eps=5.0))
    for pair in mech.pairs.values():
        a, b = pair.links
        np.testing.assert_array_equal(r.on(a, b), -r.on(b, a))


# ----------------------------------------------------------------------------------------------
# 3. the four-bar: every link in equilibrium under the reported reactions
# ----------------------------------------------------------------------------------------------

FB = dict(l1=0.1, l2=0.3, l3=0.25, C=np.array([0.3, 0.0]), m1=1.0, m2=3.0, J2=0.0225, m3=2.0,
          J3=0.0104167, s2=0.15, s3=0.125, E=(0.15 * math.cos(math.radians(30)),
                                                0.15 * math.sin(math.radians(30))))


def four_bar_kinematics(phi):
    """Closed-form four-bar O-A-B-C (B left of A -> C) and exact analogs from the loop equation."""
    l1, l2, l3, C = FB["l1"], FB["l2"], FB["l3"], FB["C"]
    A = l1 * unit(phi)
    d = C - A
    D = np.hypot(*d.T)
    a = (l2**2 - l3**2 + D**2) / (2 * D)
    h = np.sqrt(l2**2 - a**2)
    e = d / D[:, None]
    B = A + a[:, None] * e + h[:, None] * np.stack([-e[:, 1], e[:, 0]], axis=1)
    th2 = np.arctan2(*(B - A).T[::-1])
    th3 = np.arctan2(*(B - C).T[::-1])
    # A + l2 e2 - C - l3 e3 = 0  ->  M [th2', th3'] = -l1 e1perp
    Mx = np.stack([l2 * unit_perp(th2), -l3 * unit_perp(th3)], axis=2)
    t1 = np.linalg.solve(Mx, (-l1 * unit_perp(phi))[..., None])[..., 0]
    rhs2 = (l1 * unit(phi) + l2 * (t1[:, 0] ** 2)[:, None] * unit(th2)
            - l3 * (t1[:, 1] ** 2)[:, None] * unit(th3))
    t2 = np.linalg.solve(Mx, rhs2[..., None])[..., 0]
    return {"A": A, "B": B, "th1": phi, "th2": th2, "th3": th3,
            "th2'": t1[:, 0], "th3'": t1[:, 1], "th2''": t2[:, 0], "th3''": t2[:, 1]}


def _point_on(kin, link, local, phi):
    """Position, analog and second analog of a point fixed in link 1, 2 or 3 of the four-bar."""
    base = {"1": np.zeros((len(phi), 2)), "2": kin["A"], "3": np.tile(FB["C"], (len(phi), 1))}[link]
    th = {"1": phi, "2": kin["th2"], "3": kin["th3"]}[link]
    t1 = {"1": np.ones_like(phi), "2": kin["th2'"], "3": kin["th3'"]}[link]
    t2 = {"1": np.zeros_like(phi), "2": kin["th2''"], "3": kin["th3''"]}[link]
    b1 = {"1": 0 * base, "2": FB["l1"] * unit_perp(phi), "3": 0 * base}[link]
    b2 = {"1": 0 * base, "2": -FB["l1"] * unit(phi), "3": 0 * base}[link]
    px, py = local
    r = np.stack([np.cos(th) * px - np.sin(th) * py, np.sin(th) * px + np.cos(th) * py], axis=1)
    er = np.stack([-r[:, 1], r[:, 0]], axis=1)
    return base + r, b1 + t1[:, None] * er, b2 + t2[:, None] * er - (t1**2)[:, None] * r


def test_four_bar_oracle_self_consistent():
    h = 1e-3
    kin = four_bar_kinematics(PHI)
    st = {o: four_bar_kinematics(PHI + o * h) for o in (-2, -1, 1, 2)}
    for q in ("th2", "th3"):
        v = {o: np.unwrap(np.stack([kin[q], st[o][q]]), axis=0)[1] for o in st}
        d1 = (v[-2] - 8 * v[-1] + 8 * v[1] - v[2]) / (12 * h)
        d2 = (-v[-2] + 16 * v[-1] - 30 * kin[q] + 16 * v[1] - v[2]) / (12 * h**2)
        assert np.max(np.abs(d1 - kin[q + "'"])) < 1e-8
        assert np.max(np.abs(d2 - kin[q + "''"])) < 1e-5
    mech = linkage.load("four_bar")
    motion = linkage.analyze(mech, PHI, order=0)
    assert np.max(np.abs(motion.point("B") - kin["B"])) < 1e-14


@pytest.mark.parametrize("omega, eps", [(OMEGA, 0.0), (10.0, -30.0), (OMEGA, 12.0 * np.sin(2 * PHI))])
def test_four_bar_every_link_in_equilibrium(omega, eps):
    mech = linkage.load("four_bar")
    f_E, m_3 = np.array([40.0, -25.0]), 3.5
    loads = Loads(gravity=(0.0, -G), forces=(PointForce("E", "2", tuple(f_E)),),
                  moments=(LinkMoment("3", m_3),))
    r = solve_reactions(linkage.analyze(mech, PHI, omega=omega, eps=eps), loads)

    kin = four_bar_kinematics(PHI)
    w = np.broadcast_to(omega, PHI.shape)
    e = np.broadcast_to(eps, PHI.shape)
    g = np.array([0.0, -G])
    O, A, B, C = np.zeros((N, 2)), kin["A"], kin["B"], np.tile(FB["C"], (N, 1))
    S = {"1": _point_on(kin, "1", (0.0, 0.0), PHI), "2": _point_on(kin, "2", (FB["s2"], 0.0), PHI),
         "3": _point_on(kin, "3", (FB["s3"], 0.0), PHI)}
    mass = {"1": FB["m1"], "2": FB["m2"], "3": FB["m3"]}
    J = {"1": 0.0, "2": FB["J2"], "3": FB["J3"]}
    eps_k = {"1": e, "2": kin["th2''"] * w**2 + kin["th2'"] * e, "3": kin["th3''"] * w**2 + kin["th3'"] * e}
    E = _point_on(kin, "2", FB["E"], PHI)[0]

    # (force, point) lists and pure moments acting on each link
    forces = {k: [] for k in "123"}
    moments = {k: [] for k in "123"}
    for k in "123":
        pos, v1, a2 = S[k]
        aS = a2 * (w**2)[:, None] + v1 * e[:, None]
        forces[k] += [(np.tile(mass[k] * g, (N, 1)), pos), (-mass[k] * aS, pos)]
        moments[k].append(-J[k] * eps_k[k])
    forces["2"].append((np.tile(f_E, (N, 1)), E))
    moments["3"].append(np.full(N, m_3))
    moments["1"].append(r.balancing_moment)
    joints = {("1", "0"): O, ("1", "2"): A, ("2", "1"): A, ("2", "3"): B, ("3", "2"): B, ("3", "0"): C}
    for (i, j), at in joints.items():
        forces[i].append((r.on(i, j), at))

    scale_f = max(np.max(np.hypot(*f.T)) for k in forces for f, _ in forces[k])
    scale_m = scale_f * 0.4
    for k in "123":
        total_f = sum(f for f, _ in forces[k])
        total_m = sum(cross(p, f) for f, p in forces[k]) + sum(moments[k])
        assert np.max(np.hypot(*total_f.T)) <= 1e-9 * scale_f, f"link {k}: force balance"
        assert np.max(np.abs(total_m)) <= 1e-9 * scale_m, f"link {k}: moment balance"
    for i, j in [("1", "0"), ("1", "2"), ("2", "3"), ("3", "0")]:
        np.testing.assert_allclose(r.on(i, j), -r.on(j, i), rtol=0, atol=1e-12 * scale_f)


# ----------------------------------------------------------------------------------------------
# 4. statics by virtual work
# ----------------------------------------------------------------------------------------------


def test_four_bar_static_balancing_moment_by_virtual_work():
    mech = linkage.load("four_bar")
    motion = linkage.analyze(mech, PHI)  # omega = None: no inertia
    assert motion.omega is None
    r = solve_reactions(motion)
    assert not any(t.kind == "inertia" for t in r.terms)

    def com_heights(phi):
        kin = four_bar_kinematics(phi)
        return (_point_on(kin, "2", (FB["s2"], 0.0), phi)[0][:, 1],
                _point_on(kin, "3", (FB["s3"], 0.0), phi)[0][:, 1])

    h = 1e-3
    ys = {o: com_heights(PHI + o * h) for o in (-2, -1, 1, 2)}
    dy = [(ys[-2][i] - 8 * ys[-1][i] + 8 * ys[1][i] - ys[2][i]) / (12 * h) for i in range(2)]
    # M_b dphi + sum m g . dr_S = 0, g = (0, -9.81); the crank's centre is at O (y' = 0)
    expected = -(FB["m2"] * (-G) * dy[0] + FB["m3"] * (-G) * dy[1])
    assert rel_err(r.balancing_moment, expected) < 1e-8
    assert any("static" in note for note in r.notes)


def test_static_with_zero_gravity_needs_no_moment():
    data = to_dict(linkage.load("four_bar"))
    data["loads"] = {"gravity": [0.0, 0.0]}
    r = solve_reactions(linkage.analyze(from_dict(data), PHI))
    assert np.all(r.balancing_moment == 0.0)
    for name in data["pairs"]:
        assert np.all(r.magnitude(name) == 0.0)


def test_inertia_needs_second_analogs():
    mech = linkage.load("four_bar")
    with pytest.raises(ValueError):
        solve_reactions(linkage.analyze(mech, PHI, order=1, omega=OMEGA))


def test_unknown_pair_in_on():
    r = solve_reactions(linkage.analyze(linkage.load("four_bar"), PHI[:3]))
    with pytest.raises(ValueError, match="no pair"):
        r.on("1", "3")
    with pytest.raises(ValueError, match="revolute"):
        r.moment("A")
    with pytest.raises(SchemeError):
        loads_of(linkage.load("four_bar").with_extra(loads={"gravity": "down"}))
