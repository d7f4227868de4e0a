"""Feasibility of design variants: does a mechanism turn, stay regular and transmit force well?

A generator of assignments draws variants of a scheme (other lengths, other offsets) and keeps
the feasible ones. :func:`check` judges one variant against :class:`Requirements` with one
analysis over the input's travel and says which rule rejected it and why, in words, with the
numbers; :func:`transmission_angles` gives the transmission angle of every group that has one.

>>> import linkage
>>> verdict = check(linkage.load("four_bar"), Requirements(min_transmission_angle_deg=30.0))
>>> verdict.feasible, round(verdict.figures["min_transmission_angle_deg"], 2)
(True, 41.41)

The rules, in the order they are checked (the first that fails is the verdict's ``rule``):

- ``"assembles"``: the scheme builds, decomposes and assembles at some angle of the travel;
- ``"full_rotation"``: it assembles at every angle of the travel (a turn, or the declared input
  range); the reason is :func:`~linkage.kinematics.full_turn.input_cannot_turn`'s sentence: where
  the input can turn and the dimensional reason (Grashof, rod against crank plus offset ...);
- ``"non_singular"``: no group is singular (status -2) at any angle;
- ``"no_change_point"``: no group passes a change point (docs/numerics.md), and the analysis
  raises no :class:`~linkage.kinematics.motion.BranchWarning`;
- ``"transmission_angle"``: the smallest transmission angle over the travel is at least the
  required one;
- ``"stroke"``: the stroke of the scheme's output lies within the required bounds.

A change point is a singular position by nature, and the deltoid's can even fail to assemble at
the one angle where its pivots coincide: angles within one step of the sweep (or
:data:`~linkage.kinematics.assembly.CROSSING_STEP`, whichever is larger) of a change point are therefore
judged by ``"no_change_point"`` alone, not by ``"full_rotation"`` or ``"non_singular"``.
"""

from __future__ import annotations

import difflib
import math
import warnings
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field, fields
from typing import Any

import numpy as np

from assur.base import (
    CANNOT_ASSEMBLE,
    NOT_CONVERGED,
    SINGULAR,
    Group,
    PrismaticJoint,
    RevoluteJoint,
    cross,
    dot,
    global_point,
    perp,
    rotate,
)

from ..errors import InputError, LinkageError, SchemeError
from ..model.mechanism import Mechanism
from ..structure import structure_of
from .assembly import assembly_plans
from .full_turn import cannot_turn_sentence, near_change_points
from .motion import BranchWarning, Motion, analyze

__all__ = [
    "RULES",
    "Requirements",
    "Verdict",
    "check",
    "parse_requirements",
    "sweep_angles",
    "transmission_angles",
]

MIN_POSITIONS, MAX_POSITIONS = 12, 100_000
TWO_PI = 2 * np.pi


# ----------------------------------------------------------------------------------------------
# transmission angles
# ----------------------------------------------------------------------------------------------


def transmission_angles(motion: Motion) -> dict[str, np.ndarray]:
    """The transmission angle of every group whose two links meet at an inner revolute pair.

    Each of the group's two links can push on the inner pin only along one line: a link whose
    other pair is revolute along the line through that pair's point and the inner pin (a
    two-force member); a link whose other pair is prismatic along the normal of its guide (an
    ideal slider carries no force along its guide). The transmission angle is the acute angle
    between these two lines: 90 deg is the best transmission, 0 deg a dead point, where the group
    is singular. For the four-bar's RRR dyad it is the classic angle between coupler and rocker
    folded to the acute one; for the slider-crank's RRP dyad, 90 deg minus the rod's inclination
    to the guide; for a PRP dyad, the angle between its two guides.

    A group whose inner pair is prismatic (RPR, the slotted link; RPP) has none and is left out:
    its inner pair transmits a force normal to its slot whatever the angles, so there are no two
    lines of action meeting at a pin to compare. Class-III groups (four links) are left out too.
    The test is on the kinds of the pairs, never on the group's kind or the scheme's name.

    Parameters
    ----------
    motion : Motion
        Positions over N input angles (any analog order).

    Returns
    -------
    dict of str -> ndarray, shape (N,)
        Keyed by the group's label as the structural formula writes it (``"II-RRR(2,3)"``, the keys
        of ``Motion.conditioning``), in deg in [0, 90]; NaN where the group is not placed
        (cannot be assembled).
    """
    out = {}
    for group in motion.structure.groups:
        lines = _pushing_lines(group)
        if lines is None or not all(link in motion.poses for link in group.links):
            continue
        first, second = (line(motion.poses) for line in lines)
        with np.errstate(invalid="ignore"):
            mu = np.arctan2(np.abs(cross(first, second)), np.abs(dot(first, second)))
        out[repr(group)] = np.degrees(mu)
    return out


