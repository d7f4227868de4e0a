"""Shared arrangement of class-II groups (dyads): two links, three pairs, ext-int-ext.

A dyad kind subclasses :class:`Dyad`, sets ``kind`` to its pattern (e.g. ``"RRP"``) and the roles of its
prismatic pairs, and implements ``_position``. Binding tries both orders of the two links so
that ``PRR`` is recognised as ``RRP`` with the links swapped.
"""

from __future__ import annotations

from abc import abstractmethod
from typing import ClassVar

import numpy as np

from .base import (
    ANALOG_TOL,
    CANNOT_ASSEMBLE,
    CLOSURE_TOL,
    COINCIDENT,
    OK,
    SINGULAR,
    Group,
    GroupSolution,
    Joint,
    PrismaticJoint,
    error_bound,
    flag_second_analogs,
)
from .rows import arm, frame, rows_of, xy

__all__ = ["Dyad"]


class Dyad(Group):
    """A class-II group: links ``(L1, L2)`` with pairs ``ext1`` (L1-known), ``inner`` (L1-L2)
    and ``ext2`` (L2-known).

    ``slider_roles`` maps each P position of the pattern (``"ext1"``, ``"inner"``, ``"ext2"``) to
    the link that must be the *slider* of that prismatic pair (``"L1"`` or ``"L2"``); the other
    side is the guide. A group whose roles differ is not bound by that kind.
    """

    slider_roles: ClassVar[dict[str, str]] = {}

    def __init__(self, links, joints, size, ext1: Joint, inner: Joint, ext2: Joint):
        super().__init__(links, joints, size)
        self.ext1, self.inner, self.ext2 = ext1, inner, ext2

    @classmethod
    def _bind(cls, links, joints, known, size):
        if len(links) != 2 or len(joints) != 3:
            return None
        for l1, l2 in (links, links[::-1]):
            arranged = _arrange(l1, l2, joints, known)
            if arranged is None:
                continue
            ext1, inner, ext2 = arranged
            if ext1.kind + inner.kind + ext2.kind != cls.kind:
                continue
            roles = {"ext1": ext1, "inner": inner, "ext2": ext2}
            names = {"L1": l1, "L2": l2}
            if all(roles[slot].b == names[who] for slot, who in cls.slider_roles.items()):
                return cls((l1, l2), (ext1, inner, ext2), size, ext1, inner, ext2)
        return None

    # -- the fast path ------------------------------------------------------------------------
    def solve(self, poses, first=None, second=None, branch: int = 1, input_error=0.0,
              frames=None, out=None, start=None) -> GroupSolution:
        """:meth:`Group.solve` in closed form: the same statuses, conditioning, bounds and analogs.

        The six unknowns of the analog systems are eliminated pair by pair: each external pair
        fixes its link's velocity up to one parameter along the null vector of its two rows, and
        the inner pair's two rows give those two parameters (a 2x2 system whose determinant is
        the determinant of the group Jacobian). ``frames`` may carry the known links' frames
        (:func:`assur.rows.frame`) computed once for every group that uses them; it receives the
        group's own frames. ``out``: ``(poses, first, second)`` dicts of ``(N, 3)`` arrays to write
        the group's results into (see :meth:`Group.solve`). ``start`` is not used (closed form).
        """
        if branch not in self.branches:
            raise ValueError(f"{self!r}: branch must be one of {self.branches}, got {branch!r}")
        frames = {} if frames is None else frames
        for link in self.known_links:
            if link not in frames:
                frames[link] = frame(poses[link])
        placed, ok = self._place(frames, branch)
        frames.update(placed)
        ext1, inner, ext2 = rows = [rows_of(j, frames) for j in self.joints]
        closure = np.maximum(np.maximum(ext1.residual(frames, self.size), inner.residual(frames, self.size)),
                             ext2.residual(frames, self.size))
        with np.errstate(invalid="ignore"):
            assembled = ok & (closure <= CLOSURE_TOL * self.size)   # False where NaN
        l1, l2 = self.links
        # the null vectors of the external pairs, carried through the inner pair: the columns of
        # the 2x2 system of both analog orders, whose determinant is the group Jacobian's
        c1, c2 = inner.act(l1, ext1.null(l1)), inner.act(l2, ext2.null(l2))
        det = c1[0] * c2[1] - c1[1] * c2[0]
        ratio, scale = self._conditioning(rows, frames, det)
        bound = np.where(assembled, error_bound(ratio, input_error, self.roundoff_factor), np.inf)
        status = np.where(assembled, np.where(bound <= ANALOG_TOL, OK, SINGULAR), CANNOT_ASSEMBLE)
        sign = np.where(assembled, np.sign(det), 0.0)
        conditioning = np.where(assembled, ratio, np.nan)
        if not assembled.all():    # later groups see NaN where this one is not assembled
            placed = {k: tuple(np.where(assembled, c, np.nan) for c in f) for k, f in placed.items()}
            frames.update(placed)
        into = (None, None, None) if out is None else out
        new = {k: _pose_array((f[0], f[1], f[4]), ~assembled, into[0], k) for k, f in placed.items()}
        d1 = d2 = None
        if first is not None:
            bad = status != OK
            with np.errstate(divide="ignore", invalid="ignore"):
                system = (c1, c2, np.where(bad, 1.0, det))
                known = {k: _columns(first[k]) for k in self.known_links}
                q1, q2 = self._eliminate(rows, system, known, None)
                d1 = {l1: _pose_array(q1, bad, into[1], l1), l2: _pose_array(q2, bad, into[1], l2)}
                if second is not None:
                    gammas = [r.quadratic({**known, l1: q1, l2: q2}) for r in rows]
                    known2 = {k: _columns(second[k]) for k in self.known_links}
                    a1, a2 = self._eliminate(rows, system, known2, gammas)
                    d2 = {l1: _pose_array(a1, bad, into[2], l1), l2: _pose_array(a2, bad, into[2], l2)}
                    status, bound = flag_second_analogs(self, status, bound, ratio, input_error, scale,
                                                        {**known, l1: q1, l2: q2}, {**known2, l1: a1, l2: a2},
                                                        (d1, d2))
        return GroupSolution(new, status, sign, conditioning, bound, d1, d2)

    def _eliminate(self, rows, system, known, gammas):
        """Generalized velocities ``(tx, ty, w)`` of L1 and L2 from the rows' right-hand sides
        ``gamma - Phi_k q_k`` (``gamma`` = 0 for first analogs); ``system`` = the 2x2 system's
        columns and determinant (see :meth:`solve`)."""
        l1, l2 = self.links
        ext1, inner, ext2 = rows
        c1, c2, det = system

        def rhs(i, link):
            r = rows[i]
            other = r.links[0] if r.links[1] == link else r.links[1]
            k0, k1 = r.act(other, known[other])
            g = (0.0, 0.0) if gammas is None else gammas[i]
            return g[0] - k0, g[1] - k1

        p1, p2 = ext1.particular(l1, rhs(0, l1)), ext2.particular(l2, rhs(2, l2))
        a1, a2 = inner.act(l1, p1), inner.act(l2, p2)
        g = (0.0, 0.0) if gammas is None else gammas[1]
        rx, ry = g[0] - a1[0] - a2[0], g[1] - a1[1] - a2[1]
        tau1 = (rx * c2[1] - ry * c2[0]) / det
        tau2 = (c1[0] * ry - c1[1] * rx) / det
        return ([p + tau1 * n for p, n in zip(p1, ext1.null(l1))], [p + tau2 * n for p, n in zip(p2, ext2.null(l2))])

    def _conditioning(self, rows, frames, det):
        """:meth:`Group.conditioning` elementwise: the Hadamard ratio ``(N,)`` of the scaled
        Jacobian, from the determinant ``det`` ``(N,)`` of the unscaled one, and the group's
        scale ``(N,)``, m (:meth:`Group.scale`)."""
        l1, l2 = self.links
        ext1, inner, ext2 = rows
        (ax, ay), (bx, by), (cx, cy) = ext1.contact, inner.contact, ext2.contact
        spread = np.maximum(np.maximum(np.hypot(bx - ax, by - ay), np.hypot(cx - bx, cy - by)),
                            np.hypot(cx - ax, cy - ay))
        biggest = np.maximum(np.maximum(np.maximum(np.abs(ax), np.abs(ay)), np.maximum(np.abs(bx), np.abs(by))),
                             np.maximum(np.abs(cx), np.abs(cy)))
        scale = np.maximum(spread, np.maximum(1e-12 * biggest, COINCIDENT * self.size))
        centroid = {l1: (0.5 * (ax + bx), 0.5 * (ay + by)), l2: (0.5 * (bx + cx), 0.5 * (by + cy))}
        product = 1.0
        for r in rows:
            row0 = row1 = 0.0
            for link in (l1, l2):
                if link in r.links:
                    s0, s1 = r.norms_squared(link, centroid[link], frames[link], scale)
                    row0, row1 = row0 + s0, row1 + s1
            product = product * row0 * row1
        prismatic = sum(r.kind == "P" for r in rows)
        with np.errstate(invalid="ignore"):
            return np.abs(det) * scale ** (prismatic - 2) / np.sqrt(product), scale

    # -- reactions: the transposed elimination --------------------------------------------------
    def reactions(self, poses, loads, valid=None, frames=None):
        """:meth:`Group.reactions` in closed form: the same multipliers and transmitted loads.

        The transposed system ``Phi_q^T lambda = -Q`` is eliminated like the analogs: the load
        on each link projected on its external pair's null vector involves only the inner pair's
        multipliers (the 2x2 system of :meth:`solve`, transposed); the external pairs' multipliers
        then carry what is left of their link's load. ``frames``: the links' frames
        (:func:`assur.rows.frame`) when the caller has them.
        """
        l1, l2 = self.links
        frames = {k: frame(poses[k]) for k in (l1, l2, *self.known_links)} if frames is None else frames
        with np.errstate(invalid="ignore", over="ignore"):
            ok, lam, transmitted = self._transposed(frames, {k: _columns(loads[k]) for k in (l1, l2)},
                                                    True if valid is None else np.asarray(valid, bool))
        multipliers = {name: _pose_array(v, ~ok) for name, v in lam.items()}
        transmitted = {k: _pose_array(v, ~ok) for k, v in transmitted.items()}
        return multipliers, transmitted

    def _transposed(self, frames, loads, valid):
        """The elimination of :meth:`reactions` on the links' ``frames`` and the loads on the
        group's links (link -> ``(Fx, Fy, M)`` columns): where its 2x2 system is regular and
        ``valid``, the multipliers (pair -> columns) and the loads on the known links (link ->
        ``(Fx, Fy, M)``); written on columns, so that the compiled reactions
        (:mod:`linkage.kinetostatics.kernel`) trace it as it is."""
        l1, l2 = self.links
        ext1, inner, ext2 = [rows_of(j, frames) for j in self.joints]
        n1, n2 = ext1.null(l1), ext2.null(l2)
        c1, c2 = inner.act(l1, n1), inner.act(l2, n2)
        det = c1[0] * c2[1] - c1[1] * c2[0]
        ok = np.isfinite(det) & (det != 0) & valid
        det = np.where(ok, det, 1.0)
        q1, q2 = loads[l1], loads[l2]
        b1 = -(n1[0] * q1[0] + n1[1] * q1[1] + n1[2] * q1[2])
        b2 = -(n2[0] * q2[0] + n2[1] * q2[1] + n2[2] * q2[2])
        lam_inner = ((b1 * c2[1] - b2 * c1[1]) / det, (c1[0] * b2 - c2[0] * b1) / det)
        lam = {}
        for r, link, q in ((ext1, l1, q1), (ext2, l2, q2)):
            carried = inner.constraint_load(link, lam_inner)
            lam[r] = r.multipliers(link, tuple(-a - b for a, b in zip(q, carried)))
        lam[inner] = lam_inner
        transmitted = {}
        for r in (ext1, ext2):
            known = r.links[0] if r.links[1] in self.links else r.links[1]
            load = r.constraint_load(known, lam[r])
            old = transmitted.get(known)
            transmitted[known] = load if old is None else tuple(a + b for a, b in zip(old, load))
        return ok, {r.joint.name: lam[r] for r in (ext1, inner, ext2)}, transmitted

    # -- positions -----------------------------------------------------------------------------
    def _position(self, poses, branch):
        placed, ok = self._place(self._frames(poses), branch)
        return {k: np.column_stack([f[0], f[1], f[4]]) for k, f in placed.items()}, ok

    @abstractmethod
    def _place(self, frames, branch):
        """Hook: ``({link: frame}, assembled)`` of the group's links in closed form, from the known
        links' frames ``(x, y, c, s, theta)`` (:func:`assur.rows.frame`)."""

    def _frames(self, poses):
        """Frames of the known links from their poses."""
        return {k: frame(poses[k]) for k in self.known_links}

    # -- helpers for closed forms (vectors as (x, y) pairs of (N,) arrays) ------------------------
    @staticmethod
    def known_point(frames, joint: Joint, link: str):
        """Global position ``(x, y)`` of ``joint``'s point as carried by the known link (not ``link``)."""
        _, other, p_other = joint.local(link)
        f = frames[other]
        rx, ry = arm(f, xy(p_other))
        return f[0] + rx, f[1] + ry

    @staticmethod
    def guide_line(frames, joint: PrismaticJoint):
        """Global point ``(x, y)`` and unit direction ``(x, y)`` of a prismatic joint's guide line."""
        f = frames[joint.a]
        gx, gy = arm(f, xy(joint.g))
        return (f[0] + gx, f[1] + gy), arm(f, xy(joint.u))

    @staticmethod
    def turned(c, s, theta, beta):
        """``(c, s, theta)`` of the angle ``theta + beta`` from the cosine and sine of ``theta``."""
        cb, sb = np.cos(beta), np.sin(beta)
        return c * cb - s * sb, s * cb + c * sb, theta + beta

    @staticmethod
    def place_by_two_points(p1, p2, local_1, local_2, length):
        """Frame of a link whose local points 1 and 2 (``(2,)`` or ``(N, 2)``) are at the global
        points ``p1``, ``p2`` (``(x, y)``), ``length`` apart."""
        (ax, ay), (bx, by) = xy(local_1), xy(local_2)
        offset = np.arctan2(by - ay, bx - ax)
        dx, dy = p2[0] - p1[0], p2[1] - p1[1]
        theta = np.arctan2(dy, dx) - offset
        ux, uy = dx / length, dy / length
        co, so = np.cos(offset), np.sin(offset)
        c, s = ux * co + uy * so, uy * co - ux * so
        return p1[0] - (c * ax - s * ay), p1[1] - (s * ax + c * ay), c, s, theta

    @staticmethod
    def place_by_point_and_angle(p, local, c, s, theta):
        """Frame of a link with angle ``theta`` (cosine ``c``, sine ``s``) whose local point is at ``p``."""
        px, py = xy(local)
        return p[0] - (c * px - s * py), p[1] - (s * px + c * py), c, s, theta


def _columns(q: np.ndarray):
    """``(N, 3)`` analogs as three ``(N,)`` columns."""
    return q[:, 0], q[:, 1], q[:, 2]


def _pose_array(q, bad: np.ndarray, into: dict | None = None, link: str | None = None) -> np.ndarray:
    """Columns as an ``(N, len(q))`` array (``into[link]`` when given), NaN at the positions ``bad``."""
    out = np.empty((len(bad), len(q))) if into is None else into[link]
    for i, column in enumerate(q):
        out[:, i] = column
    if bad.any():
        out[bad] = np.nan
    return out


def _arrange(l1: str, l2: str, joints, known):
    """(ext1, inner, ext2) when the joints form a dyad L1-L2 on known links, else None."""
    ext1 = [j for j in joints if {j.a, j.b} - {l1} <= known and l1 in (j.a, j.b) and l2 not in (j.a, j.b)]
    ext2 = [j for j in joints if {j.a, j.b} - {l2} <= known and l2 in (j.a, j.b) and l1 not in (j.a, j.b)]
    inner = [j for j in joints if {j.a, j.b} == {l1, l2}]
    if len(ext1) == len(ext2) == len(inner) == 1:
        return ext1[0], inner[0], ext2[0]
    return None
