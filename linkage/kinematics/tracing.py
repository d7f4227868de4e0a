"""Assembly modes of the groups solved by Newton's method, traced over a sweep of the input.

A group beyond the dyads (the class-III triad, groups with several sliders or slots) has several
assembly modes and no closed form that names them. :func:`trace_modes` finds them wherever they
exist on a sweep of the input and follows each one over it:

- modes are looked for at many angles of the sweep: where the group lists its modes
  (:meth:`assur.generic.NewtonGroup.modes`, the triad) at every angle, else by Newton's method
  from :data:`STARTS` random starts at :data:`SEEDS` angles spread over the sweep
  (:func:`random_start_modes`); a mode that no trace holds yet at its angle starts a new trace;
- each new trace is followed from its angle in both directions (over a turn, round to where it
  started) with step control: where a step jumps or Newton's method fails, the step is halved up
  to :data:`REFINEMENTS` times (:func:`_refine`);
- where a mode ends (a limit position, where it meets another mode and both cease to exist) the
  end is located by :data:`LIMIT_BISECTIONS` bisections, so the trace holds the mode up to within
  about 1e-7 rad of its limit;
- traces of one mode found from different angles are stitched into one (:func:`_stitched`).

The assembly plan (:mod:`linkage.kinematics.assembly`) then chooses the declared mode among the
traces and solves the group at any input angle by Newton's method from the chosen trace.
"""

from __future__ import annotations

from typing import Callable, NamedTuple

import numpy as np

from assur.generic import TRACE_JUMP, newton_closing

__all__ = ["Trace", "trace_modes", "track_of", "random_start_modes", "poses_distance", "finite_poses", "same_circuit", "STARTS", "SEEDS",
           "REFINEMENTS", "LIMIT_BISECTIONS"]

TWO_PI = 2 * np.pi

#: multi-start guesses at one angle for a group that cannot list its modes
STARTS = 64
#: angles of the sweep (evenly spread) where a group that cannot list its modes is searched for them
SEEDS = 8
#: halvings of a sweep step tried where a traced mode jumps or Newton's method fails between two
#: sweep angles (the step shrinks to 1/16 of the sweep's) before the mode is declared ended there
REFINEMENTS = 4
#: bisections that locate where a mode ends, between the last sub-step it was followed to and the
#: next (1/16 of a sweep step, divided by 2**10: about 1e-7 rad for a sweep of 360 angles), each
#: with at most LIMIT_STEPS Newton steps (next to the end the mode is singular and flagged anyway)
LIMIT_BISECTIONS = 10
LIMIT_STEPS = 12
#: two poses of a group closer than this fraction of its size are the same assembly mode
SAME_MODE = 1e-6
#: a traced step stops Newton's method once the group closes to this fraction of its size (a
#: step is good where it closes to 1e-9): a trace's poses are starts for the analysis, which
#: polishes them to its own tolerance
TRACE_CLOSURE = 1e-12
#: new traces started at most (each from a mode no earlier trace holds)
MAX_TRACES = 48

Poses = dict[str, np.ndarray]


class Trace(NamedTuple):
    """One assembly mode followed over the sweep: its poses ``{link: (M, 3)}`` at the sweep's M
    angles (NaN where it does not exist) and the poses ``{link: (E, 3)}`` at the E angles
    ``refined_at`` (rad, possibly a turn away from the sweep's) between them, where the step was
    refined or the mode's end located."""

    rows: Poses
    refined_at: np.ndarray
    refined: Poses


