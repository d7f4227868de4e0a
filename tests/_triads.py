"""Random class-III triads on a crank for ``test_triad_modes.py``: designs, mechanisms, an oracle.

A *design* (:class:`Triad`) is drawn the way a designer draws one: a crank OA (length ``crank``,
pivot O at the origin) at the input angle ``phi0_deg``, a ternary link with the pins B, C, D
(global coordinates in that drawing) and three legs, one from each pin to an anchor: leg 0 from
B to the crank pin A, legs 1 and 2 from C and D to the frame points E and F. Every leg is
one of

- ``"R"``: a binary link pinned at both ends (its length read off the drawing);
- ``"slider"``: its outer pair is prismatic: a block carrying the pin P (B, C or D) slides on a
  guide of the known link (the crank for leg 0, else the frame) through P's drawn position at
  the angle ``guide_deg`` (global, in the drawing);
- ``"slot"``: its inner pair is prismatic: a block pinned to the anchor K (A, E or F) slides in
  a slot of the ternary link through K's drawn position at the angle ``guide_deg``.

The drawing is an assembly by construction (the *declared configuration*). :func:`build`
declares it through :class:`linkage.model.builder.MechanismBuilder` with an assembly condition
(:func:`condition`) that holds at ``phi0_deg`` for the drawn configuration and for no other
assembly mode there, so it picks the drawn one.

The oracle is written here from the link geometry, independent of :mod:`assur` and
:mod:`linkage.kinematics`: the three legs' closure equations in the ternary link's pose
``q = (x, y, theta)`` (:func:`residual`, its Jacobian :func:`jacobian`), every root at an input
angle by least squares from many starts (:func:`roots`), a scale-free conditioning
(:func:`conditioning`) and the continuation of the declared configuration over the input angle
in both directions with step control (:func:`continuation`), which ends where the mode ends (a
limit position: the Jacobian becomes singular and no step, however small, can be taken).

Run ``python tests/_triads.py`` to repeat the seeded search that found the pinned regression
designs of ``test_triad_modes.py`` (see :func:`search`).
"""

from __future__ import annotations

import math
import sys
import warnings
from dataclasses import dataclass
from itertools import permutations

import numpy as np
from scipy.optimize import least_squares

from linkage.model.builder import MechanismBuilder

__all__ = [
    "LEG_KINDS",
    "Condition",
    "Trace",
    "Triad",
    "build",
    "condition",
    "conditioning",
    "continuation",
    "draw",
    "jacobian",
    "link_poses",
    "pose_gap",
    "residual",
    "roots",
    "size_of",
]

TWO_PI = 2.0 * math.pi
LEG_KINDS = ("R", "slider", "slot")
PINS = ("B", "C", "D")          # leg i's pin on the ternary link
ANCHORS = ("A", "E", "F")       # leg i's anchor on a known link (A on the crank)
LEGS = ("2", "4", "5")          # leg i's link
TERNARY = "3"


# ==============================================================================================
# the design
# ==============================================================================================


@dataclass(frozen=True)
class Triad:
    """A crank and a class-III triad in its drawn (declared) configuration.

    Attributes
    ----------
    crank : float
        |OA|, m (O at the origin).
    phi0_deg : float
        The crank angle of the drawing, deg (an integer: the library's branch sweep samples whole
        degrees, and the assembly condition is checked there).
    pins : ((float, float), (float, float), (float, float))
        B, C, D in the drawing, m.
    anchors : ((float, float), (float, float))
        E, F (frame points), m.
    legs : (str, str, str)
        Kind of legs 0, 1, 2 (:data:`LEG_KINDS`).
    guide_deg : float
        Angle of the guide or slot of the leg that has one (global in the drawing), deg.
    """

    crank: float
    phi0_deg: float
    pins: tuple
    anchors: tuple
    legs: tuple = ("R", "R", "R")
    guide_deg: float = 0.0

    @property
    def phi0(self) -> float:
        return math.radians(self.phi0_deg)

    @property
    def kind(self) -> str:
        """``"RRR"``, ``"slider"`` or ``"slot"`` (with the leg's index)."""
        odd = [(i, k) for i, k in enumerate(self.legs) if k != "R"]
        return "RRR" if not odd else "+".join(f"{k}{i}" for i, k in odd)

    def anchor0(self) -> np.ndarray:
        """The drawn crank pin A."""
        return self.crank * np.array([math.cos(self.phi0), math.sin(self.phi0)])

    def drawn(self) -> dict[str, np.ndarray]:
        """Every named point of the drawing (global, m)."""
        out = {"O": np.zeros(2), "A": self.anchor0()}
        out.update({n: np.asarray(p, float) for n, p in zip(PINS, self.pins)})
        out.update({n: np.asarray(p, float) for n, p in zip(ANCHORS[1:], self.anchors)})
        return out


