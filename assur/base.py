"""The group protocol and the constraint machinery every group kind shares (docs/methods.md#analogs).

Shapes and conventions
----------------------
Everything is vectorised over a leading positions axis of length N.

- A *pose* of link k is an array ``(N, 3)``: ``x, y`` of the link's local origin (m) and
  ``theta``, the angle of its local x axis (rad, CCW from global +x). Poses travel in a
  ``dict`` link name -> array. First / second analogs (derivatives with respect to the input
  angle phi) use the same layout.
- Joints carry the local geometry of one kinematic pair (:class:`RevoluteJoint`,
  :class:`PrismaticJoint`). Each contributes two constraint equations ``Phi = 0``.

The plug-in contract of a group kind
------------------------------------
A kind subclasses :class:`Group` and fills in

- ``kind`` (registry name), ``branches`` (``(1, -1)`` when the closed form has two assembly
  branches, ``(1,)`` otherwise);
- ``_bind(links, joints, known)`` (classmethod): return an instance when this kind solves the
  group with these joints (roles of guide and slider included) or ``None``;
- ``_position(poses, branch)``: closed-form poses of the group's links from the known poses,
  returning ``(new_poses, assembled)`` where ``assembled`` is a boolean mask; positions that
  cannot be assembled may hold anything (they are replaced by NaN).

The public template methods :meth:`Group.position`, :meth:`Group.analogs` and
:meth:`Group.reactions` add the shared checks (closure, singularity relative to the mechanism
size) and the shared linear algebra (constraint Jacobian for analogs, its transpose for
reactions). Status codes per position: ``OK = 0``, ``CANNOT_ASSEMBLE = -1``, ``SINGULAR = -2``,
``NOT_CONVERGED = -4`` (a group solved by Newton's method was given a start but did not reach a
closed position from it; -3 is a batch's ``linkage.kinematics.batch.OTHER_BRANCH``).
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from dataclasses import dataclass
from typing import ClassVar, Mapping, Sequence

import numpy as np

__all__ = [
    "ANALOG_TOL",
    "SINGULAR_TOL",
    "OK",
    "CANNOT_ASSEMBLE",
    "SINGULAR",
    "NOT_CONVERGED",
    "RevoluteJoint",
    "PrismaticJoint",
    "DrivenPrismaticJoint",
    "Group",
    "GroupPosition",
    "GroupSolution",
    "rotate",
    "perp",
    "error_bound",
    "analog_size",
    "second_analog_excess",
    "flag_second_analogs",
    "global_point",
    "point_analogs",
]

OK, CANNOT_ASSEMBLE, SINGULAR = 0, -1, -2
#: Newton's method was given a start but did not converge, or converged to a point that does not close
NOT_CONVERGED = -4

#: relative closure residual above which a closed-form position counts as not assembled
CLOSURE_TOL = 1e-9
#: the status-OK guarantee: first analogs accurate to this, relative to the largest first analog
#: of the group and of the links it attaches to (second analogs: 10 times this)
ANALOG_TOL = 1e-8
#: contact points of a group closer than this fraction of the mechanism's size coincide
COINCIDENT = 1e-9
#: round-off model of a group's first analogs: relative error <= ROUNDOFF_FACTOR * eps / r**2
#: for conditioning r (measured factor <= 0.26 for every dyad kind in benchmarks/results_guarantee.md;
#: ten times that for a margin)
ROUNDOFF_FACTOR = 3.0
#: conditioning below which a group alone cannot keep the guarantee (about 2.6e-4)
SINGULAR_TOL = float(np.sqrt(ROUNDOFF_FACTOR * np.finfo(float).eps / ANALOG_TOL))
#: round-off model of a group's first analogs as their error reaches its second analogs through
#: the quadratic terms, next to a change point: CHANGE_FACTOR * eps / r**2 (see
#: :func:`second_analog_excess`; measured factor <= 0.03 over the change-point sweeps of
#: benchmarks/results_guarantee.md and denser ones, 0.2 for a margin)
CHANGE_FACTOR = 0.2

Poses = Mapping[str, np.ndarray]


# ----------------------------------------------------------------------------------------------
# small vectorised geometry
# ----------------------------------------------------------------------------------------------


def rotate(theta: np.ndarray, p) -> np.ndarray:
    """``Rot(theta) @ p`` for angles ``(N,)`` and a vector ``(2,)`` or ``(N, 2)`` -> ``(N, 2)``."""
    c, s = np.cos(theta), np.sin(theta)
    p = np.asarray(p, dtype=float)
    px, py = p[..., 0], p[..., 1]
    out = np.empty(np.broadcast_shapes(c.shape, px.shape) + (2,))
    out[..., 0] = c * px - s * py
    out[..., 1] = s * px + c * py
    return out


def perp(v: np.ndarray) -> np.ndarray:
    """``E @ v``: rotate vectors ``(..., 2)`` by +90 degrees."""
    out = np.empty(v.shape)
    out[..., 0] = -v[..., 1]
    out[..., 1] = v[..., 0]
    return out


def cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """z component of ``a x b`` for vectors ``(..., 2)``."""
    return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]


def dot(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return np.einsum("...i,...i->...", a, b)


def angle_of(v: np.ndarray) -> np.ndarray:
    """Direction angle (rad) of vectors ``(..., 2)``."""
    return np.arctan2(v[..., 1], v[..., 0])


def error_bound(ratio: np.ndarray, input_error, factor: float = ROUNDOFF_FACTOR) -> np.ndarray:
    """Bound ``(N,)`` of the relative error of a group's first analogs for its conditioning
    ``ratio``: ``factor * eps / r**2 + input_error / r`` (inf where r = 0); ``factor``: the
    kind's round-off factor (:attr:`Group.roundoff_factor`)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        own = np.where(ratio > 0, factor * np.finfo(float).eps / ratio**2, np.inf)
        return own + np.where(np.greater(input_error, 0), input_error / ratio, 0.0)


