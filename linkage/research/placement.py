"""Groups solved by Newton's method: the assembly mode of the reference position, placed, followed, declared.

A group with two branches keeps the branch of the reference position (``branch = ±1``); a group
solved by Newton's method keeps its assembly mode there (:func:`placement`: followed from the
reference position as the crank shrinks, then over a turn), declared by a readable condition, a
point left or right of a line through two known points, that the mode meets and the group's other
modes at the reference angle do not (:func:`mode_conditions`). :func:`build_combination` declares a
combination's whole mechanism: its branches, conditions and output.

Cheap checks on the reference mode -- its conditioning at the reference angle, then the mode
followed over a turn (:func:`_followed_turn`) -- come before the scheme is loaded, since loading
traces every mode of the group over 360 angles (:mod:`linkage.kinematics.assembly`). The walk here
is not that tracer: it follows one given mode of the whole chain (every group together, closed
forms on the reference branch) of a combination whose assembly conditions are not declared yet, so
that it has no assembly plans, from the reference angle in coarse adaptive steps, and stops at the
first sign that the mode is no sensible default (a limit position, a conditioning below
:data:`MIN_CONDITIONING`). The other modes at the reference angle are found as the plans find a
group's modes (:func:`~linkage.kinematics.tracing.random_start_modes`).
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass, replace

import numpy as np

from assur.base import OK, SINGULAR, global_point
from assur.generic import TRACE_JUMP

from ..errors import AssemblyError, StructureError
from ..kinematics.tracing import poses_distance, random_start_modes
from ..kinematics.inputs import input_poses
from ..kinetostatics.loads import loads_of
from ..model.mechanism import Mechanism
from ..structure import Structure, decompose
from .assignments import Assignment, Reference, reference_positions
from .geometry import combination_builder, condition_points, output_candidates, reference_branches, solvable

__all__ = [
    "MIN_CONDITIONING",
    "Placement",
    "build_combination",
    "mode_conditions",
    "placement",
]

#: smallest conditioning of every group over the turn (docs/numerics.md: 1 well proportioned, 0
#: singular) for a geometry to count as a sensible default; the shipped schemes stay above 0.1
MIN_CONDITIONING = 0.05
#: step of the crank's length (a fraction of the source's) by which a group solved by Newton's
#: method is followed from the reference position to a shorter crank
CRANK_STEP = 0.2
#: largest and smallest steps of the input angle, rad, by which the reference mode is followed over a turn
FOLLOW_STEPS = (math.radians(10.0), math.radians(0.25))
#: a step is halved where Newton's method lands farther than this fraction of the size (or than half
#: the predicted move) from the prediction
FOLLOW_MISS = 0.05
#: readable assembly conditions tried for a group solved by Newton's method, best first
CONDITION_TRIALS = 3


@dataclass(frozen=True)
class Placement:
    """A combination with groups solved by Newton's method, in the assembly mode of the reference
    position: at the reference angle and followed over a turn (crank at ``factor`` of the source's).

    Attributes
    ----------
    mech : Mechanism
        The combination without assembly conditions or output.
    structure : Structure
        Its groups.
    branches : dict of int -> int
        Group index -> the branch (raw sign) of the reference position, for groups with two branches.
    poses : dict of str -> ndarray, shape (3,)
        Every link's pose ``(x, y, theta)`` (m, m, rad) at the reference angle: the reference
        position itself at factor 1, followed from it as the crank shrinks otherwise.
    turn : dict of str -> ndarray, shape (S, 3)
        Every link's pose at the S input angles the mode was followed through, from the reference
        angle counter-clockwise (S = 1 when it was not followed).
    problem : str or None
        Why this mode is no sensible default over a turn (:func:`placement`), or None.
    """

    mech: Mechanism
    structure: Structure
    branches: dict[int, int]
    poses: dict[str, np.ndarray]
    turn: dict[str, np.ndarray]
    problem: str | None

    def mismatch(self, poses: dict[str, np.ndarray]) -> float:
        """Largest distance (m; angles times the size) between ``poses`` ``{link: (3,)}`` and these."""
        return float(np.max([_pose_gap({k: pose}, {k: self.poses[k]}, self.mech.size) for k, pose in poses.items()]))


def placement(source: Mechanism, ref: Reference, assignment: Assignment, factor: float = 1.0) -> Placement:
    """The combination's assembly mode of the reference position, at the reference angle and over a turn.

    At ``factor`` 1 the reference position is a position of the combination (by construction). With
    a shorter crank each group solved by Newton's method is followed from it in steps of
    :data:`CRANK_STEP` of the crank's length (Newton's method from the poses of the step before); a
    group with two branches keeps the branch of the reference position. The mode is no sensible
    default (``problem``) when a group of two links solved by Newton's method has a conditioning
    below :data:`MIN_CONDITIONING` at the reference angle; else it is followed over a turn
    (:func:`_followed_turn`), and it is none when it cannot be followed past an angle (a limit
    position), when a group comes close to a singular position at the angles reached
    (:func:`too_close_to_singular`), or when it does not come back to itself after the turn.
    These are cheap checks before the scheme is loaded (which traces every mode of the group over
    360 angles); the check of the loaded scheme has the last word.

    Raises
    ------
    AssemblyError
        When a group solved by Newton's method cannot be placed as the crank shrinks (naming it,
        the input angle and the crank's length).
    """
    mech = combination_builder(source, ref, assignment, 1.0).build()
    structure = decompose(mech)
    branches = reference_branches(structure, ref)
    poses = dict(ref.poses)
    steps = max(0, math.ceil((1.0 - factor) / CRANK_STEP - 1e-9))
    for before, fraction in itertools.pairwise(np.linspace(1.0, factor, steps + 1)):
        mech = combination_builder(source, ref, assignment, float(fraction)).build()
        structure = decompose(mech)
        for i, group in enumerate(structure.groups):
            placed = _placed(group, {k: poses[k][None] for k in group.known_links}, branches.get(i, 1),
                             {k: poses[k] for k in group.links})
            if getattr(group, "tracked", False) and placed.status[0] not in (OK, SINGULAR):
                raise AssemblyError(
                    f"group {group!r} cannot be placed at the reference angle phi = {math.degrees(ref.phi):.6g} deg "
                    f"with the crank at {fraction:g} of the source's (Newton's method from its position with the "
                    f"crank at {before:g} does not converge)", np.array([math.degrees(ref.phi)]))
            poses.update({k: v[0] for k, v in placed.poses.items()})
    place = Placement(mech, structure, branches, poses, {k: v[None] for k, v in poses.items()}, None)
    for group in structure.groups:
        if getattr(group, "tracked", False) and len(group.links) == 2:
            merged = {k: poses[k][None] for k in (*group.known_links, *group.links)}
            conditioning = float(group.conditioning(group.jacobians(merged)[0], merged)[0][0])
            if not conditioning >= MIN_CONDITIONING:
                return replace(place, problem=singular_words(group, conditioning, ref.phi))
    turn, problem = _followed_turn(place, ref)
    return replace(place, turn=turn, problem=problem)


def singular_words(group, conditioning: float, phi: float | None = None, largest: float | None = None) -> str:
    """Why ``group`` is no sensible default: its conditioning falls below the floor of
    :func:`too_close_to_singular` (at the input angle ``phi``, rad)."""
    where = "" if phi is None else f" at phi = {math.degrees(phi) % 360:.6g} deg"
    if largest is None:
        return (f"group {group!r} comes close to a singular position{where} (conditioning {conditioning:.2g}; "
                f"at least {MIN_CONDITIONING:g} wanted)")
    return (f"group {group!r} comes close to a singular position{where} (conditioning {conditioning:.2g}, "
            f"{conditioning / largest:.2g} of its largest over the turn; at least {MIN_CONDITIONING:g} of it wanted)")


def too_close_to_singular(group, conditioning: np.ndarray) -> bool:
    """Whether a group's conditioning over a turn ``(N,)`` (NaN where not placed) comes close to a
    singular position: below :data:`MIN_CONDITIONING` for a group of two links (where it behaves
    like the sine of a transmission angle, docs/numerics.md), below that fraction of its largest
    value over the turn for a larger group (whose measure is not on that scale: the shipped triad's
    stays between 3e-4 and 1.1e-3)."""
    low, high = np.nanmin(conditioning), np.nanmax(conditioning)
    return bool(low < MIN_CONDITIONING * (1.0 if len(group.links) == 2 else high))


def _placed(group, known: dict[str, np.ndarray], branch: int, near: dict[str, np.ndarray]):
    """The group at one position: its closed form on ``branch``, or (solved by Newton's method) the
    mode Newton's method reaches from the poses ``near`` ``{link: (3,)}``."""
    with np.errstate(all="ignore"):   # a link of zero length (a pin where a slider was) is NaN here
        if getattr(group, "tracked", False):
            return group.position(known, start={k: v[None] for k, v in near.items()})
        return group.position(known, branch)


def _followed_turn(place: Placement, ref: Reference) -> tuple[dict[str, np.ndarray], str | None]:
    """The mode of ``place`` followed from the reference angle over a turn counter-clockwise: every
    link's poses ``(S, 3)`` at the angles reached, and why it does not run (None when it does).

    Every group is placed in turn (a closed form on its branch; Newton's method from the poses
    extrapolated from the last three angles reached by a parabola), in steps of at most 10 deg,
    halved down to 0.25 deg where a step is not good (:func:`_good_step`) and grown by half after
    a good one (:data:`FOLLOW_STEPS`). The conditioning of every group is judged by
    :func:`too_close_to_singular` at each angle reached (a larger group's against its largest
    value so far, which the rest of the turn can only raise), so that the walk stops before a
    limit position, where its steps would shrink.
    """
    size, groups = place.mech.size, place.structure.groups
    links = list(place.poses)
    first, largest_ratios = _chain_at(place, ref.phi, place.poses, links)
    samples = [np.array([place.poses[k] for k in links])]               # (L, 3) each
    if first is None:
        return {k: v[None] for k, v in place.poses.items()}, (
            f"the combination cannot be placed at the reference angle phi = {math.degrees(ref.phi):.6g} deg")
    largest, smallest = FOLLOW_STEPS
    done, step, slope, bend, last, problem = 0.0, largest, None, 0.0, 0.0, None
    while done < 2 * np.pi - 1e-12 and problem is None:
        step = min(step, 2 * np.pi - done)
        guess = samples[-1] if slope is None else samples[-1] + step * slope + step * (step + last) * bend
        reached, ratios = _chain_at(place, ref.phi + done + step, dict(zip(links, guess)), links)
        if not _good_step(reached, guess, samples[-1], slope is not None, links, size):
            if step > smallest:
                step /= 2
                continue
            problem = (f"the assembly mode of the reference position phi = {math.degrees(ref.phi):.6g} deg cannot "
                       f"be followed past phi = {math.degrees(ref.phi + done) % 360:.6g} deg (it ends there, at a "
                       "limit position, or runs off)")
            break
        turned = reached - samples[-1]
        turned[:, 2] = (turned[:, 2] + np.pi) % (2 * np.pi) - np.pi
        if slope is not None:                  # divided differences of the last three angles reached
            bend = (turned / step - slope) / (step + last)
        slope, last, done = turned / step, step, done + step
        samples.append(samples[-1] + turned)
        largest_ratios = np.fmax(largest_ratios, ratios)
        for i, group in enumerate(groups):
            if too_close_to_singular(group, np.array([ratios[i], largest_ratios[i]])):
                problem = singular_words(group, ratios[i], ref.phi + done,
                                         None if len(group.links) == 2 else largest_ratios[i])
                break
        step = min(1.5 * step, largest)
    if problem is None and _pose_gap(dict(zip(links, samples[-1])), place.poses, size) > 1e-6 * size:
        problem = (f"the assembly mode of the reference position phi = {math.degrees(ref.phi):.6g} deg does not "
                   "come back to itself after a turn")
    stacked = np.array(samples)                                            # (S, L, 3)
    return {k: stacked[:, n] for n, k in enumerate(links)}, problem


def _good_step(reached: np.ndarray | None, guess: np.ndarray, current: np.ndarray, predicted: bool,
               links: list[str], size: float) -> bool:
    """Whether a step of the walk of :func:`_followed_turn` from the poses ``current`` ``(L, 3)``
    stays on its mode: every group placed (``reached``), landing within :data:`FOLLOW_MISS` of the
    size or half the predicted move from the prediction ``guess``; without a prediction (the first
    step), moving by at most :data:`TRACE_JUMP` of the size, as a scheme's assembly plan traces a
    mode."""
    if reached is None:
        return False
    landed, before = dict(zip(links, reached)), dict(zip(links, current))
    if not predicted:
        return _pose_gap(landed, before, size) <= TRACE_JUMP * size
    predicted_at = dict(zip(links, guess))
    return _pose_gap(landed, predicted_at, size) <= max(FOLLOW_MISS * size, 0.5 * _pose_gap(predicted_at, before, size))


def _chain_at(place: Placement, phi: float, near: dict[str, np.ndarray], links: list[str]):
    """Every group placed at the input angle ``phi`` (rad), those solved by Newton's method from
    ``near``: the poses ``(L, 3)`` of ``links`` and every group's conditioning ``(G,)``; None
    where a group cannot be placed."""
    poses = input_poses(place.mech, place.structure, np.array([phi]))
    ratios = []
    for i, group in enumerate(place.structure.groups):
        placed = _placed(group, {k: poses[k] for k in group.known_links}, place.branches.get(i, 1),
                         {k: near[k] for k in group.links})
        if placed.status[0] not in (OK, SINGULAR):
            return None, None
        poses.update(placed.poses)
        ratios.append(float(placed.conditioning[0]))
    return np.array([poses[k][0] for k in links]), np.array(ratios)


def _other_modes(group, known: dict[str, np.ndarray], mode: dict[str, np.ndarray]) -> list[dict[str, np.ndarray]]:
    """The group's assembly modes at one position other than ``mode`` (``{link: (3,)}``): every mode
    a kind lists (the triad), else those Newton's method reaches from random starts around the mode
    (:func:`~linkage.kinematics.tracing.random_start_modes`); each ``{link: (3,)}``, distinct."""
    size = float(group.size)
    listed = group.modes(known)
    if listed is None:
        with np.errstate(all="ignore"):
            found = random_start_modes(group, known, size, around={k: v[None] for k, v in mode.items()},
                                       besides=mode)
        return [{k: v[n] for k, v in found.items()} for n in range(len(next(iter(found.values()))))]
    candidates, valid = listed
    found = {k: v[0][valid[0]] for k, v in candidates.items()}
    kept = [mode]
    for n in range(len(next(iter(found.values())))):
        candidate = {k: v[n] for k, v in found.items()}
        if all(_pose_gap(candidate, other, size) > 1e-6 * size for other in kept):
            kept.append(candidate)
    return kept[1:]


def _pose_gap(a: dict[str, np.ndarray], b: dict[str, np.ndarray], size: float) -> float:
    """Distance between two sets of poses ``{link: (3,)}`` (the links of ``a``), m (angles weighted
    by ``size``, wrapped)."""
    return float(poses_distance(a, b, a, size))


def mode_conditions(mech: Mechanism, place: Placement, index: int,
                    points: list[str]) -> list[tuple[str, str, tuple[str, str]]]:
    """Readable assembly conditions for group ``index`` (solved by Newton's method) that pick its
    mode in ``place``, best first: ``(point, "left_of" or "right_of", (X, Y))``.

    The point is one of ``points`` (the group's own, :func:`~.geometry.condition_points`); the
    line runs through two points that do not move with the group's mode (points of the frame, the
    crank and earlier groups), at least 0.01 of the size apart. A condition qualifies when the mode
    meets it at the reference angle and every other mode found there (:func:`_other_modes`) does
    not; it ranks first when the mode meets it at every angle it was followed through
    (``place.turn``), then by its margin at the reference angle: the smaller of how far the mode's
    point lies on its side of the line and how far every other mode's lies on the other, m. Which
    mode a condition picks over a turn is decided when the scheme is loaded
    (:mod:`linkage.kinematics.assembly`); :func:`~.enumeration.enumerate_chain` checks that it is
    this one.
    """
    group = place.structure.groups[index]
    placed = {mech.frame, *place.structure.inputs} | {k for g in place.structure.groups[:index + 1] for k in g.links}
    before = placed - set(group.links)
    size = mech.size
    fixed = sorted(p for p in mech.point_names if _first_placed(mech, p, placed) in before)
    lines = [(x, y) for x, y in itertools.combinations(fixed, 2)
             if np.linalg.norm(_located(mech, y, place.poses, placed) - _located(mech, x, place.poses, placed))
             >= 0.01 * size]
    own = [p for p in points if _first_placed(mech, p, placed) in group.links]
    if not lines or not own:
        return []
    mode = {k: place.poses[k] for k in group.links}
    modes = [mode, *_other_modes(group, {k: place.poses[k][None] for k in group.known_links}, mode)]
    at_reference = {k: np.array([m[k] if k in m else place.poses[k] for m in modes]) for k in placed}
    side = _sides(mech, at_reference, placed, own, lines)                      # (M, P, L), m
    sign = np.sign(side[0])
    margin = np.min(np.concatenate([(sign * side[0])[None], -sign * side[1:]]), axis=0)   # (P, L)
    stays = np.all(sign * _sides(mech, place.turn, placed, own, lines) > 0, axis=0)      # (P, L)
    qualified = np.flatnonzero(margin.ravel() > 1e-6 * size)
    best = qualified[np.lexsort((-margin.ravel()[qualified], ~stays.ravel()[qualified]))][:CONDITION_TRIALS]
    return [(own[p], "left_of" if sign[p, line] > 0 else "right_of", lines[line])
            for p, line in zip(*np.unravel_index(best, margin.shape))]


def _first_placed(mech: Mechanism, point: str, placed: set[str]) -> str | None:
    """The link whose ``point`` an assembly condition uses (the first placed one that declares it)."""
    return next((k for k in mech.point_links(point) if k in placed), None)


def _located(mech: Mechanism, point: str, poses: dict[str, np.ndarray], placed: set[str]) -> np.ndarray:
    """Global position of ``point`` ``(..., 2)`` at the poses ``{link: (..., 3)}``, m, on the link
    an assembly condition uses."""
    link = _first_placed(mech, point, placed)
    pose = np.asarray(poses[link])
    return global_point(pose.reshape(-1, 3), mech.links[link].points[point]).reshape(*pose.shape[:-1], 2)


def _sides(mech: Mechanism, poses: dict[str, np.ndarray], placed: set[str], points: list[str],
           lines: list[tuple[str, str]]) -> np.ndarray:
    """Signed distances ``(N, P, L)``, m, of ``points`` from the directed lines ``X -> Y`` (left
    positive) at N positions ``{link: (N, 3)}``."""
    start = np.stack([_located(mech, x, poses, placed) for x, _ in lines], axis=1)        # (N, L, 2)
    along = np.stack([_located(mech, y, poses, placed) for _, y in lines], axis=1) - start
    along /= np.linalg.norm(along, axis=2)[..., None]
    where = np.stack([_located(mech, p, poses, placed) for p in points], axis=1)           # (N, P, 2)
    offset = where[:, :, None, :] - start[:, None]                                          # (N, P, L, 2)
    return along[:, None, :, 0] * offset[..., 1] - along[:, None, :, 1] * offset[..., 0]


def build_combination(source: Mechanism, assignment: Assignment, *, factor: float = 1.0,
                      ref: Reference | None = None, output: str | None = None, choice: int = 0) -> Mechanism:
    """The mechanism of one assignment with the source's geometry (crank shrunk by ``factor``).

    Parameters
    ----------
    source : Mechanism
        The chain: a scheme with one input link.
    assignment : Assignment
        Pair kinds (from :func:`~.assignments.assignments`).
    factor : float
        The crank's length as a fraction of the source's (its points move towards its pivot).
    ref : Reference, optional
        The source's reference position (default: the first of
        :func:`~.assignments.reference_positions`).
    output : str, optional
        The output quantity to declare (default: the first of :func:`~.geometry.output_candidates`).
    choice : int
        Which of the conditions of :func:`mode_conditions` each group solved by Newton's method
        gets (0: the first).

    Returns
    -------
    Mechanism
        With the source's gravity (its other loads left out), the output and, for every group with
        two branches, the branch of the reference position (``branch = ±1``); for every group
        solved by Newton's method, a readable condition (``left_of`` / ``right_of`` a line) that
        picks its mode of :func:`placement`.

    Raises
    ------
    StructureError
        When the assignment is not solvable (the reason :class:`~.enumeration.Rejected` gives,
        naming the group).
    AssemblyError
        When a group solved by Newton's method cannot be placed at the reference angle or has
        no condition number ``choice`` that tells its modes apart there.
    """
    ref = reference_positions(source)[0] if ref is None else ref
    structure = solvable(source, ref, assignment)
    if isinstance(structure, str):
        raise StructureError(f"scheme '{source.name}', assignment {assignment.id}: {structure}")
    place = placement(source, ref, assignment, factor) if tracked_groups(structure) else None
    return declared_combination(source, assignment, factor, ref, output, choice, structure, place)


def tracked_groups(structure: Structure) -> list[int]:
    """Indices of the groups solved by Newton's method (their modes traced over a turn)."""
    return [i for i, group in enumerate(structure.groups) if getattr(group, "tracked", False)]


def declared_combination(source: Mechanism, assignment: Assignment, factor: float, ref: Reference,
                         output: str | None, choice: int, structure: Structure, place: Placement | None) -> Mechanism:
    """:func:`build_combination` with the structure (crank 1) and the placement (crank ``factor``) known."""
    points, marks = condition_points(structure, combination_builder(source, ref, assignment, factor).build())
    builder = combination_builder(source, ref, assignment, factor, marks)
    for i, branch in reference_branches(structure, ref).items():
        builder.assembly(points[i][0], branch=branch)
    if place is not None:
        marked = builder.build()
        for i in tracked_groups(structure):
            conditions = mode_conditions(marked, place, i, points[i])
            if len(conditions) <= choice:
                raise AssemblyError(
                    f"group {structure.groups[i]!r}: {len(conditions)} readable assembly conditions tell its mode "
                    f"at the reference angle phi = {math.degrees(ref.phi):.6g} deg from its other modes there "
                    f"(condition {choice + 1} asked for)", np.array([math.degrees(ref.phi)]))
            point, side, line = conditions[choice]
            builder.assembly(point, **{side: line})
    output = output_candidates(source, assignment, structure)[0] if output is None else output
    builder.output(output, source.output.start if source.output is not None else "max")
    builder.description = (f"{source.name} with pairs " + ", ".join(k.words for k in assignment.kinds)
                           + (f"; crank {factor:g} of the source's" if factor != 1.0 else ""))
    return builder.build(loads={"gravity": list(loads_of(source).gravity)})
