"""The ``[dynamics]`` section of a scheme: a machine's dynamics inputs and their checks.

:class:`DynamicsSpec` holds the inputs (mean speed, coefficient of speed fluctuation, table
positions, the cycle's start, constant inertias, motor, start-up); :func:`parse_dynamics` reads
them from a scheme's ``[dynamics]`` table (registered as the section's parser) and
:func:`dynamics_of` gives the ones a mechanism declares. The checks the dynamics solvers share:
:func:`check_spec` (the same rules for a spec from a file or built in Python),
:func:`override_spec` (the declared inputs with a call's overrides), :func:`require_full_turn`
(a cycle needs the input to turn fully) and :func:`kinetic_energy` (``I w^2 / 2`` within float64).
"""

from __future__ import annotations

import math
import sys
from dataclasses import dataclass, replace
from typing import Any, Mapping

import numpy as np

from ..errors import DynamicsError, DynamicsInputError, LinkageError, SchemeError
from ..kinematics.extremes import extreme_positions
from ..model.mechanism import Mechanism
from ..model.numbers import MAX_MAGNITUDE, MAX_POSITIONS, MIN_MAGNITUDE, check_number, is_number, unknown_keys
from ..model.scheme import register_section, section_of
from .motors import RPM, motor_from_spec, starting_moment

__all__ = ["DELTA_RESOLVED", "MAX_CYCLES", "DynamicsSpec", "dynamics_of", "parse_dynamics"]


#: The exact energy method resolves ``delta`` from speeds computed in float64: each carries a
#: relative rounding error of ~1e-16, so the computed delta is uncertain by ~1e-16 and the
#: constant inertia found for it by ~1e-16 / delta relative (measured on course_slider_crank
#: against the linear limit of Mertsalov's method: 1e-11 at delta = 1e-6, 1.2e-7 at 1e-9). Below
#: this delta the answer would be mostly rounding: :func:`~.cycle.exact_method` refuses it (Mertsalov's
#: :func:`~.cycle.course_method`, exact in the limit delta -> 0, has no such floor).
DELTA_RESOLVED = 1e-9


def is_real(value: Any) -> bool:
    """A finite real number (not a bool)."""
    return (isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, (bool, np.bool_))
            and math.isfinite(value))


def require(ok: bool, name: str, value: Any, rule: str) -> None:
    if not ok:
        raise DynamicsInputError(f"{name} must be {rule}, got {value!r}")


def require_count(name: str, value: Any) -> None:
    require(isinstance(value, (int, np.integer)) and not isinstance(value, (bool, np.bool_)) and value >= 1,
            name, value, "a positive integer")


def check_spec(spec: DynamicsSpec) -> DynamicsSpec:
    """``spec`` after checking every value the solvers rely on (DynamicsInputError naming the first
    bad one): the same rules whether the spec came from a scheme file or was built in Python."""
    if not isinstance(spec, DynamicsSpec):
        raise DynamicsInputError(f"spec must be a DynamicsSpec, got {spec!r}")
    w = spec.mean_speed
    require(is_real(w) and w != 0, "mean_speed", w, "a finite nonzero number (rad/s; its sign is the rotation)")
    w2 = float(w) * float(w)  # python floats: inf or 0.0 on overflow, never an exception
    require(math.isfinite(w2) and w2 >= sys.float_info.min, "mean_speed", w,
            "a speed whose square (the scale of the kinetic energy) float64 holds: "
            f"{math.sqrt(sys.float_info.min):.3g} <= |mean_speed| <= {math.sqrt(sys.float_info.max):.3g} rad/s")
    require(spec.delta is None or (is_real(spec.delta) and spec.delta > 0), "delta", spec.delta,
            "a finite number > 0 (the coefficient of speed fluctuation)")
    require_count("positions", spec.positions)
    require_count("cycles", spec.cycles)
    for name in ("inertia_0", "flywheel"):
        value = getattr(spec, name)
        require(is_real(value) and value >= 0, name, value, "a finite number >= 0 (kg m^2)")
    for i, rotor in enumerate(spec.rotors):
        ok = isinstance(rotor, tuple) and len(rotor) == 2 and is_real(rotor[0]) and rotor[0] >= 0 and is_real(rotor[1])
        require(ok, f"rotors[{i}]", rotor, "(inertia >= 0 in kg m^2, finite gear ratio U)")
    require(math.isfinite(spec.constant_inertia), "the constant inertia inertia_0 + sum(J U^2) + flywheel",
            spec.constant_inertia, "finite in float64 (kg m^2)")
    require(spec.initial_speed is None or (is_real(spec.initial_speed) and spec.initial_speed >= 0), "initial_speed",
            spec.initial_speed, "a finite number >= 0 (|omega| at the start, rad/s; 0: from rest)")
    require(spec.motor is None or callable(spec.motor), "motor", spec.motor,
            "a motor characteristic motor(w) -> M (linkage.dynamics.motors)")
    return spec


