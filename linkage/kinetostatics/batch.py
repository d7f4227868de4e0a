"""Kinetostatics of a batch of design variants: masses and loads with a variants axis.

:func:`variant_reactions` takes the kinematics of V variants (:func:`linkage.analyze_variants`)
and each variant's masses, moments of inertia, centres of mass, external forces and moments as
arrays, and solves the reactions in every pair and the balancing moment of all V n positions in
one call, through the same group solvers as :func:`linkage.kinetostatics.reactions.solve_reactions`.

>>> import numpy as np, linkage
>>> from linkage.kinetostatics.batch import variant_reactions
>>> mech = linkage.load("four_bar")
>>> batch = linkage.analyze_variants(mech, np.radians([0.0, 90.0]), {"1": {"A": [[0.1, 0.0], [0.12, 0.0]]}})
>>> reactions = variant_reactions(batch, omega=10.0, mass={"2": [3.0, 4.0]})
>>> reactions.balancing_moment.shape
(2, 2)
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Mapping

import numpy as np
from numpy.typing import ArrayLike

from assur.base import point_analogs

from ..errors import InputError
from ..kinematics.batch import VariantMotion, link_points, repeat_per_angle
from .loads import LoadTerm, loads_of
from .reactions import Reactions, reactions_under, virtual_power_residual

__all__ = ["VariantReactions", "variant_reactions"]


@dataclass(frozen=True)
class VariantReactions:
    """Reactions of V variants at n input angles (see :func:`variant_reactions`).

    Attributes
    ----------
    variants : VariantMotion
        The kinematics.
    flat : Reactions
        The reactions of the V n positions flattened variant by variant (the arrays of the
        methods below, before reshaping).
    """

    variants: VariantMotion
    flat: Reactions

    @property
    def balancing_moment(self) -> np.ndarray:
        """``M_b`` ``(V, n)``, N m (CCW positive); NaN where the position's status is not OK."""
        return self.flat.balancing_moment.reshape(self.variants.status.shape)

    def force(self, pair: str) -> np.ndarray:
        """``R[a, b]`` ``(V, n, 2)`` for the pair declared with ``links = [a, b]``, N."""
        return self.flat.force(pair).reshape(*self.variants.status.shape, 2)

    def magnitude(self, pair: str) -> np.ndarray:
        """``|R[a, b]|`` ``(V, n)``, N."""
        return self.flat.magnitude(pair).reshape(self.variants.status.shape)

    def moment(self, pair: str) -> np.ndarray:
        """Prismatic pair: moment ``(V, n)`` of the slider on the guide about the slider's point, N m."""
        return self.flat.moment(pair).reshape(self.variants.status.shape)

    def virtual_power_residual(self) -> np.ndarray:
        """The virtual-power check of every position ``(V, n)`` (see
        :func:`linkage.kinetostatics.reactions.virtual_power_residual`; <= 1e-9 where the status is OK)."""
        return virtual_power_residual(self.flat).reshape(self.variants.status.shape)


