"""The four-bar's kinematics written out by hand in numpy: the speed a library call is measured against.

The crank-rocker four-bar O-A-B-C of ``schemes/four_bar.toml`` (O at the origin, C fixed), its
RRR dyad in closed form, every quantity the library's ``analyze(..., order=2)`` gives for it:
positions and first / second analogs (derivatives with respect to the crank angle phi) of the
points A, B, E and of the angles of links 2 (A -> B) and 3 (C -> B). Nothing is general: no
graph, no groups, no status; one pass of whole-array numpy operations that reuse their
temporaries (``out=``) and never stack.

The dyad: with ``d = C - A``, ``along = (AB^2 - CB^2 + |d|^2) / (2 |d|^2)`` and
``h^2 = AB^2 / |d|^2 - along^2``, ``B = A + along d + h perp(d)`` where ``perp(x, y) = (-y, x)``
(B on the left of the directed line A -> C; ``h^2 < 0``: the dyad cannot be assembled and every
output is NaN there). With ``u = (B - A) / AB`` and ``w = (B - C) / CB`` the unit vectors of
links 2 and 3 and ``s = u x w`` (the sine of the angle from link 2 to link 3), differentiating
``AB u - CB w = C - A`` once and twice gives::

    theta2' = -(A' . w) / (AB s)          theta3' = -(A' . u) / (CB s)
    theta2'' = (R . w) / (AB s)           theta3'' = (R . u) / (CB s)
    R = -A'' + AB theta2'^2 u - CB theta3'^2 w

and the points follow as rigid-body motion: ``B' = theta3' perp(B - C)``,
``B'' = theta3'' perp(B - C) - theta3'^2 (B - C)``, ``E = A + r``,
``E' = A' + theta2' perp(r)``, ``E'' = A'' + theta2'' perp(r) - theta2'^2 r`` with ``r`` the
coupler point's local coordinates turned by theta2.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

# ----------------------------------------------------------------------------------------------
# pieces
# ----------------------------------------------------------------------------------------------


def _pair(n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A (2, n) buffer and its two rows: x and y stay contiguous, ``buf.T`` is the (n, 2) result."""
    buf = np.empty((2, n))
    return buf, buf[0], buf[1]


def _crank(phi: np.ndarray, oa: float):
    """Crank pin A = OA (cos phi, sin phi) and the unit direction (cos, sin), each (2, n)."""
    a, ax, ay = _pair(len(phi))
    np.cos(phi, out=ax)
    np.sin(phi, out=ay)
    unit = a.copy()
    a *= oa
    return a, unit


def _dyad(a: np.ndarray, ab: float, cb: float, c: tuple[float, float]):
    """B (2, n) on the left of A -> C, at ``ab`` from A and ``cb`` from C; NaN where h^2 < 0.

    Returns B and the offset ``d = C - A`` (2, n), reused by the caller as a temporary.
    """
    _d, dx, dy = _pair(a.shape[1])
    np.subtract(c[0], a[0], out=dx)
    np.subtract(c[1], a[1], out=dy)
    d2 = dx * dx
    d2 += dy * dy
    along = d2 + (ab * ab - cb * cb)
    along /= 2.0
    along /= d2                                        # (AB^2 - CB^2 + |d|^2) / (2 |d|^2)
    h = np.divide(ab * ab, d2, out=d2)
    h -= along * along
    with np.errstate(invalid="ignore"):
        np.sqrt(h, out=h)                              # NaN where h^2 < 0: not assembled
    b, bx, by = _pair(a.shape[1])
    np.multiply(along, dx, out=bx)
    bx -= h * dy
    bx += a[0]
    np.multiply(along, dy, out=by)
    by += h * dx
    by += a[1]
    return b


def _unit(p: np.ndarray, q: np.ndarray, length: float) -> np.ndarray:
    """(p - q) / length, (2, n); ``q`` a (2, n) array or a point (x, y)."""
    u, ux, uy = _pair(p.shape[1])
    np.subtract(p[0], q[0], out=ux)
    np.subtract(p[1], q[1], out=uy)
    u /= length
    return u


def _angle(u: np.ndarray) -> np.ndarray:
    """Angle of the unit vectors ``u`` (2, n), rad in (-pi, pi]."""
    return np.arctan2(u[1], u[0])


def _coupler_point(a: np.ndarray, u: np.ndarray, local: tuple[float, float]):
    """E = A + r and r = R(theta2) local, each (2, n)."""
    ex, ey = local
    r, rx, ry = _pair(a.shape[1])
    np.multiply(u[0], ex, out=rx)
    rx -= u[1] * ey
    np.multiply(u[1], ex, out=ry)
    ry += u[0] * ey
    return a + r, r


def _rigid_first(base: np.ndarray | None, rate: np.ndarray, r: np.ndarray) -> np.ndarray:
    """base' + rate perp(r), (2, n); ``base`` None for a fixed base point."""
    v, vx, vy = _pair(r.shape[1])
    np.multiply(rate, r[1], out=vx)
    np.negative(vx, out=vx)
    np.multiply(rate, r[0], out=vy)
    if base is not None:
        v += base
    return v


