"""The crank's law of motion over one cycle from the energy equation (docs/methods.md,
"Mertsalov's method (the course method)" and "The exact energy method").

- :func:`course_method` -- the course method: constant driving moment from the cycle balance
  (trapezoid on the table positions), Mertsalov's flywheel, omega and eps by the course formulas;
- :func:`exact_method` -- the energy equation without Mertsalov's approximation on a fine grid,
  and the exact flywheel for the same coefficient of speed fluctuation.

Both give a :class:`LawOfMotion` (as does the equation of motion's steady state,
:mod:`linkage.dynamics.equation`). The cycle's grid and speeds are shared with the other
dynamics modules: :func:`cycle_positions` (the table angles of a cycle), :func:`fine_cycle`,
:func:`cycle_speeds` and :func:`speed_fluctuation` (the exact method's grid, speeds and delta),
:func:`angular_acceleration` and :func:`reduced_at`.

All reduced quantities refer to ``psi = s phi`` with ``s = sign(omega_m)``: a reduced moment is
positive when it drives, speeds ``w = |omega|`` are positive.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import brentq

from ..errors import DynamicsError, DynamicsInputError
from ..kinematics.extremes import table_angles
from ..model.mechanism import Mechanism
from .reduced import Reduced, reduced_characteristics
from .spec import (
    DELTA_RESOLVED,
    DynamicsSpec,
    kinetic_energy,
    override_spec,
    require_count,
    require_full_turn,
)

__all__ = ["FINE_SAMPLES", "LawOfMotion", "course_method", "exact_method"]


# ----------------------------------------------------------------------------------------------
# results
# ----------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class LawOfMotion:
    """The crank's law of motion over one cycle, at the table positions.

    Attributes
    ----------
    method : str
        "course", "exact" or "ode".
    phi : ndarray (n+1,)
        Table input angles, rad (``phi_i = phi0 + s (i-1) 2 pi / n``).
    reduced : Reduced
        Reduced characteristics of the machine as declared at the table positions
        (``reduced.inertia`` is ``I_0 + I''``, without a flywheel the method adds).
    driving_moment : float
        Constant (or cycle-mean, for "ode") driving moment, N m.
    required_constant_inertia : float
        Constant inertia at the crank needed for ``delta``: Mertsalov's ``I'`` (course) or
        ``I_0 + I_fw`` of the exact solution, kg m^2.
    flywheel_inertia : float or None
        Flywheel to add, kg m^2; None when none is needed.
    delta_actual : float
        Coefficient of speed fluctuation of the resulting motion.
    constant_inertia : float
        Constant inertia at the crank in the resulting motion: ``I_0`` plus the flywheel, kg m^2.
    omega, eps : ndarray (n+1,)
        Angular velocity (rad/s, signed) and acceleration (rad/s^2) of the crank.
    details : dict
        Method-specific intermediate results (work of resistance, energy changes ...).
    """

    method: str
    phi: np.ndarray
    reduced: Reduced
    driving_moment: float
    required_constant_inertia: float
    flywheel_inertia: float | None
    delta_actual: float
    constant_inertia: float
    omega: np.ndarray
    eps: np.ndarray
    details: dict = field(default_factory=dict)

    @property
    def inertia(self) -> np.ndarray:
        """Reduced moment of inertia in the resulting motion, flywheel included, kg m^2."""
        return self.constant_inertia + self.reduced.inertia_variable

    @property
    def driving(self) -> np.ndarray:
        """The driving moment at the table positions, N m: the constant ``driving_moment`` (course,
        exact), the motor's moment at each position's speed (ode, ``details["motor_moment"]``)."""
        motor = self.details.get("motor_moment")
        return np.full(len(self.phi), float(self.driving_moment)) if motor is None else np.asarray(motor, float)

    @property
    def mean_speed_actual(self) -> float:
        return float(np.sign(self.omega[0]) * (np.max(np.abs(self.omega)) + np.min(np.abs(self.omega))) / 2)


def cycle_positions(mech: Mechanism, spec: DynamicsSpec, positions: int | None = None):
    n = spec.positions if positions is None else positions
    phi = table_angles(mech, n, spec.start, spec.rotation)
    ends = np.zeros(n + 1, bool)
    ends[-1] = True
    return phi, ends


def angular_acceleration(reduced: Reduced, driving: float | np.ndarray, inertia: np.ndarray,
                         w: np.ndarray) -> np.ndarray:
    """``s (M_d + M_c - dI/dpsi w^2 / 2) / I`` (docs/methods.md, "Mertsalov's method")."""
    return reduced.rotation * (driving + reduced.moment - 0.5 * reduced.inertia_derivative * w**2) / inertia


# ----------------------------------------------------------------------------------------------
# the course method
# ----------------------------------------------------------------------------------------------


def course_method(mech: Mechanism, spec: DynamicsSpec | None = None, *, positions: int | None = None,
                  delta: float | None = None, mean_speed: float | None = None) -> LawOfMotion:
    """Mertsalov's method on the table positions (docs/methods.md, "Mertsalov's method").

    ``positions``, ``delta`` and ``mean_speed`` override the declared inputs. The method is plain
    arithmetic on the table (no tolerance): a consistently scaled machine gives results scaled
    to rounding (~1e-15 relative).

    Raises
    ------
    DynamicsInputError
        An argument out of range (``delta`` missing or not a finite number > 0, ``mean_speed`` zero or
        beyond float64's range, ``positions`` < 1 ...), or a ``delta`` so small that the constant
        inertia it needs overflows float64.
    DynamicsError
        The machine has no inertia at the crank and needs none, so its speed is undetermined.
    """
    require_full_turn(mech, "the course method (Mertsalov)")
    spec = override_spec(mech, spec, delta, mean_speed, positions)
    if spec.delta is None:
        raise DynamicsInputError(f"mechanism '{mech.name}': the course method needs delta (the coefficient of "
                                 "speed fluctuation): declare it in [dynamics] or pass delta=")
    phi, ends = cycle_positions(mech, spec)
    n = len(phi) - 1
    red = reduced_characteristics(mech, phi, spec.rotation, extra_inertia=spec.constant_inertia, ends=ends,
                                  friction=spec.friction, speed=spec.friction_speed)
    step = 2 * np.pi / n
    work = np.concatenate([[0.0], np.cumsum((red.moment[1:] + red.moment[:-1]) / 2 * step)])
    driving = -work[-1] / (2 * np.pi)
    psi = np.arange(n + 1) * step
    energy = driving * psi + work  # Delta T
    wm = abs(spec.mean_speed)
    wm2 = wm * wm
    kinetic_energy(red.inertia_constant + float(np.max(red.inertia_variable)), wm, f"mechanism '{mech.name}'")
    energy_links = red.inertia_variable * wm2 / 2  # T''
    energy_flywheel = energy - energy_links  # Delta T'
    swing = float(np.max(energy_flywheel) - np.min(energy_flywheel))
    required = swing / spec.delta / wm2
    if not math.isfinite(required):
        raise DynamicsInputError(f"delta = {spec.delta!r}: the constant inertia it needs, Delta T'_ab / (delta "
                                 f"w_m^2) = {swing:.6g} J / ({spec.delta!r} x {wm2:.6g} rad^2/s^2), overflows "
                                 "float64")
    flywheel = required - red.inertia_constant
    constant = max(required, red.inertia_constant)
    if not constant > 0:
        raise DynamicsError(f"mechanism '{mech.name}': no constant inertia at the crank (I_0 = 0) and none "
                            "needed for delta (no energy swing): the speed is undetermined; declare the "
                            "crank's or the rotors' inertia")
    delta_actual = spec.delta if flywheel > 0 else swing / (red.inertia_constant * wm2)
    mean_energy = constant * wm2 / 2
    energy_total = mean_energy + energy_flywheel - (np.max(energy_flywheel) + np.min(energy_flywheel)) / 2
    w = np.sqrt(2 * energy_total / constant)
    inertia = constant + red.inertia_variable
    return LawOfMotion("course", phi, red, float(driving), float(required),
                       float(flywheel) if flywheel > 0 else None, float(delta_actual), float(constant),
                       spec.rotation * w, angular_acceleration(red, driving, inertia, w),
                       {"work_resistance": work, "energy_change": energy, "energy_links": energy_links,
                        "energy_flywheel": energy_flywheel, "energy_swing": swing})


# ----------------------------------------------------------------------------------------------
# the exact energy method
# ----------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class _Cycle:
    """Reduced characteristics on a fine grid over one cycle, with the energy change."""

    psi: np.ndarray
    reduced: Reduced
    driving: float
    energy: np.ndarray  # Delta T(psi) with the balancing constant driving moment


def fine_cycle(mech: Mechanism, spec: DynamicsSpec, samples: int) -> _Cycle:
    n = spec.positions * max(1, math.ceil(samples / spec.positions))
    phi, ends = cycle_positions(mech, spec, n)
    red = reduced_characteristics(mech, phi, spec.rotation, extra_inertia=spec.constant_inertia, ends=ends,
                                  friction=spec.friction, speed=spec.friction_speed)
    psi = np.arange(n + 1) * 2 * np.pi / n
    work = np.concatenate([[0.0], np.cumsum((red.moment[1:] + red.moment[:-1]) / 2 * np.diff(psi))])
    driving = -work[-1] / (2 * np.pi)
    return _Cycle(psi, red, float(driving), driving * psi + work)


def cycle_speeds(cycle: _Cycle, constant: float, mean: float) -> np.ndarray | None:
    """|omega|(psi) with the energy level chosen so that (max + min) / 2 = mean.

    ``None`` when no level reaches it: even with omega_min = 0 the mean is above ``mean`` (the
    machine cannot run that slowly with so little inertia; its delta would exceed 2).
    """
    inertia = constant + cycle.reduced.inertia_variable
    low = -np.min(cycle.energy)

    def mid(t0):
        w = np.sqrt(2 * np.maximum(t0 + cycle.energy, 0.0) / inertia)
        return (np.max(w) + np.min(w)) / 2 - mean

    if mid(low) > 0:
        return None
    high = abs(low) + float(np.max(inertia)) * mean * mean  # mid(high) >= (sqrt(2) - 1) mean > 0
    t0 = brentq(mid, low, high, xtol=1e-14 * high, rtol=1e-15)  # relative to the energy scale
    return np.sqrt(2 * np.maximum(t0 + cycle.energy, 0.0) / inertia)


def speed_fluctuation(w: np.ndarray | None, mean: float) -> float:
    """Coefficient of speed fluctuation; 2 where the mean speed is out of reach (the limit of
    ``(w_max - 0) / ((w_max + 0) / 2)``, so the function stays continuous for root finding)."""
    if w is None:
        return 2.0
    return float((np.max(w) - np.min(w)) / mean)


FINE_SAMPLES = 3600  # grid of the exact method (and of the cycle balance that decides k_dyn)


def exact_method(mech: Mechanism, spec: DynamicsSpec | None = None, *, positions: int | None = None,
                 delta: float | None = None, mean_speed: float | None = None,
                 samples: int = FINE_SAMPLES) -> LawOfMotion:
    """The energy equation solved without Mertsalov's approximation, on ``samples`` grid points.

    The constant driving moment balances the cycle (trapezoid on the fine grid); the kinetic
    energy ``T = T_0 + Delta T(psi)`` gives ``|omega| = sqrt(2 T / I(psi))`` with ``T_0`` such that
    ``(omega_max + omega_min) / 2 = |omega_m|``; the flywheel is the added constant inertia that
    makes ``delta`` equal the target (found by Brent's method).

    Every tolerance is relative to the problem's own scale, so a consistently scaled machine
    gives consistently scaled results: ``T_0`` to 1e-14 of the energy scale ``I_max w_m^2``, the
    constant inertia to 1e-14 relative (plus 1e-15 of the problem's inertia scale
    ``max I'' + I'_Mertsalov``, which does not include the declared ``I_0``). The computed delta
    itself carries rounding of ~1e-16, so the constant inertia is accurate to about
    ``1e-16 / delta`` relative (~1e-14 at delta = 0.01); ``delta`` below :data:`DELTA_RESOLVED`
    is refused. When the links' own inertia keeps the fluctuation below ``delta`` even without a
    constant inertia, the required constant inertia is reported as 1e-12 of that scale
    (practically zero).

    Raises
    ------
    DynamicsInputError
        An argument out of range (see :func:`course_method`), ``samples`` < 1, or ``delta`` below
        :data:`DELTA_RESOLVED`.
    DynamicsError
        No constant inertia gives the mean speed (without ``delta``), or the machine has no
        inertia and no energy swing (its speed is undetermined).
    """
    require_full_turn(mech, "the exact energy method")
    spec = override_spec(mech, spec, delta, mean_speed, positions)
    require_count("samples", samples)
    if spec.delta is not None and spec.delta < DELTA_RESOLVED:
        raise DynamicsInputError(f"delta = {spec.delta!r} is below what the exact energy method resolves in "
                                 f"float64 (delta >= {DELTA_RESOLVED:g}: speeds carry rounding of ~1e-16 "
                                 "relative); use the course method, exact in the limit delta -> 0")
    cycle = fine_cycle(mech, spec, samples)
    wm = abs(spec.mean_speed)
    base = cycle.reduced.inertia_constant
    kinetic_energy(base + float(np.max(cycle.reduced.inertia_variable)), wm, f"mechanism '{mech.name}'")
    # Mertsalov's I' on the fine grid: the exact answer as delta -> 0, and the problem's inertia scale
    swing = float(np.ptp(cycle.energy - cycle.reduced.inertia_variable * (wm * wm / 2)))
    mertsalov = swing / spec.delta / (wm * wm) if spec.delta is not None else 0.0
    if not math.isfinite(mertsalov):
        raise DynamicsInputError(f"delta = {spec.delta!r}: the constant inertia it needs (about {swing:.6g} J / "
                                 f"(delta w_m^2)) overflows float64")
    # the problem's own inertia scale: what delta needs does not depend on the declared I_0
    scale = float(np.max(cycle.reduced.inertia_variable)) + mertsalov
    required = base
    if spec.delta is not None:
        # the constant inertia that gives exactly delta, whether or not I_0 already exceeds it
        fluctuation = lambda c: speed_fluctuation(cycle_speeds(cycle, c, wm), wm) - spec.delta  # noqa: E731
        low = 1e-12 * scale
        if not scale > 0:  # no variable inertia, no energy swing: the speed is constant
            required = 0.0
        elif fluctuation(low) <= 0:  # the links' own inertia keeps delta: (practically) none needed
            required = low
        else:
            high = 2 * mertsalov + scale
            for _ in range(64):
                if fluctuation(high) <= 0:
                    break
                high *= 2
            else:
                raise DynamicsError(f"mechanism '{mech.name}': no constant inertia up to {high:.6g} kg m^2 "
                                    f"gives delta = {spec.delta!r}")
            required = brentq(fluctuation, low, high, xtol=1e-3 * low, rtol=1e-14, maxiter=200)
    flywheel = required - base if required > base else None
    constant = max(required, base)
    if not float(np.min(constant + cycle.reduced.inertia_variable)) > 0:
        raise DynamicsError(f"mechanism '{mech.name}': the reduced inertia vanishes (no constant inertia at the "
                            "crank, none needed for delta): the speed is undetermined; declare the crank's or "
                            "the rotors' inertia")
    w = cycle_speeds(cycle, constant, wm)
    if w is None:
        raise DynamicsError(f"mechanism '{mech.name}': with the constant inertia {constant:.6g} kg m^2 "
                            f"the machine cannot keep the mean speed {wm:.6g} rad/s: give delta to size "
                            "a flywheel")
    stride = (len(cycle.psi) - 1) // spec.positions
    pick = slice(None, None, stride)
    red = reduced_at(cycle.reduced, pick)
    w_table = w[pick]
    return LawOfMotion("exact", red.phi, red, cycle.driving, float(required),
                       None if flywheel is None else float(flywheel), speed_fluctuation(w, wm), float(constant),
                       spec.rotation * w_table,
                       angular_acceleration(red, cycle.driving, constant + red.inertia_variable, w_table),
                       {"samples": len(cycle.psi) - 1, "fine_cycle": cycle})


def reduced_at(red: Reduced, index) -> Reduced:
    return Reduced(red.phi[index], red.rotation, red.moment_resistance[index], red.moment_driving[index],
                   red.inertia_constant, red.inertia_variable[index], red.inertia_derivative[index],
                   None if red.moment_friction is None else red.moment_friction[index])