def size_of(design: Triad) -> float:
    """The design's length scale, m: the largest distance between two points of the drawing."""
    pts = np.array(list(design.drawn().values()))
    return float(np.max(np.linalg.norm(pts[:, None] - pts[None], axis=2)))


def _rot(theta, v):
    c, s = np.cos(theta), np.sin(theta)
    v = np.asarray(v, float)
    return np.array([c * v[0] - s * v[1], s * v[0] + c * v[1]])


def _perp(v):
    return np.array([-v[1], v[0]])


def _wrap(a):
    return (np.asarray(a, float) + math.pi) % TWO_PI - math.pi


@dataclass
class _Leg:
    """One leg in local coordinates: its kind, the pin on the ternary link (R, slider), its
    length (R), the guide (slider: on the crank "1" or the frame "0"; slot: on the ternary link)
    as a local point and a local angle (rad)."""

    kind: str
    pin: tuple[float, float] | None = None
    length: float | None = None
    guide_link: str | None = None
    guide_point: tuple[float, float] | None = None
    guide_angle: float | None = None


@dataclass
class _Geometry:
    """The design's link geometry in each link's local frame (what the builder is given)."""

    design: Triad
    ternary0: float                 # drawn angle of the ternary link's frame
    origin0: np.ndarray             # drawn global position of its local origin (the drawn B)
    legs: list[_Leg]
    size: float


def geometry(design: Triad) -> _Geometry:
    """Local coordinates of everything: the ternary link's frame has its origin at the drawn B
    and its x axis along B -> C; a pinned leg's frame its origin at the anchor and x axis to the
    pin; a slider block's its origin at the pin, a slot block's at the anchor."""
    pts = design.drawn()
    origin, t0 = pts["B"], math.atan2(*(pts["C"] - pts["B"])[::-1])
    angle = math.radians(design.guide_deg)
    legs = []
    for i, kind in enumerate(design.legs):
        P, K = pts[PINS[i]], pts[ANCHORS[i]]
        pin = tuple(_rot(-t0, P - origin)) if kind != "slot" else None
        if kind == "R":
            legs.append(_Leg(kind, pin, float(np.linalg.norm(P - K))))
        elif kind == "slider":          # a guide on the known link through P
            if i == 0:
                legs.append(_Leg(kind, pin, None, "1", tuple(_rot(-design.phi0, P)), angle - design.phi0))
            else:
                legs.append(_Leg(kind, pin, None, "0", tuple(P), angle))
        else:                           # a slot in the ternary link through K
            legs.append(_Leg(kind, None, None, TERNARY, tuple(_rot(-t0, K - origin)), angle - t0))
    return _Geometry(design, t0, origin, legs, size_of(design))


# ==============================================================================================
# the closure equations in the ternary link's pose (written here from the link geometry)
# ==============================================================================================


def _anchor(g: _Geometry, i: int, phi: float) -> tuple[float, float]:
    """Leg i's anchor at the crank angle phi (global, m): the crank pin A, or E, F."""
    if i == 0:
        return g.design.crank * math.cos(phi), g.design.crank * math.sin(phi)
    return tuple(map(float, g.design.anchors[i - 1]))


