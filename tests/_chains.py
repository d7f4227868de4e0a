"""Random chains of dyads for ``test_fuzz_chains.py``: designs, mechanisms, an independent oracle.

A *shape* (:class:`ChainShape`) is a handful of nondimensional random numbers. :func:`realize`
turns it into a *design* (:class:`Chain`) the way a designer would: the mechanism is drawn in one
reference configuration (crank at ``phi0``) in global coordinates, every link gets a local frame,
and lengths, guide positions, pair angles and assembly branches are read off that drawing, so the
reference configuration is a known solution on a known branch. :func:`build` declares the design
through :class:`linkage.model.mechanism.MechanismBuilder` (in any declaration order); :func:`oracle` solves
the same design over input angles with closed forms written here (circle-circle, circle-line,
line-line and 2x2 linear intersections), independent of :mod:`assur`, and returns each group's
conditioning at its own scale (a nondimensional sine per kind, see :func:`oracle`).

How a dyad attaches (``DyadShape.mode``) -- every dyad is driven by links already placed:

- ``"anchor"``: around a revolute pair X of two known links (the crank pivot O, or any pin of an
  earlier group); its external joints are at distances ~L from X on the two links. Their relative
  motion near X is a rotation about X, so the dyad's motion *in units of L* does not depend on L:
  the dyad may be any size relative to the rest (L = factor x crank length).
- ``"rigid"``: both externals on one moving link (the dyad is rigid relative to it).
- ``"span"``: externals at existing points of two different known links (a classical second
  dyad); only drawn when every dyad so far has factor 1, so that the same shape at unit scale
  (the *unit twin*, ``realize(shape, unit=True)``) is the same mechanism scaled.

Hence the unit twin has the same link angles at every input angle as the mixed-scale design, and
every group has the same conditioning: it is the reference for "a well-conditioned mechanism is
not singular because of its scale".
"""

from __future__ import annotations

import math
import random
from dataclasses import dataclass, field, replace

import numpy as np

from linkage.kinetostatics.loads import LinkMoment, Loads, PointForce
from linkage.model.builder import MechanismBuilder

__all__ = ["KINDS", "DyadShape", "ChainShape", "Chain", "realize", "build", "oracle", "loads_of",
           "rot", "gpt", "wrap", "cross", "dot", "direction", "norm", "extent"]

KINDS = ("RRR", "RRP", "RPR", "PRP", "RPP")
TWO_PI = 2.0 * math.pi
#: smallest conditioning of every group at the reference configuration (a designer's drawing)
REFERENCE_MARGIN = 0.12
#: number of uniforms per dyad shape
N_UNIFORMS = 24


# ==============================================================================================
# plane geometry (written here, not taken from the library)
# ==============================================================================================


def rot(theta, v):
    """``Rot(theta) v`` for angles ``()`` or ``(N,)`` and vectors ``(2,)`` or ``(N, 2)``."""
    theta = np.asarray(theta, dtype=float)
    v = np.asarray(v, dtype=float)
    c, s = np.cos(theta), np.sin(theta)
    return np.stack([c * v[..., 0] - s * v[..., 1], s * v[..., 0] + c * v[..., 1]], axis=-1)


def direction(angle):
    angle = np.asarray(angle, dtype=float)
    return np.stack([np.cos(angle), np.sin(angle)], axis=-1)


def left(v):
    v = np.asarray(v, dtype=float)
    return np.stack([-v[..., 1], v[..., 0]], axis=-1)


def cross(a, b):
    return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]


def dot(a, b):
    return a[..., 0] * b[..., 0] + a[..., 1] * b[..., 1]


def norm(v):
    return np.hypot(v[..., 0], v[..., 1])


def angle_of(v):
    return np.arctan2(v[..., 1], v[..., 0])


def wrap(a):
    """Angle brought into [-pi, pi)."""
    return (np.asarray(a, dtype=float) + math.pi) % TWO_PI - math.pi


def gpt(pose, local):
    """Global position ``(N, 2)`` of the local point ``local`` of a link with ``pose`` ``(N, 3)``."""
    return pose[:, :2] + rot(pose[:, 2], local)


def foot(point, through, u):
    """Foot of ``point`` on the line ``through + t u`` (u a unit vector)."""
    return through + dot(point - through, u) * u