def analog_size(analogs, scale) -> np.ndarray:
    """The largest analog ``(N,)`` of some links: the largest of ``|w|`` and ``|v| / scale``
    (lengths in units of ``scale`` ``(N,)``, m) over ``analogs``, each three columns
    ``(vx, vy, w)`` of ``(N,)`` (or an ``(N, 3)`` array transposed)."""
    turn = move = 0.0
    for vx, vy, w in analogs:
        turn = np.maximum(turn, np.abs(w))
        move = np.maximum(move, vx * vx + vy * vy)
    return np.maximum(turn, np.sqrt(move) / scale)


def second_analog_excess(ratio: np.ndarray, input_error, rotation, first_size, second_size) -> np.ndarray:
    """Bound ``(N,)`` of the relative error a group's second analogs take from the error of its
    first analogs, which the quadratic terms bring into the second solve amplified by ``1 / r``:

    ``2 A (CHANGE_FACTOR * eps / r**2 + input_error / r) / r``,  ``A = w * min(1, s1 / s2)``

    ``w`` ``(N,)``: the largest rotation analog of the group's links and of the known links that
    guide its prismatic pairs (the quadratic terms the group's own first analogs enter carry
    these); ``s1``, ``s2``: the largest first and second analogs of the group and the links it
    hangs on (:func:`analog_size`). At a toggle the analogs grow like ``1 / r`` and ``1 / r**3``,
    so ``A ~ r`` and the term stays within the first analogs' bound; next to a change point they
    stay bounded while ``r`` goes to 0, and the term takes over (docs/numerics.md)."""
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        amplitude = rotation * np.where(second_size > first_size, first_size / second_size, 1.0)
        first = CHANGE_FACTOR * np.finfo(float).eps / ratio**2 + input_error / ratio
        return np.where(ratio > 0, 2.0 * amplitude * first / ratio, np.inf)


def second_analog_status(group: "Group", status, bound, ratio, input_error, scale, first, second):
    """Statuses and bounds ``(N,)`` of a group once its second analogs are solved.

    At status-OK positions the bound grows by a tenth of :func:`second_analog_excess` (the
    second analogs are promised ten times ``ANALOG_TOL``); a position whose bound then exceeds
    ``ANALOG_TOL`` becomes ``SINGULAR``. ``scale``: the group's size ``(N,)``, m; ``first``,
    ``second``: analogs of every link involved, link -> three columns ``(vx, vy, w)`` of
    ``(N,)`` (or an ``(N, 3)`` array transposed). Array operations only (the compiled kernel,
    :mod:`linkage.kinematics.kernel`, traces it as it is).
    """
    guides = {j.a for j in group.joints if j.kind == "P"}
    rotation = 0.0
    for link in sorted({*group.links, *(guides & set(group.known_links))}):
        rotation = np.maximum(rotation, np.abs(first[link][2]))
    links = (*group.known_links, *group.links)
    excess = second_analog_excess(ratio, input_error, rotation, analog_size([first[k] for k in links], scale),
                                  analog_size([second[k] for k in links], scale))
    ok = status == OK
    with np.errstate(invalid="ignore"):
        bound = np.where(ok, bound + excess / 10.0, bound)
    return np.where(ok & ~(bound <= ANALOG_TOL), SINGULAR, status), bound


