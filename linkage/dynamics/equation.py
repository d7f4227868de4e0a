"""The equation of motion with a motor characteristic (docs/methods.md, "The equation of motion").

The motor (:mod:`linkage.dynamics.motors`) drives the machine through
``I(psi) w dw/dpsi + I'(psi) w^2 / 2 = M_d(w) + M(psi)``, integrated with
``scipy.integrate.solve_ivp``:

- :func:`simulate` -- a start-up transient over K cycles (a :class:`Transient`), from a given
  speed or from rest (its first degree integrated in time); a start-up whose speed falls to zero
  raises :class:`StartupStall`, which holds the motion up to the stall and where and why it
  stalls (a :class:`Stall`);
- :func:`steady_state` -- the periodic steady state by shooting on ``omega(0) = omega(2 pi)``
  (a :class:`~linkage.dynamics.cycle.LawOfMotion` with method "ode").
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Any

import numpy as np
from scipy.integrate import solve_ivp
from scipy.interpolate import CubicSpline
from scipy.optimize import brentq

from ..errors import DynamicsError, DynamicsInputError
from ..model.mechanism import Mechanism
from .cycle import (
    LawOfMotion,
    angular_acceleration,
    cycle_positions,
    cycle_speeds,
    fine_cycle,
    speed_fluctuation,
)
from .motors import RPM, ConstantMotor, starting_moment
from .reduced import reduced_characteristics
from .spec import (
    DynamicsSpec,
    check_spec,
    dynamics_of,
    is_real,
    kinetic_energy,
    require,
    require_count,
    require_full_turn,
)

__all__ = ["REST_START_ANGLE", "Stall", "StartupStall", "Transient", "simulate", "steady_state"]

#: ``scipy.integrate.solve_ivp``'s status when an integration step failed
IVP_FAILED = -1


@dataclass(frozen=True)
class Transient:
    """Solution of the equation of motion: ``psi`` (rad from the cycle start), time ``t`` (s) and
    ``omega`` (rad/s, signed) at the solver's output points, plus the dense solution ``sol``
    (``sol(psi) -> [T, t]``, kinetic energy and time as functions of psi)."""

    psi: np.ndarray
    t: np.ndarray
    omega: np.ndarray
    sol: Any
    message: str = ""

    def columns(self) -> dict[str, np.ndarray]:
        """The start-up as a table, one row per output point of the solver: ``t`` (s, from the
        start), ``phi_deg`` (the crank angle travelled from the start in the direction of
        rotation, deg; ``psi`` in degrees, so it grows by 360 per cycle), ``omega`` (rad/s,
        signed)."""
        return {"t": np.asarray(self.t, dtype=float), "phi_deg": np.degrees(self.psi),
                "omega": np.asarray(self.omega, dtype=float)}


@dataclass(frozen=True)
class Stall:
    """Where and why a start-up transient stalls: its speed falls to zero (omega -> 0).

    A stall at ``psi`` needs the driving moment at rest below the resistance there,
    ``M_d(0) < -M_red(psi)`` (at omega = 0 the equation of motion leaves ``I domega/dt =
    M_d(0) + M_red(psi)``). So a driving moment at rest above :attr:`largest_resisting`, the
    largest resisting reduced moment over the turn, stalls from no start: :attr:`shortfall` is
    how much more moment at rest that takes.

    Attributes
    ----------
    psi : float
        Crank angle travelled from the start to the stall, rad (from position 1 in the direction
        of rotation, 2 pi per turn; 0: the machine does not move from position 1).
    t : float
        Time from the start to the stall, s.
    initial_speed : float
        |omega| at the start of the transient, rad/s (0: from rest).
    starting_moment : float
        The driving moment at rest ``M_d(0)`` at the crank, N m (the motor's starting torque, or
        the constant moment from the cycle balance when no motor is declared).
    resisting : float
        The resisting reduced moment ``-M_red`` at the stall, N m.
    largest_resisting : float
        The largest resisting reduced moment over the turn, ``max(-M_red)``, N m.
    largest_at : float
        Where it is, rad in [0, 2 pi) from position 1.
    motor_declared : bool
        False when no motor is declared and the constant moment from the cycle balance drives.
    """

    psi: float
    t: float
    initial_speed: float
    starting_moment: float
    resisting: float
    largest_resisting: float
    largest_at: float
    motor_declared: bool = True

    @property
    def turn(self) -> int:
        """The turn of the crank (from 1) in which the machine stalls."""
        return int(self.psi // (2 * np.pi)) + 1

    @property
    def degrees(self) -> float:
        """The stall's crank angle within its turn, deg in [0, 360) from position 1."""
        return math.degrees(self.psi % (2 * np.pi))

    @property
    def shortfall(self) -> float:
        """How much more driving moment at rest (N m) would make a stall impossible:
        :attr:`largest_resisting` minus :attr:`starting_moment` (> 0 at any stall)."""
        return self.largest_resisting - self.starting_moment

    def words(self) -> str:
        """The stall in one sentence: where (psi, deg, and the turn), when (t, s), the resistance
        there, the driving moment at rest, and the moment at rest that no start can stall."""
        start = "from rest" if self.initial_speed == 0 else f"from |omega| = {self.initial_speed:.6g} rad/s"
        if self.motor_declared:
            driver = f"the motor's moment at rest is {self.starting_moment:.6g} N m at the crank"
        else:
            driver = (f"no [dynamics.motor] is declared, so the constant driving moment from the cycle balance, "
                      f"{self.starting_moment:.6g} N m, drives it (it gains no energy over a turn, so it cannot "
                      "bring the machine up to speed)")
        if self.psi == 0:
            where = (f"the machine does not start {start}: the starting torque {self.starting_moment:.6g} N m does "
                     f"not overcome the resisting moment {self.resisting:.6g} N m at the cycle's start (position 1)")
        else:
            turn, degrees = self.turn, self.degrees
            if f"{degrees:.1f}" == "360.0":  # the end of a turn, said as the start of the next
                turn, degrees = turn + 1, 0.0
            where = (f"the start-up {start} stalls (omega -> 0) at psi = {degrees:.1f} deg of turn {turn} (psi: the "
                     f"crank angle from position 1 in the direction of rotation, 0..360 deg) after t = "
                     f"{self.t:.4g} s, where the resisting reduced moment is {self.resisting:.4g} N m")
        largest = (f"the largest resisting reduced moment over the turn, {self.largest_resisting:.4g} N m at psi = "
                   f"{math.degrees(self.largest_at):.1f} deg")
        if self.motor_declared:
            more = f" ({self.shortfall:.4g} N m more than this motor's)" if self.shortfall > 0 else ""
            need = f"no start can stall a machine whose moment at rest exceeds {largest}{more}"
        else:
            need = (f"to start it, declare a [dynamics.motor] whose moment at rest exceeds {largest}: no start can "
                    "stall such a machine")
        return f"{where}; {driver}; {need}"


