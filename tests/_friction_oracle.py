"""An oracle for Coulomb friction in the pairs (tests/test_friction_oracle.py), independent of the library.

Two mechanisms, each declared by a scheme text built from the parameters below and solved here
without the library:

- closed-form kinematics (positions and the first and second analogs d/dphi) of an offset
  slider-crank on a possibly tilted guide and of a four-bar by circle intersection;
- the Newton-Euler (d'Alembert) equations of every moving link: 3 per link (forces along x, y and
  the moment about the global origin) in the unknown pair reactions, the prismatic normal force
  and moment, and the balancing moment on the crank; gravity ``m g`` and the inertia force
  ``-m a_S`` at the centre of mass S, the inertia moment ``-J_S eps_k``, the external loads;
- Coulomb friction: in a revolute pair between links i and j the moment ``-f r |R| sign(w_i - w_j)``
  on i and its opposite on j; in the slide the force ``-f P sign(v_slide) u`` on the slider at its
  point B (``P = |N|``, or ``|N1| + |N2|`` with ``N1, N2 = N/2 +- M/L`` for a block of length L);
  solved by a fixed point on the friction magnitudes (one numpy linear solve per iterate).

Conventions of the unknowns (named ``F<i><j>``: the force link j exerts on link i, N): the slider
crank has F10, F12, F23, N (guide on slider along n = perp(u)), M (guide on slider, about B) and
Mb; the four-bar F10, F12, F23, F30 and Mb. Everything is per position, arrays (N, ...).
"""

from __future__ import annotations

import math

import numpy as np

GRAVITY = np.array([0.0, -9.81])

# -- the mechanisms' data (shared by the scheme texts and the oracle) -----------------------------

SLIDER_CRANK = {
    "crank": 0.08, "rod": 0.25,
    # link: mass kg, centre of mass (distance m, angle deg from the link's line; slider: local x, y), J_S kg m^2
    "m1": 2.0, "s1": (0.03, 25.0), "j1": 0.004,
    "m2": 5.0, "s2": (0.09, -8.0), "j2": 0.03,
    "m3": 3.0, "s3": (0.02, 0.015), "j3": 0.002,
    "k3": (0.05, -0.01), "force_k": (-600.0, 150.0),     # external force on the slider at its point K, N
    "moment2": 4.0,                                     # external moment on the rod, N m
    "friction": {"O": (0.1, 0.02), "A": (0.08, 0.025), "B": (0.12, 0.015)}, "f_slide": 0.15,
}

FOUR_BAR = {
    "crank": 0.1, "coupler": 0.3, "rocker": 0.25, "ground": 0.3,
    "m1": 1.0, "s1": (0.02, 40.0), "j1": 0.001,
    "m2": 3.0, "s2": (0.15, 12.0), "j2": 0.0225,
    "m3": 2.0, "s3": (0.125, -10.0), "j3": 0.0104,
    "moment3": -5.0,                                    # external moment on the rocker, N m
    "friction": {"O": (0.1, 0.02), "A": (0.07, 0.015), "B": (0.12, 0.01), "C": (0.09, 0.025)},
}


