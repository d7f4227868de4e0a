"""The generic group solver: Newton's method on any statically determinate group's constraints.

A group that no closed-form kind binds -- a class-III triad, a class-IV group, a group with
prismatic pairs in any arrangement -- is solved by Newton's method on its constraint equations
``Phi(q) = 0`` with the analytic Jacobian the group protocol builds (:meth:`Group.jacobians`),
started from a *start*: poses of the group's links near the wanted solution. The start comes from
the group's assembly plan (:mod:`linkage.kinematics.assembly`): the chosen assembly mode, traced over a sweep
of the input angle by continuation, interpolated at each analysed angle; Newton only polishes it.
Everything else -- the closure and singularity checks, the exact analogs, the kinetostatics -- is
the shared generic path of :class:`assur.base.Group`.

A group kind that can list all its assembly modes in closed form (the RRR triad,
:mod:`assur.triad`) overrides :meth:`NewtonGroup.modes`; then the plan traces every mode and the
analysis picks the listed solution nearest to the start.
"""

from __future__ import annotations

import numpy as np

from .base import CANNOT_ASSEMBLE, NOT_CONVERGED, OK, SINGULAR, Group, GroupPosition, Poses
from .fused import layout_of

__all__ = ["NewtonGroup", "NEWTON_STEPS", "TRACE_JUMP", "GROUP_ROUNDOFF_FACTOR", "newton", "newton_closing",
           "newton_pairwise",
           "group_class_of"]

#: most Newton steps per solve
NEWTON_STEPS = 40
#: converged when the step is below this fraction of the mechanism's size (angles: rad)
STEP_TOL = 1e-13
#: a solution farther than this fraction of the mechanism's size from its start (link angles
#: weighted by the size) is another assembly mode, not the start's: a traced mode moves less than
#: this between two samples of its trace
TRACE_JUMP = 0.1
#: round-off model of the first analogs of a group solved here: relative error <= GROUP_ROUNDOFF_FACTOR *
#: eps / r**2 for its conditioning r = sigma_min / sigma_max (:meth:`NewtonGroup.conditioning`); measured
#: factor <= 0.061 over 480 random triads (RRR legs, a slider on a leg, a slot; regular and 1e-1 .. 1e-8
#: rad from singular) against 50-digit references (benchmarks/bench_guarantee_groups.py, results in
#: benchmarks/results_guarantee_groups.md); about ten times that for a margin
GROUP_ROUNDOFF_FACTOR = 0.6

try:        # the batched solve np.linalg.solve calls, without its checks (singular systems give NaN)
    from numpy.linalg import _umath_linalg

    def _SOLVE(a, b):
        return _umath_linalg.solve1(a, b, signature="dd->d")
except (ImportError, AttributeError):       # pragma: no cover - another numpy
    _SOLVE = None


def group_class_of(links, joints) -> str:
    """Assur's class of a group as a Roman numeral: the number of sides of the largest closed
    contour its internal pairs form (IV, V, ...), else III when a link has three internal pairs
    (a triad), else II."""
    inner = [j for j in joints if j.a in links and j.b in links]
    neighbours = {k: {j.b if j.a == k else j.a for j in inner if k in (j.a, j.b)} for k in links}
    longest = 0

    def walk(path):
        nonlocal longest
        for nxt in neighbours[path[-1]]:
            if nxt == path[0] and len(path) >= 3:
                longest = max(longest, len(path))
            elif nxt not in path:
                walk(path + [nxt])

    for k in links:
        walk([k])
    if longest >= 4:
        return _roman(longest)
    if any(len(n) >= 3 for n in neighbours.values()):
        return "III"
    return "II"


def _roman(n: int) -> str:
    return {4: "IV", 5: "V", 6: "VI", 7: "VII", 8: "VIII"}.get(n, str(n))