def _pushing_lines(group: Group) -> tuple[Callable, Callable] | None:
    """Two functions ``poses -> (N, 2)`` giving the directions along which the group's two links
    push on their inner revolute pair, or None when the group has no such pair."""
    if len(group.links) != 2:
        return None
    inner = [j for j in group.joints if {j.a, j.b} == set(group.links)]
    if len(inner) != 1 or not isinstance(inner[0], RevoluteJoint):
        return None
    inner = inner[0]
    lines = []
    for link in group.links:
        others = [j for j in group.joints if j is not inner and link in (j.a, j.b)]
        if len(others) != 1:
            return None
        lines.append(_line_of(link, others[0], inner))
    return lines[0], lines[1]


def _line_of(link: str, outer, inner: RevoluteJoint) -> Callable:
    """``poses -> (N, 2)``: the direction along which ``link`` pushes on the pin ``inner``."""
    pin_local = inner.local(link)[0]
    if isinstance(outer, PrismaticJoint):
        def normal(poses):
            return perp(rotate(poses[outer.a][:, 2], outer.u))
        return normal
    outer_local = outer.local(link)[0]

    def along(poses):
        pose = poses[link]
        return global_point(pose, pin_local) - global_point(pose, outer_local)
    return along


# ----------------------------------------------------------------------------------------------
# requirements
# ----------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Requirements:
    """What a feasible variant must satisfy (see the module docstring for the rules).

    Attributes
    ----------
    full_rotation : bool
        It assembles at every angle of the input's travel (a turn, or the declared input range).
    non_singular : bool
        No group is singular (status -2) at any angle checked.
    no_change_point : bool
        No group passes a change point, and the analysis raises no ``BranchWarning``.
    min_transmission_angle_deg : float or None
        Smallest transmission angle allowed, deg in (0, 90); None: not checked.
    stroke : (float, float) or None
        Bounds ``(low, high)`` of the output's stroke (max - min of the scheme's output quantity
        over the travel, in its unit: m, or rad for a link angle); None: not checked.
    positions : int
        Number of input angles checked over the travel (12 .. 100000): a turn in equal steps from
        phi = 0, or the input range with both ends.
    """

    full_rotation: bool = True
    non_singular: bool = True
    no_change_point: bool = True
    min_transmission_angle_deg: float | None = None
    stroke: tuple[float, float] | None = None
    positions: int = 360

    def __post_init__(self) -> None:
        problems = _requirement_problems({f.name: getattr(self, f.name) for f in fields(self)})
        if problems:
            raise InputError("Requirements: " + "; ".join(problems))
        if self.stroke is not None:
            object.__setattr__(self, "stroke", (float(self.stroke[0]), float(self.stroke[1])))
        if self.min_transmission_angle_deg is not None:
            object.__setattr__(self, "min_transmission_angle_deg", float(self.min_transmission_angle_deg))


_FIELDS = ("full_rotation", "non_singular", "no_change_point", "min_transmission_angle_deg", "stroke",
           "positions")


def _is_real(value: Any) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)


def _requirement_problems(values: Mapping[str, Any]) -> list[str]:
    """Problems of requirement values (only the keys present are checked), each naming the key
    and the value."""
    problems = []
    for key in ("full_rotation", "non_singular", "no_change_point"):
        if key in values and not isinstance(values[key], bool):
            problems.append(f"{key} must be true or false, got {values[key]!r}")
    angle = values.get("min_transmission_angle_deg")
    if angle is not None and not (_is_real(angle) and 0 < angle < 90):
        problems.append(f"min_transmission_angle_deg must be a number of degrees in (0, 90), got {angle!r}")
    stroke = values.get("stroke")
    if stroke is not None and not (isinstance(stroke, (list, tuple)) and len(stroke) == 2
                                   and all(_is_real(v) for v in stroke) and 0 <= stroke[0] < stroke[1]):
        problems.append(f"stroke must be [low, high], two numbers with 0 <= low < high (in the unit of the "
                        f"output: m, or rad for a link angle), got {stroke!r}")
    if "positions" in values:
        n = values["positions"]
        if not (isinstance(n, int) and not isinstance(n, bool) and MIN_POSITIONS <= n <= MAX_POSITIONS):
            problems.append(f"positions must be an integer in {MIN_POSITIONS}..{MAX_POSITIONS}, got {n!r}")
    return problems


