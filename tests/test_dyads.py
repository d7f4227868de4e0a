"""Tests of the five class-II group (dyad) solvers of :mod:`assur` against independent oracles.

Every expected number here is computed in this file from the joints' local geometry (docs/methods.md
sections 3, 4 and 8), never read back from the solvers:

1. per kind, the solver against textbook geometry written here (circle-circle, circle-line,
   line-line intersections, ...), hand-checked numbers, and a Newton solve (scipy) of the pair
   equations from a perturbed start near the expected branch;
2. a contract suite parametrized over ``assur.GROUP_KINDS``: random assembled dyads built by
   construction (random poses of all four links, local geometry derived from them, so the true
   solution at phi = 0 is known), known links moving along a smooth path phi -> pose with exact
   derivatives; closure of every pair (residual computed here), both branches (mirror-related),
   batch == per-row loop, analogs == finite differences, scale and mirror invariance, and
   invariance under the (arbitrary) choice of each moving link's local frame;
3. non-assemblable and singular positions, and ``analyze(..., on_failure=...)``.
"""

from __future__ import annotations

import math
import re
import sys
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, Phase, assume, given, settings
from hypothesis import strategies as st
from scipy.optimize import least_squares

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # run from anywhere without install

import assur  # noqa: E402
import linkage  # noqa: E402
from assur import GROUP_KINDS, PrismaticJoint, RevoluteJoint  # noqa: E402
from linkage.model.builder import MechanismBuilder  # noqa: E402

_QUIET = [HealthCheck.filter_too_much, HealthCheck.too_slow]
# no shrinking: a failure is reported as found (shrinking these nested draws can take minutes,
# and the file must stay fast even while a test documents a bug)
_PHASES = (Phase.explicit, Phase.generate)
SETTINGS = settings(deadline=None, max_examples=60, database=None, suppress_health_check=_QUIET,
                    phases=_PHASES, report_multiple_bugs=False)
#: for the costlier checks (per-row loops, two solves per example)
SETTINGS_40 = settings(SETTINGS, max_examples=40)
#: smallest nondimensional distance from non-assembly / singularity accepted for random cases
MARGIN = 0.05
#: input angles of the smooth path of the known links
PHI_GRID = np.linspace(-0.5, 0.5, 9)
#: every input angle any test evaluates (margins are checked on all of them)
PHI_CHECK = np.linspace(-0.56, 0.56, 57)
TWO_PI = 2 * np.pi


# ==============================================================================================
# independent plane geometry (docs/methods.md#analogs), written without the library's helpers
# ==============================================================================================


def rot(theta, p):
    """``Rot(theta) p`` for angles ``(N,)`` and vectors ``(2,)`` or ``(N, 2)``."""
    theta = np.asarray(theta, dtype=float)
    p = np.broadcast_to(np.asarray(p, dtype=float), theta.shape + (2,))
    c, s = np.cos(theta), np.sin(theta)
    return np.stack([c * p[..., 0] - s * p[..., 1], s * p[..., 0] + c * p[..., 1]], axis=-1)


def left_normal(v):
    return np.stack([-v[..., 1], v[..., 0]], axis=-1)


def cross2(a, b):
    return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]


def dot2(a, b):
    return a[..., 0] * b[..., 0] + a[..., 1] * b[..., 1]


def wrap(a):
    """Angle difference brought into [-pi, pi)."""
    return (np.asarray(a) + np.pi) % TWO_PI - np.pi


def gpt(pose, local):
    """Global position of a point with local coordinates ``local`` on a link with ``pose``."""
    pose = np.asarray(pose, dtype=float)
    return pose[..., :2] + rot(pose[..., 2], local)


def to_local(pose, point):
    """Local coordinates on a link with ``pose`` (3,) of a global point (2,)."""
    return tuple(float(v) for v in rot(-pose[2], np.subtract(point, pose[:2])))


def lp(joint, link):
    """Local point of a revolute ``joint`` on ``link``."""
    return joint.pa if link == joint.a else joint.pb


def place2(P1, P2, q1, q2):
    """Pose of a link whose local points q1, q2 are at the global points P1, P2 ``(N, 2)``."""
    th = np.arctan2(P2[:, 1] - P1[:, 1], P2[:, 0] - P1[:, 0]) - math.atan2(q2[1] - q1[1], q2[0] - q1[0])
    return np.column_stack([P1 - rot(th, q1), th])


def place1(P, q, th):
    """Pose of a link at angle ``th`` whose local point q is at the global point P."""
    return np.column_stack([P - rot(th, q), th])


def closure(joints, poses, size):
    """Residual of every pair ``(N, 2 * len(joints))`` from the joint geometry (angle rows x size)."""
    rows = []
    for j in joints:
        pa, pb = np.asarray(poses[j.a], float), np.asarray(poses[j.b], float)
        if isinstance(j, RevoluteJoint):
            rows.append(gpt(pa, j.pa) - gpt(pb, j.pb))
        else:
            u = rot(pa[:, 2], j.u)
            d = gpt(pb, j.p) - gpt(pa, j.g)
            rows.append(np.column_stack([dot2(left_normal(u), d),
                                         wrap(pb[:, 2] - pa[:, 2] - j.beta) * size]))
    return np.concatenate(rows, axis=1)


def assert_poses_close(got, want, size, tol, what=""):
    got, want = np.asarray(got, float), np.asarray(want, float)
    assert got.shape == want.shape, what
    np.testing.assert_allclose(got[:, :2], want[:, :2], rtol=0, atol=tol * size, err_msg=what)
    dth = np.abs(wrap(got[:, 2] - want[:, 2]))
    assert np.all(dth <= tol), f"{what}: angle differs by {dth.max():.3g} rad"


# ==============================================================================================
# random dyads built by construction
# ==============================================================================================


@dataclass(frozen=True)
class Case:
    """A dyad of ``kind`` with links L1, L2 (kind order: L1 carries ext1, L2 carries ext2)."""

    kind: str
    bind_links: tuple  # order handed to ``bind``
    joints: dict  # role ("ext1", "inner", "ext2") -> joint
    order: tuple  # order of the joints handed to ``bind``
    k1: str  # known link of ext1
    k2: str  # known link of ext2 (may equal k1)
    base: dict  # known link -> pose (3,) at phi = 0
    amp: dict  # known link -> (3,) amplitudes of the path
    freq: dict
    phase: dict
    size: float
    truth: dict  # "L1" / "L2" -> pose (3,) at phi = 0 (by construction)

    @property
    def known(self):
        return {self.k1, self.k2}

    @property
    def joint_list(self):
        return [self.joints[r] for r in self.order]

    def bind(self):
        group = GROUP_KINDS[self.kind].bind(self.bind_links, self.joint_list, self.known, self.size)
        assert group is not None, f"{self.kind} does not bind its own dyad {self.joints}"
        return group

    def path(self, phi):
        """Poses, first and second analogs ``(N, 3)`` of the known links along the path."""
        phi = np.asarray(phi, dtype=float)[:, None]
        poses, first, second = {}, {}, {}
        for k in self.known:
            a, w, c = self.amp[k], self.freq[k], self.phase[k]
            poses[k] = self.base[k] + a * (np.sin(w * phi + c) - np.sin(c))
            first[k] = a * w * np.cos(w * phi + c)
            second[k] = -a * w**2 * np.sin(w * phi + c)
        return poses, first, second


def finite(lo, hi):
    return st.floats(lo, hi, allow_nan=False, allow_infinity=False)


POINT = st.tuples(finite(-1, 1), finite(-1, 1)).map(np.array)
ANGLE = finite(-math.pi, math.pi)
POSE = st.tuples(finite(-1, 1), finite(-1, 1), ANGLE).map(np.array)