def newton(group: Group, poses: Poses, start: Poses, steps: int | None = None):
    """Newton's method on ``group``'s constraints from the ``start`` poses of its links.

    Each iteration evaluates the whole residual and group Jacobian at once with the group's
    :class:`assur.fused.FusedLayout`; where the group has none (or with :data:`assur.fused.FUSED`
    off) pair by pair (:func:`newton_pairwise`: the same numbers).

    Parameters
    ----------
    poses : dict of link -> ndarray (N, 3)
        Poses of the known links.
    start : dict of link -> ndarray (N, 3)
        Start poses of the group's links.
    steps : int, optional
        Most steps (default :data:`NEWTON_STEPS`, read at each call).

    Returns
    -------
    solved : dict of link -> ndarray (N, 3)
        The poses reached.
    converged : ndarray of bool (N,)
        Where the last step was below ``STEP_TOL`` times the size (rad for angles).
    """
    layout = layout_of(group)
    if layout is None:
        return newton_pairwise(group, poses, start, steps)
    stack = _stack(layout, group, poses, start)
    converged, _ = _iterate(layout, group, stack, NEWTON_STEPS if steps is None else steps)
    return _split(stack[:, :len(group.links)].reshape(len(stack), -1), group.links), converged


def newton_closing(group: Group, poses: Poses, start: Poses, closure: float, steps: int | None = None):
    """Newton's method as :func:`newton`, each position stopped as soon as it closes to ``closure``.

    What following an assembly mode over a sweep needs (:mod:`linkage.kinematics.tracing`): poses
    that close to a tolerance, and how well they close, without the iteration that confirms a
    step below :data:`STEP_TOL` nor a separate evaluation of the residual.

    Parameters
    ----------
    poses : dict of link -> ndarray (N, 3) or (1, 3)
        Poses of the known links.
    start, steps
        As :func:`newton`.
    closure : float
        m: a position stops once every equation's residual (prismatic angle rows times the
        group's size) is at most this.

    Returns
    -------
    solved : dict of link -> ndarray (N, 3)
        The poses reached.
    gap : ndarray (N,)
        m: the largest residual at ``solved`` (inf where a pose is not finite).
    """
    steps = NEWTON_STEPS if steps is None else steps
    layout = layout_of(group)
    if layout is None:
        N = len(start[group.links[0]])
        poses = {k: np.broadcast_to(v, (N, 3)) for k, v in poses.items()}
        solved, _ = newton_pairwise(group, poses, start, steps)
        gap = np.max(np.abs(group.residual({**poses, **solved})), axis=1)
        return solved, np.nan_to_num(gap, nan=np.inf)
    stack = _stack(layout, group, poses, start)
    _, gap = _iterate(layout, group, stack, steps, closure)
    return _split(stack[:, :len(group.links)].reshape(len(stack), -1), group.links), gap


def _stack(layout, group: Group, poses: Poses, start: Poses) -> np.ndarray:
    """The pose stack ``(N, L + K, 3)`` of :meth:`assur.fused.FusedLayout.evaluate`: the start
    poses of the group's links, then the known links' poses (broadcast to N)."""
    links = group.links
    N = len(start[links[0]])
    stack = np.empty((N, len(layout.order), 3))
    for i, k in enumerate(layout.order):
        stack[:, i] = start[k] if i < len(links) else poses[k]
    return stack