def trace_modes(group, phi: np.ndarray, known: Poses, known_at: Callable[[np.ndarray], Poses],
                periodic: bool) -> list[Trace]:
    """Every assembly mode of ``group`` found over the sweep ``phi`` and followed over it.

    Parameters
    ----------
    group : assur.generic.NewtonGroup
    phi : ndarray, shape (M,)
        The sweep, rad (or m for a slide input), equally spaced and increasing.
    known : dict of link -> ndarray (M, 3)
        Poses of the group's known links at the sweep.
    known_at : callable
        The same at any input angles ``(n,)``.
    periodic : bool
        Whether the sweep is a whole turn (traces then wrap round).

    Returns
    -------
    list of Trace
        One per mode (distinct where they both exist), in the order they were found.
    """
    size = float(np.max(group.size))
    listed = group.modes(known)
    walk = _Walk(group, phi, known, known_at, periodic, listed, size)
    traces: list[Trace] = []
    if listed is not None:
        while len(traces) < MAX_TRACES:
            m, modes = _first_uncovered(listed, traces, group.links, size)
            if m is None:
                break
            traces += walk.both_ways(m, modes)
    else:
        seeds = np.unique(np.linspace(0, len(phi), SEEDS, endpoint=False).astype(int))
        solved, good = _random_starts(group, {k: v[seeds] for k, v in known.items()}, size)
        for s, m in enumerate(seeds):
            found = _distinct(group, {k: v[s] for k, v in solved.items()}, good[s], size)
            fresh = _not_held(found, traces, m, group.links, size)
            if len(fresh) and len(traces) < MAX_TRACES:
                traces += walk.both_ways(int(m), {k: v[fresh] for k, v in found.items()})
    return _stitched(group, traces, size)


def track_of(phi: np.ndarray, trace: Trace, periodic: bool) -> tuple[np.ndarray, Poses]:
    """The samples of a trace, sweep angles and refined ones, in increasing angle (over a turn,
    folded into the turn that starts at the sweep's first angle)."""
    angles = np.concatenate([phi, trace.refined_at])
    if periodic:
        angles = (angles - phi[0]) % TWO_PI + phi[0]
    order = np.argsort(angles, kind="stable")
    return angles[order], {k: np.concatenate([v, trace.refined[k]])[order] for k, v in trace.rows.items()}


# ----------------------------------------------------------------------------------------------
# where to start traces
# ----------------------------------------------------------------------------------------------


def _held(traces: list[Trace], links, m: int | slice) -> Poses:
    """Poses ``{link: (..., C, 3)}`` of the C traces at the sweep index (or indices) ``m``."""
    return {k: np.stack([t.rows[k][m] for t in traces], axis=-2) for k in links}


def _first_uncovered(listed, traces: list[Trace], links, size: float) -> tuple[int | None, Poses]:
    """The first sweep index where the group lists a mode that no trace holds, and those modes
    ``{link: (c, 3)}`` (None and {} when every listed mode is held)."""
    poses, valid = listed
    uncovered = valid.copy()
    if traces:
        held = _held(traces, links, slice(None))                                        # (M, C, 3)
        gap = poses_distance({k: v[:, :, None] for k, v in poses.items()},
                             {k: v[:, None] for k, v in held.items()}, links, size)      # (M, K, C)
        uncovered &= ~np.any(np.nan_to_num(gap, nan=np.inf) <= SAME_MODE * size, axis=2)
    rows = np.flatnonzero(uncovered.any(axis=1))
    if not len(rows):
        return None, {}
    m = int(rows[0])
    return m, {k: v[m, uncovered[m]] for k, v in poses.items()}


def _not_held(found: Poses, traces: list[Trace], m: int, links, size: float) -> np.ndarray:
    """Indices of the modes ``found`` ``{link: (c, 3)}`` at sweep index ``m`` that no trace holds."""
    count = len(next(iter(found.values())))
    if not traces or not count:
        return np.arange(count)
    held = _held(traces, links, m)                                                        # (C, 3)
    gap = poses_distance({k: v[:, None] for k, v in found.items()}, {k: v[None] for k, v in held.items()},
                         links, size)                                                      # (c, C)
    return np.flatnonzero(~np.any(np.nan_to_num(gap, nan=np.inf) <= SAME_MODE * size, axis=1))


def random_start_modes(group, at0: Poses, size: float, around: Poses | None = None,
                       besides: Poses | None = None) -> Poses:
    """The distinct assembly modes ``{link: (C, 3)}`` Newton's method reaches from :data:`STARTS`
    random starts at one position, where the known links have the poses ``at0`` ``{link: (1, 3)}``.

    The starts are :func:`_random_starts`'s (seeded: the same inputs give the same modes in the
    same order), around the poses ``around`` ``{link: (1, 3)}``. A solution counts where Newton's
    method closes to :data:`TRACE_CLOSURE` of ``size``; it is a new mode when it lies farther
    than :data:`SAME_MODE` of ``size`` (:func:`poses_distance`) from every mode kept before it and
    from ``besides`` (a mode ``{link: (3,)}`` already known, not returned).
    """
    solved, good = _random_starts(group, at0, size, around)
    return _distinct(group, {k: v[0] for k, v in solved.items()}, good[0], size, besides)


