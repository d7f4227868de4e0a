"""Dynamics at the edges (issue 7): degenerate ratios, extreme arguments, typed errors.

Every expected value comes from an independent oracle written here: closed-form slider-crank
kinematics (docs/methods.md#checks), the tangency condition of a slotted link's stroke ends, the
cycle balance of conservative and constant loads, Kloss's formula and its linear limit, the
proportionality of Mertsalov's inertia to 1 / delta, and the constant speed a huge flywheel
imposes at the motor's balance point.

1. ``k_dyn`` is None (JSON null) with a note when the mean driving moment is zero to round-off
   (a conservative cycle); a small but real mean driving moment still gives a number.
2. ``virtual_power_residual`` stays <= 1e-9 on correct reactions where every power is round-off
   (dead centres of a slider-crank and of a shaper with a load on the output, a load through the
   crank's pivot, no loads at all) and still flags wrong reactions.
3. Arguments of the dynamics functions out of range raise ``DynamicsInputError`` (a
   ``LinkageError`` and a ``ValueError``) naming the argument and the value.
4. Extreme but valid arguments (delta = 5e-324, constant inertia 1e300 / 1e308, overload 1e200,
   mean speed +-1e200) give the right answer or a ``DynamicsError`` saying why, never a raw
   SciPy / Python exception or a numpy warning.
"""

from __future__ import annotations

import json
import math
import re
import warnings
from dataclasses import replace

import numpy as np
import pytest

import linkage
from linkage.dynamics import (DynamicsSpec, course_method, dynamics_of, exact_method, run_dynamics, simulate,
                              steady_state)
from linkage.errors import DynamicsError, DynamicsInputError, LinkageError
from linkage.kinetostatics.reactions import solve_reactions, virtual_power_residual
from linkage.dynamics.motors import RPM, ConstantMotor, InductionMotor, LinearMotor
from linkage.dynamics.reduced import reduced_characteristics
from linkage.model.scheme import from_dict, to_dict


@pytest.fixture(autouse=True)
def warnings_are_errors():
    """No numpy (or any other) warning may escape from the solvers in these tests."""
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        yield


def variant(name: str, **sections) -> linkage.Mechanism:
    data = to_dict(linkage.load(name))
    for key, value in sections.items():
        if value is None:
            data.pop(key, None)
        else:
            data[key] = value
    return from_dict(data)


@pytest.fixture(scope="module")
def shears():
    return linkage.load("flying_shears")


# ----------------------------------------------------------------------------------------------
# 1. the coefficient of dynamics when the mean driving moment vanishes
# ----------------------------------------------------------------------------------------------

FOUR_BAR_DYNAMICS = {"mean_speed": 10.0, "delta": 0.05, "positions": 12}


def test_k_dyn_is_null_for_a_conservative_cycle():
    """Gravity alone is a potential force: its work over a cycle is exactly zero, so the mean
    driving moment is round-off (exact method) or the trapezoid's error on 12 positions (course
    method, ~1e-6 of the moment scale) and max|M_b| / |M_d| means nothing (it printed 2.85e16)."""
    mech = variant("four_bar", dynamics=FOUR_BAR_DYNAMICS)
    for method, quadrature in (("course", 1e-5), ("exact", 1e-12)):
        report = run_dynamics(mech, method)
        law = report.law
        # the oracle: a conservative cycle needs no net drive
        assert abs(law.driving_moment) <= quadrature * np.max(np.abs(law.reduced.moment))
        assert report.dynamic_coefficient is None
        summary = report.summary()
        assert json.loads(json.dumps(summary))["dynamic_coefficient"] is None
        assert any("coefficient of dynamics undefined" in note for note in report.notes)