def parse_requirements(raw: Mapping[str, Any] | None, where: str) -> Requirements:
    """Requirements from a TOML table (e.g. ``[template.require]``); None gives the defaults.

    Parameters
    ----------
    raw : mapping or None
        Keys exactly the fields of :class:`Requirements`; a key left out keeps its default.
        ``stroke = [low, high]`` in the output's unit.
    where : str
        Names the table in messages, e.g. ``"press.toml [template.require]"``.

    Raises
    ------
    SchemeError
        Listing every problem (an unknown key with the known key it resembles, a value of the
        wrong type or out of range), each message starting with ``where``.

    Examples
    --------
    >>> parse_requirements({"min_transmission_angle_deg": 40, "stroke": [0.1, 0.2]}, "t.toml").stroke
    (0.1, 0.2)
    >>> parse_requirements({"min_transmision_angle_deg": 40}, "t.toml")
    Traceback (most recent call last):
    ...
    linkage.errors.SchemeError: t.toml: unknown key 'min_transmision_angle_deg'; did you mean 'min_transmission_angle_deg'? (known: full_rotation, min_transmission_angle_deg, no_change_point, non_singular, positions, stroke)
    """
    if raw is None:
        return Requirements()
    if not isinstance(raw, Mapping):
        raise SchemeError(f"{where}: expected a table of requirements, got {raw!r}")
    problems = []
    for key in sorted(k for k in raw if k not in _FIELDS):
        meant = difflib.get_close_matches(str(key), _FIELDS, n=1, cutoff=0.6)
        hint = f"; did you mean {meant[0]!r}?" if meant else ""
        problems.append(f"{where}: unknown key {key!r}{hint} (known: {', '.join(sorted(_FIELDS))})")
    known = {k: v for k, v in raw.items() if k in _FIELDS}
    problems += [f"{where}: {p}" for p in _requirement_problems(known)]
    if problems:
        raise SchemeError(problems)
    if known.get("stroke") is not None:
        known["stroke"] = tuple(known["stroke"])
    return Requirements(**known)


# ----------------------------------------------------------------------------------------------
# the verdict
# ----------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Verdict:
    """The judgement of one variant.

    Attributes
    ----------
    feasible : bool
    rule : str or None
        The first rule that rejects it (one of :data:`RULES`); None when feasible.
    reason : str or None
        One line in words with the numbers; None when feasible.
    figures : dict
        Measured values for an index of variants (None where not measured), whether or not the
        variant is feasible, as far as the analysis got:

        - ``positions``: number of input angles checked;
        - ``assembled_positions``: how many of them assemble;
        - ``unassembled_deg``: spans ``(low, high)`` of input angles (deg) where it cannot be
          assembled;
        - ``min_conditioning``, ``min_conditioning_group``: the smallest conditioning of any
          group (1 well proportioned, 0 singular; docs/numerics.md) and the group's label;
        - ``change_points_deg``: group label -> input angles (deg, [0, 360)) of its change points;
        - ``min_transmission_angle_deg``, ``min_transmission_angle_group``,
          ``min_transmission_angle_phi_deg``: the smallest transmission angle (deg) over the
          travel, its group and the input angle (deg) where it occurs; None when no group has a
          transmission angle;
        - ``transmission_angle_deg``: group label -> its smallest transmission angle, deg (every
          group that has one);
        - ``output``, ``stroke``, ``stroke_unit``: the output quantity and its stroke (max - min
          over the travel, m or rad); None without an output or where the travel does not
          assemble whole.
    """

    feasible: bool
    rule: str | None = None
    reason: str | None = None
    figures: dict = field(default_factory=dict)


def sweep_angles(mech: Mechanism, positions: int) -> np.ndarray:
    """The input angles ``(positions,)`` that :func:`check` analyses, rad: a turn in equal steps
    from 0 (2 pi left out: it is 0 again), or the declared input range with both ends."""
    if mech.input_range is None:
        return np.linspace(0.0, TWO_PI, positions, endpoint=False)
    return np.linspace(*mech.input_range, positions)


