"""Extreme positions of an output coordinate and the input angles of position tables.

An extreme position is a root of the output's first analog ``q'(phi) = 0`` (METHOD section 7),
found by bracketing on a sweep and refining with Brent's method to ~1e-13 rad.

>>> import math, linkage
>>> ext = linkage.extreme_positions(linkage.load("slider_crank"), "B.x")
>>> round(math.degrees(ext.phi_max), 3)
2.579
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import brentq

from .errors import InputError
from .kinematics import _cache, analyze
from .model import Mechanism

__all__ = ["Extremes", "extreme_positions", "table_angles", "wrap_angle"]


@dataclass(frozen=True)
class Extremes:
    """Extreme positions of one output quantity.

    Attributes
    ----------
    quantity : str
    phi_max, phi_min : float
        Input angles (rad, in [0, 2 pi)) where the quantity is largest / smallest.
    value_max, value_min : float
        The quantity there (m or rad).
    roots : ndarray
        Every root of the first analog found in [0, 2 pi), sorted.
    """

    quantity: str
    phi_max: float
    phi_min: float
    value_max: float
    value_min: float
    roots: np.ndarray

    @property
    def stroke(self) -> float:
        """``value_max - value_min``."""
        return self.value_max - self.value_min


def wrap_angle(angle):
    """Angles (rad) folded into [-pi, pi)."""
    return np.mod(np.asarray(angle) + np.pi, 2 * np.pi) - np.pi


def _output_quantity(mech: Mechanism, quantity: str | None) -> str:
    if quantity is not None:
        return quantity
    if mech.output is None:
        raise InputError(f"mechanism '{mech.name}' declares no output: name the quantity (e.g. 'B.x')")
    return mech.output.quantity


def extreme_positions(mech: Mechanism, quantity: str | None = None, *, samples: int = 720,
                      xtol: float = 1e-14) -> Extremes:
    """Find the extreme positions of ``quantity`` (default: the mechanism's declared output).

    Parameters
    ----------
    mech : Mechanism
    quantity : str, optional
        ``"P.x"``, ``"P.y"``, ``"L.theta"`` or ``"K.s"``.
    samples : int
        Size of the bracketing sweep over one revolution.
    xtol : float
        Absolute tolerance of the roots, rad.

    Raises
    ------
    InputError
        (a ``ValueError``) When the quantity has no extreme position over a revolution (it is monotonic or constant).
    """
    quantity = _output_quantity(mech, quantity)
    key = ("extremes", quantity, samples, xtol)
    cache = _cache(mech)
    if key not in cache:
        cache[key] = _find_extremes(mech, quantity, samples, xtol)
    return cache[key]


def _find_extremes(mech: Mechanism, quantity: str, samples: int, xtol: float) -> Extremes:
    def derivative(phi: float) -> float:
        return analyze(mech, [phi], order=1, outputs=[quantity]).quantity(quantity)[1][0]

    grid = np.linspace(0.0, 2 * np.pi, samples, endpoint=False)
    motion = analyze(mech, grid, order=1, outputs=[quantity], on_failure="mask")
    d1 = motion.quantity(quantity)[1]
    if not np.isfinite(d1).any():
        raise InputError(f"mechanism '{mech.name}' cannot be assembled at any input angle")
    scale = 1.0 if quantity.endswith(".theta") else mech.size  # an angle's analog is in rad/rad
    if not np.nanmax(np.abs(d1)) > 1e-12 * scale:
        raise InputError(f"'{quantity}' of mechanism '{mech.name}' does not move: it has no extreme "
                         "positions")
    step = 2 * np.pi / samples
    following = np.roll(d1, -1)  # cyclic: the last interval closes the revolution at 2 pi
    valid = np.isfinite(d1) & np.isfinite(following)
    roots = list(grid[valid & (d1 == 0.0)])
    for i in np.flatnonzero(valid & (d1 * following < 0)):
        roots.append(brentq(derivative, grid[i], grid[i] + step, xtol=xtol, rtol=4 * np.finfo(float).eps))
    if not roots:
        raise InputError(f"'{quantity}' of mechanism '{mech.name}' has no extreme position: its first "
                         "analog does not change sign over a revolution")
    roots = np.mod(roots, 2 * np.pi)
    roots = np.unique(np.where(roots > 2 * np.pi - 1e-12, 0.0, roots))
    values = analyze(mech, roots, order=0, outputs=[quantity]).quantity(quantity)[0]
    if quantity.endswith(".theta"):  # angles: compare across the +-pi cut
        values = values[0] + wrap_angle(values - values[0])
    i_max, i_min = int(np.argmax(values)), int(np.argmin(values))
    return Extremes(quantity, float(roots[i_max]), float(roots[i_min]), float(values[i_max]),
                    float(values[i_min]), roots)


def table_angles(mech: Mechanism, n: int = 12, start: str | float = "extreme", direction: int = 1,
                 quantity: str | None = None) -> np.ndarray:
    """Input angles ``phi_i = phi0 + direction (i - 1) 2 pi / n``, i = 1..n+1 (METHOD section 1).

    Parameters
    ----------
    n : int
        Number of equal steps per revolution.
    start : "extreme", "max", "min" or float
        ``"extreme"``: the extreme position of the output that the mechanism declares as the start
        (``output.start``); ``"max"`` / ``"min"``: that extreme of the output; a float: phi0 in
        degrees.
    direction : {1, -1}
        Sign of the input angular velocity (the order of positions).
    """
    if n < 1:
        raise InputError(f"the number of positions must be >= 1, got {n}")
    if direction not in (1, -1):
        raise InputError(f"direction must be +1 or -1, got {direction!r}")
    if isinstance(start, str):
        if start not in ("extreme", "max", "min"):
            raise InputError(f"start must be 'extreme', 'max', 'min' or an angle in deg, got {start!r}")
        which = start if start != "extreme" else (mech.output.start if mech.output else "max")
        ext = extreme_positions(mech, quantity)
        phi0 = ext.phi_max if which == "max" else ext.phi_min
    else:
        phi0 = np.radians(float(start))
    return phi0 + direction * np.arange(n + 1) * 2 * np.pi / n
