"""Machine dynamics of a one-degree-of-freedom mechanism (docs/methods.md, from
"Reduced moment and moment of inertia" to "Coefficient of dynamics").

Three ways to the crank's law of motion, all on any mechanism the graph can express:

- :func:`course_method` -- the course method: constant driving moment from the cycle balance
  (trapezoid on the table positions), Mertsalov's flywheel, omega and eps by the course formulas;
- :func:`exact_method` -- the energy equation without Mertsalov's approximation on a fine grid,
  and the exact flywheel for the same coefficient of speed fluctuation;
- :func:`steady_state` / :func:`simulate` -- the equation of motion with a motor characteristic
  (:mod:`linkage.dynamics.motors`), integrated with ``scipy.integrate.solve_ivp``: a start-up transient
  over K cycles, and the periodic steady state by shooting.

:func:`run_dynamics` runs the whole course pipeline in one call: reduced characteristics, law of
motion, then the kinetostatics under the real motion and the coefficient of dynamics
``k_dyn = max|M_b| / |M_d|`` (this project's definition: the peak torque on the drive shaft over
the mean driving torque).

All reduced quantities refer to ``psi = s phi`` with ``s = sign(omega_m)``: a reduced moment is
positive when it drives, speeds ``w = |omega|`` are positive.
"""

from __future__ import annotations

import math
import sys
from dataclasses import dataclass, field, replace
from typing import Any, Mapping

import numpy as np
from scipy.integrate import solve_ivp
from scipy.interpolate import CubicSpline
from scipy.optimize import brentq

from ..errors import DynamicsError, DynamicsInputError, LinkageError, SchemeError
from ..kinematics.extremes import extreme_positions, table_angles
from ..kinematics.motion import analyze, table_positions_deg
from ..kinetostatics.reactions import solve_reactions
from ..model.mechanism import (
    MAX_MAGNITUDE,
    MAX_POSITIONS,
    MIN_MAGNITUDE,
    Mechanism,
    _is_number,
    check_number,
    unknown_keys,
)
from ..model.scheme import register_section, section_of
from .motors import RPM, ConstantMotor, motor_from_spec, starting_moment
from .reduced import Reduced, reduced_characteristics

__all__ = [
    "DynamicsError",
    "DynamicsInputError",
    "DynamicsSpec",
    "LawOfMotion",
    "Transient",
    "dynamics_of",
    "course_method",
    "exact_method",
    "simulate",
    "steady_state",
    "run_dynamics",
    "DynamicsReport",
]


#: The exact energy method resolves ``delta`` from speeds computed in float64: each carries a
#: relative rounding error of ~1e-16, so the computed delta is uncertain by ~1e-16 and the
#: constant inertia found for it by ~1e-16 / delta relative (measured on course_slider_crank
#: against the linear limit of Mertsalov's method: 1e-11 at delta = 1e-6, 1.2e-7 at 1e-9). Below
#: this delta the answer would be mostly rounding: :func:`exact_method` refuses it (Mertsalov's
#: :func:`course_method`, exact in the limit delta -> 0, has no such floor).
DELTA_RESOLVED = 1e-9

#: ``k_dyn`` is reported only when the cycle's mean driving moment, on the exact method's fine
#: grid, exceeds this fraction of the machine's moment scale (the largest of ``|M_b|`` and
#: ``|M_red|`` over the cycle): below it the cycle needs no net drive (conservative loads such as
#: gravity alone), the mean driving moment is round-off or the quadrature error of the table
#: positions (2.6e-6 of the scale for a four-bar under gravity at 12 positions), and the ratio
#: means nothing.
MEAN_MOMENT_RESOLVED = 1e-9


def _real(value: Any) -> bool:
    """A finite real number (not a bool)."""
    return (isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, (bool, np.bool_))
            and math.isfinite(value))


def _require(ok: bool, name: str, value: Any, rule: str) -> None:
    if not ok:
        raise DynamicsInputError(f"{name} must be {rule}, got {value!r}")


def _require_count(name: str, value: Any) -> None:
    _require(isinstance(value, (int, np.integer)) and not isinstance(value, (bool, np.bool_)) and value >= 1,
             name, value, "a positive integer")


