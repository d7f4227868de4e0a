"""Accuracy of a stroke's law of motion (linkage.dynamics.stroke): time and speed to 1e-9 relative.

Oracles, all written here:

- a bare slider of mass m on a guide inclined at alpha, under gravity and a constant force F
  along +s: a constant acceleration a = (F - m g sin alpha) / m, so along the travel
  v^2 = v0^2 + 2 a_t u and t = 2 u / (v0 + v) (u the distance travelled, a_t = sigma a);
- the shipped cylinder_boom and piston_driven_crank against the Lagrange equation in s,
  m(s) s'' + m'(s) s'^2 / 2 = F + Q(s), integrated by scipy's DOP853 at rtol 1e-13 with events at the
  table's slides, m and Q Chebyshev interpolants of the API's reduced mass and force (m' their
  derivative, not the API's).
"""

from __future__ import annotations

import functools
import math

import numpy as np
import pytest
from numpy.polynomial import Chebyshev
from scipy.integrate import solve_ivp

import linkage
from linkage.dynamics.reduced import reduced_characteristics
from linkage.dynamics.stroke import stroke_motion
from linkage.errors import DynamicsError

G = 9.81
MASS = 2.5
INCLINE = math.radians(30.0)


@functools.lru_cache(maxsize=None)
def shipped(name):
    """A shipped scheme, loaded once (cylinder_boom traces its assembly mode when loaded)."""
    return linkage.load(name)


def bare_slider(stroke):
    """A slider of MASS kg on a frame guide at INCLINE through the origin; gravity (0, -9.81) by
    default of the builder."""
    b = linkage.MechanismBuilder("bare_slider")
    b.link("0", points={"O": (0.0, 0.0)}, guides={"g": {"through": (0.0, 0.0), "angle_deg": math.degrees(INCLINE)}})
    b.link("1", points={"B": (0.0, 0.0)}, mass=MASS, com="B")
    b.prismatic("g", "0", "1", guide="g", at="B")
    b.inputs("1")
    b.input_range(*stroke)
    return b.build()


def constant_acceleration(s, s0, sense, v0, accel_along):
    """Speed |ds/dt| and time at slides ``s`` under a constant acceleration along the travel."""
    u = np.abs(s - s0)
    v = np.sqrt(v0**2 + 2 * accel_along * u)
    return v, 2 * u / np.where(u > 0, v0 + v, 1.0)


def assert_relative(actual, expected, rtol, what):
    error = np.max(np.abs(actual - expected) / np.abs(expected))
    assert error <= rtol, f"{what}: relative error {error:.3g} > {rtol:g}"


@pytest.mark.parametrize("stroke, force, v0", [
    ((0.2, 0.9), 40.0, 0.0),          # from rest, up the incline
    ((0.2, 0.9), 40.0, 0.7),          # with a start speed
    ((0.9, 0.2), 3.0, 0.0),           # down the incline, gravity helping
    ((0.9, 0.2), 20.0, 2.5),          # down, braked by the force
    ((0.2, 0.9), 40.0, 1e-6),         # all but from rest: the time's integrand nearly singular
])
def test_bare_slider_matches_constant_acceleration(stroke, force, v0):
    mech = bare_slider(stroke)
    motion = stroke_motion(mech, force, initial_speed=v0, positions=7)
    s0, s1 = stroke
    sense = np.sign(s1 - s0)
    accel = force / MASS - G * math.sin(INCLINE)                 # along +s
    v, t = constant_acceleration(motion.s, s0, sense, v0, sense * accel)
    np.testing.assert_allclose(motion.s, np.linspace(s0, s1, 8), atol=1e-15)
    assert motion.t[0] == 0 and motion.speed[0] == sense * v0
    assert_relative(motion.t[1:], t[1:], 1e-9, "time")
    assert_relative(np.abs(motion.speed[1:]), v[1:], 1e-9, "speed")
    assert np.all(np.sign(motion.speed[1:]) == sense)
    assert_relative(motion.acceleration, np.full(8, accel), 1e-9, "acceleration")


def test_bare_slider_force_with_a_jump():
    """F = 40 N up to s = 0.5 m (not a table slide), 25 N after: two constant accelerations."""
    mech = bare_slider((0.2, 0.9))
    jump = 0.5

    def force(s):
        return np.where(s < jump, 40.0, 25.0)

    motion = stroke_motion(mech, force, initial_speed=0.0, positions=5)
    a1, a2 = 40.0 / MASS - G * math.sin(INCLINE), 25.0 / MASS - G * math.sin(INCLINE)
    v_jump, t_jump = constant_acceleration(np.array([jump]), 0.2, 1, 0.0, a1)
    v_first, t_first = constant_acceleration(motion.s, 0.2, 1, 0.0, a1)
    v_second, t_second = constant_acceleration(motion.s, jump, 1, v_jump[0], a2)
    v = np.where(motion.s <= jump, v_first, v_second)
    t = np.where(motion.s <= jump, t_first, t_jump[0] + t_second)
    assert_relative(motion.t[1:], t[1:], 1e-9, "time")
    assert_relative(motion.speed[1:], v[1:], 1e-9, "speed")