# ==============================================================================================
# shapes (what hypothesis draws) and designs
# ==============================================================================================


@dataclass(frozen=True)
class DyadShape:
    """Nondimensional description of one dyad of a chain.

    ``pick``/``pick2`` in [0, 1) choose the anchor pin / links / points among those available;
    ``swap`` which attachment link gets the first external pair; ``branch`` the assembly the
    designer draws; ``factor`` the dyad's size relative to the crank; ``u`` the kind's geometry.
    """

    kind: str
    mode: str
    pick: float
    pick2: float
    swap: bool
    branch: int
    factor: float
    u: tuple[float, ...]


@dataclass(frozen=True)
class ChainShape:
    """A crank and one to three dyads, at a global ``scale`` (crank length, m).

    ``far`` (or None): an unused frame point at ``far`` crank lengths from the pivot.
    ``load_u``: uniforms for masses, inertias, gravity, forces, moments and the input motion.
    """

    phi0: float
    pivot: tuple[float, float]
    dyads: tuple[DyadShape, ...]
    scale: float
    far: float | None
    far_angle: float
    load_u: tuple[float, ...]


@dataclass
class LinkDesign:
    """A link drawn in the reference configuration: its pose and global points / guides there."""

    name: str
    pose: np.ndarray  # (3,) reference pose: origin and angle of the local frame
    points: dict = field(default_factory=dict)  # name -> global (2,) at the reference
    guides: dict = field(default_factory=dict)  # name -> (global point (2,), global angle)

    def local(self, point: str) -> tuple[float, float]:
        v = rot(-self.pose[2], self.points[point] - self.pose[:2])
        return (float(v[0]), float(v[1]))

    def local_guide(self, guide: str) -> tuple[tuple[float, float], float]:
        P, a = self.guides[guide]
        v = rot(-self.pose[2], P - self.pose[:2])
        return (float(v[0]), float(v[1])), float(a - self.pose[2])


@dataclass(frozen=True)
class Pair:
    """A pair of the design: revolute (``a``, ``b``, point) or prismatic (guide link ``a``,
    slider link ``b``, guide name, slider point, pair angle)."""

    name: str
    kind: str
    a: str
    b: str
    point: str
    guide: str = ""
    angle: float = 0.0


@dataclass(frozen=True)
class DyadDesign:
    kind: str
    index: int
    links: tuple[str, str]  # (L1, L2): L1 carries ext1 (on k1), L2 carries ext2 (on k2)
    known: tuple[str, str]  # (k1, k2), possibly equal
    ext1: Pair
    inner: Pair
    ext2: Pair
    branch: int  # this file's branch sign (see :func:`oracle`)
    scale: float  # the group's own scale: largest distance between its joint points, m
    factor: float  # dimensions relative to the crank (1 in the unit twin)
    assembly: tuple | None  # (point, keyword, value) for MechanismBuilder.assembly
    beta: tuple[float, ...]  # relative angles fixed by prismatic pairs (see _solve_dyad)
    mode: str = "anchor"  # how it attaches (see the module docstring)


@dataclass
class Chain:
    shape: ChainShape
    unit: bool
    links: dict[str, LinkDesign]
    pairs: list[Pair]
    dyads: list[DyadDesign]
    crank: float  # crank length, m
    size: float  # largest distance between two joint points of the reference drawing, m
    masses: dict = field(default_factory=dict)  # link -> (mass, inertia)
    gravity: tuple[float, float] = (0.0, 0.0)
    forces: list = field(default_factory=list)  # (point, link, (Fx, Fy))
    moments: list = field(default_factory=list)  # (link, M)
    omega: float = 1.0
    eps: float = 0.0

    @property
    def moving(self) -> list[str]:
        return [k for k in self.links if k != "0"]

    def group_of_link(self, link: str) -> int:
        """0 for the frame and the crank, g >= 1 for the links of dyad g."""
        for d in self.dyads:
            if link in d.links:
                return d.index
        return 0

    def group_scale(self, g: int) -> float:
        return self.crank if g == 0 else self.dyads[g - 1].scale


class Reject(Exception):
    """The drawn shape gives no sound design (a degenerate drawing): hypothesis rejects it."""


