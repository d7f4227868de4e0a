"""Kinematic analysis: run the Assur groups in order over a batch of input angles.

>>> import numpy as np, linkage
>>> mech = linkage.load("slider_crank")
>>> motion = linkage.analyze(mech, np.radians([0.0, 90.0]))
>>> motion.point("B").shape
(2, 2)

Results are exact: positions by each group's closed form, first and second transfer functions
(analogs, derivatives with respect to the input angle phi) from the group constraint Jacobians
(docs/methods.md#analogs); real velocities and accelerations follow as ``q' omega`` and
``q'' omega^2 + q' eps``.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field
from typing import Iterable, Literal, Mapping

import numpy as np
from numpy.typing import ArrayLike

from assur.base import (
    ANALOG_TOL,
    CANNOT_ASSEMBLE,
    NOT_CONVERGED,
    OK,
    SINGULAR,
    point_analogs,
)
from assur.rows import frame, xy

from ..errors import AssemblyError, ConvergenceError, InputError
from ..model.input_laws import ANGLE_TOL
from ..model.mechanism import Mechanism, Prismatic
from ..structure import Structure, structure_of
from .assembly import assembly_plans, place_group
from .inputs import input_state
from .kernel import run_kernel

__all__ = ["Motion", "analyze", "input_sweep", "SWEEP", "BranchWarning",
           "parse_quantity", "table_positions_deg", "angle_in_half_turn", "position_column"]


#: input angles of :func:`input_sweep` (a turn in 360 steps, both ends included, or the input range)
SWEEP = 361


class BranchWarning(UserWarning):
    """A group changes assembly mode between analysed positions (it passes a singular position)."""


# ----------------------------------------------------------------------------------------------
# the result
# ----------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Motion:
    """Kinematics of a mechanism over N input angles.

    Attributes
    ----------
    phi : ndarray, shape (N,)
        The first input's coordinates: angles, rad, or for a slide input its slide, m
        (``mechanism.coordinate``).
    poses, first, second : dict of link -> ndarray (N, 3)
        Poses ``(x, y, theta)`` and their first / second analogs (``None`` when not computed).
    status : ndarray of int, shape (N,)
        0 ok, -1 cannot be assembled, -2 singular (analogs unbounded; they are NaN there), -4 a
        group solved by Newton's method did not converge (docs/groups.md; values NaN there).
    omega, eps : ndarray (N,) or None
        Input angular velocity (rad/s) and acceleration (rad/s^2) for real velocities (a slide
        input's speed, m/s, and acceleration, m/s^2).
    conditioning : dict of group label -> ndarray (N,)
        Each analysed group's scale-free distance from a singular position (the conditioning
        ratio of ``assur.Group.conditioning``: 1 well conditioned, 0 singular; NaN where the
        group is not assembled), e.g. ``motion.conditioning["II-RRR(2,3)"]``.
    error_bound : ndarray (N,)
        Bound of the relative error of the first analogs at each position (the status-OK
        guarantee: at most ``assur.ANALOG_TOL`` = 1e-8 where the status is 0; inf where a
        group is not assembled).
    """

    mechanism: Mechanism
    structure: Structure
    phi: np.ndarray
    poses: dict[str, np.ndarray]
    first: dict[str, np.ndarray] | None
    second: dict[str, np.ndarray] | None
    status: np.ndarray
    omega: np.ndarray | None = None
    eps: np.ndarray | None = None
    conditioning: dict[str, np.ndarray] | None = None
    error_bound: np.ndarray | None = None
    _turns: dict = field(default_factory=dict, init=False, repr=False, compare=False)

    def arm(self, link: str, local) -> np.ndarray:
        """``Rot(theta) p`` ``(N, 2)``, m: the vector from ``link``'s origin to its local point
        ``p`` (``(2,)``, or ``(N, 2)`` per position) in global axes, the link's cosines and sines
        computed once per motion (and the arm of a ``(2,)`` point too: do not write into it)."""
        key = ("arm", link, tuple(float(c) for c in local)) if np.ndim(local) == 1 else None
        if key in self._turns:
            return self._turns[key]
        _, _, c, s, _ = self.frame(link)
        px, py = xy(local)
        arm = np.column_stack([c * px - s * py, s * px + c * py])
        if key is not None:
            self._turns[key] = arm
        return arm

    def frame(self, link: str) -> tuple[np.ndarray, ...]:
        """``(x, y, cos theta, sin theta, theta)`` of ``link``, each ``(N,)`` (the solvers' link
        frame, :func:`assur.rows.frame`), computed once per motion."""
        if link not in self._turns:
            self._turns[link] = frame(self.poses[link])
        return self._turns[link]

    @property
    def joints(self) -> dict:
        """Pair name -> solver-side joint (from the structure)."""
        return self.structure.joints

    @property
    def success(self) -> np.ndarray:
        return self.status == OK

    # -- points, links, slides -----------------------------------------------------------------
    def point(self, name: str) -> np.ndarray:
        """Global position ``(N, 2)`` of a named point, m."""
        return self.local_point(*self._owner(name))[0]

    def point_analogs(self, name: str) -> tuple[np.ndarray, np.ndarray | None]:
        """First and second analogs ``(N, 2)`` of a named point, m/rad and m/rad^2."""
        self._need(1)
        return self.local_point(*self._owner(name))[1:]

    def local_point(self, link: str, local) -> tuple[np.ndarray, np.ndarray | None, np.ndarray | None]:
        """Global position ``(N, 2)`` and first and second analogs of the point ``local``
        (``(2,)``, m) fixed in ``link`` (None beyond the order computed), computed once per motion
        (by the compiled kernel, where it ran, for named points and centres of mass)."""
        key = ("at", link, local if type(local) is tuple else (float(local[0]), float(local[1])))
        got = self._turns.get(key)
        if got is None:
            kernel = self._turns.get("kernel points")     # linkage.kinematics.kernel_rows.PointRows
            got = kernel.get(key[1:]) if kernel is not None else None
            if got is None:
                arm, pose = self.arm(link, local), self.poses[link]
                analogs = (None, None) if self.first is None else \
                    point_analogs(pose, self.first[link], self.second and self.second[link], local, arm)
                got = (pose[:, :2] + arm, *analogs)
            self._turns[key] = got
        return got

    def _owner(self, name: str) -> tuple[str, tuple[float, float]]:
        """``(link, local point)`` of a named point (kept on the mechanism)."""
        owners = self.mechanism.cache.setdefault("point owners", {})
        got = owners.get(name)
        if got is None:
            link = self.mechanism.point_link(name)
            local = self.mechanism.links[link].points[name]
            got = owners[name] = (link, (float(local[0]), float(local[1])))
        if got[0] not in self.poses:
            raise InputError(f"point '{name}' (link '{got[0]}') was not among the requested outputs")
        return got

    def _need(self, order: int) -> None:
        have = 0 if self.first is None else 1 if self.second is None else 2
        if have < order:
            raise InputError(f"analogs of order {order} were not computed (analyze(..., order={order}))")

    def quantity(self, name: str) -> tuple[np.ndarray, np.ndarray | None, np.ndarray | None]:
        """Value and first / second analogs of ``"P.x"``, ``"P.y"``, ``"L.theta"`` or ``"K.s"``."""
        kind, obj, axis = parse_quantity(self.mechanism, name)
        if kind == "point":
            return tuple(None if v is None else v[:, axis] for v in self.local_point(*self._owner(obj)))
        if kind == "link":
            first, second = (None if d is None else d[obj][:, 2] for d in (self.first, self.second))
            return self.poses[obj][:, 2], first, second
        joint = self.joints[obj]
        return joint.slide(self.poses, self.first, self.second)

    def velocity(self, name: str) -> np.ndarray:
        """Real velocity ``q' omega``: of a point ``(N, 2)`` given its name, or of a quantity
        (``"B.x"``, ``"3.theta"``, ``"K.s"``) ``(N,)``."""
        self._need_speed()
        d1 = self._analogs(name)[0]
        return d1 * (self.omega[:, None] if d1.ndim == 2 else self.omega)

    def acceleration(self, name: str) -> np.ndarray:
        """Real acceleration ``q'' omega^2 + q' eps`` of a point ``(N, 2)`` or a quantity ``(N,)``."""
        self._need_speed()
        self._need(2)
        d1, d2 = self._analogs(name)
        w, e = (self.omega[:, None], self.eps[:, None]) if d1.ndim == 2 else (self.omega, self.eps)
        return d2 * w**2 + d1 * e

    def _analogs(self, name: str):
        if name in self.mechanism.point_names:
            return self.point_analogs(name)
        return self.quantity(name)[1:]

    def _need_speed(self) -> None:
        if self.omega is None:
            raise InputError("real velocities need omega (analyze(..., omega=..., eps=...))")

    # -- table ---------------------------------------------------------------------------------
    def columns(self, direction: int | None = None) -> dict[str, np.ndarray]:
        """The standard table (the one ``linkage analyze`` prints), in the table conventions of
        :func:`table_positions_deg` and :func:`angle_in_half_turn`.

        Columns: ``i`` (position number from 1), ``phi_deg`` (the input angle travelled from the
        first row along the table, deg: 0, 30, ... 360 for a turn in 12 steps, in either sense of
        rotation); per point ``P.x P.y P.x' P.y' P.x'' P.y''``; per moving link
        ``L.theta L.theta' L.theta''`` (``L.theta`` the link's absolute angle, CCW from +x, rad, in
        (-pi, pi]; for the input link it is the absolute input angle phi); per prismatic pair
        ``K.s K.s' K.s''``. SI units: m, rad; ``'`` and ``''`` are d/dphi and d2/dphi2 of the
        absolute input angle. The tables for people (``linkage analyze``, the report folder, the
        course keys) give the first analogs per rad turned instead, d/dpsi = ``direction`` d/dphi
        (:func:`linkage.report.tables.per_turned_angle`; docs/conventions.md).

        Parameters
        ----------
        direction : {1, -1}, optional
            The sense that ``phi_deg`` counts in. Default: the sense of the analysed angles (of
            their first step); for a single angle the sign of a nonzero ``omega``, else +1.
        """
        mech = self.mechanism
        direction = self.direction if direction is None else direction
        if direction not in (1, -1):
            raise InputError(f"direction must be +1 or -1, got {direction!r}")
        cols = self.position_columns(direction)
        primes = ("", "'", "''")
        for p in mech.point_names:
            if mech.point_link(p) in self.poses:
                values = {a: self.quantity(f"{p}.{a}") for a in "xy"}
                for k, prime in enumerate(primes):
                    for a in "xy":
                        if values[a][k] is not None:
                            cols[f"{p}.{a}{prime}"] = values[a][k]
        quantities = [f"{link}.theta" for link in mech.moving_links if link in self.poses]
        quantities += [f"{name}.s" for name, j in sorted(self.joints.items())
                       if j.kind == "P" and j.a in self.poses and j.b in self.poses]
        for q in quantities:
            for prime, arr in zip(primes, self.quantity(q)):
                if arr is not None:
                    cols[q + prime] = angle_in_half_turn(arr) if q.endswith(".theta") and not prime else arr
        return cols

    def position_columns(self, direction: int | None = None) -> dict[str, np.ndarray]:
        """The leading columns of every table: ``i`` and the position column (:func:`position_column`)."""
        direction = self.direction if direction is None else direction
        coordinate = self.mechanism.coordinate
        values = table_positions_deg(self.phi, direction) if coordinate.is_angle else self.phi.copy()
        return {"i": np.arange(1, len(self.phi) + 1), position_column(self.mechanism): values}

    @property
    def direction(self) -> int:
        """The sense of the table: of the first step between the angles; for a single angle the
        sign of a nonzero omega; else +1."""
        sense = _sense(self.phi)
        if sense is None and self.omega is not None:
            moving = self.omega[np.isfinite(self.omega) & (self.omega != 0)]
            sense = (1 if moving[0] > 0 else -1) if len(moving) else None
        return 1 if sense is None else sense


