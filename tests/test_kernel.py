"""The compiled kinematics kernel (linkage/kinematics/kernel.py) against the general path (issue 24).

The general path (``linkage.analyze``: ``run_blocks`` and each group's ``Dyad.solve``) is the
oracle. For every shipped scheme whose groups are all closed-form dyads, for the edge mechanisms
of every dyad kind at and around their singular positions (tests/_edge_mechanisms.py), and for
random chains of one to three dyads of all five kinds (tests/_chains.py) on the declared and the
flipped branches, the kernel must give the same statuses (each group's and the mechanism's) and
conditioning, and poses, first / second analogs, the named points with their analogs and error
bounds equal to 1e-13 relative to
the mechanism's size (to 1e-13 relative for the analogs and bounds, which grow without bound
near a singular position), with NaN at the same positions.
"""

from __future__ import annotations

import math
import sys
import warnings
import zlib
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))

import linkage  # noqa: E402
from linkage.errors import LinkageError  # noqa: E402
from linkage.kinematics.assembly import assembly_plans  # noqa: E402
from linkage.kinematics.kernel import KERNEL_BLOCK, kernel_for, kernel_source, run_kernel  # noqa: E402
from linkage.kinematics.motion import BranchWarning, run_blocks  # noqa: E402
from linkage.structure import structure_of  # noqa: E402
from assur.base import global_point, point_analogs  # noqa: E402

import _chains as C  # noqa: E402
import _edge_mechanisms as E  # noqa: E402

TOL = 1e-13
CLOSED_FORM_SCHEMES = ["four_bar", "slider_crank", "six_bar", "watt_six_bar", "flying_shears", "slotted_link",
                       "slotted_link_two_dyad", "scotch_yoke", "slider_crank_vertical", "course_slider_crank",
                       "stephenson_six_bar", "five_bar_two_input", "piston_driven_crank"]
#: offsets (rad, or m for a slide input) around a singular position
NEAR = np.array([0.0, 1e-15, 1e-13, 1e-11, 1e-9, 1e-7, 1e-5, 1e-3, 1e-2])


def general(mech, phi, order, branches=None):
    """The general path's results: ``analyze`` on the planned branches, else ``run_blocks`` with
    each group's plan set to keep ``branches``."""
    structure = structure_of(mech)
    plans = assembly_plans(mech)
    if branches is not None:
        plans = tuple(replace(p, branch=b, mode="keep") for p, b in zip(plans, branches))
    run = run_blocks(mech, structure, plans, list(range(len(structure.groups))), phi, order)
    points = {}    # every named point of a moving link and every moving link's centre of mass
    wanted = [(mech.point_link(p), mech.links[mech.point_link(p)].points[p]) for p in mech.point_names]
    for link, local in wanted + [(k, mech.links[k].center_of_mass) for k in mech.moving_links]:
        if link != mech.frame:
            pose = run.poses[link]
            analogs = (None, None) if order == 0 else \
                point_analogs(pose, run.first[link], run.second and run.second[link], local)
            points[link, tuple(local)] = (global_point(pose, local), *analogs)
    scales = {}     # each group's length scale where it is assembled (Group.scale)
    for i, group in enumerate(structure.groups):
        with np.errstate(invalid="ignore"):
            scales[i] = np.where(run.solved[i] != -1, group.scale(run.poses), np.nan)
    return {"poses": run.poses, "first": run.first, "second": run.second, "status": run.status,
            "conditioning": run.conditioning, "error_bound": run.error_bound, "signs": run.signs,
            "solved": run.solved, "points": points, "scales": scales}


def assert_same(got: dict, ref: dict, size: float, what: str) -> None:
    """The kernel's ``got`` equals the general path's ``ref`` (see the module docstring)."""
    np.testing.assert_array_equal(got["status"], ref["status"], err_msg=f"{what}: status")
    for i, s in ref["solved"].items():
        np.testing.assert_array_equal(got["solved"][i], s, err_msg=f"{what}: status of group {i}")
        np.testing.assert_array_equal(got["signs"][i], ref["signs"][i], err_msg=f"{what}: sign of group {i}")
    assert got["conditioning"].keys() == ref["conditioning"].keys()
    for g, c in ref["conditioning"].items():
        _close(got["conditioning"][g], c, TOL * np.ones_like(c), f"{what}: conditioning of {g}")
    b = ref["error_bound"]
    _close(got["error_bound"], b, TOL * np.abs(b), f"{what}: error bound")
    for name in ("poses", "first", "second"):
        if ref[name] is None:
            assert got[name] is None
            continue
        assert got[name].keys() == ref[name].keys(), f"{what}: links of {name}"
        for link, value in ref[name].items():
            scale = np.abs(value) + np.array([size, size, 1.0])
            _close(got[name][link], value, TOL * scale, f"{what}: {name} of link {link}")
    for i, scale in ref["scales"].items():     # the jump check's weight of turns: from other round-off
        _close(got["scales"][i], scale, 1e-9 * np.abs(scale), f"{what}: scale of group {i}")
    assert set(got["points"]) == set(ref["points"]), f"{what}: the points"
    for point, values in ref["points"].items():
        for name, value, mine in zip(("position", "first analog", "second analog"), values, got["points"][point]):
            if value is None:
                assert mine is None, f"{what}: {name} of point {point} beyond the order"
                continue
            scale = np.abs(value) + size
            _close(mine, value, TOL * scale, f"{what}: {name} of point {point}")