def realize(shape: ChainShape, unit: bool = False) -> Chain:
    """The design of ``shape``: at its scales, or (``unit``) with crank 1 m and every factor 1
    and no far frame point.

    Raises :class:`Reject` when the drawing is degenerate.
    """
    S = 1.0 if unit else shape.scale
    O = S * np.asarray(shape.pivot, dtype=float)
    frame = LinkDesign("0", np.zeros(3), {"O": O})
    crank = LinkDesign("1", np.array([O[0], O[1], shape.phi0]),
                       {"O": O, "T": O + S * direction(shape.phi0)})
    links = {"0": frame, "1": crank}
    pairs = [Pair("O", "R", "0", "1", "O")]
    pins = [("O", "0", "1")]  # revolute pairs between two placed links: anchor candidates
    dyads: list[DyadDesign] = []
    all_unit = True
    for g, ds in enumerate(shape.dyads, start=1):
        all_unit = all_unit and ds.factor == 1.0
        L = S * (1.0 if unit else ds.factor)
        mode = ds.mode if (ds.mode != "span" or all_unit) else "anchor"
        k1, k2, P1, P2 = _attachment(mode, ds, links, pins, L)
        if ds.swap:
            k1, k2, P1, P2 = k2, k1, P2, P1
        dyad = _DRAW[ds.kind](g, ds, links, k1, k2, P1, P2, L)
        dyad = replace(dyad, factor=1.0 if unit else ds.factor, mode=mode)
        dyads.append(dyad)
        pairs += [dyad.ext1, dyad.inner, dyad.ext2]
        pins += [(p.point, p.a, p.b) for p in (dyad.ext1, dyad.inner, dyad.ext2) if p.kind == "R"]
    pts = [p for lk in links.values() for p in lk.points.values()]
    size = max(float(norm(p - q)) for i, p in enumerate(pts) for q in pts[i + 1:])
    if shape.far is not None and not unit:
        frame.points["Far"] = O + S * shape.far * direction(shape.far_angle)
    chain = Chain(shape, unit, links, pairs, dyads, S, size)
    _draw_loads(chain, shape.load_u)
    return chain


def _attachment(mode, ds, links, pins, L):
    """(k1, k2, P1, P2): the known links the dyad attaches to and a point near each."""
    u = ds.u
    r1 = L * (0.3 + 0.7 * u[20]) * direction(TWO_PI * u[21])
    r2 = L * (0.5 + 1.0 * u[22]) * direction(TWO_PI * u[23])
    moving = [k for k in links if k != "0"]
    if mode == "span":
        pairs = [(a, b) for a in links for b in links if a < b]
        a, b = pairs[int(ds.pick * len(pairs)) % len(pairs)]
        pa = sorted(links[a].points)
        pb = sorted(links[b].points)
        P1 = links[a].points[pa[int(ds.pick2 * len(pa)) % len(pa)]]
        P2 = links[b].points[pb[int(ds.pick2 * 7.0 * len(pb)) % len(pb)]]
        if float(norm(P2 - P1)) < 0.2 * L:
            raise Reject("span: the two attachment points nearly coincide")
        scale = float(norm(P2 - P1))
        return a, b, P1 + 0.15 * scale / L * r1, P2 + 0.15 * scale / L * r2
    if mode == "rigid":
        k = moving[int(ds.pick * len(moving)) % len(moving)]
        names = sorted(links[k].points)
        Y = links[k].points[names[int(ds.pick2 * len(names)) % len(names)]]
        P1 = Y + r1
        return k, k, P1, P1 + r2
    name, a, b = pins[int(ds.pick * len(pins)) % len(pins)]
    X = links[a].points[name]
    P1 = X + r1
    return a, b, P1, P1 + r2


def _new_link(links, name, origin, theta, points):
    lk = LinkDesign(name, np.array([origin[0], origin[1], theta]), dict(points))
    links[name] = lk
    return lk


def _frame_origin(P, L, ua, ub):
    """A link's local origin: near one of its points (a designer's choice; any would do)."""
    return P + 0.3 * L * np.array([ua - 0.5, ub - 0.5])


def _pin_order(name, l1, l2, swap):
    return Pair(name, "R", *((l2, l1) if swap else (l1, l2)), name)