def closure(g: _Geometry, q, phi: float):
    """The three legs' closure residuals ``F`` (m), ``dF/dq`` (3 x 3; columns x, y in 1, theta in
    m/rad) and ``dF/dphi`` (m/rad) at the ternary pose ``q = (x, y, theta)``, in plain floats.

    A pinned leg: ``|P - K| - d`` (P the pin, K the anchor, d the length). A slider: the distance
    ``n . (P - G)`` of the pin from the guide (point G, unit normal n). A slot: the distance
    ``n . (K - G)`` of the anchor from the slot (G and n turn with the ternary link)."""
    x, y, t = (float(v) for v in q)
    c, s = math.cos(t), math.sin(t)
    F, J, Fphi = [0.0] * 3, [[0.0] * 3 for _ in range(3)], [0.0] * 3
    for i, leg in enumerate(g.legs):
        kx, ky = _anchor(g, i, phi)
        dkx, dky = (-ky, kx) if i == 0 else (0.0, 0.0)        # dK/dphi
        if leg.kind in ("R", "slider"):
            ax, ay = c * leg.pin[0] - s * leg.pin[1], s * leg.pin[0] + c * leg.pin[1]     # arm to the pin
            px, py = x + ax, y + ay
            if leg.kind == "R":
                dx, dy = px - kx, py - ky
                r = math.hypot(dx, dy)
                F[i] = r - leg.length
                ex, ey = dx / r, dy / r
                J[i] = [ex, ey, -ex * ay + ey * ax]
                Fphi[i] = -(ex * dkx + ey * dky)
            else:
                if leg.guide_link == "1":
                    cp, sp = math.cos(phi), math.sin(phi)
                    gx = cp * leg.guide_point[0] - sp * leg.guide_point[1]
                    gy = sp * leg.guide_point[0] + cp * leg.guide_point[1]
                    ux, uy = math.cos(phi + leg.guide_angle), math.sin(phi + leg.guide_angle)
                else:
                    gx, gy = leg.guide_point
                    ux, uy = math.cos(leg.guide_angle), math.sin(leg.guide_angle)
                nx, ny = -uy, ux
                F[i] = nx * (px - gx) + ny * (py - gy)
                J[i] = [nx, ny, -nx * ay + ny * ax]
                if leg.guide_link == "1":       # n turns by -u, G by perp(G) with the crank
                    Fphi[i] = -(ux * (px - gx) + uy * (py - gy)) - (nx * -gy + ny * gx)
        else:
            lx, ly = leg.guide_point
            vx, vy = c * lx - s * ly, s * lx + c * ly            # from the ternary origin to G
            gx, gy = x + vx, y + vy
            ux, uy = math.cos(t + leg.guide_angle), math.sin(t + leg.guide_angle)
            nx, ny = -uy, ux
            F[i] = nx * (kx - gx) + ny * (ky - gy)
            J[i] = [-nx, -ny, -(ux * (kx - gx) + uy * (ky - gy)) - (nx * -vy + ny * vx)]
            Fphi[i] = nx * dkx + ny * dky
    return F, J, Fphi


def _solve3(J, b):
    """``J^-1 b`` for a 3 x 3 list by Cramer's rule; None where singular."""
    (a, b_, c), (d, e, f), (g, h, i) = J
    det = a * (e * i - f * h) - b_ * (d * i - f * g) + c * (d * h - e * g)
    if det == 0.0 or not math.isfinite(det):
        return None
    x0, x1, x2 = b
    return [(x0 * (e * i - f * h) - b_ * (x1 * i - f * x2) + c * (x1 * h - e * x2)) / det,
            (a * (x1 * i - f * x2) - x0 * (d * i - f * g) + c * (d * x2 - x1 * g)) / det,
            (a * (e * x2 - x1 * h) - b_ * (d * x2 - x1 * g) + x0 * (d * h - e * g)) / det]


def residual(g: _Geometry, q, phi: float) -> np.ndarray:
    return np.array(closure(g, q, phi)[0])


def jacobian(g: _Geometry, q, phi: float) -> np.ndarray:
    return np.array(closure(g, q, phi)[1])


def contacts(g: _Geometry, q, phi: float) -> np.ndarray:
    """The points (6, 2) where the triad's pairs act: each leg's pin (or, for a slot, the
    anchor) and anchor (or, for a slider, the pin)."""
    x, y, t = q
    out = []
    for i, leg in enumerate(g.legs):
        K = np.array(_anchor(g, i, phi))
        P = K if leg.kind == "slot" else np.array([x, y]) + _rot(t, leg.pin)
        out += [P, P if leg.kind == "slider" else K]
    return np.array(out)


