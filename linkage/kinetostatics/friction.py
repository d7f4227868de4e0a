"""Coulomb friction in the pairs, in motion (docs/methods.md#friction-in-the-pairs).

A scheme declares it in ``[friction]``::

    [friction]
    revolute = { f = 0.1, radius = 0.02 }    # every revolute pair: friction circle rho = f * radius
    prismatic = { f = 0.15 }                  # every prismatic pair (length = block length, m)
    pairs.A = { f = 0.08, radius = 0.025 }    # one pair's own values

parsed once with the scheme into a :class:`Friction` (:func:`friction_of`). The model:

- a revolute pair between links a and b: a moment ``f·r·|R|`` on each link, opposing their
  relative rotation (``−sign(ω_a − ω_b)`` on a, the opposite on b);
- a prismatic pair: a force ``f·|N|`` along the guide through the slider's point, on the slider
  against its sliding relative to the guide, and its opposite on the guide link; with a block of
  ``length`` L the pair's moment M is carried by two edge forces ``N1, N2 = N/2 ± M/L`` and the
  friction is ``f·(|N1| + |N2|)``;
- where the relative motion stops (a rocker's reversal) its sense is that of the motion that
  follows (the sign of the relative second analog); where a pair never moves it carries none.

The friction loads are :class:`~linkage.kinetostatics.loads.LoadTerm` of kind ``"friction"``
(label: the pair), so every balance that sums load terms (virtual power, reduced moments) counts
them. They depend on the reactions they help to produce: :func:`group_with_friction` solves a
group by a fixed-point iteration from the frictionless solution and flags the positions where it
does not converge -- there no finite load moves the group against its friction (self-locking).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Callable, Mapping

import numpy as np

from assur.base import PrismaticJoint, RevoluteJoint, cross

from ..model.mechanism import Mechanism
from ..model.numbers import check_number, unknown_keys
from ..model.scheme import register_section, section_of
from .loads import LoadTerm, generalized_loads

__all__ = ["PairFriction", "Friction", "friction_of", "parse_friction", "friction_terms", "group_with_friction",
           "FRICTION_TOL", "FIXED_POINT_STEPS", "FRICTION_ITERATIONS", "LOCKED_GROWTH"]

#: a group's reactions with friction are converged when no multiplier changes by more than this
#: relative to the group's largest one (and the loads' scale)
FRICTION_TOL = 1e-13
#: plain fixed-point iterations before Newton's method takes over
FIXED_POINT_STEPS = 30
#: Newton steps before a position is called self-locking
FRICTION_ITERATIONS = 40
#: reactions this many times the frictionless ones: the group is self-locking there
LOCKED_GROWTH = 1e8
#: a relative analog below this (rad per unit of the input; m per unit for a slide, over the
#: mechanism's size) is a stop of the relative motion: its sense is taken from the second analog
STOP_TOL = 1e-9


@dataclass(frozen=True)
class PairFriction:
    """One pair's friction: ``f`` (≥ 0); ``radius`` (m, revolute: the journal's, so the friction
    circle is ``f·radius``); ``length`` (m, prismatic: the slider block's, None for one contact)."""

    pair: str
    kind: str
    f: float
    radius: float | None = None
    length: float | None = None


@dataclass(frozen=True)
class Friction:
    """The friction of a mechanism's pairs: pair name -> :class:`PairFriction` (pairs with f = 0
    left out)."""

    pairs: Mapping[str, PairFriction] = field(default_factory=dict)

    def __bool__(self) -> bool:
        return bool(self.pairs)


_CLASS_KEYS = {"revolute": ("R", {"f", "radius"}), "prismatic": ("P", {"f", "length"})}


def parse_friction(mech: Mechanism, raw: Mapping[str, Any] | None) -> tuple[Friction | None, list[str]]:
    """The :class:`Friction` of a scheme's ``[friction]`` table (None without one) and the list of
    problems: negative or non-finite values, a pair that does not exist, a radius on a prismatic
    pair, a length on a revolute one, a revolute pair without a radius."""
    if raw is None:
        return None, []
    problems: list[str] = []
    if not isinstance(raw, Mapping):
        return None, [f"expected a table, got {raw!r}"]
    unknown_keys(raw, {"revolute", "prismatic", "pairs"}, "", problems)
    defaults: dict[str, dict] = {}
    for key, (kind, keys) in _CLASS_KEYS.items():
        if key in raw:
            spec = _entry(raw[key], key, kind, keys, problems)
            if spec is not None:
                defaults[kind] = spec
    own: dict[str, dict] = {}
    pairs_raw = raw.get("pairs", {})
    if not isinstance(pairs_raw, Mapping):
        problems.append(f"pairs: expected a table of pair name -> {{ f = ..., radius = ... }}, got {pairs_raw!r}")
        pairs_raw = {}
    for name, spec in pairs_raw.items():
        pair = mech.pairs.get(name)
        if pair is None:
            problems.append(f"pairs.{name}: mechanism '{mech.name}' has no pair '{name}' "
                            f"(its pairs: {', '.join(sorted(mech.pairs))})")
            continue
        kind = pair.kind
        keys = _CLASS_KEYS["revolute" if kind == "R" else "prismatic"][1]
        entry = _entry(spec, f"pairs.{name}", kind, keys, problems, partial=kind in defaults)
        if entry is not None:
            own[name] = entry
    result: dict[str, PairFriction] = {}
    no_radius: dict[str, list[str]] = {}
    for name, pair in sorted(mech.pairs.items()):
        spec = {**defaults.get(pair.kind, {}), **own.get(name, {})}
        if not spec or spec.get("f", 0.0) == 0.0:
            continue
        if pair.kind == "R" and spec.get("radius") is None:
            no_radius.setdefault(f"pairs.{name}" if name in own else "revolute", []).append(name)
            continue
        result[name] = PairFriction(name, pair.kind, spec["f"], spec.get("radius"), spec.get("length"))
    for where, names in no_radius.items():
        problems.append(f"{where}: needs radius = r (m, the journal's radius: the friction moment is f·r·|R|) "
                        f"for the revolute pair(s) {', '.join(names)}")
    return Friction(result), problems


def _entry(spec: Any, where: str, kind: str, keys: set[str], problems: list[str], partial: bool = False
           ) -> dict | None:
    """One ``{ f = ..., radius = ... }`` entry, checked; None with its problems."""
    if not isinstance(spec, Mapping):
        problems.append(f"{where}: expected a table like {{ f = 0.1{', radius = 0.02' if kind == 'R' else ''} }}, "
                        f"got {spec!r}")
        return None
    before = len(problems)
    wrong = {"radius": "a radius belongs to a revolute pair (its journal); a prismatic pair takes f and "
                       "length (the slider block's, m)",
             "length": "a length belongs to a prismatic pair (its slider block); a revolute pair takes f and "
                       "radius (its journal's, m)"}
    for key in spec:
        if key in wrong and key not in keys:
            problems.append(f"{where}: {key} = {spec[key]!r}: {wrong[key]}")
    unknown_keys({k: v for k, v in spec.items() if k not in wrong}, keys, where, problems)
    out: dict = {}
    if "f" in spec:
        out["f"] = check_number(spec["f"], where, "f", problems, "nonnegative")
    elif not partial:
        problems.append(f"{where}: needs f, the coefficient of friction (a number >= 0)")
    for key in ("radius", "length"):
        if key in spec and key in keys:
            out[key] = check_number(spec[key], where, key, problems, "positive", "m")
    return out if len(problems) == before else None


def friction_of(mech: Mechanism) -> Friction | None:
    """The friction the mechanism declares (``[friction]``), None without the section."""
    return section_of(mech, "friction")


register_section("friction", parse_friction)


# ----------------------------------------------------------------------------------------------
# the friction loads of given reactions
# ----------------------------------------------------------------------------------------------


def _sense(first: np.ndarray, second: np.ndarray | None, scale: float, sense: np.ndarray) -> np.ndarray:
    """The sign of a relative motion in time: of the first analog times the input's sense, else
    (where it stops) of the second analog (the motion that follows), else 0."""
    moving = np.abs(first) > STOP_TOL * scale
    after = np.sign(second) if second is not None else np.zeros_like(first)
    return np.where(moving, np.sign(first) * sense, after)


def friction_terms(motion, friction: Friction, multipliers: Mapping[str, np.ndarray], sense: np.ndarray
                   ) -> list[LoadTerm]:
    """The friction loads of the pairs in ``multipliers`` that have friction, at the reactions
    the multipliers give (:class:`~linkage.kinetostatics.reactions.Reactions`' convention).

    Parameters
    ----------
    motion : Motion
        With first and second analogs.
    friction : Friction
    multipliers : dict of pair -> ndarray (N, 2 or 3)
    sense : ndarray (N,)
        The input's sense of motion (+1 its coordinate increasing, -1 decreasing).

    Returns
    -------
    list of LoadTerm
        Two per pair (one on each of its links), kind ``"friction"``, label the pair's name; each
        at the link's origin (its moment about the origin included).
    """
    terms: list[LoadTerm] = []
    size = motion.mechanism.size
    no_force = np.zeros((len(motion.phi), 2))
    for name, lam in multipliers.items():
        spec = friction.pairs.get(name)
        joint = motion.joints.get(name)
        if spec is None or joint is None:
            continue
        a, b = joint.a, joint.b
        if isinstance(joint, RevoluteJoint):
            rel = motion.first[a][:, 2] - motion.first[b][:, 2]
            rel2 = motion.second[a][:, 2] - motion.second[b][:, 2]
            moment = -spec.f * spec.radius * np.hypot(lam[:, 0], lam[:, 1]) * _sense(rel, rel2, 1.0, sense)
            terms += [LoadTerm(a, (0.0, 0.0), no_force, moment, "friction", name),
                      LoadTerm(b, (0.0, 0.0), no_force, -moment, "friction", name)]
        elif isinstance(joint, PrismaticJoint):
            u, _, _, pb, _ = joint.frame(motion.poses)
            _, s1, s2 = joint.slide(motion.poses, motion.first, motion.second)
            normal, couple = lam[:, 0], lam[:, 1]
            if spec.length:
                pressing = np.abs(normal / 2 + couple / spec.length) + np.abs(normal / 2 - couple / spec.length)
            else:
                pressing = np.abs(normal)
            force = -(spec.f * pressing * _sense(s1, s2, size, sense))[:, None] * u     # on the slider b
            at = motion.poses[b][:, :2] + pb                                           # the slider's point
            for link, f in ((b, force), (a, -force)):
                terms.append(LoadTerm(link, (0.0, 0.0), f, cross(at - motion.poses[link][:, :2], f), "friction", name))
    return terms


# ----------------------------------------------------------------------------------------------
# a group solved with its friction
# ----------------------------------------------------------------------------------------------


@dataclass
class GroupFriction:
    """A group's reactions with friction: ``multipliers`` and ``transmitted`` as the group solver
    gives them, the friction ``terms`` of its pairs, the positions where the iteration did not
    converge (``locked``, bool (N,)) and the pair whose friction grew most there (``worst``)."""

    multipliers: dict[str, np.ndarray]
    transmitted: dict[str, np.ndarray]
    terms: list[LoadTerm]
    locked: np.ndarray
    worst: str


def group_with_friction(motion, solve: Callable[[dict], tuple[dict, dict]], applied: dict[str, np.ndarray],
                        links: set[str], friction: Friction, sense: np.ndarray, valid: np.ndarray,
                        first: tuple[dict, dict]) -> GroupFriction:
    """Solve one group with the friction of its pairs.

    The friction loads depend on the reactions of the pairs that carry them, x (the first two
    multipliers of each such pair: a revolute pair's force, a prismatic pair's normal force and
    moment); the group's solve is linear in its loads. So the reactions with friction are the fixed
    point ``x = Φ(x)``, ``Φ(x)`` = the solve under ``applied`` plus the friction loads of x on the
    group's ``links``. From the frictionless ``first`` solution (multipliers, transmitted):
    :data:`FIXED_POINT_STEPS` plain iterations (a contraction for ordinary f: its factor is about
    f times the lever ratios, f·tan β for a slider pushed at the pressure angle β), then Newton's
    method on ``x − Φ(x)`` with a finite-difference Jacobian for the positions not yet converged
    (near self-locking the factor nears 1). Converged: ``|x − Φ(x)| <= FRICTION_TOL`` of the
    largest multiplier. A position that does not converge in :data:`FRICTION_ITERATIONS` Newton
    steps, or whose reactions grow beyond :data:`LOCKED_GROWTH` times the frictionless ones, is
    ``locked``: no finite load moves the group there (self-locking).
    """
    lam, transmitted = first
    names = [k for k in lam if k in friction.pairs]
    n = len(motion.phi)
    floor = np.maximum(_size(lam, n), 1e-300)
    active = valid.copy()

    def unknowns(multipliers):
        return np.concatenate([multipliers[k][:, :2] for k in names], axis=1)

    def phi_of(x):
        """Φ(x), the solve's multipliers and transmitted loads, and the friction loads of x."""
        terms = friction_terms(motion, friction, {k: x[:, 2 * j:2 * j + 2] for j, k in enumerate(names)}, sense)
        extra = generalized_loads(motion, terms)
        new, sent = solve({k: (v + extra[k] if k in links else v) for k, v in applied.items()})
        return unknowns(new), new, sent, terms

    def residual(x, image):
        return np.max(np.abs(x - image), axis=1)

    x = unknowns(lam)
    converged = ~active
    for _ in range(FIXED_POINT_STEPS):
        image, lam, transmitted, _ = phi_of(x)
        size = np.maximum(_size(lam, n), floor)
        converged |= residual(x, image) <= FRICTION_TOL * size
        x = image
        if converged.all():
            break
    steps = 0
    while not converged.all() and steps < FRICTION_ITERATIONS:
        steps += 1
        image, lam, transmitted, _ = phi_of(x)
        g = x - image
        size = np.maximum(_size(lam, n), floor)
        converged |= np.max(np.abs(g), axis=1) <= FRICTION_TOL * size
        runaway = ~converged & (size > LOCKED_GROWTH * floor)
        active &= ~runaway
        converged |= runaway                    # given up: flagged below
        if converged.all():
            break
        jac = np.repeat(np.eye(x.shape[1])[None], n, axis=0)
        h = 1e-7 * (np.abs(x) + size[:, None])
        for j in range(x.shape[1]):
            shifted = x.copy()
            shifted[:, j] += h[:, j]
            jac[:, :, j] -= (phi_of(shifted)[0] - image) / h[:, j:j + 1]
        todo = ~converged
        step = np.zeros_like(x)
        try:
            step[todo] = np.linalg.solve(jac[todo], -g[todo][:, :, None])[:, :, 0]
        except np.linalg.LinAlgError:
            break
        x = np.where(todo[:, None], x + step, image)
    image, lam, transmitted, terms = phi_of(x)
    size = np.maximum(_size(lam, n), floor)
    locked = valid & ~(active & (residual(x, image) <= 1e3 * FRICTION_TOL * size) & (size <= LOCKED_GROWTH * floor))
    worst = ""
    if locked.any():
        growth = {k: float(np.nanmax(np.abs(lam[k][locked]) / floor[locked, None])) for k in names}
        worst = max(growth, key=growth.get) if growth else ""
    return GroupFriction(lam, transmitted, terms, locked, worst)


def _size(lam: Mapping[str, np.ndarray], n: int) -> np.ndarray:
    """The largest multiplier per position (N,)."""
    if not lam:
        return np.zeros(n)
    return np.max(np.stack([np.max(np.abs(v), axis=1) for v in lam.values()]), axis=0)


def friction_angle_deg(f: float) -> float:
    """``φ_f = atan f``, degrees."""
    return math.degrees(math.atan(f))
