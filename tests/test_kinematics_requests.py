"""What a request computes (only the groups its outputs need), branch-continuity warnings, real
velocities and accelerations from per-position omega and eps."""

import warnings
from pathlib import Path

import numpy as np
import pytest

import linkage
from linkage.kinematics.motion import BranchWarning


def test_outputs_limit_the_groups_that_run_and_give_the_same_numbers():
    mech = linkage.load("six_bar")
    phi = np.radians(np.arange(0.0, 360.0, 15.0))
    full = linkage.analyze(mech, phi)
    only_b = linkage.analyze(mech, phi, outputs=["B"])
    assert set(only_b.poses) == {"0", "1", "2", "3"}  # the RRP group of links 4, 5 did not run
    np.testing.assert_array_equal(only_b.point("B"), full.point("B"))
    np.testing.assert_array_equal(only_b.point_analogs("B")[1], full.point_analogs("B")[1])
    with pytest.raises(ValueError, match="point 'F'"):
        only_b.point("F")
    only_f = linkage.analyze(mech, phi, outputs=["F.x"])
    assert set(only_f.poses) == {"0", "1", "2", "3", "4", "5"}  # F needs both groups


def _sliding_pin():
    """Crank 1 carries a guide along itself; block 2 slides on it and is pinned at B to block 3,
    which slides on the frame's horizontal guide y = 1: B = (cot(phi), 1). At phi = 0 and pi the
    two guides are parallel (the PRP group is singular and B runs off to infinity)."""
    b = linkage.MechanismBuilder("sliding_pin")
    b.link("0", points={"O": (0.0, 0.0)}, guides={"rail": {"through": (0.0, 1.0), "angle": 0.0}})
    b.link("1", line=("O", "A"), length=1.0, guides={"arm": {"through": "O", "angle": 0.0}})
    b.link("2", points={"B": (0.0, 0.0)})
    b.link("3", points={"B": (0.0, 0.0)})
    b.revolute("O", "0", "1").revolute("B", "2", "3")
    b.prismatic("arm_B", "1", "2", guide="arm", at="B")
    b.prismatic("rail_B", "0", "3", guide="rail", at="B")
    return b.inputs("1").build()


def test_prp_oracle_and_a_warning_when_the_group_changes_assembly_mode():
    mech = _sliding_pin()
    assert linkage.structure_of(mech).formula == "I(0,1) → II-PRP(2,3)"
    phi = np.array([np.pi / 3, np.pi / 2, 2 * np.pi / 3])
    with warnings.catch_warnings():
        warnings.simplefilter("error", BranchWarning)  # one side of the singularity: no warning
        motion = linkage.analyze(mech, phi)
    np.testing.assert_allclose(motion.point("B"), np.column_stack([1 / np.tan(phi), np.ones(3)]),
                               atol=1e-14)
    # x_B = cot(phi): x' = -1/sin^2, x'' = 2 cos / sin^3
    first, second = motion.point_analogs("B")
    np.testing.assert_allclose(first[:, 0], -1 / np.sin(phi) ** 2, rtol=1e-12)
    np.testing.assert_allclose(second[:, 0], 2 * np.cos(phi) / np.sin(phi) ** 3, rtol=1e-12)
    with pytest.warns(BranchWarning, match="PRP"):
        linkage.analyze(mech, np.array([np.pi / 2, 3 * np.pi / 2]))


def test_parallel_guides_are_reported_not_returned():
    mech = _sliding_pin()
    with pytest.raises(linkage.AssemblyError, match="cannot be assembled at 1 input angle"):
        linkage.analyze(mech, np.array([0.0, np.pi / 2]))


def test_real_velocity_and_acceleration_with_per_position_omega_and_eps():
    """Scotch yoke: x_D = r cos(phi) + 0.15, so v = -r sin(phi) omega and
    a = -r cos(phi) omega^2 - r sin(phi) eps for any per-position omega and eps."""
    mech = linkage.load("scotch_yoke")
    r = 0.05
    phi = np.radians([10.0, 75.0, 200.0, 330.0])
    omega = np.array([3.0, -7.0, 12.0, 0.5])
    eps = np.array([0.0, 40.0, -5.0, 2.0])
    motion = linkage.analyze(mech, phi, omega=omega, eps=eps)
    np.testing.assert_allclose(motion.velocity("D.x"), -r * np.sin(phi) * omega, atol=1e-15)
    np.testing.assert_allclose(motion.acceleration("D.x"),
                               -r * np.cos(phi) * omega**2 - r * np.sin(phi) * eps, atol=1e-13)
    np.testing.assert_allclose(motion.velocity("D")[:, 0], motion.velocity("D.x"), atol=0)
    np.testing.assert_allclose(motion.acceleration("D")[:, 1], 0.0, atol=1e-15)
    with pytest.raises(ValueError, match="need omega"):
        linkage.analyze(mech, phi).velocity("D")


