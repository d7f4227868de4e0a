"""Motor characteristics reduced to the input link (docs/methods.md, "Motor characteristics").

Each motor is a callable ``motor(w) -> M``: the driving moment at the input link (N m, positive
when it drives) for the input's speed ``w = |omega| > 0`` (rad/s) in the direction of rotation.
A motor with gear ratio ``U`` (motor speed / input speed) and efficiency ``eta`` gives
``M = U eta M_motor(U w)``.

>>> motor = InductionMotor(rated_moment=10.0, synchronous_rpm=1500, rated_rpm=1440, overload=2.0,
...                        ratio=14.4)
>>> round(float(motor(1440 / 14.4 * 2 * 3.141592653589793 / 60)), 6)  # rated speed -> U eta M_nom
144.0
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Mapping

import numpy as np

from ..errors import DynamicsInputError
from ..model.numbers import check_number, unknown_keys

__all__ = ["ConstantMotor", "LinearMotor", "InductionMotor", "motor_from_spec", "starting_moment", "RPM"]

RPM = 2 * math.pi / 60  # rad/s per rpm


@dataclass(frozen=True)
class ConstantMotor:
    """A constant driving moment at the input link, N m."""

    moment: float

    def __post_init__(self):
        _check(self, moment="finite")

    def __call__(self, w):
        return np.full_like(np.asarray(w, dtype=float), self.moment)

    def balance_speed(self, moment: float) -> float | None:
        """A constant moment balances any speed (or none): no unique operating speed."""
        return None


@dataclass(frozen=True)
class LinearMotor:
    """``M_motor = stall_moment (1 - w_m / no_load_speed)`` on the motor shaft (w_m in rad/s)."""

    stall_moment: float
    no_load_speed: float
    ratio: float = 1.0
    efficiency: float = 1.0

    def __post_init__(self):
        _check(self, stall_moment="finite", no_load_speed="> 0", ratio="> 0", efficiency="(0, 1]")

    def __call__(self, w):
        wm = self.ratio * np.asarray(w, dtype=float)
        return self.ratio * self.efficiency * self.stall_moment * (1.0 - wm / self.no_load_speed)

    def balance_speed(self, moment: float) -> float | None:
        """Input speed at which the reduced moment equals ``moment``."""
        m_motor = moment / (self.ratio * self.efficiency)
        return self.no_load_speed * (1.0 - m_motor / self.stall_moment) / self.ratio


@dataclass(frozen=True)
class InductionMotor:
    """Induction motor by Kloss: ``M = 2 M_k S S_k / (S^2 + S_k^2)`` on the motor shaft.

    ``S = (n_s - n) / n_s`` is the slip, ``M_k = overload * rated_moment`` the breakdown moment
    and ``S_k = S_nom (overload + sqrt(overload^2 - 1))`` the breakdown slip from the rated slip.
    Speeds in rpm on the motor shaft.

    The characteristic is evaluated as ``M = 2 M_nom (lambda x) / (1 + x^2)`` with ``x = S / S_k``
    and ``lambda x = S / (S_nom (1 + sqrt(1 - 1/lambda^2)))``: the same function, finite for any
    finite overload ``lambda > 1`` (for a huge one it tends to the linear ``M_nom S / S_nom``).
    """

    rated_moment: float
    synchronous_rpm: float
    rated_rpm: float
    overload: float = 2.0
    ratio: float = 1.0
    efficiency: float = 1.0

    def __post_init__(self):
        _check(self, rated_moment="> 0", synchronous_rpm="> 0", rated_rpm="> 0", overload="> 1", ratio="> 0",
               efficiency="(0, 1]")
        if not self.rated_rpm < self.synchronous_rpm:
            _fail(f"InductionMotor: rated_rpm must be below synchronous_rpm ({self.synchronous_rpm!r}), got "
                  f"{self.rated_rpm!r}")

    @property
    def _slip_per_overload(self) -> float:
        """``S_k / overload = S_nom (1 + sqrt(1 - 1/overload^2))``, finite for any overload."""
        rated_slip = (self.synchronous_rpm - self.rated_rpm) / self.synchronous_rpm
        r = 1.0 / self.overload
        return rated_slip * (1.0 + math.sqrt(1.0 - r * r))

    @property
    def breakdown_slip(self) -> float:
        return self.overload * self._slip_per_overload

    def __call__(self, w):
        n = self.ratio * np.asarray(w, dtype=float) / RPM
        slip = (self.synchronous_rpm - n) / self.synchronous_rpm
        lam_x = slip / self._slip_per_overload  # overload * S / S_k
        x = lam_x / self.overload  # S / S_k
        m_motor = 2 * self.rated_moment * lam_x / (1 + x * x)
        return self.ratio * self.efficiency * m_motor

    def balance_speed(self, moment: float) -> float | None:
        """Input speed on the stable branch (slip < S_k) where the reduced moment is ``moment``."""
        m = moment / (self.ratio * self.efficiency) / self.rated_moment  # in rated moments
        if m >= self.overload:
            return None
        # m (S^2 + sk^2) = 2 mk sk S -> S = sk (mk - sqrt(mk^2 - m^2)) / m = sk mu / (1 + sqrt(1 - mu^2))
        # with mu = m / mk, and sk mu = (S_k / overload) m: no overflow for any overload
        mu = m / self.overload
        slip = self._slip_per_overload * m / (1.0 + math.sqrt(1.0 - mu * mu)) if m > 0 else 0.0
        return self.synchronous_rpm * (1 - slip) * RPM / self.ratio


def starting_moment(motor: Any) -> float:
    """The motor's moment at the input link at rest (``w = 0``), N m: its starting torque
    reduced to the input (a constant motor's moment, ``U eta M_0`` of a linear motor, the Kloss
    moment at slip 1 of an induction motor). A start from rest needs it > 0."""
    return float(np.asarray(motor(0.0), dtype=float))


def _fail(message: str) -> None:

    raise DynamicsInputError(message)


def _check(motor: Any, **rules: str) -> None:
    """DynamicsInputError naming the first parameter of ``motor`` that breaks its rule
    ("finite", "> 0", "> 1" or "(0, 1]"; every rule implies a finite real number)."""
    tests = {"finite": lambda v: True, "> 0": lambda v: v > 0, "> 1": lambda v: v > 1,
             "(0, 1]": lambda v: 0 < v <= 1}
    for name, rule in rules.items():
        v = getattr(motor, name)
        real = isinstance(v, (int, float, np.integer, np.floating)) and not isinstance(v, (bool, np.bool_))
        if not (real and math.isfinite(v) and tests[rule](v)):
            _fail(f"{type(motor).__name__}: {name} must be {'a finite number' if rule == 'finite' else rule}, "
                  f"got {v!r}")


def motor_from_spec(spec: Mapping[str, Any]) -> tuple[Any | None, list[str]]:
    """A motor and the list of problems from a scheme's ``[dynamics.motor]`` table.

    Keys (``kind`` and, per kind; every speed and moment on the motor's shaft unless said):

    - ``constant``: ``moment`` (N m, at the input link, no gear);
    - ``linear``: ``stall_moment`` M_0 (N m, at rest), ``no_load_speed`` (rad/s) or
      ``no_load_rpm`` (rpm), ``ratio`` U = motor speed / input speed (default 1), ``efficiency``
      (default 1);
    - ``induction``: ``synchronous_rpm``, ``rated_rpm`` (rpm), ``rated_moment`` (N m) or
      ``rated_power`` (W), ``overload`` M_k / M_nom (default 2), ``ratio``, ``efficiency``.

    Every number is checked against its range (``schemes/README.md``, "Ranges"): moments within
    1e50 in magnitude, speeds, ratios, rated power and moment in [1e-50, 1e50], efficiency in
    (0, 1], overload in (1, 1e50], rated_rpm below synchronous_rpm.
    """

    if not isinstance(spec, Mapping):
        return None, [f"motor: expected a table, got {spec!r}"]
    kind = spec.get("kind")
    fields = {
        "constant": (ConstantMotor, {"moment"}, set()),
        "linear": (LinearMotor, {"stall_moment", "no_load_speed"}, {"ratio", "efficiency"}),
        "induction": (InductionMotor, {"synchronous_rpm", "rated_rpm"},
                      {"rated_moment", "rated_power", "overload", "ratio", "efficiency"}),
    }
    if not isinstance(kind, str) or kind not in fields:
        return None, [f"motor: kind must be one of {sorted(fields)}, got {kind!r}"]
    cls, required, optional = fields[kind]
    where = f"motor ({kind})"
    problems: list[str] = []
    # rpm twins of speeds in rad/s: no_load_rpm for no_load_speed
    twins = {"no_load_rpm": "no_load_speed"} if kind == "linear" else {}
    if unknown_keys({k: v for k, v in spec.items() if k != "kind"}, required | optional | set(twins), where,
                    problems):
        return None, problems
    for twin, key in twins.items():
        if twin in spec and key in spec:
            return None, [f"{where}: give either {key} (rad/s) or {twin} (rpm), not both"]
    given = {twins.get(k, k) for k in spec} - {"kind"}
    if required - given:
        problems.append(f"{where}: missing {sorted(required - given)}"
                        + (" (or no_load_rpm)" if "no_load_speed" in required - given else ""))
    ranges = {"moment": ("real", "N m"), "stall_moment": ("real", "N m"), "no_load_speed": ("positive", "rad/s"),
              "no_load_rpm": ("positive", "rpm"),
              "ratio": ("positive", ""), "synchronous_rpm": ("positive", "rpm"), "rated_rpm": ("positive", "rpm"),
              "rated_power": ("positive", "W"), "rated_moment": ("positive", "N m")}
    args = {}
    for k in sorted(set(spec) - {"kind"}):
        v = spec[k]
        if k == "efficiency":
            if _is_real(v) and 0 < v <= 1:
                args[k] = float(v)
            else:
                problems.append(f"{where}: efficiency must be a number in (0, 1], got {v!r}")
        elif k == "overload":
            if _is_real(v) and 1 < v <= 1e50:
                args[k] = float(v)
            else:
                problems.append(f"{where}: overload (M_k / M_nom) must be a number in (1, 1e+50], got {v!r}")
        else:
            args[k] = check_number(v, where, k, problems, *ranges[k])
    if problems:
        return None, problems
    for twin, key in twins.items():
        if twin in args:
            args[key] = args.pop(twin) * RPM
    if kind == "induction":
        if ("rated_moment" in args) == ("rated_power" in args):
            return None, [f"{where}: give exactly one of rated_moment (N m) or rated_power (W)"]
        if args["rated_rpm"] >= args["synchronous_rpm"]:
            return None, [f"{where}: rated_rpm {args['rated_rpm']} must be below "
                          f"synchronous_rpm {args['synchronous_rpm']}"]
        if "rated_power" in args:
            args["rated_moment"] = args.pop("rated_power") / (args["rated_rpm"] * RPM)
    return cls(**args), []


def _is_real(v: Any) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)