def _iterate(layout, group: Group, stack: np.ndarray, steps: int, closure: float | None = None):
    """Newton's iterations on the pose stack ``stack`` (its group links' poses updated in place).

    Without ``closure`` a position stops when its step is below :data:`STEP_TOL` (converged),
    its system is singular or its poses leave the finite numbers: returns ``(converged, None)``.
    With ``closure`` (m) a position stops as soon as its residual is at most ``closure``:
    returns ``(None, gap)``, the largest residual at the poses left (inf where not finite).
    Steps are damped as in :func:`newton_pairwise`.
    """
    N, L = len(stack), len(group.links)
    width = 3 * L
    q = stack[:, :L].reshape(N, width)          # a view: the stack's rows of the group's links
    limit, unit, positive = layout.damping(group.size, N)
    converged = np.zeros(N, bool)
    gap = np.full(N, np.inf) if closure is not None else None
    weight = None           # (N, m): 1, the size on the prismatic angle rows (the closure is in m)
    if closure is not None and len(layout.angle_rows):
        weight = np.ones((N, layout.rows))
        weight[:, layout.angle_rows] = np.reshape(group.size, (-1, 1))
    rows = np.flatnonzero(np.isfinite(q).all(axis=1))       # the positions still iterated
    for _ in range(steps if len(rows) else 0):
        every = len(rows) == N
        residual, full = layout.evaluate(stack if every else stack[rows])
        if closure is not None:
            norm = np.abs(residual if weight is None else residual * weight[rows]).max(axis=1)
            close = norm <= closure
            if close.any():
                gap[rows[close]] = norm[close]
                keep = ~close
                rows, residual, full, norm = rows[keep], residual[keep], full[keep], norm[keep]
                if not len(rows):
                    break
                every = False
        step, solvable = _solve_regular(full[:, :, :width], -residual)
        scale = limit if limit.ndim == 1 else limit[rows]
        if solvable is True and positive:
            # every system solved, every step finite: the damping of newton_pairwise in fewer calls
            factor = (scale / np.maximum(np.abs(step), scale)).min(axis=1)
            step *= factor[:, None]
        else:
            solvable = np.ones(len(rows), bool) if solvable is True else solvable
            with np.errstate(invalid="ignore", divide="ignore"):
                factor = np.min(np.where(np.abs(step) > scale, scale / np.abs(step), 1.0), axis=1)
            step *= factor[:, None]
            step[~solvable] = 0.0
        if every:
            q += step
            here = q
        else:
            here = q[rows] + step
            q[rows] = here
        lost = None if np.isfinite(here).all() else ~np.isfinite(here).all(axis=1)     # positions that stop
        if solvable is not True:
            lost = ~solvable if lost is None else lost | ~solvable
            if closure is not None:
                gap[rows[~solvable]] = np.nan_to_num(norm[~solvable], nan=np.inf)
        if closure is None:
            done = ((np.abs(step) / (unit if unit.ndim == 1 else unit[rows])).max(axis=1) <= STEP_TOL) & (factor == 1.0)
            if solvable is not True:
                done &= solvable
            converged[rows[done]] = True
            lost = done if lost is None else done | lost
        if lost is not None and lost.any():
            rows = rows[~lost]
            if not len(rows):
                break
    else:
        if closure is not None and len(rows):           # out of steps: how well the last poses close
            residual, _ = layout.evaluate(stack[rows], jacobian=False)
            if weight is not None:
                residual = residual * weight[rows]
            with np.errstate(invalid="ignore"):
                gap[rows] = np.nan_to_num(np.abs(residual).max(axis=1), nan=np.inf)
    return converged, gap


def newton_pairwise(group: Group, poses: Poses, start: Poses, steps: int | None = None):
    """:func:`newton` with the residual and Jacobian assembled pair by pair
    (:meth:`Group.jacobians`): the reference of the fused path, and the path of a group whose
    pairs :mod:`assur.fused` does not know."""
    links = group.links
    steps = NEWTON_STEPS if steps is None else steps
    q = np.concatenate([np.asarray(start[k], float) for k in links], axis=1).copy()
    N = len(q)
    size = np.broadcast_to(np.asarray(group.size, float), (N,))
    active = np.all(np.isfinite(q), axis=1)
    converged = np.zeros(N, bool)
    angles = np.zeros(q.shape[1], bool)
    angles[2::3] = True
    for _ in range(steps):
        if not active.any():
            break
        rows = np.flatnonzero(active)
        current = {**{k: v[rows] for k, v in poses.items()}, **_split(q[rows], links)}
        residual = np.concatenate([j.residual(current) for j in group.joints], axis=1)
        phi_q, _ = group.jacobians(current)
        step, solvable = _solve(phi_q, -residual)
        # damping: no step moves a point by more than half the size or turns a link by more than 0.5 rad
        scale = np.where(angles, 0.5, 0.5 * size[rows, None])
        with np.errstate(invalid="ignore", divide="ignore"):
            factor = np.min(np.where(np.abs(step) > scale, scale / np.abs(step), 1.0), axis=1)
        step *= factor[:, None]
        q[rows] += np.where(solvable[:, None], step, 0.0)
        small = np.max(np.abs(step) / np.where(angles, 1.0, size[rows, None]), axis=1) <= STEP_TOL
        done = solvable & small & (factor == 1.0)
        converged[rows[done]] = True
        active[rows[done | ~solvable | ~np.all(np.isfinite(q[rows]), axis=1)]] = False
    return _split(q, links), converged


