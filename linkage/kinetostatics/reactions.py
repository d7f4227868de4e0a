"""Kinetostatic force analysis: pair reactions and the balancing moment (docs/methods.md#kinetostatics).

The groups are solved in reverse order of the structure ("from the farthest group") through the
shared group protocol (the transposed constraint Jacobian, :meth:`assur.base.Group.reactions`);
the reactions of a group's external pairs load the links it is attached to. The input link comes
last: its frame reaction and the balancing moment ``M_b``.

Convention: ``R[i, j]`` is the force that link j exerts on link i. For a pair declared with
``links = [a, b]`` the reported force is ``R[a, b]`` (for a prismatic pair: the force of the slider
on the guide, normal to the guide, and the moment of the slider on the guide about the slider's
point).

>>> import numpy as np, linkage
>>> from linkage.kinetostatics.reactions import solve_reactions, virtual_power_residual
>>> mech = linkage.load("four_bar")
>>> motion = linkage.analyze(mech, np.radians([0.0, 45.0]), omega=10.0, eps=0.0)
>>> reactions = solve_reactions(motion)
>>> bool(np.all(virtual_power_residual(reactions) < 1e-9))
True
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Iterable

import numpy as np
from numpy.typing import ArrayLike

from assur.base import OK, DrivenPrismaticJoint, PrismaticJoint, point_analogs
from assur.rows import rows_of

from ..errors import InputError
from ..kinematics.inputs import input_angles
from ..kinematics.motion import Motion, angle_in_half_turn
from .loads import Loads, LoadTerm, evaluate_loads, generalized_loads, inertia_terms, loads_of

__all__ = ["Reactions", "reactions_under", "solve_reactions", "virtual_power_residual"]


@dataclass(frozen=True)
class Reactions:
    """Reactions in every pair and the balancing moment at N positions.

    Attributes
    ----------
    motion : Motion
    multipliers : dict of pair name -> ndarray (N, 2)
        The group solvers' Lagrange multipliers (see :class:`assur.base.RevoluteJoint` and
        :class:`assur.base.PrismaticJoint`).
    balancing_moment : ndarray (N,)
        ``M_b``, the moment to apply to the (first) input link for the given motion, N m (CCW
        positive).
    terms : list of LoadTerm
        The applied and inertia loads used.
    notes : tuple of str
    balancing_moments : dict of input link -> ndarray (N,)
        The balancing moment of every input link, N m (CCW positive), or force, N, for a slide
        input: with several inputs (:class:`~linkage.model.input_laws.InputLaw`), each motor's share; the
        first is ``balancing_moment``. Keyed by ``Structure.inputs`` (a cylinder's by its driver,
        ``"K.s"`` for the pair K).
    """

    motion: Motion
    multipliers: dict[str, np.ndarray]
    balancing_moment: np.ndarray
    terms: list[LoadTerm]
    notes: tuple[str, ...] = ()
    balancing_moments: dict[str, np.ndarray] = field(default_factory=dict)

    def force(self, pair: str) -> np.ndarray:
        """``R[a, b]`` ``(N, 2)`` for the pair declared with ``links = [a, b]``, N."""
        joint = self.motion.joints[pair]
        lam = self.multipliers[pair]
        if isinstance(joint, PrismaticJoint):
            u, n, *_ = joint.frame(self.motion.poses)
            return -lam[:, :1] * n
        return lam

    def moment(self, pair: str) -> np.ndarray:
        """Prismatic pair: moment of the slider on the guide about the slider's point, N m."""
        if not isinstance(self.motion.joints[pair], PrismaticJoint):
            raise InputError(f"pair '{pair}' is revolute: its reaction is a force only")
        return -self.multipliers[pair][:, 1]

    def on(self, i: str, j: str) -> np.ndarray:
        """``R[i, j]``: the force that link j exerts on link i (summed over pairs joining them)."""
        total = None
        for name, pair in self.motion.mechanism.pairs.items():
            if set(pair.links) == {i, j} and name in self.multipliers:
                f = self.force(name) * (1.0 if pair.links[0] == i else -1.0)
                total = f if total is None else total + f
        if total is None:
            raise InputError(f"no pair joins links '{i}' and '{j}'")
        return total

    def magnitude(self, pair: str) -> np.ndarray:
        return np.hypot(*self.force(pair).T)

    def direction_deg(self, pair: str) -> np.ndarray:
        """Direction angle of ``R[a, b]``, deg CCW from +x, in (-180, 180]."""
        f = self.force(pair)
        return np.degrees(angle_in_half_turn(np.arctan2(f[:, 1], f[:, 0])))

    def columns(self, full: bool = False, direction: int | None = None) -> dict[str, np.ndarray]:
        """Table: ``i``, ``phi_deg`` (as in :meth:`Motion.columns`; ``s`` for a slide input),
        ``balancing_moment`` (N m; ``balancing_force``, N, for a slide input; with several inputs,
        the first's, and ``balancing_moment.K`` or ``balancing_force.K`` for each further input K), per
        pair ``K.R`` (magnitude of ``R[a, b]``, N) and ``K.angle_deg`` (its direction, deg CCW
        from +x in (-180, 180]); with ``full`` also ``K.Rx``, ``K.Ry`` (N) and, for
        prismatic pairs, ``K.M`` (N m, the moment of the slider on the guide about the slider's
        point). Pairs in the order of their names. ``direction``: see :meth:`Motion.columns`."""
        cols = self.motion.position_columns(direction)
        load = self.motion.mechanism.coordinate.load
        cols[f"balancing_{load}"] = self.balancing_moment
        mech = self.motion.mechanism
        for link, declared in list(zip(self.motion.structure.inputs, mech.inputs))[1:]:
            kind = "moment" if mech.input_kind(declared) == "angle" else "force"
            missing = np.full(len(self.motion.phi), np.nan)
            cols[f"balancing_{kind}.{declared}"] = self.balancing_moments.get(link, missing)
        for name in sorted(self.multipliers):
            cols[f"{name}.R"] = self.magnitude(name)
            cols[f"{name}.angle_deg"] = self.direction_deg(name)
            if full:
                f = self.force(name)
                cols[f"{name}.Rx"], cols[f"{name}.Ry"] = f[:, 0], f[:, 1]
                if isinstance(self.motion.joints[name], PrismaticJoint):
                    cols[f"{name}.M"] = self.moment(name)
        return cols


