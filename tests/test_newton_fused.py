"""The fused residual and Jacobian of the groups solved by Newton's method (assur/fused.py) against
the pair-by-pair path of assur/base.py (each pair's own equations and Jacobian blocks, stacked),
against central differences of the fused residual, and the analysed motions with the fused path
on and off."""

from __future__ import annotations

import sys
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))

import _triads  # noqa: E402
from test_triad_modes import REGRESSIONS  # noqa: E402

import assur.fused  # noqa: E402
import linkage  # noqa: E402
from assur.base import Group  # noqa: E402
from assur.fused import layout_of  # noqa: E402
from assur.generic import NewtonGroup, newton, newton_closing, newton_pairwise  # noqa: E402
from linkage.kinematics import tracing  # noqa: E402
from linkage.structure import structure_of  # noqa: E402

TIGHT = 1e-13


def _newton_group(mech):
    (group,) = [g for g in structure_of(mech).groups if getattr(g, "tracked", False)]
    return group


def _groups():
    """(label, group): the triads of tests/_triads.py (RRR legs, a slot on leg 0, a slider on leg
    2), six_bar_class3's triad and cylinder_boom's group (a driven prismatic pair)."""
    out = [(f"triad-{design.kind}", _newton_group(_triads.build(design, rule))) for design, rule in REGRESSIONS[:3]]
    out += [(name, _newton_group(linkage.load(name))) for name in ("six_bar_class3", "cylinder_boom")]
    # the same pairs with every local vector and angle redrawn at random: no entry is zero by
    # the drawing (a pin at a link's origin), so that each one is checked
    rng = np.random.default_rng(0)

    def redrawn(joint):
        fields = {f: tuple(rng.uniform(-0.3, 0.3, 2)) for f in ("pa", "pb", "g", "p") if hasattr(joint, f)}
        if hasattr(joint, "u"):
            turn = rng.uniform(-np.pi, np.pi)
            fields.update(u=(np.cos(turn), np.sin(turn)), beta=rng.uniform(-np.pi, np.pi))
        return replace(joint, **fields)

    out += [(f"{label}-redrawn", NewtonGroup(group.links, [redrawn(j) for j in group.joints], group.size))
            for label, group in out]
    return out


GROUPS = _groups()


def _random_poses(group, N: int, seed: int) -> dict[str, np.ndarray]:
    """Poses of every link the group's equations read, anywhere (not solutions): x, y within the
    size, angles over two turns (the angle rows' wrap included)."""
    rng = np.random.default_rng(seed)
    size = float(np.max(group.size))
    return {k: np.column_stack([rng.uniform(-size, size, N), rng.uniform(-size, size, N),
                                rng.uniform(-2 * np.pi, 2 * np.pi, N)]) for k in (*group.links, *group.known_links)}


def _close(a, b, scale):
    np.testing.assert_allclose(a, b, rtol=TIGHT, atol=TIGHT * scale)


@pytest.mark.parametrize("label, group", GROUPS, ids=[label for label, _ in GROUPS])
def test_the_fused_residual_and_jacobian_equal_the_pairwise_ones_at_random_poses(label, group):
    assert layout_of(group) is not None
    for N, seed in ((1, 1), (7, 2), (200, 3)):
        poses = _random_poses(group, N, seed)
        expected, got = Group.residual(group, poses), group.residual(poses)
        assert got.shape == expected.shape == (N, group.row_count)
        _close(got, expected, np.max(np.abs(expected)))
        # the unscaled residual Newton's method takes, evaluated with the Jacobian
        raw = np.concatenate([j.residual(poses) for j in group.joints], axis=1)
        _close(layout_of(group).evaluate(layout_of(group).stack(poses))[0], raw, np.max(np.abs(raw)))
        phi_q, phi_k = Group.jacobians(group, poses)
        fused_q, fused_k = group.jacobians(poses)
        assert fused_q.shape == phi_q.shape and set(fused_k) == set(phi_k)
        scale = np.max(np.abs(phi_q))
        _close(fused_q, phi_q, scale)
        for k in phi_k:
            _close(fused_k[k], phi_k[k], scale)