def check(mech: Mechanism | Callable[[], Mechanism], req: Requirements = Requirements()) -> Verdict:
    """Judge one variant against the requirements: the rules of :data:`RULES`, in that order,
    stopping at the first that fails.

    One analysis at ``req.positions`` input angles (:func:`sweep_angles`): of positions, with the
    first analogs when change points or the stroke are checked (``analyze`` then compares the
    motion between the angles with them, and the stroke's extremes are refined with them). The
    assembly plans (change points) are computed once per mechanism and cached, as loading a
    scheme file already does. The smallest transmission angle and the stroke are refined between
    the angles (parabola, Hermite cubic): to about 1e-5 deg and 1e-10 relative at 360 angles.
    Warnings are caught: nothing reaches the user's stderr.

    Parameters
    ----------
    mech : Mechanism or callable
        The variant, or a function without arguments that builds it (e.g.
        ``lambda: linkage.loads(text)``), so that a variant which cannot even be built is a
        rejection too.
    req : Requirements

    Returns
    -------
    Verdict
        A ``LinkageError`` (``SchemeError``, ``StructureError``, ``AssemblyError``) raised while
        building or analysing the variant is a rejection by ``"assembles"`` with its message, not
        an exception.
    """
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            if not isinstance(mech, Mechanism):
                mech = mech()
            structure_of(mech)
            plans = assembly_plans(mech)
            phi = sweep_angles(mech, req.positions)
            motion = analyze(mech, phi, order=_order(req), on_failure="mask")
        except LinkageError as exc:
            return Verdict(False, "assembles", _one_line(str(exc)), {})
    branch_warnings = [str(w.message) for w in caught if issubclass(w.category, BranchWarning)]
    with np.errstate(invalid="ignore", divide="ignore"):
        return _judge(mech, req, motion, plans, branch_warnings)


def _order(req: Requirements) -> int:
    """Analog order of the sweep: 1 when change points are checked (``analyze`` then compares the
    motion between the angles with the analogs) or the stroke is (its extremes are refined with
    them); positions alone otherwise."""
    return 1 if req.no_change_point or req.stroke is not None else 0


def _one_line(text: str) -> str:
    return "; ".join(part.strip() for part in text.splitlines() if part.strip())


@dataclass(frozen=True)
class _Sweep:
    """What the rules look at: the analysed sweep and the measures taken on it."""

    mech: Mechanism
    req: Requirements
    motion: Motion
    changes: dict                 # group label -> change points (rad) of groups that have any
    excused: np.ndarray           # (N,) bool: angles at a change point (judged by no_change_point)
    branch_warnings: list
    minima: dict                  # group label -> (smallest transmission angle deg, phi rad)
    stroke: float | None

    @property
    def angles(self) -> tuple[str, float, float] | None:
        """(group, smallest transmission angle of all groups in deg, phi in rad), or None."""
        if not self.minima:
            return None
        group = min(self.minima, key=lambda g: self.minima[g][0])
        return (group, *self.minima[group])

    @property
    def name(self) -> str:
        return f"mechanism '{self.mech.name}'"


def _judge(mech: Mechanism, req: Requirements, motion: Motion, plans, branch_warnings) -> Verdict:
    """Apply the rules after ``"assembles"`` in the order of :data:`RULES`; the first reason wins."""
    groups = [repr(g) for g in motion.structure.groups]
    changes = {g: plan.change_points for g, plan in zip(groups, plans) if len(plan.change_points)}
    minima = _transmission_minima(transmission_angles(motion), motion.phi, mech.input_range is None)
    sweep = _Sweep(mech, req, motion, changes, near_change_points(mech, motion.phi), branch_warnings,
                   minima, _stroke(mech, motion))
    figures = _figures(sweep)
    for rule, applies, judge in _RULE_CHECKS:
        reason = judge(sweep) if applies(req) else None
        if reason is not None:
            return Verdict(False, rule, reason, figures)
    return Verdict(True, None, None, figures)


def _assembles_somewhere(sweep: _Sweep) -> str | None:
    phi = sweep.motion.phi
    if np.all(sweep.motion.status == CANNOT_ASSEMBLE):
        return (f"{sweep.name} cannot be assembled at any of the {len(phi)} input angles checked over "
                f"{_travel(sweep.mech)}")
    return None