def conditioning(g: _Geometry, q, phi: float) -> float:
    """Scale-free distance of the triad from a singular position, in [0, 1]: the Hadamard ratio
    ``|det J| / prod |J_i|`` of the Jacobian with the rotation taken about the centroid of the
    contact points and divided by the triad's extent L (every column in m/m). 1 for orthogonal
    rows, 0 where the legs' lines of action meet in one point or are parallel (the ternary link
    can move infinitesimally: a limit position, or where two modes meet)."""
    J = np.array(closure(g, q, phi)[1])
    pts = contacts(g, q, phi)
    L = float(np.max(np.linalg.norm(pts[:, None] - pts[None], axis=2)))
    r = np.mean(pts, axis=0) - np.asarray(q[:2], float)
    J[:, 2] = (J[:, 2] + J[:, 0] * r[1] - J[:, 1] * r[0]) / L
    return float(abs(np.linalg.det(J)) / np.prod(np.linalg.norm(J, axis=1)))


def link_poses(g: _Geometry, q, phi: float) -> dict[str, np.ndarray]:
    """Poses ``(x, y, theta)`` of the four moving links of the triad in the frames the builder
    declares (see :func:`geometry`)."""
    q = np.asarray(q, float)
    out = {TERNARY: q.copy()}
    for i, leg in enumerate(g.legs):
        K = np.array(_anchor(g, i, phi))
        if leg.kind == "R":
            P = q[:2] + _rot(q[2], leg.pin)
            out[LEGS[i]] = np.array([K[0], K[1], math.atan2(P[1] - K[1], P[0] - K[0])])
        elif leg.kind == "slider":
            P = q[:2] + _rot(q[2], leg.pin)
            out[LEGS[i]] = np.array([P[0], P[1], (phi if leg.guide_link == "1" else 0.0) + leg.guide_angle])
        else:
            out[LEGS[i]] = np.array([K[0], K[1], q[2] + leg.guide_angle])
    return out


def pose_gap(a: dict[str, np.ndarray], b: dict[str, np.ndarray], size: float) -> float:
    """Largest difference between two sets of link poses: positions / size, angles (rad, wrapped)."""
    worst = 0.0
    for k in a:
        d = np.asarray(a[k], float)[..., :3] - np.asarray(b[k], float)[..., :3]
        worst = max(worst, float(np.max(np.abs(d[..., :2]))) / size, float(np.max(np.abs(_wrap(d[..., 2])))))
    return worst


def drawn_pose(g: _Geometry) -> np.ndarray:
    """The ternary link's pose in the drawing (a root at phi0 by construction)."""
    return np.array([g.origin0[0], g.origin0[1], g.ternary0])


def newton(g: _Geometry, q, phi: float, steps: int = 30, tol: float = 1e-14):
    """Newton's method on the closure from q: ``(q, converged)`` (step below ``tol`` of the size,
    rad for the angle)."""
    q = [float(v) for v in q]
    for _ in range(steps):
        F, J, _ = closure(g, q, phi)
        dq = _solve3(J, [-v for v in F])
        if dq is None:
            return np.array(q), False
        q = [a + b for a, b in zip(q, dq)]
        if not all(math.isfinite(v) for v in q) or abs(q[0]) + abs(q[1]) > 1e3 * g.size:
            return np.array(q), False
        if max(abs(dq[0]) / g.size, abs(dq[1]) / g.size, abs(dq[2])) <= tol:
            return np.array(q), True
    return np.array(q), False


# ==============================================================================================
# every root at one angle
# ==============================================================================================


def _pinned_pair(g: _Geometry) -> tuple[int, int, int]:
    """Two pinned legs (whose loci of the ternary origin, for a given ternary angle, are circles)
    and the third leg."""
    pinned = [i for i, leg in enumerate(g.legs) if leg.kind == "R"]
    third = [i for i in range(3) if i not in pinned[:2]]
    return pinned[0], pinned[1], third[0]