def test_k_dyn_is_a_number_for_a_small_but_real_mean_moment():
    """A constant resisting moment c on the crank (CCW) does work -2 pi c per cycle, and without
    gravity nothing else does: M_d = c exactly, however small against the machine's moment scale
    (the inertia torques, ~1 N m here)."""
    c = 1e-6
    mech = variant("four_bar", dynamics=FOUR_BAR_DYNAMICS,
                   loads={"gravity": [0.0, 0.0], "moments": [{"link": "1", "moment": -c}]})
    report = run_dynamics(mech, "course")
    assert report.law.driving_moment == pytest.approx(c, rel=1e-12)
    law = report.law
    ends = np.zeros(len(law.phi), bool)
    ends[-1] = True
    mb = solve_reactions(linkage.analyze(mech, law.phi, order=2, omega=law.omega, eps=law.eps),
                         ends=ends).balancing_moment
    assert np.max(np.abs(mb)) > 1e3 * c  # the machine's moment scale dwarfs M_d
    assert report.dynamic_coefficient == pytest.approx(np.max(np.abs(mb)) / c, rel=1e-12)
    assert not any("coefficient of dynamics" in note for note in report.notes)


def test_cli_prints_null_and_the_note(capsys):
    from linkage.cli import main

    code = main(["dynamics", "four_bar", "--omega", "10", "--delta", "0.05", "--positions", "8",
                 "--format", "json"])
    out, err = capsys.readouterr()
    assert code == 0, err
    assert json.loads(out)["dynamic_coefficient"] is None
    assert "coefficient of dynamics undefined" in err
    code = main(["dynamics", "four_bar", "--omega", "10", "--delta", "0.05", "--positions", "8"])
    out, err = capsys.readouterr()
    assert code == 0, err
    assert "# dynamic_coefficient: undefined (see the note)" in out.splitlines()


# ----------------------------------------------------------------------------------------------
# 2. the virtual-power residual where every power is round-off
# ----------------------------------------------------------------------------------------------

L1, L2, E = 0.0742, 0.2225, 0.01335  # the shipped slider_crank: crank, rod, guide offset (m)
F_SLIDER = -1000.0                     # N along x on the slider


def slider_x1(phi):
    """``x_B'`` of the offset slider-crank, closed form (docs/methods.md#checks)."""
    sin2 = (E - L1 * np.sin(phi)) / L2
    cos2 = np.sqrt(1 - sin2**2)
    i21 = -L1 * np.cos(phi) / (L2 * cos2)
    return -L1 * np.sin(phi) - L2 * sin2 * i21


@pytest.fixture(scope="module")
def loaded_slider_crank():
    return variant("slider_crank", loads={"gravity": [0.0, 0.0],
                                          "forces": [{"point": "B", "link": "3", "force": [F_SLIDER, 0.0]}]})


def test_residual_at_the_dead_centres_of_a_slider_crank(loaded_slider_crank):
    """Crank and rod collinear (x_B' = 0): extended at sin(phi) = e / (l1 + l2), folded at
    sin(phi) = -e / (l2 - l1) with cos(phi) < 0. The slider's force does no virtual work there,
    so M_b = -F x_B' = 0 and every power is round-off: the residual was 1.0 and 0.099."""
    dead = [math.asin(E / (L1 + L2)), math.pi + math.asin(E / (L2 - L1))]
    assert np.max(np.abs(slider_x1(np.array(dead)))) < 1e-15  # the oracle's own check
    phi = np.array(dead + [0.7, 2.0, 4.0])
    reactions = solve_reactions(linkage.analyze(loaded_slider_crank, phi, order=2), inertia=False)
    # the reactions are right: M_b = -F_x x_B' (static balance, virtual work, closed form)
    expected = -F_SLIDER * slider_x1(phi)
    assert np.max(np.abs(reactions.balancing_moment - expected)) <= 1e-12 * abs(F_SLIDER) * L1
    assert np.max(virtual_power_residual(reactions)) <= 1e-9


def test_residual_flags_wrong_reactions(loaded_slider_crank):
    """The same positions with M_b off by 1e-6 of F l1: the residual must see it everywhere,
    dead centres included (so the tests above can fail)."""
    phi = np.array([math.asin(E / (L1 + L2)), 0.7, 2.0])
    reactions = solve_reactions(linkage.analyze(loaded_slider_crank, phi, order=2), inertia=False)
    wrong = replace(reactions, balancing_moment=reactions.balancing_moment + 1e-6 * abs(F_SLIDER) * L1)
    assert np.min(virtual_power_residual(wrong)) > 1e-8