class StartupStall(DynamicsError):
    """A start-up transient stalls (omega -> 0): :attr:`stall` says where and why (a
    :class:`Stall`), :attr:`transient` holds the motion from the start up to the stall (a
    :class:`Transient`; its one row at t = 0 when the machine does not move)."""

    def __init__(self, message: str, stall: Stall, transient: Transient):
        super().__init__(message)
        self.stall, self.transient = stall, transient


class _Equation:
    """``I(psi) w dw/dpsi + I'(psi) w^2 / 2 = M_d(w) + M(psi)`` in the energy form
    ``dT/dpsi = M_d(w) + M(psi)`` with ``w = sqrt(2 T / I)``; ``dt/dpsi = 1 / w``.

    ``scale`` is the kinetic energy ``I_max w_m^2 / 2`` at the declared mean speed and ``work``
    the work scale of the loads ``2 pi max|M|`` (the size of the energy changes over a cycle);
    :func:`_integrate` takes its tolerances from them and from its own initial state."""

    def __init__(self, mech: Mechanism, spec: DynamicsSpec, motor, constant: float, samples: int = 720):
        cycle = fine_cycle(mech, spec, samples)
        psi = cycle.psi
        inertia = constant + cycle.reduced.inertia_variable
        inertia[-1] = inertia[0]
        # the problem's own scales: every tolerance of the integration is relative to them
        self.scale = kinetic_energy(float(np.max(inertia)), spec.mean_speed, f"mechanism '{mech.name}'")
        self.work = 2 * np.pi * float(np.max(np.abs(cycle.reduced.moment)))
        if not float(np.min(inertia)) > 0:
            k = int(np.argmin(inertia))
            raise DynamicsError(f"mechanism '{mech.name}': the reduced inertia I = {constant:.6g} + I'' vanishes at "
                                f"psi = {math.degrees(psi[k]):.1f} deg: the equation of motion is singular; give a "
                                "constant inertia > 0")
        self.inertia = CubicSpline(psi, inertia, bc_type="periodic")
        self.psi_grid, self.moment_grid = psi, cycle.reduced.moment
        self.motor, self.rotation = motor, spec.rotation
        self.cycle, self.constant = cycle, constant
        self.name = mech.name
        self.motor_declared = spec.motor is not None

    @property
    def driver(self) -> str:
        """What drives the machine, in words: the motor, or the constant moment from the cycle balance."""
        if self.motor_declared:
            return "the motor"
        return f"the constant driving moment from the cycle balance ({self.cycle.driving:.6g} N m; no motor declared)"

    def stall(self, psi: float, t: float, initial_speed: float) -> Stall:
        """The :class:`Stall` at ``psi`` (rad from the start) and ``t`` (s)."""
        resisting = -self.moment_grid
        k = int(np.argmax(resisting))
        return Stall(float(psi), float(t), float(initial_speed), starting_moment(self.motor),
                     -float(self.moment(psi)), float(resisting[k]), float(self.psi_grid[k] % (2 * np.pi)),
                     self.motor_declared)

    def moment(self, psi):
        return np.interp(np.mod(psi, 2 * np.pi), self.psi_grid, self.moment_grid)

    def speed(self, psi, energy):
        return np.sqrt(2 * np.maximum(energy, 0.0) / self.inertia(np.mod(psi, 2 * np.pi)))

    def rhs(self, psi, state):
        energy = state[0]
        w = self.speed(psi, energy)
        driving = float(self.motor(w))
        if not math.isfinite(driving):
            raise DynamicsError(f"mechanism '{self.name}': the motor's moment at |omega| = {float(w):.6g} rad/s is "
                                f"{driving!r}, not a finite number")
        return [driving + float(self.moment(psi)), 1.0 / max(float(w), 1e-300)]