def _scan(g: _Geometry, phi: float, theta: np.ndarray):
    """For ternary angles ``theta`` (T,): the ternary origins ``(2, T, 2)`` on which the two pinned
    legs close (the two intersections of their circles, NaN where they miss) and the third leg's
    residual there ``(2, T)``."""
    i, j, k = _pinned_pair(g)
    c, s = np.cos(theta), np.sin(theta)

    def arm(p):
        return np.stack([c * p[0] - s * p[1], s * p[0] + c * p[1]], axis=-1)

    c1 = np.array(_anchor(g, i, phi)) - arm(g.legs[i].pin)
    c2 = np.array(_anchor(g, j, phi)) - arm(g.legs[j].pin)
    r1, r2 = g.legs[i].length, g.legs[j].length
    d = c2 - c1
    L = np.hypot(d[:, 0], d[:, 1])
    with np.errstate(invalid="ignore", divide="ignore"):     # L = 0 (coincident anchors): NaN, no root there
        along = (L**2 + r1**2 - r2**2) / (2 * L)
        h = np.sqrt(r1**2 - along**2)
        u = d / L[:, None]
    n = np.stack([-u[:, 1], u[:, 0]], axis=-1)
    foot = c1 + along[:, None] * u
    origins = np.stack([foot + h[:, None] * n, foot - h[:, None] * n])
    leg, K = g.legs[k], np.array(_anchor(g, k, phi))
    if leg.kind == "R":
        P = origins + arm(leg.pin)[None]
        f = np.hypot(P[..., 0] - K[0], P[..., 1] - K[1]) - leg.length
    elif leg.kind == "slider":
        P = origins + arm(leg.pin)[None]
        G = np.array(leg.guide_point)
        a = leg.guide_angle
        if leg.guide_link == "1":
            G, a = _rot(phi, G), a + phi
        f = -math.sin(a) * (P[..., 0] - G[0]) + math.cos(a) * (P[..., 1] - G[1])
    else:
        G = origins + arm(leg.guide_point)[None]
        a = theta + leg.guide_angle
        f = -np.sin(a) * (K[0] - G[..., 0]) + np.cos(a) * (K[1] - G[..., 1])
    return origins, f


def roots(g: _Geometry, phi: float, scan: int = 1440, starts: int = 12, seed: int = 0) -> list[np.ndarray]:
    """Every pose of the ternary link that closes the triad at the crank angle ``phi``.

    Many starts: for ``scan`` ternary angles the two pinned legs' circle intersections give the
    origin, the third leg's residual changes sign between neighbouring angles at each transversal
    root (each bracket is bisected to round-off), and the samples next to the angles where the
    circles stop meeting start Newton's method too (a root there joins the two intersections'
    branches without a sign change on either); plus ``starts`` random starts within the size
    of the anchors' centroid, each run through :func:`scipy.optimize.least_squares`. Every start
    is polished by Newton's method on :func:`closure`;
    distinct to 1e-8 of the size; sorted by angle."""
    theta = np.linspace(-math.pi, math.pi, scan + 1)
    origins, f = _scan(g, phi, theta[:-1])
    f, origins = np.concatenate([f, f[:, :1]], axis=1), np.concatenate([origins, origins[:, :1]], axis=1)
    branch, cell = np.nonzero(np.isfinite(f[:, :-1]) & np.isfinite(f[:, 1:]) & (np.sign(f[:, :-1]) != np.sign(f[:, 1:])))
    low, high, f_low = theta[cell], theta[cell + 1], f[branch, cell]
    for _ in range(55):
        mid = 0.5 * (low + high)
        _, fm = _scan(g, phi, mid)
        fm = fm[branch, np.arange(len(mid))]
        left = np.sign(fm) == np.sign(f_low)
        low, high, f_low = np.where(left, mid, low), np.where(left, high, mid), np.where(left, fm, f_low)
    origin, _ = _scan(g, phi, low)
    seeds = [np.r_[origin[b, n], low[n]] for n, b in enumerate(branch)]
    # where the two circles stop meeting, their intersections' branches join: a root there lies
    # on the arc from one branch's last sample to the other's (no sign change on either branch)
    finite = np.isfinite(f)
    edge, at = np.nonzero(finite[:, :-1] != finite[:, 1:])
    for b, k in zip(edge, at):
        k = k if finite[b, k] else k + 1
        seeds.append(np.r_[origins[b, k], theta[k]])
    rng = np.random.default_rng(seed)
    centre = np.mean([_anchor(g, i, phi) for i in range(3)], axis=0)
    for _ in range(starts):          # trust-region least squares from random starts, then Newton's polish
        x0 = np.r_[centre + g.size * rng.uniform(-1, 1, 2), rng.uniform(-math.pi, math.pi)]
        fit = least_squares(lambda q: residual(g, q, phi), x0, jac=lambda q: jacobian(g, q, phi),
                            xtol=1e-15, ftol=1e-15, gtol=1e-15, max_nfev=100)
        seeds.append(fit.x)
    found: list[np.ndarray] = []
    for x0 in seeds:
        if not np.all(np.isfinite(x0)):
            continue
        q, ok = newton(g, x0, phi)
        if not ok or not np.max(np.abs(residual(g, q, phi))) <= 1e-12 * g.size:
            continue
        q[2] = _wrap(q[2])
        if all(max(abs(q[0] - p[0]) / g.size, abs(q[1] - p[1]) / g.size, abs(_wrap(q[2] - p[2]))) > 1e-8
               for p in found):
            found.append(q)
    return sorted(found, key=lambda p: p[2])