def _size(joints) -> float:
    """Largest distance between two local points of one link (as ``Mechanism.size``), >= 1."""
    pts: dict[str, list] = {}
    for j in joints:
        if isinstance(j, RevoluteJoint):
            pts.setdefault(j.a, []).append(j.pa)
            pts.setdefault(j.b, []).append(j.pb)
        else:
            pts.setdefault(j.a, []).append(j.g)
            pts.setdefault(j.b, []).append(j.p)
    size = max((math.dist(p, q) for v in pts.values() for p in v for q in v), default=0.0)
    # the random geometry spans the box [-1, 1]^2: a link whose points nearly coincide must not
    # make the characteristic length tiny
    return max(size, 1.0)


@st.composite
def cases(draw, kind):
    same = draw(st.booleans())
    k1, k2 = "k1", ("k1" if same else "k2")
    pose = {"k1": draw(POSE), "k2": draw(POSE), "L1": draw(POSE), "L2": draw(POSE)}
    if same:
        pose["k2"] = pose["k1"]

    def rev(name, l1, l2, P):
        a, b = (l2, l1) if draw(st.booleans()) else (l1, l2)
        return RevoluteJoint(name, a, b, to_local(pose[a], P), to_local(pose[b], P))

    def pri(name, guide, slider):
        """Slider's point P on a guide line through G = P - s0 u (global direction alpha)."""
        P, alpha, s0 = draw(POINT), draw(ANGLE), draw(finite(-1, 1))
        u = np.array([math.cos(alpha), math.sin(alpha)])
        ga, sl = pose[guide], pose[slider]
        return PrismaticJoint(name, guide, slider, to_local(ga, P - s0 * u),
                              tuple(float(v) for v in rot(-ga[2], u)), to_local(sl, P),
                              float(wrap(sl[2] - ga[2])))

    if kind == "RRR":
        A, B, C = draw(POINT), draw(POINT), draw(POINT)
        assume(min(np.linalg.norm(B - A), np.linalg.norm(B - C), np.linalg.norm(C - A)) > 0.1)
        joints = {"ext1": rev("A", k1, "L1", A), "inner": rev("B", "L1", "L2", B),
                  "ext2": rev("C", "L2", k2, C)}
    elif kind == "RRP":
        A, B = draw(POINT), draw(POINT)
        assume(np.linalg.norm(B - A) > 0.1)
        joints = {"ext1": rev("A", k1, "L1", A), "inner": rev("B", "L1", "L2", B),
                  "ext2": pri("P", k2, "L2")}
    elif kind == "RPR":
        A, C = draw(POINT), draw(POINT)
        joints = {"ext1": rev("A", k1, "L1", A), "inner": pri("S", "L2", "L1"),
                  "ext2": rev("C", "L2", k2, C)}
    elif kind == "PRP":
        B = draw(POINT)
        joints = {"ext1": pri("P1", k1, "L1"), "inner": rev("B", "L1", "L2", B),
                  "ext2": pri("P2", k2, "L2")}
    elif kind == "RPP":
        A = draw(POINT)
        joints = {"ext1": rev("A", k1, "L1", A), "inner": pri("S", "L2", "L1"),
                  "ext2": pri("P", k2, "L2")}
    else:  # pragma: no cover - guarded by test_every_kind_has_a_generator
        raise AssertionError(kind)
    order = tuple(draw(st.permutations(["ext1", "inner", "ext2"])))
    bind_links = ("L1", "L2") if draw(st.booleans()) else ("L2", "L1")
    known = {k1, k2}
    scale = draw(st.sampled_from([1.0, 0.5, 0.2, 0.0]))
    amp = {k: scale * np.array([draw(finite(-0.15, 0.15)), draw(finite(-0.15, 0.15)),
                                draw(finite(-0.4, 0.4))]) for k in sorted(known)}
    freq = {k: draw(finite(0.5, 2.0)) for k in sorted(known)}
    phase = {k: draw(ANGLE) for k in sorted(known)}
    case = Case(kind, bind_links, joints, order, k1, k2, {k: pose[k] for k in known}, amp, freq,
                phase, _size(joints.values()), {"L1": pose["L1"], "L2": pose["L2"]})
    # assemblable with a margin all along the path (judged by the independent textbook geometry)
    kp, _, _ = case.path(PHI_CHECK)
    _, margin = textbook(case, kp, 1)
    assume(np.all(margin > MARGIN))
    return case


# ==============================================================================================
# textbook geometry per kind (docs/methods.md#positions-the-five-dyads, derived independently)
# ==============================================================================================


def textbook(case: Case, kp: dict, M: int):
    """Poses of L1, L2 ``(N, 3)`` from the known poses, and a nondimensional margin ``(N,)``.

    ``M`` is this file's own branch sign: RRR +1 = B left of the directed line A -> C (A the pin
    of L1, C the pin of L2); RRP +1 = B ahead of the foot of A along the guide direction;
    RPR +1 = A ahead of C along the slot direction. The margin is > 0 where the dyad can be
    assembled and grows with the distance from non-assembly and singular positions.
    """
    J, k1, k2, size = case.joints, case.k1, case.k2, case.size
    ext1, inner, ext2 = J["ext1"], J["inner"], J["ext2"]
    if case.kind == "RRR":
        A, C = gpt(kp[k1], lp(ext1, k1)), gpt(kp[k2], lp(ext2, k2))
        a1, b1, b2, c2 = lp(ext1, "L1"), lp(inner, "L1"), lp(inner, "L2"), lp(ext2, "L2")
        l2, l3 = math.dist(a1, b1), math.dist(b2, c2)
        D = C - A
        d = np.hypot(D[:, 0], D[:, 1])
        psi = np.arctan2(D[:, 1], D[:, 0])
        # law of cosines: the angle at A between A->C and A->B
        gam = np.arccos(np.clip((l2**2 + d**2 - l3**2) / (2 * l2 * d), -1, 1))
        B = A + l2 * np.column_stack([np.cos(psi + M * gam), np.sin(psi + M * gam)])
        margin = np.minimum(l2 + l3 - d, d - abs(l2 - l3)) / size
        return {"L1": place2(A, B, a1, b1), "L2": place2(C, B, c2, b2)}, margin
    if case.kind == "RRP":
        A = gpt(kp[k1], lp(ext1, k1))
        a1, b1, b2 = lp(ext1, "L1"), lp(inner, "L1"), lp(inner, "L2")
        l = math.dist(a1, b1)
        th2 = kp[k2][:, 2] + ext2.beta
        U = rot(kp[k2][:, 2], ext2.u)
        Q0 = gpt(kp[k2], ext2.g) + rot(th2, np.subtract(b2, ext2.p))  # B runs on Q0 + s U
        # circle |B - A| = l against the line: s^2 + 2 s U.(Q0 - A) + |Q0 - A|^2 - l^2 = 0
        bq = dot2(U, Q0 - A)
        disc = bq**2 - dot2(Q0 - A, Q0 - A) + l**2
        s = -bq + M * np.sqrt(np.maximum(disc, 0))
        B = Q0 + s[:, None] * U
        margin = (l - np.abs(cross2(U, A - Q0))) / size
        return {"L1": place2(A, B, a1, b1), "L2": place1(B, b2, th2)}, margin
    if case.kind == "RPR":
        A, C = gpt(kp[k1], lp(ext1, k1)), gpt(kp[k2], lp(ext2, k2))
        a1, c2 = lp(ext1, "L1"), lp(ext2, "L2")
        u = np.asarray(inner.u)
        # in L2's frame, relative to C's local point: Rot(-th2)(A - C) = v + s u
        v = np.subtract(inner.g, c2) - rot(np.array([inner.beta]), np.subtract(inner.p, a1))[0]
        D = A - C
        d2 = dot2(D, D)
        uv = float(u @ v)
        e = float(cross2(u, v))  # offset of the slot line from C (along u's left normal)
        s = -uv + M * np.sqrt(np.maximum(d2 - e**2, 0))
        w = v + s[:, None] * u
        th2 = np.arctan2(D[:, 1], D[:, 0]) - np.arctan2(w[:, 1], w[:, 0])
        th1 = th2 + inner.beta
        margin = (np.sqrt(d2) - abs(e)) / size
        return {"L1": place1(A, a1, th1), "L2": place1(C, c2, th2)}, margin
    if case.kind == "PRP":
        lines, ths = [], []
        for link, g, b in (("L1", ext1, lp(inner, "L1")), ("L2", ext2, lp(inner, "L2"))):
            kpo = kp[g.a]
            th = kpo[:, 2] + g.beta
            lines.append((gpt(kpo, g.g) + rot(th, np.subtract(b, g.p)), rot(kpo[:, 2], g.u)))
            ths.append(th)
        (Q1, U1), (Q2, U2) = lines
        mat = np.stack([U1, -U2], axis=-1)  # [U1 -U2] (t1, t2) = Q2 - Q1
        ok = np.abs(cross2(U1, U2)) > 1e-3
        mat[~ok] = np.eye(2)
        t = np.linalg.solve(mat, (Q2 - Q1)[..., None])[..., 0]
        B = Q1 + t[:, :1] * U1
        return ({"L1": place1(B, lp(inner, "L1"), ths[0]), "L2": place1(B, lp(inner, "L2"), ths[1])},
                np.abs(cross2(U1, U2)))
    if case.kind == "RPP":
        A = gpt(kp[k1], lp(ext1, k1))
        a1 = lp(ext1, "L1")
        th2 = kp[k2][:, 2] + ext2.beta
        th1 = th2 + inner.beta
        P1 = A + rot(th1, np.subtract(inner.p, a1))  # L1's point in L2's slot
        G, U = gpt(kp[k2], ext2.g), rot(kp[k2][:, 2], ext2.u)
        Us = rot(th2, inner.u)
        # r2 + Rot(th2) g_s + t Us = P1 and r2 + Rot(th2) p_g = G + t' U: eliminate r2
        rhs = P1 - rot(th2, inner.g) - G + rot(th2, ext2.p)
        mat = np.stack([Us, U], axis=-1)  # t Us + t' U = rhs
        ok = np.abs(cross2(Us, U)) > 1e-3
        mat[~ok] = np.eye(2)
        t = np.linalg.solve(mat, rhs[..., None])[..., 0]
        r2 = G + t[:, 1:2] * U - rot(th2, ext2.p)
        return ({"L1": place1(A, a1, th1), "L2": np.column_stack([r2, th2])},
                np.abs(cross2(Us, U)))
    raise AssertionError(case.kind)  # pragma: no cover