def flag_second_analogs(group: "Group", status, bound, ratio, input_error, scale, first, second, solved):
    """:func:`second_analog_status`, and the group's analog dicts of ``(N, 3)`` arrays ``solved``
    set to NaN in place where a position is flagged."""
    flagged_status, bound = second_analog_status(group, status, bound, ratio, input_error, scale, first, second)
    flagged = flagged_status != status
    for values in solved:
        for v in values.values():
            v[flagged] = np.nan
    return flagged_status, bound


def global_point(pose: np.ndarray, local) -> np.ndarray:
    """Global position ``(N, 2)`` of a point with local coordinates ``local`` on a link."""
    return pose[:, :2] + rotate(pose[:, 2], local)


def point_analogs(pose, first, second, local, rho=None):
    """First and second analogs ``(N, 2)`` of a point fixed in a link (docs/methods.md#analogs);
    ``rho`` = ``Rot(theta) local`` ``(N, 2)`` when the caller has it."""
    rho = rotate(pose[:, 2], local) if rho is None else rho
    d1 = None if first is None else first[:, :2] + perp(rho) * first[:, 2:3]
    d2 = None
    if second is not None:
        d2 = second[:, :2] + perp(rho) * second[:, 2:3] - rho * first[:, 2:3] ** 2
    return d1, d2


# ----------------------------------------------------------------------------------------------
# joints: the two constraint equations of a pair, their Jacobian and quadratic terms
# ----------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class RevoluteJoint:
    """``r_a + Rot(theta_a) p_a - r_b - Rot(theta_b) p_b = 0``; ``lambda`` = force of b on a."""

    name: str
    a: str
    b: str
    pa: tuple[float, float]
    pb: tuple[float, float]
    kind: ClassVar[str] = "R"
    rows: ClassVar[int] = 2

    def local(self, link: str):
        """(local point on ``link``, other link, local point on the other link)."""
        return (self.pa, self.b, self.pb) if link == self.a else (self.pb, self.a, self.pa)

    def residual(self, poses: Poses) -> np.ndarray:
        return global_point(poses[self.a], self.pa) - global_point(poses[self.b], self.pb)

    def jacobian(self, poses: Poses) -> dict[str, np.ndarray]:
        out = {}
        for link, p, sign in ((self.a, self.pa, 1.0), (self.b, self.pb, -1.0)):
            rho = rotate(poses[link][:, 2], p)
            block = np.zeros((len(rho), 2, 3))
            block[:, 0, 0] = block[:, 1, 1] = sign
            block[:, :, 2] = sign * perp(rho)
            out[link] = block
        return out

    def quadratic(self, poses: Poses, first: Poses) -> np.ndarray:
        """Right-hand side terms of the second-analog system (gamma of docs/methods.md#analogs)."""
        ta, tb = first[self.a][:, 2:3], first[self.b][:, 2:3]
        return ta**2 * rotate(poses[self.a][:, 2], self.pa) - tb**2 * rotate(poses[self.b][:, 2], self.pb)

    def row_scale(self, size: float) -> np.ndarray:
        return np.array([1.0, 1.0])