def _check_spec(spec: DynamicsSpec) -> DynamicsSpec:
    """``spec`` after checking every value the solvers rely on (DynamicsInputError naming the first
    bad one): the same rules whether the spec came from a scheme file or was built in Python."""
    if not isinstance(spec, DynamicsSpec):
        raise DynamicsInputError(f"spec must be a DynamicsSpec, got {spec!r}")
    w = spec.mean_speed
    _require(_real(w) and w != 0, "mean_speed", w, "a finite nonzero number (rad/s; its sign is the rotation)")
    w2 = float(w) * float(w)  # python floats: inf or 0.0 on overflow, never an exception
    _require(math.isfinite(w2) and w2 >= sys.float_info.min, "mean_speed", w,
             "a speed whose square (the scale of the kinetic energy) float64 holds: "
             f"{math.sqrt(sys.float_info.min):.3g} <= |mean_speed| <= {math.sqrt(sys.float_info.max):.3g} rad/s")
    _require(spec.delta is None or (_real(spec.delta) and spec.delta > 0), "delta", spec.delta,
             "a finite number > 0 (the coefficient of speed fluctuation)")
    _require_count("positions", spec.positions)
    _require_count("cycles", spec.cycles)
    for name in ("inertia_0", "flywheel"):
        value = getattr(spec, name)
        _require(_real(value) and value >= 0, name, value, "a finite number >= 0 (kg m^2)")
    for i, rotor in enumerate(spec.rotors):
        ok = isinstance(rotor, tuple) and len(rotor) == 2 and _real(rotor[0]) and rotor[0] >= 0 and _real(rotor[1])
        _require(ok, f"rotors[{i}]", rotor, "(inertia >= 0 in kg m^2, finite gear ratio U)")
    _require(math.isfinite(spec.constant_inertia), "the constant inertia inertia_0 + sum(J U^2) + flywheel",
             spec.constant_inertia, "finite in float64 (kg m^2)")
    _require(spec.initial_speed is None or (_real(spec.initial_speed) and spec.initial_speed >= 0), "initial_speed",
             spec.initial_speed, "a finite number >= 0 (|omega| at the start, rad/s; 0: from rest)")
    _require(spec.motor is None or callable(spec.motor), "motor", spec.motor,
             "a motor characteristic motor(w) -> M (linkage.dynamics.motors)")
    return spec


def _kinetic_energy(inertia: float, speed: float, what: str) -> float:
    """``inertia speed^2 / 2`` (J) in float64; DynamicsError naming ``what`` when it overflows."""
    energy = float(inertia) * float(speed) * float(speed) / 2  # python floats: inf, never an exception
    if not math.isfinite(energy) or (energy == 0 and inertia != 0 and speed != 0):
        raise DynamicsError(f"{what}: the kinetic energy I w^2 / 2 = {float(inertia):.6g} kg m^2 x "
                            f"({float(speed):.6g} rad/s)^2 / 2 {'underflows' if energy == 0 else 'overflows'} "
                            "float64")
    return energy


# ----------------------------------------------------------------------------------------------
# inputs
# ----------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class DynamicsSpec:
    """Dynamics inputs of a machine (the ``[dynamics]`` section of a scheme).

    Attributes
    ----------
    mean_speed : float
        Mean angular velocity of the input link, rad/s, signed (negative: clockwise).
    delta : float or None
        Target coefficient of speed fluctuation ``(omega_max - omega_min) / omega_m``.
    positions : int
        Table positions per revolution (course method).
    start : "extreme" or float
        Start of the cycle: the output's extreme position, or an input angle in degrees.
    inertia_0 : float
        Constant inertia reduced to the input besides the input link's own, kg m^2.
    rotors : tuple of (inertia, ratio)
        Rotors and gears, reduced as ``J U^2`` (U = rotor speed / input speed).
    flywheel : float
        An installed flywheel on the input shaft, kg m^2.
    motor : callable or None
        Motor characteristic reduced to the input (:mod:`linkage.dynamics.motors`).
    initial_speed : float or None
        Initial |omega| of the start-up transient, rad/s; 0 starts from rest (the motor needs a
        starting torque, see :func:`simulate`).
    cycles : int
        Cycles of the start-up transient.
    """

    mean_speed: float
    delta: float | None = None
    positions: int = 12
    start: Any = "extreme"
    inertia_0: float = 0.0
    rotors: tuple[tuple[float, float], ...] = ()
    flywheel: float = 0.0
    motor: Any = None
    initial_speed: float | None = None
    cycles: int = 10

    @property
    def rotation(self) -> int:
        return 1 if self.mean_speed > 0 else -1

    @property
    def constant_inertia(self) -> float:
        """Declared constant inertia at the input besides the input link's own, kg m^2."""
        return self.inertia_0 + sum(j * u * u for j, u in self.rotors) + self.flywheel