def test_residual_at_the_stroke_ends_of_a_shaper():
    """Shaper (slotted_link_two_dyad): the ram stops when the rocker is tangent to the crank
    circle, (A - O3) . (A - O1) = 0 with A = O1 + r u: r + O1 . u = 0, i.e. sin(phi) = -r / d
    (O1 = (0, d), d = 0.12 m, r = 0.076 m). A load on the ram alone does no virtual work there:
    M_b = 0 and every power is round-off (the residual was 0.097)."""
    shaper = variant("slotted_link_two_dyad",
                     loads={"gravity": [0.0, 0.0], "forces": [{"point": "B", "link": "5", "force": [-3000.0, 0.0]}]})
    s = math.asin(-0.076 / 0.12)
    phi = np.array([s, math.pi - s, 1.0])
    reactions = solve_reactions(linkage.analyze(shaper, phi, order=2), inertia=False)
    ram_x1 = linkage.analyze(shaper, phi, order=1, outputs=["B.x"]).quantity("B.x")[1]
    assert np.max(np.abs(ram_x1[:2])) < 1e-12  # the tangency oracle agrees with the kinematics
    assert np.max(np.abs(reactions.balancing_moment[:2])) <= 1e-12 * 3000.0 * 0.5
    assert reactions.balancing_moment[2] == pytest.approx(3000.0 * ram_x1[2], rel=1e-12)
    assert np.max(virtual_power_residual(reactions)) <= 1e-9


def test_residual_with_a_load_through_the_crank_pivot():
    """A force at the crank's pivot O does no virtual work at any angle: it balances exactly
    (M_b = 0), and the residual must not mistake round-off of M_b for an error."""
    mech = variant("four_bar", loads={"gravity": [0.0, 0.0],
                                      "forces": [{"point": "O", "link": "1", "force": [123.0, -456.0]}]})
    phi = np.linspace(0.0, 2 * np.pi, 13)
    reactions = solve_reactions(linkage.analyze(mech, phi, order=2), inertia=False)
    assert np.max(np.abs(reactions.balancing_moment)) <= 1e-12 * 472.3 * 0.3
    assert np.max(virtual_power_residual(reactions)) <= 1e-9


def test_residual_without_any_load():
    """No gravity, no masses, no forces: every power is exactly zero -> residual 0; a balancing
    moment that is not zero is then entirely wrong -> residual 1."""
    data = to_dict(linkage.load("four_bar"))
    for link in data["links"].values():
        link.pop("mass", None)
        link["inertia"] = 0.0
    data["loads"] = {"gravity": [0.0, 0.0]}
    mech = from_dict(data)
    reactions = solve_reactions(linkage.analyze(mech, np.linspace(0, 6, 7), order=2, omega=10.0, eps=0.0))
    assert np.all(reactions.balancing_moment == 0)
    assert np.all(virtual_power_residual(reactions) == 0)
    wrong = replace(reactions, balancing_moment=np.ones(7))
    np.testing.assert_array_equal(virtual_power_residual(wrong), 1.0)


# ----------------------------------------------------------------------------------------------
# 3. typed errors for arguments out of range
# ----------------------------------------------------------------------------------------------


def test_initial_speed_zero_without_a_starting_torque_is_a_typed_error(shears):
    """A start from rest (initial_speed = 0) needs a motor with a starting torque
    (tests/test_scheme_format.py); a constant motor of 0 N m has none."""
    no_torque = replace(dynamics_of(shears), motor=ConstantMotor(0.0))
    with pytest.raises(DynamicsInputError, match=r"initial_speed = 0 .* starting torque") as info:
        simulate(shears, no_torque, initial_speed=0)
    assert isinstance(info.value, LinkageError) and isinstance(info.value, ValueError)
    assert isinstance(info.value, DynamicsError)


