"""The compiled reactions kernel (linkage/kinetostatics/kernel.py, issue 24) against the general path.

The oracle is ``reactions_under`` group by group (``Dyad.reactions``, then each input link's
equilibrium) with the kernels switched off (:data:`linkage.kinematics.motion.USE_KERNEL`). For
every shipped scheme whose groups are all closed-form dyads, under its declared loads, gravity
and inertia at a real speed, at random angles and at the positions where a group is singular or
cannot be assembled: the same NaN positions, and every pair's multipliers and the balancing load
equal to 1e-13 of the largest load. Virtual power (an independent invariant: reactions of ideal
pairs do no work) holds through the kernel.
"""

from __future__ import annotations

import warnings
import zlib
from pathlib import Path

import numpy as np
import pytest

import linkage
import linkage.kinematics.motion as motion_module
from linkage.kinematics.motion import BranchWarning
from linkage.kinetostatics.kernel import reactions_kernel_for
from linkage.kinetostatics.reactions import solve_reactions, virtual_power_residual
from linkage.model.scheme import scheme_path

SCHEMES = ["four_bar", "slider_crank", "six_bar", "watt_six_bar", "flying_shears", "slotted_link",
           "slotted_link_two_dyad", "scotch_yoke", "slider_crank_vertical", "course_slider_crank",
           "stephenson_six_bar", "five_bar_two_input", "piston_driven_crank"]
TOL = 1e-13


def reactions(mech, phi, kernel: bool, monkeypatch):
    monkeypatch.setattr(motion_module, "USE_KERNEL", kernel)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", BranchWarning)
        motion = linkage.analyze(mech, phi, omega=7.0, eps=-2.0, on_failure="mask")
        return solve_reactions(motion)


def same(got, want, scale, what):
    got, want = np.asarray(got), np.asarray(want)
    np.testing.assert_array_equal(np.isnan(got), np.isnan(want), err_msg=f"{what}: NaN elsewhere")
    finite = np.isfinite(want)
    err = np.abs(got[finite] - want[finite])
    assert (err <= TOL * scale).all(), f"{what}: off by {err.max():.3g} (scale {scale:.3g})"


@pytest.mark.parametrize("name", SCHEMES)
def test_the_kernel_gives_the_general_path_s_reactions(name, monkeypatch):
    mech = linkage.load(name)
    assert reactions_kernel_for(mech) is not None
    rng = np.random.default_rng(zlib.crc32(name.encode()))
    low, high = mech.input_range if mech.input_range is not None else (0.0, 2 * np.pi)
    phi = np.sort(np.concatenate([rng.uniform(min(low, high), max(low, high), 60), [low, high]]))
    fast, slow = (reactions(mech, phi, kernel, monkeypatch) for kernel in (True, False))
    scale = max(np.nanmax(np.abs(v)) for v in [slow.balancing_moment, *slow.multipliers.values()])
    assert np.isfinite(slow.balancing_moment).mean() > 0.5
    same(fast.balancing_moment, slow.balancing_moment, scale, f"{name}: balancing load")
    assert fast.multipliers.keys() == slow.multipliers.keys()
    for pair, value in slow.multipliers.items():
        same(fast.multipliers[pair], value, scale, f"{name}: multipliers of pair {pair}")
    for link, value in slow.balancing_moments.items():
        same(fast.balancing_moments[link], value, scale, f"{name}: balancing load of input {link}")
    residual = virtual_power_residual(fast)
    assert np.nanmax(residual) < 1e-9, f"{name}: virtual power off by {np.nanmax(residual):.3g}"


def test_where_the_mechanism_cannot_be_assembled_the_reactions_are_nan(monkeypatch, tmp_path):
    """The shipped four-bar with a coupler of 0.12 m instead of 0.3 m: AB + CB = 0.37 m < |AC| =
    0.4 m near 180 deg, so NaN there and numbers elsewhere, at the same positions."""
    text = Path(scheme_path("four_bar")).read_text()
    assert text.count("length = 0.3\n") == 1
    path = tmp_path / "short_coupler.toml"
    path.write_text(text.replace("length = 0.3\n", "length = 0.12\n"))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        mech = linkage.load(path)
    phi = np.linspace(0.0, 2 * np.pi, 73)
    fast, slow = (reactions(mech, phi, kernel, monkeypatch) for kernel in (True, False))
    gap = np.hypot(0.3 - 0.1 * np.cos(phi), 0.1 * np.sin(phi)) > 0.37     # |AC| > AB + CB
    np.testing.assert_array_equal(np.isnan(slow.balancing_moment), gap)
    np.testing.assert_array_equal(np.isnan(fast.balancing_moment), gap)
    same(fast.balancing_moment, slow.balancing_moment, np.nanmax(np.abs(slow.balancing_moment)), "short coupler")