#: Largest number of cycles of a start-up transient a scheme may declare (the integration time
#: grows with it); the largest number of table positions is :data:`linkage.model.mechanism.MAX_POSITIONS`.
MAX_CYCLES = 1_000


def _count(raw: Mapping[str, Any], key: str, largest: int, problems: list[str]) -> int | None:
    v = raw[key]
    if isinstance(v, int) and not isinstance(v, bool) and 1 <= v <= largest:
        return v
    problems.append(f"{key} must be a whole number in [1, {largest}], got {v!r}")
    return None


def parse_dynamics(mech: Mechanism, raw: Mapping[str, Any] | None) -> tuple[DynamicsSpec | None, list[str]]:
    """The dynamics inputs and the list of problems from a scheme's ``[dynamics]`` table.

    Every number is checked against its range (``schemes/README.md``, "Ranges"): speeds nonzero
    and within [1e-50, 1e50] in magnitude, ``delta`` in [DELTA_RESOLVED, 2), inertias >= 0,
    ``positions`` and ``cycles`` whole numbers up to :data:`MAX_POSITIONS` / :data:`MAX_CYCLES`.
    A cycle that starts at the output's extreme position needs the output to have one: it is
    found here, once.
    """
    if raw is None:
        return None, []
    if not isinstance(raw, Mapping):
        return None, [f"expected a table, got {raw!r}"]
    known = {"mean_speed", "mean_rpm", "delta", "positions", "start_deg", "inertia_0", "rotors",
             "flywheel", "motor", "initial_speed", "initial_rpm", "cycles"}
    problems: list[str] = []
    if unknown_keys(raw, known, "", problems):
        return None, problems
    if ("mean_speed" in raw) == ("mean_rpm" in raw):
        problems.append("give exactly one of mean_speed (rad/s, signed) or mean_rpm (signed)")
        return None, problems
    key = "mean_speed" if "mean_speed" in raw else "mean_rpm"
    speed = check_number(raw[key], "", f"{key} (signed: the sign is the rotation)", problems,
                         "nonzero", "rad/s" if key == "mean_speed" else "rpm")
    args: dict[str, Any] = {"mean_speed": (speed or 1.0) * (RPM if key == "mean_rpm" else 1.0)}
    if "delta" in raw:
        v = raw["delta"]
        if _is_number(v) and DELTA_RESOLVED <= v < 2:
            args["delta"] = float(v)
        else:
            problems.append(f"delta must be a number in [{DELTA_RESOLVED:g}, 2) ((omega_max - "
                            f"omega_min) / omega_m; below {DELTA_RESOLVED:g} it is rounding), got {v!r}")
    for key in ("inertia_0", "flywheel"):
        if key in raw:
            args[key] = check_number(raw[key], "", key, problems, "nonnegative", "kg m^2")
    for key, largest in (("positions", MAX_POSITIONS), ("cycles", MAX_CYCLES)):
        if key in raw:
            args[key] = _count(raw, key, largest, problems)
    if "start_deg" in raw and mech.input_range is not None:
        a, b = np.degrees(mech.input_range)
        problems.append(f"start_deg = {raw['start_deg']!r}: the scheme declares range_deg = [{a:.10g}, {b:.10g}], "
                        f"whose first end ({a:.10g} deg) is position 1; start_deg applies to a full turn")
    elif "start_deg" in raw:
        args["start"] = check_number(raw["start_deg"], "", "start_deg", problems, "angle_deg", "deg")
    elif mech.input_range is not None:
        pass  # position 1 is the range's first end
    elif mech.output is None:
        problems.append("the cycle starts at the output's extreme position: declare an output "
                        "or start_deg")
    else:
        try:
            extreme_positions(mech)
        except (LinkageError, ValueError) as exc:
            problems.append(f"the cycle starts at the output's extreme position, but {exc}: "
                            "declare start_deg")
    rotors = []
    raw_rotors = raw.get("rotors", [])
    if not isinstance(raw_rotors, list):
        problems.append(f"rotors: expected a list of {{inertia = J (kg m^2), ratio = U}}, got {raw_rotors!r}")
        raw_rotors = []
    for i, r in enumerate(raw_rotors):
        where = f"rotors[{i}]"
        if not isinstance(r, Mapping):
            problems.append(f"{where}: expected {{inertia = J (kg m^2), ratio = U}}, got {r!r}")
            continue
        if unknown_keys(r, {"inertia", "ratio"}, where, problems):
            continue
        inertia = check_number(r.get("inertia"), where, "inertia", problems, "nonnegative", "kg m^2")
        ratio = check_number(r.get("ratio", 1.0), where, "ratio", problems, "real")
        if inertia is not None and ratio is not None:
            rotors.append((inertia, ratio))
    args["rotors"] = tuple(rotors)
    start_key = None
    if "initial_speed" in raw and "initial_rpm" in raw:
        problems.append("give either initial_speed (rad/s) or initial_rpm (rpm), not both")
    elif "initial_speed" in raw or "initial_rpm" in raw:
        start_key = "initial_speed" if "initial_speed" in raw else "initial_rpm"
        v = raw[start_key]
        unit = "rad/s" if start_key == "initial_speed" else "rpm"
        if _is_number(v) and (v == 0 or MIN_MAGNITUDE <= v <= MAX_MAGNITUDE):
            args["initial_speed"] = float(v) * (RPM if start_key == "initial_rpm" else 1.0)
        else:
            problems.append(f"{start_key} (|omega| at the start of the transient) must be 0 (from rest) or a "
                            f"number in [{MIN_MAGNITUDE:g}, {MAX_MAGNITUDE:g}] {unit}, got {v!r}")
    if "motor" in raw:
        motor, motor_problems = motor_from_spec(raw["motor"])
        problems += motor_problems
        args["motor"] = motor
        if motor is not None and args.get("initial_speed") == 0:
            m0 = starting_moment(motor)
            if not m0 > 0:
                kind = raw["motor"].get("kind")
                problems.append(f"{start_key} = {raw[start_key]!r} starts from rest, but the {kind} "
                                f"motor has no starting torque: its moment at rest is {m0:.6g} N m at the input "
                                "(a start from rest needs one > 0: a linear motor with stall_moment > 0, an "
                                "induction motor); give a start speed > 0")
    return (DynamicsSpec(**args) if not problems else None), problems


