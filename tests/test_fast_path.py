"""The fast path of the dyads (``Dyad.solve``: closed-form elimination, conditioning and closure
computed elementwise) against the generic Jacobian path (``Group.solve``: ``(N, 6, 6)``
Jacobians, LAPACK solves and determinants), the oracle: every kind, random geometry and paths,
both branches, positions where the group cannot be assembled, singular positions, and a batch
whose local geometry differs at every position."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

sys.path.insert(0, str(Path(__file__).resolve().parent))

from test_dyads import SETTINGS, cases  # noqa: E402

import linkage  # noqa: E402
from assur.base import CANNOT_ASSEMBLE, OK, SINGULAR, Group, PrismaticJoint, RevoluteJoint  # noqa: E402
from assur.registry import GROUP_KINDS  # noqa: E402

KINDS = ["RRR", "RRP", "RPR", "PRP", "RPP"]
PHI = np.linspace(-3.0, 3.0, 61)


def assert_same(fast, oracle, size):
    """Statuses and signs equal; poses and analogs equal to round-off; conditioning and bounds to
    1e-6 relative (where a group's contact points coincide -- a PRP whose sliders' points are its
    pin -- its scale is the floor 1e-9 of the mechanism's size, and the conditioning carries the
    contacts' round-off amplified by 1e9 inside a sum with 1)."""
    np.testing.assert_array_equal(fast.status, oracle.status)
    ok = oracle.status == OK
    placed = oracle.status != CANNOT_ASSEMBLE
    clear = placed & (oracle.conditioning > 1e-10)     # at an exact toggle the sign is round-off
    np.testing.assert_array_equal(fast.jacobian_sign[clear], oracle.jacobian_sign[clear])
    np.testing.assert_array_equal(np.isnan(fast.conditioning), np.isnan(oracle.conditioning))
    np.testing.assert_allclose(fast.conditioning[placed], oracle.conditioning[placed], rtol=1e-6, atol=1e-14)
    np.testing.assert_allclose(fast.error_bound[clear], oracle.error_bound[clear], rtol=3e-6)
    for link in oracle.poses:
        np.testing.assert_array_equal(np.isnan(fast.poses[link]), np.isnan(oracle.poses[link]))
        np.testing.assert_allclose(fast.poses[link][placed], oracle.poses[link][placed], rtol=0, atol=1e-12 * size)
        for got, want in ((fast.first, oracle.first), (fast.second, oracle.second)):
            assert np.all(np.isnan(got[link][~ok]))
            scale = max(1.0, float(np.max(np.abs(want[link][ok]), initial=0.0)))
            np.testing.assert_allclose(got[link][ok], want[link][ok], rtol=0, atol=1e-9 * scale)


@pytest.mark.parametrize("kind", KINDS)
@settings(SETTINGS, max_examples=40)
@given(data=st.data())
def test_fast_path_equals_the_generic_path(kind, data):
    case = data.draw(cases(kind))
    group = case.bind()
    poses, first, second = case.path(PHI)     # PHI runs beyond the assembled range of many cases
    for branch in group.branches:
        fast = group.solve(poses, first, second, branch)
        oracle = Group.solve(group, poses, first, second, branch)
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
    np.testing.assert_array_equal(only.status, full.status)
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


@pytest.mark.parametrize("d, status", [(1.0, OK), (2.0 - 1e-9, SINGULAR), (2.0, SINGULAR), (2.1, CANNOT_ASSEMBLE)])
def test_statuses_at_the_toggle_and_beyond(d, status):
    """The isosceles RRR: well conditioned at d = 1, singular at the stretched position d = 2
    (and 1e-9 short of it: the bound of the analogs' error is far above 1e-8), not assembled
    beyond; the fast path gives the oracle's status, closed-form conditioning and bound."""
    group = _rrr(d)
    frame = {"0": np.zeros((1, 3))}
    zeros = {"0": np.zeros((1, 3))}
    fast = group.solve(frame, zeros, zeros, 1)
    oracle = Group.solve(group, frame, zeros, zeros, 1)
    assert fast.status.tolist() == [status]
    assert_same(fast, oracle, 2.0)
    if status != CANNOT_ASSEMBLE:
        # conditioning of the isosceles RRR in closed form: the Hadamard ratio of its scaled
        # Jacobian is |sin| of the angle between AB and CB over a product of row norms; at d = 1
        # the triangle is equilateral. Here only its limit is checked: 0 at the toggle.
        if d == 2.0:
            assert fast.conditioning[0] < 1e-7


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
