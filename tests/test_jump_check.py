"""The jump check of analyze (motion.jump_steps): a step between two analysed angles where a
group's links move more than the trapezoid rule on their first analogs allows.

The four-bar is solved at 1-degree steps on its declared branch; a jump is planted by taking the
other assembly mode (the kernel on the other branch) from one position on. The rule is checked
against a plain loop over steps, links and coordinates written from its statement, and against
what the motion does: only the planted step is flagged, a whole turn added to a link's angle is
no move."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import linkage
from linkage.kinematics.kernel import kernel_for
from linkage.kinematics.motion import BranchWarning, jump_steps
from linkage.structure import structure_of

N = 361
PHI = np.radians(np.arange(N, dtype=float))


def _rule(poses, first, dphi, scale):
    """The rule as stated, one step, link and coordinate at a time."""
    out = []
    for j in range(len(dphi)):
        miss2 = moved2 = allowed2 = 0.0
        for k in poses:
            for c, weight in ((0, 1.0), (1, 1.0), (2, scale)):
                move = poses[k][j + 1, c] - poses[k][j, c]
                if c == 2:
                    move = (move + np.pi) % (2 * np.pi) - np.pi
                move *= weight
                allow = weight * 0.5 * (first[k][j, c] + first[k][j + 1, c]) * dphi[j]
                miss2 += (move - allow) ** 2
                moved2 += move ** 2
                allowed2 += allow ** 2
        miss = np.sqrt(miss2)
        out.append(bool(miss > 0.5 * (np.sqrt(moved2) + np.sqrt(allowed2)) and miss > 1e-9 * scale))
    return np.array(out)


@pytest.fixture(scope="module")
def four_bar():
    mech = linkage.load("four_bar")
    group = structure_of(mech).groups[0]
    kernel = kernel_for(mech, 2)
    declared = kernel(PHI, branches=(group.branches[0],))
    other = kernel(PHI, branches=(group.branches[1],))
    return mech, group, declared, other


def _planted(group, declared, other, at):
    poses = {k: np.where(np.arange(N)[:, None] >= at, other["poses"][k], declared["poses"][k]) for k in group.links}
    first = {k: np.where(np.arange(N)[:, None] >= at, other["first"][k], declared["first"][k]) for k in group.links}
    return poses, first


def test_a_smooth_motion_has_no_jump_and_analyze_stays_silent(four_bar):
    mech, group, declared, _ = four_bar
    dphi = np.diff(PHI)
    poses = {k: declared["poses"][k] for k in group.links}
    first = {k: declared["first"][k] for k in group.links}
    bad = jump_steps(group, poses, first, np.ones(N - 1, bool), dphi, mech.size)
    assert not bad.any()
    with warnings.catch_warnings():
        warnings.simplefilter("error", BranchWarning)
        linkage.analyze(mech, PHI)


@pytest.mark.parametrize("at", [1, 100, 360])
def test_only_the_step_into_the_other_mode_is_flagged(four_bar, at):
    mech, group, declared, other = four_bar
    poses, first = _planted(group, declared, other, at)
    dphi = np.diff(PHI)
    bad = jump_steps(group, poses, first, np.ones(N - 1, bool), dphi, mech.size)
    assert np.flatnonzero(bad).tolist() == [at - 1]
    np.testing.assert_array_equal(bad, _rule(poses, first, dphi, mech.size))
    # steps left out of the check are never flagged
    pairs = np.ones(N - 1, bool)
    pairs[at - 1] = False
    assert not jump_steps(group, poses, first, pairs, dphi, mech.size).any()


def test_a_whole_turn_added_to_an_angle_is_no_move(four_bar):
    mech, group, declared, _ = four_bar
    link = group.links[0]
    poses = {k: declared["poses"][k].copy() for k in group.links}
    poses[link][50:, 2] += 2 * np.pi
    poses[link][200:, 2] -= 6 * np.pi
    first = {k: declared["first"][k] for k in group.links}
    dphi = np.diff(PHI)
    bad = jump_steps(group, poses, first, np.ones(N - 1, bool), dphi, mech.size)
    assert not bad.any()
    np.testing.assert_array_equal(bad, _rule(poses, first, dphi, mech.size))
