"""Dynamics of a stroke: a slide input pushed by a force (a piston, a hydraulic cylinder).

A crank's dynamics is periodic -- a cycle is a turn (:mod:`linkage.dynamics.cycle`). A slide input moves
over its stroke once, so its law of motion follows from the energy equation along the stroke
(docs/inputs.md, "Dynamics of a stroke"): with ``s`` the slide, ``sigma = sign(s_end - s_start)``
the sense of travel and ``w = |ds/dt|``,

    1/2 m(s) w^2 = 1/2 m(s_0) w_0^2 + integral from s_0 to s of (sigma F + F_red) |ds|

where ``m(s)`` is the reduced mass (kg) and ``F_red`` the reduced force of the declared loads
along the travel (N), both from :func:`linkage.dynamics.reduced.reduced_characteristics` (the crank's
reduced inertia and moment, with analogs per m), and ``F`` the actuator's force along +s (N). The
acceleration is ``d2s/dt2 = sigma (sigma F + F_red - m'(s) w^2 / 2) / m(s)`` and the time
``t = integral of |ds| / w`` (the mean of the two speeds on each step: exact for a constant
acceleration, finite when the stroke starts from rest).

>>> import linkage
>>> stroke = stroke_motion(linkage.load("piston_driven_crank"), force=-800.0, initial_speed=0.5)
>>> bool(abs(stroke.speed[-1]) > 0.5), round(float(stroke.s[-1]), 6)
(True, 0.32)
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np
from scipy.integrate import cumulative_trapezoid

from ..errors import DynamicsError, DynamicsInputError
from ..kinematics.motion import analyze
from ..kinetostatics.reactions import Reactions, solve_reactions
from ..model.mechanism import Mechanism
from .cycle import angular_acceleration, reduced_at
from .reduced import Reduced, reduced_characteristics

__all__ = ["StrokeMotion", "stroke_motion", "SUBSTEPS"]

#: integration steps per table step: the energy is integrated by the trapezoid rule on this finer
#: grid (relative error of the speed ~1e-7 for the shipped schemes; docs/inputs.md)
SUBSTEPS = 64


@dataclass(frozen=True)
class StrokeMotion:
    """The law of motion of a slide input over its stroke, at ``N`` table positions.

    Attributes
    ----------
    mechanism : Mechanism
    s : ndarray (N,)
        The slide, m (from the stroke's start to its end).
    t : ndarray (N,)
        Time from the start of the stroke, s.
    speed : ndarray (N,)
        ``ds/dt``, m/s (signed: negative when the stroke runs towards smaller s).
    acceleration : ndarray (N,)
        ``d2s/dt2``, m/s^2.
    force : ndarray (N,)
        The actuator's force along +s, N.
    reduced : Reduced
        Reduced mass (``reduced.inertia``, kg) and forces (N) at the positions.
    """

    mechanism: Mechanism
    s: np.ndarray
    t: np.ndarray
    speed: np.ndarray
    acceleration: np.ndarray
    force: np.ndarray
    reduced: Reduced

    def reactions(self) -> Reactions:
        """Kinetostatics under the real motion: the pair reactions and the balancing force, which
        equals the actuator's force when the motion is right (checked in the tests)."""
        motion = analyze(self.mechanism, self.s, order=2, omega=self.speed, eps=self.acceleration)
        return solve_reactions(motion)

    def columns(self) -> dict[str, np.ndarray]:
        """Table: ``i``, ``s`` (m), ``t`` (s), ``v`` (m/s), ``a`` (m/s^2), ``force`` (N),
        ``reduced_mass`` (kg), ``reduced_force`` (N, the declared loads along +s) and
        ``balancing_force`` (N, from the kinetostatics under this motion)."""
        sense = self.reduced.rotation
        return {"i": np.arange(1, len(self.s) + 1), "s": self.s, "t": self.t, "v": self.speed,
                "a": self.acceleration, "force": self.force, "reduced_mass": self.reduced.inertia,
                "reduced_force": sense * self.reduced.moment,
                "balancing_force": self.reactions().balancing_moment}


def stroke_motion(mech: Mechanism, force: float | Callable[[np.ndarray], np.ndarray] = 0.0, *,
                  initial_speed: float = 0.0, positions: int = 24) -> StrokeMotion:
    """The law of motion of ``mech``'s slide input over its stroke (``mech.input_range``).

    Parameters
    ----------
    mech : Mechanism
        A mechanism whose first input is a slide (a slider on a frame guide, or a cylinder).
    force : float or callable
        The actuator's force along +s, N: a constant, or a function of the slide ``s`` (m, an
        array) returning an array of forces. The declared loads (gravity, forces, moments) act
        besides it.
    initial_speed : float
        ``|ds/dt|`` at the start of the stroke, m/s (>= 0).
    positions : int
        Equal steps of the stroke in the table (the energy is integrated :data:`SUBSTEPS` times
        finer).

    Raises
    ------
    DynamicsInputError
        The first input is a crank, or an argument is out of range.
    DynamicsError
        The mechanism stops before the end of the stroke (the loads take all its kinetic energy),
        naming the slide where it stops.
    """
    coordinate = mech.coordinate
    if coordinate.is_angle:
        raise DynamicsInputError(f"mechanism '{mech.name}': its input '{mech.inputs[0]}' is a crank; a stroke's "
                                 "dynamics is for a slide input (the crank's dynamics: linkage.dynamics.run_dynamics)")
    if not (np.isfinite(initial_speed) and initial_speed >= 0):
        raise DynamicsInputError(f"initial_speed must be a finite speed >= 0 (m/s), got {initial_speed!r}")
    if isinstance(positions, bool) or not isinstance(positions, (int, np.integer)) or not 1 <= positions <= 100000:
        raise DynamicsInputError(f"positions must be a whole number from 1 to 100000, got {positions!r}")
    start, end = mech.input_range
    sense = 1 if end > start else -1
    s = np.linspace(start, end, positions * SUBSTEPS + 1)
    pushed = np.broadcast_to(np.asarray(force(s) if callable(force) else force, dtype=float), s.shape)
    if not np.all(np.isfinite(pushed)):
        raise DynamicsInputError(f"the actuator's force must be finite along the stroke, got "
                                 f"{pushed[~np.isfinite(pushed)][:3]}")
    reduced = reduced_characteristics(mech, s, sense)
    along = sense * pushed + reduced.moment                      # N, along the travel
    energy = 0.5 * reduced.inertia[0] * initial_speed**2 + cumulative_trapezoid(along, dx=abs(s[1] - s[0]), initial=0)
    speed2 = 2 * energy / reduced.inertia
    stopped = np.flatnonzero(speed2 < -1e-12 * max(float(np.max(np.abs(speed2))), 1e-300))
    if len(stopped):
        k = stopped[0]
        raise DynamicsError(f"mechanism '{mech.name}' stops at s = {s[k - 1]:.6g}..{s[k]:.6g} m, before the end of "
                            f"its stroke ({end:.6g} m): the loads take all its kinetic energy there (give a larger "
                            f"force or initial speed; force {pushed[k]:.6g} N, reduced force of the loads "
                            f"{reduced.moment[k]:.6g} N along the travel)")
    w = np.sqrt(np.maximum(speed2, 0.0))
    with np.errstate(divide="ignore"):
        steps = np.where(w[:-1] + w[1:] > 0, 2 * abs(s[1] - s[0]) / (w[:-1] + w[1:]), np.inf)
    t = np.concatenate([[0.0], np.cumsum(steps)])
    accel = angular_acceleration(reduced, sense * pushed, reduced.inertia, w)      # the crank's formula, per m
    keep = slice(None, None, SUBSTEPS)
    return StrokeMotion(mech, s[keep], t[keep], sense * w[keep], accel[keep], pushed[keep].copy(),
                        reduced_at(reduced, keep))