def _solve_regular(a: np.ndarray, b: np.ndarray):
    """:func:`_solve` where every system is finite and regular, ``(x, True)``; else :func:`_solve`."""
    if np.isfinite(b).all() and np.isfinite(a).all():
        try:
            with np.errstate(invalid="ignore", over="ignore", divide="ignore", under="ignore"):
                x = _SOLVE(a, b) if _SOLVE is not None else np.linalg.solve(a, b[..., None])[..., 0]
        except (np.linalg.LinAlgError, TypeError, ValueError):   # a numpy whose private solve differs too
            x = None
        if x is not None and np.isfinite(x).all():
            return x, True
    return _solve(a, b)


def _solve(a: np.ndarray, b: np.ndarray):
    """Batched ``a x = b`` ``(N, m, m)``, ``(N, m)``; ``(x, solvable)`` where exactly singular or
    non-finite systems give ``x = 0`` and ``solvable = False``."""
    solvable = np.all(np.isfinite(a), axis=(1, 2)) & np.all(np.isfinite(b), axis=1)
    a = np.where(solvable[:, None, None], a, np.eye(a.shape[1]))
    b = np.where(solvable[:, None], b, 0.0)
    try:
        return np.linalg.solve(a, b[..., None])[..., 0], solvable
    except np.linalg.LinAlgError:
        x = np.zeros_like(b)
        for n in range(len(a)):
            try:
                x[n] = np.linalg.solve(a[n], b[n])
            except np.linalg.LinAlgError:
                solvable[n] = False
        return x, solvable


def _split(q: np.ndarray, links) -> dict[str, np.ndarray]:
    return {k: q[:, 3 * i:3 * i + 3] for i, k in enumerate(links)}