def _random_starts(group, at0: Poses, size: float, around: Poses | None = None) -> tuple[Poses, np.ndarray]:
    """Newton's method from :data:`STARTS` random starts at each of S positions, where the known
    links have the poses ``at0`` ``{link: (S, 3)}``, all in one call.

    The starts lie within ``size`` (m) in x and y of the centroid of the group's contact points
    with its links at the poses ``around`` ``{link: (1, 3)}`` (default: each at the origin,
    unturned), each link turned at random; the generator is seeded (0) at every call, and every
    position takes the same draws. Returns the poses reached ``{link: (S, STARTS, 3)}`` and where
    they close to :data:`TRACE_CLOSURE` of ``size`` ``(S, STARTS)``.
    """
    S = len(next(iter(at0.values())))
    rng = np.random.default_rng(0)
    draws = {k: (rng.uniform(-1, 1, STARTS), rng.uniform(-1, 1, STARTS), rng.uniform(-np.pi, np.pi, STARTS))
             for k in group.links}
    at = {k: np.zeros((S, 3)) if around is None else np.repeat(around[k], S, axis=0) for k in group.links}
    centre = np.nanmean(group.contact_points({**at0, **at}), axis=1)                        # (S, 2)
    guesses = {k: np.stack([centre[:, :1] + size * x, centre[:, 1:] + size * y, np.broadcast_to(turn, (S, STARTS))],
                           axis=-1).reshape(S * STARTS, 3) for k, (x, y, turn) in draws.items()}
    known = {k: np.repeat(v, STARTS, axis=0) for k, v in at0.items()}
    solved, gap = newton_closing(group, known, guesses, TRACE_CLOSURE * size)
    return {k: v.reshape(S, STARTS, 3) for k, v in solved.items()}, (gap <= TRACE_CLOSURE * size).reshape(S, STARTS)


def _distinct(group, solved: Poses, good: np.ndarray, size: float, besides: Poses | None = None) -> Poses:
    """The solutions ``solved`` ``{link: (n, 3)}`` where ``good`` ``(n,)``, each kept when it lies
    farther than :data:`SAME_MODE` of ``size`` from every one kept before it and from ``besides``."""
    rows = np.flatnonzero(good)
    found = {k: v[rows] for k, v in solved.items()}
    apart = poses_distance({k: v[:, None] for k, v in found.items()}, {k: v[None] for k, v in found.items()},
                           group.links, size) > SAME_MODE * size                                  # (G, G)
    usable = np.ones(len(rows), bool) if besides is None else \
        poses_distance(found, {k: np.asarray(v)[None] for k, v in besides.items()}, group.links, size) > SAME_MODE * size
    kept: list[int] = []
    for n in np.flatnonzero(usable):
        if apart[n, kept].all():
            kept.append(int(n))
    return {k: v[kept] for k, v in found.items()}


# ----------------------------------------------------------------------------------------------
# following modes
# ----------------------------------------------------------------------------------------------