def dynamics_of(mech: Mechanism) -> DynamicsSpec:
    """The dynamics inputs a mechanism declares (its ``[dynamics]`` section).

    Parsed once (when the scheme is loaded, or on first use) and kept on the mechanism.

    Raises
    ------
    SchemeError
        When the section is declared wrongly, or when the mechanism declares none.
    """
    spec = section_of(mech, "dynamics")
    if spec is None:
        raise SchemeError(f"mechanism '{mech.name}' declares no [dynamics] section (mean speed, delta, ...)")
    return spec


register_section("dynamics", parse_dynamics)


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
    def mean_speed_actual(self) -> float:
        return float(np.sign(self.omega[0]) * (np.max(np.abs(self.omega)) + np.min(np.abs(self.omega))) / 2)


def _require_full_turn(mech: Mechanism, what: str) -> None:
    """DynamicsInputError when ``mech`` is analysed over a partial input range: ``what`` (a cycle
    of the machine's dynamics) needs its input to turn fully."""
    if mech.input_range is not None:
        a, b = np.degrees(mech.input_range)
        raise DynamicsInputError(
            f"mechanism '{mech.name}': {what} needs the input to turn fully (one cycle is one turn), but the "
            f"scheme declares range_deg = [{a:.10g}, {b:.10g}]: its input turns only over that range. Its "
            "kinematics and forces are analysed over the range ('linkage analyze', 'linkage forces'); for "
            "the cycle dynamics leave range_deg out of a mechanism whose input turns fully")


def _cycle(mech: Mechanism, spec: DynamicsSpec, positions: int | None = None):
    n = spec.positions if positions is None else positions
    phi = table_angles(mech, n, spec.start, spec.rotation)
    ends = np.zeros(n + 1, bool)
    ends[-1] = True
    return phi, ends


def _eps(reduced: Reduced, driving: float | np.ndarray, inertia: np.ndarray, w: np.ndarray) -> np.ndarray:
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
    _require_full_turn(mech, "the course method (Mertsalov)")
    spec = _override(mech, spec, delta, mean_speed, positions)
    if spec.delta is None:
        raise DynamicsInputError(f"mechanism '{mech.name}': the course method needs delta (the coefficient of "
                                 "speed fluctuation): declare it in [dynamics] or pass delta=")
    phi, ends = _cycle(mech, spec)
    n = len(phi) - 1
    red = reduced_characteristics(mech, phi, spec.rotation, extra_inertia=spec.constant_inertia, ends=ends)
    step = 2 * np.pi / n
    work = np.concatenate([[0.0], np.cumsum((red.moment[1:] + red.moment[:-1]) / 2 * step)])
    driving = -work[-1] / (2 * np.pi)
    psi = np.arange(n + 1) * step
    energy = driving * psi + work  # Delta T
    wm = abs(spec.mean_speed)
    wm2 = wm * wm
    _kinetic_energy(red.inertia_constant + float(np.max(red.inertia_variable)), wm, f"mechanism '{mech.name}'")
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
                       spec.rotation * w, _eps(red, driving, inertia, w),
                       {"work_resistance": work, "energy_change": energy, "energy_links": energy_links,
                        "energy_flywheel": energy_flywheel, "energy_swing": swing})