def textbook_branches(case: Case):
    return (1, -1) if case.kind in ("RRR", "RRP", "RPR") else (1,)


def solver_branch(case: Case, group, M: int) -> int:
    """The solver's branch for this file's branch M (docstrings: RRR's A is the pin of
    ``group.links[0]``, so a group bound as (L2, L1) sees A and C swapped)."""
    if case.kind == "RRR" and group.links[0] == "L2":
        return -M
    return M


def true_branch(case: Case) -> int:
    """This file's branch sign of the construction, from the geometry at phi = 0."""
    J, T = case.joints, case.truth
    if case.kind == "RRR":
        A = gpt(T["L1"], lp(J["ext1"], "L1"))
        C = gpt(T["L2"], lp(J["ext2"], "L2"))
        B = gpt(T["L1"], lp(J["inner"], "L1"))
        return int(np.sign(cross2(C - A, B - A)))
    if case.kind == "RRP":
        A = gpt(T["L1"], lp(J["ext1"], "L1"))
        B = gpt(T["L1"], lp(J["inner"], "L1"))
        U = rot(case.base[case.k2][2], J["ext2"].u)
        return int(np.sign(dot2(U, B - A)))
    if case.kind == "RPR":
        A = gpt(T["L1"], lp(J["ext1"], "L1"))
        C = gpt(T["L2"], lp(J["ext2"], "L2"))
        U = rot(T["L2"][2], J["inner"].u)
        return int(np.sign(dot2(U, A - C)))
    return 1


def solve(case: Case, group, kp, branch):
    placed = group.position(dict(kp), branch)
    return placed, {**kp, **placed.poses}


# ==============================================================================================
# 1. each kind against textbook geometry, hand-checked numbers and a Newton solve
# ==============================================================================================


def test_every_kind_has_a_generator():
    """The contract suite covers every registered closed-form dyad kind (add a generator for a
    new one); the triad and the generic Newton solver have their own suite (test_generic.py)."""
    assert set(GROUP_KINDS) == {"RRR", "RRP", "RPR", "PRP", "RPP", "RRR-RRR", "N"}


@pytest.mark.parametrize("kind", ["RRR", "RRP", "RPR", "PRP", "RPP"])
@SETTINGS
@given(data=st.data())
def test_textbook_geometry(kind, data):
    """The solver equals this file's textbook closed form on every branch along a path, and the
    textbook form reproduces the construction at phi = 0 (which checks the oracle itself)."""
    case = data.draw(cases(kind))
    group = case.bind()
    kp, _, _ = case.path(PHI_GRID)
    M0 = true_branch(case)
    i0 = int(np.argmin(np.abs(PHI_GRID)))
    for M in textbook_branches(case):
        want, _ = textbook(case, kp, M)
        placed, _ = solve(case, group, kp, solver_branch(case, group, M))
        assert np.all(placed.status == assur.OK), placed.status
        for link in ("L1", "L2"):
            assert_poses_close(placed.poses[link], want[link], case.size, 1e-10, f"{kind} M={M} {link}")
            if M == M0:
                assert_poses_close(want[link][i0:i0 + 1], case.truth[link][None], case.size, 1e-10,
                                   "textbook vs construction")


def _pose(x, y, th, n=1):
    return np.tile([x, y, th], (n, 1)).astype(float)


def test_rrr_hand_numbers_3_4_5():
    """A = (0, 0), C = (5, 0), AB = 3, CB = 4: B = (1.8, +-2.4)."""
    j = [RevoluteJoint("A", "0", "2", (0.0, 0.0), (0.0, 0.0)),
         RevoluteJoint("B", "2", "3", (3.0, 0.0), (4.0, 0.0)),
         RevoluteJoint("C", "3", "0", (0.0, 0.0), (5.0, 0.0))]
    group = GROUP_KINDS["RRR"].bind(("2", "3"), j, {"0"}, 5.0)
    for M in (1, -1):
        placed = group.position({"0": _pose(0, 0, 0)}, M)
        assert placed.status.tolist() == [0]
        th2, th3 = math.atan2(M * 2.4, 1.8), math.atan2(M * 2.4, 1.8 - 5.0)
        assert_poses_close(placed.poses["2"], [[0, 0, th2]], 5, 1e-14)
        assert_poses_close(placed.poses["3"], [[5, 0, th3]], 5, 1e-14)