class _Energy:
    """The dense solution ``psi -> [T, t]`` of an integration whose state is ``[T - T_0, t]``."""

    def __init__(self, dense, energy0: float):
        self.dense, self.energy0 = dense, energy0

    def __call__(self, psi):
        out = np.array(self.dense(psi), dtype=float)
        out[0] += self.energy0
        return out


def _integrate(eq: _Equation, energy0: float, cycles: float, rtol: float, atol: float | None,
               speed_limit: float, psi0: float = 0.0, t0: float = 0.0) -> Any:
    """``solve_ivp`` (RK45) from ``psi0`` (time ``t0``) to ``2 pi cycles`` from the kinetic energy
    ``energy0``.

    The state is ``[T - energy0, t]``: the energy's change, not its level, so the changes (the
    work of the loads, the swing within a cycle) are resolved to ``rtol`` relative and ``atol``
    absolute (default ``rtol`` times the smaller of ``energy0`` and the work scale) however
    large the kinetic energy is (a huge flywheel), and one cycle's energy gain is read without
    cancellation. Time: ``rtol`` and 1e-10 of one cycle at the initial speed. The machine stalls
    when its energy falls below 1e-10 of ``energy0``. ``sol.sol`` gives ``[T, t]``. All of these
    scales come from the integration's own state, not from the declared mean speed, which a
    motor need not reach.
    """
    if not math.isfinite(energy0) or energy0 <= 0:
        raise DynamicsError(f"mechanism '{eq.name}': the initial kinetic energy {energy0!r} J is not a finite "
                            "positive number")
    floor = 1e-10 * energy0
    energy_tol = rtol * (eq.work if 0 < eq.work < energy0 else energy0)
    time_tol = 1e-10 * 2 * np.pi / float(eq.speed(psi0, energy0))

    def rhs(psi, y):
        return eq.rhs(psi, (energy0 + y[0], y[1]))

    def stall(psi, y):
        return (energy0 - floor) + y[0]

    stall.terminal, stall.direction = True, -1

    def runaway(psi, y):
        return eq.speed(psi, energy0 + y[0]) - speed_limit

    runaway.terminal, runaway.direction = True, 1
    sol = solve_ivp(rhs, (psi0, 2 * np.pi * cycles), [0.0, t0], method="RK45", rtol=rtol,
                    atol=[atol if atol is not None else energy_tol, time_tol],
                    dense_output=True, events=[stall, runaway], max_step=2 * np.pi / 90)
    if sol.sol is not None:
        sol.sol = _Energy(sol.sol, energy0)
    return sol


