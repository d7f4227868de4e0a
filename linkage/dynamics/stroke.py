"""Dynamics of a stroke: a slide input pushed by a force (a piston, a hydraulic cylinder).

A crank's dynamics is periodic -- a cycle is a turn (:mod:`linkage.dynamics.cycle`). A slide input moves
over its stroke once, so its law of motion follows from the energy equation along the stroke
(docs/inputs.md, "Dynamics of a stroke"): with ``s`` the slide, ``sigma = sign(s_end - s_start)``
the sense of travel, ``u = |s - s_0|`` the distance travelled and ``w = |ds/dt|``,

    T(u) = 1/2 m(s) w^2 = 1/2 m(s_0) w_0^2 + integral from 0 to u of (sigma F + F_red) du

where ``m(s)`` is the reduced mass (kg) and ``F_red`` the reduced force of the declared loads
along the travel (N), both from :func:`linkage.dynamics.reduced.reduced_characteristics` (the crank's
reduced inertia and moment, with analogs per m), and ``F`` the actuator's force along +s (N). The
speed is ``w = sqrt(2 T / m)``, the time ``t = integral of du / w`` and the acceleration
``d2s/dt2 = sigma (sigma F + F_red - m'(s) w^2 / 2) / m(s)``.

Both integrals are adaptive Clenshaw-Curtis quadratures (Chebyshev interpolants of degree
:data:`DEGREE` on each panel): the panels start as the table's steps and are halved until the
Chebyshev coefficients of both integrands show
each panel's integrals to :data:`TOLERANCE` of their size, so the table's time and speed are
accurate to ~1e-9 relative or better (docs/inputs.md). From rest the time's integrand
``1 / w ~ 1 / sqrt(u)`` is singular at the start: the quadrature runs in ``x = sqrt(u)``
(``du / w = 2 x dx / w``, smooth), which removes it.

>>> import linkage
>>> stroke = stroke_motion(linkage.load("piston_driven_crank"), force=-800.0, initial_speed=0.5)
>>> bool(abs(stroke.speed[-1]) > 0.5), round(float(stroke.s[-1]), 6)
(True, 0.32)
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np
from numpy.polynomial import chebyshev
from scipy.optimize import brentq

from ..errors import DynamicsError, DynamicsInputError
from ..kinematics.motion import analyze
from ..kinetostatics.reactions import Reactions, solve_reactions
from ..model.mechanism import Mechanism
from .cycle import angular_acceleration
from .reduced import Reduced, reduced_characteristics

__all__ = ["StrokeMotion", "stroke_motion", "DEGREE", "TOLERANCE"]

#: degree of the Chebyshev interpolants of the integrands on each panel (DEGREE + 1 nodes, the
#: panel's ends among them)
DEGREE = 16
#: each panel's integrals are accepted when their estimated error is below this part of their size
TOLERANCE = 1e-12
#: rounds of halving the panels that fail the tolerance before the stroke is refused
MAX_ROUNDS = 60
#: panels the halvings may add before the stroke is refused
MAX_NEW_PANELS = 20000

_Y = -np.cos(np.pi * np.arange(DEGREE + 1) / DEGREE)        # Chebyshev points on [-1, 1], ascending
_TO_COEFFICIENTS = np.linalg.inv(chebyshev.chebvander(_Y, DEGREE))
#: ``values @ _RUNNING.T``: the integral of the values' interpolant from -1 to each node
_RUNNING = np.column_stack([chebyshev.chebval(_Y, chebyshev.chebint(np.eye(DEGREE + 1)[k], lbnd=-1))
                            for k in range(DEGREE + 1)]) @ _TO_COEFFICIENTS
_W = _RUNNING[-1]                                           # Clenshaw-Curtis weights on [-1, 1]


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
        array, in any order) returning an array of forces. The declared loads (gravity, forces,
        moments) act besides it. A force with jumps is integrated too (the panels shrink about a
        jump), more slowly.
    initial_speed : float
        ``|ds/dt|`` at the start of the stroke, m/s (>= 0).
    positions : int
        Equal steps of the stroke in the table (the integrals are adaptive within each step).

    Raises
    ------
    DynamicsInputError
        The first input is a crank, or an argument is out of range, or the force is not finite.
    DynamicsError
        The mechanism stops before the end of the stroke (the loads take all its kinetic energy),
        naming the slide where it stops; or the quadrature cannot reach its tolerance (the speed
        all but vanishes inside the stroke), naming where.
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
    stroke = _Stroke(mech, force, start, end)
    s, pushed, reduced = stroke.table(positions)
    kinetic0 = 0.5 * reduced.inertia[0] * initial_speed**2
    along0 = sense * pushed[0] + reduced.moment[0]
    if initial_speed == 0 and along0 <= 0:
        stroke.refuse_stop(start, pushed[0], reduced.moment[0])
    work, time = stroke.integrate(positions, kinetic0, from_rest=initial_speed == 0)
    kinetic = kinetic0 + np.concatenate([[0.0], np.cumsum(work)])
    w = np.sqrt(2 * np.maximum(kinetic, 0.0) / reduced.inertia)
    w[0] = initial_speed
    t = np.concatenate([[0.0], np.cumsum(time)])
    accel = angular_acceleration(reduced, sense * pushed, reduced.inertia, w)      # the crank's formula, per m
    return StrokeMotion(mech, s, t, sense * w, accel, pushed, reduced)


class _Stroke:
    """The integrands of a stroke: the slide ``s = s_0 + sigma u(x)`` as a function of the
    quadrature's variable ``x`` (``u = x`` with a start speed, ``u = x^2`` from rest)."""

    def __init__(self, mech: Mechanism, force, start: float, end: float):
        self.mech, self.force, self.start, self.end = mech, force, start, end
        self.sense = 1 if end > start else -1
        self.length = abs(end - start)

    def pushed(self, s: np.ndarray) -> np.ndarray:
        """The actuator's force at ``s``, N (checked finite)."""
        value = np.broadcast_to(np.asarray(self.force(s) if callable(self.force) else self.force, dtype=float),
                                s.shape)
        if not np.all(np.isfinite(value)):
            raise DynamicsInputError(f"the actuator's force must be finite along the stroke, got "
                                     f"{value[~np.isfinite(value)][:3]} at s = {s[~np.isfinite(value)][:3]} m")
        return value.copy()

    def table(self, positions: int) -> tuple[np.ndarray, np.ndarray, Reduced]:
        """The table's slides (m), the actuator's force there (N) and the reduced characteristics."""
        s = np.linspace(self.start, self.end, positions + 1)
        return s, self.pushed(s), reduced_characteristics(self.mech, s, self.sense)

    def sample(self, x: np.ndarray, from_rest: bool) -> tuple[np.ndarray, np.ndarray]:
        """At quadrature points ``x`` (any shape): the force along the travel ``sigma F + F_red``
        (N) and the reduced mass (kg)."""
        s = self.start + self.sense * (x * x if from_rest else x).ravel()
        reduced = reduced_characteristics(self.mech, s, self.sense)
        along = self.sense * self.pushed(s) + reduced.moment
        mass = reduced.inertia
        bad = ~(np.isfinite(along) & np.isfinite(mass) & (mass > 0))
        if np.any(bad):
            raise DynamicsError(f"mechanism '{self.mech.name}': the reduced mass or force is not finite (or the "
                                f"mass not > 0) at s = {s[bad][:3]} m of its stroke")
        return along.reshape(x.shape), mass.reshape(x.shape)

    def integrate(self, positions: int, kinetic0: float, *, from_rest: bool) -> tuple[np.ndarray, np.ndarray]:
        """The work (J) and the time (s) of each of the table's ``positions`` steps, each to
        :data:`TOLERANCE` of its size by adaptive Clenshaw-Curtis panels in ``x`` (halved until
        accepted; ``u = x^2`` from rest, else ``u = x``)."""
        edges = np.linspace(0, self.length, positions + 1)
        edges = np.sqrt(edges) if from_rest else edges
        lo, hi, step = edges[:-1], edges[1:], np.arange(positions)
        along, mass = self.sample(_nodes(lo, hi), from_rest)
        for _ in range(MAX_ROUNDS):
            x, half = _nodes(lo, hi), 0.5 * (hi - lo)
            du = 2 * x if from_rest else 1.0
            f = along * du                                              # dT/dx, J per unit of x
            running = half[:, None] * (f @ _RUNNING.T)
            work = running[:, -1]
            kinetic = kinetic0 + np.concatenate([[0.0], np.cumsum(work)[:-1]])[:, None] + running
            failing = _failing(f, half, step, positions)
            moving = kinetic > 0
            moving[0, 0] |= from_rest                                   # the start, from rest
            stopped = np.flatnonzero(~np.all(moving, axis=1))
            if len(stopped):
                first = stopped[0]
                if not np.any(failing[:first + 1]):
                    self.stop_in_panel(x[first], kinetic[first], from_rest)
                failing[first + 1:] = False
            else:
                with np.errstate(divide="ignore", invalid="ignore"):
                    integrand = du * np.sqrt(mass / (2 * kinetic))          # dt/dx, s per unit of x
                if from_rest:      # at x = 0: T = g0 x^2 + ..., so 2 x sqrt(m / 2T) -> sqrt(2 m0 / g0)
                    integrand[0, 0] = np.sqrt(2 * mass[0, 0] / along[0, 0])
                failing |= _failing(integrand, half, step, positions)
                if not np.any(failing):
                    time = half * (integrand @ _W)
                    return np.bincount(step, work, positions), np.bincount(step, time, positions)
            if len(lo) + np.count_nonzero(failing) > positions + MAX_NEW_PANELS:
                break
            lo, hi, step, along, mass = _halve(failing, lo, hi, step, along, mass,
                                               lambda a, b: self.sample(_nodes(a, b), from_rest))
        worst = np.flatnonzero(failing)[0]
        u = (lo[worst]**2, hi[worst]**2) if from_rest else (lo[worst], hi[worst])
        raise DynamicsError(f"mechanism '{self.mech.name}': the time of its stroke does not reach a relative "
                            f"accuracy of {TOLERANCE:g} at s = {self.start + self.sense * u[0]:.9g}.."
                            f"{self.start + self.sense * u[1]:.9g} m (its quadrature's panels halved "
                            f"{MAX_ROUNDS} times, or {MAX_NEW_PANELS} panels added): the speed all but "
                            "vanishes there (the loads take nearly all its kinetic energy), or the force jumps "
                            "too often")

    def stop_in_panel(self, x: np.ndarray, kinetic: np.ndarray, from_rest: bool):
        """Refuse the stroke where the kinetic energy, ``kinetic`` (J) at the panel's nodes ``x``,
        first reaches zero (the root of its Chebyshev interpolant)."""
        series = chebyshev.Chebyshev(_TO_COEFFICIENTS @ kinetic, domain=[x[0], x[-1]])
        k = int(np.flatnonzero(kinetic[1:] <= 0)[0]) + 1
        root = x[k - 1] if kinetic[k - 1] <= 0 else brentq(series, x[k - 1], x[k], xtol=1e-15 * x[-1])
        s = self.start + self.sense * (root * root if from_rest else root)
        reduced = reduced_characteristics(self.mech, np.array([s]), self.sense)
        self.refuse_stop(s, self.pushed(np.array([s]))[0], reduced.moment[0])

    def refuse_stop(self, s: float, pushed: float, loads: float):
        raise DynamicsError(f"mechanism '{self.mech.name}' stops at s = {s:.6g} m, before the end of its stroke "
                            f"({self.end:.6g} m): the loads take all its kinetic energy there (give a larger "
                            f"force or initial speed; force {pushed:.6g} N, reduced force of the loads "
                            f"{loads:.6g} N along the travel)")