def _close(got, ref, tol, what):
    got, ref = np.asarray(got), np.asarray(ref)
    assert got.shape == ref.shape, what
    same_special = (np.isnan(got) == np.isnan(ref)).all() and (np.isinf(ref) == np.isinf(got)).all() \
        and (got[np.isinf(ref)] == ref[np.isinf(ref)]).all()
    assert same_special, f"{what}: NaN / inf at other positions"
    finite = np.isfinite(ref)
    err = np.abs(got[finite] - ref[finite])
    assert (err <= tol[finite]).all(), f"{what}: off by {err.max():.3g} (tolerance {tol[finite].min():.3g})"


def compare(mech, phi, order, branches=None, what="") -> bool:
    """Kernel against the general path; False when the kernel does not apply to these angles."""
    got = kernel_for(mech, order)(phi, branches)
    if got is None:
        return False
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", BranchWarning)
        ref = general(mech, phi, order, branches)
    size = float(max(np.max(g.size) for g in structure_of(mech).groups))
    assert_same(got, ref, size, f"{mech.name} order {order} branches {got['branches']} {what}")
    return True


def flipped(mech) -> tuple[int, ...]:
    """Every group on its other branch (one-branch kinds keep theirs)."""
    return tuple(g.branches[-1] if p.branch == g.branches[0] else g.branches[0]
                 for g, p in zip(structure_of(mech).groups, assembly_plans(mech)))


def travel(mech, n, rng):
    low, high = mech.input_range if mech.input_range is not None else (0.0, 2 * np.pi)
    return np.sort(rng.uniform(min(low, high), max(low, high), n))


# ----------------------------------------------------------------------------------------------


@pytest.mark.parametrize("name", CLOSED_FORM_SCHEMES)
def test_shipped_schemes(name):
    mech = linkage.load(name)
    assert kernel_for(mech, 2) is not None
    rng = np.random.default_rng(zlib.crc32(name.encode()))
    phi = travel(mech, 150, rng)
    compared = 0
    for order in (0, 1, 2):
        compared += compare(mech, phi, order)
        compared += compare(mech, phi, order, flipped(mech), "flipped")
    # near each group's least conditioning and assembly limits on the sweep
    dense = travel(mech, 2000, rng)
    ref = general(mech, dense, 0)
    spots = []
    for i, s in ref["solved"].items():
        c = np.where(np.isfinite(ref["conditioning"][repr(structure_of(mech).groups[i])]),
                     ref["conditioning"][repr(structure_of(mech).groups[i])], np.inf)
        spots.append(dense[np.argmin(c)])
        spots += list(dense[np.flatnonzero(np.diff(s) != 0)])
    near = np.sort((np.array(spots)[:, None] + np.concatenate([NEAR, -NEAR])[None, :]).ravel())
    compared += compare(mech, near, 2, what="near its least conditioning")
    assert compared >= 4


@pytest.mark.parametrize("case", [*E.CASES, "CHAIN"])
def test_edge_mechanisms_at_their_singular_positions(case):
    """Toggles, dead centres and parallel guides: statuses flip between OK, singular and cannot
    be assembled within a few ulps of the angle; the kernel must flip at the same positions."""
    edge = E.CHAIN if case == "CHAIN" else E.CASES[case]
    mech = linkage.loads(edge.toml)
    at = edge.singular_phi
    steps = np.concatenate([NEAR, -NEAR, 1e-16 * np.arange(-40, 41)])
    phi = np.sort(at + steps)
    for order in (0, 1, 2):
        assert compare(mech, phi, order)
        compare(mech, phi, order, flipped(mech), "flipped")
    ref = general(mech, phi, 2)
    assert len(set(ref["status"].tolist())) >= 2, "the angles should straddle the singular position"


def test_rpp_edges():
    """The Scotch yoke's guides near parallel (gamma, deg): singular at every angle below ~1e-5 deg."""
    for gamma in (1e-9, 1e-6, 3e-4, 1.0, 30.0, 90.0):
        mech = linkage.loads(E.rpp_toml(gamma))
        phi = np.linspace(0.0, 2 * np.pi, 97)
        for order in (0, 1, 2):
            assert compare(mech, phi, order)