def _raise_events(sol, eq: _Equation, what: str, stalls: bool = True) -> None:
    """DynamicsError when the integration failed, the machine runs away or (``stalls``) stalls;
    with ``stalls=False`` a stall is left to the caller (a start-up: :class:`StartupStall`)."""
    if sol.status == IVP_FAILED:
        raise DynamicsError(f"{what}: the integration failed ({sol.message})")
    if stalls and len(sol.t_events[0]):
        psi = sol.t_events[0][0]
        raise DynamicsError(f"{what}: the machine stalls (omega -> 0) at psi = {math.degrees(psi):.1f} deg "
                            f"after {sol.y_events[0][0][1]:.3g} s: {eq.driver} cannot overcome the load")
    if len(sol.t_events[1]):
        psi = sol.t_events[1][0]
        raise DynamicsError(f"{what}: the machine runs away (|omega| above the speed limit) at psi = "
                            f"{math.degrees(psi):.1f} deg after {sol.y_events[1][0][1]:.3g} s")


def _motor_of(spec: DynamicsSpec, driving: float):
    return spec.motor if spec.motor is not None else ConstantMotor(driving)


def _speed_limit(spec: DynamicsSpec, motor) -> float:
    sync = getattr(motor, "synchronous_rpm", None)
    limits = [abs(spec.mean_speed)]
    if sync is not None:
        limits.append(sync * RPM / motor.ratio)
    if getattr(motor, "no_load_speed", None):
        limits.append(motor.no_load_speed / motor.ratio)
    return 10 * max(limits)


def _check_ode_args(rtol: Any, atol: Any, samples: Any, constant_inertia: Any) -> None:
    """DynamicsInputError naming the first out-of-range argument of :func:`simulate` /
    :func:`steady_state`."""
    require(is_real(rtol) and _RTOL_MIN <= rtol < 1, "rtol", rtol,
            f"a relative tolerance in [{_RTOL_MIN:.3g}, 1) (float64 cannot meet a tighter one)")
    require(atol is None or (is_real(atol) and atol > 0), "atol", atol, "None or a number > 0 (J)")
    require_count("samples", samples)
    require(constant_inertia is None or (is_real(constant_inertia) and constant_inertia >= 0), "constant_inertia",
            constant_inertia, "None or a finite number >= 0 (kg m^2)")


#: the tightest relative tolerance ``solve_ivp`` accepts without changing it (100 x machine epsilon)
_RTOL_MIN = 100 * np.finfo(float).eps