@pytest.mark.parametrize("call, match", [
    (lambda m: simulate(m, initial_speed=float("nan")), r"initial_speed .* got nan"),
    (lambda m: simulate(m, initial_speed=-3.0), r"initial_speed .* got -3\.0"),
    (lambda m: simulate(m, cycles=0), r"cycles must be a positive integer, got 0"),
    (lambda m: simulate(m, atol=0.0), r"atol .* got 0\.0"),
    (lambda m: simulate(m, rtol=0.0), r"rtol .* got 0\.0"),
    (lambda m: steady_state(m, rtol=1e-20), r"rtol .* got 1e-20"),
    (lambda m: steady_state(m, rtol=1.0), r"rtol .* got 1\.0"),
    (lambda m: steady_state(m, constant_inertia=-1.0), r"constant_inertia .* got -1\.0"),
    (lambda m: steady_state(m, constant_inertia=float("inf")), r"constant_inertia .* got inf"),
    (lambda m: steady_state(m, samples=0), r"samples must be a positive integer, got 0"),
    (lambda m: steady_state(m, max_iterations=0), r"max_iterations .* got 0"),
    (lambda m: steady_state(m, positions=-2), r"positions must be a positive integer, got -2"),
    (lambda m: course_method(m, delta=0.0), r"delta must be .* got 0\.0"),
    (lambda m: course_method(m, delta=float("nan")), r"delta must be .* got nan"),
    (lambda m: course_method(m, delta="0.1"), r"delta must be .* got '0\.1'"),
    (lambda m: course_method(m, mean_speed=0.0), r"mean_speed must be .* got 0\.0"),
    (lambda m: course_method(m, mean_speed=float("-inf")), r"mean_speed must be .* got -inf"),
    (lambda m: course_method(m, positions=0), r"positions must be a positive integer, got 0"),
    (lambda m: course_method(m, positions=True), r"positions must be a positive integer, got True"),
    (lambda m: exact_method(m, samples=0), r"samples must be a positive integer, got 0"),
    (lambda m: run_dynamics(m, "fast"), r"method must be 'course', 'exact' or 'ode', got 'fast'"),
    (lambda m: course_method(m, DynamicsSpec(mean_speed=0.0, delta=0.1)), r"mean_speed .* got 0\.0"),
    (lambda m: course_method(m, DynamicsSpec(mean_speed=1.0, delta=0.1, flywheel=-1.0)),
     r"flywheel must be .* got -1\.0"),
    (lambda m: course_method(m, DynamicsSpec(mean_speed=1.0, delta=0.1, rotors=((1.0, float("nan")),))),
     r"rotors\[0\] .* got \(1\.0, nan\)"),
    (lambda m: course_method(m, DynamicsSpec(mean_speed=1.0, delta=0.1, rotors=((1e300, 1e10),))),
     r"constant inertia .* got inf"),
    (lambda m: steady_state(m, DynamicsSpec(mean_speed=1.0, motor="fast")), r"motor must be .* got 'fast'"),
    (lambda m: reduced_characteristics(m, [0.0], rotation=0), r"rotation must be \+1 or -1, got 0"),
    (lambda m: reduced_characteristics(m, [0.0], rotation=1, extra_inertia=-2.0), r"extra_inertia .* got -2\.0"),
])
def test_arguments_out_of_range_name_the_argument_and_the_value(shears, call, match):
    with pytest.raises(DynamicsInputError, match=match):
        call(shears)


@pytest.mark.parametrize("make, match", [
    (lambda: ConstantMotor(float("nan")), r"ConstantMotor: moment must be a finite number, got nan"),
    (lambda: LinearMotor(10.0, 0.0), r"LinearMotor: no_load_speed must be > 0, got 0\.0"),
    (lambda: LinearMotor(10.0, 100.0, efficiency=1.5), r"efficiency must be \(0, 1\], got 1\.5"),
    (lambda: InductionMotor(10.0, 1500, 1440, overload=1.0), r"overload must be > 1, got 1\.0"),
    (lambda: InductionMotor(10.0, 1500, 1500), r"rated_rpm must be below synchronous_rpm"),
    (lambda: InductionMotor(-1.0, 1500, 1440), r"rated_moment must be > 0, got -1\.0"),
])
def test_motor_parameters_out_of_range(make, match):
    with pytest.raises(DynamicsInputError, match=match):
        make()


