"""Machine dynamics (docs/methods.md) against oracles written independently in this file.

Every expected number is derived here: closed-form slider-crank kinematics (docs/methods.md#checks),
finite differences of positions, the course formulas re-evaluated step by step, our own trapezoid
and Simpson quadratures, the virtual-power balance and conservation of energy. No value is copied
from the library's output.

1. Reduced characteristics: ``M_red = s sum(F . r'_P)`` against the closed form ``s F x_B'`` and
   against the static balancing moment (``M_red = -s M_b``); ``I''`` against
   ``m2 |S2'|^2 + J2 i21^2 + m3 x_B'^2``; ``dI/dpsi`` against central differences of ``I``.
2. The course method on ``course_slider_crank`` recomputed from the course formulas.
3. Mertsalov's method and the exact energy solution agree as ``delta -> 0`` (linearly).
4. Cycle energy balance of the exact method; its kinetic energy, mean speed, delta and eps.
5. Free motion (no loads, zero motor moment): ``I(psi) omega^2 / 2`` is conserved.
6. The ODE steady state under the balancing constant moment equals the exact energy solution.
7. Clockwise and counter-clockwise rotation under reversible loads give mirrored results.
8. Motor-driven machines: periodic steady state, mean driving moment = mean resistance, stall is
   a DynamicsError (never a hang), a start-up transient approaches the steady state.
9. The virtual-power balance under the real law of motion, and ``M_b = s M_d - I_c eps``.
10. The summary (JSON keys of ``linkage dynamics``).

Convention (docs/methods.md#reduced-moment-and-moment-of-inertia): ``s = sign(omega_m)``, ``psi = s phi``; reduced moments are
positive when they drive; ``w = |omega|``.
"""

from __future__ import annotations

import contextlib
import copy
import json
import math
import signal
import time
from dataclasses import replace

import numpy as np
import pytest

import linkage
from linkage.dynamics import (DynamicsSpec, course_method, dynamics_of, exact_method, run_dynamics, simulate,
                              steady_state)
from linkage.errors import DynamicsError
from linkage.kinetostatics.loads import Loads, PointForce
from linkage.kinetostatics.reactions import solve_reactions, virtual_power_residual
from linkage.dynamics.motors import RPM, ConstantMotor, InductionMotor, LinearMotor
from linkage.dynamics.reduced import reduced_characteristics
from linkage.model.scheme import from_dict, to_dict

from _texts import slider_crank_toml

G = 9.81

# the course press (schemes/course_slider_crank.toml): the spec, not the library's output
L1, L2, LS2, E = 0.0742, 0.2225, 0.0741, 0.01335  # crank, rod, A-S2, guide offset (m)
M1, M2, J2, M3 = 30.0, 400.0, 8.35, 500.0           # crank at O (no own J), rod, slider
I0_DECLARED = 90.264                                # kg m^2, rotor and gears at the crank
OMEGA_M, DELTA, N_POS = -10.472, 0.0556, 12
CYCLE_FORCE = np.array([0, 0, 0, 0, 0, 0, 0, 0, 0, 0, -12321, -27142, -125000], float)
PHI0 = math.asin(E / (L1 + L2))                     # far extreme position of the slider


# ----------------------------------------------------------------------------------------------
# helpers (independent of the library)
# ----------------------------------------------------------------------------------------------


def slider_crank_closed(phi):
    """Closed-form analogs of the offset slider-crank (docs/methods.md#checks).

    Returns ``i21``, ``x_B'``, ``S2'`` (N, 2) and ``I''`` = m2 |S2'|^2 + J2 i21^2 + m3 x_B'^2."""
    phi = np.asarray(phi, float)
    sin2 = (E - L1 * np.sin(phi)) / L2          # B stays on the line y = E, right of O
    cos2 = np.sqrt(1 - sin2**2)
    i21 = -L1 * np.cos(phi) / (L2 * cos2)
    xb1 = -L1 * np.sin(phi) - L2 * sin2 * i21
    s2 = np.stack([-L1 * np.sin(phi) - LS2 * sin2 * i21, L1 * np.cos(phi) + LS2 * cos2 * i21], axis=-1)
    inertia = M2 * np.sum(s2**2, axis=-1) + J2 * i21**2 + M3 * xb1**2
    return i21, xb1, s2, inertia


def press_moment(phi, force_x, s):
    """``M_red = s (F_x x_B' + sum m g . r'_S)`` of the press: the crank's centre is at O, the
    slider moves horizontally, so only the rod's weight has a reduced moment."""
    _, xb1, s2, _ = slider_crank_closed(phi)
    return s * (force_x * xb1 - M2 * G * s2[:, 1])


