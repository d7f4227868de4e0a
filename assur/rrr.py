"""RRR dyad: two binary links pinned to known links at A and C and to each other at B.

Closed form (docs/methods.md#positions-the-five-dyads): ``d = |C - A|``, ``a = (l2^2 - l3^2 + d^2) / (2 d)``,
``h^2 = l2^2 - a^2`` (< 0: cannot be assembled), ``B = A + a e + M h E e``.
Branch ``M = +1`` puts B to the left of the directed line A -> C (A on link L1, C on link L2).
"""

from __future__ import annotations

import numpy as np

from .base import perp
from .dyad import Dyad

__all__ = ["RRR"]


class RRR(Dyad):
    kind = "RRR"
    branches = (1, -1)
    slider_roles: dict[str, str] = {}

    def _position(self, poses, branch):
        l1, l2 = self.links
        a_loc, _, _ = self.ext1.local(l1)
        c_loc, _, _ = self.ext2.local(l2)
        b1_loc, _, _ = self.inner.local(l1)
        b2_loc, _, _ = self.inner.local(l2)
        A = self.known_point(poses, self.ext1, l1)
        C = self.known_point(poses, self.ext2, l2)
        len1 = np.hypot(*np.subtract(b1_loc, a_loc))
        len2 = np.hypot(*np.subtract(b2_loc, c_loc))
        d = np.linalg.norm(C - A, axis=1)
        ok = d > 1e-12 * self.size
        d_safe = np.where(ok, d, 1.0)
        e = (C - A) / d_safe[:, None]
        a = (len1**2 - len2**2 + d_safe**2) / (2 * d_safe)
        h2 = len1**2 - a**2
        h2 = np.where((h2 < 0) & (h2 > -(1e-12 * self.size) ** 2), 0.0, h2)
        ok &= h2 >= 0
        h = np.sqrt(np.where(ok, h2, 0.0))
        B = A + a[:, None] * e + branch * h[:, None] * perp(e)
        return {
            l1: self.place_by_two_points(A, B, a_loc, b1_loc),
            l2: self.place_by_two_points(C, B, c_loc, b2_loc),
        }, ok

    def assembly_failure(self, poses):
        l1, l2 = self.links
        a, c, b = self.ext1.name, self.ext2.name, self.inner.name
        d = np.linalg.norm(self.known_point(poses, self.ext2, l2) - self.known_point(poses, self.ext1, l1), axis=1)
        len1 = np.hypot(*np.subtract(self.inner.local(l1)[0], self.ext1.local(l1)[0]))
        len2 = np.hypot(*np.subtract(self.inner.local(l2)[0], self.ext2.local(l2)[0]))
        if np.min(d) > len1 + len2:
            return (f"|{a}{c}| >= {np.min(d):.6g} m at every angle but {a}{b} + {c}{b} = "
                    f"{len1 + len2:.6g} m")
        if np.max(d) < abs(len1 - len2):
            return (f"|{a}{c}| <= {np.max(d):.6g} m at every angle but |{a}{b} - {c}{b}| = "
                    f"{abs(len1 - len2):.6g} m")
        return None
