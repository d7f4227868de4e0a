"""Fused constraint evaluation of a group: its whole residual and Jacobian in a few array expressions.

The generic path (:meth:`assur.base.Group.residual`, :meth:`assur.base.Group.jacobians`) asks each
pair for its two (three) equations and its Jacobian blocks and stacks them: some twenty small numpy
calls per pair, which is what a Newton iteration at a few positions costs. A :class:`FusedLayout`
is built once per group (:func:`layout_of` keeps it on the group object) from the group's pairs:

- every local vector a pair rotates with a link's angle -- a revolute pair's points on both links,
  a prismatic pair's guide direction ``u`` and guide point ``g`` on the guide link and its slider
  point ``p`` -- stacked as constant arrays with the index of the link that carries each;
- the rows and columns each pair fills in the residual ``(m,)`` and in the Jacobian
  ``(m, 3 (L + K))`` over the group's L links then its K known links (:attr:`FusedLayout.order`),
  as flat indices, and the Jacobian's constant entries (the ``+-1`` of the translations, of the
  prismatic angle rows and of a driven pair's driver) as one template.

:meth:`FusedLayout.evaluate` then rotates every vector at once, forms the revolute closures of
all revolute pairs together and the prismatic equations of all prismatic pairs together, and
scatters them with one indexed assignment each. Every entry is computed by the same floating-point
operations as the pair-by-pair path (tests/test_newton_fused.py checks the two agree to 1e-13).

``FUSED`` switches the fused path off (the pair-by-pair path then serves every call), for the
comparisons of benchmarks/bench_newton.py and the tests.
"""

from __future__ import annotations

from numbers import Real
from typing import Mapping

import numpy as np

from .base import DrivenPrismaticJoint, PrismaticJoint, RevoluteJoint

__all__ = ["FUSED", "FusedLayout", "layout_of"]

#: evaluate groups' residuals and Jacobians fused (False: the pair-by-pair path of assur.base)
FUSED = True

_ATTRIBUTE = "_fused_layout"


def layout_of(group) -> "FusedLayout | None":
    """The group's :class:`FusedLayout`, built at the first call and kept on the group; None when
    :data:`FUSED` is off or a pair is not one the layout knows (a joint type of its own, local
    geometry that varies per position as in a variant batch): the caller then takes the
    pair-by-pair path."""
    if not FUSED:
        return None
    cached = group.__dict__.get(_ATTRIBUTE, False)
    if cached is False:
        cached = FusedLayout.of(group.links, group.known_links, group.joints)
        group.__dict__[_ATTRIBUTE] = cached
    return cached


def _vector(value) -> tuple[float, float] | None:
    """A constant local vector as two floats, or None when it is not one (per-position arrays)."""
    if np.shape(value) != (2,):
        return None
    x, y = value
    return (float(x), float(y)) if isinstance(x, Real) and isinstance(y, Real) else None


