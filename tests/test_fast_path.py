"""The fast path of the dyads (``Dyad.solve``: closed-form elimination, conditioning and closure
computed elementwise) against an oracle that shares none of its code: the links placed by plane
geometry written in the tests (test_dyads.textbook: circle-circle, circle-line, line-line
intersections; here the line-line ones of PRP and RPP without a cut-off), their closure measured
from the joints' geometry, and the generic Jacobian path on those poses (``(N, 6, 6)`` Jacobians,
LAPACK solves and determinants): every kind, random geometry and paths, both branches, positions
where the group cannot be assembled, singular positions, and a batch whose local geometry differs
at every position. The conditioning of the RRR dyad is also compared with its closed form worked
out here by hand (docs/numerics.md)."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

sys.path.insert(0, str(Path(__file__).resolve().parent))

from test_dyads import SETTINGS, cases, closure, cross2, gpt, lp, rot, solver_branch, textbook  # noqa: E402

import linkage  # noqa: E402
from assur.base import (  # noqa: E402
    ANALOG_TOL,
    CANNOT_ASSEMBLE,
    CLOSURE_TOL,
    OK,
    ROUNDOFF_FACTOR,
    SINGULAR,
    Group,
    GroupSolution,
    PrismaticJoint,
    RevoluteJoint,
)
from assur.registry import GROUP_KINDS  # noqa: E402

KINDS = ["RRR", "RRP", "RPR", "PRP", "RPP"]
PHI = np.linspace(-3.0, 3.0, 61)
EPS = np.finfo(float).eps


# ----------------------------------------------------------------------------------------------
# the oracle: links placed independently, then the generic Jacobian path on those poses
# ----------------------------------------------------------------------------------------------


def place_independently(case, kp, branch, group):
    """Poses ``(N, 3)`` of L1, L2 on the solver's ``branch`` by plane geometry written in the tests,
    not by the library's ``_place``: test_dyads.textbook for RRR, RRP, RPR (circle-circle,
    circle-line); for PRP and RPP the line-line intersection by Cramer's rule, NaN only where the
    lines are exactly parallel (textbook's own cut-off at |sin| < 1e-3 would misplace groups that
    the fast path rightly assembles)."""
    M = solver_branch(case, group, branch)       # its own inverse: a sign flip or nothing
    J = case.joints
    ext1, inner, ext2 = J["ext1"], J["inner"], J["ext2"]
    if case.kind == "PRP":
        lines, angles = [], []
        for g, b in ((ext1, lp(inner, "L1")), (ext2, lp(inner, "L2"))):
            known = kp[g.a]
            th = known[:, 2] + g.beta
            lines.append((gpt(known, g.g) + rot(th, np.subtract(b, g.p)), rot(known[:, 2], g.u)))
            angles.append(th)
        (Q1, U1), (Q2, U2) = lines
        with np.errstate(divide="ignore", invalid="ignore"):
            t1 = cross2(Q2 - Q1, U2) / cross2(U1, U2)    # Q1 + t1 U1 on the line Q2 + t2 U2
        B = Q1 + t1[:, None] * U1
        return {link: np.column_stack([B - rot(th, lp(inner, link)), th]) for link, th in zip(("L1", "L2"), angles)}
    if case.kind == "RPP":
        A = gpt(kp[case.k1], lp(ext1, case.k1))
        a1 = lp(ext1, "L1")
        th2 = kp[case.k2][:, 2] + ext2.beta
        th1 = th2 + inner.beta
        P1 = A + rot(th1, np.subtract(inner.p, a1))      # L1's point in L2's slot
        G, U = gpt(kp[case.k2], ext2.g), rot(kp[case.k2][:, 2], ext2.u)
        Us = rot(th2, inner.u)
        # r2 + Rot(th2) g_s + t Us = P1 and r2 + Rot(th2) p = G + t' U: eliminate r2 and t
        rhs = P1 - rot(th2, inner.g) - G + rot(th2, ext2.p)
        with np.errstate(divide="ignore", invalid="ignore"):
            t_rail = cross2(Us, rhs) / cross2(Us, U)
        r2 = G + t_rail[:, None] * U - rot(th2, ext2.p)
        return {"L1": np.column_stack([A - rot(th1, a1), th1]), "L2": np.column_stack([r2, th2])}
    placed, _ = textbook(case, kp, M)
    return placed


def generic_oracle(group, poses, first, second, placed, size):
    """What ``Dyad.solve`` must give, from poses of the group's links ``placed`` independently of
    the library's closed forms: closure from the joints' geometry (test_dyads.closure; assembled
    where every pair closes to CLOSURE_TOL x size), conditioning and the sign of the determinant by
    the generic ``Group.conditioning`` (LAPACK determinant of the scaled ``(N, 6, 6)`` Jacobian),
    status SINGULAR where the bound ROUNDOFF_FACTOR eps / r**2 of the analogs' error exceeds
    ANALOG_TOL (docs/numerics.md), analogs by the generic ``Group.analogs`` (LAPACK solves)."""
    merged = {**poses, **placed}
    residual = closure(group.joints, merged, size)
    with np.errstate(invalid="ignore"):
        assembled = np.all(np.isfinite(residual), axis=1) & (np.max(np.abs(residual), axis=1) <= CLOSURE_TOL * size)
    n = len(assembled)
    status = np.full(n, CANNOT_ASSEMBLE)
    sign, conditioning, bound = np.zeros(n), np.full(n, np.nan), np.full(n, np.inf)
    if assembled.any():
        at = {k: v[assembled] for k, v in merged.items()}
        ratio, det_sign = Group.conditioning(group, Group.jacobians(group, at)[0], at)
        with np.errstate(divide="ignore"):
            own = np.where(ratio > 0, ROUNDOFF_FACTOR * EPS / ratio**2, np.inf)
        sign[assembled], conditioning[assembled], bound[assembled] = det_sign, ratio, own
        status[assembled] = np.where(own <= ANALOG_TOL, OK, SINGULAR)
    new = {k: np.where(assembled[:, None], v, np.nan) for k, v in placed.items()}
    d1 = d2 = None
    if first is not None:
        d1, d2 = Group.analogs(group, {**poses, **new}, first, second, valid=status == OK)
    if second is not None:
        status, bound = _second_analogs_term(group, {**poses, **new}, first, second, d1, d2, status, bound)
    return GroupSolution(new, status, sign, conditioning, bound, d1, d2)


def _second_analogs_term(group, poses, first, second, d1, d2, status, bound):
    """docs/numerics.md: with second analogs the bound adds a tenth of ``2 A CHANGE_FACTOR eps / r**3``,
    ``A = w min(1, s1 / s2)`` (w: the largest rotation analog of the group's links and of the known
    links guiding its prismatic pairs; s1, s2: the largest first / second analogs of every link
    involved, lengths over the largest distance between the group's contact points)."""
    from assur.base import CHANGE_FACTOR
    ok = status == OK
    if not ok.any():
        return status, bound
    at = {k: v[ok] for k, v in poses.items()}
    r = Group.conditioning(group, Group.jacobians(group, at)[0], at)[0]
    contacts = Group.contact_points(group, at)
    size = np.max(np.linalg.norm(contacts[:, :, None] - contacts[:, None], axis=-1), axis=(1, 2))
    size = np.maximum(size, np.maximum(1e-12 * np.max(np.abs(contacts), axis=(1, 2)), 1e-9 * group.size))
    one = {**first, **d1}
    two = {**second, **d2}
    involved = [*group.known_links, *group.links]
    turning = set(group.links) | {j.a for j in group.joints if isinstance(j, PrismaticJoint)}
    w = np.max([np.abs(one[k][ok, 2]) for k in involved if k in turning], axis=0)

    def largest(q):
        return np.max([np.maximum(np.abs(q[k][ok, 2]), np.linalg.norm(q[k][ok, :2], axis=1) / size)
                       for k in involved], axis=0)

    s1, s2 = largest(one), largest(two)
    amplitude = w * np.minimum(1.0, s1 / np.where(s2 > 0, s2, np.inf))
    bound = bound.copy()
    bound[ok] += 2 * amplitude * CHANGE_FACTOR * EPS / r**3 / 10
    flagged = ok & (bound > ANALOG_TOL)
    for analogs in (d1, d2):
        for v in analogs.values():
            v[flagged] = np.nan
    return np.where(flagged, SINGULAR, status), bound


def conditioning_tolerance(want):
    """How far two independent computations of the conditioning r may differ: 1e-6 relative (where
    a group's contact points coincide -- a PRP whose sliders' points are its pin -- its scale is the
    floor 1e-9 of the mechanism's size, and the conditioning carries the contacts' round-off
    amplified by 1e9 inside a sum with 1), plus the round-off of positions placed independently
    next to a singular position, which moves r by about eps / r (measured factor below 0.1 next
    to the toggles in the RRR sweep of test_rrr_conditioning_equals_its_closed_form_over_many_positions;
    2 here)."""
    with np.errstate(divide="ignore"):
        return 1e-6 * want + 1e-14 + np.where(want > 0, 2 * EPS / want, 0.0)


def assert_same(fast, oracle, size):
    """Statuses and signs equal; poses and analogs equal to round-off (positions placed
    independently differ by about eps x size / r next to a singular position); conditioning
    within :func:`conditioning_tolerance`, bounds (proportional to 1 / r**2) accordingly."""
    np.testing.assert_array_equal(fast.status, oracle.status)
    ok = oracle.status == OK
    placed = oracle.status != CANNOT_ASSEMBLE
    clear = placed & (oracle.conditioning > 1e-10)     # at an exact toggle the sign is round-off
    np.testing.assert_array_equal(fast.jacobian_sign[clear], oracle.jacobian_sign[clear])
    np.testing.assert_array_equal(np.isnan(fast.conditioning), np.isnan(oracle.conditioning))
    r = oracle.conditioning[placed]
    gap = np.abs(fast.conditioning[placed] - r)
    assert np.all(gap <= conditioning_tolerance(r)), f"conditioning differs by {gap.max():.3g}"
    rc, bound = oracle.conditioning[clear], oracle.error_bound[clear]
    gap = np.abs(fast.error_bound[clear] - bound)
    assert np.all(gap <= 3 * bound * conditioning_tolerance(rc) / rc), "error bounds differ"
    with np.errstate(divide="ignore"):
        spread = size * (1e-12 + 4 * EPS / np.where(placed, oracle.conditioning, np.inf))
    for link in oracle.poses:
        np.testing.assert_array_equal(np.isnan(fast.poses[link]), np.isnan(oracle.poses[link]))
        d = fast.poses[link][placed] - oracle.poses[link][placed]
        d[:, 2] = (d[:, 2] + np.pi) % (2 * np.pi) - np.pi
        assert np.all(np.abs(d[:, :2]) <= spread[placed, None]), f"{link}: poses differ by {np.abs(d[:, :2]).max():.3g}"
        assert np.all(np.abs(d[:, 2]) <= spread[placed] / size), f"{link}: angles differ by {np.abs(d[:, 2]).max():.3g}"
        for got, want in ((fast.first, oracle.first), (fast.second, oracle.second)):
            assert np.all(np.isnan(got[link][~ok]))
            scale = max(1.0, float(np.max(np.abs(want[link][ok]), initial=0.0)))
            np.testing.assert_allclose(got[link][ok], want[link][ok], rtol=0, atol=1e-9 * scale)


@pytest.mark.parametrize("kind", KINDS)
@settings(SETTINGS, max_examples=40)
@given(data=st.data())
def test_fast_path_equals_the_generic_path(kind, data):
    """The fast path against :func:`generic_oracle` on links placed by :func:`place_independently`
    (the library's placement is not used by the oracle)."""
    case = data.draw(cases(kind))
    group = case.bind()
    poses, first, second = case.path(PHI)     # PHI runs beyond the assembled range of many cases
    for branch in group.branches:
        fast = group.solve(poses, first, second, branch)
        placed = place_independently(case, poses, branch, group)
        oracle = generic_oracle(group, poses, first, second, placed, case.size)
        assert_same(fast, oracle, case.size)


@pytest.mark.parametrize("kind", KINDS)
@settings(SETTINGS, max_examples=15)
@given(data=st.data())
def test_positions_only_and_first_order_agree_with_the_full_solve(kind, data):
    case = data.draw(cases(kind))
    group = case.bind()
    poses, first, second = case.path(PHI)
    full = group.solve(poses, first, second)
    only = group.solve(poses)
    one = group.solve(poses, first)
    assert only.first is None and one.second is None
    # the second analogs may flag a position more (docs/numerics.md): next to a change point
    np.testing.assert_array_equal(only.status, one.status)
    np.testing.assert_array_equal(only.status[full.status != SINGULAR], full.status[full.status != SINGULAR])
    for link in full.poses:
        np.testing.assert_array_equal(only.poses[link], full.poses[link])
        np.testing.assert_array_equal(one.first[link], full.first[link])


def _rrr(d):
    """RRR on the frame: A = (0, 0), C = (d, 0), AB = 1, CB = 1 (B at the apex of an isosceles
    triangle): singular (stretched) at d = 2, not assembled beyond."""
    joints = [RevoluteJoint("A", "0", "1", (0.0, 0.0), (0.0, 0.0)),
              RevoluteJoint("B", "1", "2", (1.0, 0.0), (1.0, 0.0)),
              RevoluteJoint("C", "2", "0", (0.0, 0.0), (d, 0.0))]
    return GROUP_KINDS["RRR"].bind(("1", "2"), joints, {"0"}, 2.0)


def rrr_apex(A, C, ab, cb, M):
    """B ``(N, 2)`` of the triangle A, B, C with |AB| = ab, |CB| = cb, left of A -> C for M = +1
    (the RRR's branch +1, assur/rrr.py), by the law of cosines; NaN where it does not close."""
    w = C - A
    d = np.hypot(w[:, 0], w[:, 1])
    e = w / d[:, None]
    a = (ab**2 - cb**2 + d**2) / (2 * d)
    with np.errstate(invalid="ignore"):
        h = np.sqrt(ab**2 - a**2)
    return A + a[:, None] * e + M * h[:, None] * np.column_stack([-e[:, 1], e[:, 0]])


def rrr_conditioning(A, B, C):
    """The conditioning of an RRR dyad with pins A, C on known links and B between its links AB
    and CB, in closed form (docs/numerics.md): the Hadamard ratio |det J| / prod |row_i| of its
    6 x 6 constraint Jacobian with each link's rotation taken about the middle of its two pins and
    divided by the group's scale L = max(|AB|, |CB|, |AC|). With u = B - A, v = B - C, written out
    by hand: |det J| = |u x v| / L**2; the rows of pin A are (-I, -E(A - m1) / L), E(A - m1) / L =
    E(-u / 2L), of pin B (I, E(u / 2L), -I, -E(v / 2L)), of pin C (I, E(-v / 2L)); E turns by
    +90 deg. So with q(z) = (z / 2L)**2 the squared row norms are 1 + q(u_y), 1 + q(u_x),
    2 + q(u_y) + q(v_y), 2 + q(u_x) + q(v_x), 1 + q(v_y), 1 + q(v_x)."""
    u, v, w = B - A, B - C, C - A
    L = np.maximum(np.maximum(np.hypot(u[:, 0], u[:, 1]), np.hypot(v[:, 0], v[:, 1])), np.hypot(w[:, 0], w[:, 1]))

    def q(z):
        return (z / (2 * L)) ** 2

    rows = ((1 + q(u[:, 1])) * (1 + q(u[:, 0])) * (2 + q(u[:, 1]) + q(v[:, 1])) * (2 + q(u[:, 0]) + q(v[:, 0]))
            * (1 + q(v[:, 1])) * (1 + q(v[:, 0])))
    return np.abs(u[:, 0] * v[:, 1] - u[:, 1] * v[:, 0]) / L**2 / np.sqrt(rows)


def rrr_placed(A, B, C):
    """Poses of links 1 (local A = (0, 0), B on its x axis) and 2 (local C = (0, 0), B on its x
    axis) of :func:`_rrr` / :func:`_rrr_triangle` from the pins, for :func:`generic_oracle`."""
    return {"1": np.column_stack([A, np.arctan2(B[:, 1] - A[:, 1], B[:, 0] - A[:, 0])]),
            "2": np.column_stack([C, np.arctan2(B[:, 1] - C[:, 1], B[:, 0] - C[:, 0])])}


def assert_conditioning(got, want):
    """``got`` within :func:`conditioning_tolerance` of the closed form, less the 1e-6 that
    coinciding contact points need (none here): 1e-14 relative plus the positions' round-off."""
    with np.errstate(divide="ignore"):
        tol = 1e-14 * want + np.where(want > 0, 2 * EPS / want, 1e-15)
    gap = np.abs(got - want)
    assert np.all(gap <= tol), f"worst {gap[np.argmax(gap / tol)]:.3g} at r = {want[np.argmax(gap / tol)]:.3g}"


def test_the_conditioning_closed_form_by_hand():
    """:func:`rrr_conditioning` at the equilateral triangle (A = (0, 0), C = (1, 0), sides 1),
    evaluated by hand: |u x v| = sqrt(3)/2, L = 1, q = 3/16 or 1/16, rows (19/16 17/16)^2 38/16 34/16."""
    A, C = np.array([[0.0, 0.0]]), np.array([[1.0, 0.0]])
    B = rrr_apex(A, C, 1.0, 1.0, 1)
    np.testing.assert_allclose(B, [[0.5, np.sqrt(3) / 2]], rtol=0, atol=1e-16)
    hand = (np.sqrt(3) / 2) / (19 * 17 / 256 * np.sqrt(38 * 34) / 16)
    np.testing.assert_allclose(rrr_conditioning(A, B, C), [hand], rtol=1e-15)


@pytest.mark.parametrize("d, status", [(1.0, OK), (2.0 - 1e-9, SINGULAR), (2.0, SINGULAR), (2.1, CANNOT_ASSEMBLE)])
def test_statuses_at_the_toggle_and_beyond(d, status):
    """The isosceles RRR: well conditioned at d = 1, singular at the stretched position d = 2
    (and 1e-9 short of it: the bound of the analogs' error is far above 1e-8), not assembled
    beyond; the fast path gives the oracle's status (on B placed here), the closed-form
    conditioning and its bound 3 eps / r**2."""
    group = _rrr(d)
    frame = {"0": np.zeros((1, 3))}
    zeros = {"0": np.zeros((1, 3))}
    fast = group.solve(frame, zeros, zeros, 1)
    assert fast.status.tolist() == [status]
    A, C = np.array([[0.0, 0.0]]), np.array([[d, 0.0]])
    B = rrr_apex(A, C, 1.0, 1.0, 1)
    assert np.isnan(B).any() == (status == CANNOT_ASSEMBLE)
    placed = rrr_placed(A, np.nan_to_num(B, nan=1e3), C)     # beyond the toggle: a pose that does not close
    assert_same(fast, generic_oracle(group, frame, zeros, zeros, placed, 2.0), 2.0)
    if status != CANNOT_ASSEMBLE:
        want = rrr_conditioning(A, B, C)
        assert_conditioning(fast.conditioning, want)
        if d == 2.0:
            assert want[0] == 0.0 and fast.error_bound[0] == np.inf
        else:
            np.testing.assert_allclose(fast.error_bound, ROUNDOFF_FACTOR * EPS / want**2, rtol=1e-6)
    else:
        assert np.isnan(fast.conditioning[0]) and fast.error_bound[0] == np.inf


def _rrr_triangle(ab, cb, d):
    """RRR on the frame: A = (0, 0), C = (d, 0) in the frame's coordinates, AB = ab, CB = cb."""
    joints = [RevoluteJoint("A", "0", "1", (0.0, 0.0), (0.0, 0.0)),
              RevoluteJoint("B", "1", "2", (ab, 0.0), (cb, 0.0)),
              RevoluteJoint("C", "2", "0", (0.0, 0.0), (d, 0.0))]
    return GROUP_KINDS["RRR"].bind(("1", "2"), joints, {"0"}, 2.0)


@pytest.mark.parametrize("ab, cb", [(1.0, 1.0), (1.0, 0.6), (0.3, 1.7)])
def test_rrr_conditioning_equals_its_closed_form_over_many_positions(ab, cb):
    """The conditioning of the fast path (and of the generic path on the same poses) equals
    :func:`rrr_conditioning` over the whole range |ab - cb| < d < ab + cb, down to 1e-12 from
    both toggles, on both branches, with the frame moved and turned at random (the measure is
    not invariant under rotation: the row norms depend on the directions of u and v); the
    statuses are those of the bound 3 eps / r**2 <= 1e-8, and B is where the triangle puts it."""
    lo, hi = abs(ab - cb), ab + cb
    near = 10.0 ** -np.arange(2, 13, 2)
    ds = np.concatenate([np.linspace(lo, hi, 41)[1:-1], hi - near * hi, lo + near * hi if lo > 0 else []])
    rng = np.random.default_rng(7)
    n = 9
    for d in ds:
        group = _rrr_triangle(ab, cb, d)
        frame = np.column_stack([rng.uniform(-3, 3, n), rng.uniform(-3, 3, n), rng.uniform(-np.pi, np.pi, n)])
        A = frame[:, :2]
        C = A + d * np.column_stack([np.cos(frame[:, 2]), np.sin(frame[:, 2])])
        for M in (1, -1):
            B = rrr_apex(A, C, ab, cb, M)
            want = rrr_conditioning(A, B, C)
            fast = group.solve({"0": frame}, None, None, M)
            generic = generic_oracle(group, {"0": frame}, None, None, rrr_placed(A, B, C), 2.0)
            assert_conditioning(fast.conditioning, want)
            assert_conditioning(generic.conditioning, want)
            singular = ROUNDOFF_FACTOR * EPS / want**2 > ANALOG_TOL
            settled = np.abs(want / np.sqrt(ROUNDOFF_FACTOR * EPS / ANALOG_TOL) - 1) > 1e-6
            np.testing.assert_array_equal(fast.status[settled], np.where(singular, SINGULAR, OK)[settled])
            got_b = fast.poses["1"][:, :2] + ab * np.column_stack([np.cos(fast.poses["1"][:, 2]),
                                                                   np.sin(fast.poses["1"][:, 2])])
            np.testing.assert_allclose(got_b, B, rtol=0, atol=1e-12 + 8 * EPS / want.min())


def test_batch_geometry_per_position_equals_one_geometry_at_a_time():
    """Local coordinates given per position (a batch of design variants) give, position by
    position, what each geometry gives alone."""
    mech = linkage.load("slotted_link_two_dyad")
    structure = linkage.structure_of(mech)
    phi = np.linspace(0.1, 6.0, 9)
    motion = linkage.analyze(mech, phi)
    rng = np.random.default_rng(3)
    for group in structure.groups:
        factors = 1.0 + 0.05 * rng.standard_normal((len(phi), 2))
        joints = []
        for j in group.joints:
            if isinstance(j, RevoluteJoint):
                joints.append(RevoluteJoint(j.name, j.a, j.b, np.asarray(j.pa) * factors, np.asarray(j.pb) * factors))
            else:
                joints.append(PrismaticJoint(j.name, j.a, j.b, j.g, j.u, np.asarray(j.p) * factors, j.beta))
        batch = type(group).bind(group.links, joints, set(group.known_links), group.size)
        kp = {k: motion.poses[k] for k in group.known_links}
        k1 = {k: motion.first[k] for k in group.known_links}
        k2 = {k: motion.second[k] for k in group.known_links}
        together = batch.solve(kp, k1, k2, 1)
        for i in range(len(phi)):
            alone_joints = [RevoluteJoint(j.name, j.a, j.b, tuple(np.asarray(j.pa)[i]), tuple(np.asarray(j.pb)[i]))
                            if isinstance(j, RevoluteJoint) else
                            PrismaticJoint(j.name, j.a, j.b, j.g, j.u, tuple(np.asarray(j.p)[i]), j.beta)
                            for j in joints]
            alone = type(group).bind(group.links, alone_joints, set(group.known_links), group.size)
            one = Group.solve(alone, {k: v[i:i + 1] for k, v in kp.items()}, {k: v[i:i + 1] for k, v in k1.items()},
                              {k: v[i:i + 1] for k, v in k2.items()}, 1)
            assert together.status[i] == one.status[0]
            for link in group.links:
                for got, want in ((together.poses, one.poses), (together.first, one.first),
                                  (together.second, one.second)):
                    np.testing.assert_allclose(got[link][i], want[link][0], rtol=1e-12, atol=1e-12)


@pytest.mark.parametrize("kind", KINDS)
@settings(SETTINGS, max_examples=30)
@given(data=st.data())
def test_fast_reactions_equal_the_generic_solve_and_balance_every_link(kind, data):
    """``Dyad.reactions`` (transposed elimination) against ``Group.reactions`` (``(N, 6, 6)``
    LAPACK solves of ``Phi_q^T lambda = -Q``), and each link's equilibrium ``Phi_q^T lambda + Q = 0``
    checked with the generic Jacobian."""
    case = data.draw(cases(kind))
    group = case.bind()
    poses, _, _ = case.path(PHI)
    solution = Group.solve(group, poses, branch=group.branches[0])
    full = {**poses, **solution.poses}
    n = len(PHI)
    rng = np.random.default_rng(data.draw(st.integers(0, 2**32 - 1)))
    loads = {k: rng.normal(size=(n, 3)) * [1.0, 1.0, case.size] for k in group.links}
    valid = solution.status == OK
    fast_lam, fast_out = group.reactions(full, loads, valid=valid)
    slow_lam, slow_out = Group.reactions(group, full, loads, valid=valid)
    assert set(fast_lam) == set(slow_lam) and set(fast_out) == set(slow_out)
    # the LAPACK solve's own error grows as 1 / conditioning
    amplification = 1.0 / max(1e-6, float(np.min(solution.conditioning[valid], initial=1.0)))
    for name in slow_lam:
        np.testing.assert_array_equal(np.isnan(fast_lam[name]), ~valid[:, None] | np.zeros((1, 2), bool))
        size = np.maximum(1.0, np.max(np.abs(slow_lam[name][valid]), initial=0.0))
        np.testing.assert_allclose(fast_lam[name][valid], slow_lam[name][valid], rtol=0,
                                   atol=1e-9 * size * amplification)
    for k in slow_out:
        scale = np.maximum(1.0, np.max(np.abs(slow_out[k][valid]), initial=0.0))
        np.testing.assert_allclose(fast_out[k][valid], slow_out[k][valid], rtol=0, atol=1e-9 * scale * amplification)
    phi_q, _ = group.jacobians(full)
    lam = np.concatenate([fast_lam[j.name] for j in group.joints], axis=1)
    q = np.concatenate([loads[k] for k in group.links], axis=1)
    balance = np.einsum("nji,nj->ni", phi_q, lam) + q
    typical = np.max(np.abs(np.einsum("nji,nj->nji", phi_q, lam)), axis=(1, 2)) + np.max(np.abs(q), axis=1)
    assert np.all(np.abs(balance[valid]) <= 1e-12 * typical[valid, None])