# ----------------------------------------------------------------------------------------------
# 4. extreme but valid arguments
# ----------------------------------------------------------------------------------------------


def test_tiny_delta_course_method(shears):
    """Mertsalov's I' = Delta T'_ab / (delta w_m^2) is proportional to 1 / delta: exact at
    delta = 1e-300; at 5e-324 it overflows float64, which is said, not returned as inf."""
    ref = course_method(shears)
    tiny = course_method(shears, delta=1e-300)
    assert tiny.required_constant_inertia * 1e-300 == pytest.approx(ref.required_constant_inertia * 0.08,
                                                                    rel=1e-13)
    with pytest.raises(DynamicsInputError, match=r"delta = 5e-324: .* overflows float64"):
        course_method(shears, delta=5e-324)


def test_tiny_delta_exact_method_and_ode(shears):
    with pytest.raises(DynamicsInputError, match=r"delta = 5e-324 is below what the exact energy method resolves"):
        exact_method(shears, delta=5e-324)
    with pytest.raises(DynamicsInputError, match=r"delta = 5e-324"):
        run_dynamics(shears, "ode", delta=5e-324)
    # the course pipeline still runs at delta = 1e-12, leaving out the comparison it cannot make
    report = run_dynamics(shears, "course", delta=1e-12)
    assert report.comparison == {}
    assert any("below what the exact method resolves" in note for note in report.notes)
    ref = course_method(shears)
    assert report.law.required_constant_inertia * 1e-12 == pytest.approx(ref.required_constant_inertia * 0.08,
                                                                         rel=1e-12)


@pytest.mark.parametrize("speed", [1e200, -1e200, 1e-200])
def test_mean_speed_beyond_float64(shears, speed):
    for call in (lambda: course_method(shears, mean_speed=speed), lambda: exact_method(shears, mean_speed=speed),
                 lambda: run_dynamics(shears, "ode", mean_speed=speed),
                 lambda: steady_state(shears, replace(dynamics_of(shears), mean_speed=speed))):
        with pytest.raises(DynamicsInputError, match=rf"mean_speed must be .* got {re.escape(repr(speed))}"):
            call()


def test_constant_inertia_that_overflows_the_kinetic_energy(shears):
    for call in (lambda: steady_state(shears, constant_inertia=1e308),
                 lambda: simulate(shears, constant_inertia=1e308)):
        with pytest.raises(DynamicsError, match=r"kinetic energy .* overflows float64"):
            call()


def kloss_balance_speed(moment, motor):
    """Input speed where Kloss's moment, reduced through U and eta, equals ``moment`` (own
    inversion of M = 2 M_k S S_k / (S^2 + S_k^2) on the stable branch S < S_k)."""
    lam = motor.overload
    s_nom = 1 - motor.rated_rpm / motor.synchronous_rpm
    sk = s_nom * (lam + math.sqrt(lam * lam - 1))
    mk = lam * motor.rated_moment
    m = moment / (motor.ratio * motor.efficiency)
    slip = sk * (mk - math.sqrt(mk * mk - m * m)) / m
    return motor.synchronous_rpm * (1 - slip) * RPM / motor.ratio