def variant_reactions(
    variants: VariantMotion,
    *,
    omega: ArrayLike | None = None,
    eps: ArrayLike = 0.0,
    mass: Mapping[str, ArrayLike] | None = None,
    inertia: Mapping[str, ArrayLike] | None = None,
    center_of_mass: Mapping[str, ArrayLike] | None = None,
    forces: Mapping[str, Mapping[str, ArrayLike]] | None = None,
    moments: Mapping[str, ArrayLike] | None = None,
    gravity: ArrayLike | None = None,
) -> VariantReactions:
    """Reactions in every pair and the balancing moment of a batch of variants, in one call.

    Every per-variant value may be a constant, an array with the variants axis first (``(V,)``
    for a scalar, ``(V, 2)`` for a vector) or with the variants and the positions axes
    (``(V, n)``, ``(V, n, 2)``).

    Parameters
    ----------
    variants : VariantMotion
        Kinematics of the variants with second analogs (``analyze_variants(..., order=2)``).
    omega, eps : float or array_like, optional
        Input speed (rad/s) and angular acceleration (rad/s^2) per variant or per position.
        Without ``omega`` the analysis is static (no inertia loads; a note says so).
    mass : mapping link -> array_like, optional
        Masses, kg (default: the base mechanism's).
    inertia : mapping link -> array_like, optional
        Moments of inertia about the centre of mass, kg m^2 (default: the base mechanism's).
    center_of_mass : mapping link -> array_like (2,) or (V, 2), optional
        Centres of mass in the link's frame, m. Default: the variant's own position of the point
        the base mechanism's centre of mass lies on (``com = "S2"`` follows S2 of each variant's
        geometry), else the base mechanism's coordinates.
    forces : mapping link -> {point -> array_like (2,), (V, 2) or (V, n, 2)}, optional
        External forces (Fx, Fy), N, at points of links (the points of the variants' geometry).
    moments : mapping link -> array_like, optional
        External moments on links, N m, CCW positive.
    gravity : array_like (2,), optional
        m/s^2; default: the base mechanism's (``[loads] gravity``).

    Returns
    -------
    VariantReactions

    Raises
    ------
    InputError
        When the batch has no second analogs, an entry names an unknown link or point, a shape
        fits neither V nor (V, n), or the mechanism declares external loads (diagrams, tables,
        constants) and neither ``forces`` nor ``moments`` is given: a batch takes its loads as
        arrays (``forces={}`` for none).
    """
    mech = variants.mechanism
    if variants.second is None:
        raise InputError("reactions need the variants' second analogs: analyze_variants(..., order=2)")
    count, n = variants.status.shape
    declared = loads_of(mech)
    if (declared.forces or declared.moments) and forces is None and moments is None:
        named = [f"force at '{f.point}'" for f in declared.forces] + [f"moment on '{m.link}'" for m in declared.moments]
        raise InputError(f"mechanism '{mech.name}' declares external loads ({', '.join(named)}); a batch of variants "
                         "takes its loads as arrays: pass forces={link: {point: ...}} and/or moments={link: ...} "
                         "(forces={} for none)")
    shape = (count, n)

    def values(value, what: str, tail: tuple[int, ...] = ()) -> np.ndarray:
        return _flat(value, shape, tail, what)

    g = values(declared.gravity if gravity is None else gravity, "gravity", (2,))
    motion = variants.flat(None if omega is None else values(omega, "omega"), values(eps, "eps"))
    for entries, what in ((mass, "mass"), (inertia, "inertia"), (center_of_mass, "center_of_mass"),
                          (moments, "moments"), (forces, "forces")):
        unknown = sorted(set(entries or {}) - set(mech.moving_links))
        if unknown:
            raise InputError(f"{what}: mechanism '{mech.name}' has no moving link(s) {unknown} "
                             f"(moving links {sorted(mech.moving_links)})")
    terms = []
    for k in mech.moving_links:
        link = mech.links[k]
        m = values((mass or {}).get(k, link.mass), f"mass['{k}']")
        J = values((inertia or {}).get(k, link.inertia), f"inertia['{k}']")
        if np.any(m < 0) or np.any(J < 0):
            raise InputError(f"mass['{k}'] and inertia['{k}'] must be nonnegative")
        if not (np.any(m) or np.any(J)):
            continue
        center = _center(variants, k, (center_of_mass or {}).get(k), shape)
        if np.any(g) and np.any(m):
            terms.append(LoadTerm(k, center, m[:, None] * g, np.zeros(len(m)), "gravity", f"G{k}"))
        if motion.omega is not None:
            d1, d2 = point_analogs(motion.poses[k], motion.first[k], motion.second[k], center,
                                   motion.arm(k, center))
            w, e = motion.omega, motion.eps
            acc = d2 * (w**2)[:, None] + d1 * e[:, None]
            eps_k = motion.second[k][:, 2] * w**2 + motion.first[k][:, 2] * e
            terms.append(LoadTerm(k, center, -m[:, None] * acc, -J * eps_k, "inertia", f"Fi{k}"))
    for k, point, value in link_points(mech, forces or {}, "forces", "forces (Fx, Fy)"):
        local = repeat_per_angle(variants.geometry[k][point], n)
        force = values(value, f"forces['{k}']['{point}']", (2,))
        terms.append(LoadTerm(k, local, force, np.zeros(len(force)), "external", f"F{point}"))
    for k, value in (moments or {}).items():
        moment = values(value, f"moments['{k}']")
        terms.append(LoadTerm(k, (0.0, 0.0), np.zeros((len(moment), 2)), moment, "external", f"M{k}"))
    notes = () if omega is not None else ("no speed given: inertia loads are zero (static analysis)",)
    return VariantReactions(variants, reactions_under(motion, terms, notes=notes))


def _flat(value: ArrayLike, shape: tuple[int, int], tail: tuple[int, ...], what: str) -> np.ndarray:
    """A constant, per-variant ``(V, *tail)`` or per-position ``(V, n, *tail)`` value as
    ``(V n, *tail)`` floats (finite)."""
    arr = np.asarray(value, dtype=float)
    count, n = shape
    if arr.shape == tail:
        out = np.broadcast_to(arr, (count * n, *tail))
    elif arr.shape == (count, *tail):
        out = np.repeat(arr, n, axis=0)
    elif arr.shape == (count, n, *tail):
        out = arr.reshape(count * n, *tail)
    else:
        raise InputError(f"{what}: expected shape {tail or '()'} (one value), {(count, *tail)} (per variant) or "
                         f"{(count, n, *tail)} (per variant and position), got {arr.shape}")
    if not np.all(np.isfinite(out)):
        raise InputError(f"{what} must be finite")
    return np.ascontiguousarray(out)


def _center(variants: VariantMotion, link: str, given, shape: tuple[int, int]) -> np.ndarray:
    """Centres of mass ``(V n, 2)`` of ``link`` in its frame (see :func:`variant_reactions`)."""
    count, n = shape
    if given is not None:
        return _flat(given, shape, (2,), f"center_of_mass['{link}']")
    base = variants.mechanism.links[link]
    on = [p for p, xy in base.points.items() if np.allclose(xy, base.center_of_mass, rtol=0, atol=0)]
    if on:
        return repeat_per_angle(variants.geometry[link][sorted(on)[0]], n)
    return np.broadcast_to(np.asarray(base.center_of_mass, float), (count * n, 2))
