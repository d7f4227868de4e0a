"""Enumerate pair kinds: every R/P assignment of a chain's pairs, each as a scheme that runs a full turn.

A chain is a scheme's topology: its links, which pair joins which two links, the frame and the
input link. Its input pair (input link - frame) stays revolute; each other pair is either
revolute (``R``) or prismatic (``P``), and a prismatic pair carries its guide on one of its two
links (``P3``: the guide is on link 3, the other link slides on it). An assignment is kept when
the mechanism decomposes (:func:`linkage.structure.decompose`) into groups that a registered
solver binds (:func:`assur.registry.solver_for`: the closed-form dyads RRR, RRP, RPR, PRP, RPP,
the class-III triad, and Newton's method for any other statically determinate group) and no
group's prismatic pairs close a loop (:func:`_angle_loop`: they would fix one angle twice, so
the group's equations are dependent whatever its dimensions); the others are rejected with the
reason.

Each kept assignment gets the source scheme's own geometry (docs/enumerate.md): its links keep
their local points, masses and inertias; a pair that becomes prismatic gets a guide through its
point, along the line from the guide link's nearest other joint to the slider link's (a pair that
is prismatic in the source keeps its guide line); a pair that becomes revolute is pinned where its
slider's point is. Everything is taken at a reference position of the source
(:func:`reference_positions`), which is therefore a position of every combination. A group with
two branches keeps the branch of that position (``branch = ±1``); a group solved by Newton's
method keeps its assembly mode there (:func:`placement`), declared by a readable condition, a
point left or right of a line through two known points (:func:`mode_conditions`), and the scheme
is loaded to check that the mode its plan traces is that one. A combination whose geometry does
not run a full turn (or comes close to a singular position) is tried with a shorter crank
(:data:`CRANK_FACTORS`) and other reference positions; where none runs, it is listed with the
reason and never written. For groups solved by Newton's method, cheap checks on the reference
mode -- its conditioning at the reference angle, then the mode followed over a turn -- come
before the scheme is loaded, since loading traces every mode of the group over 360 angles.

>>> import linkage
>>> found = assignments(linkage.load("four_bar"))
>>> len(found), found[0].id, found[-1].id
(27, 'A=R,B=R,C=R', 'A=P2,B=P3,C=P3')
"""

from __future__ import annotations

import itertools
import math
import re
import warnings
from collections.abc import Callable, Iterable
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from assur.base import OK, SINGULAR, PrismaticJoint, global_point
from assur.generic import TRACE_JUMP, newton

from ..errors import AssemblyError, InputError, LinkageError, SchemeError, StructureError
from ..kinematics.assembly import has_modes, poses_distance
from ..kinematics.extremes import extreme_positions, wrap_angle
from ..kinematics.feasibility import check, sweep_angles
from ..kinematics.inputs import input_poses
from ..kinematics.motion import BranchWarning, analyze, input_sweep
from ..kinetostatics.loads import loads_of
from ..kinetostatics.reactions import solve_reactions
from ..model.mechanism import Mechanism, MechanismBuilder, Prismatic, Revolute
from ..model.scheme import dumps, load, loads
from ..report import format_columns
from ..structure import Structure, decompose

__all__ = [
    "CRANK_FACTORS",
    "DEFAULT_OMEGA",
    "MIN_CONDITIONING",
    "POSITIONS",
    "Assignment",
    "Combination",
    "Enumeration",
    "PairKind",
    "Placement",
    "Reference",
    "Rejected",
    "assignments",
    "build_combination",
    "enumerate_chain",
    "guide_direction",
    "measure",
    "mode_conditions",
    "output_candidates",
    "placement",
    "reference_angle",
    "reference_positions",
]

#: lengths of the crank tried, as fractions of the source's crank, until a combination runs a full turn
CRANK_FACTORS = (1.0, 0.8, 0.6, 0.4, 0.2)
#: input speed of the balancing moment in the table, rad/s (counter-clockwise)
DEFAULT_OMEGA = 10.0
#: input angles of a turn checked and measured (1 deg steps)
POSITIONS = 360
#: smallest conditioning of every group over the turn (docs/numerics.md: 1 well proportioned, 0
#: singular) for a geometry to count as a sensible default; the shipped schemes stay above 0.1
MIN_CONDITIONING = 0.05
#: points closer than this fraction of the mechanism's size are one point
COINCIDENT = 1e-9


# ----------------------------------------------------------------------------------------------
# assignments
# ----------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class PairKind:
    """The kind of one pair in an assignment: ``"R"``, or ``"P"`` with the link that carries the guide."""

    pair: str
    kind: str
    guide_link: str | None = None

    @property
    def label(self) -> str:
        """``"B=R"`` or ``"B=P3"`` (prismatic, guide on link 3)."""
        return f"{self.pair}={self.kind}" + (self.guide_link if self.kind == "P" else "")

    @property
    def words(self) -> str:
        """``"B revolute"`` or ``"B prismatic, guide on link 3"``."""
        if self.kind == "R":
            return f"{self.pair} revolute"
        return f"{self.pair} prismatic, guide on link {self.guide_link}"


@dataclass(frozen=True)
class Assignment:
    """Pair kinds of every pair but the input's, in the order of the pair names."""

    kinds: tuple[PairKind, ...]

    @property
    def id(self) -> str:
        """``"A=R,B=P3,C=R"``: the labels joined by commas (no spaces: a word of the shell)."""
        return ",".join(k.label for k in self.kinds)

    @property
    def file_name(self) -> str:
        """The id as a file name (characters other than letters, digits and ``_.,=-`` become ``_``)."""
        return re.sub(r"[^A-Za-z0-9_.,=-]", "_", self.id) + ".toml"

    def of(self, pair: str) -> PairKind | None:
        """The kind given to ``pair`` (None for the input pair)."""
        return next((k for k in self.kinds if k.pair == pair), None)


def input_pair(mech: Mechanism) -> str:
    """The revolute pair that pins the input link to the frame (the first by name)."""
    (link,) = _one_input(mech)
    return min(name for name, p in mech.pairs.items()
                  if isinstance(p, Revolute) and set(p.links) == {link, mech.frame})