def kinetic_energy(inertia: float, speed: float, what: str) -> float:
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
        starting torque, see :func:`~.equation.simulate`).
    cycles : int
        Cycles of the start-up transient.
    friction : Friction or None
        Coulomb friction in the pairs (:mod:`linkage.kinetostatics.friction`) whose reduced
        moment joins the resistance; None: frictionless (the default;
        ``run_dynamics(..., friction=True)`` and ``linkage dynamics --friction`` take the
        scheme's ``[friction]``).
    friction_motion : callable or None
        The motion the friction's reactions are computed under: ``friction_motion(phi) ->
        (omega, eps)`` arrays (rad/s, rad/s^2) at the input angles ``phi``; None: the mean
        speed, eps = 0 (the course's approximation). :attr:`friction_speed` gives the one used.
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
    friction: Any = None
    friction_motion: Any = None

    @property
    def friction_speed(self) -> Any:
        """The speed the friction is computed at: ``friction_motion`` or the mean speed."""
        return self.friction_motion if self.friction_motion is not None else self.mean_speed

    @property
    def rotation(self) -> int:
        return 1 if self.mean_speed > 0 else -1

    @property
    def constant_inertia(self) -> float:
        """Declared constant inertia at the input besides the input link's own, kg m^2."""
        return self.inertia_0 + sum(j * u * u for j, u in self.rotors) + self.flywheel


#: Largest number of cycles of a start-up transient a scheme may declare (the integration time
#: grows with it); the largest number of table positions is :data:`linkage.model.numbers.MAX_POSITIONS`.
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
        if is_number(v) and DELTA_RESOLVED <= v < 2:
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
        if is_number(v) and (v == 0 or MIN_MAGNITUDE <= v <= MAX_MAGNITUDE):
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


def require_full_turn(mech: Mechanism, what: str) -> None:
    """DynamicsInputError when ``mech`` is analysed over a partial input range: ``what`` (a cycle
    of the machine's dynamics) needs its input to turn fully."""
    if mech.input_range is not None:
        a, b = np.degrees(mech.input_range)
        raise DynamicsInputError(
            f"mechanism '{mech.name}': {what} needs the input to turn fully (one cycle is one turn), but the "
            f"scheme declares range_deg = [{a:.10g}, {b:.10g}]: its input turns only over that range. Its "
            "kinematics and forces are analysed over the range ('linkage analyze', 'linkage forces'); for "
            "the cycle dynamics leave range_deg out of a mechanism whose input turns fully")


def override_spec(mech, spec, delta, mean_speed, positions=None) -> DynamicsSpec:
    """The declared (or given) inputs with the arguments that override them, all checked."""
    if spec is None:
        if mech.extra.get("dynamics") is None and mean_speed is not None:
            require(is_real(mean_speed) and mean_speed != 0, "mean_speed", mean_speed,
                    "a finite nonzero number (rad/s; its sign is the rotation)")
            spec = DynamicsSpec(mean_speed=float(mean_speed))
        else:
            spec = dynamics_of(mech)
    changes: dict[str, Any] = {}
    if delta is not None:
        require(is_real(delta) and delta < 2, "delta", delta,
                "a number in (0, 2) (the coefficient of speed fluctuation (w_max - w_min) / w_m)")
        changes["delta"] = float(delta)
    if mean_speed is not None:
        require(is_real(mean_speed), "mean_speed", mean_speed, "a finite nonzero number (rad/s; its sign is the "
                                                              "rotation)")
        changes["mean_speed"] = float(mean_speed)
    if positions is not None:
        changes["positions"] = positions
    return check_spec(replace(spec, **changes))
