"""One combination's mechanism: the source's geometry given to an assignment's pairs; whether it is solvable.

Each assignment gets the source scheme's own geometry (docs/enumerate.md), taken at a reference
position of the source (:class:`~.assignments.Reference`): its links keep their local points,
masses and inertias; a pair that becomes prismatic gets a guide through its point, along the line
from the guide link's nearest other joint to the slider link's (:func:`guide_direction`; a pair
that is prismatic in the source keeps its guide line); a pair that becomes revolute is pinned
where its slider's point is. :func:`combination_builder` declares it, the crank shrunk towards its
pivot by a factor. An assignment is kept (:func:`solvable`) when the mechanism decomposes
(:func:`linkage.structure.decompose`) into groups that a registered solver binds
(:func:`assur.registry.solver_for`: the closed-form dyads RRR, RRP, RPR, PRP, RPP, the class-III
triad, and Newton's method for any other statically determinate group) and no group's prismatic
pairs close a loop (:func:`_angle_loop`: they would fix one angle twice, so the group's equations
are dependent whatever its dimensions); the others are rejected with the reason. Also here: the
quantities that may be a combination's output (:func:`output_candidates`), the branch of the
reference position of each group with two branches (:func:`reference_branches`), and the points
an assembly condition of each group with several modes may name (:func:`condition_points`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from assur.base import PrismaticJoint

from ..errors import LinkageError
from ..kinematics.assembly import has_modes
from ..kinematics.extremes import wrap_angle
from ..model.builder import MechanismBuilder
from ..model.mechanism import Mechanism, Prismatic
from ..structure import Structure, decompose
from .assignments import Assignment, Reference, input_pair, one_input

__all__ = [
    "guide_direction",
    "output_candidates",
]

#: points closer than this fraction of the mechanism's size are one point
COINCIDENT = 1e-9


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
    (crank,) = one_input(source)
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


def combination_builder(source: Mechanism, ref: Reference, assignment: Assignment, factor: float,
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


def reference_branches(structure: Structure, ref: Reference) -> dict[int, int]:
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


def condition_points(structure: Structure, mech: Mechanism) -> tuple[dict[int, list[str]], dict[str, str]]:
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
# which assignments are solvable
# ----------------------------------------------------------------------------------------------


def solvable(source: Mechanism, ref: Reference, assignment: Assignment) -> Structure | str:
    """The combination's structure, or the reason it is not solvable: it does not decompose into
    groups that a registered solver binds, or a group's prismatic pairs fix one angle twice
    (:func:`_angle_loop`)."""
    try:
        structure = decompose(combination_builder(source, ref, assignment, 1.0).build())
    except LinkageError as exc:
        return one_line(exc)
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


def one_line(text: object) -> str:
    """``text`` (an error's message) on one line: its non-blank lines, stripped, joined by ``"; "``."""
    return "; ".join(part.strip() for part in str(text).splitlines() if part.strip())