def _one_input(mech: Mechanism) -> tuple[str]:
    if len(mech.inputs) != 1:
        raise InputError(f"scheme '{mech.name}' has {len(mech.inputs)} input links {list(mech.inputs)}; "
                         "pair kinds are enumerated for a chain with one input link")
    return (mech.inputs[0],)


def assignments(mech: Mechanism) -> list[Assignment]:
    """Every assignment of R or P to the pairs of ``mech`` other than its input pair.

    Each pair is ``R``, ``P`` with the guide on its first link or ``P`` with the guide on its
    second link (links in name order): ``3**n`` assignments for ``n`` pairs, in the order of
    :func:`itertools.product` over the pairs sorted by name.
    """
    fixed = input_pair(mech)
    options = []
    for name in sorted(mech.pairs):
        if name == fixed:
            continue
        links = sorted(mech.pairs[name].links)
        options.append([PairKind(name, "R")] + [PairKind(name, "P", link) for link in links])
    return [Assignment(tuple(choice)) for choice in itertools.product(*options)]


# ----------------------------------------------------------------------------------------------
# the reference position of the source
# ----------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Reference:
    """The source scheme at one assembled position, from which every combination takes its geometry.

    Attributes
    ----------
    phi : float
        Input angle of the position, rad.
    poses : dict of str -> ndarray, shape (3,)
        Every link's pose ``(x, y, theta)`` (m, m, rad).
    joints : dict of str -> (str, ndarray of shape (2,))
        Every pair's point name (a revolute pair's pin; a prismatic pair's slider point) and its
        global position, m.
    size : float
        The source's characteristic length, m.
    """

    phi: float
    poses: dict[str, np.ndarray]
    joints: dict[str, tuple[str, np.ndarray]]
    size: float

    def to_local(self, link: str, point: np.ndarray) -> tuple[float, float]:
        """Local coordinates (m) on ``link`` of a global point ``(2,)`` of the reference position."""
        x, y, theta = self.poses[link]
        dx, dy = point[0] - x, point[1] - y
        c, s = math.cos(theta), math.sin(theta)
        return (c * dx + s * dy, -s * dx + c * dy)

    def to_global(self, link: str, local) -> np.ndarray:
        """Global position ``(2,)`` of ``link``'s local point at the reference position, m."""
        x, y, theta = self.poses[link]
        c, s = math.cos(theta), math.sin(theta)
        return np.array([x + c * local[0] - s * local[1], y + s * local[0] + c * local[1]])


def reference_angle(mech: Mechanism) -> float | None:
    """Input angle (rad, in [0, 2 pi)) halfway from the extreme position "max" of the source's
    output to its extreme position "min", turning counter-clockwise: the position farthest (in
    input angle) from both dead points, where the joints are least in line. None without an
    output, with an input range, or when the output has no extreme positions."""
    if mech.output is None or mech.input_range is not None:
        return None
    try:
        ext = extreme_positions(mech)
    except LinkageError:
        return None
    return float((ext.phi_max + ((ext.phi_min - ext.phi_max) % (2 * np.pi)) / 2) % (2 * np.pi))


#: reference positions tried: the first reference angle and the angles a quarter, a half and three
#: quarters of a turn further
REFERENCE_STEPS = 4


def reference_positions(mech: Mechanism) -> list[Reference]:
    """The reference positions from which the combinations take their geometry, in the order tried.

    The first angle is :func:`reference_angle` (or, without one, or where the source is not
    assembled and regular there, the first angle of the 1 deg sweep from 0 at which it is); then
    the angles 90, 180 and 270 deg further, those at which the source is assembled and regular.

    Raises
    ------
    InputError
        When the scheme is assembled and regular at no angle of the sweep.
    """
    first = reference_angle(mech)
    if first is None or analyze(mech, [first], order=0, on_failure="mask").status[0] != OK:
        sweep = input_sweep(mech)
        ok = np.flatnonzero(sweep.status == OK)
        if not len(ok):
            raise InputError(f"scheme '{mech.name}' is assembled and regular at none of the {len(sweep.phi)} "
                             "input angles of its travel: it has no reference position to take a geometry from")
        first = float(sweep.phi[ok[0]])
    phi = (first + np.arange(REFERENCE_STEPS) * 2 * np.pi / REFERENCE_STEPS) % (2 * np.pi)
    motion = analyze(mech, phi, order=0, on_failure="mask")
    return [_reference(mech, motion, i) for i in np.flatnonzero(motion.status == OK)]


def _reference(mech: Mechanism, motion, i: int) -> Reference:
    """The :class:`Reference` of position ``i`` of an analysed motion."""
    poses = {link: np.array(pose[i], dtype=float) for link, pose in motion.poses.items()}
    ref = Reference(float(motion.phi[i]), poses, {}, mech.size)
    for name, pair in mech.pairs.items():
        on = pair.links[0] if isinstance(pair, Revolute) else pair.links[1]
        ref.joints[name] = (pair.point, ref.to_global(on, mech.links[on].points[pair.point]))
    return ref


# ----------------------------------------------------------------------------------------------
# one combination's mechanism
# ----------------------------------------------------------------------------------------------


def _joint_names(source: Mechanism, ref: Reference) -> dict[str, str]:
    """Pair -> the name of its point in the combinations: the source's name, or ``P_K`` when one
    of the pair's links already has a different point called ``P``."""
    names = {}
    for name, pair in source.pairs.items():
        point, where = ref.joints[name]
        clash = any(point in source.links[link].points
                    and np.linalg.norm(ref.to_global(link, source.links[link].points[point]) - where)
                    > COINCIDENT * ref.size for link in pair.links)
        names[name] = f"{point}_{name}" if clash else point
    return names


def _nearest_joint(source: Mechanism, ref: Reference, pair: str, link: str) -> np.ndarray | None:
    """Global point ``(2,)`` at the reference position of ``link``'s joint nearest to ``pair``'s point
    (among its other pairs), not counting joints that coincide with it; None when there is none."""
    here = ref.joints[pair][1]
    others = sorted((float(np.linalg.norm(ref.joints[k][1] - here)), k) for k, p in source.pairs.items()
                    if k != pair and link in p.links)
    others = [k for d, k in others if d > COINCIDENT * ref.size]
    return ref.joints[others[0]][1] if others else None


