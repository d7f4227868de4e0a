"""Extreme positions of an output coordinate and the input angles of position tables.

An extreme position is a root of the output's first analog ``q'(phi) = 0`` (docs/methods.md,
"Extreme positions and table positions"), found by bracketing on a sweep and refining with Brent's
method to ~1e-13 rad. Over a mechanism's input range (``range_deg``) the range's ends are
candidates too.

>>> import math, linkage
>>> ext = linkage.extreme_positions(linkage.load("slider_crank"), "B.x")
>>> round(math.degrees(ext.phi_max), 3)
2.579
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import brentq

from assur.base import NOT_CONVERGED

from ..errors import InputError
from ..model.mechanism import Mechanism
from .full_turn import input_cannot_turn
from .motion import analyze

__all__ = ["Extremes", "NO_STROKE", "extreme_positions", "table_angles", "wrap_angle"]

#: A stroke at most this (rad for an angle; times the mechanism's size for a coordinate in m) is
#: none: the quantity does not move (:meth:`Extremes.moves`)
NO_STROKE = 1e-9


@dataclass(frozen=True)
class Extremes:
    """Extreme positions of one output quantity.

    Attributes
    ----------
    quantity : str
    phi_max, phi_min : float
        Input angles (rad, in [0, 2 pi); within the mechanism's ``input_range`` when it declares
        one) where the quantity is largest / smallest.
    value_max, value_min : float
        The quantity there (m or rad).
    roots : ndarray
        Every root of the first analog found in [0, 2 pi) (within the input range), sorted.
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

    def moves(self, size: float) -> bool:
        """Whether the quantity has a stroke: more than :data:`NO_STROKE` rad for an angle
        (``*.theta``), more than ``NO_STROKE * size`` for a coordinate in m (``size``: the
        mechanism's, m)."""
        return self.stroke > NO_STROKE * (1.0 if self.quantity.endswith(".theta") else size)


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

    Over a revolution, the extremes are roots of the first analog. A mechanism with an
    ``input_range`` is searched within the range only: its extremes are the largest and smallest
    values among the roots inside the range and the range's two ends (an output that is monotonic
    over the range has its extremes at the ends).

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
    cache = mech.cache
    if key not in cache:
        cache[key] = _find_extremes(mech, quantity, samples, xtol)
    return cache[key]


def _analog_root(mech: Mechanism, quantity: str, derivative, a: float, b: float, xtol: float) -> float:
    """The root of ``quantity``'s first analog between the sweep's input coordinates ``a`` and ``b``,
    where the sweep found it changing sign; InputError when the analyses at ``a`` and ``b`` alone
    do not confirm the change (the motion is not resolved there: e.g. an input law that turns a
    further input too fast for float64)."""
    try:
        return brentq(derivative, a, b, xtol=xtol, rtol=4 * np.finfo(float).eps)
    except ValueError:  # scipy: f(a) and f(b) must have different signs
        ends = " and ".join(f"{v:.6g}" for v in mech.coordinate.shown([a, b]))
        raise InputError(f"'{quantity}' of mechanism '{mech.name}': its first analog changes sign between the "
                         f"input {mech.coordinate.kind}s {ends} {mech.coordinate.shown_unit} over the sweep, but "
                         "not when analysed at these two alone: the motion is not resolved there (e.g. an input "
                         "law with a huge ratio), so its extreme positions cannot be found") from None


def _find_extremes(mech: Mechanism, quantity: str, samples: int, xtol: float) -> Extremes:
    def derivative(phi: float) -> float:
        return analyze(mech, [phi], order=1, outputs=[quantity]).quantity(quantity)[1][0]

    if mech.input_range is not None:
        return _find_extremes_in_range(mech, quantity, samples, xtol, derivative)

    grid = np.linspace(0.0, 2 * np.pi, samples, endpoint=False)
    motion = analyze(mech, grid, order=1, outputs=[quantity], on_failure="mask")
    d1 = motion.quantity(quantity)[1]
    if not np.isfinite(d1).any():
        _raise_unconverged(mech, grid, quantity, motion.status)
        raise InputError(f"mechanism '{mech.name}' cannot be assembled at any input angle")
    scale = 1.0 if quantity.endswith(".theta") else mech.size  # an angle's analog is in rad/rad
    if not np.nanmax(np.abs(d1)) > 1e-12 * scale:
        raise _first_the_turn(mech, f"'{quantity}' of mechanism '{mech.name}' does not move: it has no extreme "
                              "positions")
    step = 2 * np.pi / samples
    following = np.roll(d1, -1)  # cyclic: the last interval closes the revolution at 2 pi
    valid = np.isfinite(d1) & np.isfinite(following)
    roots = list(grid[valid & (d1 == 0.0)])
    for i in np.flatnonzero(valid & (d1 * following < 0)):
        roots.append(_analog_root(mech, quantity, derivative, grid[i], grid[i] + step, xtol))
    if not roots:
        raise _first_the_turn(mech, f"'{quantity}' of mechanism '{mech.name}' has no extreme position: its first "
                              "analog does not change sign over a revolution")
    roots = np.mod(roots, 2 * np.pi)
    roots = np.unique(np.where(roots > 2 * np.pi - 1e-12, 0.0, roots))
    values = analyze(mech, roots, order=0, outputs=[quantity]).quantity(quantity)[0]
    if quantity.endswith(".theta"):  # angles: compare across the +-pi cut
        values = values[0] + wrap_angle(values - values[0])
    i_max, i_min = int(np.argmax(values)), int(np.argmin(values))
    return Extremes(quantity, float(roots[i_max]), float(roots[i_min]), float(values[i_max]),
                    float(values[i_min]), roots)