def test_rrp_hand_numbers():
    """A = (0, 0), rod 5, slider on the line y = -3 along +x: B = (+-4, -3)."""
    j = [RevoluteJoint("A", "0", "2", (0.0, 0.0), (0.0, 0.0)),
         RevoluteJoint("B", "2", "3", (5.0, 0.0), (0.0, 0.0)),
         PrismaticJoint("P", "0", "3", (0.0, -3.0), (1.0, 0.0), (0.0, 0.0), 0.0)]
    group = GROUP_KINDS["RRP"].bind(("2", "3"), j, {"0"}, 5.0)
    for M in (1, -1):
        placed = group.position({"0": _pose(0, 0, 0)}, M)
        assert placed.status.tolist() == [0]
        assert_poses_close(placed.poses["2"], [[0, 0, math.atan2(-3, 4 * M)]], 5, 1e-14)
        assert_poses_close(placed.poses["3"], [[4 * M, -3, 0]], 5, 1e-14)


def test_rpr_hand_numbers_offset_slot():
    """A = (3, 4), C = (0, 0), slot along L3's x axis offset 3 to its left: in L3's frame A is
    at (+-4, 3), so theta3 = atan2(4, 3) - atan2(3, 4) (M = +1) or -pi/2 (M = -1)."""
    j = [RevoluteJoint("A", "0", "2", (3.0, 4.0), (0.0, 0.0)),
         PrismaticJoint("S", "3", "2", (0.0, 3.0), (1.0, 0.0), (0.0, 0.0), 0.0),
         RevoluteJoint("C", "3", "0", (0.0, 0.0), (0.0, 0.0))]
    group = GROUP_KINDS["RPR"].bind(("2", "3"), j, {"0"}, 5.0)
    expect = {1: math.atan2(4, 3) - math.atan2(3, 4), -1: -math.pi / 2}
    for M in (1, -1):
        placed = group.position({"0": _pose(0, 0, 0)}, M)
        assert placed.status.tolist() == [0]
        assert_poses_close(placed.poses["3"], [[0, 0, expect[M]]], 5, 1e-14)
        assert_poses_close(placed.poses["2"], [[3, 4, expect[M]]], 5, 1e-14)


def test_prp_hand_numbers():
    """Guides y = 1 (slider 2) and x = 2 (slider 3, pin B 0.5 to its right): B = (2.5, 1)."""
    j = [PrismaticJoint("P1", "0", "2", (0.0, 1.0), (1.0, 0.0), (0.0, 0.0), 0.0),
         RevoluteJoint("B", "2", "3", (0.0, 0.0), (0.5, 0.0)),
         PrismaticJoint("P2", "0", "3", (2.0, 0.0), (0.0, 1.0), (0.0, 0.0), 0.0)]
    group = GROUP_KINDS["PRP"].bind(("2", "3"), j, {"0"}, 2.0)
    placed = group.position({"0": _pose(0, 0, 0)}, 1)
    assert placed.status.tolist() == [0]
    assert_poses_close(placed.poses["2"], [[2.5, 1, 0]], 2, 1e-14)
    assert_poses_close(placed.poses["3"], [[2, 1, 0]], 2, 1e-14)


def test_rpp_scotch_yoke_hand_numbers():
    """Scotch yoke: crank pin A = (cos phi, sin phi) in the vertical slot of the yoke 3, which
    slides along x: yoke at x = cos phi, x'' = -cos phi."""
    phi = np.linspace(-3, 3, 13)
    j = [RevoluteJoint("A", "1", "2", (1.0, 0.0), (0.0, 0.0)),
         PrismaticJoint("S", "3", "2", (0.0, 0.0), (0.0, 1.0), (0.0, 0.0), 0.0),
         PrismaticJoint("P", "0", "3", (0.0, 0.0), (1.0, 0.0), (0.0, 0.0), 0.0)]
    group = GROUP_KINDS["RPP"].bind(("2", "3"), j, {"0", "1"}, 1.0)
    z = np.zeros_like(phi)
    kp = {"0": np.zeros((len(phi), 3)), "1": np.column_stack([z, z, phi])}
    placed = group.position(kp, 1)
    assert np.all(placed.status == 0)
    assert_poses_close(placed.poses["3"], np.column_stack([np.cos(phi), z, z]), 1, 1e-14)
    assert_poses_close(placed.poses["2"], np.column_stack([np.cos(phi), np.sin(phi), z]), 1, 1e-14)
    first = {"0": np.zeros((len(phi), 3)), "1": np.column_stack([z, z, z + 1])}
    second = {"0": np.zeros((len(phi), 3)), "1": np.zeros((len(phi), 3))}
    d1, d2 = group.analogs({**kp, **placed.poses}, first, second)
    np.testing.assert_allclose(d1["3"], np.column_stack([-np.sin(phi), z, z]), atol=1e-13)
    np.testing.assert_allclose(d2["3"], np.column_stack([-np.cos(phi), z, z]), atol=1e-13)
    np.testing.assert_allclose(d2["2"], np.column_stack([-np.cos(phi), -np.sin(phi), z]), atol=1e-13)


@pytest.mark.parametrize("kind", ["RRR", "RRP", "RPR", "PRP", "RPP"])
@settings(SETTINGS, max_examples=25)
@given(data=st.data())
def test_newton_solution_of_the_pair_equations(kind, data):
    """Newton (scipy least_squares) on this file's pair equations, started from the construction
    perturbed by up to 3 % of the size / 0.03 rad, converges to the solver's expected branch."""
    case = data.draw(cases(kind))
    group = case.bind()
    kp = {k: v[None] for k, v in case.base.items()}
    start = np.concatenate([case.truth["L1"], case.truth["L2"]])
    kick = np.array(data.draw(st.lists(finite(-1, 1), min_size=6, max_size=6)))
    start = start + 0.03 * kick * np.array([case.size, case.size, 1] * 2)
    joints = case.joint_list

    def fun(q):
        return closure(joints, {**kp, "L1": q[None, :3], "L2": q[None, 3:]}, case.size)[0]

    sol = least_squares(fun, start, xtol=1e-15, ftol=1e-15, gtol=1e-15, method="lm")
    assume(np.max(np.abs(fun(sol.x))) < 1e-13 * case.size)
    placed, _ = solve(case, group, kp, solver_branch(case, group, true_branch(case)))
    assert placed.status.tolist() == [0]
    assert_poses_close(placed.poses["L1"], sol.x[None, :3], case.size, 1e-10, "L1")
    assert_poses_close(placed.poses["L2"], sol.x[None, 3:], case.size, 1e-10, "L2")


def _slider_crank(l1, l2, e, towards=0.0):
    b = MechanismBuilder("slider_crank_test")
    b.link("0", points={"O": (0.0, 0.0)}, guides={"slide": {"through": (0.0, e), "angle": 0.0}})
    b.link("1", line=("O", "A"), length=l1)
    b.link("2", line=("A", "B"), length=l2)
    b.link("3", points={"B": (0.0, 0.0)})
    b.revolute("O", "0", "1").revolute("A", "1", "2").revolute("B", "2", "3")
    b.prismatic("slide", "0", "3", guide="slide", at="B")
    b.inputs("1").assembly("B", towards=towards, origin="O")
    return b.build()