def _nodes(lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """The Chebyshev points of the panels ``[lo, hi]``, shape (P, DEGREE + 1)."""
    return 0.5 * (lo + hi)[:, None] + 0.5 * (hi - lo)[:, None] * _Y


def _halve(failing, lo, hi, step, along, mass, sample):
    """Split the ``failing`` panels in two, sampled anew by ``sample(lo, hi)``; panels in order."""
    mid = 0.5 * (lo[failing] + hi[failing])
    new_lo, new_hi = np.concatenate([lo[failing], mid]), np.concatenate([mid, hi[failing]])
    new_along, new_mass = sample(new_lo, new_hi)
    keep = ~failing
    lo, hi = np.concatenate([lo[keep], new_lo]), np.concatenate([hi[keep], new_hi])
    step = np.concatenate([step[keep], step[failing], step[failing]])
    along, mass = np.concatenate([along[keep], new_along]), np.concatenate([mass[keep], new_mass])
    order = np.argsort(lo, kind="stable")
    return lo[order], hi[order], step[order], along[order], mass[order]


def _failing(values: np.ndarray, half: np.ndarray, step: np.ndarray, positions: int) -> np.ndarray:
    """Panels (rows of ``values`` at their Chebyshev points, half-widths ``half``, in table steps
    ``step``) whose integral's error, estimated by the last two Chebyshev coefficients of the
    interpolant, exceeds :data:`TOLERANCE` of the integral of ``|values|`` over their table step
    plus the step's share of the whole stroke's. (Not of the panel's own: about a jump the error
    stays in proportion to a panel's width however small it is.)"""
    coefficients = values @ _TO_COEFFICIENTS.T
    error = 2 * half * (np.abs(coefficients[:, -1]) + np.abs(coefficients[:, -2]))
    size = np.bincount(step, half * (np.abs(values) @ _W), positions)
    return ~(error <= TOLERANCE * (size[step] + np.sum(size) / positions))
