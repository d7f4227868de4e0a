"""The class-III triad RRR-RRR: a ternary link pinned to three binary links (legs), each leg pinned
to a known link. Every assembly mode is listed in closed form; Newton's method only polishes.

Geometry: leg i joins the known point ``A_i`` (carried by a known link) to the ternary link's pin
``P_i``, ``|A_i P_i| = d_i``. With ``P_1 = A_1 + d_1 (cos a, sin a)`` and the ternary link's angle
``t``, ``P_i = P_1 + Rot(t) q_i`` (``q_i = p_i - p_1`` in its frame), the two remaining legs give

    u(a) . w_i(t) = h_i(t),   w_i = A_1 - A_i + Rot(t) q_i,   h_i = (d_i^2 - d_1^2 - |w_i|^2) / (2 d_1)

for i = 2, 3: a linear system in ``(cos a, sin a)``. Its solution ``(C, S) / D`` (Cramer) lies on
the unit circle where ``f(t) = C^2 + S^2 - D^2 = 0``. ``w_i`` and ``h_i`` are of degree 1 in
``(cos t, sin t)``, so ``f`` is a trigonometric polynomial of degree at most 4 (its degree-4 terms
cancel for most triads, leaving degree 3: at most six modes): with ``z = e^{i t}`` and f's degree
m, ``z^m f`` is a polynomial of degree 2m whose roots on the unit circle are the assembly modes.
Its coefficients are the discrete Fourier transform of ``f`` at 16 angles (exact up to degree 7);
its roots are the eigenvalues of the companion matrix, for all positions at once.
"""

from __future__ import annotations

import numpy as np

from .generic import NewtonGroup, newton
from .rows import arm, frame, xy

__all__ = ["Triad"]

#: distance from the unit circle within which a root counts as real (then polished by Newton)
UNIT_CIRCLE_TOL = 1e-3


class Triad(NewtonGroup):
    """A class-III group of four links and six revolute pairs: a ternary link and three legs."""

    kind = "RRR-RRR"

    def __init__(self, links, joints, size, ternary: str, legs):
        super().__init__(links, joints, size)
        self.ternary = ternary
        self.legs = tuple(legs)    # (leg link, joint with the ternary link, joint with a known link)

    @classmethod
    def _bind(cls, links, joints, known, size):
        if len(links) != 4 or len(joints) != 6 or any(j.kind != "R" for j in joints):
            return None
        inner = [j for j in joints if j.a in links and j.b in links]
        count = {k: sum(k in (j.a, j.b) for j in inner) for k in links}
        ternary = [k for k, c in count.items() if c == 3]
        if len(ternary) != 1:
            return None
        (t,) = ternary
        legs = []
        for k in sorted(set(links) - {t}):
            own = [j for j in joints if k in (j.a, j.b)]
            to_t = [j for j in own if t in (j.a, j.b)]
            out = [j for j in own if ({j.a, j.b} - {k}) <= known]
            if len(own) != 2 or len(to_t) != 1 or len(out) != 1:
                return None
            legs.append((k, to_t[0], out[0]))
        return cls(links, joints, size, t, legs)

    # -- every assembly mode -------------------------------------------------------------------
    def modes(self, poses):
        """Every real assembly mode ``({link: (N, 8, 3)}, valid (N, 8))`` at the known ``poses``
        (up to six valid per position; invalid slots are NaN)."""
        frames = {k: frame(poses[k]) for k in self.known_links}
        anchors, lengths, pins, legs_local = [], [], [], []
        for leg, to_t, out in self.legs:
            anchors.append(_known_point(frames, out, leg))
            e, c = xy(out.local(leg)[0]), xy(to_t.local(leg)[0])
            lengths.append(np.hypot(c[0] - e[0], c[1] - e[1]))
            pins.append(xy(to_t.local(self.ternary)[0]))
            legs_local.append((e, c))
        N = len(anchors[0][0])
        A = np.stack([np.stack(np.broadcast_arrays(*a), axis=-1) for a in anchors], axis=1)          # (N, 3, 2)
        d = np.stack([np.broadcast_to(v, (N,)) for v in lengths], axis=1)                         # (N, 3)
        p = np.stack([np.stack(np.broadcast_arrays(*v, np.zeros(N))[:2], axis=-1) for v in pins], axis=1)
        angles = _real_roots(lambda t: _closure(A, d, p, t)[0], N)                                   # (N, 8)
        f, C, S, D = _closure(A, d, p, angles)
        with np.errstate(invalid="ignore", divide="ignore"):
            ca, sa = C / D, S / D
            norm = np.hypot(ca, sa)
            ca, sa = ca / norm, sa / norm
        ct, st = np.cos(angles), np.sin(angles)
        P1 = A[:, None, 0] + d[:, None, 0, None] * np.stack([ca, sa], axis=-1)                        # (N, 8, 2)
        origin = P1 - _rotated(ct, st, p[:, None, 0])
        candidates = {self.ternary: np.concatenate([origin, angles[..., None]], axis=-1)}
        for i, (leg, _, _) in enumerate(self.legs):
            Pi = origin + _rotated(ct, st, p[:, None, i])
            candidates[leg] = _leg_pose(A[:, None, i], Pi, *legs_local[i])
        valid = np.isfinite(angles)
        flat = {k: v.reshape(N * 8, 3) for k, v in candidates.items()}
        known = {k: np.repeat(poses[k], 8, axis=0) for k in self.known_links}
        polished, converged = newton(self, known, {k: np.where(np.isfinite(v), v, np.nan) for k, v in flat.items()},
                                     steps=8)
        merged = {**known, **polished}
        residual = np.max(np.abs(self.residual(merged)), axis=1)
        size = np.broadcast_to(np.asarray(self.size, float), (N,))
        with np.errstate(invalid="ignore"):
            good = (converged & (residual <= 1e-9 * np.repeat(size, 8))).reshape(N, 8) & valid
        good &= ~_duplicates(polished[self.ternary].reshape(N, 8, 3), good, size)
        out = {k: np.where(good[..., None], v.reshape(N, 8, 3), np.nan) for k, v in polished.items()}
        return out, good


