"""Assembly modes: which closed-form branch each group takes at each input angle.

A group with two assembly branches (RRR, RRP, RPR) is declared by a readable condition
(``left_of``, ``towards`` ... see :class:`linkage.model.mechanism.Assembly`). Where the group passes a
singular position with both sides assembled -- a *change point*, such as the parallelogram
four-bar's collinear position or the deltoid's coincident pivots -- its two assembly modes meet
and the motion may go on in either. This module finds those points once per mechanism, on a
sweep of the input angle refined by a bounded minimisation of the group's conditioning, and
decides for each whether the continuous motion changes closed-form branch there (by
extrapolating the group's poses from one side to the other). A group then either keeps its
declared branch (``mode = "keep"``, the default: the mechanism switches assembly mode at the
change point, and ``analyze`` warns when the analysed angles pass one) or follows the motion
through it (``mode = "follow"``).

>>> import linkage
>>> plans = assembly_plans(linkage.load("four_bar"))
>>> plans[0].branch, plans[0].mode, len(plans[0].change_points)
(1, 'keep', 0)
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
from scipy.optimize import brentq, minimize_scalar

from assur.base import CANNOT_ASSEMBLE, OK, SINGULAR, Group, GroupSolution, global_point

from ..errors import SchemeError
from ..model.mechanism import Mechanism
from ..structure import Structure, structure_of
from .inputs import input_poses
from .tracing import finite_poses, same_circuit, trace_modes, track_of
from .turning import turning_reason

__all__ = ["BranchPlan", "assembly_plans", "assembly_branches", "place_group", "BRANCH_SWEEP"]

#: number of input angles of the sweep that resolves conditions and finds change points
BRANCH_SWEEP = 360
#: conditioning below which a local minimum counts as a meeting of the two assembly modes
CHANGE_POINT_TOL = 1e-6
#: step (rad) of the poses extrapolated across a change point to tell how the motion goes on
CROSSING_STEP = 1e-3

TWO_PI = 2 * np.pi


@dataclass(frozen=True)
class BranchPlan:
    """How one group's closed-form branch is chosen at every input angle.

    Attributes
    ----------
    branch : int
        The declared branch (+1 / -1; for ``"follow"``, the branch from phi = 0 up to the first
        change point that swaps).
    mode : {"keep", "follow"}
        Keep the declared branch everywhere, or follow the motion through change points.
    change_points : ndarray (K,)
        Input angles in [0, 2 pi) where the group's two assembly modes meet, rad.
    swaps : ndarray of bool (K,)
        Whether the continuous motion changes closed-form branch at each change point.
    track : (ndarray (S,), dict of link -> ndarray (S, 3)) or None
        For a group solved by Newton's method: its chosen assembly mode sampled at S increasing
        input angles (rad: the sweep's and those where its step was refined), NaN where the mode
        does not exist; None for closed forms.
    periodic : bool
        Whether the track covers a whole turn (it then wraps around).
    period : float or None
        The period of the input coordinate (2 pi for an angle; None for a slide, whose change
        points have no copies).
    """

    branch: int
    mode: str
    change_points: np.ndarray
    swaps: np.ndarray
    track: tuple[np.ndarray, dict[str, np.ndarray]] | None = None
    periodic: bool = False
    period: float | None = TWO_PI

    def start(self, phi: np.ndarray) -> dict[str, np.ndarray] | None:
        """Start poses ``{link: (N, 3)}`` at the input angles ``phi`` for a group solved by
        Newton's method: its chosen assembly mode traced over the plan's sweep, interpolated
        (NaN where the mode does not exist); ``None`` for closed forms."""
        if self.track is None:
            return None
        sweep, poses = self.track
        phi = np.asarray(phi, dtype=float)
        if self.periodic:
            at = (phi - sweep[0]) % TWO_PI + sweep[0]
            sweep = np.append(sweep, sweep[0] + TWO_PI)
            poses = {k: np.vstack([v, v[:1]]) for k, v in poses.items()}
        else:
            at = np.where((phi >= sweep[0] - 1e-12) & (phi <= sweep[-1] + 1e-12), phi, np.nan)
        out = {}
        for k, v in poses.items():
            theta = v[:, 2].copy()
            finite = np.isfinite(theta)
            theta[finite] = np.unwrap(theta[finite])
            columns = [np.interp(at, sweep, v[:, 0]), np.interp(at, sweep, v[:, 1]), np.interp(at, sweep, theta)]
            out[k] = np.column_stack(columns)
        return out

    def branches(self, phi: np.ndarray) -> np.ndarray:
        """Closed-form branch ``(N,)`` at the (unwrapped) input angles ``phi``."""
        phi = np.asarray(phi, dtype=float)
        if self.mode == "keep" or not self.swaps.any():
            return np.full(phi.shape, self.branch, dtype=int)
        points = np.sort(self.change_points[self.swaps])
        if self.period is None:
            return np.where(np.searchsorted(points, phi, side="right") % 2 == 0, self.branch, -self.branch)
        turns = np.floor(phi / TWO_PI)
        count = turns.astype(int) * len(points) + np.searchsorted(points, phi - turns * TWO_PI, side="right")
        return np.where(count % 2 == 0, self.branch, -self.branch)

    def crossed(self, phi: np.ndarray) -> np.ndarray:
        """``(K, N-1)`` bool: whether the step between consecutive angles ``phi`` (rad, unwrapped)
        passes each change point (or one of its copies a whole number of turns away)."""
        phi = np.asarray(phi, dtype=float)
        low, high = np.minimum(phi[:-1], phi[1:]), np.maximum(phi[:-1], phi[1:])
        points = self.change_points[:, None]
        if self.period is None:
            return (low < points) & (points <= high)
        return np.floor((high - points) / TWO_PI) > np.floor((low - points) / TWO_PI)

    @property
    def closes(self) -> bool:
        """Whether the followed motion repeats after one turn (an even number of swaps)."""
        return self.mode == "keep" or int(np.sum(self.swaps)) % 2 == 0


def place_group(group: Group, poses, branches, input_error=0.0, first=None, second=None,
                frames=None, out=None, start=None) -> GroupSolution:
    """:meth:`Group.solve` with a branch per position ``(N,)`` (each branch solved where it is
    used), or one branch (int) for all.

    ``first`` / ``second``: analogs of the known links (``None``: positions only); ``frames``,
    ``out`` and ``start`` (:meth:`BranchPlan.start`): see :meth:`assur.base.Group.solve`.
    """
    values = np.unique(branches)
    if len(values) == 1:
        return group.solve(poses, first, second, int(values[0]), input_error, frames=frames, out=out, start=start)
    parts = {int(b): group.solve(poses, first, second, int(b), input_error) for b in values}

    def pick(get):
        out = get(parts[int(values[0])])
        if out is None:
            return None
        for b in values[1:]:
            mask = branches == b
            out = np.where(mask[:, None] if out.ndim == 2 else mask, get(parts[int(b)]), out)
        return out

    def links(get):
        one = get(parts[int(values[0])])
        return None if one is None else {k: pick(lambda p, k=k: get(p)[k]) for k in one}

    solved = GroupSolution(links(lambda p: p.poses), pick(lambda p: p.status), pick(lambda p: p.jacobian_sign),
                           pick(lambda p: p.conditioning), pick(lambda p: p.error_bound),
                           links(lambda p: p.first), links(lambda p: p.second))
    if out is not None:
        for into, got in zip(out, (solved.poses, solved.first, solved.second)):
            for link, value in (got or {}).items():
                into[link][...] = value
    if frames is not None:
        frames.clear()     # the parts' frames are not kept: the next groups recompute theirs
    return solved


# ----------------------------------------------------------------------------------------------
# resolving the declared conditions
# ----------------------------------------------------------------------------------------------


def assembly_plans(mech: Mechanism) -> tuple[BranchPlan, ...]:
    """The branch plan of every group of ``mech`` (cached on the mechanism).

    A readable condition is evaluated on both candidate motions over a sweep of input angles (a
    turn, or the mechanism's input range when it declares one); the candidate that satisfies it
    at more positions wins.

    Raises
    ------
    SchemeError
        When a condition names no suitable point, does not tell the candidates apart, or a
        group can be assembled at no input angle (the message names the group and the
        dimensional reason).
    """

    cache = mech.cache
    if "plans" in cache:
        return cache["plans"]
    structure = structure_of(mech)
    rules = _rules_per_group(mech, structure)
    if mech.input_range is None:
        phi = np.linspace(0.0, TWO_PI, BRANCH_SWEEP, endpoint=False)
    else:  # an input that does not turn fully: conditions and change points within its range
        phi = np.linspace(*mech.input_range, BRANCH_SWEEP)
    poses = input_poses(mech, structure, phi)
    plans: list[BranchPlan] = []
    assembled: dict[int, np.ndarray] = {}       # group -> where it assembles on the sweep (M,)
    for i, group in enumerate(structure.groups):
        try:
            plan = _plan(mech, structure, plans, i, rules.get(i), poses, phi, assembled)
        except SchemeError as exc:
            raise _first_cause(mech, structure, poses, phi, assembled, exc) from None
        plans.append(plan)
        poses.update(place_group(group, poses, plan.branches(phi), start=plan.start(phi)).poses)
    cache["plans"] = tuple(plans)
    return cache["plans"]


def _plan(mech, structure, plans, i, rule, poses, phi, assembled) -> BranchPlan:
    """The branch plan of group ``i`` (earlier groups placed in ``poses`` at the sweep ``phi``);
    records in ``assembled[i]`` where the group assembles."""
    group = structure.groups[i]
    if getattr(group, "tracked", False):
        return _traced_plan(mech, structure, plans, i, rule, poses, phi, assembled)
    mode = rule.mode if rule is not None else "keep"
    # the first branch's placement: both branches of a closed form assemble at the same angles
    first = group.position(poses, group.branches[0])
    assembled[i] = first.status != CANNOT_ASSEMBLE
    if not assembled[i].any():
        _narrow_window(mech, structure, plans, i, phi, poses)
        _never_assembles(mech, structure, plans, i, phi, poses)
    if len(group.branches) == 1:
        return BranchPlan(1, "keep", np.empty(0), np.empty(0, bool), period=mech.coordinate.period)
    changes, swaps = _change_points(mech, structure, plans, i, phi, first.conditioning)
    candidates = {m: BranchPlan(m, mode, changes, swaps, period=mech.coordinate.period) for m in group.branches}
    if rule is not None and rule.phi is not None:
        at = np.array([rule.phi])
        return candidates[_choose(mech, group, rule, candidates, _chain(mech, structure, plans, i, at), at)]
    return candidates[_choose(mech, group, rule, candidates, poses, phi)]


def _first_cause(mech, structure, poses, phi, assembled, exc: SchemeError) -> SchemeError:
    """``exc`` with the reason a person checks first put before it: when a group up to the one
    refused does not assemble over the whole sweep, the input cannot turn fully
    (:func:`~.turning.turning_reason`: where it assembles, and why not)."""
    for j, where in assembled.items():
        if where.any() and not where.all():
            sentence = turning_reason(mech, structure.groups[j], poses, phi, where)
            return SchemeError([f"mechanism '{mech.name}': {sentence}", *exc.problems])
    return exc


def assembly_branches(mech: Mechanism) -> tuple[int, ...]:
    """The declared branch sign of every group (see :func:`assembly_plans`)."""
    return tuple(p.branch for p in assembly_plans(mech))


def _choose(mech, group, rule, candidates, poses, phi) -> int:
    if rule.rule == "branch":
        return rule.value
    votes = {}
    for m, plan in candidates.items():
        trial = {**poses, **place_group(group, poses, plan.branches(phi)).poses}
        # a point on the reference line (within round-off) satisfies neither side
        votes[m] = int(np.sum(_rule_score(mech, rule, trial) > 1e-9 * mech.size))
    if votes[1] == votes[-1]:
        where = (f"at the input angle {np.degrees(rule.phi):.6g} deg" if rule.phi is not None else
                 f"(each satisfies it at {votes[1]} of {BRANCH_SWEEP} input angles; give the input "
                 "angle at which it holds with phi_deg)")
        raise SchemeError(
            f"mechanism '{mech.name}': assembly of point '{rule.point}' ({_describe(rule)}) does not "
            f"tell the two branches of {group!r} apart {where}")
    return max(votes, key=votes.get)


def _describe(rule) -> str:
    if rule.rule == "towards":
        return f"from '{rule.refs[0]}' towards {np.degrees(rule.angle):.6g} deg"
    return f"{rule.rule} {list(rule.refs)}"


def _never_assembles(mech, structure, plans, i, phi, poses) -> None:
    """SchemeError naming group ``i``, which assembles at no angle of the sweep ``phi``, and the
    reason: the upstream assembly condition when the group assembles with another branch of an
    earlier group, else the dimensional reason (its own, or the group's "check the dimensions")."""
    group = structure.groups[i]
    head = f"mechanism '{mech.name}': group {group!r} cannot be assembled at any input {mech.coordinate.kind}"
    other = _assembles_with_other_branch(mech, structure, plans, i, phi)
    if other is not None:
        j, count = other
        rule = next((r for r in mech.assembly if any(r.point in mech.links[k].points
                                                     for k in structure.groups[j].links)), None)
        named = f"the condition on point '{rule.point}' ({_describe(rule)})" if rule is not None else "its branch"
        raise SchemeError(
            f"{head} with the assembly mode that {named} chooses for group {structure.groups[j]!r}; with that "
            f"group's other branch it assembles at {count} of {len(phi)} input {mech.coordinate.kind}s of the "
            "sweep: check that condition")
    reason = group.assembly_failure(poses)
    raise SchemeError(head + (f": {reason}" if reason else "") + " (check the dimensions of its links)")


def _narrow_window(mech, structure, plans, i, phi, poses) -> None:
    """SchemeError when group ``i``, which assembles at no angle of the sweep ``phi``, does assemble
    between two of them: where its :meth:`~assur.base.Group.assembly_margin` comes closest to 0,
    maximised within a sweep step; the message gives the window and how to analyse it."""
    group = structure.groups[i]
    margin = group.assembly_margin(poses)
    if margin is None or len(phi) < 2:
        return
    step = abs(phi[1] - phi[0])
    low = min(0.0, 1e-9 * mech.size)

    def at(x: float) -> float:
        value = group.assembly_margin(_chain(mech, structure, plans, i, np.array([x])))
        return float(value[0]) if np.isfinite(value[0]) else -np.inf

    near = np.argsort(np.nan_to_num(-np.asarray(margin, float), nan=np.inf))[:4]
    for k in near:
        best = minimize_scalar(lambda x: -at(x), bounds=(phi[k] - step, phi[k] + step), method="bounded",
                               options={"xatol": 1e-13})
        if -best.fun <= low:
            continue
        x = float(best.x)
        ends = [brentq(at, x - side * step, x, xtol=1e-14) if at(x - side * step) < 0 else x - side * step
                for side in (1, -1)]
        a, b = sorted(mech.coordinate.shown(np.array(ends)))
        unit = mech.coordinate.shown_unit
        key = "range_deg" if mech.coordinate.is_angle else "range"
        raise SchemeError(
            f"mechanism '{mech.name}': group {group!r} can be assembled only for input {mech.coordinate.kind}s from "
            f"{a:.6g} to {b:.6g} {unit}, a window narrower than the {mech.coordinate.shown(step):.3g} {unit} "
            f"step of the sweep that resolves assembly conditions (it closes by at most {-best.fun:.3g} m there): "
            f"the input cannot turn; to analyse that window, declare {key} = [{a:.6g}, {b:.6g}] for the input")


def _assembles_with_other_branch(mech, structure, plans, i, phi) -> tuple[int, int] | None:
    """The earlier closed-form group with two branches whose other branch lets group ``i``
    assemble at some sweep angles, and at how many (None when there is none)."""
    group = structure.groups[i]
    if getattr(group, "tracked", False):
        return None
    for j in structure.needed_groups(group.known_links):
        if len(structure.groups[j].branches) < 2 or plans[j].track is not None:
            continue
        flipped = list(plans)
        flipped[j] = replace(plans[j], branch=-plans[j].branch)
        known = _chain(mech, structure, flipped, i, phi)
        count = int(np.sum(group.position(known, group.branches[0]).status != CANNOT_ASSEMBLE))
        if count:
            return j, count
    return None


def _rules_per_group(mech: Mechanism, structure: Structure) -> dict:
    rules: dict[int, object] = {}
    problems = []
    for rule in mech.assembly:
        owners = [i for i, g in enumerate(structure.groups)
                  if has_modes(g) and any(rule.point in mech.links[k].points for k in g.links)]
        if not owners:
            problems.append(f"assembly of point '{rule.point}': no group with two or more assembly modes "
                            "places this point")
        elif owners[0] in rules:
            problems.append(f"assembly of point '{rule.point}': group {structure.groups[owners[0]]!r} "
                            f"already has the condition on point '{rules[owners[0]].point}'")
        else:
            rules[owners[0]] = rule
    for i, g in enumerate(structure.groups):
        if has_modes(g) and i not in rules:
            pts = sorted({p for k in g.links for p in mech.links[k].points})
            modes = "two assembly branches" if len(g.branches) > 1 else "several assembly modes"
            problems.append(f"group {g!r} has {modes}: declare which one with an assembly condition on one of "
                            f"its points {pts}")
    if problems:
        raise SchemeError([f"mechanism '{mech.name}': {p}" for p in problems])
    return rules


def has_modes(group) -> bool:
    """Whether the group can be assembled in more than one way (a condition must choose)."""
    return len(group.branches) > 1 or getattr(group, "tracked", False)


def _rule_score(mech: Mechanism, rule, poses) -> np.ndarray:
    """Signed distance (m), positive where the condition holds (NaN where a point is not placed)."""

    def at(point):
        for link in mech.point_links(point):
            if link in poses:
                return global_point(poses[link], mech.links[link].points[point])
        raise SchemeError(f"assembly of point '{rule.point}': point '{point}' is not placed yet")

    P = at(rule.point)
    if rule.rule in ("left_of", "right_of"):
        X, Y = at(rule.refs[0]), at(rule.refs[1])
        side = (Y - X)[:, 0] * (P - X)[:, 1] - (Y - X)[:, 1] * (P - X)[:, 0]
        with np.errstate(divide="ignore", invalid="ignore"):
            side = side / np.linalg.norm(Y - X, axis=1)
        return side if rule.rule == "left_of" else -side
    X = at(rule.refs[0])
    return (P - X) @ np.array([np.cos(rule.angle), np.sin(rule.angle)])


# ----------------------------------------------------------------------------------------------
# groups solved by Newton's method: their modes traced over the sweep (linkage.kinematics.tracing)
# ----------------------------------------------------------------------------------------------


def _traced_plan(mech, structure, plans, i, rule, poses, phi, assembled) -> BranchPlan:
    """The plan of a group solved by Newton's method: its assembly modes found over the sweep and
    each followed over it (:func:`linkage.kinematics.tracing.trace_modes`); the declared condition
    chooses one (:func:`_chosen_trace`); the change points where the chosen mode meets another
    are recorded."""
    group = structure.groups[i]
    known = {k: poses[k] for k in group.known_links}

    def known_at(angles: np.ndarray) -> dict[str, np.ndarray]:
        chain = _chain(mech, structure, plans, i, np.asarray(angles, float))
        return {k: chain[k] for k in group.known_links}

    periodic = mech.input_range is None
    traces = trace_modes(group, phi, known, known_at, periodic)
    assembled[i] = np.any([finite_poses(t.rows) for t in traces], axis=0) if traces else np.zeros(len(phi), bool)
    if not traces:
        _never_assembles(mech, structure, plans, i, phi, known)
    chosen = traces[_chosen_trace(mech, group, rule, traces, poses, phi)]
    plan = BranchPlan(1, "keep", np.empty(0), np.empty(0, bool), track_of(phi, chosen, periodic), periodic,
                      mech.coordinate.period)
    changes = _traced_change_points(mech, group, known, known_at, plan, phi, chosen.rows)
    return replace(plan, change_points=changes, swaps=np.zeros(len(changes), bool))


def _chosen_trace(mech, group, rule, traces, poses, phi) -> int:
    """Which of the traced modes the group's assembly condition declares: the one that satisfies
    a readable condition at the most sweep angles (or at its ``phi_deg``), or for ``branch = +1 /
    -1`` the one whose Jacobian determinant has that sign. Raises SchemeError, naming the rule,
    when the condition cannot choose."""
    if rule is None:
        return 0      # one mode only (a rule is required where there are several)
    where = f"mechanism '{mech.name}': assembly of group {group!r}"
    if rule.rule == "branch":
        signs = [_mode_sign(group, {**poses, **t.rows}, t.rows) for t in traces]
        matching = [n for n, s in enumerate(signs) if s == rule.value]
        if len(matching) == 1:
            return matching[0]
        count = {+1: signs.count(1), -1: signs.count(-1)}
        raise SchemeError(
            f"{where}: branch = {rule.value:+d} chooses the mode whose Jacobian determinant has that sign, but "
            f"{len(matching)} of its {len(traces)} assembly modes have it ({count[1]} positive, {count[-1]} "
            f"negative); declare the mode by a point instead (left_of, right_of or towards, with phi_deg if "
            "needed; docs/groups.md)")
    scores = []
    for trace in traces:
        score = _rule_score(mech, rule, {**poses, **trace.rows})
        if rule.phi is not None:
            near = int(np.argmin(_apart(phi, rule.phi, mech)))
            score = score[near:near + 1]
        with np.errstate(invalid="ignore"):
            scores.append(int(np.sum(score > 1e-9 * mech.size)))
    order = np.argsort(scores, kind="stable")[::-1]
    best = scores[order[0]]
    at = (f"at the input angle {np.degrees(rule.phi):.6g} deg" if rule.phi is not None else
          f"at any of the {len(phi)} input angles of the sweep")
    if best == 0:
        raise SchemeError(f"{where}: none of its {len(traces)} assembly modes places point '{rule.point}' "
                          f"{_describe(rule)} {at}; check the condition (and its phi_deg)")
    tied = [int(n) for n in order if scores[n] == best]
    if len(tied) > 1 and all(same_circuit(group, traces[tied[0]], traces[n]) for n in tied[1:]):
        # one mode that runs more than a turn, traced from two angles: either holds the declared pose
        return max(tied, key=lambda n: int(np.sum(finite_poses(traces[n].rows))))
    if len(tied) > 1:
        raise SchemeError(
            f"{where}: assembly of point '{rule.point}' ({_describe(rule)}) does not tell its assembly modes "
            f"apart (two of its {len(traces)} modes satisfy it at {best} of {len(phi)} input angles; choose a "
            "condition that only one mode meets, or give the input angle at which it holds with phi_deg)")
    return int(order[0])


def _mode_sign(group, merged, rows) -> int:
    """The sign (+1 / -1) of the group's Jacobian determinant along a traced mode (the sign it has
    at most of the sweep angles where the mode exists; 0 when it has none)."""
    ok = finite_poses(rows)
    if not ok.any():
        return 0
    at = {k: v[ok] for k, v in merged.items()}
    signs = group.conditioning(group.jacobians(at)[0], at)[1]
    total = float(np.sum(signs))
    return int(np.sign(total))


def _traced_change_points(mech, group, known, known_at, plan: BranchPlan, phi, rows) -> np.ndarray:
    """Input angles in [0, 2 pi) where the traced mode ``rows`` ``{link: (M, 3)}`` (the plan's)
    meets another mode: a local minimum of the group's conditioning along it, refined by a bounded
    minimisation to below :data:`CHANGE_POINT_TOL`, with the mode assembled on both sides (not a
    limit position where the mode ends)."""
    M = len(phi)
    r = np.full(M, np.nan)
    ok = finite_poses(rows)
    if ok.any():
        merged = {**{k: v[ok] for k, v in known.items()}, **{k: v[ok] for k, v in rows.items()}}
        r[ok] = group.conditioning(group.jacobians(merged)[0], merged)[0]

    def placed(x: np.ndarray):
        x = np.asarray(x, float)
        return group.position(known_at(x), start=plan.start(x))

    def measure(x: float) -> float:
        value = placed(np.array([x])).conditioning[0]
        return float(value) if np.isfinite(value) else 2.0

    found: list[float] = []
    for x in _conditioning_minima(mech, phi, r, measure):
        sides = placed(x + crossing_step(mech) * np.array([-1.0, 1.0])).status
        if np.any((sides != OK) & (sides != SINGULAR)):
            continue    # the mode ends there: a limit position
        angle = _fold(x, mech)
        if all(_apart(angle, a, mech) >= 1e-9 for a in found):
            found.append(angle)
    return np.sort(np.asarray(found, float))


# ----------------------------------------------------------------------------------------------
# change points
# ----------------------------------------------------------------------------------------------


def _chain(mech, structure, plans, i, phi):
    """Poses of the known links of group ``i`` at the angles ``phi`` (earlier groups placed)."""

    poses = input_poses(mech, structure, phi)
    for j in structure.needed_groups(structure.groups[i].known_links):
        poses.update(place_group(structure.groups[j], poses, plans[j].branches(phi), start=plans[j].start(phi)).poses)
    return poses


def _change_points(mech, structure, plans, i, phi, r) -> tuple[np.ndarray, np.ndarray]:
    """Angles in [0, 2 pi) where group ``i``'s assembly modes meet (from its conditioning ``r``
    over the sweep ``phi``), and whether the motion swaps closed-form branch there."""
    group = structure.groups[i]

    def measure(x: float) -> float:
        value = group.position(_chain(mech, structure, plans, i, np.array([x])), 1).conditioning[0]
        return float(value) if np.isfinite(value) else 2.0

    found, swaps = [], []
    for x in _conditioning_minima(mech, phi, r, measure):
        swap = _swaps(mech, structure, plans, i, x)
        if swap is None:
            continue  # one side cannot be assembled: a limit position, not a change point
        angle = _fold(x, mech)
        if any(_apart(angle, a, mech) < 1e-9 for a in found):
            continue
        found.append(angle)
        swaps.append(swap)
    order = np.argsort(found)
    return np.asarray(found, float)[order], np.asarray(swaps, bool)[order]


def crossing_step(mech) -> float:
    """:data:`CROSSING_STEP` in the first input's coordinate: rad, or that times the mechanism's
    size for a slide (m)."""
    return CROSSING_STEP if mech.coordinate.is_angle else CROSSING_STEP * mech.size


def _fold(x: float, mech) -> float:
    """A change point's coordinate: an angle folded into [0, 2 pi) (its copies a turn away are
    the same point), a slide as it is."""
    return x % TWO_PI if mech.coordinate.is_angle else float(x)


def _apart(a, b, mech):
    """How far apart input coordinates are (angles: modulo a turn); elementwise on arrays."""
    gap = np.subtract(a, b)
    return np.abs((gap + np.pi) % TWO_PI - np.pi if mech.coordinate.is_angle else gap)


def _conditioning_minima(mech, phi, r, measure) -> list[float]:
    """Input angles (rad) where the conditioning falls below :data:`CHANGE_POINT_TOL`: each local
    minimum of ``r`` (the conditioning over the sweep ``phi``, NaN where not assembled) below 0.1,
    and each single unassembled angle between two assembled ones, refined by a bounded
    minimisation of ``measure(x)`` (the conditioning at the input angle x) within a sweep step."""
    ok = np.isfinite(r)
    low = np.where(ok, r, np.inf)
    before, after = np.roll(low, 1), np.roll(low, -1)
    # local minima of the conditioning, and single angles where the closed form gives up between
    # two assembled neighbours (e.g. the deltoid's coincident pivots)
    inside = np.roll(ok, 1) & np.roll(ok, -1)
    if mech.input_range is not None:     # the sweep does not wrap around: no neighbours at its ends
        inside[[0, -1]] = False
    cells = np.flatnonzero(inside & (~ok | (low <= np.minimum(before, after)))
                           & (np.minimum(low, np.minimum(before, after)) < 0.1))
    step = abs(phi[1] - phi[0])
    minima = []
    for k in cells:
        best = minimize_scalar(measure, bounds=(phi[k] - step, phi[k] + step), method="bounded",
                               options={"xatol": 1e-12})
        if best.fun <= CHANGE_POINT_TOL:
            minima.append(float(best.x))
    return minima


# Lagrange weights that extrapolate values at t = -3, -2, -1 to t = 1, 2, 3 (rows)
_NODES = np.array([-3.0, -2.0, -1.0])
_EXTRAPOLATE = np.array([[np.prod([(t - n) / (m - n) for n in _NODES if n != m]) for m in _NODES]
                         for t in (1.0, 2.0, 3.0)])


def _swaps(mech, structure, plans, i, angle) -> bool | None:
    """Whether branch +1 on the left of ``angle`` goes on as branch -1 on its right (None when
    one side cannot be assembled)."""
    group = structure.groups[i]
    offsets = crossing_step(mech) * np.array([-3.0, -2.0, -1.0, 1.0, 2.0, 3.0])
    poses = _chain(mech, structure, plans, i, angle + offsets)
    features = {}
    for m in group.branches:
        placed = group.position(poses, m)
        if np.any(placed.status == CANNOT_ASSEMBLE):
            return None
        merged = {**poses, **placed.poses}
        contacts = group.contact_points(merged)                      # (6, J, 2)
        scale = float(np.max(group.scale(merged, contacts)))
        parts = [contacts.reshape(6, -1)]
        for link in group.links:
            theta = merged[link][:, 2]
            parts.append(scale * np.column_stack([np.cos(theta), np.sin(theta)]))
        features[m] = np.concatenate(parts, axis=1)
    predicted = _EXTRAPOLATE @ features[1][:3]
    miss = {m: np.linalg.norm(predicted - features[m][3:]) for m in group.branches}
    return bool(miss[-1] < miss[1])