def test_slider_crank_textbook_formulas_through_analyze():
    """docs/methods.md#checks: x_B = l1 cos phi + sqrt(l2^2 - (l1 sin phi - e)^2), i21 = -l1 cos phi /
    (l2 cos theta2), x_B' = -l1 sin phi - l2 sin theta2 i21, through the builder and analyze."""
    l1, l2, e = 0.0742, 0.2225, 0.01335
    phi = np.linspace(0, TWO_PI, 25)
    motion = linkage.analyze(_slider_crank(l1, l2, e), phi, order=2)
    xb = l1 * np.cos(phi) + np.sqrt(l2**2 - (l1 * np.sin(phi) - e) ** 2)
    th2 = np.arcsin((e - l1 * np.sin(phi)) / l2)
    i21 = -l1 * np.cos(phi) / (l2 * np.cos(th2))
    xb1 = -l1 * np.sin(phi) - l2 * np.sin(th2) * i21
    x, x1, _ = motion.quantity("B.x")
    np.testing.assert_allclose(x, xb, rtol=0, atol=1e-14)
    np.testing.assert_allclose(motion.point("B")[:, 1], e, rtol=0, atol=1e-14)
    np.testing.assert_allclose(wrap(motion.quantity("2.theta")[0] - th2), 0, atol=1e-13)
    np.testing.assert_allclose(motion.quantity("2.theta")[1], i21, rtol=0, atol=1e-12)
    np.testing.assert_allclose(x1, xb1, rtol=0, atol=1e-14)
    s, s1, _ = motion.quantity("slide.s")
    np.testing.assert_allclose(s, xb, atol=1e-14)
    np.testing.assert_allclose(s1, xb1, atol=1e-14)


# ==============================================================================================
# 2. the contract suite over every registered kind
# ==============================================================================================

KINDS = sorted(k for k, cls in GROUP_KINDS.items() if issubclass(cls, assur.dyad.Dyad))


@pytest.mark.parametrize("kind", KINDS)
@SETTINGS
@given(data=st.data())
def test_contract_closure_on_every_branch(kind, data):
    """Every pair of the group closes to 1e-12 x size on every branch (residual from the joint
    geometry in this file); the registry picks this kind for these joints."""
    case = data.draw(cases(kind))
    group = case.bind()
    chosen = assur.solver_for(case.bind_links, case.joint_list, case.known, case.size)
    assert chosen is not None and chosen.kind == kind
    kp, _, _ = case.path(PHI_GRID)
    assert tuple(group.branches) == textbook_branches(case)
    for branch in group.branches:
        placed, merged = solve(case, group, kp, branch)
        assert np.all(placed.status == assur.OK), placed.status
        res = closure(case.joint_list, merged, case.size)
        assert np.max(np.abs(res)) <= 1e-12 * case.size, np.max(np.abs(res))
        for link in group.links:
            assert np.all(np.isfinite(placed.poses[link]))


@pytest.mark.parametrize("kind", [k for k in KINDS if len(GROUP_KINDS[k].branches) == 2])
@SETTINGS_40
@given(data=st.data())
def test_contract_two_branches_are_mirror_images(kind, data):
    """The two branches differ and are mirror-related: RRR B(-1) is B(+1) mirrored in the line
    A C; RRP the two B are mirrored about the foot of A on B's line; RPR A seen from L2 has the
    same offset from the slot and opposite along-slot coordinate. The docstring branch meaning
    picks the construction's assembly at phi = 0."""
    case = data.draw(cases(kind))
    group = case.bind()
    kp, _, _ = case.path(PHI_GRID)
    J = case.joints
    out = {M: solve(case, group, kp, solver_branch(case, group, M))[0].poses for M in (1, -1)}
    i0 = int(np.argmin(np.abs(PHI_GRID)))
    for link in ("L1", "L2"):
        assert_poses_close(out[true_branch(case)][link][i0:i0 + 1], case.truth[link][None],
                           case.size, 1e-10, f"branch meaning ({link})")
    if kind == "RRR":
        A, C = gpt(kp[case.k1], lp(J["ext1"], case.k1)), gpt(kp[case.k2], lp(J["ext2"], case.k2))
        Bp, Bm = (gpt(out[M]["L1"], lp(J["inner"], "L1")) for M in (1, -1))
        e = (C - A) / np.linalg.norm(C - A, axis=1)[:, None]
        rel = Bp - A
        mirrored = A + 2 * dot2(rel, e)[:, None] * e - rel
        np.testing.assert_allclose(Bm, mirrored, rtol=0, atol=1e-11 * case.size)
        assert np.all(cross2(C - A, Bp - A) > 0) and np.all(cross2(C - A, Bm - A) < 0)
        sep = np.linalg.norm(Bp - Bm, axis=1)
    elif kind == "RRP":
        A = gpt(kp[case.k1], lp(J["ext1"], case.k1))
        U = rot(kp[case.k2][:, 2], J["ext2"].u)
        Bp, Bm = (gpt(out[M]["L1"], lp(J["inner"], "L1")) for M in (1, -1))
        foot = Bp - dot2(Bp - A, U)[:, None] * U
        np.testing.assert_allclose(Bp + Bm, 2 * foot, rtol=0, atol=1e-11 * case.size)
        assert np.all(dot2(U, Bp - A) > 0) and np.all(dot2(U, Bm - A) < 0)
        sep = np.linalg.norm(Bp - Bm, axis=1)
    else:  # RPR
        A, C = gpt(kp[case.k1], lp(J["ext1"], case.k1)), gpt(kp[case.k2], lp(J["ext2"], case.k2))
        u = np.asarray(J["inner"].u)
        q = {M: rot(-out[M]["L2"][:, 2], A - C) for M in (1, -1)}
        np.testing.assert_allclose(cross2(u, q[1]), cross2(u, q[-1]), rtol=0, atol=1e-11 * case.size)
        np.testing.assert_allclose(dot2(u, q[1]), -dot2(u, q[-1]), rtol=0, atol=1e-11 * case.size)
        assert np.all(dot2(u, q[1]) > 0)
        sep = np.abs(wrap(out[1]["L2"][:, 2] - out[-1]["L2"][:, 2]))
    assert np.all(sep > 1e-3 * case.size)


@pytest.mark.parametrize("kind", KINDS)
@SETTINGS_40
@given(data=st.data())
def test_contract_batch_equals_per_row_loop(kind, data):
    """N positions at once equal N single-position calls; a NaN row fails alone (status -1,
    NaN poses) and leaves every other row as it is."""
    case = data.draw(cases(kind))
    group = case.bind()
    phi = PHI_GRID[::2]
    kp, _, _ = case.path(phi)
    bad = data.draw(st.integers(0, len(phi) - 1))
    kp[case.k2] = kp[case.k2].copy()
    kp[case.k2][bad] = np.nan
    for branch in group.branches:
        batch, _ = solve(case, group, kp, branch)
        want_status = np.zeros(len(phi), int)
        want_status[bad] = assur.CANNOT_ASSEMBLE
        np.testing.assert_array_equal(batch.status, want_status)
        for i in range(len(phi)):
            one, _ = solve(case, group, {k: v[i:i + 1] for k, v in kp.items()}, branch)
            assert one.status[0] == batch.status[i]
            for link in group.links:
                if i == bad:
                    assert np.all(np.isnan(batch.poses[link][i]))
                else:
                    np.testing.assert_allclose(batch.poses[link][i], one.poses[link][0], rtol=0,
                                               atol=1e-14 * case.size)


# 6th-order central differences
FD1 = np.array([-1 / 60, 3 / 20, -3 / 4, 0, 3 / 4, -3 / 20, 1 / 60])
FD2 = np.array([1 / 90, -3 / 20, 3 / 2, -49 / 18, 3 / 2, -3 / 20, 1 / 90])
FD_H = 2e-3
FD_PHI0 = np.array([-0.45, -0.1, 0.2, 0.5])


