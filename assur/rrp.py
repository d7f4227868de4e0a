"""RRP dyad: link L1 pinned to a known link at A and to slider L2 at B; L2 slides on a guide of
a known link.

Closed form (docs/methods.md#positions-the-five-dyads): the slider's angle is fixed by the guide, so B runs on a line
``G_B + s u``; with ``h = n . (A - G_B)``: ``s = u . (A - G_B) + M sqrt(l^2 - h^2)``.
Branch ``M = +1`` puts B ahead of A's foot along the guide direction ``u``.
"""

from __future__ import annotations

import numpy as np

from .dyad import Dyad
from .rows import xy

__all__ = ["RRP"]


class RRP(Dyad):
    kind = "RRP"
    branches = (1, -1)
    slider_roles = {"ext2": "L2"}

    def _line_of_b(self, frames):
        """A, the line ``G_B + s u`` that B runs on (``G_B``, ``u``), the slider's angle
        ``(c, s, theta)`` and the length AB."""
        l1, l2 = self.links
        guide = self.ext2
        A = self.known_point(frames, self.ext1, l1)
        G, u = self.guide_line(frames, guide)
        c2, s2, theta2 = self.turned(*frames[guide.a][2:], guide.beta)
        (bx, by), (px, py) = xy(self.inner.local(l2)[0]), xy(guide.p)
        G_B = G[0] + c2 * (bx - px) - s2 * (by - py), G[1] + s2 * (bx - px) + c2 * (by - py)
        (ax, ay), (b1x, b1y) = xy(self.ext1.local(l1)[0]), xy(self.inner.local(l1)[0])
        return A, G_B, u, (c2, s2, theta2), np.hypot(b1x - ax, b1y - ay)

    def _place(self, frames, branch):
        l1, l2 = self.links
        A, G_B, u, angle, length = self._line_of_b(frames)
        wx, wy = A[0] - G_B[0], A[1] - G_B[1]
        h = u[0] * wy - u[1] * wx
        disc = length * length - h * h
        disc = np.where((disc < 0) & (disc > -(1e-12 * self.size) ** 2), 0.0, disc)
        ok = disc >= 0
        s = u[0] * wx + u[1] * wy + branch * np.sqrt(np.where(ok, disc, 0.0))
        B = G_B[0] + s * u[0], G_B[1] + s * u[1]
        return {
            l1: self.place_by_two_points(A, B, self.ext1.local(l1)[0], self.inner.local(l1)[0], length),
            l2: self.place_by_point_and_angle(B, self.inner.local(l2)[0], *angle),
        }, ok

    def assembly_failure(self, poses):
        A, G_B, u, _, length = self._line_of_b(self._frames(poses))
        h = np.abs(u[0] * (A[1] - G_B[1]) - u[1] * (A[0] - G_B[0]))
        if np.min(h) > np.max(length):
            return (f"{self.ext1.name} stays at least {np.min(h):.6g} m from the line of "
                    f"{self.inner.name} on guide '{self.ext2.name}', but the link {self.ext1.name}"
                    f"{self.inner.name} is {np.max(length):.6g} m long")
        return None

    def assembly_margin(self, poses):
        """``(N,)`` m: the length AB less the distance of A from the line B runs on (negative
        where the dyad cannot be assembled)."""
        A, G_B, u, _, length = self._line_of_b(self._frames(poses))
        return length - np.abs(u[0] * (A[1] - G_B[1]) - u[1] * (A[0] - G_B[0]))