def _solved(sweep: _Sweep) -> str | None:
    """A group solved by Newton's method that did not converge: the solver failed, so nothing can
    be said of the geometry there (docs/groups.md)."""
    failed = sweep.motion.status == NOT_CONVERGED
    if not failed.any():
        return None
    return (f"{sweep.name}: Newton's method did not converge for a group without a closed form at phi = "
            f"{_spans_text(sweep.mech, sweep.motion.phi, failed)} deg ({int(failed.sum())} of "
            f"{len(sweep.motion.phi)} input angles checked): the geometry there is unknown")


def _turns_fully(sweep: _Sweep) -> str | None:
    """The input cannot turn fully: the words of :func:`~.full_turn.input_cannot_turn` (where the
    mechanism assembles and the dimensional reason) for the angles of this sweep."""
    failed = _stops(sweep)
    return cannot_turn_sentence(sweep.motion, failed) if failed.any() else None


def _stops(sweep: _Sweep) -> np.ndarray:
    """``(N,)`` bool: the angles of the sweep where the mechanism cannot be assembled (those at a
    change point excused)."""
    return (sweep.motion.status == CANNOT_ASSEMBLE) & ~sweep.excused


def _stays_regular(sweep: _Sweep) -> str | None:
    singular = (sweep.motion.status == SINGULAR) & ~sweep.excused
    if not singular.any():
        return None
    group, r = _worst_group(sweep.motion, singular)
    return (f"group {group} of {sweep.name} is singular at phi = "
            f"{_spans_text(sweep.mech, sweep.motion.phi, singular)} deg (conditioning down to {r:.2g}, "
            "where 1 is well proportioned and 0 a dead point)")


def _passes_no_change_point(sweep: _Sweep) -> str | None:
    if sweep.changes:
        told = "; ".join(f"group {g} at phi = {_degrees_text(c)} deg" for g, c in sweep.changes.items())
        return (f"{sweep.name} passes change points, where a group's two assembly modes meet and the "
                f"motion may go on in either: {told}")
    if sweep.branch_warnings:
        return f"{sweep.name}: {' '.join(sweep.branch_warnings[0].split())}"
    return None


def _transmits_well(sweep: _Sweep) -> str | None:
    need = sweep.req.min_transmission_angle_deg
    if sweep.angles is None:
        return (f"no group of {sweep.name} has a transmission angle (no two-link group meets at an inner "
                f"revolute pair: {sweep.motion.structure.formula}), so the required {need:g} deg cannot be "
                "checked")
    group, value, at = sweep.angles
    if value >= need:
        return None
    return (f"the transmission angle of {group} falls to {value:.4g} deg at phi = {_phi_text(sweep.mech, at)} "
            f"deg, below the required {need:g} deg")


def _stroke_within_bounds(sweep: _Sweep) -> str | None:
    low, high = sweep.req.stroke
    output = sweep.mech.output
    if output is None:
        return f"{sweep.name} declares no output, so its stroke cannot be checked against [{low:g}, {high:g}]"
    if sweep.stroke is None:
        failed = _stops(sweep)
        why = cannot_turn_sentence(sweep.motion, failed) if failed.any() else \
            f"{sweep.name} does not assemble over its whole travel"
        return f"the stroke of {output.quantity} cannot be measured: {why}"
    unit = _unit(output.quantity)
    if low <= sweep.stroke <= high:
        return None
    return (f"the stroke of {output.quantity} is {sweep.stroke:.6g} {unit}, outside the required "
            f"[{low:g}, {high:g}] {unit}")


#: (rule, whether the requirements ask for it, the judge: reason or None), in the order of RULES
_RULE_CHECKS = (
    ("assembles", lambda req: True, _assembles_somewhere),
    ("solved", lambda req: True, _solved),
    ("full_rotation", lambda req: req.full_rotation, _turns_fully),
    ("non_singular", lambda req: req.non_singular, _stays_regular),
    ("no_change_point", lambda req: req.no_change_point, _passes_no_change_point),
    ("transmission_angle", lambda req: req.min_transmission_angle_deg is not None, _transmits_well),
    ("stroke", lambda req: req.stroke is not None, _stroke_within_bounds),
)
#: the rules in the order :func:`check` applies them: "assembles", "solved" (Newton's method converged
#: wherever a group without a closed form was solved), "full_rotation", "non_singular",
#: "no_change_point", "transmission_angle", "stroke"
RULES = tuple(rule for rule, _, _ in _RULE_CHECKS)