def _known_point(frames, joint, link):
    """Global point ``(x, y)`` of ``joint`` as carried by its known link (not ``link``)."""
    _, other, p_other = joint.local(link)
    f = frames[other]
    rx, ry = arm(f, xy(p_other))
    return f[0] + rx, f[1] + ry


def _rotated(c, s, v):
    return np.stack([c * v[..., 0] - s * v[..., 1], s * v[..., 0] + c * v[..., 1]], axis=-1)


def _closure(A, d, p, t):
    """``f(t)`` and Cramer's ``C, S, D`` (see the module docstring) at angles ``t`` ``(N, K)``."""
    c, s = np.cos(t), np.sin(t)
    w, h = [], []
    for i in (1, 2):
        q = p[:, None, i] - p[:, None, 0]                                    # (N, 1, 2)
        wi = (A[:, None, 0] - A[:, None, i]) + _rotated(c, s, q)            # (N, K, 2)
        hi = (d[:, None, i] ** 2 - d[:, None, 0] ** 2 - np.sum(wi**2, axis=-1)) / (2 * d[:, None, 0])
        w.append(wi)
        h.append(hi)
    (w2, w3), (h2, h3) = w, h
    D = w2[..., 0] * w3[..., 1] - w2[..., 1] * w3[..., 0]
    C = h2 * w3[..., 1] - h3 * w2[..., 1]
    S = w2[..., 0] * h3 - w3[..., 0] * h2
    return C**2 + S**2 - D**2, C, S, D


def _real_roots(f, N: int) -> np.ndarray:
    """Roots in (-pi, pi] ``(N, 8)`` (NaN-padded) of the trigonometric polynomials ``f(t)``
    ``(N, K) -> (N, K)`` of degree at most 4: Fourier coefficients from 16 samples, then the
    eigenvalues of the companion matrix of ``z^m f`` for the degree m each position has (the
    triad's degree-4 terms cancel for most geometries, leaving degree 3: six roots)."""
    samples = 2 * np.pi * np.arange(16) / 16
    values = f(np.broadcast_to(samples, (N, 16)))
    c = np.fft.fft(values, axis=1) / 16                      # c[k] = coefficient of e^{ikt}; c[-k] at 16 - k
    scale = np.max(np.abs(c), axis=1)
    tiny = 1e-11 * np.where(scale > 0, scale, 1.0)
    degree = np.zeros(N, int)
    for m in (1, 2, 3, 4):
        degree = np.where(np.abs(c[:, m]) > tiny, m, degree)
    roots = np.full((N, 8), np.nan + 0j)
    for m in (1, 2, 3, 4):
        rows = np.flatnonzero(degree == m)
        if not len(rows):
            continue
        coefficients = np.stack([c[rows, k % 16] for k in range(m, -m - 1, -1)], axis=1)   # z^2m ... z^0
        monic = coefficients[:, 1:] / coefficients[:, :1]
        companion = np.zeros((len(rows), 2 * m, 2 * m), complex)
        companion[:, 0, :] = -monic
        companion[:, np.arange(1, 2 * m), np.arange(2 * m - 1)] = 1.0
        roots[rows, :2 * m] = np.linalg.eigvals(companion)
    on_circle = np.abs(np.abs(roots) - 1.0) <= UNIT_CIRCLE_TOL
    return np.where(on_circle, np.angle(roots), np.nan)


def _column(v):
    """A local coordinate: a float, or ``(N,)`` per position as a column ``(N, 1)``."""
    v = np.asarray(v, float)
    return v[:, None] if v.ndim == 1 else v


def _leg_pose(A, P, e, c):
    """Pose ``(N, K, 3)`` of a leg whose local points ``e`` and ``c`` lie at ``A`` and ``P`` ``(N, K, 2)``."""
    (ex, ey), (cx, cy) = [(_column(v[0]), _column(v[1])) for v in (e, c)]
    offset = np.arctan2(cy - ey, cx - ex)
    theta = np.arctan2(P[..., 1] - A[..., 1], P[..., 0] - A[..., 0]) - offset
    ct, st = np.cos(theta), np.sin(theta)
    origin = np.stack([A[..., 0] - (ct * ex - st * ey), A[..., 1] - (st * ex + ct * ey)], axis=-1)
    return np.concatenate([origin, theta[..., None]], axis=-1)


def _duplicates(ternary: np.ndarray, good: np.ndarray, size: np.ndarray) -> np.ndarray:
    """``(N, 8)``: slots that repeat an earlier good slot's pose (a double root polished twice)."""
    repeated = np.zeros(good.shape, bool)
    for k in range(1, 8):
        for j in range(k):
            gap = ternary[:, k] - ternary[:, j]
            gap[:, 2] = ((gap[:, 2] + np.pi) % (2 * np.pi) - np.pi) * size
            with np.errstate(invalid="ignore"):
                same = np.max(np.abs(gap), axis=1) <= 1e-7 * size
            repeated[:, k] |= good[:, j] & good[:, k] & same
    return repeated
