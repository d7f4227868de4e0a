"""Motor characteristics reduced to the input link (METHOD section 6).

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

__all__ = ["ConstantMotor", "LinearMotor", "InductionMotor", "motor_from_spec", "RPM"]

RPM = 2 * math.pi / 60  # rad/s per rpm


@dataclass(frozen=True)
class ConstantMotor:
    """A constant driving moment at the input link, N m."""

    moment: float

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
    """

    rated_moment: float
    synchronous_rpm: float
    rated_rpm: float
    overload: float = 2.0
    ratio: float = 1.0
    efficiency: float = 1.0

    @property
    def breakdown_slip(self) -> float:
        rated_slip = (self.synchronous_rpm - self.rated_rpm) / self.synchronous_rpm
        lam = self.overload
        return rated_slip * (lam + math.sqrt(lam * lam - 1.0))

    def __call__(self, w):
        n = self.ratio * np.asarray(w, dtype=float) / RPM
        slip = (self.synchronous_rpm - n) / self.synchronous_rpm
        sk = self.breakdown_slip
        m_motor = 2 * self.overload * self.rated_moment * slip * sk / (slip**2 + sk**2)
        return self.ratio * self.efficiency * m_motor

    def balance_speed(self, moment: float) -> float | None:
        """Input speed on the stable branch (slip < S_k) where the reduced moment is ``moment``."""
        m = moment / (self.ratio * self.efficiency)
        mk, sk = self.overload * self.rated_moment, self.breakdown_slip
        if m >= mk:
            return None
        # m (S^2 + sk^2) = 2 mk sk S -> S = sk (mk - sqrt(mk^2 - m^2)) / m
        slip = sk * (mk - math.sqrt(mk * mk - m * m)) / m if m > 0 else 0.0
        return self.synchronous_rpm * (1 - slip) * RPM / self.ratio


def motor_from_spec(spec: Mapping[str, Any]) -> tuple[Any | None, list[str]]:
    """A motor and the list of problems from a scheme's ``[dynamics.motor]`` table."""
    if not isinstance(spec, Mapping):
        return None, [f"motor: expected a table, got {spec!r}"]
    kind = spec.get("kind")
    fields = {
        "constant": (ConstantMotor, {"moment"}, set()),
        "linear": (LinearMotor, {"stall_moment", "no_load_speed"}, {"ratio", "efficiency"}),
        "induction": (InductionMotor, {"synchronous_rpm", "rated_rpm"},
                      {"rated_moment", "rated_power", "overload", "ratio", "efficiency"}),
    }
    if kind not in fields:
        return None, [f"motor: kind must be one of {sorted(fields)}, got {kind!r}"]
    cls, required, optional = fields[kind]
    given = set(spec) - {"kind"}
    problems = []
    if given - required - optional:
        problems.append(f"motor ({kind}): unknown keys {sorted(given - required - optional)} "
                        f"(known: {sorted(required | optional)})")
    if required - given:
        problems.append(f"motor ({kind}): missing {sorted(required - given)}")
    for k in given & (required | optional):
        v = spec[k]
        if not (isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)):
            problems.append(f"motor ({kind}): {k} must be a number, got {v!r}")
        elif k in ("no_load_speed", "ratio", "synchronous_rpm", "rated_rpm", "rated_power",
                   "rated_moment") and v <= 0:
            problems.append(f"motor ({kind}): {k} must be > 0, got {v!r}")
        elif k == "efficiency" and not 0 < v <= 1:
            problems.append(f"motor ({kind}): efficiency must be in (0, 1], got {v!r}")
        elif k == "overload" and v <= 1:
            problems.append(f"motor ({kind}): overload (M_k / M_nom) must be > 1, got {v!r}")
    if problems:
        return None, problems
    args = {k: float(spec[k]) for k in given}
    if kind == "induction":
        if ("rated_moment" in args) == ("rated_power" in args):
            return None, ["motor (induction): give exactly one of rated_moment (N m) or rated_power (W)"]
        if args["rated_rpm"] >= args["synchronous_rpm"]:
            return None, [f"motor (induction): rated_rpm {args['rated_rpm']} must be below "
                          f"synchronous_rpm {args['synchronous_rpm']}"]
        if "rated_power" in args:
            args["rated_moment"] = args.pop("rated_power") / (args["rated_rpm"] * RPM)
    return cls(**args), []