def slider_crank_text(through=(0.0, 0.02), angle_deg=0.0, length=None, scale=1.0) -> str:
    """The slider-crank's scheme: guide through ``through`` at ``angle_deg``; ``length`` of the
    slider block (None: one contact); every f multiplied by ``scale``."""
    p = SLIDER_CRANK
    fr = {k: (f * scale, r) for k, (f, r) in p["friction"].items()}
    block = f", length = {length!r}" if length else ""
    return f"""
name = "slider_crank_friction_oracle"
input = "1"
[links.0]
points = {{ O = [0.0, 0.0] }}
guides.slide = {{ through = [{through[0]!r}, {through[1]!r}], angle_deg = {angle_deg!r} }}
[links.1]
line = ["O", "A"]
length = {p["crank"]!r}
points.S1 = {{ from = "O", distance = {p["s1"][0]!r}, angle_deg = {p["s1"][1]!r} }}
mass = {p["m1"]!r}
com = "S1"
inertia = {p["j1"]!r}
[links.2]
line = ["A", "B"]
length = {p["rod"]!r}
points.S2 = {{ from = "A", distance = {p["s2"][0]!r}, angle_deg = {p["s2"][1]!r} }}
mass = {p["m2"]!r}
com = "S2"
inertia = {p["j2"]!r}
[links.3]
points.B = [0.0, 0.0]
points.S3 = [{p["s3"][0]!r}, {p["s3"][1]!r}]
points.K = [{p["k3"][0]!r}, {p["k3"][1]!r}]
mass = {p["m3"]!r}
com = "S3"
inertia = {p["j3"]!r}
[pairs.O]
links = ["0", "1"]
[pairs.A]
links = ["1", "2"]
[pairs.B]
links = ["2", "3"]
[pairs.slide]
kind = "P"
links = ["0", "3"]
guide = "slide"
at = "B"
[assembly.B]
from = "O"
towards_deg = {angle_deg!r}
[loads]
gravity = [{float(GRAVITY[0])!r}, {float(GRAVITY[1])!r}]
[[loads.forces]]
point = "K"
link = "3"
force = [{p["force_k"][0]!r}, {p["force_k"][1]!r}]
[[loads.moments]]
link = "2"
moment = {p["moment2"]!r}
[friction]
revolute = {{ f = {fr["O"][0]!r}, radius = {fr["O"][1]!r} }}
prismatic = {{ f = {p["f_slide"] * scale!r}{block} }}
pairs.A = {{ f = {fr["A"][0]!r}, radius = {fr["A"][1]!r} }}
pairs.B = {{ f = {fr["B"][0]!r}, radius = {fr["B"][1]!r} }}
"""


def four_bar_text(scale=1.0) -> str:
    """The four-bar's scheme, every f multiplied by ``scale``."""
    p = FOUR_BAR
    fr = {k: (f * scale, r) for k, (f, r) in p["friction"].items()}
    return f"""
name = "four_bar_friction_oracle"
input = "1"
[links.0]
points = {{ O = [0.0, 0.0], C = [{p["ground"]!r}, 0.0] }}
[links.1]
line = ["O", "A"]
length = {p["crank"]!r}
points.S1 = {{ from = "O", distance = {p["s1"][0]!r}, angle_deg = {p["s1"][1]!r} }}
mass = {p["m1"]!r}
com = "S1"
inertia = {p["j1"]!r}
[links.2]
line = ["A", "B"]
length = {p["coupler"]!r}
points.S2 = {{ from = "A", distance = {p["s2"][0]!r}, angle_deg = {p["s2"][1]!r} }}
mass = {p["m2"]!r}
com = "S2"
inertia = {p["j2"]!r}
[links.3]
line = ["C", "B"]
length = {p["rocker"]!r}
points.S3 = {{ from = "C", distance = {p["s3"][0]!r}, angle_deg = {p["s3"][1]!r} }}
mass = {p["m3"]!r}
com = "S3"
inertia = {p["j3"]!r}
[pairs.O]
links = ["0", "1"]
[pairs.A]
links = ["1", "2"]
[pairs.B]
links = ["2", "3"]
[pairs.C]
links = ["3", "0"]
[assembly.B]
left_of = ["A", "C"]
[loads]
gravity = [{float(GRAVITY[0])!r}, {float(GRAVITY[1])!r}]
[[loads.moments]]
link = "3"
moment = {p["moment3"]!r}
[friction]
revolute = {{ f = {fr["O"][0]!r}, radius = {fr["O"][1]!r} }}
pairs.A = {{ f = {fr["A"][0]!r}, radius = {fr["A"][1]!r} }}
pairs.B = {{ f = {fr["B"][0]!r}, radius = {fr["B"][1]!r} }}
pairs.C = {{ f = {fr["C"][0]!r}, radius = {fr["C"][1]!r} }}
"""