class NewtonGroup(Group):
    """Any statically determinate group of revolute and prismatic pairs, solved by Newton's method
    from a start (see the module docstring). The registry tries it after the closed forms."""

    kind = "N"
    tracked = True      # its assembly plan traces its modes over a sweep and gives starts
    roundoff_factor = GROUP_ROUNDOFF_FACTOR     # for its conditioning sigma_min / sigma_max

    def __init__(self, links, joints, size=1.0):
        super().__init__(links, joints, size)
        self.group_class = group_class_of(self.links, self.joints)

    @classmethod
    def _bind(cls, links, joints, known, size):
        rows = sum(j.rows for j in joints)
        return cls(links, joints, size) if 3 * len(links) == rows and (len(links) >= 2 or rows > 2 * len(joints)) \
            else None

    def __repr__(self) -> str:
        return f"{self.group_class}({','.join(sorted(self.links, key=_natural))})"

    def residual(self, poses: Poses) -> np.ndarray:
        """:meth:`Group.residual` ``(N, m)``, evaluated fused (:mod:`assur.fused`)."""
        layout = layout_of(self)
        return super().residual(poses) if layout is None else layout.residual(poses, self.size)

    def jacobians(self, poses: Poses) -> tuple[np.ndarray, dict[str, np.ndarray]]:
        """:meth:`Group.jacobians` (``Phi_q`` ``(N, m, m)``, known links' blocks ``(N, m, 3)``),
        evaluated fused (:mod:`assur.fused`)."""
        layout = layout_of(self)
        return super().jacobians(poses) if layout is None else layout.jacobians(poses)

    def conditioning(self, phi_q: np.ndarray, poses: Poses) -> tuple[np.ndarray, np.ndarray]:
        """The group's distance to a singular position, scale-free, and the sign of its Jacobian's
        determinant.

        The ratio ``sigma_min / sigma_max`` of the singular values of the group Jacobian made
        dimensionless at the group's own scale as in :meth:`Group.conditioning` (rotations about
        the middle of each link's pairs, lengths in units of the largest distance between the
        group's pair points), each row then divided by its norm (the measure does not depend on how
        an equation is written). It is the inverse condition number of that Jacobian: 1 for
        orthogonal rows, 0 at a singular position, and it falls in proportion to the distance
        from one. The Hadamard ratio of the dyads is the product of all the singular values: for a
        12 x 12 Jacobian it is small at a well-proportioned position too (1e-3 for
        ``six_bar_class3``), this is not (0.01 .. 0.1).

        Parameters
        ----------
        phi_q : ndarray, shape (N, m, m)
            The group Jacobian (:meth:`Group.jacobians`).
        poses : dict
            Poses ``(N, 3)`` of the group's and known links.

        Returns
        -------
        ratio : ndarray, shape (N,)
            The conditioning in [0, 1].
        sign : ndarray, shape (N,)
            Sign of ``det(phi_q)``.
        """
        scaled = self.scaled_jacobian(phi_q, poses)
        norms = np.linalg.norm(scaled, axis=2, keepdims=True)
        values = np.linalg.svd(scaled / np.where(norms > 0, norms, 1.0), compute_uv=False)
        ratio = values[:, -1] / np.where(values[:, 0] > 0, values[:, 0], 1.0)
        return ratio, np.linalg.slogdet(phi_q)[0]

    def modes(self, poses: Poses):
        """Hook: every assembly mode at each position, ``({link: (N, K, 3)}, valid (N, K))``, or
        ``None`` when the kind cannot list them (the plan then finds them by Newton's method from
        many starts at the first angle and continues them)."""
        return None

    def position(self, poses: Poses, branch: int = 1, input_error=0.0, start: Poses | None = None) -> GroupPosition:
        """:meth:`Group.position` from ``start`` (the poses of the group's links near the wanted
        assembly mode, ``(N, 3)`` each).

        The singular check is :meth:`Group.position`'s with this kind's error model,
        its round-off factor :data:`GROUP_ROUNDOFF_FACTOR` for the conditioning :meth:`conditioning`. Where the kind lists
        its modes, the listed solution nearest to the start is polished. The position is also
        singular (-2) when a second listed mode is nearly as near (the start cannot
        tell them apart), or when no listed mode lies within :data:`TRACE_JUMP` of the size (the
        listing lost the start's mode, as it does next to a position where two modes meet; Newton's
        method then runs from the start itself). Statuses beyond :meth:`Group.position`'s:

        - -1 (cannot be assembled) where the start or a known pose is NaN (the traced mode does
          not exist there, or an earlier group failed);
        - -4 (``NOT_CONVERGED``) where Newton's method had a start but did not converge: the point
          it reached does not close, lies farther than :data:`TRACE_JUMP` of the size from the
          start (another assembly mode), or closes at a regular position while its last step was
          still above :data:`STEP_TOL` (a point that closes where the group is singular is -2:
          there the steps cannot settle). Its poses are NaN; :meth:`closure` gives the residual.
        """
        if start is None:
            raise ValueError(f"{self!r} is solved by Newton's method and needs start poses (its assembly plan)")
        solved, converged, ambiguous = self._reached(poses, start)
        N = len(converged)
        size = np.broadcast_to(np.asarray(self.size, float), (N,))
        with np.errstate(invalid="ignore"):
            wandered = _distance(self, solved, start) > TRACE_JUMP * size
        placed = self._checked(poses, solved, _finite_rows(solved) & ~wandered, input_error)
        status = placed.status.copy()
        started = _finite_rows(start) & _finite_rows({k: poses[k] for k in self.known_links})
        status[(status == OK) & ~converged] = NOT_CONVERGED
        status[started & (status == CANNOT_ASSEMBLE)] = NOT_CONVERGED
        status[ambiguous & (status == OK)] = SINGULAR
        unsolved = status == NOT_CONVERGED
        return GroupPosition({k: np.where(unsolved[:, None], np.nan, v) for k, v in placed.poses.items()}, status,
                             np.where(unsolved, 0.0, placed.jacobian_sign), placed.conditioning,
                             np.where(unsolved, np.inf, placed.error_bound))

    def closure(self, poses: Poses, start: Poses) -> np.ndarray:
        """Closure residual ``(N,)``, m, of the point Newton's method reaches from ``start`` (the
        solve of :meth:`position`): the largest opening of a pair -- for a revolute pair the
        distance between its points on the two links, for a prismatic pair the norm of the
        slider point's offset from the guide and the size times the angle error. NaN where the
        iteration left the finite numbers."""
        solved, _, _ = self._reached(poses, start)
        gaps = self.residual({**poses, **solved})
        return np.max(np.stack([np.linalg.norm(gaps[:, rows], axis=1) for rows in self.joint_rows], axis=1), axis=1)

    def _reached(self, poses: Poses, start: Poses):
        """Newton's method from ``start``, or from the listed mode nearest to it: the poses
        reached ``{link: (N, 3)}``, where its last step was below :data:`STEP_TOL`, and where the
        start cannot tell the listed modes apart (see :meth:`position`)."""
        ambiguous = np.zeros(len(next(iter(start.values()))), bool)
        listed = self.modes(poses)
        if listed is not None:
            start, ambiguous = _nearest(self, listed, start)
        solved, converged = newton(self, poses, start)
        return solved, converged, ambiguous

    def _position(self, poses: Poses, branch: int):
        raise ValueError(f"{self!r} is solved by Newton's method from start poses: call position(..., start=...)")