def _override(mech, spec, delta, mean_speed, positions=None) -> DynamicsSpec:
    """The declared (or given) inputs with the arguments that override them, all checked."""
    if spec is None:
        if mech.extra.get("dynamics") is None and mean_speed is not None:
            _require(_real(mean_speed) and mean_speed != 0, "mean_speed", mean_speed,
                     "a finite nonzero number (rad/s; its sign is the rotation)")
            spec = DynamicsSpec(mean_speed=float(mean_speed))
        else:
            spec = dynamics_of(mech)
    changes: dict[str, Any] = {}
    if delta is not None:
        _require(_real(delta) and delta < 2, "delta", delta,
                 "a number in (0, 2) (the coefficient of speed fluctuation (w_max - w_min) / w_m)")
        changes["delta"] = float(delta)
    if mean_speed is not None:
        _require(_real(mean_speed), "mean_speed", mean_speed, "a finite nonzero number (rad/s; its sign is the "
                                                             "rotation)")
        changes["mean_speed"] = float(mean_speed)
    if positions is not None:
        changes["positions"] = positions
    return _check_spec(replace(spec, **changes))


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


def _fine_cycle(mech: Mechanism, spec: DynamicsSpec, samples: int) -> _Cycle:
    n = spec.positions * max(1, math.ceil(samples / spec.positions))
    phi, ends = _cycle(mech, spec, n)
    red = reduced_characteristics(mech, phi, spec.rotation, extra_inertia=spec.constant_inertia, ends=ends)
    psi = np.arange(n + 1) * 2 * np.pi / n
    work = np.concatenate([[0.0], np.cumsum((red.moment[1:] + red.moment[:-1]) / 2 * np.diff(psi))])
    driving = -work[-1] / (2 * np.pi)
    return _Cycle(psi, red, float(driving), driving * psi + work)


def _speeds(cycle: _Cycle, constant: float, mean: float) -> np.ndarray | None:
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


def _delta(w: np.ndarray | None, mean: float) -> float:
    """Coefficient of speed fluctuation; 2 where the mean speed is out of reach (the limit of
    ``(w_max - 0) / ((w_max + 0) / 2)``, so the function stays continuous for root finding)."""
    if w is None:
        return 2.0
    return float((np.max(w) - np.min(w)) / mean)


_FINE_SAMPLES = 3600  # grid of the exact method (and of the cycle balance that decides k_dyn)


def exact_method(mech: Mechanism, spec: DynamicsSpec | None = None, *, positions: int | None = None,
                 delta: float | None = None, mean_speed: float | None = None,
                 samples: int = _FINE_SAMPLES) -> LawOfMotion:
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
    _require_full_turn(mech, "the exact energy method")
    spec = _override(mech, spec, delta, mean_speed, positions)
    _require_count("samples", samples)
    if spec.delta is not None and spec.delta < DELTA_RESOLVED:
        raise DynamicsInputError(f"delta = {spec.delta!r} is below what the exact energy method resolves in "
                                 f"float64 (delta >= {DELTA_RESOLVED:g}: speeds carry rounding of ~1e-16 "
                                 "relative); use the course method, exact in the limit delta -> 0")
    cycle = _fine_cycle(mech, spec, samples)
    wm = abs(spec.mean_speed)
    base = cycle.reduced.inertia_constant
    _kinetic_energy(base + float(np.max(cycle.reduced.inertia_variable)), wm, f"mechanism '{mech.name}'")
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
        fluctuation = lambda c: _delta(_speeds(cycle, c, wm), wm) - spec.delta  # noqa: E731
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
    w = _speeds(cycle, constant, wm)
    if w is None:
        raise DynamicsError(f"mechanism '{mech.name}': with the constant inertia {constant:.6g} kg m^2 "
                            f"the machine cannot keep the mean speed {wm:.6g} rad/s: give delta to size "
                            "a flywheel")
    stride = (len(cycle.psi) - 1) // spec.positions
    pick = slice(None, None, stride)
    red = _pick(cycle.reduced, pick)
    w_table = w[pick]
    return LawOfMotion("exact", red.phi, red, cycle.driving, float(required),
                       None if flywheel is None else float(flywheel), _delta(w, wm), float(constant),
                       spec.rotation * w_table,
                       _eps(red, cycle.driving, constant + red.inertia_variable, w_table),
                       {"samples": len(cycle.psi) - 1, "fine_cycle": cycle})