@pytest.mark.parametrize("kind", KINDS)
@SETTINGS
@given(data=st.data())
def test_contract_analogs_equal_finite_differences(kind, data):
    """First and second analogs (known links moving and turning along the path, with exact
    derivatives) equal 6th-order central differences of the solved positions."""
    case = data.draw(cases(kind))
    group = case.bind()
    k = np.arange(-3, 4)
    phis = (FD_PHI0[:, None] + k[None, :] * FD_H).ravel()
    kp, k1st, k2nd = case.path(phis)
    centre = {n: v[3::7] for n, v in kp.items()}
    c1, c2 = ({n: v[3::7] for n, v in d.items()} for d in (k1st, k2nd))
    for branch in group.branches:
        placed, merged = solve(case, group, kp, branch)
        assert np.all(placed.status == assur.OK)
        _, at_centre = solve(case, group, centre, branch)
        d1, d2 = group.analogs(at_centre, c1, c2)
        d1_only, none = group.analogs(at_centre, c1)
        assert none is None
        for link in group.links:
            q = placed.poses[link].reshape(len(FD_PHI0), 7, 3).copy()
            q[:, :, 2] = q[:, 3:4, 2] + wrap(q[:, :, 2] - q[:, 3:4, 2])  # unwrap about the centre
            fd1 = np.einsum("k,nkj->nj", FD1, q) / FD_H
            fd2 = np.einsum("k,nkj->nj", FD2, q) / FD_H**2
            scale = np.array([case.size, case.size, 1.0])
            tol1 = 1e-8 * scale * (1 + np.abs(fd1 / scale).max())
            tol2 = 1e-6 * scale * (1 + np.abs(fd2 / scale).max())
            assert np.all(np.abs(d1[link] - fd1) <= tol1), (link, branch, d1[link], fd1)
            assert np.all(np.abs(d2[link] - fd2) <= tol2), (link, branch, d2[link], fd2)
            np.testing.assert_array_equal(d1_only[link], d1[link])


def scaled(case: Case, k: float) -> Case:
    """All lengths x k (local points, known positions, path amplitudes, size); angles kept."""
    def sj(j):
        if isinstance(j, RevoluteJoint):
            return replace(j, pa=tuple(k * np.array(j.pa)), pb=tuple(k * np.array(j.pb)))
        return replace(j, g=tuple(k * np.array(j.g)), p=tuple(k * np.array(j.p)))
    m = np.array([k, k, 1.0])
    return replace(case, joints={r: sj(j) for r, j in case.joints.items()},
                   base={n: m * v for n, v in case.base.items()},
                   amp={n: m * v for n, v in case.amp.items()},
                   size=k * case.size, truth={n: m * v for n, v in case.truth.items()})


def mirrored(case: Case) -> Case:
    """The mirror image in the x axis: y -> -y, angles -> -angles (local frames mirrored too)."""
    f = np.array([1.0, -1.0])

    def mj(j):
        if isinstance(j, RevoluteJoint):
            return replace(j, pa=tuple(f * j.pa), pb=tuple(f * j.pb))
        return replace(j, g=tuple(f * j.g), u=tuple(f * j.u), p=tuple(f * j.p), beta=-j.beta)
    m = np.array([1.0, -1.0, -1.0])
    return replace(case, joints={r: mj(j) for r, j in case.joints.items()},
                   base={n: m * v for n, v in case.base.items()},
                   amp={n: m * v for n, v in case.amp.items()},
                   phase=dict(case.phase), truth={n: m * v for n, v in case.truth.items()})


@pytest.mark.parametrize("kind", KINDS)
@SETTINGS_40
@given(data=st.data(), log_k=finite(-3, 3))
def test_contract_scale_invariance(kind, data, log_k):
    """All lengths x k: positions x k, angles unchanged, same status; analogs: lengths x k."""
    case = data.draw(cases(kind))
    k = 10.0**log_k
    big = scaled(case, k)
    g, gb = case.bind(), big.bind()
    kp, k1, k2 = case.path(PHI_GRID)
    bkp, bk1, bk2 = big.path(PHI_GRID)
    m = np.array([k, k, 1.0])
    for branch in g.branches:
        p, merged = solve(case, g, kp, branch)
        pb, bmerged = solve(big, gb, bkp, branch)
        np.testing.assert_array_equal(p.status, pb.status)
        d1, d2 = g.analogs(merged, k1, k2)
        b1, b2 = gb.analogs(bmerged, bk1, bk2)
        for link in g.links:
            assert_poses_close(pb.poses[link], m * p.poses[link], big.size, 1e-11, f"{link} pose")
            np.testing.assert_allclose(b1[link], m * d1[link], rtol=1e-9, atol=1e-11 * big.size)
            np.testing.assert_allclose(b2[link], m * d2[link], rtol=1e-8, atol=1e-10 * big.size)


@pytest.mark.parametrize("kind", KINDS)
@SETTINGS_40
@given(data=st.data())
def test_contract_mirror_symmetry(kind, data):
    """Mirroring the dyad and its known links in the x axis mirrors the solution (docs/methods.md#checks).
    RRR changes branch (left of A->C becomes right); RRP and RPR keep it (their branch is an
    along-guide direction, which the mirror keeps)."""
    case = data.draw(cases(kind))
    mir = mirrored(case)
    g, gm = case.bind(), mir.bind()
    kp, _, _ = case.path(PHI_GRID)
    mkp, _, _ = mir.path(PHI_GRID)
    m = np.array([1.0, -1.0, -1.0])
    for branch in g.branches:
        mbranch = -branch if kind == "RRR" else branch
        p, _ = solve(case, g, kp, branch)
        pm, _ = solve(mir, gm, mkp, mbranch)
        np.testing.assert_array_equal(p.status, pm.status)
        for link in g.links:
            assert_poses_close(pm.poses[link], m * p.poses[link], case.size, 1e-11, f"{link} M={branch}")


def reframed(case: Case, frames: dict) -> Case:
    """The same dyad with the local frame of each moving link moved: ``frames[X] = (t, phi)``
    puts X's new origin at its old local point t, its new x axis at phi from the old one.
    Local points become ``Rot(-phi)(p - t)``; a pose becomes ``(r + Rot(theta) t, theta + phi)``."""
    def point(link, p):
        if link not in frames:
            return tuple(p)
        t, ph = frames[link]
        return tuple(float(v) for v in rot(np.array([-ph]), np.subtract(p, t))[0])

    def rj(j):
        if isinstance(j, RevoluteJoint):
            return replace(j, pa=point(j.a, j.pa), pb=point(j.b, j.pb))
        turn_a = frames[j.a][1] if j.a in frames else 0.0
        turn_b = frames[j.b][1] if j.b in frames else 0.0
        ua = tuple(float(v) for v in rot(np.array([-turn_a]), j.u)[0])
        beta = j.beta - turn_a + turn_b
        return replace(j, g=point(j.a, j.g), u=ua, p=point(j.b, j.p), beta=beta)

    truth = {}
    for link, pose in case.truth.items():
        t, ph = frames[link]
        truth[link] = np.concatenate([pose[:2] + rot(np.array([pose[2]]), t)[0], [pose[2] + ph]])
    return replace(case, joints={r: rj(j) for r, j in case.joints.items()}, truth=truth)


@pytest.mark.parametrize("kind", KINDS)
@SETTINGS_40
@given(data=st.data(), direction=ANGLE, turn1=ANGLE, turn2=ANGLE)
def test_contract_local_frames_do_not_matter(kind, data, direction, turn1, turn2):
    """Where each moving link's local origin and axes are put is a modelling choice: moving them
    (origin 1, 10, 100 x size away from the link's points) changes neither the status nor the
    global placement of any joint point. (The size used for tolerances is unchanged: it is the
    largest distance between two points of one link, which a change of frame keeps.)"""
    case = data.draw(cases(kind))
    g = case.bind()
    kp, _, _ = case.path(PHI_GRID)
    for factor in (1.0, 10.0, 100.0):
        R = factor * case.size
        t = R * np.array([math.cos(direction), math.sin(direction)])
        far = reframed(case, {"L1": (t, turn1), "L2": (-t, turn2)})
        gf = far.bind()
        for branch in g.branches:
            p, merged = solve(case, g, kp, branch)
            pf, fmerged = solve(far, gf, kp, branch)
            np.testing.assert_array_equal(pf.status, assur.OK, err_msg=f"frames {factor:g} x size away")
            res = closure(far.joint_list, fmerged, far.size)
            assert np.max(np.abs(res)) <= 1e-12 * (far.size + R)
            for role, j in case.joints.items():
                jf = far.joints[role]
                if isinstance(j, RevoluteJoint):
                    np.testing.assert_allclose(gpt(fmerged[jf.a], jf.pa), gpt(merged[j.a], j.pa),
                                               rtol=0, atol=1e-11 * (case.size + R))
                else:
                    np.testing.assert_allclose(gpt(fmerged[jf.b], jf.p), gpt(merged[j.b], j.p),
                                               rtol=0, atol=1e-11 * (case.size + R))