def simulate(mech: Mechanism, spec: DynamicsSpec | None = None, *, initial_speed: float | None = None,
             cycles: int | None = None, constant_inertia: float | None = None, rtol: float = 1e-8,
             atol: float | None = None, samples: int = 720) -> Transient:
    """Start-up transient from ``initial_speed`` (|omega|, rad/s) over ``cycles`` revolutions.

    ``constant_inertia`` is the constant inertia at the crank (default: the declared one,
    input link included). The integration (RK45) controls the change of the kinetic energy
    from its start to ``rtol`` relative and ``atol`` absolute (J; default ``rtol`` times the
    smaller of the initial kinetic energy and the work scale ``2 pi max|M_red|``) and the time to
    ``rtol`` relative and 1e-10 of one cycle at the initial speed: every tolerance is relative to
    the problem's own scales, however large the flywheel. The global error is larger than
    ``rtol`` (the reduced moment is interpolated linearly between ``samples`` points per cycle):
    measured on the flying shears, the energy at rtol = 1e-9 is within 250 rtol of a run at
    1e-13.

    ``initial_speed = 0`` starts from rest, which needs a motor with a starting torque (its
    moment at rest > 0: any induction motor, a linear motor with ``stall_moment > 0``, a positive
    constant moment). The energy form's ``dt/dpsi = 1 / omega`` is singular at omega = 0, so the
    first :data:`REST_START_ANGLE` (1 deg) of rotation is integrated in time,
    ``I(psi) domega/dt = M_d(omega) + M(psi) - I'(psi) omega^2 / 2``, ``dpsi/dt = omega``
    (RK45, ``rtol``), from ``psi = omega = 0``; the energy form takes over from there.

    Raises
    ------
    DynamicsInputError
        An argument out of range: ``initial_speed`` not a finite number >= 0 (or 0 with a motor
        that has no starting torque), ``cycles`` < 1,
        ``rtol`` outside [2.2e-14, 1), ``atol`` <= 0, ``samples`` < 1, ``constant_inertia`` < 0,
        or a declared input out of range.
    StartupStall
        A DynamicsError: the machine stalls (omega -> 0; or a start from rest whose starting
        torque does not overcome the resistance at position 1). It holds the :class:`Stall` (where,
        when, and the moment at rest no start can stall) and the motion up to it.
    DynamicsError
        On run-away, or when the kinetic energy overflows float64; a mechanism analysed over a
        partial input range (``range_deg``) has no cycle (DynamicsInputError).
    """
    require_full_turn(mech, "the start-up transient")
    spec = check_spec(dynamics_of(mech) if spec is None else spec)
    w0 = initial_speed if initial_speed is not None else spec.initial_speed
    require(is_real(w0) and w0 >= 0, "initial_speed", w0, "a finite number >= 0 (|omega| at the start of the "
                                                         "transient, rad/s; 0: from rest)")
    if cycles is not None:
        require_count("cycles", cycles)
    _check_ode_args(rtol, atol, samples, constant_inertia)
    constant = _default_constant(mech, spec) if constant_inertia is None else float(constant_inertia)
    eq = _Equation(mech, spec, None, constant, samples)
    eq.motor = _motor_of(spec, eq.cycle.driving)
    name = f"mechanism '{mech.name}' transient"
    limit = _speed_limit(spec, eq.motor)
    if w0 == 0:
        return _from_rest(eq, spec, cycles or spec.cycles, rtol, atol, limit, name,
                          declared=spec.motor is not None)
    energy0 = kinetic_energy(float(eq.inertia(0.0)), w0, f"{name} (initial_speed)")
    sol = _integrate(eq, energy0, cycles or spec.cycles, rtol, atol, limit)
    _raise_events(sol, eq, name, stalls=False)
    w = eq.speed(sol.t, energy0 + sol.y[0])
    transient = Transient(sol.t, sol.y[1], spec.rotation * w, sol.sol, sol.message)
    if len(sol.t_events[0]):
        _stalled(eq, name, eq.stall(sol.t_events[0][0], sol.y_events[0][0][1], w0), transient)
    return transient


def _stalled(eq: _Equation, name: str, stall: Stall, transient: Transient) -> None:
    """Raise :class:`StartupStall` for ``stall``, with the motion up to it."""
    raise StartupStall(f"{name}: {stall.words()}", stall, transient)


#: A start from rest is integrated in time over its first REST_START_ANGLE (rad, 1 deg) of input
#: rotation, where the energy form's dt/dpsi = 1 / omega is singular at omega = 0; the energy
#: form in psi takes over from there (omega is then well above zero).
REST_START_ANGLE = 2 * np.pi / 360