# ----------------------------------------------------------------------------------------------
# only what a request needs, counted: group evaluations, their orders, the force work
# ----------------------------------------------------------------------------------------------


class _Counter:
    """Counts the solves and kinetostatic solutions of every group kind (wrapping the methods)."""

    def __init__(self, monkeypatch):
        from assur.base import Group
        from assur.dyad import Dyad

        self.solves, self.reactions = [], []
        solve = Dyad.solve

        def counted_solve(group, poses, first=None, second=None, *args, **kwargs):
            self.solves.append((repr(group), 0 if first is None else 1 if second is None else 2))
            return solve(group, poses, first, second, *args, **kwargs)

        def counting(reactions):
            def counted_reactions(group, *args, **kwargs):
                self.reactions.append(repr(group))
                return reactions(group, *args, **kwargs)
            return counted_reactions

        monkeypatch.setattr(Dyad, "solve", counted_solve)
        for kind in (Group, Dyad):      # the generic kinetostatics and the dyads' closed form
            monkeypatch.setattr(kind, "reactions", counting(kind.__dict__["reactions"]))


def test_one_point_runs_only_its_ancestors_and_no_derivatives(monkeypatch):
    mech = linkage.load("six_bar")        # I(0,1) -> II-RRR(2,3) -> II-RRP(4,5)
    linkage.analyze(mech, [0.3])         # loads and caches the assembly plans outside the count
    count = _Counter(monkeypatch)
    phi = np.radians(np.arange(0.0, 360.0, 30.0))
    motion = linkage.analyze(mech, phi, order=0, outputs=["B"])
    assert count.solves == [("II-RRR(2,3)", 0)]
    assert motion.first is None and set(motion.poses) == {"0", "1", "2", "3"}
    count.solves.clear()
    linkage.analyze(mech, phi, order=1, outputs=["F.x"])
    assert count.solves == [("II-RRR(2,3)", 1), ("II-RRP(4,5)", 1)]
    assert count.reactions == []           # kinematics does no force work


def test_one_reaction_runs_the_groups_it_needs(monkeypatch):
    from linkage.kinetostatics.reactions import solve_reactions

    mech = linkage.load("six_bar")
    phi = np.radians(np.arange(0.0, 360.0, 30.0))
    full = solve_reactions(linkage.analyze(mech, phi, omega=10.0))
    count = _Counter(monkeypatch)
    # the farthest group's pair: its group alone (and, for its kinematics, its ancestors)
    farthest = [j.name for j in linkage.structure_of(mech).groups[1].joints]
    motion = linkage.analyze(mech, phi, omega=10.0, outputs=["4", "5"])
    count.solves.clear()
    only = solve_reactions(motion, pairs=[farthest[0]])
    assert count.reactions == ["II-RRP(4,5)"] and count.solves == []
    np.testing.assert_allclose(only.multipliers[farthest[0]], full.multipliers[farthest[0]], rtol=1e-12, atol=1e-9)
    assert np.all(np.isnan(only.balancing_moment)) and "balancing moment not computed" in only.notes[-1]
    # a pair of the first group: that group and the group that loads it (on the group-by-group
    # path; the reactions kernel solves every group at once, kinetostatics/kernel.py)
    import linkage.kinematics.motion as motion_module

    monkeypatch.setattr(motion_module, "USE_KERNEL", False)
    count.reactions.clear()
    near = linkage.structure_of(mech).groups[0].joints[1].name
    solve_reactions(linkage.analyze(mech, phi, omega=10.0), pairs=[near])
    assert count.reactions == ["II-RRP(4,5)", "II-RRR(2,3)"]


def test_massless_links_give_no_inertia_work():
    from linkage.kinetostatics.loads import inertia_terms

    mech = linkage.load("four_bar")             # links 1, 2, 3 carry masses
    motion = linkage.analyze(mech, [0.1, 0.2], omega=5.0)
    assert [t.link for t in inertia_terms(motion)] == ["1", "2", "3"]
    assert inertia_terms(motion, ["2"])[0].link == "2" and len(inertia_terms(motion, ["2"])) == 1
    bare = linkage.loads((Path(__file__).resolve().parent.parent / "schemes" / "four_bar.toml").read_text()
                         .replace("mass = 1.0", "").replace("mass = 3.0", "").replace("mass = 2.0", "")
                         .replace("inertia = 0.0225", "").replace("inertia = 0.0104167", ""))
    assert inertia_terms(linkage.analyze(bare, [0.1, 0.2], omega=5.0)) == []
