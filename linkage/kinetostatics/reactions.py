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

from dataclasses import dataclass, field, replace
from typing import Iterable

import numpy as np
from numpy.typing import ArrayLike

from assur.base import OK, DrivenPrismaticJoint, PrismaticJoint, point_analogs
from assur.rows import rows_of

from ..errors import InputError
from ..kinematics.inputs import input_angles
from ..kinematics.motion import Motion, angle_in_half_turn
from .friction import Friction, friction_angle_deg, friction_of, group_with_friction
from .kernel import input_freedom, run_reactions_kernel
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
    friction : Friction or None
        The pairs' friction the reactions include (None: frictionless); their loads are the
        ``terms`` of kind ``"friction"`` (label: the pair).
    sense : float
        The sense of motion of a static analysis (no ``motion.omega``): +1 the input's coordinate
        increasing, -1 decreasing; the friction opposes it and the powers are per unit of speed.
    locked_pair : ndarray (N,) of str, or None
        With friction: at the positions where no finite balancing load moves the mechanism
        (self-locking; every value NaN there, :attr:`locked`) the pair whose friction locks it,
        "" elsewhere.
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
    friction: Friction | None = None
    locked_pair: np.ndarray | None = None
    sense: float = 1.0

    @property
    def locked(self) -> np.ndarray | None:
        """With friction: where the mechanism self-locks (bool (N,)); None without friction."""
        return None if self.locked_pair is None else self.locked_pair != ""

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

    # -- friction, powers and efficiency ------------------------------------------------------

    def speed(self) -> np.ndarray:
        """The input's speed the powers are at (N,): ``motion.omega`` (rad/s; m/s for a slide
        input), or, for a static analysis, the sense of motion the friction opposed (+1 or -1,
        so the powers are per unit of speed)."""
        if self.motion.omega is not None:
            return np.asarray(self.motion.omega, float)
        return np.full(len(self.motion.phi), self.sense)

    def term_power(self, term: LoadTerm) -> np.ndarray:
        """The power of one load term (N,), W: ``(F·r'_P + M·θ')·ω``; 0 where it is round-off
        (below 1e-12 of the power the load would have at the mechanism's typical speed, as
        :func:`virtual_power_residual` scales it: a load at a dead centre does no work)."""
        v, _ = point_analogs(self.motion.poses[term.link], self.motion.first[term.link], None, term.local)
        analog = np.einsum("ni,ni->n", term.force, v) + term.moment * self.motion.first[term.link][:, 2]
        typical = np.hypot(term.force[:, 0], term.force[:, 1]) * self.motion.mechanism.size + np.abs(term.moment)
        return np.where(np.abs(analog) <= 1e-12 * typical, 0.0, analog) * self.speed() + 0.0

    def friction_load(self, pair: str) -> np.ndarray:
        """The friction in ``pair`` (N,): for a revolute pair the moment on its first link (N m),
        for a prismatic pair the force on the slider along the guide's direction (N); 0 without
        friction in the pair."""
        if pair not in self.motion.mechanism.pairs:
            raise InputError(f"mechanism '{self.motion.mechanism.name}' has no pair '{pair}'")
        joint = self.motion.joints[pair]
        on_first = [t for t in self.terms if t.kind == "friction" and t.label == pair]
        if not on_first:
            return np.zeros(len(self.motion.phi))
        if isinstance(joint, PrismaticJoint):
            u, *_ = joint.frame(self.motion.poses)
            slider = next(t for t in on_first if t.link == joint.b)
            return np.einsum("ni,ni->n", slider.force, u)
        return next(t for t in on_first if t.link == joint.a).moment

    def friction_power(self, pair: str | None = None) -> np.ndarray:
        """The power friction takes in ``pair`` (every pair's sum by default), W, <= 0 (N,)."""
        return sum((self.term_power(t) for t in self.terms if t.kind == "friction"
                    and (pair is None or t.label == pair)), np.zeros(len(self.motion.phi)))

    def powers(self) -> dict[str, np.ndarray]:
        """The powers at every position (N,), W: ``driving`` (the balancing load's, with the loads
        declared as driving), ``useful`` (the resisting external loads', <= 0 where they resist),
        ``gravity``, ``inertia`` and ``friction`` (<= 0). Their sum is 0 (virtual power)."""
        n = len(self.motion.phi)
        out = {k: np.zeros(n) for k in ("driving", "useful", "gravity", "inertia", "friction")}
        rates = input_angles(self.motion.mechanism, self.motion.structure, self.motion.phi)
        speed = self.speed()
        out["driving"] = out["driving"] + self.balancing_moment * speed
        for link in self.motion.structure.inputs[1:]:
            out["driving"] = out["driving"] + self.balancing_moments[link] * rates[link][1] * speed
        for t in self.terms:              # an external load is the useful resistance
            kind = "useful" if t.kind == "external" else t.kind
            out[kind] = out[kind] + self.term_power(t)
        return out

    def efficiency(self) -> np.ndarray:
        """Instantaneous efficiency ``η = −P_useful / P_driving`` (N,): NaN where the drive
        delivers no power (P_driving <= 0: the mechanism is driven by its inertia, gravity or a
        load there) and where the reactions are NaN."""
        p = self.powers()
        driving = p["driving"]
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.where(driving > 0, 0.0 - p["useful"] / np.where(driving > 0, driving, 1.0), np.nan) + 0.0

    def columns(self, full: bool = False, direction: int | None = None) -> dict[str, np.ndarray]:
        """Table: ``i``, ``phi_deg`` (as in :meth:`Motion.columns`; ``s`` for a slide input),
        ``balancing_moment`` (N m; ``balancing_force``, N, for a slide input; with several inputs,
        the first's, and ``balancing_moment.K`` or ``balancing_force.K`` for each further input K), per
        pair ``K.R`` (magnitude of ``R[a, b]``, N) and ``K.angle_deg`` (its direction, deg CCW
        from +x in (-180, 180]); with ``full`` also ``K.Rx``, ``K.Ry`` (N) and, for
        prismatic pairs, ``K.M`` (N m, the moment of the slider on the guide about the slider's
        point). Pairs in the order of their names. ``direction``: see :meth:`Motion.columns`.
        With friction: ``efficiency`` (η, :meth:`efficiency`), ``power_lost`` (W, every pair's
        friction) and per pair with friction ``K.Mf`` (revolute: the friction moment on the pair's
        first link, N m) or ``K.Ff`` (prismatic: the friction force on the slider along the guide,
        N), and ``K.power_lost`` (W, >= 0): see :meth:`friction_load`."""
        cols = self.motion.position_columns(direction)
        load = self.motion.mechanism.coordinate.load
        cols[f"balancing_{load}"] = self.balancing_moment
        mech = self.motion.mechanism
        for link, declared in list(zip(self.motion.structure.inputs, mech.inputs))[1:]:
            kind = "moment" if mech.input_kind(declared) == "angle" else "force"
            missing = np.full(len(self.motion.phi), np.nan)
            cols[f"balancing_{kind}.{declared}"] = self.balancing_moments.get(link, missing)
        if self.friction:
            cols["efficiency"] = self.efficiency()
            cols["power_lost"] = -self.friction_power()
        for name in sorted(self.multipliers):
            cols[f"{name}.R"] = self.magnitude(name)
            cols[f"{name}.angle_deg"] = self.direction_deg(name)
            if full:
                f = self.force(name)
                cols[f"{name}.Rx"], cols[f"{name}.Ry"] = f[:, 0], f[:, 1]
                if isinstance(self.motion.joints[name], PrismaticJoint):
                    cols[f"{name}.M"] = self.moment(name)
            if self.friction and name in self.friction.pairs:
                kind = "Ff" if isinstance(self.motion.joints[name], PrismaticJoint) else "Mf"
                cols[f"{name}.{kind}"] = self.friction_load(name)
                cols[f"{name}.power_lost"] = -self.friction_power(name)
        return cols


