"""A pair's two constraint rows evaluated elementwise, for the fast solve of dyads (docs/numerics.md#fast-path).

The generic path of :class:`assur.base.Group` builds each group's constraint Jacobian as an
``(N, m, m)`` array and hands it to LAPACK. A dyad's Jacobian is sparse and tiny: each pair's two
rows touch at most two links, and the action of those rows on a link's generalized velocity
``q = (t_x, t_y, w)`` needs a handful of products. This module evaluates, for one pair at N
positions, exactly the quantities of :mod:`assur.base` -- residual, Jacobian rows, quadratic
terms -- as separate ``x`` / ``y`` arrays, so that :meth:`assur.dyad.Dyad.solve` can eliminate
the dyad's six unknowns in closed form.

The transposed rows serve the kinetostatics the same way (:meth:`assur.dyad.Dyad.reactions`):
``constraint_load`` is the load a pair's multipliers put on a link, ``multipliers`` its inverse.

Conventions: a *frame* of a link is ``(x, y, c, s, theta)``, the origin, the cosine and sine of
its angle and the angle, each ``(N,)``; its analogs are ``(vx, vy, w)`` (first) and ``(ax, ay, al)`` (second).
Local coordinates are ``(2,)`` or ``(N, 2)`` (one geometry per position, for batches of design
variants).
"""

from __future__ import annotations

import numpy as np

__all__ = ["xy", "frame", "arm", "RevoluteRows", "PrismaticRows", "rows_of"]


def xy(p):
    """The two coordinates of local point(s) ``(2,)`` or ``(N, 2)``: floats or ``(N,)`` arrays
    (a tuple of two columns passes as it is)."""
    if type(p) is tuple and len(p) == 2 and not isinstance(p[0], (int, float)):
        return p
    p = np.asarray(p, dtype=float)
    return (float(p[0]), float(p[1])) if p.ndim == 1 else (p[:, 0], p[:, 1])


def frame(pose: np.ndarray):
    """The frame ``(x, y, c, s, theta)`` of a link from its pose ``(N, 3)``."""
    theta = pose[:, 2]
    return pose[:, 0], pose[:, 1], np.cos(theta), np.sin(theta), theta


def arm(frame, local):
    """``Rot(theta) p`` for a link frame and local coordinates (see :func:`xy`): ``(x, y)``."""
    c, s = frame[2], frame[3]
    px, py = local
    return c * px - s * py, s * px + c * py


class RevoluteRows:
    """Rows of a revolute pair: ``P_a - P_b = 0`` with ``P_L = o_L + rho_L``.

    The rows' action on a velocity ``q = (t, w)`` of link L is ``sign_L (t + w E rho_L)``, with
    ``sign`` +1 for link a and -1 for link b.
    """

    kind = "R"

    def __init__(self, joint, frames):
        self.joint = joint
        self.links = (joint.a, joint.b)
        self.arms = {joint.a: arm(frames[joint.a], xy(joint.pa)), joint.b: arm(frames[joint.b], xy(joint.pb))}
        self.sign = {joint.a: 1.0, joint.b: -1.0}
        fa = frames[joint.a]
        ra = self.arms[joint.a]
        self.contact = (fa[0] + ra[0], fa[1] + ra[1])

    def residual(self, frames, size):
        """Largest absolute residual ``(N,)`` of the two rows, m."""
        fb, rb = frames[self.joint.b], self.arms[self.joint.b]
        return np.maximum(np.abs(self.contact[0] - fb[0] - rb[0]), np.abs(self.contact[1] - fb[1] - rb[1]))

    def act(self, link, q):
        """The rows' action ``(r0, r1)`` on the velocity ``q = (tx, ty, w)`` of ``link``."""
        rx, ry = self.arms[link]
        tx, ty, w = q
        s = self.sign[link]
        return s * (tx - w * ry), s * (ty + w * rx)

    def particular(self, link, r):
        """A velocity of ``link`` that the rows map to ``r``."""
        s = self.sign[link]
        return s * r[0], s * r[1], 0.0

    def null(self, link):
        """The null vector of the rows in ``link``'s columns: their cross product."""
        rx, ry = self.arms[link]
        return ry, -rx, 1.0

    def constraint_load(self, link, lam):
        """The rows' transpose applied to the multipliers ``lam = (l0, l1)``: the generalized load
        ``(Fx, Fy, M)`` (moment about the link's origin) the pair puts on ``link``."""
        rx, ry = self.arms[link]
        s = self.sign[link]
        return s * lam[0], s * lam[1], s * (rx * lam[1] - ry * lam[0])

    def multipliers(self, link, load):
        """The multipliers whose :meth:`constraint_load` on ``link`` is ``load`` (a load the rows
        can carry: its moment is the force's moment about the pin)."""
        s = self.sign[link]
        return s * load[0], s * load[1]

    def quadratic(self, first):
        """``gamma`` of the second-analog rows: ``w_a^2 rho_a - w_b^2 rho_b``."""
        (ax, ay), (bx, by) = self.arms[self.joint.a], self.arms[self.joint.b]
        wa, wb = first[self.joint.a][2], first[self.joint.b][2]
        wa2, wb2 = wa * wa, wb * wb
        return wa2 * ax - wb2 * bx, wa2 * ay - wb2 * by

    def norms_squared(self, link, centroid, origin, scale):
        """Squared norms of the two rows of the scaled Jacobian, the part of ``link``'s columns."""
        dx, dy = (self.contact[0] - centroid[0]) / scale, (self.contact[1] - centroid[1]) / scale
        return 1.0 + dy * dy, 1.0 + dx * dx