def _sense(phi: np.ndarray) -> int | None:
    """+1 / -1: the sign of the first nonzero step of ``phi``; None when there is none."""
    steps = np.diff(phi)
    steps = steps[steps != 0]
    return (1 if steps[0] > 0 else -1) if len(steps) else None


def position_column(mech: Mechanism) -> str:
    """Name of a table's position column: ``"phi_deg"`` (the input angle travelled from the first
    row, deg) when the first input is a crank, ``"s"`` (the input's slide, m, as in its pair's
    ``K.s`` column) when it is a slide."""
    return "phi_deg" if mech.coordinate.is_angle else "s"


def table_positions_deg(phi: ArrayLike, direction: int | None = None) -> np.ndarray:
    """The ``phi_deg`` column of every table: the input angle travelled from the first row along
    the table, deg: ``direction (phi - phi[0])`` with ``direction`` (default) the sense of the
    table's first step. Over a turn it runs 0 .. 360 whatever the sense of rotation; over an
    input range [a, b], 0 .. |b - a|. Rounded to 1e-10 deg, so that table steps read 30, not
    29.999999999999996 (far below the rounding of the angles themselves, ~1e-13 deg).

    >>> table_positions_deg(np.radians([10.0, -20.0, -50.0])).tolist()
    [0.0, 30.0, 60.0]
    """
    phi = np.atleast_1d(np.asarray(phi, dtype=float))
    if not len(phi):
        return phi.copy()
    if direction is None:
        direction = _sense(phi) or 1
    return np.round(np.degrees(direction * (phi - phi[0])), 10) + 0.0