def test_status_does_not_depend_on_link_frame_origin():
    """Minimal form of the above: a regular four-bar (OA = 0.1 rotating, AB = 0.3, CB = 0.25,
    OC = 0.3) whose coupler and rocker frames sit `off` m from their points must be OK at every
    angle. Physically nothing changes with `off`."""
    phi = np.linspace(0, TWO_PI, 13)
    z = np.zeros_like(phi)
    kp = {"0": np.zeros((13, 3)), "1": np.column_stack([z, z, phi])}
    for off in (0.0, 3.0, 10.0, 30.0):
        j = [RevoluteJoint("A", "1", "2", (0.1, 0.0), (off, 0.0)),
             RevoluteJoint("B", "2", "3", (off + 0.3, 0.0), (off + 0.25, 0.0)),
             RevoluteJoint("C", "3", "0", (off, 0.0), (0.3, 0.0))]
        group = GROUP_KINDS["RRR"].bind(("2", "3"), j, {"0", "1"}, 0.3)
        placed = group.position(kp, 1)
        np.testing.assert_array_equal(placed.status, 0, err_msg=f"frames {off} m from the links' points")
        B = gpt(placed.poses["2"], (off + 0.3, 0.0))
        A = 0.1 * np.column_stack([np.cos(phi), np.sin(phi)])
        np.testing.assert_allclose(np.linalg.norm(B - A, axis=1), 0.3, atol=1e-12)
        np.testing.assert_allclose(np.linalg.norm(B - [0.3, 0.0], axis=1), 0.25, atol=1e-12)


# ==============================================================================================
# 3. positions that cannot be assembled, singular positions, errors
# ==============================================================================================


def _rrr_on_frame(l2, l3):
    """RRR with A = (0, 0) on link 'k' and C on link 'c' (a translating frame)."""
    j = [RevoluteJoint("A", "k", "2", (0.0, 0.0), (0.0, 0.0)),
         RevoluteJoint("B", "2", "3", (l2, 0.0), (l3, 0.0)),
         RevoluteJoint("C", "3", "c", (0.0, 0.0), (0.0, 0.0))]
    return GROUP_KINDS["RRR"].bind(("2", "3"), j, {"k", "c"}, max(l2, l3))


@pytest.mark.parametrize("l2, l3", [(0.3, 0.2), (0.2, 0.3), (0.25, 0.25)])
def test_rrr_out_of_reach_is_minus_one_and_ok_elsewhere(l2, l3):
    """C moves along a line: status -1 exactly where d > l2 + l3 or d < |l2 - l3|, NaN poses
    there; 0 with finite poses everywhere else (the boundary itself is not sampled)."""
    d = np.linspace(0.001, 0.9, 200)
    d = d[np.minimum(np.abs(d - (l2 + l3)), np.abs(d - abs(l2 - l3))) > 1e-6]
    ang = 0.7
    kp = {"k": np.zeros((len(d), 3)),
          "c": np.column_stack([d * math.cos(ang), d * math.sin(ang), np.zeros_like(d)])}
    group = _rrr_on_frame(l2, l3)
    reach = (d < l2 + l3) & (d > abs(l2 - l3))
    for M in (1, -1):
        placed = group.position(kp, M)
        np.testing.assert_array_equal(placed.status, np.where(reach, 0, -1))
        for link in ("2", "3"):
            assert np.all(np.isnan(placed.poses[link][~reach]))
            assert np.all(np.isfinite(placed.poses[link][reach]))


@pytest.mark.parametrize("kind_case", ["RRP", "RPR"])
def test_rrp_rpr_out_of_reach(kind_case):
    """RRP: pin A farther than the rod from the slider's line -> -1. RPR: A closer to C than the
    slot's offset -> -1. Elsewhere 0."""
    dist = np.linspace(0.0, 2.0, 81)
    dist = dist[np.abs(dist - 1.0) > 1e-6]
    z = np.zeros_like(dist)
    if kind_case == "RRP":
        j = [RevoluteJoint("A", "k", "2", (0.0, 0.0), (0.0, 0.0)),
             RevoluteJoint("B", "2", "3", (1.0, 0.0), (0.0, 0.0)),
             PrismaticJoint("P", "0", "3", (0.0, 0.0), (1.0, 0.0), (0.0, 0.0), 0.0)]
        known = {"k", "0"}
        kp = {"0": np.zeros((len(dist), 3)), "k": np.column_stack([0.3 + z, dist, z])}  # h = dist
    else:
        j = [RevoluteJoint("A", "k", "2", (0.0, 0.0), (0.0, 0.0)),
             PrismaticJoint("S", "3", "2", (0.0, 1.0), (1.0, 0.0), (0.0, 0.0), 0.0),  # offset 1
             RevoluteJoint("C", "3", "0", (0.0, 0.0), (0.0, 0.0))]
        known = {"k", "0"}
        kp = {"0": np.zeros((len(dist), 3)),
              "k": np.column_stack([dist * math.cos(2.0), dist * math.sin(2.0), z])}  # d = dist
    group = GROUP_KINDS[kind_case].bind(("2", "3"), j, known, 1.0)
    ok = dist < 1.0 if kind_case == "RRP" else dist > 1.0
    for M in (1, -1):
        placed = group.position(kp, M)
        np.testing.assert_array_equal(placed.status, np.where(ok, 0, -1))
        assert np.all(np.isnan(placed.poses["2"][~ok])) and np.all(np.isfinite(placed.poses["2"][ok]))


def test_rrr_exact_toggle_is_flagged_by_the_group():
    """A = (0, 0), C = (5, 0), l2 = 2, l3 = 3: A, B, C collinear (h = 0 exactly): the position
    is singular (-2) or refused (-1), never OK; d = 5 +- 0.5 are OK."""
    group = _rrr_on_frame(2.0, 3.0)
    d = np.array([5.0, 4.5, 4.99, 5.0])
    z = np.zeros_like(d)
    kp = {"k": np.zeros((4, 3)), "c": np.column_stack([d, z, z])}
    for M in (1, -1):
        placed = group.position(kp, M)
        assert placed.status[0] in (assur.SINGULAR, assur.CANNOT_ASSEMBLE)
        assert placed.status[3] in (assur.SINGULAR, assur.CANNOT_ASSEMBLE)
        assert placed.status[1] == placed.status[2] == assur.OK
        if placed.status[0] == assur.SINGULAR:  # the position itself exists: B = (2, 0)
            np.testing.assert_allclose(gpt(placed.poses["2"][:1], (2.0, 0.0)), [[2.0, 0.0]], atol=1e-14)