class _Walk:
    """What following a group's modes over one sweep needs (see :func:`trace_modes`)."""

    def __init__(self, group, phi, known, known_at, periodic, listed, size):
        self.group, self.phi, self.known, self.known_at = group, phi, known, known_at
        self.periodic, self.listed, self.size = periodic, listed, size
        self.step = float(phi[1] - phi[0]) if len(phi) > 1 else 0.0

    def both_ways(self, m: int, starts: Poses) -> list[Trace]:
        """Traces of the modes ``starts`` ``{link: (C, 3)}`` at sweep index ``m``, followed forward
        and then backward (backward only where the forward walk did not already reach)."""
        forward = self._walk(m, starts, +1)
        filled = _finite_rows3(forward[0])
        backward = self._walk(m, starts, -1, filled)
        rows = {k: np.where(np.isfinite(forward[0][k]), forward[0][k], backward[0][k]) for k in self.group.links}
        C = len(next(iter(starts.values())))
        at = np.concatenate([forward[1], backward[1]])
        owner = np.concatenate([forward[2], backward[2]])
        extra = {k: np.concatenate([forward[3][k], backward[3][k]]) for k in self.group.links}
        return [Trace({k: v[:, c] for k, v in rows.items()}, at[owner == c], {k: v[owner == c] for k, v in extra.items()})
                for c in range(C)]

    def _walk(self, m: int, starts: Poses, direction: int, filled: np.ndarray | None = None):
        """Follow the C modes ``starts`` from sweep index ``m`` one way over the sweep.

        Returns rows ``{link: (M, C, 3)}`` (NaN where not reached), and the refined samples:
        angles ``(E,)``, the trace each belongs to ``(E,)`` and poses ``{link: (E, 3)}``. With
        ``filled`` ``(M, C)`` a trace stops where its sweep index is already filled."""
        group, phi, known, listed, size = self.group, self.phi, self.known, self.listed, self.size
        M = len(phi)
        C = len(next(iter(starts.values())))
        rows = {k: np.full((M, C, 3), np.nan) for k in group.links}
        if direction > 0:
            for k in group.links:
                rows[k][m] = starts[k]
        samples: list[tuple[int, np.ndarray, Poses]] = []
        step = direction * self.step
        if self.periodic:
            indices = [(m + direction * s) % M for s in range(1, M)]
        else:
            indices = list(range(m + 1, M)) if direction > 0 else list(range(m - 1, -1, -1))
        current, angle, history = dict(starts), float(phi[m]), ()
        for index in indices:
            if filled is not None:
                stop = filled[index]
                current = {k: np.where(stop[:, None], np.nan, v) for k, v in current.items()}
            if not finite_poses(current).any():
                break
            options = None if listed is None else ({k: v[index:index + 1] for k, v in listed[0].items()},
                                                   listed[1][index:index + 1])
            reached, ok = _advance(group, current, {k: v[index:index + 1] for k, v in known.items()}, options, size,
                                   history)
            retry = np.flatnonzero(~ok & finite_poses(current))
            if len(retry):
                fixed, good, found = _refine(group, {k: v[retry] for k, v in current.items()}, angle, step,
                                             self.known_at, listed is not None, size)
                for k in group.links:
                    reached[k][retry] = fixed[k]
                ok[retry] = good
                samples += [(int(retry[j]), at, poses) for j, at, poses in found]
            history = (current,) + history[:1] if not len(retry) else ()      # a refined step: no even pace
            current = {k: np.where(ok[:, None], v, np.nan) for k, v in reached.items()}
            for k in group.links:
                rows[k][index] = current[k]
            angle = angle + step
        at = np.concatenate([s[1] for s in samples]) if samples else np.empty(0)
        owner = np.concatenate([np.full(len(s[1]), s[0]) for s in samples]) if samples else np.empty(0, int)
        extra = {k: np.concatenate([s[2][k] for s in samples]) if samples else np.empty((0, 3)) for k in group.links}
        return rows, at, owner, extra


def _advance(group, current: Poses, known: Poses, options, size: float, history: tuple[Poses, ...] = (),
             steps: int | None = None):
    """One step of every trace: from its poses ``current`` ``{link: (C, 3)}`` to the next angle,
    where the known links have the poses ``known`` ``{link: (1, 3)}`` and the listed modes are
    ``options`` (``({link: (1, K, 3)}, valid (1, K))``, or None). Each trace takes the listed
    mode nearest to it, else (none listed, or none near: a listing may lose a mode next to a
    position where two modes meet) the point Newton's method reaches from it. Returns the poses
    reached and where the step is good: a position that closes to 1e-9 of the size, within
    :data:`TRACE_JUMP` of the size of the current one. ``history``: the poses one and two equal
    steps before ``current`` (most recent first), as many as there are: Newton's method then
    starts from their extrapolation, quadratic or linear (one or two iterations fewer on a smooth
    trace). ``steps``: Newton steps at most (default :data:`assur.generic.NEWTON_STEPS`)."""
    links = group.links
    C = len(current[links[0]])
    reached, ok = {k: np.full((C, 3), np.nan) for k in links}, np.zeros(C, bool)
    if options is not None:
        candidates, valid = options
        gap2 = sum(_squared_gap(candidates[k][0][None], current[k][:, None], size) for k in links)
        gap2 = np.where(valid[0][None], np.nan_to_num(gap2, nan=np.inf), np.inf)            # (C, K)
        best = np.argmin(gap2, axis=1)
        reached = {k: candidates[k][0][best] for k in links}
        ok = poses_distance(reached, current, links, size) <= TRACE_JUMP * size      # False where NaN
    rows = np.flatnonzero(~ok & finite_poses(current))
    if len(rows):
        start = _extrapolated(current, history) if history else current
        if len(rows) < C:
            start, current = ({k: v[rows] for k, v in start.items()}, {k: v[rows] for k, v in current.items()})
        solved, gap = newton_closing(group, known, start, TRACE_CLOSURE * size, steps)
        ok[rows] = (gap <= 1e-9 * size) & (poses_distance(solved, current, links, size) <= TRACE_JUMP * size)
        for k in links:
            reached[k][rows] = solved[k]
    return reached, ok