def solve_reactions(
    motion: Motion,
    loads: Loads | None = None,
    *,
    inertia: bool = True,
    ends: ArrayLike | None = None,
    pairs: Iterable[str] | None = None,
) -> Reactions:
    """Reactions in every pair and the balancing moment, group by group from the farthest.

    Parameters
    ----------
    motion : Motion
        Kinematics with second analogs; with ``omega`` (and ``eps``) when ``inertia`` is on.
    loads : Loads, optional
        Default: the loads the mechanism declares (gravity alone when it declares none), parsed
        once with the scheme (:func:`linkage.kinetostatics.loads.loads_of`); force diagrams carry their stroke
        ends, so no kinematics is re-run here.
    inertia : bool
        Include inertia forces and moments (needs ``motion.omega``).
    ends : array_like of bool, optional
        Positions that end a cycle (force diagrams take their end-of-stroke value there).
    pairs : iterable of str, optional
        Only the reactions in these pairs: the groups that place them and the groups that load
        those (:meth:`linkage.structure.Structure.loading_groups`) are solved, and only their
        links' loads are evaluated; the motion needs only those links (``analyze(...,
        outputs=...)``). The balancing moment needs the input's pair; without it, it is NaN.
        Default: every pair and the balancing moment.
    """
    mech = motion.mechanism
    if motion.second is None:
        raise InputError("reactions need a motion analysed with order=2")
    loads = loads_of(mech) if loads is None else loads
    links = _links_loaded(motion, pairs)
    terms = evaluate_loads(motion, loads, ends, links)
    if inertia and motion.omega is not None:
        terms += inertia_terms(motion, links)
    notes = loads.notes + (() if inertia and motion.omega is not None or not inertia else
                           ("no speed given: inertia loads are zero (static analysis)",))
    return reactions_under(motion, terms, pairs, notes)


def _links_loaded(motion: Motion, pairs: Iterable[str] | None) -> set[str] | None:
    """The links whose loads the reactions in ``pairs`` need (None: every link), checked
    against the mechanism's pairs and the links the motion places."""
    structure = motion.structure
    if pairs is None:
        return None
    unknown = set(pairs) - set(structure.joints)
    if unknown:
        raise InputError(f"mechanism '{motion.mechanism.name}' has no pair(s) {sorted(unknown)} "
                         f"(pairs {sorted(structure.joints)})")
    group_ids = structure.loading_groups(set(pairs))
    everything = len(group_ids) == len(structure.groups)
    links = {k for i in group_ids for k in structure.groups[i].links} | (set(structure.inputs) if everything else set())
    missing = sorted(links - set(motion.poses))
    if missing:
        raise InputError(f"the reactions asked for need links {missing}, which the motion does not place "
                         "(analyze them: outputs=...)")
    return None if everything else links