def _scale_of(*points):
    pts = list(points)
    return max(float(norm(p - q)) for i, p in enumerate(pts) for q in pts[i + 1:])


def _offset(L, u_on, u_len, u_ang):
    """A slider's pin offset: zero for ~40 % of draws, else up to 0.4 L."""
    if u_on < 0.4:
        return np.zeros(2)
    return 0.4 * L * u_len * direction(TWO_PI * u_ang)


def _draw_rrr(g, ds, links, k1, k2, A, C, L):
    u, M = ds.u, ds.branch
    l1, l2 = str(2 * g), str(2 * g + 1)
    nA, nB, nC = f"A{g}", f"B{g}", f"C{g}"
    d = float(norm(C - A))
    length = d * (0.4 + 1.4 * u[0])
    gamma = 0.35 + 2.2 * u[1]
    B = A + length * direction(float(angle_of(C - A)) + M * gamma)
    sin_b = abs(float(cross(A - B, C - B))) / (float(norm(A - B)) * float(norm(C - B)))
    if sin_b < 0.15:
        raise Reject("RRR drawn near a toggle")
    links[k1].points[nA] = A
    links[k2].points[nC] = C
    _new_link(links, l1, _frame_origin(A, L, u[2], u[3]), TWO_PI * u[4], {nA: A, nB: B})
    _new_link(links, l2, _frame_origin(C, L, u[5], u[6]), TWO_PI * u[7], {nC: C, nB: B})
    rule = (nB, "left_of" if M > 0 else "right_of", (nA, nC))
    return DyadDesign("RRR", g, (l1, l2), (k1, k2), _pin_order(nA, k1, l1, u[8] < 0.5),
                      _pin_order(nB, l1, l2, u[9] < 0.5), _pin_order(nC, l2, k2, u[10] < 0.5), M,
                      _scale_of(A, B, C), 1.0, rule, ())


def _draw_rrp(g, ds, links, k1, k2, A, P2, L):
    u, M = ds.u, ds.branch
    l1, l2 = str(2 * g), str(2 * g + 1)
    nA, nB, nC = f"A{g}", f"B{g}", f"C{g}"
    alpha = TWO_PI * u[0]
    uu = direction(alpha)
    G0 = P2 + L * (u[1] - 0.5) * left(uu)
    b = _offset(L, u[2], u[3], u[4])
    w = L * (0.3 + 1.2 * u[5])
    s = M * w - float(dot(G0 + b - A, uu))
    P = G0 + s * uu
    B = P + b
    if w / float(norm(B - A)) < REFERENCE_MARGIN:
        raise Reject("RRP drawn near its dead centre")
    links[k1].points[nA] = A
    links[k2].guides[f"g{nC}"] = (G0, alpha)
    _new_link(links, l1, _frame_origin(A, L, u[6], u[7]), TWO_PI * u[8], {nA: A, nB: B})
    theta2 = TWO_PI * u[9]
    _new_link(links, l2, _frame_origin(B, L, u[10], u[11]), theta2, {nB: B, nC: P})
    beta = theta2 - links[k2].pose[2]
    return DyadDesign("RRP", g, (l1, l2), (k1, k2), _pin_order(nA, k1, l1, u[12] < 0.5),
                      _pin_order(nB, l1, l2, u[13] < 0.5),
                      Pair(nC, "P", k2, l2, nC, f"g{nC}", theta2 - alpha), M,
                      _scale_of(A, B, P, G0), 1.0, (nB, "branch", M), (beta,))


