"""Groups beyond the dyads: the class-III triad (every assembly mode listed in closed form) and the
generic Newton solver (any statically determinate group), against independent computations:
a multi-start least-squares solve of the triad written here, the dyads' closed forms, finite
differences and the virtual-power balance."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st
from scipy.optimize import least_squares

sys.path.insert(0, str(Path(__file__).resolve().parent))

from test_dyads import SETTINGS, cases  # noqa: E402

import linkage  # noqa: E402
from assur.base import OK, RevoluteJoint  # noqa: E402
from assur.generic import NewtonGroup, group_class_of  # noqa: E402
from assur.triad import Triad  # noqa: E402
from linkage.kinetostatics.reactions import solve_reactions, virtual_power_residual  # noqa: E402

SCHEMES = Path(__file__).resolve().parent.parent / "schemes"


def triad(crank: float, B, C, D, E, F, size: float = 0.5):
    """A crank OA (A at (crank, 0) when phi = 0) driving a triad: leg 2 (A-B), ternary link 3
    (B, C, D in global coordinates at phi = 0), legs 4 (E-C) and 5 (F-D) to frame points E, F."""
    A0 = np.array([crank, 0.0])
    B, C, D, E, F = map(np.asarray, (B, C, D, E, F))
    joints = [RevoluteJoint("A", "1", "2", (crank, 0.0), (0.0, 0.0)),
              RevoluteJoint("B", "2", "3", (float(np.hypot(*(B - A0))), 0.0), tuple(B)),
              RevoluteJoint("C", "3", "4", tuple(C), (float(np.hypot(*(C - E))), 0.0)),
              RevoluteJoint("D", "3", "5", tuple(D), (float(np.hypot(*(D - F))), 0.0)),
              RevoluteJoint("E", "4", "0", (0.0, 0.0), tuple(E)),
              RevoluteJoint("F", "5", "0", (0.0, 0.0), tuple(F))]
    lengths = (float(np.hypot(*(B - A0))), float(np.hypot(*(C - E))), float(np.hypot(*(D - F))))
    return Triad.bind(["2", "3", "4", "5"], joints, {"0", "1"}, size), (B, C, D, E, F, lengths)


def brute_force_modes(crank, phi, geometry, starts=300, seed=0):
    """Every pose (x, y, theta) of the ternary link at the crank angle ``phi`` by least squares
    on the three leg lengths from many random starts (independent of the library)."""
    B, C, D, E, F, (lab, lec, lfd) = geometry
    A = np.array([crank * np.cos(phi), crank * np.sin(phi)])

    def residual(x):
        R = np.array([[np.cos(x[2]), -np.sin(x[2])], [np.sin(x[2]), np.cos(x[2])]])
        return [np.hypot(*(x[:2] + R @ P - anchor)) - length
                for P, anchor, length in ((B, A, lab), (C, E, lec), (D, F, lfd))]

    rng = np.random.default_rng(seed)
    found = []
    for _ in range(starts):
        x0 = np.r_[rng.uniform(-0.6, 0.6, 2), rng.uniform(-np.pi, np.pi)]
        s = least_squares(residual, x0, xtol=1e-15, ftol=1e-15, gtol=1e-15)
        if np.max(np.abs(s.fun)) < 1e-11:
            x = s.x.copy()
            x[2] = (x[2] + np.pi) % (2 * np.pi) - np.pi
            if not any(np.max(np.abs(x - y)) < 1e-7 for y in found):
                found.append(x)
    return sorted(found, key=lambda x: x[2])


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_every_triad_mode_is_listed_and_closes(seed):
    """Random triads: the listed modes at 6 crank angles equal the brute-force solutions (count and
    poses), and every listed mode closes every pair to 1e-12 of the size."""
    rng = np.random.default_rng(seed)
    B = np.array([0.15, 0.1]) + rng.uniform(-0.05, 0.05, 2)
    C = B + np.array([0.15, 0.0]) + rng.uniform(-0.05, 0.05, 2)
    D = B + np.array([0.05, 0.15]) + rng.uniform(-0.05, 0.05, 2)
    E = C + np.array([0.1, -0.15]) + rng.uniform(-0.08, 0.08, 2)
    F = D + np.array([-0.15, 0.1]) + rng.uniform(-0.08, 0.08, 2)
    group, geometry = triad(0.05, B, C, D, E, F)
    phi = np.radians([0.0, 47.0, 101.0, 180.0, 233.0, 301.0])
    poses = {"0": np.zeros((6, 3)), "1": np.column_stack([np.zeros(6), np.zeros(6), phi])}
    listed, valid = group.modes(poses)
    assert valid[0].sum() >= 1                                   # assembled as designed at phi = 0
    for n, angle in enumerate(phi):
        expected = brute_force_modes(0.05, angle, geometry, starts=120)
        got = sorted(listed["3"][n][valid[n]], key=lambda x: x[2])
        assert len(got) == len(expected)
        for a, b in zip(got, expected):
            np.testing.assert_allclose(a, b, atol=1e-9)
    merged = {**{k: np.repeat(v, 8, axis=0) for k, v in poses.items()},
              **{k: v.reshape(-1, 3) for k, v in listed.items()}}
    closure = np.max(np.abs(group.residual(merged)), axis=1).reshape(6, 8)
    assert np.all(closure[valid] <= 1e-12 * 0.5)


def test_newton_started_near_a_mode_converges_to_it():
    group, _ = triad(0.05, (0.10, 0.15), (0.23, 0.13), (0.19, 0.31), (0.33, 0.02), (-0.04, 0.44))
    generic = NewtonGroup(group.links, group.joints, group.size)
    phi = np.radians(np.arange(0.0, 360.0, 15.0))
    n = len(phi)
    poses = {"0": np.zeros((n, 3)), "1": np.column_stack([np.zeros(n), np.zeros(n), phi])}
    listed, valid = group.modes(poses)
    assert np.all(valid.sum(axis=1) == 2)
    rng = np.random.default_rng(4)
    for slot in range(8):
        rows = valid[:, slot]
        if not rows.any():
            continue
        exact = {k: v[rows, slot] for k, v in listed.items()}
        start = {k: v + rng.normal(scale=[2e-3, 2e-3, 1e-2], size=v.shape) for k, v in exact.items()}
        known = {k: v[rows] for k, v in poses.items()}
        got = generic.position(known, start=start)
        assert np.all(got.status == OK)
        for k in exact:
            np.testing.assert_allclose(got.poses[k], exact[k], atol=1e-12)


@pytest.mark.parametrize("kind", ["RRR", "RRP", "RPR", "PRP", "RPP"])
@settings(SETTINGS, max_examples=15)
@given(data=st.data())
def test_the_generic_solver_equals_the_closed_form_of_every_dyad(kind, data):
    """Newton's method from the closed form moved by 1 % of the size (0.01 rad) reaches it again,
    with the same statuses and analogs (the generic analogs are the dyads' oracle)."""
    case = data.draw(cases(kind))
    group = case.bind()
    generic = NewtonGroup(group.links, group.joints, group.size)
    poses, first, second = case.path(np.linspace(-0.5, 0.5, 11))
    exact = group.solve(poses, first, second, group.branches[0])
    ok = exact.status == OK
    assume(ok.any())       # hypothesis counts and replaces a draw with nothing to compare
    known = {k: v[ok] for k, v in poses.items()}
    rng = np.random.default_rng(data.draw(st.integers(0, 2**31)))
    start = {k: v[ok] + rng.uniform(-1, 1, (int(ok.sum()), 3)) * [0.01 * case.size, 0.01 * case.size, 0.01]
             for k, v in exact.poses.items()}
    got = generic.solve(known, {k: v[ok] for k, v in first.items()}, {k: v[ok] for k, v in second.items()},
                        start=start)
    assert np.all(got.status == OK)
    for k in exact.poses:
        turn = (got.poses[k][:, 2] - exact.poses[k][ok, 2] + np.pi) % (2 * np.pi) - np.pi
        np.testing.assert_allclose(got.poses[k][:, :2], exact.poses[k][ok, :2], atol=1e-11 * case.size)
        np.testing.assert_allclose(turn, 0.0, atol=1e-11)
        scale = max(1.0, float(np.max(np.abs(exact.first[k][ok]))))
        np.testing.assert_allclose(got.first[k], exact.first[k][ok], atol=1e-9 * scale)


def test_group_classes():
    ternary = triad(0.05, (0.10, 0.15), (0.23, 0.13), (0.19, 0.31), (0.33, 0.02), (-0.04, 0.44))[0]
    assert group_class_of(ternary.links, ternary.joints) == "III"
    square = [RevoluteJoint(n, a, b, (0.0, 0.0), (0.0, 0.0))
              for n, a, b in (("P", "2", "3"), ("Q", "3", "4"), ("R", "4", "5"), ("S", "5", "2"),
                              ("T", "2", "0"), ("U", "4", "0"))]
    assert group_class_of(["2", "3", "4", "5"], square) == "IV"      # a closed contour of four links


def test_class_three_scheme_kinetostatics_balance_and_positions_match_brute_force():
    mech = linkage.load("six_bar_class3")
    phi = np.radians(np.arange(0.0, 360.0, 10.0) + 3.0)
    motion = linkage.analyze(mech, phi, omega=10.0)
    assert np.all(motion.status == OK)
    assert np.all(virtual_power_residual(solve_reactions(motion)) <= 1e-9)
    geometry = ((0.10, 0.15), (0.23, 0.13), (0.19, 0.31), (0.33, 0.02), (-0.04, 0.44))
    _, full = triad(0.05, *geometry)
    D = motion.point("D")
    for n in (0, 9, 20, 31):
        modes = brute_force_modes(0.05, phi[n], full, starts=150)
        # the brute force gives the ternary link's pose in the frame of geometry (B at (0.10, 0.15)):
        # D of each mode; the declared one is left of F -> C
        candidates = []
        for x in modes:
            R = np.array([[np.cos(x[2]), -np.sin(x[2])], [np.sin(x[2]), np.cos(x[2])]])
            candidates.append(x[:2] + R @ np.array(geometry[2]))
        assert min(np.max(np.abs(D[n] - c)) for c in candidates) <= 1e-10


def test_a_group_without_closed_form_is_solved_by_newton_from_many_starts():
    """The triad with its leg DF replaced by a slider on a frame guide (no closed form registered):
    found by Newton's method from many starts, traced over its input range; closes, and its
    analogs equal finite differences."""
    text = (SCHEMES / "six_bar_class3.toml").read_text()
    text = text.replace('F = [-0.04, 0.44] }', 'F = [-0.04, 0.44] }\nguides.way = { through = [0.19, 0.31], '
                        'angle_deg = -29.47588900324573 }')
    start, end = text.index("[links.5]"), text.index("[pairs.O]")
    text = text[:start] + '[links.5]\npoints.D = [0.0, 0.0]\nmass = 1.0\ncom = "D"\n\n' + text[end:]
    text = text.replace('[pairs.F]\nlinks = ["5", "0"]',
                        '[pairs.F]\nkind = "P"\nlinks = ["0", "5"]\nguide = "way"\nat = "D"')
    text = text.replace('input = "1"', 'input = "1"\nrange_deg = [0, 100]')
    # its two modes (B at (0.10, 0.15) or about (0.117, 0.143) when phi = 0) both have D left of F -> C
    text = text.replace('[assembly.D]', '[assembly.B]').replace('left_of = ["F", "C"]', 'from = "A"\ntowards_deg = 158')
    mech = linkage.loads(text)
    group = linkage.structure_of(mech).groups[0]
    assert type(group) is NewtonGroup and repr(group) == "III(2,3,4,5)"
    phi = np.radians(np.linspace(2.0, 98.0, 25))
    motion = linkage.analyze(mech, phi, omega=10.0)
    assert np.all(motion.status == OK)
    h = 1e-5
    ahead, behind = (linkage.analyze(mech, phi + d, order=0) for d in (h, -h))
    for point in ("B", "C", "D"):
        finite = (ahead.point(point) - behind.point(point)) / (2 * h)
        np.testing.assert_allclose(motion.point_analogs(point)[0], finite, atol=1e-7)
        closure_b = np.hypot(*(motion.point("B") - motion.point("A")).T) - mech.links["2"].points["B"][0]
        assert np.max(np.abs(closure_b)) <= 1e-12
    assert np.all(virtual_power_residual(solve_reactions(motion)) <= 1e-9)
