"""Scale-free numerics (issue 7, Build 3): a consistently scaled machine gives exactly scaled results.

The oracle is dimensional analysis, not the library's output. Scale every length of the
flying shears by ``k``, every mass by ``m`` and every force by ``f``. Newton's law ``F = m a``
then fixes the time scale: ``a ~ k / tau^2`` so ``tau^2 = m k / f`` and every speed scales by
``w_s = 1 / tau = sqrt(f / (m k))``. Each input scales by its dimension:

======================================  =========================  ===================
quantity                                unit                       factor
======================================  =========================  ===================
point coordinates, centres of mass      m                          k
mass                                    kg                         m
moment of inertia (links, rotors)       kg m^2                     m k^2
force (diagram values)                  N                          f
gravity                                 m / s^2                    k w_s^2 = f / m
angular speed (mean, initial, motor)    rad / s (and rpm)          w_s
motor moment                            N m                        f k
motor power                             W = N m / s                f k w_s
delta, positions, gear ratio, eta, ...  1                          1
======================================  =========================  ===================

and so must every result (``w_s^2 = f / (m k)`` makes kinetic energy ``m k^2 w_s^2 = f k``
scale as work, which is what keeps the energy equation consistent):

- reduced moment, driving moment, balancing moment: N m -> ``f k``;
- reduced inertia and its derivative, required / constant / flywheel inertia: ``m k^2``;
- omega: ``w_s``; eps: ``w_s^2``; time and period: ``1 / w_s``; kinetic energy: ``f k``;
- angles, delta, the coefficient of dynamics, relative differences: 1.

The factors are powers of ten, which are not exact in binary, so even an ideal computation
differs by rounding: a few 1e-16 per operation. Tolerances, and why:

- course method: plain arithmetic on the table (the start angle comes from a root of ``q' = 0``
  found to ~1e-14 rad) -> 1e-12;
- exact method: Brent's method to 1e-14 relative on ``T_0`` and on the inertia; the computed
  delta carries ~1e-16 of rounding, i.e. ~1e-16 / delta = 1.3e-15 of the inertia at delta = 0.08
  -> 1e-9 (what the issue asks for; measured at most 1.2e-14, course and exact alike);
- ODE (steady state by shooting, start-up transient): RK45 controls the local error per step
  to ``rtol``, relative to the problem's own scales; the global error over a cycle of ~270
  steps with a piecewise-linear reduced moment is larger and erratic: measured against runs at
  rtol = 1e-13, omega is off by 80 rtol at rtol = 1e-9 (up to 1300 rtol at other rtol) and the
  transient's kinetic energy by 250 rtol. Two scaled runs are two such solutions (rounding of the scaled
  inputs flips some step decisions, so their steps differ), hence 3e3 rtol for speeds, time and
  energy, and 1 / S times that for moments, which the motor's characteristic makes from the
  speed through the slip S at the operating speed (dM / M = (dw / w) / S; S = 0.016, 1 / S = 64).

Before the fix (absolute ``xtol`` and bracket of the exact method's root finding, in kg m^2),
these tests failed: the exact method's required inertia had a relative error of 123 at
k = 1e-8 (m k^2 = 1e-16 kg m^2), 1.2e10 at k = m = 1e-8, and 22 whenever the declared inertia
exceeded the needed one 1e14 times; masses alone x 1e-8 gave 1.2e-10 and x 1e-14 gave 0.24. The
ODE's time tolerance was 1e-10 s whatever the period.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import linkage
from linkage.dynamics import exact_method, run_dynamics, simulate, steady_state
from linkage.dynamics.motors import RPM
from linkage.model.scheme import from_dict, to_dict

# (k, m, f): lengths, masses, forces. Single factors from 1e-8 to 1e8 with the others 1, and
# mixed corners where the speeds scale by up to 1e+-12.
SCALES = [
    (1e-8, 1.0, 1.0), (1e-4, 1.0, 1.0), (1e4, 1.0, 1.0), (1e8, 1.0, 1.0),
    (1.0, 1e-8, 1.0), (1.0, 1e-4, 1.0), (1.0, 1e4, 1.0), (1.0, 1e8, 1.0),
    (1e-8, 1e8, 1e-4), (1e8, 1e-8, 1e4), (1e8, 1e8, 1e-8), (1e-8, 1e-8, 1e8),
]
ODE_SCALES = [(1.0, 1e-8, 1.0), (1e8, 1e8, 1e-8), (1e-8, 1e-8, 1e8)]

COURSE_TOL, EXACT_TOL = 1e-12, 1e-9
STEADY_RTOL = SIMULATE_RTOL = 1e-9
ODE_ACCURACY = 3e3  # two solutions' difference / rtol (see the module docstring)
I_FLYWHEEL = 2.0  # kg m^2 at the crank in the ODE runs (scaled as m k^2)


def ids(scale):
    return "k={:g},m={:g},f={:g}".format(*scale)


def speed_factor(k, m, f):
    """``w_s = sqrt(f / (m k))`` (tau^2 = m k / f from F = m a)."""
    return math.sqrt(f / (m * k))


def scaled(data: dict, k: float, m: float, f: float) -> dict:
    """The scheme ``data`` (from ``to_dict``) with every dimensional input scaled."""
    ws = speed_factor(k, m, f)
    out = {key: value for key, value in data.items()}
    out["links"] = {}
    for name, link in data["links"].items():
        new = dict(link)
        new["points"] = {p: [k * c for c in xy] for p, xy in link["points"].items()}
        if "guides" in link:
            new["guides"] = {g: {**gd, "through": [k * c for c in gd["through"]]} for g, gd in link["guides"].items()}
        new["com"] = [k * c for c in link["com"]]
        if "mass" in link:
            new["mass"] = m * link["mass"]
        new["inertia"] = m * k * k * link["inertia"]
        out["links"][name] = new
    loads = dict(data["loads"])
    loads["gravity"] = [g * f / m for g in loads["gravity"]]  # k w_s^2 = f / m
    forces = []
    for spec in loads.get("forces", []):
        spec = dict(spec)
        if "force" in spec:
            spec["force"] = [f * x for x in spec["force"]]
        if "diagram" in spec:
            spec["diagram"] = {**spec["diagram"], "values": [f * x for x in spec["diagram"]["values"]]}
        if "cycle" in spec:
            spec["cycle"] = [f * x for x in spec["cycle"]]
        forces.append(spec)
    loads["forces"] = forces
    assert not loads.get("moments"), "scale link moments by f k here"
    out["loads"] = loads
    dyn = dict(data["dynamics"])
    for key in ("mean_rpm", "mean_speed", "initial_rpm", "initial_speed"):
        if key in dyn:
            dyn[key] = ws * dyn[key]
    for key in ("inertia_0", "flywheel"):
        if key in dyn:
            dyn[key] = m * k * k * dyn[key]
    dyn["rotors"] = [{**r, "inertia": m * k * k * r["inertia"]} for r in dyn.get("rotors", [])]
    motor = dict(dyn["motor"])
    assert motor["kind"] == "induction"
    for key in ("synchronous_rpm", "rated_rpm"):
        motor[key] = ws * motor[key]
    if "rated_power" in motor:
        motor["rated_power"] = f * k * ws * motor["rated_power"]
    if "rated_moment" in motor:
        motor["rated_moment"] = f * k * motor["rated_moment"]
    dyn["motor"] = motor
    out["dynamics"] = dyn
    return out


@pytest.fixture(scope="module")
def base_data():
    return to_dict(linkage.load("flying_shears"))


@pytest.fixture(scope="module")
def reference(base_data):
    mech = from_dict(base_data)
    return {"mech": mech, "report": run_dynamics(mech), "exact": exact_method(mech, samples=720)}


def assert_scaled(actual, expected, factor, tol, what):
    actual = np.asarray(actual, float)
    expected = np.asarray(expected, float) * factor
    scale = np.max(np.abs(expected))
    assert scale > 0, what
    err = np.max(np.abs(actual - expected)) / scale
    assert err <= tol, f"{what}: relative error {err:.3g} > {tol:g}"


def test_the_scaler_scales_what_dimensional_analysis_says(base_data):
    """The helper itself, on a few inputs read back from the built mechanism (k = 2, m = 3, f = 5)."""
    k, m, f = 2.0, 3.0, 5.0
    mech = from_dict(scaled(base_data, k, m, f))
    ref = from_dict(base_data)
    assert mech.links["2"].mass == pytest.approx(3.0 * ref.links["2"].mass, rel=1e-15)
    assert mech.links["2"].inertia == pytest.approx(12.0 * ref.links["2"].inertia, rel=1e-15)
    assert mech.size == pytest.approx(2.0 * ref.size, rel=1e-15)
    ws = math.sqrt(5.0 / 6.0)
    spec, spec0 = linkage.dynamics.dynamics_of(mech), linkage.dynamics.dynamics_of(ref)
    assert spec.mean_speed == pytest.approx(ws * spec0.mean_speed, rel=1e-15)
    assert spec.constant_inertia == pytest.approx(12.0 * spec0.constant_inertia, rel=1e-15)


@pytest.mark.parametrize("scale", SCALES, ids=ids)
def test_course_and_exact_methods_scale_exactly(base_data, reference, scale):
    k, m, f = scale
    ws = speed_factor(k, m, f)
    mech = from_dict(scaled(base_data, k, m, f))
    report = run_dynamics(mech)  # course method, the exact method beside it, reactions
    ref = reference["report"]
    law, law0 = report.law, ref.law
    moment, inertia = f * k, m * k * k
    np.testing.assert_allclose(law.phi, law0.phi, rtol=0, atol=1e-12)
    assert_scaled(law.reduced.moment, law0.reduced.moment, moment, COURSE_TOL, "reduced moment")
    assert_scaled(law.reduced.inertia, law0.reduced.inertia, inertia, COURSE_TOL, "reduced inertia")
    assert_scaled(law.reduced.inertia_derivative, law0.reduced.inertia_derivative, inertia, COURSE_TOL, "dI/dpsi")
    assert_scaled(law.driving_moment, law0.driving_moment, moment, COURSE_TOL, "driving moment")
    assert_scaled(law.required_constant_inertia, law0.required_constant_inertia, inertia, COURSE_TOL, "I'")
    assert_scaled(law.flywheel_inertia, law0.flywheel_inertia, inertia, COURSE_TOL, "flywheel")
    assert_scaled(law.delta_actual, law0.delta_actual, 1.0, COURSE_TOL, "delta")
    assert_scaled(law.omega, law0.omega, ws, COURSE_TOL, "omega")
    assert_scaled(law.eps, law0.eps, ws * ws, COURSE_TOL, "eps")
    assert_scaled(report.balancing_moment, ref.balancing_moment, moment, COURSE_TOL, "M_b")
    assert_scaled(report.dynamic_coefficient, ref.dynamic_coefficient, 1.0, COURSE_TOL, "k_dyn")
    # the exact method (run beside the course method by run_dynamics)
    cmp, cmp0 = report.comparison, ref.comparison
    assert_scaled(cmp["exact_required_constant_inertia"], cmp0["exact_required_constant_inertia"], inertia,
                  EXACT_TOL, "exact I")
    assert_scaled(cmp["course_delta_exact"], cmp0["course_delta_exact"], 1.0, EXACT_TOL, "course delta, exactly")


@pytest.mark.parametrize("scale", SCALES, ids=ids)
def test_exact_law_of_motion_scales_exactly(base_data, reference, scale):
    k, m, f = scale
    ws = speed_factor(k, m, f)
    law = exact_method(from_dict(scaled(base_data, k, m, f)), samples=720)
    law0 = reference["exact"]
    assert_scaled(law.required_constant_inertia, law0.required_constant_inertia, m * k * k, EXACT_TOL, "I")
    assert_scaled(law.flywheel_inertia, law0.flywheel_inertia, m * k * k, EXACT_TOL, "flywheel")
    assert_scaled(law.delta_actual, law0.delta_actual, 1.0, EXACT_TOL, "delta")
    assert_scaled(law.omega, law0.omega, ws, EXACT_TOL, "omega")
    assert_scaled(law.eps, law0.eps, ws * ws, EXACT_TOL, "eps")
    # the inertia that delta needs does not depend on the declared one: with a rotor 1e14 times
    # larger than the machine's inertia it is still found to the same tolerance (no flywheel)
    data = scaled(base_data, k, m, f)
    data["dynamics"]["rotors"] = [{"inertia": 1e14 * m * k * k, "ratio": 1.0}]
    heavy = exact_method(from_dict(data), samples=720)
    assert heavy.flywheel_inertia is None
    assert_scaled(heavy.required_constant_inertia, law0.required_constant_inertia, m * k * k, EXACT_TOL,
                  "I with a large declared I_0")


@pytest.fixture(scope="module")
def ode_reference(base_data):
    mech = from_dict(base_data)
    return (steady_state(mech, constant_inertia=I_FLYWHEEL, samples=360, rtol=STEADY_RTOL),
            simulate(mech, constant_inertia=I_FLYWHEEL, cycles=2, samples=360, rtol=SIMULATE_RTOL))


@pytest.mark.parametrize("scale", ODE_SCALES, ids=ids)
def test_ode_steady_state_and_transient_scale_to_their_accuracy(base_data, ode_reference, scale):
    k, m, f = scale
    ws = speed_factor(k, m, f)
    mech = from_dict(scaled(base_data, k, m, f))
    law0, tr0 = ode_reference
    law = steady_state(mech, constant_inertia=I_FLYWHEEL * m * k * k, samples=360, rtol=STEADY_RTOL)
    tol = ODE_ACCURACY * STEADY_RTOL
    assert_scaled(law.omega, law0.omega, ws, tol, "omega")
    assert_scaled(law.details["period"], law0.details["period"], 1 / ws, tol, "period")
    assert abs(law.delta_actual - law0.delta_actual) <= 2 * tol  # (w_max - w_min) / w_m
    motor = linkage.dynamics.dynamics_of(from_dict(base_data)).motor
    slip = 1 - np.mean(np.abs(law0.omega)) * motor.ratio / RPM / motor.synchronous_rpm  # operating slip
    assert 0 < slip < 0.05
    moment_tol = tol / slip  # through the motor: dM / M = (dw / w) / S
    assert_scaled(law.driving_moment, law0.driving_moment, f * k, moment_tol, "mean driving moment")
    assert_scaled(law.eps, law0.eps, ws * ws, moment_tol, "eps")
    # the start-up transient: kinetic energy and time at fixed angles (the dense solution)
    tr = simulate(mech, constant_inertia=I_FLYWHEEL * m * k * k, cycles=2, samples=360, rtol=SIMULATE_RTOL)
    psi = np.linspace(0.0, 4 * np.pi, 49)
    state0, state = tr0.sol(psi), tr.sol(psi)
    tol = ODE_ACCURACY * SIMULATE_RTOL
    assert_scaled(state[0], state0[0], f * k, tol, "kinetic energy")
    assert_scaled(state[1], state0[1], 1 / ws, tol, "time")