def _draw_rpr(g, ds, links, k1, k2, A, C, L):
    u, M = ds.u, ds.branch
    l1, l2 = str(2 * g), str(2 * g + 1)
    nA, nB, nC = f"A{g}", f"B{g}", f"C{g}"
    b = _offset(L, u[0], u[1], u[2])
    dA = float(norm(A - C))
    rho = -0.85 + 1.7 * u[3]
    delta = math.asin(rho)
    psi = float(angle_of(A - C))
    alpha = psi - delta if M > 0 else psi - math.pi + delta
    uu = direction(alpha)
    P = A + b  # the block's point on the slot line
    G = foot(C, P, uu)
    if abs(float(dot(A - C, uu))) / max(dA, L) < REFERENCE_MARGIN:
        raise Reject("RPR drawn near its singular position")
    links[k1].points[nA] = A
    links[k2].points[nC] = C
    theta1, theta2 = TWO_PI * u[4], TWO_PI * u[5]
    _new_link(links, l1, _frame_origin(A, L, u[6], u[7]), theta1, {nA: A, nB: P})
    lk2 = _new_link(links, l2, _frame_origin(C, L, u[8], u[9]), theta2, {nC: C})
    lk2.guides[f"g{nB}"] = (G, alpha)
    return DyadDesign("RPR", g, (l1, l2), (k1, k2), _pin_order(nA, k1, l1, u[10] < 0.5),
                      Pair(nB, "P", l2, l1, nB, f"g{nB}", theta1 - alpha),
                      _pin_order(nC, l2, k2, u[11] < 0.5), M, _scale_of(A, C, P, G), 1.0,
                      (nB, "branch", M), (theta1 - theta2,))


def _guide_angles(u_a, u_d, u_s):
    a1 = TWO_PI * u_a
    delta = (0.35 + (math.pi - 0.7) * u_d) * (1 if u_s < 0.5 else -1)
    return a1, a1 + delta


def _draw_prp(g, ds, links, k1, k2, P1, P2, L):
    u = ds.u
    l1, l2 = str(2 * g), str(2 * g + 1)
    nA, nB, nC = f"A{g}", f"B{g}", f"C{g}"
    B = 0.5 * (P1 + P2) + 0.5 * L * u[0] * direction(TWO_PI * u[1])
    a1, a2 = _guide_angles(u[2], u[3], u[4])
    Q1 = B + _offset(L, u[5], u[6], u[7])
    Q2 = B + _offset(L, u[8], u[9], u[10])
    G1 = foot(P1, Q1, direction(a1))
    G2 = foot(P2, Q2, direction(a2))
    links[k1].guides[f"g{nA}"] = (G1, a1)
    links[k2].guides[f"g{nC}"] = (G2, a2)
    theta1, theta2 = TWO_PI * u[11], TWO_PI * u[12]
    _new_link(links, l1, _frame_origin(B, L, u[13], u[14]), theta1, {nB: B, nA: Q1})
    _new_link(links, l2, _frame_origin(B, L, u[15], u[16]), theta2, {nB: B, nC: Q2})
    beta = (theta1 - links[k1].pose[2], theta2 - links[k2].pose[2])
    return DyadDesign("PRP", g, (l1, l2), (k1, k2),
                      Pair(nA, "P", k1, l1, nA, f"g{nA}", theta1 - a1),
                      _pin_order(nB, l1, l2, u[17] < 0.5),
                      Pair(nC, "P", k2, l2, nC, f"g{nC}", theta2 - a2), 1,
                      _scale_of(B, Q1, Q2, G1, G2), 1.0, None, beta)


def _draw_rpp(g, ds, links, k1, k2, A, P2, L):
    u = ds.u
    l1, l2 = str(2 * g), str(2 * g + 1)
    nA, nB, nC = f"A{g}", f"B{g}", f"C{g}"
    Q = A + _offset(L, u[0], u[1], u[2])  # the block's point in the slot
    a1, a2 = _guide_angles(u[3], u[4], u[5])
    R = P2 + 0.3 * L * u[6] * direction(TWO_PI * u[7])  # the yoke's point on the guide
    Gs = foot(R, Q, direction(a1))
    G2 = foot(P2, R, direction(a2))
    links[k1].points[nA] = A
    links[k2].guides[f"g{nC}"] = (G2, a2)
    theta1, theta2 = TWO_PI * u[8], TWO_PI * u[9]
    _new_link(links, l1, _frame_origin(A, L, u[10], u[11]), theta1, {nA: A, nB: Q})
    lk2 = _new_link(links, l2, _frame_origin(R, L, u[12], u[13]), theta2, {nC: R})
    lk2.guides[f"g{nB}"] = (Gs, a1)
    beta = (theta2 - links[k2].pose[2], theta1 - theta2)
    return DyadDesign("RPP", g, (l1, l2), (k1, k2), _pin_order(nA, k1, l1, u[14] < 0.5),
                      Pair(nB, "P", l2, l1, nB, f"g{nB}", theta1 - a1),
                      Pair(nC, "P", k2, l2, nC, f"g{nC}", theta2 - a2), 1,
                      _scale_of(A, Q, R, Gs, G2), 1.0, None, beta)