def _angle_from(start: np.ndarray | None, end: np.ndarray | None, size: float) -> float | None:
    """Direction (rad) of the line ``start -> end``; None when a point is missing or they coincide."""
    if start is None or end is None or np.linalg.norm(end - start) <= COINCIDENT * size:
        return None
    return math.atan2(end[1] - start[1], end[0] - start[0])


def guide_direction(source: Mechanism, ref: Reference, pair: str, guide_link: str) -> float:
    """Global direction (rad) at the reference position of the guide of ``pair`` on ``guide_link``.

    A pair that is prismatic in the source keeps its guide line (on whichever link carries it).
    Otherwise the guide runs along the line from the guide link's nearest other joint G to the
    slider link's nearest other joint S (nearest to the pair's point, at the reference position):
    S then moves along a line through G fixed in the guide link -- a frame guide at the pair of a
    rocker gives the central slider-crank, a slot in a rocker the slotted link whose slot passes
    through its pivot. Without S (a block whose joints coincide) the guide runs from G to the
    pair's point; without G from the pair's point to S; without both along +x.
    """
    declared = source.pairs[pair]
    if isinstance(declared, Prismatic):
        guide = source.links[declared.links[0]].guides[declared.guide]
        return float(ref.poses[declared.links[0]][2] + guide.angle)
    slider = next(k for k in declared.links if k != guide_link)
    here = ref.joints[pair][1]
    near_guide, near_slider = (_nearest_joint(source, ref, pair, k) for k in (guide_link, slider))
    for start, end in ((near_guide, near_slider), (near_guide, here), (here, near_slider)):
        angle = _angle_from(start, end, ref.size)
        if angle is not None:
            return angle
    return 0.0


@dataclass
class _Geometry:
    """Local points and guides of every link of one combination (mutable while it is declared)."""

    points: dict[str, dict[str, tuple[float, float]]]
    guides: dict[str, dict[str, tuple[tuple[float, float], float]]]

    @classmethod
    def of(cls, source: Mechanism) -> _Geometry:
        return cls({k: dict(link.points) for k, link in source.links.items()},
                   {k: {g: (guide.point, guide.angle) for g, guide in link.guides.items()}
                    for k, link in source.links.items()})

    def ensure_point(self, link: str, name: str, ref: Reference, where: np.ndarray) -> None:
        """Declare ``name`` on ``link`` at the global reference point ``where`` unless it is there."""
        if name not in self.points[link]:
            self.points[link][name] = ref.to_local(link, where)

    def new_guide_name(self, link: str, pair: str) -> str:
        name = f"guide_{pair}"
        while name in self.guides[link]:
            name += "_"
        return name


def _declare_pairs(builder: MechanismBuilder, geometry: _Geometry, source: Mechanism, ref: Reference,
                   assignment: Assignment) -> None:
    """The pairs of the combination on ``builder``, with the points and guides they need in ``geometry``."""
    names = _joint_names(source, ref)
    for name in sorted(source.pairs):
        declared, kind = source.pairs[name], assignment.of(name)
        point, where = names[name], ref.joints[name][1]
        if kind is None or kind.kind == "R":
            for link in declared.links:
                geometry.ensure_point(link, point, ref, where)
            builder.revolute(name, *declared.links, at=point)
            continue
        guide_link = kind.guide_link
        slider = next(k for k in declared.links if k != guide_link)
        if isinstance(declared, Prismatic) and declared.links[0] == guide_link:
            builder.prismatic(name, guide_link, slider, guide=declared.guide, at=declared.point,
                              angle=declared.angle)
            continue
        geometry.ensure_point(slider, point, ref, where)
        direction = guide_direction(source, ref, name, guide_link)
        guide = geometry.new_guide_name(guide_link, name)
        geometry.guides[guide_link][guide] = (ref.to_local(guide_link, where), direction - ref.poses[guide_link][2])
        builder.prismatic(name, guide_link, slider, guide=guide, at=point,
                          angle=wrap_angle(ref.poses[slider][2] - direction))


def _scaled_crank(geometry: _Geometry, source: Mechanism, factor: float) -> tuple[float, float]:
    """Shrink the input link's points and guides towards its pivot by ``factor``; its centre of
    mass, scaled the same way, is returned."""
    (crank,) = _one_input(source)
    pivot = np.array(source.links[crank].points[source.pairs[input_pair(source)].point])

    def scaled(p) -> tuple[float, float]:
        q = pivot + factor * (np.asarray(p, dtype=float) - pivot)
        return (float(q[0]), float(q[1]))

    geometry.points[crank] = {k: scaled(p) for k, p in geometry.points[crank].items()}
    geometry.guides[crank] = {k: (scaled(p), a) for k, (p, a) in geometry.guides[crank].items()}
    return scaled(source.links[crank].center_of_mass)


def _declare_links(builder: MechanismBuilder, geometry: _Geometry, source: Mechanism, factor: float) -> None:
    crank_com = _scaled_crank(geometry, source, factor)
    for name in sorted(source.links):
        link = source.links[name]
        mass = {}
        if link.mass_declared:
            com = crank_com if name in source.inputs else link.center_of_mass
            mass = {"mass": link.mass, "com": tuple(com), "inertia": link.inertia}
        builder.link(name, points=geometry.points[name],
                     guides={g: {"through": p, "angle": a} for g, (p, a) in geometry.guides[name].items()},
                     **mass)


def _builder(source: Mechanism, ref: Reference, assignment: Assignment, factor: float,
             marks: dict[str, str] | None = None) -> MechanismBuilder:
    """A builder holding the combination's links, pairs and input (no output, no assembly yet);
    ``marks``: link -> the name of a point to add at its origin."""
    builder = MechanismBuilder(f"{source.name} {assignment.id}", frame=source.frame)
    geometry = _Geometry.of(source)
    _declare_pairs(builder, geometry, source, ref, assignment)
    for link, name in (marks or {}).items():
        geometry.points[link][name] = (0.0, 0.0)
    _declare_links(builder, geometry, source, factor)
    builder.inputs(*source.inputs)
    return builder


