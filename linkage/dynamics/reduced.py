"""Reduced characteristics at the input link (docs/methods.md#reduced-moment-and-moment-of-inertia).

For a slide input (docs/inputs.md) the same formulas give the reduced mass (kg) and the reduced
force (N): the analogs are per m of the slide.

With ``s = sign(omega_m)`` and ``psi = s phi`` (the angle in the direction of rotation):

- reduced moment by equality of powers ``M_red = s sum(F . r'_P) + s sum(M_k theta_k')``,
  split into the driving part (loads declared as driving) and the resisting part ``M_c``
  (everything else, gravity included);
- reduced moment of inertia ``I(psi) = I_0 + I''(psi)`` with
  ``I'' = sum(m_k |r'_Sk|^2 + J_Sk theta_k'^2)`` over the links other than the input link(s), and
  ``I_0`` the input link's own inertia about its pivot plus the declared constant inertia
  (rotors through gear ratios, flywheel);
- ``dI/dpsi = 2 s sum(m_k r'_Sk . r''_Sk + J_Sk theta_k' theta_k'')`` exact from the analogs.

>>> import numpy as np, linkage
>>> from linkage.dynamics.reduced import reduced_characteristics
>>> red = reduced_characteristics(linkage.load("four_bar"), np.linspace(0, 2 * np.pi, 5), rotation=1)
>>> red.inertia.shape
(5,)
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Callable

import numpy as np
from numpy.typing import ArrayLike

from assur.base import point_analogs

from ..errors import DynamicsInputError
from ..kinematics.motion import analyze
from ..kinetostatics.friction import Friction
from ..kinetostatics.loads import Loads, evaluate_loads, loads_of
from ..kinetostatics.reactions import solve_reactions
from ..model.mechanism import Mechanism

__all__ = ["Reduced", "reduced_characteristics", "link_inertia_terms"]


@dataclass(frozen=True)
class Reduced:
    """Reduced characteristics at N input angles.

    Attributes
    ----------
    phi : ndarray (N,)
        Input angles, rad.
    rotation : int
        ``s``: +1 counter-clockwise, -1 clockwise.
    moment_resistance, moment_driving : ndarray (N,)
        ``M_c`` and the driving part of the declared loads, reduced to psi, N m (``M_c`` with the
        friction's reduced moment where friction is asked).
    inertia_constant : float
        ``I_0``, kg m^2.
    inertia_variable : ndarray (N,)
        ``I''``, kg m^2.
    inertia_derivative : ndarray (N,)
        ``dI/dpsi``, kg m^2 / rad.
    moment_friction : ndarray (N,) or None
        The friction's reduced moment ``M_f,red = Σ P_friction / ω`` (<= 0, part of
        ``moment_resistance``), N m; None without friction.
    """

    phi: np.ndarray
    rotation: int
    moment_resistance: np.ndarray
    moment_driving: np.ndarray
    inertia_constant: float
    inertia_variable: np.ndarray
    inertia_derivative: np.ndarray
    moment_friction: np.ndarray | None = None

    @property
    def inertia(self) -> np.ndarray:
        """``I(psi) = I_0 + I''(psi)``, kg m^2."""
        return self.inertia_constant + self.inertia_variable

    @property
    def moment(self) -> np.ndarray:
        """Total reduced moment of the declared loads, N m."""
        return self.moment_resistance + self.moment_driving


def link_inertia_terms(motion, links) -> tuple[np.ndarray, np.ndarray]:
    """``sum(m |r'_S|^2 + J theta'^2)`` and ``sum(m r'_S . r''_S + J theta' theta'')`` over links."""
    mech = motion.mechanism
    n = len(motion.phi)
    inertia, half_derivative = np.zeros(n), np.zeros(n)
    for k in links:
        link = mech.links[k]
        if link.mass == 0 and link.inertia == 0:
            continue
        d1, d2 = point_analogs(motion.poses[k], motion.first[k], motion.second[k], link.center_of_mass)
        t1, t2 = motion.first[k][:, 2], motion.second[k][:, 2]
        inertia += link.mass * np.einsum("ni,ni->n", d1, d1) + link.inertia * t1**2
        half_derivative += link.mass * np.einsum("ni,ni->n", d1, d2) + link.inertia * t1 * t2
    return inertia, half_derivative


def reduced_characteristics(
    mech: Mechanism,
    phi: ArrayLike,
    rotation: int,
    *,
    loads: Loads | None = None,
    extra_inertia: float = 0.0,
    ends: ArrayLike | None = None,
    friction: Friction | None = None,
    speed: float | Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]] | None = None,
) -> Reduced:
    """Reduced moments and moment of inertia at the input angles ``phi``.

    Parameters
    ----------
    mech : Mechanism
    phi : array_like (N,)
        Input angles, rad.
    rotation : {1, -1}
        Sign of the input's angular velocity.
    loads : Loads, optional
        Default: the mechanism's declared loads.
    extra_inertia : float
        Constant inertia reduced to the input besides the input link's own (rotors, flywheel),
        kg m^2.
    ends : array_like of bool, optional
        Positions that end the cycle (two-valued loads at stroke ends, docs/methods.md#loads).
    friction : Friction, optional
        Friction in the pairs: its reduced moment joins ``M_c``. The reactions it depends on are
        those under ``speed`` (the inertia loads of that motion).
    speed : float or callable, optional
        The motion of the friction's kinetostatics: a constant speed (rad/s, signed; eps = 0), or
        ``speed(phi) -> (omega, eps)`` arrays at the input angles (a law of motion). Default
        ``rotation`` rad/s (no inertia worth the name: give the mean speed).

    Raises
    ------
    DynamicsInputError
        ``rotation`` not +1 / -1, or ``extra_inertia`` not a finite number >= 0 (a ``ValueError``
        too).
    """
    problem = None
    if isinstance(rotation, bool) or rotation not in (1, -1):
        problem = f"rotation must be +1 or -1, got {rotation!r}"
    elif not (isinstance(extra_inertia, (int, float, np.integer, np.floating)) and np.isfinite(extra_inertia)
              and extra_inertia >= 0):
        problem = f"extra_inertia must be a finite number >= 0 (kg m^2), got {extra_inertia!r}"
    if problem:

        raise DynamicsInputError(problem)
    motion = analyze(mech, phi, order=2, omega=float(rotation), eps=0.0)
    loads = loads_of(mech) if loads is None else loads
    n = len(motion.phi)
    driving, resisting = np.zeros(n), np.zeros(n)
    for t in evaluate_loads(motion, loads, ends):
        v, _ = point_analogs(motion.poses[t.link], motion.first[t.link], None, t.local)
        power = rotation * (np.einsum("ni,ni->n", t.force, v) + t.moment * motion.first[t.link][:, 2])
        if t.kind == "driving":
            driving += power
        else:
            resisting += power
    lost = None
    if friction:
        # the same positions and analogs at the speed asked: only the real velocities change
        omega, eps = speed(motion.phi) if callable(speed) else (float(rotation if speed is None else speed), 0.0)
        at_speed = replace(motion, omega=np.broadcast_to(np.asarray(omega, float), n).copy(),
                           eps=np.broadcast_to(np.asarray(eps, float), n).copy())
        reactions = solve_reactions(at_speed, loads, ends=ends, friction=friction, sense=rotation)
        lost = rotation * reactions.friction_power() / reactions.speed()
        resisting = resisting + lost
    crank = motion.structure.inputs[0]   # further inputs (mobility W > 1) turn by their laws: variable terms
    others = [k for k in mech.moving_links if k != crank]
    variable, half_derivative = link_inertia_terms(motion, others)
    # the input link's own inertia (a cylinder's driver is no link: every link is a variable term)
    own, _ = link_inertia_terms(motion, [crank] if crank in mech.links else [])
    return Reduced(motion.phi, rotation, resisting, driving, float(own[0]) + float(extra_inertia),
                   variable, 2 * rotation * half_derivative, lost)
