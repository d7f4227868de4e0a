"""The second analogs' promise next to change points (docs/numerics.md#the-status-ok-guarantee).

At a change point the analogs stay bounded while the group's conditioning r goes to 0, so the
error of the second analogs grows like the first analogs' error over r. Swept toward the change
points of an isosceles slider-crank (guide along x and turned) and of a parallelogram four-bar,
every status-OK position must keep the promise against the textbook closed forms written here
(exact second analogs, independent of the solvers), and positions 1e-2 rad and farther from the
point must stay OK.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import linkage
from assur import ANALOG_TOL

from _texts import four_bar_toml, slider_crank_toml

#: 8 angles a decade from 1e-1 to 1e-6 rad of the change point
DISTANCES = 10.0 ** -np.linspace(1.0, 6.0, 41)


def _analyze(mech, phi):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")     # the keep mode's BranchWarning is not under test
        return linkage.analyze(mech, phi, on_failure="mask")


def _errors(got1, got2, want1, want2):
    """Largest errors ``(N,)`` of first and second analogs ``(N, k)`` relative to the largest
    first analog (at least the crank's 1) and to the largest first or second analog."""
    scale1 = np.maximum(np.max(np.abs(want1), axis=1), 1.0)
    scale2 = np.maximum(np.max(np.abs(want2), axis=1), scale1)
    return np.max(np.abs(got1 - want1), axis=1) / scale1, np.max(np.abs(got2 - want2), axis=1) / scale2


def _check(motion, e1, e2, delta):
    ok = motion.status == 0
    assert set(np.unique(motion.status)) <= {0, -2}
    assert np.all(e1[ok] <= ANALOG_TOL), (delta[ok][e1[ok] > ANALOG_TOL], e1[ok].max())
    assert np.all(e2[ok] <= 10 * ANALOG_TOL), (delta[ok][e2[ok] > 10 * ANALOG_TOL], e2[ok].max())
    assert np.all(ok[delta >= 1e-2]), delta[~ok]
    # flagged ones carry NaN analogs, never a number outside the promise
    assert np.all(np.isnan(e2[~ok]))
    return ok


@pytest.mark.parametrize("alpha_deg", [0.0, 30.0, 73.3])
@pytest.mark.parametrize("side", [-1, 1])
def test_isosceles_slider_crank_keeps_the_promise_toward_its_change_point(alpha_deg, side):
    """Crank = rod = 1, guide through O at alpha, followed through the change point (the crank
    across the guide, phi = alpha + 90 deg): s = 2 cos(phi - alpha), the rod's angle 2 alpha - phi."""
    toml = slider_crank_toml(1.0, 1.0, f'from = "O"\ntowards_deg = {alpha_deg!r}\nphi_deg = {alpha_deg + 45!r}\n'
                             'mode = "follow"', name="isosceles")
    mech = linkage.loads(toml.replace("angle_deg = 0 }", f"angle_deg = {alpha_deg!r} }}"))
    alpha = np.radians(alpha_deg)
    phi = alpha + np.pi / 2 + side * DISTANCES
    motion = _analyze(mech, phi)
    u = np.array([np.cos(alpha), np.sin(alpha)])
    s1, s2 = -2 * np.sin(phi - alpha), -2 * np.cos(phi - alpha)
    want1 = np.column_stack([s1 * u[0], s1 * u[1], s1, -np.ones_like(phi)])
    want2 = np.column_stack([s2 * u[0], s2 * u[1], s2, np.zeros_like(phi)])
    quantities = ("B.x", "B.y", "slide.s", "2.theta")
    got1 = np.column_stack([motion.quantity(q)[1] for q in quantities])
    got2 = np.column_stack([motion.quantity(q)[2] for q in quantities])
    e1, e2 = _errors(got1, got2, want1, want2)
    ok = _check(motion, e1, e2, DISTANCES)
    assert not ok[DISTANCES < 1e-4].any()        # r ~ 0.4 x distance: flagged near the point


@pytest.mark.parametrize("change_point, side", [(np.pi, -1), (np.pi, 1), (0.0, 1), (2 * np.pi, -1)])
def test_parallelogram_keeps_the_promise_toward_its_change_points(change_point, side):
    """Crank 1, coupler 2, rocker 1, ground 2 followed as a parallelogram: the coupler translates
    (B = A + (2, 0)), the rocker turns with the crank (theta_3 = phi)."""
    mech = linkage.loads(four_bar_toml(1, 2, 1, 2, 'left_of = ["A", "C"]\nphi_deg = 90\nmode = "follow"',
                                       name="parallelogram"))
    phi = change_point + side * DISTANCES
    motion = _analyze(mech, phi)
    c, s = np.cos(phi), np.sin(phi)
    want1 = np.column_stack([-s, c, np.zeros_like(phi), np.ones_like(phi)])
    want2 = np.column_stack([-c, -s, np.zeros_like(phi), np.zeros_like(phi)])
    quantities = ("B.x", "B.y", "2.theta", "3.theta")
    got1 = np.column_stack([motion.quantity(q)[1] for q in quantities])
    got2 = np.column_stack([motion.quantity(q)[2] for q in quantities])
    e1, e2 = _errors(got1, got2, want1, want2)
    ok = _check(motion, e1, e2, DISTANCES)
    assert not ok[DISTANCES < 1e-4].any()


def test_the_bound_counts_the_first_analogs_error_over_the_conditioning():
    """Where the analogs stay bounded (the parallelogram next to its change point) the reported
    bound grows like 1 / r**3 -- the first analogs' 1 / r**2 over r -- and not only like the
    first analogs' 3 eps / r**2; positions computed without second analogs keep the first
    analogs' bound and status."""
    mech = linkage.loads(four_bar_toml(1, 2, 1, 2, 'left_of = ["A", "C"]\nphi_deg = 90\nmode = "follow"',
                                       name="parallelogram"))
    phi = np.pi - np.array([1e-2, 5e-3])
    second = _analyze(mech, phi)
    first = linkage.analyze(mech, phi, order=1, on_failure="mask")
    r = second.conditioning["II-RRR(2,3)"]
    eps = np.finfo(float).eps
    np.testing.assert_allclose(first.error_bound, 3 * eps / r**2, rtol=1e-9)
    assert np.all(second.error_bound > first.error_bound + 0.01 * eps / r**3)
    assert list(first.status) == [0, 0] and list(second.status) == [0, -2]