def _fixed_angle_links(source: Mechanism, assignment: Assignment) -> set[str]:
    """Links whose angle never changes: the frame and the links joined to it through prismatic pairs."""
    fixed, grew = {source.frame}, True
    while grew:
        grew = False
        for kind in assignment.kinds:
            links = set(source.pairs[kind.pair].links)
            if kind.kind == "P" and len(links & fixed) == 1:
                fixed |= links
                grew = True
    return fixed


def output_candidates(source: Mechanism, assignment: Assignment, structure: Structure) -> list[str]:
    """The quantities that may be a combination's output, in order of preference: the source's
    output when the combination has it (a slide needs its pair prismatic, a link's angle the link
    to turn); the slides of the last group's prismatic pairs on the frame; the angles of the last
    group's links that turn (the last link first). The first that has a stroke is measured."""
    fixed = _fixed_angle_links(source, assignment)
    found = []
    if source.output is not None:
        name, _, coord = source.output.quantity.rpartition(".")
        kind = assignment.of(name)
        if (coord in ("x", "y") or (coord == "s" and kind is not None and kind.kind == "P")
                or (coord == "theta" and name not in fixed)):
            found.append(source.output.quantity)
    last = structure.groups[-1]
    found += [f"{j.name}.s" for j in last.joints if isinstance(j, PrismaticJoint) and structure.frame in (j.a, j.b)]
    found += [f"{k}.theta" for k in reversed(last.links) if k not in fixed]
    return list(dict.fromkeys(found)) or [f"{last.links[-1]}.theta"]


def _branches(structure: Structure, ref: Reference) -> dict[int, int]:
    """Group index -> the assembly branch (raw sign) whose placement is the reference position,
    for every group with two branches."""
    known = {link: pose[None, :] for link, pose in ref.poses.items()}
    chosen = {}
    for i, group in enumerate(structure.groups):
        if len(group.branches) < 2:
            continue
        misses = {}
        for branch in group.branches:
            with np.errstate(all="ignore"):   # a link of zero length (a pin where a slider was) is NaN here
                placed = group.position(known, branch).poses
            misses[branch] = max(float(np.hypot(*(placed[k][0, :2] - ref.poses[k][:2]))
                                       + ref.size * abs(wrap_angle(placed[k][0, 2] - ref.poses[k][2])))
                                 for k in group.links)
        chosen[i] = min(misses, key=lambda b: (not math.isfinite(misses[b]), misses[b]))
    return chosen


def _condition_points(structure: Structure, mech: Mechanism) -> tuple[dict[int, list[str]], dict[str, str]]:
    """For every group with several assembly modes, the points of its links that no earlier such
    group declares (so that an assembly condition on one of them is the group's), sorted;
    ``({group index: points}, {link: mark})``, where a mark is a point to add at a link's origin
    for a group whose points are all taken."""
    taken: set[str] = set()
    chosen, marks = {}, {}
    for i, group in enumerate(structure.groups):
        if not has_modes(group):
            continue
        own = {p for k in group.links for p in mech.links[k].points}
        chosen[i] = sorted(own - taken)
        if not chosen[i]:
            name = f"mark_{group.links[0]}"
            while name in mech.point_names:
                name += "_"
            chosen[i] = [name]
            marks[group.links[0]] = name
        taken |= own
    return chosen, marks


# ----------------------------------------------------------------------------------------------
# groups solved by Newton's method: the assembly mode of the reference position
# ----------------------------------------------------------------------------------------------