_DRAW = {"RRR": _draw_rrr, "RRP": _draw_rrp, "RPR": _draw_rpr, "PRP": _draw_prp, "RPP": _draw_rpp}


def extent(lk: LinkDesign) -> float:
    pts = list(lk.points.values())
    if len(pts) < 2:
        return 0.0
    return max(float(norm(p - q)) for i, p in enumerate(pts) for q in pts[i + 1:])


def _draw_loads(chain: Chain, u) -> None:
    """Masses at centres of mass S<k> (declared points), inertias, gravity, a few forces at
    points and moments on links, and the input's speed and acceleration."""
    it = iter(u)
    nxt = lambda: next(it)  # noqa: E731
    for k in chain.moving:
        lk = chain.links[k]
        size = max(extent(lk), chain.group_scale(chain.group_of_link(k)))
        centre = np.mean(list(lk.points.values()), axis=0)
        lk.points[f"S{k}"] = centre + 0.2 * size * np.array([nxt() - 0.5, nxt() - 0.5])
        mass = 10.0 ** (4 * nxt() - 2)
        chain.masses[k] = (mass, mass * size**2 * (0.02 + 0.3 * nxt()))
    g = 9.81 * nxt()
    chain.gravity = tuple(float(v) for v in g * direction(TWO_PI * nxt())) if nxt() > 0.2 else (0.0, 0.0)
    typical = 9.81 * float(np.mean([m for m, _ in chain.masses.values()]))
    for _ in range(int(3 * nxt())):
        k = chain.moving[int(nxt() * len(chain.moving)) % len(chain.moving)]
        names = sorted(p for p in chain.links[k].points if not p.startswith("S"))
        point = names[int(nxt() * len(names)) % len(names)]
        F = typical * 10.0 ** (3 * nxt() - 1) * direction(TWO_PI * nxt())
        chain.forces.append((point, k, (float(F[0]), float(F[1]))))
    for _ in range(int(3 * nxt())):
        k = chain.moving[int(nxt() * len(chain.moving)) % len(chain.moving)]
        size = chain.group_scale(chain.group_of_link(k))
        chain.moments.append((k, typical * size * 10.0 ** (3 * nxt() - 1) * (2 * nxt() - 1)))
    chain.omega = (1 if nxt() < 0.5 else -1) * 10.0 ** (3 * nxt() - 1)
    chain.eps = chain.omega**2 * (2 * nxt() - 1)


def loads_of(chain: Chain) -> Loads:
    return Loads(gravity=chain.gravity,
                 forces=tuple(PointForce(p, k, F) for p, k, F in chain.forces),
                 moments=tuple(LinkMoment(k, M) for k, M in chain.moments))


# ==============================================================================================
# the mechanism, declared through the builder
# ==============================================================================================


def build(chain: Chain, order: int | None = None, name: str = "chain"):
    """The design as a :class:`linkage.Mechanism`; ``order`` (a seed) shuffles the order in which
    links, points, guides, pairs and assembly conditions are declared."""
    rng = random.Random(order)

    def shuffled(seq):
        seq = list(seq)
        if order is not None:
            rng.shuffle(seq)
        return seq

    b = MechanismBuilder(name)
    for k in shuffled(chain.links):
        lk = chain.links[k]
        points = {p: lk.local(p) for p in shuffled(lk.points)}
        guides = {}
        for gname in shuffled(lk.guides):
            through, angle = lk.local_guide(gname)
            guides[gname] = {"through": through, "angle": angle}
        kwargs = {}
        if k in chain.masses:
            mass, inertia = chain.masses[k]
            kwargs = {"mass": mass, "com": f"S{k}", "inertia": inertia}
        b.link(k, points=points, guides=guides, **kwargs)
    for p in shuffled(chain.pairs):
        if p.kind == "R":
            b.revolute(p.name, p.a, p.b, at=p.point)
        else:
            b.prismatic(p.name, p.a, p.b, guide=p.guide, at=p.point, angle=p.angle)
    b.inputs("1")
    for d in shuffled(chain.dyads):
        if d.assembly is not None:
            point, key, value = d.assembly
            b.assembly(point, **{key: value})
    return b.build()


