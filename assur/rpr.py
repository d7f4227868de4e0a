"""RPR dyad: block L1 pinned to a known link at A slides along a guide of link L2, which is
pinned to a known link at C (the slotted link).

Closed form (docs/methods.md#positions-the-five-dyads): with ``d = |A - C|``, ``psi`` the direction of ``A - C`` and ``e``
the signed distance of the slide axis from C, ``theta_2 = psi - alpha0 - asin(e/d)`` (M = +1,
A ahead of C along the guide direction) or ``psi - alpha0 - pi + asin(e/d)`` (M = -1);
``d < |e|`` cannot be assembled.
"""

from __future__ import annotations

import numpy as np

from .base import angle_of, rotate
from .dyad import Dyad

__all__ = ["RPR"]


class RPR(Dyad):
    kind = "RPR"
    branches = (1, -1)
    slider_roles = {"inner": "L1"}

    def _position(self, poses, branch):
        l1, l2 = self.links
        slot = self.inner
        a_loc, _, _ = self.ext1.local(l1)
        c_loc, _, _ = self.ext2.local(l2)
        A = self.known_point(poses, self.ext1, l1)
        C = self.known_point(poses, self.ext2, l2)
        alpha0 = np.arctan2(slot.u[1], slot.u[0])
        normal = np.array([-slot.u[1], slot.u[0]])
        w = rotate(np.array([slot.beta]), np.subtract(slot.p, a_loc))[0]
        e = normal @ (np.subtract(slot.g, c_loc) - w)
        d = np.linalg.norm(A - C, axis=1)
        ok = d >= abs(e) - 1e-12 * self.size
        ok &= d > 1e-12 * self.size
        ratio = np.clip(e / np.where(ok, d, 1.0), -1.0, 1.0)
        psi = angle_of(A - C)
        if branch == 1:
            theta2 = psi - alpha0 - np.arcsin(ratio)
        else:
            theta2 = psi - alpha0 - np.pi + np.arcsin(ratio)
        theta2 = (theta2 + np.pi) % (2 * np.pi) - np.pi
        theta1 = theta2 + slot.beta
        return {
            l1: self.place_by_point_and_angle(A, a_loc, theta1),
            l2: self.place_by_point_and_angle(C, c_loc, theta2),
        }, ok

    def assembly_failure(self, poses):
        l1, l2 = self.links
        slot = self.inner
        normal = np.array([-slot.u[1], slot.u[0]])
        w = rotate(np.array([slot.beta]), np.subtract(slot.p, self.ext1.local(l1)[0]))[0]
        e = abs(normal @ (np.subtract(slot.g, self.ext2.local(l2)[0]) - w))
        d = np.linalg.norm(self.known_point(poses, self.ext1, l1) - self.known_point(poses, self.ext2, l2), axis=1)
        if np.max(d) < e:
            return (f"|{self.ext1.name}{self.ext2.name}| <= {np.max(d):.6g} m at every angle but the "
                    f"slot '{slot.name}' runs {e:.6g} m from {self.ext2.name}")
        return None
