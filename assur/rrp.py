"""RRP dyad: link L1 pinned to a known link at A and to slider L2 at B; L2 slides on a guide of
a known link.

Closed form (docs/methods.md#positions-the-five-dyads): the slider's angle is fixed by the guide, so B runs on a line
``G_B + s u``; with ``h = n . (A - G_B)``: ``s = u . (A - G_B) + M sqrt(l^2 - h^2)``.
Branch ``M = +1`` puts B ahead of A's foot along the guide direction ``u``.
"""

from __future__ import annotations

import numpy as np

from .base import dot, perp, rotate
from .dyad import Dyad

__all__ = ["RRP"]


class RRP(Dyad):
    kind = "RRP"
    branches = (1, -1)
    slider_roles = {"ext2": "L2"}

    def _position(self, poses, branch):
        l1, l2 = self.links
        guide = self.ext2
        a_loc, _, _ = self.ext1.local(l1)
        b1_loc, _, _ = self.inner.local(l1)
        b2_loc, _, _ = self.inner.local(l2)
        A = self.known_point(poses, self.ext1, l1)
        G, u = self.guide_line(poses, guide)
        n = perp(u)
        theta2 = poses[guide.a][:, 2] + guide.beta
        G_B = G + rotate(theta2, np.subtract(b2_loc, guide.p))
        length = np.hypot(*np.subtract(b1_loc, a_loc))
        h = dot(n, A - G_B)
        disc = length**2 - h**2
        disc = np.where((disc < 0) & (disc > -(1e-12 * self.size) ** 2), 0.0, disc)
        ok = disc >= 0
        s = dot(u, A - G_B) + branch * np.sqrt(np.where(ok, disc, 0.0))
        B = G_B + s[:, None] * u
        return {
            l1: self.place_by_two_points(A, B, a_loc, b1_loc),
            l2: self.place_by_point_and_angle(B, b2_loc, theta2),
        }, ok

    def assembly_failure(self, poses):
        l1, l2 = self.links
        guide = self.ext2
        a_loc, b1_loc = self.ext1.local(l1)[0], self.inner.local(l1)[0]
        A = self.known_point(poses, self.ext1, l1)
        G, u = self.guide_line(poses, guide)
        theta2 = poses[guide.a][:, 2] + guide.beta
        G_B = G + rotate(theta2, np.subtract(self.inner.local(l2)[0], guide.p))
        h = np.abs(dot(perp(u), A - G_B))
        length = np.hypot(*np.subtract(b1_loc, a_loc))
        if np.min(h) > length:
            return (f"{self.ext1.name} stays at least {np.min(h):.6g} m from the line of "
                    f"{self.inner.name} on guide '{guide.name}', but the link {self.ext1.name}"
                    f"{self.inner.name} is {length:.6g} m long")
        return None