def _pick(red: Reduced, index) -> Reduced:
    return Reduced(red.phi[index], red.rotation, red.moment_resistance[index], red.moment_driving[index],
                   red.inertia_constant, red.inertia_variable[index], red.inertia_derivative[index])


# ----------------------------------------------------------------------------------------------
# the equation of motion with a motor
# ----------------------------------------------------------------------------------------------


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


class _Equation:
    """``I(psi) w dw/dpsi + I'(psi) w^2 / 2 = M_d(w) + M(psi)`` in the energy form
    ``dT/dpsi = M_d(w) + M(psi)`` with ``w = sqrt(2 T / I)``; ``dt/dpsi = 1 / w``.

    ``scale`` is the kinetic energy ``I_max w_m^2 / 2`` at the declared mean speed and ``work``
    the work scale of the loads ``2 pi max|M|`` (the size of the energy changes over a cycle);
    :func:`_integrate` takes its tolerances from them and from its own initial state."""

    def __init__(self, mech: Mechanism, spec: DynamicsSpec, motor, constant: float, samples: int = 720):
        cycle = _fine_cycle(mech, spec, samples)
        psi = cycle.psi
        inertia = constant + cycle.reduced.inertia_variable
        inertia[-1] = inertia[0]
        # the problem's own scales: every tolerance of the integration is relative to them
        self.scale = _kinetic_energy(float(np.max(inertia)), spec.mean_speed, f"mechanism '{mech.name}'")
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


