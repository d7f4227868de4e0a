"""RRR dyad: two binary links pinned to known links at A and C and to each other at B.

Closed form (docs/methods.md#positions-the-five-dyads): ``d = |C - A|``, ``a = (l2^2 - l3^2 + d^2) / (2 d)``,
``h^2 = l2^2 - a^2`` (< 0: cannot be assembled), ``B = A + a e + M h E e``.
Branch ``M = +1`` puts B to the left of the directed line A -> C (A on link L1, C on link L2).
"""

from __future__ import annotations

import numpy as np

from .dyad import Dyad
from .rows import xy

__all__ = ["RRR"]


class RRR(Dyad):
    kind = "RRR"
    branches = (1, -1)
    slider_roles: dict[str, str] = {}

    def _lengths(self):
        """``(|AB|, |CB|)`` in L1 and L2 (floats, or ``(N,)`` for a batch of variants)."""
        l1, l2 = self.links
        (ax, ay), (bx, by) = xy(self.ext1.local(l1)[0]), xy(self.inner.local(l1)[0])
        (cx, cy), (dx, dy) = xy(self.ext2.local(l2)[0]), xy(self.inner.local(l2)[0])
        return np.hypot(bx - ax, by - ay), np.hypot(dx - cx, dy - cy)

    def _place(self, frames, branch):
        l1, l2 = self.links
        len1, len2 = self._lengths()
        A = self.known_point(frames, self.ext1, l1)
        C = self.known_point(frames, self.ext2, l2)
        dx, dy = C[0] - A[0], C[1] - A[1]
        d = np.hypot(dx, dy)
        ok = d > 1e-12 * self.size
        d_safe = np.where(ok, d, 1.0)
        ex, ey = dx / d_safe, dy / d_safe
        a = (len1 * len1 - len2 * len2 + d_safe * d_safe) / (2 * d_safe)
        h2 = len1 * len1 - a * a
        h2 = np.where((h2 < 0) & (h2 > -(1e-12 * self.size) ** 2), 0.0, h2)
        ok &= h2 >= 0
        h = branch * np.sqrt(np.where(ok, h2, 0.0))
        B = A[0] + a * ex - h * ey, A[1] + a * ey + h * ex
        return {
            l1: self.place_by_two_points(A, B, self.ext1.local(l1)[0], self.inner.local(l1)[0], len1),
            l2: self.place_by_two_points(C, B, self.ext2.local(l2)[0], self.inner.local(l2)[0], len2),
        }, ok

    def assembly_failure(self, poses):
        l1, l2 = self.links
        a, c, b = self.ext1.name, self.ext2.name, self.inner.name
        frames = self._frames(poses)
        A, C = self.known_point(frames, self.ext1, l1), self.known_point(frames, self.ext2, l2)
        d = np.hypot(C[0] - A[0], C[1] - A[1])
        len1, len2 = self._lengths()
        if np.min(d) > np.max(len1 + len2):
            return (f"|{a}{c}| >= {np.min(d):.6g} m at every angle but {a}{b} + {c}{b} = "
                    f"{np.max(len1 + len2):.6g} m")
        if np.max(d) < np.min(np.abs(len1 - len2)):
            return (f"|{a}{c}| <= {np.max(d):.6g} m at every angle but |{a}{b} - {c}{b}| = "
                    f"{np.min(np.abs(len1 - len2)):.6g} m")
        return None

    def assembly_margin(self, poses):
        """``(N,)`` m: by how much the triangle A, B, C closes, ``min(|AB| + |CB| - |AC|, |AC| - ||AB| - |CB||)``
        (negative where the dyad cannot be assembled)."""
        l1, l2 = self.links
        frames = self._frames(poses)
        A, C = self.known_point(frames, self.ext1, l1), self.known_point(frames, self.ext2, l2)
        d = np.hypot(C[0] - A[0], C[1] - A[1])
        len1, len2 = self._lengths()
        return np.minimum(len1 + len2 - d, d - np.abs(len1 - len2))