def _finite_rows(poses: Poses) -> np.ndarray:
    """``(N,)``: where every pose of ``poses`` is finite."""
    return np.all(np.isfinite(np.concatenate([np.asarray(v, float) for v in poses.values()], axis=1)), axis=1)


def _distance(group: Group, a: Poses, b: Poses) -> np.ndarray:
    """Distance ``(N,)``, m, between poses of the group's links (angles wrapped, weighted by the size)."""
    size = np.asarray(group.size, float)
    total = 0.0
    for k in group.links:
        d = np.asarray(a[k], float) - np.asarray(b[k], float)
        turn = (d[:, 2] + np.pi) % (2 * np.pi) - np.pi
        total = total + d[:, 0] ** 2 + d[:, 1] ** 2 + (size * turn) ** 2
    return np.sqrt(total)


def _nearest(group: NewtonGroup, listed, start):
    """The listed mode nearest to ``start`` at each position, and where the position is ambiguous:
    a second mode within twice that distance plus round-off, or no listed mode within
    :data:`TRACE_JUMP` of the size (the start's mode was not listed: next to a position where two
    modes meet the polish of the double root may fail); there the start itself is returned, for
    Newton's method."""
    candidates, valid = listed
    N, K = valid.shape
    reference = np.stack([start[k] for k in group.links], axis=1)          # (N, L, 3)
    options = np.stack([candidates[k] for k in group.links], axis=2)       # (N, K, L, 3)
    size = np.broadcast_to(np.asarray(group.size, float), (N,))
    difference = options - reference[:, None]
    difference[..., 2] = (difference[..., 2] + np.pi) % (2 * np.pi) - np.pi
    difference[..., 2] *= size[:, None, None]
    with np.errstate(invalid="ignore"):
        distance = np.where(valid, np.sqrt(np.sum(difference**2, axis=(2, 3))), np.inf)
    order = np.argsort(distance, axis=1)
    best, second = order[:, 0], order[:, 1] if K > 1 else order[:, 0]
    rows = np.arange(N)
    d1, d2 = distance[rows, best], distance[rows, second] if K > 1 else np.full(N, np.inf)
    with np.errstate(invalid="ignore"):
        found = (d1 <= TRACE_JUMP * size) & np.all(np.isfinite(reference), axis=(1, 2))
    chosen = {k: np.where(found[:, None], candidates[k][rows, best], start[k]) for k in group.links}
    ambiguous = np.where(found, d2 < 2.0 * d1 + 1e-9 * size, np.all(np.isfinite(reference), axis=(1, 2)))
    return chosen, ambiguous


def _natural(name: str):
    return (0, int(name), "") if name.isdigit() else (1, 0, name)