def _from_rest(eq: _Equation, spec: DynamicsSpec, cycles: int, rtol: float, atol: float | None,
               limit: float, name: str, declared: bool) -> Transient:
    """The start-up transient from omega = 0: the equation of motion in time,
    ``I(psi) dw/dt = M_d(w) + M(psi) - I'(psi) w^2 / 2`` and ``dpsi/dt = w`` from ``psi = w = 0``
    up to ``psi = REST_START_ANGLE``, then the energy form in psi (:func:`_integrate`)."""
    starting = starting_moment(eq.motor)
    if not starting > 0:
        what = (f"the motor's moment at rest is {starting:.6g} N m at the input" if declared else
                f"no motor is declared and the constant driving moment that balances the cycle is "
                f"{starting:.6g} N m")
        raise DynamicsInputError(f"{name}: initial_speed = 0 (a start from rest) needs a starting torque, but "
                                 f"{what}; declare a motor with one (a linear motor with stall_moment > 0, an "
                                 "induction motor) or a start speed > 0")
    resisting = float(eq.moment(0.0))
    i0 = float(eq.inertia(0.0))
    accel = (starting + resisting) / i0
    if not accel > 0:
        _stalled(eq, name, eq.stall(0.0, 0.0, 0.0),
                 Transient(np.zeros(1), np.zeros(1), np.zeros(1), None, "does not start"))
    slope = eq.inertia.derivative()
    t_scale = math.sqrt(2 * REST_START_ANGLE / accel)  # time to the switch at the initial acceleration
    w_scale = accel * t_scale

    def rhs(t, y):
        psi, w = y
        at = np.mod(psi, 2 * np.pi)
        driving = float(np.asarray(eq.motor(w), dtype=float))
        if not math.isfinite(driving):
            raise DynamicsError(f"{name}: the motor's moment at |omega| = {w:.6g} rad/s is {driving!r}, not a "
                                "finite number")
        return [w, (driving + float(eq.moment(psi)) - 0.5 * float(slope(at)) * w * w) / float(eq.inertia(at))]

    def switch(t, y):
        return y[0] - REST_START_ANGLE

    def stall(t, y):
        return y[1]

    def runaway(t, y):
        return y[1] - limit

    switch.terminal, switch.direction = True, 1
    stall.terminal, stall.direction = True, -1
    runaway.terminal, runaway.direction = True, 1
    first = solve_ivp(rhs, (0.0, 1e6 * t_scale), [0.0, 0.0], method="RK45", rtol=rtol,
                      atol=[1e-3 * rtol * REST_START_ANGLE, 1e-3 * rtol * w_scale], dense_output=True,
                      events=[switch, stall, runaway], max_step=t_scale / 10)
    if first.status == IVP_FAILED:
        raise DynamicsError(f"{name}: the integration from rest failed ({first.message})")
    if len(first.t_events[1]):
        psi_stall = float(first.y_events[1][0][0])
        keep = first.t <= first.t_events[1][0]
        _stalled(eq, name, eq.stall(psi_stall, first.t_events[1][0], 0.0),
                 Transient(first.y[0][keep], first.t[keep], spec.rotation * first.y[1][keep], None, "stalled"))
    if len(first.t_events[2]):
        raise DynamicsError(f"{name}: the machine runs away (|omega| above the speed limit) within the first "
                            f"{math.degrees(REST_START_ANGLE):g} deg from rest")
    if not len(first.t_events[0]):
        raise DynamicsError(f"{name}: the machine does not turn {math.degrees(REST_START_ANGLE):g} deg from rest "
                            f"within {first.t[-1]:.3g} s")
    t_switch = float(first.t_events[0][0])
    psi_switch, w_switch = (float(v) for v in first.y_events[0][0])
    energy = kinetic_energy(float(eq.inertia(psi_switch)), w_switch, name)
    sol = _integrate(eq, energy, cycles, rtol, atol, limit, psi0=psi_switch, t0=t_switch)
    _raise_events(sol, eq, name, stalls=False)
    keep = first.t < t_switch
    psi = np.concatenate([first.y[0][keep], sol.t])
    t = np.concatenate([first.t[keep], sol.y[1]])
    w = np.concatenate([first.y[1][keep], eq.speed(sol.t, energy + sol.y[0])])
    transient = Transient(psi, t, spec.rotation * w, _RestStart(first.sol, t_switch, psi_switch, eq, sol.sol),
                          sol.message)
    if len(sol.t_events[0]):
        _stalled(eq, name, eq.stall(sol.t_events[0][0], sol.y_events[0][0][1], 0.0), transient)
    return transient


