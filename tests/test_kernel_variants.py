"""Batches of variants through the compiled kernel (linkage/kinematics/kernel_variants.py, issue 24).

The oracle is the general path of the same batch (``run_blocks`` with every position's own
joints, :data:`linkage.kinematics.motion.USE_KERNEL` off). For every shipped scheme whose groups
are all closed-form dyads and whose one input is a crank (RRR, RRP, RPR, PRP and RPP dyads among
them), variants with every point of every link moved by up to 15 % of the mechanism's size, on
angles that include the base's least conditioning: the kernel must give the same statuses
(per position, OTHER_BRANCH included) and mode changes, and poses, analogs, conditioning and
error bounds equal to 1e-13 relative, with NaN at the same positions.
"""

from __future__ import annotations

import warnings
import zlib

import numpy as np
import pytest

import linkage
import linkage.kinematics.motion as motion_module
from linkage.kinematics.batch import analyze_variants
from linkage.kinematics.kernel_variants import variant_kernel_for
from linkage.kinematics.motion import BranchWarning

SCHEMES = ["four_bar", "slider_crank", "six_bar", "watt_six_bar", "flying_shears", "slotted_link",
           "slotted_link_two_dyad", "scotch_yoke", "slider_crank_vertical", "course_slider_crank",
           "stephenson_six_bar"]
TOL = 1e-13
VARIANTS = 60


def moved_geometry(mech, rng) -> dict:
    """Every point of every link moved by up to 15 % of the mechanism's size, per variant."""
    size = mech.size
    return {k: {p: np.asarray(xy, float) + rng.uniform(-0.15, 0.15, (VARIANTS, 2)) * size
                for p, xy in link.points.items()}
            for k, link in mech.links.items() if link.points}


def batch(mech, phi, geometry, kernel: bool, monkeypatch):
    monkeypatch.setattr(motion_module, "USE_KERNEL", kernel)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", BranchWarning)
        return analyze_variants(mech, phi, geometry, order=2)


def close(got, want, what):
    got, want = np.asarray(got), np.asarray(want)
    np.testing.assert_array_equal(np.isnan(got), np.isnan(want), err_msg=f"{what}: NaN elsewhere")
    finite = np.isfinite(want)
    err = np.abs(got[finite] - want[finite])
    tol = TOL * (np.abs(want[finite]) + 1.0)
    assert (err <= tol).all(), f"{what}: off by {err.max():.3g}"


@pytest.mark.parametrize("name", SCHEMES)
def test_a_batch_through_the_kernel_equals_the_general_path(name, monkeypatch):
    mech = linkage.load(name)
    assert variant_kernel_for(mech, 2) is not None, "the batch would not use the kernel"
    rng = np.random.default_rng(zlib.crc32(name.encode()))
    low, high = mech.input_range if mech.input_range is not None else (0.0, 2 * np.pi)
    phi = np.sort(rng.uniform(min(low, high), max(low, high), 24))
    geometry = moved_geometry(mech, rng)
    fast, slow = (batch(mech, phi, geometry, kernel, monkeypatch) for kernel in (True, False))
    np.testing.assert_array_equal(fast.status, slow.status)
    np.testing.assert_array_equal(fast.mode_change, slow.mode_change)
    assert (fast.status == 0).mean() > 0.3, "too few positions assembled to compare"
    for name_, a, b in (("poses", fast.poses, slow.poses), ("first", fast.first, slow.first),
                        ("second", fast.second, slow.second)):
        for link in b:
            close(a[link], b[link], f"{name} {name_} of link {link}")
    for group in slow.conditioning:
        close(fast.conditioning[group], slow.conditioning[group], f"{name} conditioning of {group}")
    close(fast.error_bound, slow.error_bound, f"{name} error bound")


def test_the_kernel_is_the_one_that_ran(monkeypatch):
    """A closed-form batch does not call the general path."""
    import linkage.kinematics.batch as batch_module

    def refuse(*args, **kwargs):
        raise AssertionError("the general path ran")

    monkeypatch.setattr(batch_module, "run_blocks", refuse)
    mech = linkage.load("four_bar")
    crank = np.column_stack([np.linspace(0.08, 0.12, 5), np.zeros(5)])
    got = analyze_variants(mech, np.radians([0.0, 90.0]), {"1": {"A": crank}})
    # OA = 0.1 at 90 deg: the closed form of the four-bar's B against the kernel's
    assert got.status.shape == (5, 2)
    C, AB, CB = np.array([0.3, 0.0]), 0.3, 0.25
    A = np.array([0.0, 0.1])
    d = np.linalg.norm(C - A)
    a = (AB**2 - CB**2 + d**2) / (2 * d)
    e = (C - A) / d
    h = np.sqrt(AB**2 - a**2)
    B = A + a * e + h * np.array([-e[1], e[0]])
    np.testing.assert_allclose(got.poses["2"][2, 1, 2], np.arctan2(*(B - A)[::-1]), atol=1e-12)


def test_a_two_input_mechanism_keeps_the_general_path():
    assert variant_kernel_for(linkage.load("five_bar_two_input"), 2) is None