def _raise_events(sol, eq: _Equation, what: str) -> None:
    if sol.status == -1:
        raise DynamicsError(f"{what}: the integration failed ({sol.message})")
    if len(sol.t_events[0]):
        psi = sol.t_events[0][0]
        raise DynamicsError(f"{what}: the machine stalls (omega -> 0) at psi = {math.degrees(psi):.1f} deg "
                            f"after {sol.y_events[0][0][1]:.3g} s: the motor cannot overcome the load")
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
    _require(_real(rtol) and _RTOL_MIN <= rtol < 1, "rtol", rtol,
             f"a relative tolerance in [{_RTOL_MIN:.3g}, 1) (float64 cannot meet a tighter one)")
    _require(atol is None or (_real(atol) and atol > 0), "atol", atol, "None or a number > 0 (J)")
    _require_count("samples", samples)
    _require(constant_inertia is None or (_real(constant_inertia) and constant_inertia >= 0), "constant_inertia",
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
    DynamicsError
        On stall or run-away (or a start from rest whose starting torque does not overcome the
        resistance at position 1), or when the kinetic energy overflows float64; a mechanism
        analysed over a partial input range (``range_deg``) has no cycle (DynamicsInputError).
    """
    _require_full_turn(mech, "the start-up transient")
    spec = _check_spec(dynamics_of(mech) if spec is None else spec)
    w0 = initial_speed if initial_speed is not None else spec.initial_speed
    _require(_real(w0) and w0 >= 0, "initial_speed", w0, "a finite number >= 0 (|omega| at the start of the "
                                                        "transient, rad/s; 0: from rest)")
    if cycles is not None:
        _require_count("cycles", cycles)
    _check_ode_args(rtol, atol, samples, constant_inertia)
    constant = _default_constant(mech, spec) if constant_inertia is None else float(constant_inertia)
    eq = _Equation(mech, spec, None, constant, samples)
    eq.motor = _motor_of(spec, eq.cycle.driving)
    name = f"mechanism '{mech.name}' transient"
    limit = _speed_limit(spec, eq.motor)
    if w0 == 0:
        return _from_rest(eq, spec, cycles or spec.cycles, rtol, atol, limit, name,
                          declared=spec.motor is not None)
    energy0 = _kinetic_energy(float(eq.inertia(0.0)), w0, f"{name} (initial_speed)")
    sol = _integrate(eq, energy0, cycles or spec.cycles, rtol, atol, limit)
    _raise_events(sol, eq, name)
    w = eq.speed(sol.t, energy0 + sol.y[0])
    return Transient(sol.t, sol.y[1], spec.rotation * w, sol.sol, sol.message)


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
        raise DynamicsError(f"{name}: the machine does not start from rest: the starting torque {starting:.6g} N m "
                            f"does not overcome the resisting moment {-resisting:.6g} N m at the cycle's start "
                            "(position 1)")
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
    if first.status == -1:
        raise DynamicsError(f"{name}: the integration from rest failed ({first.message})")
    if len(first.t_events[1]):
        raise DynamicsError(f"{name}: the machine stalls (omega -> 0) after {first.t_events[1][0]:.3g} s, within "
                            f"the first {math.degrees(REST_START_ANGLE):g} deg from rest: the motor cannot "
                            "overcome the load")
    if len(first.t_events[2]):
        raise DynamicsError(f"{name}: the machine runs away (|omega| above the speed limit) within the first "
                            f"{math.degrees(REST_START_ANGLE):g} deg from rest")
    if not len(first.t_events[0]):
        raise DynamicsError(f"{name}: the machine does not turn {math.degrees(REST_START_ANGLE):g} deg from rest "
                            f"within {first.t[-1]:.3g} s")
    t_switch = float(first.t_events[0][0])
    psi_switch, w_switch = (float(v) for v in first.y_events[0][0])
    energy = _kinetic_energy(float(eq.inertia(psi_switch)), w_switch, name)
    sol = _integrate(eq, energy, cycles, rtol, atol, limit, psi0=psi_switch, t0=t_switch)
    _raise_events(sol, eq, name)
    keep = first.t < t_switch
    psi = np.concatenate([first.y[0][keep], sol.t])
    t = np.concatenate([first.t[keep], sol.y[1]])
    w = np.concatenate([first.y[1][keep], eq.speed(sol.t, energy + sol.y[0])])
    return Transient(psi, t, spec.rotation * w, _RestStart(first.sol, t_switch, psi_switch, eq, sol.sol),
                     sol.message)


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
    _require_full_turn(mech, "the steady state of the equation of motion")
    spec = _check_spec(dynamics_of(mech) if spec is None else spec)
    if positions is not None:
        spec = _check_spec(replace(spec, positions=positions))
    _check_ode_args(rtol, None, samples, constant_inertia)
    _require_count("max_iterations", max_iterations)
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
        w = _speeds(eq.cycle, constant, abs(spec.mean_speed))
        if w is None:
            raise DynamicsError(f"{name}: with the constant inertia {constant:.6g} kg m^2 the machine cannot "
                                f"keep the mean speed {abs(spec.mean_speed):.6g} rad/s (it would stop "
                                "within the cycle): add a flywheel")
        energy0 = _kinetic_energy(i0, float(w[0]), name)
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
        energy0 = _kinetic_energy(i0, guess, name)
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
    phi, ends = _cycle(mech, spec, n)
    psi = np.arange(n + 1) * 2 * np.pi / n
    red = reduced_characteristics(mech, phi, spec.rotation, extra_inertia=spec.constant_inertia, ends=ends)
    inertia = constant + red.inertia_variable
    w = np.sqrt(2 * sol.sol(psi)[0] / inertia)
    fine = np.linspace(0, 2 * np.pi, 20 * n + 1)
    w_fine = eq.speed(fine, sol.sol(fine)[0])
    mean = (np.max(w_fine) + np.min(w_fine)) / 2
    driving_table = motor(w)
    cycle_mean = float(np.mean(motor(w_fine[:-1])))  # one period: psi = 2 pi is psi = 0
    flywheel = constant - red.inertia_constant
    return LawOfMotion("ode", phi, red, cycle_mean, float(constant), flywheel if flywheel > 0 else None,
                       _delta(w_fine, mean), float(constant),
                       spec.rotation * w, _eps(red, driving_table, inertia, w),
                       {"mean_speed": float(spec.rotation * mean), "period": float(sol.y[1][-1])})


# ----------------------------------------------------------------------------------------------
# the whole pipeline
# ----------------------------------------------------------------------------------------------


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
        start in the direction of rotation, deg: 0 .. 360), ``reduced_moment_resistance`` and
        ``reduced_moment_driving`` (N m, positive when they drive), ``reduced_inertia`` (kg m^2,
        the machine as declared: ``I_0 + I''``, without a flywheel the method adds),
        ``reduced_inertia_derivative`` (dI/dpsi, kg m^2/rad), ``omega`` (rad/s, signed), ``eps``
        (rad/s^2), ``balancing_moment`` (N m, under that motion)."""
        red = self.law.reduced
        return {
            "i": np.arange(1, len(self.law.phi) + 1),
            "phi_deg": table_positions_deg(self.law.phi),
            "reduced_moment_resistance": red.moment_resistance,
            "reduced_moment_driving": red.moment_driving,
            "reduced_inertia": red.inertia,
            "reduced_inertia_derivative": red.inertia_derivative,
            "omega": self.law.omega,
            "eps": self.law.eps,
            "balancing_moment": self.balancing_moment,
        }

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
            **self.comparison,
        }


