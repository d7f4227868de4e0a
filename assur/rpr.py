"""RPR dyad: block L1 pinned to a known link at A slides along a guide of link L2, which is
pinned to a known link at C (the slotted link).

Closed form (docs/methods.md#positions-the-five-dyads): with ``d = |A - C|``, ``psi`` the direction
of ``A - C`` and ``e`` the signed distance of the slide axis from C, ``theta_2 = psi - alpha0 - asin(e/d)`` (M = +1,
A ahead of C along the guide direction) or ``psi - alpha0 - pi + asin(e/d)`` (M = -1);
``d < |e|`` cannot be assembled.
"""

from __future__ import annotations

import numpy as np

from .dyad import Dyad
from .rows import xy

__all__ = ["RPR"]


class RPR(Dyad):
    kind = "RPR"
    branches = (1, -1)
    slider_roles = {"inner": "L1"}

    def _offset(self):
        """Signed distance ``e`` of the slide axis from C (float or ``(N,)``)."""
        l1, l2 = self.links
        slot = self.inner
        (ux, uy), (px, py), (gx, gy) = xy(slot.u), xy(slot.p), xy(slot.g)
        (ax, ay), (cx, cy) = xy(self.ext1.local(l1)[0]), xy(self.ext2.local(l2)[0])
        cb, sb = np.cos(slot.beta), np.sin(slot.beta)
        wx, wy = cb * (px - ax) - sb * (py - ay), sb * (px - ax) + cb * (py - ay)
        return -uy * (gx - cx - wx) + ux * (gy - cy - wy)

    def _place(self, frames, branch):
        l1, l2 = self.links
        slot = self.inner
        A = self.known_point(frames, self.ext1, l1)
        C = self.known_point(frames, self.ext2, l2)
        ux, uy = xy(slot.u)
        e = self._offset()
        dx, dy = A[0] - C[0], A[1] - C[1]
        d = np.hypot(dx, dy)
        ok = (d >= np.abs(e) - 1e-12 * self.size) & (d > 1e-12 * self.size)
        ratio = np.clip(e / np.where(ok, d, 1.0), -1.0, 1.0)
        theta2 = np.arctan2(dy, dx) - np.arctan2(uy, ux) - np.arcsin(ratio)
        if branch != 1:
            theta2 = theta2 + 2 * np.arcsin(ratio) - np.pi
        theta2 = (theta2 + np.pi) % (2 * np.pi) - np.pi
        c2, s2 = np.cos(theta2), np.sin(theta2)
        c1, s1, theta1 = self.turned(c2, s2, theta2, slot.beta)
        return {
            l1: self.place_by_point_and_angle(A, self.ext1.local(l1)[0], c1, s1, theta1),
            l2: self.place_by_point_and_angle(C, self.ext2.local(l2)[0], c2, s2, theta2),
        }, ok

    def assembly_failure(self, poses):
        l1, l2 = self.links
        frames = self._frames(poses)
        e = np.abs(self._offset())
        A, C = self.known_point(frames, self.ext1, l1), self.known_point(frames, self.ext2, l2)
        d = np.hypot(A[0] - C[0], A[1] - C[1])
        if np.max(d) < np.min(e):
            return (f"|{self.ext1.name}{self.ext2.name}| <= {np.max(d):.6g} m at every angle but the "
                    f"slot '{self.inner.name}' runs {np.min(e):.6g} m from {self.ext2.name}")
        return None

    def assembly_margin(self, poses):
        """``(N,)`` m: the distance AC less the slot's offset from C (negative where the dyad
        cannot be assembled)."""
        l1, l2 = self.links
        frames = self._frames(poses)
        A, C = self.known_point(frames, self.ext1, l1), self.known_point(frames, self.ext2, l2)
        return np.hypot(A[0] - C[0], A[1] - C[1]) - np.abs(self._offset())