def test_bare_slider_stop_is_located():
    """Braked from 0.7 m/s by gravity and a force pulling back: it stops after u = v0^2 / (2 |a|)."""
    mech = bare_slider((0.2, 0.9))
    accel = -10.0 / MASS - G * math.sin(INCLINE)
    stop = 0.2 + 0.7**2 / (2 * abs(accel))
    with pytest.raises(DynamicsError) as info:
        stroke_motion(mech, -10.0, initial_speed=0.7)
    message = str(info.value)
    assert "stops at s = " in message
    found = float(message.split("stops at s = ")[1].split()[0])
    assert found == pytest.approx(stop, rel=1e-5), message     # printed to 6 digits


# ----------------------------------------------------------------------------------------------
# shipped schemes against the Lagrange equation in s
# ----------------------------------------------------------------------------------------------


def lagrange_oracle(mech, force, v0, table):
    """Times and speeds ds/dt at the slides ``table`` from the equation of motion in s,
    ``m s'' = F(s) + Q(s) - m'(s) s'^2 / 2``, integrated in time from ``table[0]``."""
    start, end = mech.input_range
    sense = np.sign(end - start)
    domain = [min(start, end), max(start, end)]      # a step past the end extrapolates the series

    def reduced(s):
        return reduced_characteristics(mech, np.atleast_1d(s), 1)     # along +s

    mass = Chebyshev.interpolate(lambda s: reduced(s).inertia, 120, domain)
    loads = Chebyshev.interpolate(lambda s: reduced(s).moment, 120, domain)
    for series in (mass, loads):                      # the interpolants resolve the functions
        assert np.max(np.abs(series.coef[-10:])) < 1e-13 * np.max(np.abs(series.coef))
    mass_derivative = mass.deriv()

    def rhs(_, y):
        s, v = y
        return [v, (force(s) + loads(s) - 0.5 * mass_derivative(s) * v * v) / mass(s)]

    events = []
    for target in table[1:]:
        def event(_, y, target=target):
            return y[0] - target
        event.direction = sense
        events.append(event)
    events[-1].terminal = True
    solution = solve_ivp(rhs, (0.0, 20.0), [start, sense * v0], method="DOP853", rtol=1e-13, atol=1e-16,
                         events=events, first_step=1e-6, max_step=5e-3)
    assert solution.status == 1, solution.message
    times = np.array([e[0] for e in solution.t_events])
    speeds = np.array([e[0][1] for e in solution.y_events])
    return np.concatenate([[0.0], times]), np.concatenate([[sense * v0], speeds])


@pytest.mark.parametrize("name, force, v0, positions", [
    ("cylinder_boom", lambda s: 9000.0, 0.0, 24),                       # the reported case, from rest
    ("cylinder_boom", lambda s: 9000.0 - 3000.0 * (s - 0.6), 0.4, 10),  # a force varying with s
    ("piston_driven_crank", lambda s: -800.0, 0.5, 16),                 # a stroke towards smaller s
])
def test_shipped_strokes_match_the_equation_of_motion(name, force, v0, positions):
    mech = shipped(name)
    motion = stroke_motion(mech, lambda s: force(s) + 0.0 * s, initial_speed=v0, positions=positions)
    t, v = lagrange_oracle(mech, force, v0, motion.s)
    assert_relative(motion.t[1:], t[1:], 1e-9, "time")
    assert_relative(motion.speed[1:], v[1:], 1e-9, "speed")
    assert motion.speed[0] == v[0]


def test_cylinder_boom_reported_case_and_table_independence():
    """`linkage dynamics cylinder_boom --force 9000`: the stroke time to 1e-9 whatever the table's
    steps (the old fixed grid was 2.1e-6 off, and its first step 1e-5)."""
    mech = shipped("cylinder_boom")
    coarse = stroke_motion(mech, 9000.0, positions=1)
    fine = stroke_motion(mech, 9000.0, positions=70)
    t, v = lagrange_oracle(mech, lambda s: 9000.0, 0.0, coarse.s)
    assert_relative(coarse.t[-1:], t[-1:], 1e-9, "time of the stroke, one step")
    assert_relative(fine.t[-1:], t[-1:], 1e-9, "time of the stroke, 70 steps")
    assert_relative(fine.speed[-1:], v[-1:], 1e-9, "final speed")
    # the first step from rest, where the time's integrand is singular
    near = stroke_motion(mech, 9000.0, positions=70)
    t_near, _ = lagrange_oracle(mech, lambda s: 9000.0, 0.0, near.s[:3])
    assert_relative(near.t[1:3], t_near[1:3], 1e-9, "time of the first steps")