def _four_bar(OA, AB, CB, Cx, **assembly):
    b = MechanismBuilder("fb_test")
    b.link("0", points={"O": (0.0, 0.0), "C": (Cx, 0.0)})
    b.link("1", line=("O", "A"), length=OA)
    b.link("2", line=("A", "B"), length=AB)
    b.link("3", line=("C", "B"), length=CB)
    for n, a, c in [("O", "0", "1"), ("A", "1", "2"), ("B", "2", "3"), ("C", "3", "0")]:
        b.revolute(n, a, c)
    b.inputs("1").assembly("B", **assembly)
    return b.build()


@pytest.mark.parametrize("order", [0, 1, 2])
def test_analyze_masks_an_exact_toggle(order):
    """Four-bar O = (0, 0), C = (3, 0), OA = 1, AB = 4, CB = 2: at phi = 0 exactly, d = |C - A|
    = 2 = AB - CB, so A, C, B are collinear (B = (5, 0)), a singular position of the RRR group.
    ``analyze(on_failure="mask")`` must flag it (-2 or -1) with NaN analogs, and solve the other
    angles normally (d in (2, 4] is assemblable there)."""
    mech = _four_bar(1.0, 4.0, 2.0, 3.0, branch=1)
    phi = np.array([0.0, 1.0, 2.0, 3.0])
    motion = linkage.analyze(mech, phi, order=order, on_failure="mask")
    assert motion.status[0] in (assur.SINGULAR, assur.CANNOT_ASSEMBLE)
    np.testing.assert_array_equal(motion.status[1:], 0)
    if order >= 1:
        for d in (motion.first, motion.second) if order == 2 else (motion.first,):
            for link in ("2", "3"):
                assert np.all(np.isnan(d[link][0])) and np.all(np.isfinite(d[link][1:]))
    # the other angles are right: |B - A| = 4, |B - C| = 2
    B = motion.point("B")[1:]
    A = np.column_stack([np.cos(phi[1:]), np.sin(phi[1:])])
    np.testing.assert_allclose(np.linalg.norm(B - A, axis=1), 4.0, atol=1e-13)
    np.testing.assert_allclose(np.linalg.norm(B - [3.0, 0.0], axis=1), 2.0, atol=1e-13)


def test_analyze_raises_assembly_error_at_an_exact_toggle():
    """Same toggle with on_failure="raise": an AssemblyError naming 0 deg (not a LinAlgError)."""
    mech = _four_bar(1.0, 4.0, 2.0, 3.0, branch=1)
    with pytest.raises(linkage.AssemblyError) as err:
        linkage.analyze(mech, np.array([0.0, 1.0, 2.0]), order=2, on_failure="raise")
    np.testing.assert_allclose(err.value.angles_deg, [0.0])


def test_prp_parallel_guides_cannot_be_assembled():
    """Guide 2 turns with its link k; where it is parallel (or anti-parallel) to guide 1 the
    PRP group is -1 with NaN poses; elsewhere it is at the lines' intersection."""
    j = [PrismaticJoint("P1", "0", "2", (0.0, 0.5), (1.0, 0.0), (0.0, 0.0), 0.0),
         RevoluteJoint("B", "2", "3", (0.0, 0.0), (0.0, 0.0)),
         PrismaticJoint("P2", "k", "3", (0.0, 0.0), (1.0, 0.0), (0.0, 0.0), 0.0)]
    group = GROUP_KINDS["PRP"].bind(("2", "3"), j, {"0", "k"}, 1.0)
    th = np.array([0.0, math.pi, -math.pi, 0.3, 1.2, -2.0, math.pi / 2])
    z = np.zeros_like(th)
    kp = {"0": np.zeros((len(th), 3)), "k": np.column_stack([z + 0.2, z, th])}
    placed = group.position(kp, 1)
    parallel = np.abs(np.sin(th)) < 1e-12
    np.testing.assert_array_equal(placed.status, np.where(parallel, -1, 0))
    assert np.all(np.isnan(placed.poses["2"][parallel]))
    # elsewhere: B on y = 0.5 and on the line through (0.2, 0) at angle th
    xb = 0.2 + 0.5 / np.tan(th[~parallel])
    np.testing.assert_allclose(placed.poses["2"][~parallel], np.column_stack([xb, z[~parallel] + 0.5,
                                                                             z[~parallel]]), atol=1e-14)


def test_rpp_slot_parallel_to_guide_cannot_be_assembled():
    """RPP whose slot (on 3) is parallel to 3's guide on the frame: -1 at every position."""
    j = [RevoluteJoint("A", "1", "2", (1.0, 0.0), (0.0, 0.0)),
         PrismaticJoint("S", "3", "2", (0.0, 0.0), (1.0, 0.0), (0.0, 0.0), 0.0),
         PrismaticJoint("P", "0", "3", (0.0, 0.0), (1.0, 0.0), (0.0, 0.0), 0.0)]
    group = GROUP_KINDS["RPP"].bind(("2", "3"), j, {"0", "1"}, 1.0)
    phi = np.linspace(0.1, 3, 5)
    z = np.zeros_like(phi)
    placed = group.position({"0": np.zeros((5, 3)), "1": np.column_stack([z, z, phi])}, 1)
    np.testing.assert_array_equal(placed.status, -1)
    assert np.all(np.isnan(placed.poses["3"]))


# four-bar O = (0, 0), C = (0.3, 0), OA = 0.2, AB = CB = 0.15: d(phi)^2 = 0.13 - 0.12 cos phi
# <= 0.3^2 iff cos phi >= 1/3, so it assembles only for |phi| <= acos(1/3) = 70.53 deg
_FB_LIMIT = math.degrees(math.acos(1.0 / 3.0))


def _fb_failing():
    return _four_bar(0.2, 0.15, 0.15, 0.3, left_of=("A", "C"))


def test_analyze_mask_status_of_a_four_bar_that_does_not_fully_turn():
    deg = np.arange(-180.0, 180.0, 5.0)
    motion = linkage.analyze(_fb_failing(), np.radians(deg), order=2, on_failure="mask")
    want = np.where(np.abs(deg) < _FB_LIMIT, 0, -1)
    np.testing.assert_array_equal(motion.status, want)
    ok = want == 0
    B = motion.point("B")
    assert np.all(np.isnan(B[~ok])) and np.all(np.isfinite(B[ok]))
    A = 0.2 * np.column_stack([np.cos(np.radians(deg)), np.sin(np.radians(deg))])
    np.testing.assert_allclose(np.linalg.norm(B[ok] - A[ok], axis=1), 0.15, atol=1e-14)
    np.testing.assert_allclose(np.linalg.norm(B[ok] - [0.3, 0.0], axis=1), 0.15, atol=1e-14)
    assert np.all(cross2(np.array([0.3, 0.0]) - A[ok], B[ok] - A[ok]) > 0)  # left of A -> C
    for d in (motion.first, motion.second):
        assert np.all(np.isnan(d["2"][~ok])) and np.all(np.isfinite(d["2"][ok]))


def test_analyze_raise_lists_the_failing_angles():
    deg = np.arange(0.0, 360.0, 20.0)
    bad = deg[np.abs(wrap(np.radians(deg))) > math.radians(_FB_LIMIT)]
    assert 0 < len(bad) <= 20
    with pytest.raises(linkage.AssemblyError) as err:
        linkage.analyze(_fb_failing(), np.radians(deg), on_failure="raise")
    np.testing.assert_allclose(np.sort(err.value.angles_deg), bad, atol=1e-9)
    message = str(err.value)
    listed = [float(x) for x in re.findall(r"-?\d+(?:\.\d+)?(?:e[-+]?\d+)?", message.split("(deg):")[1])]
    # the message names every failing angle and no other number
    np.testing.assert_allclose(np.sort(listed), bad, atol=1e-4)
    assert issubclass(linkage.AssemblyError, linkage.LinkageError)