def reactions_under(motion: Motion, terms: list[LoadTerm], pairs: Iterable[str] | None = None,
                    notes: tuple[str, ...] = ()) -> Reactions:
    """Reactions and the balancing moment under load terms already evaluated at the motion's
    positions (:func:`solve_reactions` evaluates the mechanism's declared loads first; a
    batch of variants gives its own, :func:`linkage.kinetostatics.batch.variant_reactions`).

    ``terms`` must hold the loads on every link the reactions in ``pairs`` need (default: every
    pair and the balancing moment).
    """
    if motion.second is None:
        raise InputError("reactions need a motion analysed with order=2")
    structure = motion.structure
    everything = _links_loaded(motion, pairs) is None
    group_ids = range(len(structure.groups)) if pairs is None else structure.loading_groups(set(pairs))
    applied = generalized_loads(motion, terms)
    multipliers: dict[str, np.ndarray] = {}
    valid = motion.status == OK
    for i in reversed(group_ids):
        group = structure.groups[i]
        frames = {k: motion.frame(k) for k in (*group.links, *group.known_links)}
        lam, transmitted = group.reactions(motion.poses, applied, valid=valid, frames=frames)
        multipliers.update(lam)
        for link, load in transmitted.items():
            applied[link] = applied[link] + load
    if not everything:
        notes = notes + ("balancing moment not computed: only the reactions in pairs "
                         f"{sorted(pairs)} were asked for",)
        return Reactions(motion, multipliers, np.full(len(motion.phi), np.nan), terms, notes)
    balancing = {}
    for link in structure.inputs:
        # each input link's equilibrium: the drive takes the load's part along the link's motion
        # (a moment for a crank, a force along the guide for a slider), its pair what is left
        joint = structure.input_joints[link]
        if isinstance(joint, DrivenPrismaticJoint):
            # a cylinder: its group transmitted (-lambda[2], 0, 0) to the driver; lambda[2] balances
            balancing[link] = -applied[link][:, 0]
            continue
        rows = rows_of(joint, {k: motion.frame(k) for k in (joint.a, joint.b)})
        motion_per_unit, drive = input_freedom(joint, link, rows)
        load = -applied[link]
        balancing[link] = sum(load[:, c] * motion_per_unit[c] for c in range(3))
        rest = tuple(load[:, c] - balancing[link] * drive[c] for c in range(3))
        multipliers[joint.name] = np.column_stack(rows.multipliers(link, rest))
    bad = ~valid
    if bad.any():
        balancing = {k: np.where(bad, np.nan, v) for k, v in balancing.items()}
        multipliers = {k: np.where(bad[:, None], np.nan, v) for k, v in multipliers.items()}
    return Reactions(motion, multipliers, balancing[structure.inputs[0]], terms, notes, balancing)


def input_freedom(joint, link: str, rows) -> tuple[tuple, tuple]:
    """The motion an input ``link`` has in its ``joint`` with the frame, per unit of its coordinate
    (``(vx, vy, w)``: a turn about the pin for a crank, a slide along the guide for a slider), and
    the generalized load ``(Fx, Fy, M)`` of a unit drive (a unit moment, or a unit force along the
    slide through the link's origin) -- the drive whose value is the balancing moment or force.
    ``rows``: :func:`assur.rows.rows_of` of the joint at the motion's frames."""
    vx, vy, w = rows.null(link)
    if joint.kind == "R":
        return (vx, vy, w), (0.0, 0.0, 1.0)
    sign = 1.0 if link == joint.b else -1.0        # guide on the frame: the link slides along +u
    return (sign * vx, sign * vy, 0.0), (sign * vx, sign * vy, 0.0)


def virtual_power_residual(reactions: Reactions) -> np.ndarray:
    """Relative residual of the virtual-power balance (Zhukovsky's lever), per position.

    With virtual velocities (the first analogs: a virtual crank rate of 1 rad/s, so the result
    does not depend on the real ``omega`` and stays defined where it is 0) the powers are
    ``P_b = M_b`` (with several inputs, ``sum_k M_b,k q_k'``, q_k each input's angle or slide) and ``P_t = F . r'_P + M theta_k'`` for every applied and inertia load t.
    Reactions of ideal pairs do no work, so their sum is zero when the reactions are right. The
    residual is::

        |P_b + sum(P_t)| / (|P_b| + sum(|P_t|) + sum(|F| L + |M|))

    where ``L`` is the mechanism's size (``Mechanism.size``). The last sum is the power the loads
    would have at the machine's typical speed (a point moving at ``L`` per radian, a link turning
    at 1 rad per radian): it does not vanish at a dead centre where every power is round-off
    (~1e-16 of it), so correct reactions give a residual of ~1e-15 there too, and 0 where there
    are no loads at all. It depends only on its own position (not on the others in the batch).
    Correct reactions give <= 1e-9 at every position where the kinematics is regular (status OK).

    Returns
    -------
    ndarray (N,)
        The residual per position (NaN where the reactions are, at positions not status OK).
    """
    motion = reactions.motion
    size = motion.mechanism.size
    powers = [reactions.balancing_moment]
    rates = input_angles(motion.mechanism, motion.structure, motion.phi)
    for link in motion.structure.inputs[1:]:
        powers.append(reactions.balancing_moments[link] * rates[link][1])
    typical = np.zeros(len(motion.phi))
    for t in reactions.terms:
        pose, first = motion.poses[t.link], motion.first[t.link]
        v, _ = point_analogs(pose, first, None, t.local)
        powers.append(np.einsum("ni,ni->n", t.force, v) + t.moment * first[:, 2])
        typical = typical + np.hypot(t.force[:, 0], t.force[:, 1]) * size + np.abs(t.moment)
    powers = np.array(powers)
    scale = np.sum(np.abs(powers), axis=0) + typical
    return np.abs(np.sum(powers, axis=0)) / np.where(scale > 0, scale, 1.0)