def angle_in_half_turn(angle: ArrayLike) -> np.ndarray:
    """Angles (rad) folded into (-pi, pi], the range of every direction angle in tables (link
    angles ``L.theta``; reaction directions in degrees use the same range, (-180, 180]).

    >>> angle_in_half_turn(np.array([np.pi, -np.pi, 3 * np.pi / 2, 0.0])).round(6).tolist()
    [3.141593, 3.141593, -1.570796, 0.0]
    """
    angle = np.asarray(angle, dtype=float)
    return np.pi - np.mod(np.pi - angle, 2 * np.pi)


def parse_quantity(mech: Mechanism, name: str) -> tuple[str, str, int]:
    """``("point", P, 0|1)``, ``("link", L, 2)`` or ``("slide", K, 0)`` for a quantity name."""
    obj, _, coord = name.rpartition(".")
    if coord in ("x", "y") and any(obj in lk.points for lk in mech.links.values()):
        return "point", obj, "xy".index(coord)
    if coord == "theta" and obj in mech.links and obj != mech.frame:
        return "link", obj, 2
    if coord == "s" and isinstance(mech.pairs.get(obj), Prismatic):
        return "slide", obj, 0
    raise InputError(
        f"unknown quantity {name!r} of mechanism '{mech.name}': expected 'P.x' / 'P.y' for a point "
        f"{mech.point_names}, 'L.theta' for a moving link {mech.moving_links}, or 'K.s' for a "
        f"prismatic pair {sorted(k for k, p in mech.pairs.items() if isinstance(p, Prismatic))}"
    )