class _RestStart:
    """The dense solution ``psi -> [T, t]`` of a start from rest: before the switch angle from the
    integration in time (``t(psi)`` by inverting its monotonic ``psi(t)``), after it from the
    energy form."""

    def __init__(self, in_time, t_switch: float, psi_switch: float, eq: _Equation, after):
        self.in_time, self.psi_switch, self.eq, self.after = in_time, psi_switch, eq, after
        self.t_grid = np.linspace(0.0, t_switch, 2001)
        self.psi_grid = in_time(self.t_grid)[0]

    def __call__(self, psi):
        psi = np.asarray(psi, dtype=float)
        out = np.array(self.after(np.maximum(psi, self.psi_switch)), dtype=float)
        early = psi < self.psi_switch
        if np.any(early):
            target = psi[early] if psi.ndim else psi
            t = np.interp(target, self.psi_grid, self.t_grid)
            for _ in range(4):  # Newton on psi(t) = target (dpsi/dt = omega > 0 after the start)
                at, w = self.in_time(t)
                t = np.where(w > 0, t - (at - target) / np.where(w > 0, w, 1.0), t)
            t = np.clip(t, 0.0, self.t_grid[-1])
            w = self.in_time(t)[1]
            energy = 0.5 * self.eq.inertia(np.mod(psi[early] if psi.ndim else psi, 2 * np.pi)) * w * w
            if psi.ndim:
                out[0][early], out[1][early] = energy, t
            else:
                out = np.array([energy, t], dtype=float)
        return out


def _default_constant(mech: Mechanism, spec: DynamicsSpec) -> float:
    red = reduced_characteristics(mech, [0.0], spec.rotation, extra_inertia=spec.constant_inertia)
    return red.inertia_constant


def _opposite(a: float, b: float) -> bool:
    """``a`` and ``b`` bracket a root (without forming ``a b``, which may overflow)."""
    return a == 0 or b == 0 or (a < 0) != (b < 0)