# ==============================================================================================
# the oracle: positions by closed forms written here
# ==============================================================================================


def oracle(chain: Chain, phi):
    """Poses ``(N, 3)`` of every link (NaN where not assembled) and each dyad's conditioning.

    Conditioning (its absolute value is in [0, 1], 0 at a singular position and where the dyad
    cannot be assembled; signed for PRP and RPP, whose sign changes where the guides pass
    through parallel while the dyad stays assembled), measured at the group's own scale:
    RRR: |sin| of the angle ABC at the inner pin; RRP: |cos| of the rod's angle to the guide;
    RPR: |s| / max(|AC|, L_g) with s the slide of A along the slot from C's foot;
    PRP: |sin| of the angle between the guides; RPP: |sin| of the angle between slot and guide.

    Branches (this file's signs, as drawn): RRR +1 = B left of the directed line A -> C; RRP
    +1 = B ahead of A along the guide direction; RPR +1 = A ahead of C along the slot direction.
    """
    phi = np.asarray(phi, dtype=float)
    N = len(phi)
    O = chain.links["1"].points["O"]
    poses = {"0": np.zeros((N, 3)),
             "1": np.column_stack([np.full(N, O[0]), np.full(N, O[1]), phi])}
    margins = {}
    with np.errstate(invalid="ignore", divide="ignore"):
        for d in chain.dyads:
            new, margin = _solve_dyad(chain, d, poses)
            margin = np.where(np.isfinite(margin), margin, 0.0)
            bad = margin == 0
            for k, pose in new.items():
                poses[k] = np.where(bad[:, None], np.nan, pose)
            margins[d.index] = margin
    return poses, margins