# ----------------------------------------------------------------------------------------------
# the pipeline
# ----------------------------------------------------------------------------------------------


def analyze(
    mech: Mechanism,
    phi: ArrayLike,
    *,
    order: int = 2,
    outputs: Iterable[str] | None = None,
    omega: ArrayLike | None = None,
    eps: ArrayLike | None = 0.0,
    on_failure: Literal["raise", "mask"] = "raise",
) -> Motion:
    """Kinematics of ``mech`` at the input angles ``phi``.

    Parameters
    ----------
    mech : Mechanism
        The mechanism. With several input links, ``phi`` is the first one's angle and the others
        follow their laws (:class:`~linkage.model.input_laws.InputLaw`); analogs are derivatives with
        respect to ``phi``.
    phi : array_like, shape (N,) or scalar
        Input angles, rad (CCW from +x, docs/conventions.md); for a slide input (a piston, a
        cylinder: docs/inputs.md) its slide, m, and the analogs are per m.
    order : {0, 1, 2}
        Highest analog order to compute (0: positions only).
    outputs : iterable of str, optional
        Only what these need is computed: point names, link names or quantities (``"B.x"``).
        Default: everything.
    omega, eps : array_like, optional
        Input angular velocity (rad/s, signed) and acceleration (rad/s^2), scalars or ``(N,)``,
        for real velocities and accelerations.
    on_failure : {"raise", "mask"}
        ``"raise"`` (default): :class:`AssemblyError` listing the input angles where a group
        cannot be assembled or is singular (:class:`~linkage.errors.ConvergenceError`, naming the
        group and the residual, where Newton's method did not converge). ``"mask"``: return them
        in ``Motion.status``.

    Returns
    -------
    Motion
    """
    if order not in (0, 1, 2):
        raise InputError(f"order must be 0, 1 or 2, got {order!r}")
    if on_failure not in ("raise", "mask"):
        raise InputError(f"on_failure must be 'raise' or 'mask', got {on_failure!r}")
    structure = structure_of(mech)
    if type(phi) is not np.ndarray or phi.dtype != np.float64 or phi.ndim != 1:
        phi = np.atleast_1d(np.asarray(phi, dtype=float))
    if phi.ndim != 1 or not np.isfinite(phi).all():
        raise InputError("phi must be a finite scalar or 1-D array of angles in rad")
    _check_law_domains(mech, phi)
    plans = assembly_plans(mech)
    group_ids = range(len(structure.groups)) if outputs is None else \
        structure.needed_groups(links_needed(mech, outputs))
    run = _kernel_run(mech, phi, order) if outputs is None else None
    if run is None:
        run = run_blocks(mech, structure, plans, list(group_ids), phi, order)
    status = run.status
    every_ok = bool((status == OK).all())
    if order >= 1:          # the steps, for the jump check
        dphi = phi[1:] - phi[:-1]
        smallest = float(np.abs(dphi).min()) if len(dphi) else np.inf
    for i in group_ids:
        group = structure.groups[i]
        branches = plans[i].branches(phi) if run.branches is None else run.branches[i]
        _check_continuity(group, run.signs[i], branches, None if every_ok else run.solved[i], phi, mech.coordinate)
        _check_change_points(group, plans[i], phi, mech.coordinate)
        if order >= 1:
            _check_jumps(group, plans[i], run.poses, run.first, None if every_ok else run.solved[i], phi,
                         mech.coordinate,
                         None if run.scales is None else run.scales[i], dphi, smallest)
    if on_failure == "raise" and not every_ok:
        raise _failure(mech, phi, run, structure, plans, list(group_ids))
    poses, first, second = run.poses, run.first, run.second
    omega_arr = eps_arr = None
    if omega is not None:
        omega_arr = np.broadcast_to(np.asarray(omega, dtype=float), phi.shape).copy()
        eps_arr = np.broadcast_to(np.asarray(0.0 if eps is None else eps, dtype=float), phi.shape).copy()
    motion = Motion(mech, structure, phi, poses, first if order >= 1 else None,
                    second if order >= 2 else None, status, omega_arr, eps_arr, run.conditioning,
                    run.error_bound)
    if run.points is not None:
        motion._turns["kernel points"] = run.points
    return motion