@dataclass(frozen=True)
class PrismaticJoint:
    """Slider b's point ``p`` on guide line (``g``, ``u``) of link a; ``theta_b - theta_a = beta``.

    Equations: ``n . d = 0`` and ``theta_b - theta_a - beta = 0`` with ``u = Rot(theta_a) u_local``,
    ``n = E u``, ``d = r_b + Rot(theta_b) p - r_a - Rot(theta_a) g``. The slide is ``s = u . d``.
    ``lambda[0]`` is the normal force of the guide on the slider along ``n``; ``lambda[1]`` the
    moment of the guide on the slider about the slider point ``p``.
    """

    name: str
    a: str
    b: str
    g: tuple[float, float]
    u: tuple[float, float]
    p: tuple[float, float]
    beta: float
    kind: ClassVar[str] = "P"
    rows: ClassVar[int] = 2

    def frame(self, poses: Poses):
        """(u, n, ga, pb, d) in global coordinates, each ``(N, 2)``."""
        ta, tb = poses[self.a][:, 2], poses[self.b][:, 2]
        u = rotate(ta, self.u)
        ga, pb = rotate(ta, self.g), rotate(tb, self.p)
        d = poses[self.b][:, :2] + pb - poses[self.a][:, :2] - ga
        return u, perp(u), ga, pb, d

    def residual(self, poses: Poses) -> np.ndarray:
        u, n, _, _, d = self.frame(poses)
        angle = poses[self.b][:, 2] - poses[self.a][:, 2] - self.beta
        angle = (angle + np.pi) % (2 * np.pi) - np.pi
        return np.stack([dot(n, d), angle], axis=-1)

    def slide(self, poses: Poses, first: Poses | None = None, second: Poses | None = None):
        """Slide ``s = u . d`` and its first / second analogs (``None`` when not asked)."""
        u, n, ga, pb, d = self.frame(poses)
        s = dot(u, d)
        if first is None:
            return s, None, None
        ta1 = first[self.a][:, 2]
        d1 = first[self.b][:, :2] + perp(pb) * first[self.b][:, 2:3] - first[self.a][:, :2] - perp(ga) * ta1[:, None]
        s1 = ta1 * dot(n, d) + dot(u, d1)
        if second is None:
            return s, s1, None
        ta2, tb1 = second[self.a][:, 2], first[self.b][:, 2:3]
        d2 = (second[self.b][:, :2] + perp(pb) * second[self.b][:, 2:3] - pb * tb1**2
              - second[self.a][:, :2] - perp(ga) * ta2[:, None] + ga * ta1[:, None] ** 2)
        s2 = ta2 * dot(n, d) - ta1**2 * dot(u, d) + 2 * ta1 * dot(n, d1) + dot(u, d2)
        return s, s1, s2

    def jacobian(self, poses: Poses) -> dict[str, np.ndarray]:
        u, n, ga, pb, d = self.frame(poses)
        N = len(u)
        ja, jb = np.zeros((N, 2, 3)), np.zeros((N, 2, 3))
        ja[:, 0, :2] = -n
        ja[:, 0, 2] = -dot(u, d) - dot(n, perp(ga))
        ja[:, 1, 2] = -1.0
        jb[:, 0, :2] = n
        jb[:, 0, 2] = dot(n, perp(pb))
        jb[:, 1, 2] = 1.0
        return {self.a: ja, self.b: jb}

    def quadratic(self, poses: Poses, first: Poses) -> np.ndarray:
        u, n, ga, pb, d = self.frame(poses)
        ta, tb = first[self.a][:, 2:3], first[self.b][:, 2:3]
        d1 = first[self.b][:, :2] + perp(pb) * tb - first[self.a][:, :2] - perp(ga) * ta
        ta = ta[:, 0]
        rhs = dot(n, d) * ta**2 + 2 * ta * dot(u, d1) + dot(n, pb * tb**2 - ga * ta[:, None] ** 2)
        return np.stack([rhs, np.zeros_like(rhs)], axis=-1)

    def row_scale(self, size: float) -> np.ndarray:
        return np.array([1.0, size])


@dataclass(frozen=True)
class DrivenPrismaticJoint(PrismaticJoint):
    """A prismatic pair whose slide is driven: an actuator (a hydraulic cylinder) between two
    links, its extension an input of the mechanism.

    Three equations: the two of :class:`PrismaticJoint` and ``u . d - q = 0``, where ``q`` is the
    x coordinate of the pose of the *driver*, a pseudo-link named ``driver`` (``"K.s"`` for the
    pair K) whose pose ``(q, 0, 0)`` and analogs ``(q', 0, 0)``, ``(q'', 0, 0)`` the input sets.
    The driver is a known link of the group that holds the pair, so the analogs and the
    kinetostatics need nothing else: ``lambda[2]`` is the force the actuator exerts on the slider
    along ``u`` (on the guide link, its opposite), the balancing force of the input (N), and the
    load the group transmits to the driver is ``(-lambda[2], 0, 0)``.
    """

    driver: str = ""
    kind: ClassVar[str] = "P"
    rows: ClassVar[int] = 3

    def residual(self, poses: Poses) -> np.ndarray:
        u, _, _, _, d = self.frame(poses)
        return np.concatenate([super().residual(poses), (dot(u, d) - poses[self.driver][:, 0])[:, None]], axis=1)

    def jacobian(self, poses: Poses) -> dict[str, np.ndarray]:
        u, n, ga, pb, d = self.frame(poses)
        two = super().jacobian(poses)
        N = len(u)
        out = {}
        # row 2: d(u . d) = -u . dr_a + (n . d - u . E ga) dtheta_a + u . dr_b + u . E pb dtheta_b
        for link, rows_ab, along, turn in ((self.a, two[self.a], -u, dot(n, d) - dot(u, perp(ga))),
                                           (self.b, two[self.b], u, dot(u, perp(pb)))):
            block = np.zeros((N, 3, 3))
            block[:, :2] = rows_ab
            block[:, 2, :2] = along
            block[:, 2, 2] = turn
            out[link] = block
        driver = np.zeros((N, 3, 3))
        driver[:, 2, 0] = -1.0
        out[self.driver] = driver
        return out

    def quadratic(self, poses: Poses, first: Poses) -> np.ndarray:
        u, n, ga, pb, d = self.frame(poses)
        ta, tb = first[self.a][:, 2:3], first[self.b][:, 2:3]
        d1 = first[self.b][:, :2] + perp(pb) * tb - first[self.a][:, :2] - perp(ga) * ta
        ta = ta[:, 0]
        slide = dot(u, d) * ta**2 - 2 * ta * dot(n, d1) + dot(u, pb * tb**2 - ga * ta[:, None] ** 2)
        return np.concatenate([super().quadratic(poses, first), slide[:, None]], axis=1)

    def row_scale(self, size: float) -> np.ndarray:
        return np.array([1.0, size, 1.0])


