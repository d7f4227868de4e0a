"""RPP dyad: link L1 pinned to a known link at A slides in a guide of link L2; L2 slides on a
guide of a known link (e.g. the Scotch yoke).

Closed form (docs/methods.md#positions-the-five-dyads): both angles follow from the guides, and L2's origin from one
2x2 linear system (the two guide lines' normal equations). Parallel guides cannot be assembled.
"""

from __future__ import annotations

import numpy as np

from .dyad import Dyad
from .rows import xy

__all__ = ["RPP"]


class RPP(Dyad):
    kind = "RPP"
    branches = (1,)
    slider_roles = {"inner": "L1", "ext2": "L2"}

    def _place(self, frames, branch):
        l1, l2 = self.links
        slot, guide = self.inner, self.ext2
        A = self.known_point(frames, self.ext1, l1)
        G, u = self.guide_line(frames, guide)
        c2, s2, theta2 = self.turned(*frames[guide.a][2:], guide.beta)
        c1, s1, theta1 = self.turned(c2, s2, theta2, slot.beta)
        (ax, ay), (px, py) = xy(self.ext1.local(l1)[0]), xy(slot.p)
        S1 = A[0] + c1 * (px - ax) - s1 * (py - ay), A[1] + s1 * (px - ax) + c1 * (py - ay)
        (sux, suy), (gx, gy), (qx, qy) = xy(slot.u), xy(slot.g), xy(guide.p)
        slot_x, slot_y = c2 * sux - s2 * suy, s2 * sux + c2 * suy
        n_slot = -slot_y, slot_x
        n_guide = -u[1], u[0]
        rhs1 = n_slot[0] * (S1[0] - (c2 * gx - s2 * gy)) + n_slot[1] * (S1[1] - (s2 * gx + c2 * gy))
        rhs2 = n_guide[0] * (G[0] - (c2 * qx - s2 * qy)) + n_guide[1] * (G[1] - (s2 * qx + c2 * qy))
        det = n_slot[0] * n_guide[1] - n_slot[1] * n_guide[0]
        ok = np.abs(det) > 1e-12
        det = np.where(ok, det, 1.0)
        origin = ((rhs1 * n_guide[1] - rhs2 * n_slot[1]) / det, (n_slot[0] * rhs2 - n_guide[0] * rhs1) / det)
        return {
            l1: self.place_by_point_and_angle(A, self.ext1.local(l1)[0], c1, s1, theta1),
            l2: (origin[0], origin[1], c2, s2, theta2),
        }, ok

    def assembly_failure(self, poses):
        first, second = self.inner.name, self.ext2.name
        return f"the guides of pairs '{first}' and '{second}' are parallel at every angle"