class FusedLayout:
    """Index layout and constant local vectors of a group's constraint system (module docstring).

    Attributes
    ----------
    order : tuple of str
        The group's links, then its known links: the link axis of a pose stack.
    rows : int
        Number of equations m.
    """

    def __init__(self, links, known_links, revolute, prismatic, drivers, rows: int):
        self.links = tuple(links)
        self.order = self.links + tuple(known_links)
        self._damping = None
        self.rows = rows
        index = {k: i for i, k in enumerate(self.order)}
        width = 3 * len(self.order)
        self.width = width
        R, P = self.n_revolute, self.n_prismatic = len(revolute), len(prismatic)
        joints_r, joints_p = [j for j, _ in revolute], [j for j, _ in prismatic]
        a_r, b_r = [index[j.a] for j in joints_r], [index[j.b] for j in joints_r]
        a_p, b_p = [index[j.a] for j in joints_p], [index[j.b] for j in joints_p]

        # the rotated vectors, E = 2 R + 4 P: revolute points on a, on b; slider points p (on b),
        # guide points g, guide directions u and normals n = E u (on the guide link a)
        u_local = [_vector(j.u) for j in joints_p]
        local = np.array([_vector(j.pa) for j in joints_r] + [_vector(j.pb) for j in joints_r]
                         + [_vector(j.p) for j in joints_p] + [_vector(j.g) for j in joints_p]
                         + u_local + [(-y, x) for x, y in u_local], float).reshape(-1, 2)
        self.carrier = np.array(a_r + b_r + b_p + a_p + a_p + a_p, np.intp)
        # Rot(theta) l = cos(theta) l + sin(theta) E l, E l = (-l_y, l_x)
        self.along, self.across = local, np.column_stack([-local[:, 1], local[:, 0]])
        # link origins: revolute a, revolute b, slider links b (each with its rotated vector), guide links a
        self.origin = np.array(a_r + b_r + b_p + a_p, np.intp)
        self.beta = np.array([float(j.beta) for j in joints_p])
        self.driven = np.array([n for n, j in enumerate(joints_p) if isinstance(j, DrivenPrismaticJoint)], np.intp)
        D = len(self.driven)
        # the driven pairs' slots: a slice where they are consecutive (a cylinder: all of them)
        consecutive = D and np.array_equal(self.driven, np.arange(self.driven[0], self.driven[0] + D))
        self.driven_at = slice(int(self.driven[0]), int(self.driven[0]) + D) if consecutive else self.driven
        self.driven_u = (slice(2 * R + 2 * P + self.driven_at.start, 2 * R + 2 * P + self.driven_at.stop)
                         if consecutive else 2 * R + 2 * P + self.driven)
        self.driver = np.array([index[d] for d in drivers], np.intp)

        r_rows = np.array([r for _, r in revolute], np.intp)
        p_rows = np.array([r for _, r in prismatic], np.intp)
        d_rows = p_rows[self.driven]
        self.angle_rows = p_rows + 1
        # residual columns in the order evaluate() concatenates the equations: each revolute
        # pair's two rows, the prismatic normal rows, angle rows, driven rows
        self.residual_columns = np.concatenate([np.column_stack([r_rows, r_rows + 1]).reshape(-1), p_rows,
                                                p_rows + 1, d_rows + 2])

        # one output row per position: the residual (m), then the Jacobian (m, width) flattened
        def at(r, c):
            return rows + r * width + c

        ca, cb = 3 * np.array(a_r, np.intp), 3 * np.array(b_r, np.intp)
        pa, pb = 3 * np.array(a_p, np.intp), 3 * np.array(b_p, np.intp)
        da, db = pa[self.driven], pb[self.driven]
        template = np.zeros(rows + rows * width)
        template[at(r_rows, ca)] = template[at(r_rows + 1, ca + 1)] = 1.0
        template[at(r_rows, cb)] = template[at(r_rows + 1, cb + 1)] = -1.0
        template[at(p_rows + 1, pa + 2)] = -1.0
        template[at(p_rows + 1, pb + 2)] = 1.0
        template[at(d_rows + 2, 3 * self.driver)] = -1.0
        self.template = template

        def pairs(first, second):     # (x, y) entries of vectors, interleaved as their values are
            return np.column_stack([first, second]).reshape(-1)

        ones = np.ones
        # the variable entries, in the order of evaluate()'s values, and the sign each value takes
        self.entries = np.concatenate([
            self.residual_columns,
            pairs(at(r_rows + 1, ca + 2), at(r_rows, ca + 2)),      # revolute points on a: x, y
            pairs(at(r_rows + 1, cb + 2), at(r_rows, cb + 2)),      # on b
            pairs(at(p_rows, pa), at(p_rows, pa + 1)),              # -n on the guide link
            pairs(at(p_rows, pb), at(p_rows, pb + 1)),              # +n on the slider link
            at(p_rows, pa + 2), at(p_rows, pb + 2),                 # the turns: -(u.d + u.g), u.p
            pairs(at(d_rows + 2, da), at(d_rows + 2, da + 1)),      # driven: -u on the guide link
            pairs(at(d_rows + 2, db), at(d_rows + 2, db + 1)),      # +u on the slider link
            at(d_rows + 2, da + 2), at(d_rows + 2, db + 2),         # the turns: n.d + n.g, -n.p
        ]).astype(np.intp)
        self.signs = np.concatenate([
            ones(len(self.residual_columns)),
            np.tile([1.0, -1.0], R), np.tile([-1.0, 1.0], R),
            -ones(2 * P), ones(2 * P), -ones(P), ones(P),
            -ones(2 * D), ones(2 * D), ones(D), -ones(D)])

    def damping(self, size, N: int):
        """Newton's step limits: ``(limit, unit, positive)``, the largest step of each coordinate
        (half the size ``size``, m, for positions; 0.5 rad for angles), the unit a step is measured
        in (the size; 1 rad) and whether every limit is positive; ``(3 L,)`` for a scalar size,
        else ``(N, 3 L)``."""
        angles = np.zeros(3 * len(self.links), bool)
        angles[2::3] = True
        if np.ndim(size) == 0:
            key = float(size)
            if self._damping is None or self._damping[0] != key:
                limit = np.where(angles, 0.5, 0.5 * key)
                self._damping = (key, limit, np.where(angles, 1.0, key), bool(np.all(limit > 0)))
            return self._damping[1:]
        size = np.broadcast_to(np.asarray(size, float), (N,))
        limit = np.where(angles, 0.5, 0.5 * size[:, None])
        return limit, np.where(angles, 1.0, size[:, None]), bool(np.all(limit > 0))

    @classmethod
    def of(cls, links, known_links, joints) -> "FusedLayout | None":
        """The layout of a group's pairs ``joints`` (None when one is not a plain revolute,
        prismatic or driven prismatic pair with constant local geometry)."""
        revolute, prismatic, drivers, row = [], [], [], 0
        for j in joints:
            if type(j) is RevoluteJoint:
                if _vector(j.pa) is None or _vector(j.pb) is None:
                    return None
                revolute.append((j, row))
            elif type(j) in (PrismaticJoint, DrivenPrismaticJoint):
                if any(_vector(v) is None for v in (j.g, j.u, j.p)) or not isinstance(j.beta, Real):
                    return None
                prismatic.append((j, row))
                if type(j) is DrivenPrismaticJoint:
                    drivers.append(j.driver)
            else:
                return None
            row += j.rows
        return cls(links, known_links, revolute, prismatic, drivers, row)

    # -- evaluation ----------------------------------------------------------------------------
    def stack(self, poses: Mapping[str, np.ndarray], links=None) -> np.ndarray:
        """The poses of ``links`` (default :attr:`order`) as one array ``(N, len(links), 3)``
        (poses of length 1 broadcast)."""
        arrays = [np.asarray(poses[k], float) for k in (self.order if links is None else links)]
        if len({a.shape for a in arrays}) > 1:
            arrays = np.broadcast_arrays(*arrays)
        return np.stack(arrays, axis=1)

    def evaluate(self, stack: np.ndarray, jacobian: bool = True):
        """Residual and Jacobian of every equation of the group at the pose stack ``stack``
        ``(N, L + K, 3)`` (:meth:`stack`).

        Returns
        -------
        residual : ndarray, shape (N, m)
            The pairs' equations as :meth:`assur.base.RevoluteJoint.residual` and
            :meth:`assur.base.PrismaticJoint.residual` write them (prismatic angle rows in rad,
            not scaled to m).
        jacobian : ndarray, shape (N, m, 3 (L + K)), or None when not asked for
            Their derivatives with respect to the poses of :attr:`order`: the group Jacobian is
            the first ``3 L`` columns, each known link's block the next three columns of its own.
        """
        N = len(stack)
        R, P = self.n_revolute, self.n_prismatic
        theta = stack[:, self.carrier, 2]
        vectors = np.cos(theta)[..., None] * self.along + np.sin(theta)[..., None] * self.across    # (N, E, 2)
        origins = stack[:, self.origin, :2]
        # revolute pairs: r_a + Rot(theta_a) p_a - (r_b + Rot(theta_b) p_b); slider points r_b + Rot(theta_b) p
        points = origins[:, :2 * R + P] + vectors[:, :2 * R + P]
        values = [(points[:, :R] - points[:, R:2 * R]).reshape(N, 2 * R)]
        if P:
            # prismatic pairs: d = r_b + p - r_a - g; the dot products of u and n with d, p and g
            d = (points[:, 2 * R:] - origins[:, 2 * R + P:]) - vectors[:, 2 * R + P:2 * R + 2 * P]
            spans = np.concatenate([d[:, None], vectors[:, 2 * R:2 * R + 2 * P].reshape(N, 2, P, 2)], axis=1)
            frame = vectors[:, 2 * R + 2 * P:].reshape(N, 2, 1, P, 2)
            dots = (spans[:, None] * frame).sum(axis=-1)            # (N, {u, n}, {d, p, g}, P)
            angle = theta[:, 2 * R:2 * R + P] - theta[:, 2 * R + 2 * P:2 * R + 3 * P] - self.beta
            values += [dots[:, 1, 0], (angle + np.pi) % (2 * np.pi) - np.pi]
            driven = dots[..., self.driven_at] if len(self.driven) else None
            if driven is not None:
                values.append(driven[:, 0, 0] - stack[:, self.driver, 0])
        if not jacobian:
            residual = np.empty((N, self.rows))
            residual[:, self.residual_columns] = np.concatenate(values, axis=1)
            return residual, None
        values.append(vectors[:, :2 * R].reshape(N, 4 * R))
        if P:
            normal = vectors[:, 2 * R + 3 * P:].reshape(N, 2 * P)
            values += [normal, normal, dots[:, 0, 0] + dots[:, 0, 2], dots[:, 0, 1]]
            if driven is not None:
                direction = vectors[:, self.driven_u].reshape(N, -1)
                values += [direction, direction, driven[:, 1, 0] + driven[:, 1, 2], driven[:, 1, 1]]
        out = np.empty((N, len(self.template)))
        out[...] = self.template
        out[:, self.entries] = np.concatenate(values, axis=1) * self.signs
        return out[:, :self.rows], out[:, self.rows:].reshape(N, self.rows, self.width)

    # -- the group protocol's two calls ----------------------------------------------------------
    def residual(self, poses: Mapping[str, np.ndarray], size) -> np.ndarray:
        """:meth:`assur.base.Group.residual`: ``(N, m)``, prismatic angle rows times ``size``
        (m, scalar or ``(N,)``)."""
        residual, _ = self.evaluate(self.stack(poses), jacobian=False)
        if len(self.angle_rows):
            residual[:, self.angle_rows] *= np.asarray(size, float)[..., None] if np.ndim(size) else size
        return residual

    def jacobians(self, poses: Mapping[str, np.ndarray]) -> tuple[np.ndarray, dict[str, np.ndarray]]:
        """:meth:`assur.base.Group.jacobians`: ``Phi_q`` ``(N, m, m)`` and the known links'
        blocks ``(N, m, 3)``."""
        _, full = self.evaluate(self.stack(poses))
        q = 3 * len(self.links)
        return full[:, :, :q], {k: full[:, :, q + 3 * i:q + 3 * i + 3] for i, k in enumerate(self.order[len(self.links):])}