def _first_the_turn(mech: Mechanism, refusal: str) -> InputError:
    """The refusal, told after its cause when the input cannot turn fully (the sweep then misses
    the angles where the mechanism does not assemble)."""
    why = input_cannot_turn(mech)
    return InputError(refusal if why is None else f"{why}; so {refusal}")


def _raise_unconverged(mech: Mechanism, grid: np.ndarray, quantity: str, status: np.ndarray) -> None:
    """Where Newton's method did not converge, raise its :class:`~linkage.errors.ConvergenceError`
    (naming the group, the angles and the residuals) rather than "cannot be assembled"."""

    if np.any(status == NOT_CONVERGED):
        analyze(mech, grid[status == NOT_CONVERGED], order=1, outputs=[quantity])


def _find_extremes_in_range(mech: Mechanism, quantity: str, samples: int, xtol: float,
                            derivative) -> Extremes:
    """Extremes within ``mech.input_range``: among the roots of the analog inside it (found as
    over a turn, without wrapping) and the range's two ends."""
    lo, hi = sorted(mech.input_range)
    grid = np.linspace(lo, hi, samples + 1)
    motion = analyze(mech, grid, order=1, outputs=[quantity], on_failure="mask")
    value, d1, _ = motion.quantity(quantity)
    if not np.isfinite(d1).any():
        _raise_unconverged(mech, grid, quantity, motion.status)
        raise InputError(f"mechanism '{mech.name}' cannot be assembled at any input {mech.coordinate.kind} of its "
                         "range")
    scale = 1.0 if quantity.endswith(".theta") else mech.size
    if not mech.coordinate.is_angle:    # analogs per m of the slide: angles 1/m, lengths 1
        scale /= mech.size
    if not np.nanmax(np.abs(d1)) > 1e-12 * scale:
        raise InputError(f"'{quantity}' of mechanism '{mech.name}' does not move over the input range: it "
                         "has no extreme positions")
    valid = np.isfinite(d1[:-1]) & np.isfinite(d1[1:])
    roots = list(grid[np.flatnonzero(np.isfinite(d1) & (d1 == 0.0))])
    for i in np.flatnonzero(valid & (d1[:-1] * d1[1:] < 0)):
        roots.append(_analog_root(mech, quantity, derivative, grid[i], grid[i + 1], xtol))
    roots = np.unique(roots)
    candidates = np.concatenate([[lo, hi], roots])
    values = analyze(mech, candidates, order=0, outputs=[quantity], on_failure="mask").quantity(quantity)[0]
    if quantity.endswith(".theta"):  # angles: continuous over the range, across the +-pi cut
        values = _unwrapped_at(grid, value, candidates, values)
    i_max, i_min = int(np.nanargmax(values)), int(np.nanargmin(values))
    return Extremes(quantity, float(candidates[i_max]), float(candidates[i_min]), float(values[i_max]),
                    float(values[i_min]), roots)


def _unwrapped_at(grid, value, phi, found):
    """The angles ``found`` at ``phi`` on the continuous branch of ``value`` sampled on ``grid``."""
    smooth = np.unwrap(value)
    near = np.interp(phi, grid, smooth)
    return near + wrap_angle(found - near)


def table_angles(mech: Mechanism, n: int = 12, start: str | float = "extreme", direction: int = 1,
                 quantity: str | None = None, *, span: tuple[float, float] | None = None) -> np.ndarray:
    """Input angles ``phi_i = phi0 + direction (i - 1) 2 pi / n``, i = 1..n+1 (docs/conventions.md,
    "Table positions").

    Over an input range ``(a, b)`` (rad: ``span``, default the mechanism's ``input_range``) the
    angles are ``phi_i = a + (i - 1) (b - a) / n`` instead: the table runs from a to b as written,
    whatever ``direction``; ``start`` must then be ``"extreme"`` (the default), since the range
    fixes position 1.

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
    span = mech.input_range if span is None else span
    if span is not None:
        a, b = (float(v) for v in span)
        if not mech.coordinate.is_angle:    # a slide input's stroke, m
            if not (np.isfinite(a) and np.isfinite(b) and a != b):
                raise InputError(f"a stroke must be two finite slides that differ, got {a:.10g}, {b:.10g} m")
            if not (isinstance(start, str) and start == "extreme"):
                raise InputError(f"mechanism '{mech.name}' is analysed over the stroke [{a:.10g}, {b:.10g}] m of "
                                 f"its slide input, which fixes position 1 at its first end: a start ({start!r}) "
                                 "applies only to a full turn of a crank")
            return a + (b - a) * np.arange(n + 1) / n
        if not (np.isfinite(a) and np.isfinite(b) and 0 < abs(b - a) < 2 * np.pi):
            raise InputError(f"an input range must be two finite angles that differ by more than 0 and less "
                             f"than a full turn, got {np.degrees(a):.10g}, {np.degrees(b):.10g} deg")
        if not (isinstance(start, str) and start == "extreme"):
            raise InputError(f"mechanism '{mech.name}' is analysed over the input range [{np.degrees(a):.10g}, "
                             f"{np.degrees(b):.10g}] deg, which fixes position 1 at its first end: a start "
                             f"({start!r}) applies only to a full turn")
        return a + (b - a) * np.arange(n + 1) / n
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