def run_dynamics(mech: Mechanism, method: str = "course", *, positions: int | None = None,
                 delta: float | None = None, mean_speed: float | None = None,
                 compare: bool = True) -> DynamicsReport:
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

    Raises
    ------
    DynamicsInputError
        An unknown ``method`` or an argument out of range (see :func:`course_method`).
    DynamicsError
        See the method's function.
    """
    _require_full_turn(mech, "the machine's dynamics")
    if method not in ("course", "exact", "ode"):
        raise DynamicsInputError(f"method must be 'course', 'exact' or 'ode', got {method!r}")
    spec = _override(mech, None, delta, mean_speed, positions)
    comparison: dict[str, Any] = {}
    notes: tuple[str, ...] = ()
    needed = None  # the cycle's mean driving moment on the fine grid (decides whether k_dyn exists)
    if method == "course":
        law = course_method(mech, spec)
        if compare and spec.delta < DELTA_RESOLVED:
            notes += (f"delta = {spec.delta:.3g} is below what the exact method resolves ({DELTA_RESOLVED:g}): "
                      "no comparison with it",)
        elif compare:
            exact = exact_method(mech, spec)
            needed = exact.driving_moment
            comparison = {
                "exact_required_constant_inertia": exact.required_constant_inertia,
                "exact_flywheel_inertia": exact.flywheel_inertia,
                "course_vs_exact_inertia": law.required_constant_inertia / exact.required_constant_inertia - 1,
                "course_delta_exact": _course_delta_exactly(spec, law, exact),
            }
    elif method == "exact":
        law = exact_method(mech, spec)
        needed = law.driving_moment
    else:
        sized = exact_method(mech, spec) if spec.delta is not None else None
        law = steady_state(mech, spec, constant_inertia=sized and sized.constant_inertia)
        needed = sized and sized.driving_moment
        if spec.initial_speed is not None:
            comparison = _settling(mech, spec, law)
    if needed is None:
        needed = _fine_cycle(mech, spec, _FINE_SAMPLES).driving
    _, ends = _cycle(mech, spec)
    motion = analyze(mech, law.phi, order=2, omega=law.omega, eps=law.eps)
    reactions = solve_reactions(motion, ends=ends)
    k_dyn, k_notes = _dynamic_coefficient(law, reactions.balancing_moment, needed)
    return DynamicsReport(mech, law, reactions.balancing_moment, k_dyn, comparison,
                          reactions.notes + notes + k_notes)


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


def _settling(mech: Mechanism, spec: DynamicsSpec, law: LawOfMotion) -> dict[str, Any]:
    """Start-up transient from the declared initial speed: time to come within 1 % of the steady
    state's mean speed (cycle by cycle)."""
    transient = simulate(mech, spec, constant_inertia=law.constant_inertia)
    target = abs(law.details["mean_speed"])
    cycle = np.floor(transient.psi / (2 * np.pi)).astype(int)
    settled = None
    for k in range(int(cycle.max()) + 1):
        w = np.abs(transient.omega[cycle == k])
        if len(w) and abs((w.max() + w.min()) / 2 - target) <= 0.01 * target:
            settled = float(transient.t[cycle == k][0])
            break
    return {"transient_cycles": int(spec.cycles), "transient_time": float(transient.t[-1]),
            "settling_time": settled}


def _course_delta_exactly(spec: DynamicsSpec, law: LawOfMotion, exact: LawOfMotion) -> float:
    """The delta a machine sized by the course method really has: the exact energy solution on
    the exact method's fine grid with the course method's constant inertia."""
    cycle = exact.details["fine_cycle"]
    wm = abs(spec.mean_speed)
    return _delta(_speeds(cycle, law.constant_inertia, wm), wm)
