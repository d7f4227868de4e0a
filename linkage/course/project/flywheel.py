"""The flywheel by the course's graphical construction, and its dimensions as a rim.

- :func:`wittenbauer_tangents` -- the energy–inertia (Wittenbauer) diagram ΔT against I'':
  the two tangents to the curve at the angles the course prescribes,
  ``tan ψ_max = (μ_I / 2μ_T)·ω_m²·(1 + δ)`` and ``tan ψ_min = (μ_I / 2μ_T)·ω_m²·(1 − δ)``
  (ψ the tangent's angle with the I'' axis on paper), and the segment ``kl`` they cut on the
  ΔT axis; the constant inertia they give, ``I' = μ_T·kl / (ω_m²·δ)``.
- :func:`rim_for_inertia` -- a flywheel rim of mean diameter D, width b = ψ_b·D and height
  h = ψ_h·D with the moment of inertia I: ``D = (4·I / (π·ρ·ψ_b·ψ_h))^(1/5)``, ``m = ρ·π·D·b·h``,
  ``I = m·D²/4``.

How the tangents' inertia relates to Mertsalov's method (docs/methods.md, "Mertsalov's method"):
the diagram is drawn against the *variable* part I'' of the reduced inertia, so the segment kl
gives the whole constant inertia the machine needs, I_0 included (Mertsalov's ``I'``); the
flywheel to add is ``I' − I_0``. On paper, with physical slopes ``k_± = ω_m²·(1 ± δ)/2`` (J per
kg m²), the tangents' intercepts are ``c_max = max(ΔT − k_+·I'')`` and
``c_min = min(ΔT − k_−·I'')``; Mertsalov takes ``I''`` at ω_m for both (the intercepts of two
parallel lines at ``ω_m²/2``), so the two answers differ by at most ``max I''`` (kg m²): by an
amount of order δ, not a drawing error.

>>> import numpy as np
>>> t = wittenbauer_tangents(np.array([0.0, 50.0, 0.0]), np.array([1.0, 1.0, 1.0]), 10.0, 0.05)
>>> round(t.constant_inertia, 6)   # (c_max - c_min) / (w_m^2 delta) = (-2.5 + 47.5) / 5; Mertsalov: 50 / 5
9.0
>>> rim = rim_for_inertia(10.0)
>>> round(rim.mass * rim.diameter**2 / 4, 9)
10.0
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

__all__ = ["STEEL_DENSITY", "CAST_IRON_DENSITY", "RIM_WIDTH_RATIO", "RIM_HEIGHT_RATIO", "Tangents",
           "wittenbauer_tangents", "tangent_angles", "Rim", "rim_for_inertia"]

#: density of steel, kg/m³ (the rim's default material)
STEEL_DENSITY = 7800.0
#: density of cast iron, kg/m³
CAST_IRON_DENSITY = 7200.0
#: the rim's width over its mean diameter, ψ_b = b / D (the course's usual 0.1 .. 0.3)
RIM_WIDTH_RATIO = 0.2
#: the rim's radial height over its mean diameter, ψ_h = h / D (the course's usual 0.1 .. 0.2)
RIM_HEIGHT_RATIO = 0.15


@dataclass(frozen=True)
class Tangents:
    """The two tangents of the energy–inertia diagram, in physical units.

    Each tangent is the line ``ΔT = intercept + slope·I''`` touching the curve from above
    (``upper``: the largest speed, ω_m(1 + δ/2)) or below (``lower``).

    Attributes
    ----------
    slope_upper, slope_lower : float
        ``ω_m²(1 + δ)/2`` and ``ω_m²(1 − δ)/2``, J/(kg m²).
    intercept_upper, intercept_lower : float
        Where they cut the ΔT axis (I'' = 0): the points k and l, J.
    touch_upper, touch_lower : int
        Index of the curve's point each tangent touches (the first where several do).
    mean_speed, delta : float
        ``ω_m`` (rad/s, > 0) and δ the tangents were drawn for.
    """

    slope_upper: float
    slope_lower: float
    intercept_upper: float
    intercept_lower: float
    touch_upper: int
    touch_lower: int
    mean_speed: float
    delta: float

    @property
    def segment(self) -> float:
        """``kl`` in J: the upper tangent's intercept less the lower one's."""
        return self.intercept_upper - self.intercept_lower

    @property
    def constant_inertia(self) -> float:
        """``I' = kl / (ω_m²·δ)`` (kg m²): the constant inertia at the crank the tangents call
        for, I_0 included (on paper: ``μ_T·kl_mm / (ω_m²·δ)``)."""
        return self.segment / (self.mean_speed**2 * self.delta)


def wittenbauer_tangents(energy: ArrayLike, inertia_variable: ArrayLike, mean_speed: float,
                         delta: float) -> Tangents:
    """The tangents to the energy–inertia curve (ΔT against I'') at the course's angles.

    The curve is the polygon through the table positions (as drawn), so a tangent touches it
    at a vertex: the upper one at the largest ``ΔT − k_+·I''``, the lower one at the smallest
    ``ΔT − k_−·I''``.

    Parameters
    ----------
    energy : array_like (n,)
        ``ΔT`` at the positions, J (the change of kinetic energy from position 1).
    inertia_variable : array_like (n,)
        ``I''`` at the positions, kg m² (the reduced inertia's variable part).
    mean_speed : float
        ``ω_m``, rad/s (its magnitude is used).
    delta : float
        The coefficient of speed fluctuation, 0 < δ < 2.

    Returns
    -------
    Tangents

    Raises
    ------
    ValueError
        Arrays of different or zero length, not finite, a zero or non-finite speed, δ outside (0, 2).
    """
    e = np.asarray(energy, float)
    i2 = np.asarray(inertia_variable, float)
    if e.ndim != 1 or e.shape != i2.shape or e.size == 0 or not (np.all(np.isfinite(e)) and np.all(np.isfinite(i2))):
        raise ValueError(f"energy and inertia_variable must be finite arrays of one equal length, got shapes "
                         f"{e.shape} and {i2.shape}")
    w = abs(float(mean_speed))
    if not (math.isfinite(w) and w > 0):
        raise ValueError(f"mean_speed must be finite and nonzero, got {mean_speed!r}")
    if not (math.isfinite(delta) and 0 < delta < 2):
        raise ValueError(f"delta must be in (0, 2), got {delta!r}")
    upper, lower = w * w * (1 + delta) / 2, w * w * (1 - delta) / 2
    above, below = e - upper * i2, e - lower * i2
    k, m = int(np.argmax(above)), int(np.argmin(below))
    return Tangents(float(upper), float(lower), float(above[k]), float(below[m]), k, m, w, float(delta))


def tangent_angles(mu_inertia: float, mu_energy: float, mean_speed: float, delta: float) -> tuple[float, float]:
    """The tangents' angles with the I'' axis on paper, degrees: ``(ψ_max, ψ_min)`` with
    ``tan ψ = (μ_I / 2μ_T)·ω_m²·(1 ± δ)``.

    Parameters
    ----------
    mu_inertia : float
        μ_I, (kg m²)/mm.
    mu_energy : float
        μ_T, J/mm.
    mean_speed : float
        ω_m, rad/s.
    delta : float
        δ.

    >>> [round(a, 3) for a in tangent_angles(0.1, 10.0, 10.0, 0.05)]
    [27.699, 25.408]
    """
    base = mu_inertia / (2 * mu_energy) * float(mean_speed) ** 2
    return math.degrees(math.atan(base * (1 + delta))), math.degrees(math.atan(base * (1 - delta)))


@dataclass(frozen=True)
class Rim:
    """A flywheel rim: a ring of rectangular section, sized for a moment of inertia.

    Attributes
    ----------
    inertia : float
        The moment of inertia it was sized for, kg m².
    density : float
        ρ, kg/m³.
    width_ratio, height_ratio : float
        ψ_b = b/D and ψ_h = h/D.
    diameter : float
        D, the rim's mean diameter, m.
    width, height : float
        b (along the shaft) and h (radial), m.
    mass : float
        ``m = ρ·π·D·b·h``, kg.
    """

    inertia: float
    density: float
    width_ratio: float
    height_ratio: float
    diameter: float
    width: float
    height: float
    mass: float

    @property
    def outer_diameter(self) -> float:
        """``D + h``, m."""
        return self.diameter + self.height

    @property
    def inner_diameter(self) -> float:
        """``D − h``, m."""
        return self.diameter - self.height


def rim_for_inertia(inertia: float, density: float = STEEL_DENSITY, width_ratio: float = RIM_WIDTH_RATIO,
                    height_ratio: float = RIM_HEIGHT_RATIO) -> Rim:
    """The rim with the moment of inertia ``inertia`` (the course's thin-rim sizing).

    The rim's mass concentrated on its mean diameter: ``I = m·D²/4`` with ``m = ρ·π·D·b·h`` and
    ``b = ψ_b·D``, ``h = ψ_h·D``, so ``D = (4·I / (π·ρ·ψ_b·ψ_h))^(1/5)``.

    Parameters
    ----------
    inertia : float
        I, kg m² (> 0).
    density : float
        ρ, kg/m³ (default steel, 7800; cast iron 7200).
    width_ratio, height_ratio : float
        ψ_b and ψ_h (> 0); ψ_h < 1 so the rim has a bore.

    Returns
    -------
    Rim

    Raises
    ------
    ValueError
        A value that is not a finite positive number, or ``height_ratio`` >= 1.
    """
    for name, value in (("inertia", inertia), ("density", density), ("width_ratio", width_ratio),
                        ("height_ratio", height_ratio)):
        if not (isinstance(value, (int, float, np.integer, np.floating)) and math.isfinite(value) and value > 0):
            raise ValueError(f"{name} must be a finite number > 0, got {value!r}")
    if height_ratio >= 1:
        raise ValueError(f"height_ratio must be below 1 (the rim's height h = ψ_h·D under its mean diameter), "
                         f"got {height_ratio!r}")
    diameter = (4 * inertia / (math.pi * density * width_ratio * height_ratio)) ** 0.2
    width, height = width_ratio * diameter, height_ratio * diameter
    mass = density * math.pi * diameter * width * height
    return Rim(float(inertia), float(density), float(width_ratio), float(height_ratio), diameter, width, height, mass)