def simpson(f, x):
    """Composite Simpson on an even number of equal intervals."""
    f, x = np.asarray(f, float), np.asarray(x, float)
    n = len(x) - 1
    assert n % 2 == 0
    h = (x[-1] - x[0]) / n
    return h / 3 * (f[0] + f[-1] + 4 * np.sum(f[1:-1:2]) + 2 * np.sum(f[2:-1:2]))


def trapezoid_cumulative(f, step):
    f = np.asarray(f, float)
    return np.concatenate([[0.0], np.cumsum((f[1:] + f[:-1]) / 2 * step)])


def modified(name, **sections):
    """A shipped scheme with some top-level sections replaced (a deep copy: never the original)."""
    data = copy.deepcopy(to_dict(linkage.load(name)))
    for key, value in sections.items():
        if value is None:
            data.pop(key, None)
        else:
            data[key] = value
    return from_dict(data)


def press_fine(n_per_step=100, s=-1, extra_inertia=0.0):
    """Reduced characteristics of the press on a fine cycle grid aligned with the 12 positions
    (kinks of the piecewise-linear cycle table fall on grid nodes)."""
    mech = linkage.load("course_slider_crank")
    n = N_POS * n_per_step
    psi = np.linspace(0.0, 2 * np.pi, n + 1)
    ends = np.zeros(n + 1, bool)
    ends[-1] = True
    red = reduced_characteristics(mech, PHI0 + s * psi, s, ends=ends, extra_inertia=extra_inertia)
    return psi, red


@contextlib.contextmanager
def deadline(seconds):
    """Fail (instead of hanging) when the body runs longer than ``seconds``."""
    def handler(signum, frame):
        raise TimeoutError(f"still running after {seconds} s: a hang")

    old = signal.signal(signal.SIGALRM, handler)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, old)


def rel(actual, expected):
    actual, expected = np.asarray(actual, float), np.asarray(expected, float)
    return float(np.max(np.abs(actual - expected)) / max(float(np.max(np.abs(expected))), 1e-300))


@pytest.fixture(scope="module")
def press():
    return linkage.load("course_slider_crank")


@pytest.fixture(scope="module")
def press_md():
    """The balancing constant driving moment of the press: own Simpson on a fine grid."""
    psi, red = press_fine(100)
    return -simpson(red.moment, psi) / (2 * np.pi)


# ----------------------------------------------------------------------------------------------
# 1. reduced characteristics
# ----------------------------------------------------------------------------------------------

PHI_ANY = np.linspace(0.0, 2 * np.pi, 37)[:-1] + 0.0123  # nothing special about these


@pytest.mark.parametrize("s", [1, -1])
def test_reduced_moment_of_a_horizontal_force_is_s_F_xB_prime(press, s):
    force = -1000.0
    loads = Loads(gravity=(0.0, 0.0), forces=(PointForce("B", "3", (force, 0.0)),))
    red = reduced_characteristics(press, PHI_ANY, s, loads=loads)
    _, xb1, _, _ = slider_crank_closed(PHI_ANY)
    assert rel(red.moment, s * force * xb1) < 1e-12
    assert np.all(red.moment_driving == 0.0)  # a constant force is not declared as driving
    # with gravity too: the rod's weight is the only other term
    red = reduced_characteristics(press, PHI_ANY, s, loads=Loads(forces=loads.forces))
    assert rel(red.moment, press_moment(PHI_ANY, force, s)) < 1e-12


@pytest.mark.parametrize("s", [1, -1])
def test_reduced_moment_is_minus_s_times_static_balancing_moment(press, s):
    """Equality of powers: M_b omega + sum F . v = 0 with no inertia, so sum F . r' = -M_b and
    M_red = s sum F . r' = -s M_b (= -M_b for omega_m > 0). The press's own cycle-table force and
    gravity, at the table positions (with the cycle's end) and at arbitrary angles."""
    table = PHI0 - np.arange(N_POS + 1) * 2 * np.pi / N_POS
    for phi in (table, PHI_ANY):
        ends = np.zeros(len(phi), bool)
        if phi is table:
            ends[-1] = True
        red = reduced_characteristics(press, phi, s, ends=ends)
        mb = solve_reactions(linkage.analyze(press, phi, order=2, omega=None), ends=ends).balancing_moment
        assert rel(red.moment, -s * mb) < 1e-12


