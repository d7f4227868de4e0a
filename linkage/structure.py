"""Structural analysis: mobility (Chebyshev) and decomposition into Assur groups (docs/methods.md#structure).

Plain functions on a :class:`~linkage.model.mechanism.Mechanism`:

>>> import linkage
>>> mech = linkage.load("slider_crank")
>>> mobility(mech)
1
>>> decompose(mech).formula
'I(0,1) → II-RRP(2,3)'
"""

from __future__ import annotations

from dataclasses import dataclass
from itertools import combinations

import numpy as np

from assur import Group, PrismaticJoint, RevoluteJoint, solver_for
from assur.base import DrivenPrismaticJoint

from .errors import StructureError
from .model.mechanism import Mechanism, Prismatic, Revolute

__all__ = ["Structure", "mobility", "decompose", "structure_of", "joint_of", "group_links"]

#: largest group searched, links (class III groups have 4; a 1-DOF mechanism of 12 links may hold
#: one of 10, solved by Newton's method)
MAX_GROUP_LINKS = 10


@dataclass(frozen=True)
class Structure:
    """The decomposition of a mechanism.

    Attributes
    ----------
    inputs : tuple of str
        Input links, each forming a class-I mechanism with the frame (a crank pinned to it, or a
        slider driven along a frame guide).
    input_joints : dict
        Input link -> its joint with the frame (revolute for a crank, prismatic for a slider).
    joints : dict
        Pair name -> its solver-side joint (local geometry resolved), for every pair.
    groups : tuple of Group
        Bound group solvers in the order of kinematic analysis.
    """

    frame: str
    inputs: tuple[str, ...]
    input_joints: dict[str, RevoluteJoint | PrismaticJoint]
    groups: tuple[Group, ...]
    joints: dict[str, RevoluteJoint | PrismaticJoint]

    @property
    def formula(self) -> str:
        """Structural formula, e.g. ``I(0,1) → II-RPR(2,3) → II-PRP(4,5)``."""
        parts = [f"I({j.name})" if isinstance(j, DrivenPrismaticJoint) else f"I({self.frame},{name})"
                 for name, j in self.input_joints.items()]
        parts += [repr(g) for g in self.groups]
        return " → ".join(parts)

    def group_of(self, link: str) -> int | None:
        """Index of the group that places ``link`` (None for the frame and input links)."""
        for i, g in enumerate(self.groups):
            if link in g.links:
                return i
        return None

    def needed_groups(self, links) -> list[int]:
        """Indices (in order) of the groups needed to place ``links``: theirs and their ancestors."""
        needed: set[int] = set()
        stack = [i for i in (self.group_of(k) for k in links) if i is not None]
        while stack:
            i = stack.pop()
            if i in needed:
                continue
            needed.add(i)
            stack += [j for j in (self.group_of(k) for k in self.groups[i].known_links) if j is not None]
        return sorted(needed)


    def loading_groups(self, pairs) -> list[int]:
        """Indices (in order) of the groups whose kinetostatics the reactions in ``pairs`` need:
        the groups of those pairs and every group that loads their links, directly or through
        other groups (the groups farther from the input). A pair of an input link needs all."""
        if any(j.name in pairs for j in self.input_joints.values()):
            return list(range(len(self.groups)))
        needed = {i for i, g in enumerate(self.groups) if any(j.name in pairs for j in g.joints)}
        grew = True
        while grew:
            links = {k for i in needed for k in self.groups[i].links}
            more = {i for i, g in enumerate(self.groups) if links & set(g.known_links)} - needed
            needed |= more
            grew = bool(more)
        return sorted(needed)


def mobility(mech: Mechanism) -> int:
    """Degrees of freedom by Chebyshev's formula ``W = 3 n - 2 p5 - p4`` (lower pairs only)."""
    return 3 * len(mech.moving_links) - 2 * len(mech.pairs)