Joint = RevoluteJoint | PrismaticJoint


# ----------------------------------------------------------------------------------------------
# the group protocol
# ----------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class GroupPosition:
    """Result of :meth:`Group.position`: poses of the group's links and a status per position."""

    poses: dict[str, np.ndarray]
    status: np.ndarray
    jacobian_sign: np.ndarray  # sign of det of the group Jacobian (0 where not assembled)
    conditioning: np.ndarray   # :meth:`Group.conditioning` ratio (NaN where not assembled)
    error_bound: np.ndarray    # bound of the relative error of the first analogs (inf: not assembled)


@dataclass(frozen=True)
class GroupSolution(GroupPosition):
    """Result of :meth:`Group.solve`: a :class:`GroupPosition` with the group's analogs.

    ``first`` and ``second`` map each of the group's links to ``(N, 3)`` analogs (NaN where the
    status is not OK), or are ``None`` when not asked for. Where ``second`` is solved,
    ``error_bound`` also holds a tenth of the second analogs' own term (:func:`flag_second_analogs`).
    """

    first: dict[str, np.ndarray] | None = None
    second: dict[str, np.ndarray] | None = None


class Group(ABC):
    """Base class of Assur group solvers (see the module docstring for the plug-in contract).

    Attributes
    ----------
    links : tuple of str
        The group's links in the kind's order (e.g. RRP: the link with the external R first).
    joints : tuple of Joint
        Every pair of the group (internal and external).
    size : float
        Characteristic length of the mechanism (m), for scale-free tolerances.
    """

    kind: ClassVar[str] = ""
    group_class: ClassVar[str] = "II"
    branches: ClassVar[tuple[int, ...]] = (1,)
    #: the kind's round-off model: its first analogs' relative error <= roundoff_factor * eps / r**2
    #: for its :meth:`conditioning` r (calibrated per measure against 50-digit references)
    roundoff_factor: ClassVar[float] = ROUNDOFF_FACTOR

    @property
    def singular_tol(self) -> float:
        """Conditioning below which the group alone cannot keep the guarantee."""
        return float(np.sqrt(self.roundoff_factor * np.finfo(float).eps / ANALOG_TOL))

    def __init__(self, links: Sequence[str], joints: Sequence[Joint], size: float = 1.0):
        self.links = tuple(links)
        self.joints = tuple(joints)
        self.size = float(size) if np.ndim(size) == 0 else np.asarray(size, dtype=float)
        touched = {j.a for j in joints} | {j.b for j in joints} | {getattr(j, "driver", j.a) for j in joints}
        self.known_links = tuple(sorted(touched - set(links)))

    # -- binding -------------------------------------------------------------------------------
    @classmethod
    def bind(cls, links: Sequence[str], joints: Sequence[Joint], known: set[str], size: float = 1.0):
        """An instance of this kind for the group, or ``None`` when this kind does not solve it."""
        return cls._bind(tuple(links), tuple(joints), set(known), size)

    @classmethod
    @abstractmethod
    def _bind(cls, links, joints, known, size):
        """Hook: an instance when this kind solves the group, else ``None``."""

    def __repr__(self) -> str:
        return f"{self.group_class}-{self.kind}({','.join(self.links)})"

    # -- position ------------------------------------------------------------------------------
    def position(self, poses: Poses, branch: int = 1, input_error=0.0, start: Poses | None = None) -> GroupPosition:
        """Poses of the group's links given the known ``poses``; checks closure and singularity.

        A position is singular (status -2) where the bound of the relative error of the first
        analogs, ``roundoff_factor * eps / r**2 + input_error / r`` for the group's
        :meth:`conditioning` r, exceeds ``ANALOG_TOL``: the group's own round-off plus the error
        of the known links' analogs (``input_error``, scalar or ``(N,)``) amplified by the solve.
        ``start``: poses of the group's links near the wanted solution, for kinds solved
        iteratively (:class:`assur.generic.NewtonGroup`); closed forms do not use it.
        """
        if branch not in self.branches:
            raise ValueError(f"{self!r}: branch must be one of {self.branches}, got {branch!r}")
        new, assembled = self._position(poses, branch)
        return self._checked(poses, new, assembled, input_error)

    def _checked(self, poses: Poses, new: dict, assembled: np.ndarray, input_error=0.0) -> GroupPosition:
        """The closure and singularity checks of :meth:`position` on placed poses ``new``."""
        merged = {**poses, **new}
        residual = self.residual(merged)
        closure = np.max(np.abs(residual), axis=1) if residual.size else np.zeros(len(assembled))
        assembled = assembled & np.isfinite(closure) & (closure <= CLOSURE_TOL * self.size)
        status = np.where(assembled, OK, CANNOT_ASSEMBLE)
        sign = np.zeros(len(status))
        conditioning = np.full(len(status), np.nan)
        bound = np.full(len(status), np.inf)
        if assembled.any():
            regular = {k: v[assembled] for k, v in merged.items()}
            ratio, det_sign = self.conditioning(self.jacobians(regular)[0], regular)
            sign[assembled] = det_sign
            conditioning[assembled] = ratio
            incoming = np.broadcast_to(np.asarray(input_error, float), status.shape)[assembled]
            bound[assembled] = error_bound(ratio, incoming, self.roundoff_factor)
            status[assembled & ~(bound <= ANALOG_TOL)] = SINGULAR
        for k in new:
            new[k] = np.where(assembled[:, None], new[k], np.nan)
        return GroupPosition(new, status, sign, conditioning, bound)

    @abstractmethod
    def _position(self, poses: Poses, branch: int):
        """Hook: ``(new_poses, assembled)`` in closed form (see the module docstring)."""

    def assembly_failure(self, poses: Poses) -> str | None:
        """Hook: the dimensional reason why the group assembles at none of the known ``poses``
        (e.g. ``"|AC| >= 2.1 m but AB + CB = 2 m"``), or None when there is none to tell."""
        return None

    def assembly_margin(self, poses: Poses) -> np.ndarray | None:
        """Hook: ``(N,)`` m, by how much the group closes at the known ``poses`` (negative where it
        cannot be assembled, 0 at a limit position), for the kinds where one number says it;
        None otherwise."""
        return None

    # -- the constraint system -----------------------------------------------------------------
    def residual(self, poses: Poses) -> np.ndarray:
        """Stacked constraint residuals ``(N, 2 * n_joints)`` (prismatic angle rows scaled to m)."""
        return np.concatenate([j.residual(poses) * j.row_scale(self.size) for j in self.joints], axis=1)

    def jacobians(self, poses: Poses) -> tuple[np.ndarray, dict[str, np.ndarray]]:
        """``Phi_q`` ``(N, m, m)`` for the group's links and ``Phi_k`` blocks ``(N, m, 3)``."""
        N = len(next(iter(poses.values())))
        m = self.row_count
        col = {link: 3 * i for i, link in enumerate(self.links)}
        phi_q = np.zeros((N, m, 3 * len(self.links)))
        phi_k = {k: np.zeros((N, m, 3)) for k in self.known_links}
        for joint, rows in zip(self.joints, self.joint_rows):
            for link, block in joint.jacobian(poses).items():
                if link in col:
                    phi_q[:, rows, col[link] : col[link] + 3] += block
                else:
                    phi_k[link][:, rows, :] += block
        return phi_q, phi_k

    @property
    def row_count(self) -> int:
        """Number of constraint equations: two per pair, three for a driven prismatic pair."""
        return sum(j.rows for j in self.joints)

    @property
    def joint_rows(self) -> list[slice]:
        """The rows of each joint (in :attr:`joints` order) in the stacked constraint system."""
        out, start = [], 0
        for j in self.joints:
            out.append(slice(start, start + j.rows))
            start += j.rows
        return out

    def contact_points(self, poses: Poses) -> np.ndarray:
        """Global points ``(N, n_joints, 2)`` where the group's pairs act, m.

        A revolute pair acts at its pin; a prismatic pair at the slider's point on the guide.
        """
        points = []
        for j in self.joints:
            if isinstance(j, RevoluteJoint):
                points.append(global_point(poses[j.a], j.pa))
            else:
                points.append(global_point(poses[j.b], j.p))
        return np.stack(points, axis=1)

    def scale(self, poses: Poses, contacts: np.ndarray | None = None) -> np.ndarray:
        """The group's own length scale ``(N,)``, m: the largest distance between the points where
        its pairs act; at least the round-off of their coordinates and :data:`COINCIDENT` times the
        mechanism's size (points closer than that coincide: a Scotch yoke's pin and slider points),
        so that round-off in coinciding points does not enter the conditioning."""
        contacts = self.contact_points(poses) if contacts is None else contacts
        spread = np.linalg.norm(contacts[:, :, None, :] - contacts[:, None, :, :], axis=-1)
        floor = np.maximum(1e-12 * np.max(np.abs(contacts), axis=(1, 2)), COINCIDENT * self.size)
        return np.maximum(np.max(spread, axis=(1, 2)), floor)

    def conditioning(self, phi_q: np.ndarray, poses: Poses) -> tuple[np.ndarray, np.ndarray]:
        """Scale-free conditioning of the group Jacobian and the sign of its determinant.

        The measure is the Hadamard ratio ``|det J| / prod(|row_i|)`` of the group Jacobian made
        dimensionless *at the group's own scale* ``L`` (the largest distance between the points
        where its pairs act, see :meth:`contact_points`): each link's rotation column is taken
        about the centroid of that link's contact points (a column operation that leaves the
        determinant unchanged but frees the measure from where the local origin lies) and
        divided by ``L``; angle rows of prismatic pairs are multiplied by ``L``. The ratio is 1
        for orthogonal rows and falls to 0 at a singular (toggle, parallel-guide) position; for
        the RRR dyad it behaves like the sine of the transmission angle. It does not depend on
        the size of the rest of the mechanism, on its units or on where the group lies.

        Parameters
        ----------
        phi_q : ndarray, shape (N, m, m)
            The group Jacobian (:meth:`jacobians`).
        poses : dict
            Poses ``(N, 3)`` of the group's and known links.

        Returns
        -------
        ratio : ndarray, shape (N,)
            The conditioning measure in [0, 1].
        sign : ndarray, shape (N,)
            Sign of ``det(phi_q)``.
        """
        scaled = self.scaled_jacobian(phi_q, poses)
        det = np.linalg.det(scaled)
        norms = np.prod(np.linalg.norm(scaled, axis=2), axis=1)
        return np.abs(det) / np.where(norms > 0, norms, 1.0), np.sign(det)

    def scaled_jacobian(self, phi_q: np.ndarray, poses: Poses) -> np.ndarray:
        """The group Jacobian ``(N, m, m)`` made dimensionless at the group's own scale ``L``
        (:meth:`scale`): each link's rotation column taken about the centroid of that link's
        contact points (a column operation that leaves the determinant unchanged) and divided by
        ``L``, the angle rows of prismatic pairs multiplied by ``L``."""
        contacts = self.contact_points(poses)                          # (N, J, 2)
        scale = self.scale(poses, contacts)[:, None, None]
        scaled = phi_q.copy()
        for i, link in enumerate(self.links):
            mine = [r for r, j in enumerate(self.joints) if link in (j.a, j.b)]
            rho = contacts[:, mine].mean(axis=1) - poses[link][:, :2]
            c = 3 * i
            scaled[:, :, c + 2] += scaled[:, :, c] * rho[:, None, 1] - scaled[:, :, c + 1] * rho[:, None, 0]
            scaled[:, :, c + 2:c + 3] /= scale
        angle_rows = [rows.start + 1 for rows, j in zip(self.joint_rows, self.joints) if isinstance(j, PrismaticJoint)]
        scaled[:, angle_rows, :] *= scale
        return scaled

    # -- analogs -------------------------------------------------------------------------------
    def analogs(self, poses: Poses, first: Poses, second: Poses | None = None, valid=None):
        """First (and, if ``second`` of the known links is given, second) analogs of the group.

        Solves ``Phi_q q' = -Phi_k q'_k`` and ``Phi_q q'' = -Phi_k q''_k + gamma`` (docs/methods.md#analogs).
        Positions outside ``valid`` (default: where the group is assembled and not singular)
        give NaN.
        """
        phi_q, phi_k = self.jacobians(poses)
        ok = np.all(np.isfinite(phi_q), axis=(1, 2))
        if valid is None:
            ratio = np.zeros(len(ok))
            if ok.any():
                ratio[ok] = self.conditioning(phi_q[ok], {k: v[ok] for k, v in poses.items()})[0]
            ok &= ratio >= self.singular_tol
        else:
            ok &= np.asarray(valid, bool)
        phi_q[~ok] = np.eye(phi_q.shape[1])
        rhs1 = -sum(np.einsum("nij,nj->ni", phi_k[k], first[k]) for k in self.known_links)
        q1 = np.linalg.solve(phi_q, rhs1[..., None])[..., 0]
        q1[~ok] = np.nan
        d1 = self._split(q1)
        if second is None:
            return d1, None
        all_first = {**first, **d1}
        gamma = np.concatenate([j.quadratic(poses, all_first) for j in self.joints], axis=1)
        rhs2 = gamma - sum(np.einsum("nij,nj->ni", phi_k[k], second[k]) for k in self.known_links)
        q2 = np.linalg.solve(phi_q, rhs2[..., None])[..., 0]
        q2[~ok] = np.nan
        return d1, self._split(q2)

    def solve(self, poses: Poses, first: Poses | None = None, second: Poses | None = None, branch: int = 1,
              input_error=0.0, frames=None, out=None, start: Poses | None = None) -> GroupSolution:
        """Positions, statuses and analogs in one call: :meth:`position` then :meth:`analogs`.

        ``first`` (and ``second``) are the analogs of the known links; without them only
        positions are solved. ``out``: ``(poses, first, second)``, dicts of ``(N, 3)`` arrays
        (or None) that receive the group's results. ``frames`` (a cache of link frames shared
        by the fast paths) is not used here; ``start``: see :meth:`position`. Kinds with a fast
        path (the dyads) override this with the same results computed elementwise; this generic
        version is their oracle.
        """
        placed = self.position(poses, branch, input_error, start)
        status, bound = placed.status, placed.error_bound
        d1 = d2 = None
        if first is not None:
            merged = {**poses, **placed.poses}
            d1, d2 = self.analogs(merged, first, second, valid=status == OK)
            if d2 is not None:     # the second analogs' own bound (docs/numerics.md)
                status, bound = flag_second_analogs(
                    self, status, bound, placed.conditioning, input_error, self.scale(merged),
                    {k: v.T for k, v in {**first, **d1}.items()}, {k: v.T for k, v in {**second, **d2}.items()},
                    (d1, d2))
        if out is not None:
            for into, got in zip(out, (placed.poses, d1, d2)):
                for link, value in (got or {}).items():
                    into[link][...] = value
        return GroupSolution(placed.poses, status, placed.jacobian_sign, placed.conditioning, bound, d1, d2)

    def _split(self, q: np.ndarray) -> dict[str, np.ndarray]:
        return {link: q[:, 3 * i : 3 * i + 3] for i, link in enumerate(self.links)}

    # -- reactions -----------------------------------------------------------------------------
    def reactions(self, poses: Poses, loads: Poses, valid=None, frames=None):
        """Joint reactions from the equilibrium of the group's links.

        Parameters
        ----------
        poses : dict
            Poses of the group's and known links.
        loads : dict
            Generalized applied loads ``(N, 3)`` on each of the group's links: ``Fx, Fy`` (N)
            and the moment about the link's local origin (N m), inertia loads included.
        valid : array_like of bool, optional
            Positions to solve (others give NaN), e.g. where the motion is assembled and regular.
        frames : dict, optional
            Link frames ``(x, y, cos, sin, theta)`` the caller has computed (used by closed-form
            kinds; the generic path builds its Jacobian from ``poses``).

        Returns
        -------
        multipliers : dict of joint name -> ``(N, 2)``
            For a revolute joint the force of link b on link a; for a prismatic joint the normal
            force of the guide on the slider and its moment about the slider point.
        transmitted : dict of known link -> ``(N, 3)``
            Generalized loads the group puts on each known link through its external joints.
        """
        phi_q, phi_k = self.jacobians(poses)
        ok = np.all(np.isfinite(phi_q), axis=(1, 2))
        if valid is not None:
            ok &= np.asarray(valid, bool)
        phi_q[~ok] = np.eye(phi_q.shape[1])
        q = np.concatenate([loads[link] for link in self.links], axis=1)
        lam = np.linalg.solve(np.transpose(phi_q, (0, 2, 1)), -q[..., None])[..., 0]
        lam[~ok] = np.nan
        multipliers = {j.name: lam[:, rows] for rows, j in zip(self.joint_rows, self.joints)}
        transmitted = {k: np.einsum("nji,nj->ni", phi_k[k], lam) for k in self.known_links}
        return multipliers, transmitted