# ==============================================================================================
# the assembly condition
# ==============================================================================================


@dataclass(frozen=True)
class Condition:
    """``point`` lies left (``side = "left_of"``) or right of the directed line ``refs[0] -> refs[1]``."""

    point: str
    side: str
    refs: tuple[str, str]


def points_of(g: _Geometry, q, phi: float) -> dict[str, np.ndarray]:
    """Every named point of the mechanism (global) with the ternary link at pose q."""
    pts = {"O": np.zeros(2), **{ANCHORS[i]: np.array(_anchor(g, i, phi)) for i in range(3)}}
    for i, leg in enumerate(g.legs):
        if leg.kind != "slot":
            pts[PINS[i]] = np.asarray(q[:2], float) + _rot(q[2], leg.pin)
    return pts


def _triad_points(design: Triad) -> list[str]:
    """The named points that lie on the triad's links (an assembly condition names one of them)."""
    names = [PINS[i] for i, k in enumerate(design.legs) if k != "slot"]
    names += [ANCHORS[i] for i, k in enumerate(design.legs) if k != "slider"]
    return names


def _side(pts: dict[str, np.ndarray], point: str, x: str, y: str) -> float:
    """Signed distance (m) of ``point`` from the line ``x -> y``, positive on its left."""
    d = pts[y] - pts[x]
    n = float(np.linalg.norm(d))
    return float(d[0] * (pts[point] - pts[x])[1] - d[1] * (pts[point] - pts[x])[0]) / n if n > 0 else 0.0


def condition(g: _Geometry, modes: list[np.ndarray], declared: np.ndarray) -> Condition | None:
    """A left_of / right_of condition that the declared mode meets at phi0 and every other mode
    of ``modes`` fails, each by at least 1e-3 of the size (the largest such margin; the first in
    a fixed order among equals); None when there is none."""
    phi0, size = g.design.phi0, g.size
    others = [m for m in modes if max(abs(m[0] - declared[0]) / size, abs(m[1] - declared[1]) / size,
                                      abs(_wrap(m[2] - declared[2]))) > 1e-7]
    here = points_of(g, declared, phi0)
    there = [points_of(g, m, phi0) for m in others]
    best, margin = None, 1e-3 * size
    for point in sorted(_triad_points(g.design)):
        for x, y in permutations(sorted(here), 2):
            if point in (x, y):
                continue
            mine = _side(here, point, x, y)
            sign = 1.0 if mine > 0 else -1.0
            worst = min([sign * mine] + [-sign * _side(p, point, x, y) for p in there])
            if worst > margin:
                best, margin = Condition(point, "left_of" if sign > 0 else "right_of", (x, y)), worst
    return best


# ==============================================================================================
# the mechanism
# ==============================================================================================