def joint_of(pair: Revolute | Prismatic, mech: Mechanism) -> RevoluteJoint | PrismaticJoint:
    """The solver-side joint (local geometry resolved) of a model pair."""
    a, b = pair.links
    la, lb = mech.links[a], mech.links[b]
    if isinstance(pair, Revolute):
        return RevoluteJoint(pair.name, a, b, la.points[pair.point], lb.points[pair.point])
    guide = la.guides[pair.guide]
    # the slider's x axis runs along the guide, turned by the pair's angle
    return PrismaticJoint(pair.name, a, b, guide.point, guide.direction, lb.points[pair.point],
                          guide.angle + pair.angle)


def structure_of(mech: Mechanism) -> Structure:
    """The decomposition of ``mech`` (:func:`decompose`), computed once and kept in its cache."""
    if "structure" not in mech.cache:
        mech.cache["structure"] = decompose(mech)
    return mech.cache["structure"]


def decompose(mech: Mechanism) -> Structure:
    """Decompose a mechanism into its input links and an ordered sequence of Assur groups.

    At each step the smallest set of unknown links forming a group on the known links is taken
    (ties broken by sorted link names, so the result does not depend on declaration order).

    Raises
    ------
    StructureError
        When the mobility differs from the number of inputs, or links are left over; the
        message names the links and pairs involved.
    """
    w = mobility(mech)
    if w != len(mech.inputs):
        raise StructureError(
            f"mechanism '{mech.name}': mobility W = 3·{len(mech.moving_links)} - 2·{len(mech.pairs)}"
            f" = {w}, but {len(mech.inputs)} input link(s) are declared {list(mech.inputs)} "
            f"(moving links {mech.moving_links}; pairs {sorted(mech.pairs)})"
        )
    joints = {name: joint_of(pair, mech) for name, pair in mech.pairs.items()}
    input_joints = {}
    for name in mech.inputs:
        pair = mech.input_pair(name)
        joint = joints[pair]
        if mech.frame not in (joint.a, joint.b):
            # a cylinder: the driven pair joins two moving links; its slide is the pose of a driver
            # pseudo-link, a known link of the group that holds the pair
            joint = joints[pair] = DrivenPrismaticJoint(**vars(joint), driver=driver_of(pair))
            input_joints[joint.driver] = joint
            continue
        link = joint.b if joint.a == mech.frame else joint.a
        input_joints[link] = joint
    inputs = tuple(input_joints)
    used = {j.name for j in input_joints.values() if not isinstance(j, DrivenPrismaticJoint)}
    known = {mech.frame, *inputs}
    unknown = sorted(set(mech.links) - known)
    groups: list[Group] = []
    while unknown:
        group = _next_group(unknown, known, joints, used, mech.size)
        if group is None:
            left_pairs = sorted(set(joints) - used)
            raise StructureError(
                f"mechanism '{mech.name}': links {unknown} cannot be decomposed into Assur groups "
                f"on the known links {sorted(known)} (remaining pairs: {left_pairs}); "
                + _why_not(unknown, known, joints, used)
            )
        groups.append(group)
        known |= set(group.links)
        used |= {j.name for j in group.joints}
        unknown = [k for k in unknown if k not in known]
    return Structure(mech.frame, inputs, input_joints, tuple(groups), joints)


def driver_of(pair: str) -> str:
    """Name of the pseudo-link whose pose ``(s, 0, 0)`` carries the slide of the driven pair
    ``pair`` (a cylinder input): ``"<pair>.s"``."""
    return f"{pair}.s"


def _rows(joints) -> int:
    """Equations of the joints: two per pair, three for a driven one."""
    return sum(j.rows for j in joints)


def _group_joints(subset, known, joints, used):
    inside = set(subset) | known
    return [j for name, j in sorted(joints.items())
            if name not in used and (j.a in subset or j.b in subset) and j.a in inside and j.b in inside]


def _is_group(subset, known, joints, used) -> bool:
    """3 n = 2 p and no proper subset over-constrained (so none is floating)."""
    gj = _group_joints(subset, known, joints, used)
    if 3 * len(subset) != _rows(gj):
        return False
    for r in range(1, len(subset)):
        for part in combinations(subset, r):
            if _rows(_group_joints(part, known, joints, used)) >= 3 * len(part):
                return False
    return True


