"""How a further input link's angle follows the first input's: several inputs (mobility W > 1).

A mechanism with W input links pinned to the frame (a five-bar driven by two cranks, W = 2) is
analysed over the angle ``phi`` of its first input; every further input link k turns by a
declared law ``theta_k(phi)``: the ratio of a gear train with a phase, or a table of angles (two
motors with a programmed schedule). The law gives the link's angle and its analogs
``dtheta_k/dphi`` and ``d2theta_k/dphi2``, so the motion, the analogs, the reactions (a balancing
moment per input) and the dynamics (reduced to the first input) follow as for one input.

``theta_k`` is the angle of the input link's own x axis, like ``phi`` for the first input: for a
link declared by ``line = [O, A]``, the angle of O -> A (docs/inputs.md).

>>> import numpy as np
>>> law = InputLaw(ratio=-1.0, phase=np.pi / 2)
>>> theta, first, second = law.angles(np.array([0.0, np.pi / 2]))
>>> np.degrees(theta).round(6).tolist(), first.tolist(), second.tolist()
([90.0, 0.0], [-1.0, -1.0], [0.0, 0.0])
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property

import numpy as np

__all__ = ["ANGLE_TOL", "InputLaw", "table_problems"]

TWO_PI = 2 * math.pi
#: two input angles this close (rad) are one: a table that spans a turn "exactly", an angle at the
#: end of a law's domain
ANGLE_TOL = 1e-9


@dataclass(frozen=True)
class InputLaw:
    """The angle ``theta`` (rad) of a further input link as a function of the first input's ``phi``.

    Either ``theta = ratio * phi + phase`` (``phase`` in rad), or, when ``table`` is given, the cubic
    spline through its points ``(phi_i, theta_i)`` (rad, ``phi_i`` increasing):

    - a table whose ``phi`` spans exactly one turn, with ``theta`` gaining a whole number ``k`` of
      turns over it, is periodic: ``theta(phi + 2 pi) = theta(phi) + 2 pi k`` (a periodic spline of
      ``theta - k phi``), valid at every angle;
    - any other table (spanning less than a turn) holds only within ``[phi_0, phi_n]``: the
      mechanism must declare an input range inside it, and analyses outside it are refused.

    Build it through :meth:`linkage.model.builder.MechanismBuilder.input_law` (validated) or the scheme's
    ``[input_laws]`` table.
    """

    ratio: float = 1.0
    phase: float = 0.0
    table: tuple[tuple[float, ...], tuple[float, ...]] | None = None

    @property
    def periodic(self) -> bool:
        """Whether the law holds at every angle (a ratio, or a table over exactly one turn)."""
        if self.table is None:
            return True
        phi, theta = self.table
        turns = (theta[-1] - theta[0]) / TWO_PI
        return abs(phi[-1] - phi[0] - TWO_PI) <= ANGLE_TOL and abs(turns - round(turns)) <= ANGLE_TOL

    @property
    def domain(self) -> tuple[float, float] | None:
        """The angles ``(phi_0, phi_n)`` (rad) a table that is not periodic holds over; None otherwise."""
        return None if self.periodic else (self.table[0][0], self.table[0][-1])

    @cached_property
    def _spline(self):
        from scipy.interpolate import CubicSpline

        phi, theta = (np.asarray(v, dtype=float) for v in self.table)
        if self.periodic:
            turns = round((theta[-1] - theta[0]) / TWO_PI)
            rest = theta - turns * phi
            rest[-1] = rest[0]     # periodic to round-off: make it exact for the spline
            return CubicSpline(phi, rest, bc_type="periodic"), turns
        return CubicSpline(phi, theta, bc_type="not-a-knot"), 0

    def angles(self, phi: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``theta`` (rad), ``dtheta/dphi`` and ``d2theta/dphi2`` at the first input's angles ``phi``.

        Parameters
        ----------
        phi : ndarray (N,)
            Angles of the first input, rad.

        Returns
        -------
        theta, first, second : ndarray (N,)
            NaN outside the domain of a table that is not periodic.
        """
        phi = np.asarray(phi, dtype=float)
        if self.table is None:
            return self.ratio * phi + self.phase, np.full(phi.shape, float(self.ratio)), np.zeros(phi.shape)
        spline, turns = self._spline
        start = self.table[0][0]
        if self.periodic:
            at = (phi - start) % TWO_PI + start
            theta = spline(at) + turns * phi
        else:
            low, high = self.domain
            at = np.where((phi >= low - ANGLE_TOL) & (phi <= high + ANGLE_TOL), np.clip(phi, low, high), np.nan)
            theta = spline(at)
        return theta, spline(at, 1) + turns, spline(at, 2)


def table_problems(where: str, table) -> list[str]:
    """Problems of a law's table (empty when it is sound); ``where`` names it in the messages.

    A table holds at least 4 points ``(phi, theta)`` of finite angles (rad) with ``phi`` strictly
    increasing, spanning at most one turn; when it spans exactly one turn, ``theta`` must gain a
    whole number of turns over it (else the law jumps where the turn closes).
    """
    try:
        phi, theta = (np.asarray(v, dtype=float) for v in table)
    except (TypeError, ValueError):
        return [f"{where}: the table must be pairs [phi, theta] of numbers, got {table!r}"]
    if phi.ndim != 1 or phi.shape != theta.shape or len(phi) < 4:
        return [f"{where}: the table needs at least 4 pairs [phi, theta], got {len(phi)}"]
    if not (np.all(np.isfinite(phi)) and np.all(np.isfinite(theta))):
        return [f"{where}: the table's angles must be finite numbers"]
    steps = np.diff(phi)
    if np.any(steps <= 0):
        k = int(np.argmax(steps <= 0))
        return [f"{where}: the table's input angles must increase; entry {k + 2} "
                f"({math.degrees(phi[k + 1]):.10g} deg) follows {math.degrees(phi[k]):.10g} deg"]
    span = phi[-1] - phi[0]
    if span > TWO_PI + ANGLE_TOL:
        return [f"{where}: the table spans {math.degrees(span):.10g} deg of the first input; at most one "
                "turn (360 deg)"]
    turns = (theta[-1] - theta[0]) / TWO_PI
    if abs(span - TWO_PI) <= ANGLE_TOL and abs(turns - round(turns)) > ANGLE_TOL:
        return [f"{where}: the table spans one turn of the first input, so the link must come back to its "
                f"angle after a whole number of turns; it changes by {math.degrees(theta[-1] - theta[0]):.10g} "
                "deg (give a table over less than a turn with an input range, or end it where it starts)"]
    return []