@pytest.mark.parametrize("s", [1, -1])
def test_reduced_inertia_matches_closed_form_and_its_derivative_finite_differences(press, s):
    red = reduced_characteristics(press, PHI_ANY, s, extra_inertia=I0_DECLARED)
    *_, closed = slider_crank_closed(PHI_ANY)
    assert rel(red.inertia_variable, closed) < 1e-12
    # the crank's centre of mass is on its pivot and it declares no J: I_0 is the declared one
    assert red.inertia_constant == pytest.approx(I0_DECLARED, rel=1e-15)
    # dI/dpsi = s dI/dphi, against 4th-order central differences of the closed form
    h = 1e-3
    f = [slider_crank_closed(PHI_ANY + k * h)[3] for k in (-2, -1, 1, 2)]
    didphi = (f[0] - 8 * f[1] + 8 * f[2] - f[3]) / (12 * h)
    assert rel(red.inertia_derivative, s * didphi) < 1e-8
    # and against central differences of the library's own I(phi)
    hp = 1e-5
    up = reduced_characteristics(press, PHI_ANY + hp, s).inertia
    down = reduced_characteristics(press, PHI_ANY - hp, s).inertia
    assert rel(red.inertia_derivative, s * (up - down) / (2 * hp)) < 1e-7


# ----------------------------------------------------------------------------------------------
# 2. the course method (course_slider_crank)
# ----------------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def course(press):
    return course_method(press)


def test_course_positions_start_at_far_extreme_and_go_clockwise(course):
    assert math.degrees(PHI0) == pytest.approx(2.579, abs=5e-4)
    expected = PHI0 - np.arange(N_POS + 1) * math.radians(30.0)
    assert np.max(np.abs(course.phi - expected)) < 1e-12
    assert course.reduced.rotation == -1
    # the far extreme: x_B' = 0 there, x_B is at its maximum l1 cos + sqrt(...) = (l1 + l2) cos
    _, xb1, _, _ = slider_crank_closed([PHI0])
    assert abs(xb1[0]) < 1e-14


def test_course_reduced_characteristics_match_the_closed_form(course):
    assert rel(course.reduced.moment, press_moment(course.phi, CYCLE_FORCE, -1)) < 1e-12
    assert rel(course.reduced.inertia_variable, slider_crank_closed(course.phi)[3]) < 1e-12


def test_course_method_recomputed(course):
    s, wm, step = -1, abs(OMEGA_M), 2 * np.pi / N_POS
    moment = course.reduced.moment
    psi = np.arange(N_POS + 1) * step
    work = trapezoid_cumulative(moment, step)               # A_c, own trapezoid
    md = -work[-1] / (2 * np.pi)
    assert course.driving_moment == pytest.approx(md, rel=1e-12)
    # the same from the closed-form moments (nothing taken from the library)
    md_closed = -trapezoid_cumulative(press_moment(course.phi, CYCLE_FORCE, s), step)[-1] / (2 * np.pi)
    assert course.driving_moment == pytest.approx(md_closed, rel=1e-11)
    assert md > 0

    energy = md * psi + work                                # Delta T
    links = slider_crank_closed(course.phi)[3] * wm**2 / 2  # T''
    dtp = energy - links                                    # Delta T'
    swing = dtp.max() - dtp.min()
    required = swing / (DELTA * wm**2)                      # I'
    assert course.required_constant_inertia == pytest.approx(required, rel=1e-12)
    assert course.flywheel_inertia == pytest.approx(required - I0_DECLARED, rel=1e-10)
    assert course.flywheel_inertia > 0
    assert course.delta_actual == pytest.approx(DELTA, rel=1e-15)

    # law of motion by the course formulas
    tm = required * wm**2 / 2
    ti = tm + dtp - (dtp.max() + dtp.min()) / 2
    omega = s * np.sqrt(2 * ti / required)
    assert rel(course.omega, omega) < 1e-12
    assert np.all(course.omega < 0)
    assert course.omega[0] == pytest.approx(course.omega[-1], rel=1e-12)  # cycle closes
    # Mertsalov's approximation reproduces the target delta to first order
    w = np.abs(omega)
    assert (w.max() - w.min()) / wm == pytest.approx(DELTA, rel=1e-2)
    assert (w.max() + w.min()) / 2 == pytest.approx(wm, rel=1e-2)

    # eps = s (M_d + M_red - dI/dpsi w^2 / 2) / I with I = I' + I''
    inertia = required + slider_crank_closed(course.phi)[3]
    h = 1e-3
    f = [slider_crank_closed(course.phi + k * h)[3] for k in (-2, -1, 1, 2)]
    di_dpsi = s * (f[0] - 8 * f[1] + 8 * f[2] - f[3]) / (12 * h)
    eps = s * (md + moment - 0.5 * di_dpsi * w**2) / inertia
    assert rel(course.eps, eps) < 1e-7

    # the constant inertia in use is I' (a flywheel is needed); the declared machine keeps I_0
    assert course.constant_inertia == pytest.approx(required, rel=1e-12)
    assert course.reduced.inertia_constant == pytest.approx(I0_DECLARED, rel=1e-12)