#: step of the crank's length (a fraction of the source's) by which a group solved by Newton's
#: method is followed from the reference position to a shorter crank
CRANK_STEP = 0.2
#: largest and smallest steps of the input angle, rad, by which the reference mode is followed over a turn
FOLLOW_STEPS = (math.radians(10.0), math.radians(0.25))
#: a step is halved where Newton's method lands farther than this fraction of the size (or than half
#: the predicted move) from the prediction
FOLLOW_MISS = 0.05
#: random starts of Newton's method that look for a group's other assembly modes at the reference angle
MODE_STARTS = 64
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
    (:func:`_too_close_to_singular`), or when it does not come back to itself after the turn.
    These are cheap checks before the scheme is loaded (which traces every mode of the group over
    360 angles); the check of the loaded scheme has the last word.

    Raises
    ------
    AssemblyError
        When a group solved by Newton's method cannot be placed as the crank shrinks (naming it,
        the input angle and the crank's length).
    """
    mech = _builder(source, ref, assignment, 1.0).build()
    structure = decompose(mech)
    branches = _branches(structure, ref)
    poses = dict(ref.poses)
    steps = max(0, math.ceil((1.0 - factor) / CRANK_STEP - 1e-9))
    for before, fraction in itertools.pairwise(np.linspace(1.0, factor, steps + 1)):
        mech = _builder(source, ref, assignment, float(fraction)).build()
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
                return replace(place, problem=_singular_words(group, conditioning, ref.phi))
    turn, problem = _followed_turn(place, ref)
    return replace(place, turn=turn, problem=problem)


def _singular_words(group, conditioning: float, phi: float | None = None, largest: float | None = None) -> str:
    """Why ``group`` is no sensible default: its conditioning falls below the floor of
    :func:`_too_close_to_singular` (at the input angle ``phi``, rad)."""
    where = "" if phi is None else f" at phi = {math.degrees(phi) % 360:.6g} deg"
    if largest is None:
        return (f"group {group!r} comes close to a singular position{where} (conditioning {conditioning:.2g}; "
                f"at least {MIN_CONDITIONING:g} wanted)")
    return (f"group {group!r} comes close to a singular position{where} (conditioning {conditioning:.2g}, "
            f"{conditioning / largest:.2g} of its largest over the turn; at least {MIN_CONDITIONING:g} of it wanted)")


def _too_close_to_singular(group, conditioning: np.ndarray) -> bool:
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
    :func:`_too_close_to_singular` at each angle reached (a larger group's against its largest
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
            if _too_close_to_singular(group, np.array([ratios[i], largest_ratios[i]])):
                problem = _singular_words(group, ratios[i], ref.phi + done,
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
    a kind lists (the triad), else those Newton's method reaches from :data:`MODE_STARTS` random
    starts around the mode; each ``{link: (3,)}``, distinct."""
    size = float(group.size)
    listed = group.modes(known)
    if listed is not None:
        candidates, valid = listed
        found = {k: v[0][valid[0]] for k, v in candidates.items()}
    else:
        rng = np.random.default_rng(0)
        centre = np.mean(group.contact_points({**known, **{k: v[None] for k, v in mode.items()}})[0], axis=0)
        at = {k: np.repeat(v, MODE_STARTS, axis=0) for k, v in known.items()}
        starts = {k: np.column_stack([centre[0] + size * rng.uniform(-1, 1, MODE_STARTS),
                                      centre[1] + size * rng.uniform(-1, 1, MODE_STARTS),
                                      rng.uniform(-np.pi, np.pi, MODE_STARTS)]) for k in group.links}
        with np.errstate(all="ignore"):
            solved, converged = newton(group, at, starts)
            closure = np.max(np.abs(group.residual({**at, **solved})), axis=1)
        good = converged & (closure <= 1e-9 * size)
        found = {k: v[good] for k, v in solved.items()}
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

    The point is one of ``points`` (the group's own, :func:`_condition_points`); the line runs
    through two points that do not move with the group's mode (points of the frame, the crank and
    earlier groups), at least 0.01 of the size apart. A condition qualifies when the mode meets it
    at the reference angle and every other mode found there (:func:`_other_modes`) does not; it
    ranks first when the mode meets it at every angle it was followed through
    (``place.turn``), then by its margin at the reference angle: the smaller of how far the mode's
    point lies on its side of the line and how far every other mode's lies on the other, m. Which
    mode a condition picks over a turn is decided when the scheme is loaded
    (:mod:`linkage.kinematics.assembly`); :func:`enumerate_chain` checks that it is this one.
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
        Pair kinds (from :func:`assignments`).
    factor : float
        The crank's length as a fraction of the source's (its points move towards its pivot).
    ref : Reference, optional
        The source's reference position (default: the first of :func:`reference_positions`).
    output : str, optional
        The output quantity to declare (default: the first of :func:`output_candidates`).
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
        When the assignment is not solvable (the reason :class:`Rejected` gives, naming the group).
    AssemblyError
        When a group solved by Newton's method cannot be placed at the reference angle or has
        no condition number ``choice`` that tells its modes apart there.
    """
    ref = reference_positions(source)[0] if ref is None else ref
    structure = _solvable(source, ref, assignment)
    if isinstance(structure, str):
        raise StructureError(f"scheme '{source.name}', assignment {assignment.id}: {structure}")
    place = placement(source, ref, assignment, factor) if _tracked(structure) else None
    return _declared(source, assignment, factor, ref, output, choice, structure, place)


def _tracked(structure: Structure) -> list[int]:
    """Indices of the groups solved by Newton's method (their modes traced over a turn)."""
    return [i for i, group in enumerate(structure.groups) if getattr(group, "tracked", False)]


def _declared(source: Mechanism, assignment: Assignment, factor: float, ref: Reference, output: str | None,
              choice: int, structure: Structure, place: Placement | None) -> Mechanism:
    """:func:`build_combination` with the structure (crank 1) and the placement (crank ``factor``) known."""
    points, marks = _condition_points(structure, _builder(source, ref, assignment, factor).build())
    builder = _builder(source, ref, assignment, factor, marks)
    for i, branch in _branches(structure, ref).items():
        builder.assembly(points[i][0], branch=branch)
    if place is not None:
        marked = builder.build()
        for i in _tracked(structure):
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


# ----------------------------------------------------------------------------------------------
# measuring a combination
# ----------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Combination:
    """One valid assignment: its structure and, where a geometry runs a full turn, its figures.

    Attributes
    ----------
    assignment : Assignment
    formula : str
        Structural formula, e.g. ``I(0,1) → II-RPR(2,3)``.
    full_turn : bool or None
        A geometry was found that assembles, stays regular and passes no change point over a turn;
        None: not searched (a combination solved by Newton's method, without ``newton=True``).
    crank_factor : float or None
        The crank's length as a fraction of the source's in that geometry.
    reference_deg : float or None
        The input angle of the source's reference position it was taken at, deg.
    output : str
        The measured quantity (``"B.x"``, ``"3.theta"``, ``"K.s"``).
    stroke : float or None
        Its stroke over a turn: m for a point coordinate or a slide, deg for a link angle (the
        swing); None without a full turn or when no candidate output has one.
    stroke_unit : str
        ``"m"`` or ``"deg"``.
    min_transmission_angle_deg : float or None
        Smallest transmission angle over the turn, deg; None when no group has one.
    peak_balancing_moment : float or None
        ``max |M_b|`` over the turn at the enumeration's speed, N m.
    note : str
        Why no geometry was found, or what the figures leave out.
    scheme : str or None
        The TOML text of the combination's scheme (full turn only).
    """

    assignment: Assignment
    formula: str
    full_turn: bool | None
    crank_factor: float | None
    reference_deg: float | None
    output: str
    stroke: float | None
    stroke_unit: str
    min_transmission_angle_deg: float | None
    peak_balancing_moment: float | None
    note: str
    scheme: str | None

    @property
    def id(self) -> str:
        return self.assignment.id


@dataclass(frozen=True)
class Rejected:
    """An assignment that is not solvable, and why: it does not decompose into groups a registered
    solver binds, or a group's prismatic pairs close a loop (:func:`_angle_loop`)."""

    assignment: Assignment
    reason: str

    @property
    def id(self) -> str:
        return self.assignment.id


def _scheme_text(mech: Mechanism, source: Mechanism, assignment: Assignment, ref: Reference) -> str:
    """The scheme file of a combination: comments saying where it comes from, then the scheme."""
    header = [f"# {assignment.id}: scheme '{source.name}' with pairs " + ", ".join(k.words for k in assignment.kinds),
              (f"# written by `linkage enumerate {source.name}`: geometry of the source at phi = "
               f"{math.degrees(ref.phi):.6g} deg (docs/enumerate.md); each group keeps the assembly "
               "branch or mode of that position")]
    return "\n".join(header) + "\n" + dumps(mech)