def _extrapolated(current: Poses, history: tuple[Poses, ...]) -> Poses:
    """The poses one equal step after ``current``: the quadratic through ``current`` and the two
    poses of ``history``, or the line through ``current`` and the one; ``current`` itself where
    an earlier pose is NaN (the trace has just begun there)."""
    if len(history) == 1:
        ahead = {k: 2 * v - history[0][k] for k, v in current.items()}
    else:
        ahead = {k: 3 * (v - history[0][k]) + history[1][k] for k, v in current.items()}
    usable = finite_poses(ahead)
    return ahead if usable.all() else {k: np.where(usable[:, None], v, current[k]) for k, v in ahead.items()}


def _refine(group, current: Poses, angle: float, step: float, known_at, listing: bool, size: float):
    """Follow the R traces at poses ``current`` ``{link: (R, 3)}`` (at the input angle ``angle``)
    to ``angle + step`` in 2, 4 ... 2**REFINEMENTS equal sub-steps, until every sub-step is good.
    A trace that cannot be followed even then ends between two sub-steps: its samples go up to
    the end located by :func:`_limit`.

    Returns
    -------
    reached : dict of link -> ndarray (R, 3)
        Poses at ``angle + step`` (NaN where the trace could not be followed).
    good : ndarray of bool (R,)
    samples : list of (j, angles (n,), {link: (n, 3)})
        The poses of trace j at the intermediate sub-angles (and towards its end), rad.
    """
    R = len(next(iter(current.values())))
    reached = {k: np.full((R, 3), np.nan) for k in group.links}
    good = np.zeros(R, bool)
    samples = []
    todo = np.arange(R)
    for depth in range(1, REFINEMENTS + 1):
        n = 2**depth
        angles = angle + step * np.arange(1, n + 1) / n
        known = known_at(angles)
        listed = group.modes(known) if listing else None
        q = {k: v[todo] for k, v in current.items()}
        alive = np.ones(len(todo), bool)
        path = {k: np.empty((n, len(todo), 3)) for k in group.links}
        lived = np.zeros(len(todo), int)          # sub-steps each trace was followed
        for f in range(n):
            options = None if listed is None else ({k: v[f:f + 1] for k, v in listed[0].items()}, listed[1][f:f + 1])
            q, ok = _advance(group, q, {k: v[f:f + 1] for k, v in known.items()}, options, size)
            alive &= ok
            lived += alive
            q = {k: np.where(alive[:, None], v, np.nan) for k, v in q.items()}
            for k in group.links:
                path[k][f] = q[k]
        for j in np.flatnonzero(alive):
            samples.append((int(todo[j]), angles[:-1], {k: path[k][:-1, j] for k in group.links}))
            for k in group.links:
                reached[k][todo[j]] = path[k][-1, j]
        good[todo[alive]] = True
        if depth == REFINEMENTS:       # the traces still not followed end within this step
            for j in np.flatnonzero(~alive):
                f = int(lived[j])
                last = {k: (current[k][todo[j]] if f == 0 else path[k][f - 1, j]) for k in group.links}
                base = angle if f == 0 else float(angles[f - 1])
                ends_at, poses = _limit(group, last, base, step / n, known_at, listing, size)
                ends_at = np.concatenate([angles[:f], ends_at])
                poses = {k: np.concatenate([path[k][:f, j], poses[k]]) for k in group.links}
                if len(ends_at):
                    samples.append((int(todo[j]), ends_at, poses))
        todo = todo[~alive]
        if not len(todo):
            break
    return reached, good, samples