# -- vectors ----------------------------------------------------------------------------------------


def unit(theta):
    return np.stack([np.cos(theta), np.sin(theta)], axis=-1)


def perp(v):
    return np.stack([-v[..., 1], v[..., 0]], axis=-1)


def cross(a, b):
    return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]


def dot(a, b):
    return np.sum(a * b, axis=-1)


def carried(origin, theta, local):
    """A point fixed on a link: its position and first and second analogs (each (N, 2)) from the
    link's origin (P, P', P'') and angle (t, t', t''), ``local`` in the link's frame."""
    (p0, p1, p2), (t0, t1, t2) = origin, theta
    e = unit(t0)
    rho = local[0] * e + local[1] * perp(e)
    return p0 + rho, p1 + t1[:, None] * perp(rho), p2 + t2[:, None] * perp(rho) - (t1**2)[:, None] * rho


def polar(distance, angle_deg):
    """Local coordinates of a point ``distance`` from a link's origin, ``angle_deg`` CCW from its line."""
    return distance * math.cos(math.radians(angle_deg)), distance * math.sin(math.radians(angle_deg))


# -- closed-form kinematics ---------------------------------------------------------------------------


def slider_crank_kinematics(phi, through=(0.0, 0.02), angle_deg=0.0) -> dict:
    """Offset slider-crank on the guide through ``through`` along ``u = (cos a, sin a)``, slider B
    ahead along u: ``s = u.(A - g) + sqrt(l^2 - (n.(A - g))^2)`` (for a = 0 and g = (0, e):
    ``x_B = r cos phi + sqrt(l^2 - (r sin phi - e)^2)``), ``theta_2 = a - asin(n.(A - g)/l)``.

    Returns ``points`` name -> (P, P', P'') (N, 2), ``theta`` link -> (t, t', t'') (N,),
    ``slide`` (s, s', s'') (N,), ``u``, ``n`` (2,)."""
    p = SLIDER_CRANK
    r, l = p["crank"], p["rod"]
    phi = np.asarray(phi, float)
    zero, one = np.zeros_like(phi), np.ones_like(phi)
    alpha = math.radians(angle_deg)
    u = np.array([math.cos(alpha), math.sin(alpha)])
    n = perp(u)
    g = np.array(through, float)
    a0 = r * unit(phi)
    a1 = r * perp(unit(phi))
    a2 = -a0
    h0, h1, h2 = (a0 - g) @ n, a1 @ n, a2 @ n
    w0 = np.sqrt(l**2 - h0**2)
    w1 = -h0 * h1 / w0
    w2 = -(h1**2 + h0 * h2) / w0 - h0**2 * h1**2 / w0**3
    s0, s1, s2 = (a0 - g) @ u + w0, a1 @ u + w1, a2 @ u + w2
    b = (g + s0[:, None] * u, s1[:, None] * u, s2[:, None] * u)
    rod = (alpha + np.arctan2(-h0, w0), -h1 / w0, -h2 / w0 + h1 * w1 / w0**2)
    crank, slider = (phi, one, zero), (np.full_like(phi, alpha), zero, zero)
    origin = (np.zeros((len(phi), 2)),) * 3
    points = {"O": origin, "A": (a0, a1, a2), "B": b,
              "S1": carried(origin, crank, polar(*p["s1"])),
              "S2": carried((a0, a1, a2), rod, polar(*p["s2"])),
              "S3": carried(b, slider, p["s3"]), "K": carried(b, slider, p["k3"])}
    return {"points": points, "theta": {"1": crank, "2": rod, "3": slider}, "slide": (s0, s1, s2), "u": u, "n": n}