def build(design: Triad, rule: Condition, name: str = "triad"):
    """The design declared through :class:`MechanismBuilder`, with the assembly condition
    ``rule`` holding at the drawing's crank angle."""
    g = geometry(design)
    b = MechanismBuilder(name)
    frame_points = {"O": (0.0, 0.0), "E": tuple(design.anchors[0]), "F": tuple(design.anchors[1])}
    frame_guides, crank_guides, slots = {}, {}, {}
    for i, leg in enumerate(g.legs):
        if leg.kind != "R":
            spec = {"through": tuple(map(float, leg.guide_point)), "angle": float(leg.guide_angle)}
            {"0": frame_guides, "1": crank_guides, TERNARY: slots}[leg.guide_link][f"g{i}"] = spec
    b.link("0", points=frame_points, guides=frame_guides)
    b.link("1", line=("O", "A"), length=design.crank, guides=crank_guides)
    b.link(TERNARY, points={PINS[i]: tuple(map(float, leg.pin)) for i, leg in enumerate(g.legs) if leg.pin},
           guides=slots)
    for i, kind in enumerate(design.legs):
        P, K = PINS[i], ANCHORS[i]
        if kind == "R":
            b.link(LEGS[i], line=(K, P), length=g.legs[i].length)
        elif kind == "slider":
            b.link(LEGS[i], points={P: (0.0, 0.0)})
        else:
            b.link(LEGS[i], points={K: (0.0, 0.0)})
    b.revolute("O", "0", "1")
    for i, kind in enumerate(design.legs):
        P, K = PINS[i], ANCHORS[i]
        known = "1" if i == 0 else "0"
        if kind == "R":
            b.revolute(K, known, LEGS[i]).revolute(P, LEGS[i], TERNARY)
        elif kind == "slider":
            b.prismatic(f"s{K}", known, LEGS[i], guide=f"g{i}", at=P).revolute(P, LEGS[i], TERNARY)
        else:
            b.revolute(K, known, LEGS[i]).prismatic(f"s{P}", TERNARY, LEGS[i], guide=f"g{i}", at=K)
    b.inputs("1")
    kw = {"left_of": rule.refs} if rule.side == "left_of" else {"right_of": rule.refs}
    b.assembly(rule.point, phi=design.phi0, **kw)
    return b.build()


# ==============================================================================================
# continuation of the declared configuration
# ==============================================================================================

#: largest continuation step, rad; smallest (the mode ends where even this fails)
STEP_MAX = math.radians(0.5)
STEP_MIN = 1e-9
#: a corrected step may differ from the predicted one by at most this fraction of the step's
#: predicted movement (plus round-off), else it is halved (no jump to another mode)
PREDICTOR_SLACK = 0.25


@dataclass
class Trace:
    """The declared mode followed from phi0: its ternary poses at the requested angles (NaN where
    it is not reached), and the angles (unwrapped, rad) where it ends in each direction (None
    where it runs a whole turn)."""

    targets: np.ndarray            # (M,) unwrapped angles, increasing away from phi0
    poses: np.ndarray              # (M, 3)
    end: float | None
    closes: bool | None = None     # after a whole turn: back on the start pose


def _step(g: _Geometry, q, phi: float, h: float):
    """One predictor-corrector step of length h (rad) from the pose q at phi: the tangent
    ``dq/dphi = -J^-1 dF/dphi`` predicts, Newton's method corrects. The pose reached, or None
    where the corrector fails or lands farther from the prediction than :data:`PREDICTOR_SLACK`
    of the predicted movement (another mode, or a step across a limit position)."""
    _, J, Fphi = closure(g, q, phi)
    slope = _solve3(J, [-v for v in Fphi])
    if slope is None:
        return None
    predicted = [a + h * b for a, b in zip(q, slope)]
    got, ok = newton(g, predicted, phi + h, steps=8, tol=1e-13)
    if not ok:
        return None
    size = g.size
    moved = max(abs(got[0] - predicted[0]) / size, abs(got[1] - predicted[1]) / size, abs(got[2] - predicted[2]))
    expected = max(abs(h * slope[0]) / size, abs(h * slope[1]) / size, abs(h * slope[2]))
    return got if moved <= PREDICTOR_SLACK * expected + 1e-11 else None