def _kernel_run(mech: Mechanism, phi: np.ndarray, order: int) -> _Run | None:
    """:func:`run_blocks` of every group by the mechanism's compiled kernel
    (:mod:`linkage.kinematics.kernel`: the same numbers), None where it does not apply."""
    got = run_kernel(mech, phi, order) if USE_KERNEL and len(phi) else None
    return None if got is None else _kernel_results(got)


def _kernel_results(got: dict) -> _Run:
    """A kernel's results (:func:`linkage.kinematics.kernel.run_kernel`) as a :class:`_Run`."""
    return _Run(got["poses"], got["first"], got["second"], got["status"], got["conditioning"],
                got["error_bound"], got["signs"], got["solved"], got["points"], got["scales"], got["branches"])


def _check_law_domains(mech: Mechanism, phi: np.ndarray) -> None:
    """Refuse input angles outside the table of a further input's law that holds over less than a turn."""
    for link, law in mech.input_laws.items():
        if law.domain is None:
            continue
        low, high = law.domain
        outside = (phi < low - ANGLE_TOL) | (phi > high + ANGLE_TOL)
        if outside.any():
            shown = ", ".join(f"{v:.6g}" for v in np.degrees(phi[outside][:5]))
            raise InputError(f"mechanism '{mech.name}': input angle(s) {shown} deg lie outside the table of "
                             f"input link '{link}' ({np.degrees(low):.6g} to {np.degrees(high):.6g} deg)")


def input_sweep(mech: Mechanism) -> Motion:
    """Positions (order 0, per-position status) over the input's whole travel: a turn at
    :data:`SWEEP` angles from 0 to 2 pi, or the declared input range; computed once per mechanism
    (load-time checks and drawings share it). Mode changes are left for the analyses that pass
    them to report."""
    cache = mech.cache
    if "sweep" not in cache:
        low, high = mech.input_range if mech.input_range is not None else (0.0, 2 * np.pi)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", BranchWarning)
            cache["sweep"] = analyze(mech, np.linspace(low, high, SWEEP), order=0, on_failure="mask")
    return cache["sweep"]


def links_needed(mech: Mechanism, outputs: Iterable[str]) -> list[str]:
    """The links whose poses the named outputs (links, points, quantities such as ``B.x``) need."""
    links = []
    for name in outputs:
        if name in mech.links:
            links.append(name)
        elif any(name in lk.points for lk in mech.links.values()):
            links.append(mech.point_link(name))
        else:
            kind, obj, _ = parse_quantity(mech, name)
            links += [mech.point_link(obj)] if kind == "point" else [obj] if kind == "link" \
                else list(mech.pairs[obj].links)
    return links


#: positions solved at a time: the temporaries of a block stay in the processor's cache and the
#: memory of a call stays bounded (the result plus a few blocks)
BLOCK = 8192
#: solve a mechanism of closed-form dyads by its compiled kernel (:mod:`.kernel`; the same numbers,
#: bit for bit); False: always the general path (the oracle the kernel is tested against)
USE_KERNEL = True


@dataclass
class _Run:
    """What :func:`run_blocks` computed, over all N positions."""

    poses: dict[str, np.ndarray]
    first: dict[str, np.ndarray] | None
    second: dict[str, np.ndarray] | None
    status: np.ndarray
    conditioning: dict[str, np.ndarray]
    error_bound: np.ndarray
    signs: dict[int, np.ndarray]     # group index -> sign of its Jacobian determinant (N,)
    solved: dict[int, np.ndarray]    # group index -> the group's own status (N,)
    points: Mapping | None = None   # the kernel's: (link, local point) -> position, first, second analogs (N, 2)
    scales: dict[int, np.ndarray] | None = None   # the kernel's: group index -> its length scale (N,), m
    branches: tuple[int, ...] | None = None   # the kernel's: each group's branch, the same at every position