def four_bar_kinematics(phi) -> dict:
    """Four-bar O-A-B-C: B the intersection of the circles (A, AB) and (C, CB) on the left of
    A -> C; the angular analogs from the differentiated loop ``A + l2 e2 = C + l3 e3``."""
    p = FOUR_BAR
    r1, l2, l3 = p["crank"], p["coupler"], p["rocker"]
    phi = np.asarray(phi, float)
    zero, one = np.zeros_like(phi), np.ones_like(phi)
    c = np.array([p["ground"], 0.0])
    a0 = r1 * unit(phi)
    a1 = r1 * perp(unit(phi))
    a2 = -a0
    dist = np.linalg.norm(c - a0, axis=1)
    e = (c - a0) / dist[:, None]
    along = (l2**2 - l3**2 + dist**2) / (2 * dist)
    b0 = a0 + along[:, None] * e + np.sqrt(l2**2 - along**2)[:, None] * perp(e)
    t2 = np.arctan2(*(b0 - a0)[:, ::-1].T)
    t3 = np.arctan2(*(b0 - c)[:, ::-1].T)
    e2, e3 = unit(t2), unit(t3)
    matrix = np.stack([l2 * perp(e2), -l3 * perp(e3)], axis=-1)         # columns: theta2', theta3'
    first = np.linalg.solve(matrix, -a1[..., None])[..., 0]
    w2, w3 = first[:, 0], first[:, 1]
    rhs = -a2 + l2 * (w2**2)[:, None] * e2 - l3 * (w3**2)[:, None] * e3
    second = np.linalg.solve(matrix, rhs[..., None])[..., 0]
    crank = (phi, one, zero)
    coupler = (t2, w2, second[:, 0])
    rocker = (t3, w3, second[:, 1])
    fixed = np.zeros((len(phi), 2))
    origin, pivot = (fixed,) * 3, (fixed + c, fixed, fixed)
    a = (a0, a1, a2)
    points = {"O": origin, "C": pivot, "A": a, "B": carried(a, coupler, (l2, 0.0)),
              "S1": carried(origin, crank, polar(*p["s1"])), "S2": carried(a, coupler, polar(*p["s2"])),
              "S3": carried(pivot, rocker, polar(*p["s3"]))}
    return {"points": points, "theta": {"1": crank, "2": coupler, "3": rocker}}


def real(track, omega, eps):
    """(position, velocity, acceleration) of an analog track (t, t', t'') at the input's speed."""
    t0, t1, t2 = track
    return t0, t1 * omega, t2 * omega**2 + t1 * eps


# -- Newton-Euler equations --------------------------------------------------------------------------


class Equations:
    """``A x = b`` over N positions: 3 rows per moving link (sum of forces x, y; sum of moments
    about the global origin), one column per unknown scalar."""

    def __init__(self, n: int, links: list[str], unknowns: list[tuple[str, int]]):
        self.rows = {k: 3 * i for i, k in enumerate(links)}
        self.cols: dict[str, int] = {}
        width = 0
        for name, size in unknowns:
            self.cols[name], width = width, width + size
        assert width == 3 * len(links)
        self.a = np.zeros((n, width, width))
        self.b = np.zeros((n, width))

    def force(self, link, force, at, b=None):
        """A known force (N, 2) at the point ``at`` (N, 2) on ``link``."""
        b = self.b if b is None else b
        r = self.rows[link]
        b[:, r] -= force[:, 0]
        b[:, r + 1] -= force[:, 1]
        b[:, r + 2] -= cross(at, force)

    def moment(self, link, moment, b=None):
        b = self.b if b is None else b
        b[:, self.rows[link] + 2] -= moment

    def unknown_force(self, link, name, at, sign=1.0):
        """The unknown vector ``name`` (2 columns), times ``sign``, acting on ``link`` at ``at``."""
        r, c = self.rows[link], self.cols[name]
        self.a[:, r, c] += sign
        self.a[:, r + 1, c + 1] += sign
        self.a[:, r + 2, c] += -sign * at[:, 1]
        self.a[:, r + 2, c + 1] += sign * at[:, 0]

    def unknown_along(self, link, name, direction, at):
        """The unknown scalar ``name`` times the unit ``direction`` (2,) acting on ``link`` at ``at``."""
        r, c = self.rows[link], self.cols[name]
        self.a[:, r, c] += direction[0]
        self.a[:, r + 1, c] += direction[1]
        self.a[:, r + 2, c] += cross(at, np.broadcast_to(direction, at.shape))

    def unknown_moment(self, link, name):
        self.a[:, self.rows[link] + 2, self.cols[name]] += 1.0

    def solve(self, extra):
        x = np.linalg.solve(self.a, (self.b + extra)[..., None])[..., 0]
        return {name: x[:, c:c + 2] if name.startswith("F") else x[:, c] for name, c in self.cols.items()}