def test_huge_flywheel_runs_at_the_motors_balance_speed(shears):
    """With I = 1e300 kg m^2 the speed cannot change within a cycle: the steady state turns at
    the speed where the motor's moment equals the cycle's mean resistance M_d (Mertsalov's
    trapezoid on the same 360-point grid). Before, the cycle's energy gain (~10 J) drowned in the
    rounding of a 1e301 J kinetic energy: omega came out 5 % off with status OK (and 1.2e-4 off,
    the mean driving moment 1 % off, already at I = 1e6). Tolerances: the shooting finds the
    energy to 10 rtol (speed to 5 rtol, rtol = 1e-9) -> 1e-7; the motor turns a speed error into
    a moment error 1 / S ~ 100 times larger (slip S ~ 0.011 at this speed) -> 1e-5."""
    law = steady_state(shears, constant_inertia=1e300, samples=360)
    md = course_method(shears, positions=360).driving_moment
    w = kloss_balance_speed(md, dynamics_of(shears).motor)
    np.testing.assert_allclose(law.omega, w, rtol=1e-7)
    assert law.delta_actual < 1e-12
    assert law.driving_moment == pytest.approx(md, rel=1e-5)
    # and at I = 1e6, where the fluctuation (~3e-7) is still far below the old energy tolerance
    law = steady_state(shears, constant_inertia=1e6, samples=360)
    np.testing.assert_allclose(np.mean(np.abs(law.omega)), w, rtol=1e-6)


def test_kloss_characteristic_for_any_overload():
    """The rewritten Kloss formula equals the textbook one, and for a huge overload it tends to
    the linear ``M_nom S / S_nom`` (S_k -> 2 lambda S_nom, M_k = lambda M_nom) without overflow."""
    w = np.linspace(0.0, 1.2 * 1500 * RPM / 14.4, 50)
    motor = InductionMotor(rated_moment=10.0, synchronous_rpm=1500, rated_rpm=1440, overload=2.2, ratio=14.4,
                           efficiency=0.9)
    slip = (1500 - 14.4 * w / RPM) / 1500
    s_nom, lam = 60 / 1500, 2.2
    sk = s_nom * (lam + math.sqrt(lam * lam - 1))
    textbook = 14.4 * 0.9 * 2 * lam * 10.0 * slip * sk / (slip**2 + sk**2)
    np.testing.assert_allclose(motor(w), textbook, rtol=1e-13, atol=1e-13 * np.max(np.abs(textbook)))
    huge = replace(motor, overload=1e200)
    np.testing.assert_allclose(huge(w), 14.4 * 0.9 * 10.0 * slip / s_nom, rtol=1e-13, atol=1e-12)
    # balance speed: the linear characteristic inverted by hand
    m = 50.0
    expected = 1500 * (1 - m / (14.4 * 0.9) * s_nom / 10.0) * RPM / 14.4
    assert huge.balance_speed(m) == pytest.approx(expected, rel=1e-13)
    assert motor.balance_speed(m) == pytest.approx(kloss_balance_speed(m, motor), rel=1e-12)


def test_huge_overload_with_the_ode_method(shears):
    """overload = 1e200 (a valid induction motor given through the Python API; the scheme loader
    caps it): the machine runs as with the equivalent linear motor M = M_nom (1 - n / n_s) / S_nom,
    the limit of Kloss's formula. Both are ODE solutions at rtol = 1e-9 (speeds within ~1e-7,
    moments ~100 times more through the motor's slope)."""
    spec = dynamics_of(shears)
    induction = spec.motor
    huge = replace(spec, motor=replace(induction, overload=1e200))
    s_nom = 1 - induction.rated_rpm / induction.synchronous_rpm
    linear = replace(spec, motor=LinearMotor(stall_moment=induction.rated_moment / s_nom,
                                             no_load_speed=induction.synchronous_rpm * RPM, ratio=induction.ratio,
                                             efficiency=induction.efficiency))
    a = steady_state(shears, huge, constant_inertia=4.0, samples=360)
    b = steady_state(shears, linear, constant_inertia=4.0, samples=360)
    np.testing.assert_allclose(a.omega, b.omega, rtol=1e-6)
    assert a.driving_moment == pytest.approx(b.driving_moment, rel=1e-4)
    # the start-up transient too
    t = simulate(shears, huge, constant_inertia=4.0, cycles=2, samples=360)
    assert np.all(np.isfinite(t.omega)) and t.t[-1] > 0