def run_blocks(mech: Mechanism, structure: Structure, plans, group_ids: list[int], phi: np.ndarray,
                order: int, structure_at=None) -> _Run:
    """Solve the groups ``group_ids`` in order at the angles ``phi``, :data:`BLOCK` positions at a
    time, into arrays allocated once (links' values in columns of ``(N, 3)`` arrays).

    ``structure_at(block)``, when given, is the structure whose joints hold the geometry of the
    positions ``block`` (a slice), for batches of design variants."""
    N = len(phi)
    links = [mech.frame, *structure.inputs] + [k for i in group_ids for k in structure.groups[i].links]

    def allocate():
        # the frame's values are zeros that are never written (pages the system maps lazily)
        return {k: (np.zeros if k == mech.frame else np.empty)((3, N)).T for k in links}

    poses = allocate()
    first = allocate() if order >= 1 else None
    second = allocate() if order >= 2 else None
    status = np.full(N, OK)
    error = np.zeros(N)
    conditioning = {repr(structure.groups[i]): np.empty(N) for i in group_ids}
    signs = {i: np.empty(N) for i in group_ids}
    solved = {i: np.empty(N, dtype=int) for i in group_ids}
    branches = {}
    for i in group_ids:
        per_position = plans[i].branches(phi)
        branches[i] = int(per_position[0]) if len(phi) and np.all(per_position == per_position[0]) else per_position
    for start in range(0, max(N, 1), BLOCK):
        block = slice(start, min(start + BLOCK, N))
        if structure_at is not None:
            structure = structure_at(block)
        view = {k: v[block] for k, v in poses.items()}
        view1 = None if first is None else {k: v[block] for k, v in first.items()}
        view2 = None if second is None else {k: v[block] for k, v in second.items()}
        frames = input_state(mech, structure, phi[block], view, view1, view2)
        link_error = {k: 0.0 for k in view}
        for i in group_ids:
            group = structure.groups[i]
            incoming = _largest([link_error[k] for k in group.known_links])
            branch = branches[i] if isinstance(branches[i], int) else branches[i][block]
            got = place_group(group, view, branch, incoming, view1, view2, frames, (view, view1, view2),
                              plans[i].start(phi[block]))
            for k in group.links:
                link_error[k] = got.error_bound
            conditioning[repr(group)][block] = got.conditioning
            signs[i][block] = got.jacobian_sign
            solved[i][block] = got.status
            status[block] = np.where(status[block] == OK, got.status, status[block])
        error[block] = _largest(list(link_error.values()))
        bad = status[block] != OK
        if bad.any():
            for analogs in (view1, view2):
                for v in (analogs or {}).values():
                    v[bad] = np.nan
    return _Run(poses, first, second, status, conditioning, error, signs, solved)


def _largest(values: list) -> np.ndarray | float:
    """Elementwise maximum of scalars and arrays (0 for none)."""
    out = 0.0
    for v in values:
        out = np.maximum(out, v)
    return out


def _failure(mech: Mechanism, phi: np.ndarray, run: _Run, structure: Structure, plans, group_ids: list[int]
             ) -> AssemblyError:
    """The error of :func:`analyze` for the positions of ``run`` that are not OK, naming the input
    angles (deg) of each problem: :class:`ConvergenceError` when Newton's method did not converge
    for a group (its message also names the group and the closure residual at each such angle,
    recomputed there by :meth:`assur.generic.NewtonGroup.closure`), else :class:`AssemblyError`."""


    status, conditioning = run.status, run.conditioning
    parts = []
    coordinate = mech.coordinate
    untraced = np.zeros(len(phi), bool)
    for i in group_ids:
        plan = plans[i]
        if plan.track is None or plan.periodic:
            continue
        low, high = plan.track[0][0], plan.track[0][-1]
        outside = (run.solved[i] == CANNOT_ASSEMBLE) & ((phi < low - 1e-12) | (phi > high + 1e-12))
        if outside.any():
            untraced |= outside
            parts.append(f"has {int(outside.sum())} {coordinate.describe(phi[outside])} outside the range "
                         f"{coordinate.shown(low):.6g} .. {coordinate.shown(high):.6g} {coordinate.shown_unit} over "
                         f"which the assembly mode of group {structure.groups[i]!r} is traced (it is solved by "
                         "Newton's method from that trace: declare a range that covers them)")
    for code, what in ((CANNOT_ASSEMBLE, "cannot be assembled"), (SINGULAR, "is singular")):
        at = phi[(status == code) & ~untraced]
        if len(at):
            parts.append(f"{what} at {len(at)} {coordinate.describe(at)}")
    unconverged = []
    for i in group_ids:
        rows = np.flatnonzero(run.solved[i] == NOT_CONVERGED)
        if not len(rows):
            continue
        group = structure.groups[i]
        known = {k: run.poses[k][rows] for k in group.known_links}
        residual = group.closure(known, plans[i].start(phi[rows]))
        size = float(np.max(group.size))
        angles = coordinate.shown(phi[rows])
        unconverged.append((repr(group), angles, residual, size))
        shown = ", ".join(f"{a:.6g} ({r:.3g} m, {r / size:.3g})" for a, r in zip(angles[:20], residual[:20]))
        parts.append(f"is not solved at {len(rows)} input {coordinate.kind}(s) where Newton's method did not "
                     f"converge for group {group!r} ({coordinate.shown_unit}, closure residual m, relative to the "
                     f"size {size:.6g} m): {shown}"
                     + (" ..." if len(rows) > 20 else ""))
    singular = status == SINGULAR
    if singular.any():
        worst = {g: float(np.nanmin(r[singular])) for g, r in conditioning.items()
                 if np.any(np.isfinite(r[singular]))}
        group = min(worst, key=worst.get)
        parts.append(f"group {group} is nearly singular there (conditioning {worst[group]:.2g}, where 1 "
                     f"is well proportioned: too low to keep its analogs to {ANALOG_TOL:g} relative; "
                     "see Motion.conditioning)")
    message = (f"mechanism '{mech.name}' " + "; ".join(parts)
               + " (use on_failure='mask' to get a per-position status instead)")
    bad = coordinate.shown(phi[status != OK])
    if unconverged:
        group, angles, residual, size = unconverged[0]
        return ConvergenceError(message, bad, group, angles, residual, size)
    return AssemblyError(message, bad)