def _rigid_second(base: np.ndarray | None, rate: np.ndarray, accel: np.ndarray, r: np.ndarray) -> np.ndarray:
    """base'' + accel perp(r) - rate^2 r, (2, n); ``base`` None for a fixed base point."""
    w2 = rate * rate
    acc, ax, ay = _pair(r.shape[1])
    np.multiply(accel, r[1], out=ax)
    np.negative(ax, out=ax)
    ax -= w2 * r[0]
    np.multiply(accel, r[0], out=ay)
    ay -= w2 * r[1]
    if base is not None:
        acc += base
    return acc


# ----------------------------------------------------------------------------------------------
# the kernels
# ----------------------------------------------------------------------------------------------


def _positions(phi, oa, ab, cb, c, e_local):
    phi = np.ascontiguousarray(phi, dtype=float)
    a, crank_unit = _crank(phi, oa)
    b = _dyad(a, ab, cb, c)
    u = _unit(b, a, ab)
    w = _unit(b, c, cb)
    e, r = _coupler_point(a, u, e_local)
    return a, crank_unit, b, u, w, e, r


def fourbar_positions(phi: ArrayLike, OA: float, AB: float, CB: float, C: tuple[float, float],
                      E_local: tuple[float, float]) -> dict[str, np.ndarray]:
    """Positions of the four-bar O-A-B-C (O at the origin) over the crank angles ``phi``.

    Parameters
    ----------
    phi : array_like, shape (N,)
        Crank angles, rad (CCW from +x).
    OA, AB, CB : float
        Crank, coupler and rocker lengths, m.
    C : (float, float)
        The rocker's fixed pivot, m.
    E_local : (float, float)
        The coupler point in link 2's frame (origin A, x along A -> B), m.

    Returns
    -------
    dict
        ``A``, ``B``, ``E``: (N, 2) positions, m; ``theta2``, ``theta3``: (N,) angles of
        A -> B and C -> B, rad in (-pi, pi]. NaN where the dyad cannot be assembled.
    """
    a, _, b, u, w, e, _ = _positions(phi, OA, AB, CB, C, E_local)
    return {"A": a.T, "B": b.T, "E": e.T, "theta2": _angle(u), "theta3": _angle(w)}


def fourbar_kinematics(phi: ArrayLike, OA: float, AB: float, CB: float, C: tuple[float, float],
                       E_local: tuple[float, float]) -> dict[str, np.ndarray]:
    """Positions and first and second analogs of the four-bar O-A-B-C over ``phi``.

    Parameters
    ----------
    phi : array_like, shape (N,)
        Crank angles, rad (CCW from +x).
    OA, AB, CB : float
        Crank, coupler and rocker lengths, m.
    C : (float, float)
        The rocker's fixed pivot, m.
    E_local : (float, float)
        The coupler point in link 2's frame (origin A, x along A -> B), m.

    Returns
    -------
    dict
        For P in A, B, E: ``P`` (N, 2) m, ``dP`` (N, 2) m/rad, ``ddP`` (N, 2) m/rad^2; for
        k in 2, 3: ``thetak`` (N,) rad in (-pi, pi], ``dthetak`` (N,) rad/rad,
        ``ddthetak`` (N,) rad/rad^2. NaN where the dyad cannot be assembled (and where it is
        singular, ``u x w = 0``, the analogs are infinite or NaN).
    """
    a, crank_unit, b, u, w, e, r = _positions(phi, OA, AB, CB, C, E_local)
    da = _rigid_first(None, OA, crank_unit)            # A' = OA perp(cos, sin)
    dda = np.negative(a)                               # A'' = -A (O at the origin)
    s = u[0] * w[1]
    s -= u[1] * w[0]                                   # sin of the angle from link 2 to link 3
    t = da[0] * w[0]
    t += da[1] * w[1]
    dtheta2 = np.divide(t, s, out=t)
    dtheta2 /= -AB
    t = da[0] * u[0]
    t += da[1] * u[1]
    dtheta3 = np.divide(t, s, out=t)
    dtheta3 /= -CB
    rhs = np.multiply(u, AB * dtheta2 * dtheta2, out=np.empty_like(u))
    rhs -= CB * dtheta3 * dtheta3 * w
    rhs += a                                           # -A'' = A
    t = rhs[0] * w[0]
    t += rhs[1] * w[1]
    ddtheta2 = np.divide(t, s, out=t)
    ddtheta2 /= AB
    t = rhs[0] * u[0]
    t += rhs[1] * u[1]
    ddtheta3 = np.divide(t, s, out=t)
    ddtheta3 /= CB
    w *= CB                                            # w is now B - C
    db = _rigid_first(None, dtheta3, w)
    ddb = _rigid_second(None, dtheta3, ddtheta3, w)
    de = _rigid_first(da, dtheta2, r)
    dde = _rigid_second(dda, dtheta2, ddtheta2, r)
    return {"A": a.T, "dA": da.T, "ddA": dda.T, "B": b.T, "dB": db.T, "ddB": ddb.T,
            "E": e.T, "dE": de.T, "ddE": dde.T,
            "theta2": _angle(u), "dtheta2": dtheta2, "ddtheta2": ddtheta2,
            "theta3": np.arctan2(w[1], w[0]), "dtheta3": dtheta3, "ddtheta3": ddtheta3}