@pytest.mark.parametrize("label, group", GROUPS, ids=[label for label, _ in GROUPS])
def test_the_fused_jacobian_is_the_derivative_of_the_fused_residual(label, group):
    """Every column, the group's links' and the known links' (a cylinder's driver too), against
    central differences of the fused residual (angle rows in rad, as the Jacobian has them)."""
    layout = layout_of(group)
    poses = _random_poses(group, 5, 4)
    stack = layout.stack(poses)
    _, jacobian = layout.evaluate(stack)
    h = 1e-6
    for column in range(jacobian.shape[2]):
        link, coordinate = divmod(column, 3)
        plus, minus = stack.copy(), stack.copy()
        plus[:, link, coordinate] += h
        minus[:, link, coordinate] -= h
        numeric = (layout.evaluate(plus, jacobian=False)[0] - layout.evaluate(minus, jacobian=False)[0]) / (2 * h)
        np.testing.assert_allclose(jacobian[:, :, column], numeric, rtol=0, atol=1e-7 * (1 + np.max(np.abs(jacobian))))


DRAWN = [(label, group) for label, group in GROUPS if not label.endswith("-redrawn")]


@pytest.mark.parametrize("label, group", DRAWN, ids=[label for label, _ in DRAWN])
def test_fused_newton_reaches_what_the_pairwise_newton_reaches(label, group):
    """From starts near solutions and far from them (some do not converge): the same poses and the
    same convergence flags."""
    size = float(np.max(group.size))
    rng = np.random.default_rng(5)
    poses = _random_poses(group, 64, 6)
    known = {k: poses[k] * np.array([0.2, 0.2, 0.1]) for k in group.known_links}
    start = {k: poses[k] for k in group.links}
    fused, converged = newton(group, known, start)
    pairwise, converged_pairwise = newton_pairwise(group, known, start)
    np.testing.assert_array_equal(converged, converged_pairwise)
    assert converged.any()
    for k in group.links:
        np.testing.assert_allclose(fused[k], pairwise[k], rtol=TIGHT, atol=TIGHT * size)
    # restarted a little off the solutions reached: both converge back, to the same poses
    near = {k: np.where(converged[:, None], v + rng.normal(0, 1e-3, v.shape) * np.array([size, size, 1.0]), np.nan)
            for k, v in fused.items()}
    again, ok = newton(group, known, near)
    again_pairwise, ok_pairwise = newton_pairwise(group, known, near)
    np.testing.assert_array_equal(ok, ok_pairwise)
    for k in group.links:
        np.testing.assert_allclose(again[k], again_pairwise[k], rtol=TIGHT, atol=TIGHT * size)


@pytest.mark.parametrize("fused", [True, False], ids=["fused", "pairwise"])
@pytest.mark.parametrize("label, group", DRAWN, ids=[label for label, _ in DRAWN])
def test_newton_closing_stops_where_the_group_closes_and_reports_how_well(label, group, fused, monkeypatch):
    """newton_closing's gap is the largest residual of the pair-by-pair equations (prismatic angle
    rows times the size) at the poses it returns; a position it reports closed is the solution
    Newton's method converges to from the same start, to the closure over the conditioning."""
    monkeypatch.setattr(assur.fused, "FUSED", fused)
    size = float(np.max(group.size))
    poses = _random_poses(group, 64, 6)
    known = {k: poses[k] * np.array([0.2, 0.2, 0.1]) for k in group.known_links}
    start = {k: poses[k] for k in group.links}
    closure = 1e-12 * size
    solved, gap = newton_closing(group, known, start, closure)
    converged_at, converged = newton(group, known, start)
    residual = np.abs(Group.residual(group, {**known, **solved})).max(axis=1)
    finite = np.isfinite(residual)
    np.testing.assert_allclose(gap[finite], residual[finite], rtol=1e-12, atol=1e-15 * size)
    assert np.all(np.isinf(gap[~finite]))
    closed = gap <= closure
    assert closed.sum() >= converged.sum() > 0
    both = closed & converged
    for k in group.links:
        np.testing.assert_allclose(solved[k][both], converged_at[k][both], rtol=0, atol=1e-7 * size)
    # known poses given once, (1, 3), for every position: the same result
    once = {k: v[:1] for k, v in known.items()}
    repeated = {k: np.repeat(v, 64, axis=0) for k, v in once.items()}
    a, gap_a = newton_closing(group, once, start, closure)
    b, gap_b = newton_closing(group, repeated, start, closure)
    np.testing.assert_array_equal(gap_a, gap_b)


