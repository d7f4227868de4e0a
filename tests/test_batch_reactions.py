"""Kinetostatics of a batch of variants (``linkage.kinetostatics.batch.variant_reactions``): each
variant's reactions equal its own scheme text (masses and a force written into it) solved alone;
a slider-crank's balancing moment equals the closed form of virtual work; the virtual-power check
holds at every OK position; bad input is refused with the entry named."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))

from test_batch import PHI, SCHEMES, four_bar_geometry, four_bar_text  # noqa: E402

import linkage  # noqa: E402
from linkage.kinematics.batch import analyze_variants  # noqa: E402
from linkage.kinetostatics.batch import variant_reactions  # noqa: E402
from linkage.errors import InputError  # noqa: E402
from linkage.kinetostatics.reactions import solve_reactions  # noqa: E402


def with_masses_and_force(text: str, coupler_mass: float, rocker_inertia: float, force: tuple[float, float]) -> str:
    """The four-bar's text with the coupler's mass, the rocker's J_S and a force at E replaced, and
    the coupler's centre of mass S2 in the middle of its AB."""
    ab = float(text.split("length = ")[2].split()[0])
    for old, new in (("mass = 3.0\n", f"mass = {coupler_mass!r}\n"),
                     ("inertia = 0.0104167\n", f"inertia = {rocker_inertia!r}\n"),
                     ('points.S2 = { from = "A", distance = 0.15 }',
                      f'points.S2 = {{ from = "A", distance = {ab / 2!r} }}')):
        assert old in text
        text = text.replace(old, new)
    return text + f'\n[[loads.forces]]\npoint = "E"\nlink = "2"\nforce = [{force[0]!r}, {force[1]!r}]\n'


def test_each_variant_equals_its_own_scheme_solved_alone():
    rng = np.random.default_rng(5)
    count = 4
    dims = np.array([0.1, 0.3, 0.25, 0.3]) * (1 + 0.1 * (rng.random((count, 4)) - 0.5))
    coupler_mass = rng.uniform(1.0, 5.0, count)
    rocker_inertia = rng.uniform(0.005, 0.02, count)
    force = rng.normal(scale=50.0, size=(count, 2))
    omega = rng.uniform(5.0, 20.0, count)
    geometry = four_bar_geometry(dims)
    geometry["2"]["S2"] = np.column_stack([dims[:, 1] / 2, np.zeros(count)])    # com = "S2" follows it
    batch = analyze_variants(linkage.load("four_bar"), PHI, geometry)
    got = variant_reactions(batch, omega=omega, eps=2.0, mass={"2": coupler_mass}, inertia={"3": rocker_inertia},
                            forces={"2": {"E": force}})
    assert got.balancing_moment.shape == (count, len(PHI))
    for v in range(count):
        text = with_masses_and_force(four_bar_text(*map(float, dims[v])), float(coupler_mass[v]),
                                     float(rocker_inertia[v]), tuple(map(float, force[v])))
        alone = solve_reactions(linkage.analyze(linkage.loads(text), PHI, omega=float(omega[v]), eps=2.0))
        scale = np.max(np.abs(alone.balancing_moment))
        np.testing.assert_allclose(got.balancing_moment[v], alone.balancing_moment, rtol=0, atol=1e-12 * scale)
        for pair in ("O", "A", "B", "C"):
            np.testing.assert_allclose(got.force(pair)[v], alone.force(pair), rtol=0,
                                       atol=1e-12 * np.max(np.abs(alone.force(pair))))
    assert np.all(got.virtual_power_residual() <= 1e-9)