def random_shape(rng) -> C.ChainShape:
    """A random chain shape as ``test_fuzz_chains.chain_shapes`` draws them (mixed scales)."""
    dyads = []
    for _ in range(int(rng.integers(1, 4))):
        factor = 10.0 ** rng.uniform(-3.0, 3.0) if rng.integers(0, 3) > 0 else 1.0
        dyads.append(C.DyadShape(str(rng.choice(C.KINDS)),
                                 str(rng.choice(["anchor", "anchor", "anchor", "rigid", "span", "span"])),
                                 rng.random(), rng.random(), bool(rng.integers(0, 2)), int(rng.choice([1, -1])),
                                 factor, tuple(rng.random(C.N_UNIFORMS))))
    scale = 10.0 ** rng.uniform(-6.0, 6.0)
    far = 10.0 ** rng.uniform(2.0, 6.0) if rng.integers(0, 3) == 0 else None
    return C.ChainShape(rng.uniform(-math.pi, math.pi), tuple(rng.uniform(-1.0, 1.0, 2)), tuple(dyads), scale,
                        far, rng.uniform(0.0, 2 * math.pi), tuple(rng.random(64)))


def test_random_chains():
    """Random chains of every dyad kind, both branches: random angles and the angles next to where
    a group's status changes (found on a sweep and bisected to the last ulp)."""
    rng = np.random.default_rng(24)
    kinds, checked, tried = set(), 0, 0
    while checked < 40 and tried < 400:
        tried += 1
        try:
            chain = C.realize(random_shape(rng))
        except C.Reject:
            continue
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                mech = C.build(chain)
                structure = structure_of(mech)
                assembly_plans(mech)
        except LinkageError:
            continue
        assert kernel_for(mech, 2) is not None, structure.formula
        phi = np.sort(rng.uniform(-np.pi, 3 * np.pi, 64))
        sweep = np.linspace(0.0, 2 * np.pi, 721)
        ref = general(mech, sweep, 0)
        edges = []
        for k in np.flatnonzero(np.diff(ref["status"]) != 0)[:6]:
            lo, hi = sweep[k], sweep[k + 1]
            s_lo = ref["status"][k]
            for _ in range(60):       # bisect to the last ulp
                mid = 0.5 * (lo + hi)
                if mid in (lo, hi):
                    break
                if general(mech, np.array([mid]), 0)["status"][0] == s_lo:
                    lo = mid
                else:
                    hi = mid
            edges += [lo, hi]
        near = np.array(edges)[:, None] + np.concatenate([NEAR, -NEAR])[None, :] if edges else np.empty((0,))
        phi = np.concatenate([phi, np.ravel(near)])
        for order in (0, 1, 2):
            compare(mech, phi, order, what=f"chain {structure.formula}")
            compare(mech, phi, order, flipped(mech), f"chain {structure.formula} flipped")
        kinds |= {g.kind for g in structure.groups}
        checked += 1
    assert checked >= 40
    assert kinds == set(C.KINDS)


def test_blocks_and_cache():
    """Over more than one block of positions the kernel equals the general path; the kernel is
    compiled once per mechanism and order."""
    mech = linkage.load("six_bar")
    phi = np.linspace(-np.pi, 3 * np.pi, KERNEL_BLOCK + 1234)
    assert compare(mech, phi, 2)
    assert kernel_for(mech, 2) is kernel_for(mech, 2)
    assert kernel_for(mech, 1) is not kernel_for(mech, 2)
    source = kernel_source(mech, 2)
    assert source.startswith("def kernel(I, O):") and "for " not in source     # straight-line code


def test_not_applicable():
    """No kernel where a group has no closed form or the input is a cylinder; None (the general
    path's turn) where a group's branch changes among the positions."""
    assert kernel_for(linkage.load("six_bar_class3"), 2) is None      # a class-III group
    assert kernel_for(linkage.load("cylinder_boom"), 2) is None       # a driven cylinder
    assert run_kernel(linkage.load("four_bar"), np.array([])) is None
    with pytest.raises(ValueError):
        kernel_for(linkage.load("four_bar"), 2)(np.zeros(3), branches=(2,))


def test_analyze_runs_the_kernel_and_gives_the_general_path_s_motion(monkeypatch):
    """linkage.analyze solves a closed-form mechanism by its kernel (the general path is not
    called) and returns the Motion the general path gives, check by check."""
    import linkage.kinematics.motion as motion_module

    mech = linkage.load("six_bar")
    phi = np.linspace(0.0, 2 * np.pi, 73)
    monkeypatch.setattr(motion_module, "USE_KERNEL", False)
    oracle = linkage.analyze(mech, phi)
    monkeypatch.setattr(motion_module, "USE_KERNEL", True)

    def refuse(*args, **kwargs):
        raise AssertionError("the general path ran")

    monkeypatch.setattr(motion_module, "run_blocks", refuse)
    fast = linkage.analyze(mech, phi)
    np.testing.assert_array_equal(fast.status, oracle.status)
    for link in oracle.poses:
        for got, want in ((fast.poses, oracle.poses), (fast.first, oracle.first), (fast.second, oracle.second)):
            np.testing.assert_array_equal(got[link], want[link])
    np.testing.assert_array_equal(fast.error_bound, oracle.error_bound)