# -- the pieces of the judgement ---------------------------------------------------------------


def _travel(mech: Mechanism) -> str:
    if mech.input_range is None:
        return "a turn"
    a, b = np.degrees(mech.input_range)
    return f"its input range {a:.6g}..{b:.6g} deg"


def _unit(quantity: str) -> str:
    return "rad" if quantity.endswith(".theta") else "m"


def _worst_group(motion: Motion, where: np.ndarray) -> tuple[str, float]:
    """The group with the smallest conditioning at the positions ``where``, and that value."""
    worst = {g: float(np.nanmin(r[where])) for g, r in motion.conditioning.items() if np.isfinite(r[where]).any()}
    if not worst:
        return "(unknown)", float("nan")
    group = min(worst, key=worst.get)
    return group, worst[group]


def _transmission_minima(transmission: dict, phi: np.ndarray, periodic: bool) -> dict[str, tuple[float, float]]:
    """Group label -> (smallest transmission angle in deg, input angle in rad where it occurs) over
    the assembled positions of the sweep ``phi`` (a turn when ``periodic``), refined between its
    angles; groups never assembled are left out."""
    minima = {}
    for group, mu in transmission.items():
        if np.isfinite(mu).any():
            value, at = _refined_minimum(phi, mu, periodic)
            minima[group] = (max(value, 0.0), at)     # a dead point (0 deg) is a kink, not a parabola
    return minima


def _refined_minimum(phi: np.ndarray, values: np.ndarray, periodic: bool,
                     slopes: np.ndarray | None = None) -> tuple[float, float]:
    """Smallest of ``values`` sampled at the equally spaced angles ``phi`` (rad), refined between
    the samples; returns (value, input angle in rad).

    With the first analogs ``slopes`` (d values / d phi), by the cubic Hermite interpolant on the
    step next to the smallest sample towards which the function falls (error O(step^4)); without,
    by the parabola through the smallest sample and its two neighbours (error O(step^3)). Over a
    turn (``periodic``) the neighbours wrap round; at an end of a range the sample itself is kept,
    and so is any refinement that does not lie within the neighbouring steps or is not below it.
    """
    k = int(np.nanargmin(values))
    y0, at = float(values[k]), float(phi[k])
    n = len(values)
    if n < 3 or (not periodic and k in (0, n - 1)):
        return y0, at
    step = float(phi[1] - phi[0])
    if slopes is not None and np.isfinite(slopes[k]):
        side = -1 if slopes[k] * step > 0 else 1          # the neighbour the function falls towards
        other = (k + side) % n
        if not np.isfinite(values[other]) or not np.isfinite(slopes[other]):
            return y0, at
        t, value = _hermite_minimum(y0, float(values[other]), float(slopes[k]) * side * step,
                                    float(slopes[other]) * side * step)
        return min(value, y0), at + side * t * step
    ym, yp = float(values[(k - 1) % n]), float(values[(k + 1) % n])
    curvature = ym - 2 * y0 + yp
    if not (np.isfinite(ym) and np.isfinite(yp) and curvature > 0):
        return y0, at
    shift = 0.5 * (ym - yp) / curvature            # in steps
    if abs(shift) > 0.5:
        return y0, at
    refined = y0 - 0.125 * (yp - ym) ** 2 / curvature
    return min(refined, y0), at + shift * step


def _hermite_minimum(y0: float, y1: float, d0: float, d1: float) -> tuple[float, float]:
    """(t, value) at the smallest stationary point in [0, 1] of the cubic Hermite interpolant with
    values y0, y1 and slopes d0, d1 (per unit of t) at t = 0, 1; (0, y0) when it has none."""
    a, b, c = 6 * (y0 - y1) + 3 * (d0 + d1), 6 * (y1 - y0) - 4 * d0 - 2 * d1, d0
    roots = np.roots([a, b, c]) if abs(a) > 0 or abs(b) > 0 else np.empty(0)
    best = (0.0, y0)
    for t in roots[np.isreal(roots)].real:
        if 0.0 <= t <= 1.0:
            h = np.array([2 * t**3 - 3 * t**2 + 1, t**3 - 2 * t**2 + t, -2 * t**3 + 3 * t**2, t**3 - t**2])
            value = float(h @ [y0, d0, y1, d1])
            if value < best[1]:
                best = (float(t), value)
    return best