def _one_line(text: object) -> str:
    return "; ".join(part.strip() for part in str(text).splitlines() if part.strip())


def _full_turn_problem(mech: Mechanism) -> tuple[str | None, dict]:
    """Why ``mech`` does not run a full turn (:func:`linkage.kinematics.feasibility.check`: it assembles at
    every angle of a 1 deg sweep, stays regular, passes no change point) or comes close to a
    singular position (:func:`_too_close_to_singular` on every group's conditioning), or None;
    and the check's figures."""
    verdict = check(mech)
    if not verdict.feasible:
        return verdict.reason, verdict.figures
    if verdict.figures["min_conditioning"] >= MIN_CONDITIONING:
        return None, verdict.figures
    motion = analyze(mech, sweep_angles(mech, POSITIONS), order=0, on_failure="mask")
    for group in motion.structure.groups:
        ratios = motion.conditioning[repr(group)]
        if _too_close_to_singular(group, ratios):
            largest = None if len(group.links) == 2 else float(np.nanmax(ratios))
            return _singular_words(group, float(np.nanmin(ratios)), None, largest), verdict.figures
    return None, verdict.figures


def _stroke_of(mech: Mechanism, candidates: list[str]) -> tuple[str, float | None, str]:
    """The first candidate with a stroke (between its extreme positions, :func:`linkage.extreme_positions`):
    ``(quantity, stroke in m or deg, note)``; the first candidate, None and why when none has one."""
    for quantity in candidates:
        try:
            stroke = extreme_positions(mech, quantity).stroke
        except LinkageError:  # constant, or monotonic: a link that turns fully
            continue
        if stroke > COINCIDENT * (1.0 if quantity.endswith(".theta") else mech.size):   # rad or m
            return quantity, math.degrees(stroke) if quantity.endswith(".theta") else stroke, ""
    return candidates[0], None, f"no stroke: {', '.join(candidates)} stay constant or turn fully"


def _peak_balancing_moment(mech: Mechanism, omega: float) -> float:
    """``max |M_b|`` over a turn (:data:`POSITIONS` angles) at the constant speed ``omega``, N m."""
    phi = np.linspace(0.0, 2 * np.pi, POSITIONS, endpoint=False)
    motion = analyze(mech, phi, omega=omega, eps=0.0)
    return float(np.max(np.abs(solve_reactions(motion).balancing_moment)))


def _measured(source: Mechanism, assignment: Assignment, structure: Structure, ref: Reference, omega: float,
              factor: float, candidates: list[str]) -> Combination | str:
    """The combination with the crank ``factor`` and the geometry of ``ref``, measured; or the
    reason it does not run a full turn."""
    try:
        place = placement(source, ref, assignment, factor) if _tracked(structure) else None
        if place is not None and place.problem is not None:
            return place.problem
        mech, choice, text = _loaded(source, assignment, factor, ref, candidates[0], structure, place)
        problem, figures = _full_turn_problem(mech)
        if problem is not None:
            return problem
        output, stroke, note = _stroke_of(mech, candidates)
        if output != candidates[0]:
            text = _scheme_text(_declared(source, assignment, factor, ref, output, choice, structure, place), source,
                                assignment, ref)
            mech = loads(text, source=assignment.file_name)
        peak = _peak_balancing_moment(mech, omega)
    except LinkageError as exc:
        return _one_line(exc)
    return Combination(assignment, structure.formula, True, factor, math.degrees(ref.phi), output, stroke,
                       _unit(output), figures.get("min_transmission_angle_deg"), peak, note, text)


def _loaded(source: Mechanism, assignment: Assignment, factor: float, ref: Reference, output: str,
            structure: Structure, place: Placement | None) -> tuple[Mechanism, int, str]:
    """The combination's scheme loaded, the choice of conditions (:func:`build_combination`) it
    has, and its text.

    With groups solved by Newton's method (``place`` given) the conditions of
    :func:`mode_conditions` are tried in turn until the scheme loads and its traced mode at the
    reference angle is the mode of ``place`` (to 1e-8 of the size).

    Raises
    ------
    AssemblyError
        When no condition tried does (naming the angle and why each failed).
    """
    def loaded(choice: int) -> tuple[Mechanism, int, str]:
        text = _scheme_text(_declared(source, assignment, factor, ref, output, choice, structure, place), source,
                            assignment, ref)
        return loads(text, source=assignment.file_name), choice, text

    if place is None:
        return loaded(0)
    reasons = []
    for choice in range(CONDITION_TRIALS):
        try:
            found = loaded(choice)
        except AssemblyError as exc:       # no further condition
            reasons.append(_one_line(exc))
            break
        except SchemeError as exc:
            reasons.append(_one_line(exc))
            if "assembly of point" in str(exc):     # the condition does not tell the modes apart: try the next
                continue
            break
        mech = found[0]
        motion = analyze(mech, [ref.phi], order=0, on_failure="mask")
        miss = place.mismatch({k: motion.poses[k][0] for group in structure.groups for k in group.links})
        if motion.status[0] == OK and miss <= 1e-8 * mech.size:
            return found
        reasons.append(f"with {_condition_words(mech)} the traced mode at the reference angle is not the reference "
                       f"position's ({miss:.3g} m apart)")
    raise AssemblyError(f"no readable assembly condition picks the mode of the reference position at phi = "
                        f"{math.degrees(ref.phi):.6g} deg: " + "; ".join(reasons), np.array([math.degrees(ref.phi)]))


def _condition_words(mech: Mechanism) -> str:
    """The readable assembly conditions of ``mech``: ``"D left_of [F, C]"``."""
    return ", ".join(f"{a.point} {a.rule} [{', '.join(a.refs)}]" for a in mech.assembly if a.rule != "branch")


def _unit(quantity: str) -> str:
    """The unit of a stroke of ``quantity`` in the table: deg for a link's angle, else m."""
    return "deg" if quantity.endswith(".theta") else "m"