def _solve_dyad(chain: Chain, d: DyadDesign, poses):
    lk = chain.links
    l1, l2 = d.links
    k1, k2 = d.known
    M = d.branch
    if d.kind == "RRR":
        nA, nB, nC = d.ext1.point, d.inner.point, d.ext2.point
        A, C = gpt(poses[k1], lk[k1].local(nA)), gpt(poses[k2], lk[k2].local(nC))
        a1, b1 = np.array(lk[l1].local(nA)), np.array(lk[l1].local(nB))
        c2, b2 = np.array(lk[l2].local(nC)), np.array(lk[l2].local(nB))
        r2, r3 = float(norm(b1 - a1)), float(norm(b2 - c2))
        dist = norm(C - A)
        cos_g = (r2**2 + dist**2 - r3**2) / (2 * r2 * dist)
        ok = np.abs(cos_g) <= 1
        gam = np.arccos(np.clip(cos_g, -1, 1))
        B = A + r2 * direction(angle_of(C - A) + M * gam)
        th1 = angle_of(B - A) - float(angle_of(b1 - a1))
        th2 = angle_of(B - C) - float(angle_of(b2 - c2))
        margin = np.abs(cross(A - B, C - B)) / (r2 * r3)
        new = {l1: np.column_stack([A - rot(th1, a1), th1]), l2: np.column_stack([C - rot(th2, c2), th2])}
        return new, np.where(ok, margin, 0.0)
    if d.kind == "RRP":
        nA, nB, nC = d.ext1.point, d.inner.point, d.ext2.point
        A = gpt(poses[k1], lk[k1].local(nA))
        g_loc, g_ang = lk[k2].local_guide(d.ext2.guide)
        G = gpt(poses[k2], g_loc)
        U = direction(poses[k2][:, 2] + g_ang)
        th2 = poses[k2][:, 2] + d.beta[0]
        a1, b1 = np.array(lk[l1].local(nA)), np.array(lk[l1].local(nB))
        b2, p2 = np.array(lk[l2].local(nB)), np.array(lk[l2].local(nC))
        rod = float(norm(b1 - a1))
        Q0 = G + rot(th2, b2 - p2)  # B = Q0 + t U
        q = dot(U, Q0 - A)
        disc = q**2 - dot(Q0 - A, Q0 - A) + rod**2
        ok = disc >= 0
        t = -q + M * np.sqrt(np.where(ok, disc, 0.0))
        B = Q0 + t[:, None] * U
        th1 = angle_of(B - A) - float(angle_of(b1 - a1))
        margin = np.abs(dot(U, B - A)) / rod
        new = {l1: np.column_stack([A - rot(th1, a1), th1]), l2: np.column_stack([B - rot(th2, b2), th2])}
        return new, np.where(ok, margin, 0.0)
    if d.kind == "RPR":
        nA, nB, nC = d.ext1.point, d.inner.point, d.ext2.point
        A, C = gpt(poses[k1], lk[k1].local(nA)), gpt(poses[k2], lk[k2].local(nC))
        a1, p1 = np.array(lk[l1].local(nA)), np.array(lk[l1].local(nB))
        c2 = np.array(lk[l2].local(nC))
        g_loc, g_ang = lk[l2].local_guide(d.inner.guide)
        u_l = direction(g_ang)
        beta = d.beta[0]  # theta1 - theta2
        v = np.asarray(g_loc) + rot(beta, a1 - p1) - c2  # A - C in L2's frame is v + t u_l
        dist = norm(A - C)
        e = float(cross(u_l, v))
        disc = dist**2 - e**2
        ok = disc >= 0
        s = M * np.sqrt(np.where(ok, disc, 0.0))
        t = s - float(dot(u_l, v))
        w = v + t[:, None] * u_l
        th2 = angle_of(A - C) - angle_of(w)
        th1 = th2 + beta
        margin = np.abs(s) / np.maximum(dist, d.scale)
        new = {l1: np.column_stack([A - rot(th1, a1), th1]), l2: np.column_stack([C - rot(th2, c2), th2])}
        return new, np.where(ok, margin, 0.0)
    if d.kind == "PRP":
        lines, thetas, pins = [], [], []
        for link, known, pair, beta in ((l1, k1, d.ext1, d.beta[0]), (l2, k2, d.ext2, d.beta[1])):
            g_loc, g_ang = lk[known].local_guide(pair.guide)
            th = poses[known][:, 2] + beta
            pin = np.array(lk[link].local(d.inner.point))
            q = np.array(lk[link].local(pair.point))
            lines.append((gpt(poses[known], g_loc) + rot(th, pin - q),
                          direction(poses[known][:, 2] + g_ang)))
            thetas.append(th)
            pins.append(pin)
        (Q1, U1), (Q2, U2) = lines
        det = cross(U1, U2)
        t1 = cross(Q2 - Q1, U2) / det
        B = Q1 + t1[:, None] * U1
        new = {l1: np.column_stack([B - rot(thetas[0], pins[0]), thetas[0]]),
               l2: np.column_stack([B - rot(thetas[1], pins[1]), thetas[1]])}
        return new, det  # signed: it changes sign where the guides pass through parallel
    if d.kind == "RPP":
        nA, nB, nC = d.ext1.point, d.inner.point, d.ext2.point
        A = gpt(poses[k1], lk[k1].local(nA))
        g2_loc, g2_ang = lk[k2].local_guide(d.ext2.guide)
        gs_loc, gs_ang = lk[l2].local_guide(d.inner.guide)
        th2 = poses[k2][:, 2] + d.beta[0]
        th1 = th2 + d.beta[1]
        a1, q1 = np.array(lk[l1].local(nA)), np.array(lk[l1].local(nB))
        r2 = np.array(lk[l2].local(nC))
        Q = A + rot(th1, q1 - a1)
        n2 = left(direction(poses[k2][:, 2] + g2_ang))
        ns = left(direction(th2 + gs_ang))
        # n2 . X = n2 . (G2 - Rot(th2) r2) and ns . X = ns . (Q - Rot(th2) gs) for L2's origin X
        c1 = dot(n2, gpt(poses[k2], g2_loc) - rot(th2, r2))
        c2 = dot(ns, Q - rot(th2, gs_loc))
        det = cross(n2, ns)
        X = np.column_stack([(c1 * ns[:, 1] - c2 * n2[:, 1]) / det, (n2[:, 0] * c2 - ns[:, 0] * c1) / det])
        new = {l1: np.column_stack([A - rot(th1, a1), th1]), l2: np.column_stack([X, th2])}
        return new, det
    raise AssertionError(d.kind)  # pragma: no cover