def _loads(eq: Equations, kin: dict, data: dict, omega, eps, inertia: bool):
    """Gravity, inertia and the external loads on links 1, 2, 3 into ``eq``."""
    for k in "123":
        m, j = data[f"m{k}"], data[f"j{k}"]
        s, _, acc = real(kin["points"][f"S{k}"], omega, eps)
        eq.force(k, np.broadcast_to(m * GRAVITY, s.shape), s)
        if inertia:
            eq.force(k, -m * acc, s)
            eq.moment(k, -j * real(kin["theta"][k], omega, eps)[2])


def _fixed_point(eq: Equations, friction_rhs, tol=1e-14, limit=500):
    """Frictionless solution, then ``x = solve(b + friction(x))`` until no unknown changes by more
    than ``tol`` of the largest one. Returns the solution and the friction loads it carries."""
    x = eq.solve(0.0)
    for _ in range(limit):
        extra, _ = friction_rhs(x)
        new = eq.solve(extra)
        flat_new = np.column_stack([v.reshape(len(v), -1) for v in new.values()])
        flat_old = np.column_stack([v.reshape(len(v), -1) for v in x.values()])
        x = new
        if np.all(np.max(np.abs(flat_new - flat_old), axis=1) <= tol * np.max(np.abs(flat_new), axis=1)):
            return x, friction_rhs(x)[1]
    raise AssertionError("the oracle's friction iteration did not converge")


def _revolute(f, r, force, rel_rate):
    """Friction moment on the pair's first link (N,): ``-f r |R| sign(w_rel)``."""
    return -f * r * np.hypot(force[:, 0], force[:, 1]) * np.sign(rel_rate)


def slider_crank_oracle(phi, omega=None, eps=0.0, sense=1.0, through=(0.0, 0.02), angle_deg=0.0,
                        length=None, scale=1.0) -> dict:
    """Reactions of the slider-crank with friction. ``omega`` None: statics (no inertia), the
    friction opposing the motion in the ``sense`` of phi. Returns the unknowns (F10, F12, F23 (N, 2);
    N, M, Mb (N,)), ``friction`` (moment on the crank at O and A, on the rod at B, N m; force on the
    slider along u, N), ``rates`` (w1, w2, w3, v_slide at the speed) and the kinematics."""
    p = SLIDER_CRANK
    kin = slider_crank_kinematics(phi, through, angle_deg)
    speed = sense if omega is None else omega
    pts = {k: v[0] for k, v in kin["points"].items()}
    eq = Equations(len(kin["slide"][0]), ["1", "2", "3"],
                   [("F10", 2), ("F12", 2), ("F23", 2), ("N", 1), ("M", 1), ("Mb", 1)])
    eq.unknown_force("1", "F10", pts["O"])
    eq.unknown_force("1", "F12", pts["A"])
    eq.unknown_moment("1", "Mb")
    eq.unknown_force("2", "F12", pts["A"], -1.0)
    eq.unknown_force("2", "F23", pts["B"])
    eq.unknown_force("3", "F23", pts["B"], -1.0)
    eq.unknown_along("3", "N", kin["n"], pts["B"])
    eq.unknown_moment("3", "M")
    _loads(eq, kin, p, speed if omega is not None else 0.0, eps, omega is not None)
    force_k = np.broadcast_to(np.array(p["force_k"]), pts["K"].shape)
    eq.force("3", force_k, pts["K"])
    eq.moment("2", np.full(len(pts["K"]), p["moment2"]))
    w1, w2, w3 = (kin["theta"][k][1] * speed for k in "123")
    v_slide = kin["slide"][1] * speed
    fr = {k: (f * scale, r) for k, (f, r) in p["friction"].items()}
    f_slide = p["f_slide"] * scale

    def friction_rhs(x):
        extra = np.zeros_like(eq.b)
        m_o = _revolute(*fr["O"], x["F10"], w1)                     # on the crank from the frame
        m_a = _revolute(*fr["A"], x["F12"], w1 - w2)                # on the crank from the rod
        m_b = _revolute(*fr["B"], x["F23"], w2 - w3)                # on the rod from the slider
        if length:
            pressing = np.abs(x["N"] / 2 + x["M"] / length) + np.abs(x["N"] / 2 - x["M"] / length)
        else:
            pressing = np.abs(x["N"])
        slide = -f_slide * pressing * np.sign(v_slide)              # on the slider along u
        eq.moment("1", m_o + m_a, extra)
        eq.moment("2", -m_a + m_b, extra)
        eq.moment("3", -m_b, extra)
        eq.force("3", slide[:, None] * kin["u"], pts["B"], extra)
        return extra, {"O": m_o, "A": m_a, "B": m_b, "slide": slide}

    x, friction = _fixed_point(eq, friction_rhs)
    return dict(x, friction=friction, rates={"O": w1, "A": w1 - w2, "B": w2 - w3, "slide": v_slide}, kin=kin)