@pytest.mark.parametrize("label, group", DRAWN[-2:], ids=[label for label, _ in DRAWN[-2:]])
def test_random_starts_at_several_positions_in_one_call_find_each_positions_modes(label, group):
    """The modes found from random starts at four positions at once are those found position by
    position, in the same order (the batch changes nothing a position sees)."""
    size = float(np.max(group.size))
    poses = _random_poses(group, 4, 8)
    known = {k: poses[k] * np.array([0.2, 0.2, 0.1]) for k in group.known_links}
    solved, good = tracing._random_starts(group, known, size)
    found_somewhere = 0
    for s in range(4):
        alone = tracing.random_start_modes(group, {k: v[s:s + 1] for k, v in known.items()}, size)
        batched = tracing._distinct(group, {k: v[s] for k, v in solved.items()}, good[s], size)
        found_somewhere += len(alone[group.links[0]])
        for k in group.links:
            np.testing.assert_array_equal(batched[k], alone[k])
    assert found_somewhere > 0


def test_the_switch_and_per_position_geometry_take_the_pairwise_path(monkeypatch):
    """With FUSED off, and for pairs whose local geometry is per position (a variant batch), no
    layout: the group's residual is the pair-by-pair one."""
    group = dict(GROUPS)["six_bar_class3"]
    poses = _random_poses(group, 3, 7)
    monkeypatch.setattr(assur.fused, "FUSED", False)
    assert layout_of(group) is None
    monkeypatch.setattr(assur.fused, "FUSED", True)
    joint = group.joints[0]
    varied = NewtonGroup(group.links, (replace(joint, pa=np.tile(np.asarray(joint.pa, float), (3, 1))),
                                       *group.joints[1:]), group.size)
    assert layout_of(varied) is None
    np.testing.assert_array_equal(varied.residual(poses), Group.residual(group, poses))


def _motion(name: str, fused: bool, monkeypatch):
    monkeypatch.setattr(assur.fused, "FUSED", fused)
    mech = linkage.load(name)               # its assembly plan traced on this path
    if mech.input_range is None:
        phi = np.linspace(0.0, 2 * np.pi, 91)
    else:
        phi = np.linspace(*mech.input_range, 61)
    return linkage.analyze(mech, phi, order=2, on_failure="mask")


@pytest.mark.parametrize("name", ["six_bar_class3", "cylinder_boom"])
def test_analysed_motions_are_the_same_with_the_fused_path_on_and_off(name, monkeypatch):
    on, off = _motion(name, True, monkeypatch), _motion(name, False, monkeypatch)
    np.testing.assert_array_equal(on.status, off.status)
    assert (on.status == 0).sum() > 0.8 * len(on.status)
    size = on.mechanism.size
    for field in ("poses", "first", "second"):
        a, b = getattr(on, field), getattr(off, field)
        assert set(a) == set(b)
        for k in a:
            scale = max(size, float(np.nanmax(np.abs(b[k][:, :2]), initial=0.0)), 1.0)
            np.testing.assert_allclose(a[k], b[k], rtol=1e-12, atol=1e-12 * scale, equal_nan=True)
    for label in on.conditioning:
        np.testing.assert_allclose(on.conditioning[label], off.conditioning[label], rtol=1e-12, atol=1e-15,
                                   equal_nan=True)
    np.testing.assert_allclose(on.error_bound, off.error_bound, rtol=1e-9, equal_nan=True)