def test_slider_crank_balancing_moment_equals_virtual_work_in_closed_form():
    """No masses, no gravity, a force P(phi) along the guide on the slider: M_b = -P x_B'(phi) with
    x_B = r cos(phi) + sqrt(l^2 - (r sin(phi) - e)^2) (offset e of the guide)."""
    mech = linkage.load("slider_crank")
    cranks, rods, e = np.array([0.0742, 0.06, 0.09]), np.array([0.2225, 0.25, 0.2]), 0.01335
    zero = np.zeros(3)
    geometry = {"1": {"A": np.column_stack([cranks, zero])}, "2": {"B": np.column_stack([rods, zero])}}
    phi = np.radians(np.arange(5.0, 360.0, 10.0))
    batch = analyze_variants(mech, phi, geometry)
    P = -1000.0 * (1 + np.cos(phi))[None, :] * np.array([1.0, 2.0, 3.0])[:, None]     # (V, n), N along x
    force = np.stack([P, np.zeros_like(P)], axis=-1)
    got = variant_reactions(batch, mass={k: 0.0 for k in ("1", "2", "3")}, inertia={"2": 0.0},
                            gravity=[0.0, 0.0], forces={"3": {"B": force}})
    r, rod = cranks[:, None], rods[:, None]
    h = r * np.sin(phi) - e
    dx = -r * np.sin(phi) - h * r * np.cos(phi) / np.sqrt(rod**2 - h**2)
    np.testing.assert_allclose(got.balancing_moment, -P * dx, rtol=1e-12, atol=1e-12 * np.max(np.abs(P * dx)))
    assert "static analysis" in got.flat.notes[-1]
    # the slider's guide carries the rod's force normal to it: R[0, 3] balances the rod on the slider
    rod = got.force("B")                         # R[2, 3]: force of the slider on the rod
    np.testing.assert_allclose(got.force("slide")[..., 1], -rod[..., 1], rtol=1e-12, atol=1e-9)


def test_positions_that_are_not_ok_give_nan_and_the_others_balance():
    dims = np.array([[0.1, 0.3, 0.25, 0.3], [0.4, 0.3, 0.25, 0.3]])   # the second cannot assemble everywhere
    batch = analyze_variants(linkage.load("four_bar"), PHI, four_bar_geometry(dims))
    got = variant_reactions(batch, omega=[10.0, 12.0])
    bad = batch.status != 0
    assert bad.any() and np.all(np.isnan(got.balancing_moment[bad])) and np.all(np.isnan(got.force("B")[bad]))
    assert np.all(np.isfinite(got.balancing_moment[~bad]))
    assert np.all(got.virtual_power_residual()[~bad] <= 1e-9)


@pytest.mark.parametrize("kwargs, message", [
    ({"mass": {"9": [1.0, 2.0]}}, "no moving link(s) ['9']"),
    ({"mass": {"2": [1.0, 2.0, 3.0]}}, "mass['2']: expected shape () (one value), (2,) (per variant)"),
    ({"mass": {"2": [-1.0, 2.0]}}, "must be nonnegative"),
    ({"omega": np.ones((2, 5))}, "omega: expected shape"),
    ({"forces": {"2": {"Q": [1.0, 0.0]}}}, "link '2' has no point 'Q'"),
    ({"forces": {"2": {"E": [[1.0, 0.0]]}}}, "forces['2']['E']: expected shape (2,)"),
    ({"eps": np.nan}, "eps must be finite"),
])
def test_bad_loads_are_refused_with_the_entry_named(kwargs, message):
    dims = np.array([[0.1, 0.3, 0.25, 0.3], [0.11, 0.3, 0.25, 0.3]])
    batch = analyze_variants(linkage.load("four_bar"), PHI, four_bar_geometry(dims))
    with pytest.raises(InputError) as err:
        variant_reactions(batch, **kwargs)
    assert message in str(err.value)


def test_declared_external_loads_must_be_given_as_arrays_and_order_two_is_needed():
    mech = linkage.load("course_slider_crank")
    geometry = {"1": {"A": [[0.0742, 0.0], [0.07, 0.0]]}}
    batch = analyze_variants(mech, PHI, geometry)
    with pytest.raises(InputError, match=r"declares external loads \(force at 'B'\)"):
        variant_reactions(batch, omega=10.0)
    free = variant_reactions(batch, omega=10.0, forces={})     # explicitly none
    assert np.all(np.isfinite(free.balancing_moment[batch.status == 0]))
    with pytest.raises(InputError, match="order=2"):
        variant_reactions(analyze_variants(mech, PHI, geometry, order=1), omega=10.0, forces={})
    assert (SCHEMES / "course_slider_crank.toml").exists()
