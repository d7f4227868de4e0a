"""PRP dyad: sliders L1 and L2 on guides of known links, pinned to each other at B.

Closed form (docs/methods.md#positions-the-five-dyads): both angles are fixed by the guides, so B is the intersection of
two lines; parallel guides cannot be assembled. One branch only.
"""

from __future__ import annotations

import numpy as np

from .base import cross, rotate
from .dyad import Dyad

__all__ = ["PRP"]


class PRP(Dyad):
    kind = "PRP"
    branches = (1,)
    slider_roles = {"ext1": "L1", "ext2": "L2"}

    def _position(self, poses, branch):
        l1, l2 = self.links
        b1_loc, _, _ = self.inner.local(l1)
        b2_loc, _, _ = self.inner.local(l2)
        lines, thetas = [], []
        for guide, b_loc in ((self.ext1, b1_loc), (self.ext2, b2_loc)):
            G, u = self.guide_line(poses, guide)
            theta = poses[guide.a][:, 2] + guide.beta
            lines.append((G + rotate(theta, np.subtract(b_loc, guide.p)), u))
            thetas.append(theta)
        (G1, u1), (G2, u2) = lines
        det = cross(u1, u2)
        ok = np.abs(det) > 1e-12
        t1 = cross(G2 - G1, u2) / np.where(ok, det, 1.0)
        B = G1 + t1[:, None] * u1
        return {
            l1: self.place_by_point_and_angle(B, b1_loc, thetas[0]),
            l2: self.place_by_point_and_angle(B, b2_loc, thetas[1]),
        }, ok

    def assembly_failure(self, poses):
        first, second = self.ext1.name, self.ext2.name
        return f"the guides of pairs '{first}' and '{second}' are parallel at every angle"