def continuation(g: _Geometry, direction: int, targets_deg) -> Trace:
    """Follow the declared configuration from phi0 in ``direction`` (+1: increasing crank angle)
    through the ``targets_deg`` (offsets from phi0, deg, in (0, 360], increasing), with steps of
    at most :data:`STEP_MAX` halved down to :data:`STEP_MIN` where a step fails (:func:`_step`).
    Records the pose at each target; stops where the mode ends."""
    phi0 = g.design.phi0
    targets = phi0 + direction * np.radians(np.asarray(targets_deg, float))
    poses = np.full((len(targets), 3), np.nan)
    q, phi = drawn_pose(g), phi0
    h = STEP_MAX
    for n, goal in enumerate(targets):
        while abs(goal - phi) > 1e-15:
            step = direction * min(h, abs(goal - phi))
            got = _step(g, q, phi, step)
            if got is None:
                h = abs(step) / 2
                if h < STEP_MIN:
                    return Trace(targets, poses, phi)
                continue
            q, phi = got, phi + step
            h = min(STEP_MAX, 2 * h)
        poses[n] = q
    start = drawn_pose(g)
    closes = max(abs(q[0] - start[0]) / g.size, abs(q[1] - start[1]) / g.size, abs(_wrap(q[2] - start[2]))) < 1e-7
    return Trace(targets, poses, None, bool(closes))


# ==============================================================================================
# random designs
# ==============================================================================================


def _unit(a):
    return np.array([math.cos(a), math.sin(a)])


def draw(u, kind: str, leg: int, phi0_deg: int, crank: float = 0.05) -> Triad:
    """A design from 11 uniforms ``u`` in [0, 1): leg lengths 2..6 crank lengths, ternary sides
    1.5..5 crank lengths at 35..145 deg to each other, directions at random."""
    A = crank * _unit(math.radians(phi0_deg))
    B = A + crank * (2 + 4 * u[0]) * _unit(TWO_PI * u[1])
    side = TWO_PI * u[2]
    C = B + crank * (1.5 + 3.5 * u[3]) * _unit(side)
    D = B + crank * (1.5 + 3.5 * u[4]) * _unit(side + math.radians(35 + 110 * u[5]) * (1 if u[6] < 0.5 else -1))
    E = C + crank * (2 + 4 * u[7]) * _unit(TWO_PI * u[8])
    F = D + crank * (2 + 4 * u[9]) * _unit(TWO_PI * u[10])
    legs = ["R", "R", "R"]
    if kind != "RRR":
        legs[leg] = kind

    def r(p):           # literals that print and read back exactly
        return tuple(round(float(v), 12) for v in p)

    return Triad(crank, float(phi0_deg), (r(B), r(C), r(D)), (r(E), r(F)), tuple(legs),
                 round(float(180.0 * u[11]), 9) if len(u) > 11 else 0.0)


def search(count: int = 400, seed: int = 2024, kinds=("RRR", "slider", "slot")):
    """Seeded search for designs whose declared mode exists (by the continuation here) at crank
    angles where the library reports -1, or where the library reports no OK position at all:
    prints each one found as a literal."""
    import linkage

    rng = np.random.default_rng(seed)
    angles = np.arange(0.0, 360.0, 2.0) + 1.0
    for trial in range(count):
        kind = kinds[trial % len(kinds)]
        design = draw(rng.uniform(0, 1, 12), kind, int(rng.integers(0, 3)), int(rng.integers(0, 360)))
        g = geometry(design)
        q0 = drawn_pose(g)
        if conditioning(g, q0, design.phi0) < 0.1:
            continue
        rule = condition(g, roots(g, design.phi0), q0)
        if rule is None:
            continue
        fwd = continuation(g, +1, angles)
        back = continuation(g, -1, angles)
        exists = np.isfinite(fwd.poses[:, 0]) | np.isfinite(back.poses[::-1][:, 0])
        phi = design.phi0 + np.radians(angles)
        try:
            mech = build(design, rule)
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                status = linkage.analyze(mech, phi, order=0, on_failure="mask").status
        except Exception as error:  # noqa: BLE001  (a search: every outcome is printed)
            print(f"# trial {trial}: {type(error).__name__}: {error}")
            print(f"{design!r}, {rule!r}")
            continue
        # offsets forward and backward land on the same angles: +a and -(360 - a)
        lost = exists & (status == -1)
        if lost.any() or not (status == 0).any():
            print(f"# trial {trial} {design.kind}: -1 at {int(lost.sum())} of {int(exists.sum())} angles where the mode "
                  f"exists, OK at {int((status == 0).sum())}")
            print(f"{design!r}, {rule!r}")
        sys.stdout.flush()


if __name__ == "__main__":
    search(int(sys.argv[1]) if len(sys.argv) > 1 else 400)