def _check_continuity(group, sign: np.ndarray, branches: np.ndarray | int, solved: np.ndarray | None, phi,
                      coordinate) -> None:
    """Warn when the group's Jacobian determinant changes sign (relative to the branch in use,
    ``(N,)`` or one for every position) between the positions where the group's status
    ``solved`` is OK (None: at every position): the group passes a singular position between
    analysed angles."""
    every = solved is None
    ok = None if every else solved == OK
    signs = sign if every else sign[ok]
    if np.ndim(branches):
        signs = signs * (branches if every else branches[ok])
    if len(signs) and (signs != signs[0]).any():
        changed = coordinate.shown((phi if every else phi[ok])[signs != signs[0]])
        warnings.warn(
            f"group {group!r} is in another assembly mode at input {coordinate.kind}s ({coordinate.shown_unit}) "
            f"{np.array2string(changed[:10], precision=4)}: it passes a singular position between "
            "analysed angles", BranchWarning, stacklevel=3)


def _check_change_points(group, plan, phi, coordinate) -> None:
    """Warn when the analysed angles pass a change point that the group keeps its branch through
    (for a group solved by Newton's method: that its traced assembly mode passes), or when a
    followed motion needs two turns to repeat and a whole turn is analysed."""
    if len(phi) < 2 or not len(plan.change_points):
        return
    if plan.mode == "keep":
        passed = plan.change_points[plan.crossed(phi).any(axis=1)]
        shown = ", ".join(f"{round(float(coordinate.shown(c)), 6) % 360 + 0.0:g}" if coordinate.is_angle
                          else f"{float(c):.6g}" for c in passed)
        where = f"input {coordinate.kind}(s) {shown} {coordinate.shown_unit}"
        if len(passed) and plan.track is not None:      # a group solved by Newton's method
            warnings.warn(
                f"group {group!r} passes a change point at {where}, where its traced "
                "assembly mode meets another: the motion may go on in either there (the position at it "
                "is singular); past it the group takes the mode its plan traced, the one nearest to "
                "the motion before it", BranchWarning, stacklevel=3)
        elif len(passed):
            warnings.warn(
                f"group {group!r} passes a change point at {where}, where its two "
                "assembly modes meet; keeping its declared branch it switches assembly mode there "
                "(declare mode = \"follow\" in its assembly condition to follow the motion through "
                "it)", BranchWarning, stacklevel=3)
    elif not plan.closes and np.ptp(phi) >= 2 * np.pi * (1 - 1e-9):
        warnings.warn(
            f"group {group!r}, followed through {int(np.sum(plan.swaps))} change point(s) per turn, "
            "repeats its motion only after two turns of the input", BranchWarning, stacklevel=3)


#: largest step between analysed angles (rad; for a slide input, this times the mechanism's size,
#: m) over which :func:`_check_jumps` compares the motion with its analogs (beyond it the
#: trapezoid rule is too coarse to tell a jump from a fast motion)
JUMP_CHECK_STEP = np.pi / 18