def steady_state(mech: Mechanism, spec: DynamicsSpec | None = None, *, constant_inertia: float | None = None,
                 positions: int | None = None, rtol: float = 1e-9, samples: int = 720,
                 max_iterations: int = 60) -> LawOfMotion:
    """The periodic steady state of the equation of motion, by shooting on ``omega(0) = omega(2 pi)``.

    With a constant driving moment every initial speed is periodic when the moment balances the
    cycle; the steady state is then the one with the declared mean speed. Tolerances are relative
    to the problem's own scales: one cycle is integrated to ``rtol`` (see :func:`simulate`), the
    periodic initial energy is found to ``10 rtol`` relative from the energy gained over a cycle
    (integrated directly, so a huge flywheel does not drown it), and a constant moment balances
    the cycle when it differs from the balancing one by at most 1e-6 of the energy scale
    ``I_max w_m^2 / 2`` (per radian). The global error is larger than ``rtol`` and erratic (the
    reduced moment is interpolated linearly between ``samples`` points): measured on the flying
    shears against a run at rtol = 1e-13, omega is off by 80 rtol at rtol = 1e-9 (up to 1300
    rtol for rtol in [1e-10, 1e-8]) and the mean driving moment by 1e3 rtol (the motor's
    characteristic turns a small speed error into a larger moment error).

    Raises
    ------
    DynamicsInputError
        An argument out of range (``rtol``, ``samples``, ``positions``, ``max_iterations``,
        ``constant_inertia``; see :func:`simulate`), or a declared input out of range.
    DynamicsError
        When the machine stalls, runs away, no periodic solution is found, or the kinetic energy
        overflows float64.
    """
    require_full_turn(mech, "the steady state of the equation of motion")
    spec = check_spec(dynamics_of(mech) if spec is None else spec)
    if positions is not None:
        spec = check_spec(replace(spec, positions=positions))
    _check_ode_args(rtol, None, samples, constant_inertia)
    require_count("max_iterations", max_iterations)
    constant = _default_constant(mech, spec) if constant_inertia is None else float(constant_inertia)
    eq = _Equation(mech, spec, None, constant, samples)
    motor = eq.motor = _motor_of(spec, eq.cycle.driving)
    limit = _speed_limit(spec, motor)
    name = f"mechanism '{mech.name}' steady state"

    def one_cycle(energy0):
        sol = _integrate(eq, energy0, 1, rtol, None, limit)
        _raise_events(sol, eq, name)
        return sol

    i0 = float(eq.inertia(0.0))
    if isinstance(motor, ConstantMotor):
        w = cycle_speeds(eq.cycle, constant, abs(spec.mean_speed))
        if w is None:
            raise DynamicsError(f"{name}: with the constant inertia {constant:.6g} kg m^2 the machine cannot "
                                f"keep the mean speed {abs(spec.mean_speed):.6g} rad/s (it would stop "
                                "within the cycle): add a flywheel")
        energy0 = kinetic_energy(i0, float(w[0]), name)
        # a constant moment other than the cycle's balancing one gains or loses energy every cycle
        if abs(motor.moment - eq.cycle.driving) > 1e-6 * eq.scale:
            raise DynamicsError(f"{name}: the constant driving moment {motor.moment:.6g} N m does not "
                                f"balance the cycle's resistance ({eq.cycle.driving:.6g} N m needed): no "
                                "periodic steady state")
    else:
        guess = motor.balance_speed(eq.cycle.driving)
        if guess is None or not (math.isfinite(guess) and guess > 0):
            raise DynamicsError(f"{name}: the motor cannot deliver the mean moment {eq.cycle.driving:.6g} N m "
                                "the cycle needs: the machine would stall")
        energy0 = kinetic_energy(i0, guess, name)
        for _ in range(3):  # let the start settle towards the attracting cycle
            energy0 = energy0 + float(one_cycle(energy0).y[0][-1])
        values: dict[float, float] = {}

        def f(e0: float) -> float:  # the energy gained over one cycle (the state is T - e0)
            if e0 not in values:
                values[e0] = float(one_cycle(e0).y[0][-1])
            return values[e0]

        lo, hi = energy0 * 0.9, energy0 * 1.1
        for _ in range(max_iterations):
            if _opposite(f(lo), f(hi)):
                break
            lo, hi = lo * 0.8, hi * 1.25
        else:
            raise DynamicsError(f"{name}: no periodic solution found near |omega| = {guess:.6g} rad/s")
        try:
            energy0 = brentq(f, lo, hi, xtol=10 * rtol * energy0, rtol=10 * rtol, maxiter=100)
        except RuntimeError as exc:  # not converged in maxiter
            raise DynamicsError(f"{name}: the shooting for the periodic solution did not converge ({exc})") from None
    sol = one_cycle(energy0)
    n = spec.positions
    phi, ends = cycle_positions(mech, spec, n)
    psi = np.arange(n + 1) * 2 * np.pi / n
    red = reduced_characteristics(mech, phi, spec.rotation, extra_inertia=spec.constant_inertia, ends=ends,
                                  friction=spec.friction, speed=spec.friction_speed)
    inertia = constant + red.inertia_variable
    w = np.sqrt(2 * sol.sol(psi)[0] / inertia)
    fine = np.linspace(0, 2 * np.pi, 20 * n + 1)
    w_fine = eq.speed(fine, sol.sol(fine)[0])
    mean = (np.max(w_fine) + np.min(w_fine)) / 2
    driving_table = motor(w)
    cycle_mean = float(np.mean(motor(w_fine[:-1])))  # one period: psi = 2 pi is psi = 0
    flywheel = constant - red.inertia_constant
    return LawOfMotion("ode", phi, red, cycle_mean, float(constant), flywheel if flywheel > 0 else None,
                       speed_fluctuation(w_fine, mean), float(constant),
                       spec.rotation * w, angular_acceleration(red, driving_table, inertia, w),
                       {"mean_speed": float(spec.rotation * mean), "period": float(sol.y[1][-1]),
                        "motor_moment": np.broadcast_to(np.asarray(driving_table, float), w.shape).copy()})