def _limit(group, last: Poses, angle: float, step: float, known_at, listing: bool, size: float
           ) -> tuple[np.ndarray, Poses]:
    """Where a mode at poses ``last`` ``{link: (3,)}`` (input angle ``angle``) ends within the
    step ``step``: :data:`LIMIT_BISECTIONS` bisections, each from the farthest pose reached.
    Returns the angles ``(n,)`` and poses ``{link: (n, 3)}`` of the mode it reached beyond
    ``angle`` (none when it ends right there)."""
    good_at, good = [], {k: [] for k in group.links}
    here, low, width = {k: v[None] for k, v in last.items()}, angle, step
    for _ in range(LIMIT_BISECTIONS):
        width /= 2
        trial = np.array([low + width])
        known = known_at(trial)
        options = group.modes(known) if listing else None
        reached, ok = _advance(group, here, known, options, size, steps=LIMIT_STEPS)
        if ok[0]:
            low, here = float(trial[0]), reached
            good_at.append(low)
            for k in group.links:
                good[k].append(reached[k][0])
    return np.asarray(good_at, float), {k: np.reshape(v, (-1, 3)) for k, v in good.items()}


# ----------------------------------------------------------------------------------------------
# one trace per mode
# ----------------------------------------------------------------------------------------------


def _stitched(group, traces: list[Trace], size: float) -> list[Trace]:
    """The traces with those of one mode joined: a trace that coincides with an earlier one
    (within :data:`SAME_MODE` of the size) at every sweep angle where both exist, and at one at
    least, is merged into it (its sweep poses fill the earlier one's gaps, its refined samples are
    added). A mode that runs on for more than a turn before it ends at a limit position passes
    some angles twice: its traces coincide over part of the turn and differ where it passes twice,
    so they stay apart (each holds one of its passes there; :func:`same_circuit` tells them)."""
    kept: list[Trace] = []
    for trace in traces:
        for n, other in enumerate(kept):
            gap = poses_distance(trace.rows, other.rows, group.links, size)
            both = np.isfinite(gap)
            if both.any() and np.all(gap[both] <= SAME_MODE * size):
                rows = {k: np.where(np.isfinite(v), v, trace.rows[k]) for k, v in other.rows.items()}
                kept[n] = Trace(rows, np.concatenate([other.refined_at, trace.refined_at]),
                                {k: np.concatenate([v, trace.refined[k]]) for k, v in other.refined.items()})
                break
        else:
            if finite_poses(trace.rows).any():
                kept.append(trace)
    return kept


def finite_poses(poses: Poses) -> np.ndarray:
    """``(N,)``: where every pose of ``poses`` is finite."""
    return np.all(np.concatenate([np.isfinite(v) for v in poses.values()], axis=1), axis=1)


def _finite_rows3(rows: Poses) -> np.ndarray:
    """``(M, C)``: where every pose of ``rows`` ``{link: (M, C, 3)}`` is finite."""
    return np.all(np.stack([np.all(np.isfinite(v), axis=2) for v in rows.values()]), axis=0)


def _squared_gap(a: np.ndarray, b: np.ndarray, size: float) -> np.ndarray:
    """Squared distance between poses ``(..., 3)``, m^2 (angles weighted by ``size``, wrapped)."""
    d = a - b
    turn = d[..., 2] + np.pi
    turn %= TWO_PI
    turn -= np.pi
    turn *= size
    x, y = d[..., 0], d[..., 1]
    return x * x + y * y + turn * turn


def poses_distance(a: Poses, b: Poses, links, size: float) -> np.ndarray:
    """Distance between the poses ``(..., 3)`` of several links, m: the root of the sum over
    ``links`` of each link's squared distance (angles weighted by ``size``, wrapped)."""
    return np.sqrt(sum(_squared_gap(a[k], b[k], size) for k in links))


def same_circuit(group, a: Trace, b: Trace) -> bool:
    """Whether two traces hold one mode that runs more than a turn: they coincide (within
    :data:`SAME_MODE` of the size) at two sweep angles at least (two modes meet at single
    angles, hardly ever on the sweep itself)."""
    size = float(np.max(group.size))
    gap = poses_distance(a.rows, b.rows, group.links, size)
    return int(np.sum(np.nan_to_num(gap, nan=np.inf) <= SAME_MODE * size)) >= 2