def four_bar_oracle(phi, omega=None, eps=0.0, sense=1.0, scale=1.0) -> dict:
    """Reactions of the four-bar with friction (as :func:`slider_crank_oracle`): F10, F12, F23,
    F30 (N, 2), Mb (N,), ``friction`` (moments on the crank at O and A, on the coupler at B, on the
    rocker at C, N m), ``rates`` (the relative angular velocities of those links)."""
    p = FOUR_BAR
    kin = four_bar_kinematics(phi)
    speed = sense if omega is None else omega
    pts = {k: v[0] for k, v in kin["points"].items()}
    eq = Equations(len(pts["A"]), ["1", "2", "3"], [("F10", 2), ("F12", 2), ("F23", 2), ("F30", 2), ("Mb", 1)])
    eq.unknown_force("1", "F10", pts["O"])
    eq.unknown_force("1", "F12", pts["A"])
    eq.unknown_moment("1", "Mb")
    eq.unknown_force("2", "F12", pts["A"], -1.0)
    eq.unknown_force("2", "F23", pts["B"])
    eq.unknown_force("3", "F23", pts["B"], -1.0)
    eq.unknown_force("3", "F30", pts["C"])
    _loads(eq, kin, p, speed if omega is not None else 0.0, eps, omega is not None)
    eq.moment("3", np.full(len(pts["A"]), p["moment3"]))
    w1, w2, w3 = (kin["theta"][k][1] * speed for k in "123")
    fr = {k: (f * scale, r) for k, (f, r) in p["friction"].items()}

    def friction_rhs(x):
        extra = np.zeros_like(eq.b)
        m_o = _revolute(*fr["O"], x["F10"], w1)
        m_a = _revolute(*fr["A"], x["F12"], w1 - w2)
        m_b = _revolute(*fr["B"], x["F23"], w2 - w3)
        m_c = _revolute(*fr["C"], x["F30"], w3)
        eq.moment("1", m_o + m_a, extra)
        eq.moment("2", -m_a + m_b, extra)
        eq.moment("3", -m_b + m_c, extra)
        return extra, {"O": m_o, "A": m_a, "B": m_b, "C": m_c}

    x, friction = _fixed_point(eq, friction_rhs)
    return dict(x, friction=friction, rates={"O": w1, "A": w1 - w2, "B": w2 - w3, "C": w3}, kin=kin)