# ----------------------------------------------------------------------------------------------
# 3. Mertsalov vs the exact energy solution as delta -> 0
# ----------------------------------------------------------------------------------------------


def test_mertsalov_converges_to_exact_linearly_in_delta(press):
    diffs, speed_diffs = [], []
    for delta in (0.05, 0.005, 0.0005):
        c = course_method(press, delta=delta)
        e = exact_method(press, delta=delta, samples=N_POS)  # same 12-point trapezoid
        assert e.driving_moment == pytest.approx(c.driving_moment, rel=1e-12)
        assert np.max(np.abs(e.phi - c.phi)) < 1e-12
        diffs.append(abs(c.required_constant_inertia / e.required_constant_inertia - 1))
        speed_diffs.append(rel(c.omega, e.omega))
    assert diffs[0] > diffs[1] > diffs[2]
    assert diffs[2] < 1e-3
    for a, b in zip(diffs, diffs[1:]):  # ~linear: a tenth of delta, a tenth of the difference
        assert 7 < a / b < 13
    assert speed_diffs[0] > speed_diffs[1] > speed_diffs[2]


def test_exact_method_satisfies_its_definition_on_its_grid(press):
    """positions = samples: the table is the grid; T = I w^2 / 2 changes by the trapezoid work of
    M_d + M_red, (w_max + w_min) / 2 = |omega_m| and (w_max - w_min) / |omega_m| = delta."""
    n = 360
    law = exact_method(press, positions=n, samples=n)
    assert len(law.phi) == n + 1
    w = np.abs(law.omega)
    wm = abs(OMEGA_M)
    assert (w.max() + w.min()) / 2 == pytest.approx(wm, rel=1e-10)
    assert (w.max() - w.min()) / wm == pytest.approx(DELTA, rel=1e-8)
    assert law.delta_actual == pytest.approx(DELTA, rel=1e-8)
    red = law.reduced
    step = 2 * np.pi / n
    md = -trapezoid_cumulative(red.moment, step)[-1] / (2 * np.pi)
    assert law.driving_moment == pytest.approx(md, rel=1e-12)
    energy = (law.constant_inertia + red.inertia_variable) * w**2 / 2
    change = trapezoid_cumulative(md + red.moment, step)
    assert rel(energy - energy[0], change) < 1e-9
    assert law.constant_inertia == pytest.approx(law.required_constant_inertia, rel=1e-15)
    assert red.inertia_constant == pytest.approx(I0_DECLARED, rel=1e-15)
    assert law.flywheel_inertia == pytest.approx(law.required_constant_inertia - I0_DECLARED, rel=1e-12)


# ----------------------------------------------------------------------------------------------
# 4. cycle energy balance of the exact method
# ----------------------------------------------------------------------------------------------


def test_exact_method_cycle_energy_balance(press, press_md):
    law = exact_method(press)  # default fine grid
    psi, red = press_fine(100)
    # the constant driving moment balances the cycle: int (M_d + M_red) dpsi = 0
    residual = simpson(law.driving_moment + red.moment, psi)
    scale = simpson(np.abs(red.moment), psi)
    assert abs(residual) / scale < 1e-5
    assert law.driving_moment == pytest.approx(press_md, rel=1e-5)
    # the kinetic energy returns to its value after one revolution
    assert law.omega[0] == pytest.approx(law.omega[-1], rel=1e-12)
    # T at the 12 table positions follows the work of M_d + M_red (own Simpson per 30 deg step)
    k = 100
    seg = [simpson(law.driving_moment + red.moment[i * k:(i + 1) * k + 1], psi[i * k:(i + 1) * k + 1])
           for i in range(N_POS)]
    change = np.concatenate([[0.0], np.cumsum(seg)])
    energy = law.inertia * law.omega**2 / 2
    assert np.max(np.abs(energy - energy[0] - change)) / np.ptp(change) < 1e-4