def solve_reactions(
    motion: Motion,
    loads: Loads | None = None,
    *,
    inertia: bool = True,
    ends: ArrayLike | None = None,
    pairs: Iterable[str] | None = None,
    friction: Friction | bool | None = None,
    sense: float | None = None,
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
    friction : Friction or bool, optional
        Coulomb friction in the pairs (docs/methods.md#friction-in-the-pairs): ``True`` for the
        scheme's ``[friction]`` (:func:`~linkage.kinetostatics.friction.friction_of`; an error
        without one), or a :class:`~linkage.kinetostatics.friction.Friction`. Default: frictionless.
    sense : {1, -1}, optional
        The input's sense of motion the friction opposes where the motion has no speed (static
        analysis): +1 its coordinate increasing (default), -1 decreasing. With a speed, its sign.
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
    if friction is True:
        friction = friction_of(mech)
        if friction is None:
            raise InputError(f"scheme '{mech.name}' declares no [friction]: add it (docs/friction.md), e.g. "
                             "[friction] revolute = { f = 0.1, radius = 0.02 } and prismatic = { f = 0.15 }")
    return reactions_under(motion, terms, pairs, notes, friction=friction or None, sense=sense)


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
                    notes: tuple[str, ...] = (), *, friction: Friction | None = None,
                    sense: float | None = None) -> Reactions:
    """Reactions and the balancing moment under load terms already evaluated at the motion's
    positions (:func:`solve_reactions` evaluates the mechanism's declared loads first; a
    batch of variants gives its own, :func:`linkage.kinetostatics.batch.variant_reactions`).

    ``terms`` must hold the loads on every link the reactions in ``pairs`` need (default: every
    pair and the balancing moment). ``friction`` and ``sense``: see :func:`solve_reactions`.
    """
    if motion.second is None:
        raise InputError("reactions need a motion analysed with order=2")
    structure = motion.structure
    everything = _links_loaded(motion, pairs) is None
    group_ids = range(len(structure.groups)) if pairs is None else structure.loading_groups(set(pairs))
    applied = generalized_loads(motion, terms)
    valid = motion.status == OK
    heading = _sense(motion, sense)
    static = 1.0 if sense is None else float(sense)
    compiled = run_reactions_kernel(motion, applied, valid) if everything and not friction else None
    if compiled is not None:     # the same steps as below, compiled (kinetostatics/kernel.py)
        multipliers, balancing = compiled
        return Reactions(motion, multipliers, balancing[structure.inputs[0]], terms, notes, balancing, sense=static)
    multipliers: dict[str, np.ndarray] = {}
    n = len(motion.phi)
    locked_pair = np.full(n, "", dtype=object)
    lost: list[LoadTerm] = []
    for i in reversed(group_ids):
        group = structure.groups[i]
        frames = {k: motion.frame(k) for k in (*group.links, *group.known_links)}
        lam, transmitted = group.reactions(motion.poses, applied, valid=valid, frames=frames)
        if friction and any(k in friction.pairs for k in lam):
            def solve(loaded, group=group, frames=frames):
                return group.reactions(motion.poses, loaded, valid=valid, frames=frames)
            solved = group_with_friction(motion, solve, applied, set(group.links), friction, heading, valid,
                                         (lam, transmitted))
            lam, transmitted = solved.multipliers, solved.transmitted
            lost += solved.terms
            locked_pair[solved.locked & (locked_pair == "")] = solved.worst
            on_known = generalized_loads(motion, [t for t in solved.terms if t.link not in group.links])
            for link in group.known_links:
                if link in on_known:
                    applied[link] = applied[link] + on_known[link]
        multipliers.update(lam)
        for link, load in transmitted.items():
            applied[link] = applied[link] + load
    terms = terms + lost
    if not everything:
        notes = notes + ("balancing moment not computed: only the reactions in pairs "
                         f"{sorted(pairs)} were asked for",)
        return Reactions(motion, multipliers, np.full(n, np.nan), terms, notes, friction=friction,
                         locked_pair=locked_pair if friction else None, sense=static)
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

        def solve_input(loaded, link=link, rows=rows, motion_per_unit=motion_per_unit, drive=drive, joint=joint):
            load = -loaded[link]
            moment = sum(load[:, c] * motion_per_unit[c] for c in range(3))
            rest = tuple(load[:, c] - moment * drive[c] for c in range(3))
            return {joint.name: np.column_stack(rows.multipliers(link, rest))}, {"": moment}

        lam, out = solve_input(applied)
        if friction and joint.name in friction.pairs:
            solved = group_with_friction(motion, solve_input, applied, {link}, friction, heading, valid, (lam, out))
            lam, out = solved.multipliers, solved.transmitted
            terms = terms + solved.terms
            locked_pair[solved.locked & (locked_pair == "")] = solved.worst
        balancing[link] = out[""]
        multipliers.update(lam)
    locked = locked_pair != ""
    bad = ~valid | locked
    if bad.any():
        balancing = {k: np.where(bad, np.nan, v) for k, v in balancing.items()}
        multipliers = {k: np.where(bad[:, None], np.nan, v) for k, v in multipliers.items()}
    if friction and locked.any():
        notes = notes + (_locked_note(motion, friction, locked, locked_pair),)
        terms = [replace(t, force=np.where(locked[:, None], np.nan, t.force), moment=np.where(locked, np.nan, t.moment))
                 if t.kind == "friction" else t for t in terms]
    return Reactions(motion, multipliers, balancing[structure.inputs[0]], terms, notes, balancing, friction=friction,
                     locked_pair=locked_pair if friction else None, sense=static)


