"""PRP dyad: sliders L1 and L2 on guides of known links, pinned to each other at B.

Closed form (docs/methods.md#positions-the-five-dyads): both angles are fixed by the guides, so B is the intersection of
two lines; parallel guides cannot be assembled. One branch only.
"""

from __future__ import annotations

import numpy as np

from .dyad import Dyad
from .rows import xy

__all__ = ["PRP"]


class PRP(Dyad):
    kind = "PRP"
    branches = (1,)
    slider_roles = {"ext1": "L1", "ext2": "L2"}

    def _place(self, frames, branch):
        l1, l2 = self.links
        lines, angles = [], []
        for guide, link in ((self.ext1, l1), (self.ext2, l2)):
            G, u = self.guide_line(frames, guide)
            c, s, theta = self.turned(*frames[guide.a][2:], guide.beta)
            (bx, by), (px, py) = xy(self.inner.local(link)[0]), xy(guide.p)
            lines.append(((G[0] + c * (bx - px) - s * (by - py), G[1] + s * (bx - px) + c * (by - py)), u))
            angles.append((c, s, theta))
        (G1, u1), (G2, u2) = lines
        det = u1[0] * u2[1] - u1[1] * u2[0]
        ok = np.abs(det) > 1e-12
        t1 = ((G2[0] - G1[0]) * u2[1] - (G2[1] - G1[1]) * u2[0]) / np.where(ok, det, 1.0)
        B = G1[0] + t1 * u1[0], G1[1] + t1 * u1[1]
        return {
            l1: self.place_by_point_and_angle(B, self.inner.local(l1)[0], *angles[0]),
            l2: self.place_by_point_and_angle(B, self.inner.local(l2)[0], *angles[1]),
        }, ok

    def assembly_failure(self, poses):
        first, second = self.ext1.name, self.ext2.name
        return f"the guides of pairs '{first}' and '{second}' are parallel at every angle"
