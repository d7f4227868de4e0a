"""RPP dyad: link L1 pinned to a known link at A slides in a guide of link L2; L2 slides on a
guide of a known link (e.g. the Scotch yoke).

Closed form (docs/methods.md#positions-the-five-dyads): both angles follow from the guides, and L2's origin from one
2x2 linear system (the two guide lines' normal equations). Parallel guides cannot be assembled.
"""

from __future__ import annotations

import numpy as np

from .base import cross, dot, perp, rotate
from .dyad import Dyad

__all__ = ["RPP"]


class RPP(Dyad):
    kind = "RPP"
    branches = (1,)
    slider_roles = {"inner": "L1", "ext2": "L2"}

    def _position(self, poses, branch):
        l1, l2 = self.links
        slot, guide = self.inner, self.ext2
        a_loc, _, _ = self.ext1.local(l1)
        A = self.known_point(poses, self.ext1, l1)
        G, u = self.guide_line(poses, guide)
        theta2 = poses[guide.a][:, 2] + guide.beta
        theta1 = theta2 + slot.beta
        S1 = A + rotate(theta1, np.subtract(slot.p, a_loc))
        n_slot = perp(rotate(theta2, slot.u))
        n_guide = perp(u)
        rhs1 = dot(n_slot, S1 - rotate(theta2, slot.g))
        rhs2 = dot(n_guide, G - rotate(theta2, guide.p))
        det = cross(n_slot, n_guide)
        ok = np.abs(det) > 1e-12
        det = np.where(ok, det, 1.0)
        origin = np.column_stack([
            (rhs1 * n_guide[:, 1] - rhs2 * n_slot[:, 1]) / det,
            (n_slot[:, 0] * rhs2 - n_guide[:, 0] * rhs1) / det,
        ])
        return {
            l1: self.place_by_point_and_angle(A, a_loc, theta1),
            l2: np.column_stack([origin, theta2]),
        }, ok

    def assembly_failure(self, poses):
        first, second = self.inner.name, self.ext2.name
        return f"the guides of pairs '{first}' and '{second}' are parallel at every angle"
