"""Shared arrangement of class-II groups (dyads): two links, three pairs, ext-int-ext.

A dyad kind subclasses :class:`Dyad`, sets ``kind`` to its pattern (e.g. ``"RRP"``) and the roles of its
prismatic pairs, and implements ``_position``. Binding tries both orders of the two links so
that ``PRR`` is recognised as ``RRP`` with the links swapped.
"""

from __future__ import annotations

from typing import ClassVar

import numpy as np

from .base import Group, Joint, PrismaticJoint, angle_of, global_point, rotate

__all__ = ["Dyad"]


class Dyad(Group):
    """A class-II group: links ``(L1, L2)`` with pairs ``ext1`` (L1-known), ``inner`` (L1-L2)
    and ``ext2`` (L2-known).

    ``slider_roles`` maps each P position of the pattern (``"ext1"``, ``"inner"``, ``"ext2"``) to
    the link that must be the *slider* of that prismatic pair (``"L1"`` or ``"L2"``); the other
    side is the guide. A group whose roles differ is not bound by that kind.
    """

    slider_roles: ClassVar[dict[str, str]] = {}

    def __init__(self, links, joints, size, ext1: Joint, inner: Joint, ext2: Joint):
        super().__init__(links, joints, size)
        self.ext1, self.inner, self.ext2 = ext1, inner, ext2

    @classmethod
    def _bind(cls, links, joints, known, size):
        if len(links) != 2 or len(joints) != 3:
            return None
        for l1, l2 in (links, links[::-1]):
            arranged = _arrange(l1, l2, joints, known)
            if arranged is None:
                continue
            ext1, inner, ext2 = arranged
            if ext1.kind + inner.kind + ext2.kind != cls.kind:
                continue
            roles = {"ext1": ext1, "inner": inner, "ext2": ext2}
            names = {"L1": l1, "L2": l2}
            if all(roles[slot].b == names[who] for slot, who in cls.slider_roles.items()):
                return cls((l1, l2), (ext1, inner, ext2), size, ext1, inner, ext2)
        return None

    # -- helpers for closed forms ----------------------------------------------------------------
    @staticmethod
    def known_point(poses, joint: Joint, link: str) -> np.ndarray:
        """Global position of ``joint``'s point as carried by the known link (not ``link``)."""
        _, other, p_other = joint.local(link)
        return global_point(poses[other], p_other)

    @staticmethod
    def guide_line(poses, joint: PrismaticJoint):
        """Global point and unit direction ``(N, 2)`` of a prismatic joint's guide line."""
        theta = poses[joint.a][:, 2]
        return global_point(poses[joint.a], joint.g), rotate(theta, joint.u)

    @staticmethod
    def place_by_two_points(p_global_1, p_global_2, p_local_1, p_local_2):
        """Pose ``(N, 3)`` of a link whose local points 1 and 2 are at the global positions."""
        theta = angle_of(p_global_2 - p_global_1) - np.arctan2(
            p_local_2[1] - p_local_1[1], p_local_2[0] - p_local_1[0]
        )
        origin = p_global_1 - rotate(theta, p_local_1)
        return np.column_stack([origin, theta])

    @staticmethod
    def place_by_point_and_angle(p_global, p_local, theta) -> np.ndarray:
        """Pose ``(N, 3)`` of a link with angle ``theta`` whose local point is at ``p_global``."""
        return np.column_stack([p_global - rotate(theta, p_local), theta])


def _arrange(l1: str, l2: str, joints, known):
    """(ext1, inner, ext2) when the joints form a dyad L1-L2 on known links, else None."""
    ext1 = [j for j in joints if {j.a, j.b} - {l1} <= known and l1 in (j.a, j.b) and l2 not in (j.a, j.b)]
    ext2 = [j for j in joints if {j.a, j.b} - {l2} <= known and l2 in (j.a, j.b) and l1 not in (j.a, j.b)]
    inner = [j for j in joints if {j.a, j.b} == {l1, l2}]
    if len(ext1) == len(ext2) == len(inner) == 1:
        return ext1[0], inner[0], ext2[0]
    return None
