"""The works of one turn at a constant input speed and the cycle efficiency
(docs/methods.md#friction-in-the-pairs).

Over a turn at constant speed the kinetic energy and the potential energy of gravity return to
their values, so the driving work equals the useful work plus the work friction takes:
``A_driving = A_useful + A_friction`` (each >= 0 as reported here), and the cycle efficiency is
``η = A_useful / A_driving``. The works are the powers of
:meth:`~linkage.kinetostatics.reactions.Reactions.powers` integrated over time on an even grid of
the turn (the periodic trapezoid rule).

>>> import linkage
>>> works = cycle_works(linkage.load("course_slider_crank"), friction=False)
>>> round(works.friction, 9), works.efficiency == works.useful / works.driving
(0.0, True)
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import InputError
from ..kinematics.full_turn import input_cannot_turn
from ..kinematics.motion import analyze
from ..model.mechanism import Mechanism
from ..model.scheme import section_of
from .friction import Friction
from .reactions import solve_reactions

__all__ = ["CycleWorks", "cycle_works", "CYCLE_SAMPLES"]

#: positions of the turn the works are integrated over
CYCLE_SAMPLES = 720


@dataclass(frozen=True)
class CycleWorks:
    """The works of one turn at constant speed, J (per rad/s of speed in a static analysis).

    Attributes
    ----------
    driving : float
        Work of the drive (the balancing moment, with the loads declared as driving).
    useful : float
        Work done against the useful (external) resistances, >= 0 where they resist.
    friction : float
        Work friction takes, >= 0.
    gravity, inertia : float
        Works of gravity and of the inertia loads (0 over a turn, to the quadrature's accuracy).
    efficiency : float
        ``useful / driving`` (NaN where the drive does no work, or where the mechanism locks).
    omega : float
        The speed, rad/s (the sense +1 / -1 of a static analysis).
    samples : int
    locked : int
        Positions of the grid where the mechanism self-locks (the works are NaN then).
    """

    driving: float
    useful: float
    friction: float
    gravity: float
    inertia: float
    efficiency: float
    omega: float
    samples: int
    locked: int


def cycle_works(mech: Mechanism, omega: float | None = None, friction: Friction | bool | None = True,
                samples: int = CYCLE_SAMPLES) -> CycleWorks:
    """The works of one turn of the input at the constant speed ``omega`` (rad/s, signed;
    default the scheme's mean speed, else a static analysis turning counter-clockwise).

    Parameters
    ----------
    mech : Mechanism
        Driven by a crank that turns fully.
    omega : float, optional
    friction : Friction or bool
        As :func:`~linkage.kinetostatics.reactions.solve_reactions` (default: the scheme's).
    samples : int
        Positions of the turn (>= 8).

    Raises
    ------
    InputError
        A slide input, an input that cannot turn fully, or fewer than 8 samples.
    """
    if not mech.coordinate.is_angle or mech.input_range is not None:
        raise InputError(f"scheme '{mech.name}': the cycle's works need a crank that turns fully "
                         "(its input is a slide or has a declared range)")
    why = input_cannot_turn(mech)
    if why:
        raise InputError(why)
    if int(samples) < 8:
        raise InputError(f"samples must be at least 8, got {samples!r}")
    spec = section_of(mech, "dynamics")
    if omega is None and spec is not None:
        omega = spec.mean_speed
    sense = 1.0 if not omega else float(np.sign(omega))
    phi = sense * np.linspace(0.0, 2 * np.pi, int(samples), endpoint=False)
    motion = analyze(mech, phi, order=2, omega=omega if omega else None, eps=0.0 if omega else None,
                     on_failure="mask")
    reactions = solve_reactions(motion, friction=friction, sense=sense)
    powers = reactions.powers()
    period = 2 * np.pi / (abs(omega) if omega else 1.0)
    work = {k: float(np.mean(v)) * period for k, v in powers.items()}
    locked = int(np.count_nonzero(reactions.locked)) if reactions.locked is not None else 0
    driving, useful = work["driving"], -work["useful"]
    efficiency = useful / driving if driving > 0 and np.isfinite(driving) else float("nan")
    return CycleWorks(driving, useful, 0.0 - work["friction"], work["gravity"], work["inertia"], efficiency,
                      float(omega) if omega else sense, int(samples), locked)