def _sense(motion: Motion, sense: float | None) -> np.ndarray:
    """The input's sense of motion per position (N,): the sign of its speed, else ``sense``
    (default +1)."""
    n = len(motion.phi)
    if motion.omega is not None and np.any(motion.omega != 0):
        return np.where(motion.omega != 0, np.sign(motion.omega), 1.0 if sense is None else float(np.sign(sense)))
    if sense is not None and sense not in (1, -1):
        raise InputError(f"sense must be +1 or -1 (the input's coordinate increasing or decreasing), got {sense!r}")
    return np.full(n, 1.0 if sense is None else float(sense))


def _locked_note(motion: Motion, friction: Friction, locked: np.ndarray, pair: np.ndarray) -> str:
    """The note naming where the mechanism self-locks, the pair and its friction angle."""
    where = np.flatnonzero(locked)
    by_pair: dict[str, list[int]] = {}
    for i in where:
        by_pair.setdefault(str(pair[i]), []).append(int(i))
    parts = []
    for name, rows in by_pair.items():
        f = friction.pairs[name].f if name in friction.pairs else float("nan")
        shown = motion.mechanism.coordinate.describe(motion.phi[rows[:6]])
        more = f" and {len(rows) - 6} more" if len(rows) > 6 else ""
        parts.append(f"pair {name} (f = {f:g}, friction angle {friction_angle_deg(f):.2f} deg) at position(s) "
                     f"{', '.join(str(r + 1) for r in rows[:6])}{more} ({shown})")
    return ("self-locking: no finite balancing load moves the mechanism against its friction at "
            + "; ".join(parts) + " -- the values there are NaN")


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