def _combination(source: Mechanism, assignment: Assignment, structure: Structure, refs: list[Reference],
                 omega: float, factors: tuple[float, ...]) -> Combination:
    """The first geometry that runs a full turn: each crank factor in turn, at each reference
    position; else the combination without figures, with the reason found at the first."""
    candidates = output_candidates(source, assignment, structure)
    reasons = []
    with warnings.catch_warnings(), np.errstate(all="ignore"):
        warnings.simplefilter("ignore", RuntimeWarning)
        warnings.simplefilter("ignore", BranchWarning)
        for factor in factors:
            for ref in refs:
                found = _measured(source, assignment, structure, ref, omega, factor, candidates)
                if isinstance(found, Combination):
                    return found
                reasons.append(found)
    if not reasons:
        note = "geometry not searched"
    else:
        note = (f"no full-turn geometry found: {reasons[0]} (nor at the other {len(reasons) - 1} trials: crank "
                f"{', '.join(f'{f:g}' for f in factors)} of the source's, each at {len(refs)} reference positions)")
    return Combination(assignment, structure.formula, False, None, None, candidates[0], None, _unit(candidates[0]),
                       None, None, note, None)


# ----------------------------------------------------------------------------------------------
# the enumeration
# ----------------------------------------------------------------------------------------------

#: columns of the table and their units (None: text or a pure number)
COLUMN_UNITS = {"id": None, "formula": None, "full_turn": None, "crank_factor": None, "reference_deg": "deg",
                "output": None, "stroke": "m or deg", "stroke_unit": None, "min_transmission_angle_deg": "deg",
                "peak_balancing_moment": "N m", "note": None}


@dataclass(frozen=True)
class Enumeration:
    """Every assignment of a chain: the valid ones measured, the others with the reason.

    Attributes
    ----------
    source : str
        The source scheme's name.
    omega : float
        Input speed of the balancing moment, rad/s.
    references_deg : tuple of float
        Input angles of the source's reference positions, in the order tried, deg.
    combinations : tuple of Combination
        The valid assignments, in the order of :func:`assignments`.
    rejected : tuple of Rejected
        The others.
    """

    source: str
    omega: float
    references_deg: tuple[float, ...]
    combinations: tuple[Combination, ...]
    rejected: tuple[Rejected, ...]

    def columns(self) -> dict[str, np.ndarray]:
        """The table: one row per valid assignment, the columns of :data:`COLUMN_UNITS`.

        ``id``; ``formula``; ``full_turn`` (``yes`` / ``no`` / ``not searched``); ``crank_factor`` (the crank as a
        fraction of the source's); ``reference_deg`` (the source's position the geometry is taken
        at, deg); ``output``; ``stroke`` (in ``stroke_unit``: m, or deg for a link's swing);
        ``min_transmission_angle_deg`` (deg); ``peak_balancing_moment`` (N m, the largest
        ``|M_b|`` over a turn at ``omega``); ``note``. Missing numbers are NaN.
        """
        rows = self.combinations

        def numbers(name: str) -> np.ndarray:
            values = [getattr(c, name) for c in rows]
            return np.array([np.nan if v is None else float(v) for v in values], dtype=float)

        def texts(values) -> np.ndarray:
            return np.array(list(values), dtype=object)

        return {
            "id": texts(c.id for c in rows),
            "formula": texts(c.formula for c in rows),
            "full_turn": texts("not searched" if c.full_turn is None else "yes" if c.full_turn else "no"
                               for c in rows),
            "crank_factor": numbers("crank_factor"),
            "reference_deg": numbers("reference_deg"),
            "output": texts(c.output for c in rows),
            "stroke": numbers("stroke"),
            "stroke_unit": texts(c.stroke_unit for c in rows),
            "min_transmission_angle_deg": numbers("min_transmission_angle_deg"),
            "peak_balancing_moment": numbers("peak_balancing_moment"),
            "note": texts(c.note for c in rows),
        }

    def rejected_columns(self) -> dict[str, np.ndarray]:
        """The rejected assignments: ``id`` and ``reason``."""
        return {"id": np.array([r.id for r in self.rejected], dtype=object),
                "reason": np.array([r.reason for r in self.rejected], dtype=object)}

    def write(self, folder: str | Path) -> list[Path]:
        """Write ``<id>.toml`` for every combination that runs a full turn, ``combinations.csv``
        (the table) and ``rejected.csv`` into ``folder`` (created); return the files written.

        Raises
        ------
        InputError
            When the folder cannot be created or written (naming it).
        """
        folder = Path(folder)
        files = {c.assignment.file_name: c.scheme for c in self.combinations if c.scheme is not None}
        files["combinations.csv"] = _csv(self.columns())
        files["rejected.csv"] = _csv(self.rejected_columns())
        try:
            folder.mkdir(parents=True, exist_ok=True)
            for name, text in files.items():
                (folder / name).write_text(text, encoding="utf-8")
        except OSError as exc:
            raise InputError(f"{folder}: cannot be written ({exc.strerror or exc})") from None
        return [folder / name for name in files]


def _csv(columns: dict[str, np.ndarray]) -> str:
    """CSV text of a table (the header alone when it has no rows)."""
    return format_columns(columns, "csv") if len(next(iter(columns.values()))) else ",".join(columns) + "\n"


def _solvable(source: Mechanism, ref: Reference, assignment: Assignment) -> Structure | str:
    """The combination's structure, or the reason it is not solvable: it does not decompose into
    groups that a registered solver binds, or a group's prismatic pairs fix one angle twice
    (:func:`_angle_loop`)."""
    try:
        structure = decompose(_builder(source, ref, assignment, 1.0).build())
    except LinkageError as exc:
        return _one_line(exc)
    for group in structure.groups:
        loop = _angle_loop(group)
        if loop:
            pairs = ", ".join(_pair_words(j) for j in loop)
            return (f"group {group!r}: its prismatic pairs {pairs} close a loop through its links (the known "
                    "links counted as one), so they fix one angle twice: its equations are dependent and no "
                    "geometry assembles it regularly")
    return structure