def _check_jumps(group, plan, poses, first, status, phi, coordinate, scales: np.ndarray | None,
                 dphi: np.ndarray, smallest: float) -> None:
    """Warn where a group moves between two analysed angles (at most 10 deg apart) by more than
    its first analogs allow: the displacement of points fixed in its links differs from the
    trapezoid rule on their analogs by more than half of either (a change point or a singular
    position passed between the angles, with no other warning). Checked :data:`BLOCK` steps at
    a time; ``status``: the group's own status (None: OK at every position); ``scales``: the
    group's length scale per position where the kernel gave it; ``dphi``: the steps between the
    angles ``phi``, the smallest in magnitude ``smallest``."""
    if len(phi) < 2:
        return
    largest = JUMP_CHECK_STEP * (1.0 if plan.period is not None else float(np.max(group.size)))
    if smallest > largest:        # every step too coarse to tell a jump from a fast motion
        return
    pairs = (np.abs(dphi) <= largest) & (dphi != 0)
    if status is not None:
        pairs &= (status[:-1] == OK) & (status[1:] == OK)
    if plan.mode == "keep" and len(plan.change_points):        # passed change points: reported
        pairs &= ~plan.crossed(phi).any(axis=0)
    if not pairs.any():
        return
    if status is None:
        sample = slice(None, None, max(1, len(phi) // 4096))
    else:
        sample = np.flatnonzero(status == OK)
        sample = sample[:: max(1, len(sample) // 4096)]
    sizes = group.scale({k: v[sample] for k, v in poses.items()}) if scales is None else scales[sample]
    middle = len(sizes) // 2            # the upper median: one partition, not a sort
    scale = float(np.partition(sizes, middle)[middle])
    bad = jump_steps(group, poses, first, pairs, dphi, scale)
    if bad.any():
        k = np.flatnonzero(bad)
        values = coordinate.shown(phi)
        shown = ", ".join(f"{values[j]:.6g}..{values[j + 1]:.6g}" for j in k[:5])
        warnings.warn(
            f"group {group!r} moves between the input {coordinate.kind}s {shown} {coordinate.shown_unit} more than "
            "its analogs "
            "allow: it passes a change point or a singular position between them (analyse finer "
            "angles there)", BranchWarning, stacklevel=3)


def jump_steps(group, poses: dict, first: dict, pairs: np.ndarray, dphi: np.ndarray, scale: float) -> np.ndarray:
    """``(N-1,)``: the steps among ``pairs`` (bool ``(N-1,)``) between consecutive positions (angle
    steps ``dphi``) where a link of ``group`` moves more than its analogs allow (see
    :func:`_check_jumps`; ``scale``, m, weighs the links' turns). :data:`BLOCK` steps at a time."""
    bad = np.zeros(len(dphi), bool)
    pose, rate = _link_block(poses, group.links), _link_block(first, group.links)
    for start in range(0, len(dphi), BLOCK):
        steps = slice(start, min(start + BLOCK, len(dphi)))
        if pairs[steps].any():
            ends = slice(steps.start, steps.stop + 1)
            bad[steps] = _jumps(pose[..., ends], rate[..., ends], dphi[steps], scale) & pairs[steps]
    return bad


def _link_block(values, links) -> np.ndarray:
    """``(L, 3, N)``: the ``(N, 3)`` values of ``links`` as rows (a view of a kernel's rows where
    they are consecutive there)."""
    block = values.block(links) if hasattr(values, "block") else None
    return np.stack([values[k].T for k in links]) if block is None else block


def _jumps(pose: np.ndarray, rate: np.ndarray, dphi: np.ndarray, scale: float) -> np.ndarray:
    """For M + 1 positions: ``(M,)`` whether each step moves more than the trapezoid rule on the
    first analogs allows (see :func:`_check_jumps`), from the poses ``pose`` and first analogs
    ``rate`` of L links, ``(L, 3, M + 1)`` each. A link's move is the displacement of its origin
    and its turn times ``scale``, the turn taken in (-pi, pi]."""
    weight = np.array([1.0, 1.0, scale])[:, None]
    moved = pose[..., 1:] - pose[..., :-1]
    moved[:, 2] += np.pi
    moved[:, 2] %= 2 * np.pi
    moved[:, 2] -= np.pi
    moved *= weight
    allowed = rate[..., :-1] + rate[..., 1:]
    allowed *= 0.5 * weight
    allowed *= dphi
    moved, allowed = moved.reshape(-1, len(dphi)), allowed.reshape(-1, len(dphi))     # (3 L, M)
    miss2 = np.square(moved - allowed).sum(axis=0)
    moved2 = np.square(moved).sum(axis=0)
    allowed2 = np.square(allowed).sum(axis=0)
    miss = np.sqrt(miss2)
    with np.errstate(invalid="ignore"):
        return (miss > 0.5 * (np.sqrt(moved2) + np.sqrt(allowed2))) & (miss > 1e-9 * scale)