def group_links(unknown, known, joints, used) -> tuple[str, ...] | None:
    """The links of the Assur group :func:`decompose` takes next: the smallest set of the
    ``unknown`` links (sorted names) that forms a group on the ``known`` links over the pairs
    ``joints`` not yet ``used`` (the first of :func:`itertools.combinations` among sets of one
    size), of at most :data:`MAX_GROUP_LINKS` links; None when there is none. Up to
    :data:`MASK_LINKS` unknown links every subset is counted at once (:func:`_group_by_masks`),
    beyond that set by set."""
    if len(unknown) <= MASK_LINKS:
        return _group_by_masks(list(unknown), known, joints, used)
    for n in range(1, min(MAX_GROUP_LINKS, len(unknown)) + 1):   # odd sizes only hold a driven pair
        for subset in combinations(unknown, n):
            if _is_group(subset, known, joints, used):
                return subset
    return None


#: most unknown links whose subsets :func:`group_links` counts all at once (2**16 subsets)
MASK_LINKS = 16


def _group_by_masks(unknown: list[str], known, joints, used) -> tuple[str, ...] | None:
    """:func:`group_links` over every subset of ``unknown`` as a bit mask: each subset's equations
    (the rows of the unused pairs that touch it and join it or the known links), then the
    subsets with ``3 n`` equations of which no proper subset has ``3 n`` or more."""
    m = len(unknown)
    bit = {k: 1 << i for i, k in enumerate(unknown)}
    masks = np.arange(1 << m)
    rows = np.zeros(1 << m, dtype=np.int64)
    for name, j in joints.items():
        if name in used or (j.a not in bit and j.b not in bit):
            continue
        if not all(k in bit or k in known for k in (j.a, j.b)):
            continue
        inside = [np.ones(1 << m, bool) if k in known else (masks & bit[k]) != 0 for k in (j.a, j.b)]
        rows += j.rows * (inside[0] & inside[1])
    size = np.zeros(1 << m, dtype=np.int64)         # links in each subset (numpy 1.x has no bitwise_count)
    for i in range(m):
        size += (masks >> i) & 1
    over = (rows >= 3 * size) & (size > 0)          # no group may hold one of these as a proper part
    within = over.copy()                            # over[T] for some T within S (S itself too)
    for i in range(m):
        has = (masks & (1 << i)) != 0
        within[has] |= within[masks[has] ^ (1 << i)]
    proper = np.zeros(1 << m, bool)                 # over[T] for some T strictly within S
    for i in range(m):
        has = (masks & (1 << i)) != 0
        proper[has] |= within[masks[has] ^ (1 << i)]
    found = np.flatnonzero((rows == 3 * size) & (size > 0) & (size <= MAX_GROUP_LINKS) & ~proper)
    if not len(found):
        return None
    smallest = size[found].min()
    first = min(tuple(i for i in range(m) if x >> i & 1) for x in found[size[found] == smallest])
    return tuple(unknown[i] for i in first)


def _next_group(unknown, known, joints, used, size) -> Group | None:
    subset = group_links(unknown, known, joints, used)
    if subset is None:
        return None
    solver = solver_for(subset, _group_joints(subset, known, joints, used), known, size)
    if solver is None:
        raise StructureError(
            f"links {list(subset)} form a group with pairs "
            f"{[_describe(j) for j in _group_joints(subset, known, joints, used)]} "
            "but no registered solver handles it (kinds: RRR, RRP, RPR, PRP, RPP with the "
            "guide of each external prismatic pair on the known link)"
        )
    return solver


def _describe(j) -> str:
    if isinstance(j, PrismaticJoint):
        return f"{j.name}: P guide {j.a} / slider {j.b}"
    return f"{j.name}: R {j.a}-{j.b}"


def _why_not(unknown, known, joints, used) -> str:
    free = [k for k in unknown if not any(k in (j.a, j.b) for n, j in joints.items() if n not in used)]
    if free:
        return f"links {free} have no pairs"
    return "they form no statically determinate group (check the pairs of these links)"