def _angle_loop(group) -> list[PrismaticJoint]:
    """The prismatic pairs of ``group`` that close a loop, or ``[]``.

    A prismatic pair fixes the angle between its two links. Pairs that close a loop through the
    group's links -- the known links counted as one link, their angles being given -- fix one
    angle twice: the group's equations are then dependent (its Jacobian is singular at every pose)
    or contradict the input's turning (a loop through the known links fixes the crank's angle).
    """
    def node(link: str) -> str:
        return link if link in group.links else "known"

    edges: dict[str, list[tuple[str, PrismaticJoint]]] = {}
    for joint in group.joints:
        if not isinstance(joint, PrismaticJoint):
            continue
        a, b = node(joint.a), node(joint.b)
        path = _path(edges, a, b)
        if path is not None:
            return sorted(path + [joint], key=lambda j: j.name)
        edges.setdefault(a, []).append((b, joint))
        edges.setdefault(b, []).append((a, joint))
    return []


def _path(edges: dict, start: str, end: str) -> list | None:
    """The edges (pairs) of the path from ``start`` to ``end`` in a forest ``{node: [(next, edge)]}``,
    ``[]`` when they are one node, None when they are not connected."""
    paths = {start: []}
    queue = [start]
    while queue:
        here = queue.pop()
        if here == end:
            return paths[here]
        for there, edge in edges.get(here, ()):
            if there not in paths:
                paths[there] = paths[here] + [edge]
                queue.append(there)
    return None


def _pair_words(joint) -> str:
    """``"B: P guide 3 / slider 2"`` or ``"A: R 1-2"``."""
    if isinstance(joint, PrismaticJoint):
        return f"{joint.name}: P guide {joint.a} / slider {joint.b}"
    return f"{joint.name}: R {joint.a}-{joint.b}"


def enumerate_chain(source: Mechanism | str | Path, *, omega: float = DEFAULT_OMEGA,
                    factors: Iterable[float] = CRANK_FACTORS, geometry: bool = True, newton: bool = False,
                    progress: Callable | None = None) -> Enumeration:
    """Enumerate the pair kinds of a scheme's chain and measure every valid combination.

    Parameters
    ----------
    source : Mechanism, str or Path
        A mechanism, a shipped scheme name or a scheme file (one input link).
    omega : float
        Input speed for the balancing moment, rad/s (finite, nonzero).
    factors : iterable of float
        Crank lengths tried, as fractions of the source's, until a geometry runs a full turn (each
        at every reference position of :func:`reference_positions`).
    geometry : bool
        False: only decompose (no geometry search; every combination is listed without figures).
    newton : bool
        Search the geometry of the combinations with a group solved by Newton's method too (each
        written scheme traces its modes when loaded: about 1-2 s per trial, minutes for a
        six-bar); default False: they are listed with ``full_turn`` None ("not searched").
    progress : callable, optional
        ``progress(iterable, total)`` wrapping the loop over the valid assignments (a tqdm bar).

    Returns
    -------
    Enumeration
    """
    mech = _source(source)
    omega, factors = _checked(omega, factors)
    refs = reference_positions(mech)
    valid, rejected = [], []
    for assignment in assignments(mech):
        found = _solvable(mech, refs[0], assignment)
        if isinstance(found, str):
            rejected.append(Rejected(assignment, found))
        else:
            valid.append((assignment, found))
    loop = valid if progress is None else progress(valid, len(valid))
    rows = [_combination(mech, assignment, structure, refs, omega, factors if geometry else ())
            if newton or not geometry or not _tracked(structure) else _unsearched(mech, assignment, structure)
            for assignment, structure in loop]
    return Enumeration(mech.name, omega, tuple(math.degrees(r.phi) for r in refs), tuple(rows), tuple(rejected))


def _unsearched(source: Mechanism, assignment: Assignment, structure: Structure) -> Combination:
    """A combination with a group solved by Newton's method, listed without a geometry search."""
    output = output_candidates(source, assignment, structure)[0]
    return Combination(assignment, structure.formula, None, None, None, output, None, _unit(output), None, None,
                       "a group's modes are traced over the turn (the triad, or Newton's method): geometry not "
                       "searched (--newton searches it, slowly)",
                       None)


def measure(source: Mechanism | str | Path, assignment: Assignment | str, *, omega: float = DEFAULT_OMEGA,
            factors: Iterable[float] = CRANK_FACTORS) -> Combination:
    """One assignment's combination, measured as :func:`enumerate_chain` measures each.

    Parameters
    ----------
    source : Mechanism, str or Path
        A mechanism, a shipped scheme name or a scheme file (one input link).
    assignment : Assignment or str
        One of :func:`assignments`, or its id (``"A=R,B=P3,C=R"``).
    omega, factors
        As for :func:`enumerate_chain`.

    Returns
    -------
    Combination

    Raises
    ------
    InputError
        For an id that is no assignment of the chain (naming it).
    StructureError
        When the assignment is not solvable (the reason :class:`Rejected` would give).
    """
    mech = _source(source)
    omega, factors = _checked(omega, factors)
    if isinstance(assignment, str):
        known = {a.id: a for a in assignments(mech)}
        if assignment not in known:
            raise InputError(f"scheme '{mech.name}': {assignment!r} is no assignment of its pairs "
                             f"(e.g. {next(iter(known))!r})")
        assignment = known[assignment]
    refs = reference_positions(mech)
    found = _solvable(mech, refs[0], assignment)
    if isinstance(found, str):
        raise StructureError(f"scheme '{mech.name}', assignment {assignment.id}: {found}")
    return _combination(mech, assignment, found, refs, omega, factors)


def _source(source: Mechanism | str | Path) -> Mechanism:
    return source if isinstance(source, Mechanism) else load(source)


def _checked(omega: float, factors: Iterable[float]) -> tuple[float, tuple[float, ...]]:
    """``omega`` and the crank factors, checked (:class:`InputError` naming a bad value)."""
    if not (math.isfinite(omega) and omega != 0.0):
        raise InputError(f"omega must be a finite nonzero speed in rad/s, got {omega!r}")
    factors = tuple(float(f) for f in factors)
    if not all(0.0 < f <= 1.0 for f in factors):
        raise InputError(f"crank factors must be fractions in (0, 1], got {list(factors)}")
    return float(omega), factors