class PrismaticRows:
    """Rows of a prismatic pair: ``n . d = 0`` and ``theta_b - theta_a - beta = 0`` (see
    :class:`assur.base.PrismaticJoint`; a is the guide, b the slider)."""

    kind = "P"

    def __init__(self, joint, frames):
        self.joint = joint
        self.links = (joint.a, joint.b)
        fa, fb = frames[joint.a], frames[joint.b]
        self.u = arm(fa, xy(joint.u))
        self.n = (-self.u[1], self.u[0])
        self.ga = arm(fa, xy(joint.g))
        self.pb = arm(fb, xy(joint.p))
        self.contact = (fb[0] + self.pb[0], fb[1] + self.pb[1])
        self.d = (self.contact[0] - fa[0] - self.ga[0], self.contact[1] - fa[1] - self.ga[1])
        nx, ny = self.n
        ud = self.u[0] * self.d[0] + self.u[1] * self.d[1]
        #: rotation entries of row 0: link a (guide) and link b (slider)
        self.w0 = {joint.a: -(ud + self.ga[0] * ny - self.ga[1] * nx), joint.b: self.pb[0] * ny - self.pb[1] * nx}
        self.sign = {joint.a: -1.0, joint.b: 1.0}

    def residual(self, frames, size):
        """Largest absolute residual ``(N,)``: the normal offset, m, and the angle times ``size``."""
        nd = self.n[0] * self.d[0] + self.n[1] * self.d[1]
        angle = frames[self.joint.b][4] - frames[self.joint.a][4] - self.joint.beta
        angle = (angle + np.pi) % (2 * np.pi) - np.pi
        return np.maximum(np.abs(nd), np.abs(angle) * size)

    def act(self, link, q):
        tx, ty, w = q
        s = self.sign[link]
        return s * (self.n[0] * tx + self.n[1] * ty) + self.w0[link] * w, s * w

    def particular(self, link, r):
        s = self.sign[link]
        w = s * r[1]
        along = s * (r[0] - self.w0[link] * w)
        return along * self.n[0], along * self.n[1], w

    def null(self, link):
        return self.u[0], self.u[1], 0.0

    def constraint_load(self, link, lam):
        s = self.sign[link]
        return s * self.n[0] * lam[0], s * self.n[1] * lam[0], self.w0[link] * lam[0] + s * lam[1]

    def multipliers(self, link, load):
        s = self.sign[link]
        normal = s * (self.n[0] * load[0] + self.n[1] * load[1])
        return normal, s * (load[2] - self.w0[link] * normal)

    def quadratic(self, first):
        """``gamma``: ``(n.d) w_a^2 + 2 w_a (u.d') + n.(p_b w_b^2 - g_a w_a^2)`` and 0."""
        a, b = self.joint.a, self.joint.b
        vax, vay, wa = first[a]
        vbx, vby, wb = first[b]
        (px, py), (gx, gy) = self.pb, self.ga
        d1x = vbx - py * wb - vax + gy * wa
        d1y = vby + px * wb - vay - gx * wa
        nx, ny = self.n
        wa2, wb2 = wa * wa, wb * wb
        nd = nx * self.d[0] + ny * self.d[1]
        ud1 = self.u[0] * d1x + self.u[1] * d1y
        g0 = nd * wa2 + 2 * wa * ud1 + nx * (px * wb2 - gx * wa2) + ny * (py * wb2 - gy * wa2)
        return g0, 0.0 * g0

    def norms_squared(self, link, centroid, origin, scale):
        s = self.sign[link]
        rx, ry = centroid[0] - origin[0], centroid[1] - origin[1]
        w = (self.w0[link] + s * (self.n[0] * ry - self.n[1] * rx)) / scale
        return 1.0 + w * w, 1.0


def rows_of(joint, frames):
    """:class:`RevoluteRows` or :class:`PrismaticRows` of ``joint`` at the link ``frames``."""
    return (RevoluteRows if joint.kind == "R" else PrismaticRows)(joint, frames)
