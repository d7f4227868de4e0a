"""Machine dynamics in one call (docs/methods.md, "Dynamics under the real motion" and
"Coefficient of dynamics").

:func:`run_dynamics` runs the whole course pipeline: reduced characteristics, law of motion (by
the course method, the exact method or the equation of motion's steady state), then the
kinetostatics under the real motion and the coefficient of dynamics
``k_dyn = max|M_b| / |M_d|`` (this project's definition: the peak torque on the drive shaft over
the mean driving torque). Its :class:`DynamicsReport` also compares the course method with the
exact one and, with a declared start speed, times the start-up's settling (a start-up that stalls
is a note saying where and why: the steady state stands without it).
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Any, Callable

import numpy as np
from scipy.interpolate import CubicSpline

from ..errors import DynamicsInputError
from ..kinematics.motion import analyze, table_positions_deg
from ..kinetostatics.friction import friction_of
from ..kinetostatics.reactions import solve_reactions
from ..model.mechanism import Mechanism
from .cycle import (
    FINE_SAMPLES,
    LawOfMotion,
    course_method,
    cycle_positions,
    cycle_speeds,
    exact_method,
    fine_cycle,
    speed_fluctuation,
)
from .equation import StartupStall, simulate, steady_state
from .spec import DELTA_RESOLVED, DynamicsSpec, override_spec, require_full_turn

__all__ = ["MEAN_MOMENT_RESOLVED", "DynamicsReport", "run_dynamics"]


#: ``k_dyn`` is reported only when the cycle's mean driving moment, on the exact method's fine
#: grid, exceeds this fraction of the machine's moment scale (the largest of ``|M_b|`` and
#: ``|M_red|`` over the cycle): below it the cycle needs no net drive (conservative loads such as
#: gravity alone), the mean driving moment is round-off or the quadrature error of the table
#: positions (2.6e-6 of the scale for a four-bar under gravity at 12 positions), and the ratio
#: means nothing.
MEAN_MOMENT_RESOLVED = 1e-9


@dataclass(frozen=True)
class DynamicsReport:
    """The course pipeline's results: the law of motion, reactions under the real motion and the
    coefficient of dynamics ``k_dyn = max|M_b| / |M_d|`` (None, with a note, when the cycle's mean
    driving moment on a fine grid is zero to within :data:`MEAN_MOMENT_RESOLVED` of the machine's
    moment scale: a cycle that needs no net drive has no such ratio)."""

    mechanism: Mechanism
    law: LawOfMotion
    balancing_moment: np.ndarray
    dynamic_coefficient: float | None
    comparison: dict
    notes: tuple[str, ...] = ()

    def columns(self) -> dict[str, np.ndarray]:
        """Per position: ``i`` (from 1), ``phi_deg`` (the crank angle travelled from the cycle's
        start in the direction of rotation, deg: 0 .. 360), ``reduced_moment_resistance`` (M_c)
        and ``reduced_moment_driving`` (N m, positive when they drive: the method's driving moment
        M_d -- the constant that balances the cycle (course, exact) or the motor's moment at the
        position's speed (ode) -- plus the loads declared as driving), ``reduced_inertia`` (kg m^2,
        the machine as declared: ``I_0 + I''``, without a flywheel the method adds),
        ``reduced_inertia_derivative`` (dI/dpsi, kg m^2/rad), ``omega`` (rad/s, signed), ``eps``
        (rad/s^2), ``balancing_moment`` (N m, under that motion); with friction
        ``reduced_moment_friction`` (N m, <= 0: the friction's part of M_c)."""
        red = self.law.reduced
        return {
            "i": np.arange(1, len(self.law.phi) + 1),
            "phi_deg": table_positions_deg(self.law.phi),
            "reduced_moment_resistance": red.moment_resistance,
            **({} if red.moment_friction is None else {"reduced_moment_friction": red.moment_friction}),
            "reduced_moment_driving": red.moment_driving + self.law.driving,
            "reduced_inertia": red.inertia,
            "reduced_inertia_derivative": red.inertia_derivative,
            "omega": self.law.omega,
            "eps": self.law.eps,
            "balancing_moment": self.balancing_moment,
        }

    def _friction_summary(self) -> dict[str, float]:
        """With friction: the work it takes per cycle (J) and the cycle's efficiency
        ``1 − A_friction / A_driving``, on the grid the method integrates A_c on (the table
        positions for the course method, its fine grid for the exact method and the equation of
        motion), so ``A_driving`` is the method's own."""
        law = self.law
        if law.reduced.moment_friction is None:
            return {}
        fine = law.details.get("fine_cycle")
        if fine is not None:
            red, psi, driving = fine.reduced, fine.psi, law.driving_moment * 2 * np.pi
        else:
            red, psi = law.reduced, np.abs(law.phi - law.phi[0])
            driving = float(np.trapezoid(red.moment_driving + law.driving, psi))
        lost = -float(np.trapezoid(red.moment_friction, psi))
        return {"friction_work": lost, "cycle_efficiency": 1 - lost / driving if driving > 0 else None}

    def summary(self) -> dict[str, Any]:
        """The scalar results (JSON keys of ``linkage dynamics``); ``dynamic_coefficient`` is None
        (JSON null) when the cycle needs no net drive (see :class:`DynamicsReport`)."""
        law = self.law
        return {
            "method": law.method,
            "driving_moment": law.driving_moment,
            "required_constant_inertia": law.required_constant_inertia,
            "flywheel_inertia": law.flywheel_inertia,
            "delta_actual": law.delta_actual,
            "mean_speed_actual": law.mean_speed_actual,
            "dynamic_coefficient": self.dynamic_coefficient,
            "constant_inertia": law.constant_inertia,
            **self._friction_summary(),
            **self.comparison,
        }


def run_dynamics(mech: Mechanism, method: str = "course", *, positions: int | None = None,
                 delta: float | None = None, mean_speed: float | None = None,
                 compare: bool = True, friction: bool = False, real_speed: bool = False) -> DynamicsReport:
    """The whole pipeline: law of motion by ``method``, then kinetostatics under the real motion.

    Parameters
    ----------
    method : {"course", "exact", "ode"}
        Mertsalov's course method, the exact energy method, or the equation of motion with the
        declared motor (steady state; the flywheel is sized by the exact method for ``delta``).
    positions, delta, mean_speed
        Override the declared inputs (mean speed in rad/s, signed).
    compare : bool
        Also run the exact method next to the course method and report how far apart they are
        (left out, with a note, when ``delta`` is below :data:`DELTA_RESOLVED`).
    friction : bool
        Friction in the pairs from the scheme's ``[friction]``: its reduced moment (at the mean
        speed) joins the resistance of every method, so the flywheel and the motor account for it,
        and the reactions under the real motion include it.
    real_speed : bool
        With ``friction``: compute the friction's reactions under the law of motion's own
        omega(phi) and eps(phi) instead of the mean speed, repeating the method until the required
        inertia and the driving moment change by less than :data:`REAL_SPEED_TOL` (at most
        :data:`REAL_SPEED_ROUNDS` rounds; a note says when they did not settle).

    Raises
    ------
    DynamicsInputError
        An unknown ``method`` or an argument out of range (see :func:`course_method`).
    DynamicsError
        See the method's function.
    """
    require_full_turn(mech, "the machine's dynamics")
    if method not in ("course", "exact", "ode"):
        raise DynamicsInputError(f"method must be 'course', 'exact' or 'ode', got {method!r}")
    spec = override_spec(mech, None, delta, mean_speed, positions)
    if friction:
        declared = friction_of(mech)
        if declared is None:
            raise DynamicsInputError(f"scheme '{mech.name}' declares no [friction]: add it (docs/friction.md), e.g. "
                                     "[friction] revolute = { f = 0.1, radius = 0.02 } and prismatic = { f = 0.15 }")
        spec = replace(spec, friction=declared)
    comparison: dict[str, Any] = {}
    notes: tuple[str, ...] = ()
    needed = None  # the cycle's mean driving moment on the fine grid (decides whether k_dyn exists)
    sized = None   # the ode method's flywheel, by the exact method

    def solve(spec: DynamicsSpec) -> LawOfMotion:
        nonlocal sized
        if method == "course":
            return course_method(mech, spec)
        if method == "exact":
            return exact_method(mech, spec)
        sized = exact_method(mech, spec) if spec.delta is not None else None
        return steady_state(mech, spec, constant_inertia=sized and sized.constant_inertia)

    law = solve(spec)
    if friction and real_speed:
        spec, law, settled = _friction_under_the_law(spec, law, solve)
        notes += settled
    if method == "course":
        if compare and spec.delta < DELTA_RESOLVED:
            notes += (f"delta = {spec.delta:.3g} is below what the exact method resolves ({DELTA_RESOLVED:g}): "
                      "no comparison with it",)
        elif compare:
            exact = exact_method(mech, spec)
            needed = exact.driving_moment
            comparison = {
                "exact_required_constant_inertia": exact.required_constant_inertia,
                "exact_flywheel_inertia": exact.flywheel_inertia,
                "course_vs_exact_inertia": (law.required_constant_inertia / exact.required_constant_inertia - 1
                                            if exact.required_constant_inertia > 0 else None),
                "course_delta_exact": _course_delta_exactly(spec, law, exact),
            }
    elif method == "exact":
        needed = law.driving_moment
    else:
        needed = sized and sized.driving_moment
        if spec.initial_speed is not None:
            comparison, settling_notes = _settling(mech, spec, law)
            notes += settling_notes
    if needed is None:
        needed = fine_cycle(mech, spec, FINE_SAMPLES).driving
    _, ends = cycle_positions(mech, spec)
    motion = analyze(mech, law.phi, order=2, omega=law.omega, eps=law.eps)
    reactions = solve_reactions(motion, ends=ends, friction=spec.friction)
    k_dyn, k_notes = _dynamic_coefficient(law, reactions.balancing_moment, needed)
    return DynamicsReport(mech, law, reactions.balancing_moment, k_dyn, comparison,
                          reactions.notes + notes + k_notes)


#: relative change of the required inertia and of the driving moment at which the friction under
#: the law of motion has settled
REAL_SPEED_TOL = 1e-6
#: rounds of the method with the friction under the previous round's law of motion
REAL_SPEED_ROUNDS = 12


def law_motion(law: LawOfMotion) -> Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]]:
    """``motion(phi) -> (omega, eps)``: the law's speed and acceleration at any input angle, by
    periodic cubic splines over the angle turned through its table positions."""
    rotation = law.reduced.rotation
    psi = rotation * (law.phi - law.phi[0])
    omega, eps = np.array(law.omega, float), np.array(law.eps, float)
    omega[-1], eps[-1] = omega[0], eps[0]
    speed, acceleration = (CubicSpline(psi, v, bc_type="periodic") for v in (omega, eps))

    def motion(phi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        turned = np.mod(rotation * (np.asarray(phi, float) - law.phi[0]), 2 * np.pi)
        return speed(turned), acceleration(turned)

    return motion


def _friction_under_the_law(spec: DynamicsSpec, law: LawOfMotion, solve) -> tuple[DynamicsSpec, LawOfMotion,
                                                                                   tuple[str, ...]]:
    """Repeat ``solve`` with the friction computed under the previous law of motion until the
    required inertia and the driving moment settle (:data:`REAL_SPEED_TOL`)."""
    for rounds in range(1, REAL_SPEED_ROUNDS + 1):
        spec = replace(spec, friction_motion=law_motion(law))
        new = solve(spec)
        change = max(abs(new.required_constant_inertia - law.required_constant_inertia)
                     / max(abs(law.required_constant_inertia), 1e-300),
                     abs(new.driving_moment - law.driving_moment) / max(abs(law.driving_moment), 1e-300))
        law = new
        if change <= REAL_SPEED_TOL:
            return spec, law, (f"friction under the law of motion's omega(phi), eps(phi): settled in {rounds} "
                               f"round(s) (last change {change:.1e})",)
    return spec, law, (f"friction under the law of motion's omega(phi), eps(phi): not settled after {REAL_SPEED_ROUNDS} "
                       f"rounds (last change {change:.1e} > {REAL_SPEED_TOL:g}); the results are the last round's",)


def _dynamic_coefficient(law: LawOfMotion, balancing: np.ndarray, needed: float) -> tuple[float | None,
                                                                                      tuple[str, ...]]:
    """``k_dyn = max|M_b| / |M_d|`` with the law's ``M_d``; None and a note when the cycle needs no
    net drive: its mean driving moment on the fine grid (``needed``, free of the quadrature error
    of a few table positions) is at most :data:`MEAN_MOMENT_RESOLVED` of the machine's moment
    scale (the largest ``|M_b|`` and ``|M_red|`` over the cycle)."""
    peak = float(np.max(np.abs(balancing)))
    scale = max(peak, float(np.max(np.abs(law.reduced.moment))))
    if abs(needed) > MEAN_MOMENT_RESOLVED * scale and law.driving_moment != 0:
        return peak / abs(law.driving_moment), ()
    return None, (f"coefficient of dynamics undefined: the mean driving moment ({needed:.3g} N m on a fine "
                  f"grid, {law.driving_moment:.3g} N m by the {law.method} method) is zero within "
                  f"{MEAN_MOMENT_RESOLVED:g} of the machine's moment scale ({scale:.3g} N m): the cycle needs "
                  "no net drive",)


def _settling(mech: Mechanism, spec: DynamicsSpec, law: LawOfMotion) -> tuple[dict[str, Any], tuple[str, ...]]:
    """Start-up transient from the declared initial speed: time to come within 1 % of the steady
    state's mean speed (cycle by cycle), and notes. A start-up that stalls does not undo the
    steady state: ``transient_time`` is then the time to the stall, ``settling_time`` None, and a
    note says where and why it stalls."""
    try:
        transient = simulate(mech, spec, constant_inertia=law.constant_inertia)
    except StartupStall as stalled:
        return ({"transient_cycles": int(spec.cycles), "transient_time": stalled.stall.t, "settling_time": None},
                ((f"start-up transient: {stalled.stall.words()}. The steady state does not depend on it: it is "
                  "the motion of the machine once it runs at speed"),))
    target = abs(law.details["mean_speed"])
    cycle = np.floor(transient.psi / (2 * np.pi)).astype(int)
    settled = None
    for k in range(int(cycle.max()) + 1):
        w = np.abs(transient.omega[cycle == k])
        if len(w) and abs((w.max() + w.min()) / 2 - target) <= 0.01 * target:
            settled = float(transient.t[cycle == k][0])
            break
    return {"transient_cycles": int(spec.cycles), "transient_time": float(transient.t[-1]),
            "settling_time": settled}, ()


def _course_delta_exactly(spec: DynamicsSpec, law: LawOfMotion, exact: LawOfMotion) -> float:
    """The delta a machine sized by the course method really has: the exact energy solution on
    the exact method's fine grid with the course method's constant inertia."""
    cycle = exact.details["fine_cycle"]
    wm = abs(spec.mean_speed)
    return speed_fluctuation(cycle_speeds(cycle, law.constant_inertia, wm), wm)