def test_exact_method_eps_is_the_time_derivative_of_omega(press):
    """eps = d omega / dt = omega d omega / d phi, by central differences on a fine table; the
    positions next to the kinks of the cycle-table force (every 30 deg) are left out."""
    n = 720
    law = exact_method(press, positions=n, samples=n)
    w, h = law.omega, 2 * np.pi / n
    dw_dphi = (w[2:] - w[:-2]) / (2 * -h)  # phi decreases along the table (clockwise)
    eps_fd = w[1:-1] * dw_dphi
    i = np.arange(1, n)
    smooth = (i % (n // N_POS) > 1) & (i % (n // N_POS) < n // N_POS - 1)
    err = np.abs(eps_fd - law.eps[1:-1]) / np.max(np.abs(law.eps))
    assert np.max(err[smooth]) < 2e-3


# ----------------------------------------------------------------------------------------------
# 5. free motion conserves kinetic energy
# ----------------------------------------------------------------------------------------------


def four_bar_inertia_fd(phi, h=1e-5):
    """I'' of the four-bar from central differences of positions (no library analogs)."""
    mech = linkage.load("four_bar")
    m2, j2, m3, j3 = 3.0, 0.0225, 2.0, 0.0104167
    out = []
    for k in (-1, 1):
        mo = linkage.analyze(mech, phi + k * h, order=0)
        out.append((mo.point("S2"), mo.poses["2"][:, 2], mo.point("S3"), mo.poses["3"][:, 2]))
    d = [(b - a) / (2 * h) for a, b in zip(out[0], out[1])]
    return m2 * np.sum(d[0]**2, -1) + j2 * d[1]**2 + m3 * np.sum(d[2]**2, -1) + j3 * d[3]**2


@pytest.mark.parametrize("s", [1, -1])
def test_free_motion_conserves_kinetic_energy(s):
    mech = modified("four_bar", loads={"gravity": [0.0, 0.0]})
    i0, w0 = 0.01, 10.0
    spec = DynamicsSpec(mean_speed=s * w0, motor=ConstantMotor(0.0), initial_speed=w0, inertia_0=i0)
    cycles = 4
    tr = simulate(mech, spec, cycles=cycles)
    assert tr.psi[-1] == pytest.approx(2 * np.pi * cycles, rel=1e-12)
    assert np.all(np.sign(tr.omega) == s)
    phi0 = linkage.extreme_positions(mech, "3.theta").phi_max  # output start = "max"
    inertia = i0 + four_bar_inertia_fd(phi0 + s * tr.psi)   # the crank adds nothing (J = 0 at O)
    energy = inertia * tr.omega**2 / 2
    assert np.max(np.abs(energy / energy[0] - 1)) < 1e-8
    # the time of the cycles: t = int dpsi / w with w = sqrt(2 T0 / I(psi)), own Simpson
    grid = np.linspace(0, 2 * np.pi, 721)
    period = simpson(np.sqrt((i0 + four_bar_inertia_fd(phi0 + s * grid)) / (2 * energy[0])), grid)
    times = tr.sol(2 * np.pi * np.arange(1, cycles + 1))[1]
    assert rel(times, period * np.arange(1, cycles + 1)) < 1e-7


# ----------------------------------------------------------------------------------------------
# 6. ODE steady state with the balancing constant moment = exact energy solution
# ----------------------------------------------------------------------------------------------


def test_steady_state_with_constant_moment_equals_exact_solution(press):
    exact = exact_method(press, samples=720)
    ss = steady_state(press, constant_inertia=exact.required_constant_inertia, samples=720)
    assert np.max(np.abs(ss.phi - exact.phi)) < 1e-12
    assert rel(ss.omega, exact.omega) < 1e-5
    assert rel(ss.eps, exact.eps) < 1e-5
    assert ss.driving_moment == pytest.approx(exact.driving_moment, rel=1e-6)
    assert ss.required_constant_inertia == pytest.approx(exact.required_constant_inertia, rel=1e-15)
    assert ss.details["mean_speed"] == pytest.approx(OMEGA_M, rel=1e-4)


# ----------------------------------------------------------------------------------------------
# 7. clockwise vs counter-clockwise
# ----------------------------------------------------------------------------------------------


def test_reversal_mirrors_reduced_characteristics():
    """With loads that do not depend on the direction of motion (gravity): I'' depends on the
    position only (same function of phi); dI/dpsi = s dI/dphi flips sign; M_red = s sum F . r'
    flips sign."""
    mech = linkage.load("four_bar")
    ccw = reduced_characteristics(mech, PHI_ANY, 1)
    cw = reduced_characteristics(mech, PHI_ANY, -1)
    assert np.max(np.abs(ccw.moment)) > 1.0  # not trivially zero
    assert rel(cw.inertia_variable, ccw.inertia_variable) < 1e-15
    assert rel(cw.inertia_derivative, -ccw.inertia_derivative) < 1e-15
    assert rel(cw.moment, -ccw.moment) < 1e-15
    assert cw.inertia_constant == ccw.inertia_constant


@pytest.mark.parametrize("method", [course_method, exact_method])
def test_reversal_mirrors_the_law_of_motion(method):
    """Gravity alone is conservative: the cycle needs no driving moment (M_d = 0 both ways), the
    flywheel is the same, and the motion clockwise is the time reversal of the motion
    counter-clockwise: at the same phi, omega_cw = -omega_ccw and eps_cw = eps_ccw (eps is
    s (M_red - dI/dpsi w^2 / 2) / I and all three s, M_red, dI/dpsi flip). The clockwise table
    visits the counter-clockwise positions in reverse order."""
    dyn = {"delta": 0.05, "positions": 12, "inertia_0": 0.5}
    ccw = method(modified("four_bar", dynamics={"mean_speed": 10.0, **dyn}))
    cw = method(modified("four_bar", dynamics={"mean_speed": -10.0, **dyn}))
    assert np.max(np.abs(np.mod(cw.phi - ccw.phi[::-1] + np.pi, 2 * np.pi) - np.pi)) < 1e-12
    scale = np.max(np.abs(ccw.reduced.moment))
    assert abs(ccw.driving_moment) < 1e-5 * scale and abs(cw.driving_moment) < 1e-5 * scale
    assert cw.required_constant_inertia == pytest.approx(ccw.required_constant_inertia, rel=1e-10)
    assert cw.flywheel_inertia == pytest.approx(ccw.flywheel_inertia, rel=1e-10)
    assert cw.delta_actual == pytest.approx(ccw.delta_actual, rel=1e-10)
    assert np.all(ccw.omega > 0) and np.all(cw.omega < 0)
    assert rel(cw.omega, -ccw.omega[::-1]) < 1e-10
    assert rel(cw.eps, ccw.eps[::-1]) < 1e-8
    assert rel(cw.reduced.moment, -ccw.reduced.moment[::-1]) < 1e-12
    assert rel(cw.reduced.inertia_derivative, -ccw.reduced.inertia_derivative[::-1]) < 1e-12


# ----------------------------------------------------------------------------------------------
# 8. motor-driven machines
# ----------------------------------------------------------------------------------------------

I_MOTOR = 146.7  # kg m^2: a constant inertia at the crank (about the exact flywheel sizing)
RTOL = 1e-9      # periodicity is checked to ~1e-6: the integration must be well below that
MOTORS = {
    # 1500 rpm synchronous, 1440 rpm rated, through U = 14.4 to about 100 rpm at the crank
    "induction": InductionMotor(rated_moment=20.0, synchronous_rpm=1500, rated_rpm=1440, overload=2.0,
                                ratio=14.4),
    "linear": LinearMotor(stall_moment=60.0, no_load_speed=1500 * RPM, ratio=14.4, efficiency=0.9),
}
SAMPLES = 720


@pytest.fixture(scope="module", params=sorted(MOTORS))
def driven(request, press):
    motor = MOTORS[request.param]
    spec = replace(dynamics_of(press), motor=motor)
    law = steady_state(press, spec, constant_inertia=I_MOTOR, samples=SAMPLES, rtol=RTOL)
    return motor, spec, law


def test_motor_steady_state_is_periodic(press, driven):
    motor, spec, law = driven
    assert law.method == "ode"
    assert np.all(law.omega < 0)
    assert law.omega[-1] == pytest.approx(law.omega[0], rel=1e-6)
    # own one-cycle re-integration from the steady state's initial speed
    tr = simulate(press, spec, initial_speed=abs(law.omega[0]), cycles=1, constant_inertia=I_MOTOR,
                  samples=SAMPLES, rtol=RTOL)
    assert tr.psi[-1] == pytest.approx(2 * np.pi, rel=1e-12)
    assert tr.omega[-1] == pytest.approx(law.omega[0], rel=1e-6)
    # the speed sits near the motor's balance speed for the mean resistance
    w_balance = motor.balance_speed(law.driving_moment)
    assert abs(law.details["mean_speed"]) == pytest.approx(w_balance, rel=0.05)


def _cycle_mean_motor_moment(press, spec, law):
    """Cycle mean of the motor moment over psi, own Simpson on the re-integrated steady cycle
    with the kinetic energy T(psi) of the solver's dense output and our own I(psi)."""
    tr = simulate(press, spec, initial_speed=abs(law.omega[0]), cycles=1, constant_inertia=I_MOTOR,
                  samples=SAMPLES)
    psi, red = press_fine(100)
    w = np.sqrt(2 * tr.sol(psi)[0] / (I_MOTOR + red.inertia_variable))
    return simpson(spec.motor(w), psi) / (2 * np.pi)


def test_motor_mean_moment_balances_resistance(press, press_md, driven):
    """Periodic motion: int (M_motor(w) + M_red) dpsi = T(2 pi) - T(0) = 0, so the cycle mean of
    the motor moment equals M_d = -A_c(2 pi) / 2 pi (own Simpson)."""
    motor, spec, law = driven
    assert _cycle_mean_motor_moment(press, spec, law) == pytest.approx(press_md, rel=2e-4)


def test_motor_reported_driving_moment_is_the_cycle_mean(press, press_md, driven):
    """LawOfMotion.driving_moment of the ODE is documented as the cycle mean of the driving
    moment; it must balance the resistance like the true mean does."""
    motor, spec, law = driven
    assert law.driving_moment == pytest.approx(press_md, rel=2e-4)


def test_motor_transient_approaches_steady_state(press, driven):
    motor, spec, law = driven
    w_ss = abs(law.omega[0])
    cycles = 6
    tr = simulate(press, spec, initial_speed=0.5 * w_ss, cycles=cycles, constant_inertia=I_MOTOR,
                  samples=SAMPLES, rtol=1e-7)
    i_start = I_MOTOR + slider_crank_closed([PHI0])[3][0]
    w_ends = np.sqrt(2 * tr.sol(2 * np.pi * np.arange(cycles + 1))[0] / i_start)
    assert w_ends[0] == pytest.approx(0.5 * w_ss, rel=1e-9)
    gaps = np.abs(w_ends - w_ss)
    assert np.all(np.diff(gaps) < 0)  # closer every cycle
    assert gaps[-1] < 0.1 * gaps[0]


def test_weak_motor_stalls_with_a_dynamics_error(press):
    base = dynamics_of(press)
    # breakdown moment 2 * 8 * 14.4 = 230 N m at the crank < the mean resistance (~265 N m)
    weak = replace(base, motor=InductionMotor(rated_moment=8.0, synchronous_rpm=1500, rated_rpm=1440,
                                              overload=2.0, ratio=14.4))
    with deadline(30), pytest.raises(DynamicsError, match="stall"):
        steady_state(press, weak, constant_inertia=I_MOTOR, samples=360, rtol=1e-8)
    # 65 N m at standstill: the transient stalls within a few cycles, not after 50
    feeble = replace(base, motor=LinearMotor(stall_moment=5.0, no_load_speed=1500 * RPM, ratio=14.4,
                                             efficiency=0.9))
    t0 = time.perf_counter()
    with deadline(30), pytest.raises(DynamicsError, match="stall"):
        simulate(press, feeble, initial_speed=10.0, cycles=50, samples=360)
    assert time.perf_counter() - t0 < 20
    # a motor strong enough on average, but the press's peak resistance stops a machine with
    # almost no flywheel during the working stroke
    with deadline(30), pytest.raises(DynamicsError, match="stall"):
        steady_state(press, replace(base, motor=MOTORS["linear"]), constant_inertia=1.0, samples=360,
                     rtol=1e-8)


# ----------------------------------------------------------------------------------------------
# 9. virtual power under the real motion
# ----------------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def report(press):
    return run_dynamics(press)


def test_virtual_power_under_the_real_motion(press, report):
    law = report.law
    ends = np.zeros(len(law.phi), bool)
    ends[-1] = True
    motion = linkage.analyze(press, law.phi, order=2, omega=law.omega, eps=law.eps)
    reactions = solve_reactions(motion, ends=ends)
    assert np.max(virtual_power_residual(reactions)) <= 1e-9
    assert rel(report.balancing_moment, reactions.balancing_moment) < 1e-12
    # Energy of the links: M_b omega = dT_links/dt - P_applied with T_links = I'' w^2 / 2 (the
    # crank adds none); with the equation of motion I psi'' + dI/dpsi psi'^2 / 2 = M_d + M_red
    # and I = I_c + I'' this is M_b = s M_d - I_c eps: the shaft carries the mean driving moment
    # minus the torque that accelerates the constant inertia (flywheel and rotors).
    s = -1
    expected = s * law.driving_moment - law.required_constant_inertia * law.eps
    assert rel(reactions.balancing_moment, expected) < 1e-9


# ----------------------------------------------------------------------------------------------
# 10. the summary
# ----------------------------------------------------------------------------------------------

SUMMARY_KEYS = {"driving_moment", "required_constant_inertia", "flywheel_inertia", "delta_actual",
                "dynamic_coefficient"}


def test_summary_keys_and_values(press, report):
    summary = report.summary()
    assert SUMMARY_KEYS <= set(summary)
    json.loads(json.dumps(summary))  # plain JSON
    law = report.law
    assert summary["driving_moment"] == law.driving_moment
    assert summary["required_constant_inertia"] == law.required_constant_inertia
    assert summary["flywheel_inertia"] == pytest.approx(law.required_constant_inertia - I0_DECLARED,
                                                        rel=1e-12)
    assert summary["delta_actual"] == pytest.approx(DELTA, rel=1e-15)
    # k_dyn = max |M_b| / |M_d| with M_b from our own kinetostatics under the law's motion
    ends = np.zeros(len(law.phi), bool)
    ends[-1] = True
    mb = solve_reactions(linkage.analyze(press, law.phi, order=2, omega=law.omega, eps=law.eps),
                         ends=ends).balancing_moment
    assert summary["dynamic_coefficient"] == pytest.approx(np.max(np.abs(mb)) / abs(law.driving_moment),
                                                           rel=1e-12)
    assert summary["dynamic_coefficient"] > 1


def test_no_flywheel_needed_with_a_huge_constant_inertia(press):
    dyn = copy.deepcopy(to_dict(press)["dynamics"])
    dyn["inertia_0"] = 1.0e4
    heavy = modified("course_slider_crank", dynamics=dyn)
    rep = run_dynamics(heavy)
    summary = rep.summary()
    assert summary["flywheel_inertia"] is None
    json.loads(json.dumps(summary))
    # delta_actual = Delta T'_ab / (I_0 w_m^2) with the course quantities recomputed here
    wm, step = abs(OMEGA_M), 2 * np.pi / N_POS
    phi = PHI0 - np.arange(N_POS + 1) * step
    moment = press_moment(phi, CYCLE_FORCE, -1)
    work = trapezoid_cumulative(moment, step)
    md = -work[-1] / (2 * np.pi)
    dtp = md * np.arange(N_POS + 1) * step + work - slider_crank_closed(phi)[3] * wm**2 / 2
    assert summary["delta_actual"] == pytest.approx(np.ptp(dtp) / (1.0e4 * wm**2), rel=1e-10)
    assert summary["delta_actual"] < DELTA
    # the speed law then uses the actual constant inertia I_0
    ti = 1.0e4 * wm**2 / 2 + dtp - (dtp.max() + dtp.min()) / 2
    assert rel(rep.law.omega, -np.sqrt(2 * ti / 1.0e4)) < 1e-12
    # the exact method needs no flywheel either
    exact = exact_method(heavy, samples=720)
    assert exact.flywheel_inertia is None
    assert exact.delta_actual < DELTA


# ----------------------------------------------------------------------------------------------
# robustness (regressions found while writing these tests)
# ----------------------------------------------------------------------------------------------


def test_exact_method_sizes_flywheel_when_declared_inertia_cannot_carry_the_mean_speed():
    """Four-bar under gravity at 10 rad/s: the weight swings ~4.9 J while I'' ~ 0.01..0.05 kg m^2,
    so with the crank's own inertia (0) no energy level has (w_max + w_min) / 2 = 10 rad/s. A
    flywheel fixes that: the constant inertia needed for delta cannot depend on how much of it
    was declared as inertia_0 (here 0 and 0.5 kg m^2)."""
    dyn = {"mean_speed": 10.0, "delta": 0.05, "positions": 12}
    with_some = exact_method(modified("four_bar", dynamics={**dyn, "inertia_0": 0.5}))
    bare = exact_method(modified("four_bar", dynamics=dyn))
    assert bare.required_constant_inertia == pytest.approx(with_some.required_constant_inertia, rel=1e-9)
    assert bare.flywheel_inertia == pytest.approx(bare.required_constant_inertia, rel=1e-12)


def test_steady_state_unreachable_mean_speed_is_a_dynamics_error(press):
    """A constant driving moment and a constant inertia too small for the declared mean speed: no
    periodic steady state with that mean speed exists -> DynamicsError (documented), not a bare
    ValueError from the root finder."""
    with deadline(30), pytest.raises(DynamicsError):
        steady_state(press, constant_inertia=1.0, samples=360, rtol=1e-8)


def test_to_dict_returns_an_independent_copy_of_the_sections():
    """Modified mechanisms are built with to_dict / from_dict: editing the dict must not change
    the (frozen) mechanism it came from."""
    mech = linkage.load("course_slider_crank")
    data = to_dict(mech)
    data["dynamics"]["inertia_0"] = 1.0e4
    data["loads"]["gravity"][1] = 0.0
    assert dynamics_of(mech).inertia_0 == I0_DECLARED
    assert mech.extra["loads"]["gravity"] == [0.0, -9.81]


#: a massless, loadless slider-crank that declares a speed, delta and I_0
BARE = slider_crank_toml(0.1, 0.3, 'from = "O"\ntowards_deg = 0', name="bare", header='output = "B.x"',
                         tail="[dynamics]\nmean_rpm = 60\ndelta = 0.05\ninertia_0 = 2.0\n")


def test_a_machine_without_loads_or_masses_has_no_energy_swing_and_no_ratio_to_divide():
    """No loads and no masses: the energy never swings, so both methods need no constant inertia
    (closed form: I' = 0) and the course/exact ratio is undefined (None), not a ZeroDivisionError."""
    report = run_dynamics(linkage.loads(BARE), "course")
    summary = report.summary()
    assert summary["required_constant_inertia"] == 0.0 and summary["exact_required_constant_inertia"] == 0.0
    assert summary["course_vs_exact_inertia"] is None