def _stroke(mech: Mechanism, motion: Motion) -> float | None:
    """max - min of the output quantity over the travel (m or rad), refined between the sweep's
    angles (with the analogs when the motion has them); None without an output or when some angle
    of the travel does not assemble."""
    if mech.output is None or np.any((motion.status == CANNOT_ASSEMBLE) | (motion.status == NOT_CONVERGED)):
        return None
    quantity = mech.output.quantity
    values, slopes, _ = motion.quantity(quantity)
    periodic = mech.input_range is None
    if quantity.endswith(".theta"):
        values = np.unwrap(values)
        # a link that turns fully has no stroke of its own: its angle runs on, the sweep does not close
        periodic &= abs(values[-1] - values[0]) < np.pi
    negative = None if slopes is None else -slopes
    high = -_refined_minimum(motion.phi, -values, periodic, negative)[0]
    low = _refined_minimum(motion.phi, values, periodic, slopes)[0]
    return high - low


def _figures(sweep: _Sweep) -> dict:
    """The measured values of :attr:`Verdict.figures`."""
    mech, motion, changes, angles, stroke = sweep.mech, sweep.motion, sweep.changes, sweep.angles, sweep.stroke
    status = motion.status
    assembled = (status != CANNOT_ASSEMBLE) & (status != NOT_CONVERGED)
    worst = _worst_group(motion, assembled) if assembled.any() else (None, None)
    return {
        "positions": len(motion.phi),
        "assembled_positions": int(assembled.sum()),
        "unassembled_deg": _spans(mech, motion.phi, ~assembled),
        "min_conditioning": worst[1],
        "min_conditioning_group": worst[0],
        "change_points_deg": {g: [float(x) for x in np.round(np.degrees(c) % 360.0, 9) % 360.0]
                              for g, c in changes.items()},
        "min_transmission_angle_deg": None if angles is None else angles[1],
        "min_transmission_angle_group": None if angles is None else angles[0],
        "min_transmission_angle_phi_deg": None if angles is None else _phi_deg(mech, angles[2]),
        "transmission_angle_deg": {g: value for g, (value, _) in sweep.minima.items()},
        "output": None if mech.output is None else mech.output.quantity,
        "stroke": stroke,
        "stroke_unit": None if mech.output is None else _unit(mech.output.quantity),
    }


# -- angles in words -----------------------------------------------------------------------------


def _phi_deg(mech: Mechanism, phi: float) -> float:
    """An input angle in deg, in [0, 360) over a turn (as given within an input range)."""
    deg = round(math.degrees(phi), 9) + 0.0       # a refined angle: no 359.999999999999 for 0
    return deg % 360.0 if mech.input_range is None else deg


def _phi_text(mech: Mechanism, phi: float) -> str:
    return f"{_phi_deg(mech, phi):.4g}"


def _degrees_text(points: np.ndarray) -> str:
    """Change points (rad) as sorted degrees in [0, 360), to 1e-4 deg (their precision ~1e-6 deg)."""
    return ", ".join(f"{d:g}" for d in sorted({round(float(np.degrees(c)), 4) % 360.0 + 0.0 for c in points}))


def _spans(mech: Mechanism, phi: np.ndarray, mask: np.ndarray) -> list[tuple[float, float]]:
    """Runs of consecutive angles where ``mask`` holds, as ``(first, last)`` in deg; over a turn a
    run through phi = 0 is one span (its first angle then exceeds its last)."""
    index = np.flatnonzero(mask)
    if not len(index):
        return []
    breaks = np.flatnonzero(np.diff(index) > 1)
    starts = np.concatenate([[index[0]], index[breaks + 1]])
    ends = np.concatenate([index[breaks], [index[-1]]])
    runs = list(zip(starts.tolist(), ends.tolist()))
    if mech.input_range is None and len(runs) > 1 and runs[0][0] == 0 and runs[-1][1] == len(phi) - 1:
        runs = [(runs[-1][0], runs[0][1])] + runs[1:-1]
    return [(_phi_deg(mech, phi[a]), _phi_deg(mech, phi[b])) for a, b in runs]


def _spans_text(mech: Mechanism, phi: np.ndarray, mask: np.ndarray, shown: int = 4) -> str:
    spans = _spans(mech, phi, mask)
    words = [f"{a:.4g}" if a == b else f"{a:.4g}..{b:.4g}" for a, b in spans[:shown]]
    return ", ".join(words) + (f" and {len(spans) - shown} more spans" if len(spans) > shown else "")
